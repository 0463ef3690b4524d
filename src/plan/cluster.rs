//! Clustering (seed ch. 3.5.1, 3.5.6 and 3.6.1): partitioning a collection of sets into
//! clusters whose members share a non-empty intersection, the *underlying set*.
//!
//! The sets are bitsets — cube-map cones for setups, probe sets, A/B-grid orientation
//! sets — behind [`Set`], so one implementation serves every variable.

pub use crate::access::ones;
use crate::access::CubeMap;

/// A set the solver clusters: a bitset over a fixed universe.
pub trait Set: Clone {
    /// The intersection.
    fn and(&self, o: &Self) -> Self;
    /// The bits, 64 to a word; bits past the universe are zero.
    fn words(&self) -> &[u64];
    /// Whether the set has no element.
    fn is_empty(&self) -> bool {
        self.words().iter().all(|&w| w == 0)
    }
    /// Whether element `e` is in the set.
    fn has(&self, e: usize) -> bool {
        self.words()
            .get(e / 64)
            .is_some_and(|w| w >> (e % 64) & 1 == 1)
    }
    /// The number of elements.
    fn count(&self) -> usize {
        self.words().iter().map(|w| w.count_ones() as usize).sum()
    }
    /// Whether the two sets share no element (without making their intersection).
    fn disjoint(&self, o: &Self) -> bool {
        self.words().iter().zip(o.words()).all(|(a, b)| a & b == 0)
    }
    /// Whether every element of this set is in `o`.
    fn within(&self, o: &Self) -> bool {
        self.words().iter().zip(o.words()).all(|(a, b)| a & !b == 0)
    }
    /// The number of elements of the union (without making it).
    fn count_or(&self, o: &Self) -> usize {
        self.words()
            .iter()
            .zip(o.words())
            .map(|(a, b)| (a | b).count_ones() as usize)
            .sum()
    }
}

impl Set for CubeMap {
    fn and(&self, o: &Self) -> Self {
        CubeMap::and(self, o)
    }
    fn words(&self) -> &[u64] {
        CubeMap::words(self)
    }
}

/// A plain bitset over `0..len`: probes of a rack, orientations of a head's grid.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Bits {
    len: usize,
    words: Vec<u64>,
}

impl Bits {
    /// The empty set over `0..len`.
    pub fn empty(len: usize) -> Bits {
        Bits {
            len,
            words: vec![0; len.div_ceil(64)],
        }
    }

    /// Every element of `0..len`.
    pub fn full(len: usize) -> Bits {
        let mut b = Bits::empty(len);
        (0..len).for_each(|e| b.insert(e));
        b
    }

    /// The set of the given elements.
    pub fn of(len: usize, elems: impl IntoIterator<Item = usize>) -> Bits {
        let mut b = Bits::empty(len);
        elems.into_iter().for_each(|e| b.insert(e));
        b
    }

    /// Adds an element.
    pub fn insert(&mut self, e: usize) {
        debug_assert!(e < self.len);
        self.words[e / 64] |= 1 << (e % 64);
    }

    /// Removes an element.
    pub fn remove(&mut self, e: usize) {
        self.words[e / 64] &= !(1 << (e % 64));
    }

    /// The union.
    pub fn or(&self, o: &Bits) -> Bits {
        Bits {
            len: self.len,
            words: self
                .words
                .iter()
                .zip(&o.words)
                .map(|(a, b)| a | b)
                .collect(),
        }
    }

    /// The elements, ascending.
    pub fn ones(&self) -> impl Iterator<Item = usize> + '_ {
        ones(&self.words)
    }
}

impl Set for Bits {
    fn and(&self, o: &Self) -> Self {
        Bits {
            len: self.len,
            words: self
                .words
                .iter()
                .zip(&o.words)
                .map(|(a, b)| a & b)
                .collect(),
        }
    }
    fn words(&self) -> &[u64] {
        &self.words
    }
}

/// A cluster: members (indices into the clustered collection) and their underlying set.
#[derive(Debug, Clone, PartialEq)]
pub struct Cluster<S> {
    /// The intersection of the members' sets (non-empty unless a member was empty).
    pub set: S,
    /// The members, ascending.
    pub members: Vec<usize>,
}

/// How a clustering operation visits its input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Strategy {
    /// The seed's greedy valid clustering, input in graph order.
    Given,
    /// Greedy valid clustering, input in reverse graph order.
    Reversed,
    /// Greedy valid clustering, smallest sets first (the most constrained lead).
    SmallestFirst,
    /// The item-buffer clustering of ch. 3.6.1: repeatedly take every set holding the
    /// element of highest size × weight. Not always valid (underlying sets may overlap),
    /// as the seed notes, but it honours preferences and is greedy set cover at heart.
    Weighted,
}

impl Strategy {
    /// Every strategy, in the order ties are broken.
    pub const ALL: [Strategy; 4] = [
        Strategy::Weighted,
        Strategy::SmallestFirst,
        Strategy::Given,
        Strategy::Reversed,
    ];

    /// Its name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Given => "graph order",
            Strategy::Reversed => "reverse graph order",
            Strategy::SmallestFirst => "smallest first",
            Strategy::Weighted => "weighted",
        }
    }
}

/// Clusters `w` by `strategy`; `weight` gives each element's preference weight for the
/// weighted strategy. Deterministic: ties go to the lower index.
pub fn cluster<S: Set>(
    w: &[&S],
    strategy: Strategy,
    weight: &dyn Fn(usize) -> f64,
) -> Vec<Cluster<S>> {
    match strategy {
        Strategy::Given => valid_clustering(w, &(0..w.len()).collect::<Vec<_>>()),
        Strategy::Reversed => valid_clustering(w, &(0..w.len()).rev().collect::<Vec<_>>()),
        Strategy::SmallestFirst => {
            let mut order: Vec<usize> = (0..w.len()).collect();
            order.sort_by_key(|&i| (w[i].count(), i));
            valid_clustering(w, &order)
        }
        Strategy::Weighted => weighted_clustering(w, weight),
    }
}

/// The seed's valid clustering operation (ch. 3.5.6), visiting `w` in `order`: each
/// cluster starts with the first set left and takes every later set that keeps the
/// intersection non-empty. Every set lands in exactly one cluster and the underlying
/// sets are pairwise disjoint. An empty set forms a cluster of its own.
pub fn valid_clustering<S: Set>(w: &[&S], order: &[usize]) -> Vec<Cluster<S>> {
    let mut left: Vec<usize> = order.to_vec();
    let mut out = Vec::new();
    while let Some(&first) = left.first() {
        let mut mu = w[first].clone();
        let mut members = vec![first];
        let mut rest = Vec::with_capacity(left.len());
        for &i in &left[1..] {
            if mu.is_empty() {
                rest.push(i);
                continue;
            }
            let next = mu.and(w[i]);
            if next.is_empty() {
                rest.push(i);
            } else {
                mu = next;
                members.push(i);
            }
        }
        members.sort_unstable();
        out.push(Cluster { set: mu, members });
        left = rest;
    }
    out
}

/// The item-buffer clustering (ch. 3.6.1): count, per element, the sets left that hold
/// it; take the element of best size × weight (then size, then lowest index) and make
/// every set holding it a cluster; repeat.
pub(crate) fn weighted_clustering<S: Set>(
    w: &[&S],
    weight: &dyn Fn(usize) -> f64,
) -> Vec<Cluster<S>> {
    let mut left: Vec<usize> = (0..w.len()).collect();
    let mut out = Vec::new();
    let bits = w.first().map_or(0, |s| s.words().len() * 64);
    let mut counts = vec![0u32; bits];
    while !left.is_empty() {
        counts.iter_mut().for_each(|c| *c = 0);
        for &i in &left {
            for e in ones(w[i].words()) {
                counts[e] += 1;
            }
        }
        let mut best: Option<(f64, u32, usize)> = None;
        for (e, &c) in counts.iter().enumerate() {
            if c == 0 {
                continue;
            }
            let score = c as f64 * weight(e);
            let better = match best {
                None => true,
                Some((bs, bc, _)) => score > bs || (score == bs && c > bc),
            };
            if better {
                best = Some((score, c, e));
            }
        }
        let Some((_, _, e)) = best else {
            // Only empty sets are left: each is its own cluster.
            for &i in &left {
                out.push(Cluster {
                    set: w[i].clone(),
                    members: vec![i],
                });
            }
            break;
        };
        let (members, rest): (Vec<usize>, Vec<usize>) = left.iter().partition(|&&i| w[i].has(e));
        let mut mu = w[members[0]].clone();
        for &i in &members[1..] {
            mu = mu.and(w[i]);
        }
        out.push(Cluster { set: mu, members });
        left = rest;
    }
    out
}

/// The fewest elements that hit every set (the minimum number of clusters, ch. 3.5.6,
/// NP-hard in general), by branch and bound over distinct element signatures, within
/// `budget` search nodes. Returns the best count found and whether it is proven minimal;
/// the lower bound when the search gives up is a packing of pairwise disjoint sets.
pub fn min_hitting_set<S: Set>(w: &[&S], budget: usize) -> (usize, bool) {
    if w.is_empty() {
        return (0, true);
    }
    // Each element's signature: the sets that hold it, as a bitset over `w`, in the
    // elements' order.
    let universe = w.iter().map(|s| s.words().len()).max().unwrap_or(0) * 64;
    let mut sig: Vec<Option<Bits>> = vec![None; universe];
    for (i, s) in w.iter().enumerate() {
        for e in ones(s.words()) {
            sig[e].get_or_insert_with(|| Bits::empty(w.len())).insert(i);
        }
    }
    let mut cands: Vec<Bits> = sig.into_iter().flatten().collect();
    cands.sort_by(|a, b| b.count().cmp(&a.count()).then(a.words.cmp(&b.words)));
    cands.dedup();
    // Drop signatures contained in another.
    let mut keep: Vec<Bits> = Vec::new();
    for c in cands {
        if !keep.iter().any(|k| c.within(k)) {
            keep.push(c);
        }
    }
    let n = w.len();
    if w.iter().any(|s| s.is_empty()) {
        return (usize::MAX, true);
    }
    // Lower bound: greedy packing of pairwise disjoint sets, smallest first.
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&i| (w[i].count(), i));
    let mut packed: Vec<usize> = Vec::new();
    for &i in &order {
        if packed.iter().all(|&j| w[i].disjoint(w[j])) {
            packed.push(i);
        }
    }
    let lower = packed.len();
    // Upper bound: greedy hitting set.
    let mut covered = Bits::empty(n);
    let mut greedy = 0;
    while covered.count() < n {
        let best = keep
            .iter()
            .max_by_key(|c| c.count_or(&covered))
            .expect("every set is non-empty");
        covered = covered.or(best);
        greedy += 1;
    }
    if greedy == lower {
        return (greedy, true);
    }
    // The sets in branching order — fewest candidates hitting them first (the most
    // constrained), ties by index — and each set's candidates in `keep` order: fixed
    // for the whole search, so a node finds its branch without counting again.
    let hitters: Vec<Vec<usize>> = (0..n)
        .map(|i| (0..keep.len()).filter(|&c| keep[c].has(i)).collect())
        .collect();
    let mut branching: Vec<usize> = (0..n).collect();
    branching.sort_by_key(|&i| (hitters[i].len(), i));
    struct Search<'a> {
        keep: &'a [Bits],
        hitters: &'a [Vec<usize>],
        order: &'a [usize],
        best: usize,
        nodes: usize,
        budget: usize,
        complete: bool,
    }
    impl Search<'_> {
        fn run(&mut self, covered: &Bits, depth: usize) {
            self.nodes += 1;
            if self.nodes > self.budget {
                self.complete = false;
                return;
            }
            // Branch on the first uncovered set in branching order.
            let Some(&first) = self.order.iter().find(|&&i| !covered.has(i)) else {
                self.best = self.best.min(depth);
                return;
            };
            if depth + 1 >= self.best {
                return;
            }
            for &c in &self.hitters[first] {
                self.run(&covered.or(&self.keep[c]), depth + 1);
                if !self.complete {
                    return;
                }
            }
        }
    }
    let mut search = Search {
        keep: &keep,
        hitters: &hitters,
        order: &branching,
        best: greedy,
        nodes: 0,
        budget,
        complete: true,
    };
    search.run(&Bits::empty(n), 0);
    if search.complete {
        (search.best, true)
    } else {
        (lower, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sets(spec: &[&[usize]]) -> Vec<Bits> {
        spec.iter()
            .map(|s| Bits::of(8, s.iter().copied()))
            .collect()
    }

    #[test]
    fn the_seeds_order_example() {
        // Fig. 3.11: A..E where {A,B,C} and {D,E} share elements; order matters.
        let w = sets(&[&[0, 1], &[1, 2], &[1, 3], &[4, 5], &[5, 6]]);
        let refs: Vec<&Bits> = w.iter().collect();
        let c = valid_clustering(&refs, &[0, 3, 1, 4, 2]);
        assert_eq!(c.len(), 2);
        let c = valid_clustering(&refs, &[2, 3, 0, 1, 4]);
        assert!(c.len() >= 2);
        assert_eq!(min_hitting_set(&refs, 1000), (2, true));
    }

    #[test]
    fn weighted_prefers_heavy_elements() {
        let w = sets(&[&[0, 1], &[1], &[0]]);
        let refs: Vec<&Bits> = w.iter().collect();
        let c = weighted_clustering(&refs, &|e| if e == 0 { 1.0 } else { 0.1 });
        assert_eq!(c[0].members, vec![0, 2]);
        assert_eq!(c.len(), 2);
    }
}
