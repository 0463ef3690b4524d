//! Path planning: the whole path stage (roadmaps with the CMM local planner, parry
//! checks, shortest paths, tours, alignment) from HLIP to LLIP on real plans, and the
//! tour heuristic against the plain nearest-neighbour tour on 30, 100 and 300 random
//! goals (the seed planned 30 and 100 goals in 13 s and 24 s). Before timing, it prints
//! the tour lengths: heuristic vs nearest neighbour on the same instances.
//!
//! Run with `cargo bench --bench paths`.

use inspc::path::tour::{heuristic, nearest_neighbour, Matrix};
use inspc::plan::PlanOptions;
use inspc::source::FsWorld;
use std::path::PathBuf;

fn main() {
    for n in [30, 100, 300] {
        let m = goals(n, 7);
        let (h, nn) = (m.length(&heuristic(&m)), m.length(&nearest_neighbour(&m)));
        eprintln!(
            "{n} goals: heuristic {h:.1} mm, nearest neighbour {nn:.1} mm ({:.1} % longer)",
            (nn / h - 1.0) * 100.0
        );
    }
    for spec in ["examples/swiss_block.insp", "tests/real/nist_ctc_01.insp"] {
        let (checked, built, _) = inspc::build(
            &FsWorld,
            &[PathBuf::from(spec)],
            &PlanOptions::default(),
            &|_, _, _| {},
        );
        assert!(!checked.has_errors(), "{spec}");
        // Each group's stand-offs in program order, re-ordered both ways (straight-line
        // distances).
        let (mut h, mut nn, mut ours) = (0.0, 0.0, 0.0);
        for g in built[0].llip.setups.iter().flat_map(|s| &s.groups) {
            let pts: Vec<[f64; 3]> = g
                .blocks
                .iter()
                .flat_map(|b| b.touches.iter().map(|t| t.standoff))
                .collect();
            let m = Matrix::euclidean(&pts, g.entry.first().copied());
            ours += m.length(&(0..pts.len()).collect::<Vec<_>>());
            h += m.length(&heuristic(&m));
            nn += m.length(&nearest_neighbour(&m));
        }
        eprintln!(
            "{spec}: straight-line tour of the program {ours:.0} mm (blocks kept whole); unconstrained heuristic {h:.0} mm, nearest neighbour {nn:.0} mm"
        );
    }
    divan::main();
}

/// `n` random goals in a 200 × 200 × 100 mm box, from a start in its corner.
fn goals(n: usize, seed: u64) -> Matrix {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut r = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let pts: Vec<[f64; 3]> = (0..n)
        .map(|_| [200.0 * r(), 200.0 * r(), 100.0 * r()])
        .collect();
    Matrix::euclidean(&pts, Some([0.0, 0.0, 0.0]))
}

#[divan::bench(args = [30, 100, 300])]
fn tour_heuristic(bencher: divan::Bencher, n: usize) {
    let m = goals(n, 7);
    bencher.bench_local(|| heuristic(&m));
}

#[divan::bench(args = [30, 100, 300])]
fn tour_nearest_neighbour(bencher: divan::Bencher, n: usize) {
    let m = goals(n, 7);
    bencher.bench_local(|| nearest_neighbour(&m));
}

#[divan::bench(args = [
    "examples/swiss_block.insp",
    "examples/swiss_sphere_indexed.insp",
    "tests/real/nist_ctc_01.insp",
], sample_count = 3, sample_size = 1)]
fn path_stage(bencher: divan::Bencher, spec: &str) {
    let (checked, parts, graphs, planned) =
        inspc::plans(&FsWorld, &[PathBuf::from(spec)], &PlanOptions::default());
    let model = &checked.model;
    let p = &planned[0];
    let plan = &model.plans[p.plan];
    let g = graphs
        .iter()
        .find(|g| g.graph.plan.as_deref() == Some(&plan.name))
        .unwrap();
    let input = inspc::plan::Input {
        model,
        plan,
        geometry: &parts[g.part].as_ref().unwrap().geometry,
        fixtures: &parts[g.part].as_ref().unwrap().fixtures,
        graph: &g.graph,
    };
    let hlip = p.hlip.as_ref().unwrap();
    // The scene is built once per part and shared by the path stage's attempts.
    let scene = inspc::access::Scene::of_part(input.geometry);
    bencher.bench_local(|| {
        let mut diags = inspc::diag::Diagnostics::new();
        inspc::path::plan(
            &input,
            hlip,
            &scene,
            &|_, _| {},
            &mut diags,
            &mut Vec::new(),
        )
        .unwrap()
    });
}
