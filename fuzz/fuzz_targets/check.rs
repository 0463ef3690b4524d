//! The whole `check` pipeline — front end, geometry, sampling, measurement graphs — on any
//! spec: no panic, and every diagnostic renders.
#![no_main]

use inspc::source::MemoryWorld;
use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;

fuzz_target!(|data: &[u8]| {
    let mut world = MemoryWorld::new();
    world.insert("main.insp", data.to_vec());
    let (checked, _, _) = inspc::measurement_graphs(&world, &[PathBuf::from("main.insp")]);
    for d in &checked.diagnostics {
        let _ = inspc::diag::render_human(&checked.sources, d, Default::default());
    }
});
