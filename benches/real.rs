//! End to end on real input: `inspc build` (front end, geometry, measurement graph,
//! planning, paths, DMIS) on the four NIST specs read from their STEP files and on every
//! example, as the command line runs it. Before timing, one build of each prints its
//! stages (`time:` as `inspc build` does) so the split is in the same run; then divan
//! times whole builds.
//!
//! `scaling` builds swiss_sphere_fixed with 7, 14 and 28 points per hole (140, 280 and
//! 560 fpoints): each doubling should at most double the time. (Before the hitting-set
//! search stopped recounting at every node, 560 points took 73 s.)
//!
//! Run with `cargo bench --bench real` (the NIST specs need `../shared/parts`).

use inspc::plan::PlanOptions;
use inspc::source::{FsWorld, MemoryWorld, World};
use std::path::{Path, PathBuf};

fn main() {
    for spec in SPECS.iter().copied().chain(examples()) {
        if !Path::new(spec).exists() {
            continue;
        }
        let (_, built, t) = build(&FsWorld, spec);
        let stages: Vec<String> = t
            .stages
            .iter()
            .map(|(s, secs)| format!("{s} {secs:.2} s"))
            .collect();
        let total: f64 = t.stages.iter().map(|s| s.1).sum();
        eprintln!(
            "{spec}: {total:.2} s ({}), {} programs",
            stages.join(", "),
            built
        );
    }
    divan::main();
}

const SPECS: [&str; 4] = [
    "tests/real/nist_ctc_01.insp",
    "tests/real/nist_ctc_02.insp",
    "tests/real/nist_ftc_06.insp",
    "tests/real/nist_ftc_08.insp",
];

/// Every example, read from `examples/` (sorted), so a new one is timed too.
fn examples() -> Vec<&'static str> {
    let mut out: Vec<String> = std::fs::read_dir("examples")
        .map(|d| {
            d.filter_map(|e| e.ok())
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|x| x == "insp"))
                .map(|p| p.to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    out.sort();
    out.into_iter().map(|s| &*s.leak()).collect()
}

fn build(world: &dyn World, spec: &str) -> (bool, usize, inspc::Timings) {
    let (checked, built, t) = inspc::build(
        world,
        &[PathBuf::from(spec)],
        &PlanOptions::default(),
        &|_, _, _| {},
    );
    (checked.has_errors(), built.len(), t)
}

#[divan::bench(args = SPECS, sample_count = 2, sample_size = 1)]
fn nist(spec: &str) {
    let (errors, built, _) = build(&FsWorld, spec);
    assert!(!errors && built == 1, "{spec}");
}

#[divan::bench(args = examples(), sample_count = 3, sample_size = 1)]
fn example(spec: &str) {
    let (errors, _, _) = build(&FsWorld, spec);
    assert!(!errors, "{spec}");
}

#[divan::bench(args = [7, 14, 28], sample_count = 2, sample_size = 1)]
fn scaling(bencher: divan::Bencher, per_hole: usize) {
    let spec = "examples/swiss_sphere_fixed.insp";
    let text = std::fs::read_to_string(spec).unwrap();
    let at = format!("hammersley(points {per_hole})");
    let text = text.replace("hammersley(points 7)", &at);
    assert!(text.contains(&at));
    // The spec's own folder, so its `use "parts/…"` resolves.
    let mut world = MemoryWorld::new();
    world.insert(spec, text);
    let part = "examples/parts/swiss_sphere.insp";
    world.insert(part, std::fs::read(part).unwrap());
    bencher.bench_local(|| {
        let (errors, _, _) = build(&world, spec);
        assert!(!errors);
    });
}
