//! The mesh readers (STL binary and ASCII, OBJ), then segmentation: no panic on any file.
//! The first byte picks the reader.
#![no_main]

use inspc::geometry::{read_mesh, segment};
use inspc::source::MemoryWorld;
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Some((&kind, bytes)) = data.split_first() else {
        return;
    };
    let name = if kind % 2 == 0 { "m.stl" } else { "m.obj" };
    let mut world = MemoryWorld::new();
    world.insert(name, bytes.to_vec());
    if let Ok(raw) = read_mesh(&world, Path::new(name), 1.0) {
        let _ = segment::segment(&raw);
        let _ = segment::from_groups(&raw);
    }
});
