//! Front-end speed: parsing alone against the whole check (load, parse every module
//! including the stdlib, resolve), on the largest example, the real NIST spec and an
//! empty spec (the cost of the always-loaded standard library); then geometry, and
//! geometry with sampling and the measurement graph, on top.
//!
//! Run with `cargo bench --bench front_end`.

use inspc::source::{FileId, FsWorld};
use std::path::PathBuf;

fn main() {
    divan::main();
}

const SPECS: [&str; 3] = [
    "examples/swiss_block.insp",
    "tests/real/nist_ctc_01.insp",
    "examples/parts/swiss_sphere.insp",
];

/// Baseline: the grammar alone on one file's text.
#[divan::bench(args = SPECS)]
fn parse_only(bencher: divan::Bencher, spec: &str) {
    let text = std::fs::read_to_string(spec).unwrap();
    bencher.bench(|| inspc::syntax::parse(FileId(0), divan::black_box(&text)).unwrap());
}

/// The whole front end, as `inspc check` runs it (files read from disk).
#[divan::bench(args = SPECS)]
fn check(bencher: divan::Bencher, spec: &str) {
    let roots = [PathBuf::from(spec)];
    bencher.bench(|| {
        let c = inspc::check(&FsWorld, divan::black_box(&roots));
        assert!(!c.has_errors());
        c
    });
}

/// The standard library alone (an empty spec still loads and resolves it).
#[divan::bench]
fn stdlib_only(bencher: divan::Bencher) {
    let mut world = inspc::source::MemoryWorld::new();
    world.insert("empty.insp", "");
    let roots = [PathBuf::from("empty.insp")];
    bencher.bench(|| inspc::check(&world, divan::black_box(&roots)));
}

/// Geometry on top of the front end: booleans and face classification for constructive
/// parts, reading and fitting for the NIST mesh (issue 3's budget: well under 100 ms
/// for swiss_block).
#[divan::bench(args = PARTS)]
fn check_and_geometry(bencher: divan::Bencher, spec: &str) {
    let roots = [PathBuf::from(spec)];
    bencher.bench(|| {
        let (c, g) = inspc::check_geometry(&FsWorld, divan::black_box(&roots));
        assert!(!c.has_errors() && g.iter().any(Option::is_some));
        g
    });
}

const PARTS: [&str; 4] = [
    "examples/swiss_block.insp",
    "examples/swiss_sphere_fixed.insp",
    "tests/real/nist_ctc_01.insp",
    "tests/real/nist_ftc_08.insp",
];

/// Everything up to the measurement graph: front end, geometry, fpoint sampling and the
/// graph, as `inspc graph` runs it (issue 3's budget: well under 100 ms for swiss_block).
#[divan::bench(args = PARTS)]
fn check_geometry_and_graph(bencher: divan::Bencher, spec: &str) {
    let roots = [PathBuf::from(spec)];
    bencher.bench(|| {
        let (c, _, graphs) = inspc::measurement_graphs(&FsWorld, divan::black_box(&roots));
        assert!(!c.has_errors() && !graphs.is_empty());
        graphs
    });
}
