//! The virtual CMM: `inspc simulate` on the golden programs of the four real parts, the
//! whole run (front end, geometry, every move swept, every touch searched, fits,
//! alignments, evaluation) on one thread, at nominal and with noise. The largest is
//! NIST FTC 06 (3 setups, about 1,200 touches and 3,000 moves).
//!
//! Run with `cargo bench --bench simulate`.

use inspc::simulate::Options;
use inspc::source::FsWorld;
use std::path::Path;

fn main() {
    // One thread: the run is sequential, and the figure is the one-core one.
    std::env::set_var("RAYON_NUM_THREADS", "1");
    divan::main();
}

#[divan::bench(args = ["ctc_01", "ctc_02", "ftc_06", "ftc_08"], sample_count = 5)]
fn simulate_real_part(bencher: divan::Bencher, part: &str) {
    let spec = format!("tests/real/nist_{part}.insp");
    let program = format!("tests/cases/real_nist_{part}/program.dmi");
    bencher.bench_local(|| {
        let r = inspc::simulate(
            &FsWorld,
            Path::new(&spec),
            Path::new(&program),
            None,
            &Options {
                noise: 0.002,
                seed: 1,
            },
        );
        assert!(r.report.is_some(), "{part}");
    });
}
