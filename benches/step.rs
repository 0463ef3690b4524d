//! CAD in: reading and meshing the four NIST STEP files (Part 21 parse, B-rep, exact
//! surfaces, tessellation at the reference meshes' resolution) and the three QIF files
//! (XML, B-rep, senses from the topology, the same tessellation, PMI), on one core. The
//! baseline beside it is reading the reference OBJ mesh of the same part, which is what
//! a spec read before STEP import.
//!
//! Run with `cargo bench --bench step`.

use inspc::geometry::step::{read, RESOLUTION};

fn main() {
    std::env::set_var("RAYON_NUM_THREADS", "1");
    divan::main();
}

const PARTS: [&str; 4] = ["ctc_01", "ctc_02", "ftc_06", "ftc_08"];

#[divan::bench(args = PARTS, sample_count = 5)]
fn step_read_and_mesh(bencher: divan::Bencher, part: &str) {
    let bytes = std::fs::read(format!("../shared/parts/nist_{part}_asme1_ap242-e1.stp"))
        .expect("the NIST parts beside the repository");
    bencher.bench_local(|| {
        let p = read(&bytes, RESOLUTION).expect("reads");
        assert!(!p.mesh.triangles.is_empty());
    });
}

const QIF: [&str; 3] = [
    "nist_ctc_01_asme1_ap242",
    "nist_ftc_06_asme1_ap242",
    "nist_ftc_08_asme1_ap242-1",
];

#[divan::bench(args = QIF, sample_count = 5)]
fn qif_read_and_mesh(bencher: divan::Bencher, stem: &str) {
    let bytes = std::fs::read(format!("../shared/parts/{stem}.qif"))
        .expect("the NIST parts beside the repository");
    bencher.bench_local(|| {
        let p = inspc::geometry::qif::read(&bytes, RESOLUTION).expect("reads");
        assert!(!p.mesh.triangles.is_empty());
    });
}

#[divan::bench(args = PARTS, sample_count = 5)]
fn obj_read_baseline(bencher: divan::Bencher, part: &str) {
    let path = format!("../shared/parts/nist_{part}_asme1_ap242-e1.obj");
    bencher.bench_local(|| {
        let m =
            inspc::geometry::read_mesh(&inspc::source::FsWorld, std::path::Path::new(&path), 1.0)
                .expect("reads");
        assert!(!m.triangles.is_empty());
    });
}
