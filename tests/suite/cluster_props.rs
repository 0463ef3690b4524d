//! Property tests of the clustering operations (seed ch. 3.5.1 and 3.5.6): every set lands
//! in exactly one cluster, each cluster's underlying set is the intersection of its
//! members and is not empty, the greedy strategies are valid (underlying sets pairwise
//! disjoint), and the exact minimum never exceeds what a strategy finds.

use inspc::plan::cluster::{
    cluster, min_hitting_set, valid_clustering, Bits, Set, Strategy as Clustering,
};
use proptest::prelude::*;

fn sets() -> impl Strategy<Value = Vec<Vec<usize>>> {
    prop::collection::vec(prop::collection::vec(0usize..40, 1..8), 1..24)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn clusterings_partition_and_intersect(raw in sets(), w in prop::collection::vec(0.0f64..1.0, 40)) {
        let bits: Vec<Bits> = raw.iter().map(|s| Bits::of(40, s.iter().copied())).collect();
        let refs: Vec<&Bits> = bits.iter().collect();
        for strategy in Clustering::ALL {
            let cl = cluster(&refs, strategy, &|e| w[e]);
            let mut seen = vec![0; bits.len()];
            for c in &cl {
                prop_assert!(!c.set.is_empty());
                let mut mu = bits[c.members[0]].clone();
                for &m in &c.members {
                    seen[m] += 1;
                    mu = mu.and(&bits[m]);
                }
                prop_assert_eq!(&mu, &c.set);
            }
            prop_assert!(seen.iter().all(|&n| n == 1), "{:?}: {:?}", strategy, seen);
            if strategy != Clustering::Weighted {
                for (i, a) in cl.iter().enumerate() {
                    for b in &cl[i + 1..] {
                        prop_assert!(a.set.and(&b.set).is_empty(), "{:?} is not valid", strategy);
                    }
                }
            }
            let (min, proven) = min_hitting_set(&refs, 100_000);
            prop_assert!(!proven || min <= cl.len());
        }
    }

    #[test]
    fn the_greedy_clustering_cannot_merge_clusters(raw in sets()) {
        let bits: Vec<Bits> = raw.iter().map(|s| Bits::of(40, s.iter().copied())).collect();
        let refs: Vec<&Bits> = bits.iter().collect();
        let order: Vec<usize> = (0..bits.len()).collect();
        let cl = valid_clustering(&refs, &order);
        let (min, proven) = min_hitting_set(&refs, 100_000);
        prop_assert!(proven);
        prop_assert!(min <= cl.len());
        prop_assert!(min >= 1);
    }
}
