//! Tour quality (seed ch. 5.3.2): the heuristic that orders more than
//! `tour::EXACT_MAX` points — nearest neighbour, 2-opt, Or-opt — is measured against the
//! optimum from dynamic programming on every instance small enough to solve exactly:
//! windows of 12 consecutive stand-offs from real programs and random point sets.

use inspc::path::tour::{exact, heuristic, nearest_neighbour, Matrix};
use inspc::plan::PlanOptions;
use inspc::source::FsWorld;
use std::path::PathBuf;

/// Windows of up to 12 consecutive stand-offs from the programs of some examples.
fn real_instances() -> Vec<Matrix> {
    let mut out = Vec::new();
    for spec in [
        "examples/f2.insp",
        "examples/f4.insp",
        "examples/swiss_block.insp",
        "examples/swiss_sphere_fixed.insp",
    ] {
        let (checked, built, _) = inspc::build(
            &FsWorld,
            &[PathBuf::from(spec)],
            &PlanOptions::default(),
            &|_, _, _| {},
        );
        assert!(!checked.has_errors(), "{spec}");
        for b in &built {
            for g in b.llip.setups.iter().flat_map(|s| &s.groups) {
                let pts: Vec<[f64; 3]> = g
                    .blocks
                    .iter()
                    .flat_map(|b| b.touches.iter().map(|t| t.standoff))
                    .collect();
                for w in pts.chunks(12).filter(|w| w.len() >= 5) {
                    out.push(Matrix::euclidean(w, g.entry.first().copied()));
                }
            }
        }
    }
    out
}

/// Random instances: uniform in a 100 mm cube, and in three tight clusters.
fn random_instances() -> Vec<Matrix> {
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut r = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 * 100.0
    };
    let mut out = Vec::new();
    for k in 0..120 {
        let n = 8 + k % 5;
        let pts: Vec<[f64; 3]> = if k % 2 == 0 {
            (0..n).map(|_| [r(), r(), r()]).collect()
        } else {
            let centres: Vec<[f64; 3]> = (0..3).map(|_| [r(), r(), r()]).collect();
            (0..n)
                .map(|i| {
                    let c = centres[i % 3];
                    [c[0] + r() / 20.0, c[1] + r() / 20.0, c[2] + r() / 20.0]
                })
                .collect()
        };
        let start = (k % 3 != 0).then(|| [r(), r(), r()]);
        out.push(Matrix::euclidean(&pts, start));
    }
    out
}

#[test]
fn the_heuristic_is_within_5_percent_of_the_optimum() {
    let real = real_instances();
    let random = random_instances();
    assert!(real.len() >= 50, "{} real instances", real.len());
    for (name, set) in [("real", &real), ("random", &random)] {
        let (mut worst, mut sum, mut nn_worst, mut nn_sum) = (1.0f64, 0.0, 1.0f64, 0.0);
        for m in set.iter() {
            let best = m.length(&exact(m));
            let h = m.length(&heuristic(m));
            let nn = m.length(&nearest_neighbour(m));
            let (rh, rn) = if best > 1e-9 {
                (h / best, nn / best)
            } else {
                (1.0, 1.0)
            };
            assert!(h >= best - 1e-6, "the optimum is optimal");
            assert!(rh <= 1.05, "{name}: heuristic {h} vs optimum {best}");
            worst = worst.max(rh);
            sum += rh;
            nn_worst = nn_worst.max(rn);
            nn_sum += rn;
        }
        let n = set.len() as f64;
        eprintln!(
            "{name}: {} instances; heuristic/optimum mean {:.4} worst {:.4}; nearest neighbour mean {:.4} worst {:.4}",
            set.len(),
            sum / n,
            worst,
            nn_sum / n,
            nn_worst
        );
    }
}

#[test]
fn every_order_is_a_permutation() {
    for m in random_instances().iter().take(20) {
        for order in [exact(m), heuristic(m), nearest_neighbour(m)] {
            let mut o = order.clone();
            o.sort_unstable();
            assert_eq!(o, (0..m.len()).collect::<Vec<_>>());
        }
    }
}
