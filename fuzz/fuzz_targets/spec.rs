//! The spec front end (load, parse, resolve) on any bytes as `main.insp`: no panic, and
//! every diagnostic renders.
#![no_main]

use inspc::source::MemoryWorld;
use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;

fuzz_target!(|data: &[u8]| {
    let mut world = MemoryWorld::new();
    world.insert("main.insp", data.to_vec());
    let checked = inspc::check(&world, &[PathBuf::from("main.insp")]);
    for d in &checked.diagnostics {
        let _ = inspc::diag::render_human(&checked.sources, d, Default::default());
    }
});
