//! The virtual CMM on any program and deviations file, against one fixed part (F2,
//! compiled once): no panic, whatever the two files say. The first byte chooses where
//! the rest splits into the program (before) and the deviations file (after).
#![no_main]

use inspc::simulate::{self, deviation, Deviations, Input, Options};
use inspc::source::{FileId, MemoryWorld};
use inspc::{Checked, PartData};
use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;
use std::sync::OnceLock;

/// Inputs past this are cut: a program's run costs a sweep per move, and libFuzzer's
/// per-input timeout must measure the simulator, not the input's length.
const MAX_INPUT: usize = 16 * 1024;

/// The fixed spec, checked with its geometry once for every input.
fn f2() -> &'static (Checked, Vec<Option<PartData>>) {
    static F2: OnceLock<(Checked, Vec<Option<PartData>>)> = OnceLock::new();
    F2.get_or_init(|| {
        let mut world = MemoryWorld::new();
        world.insert("f2.insp", include_str!("../../examples/f2.insp"));
        let (checked, parts) = inspc::check_geometry(&world, &[PathBuf::from("f2.insp")]);
        assert!(!checked.has_errors(), "the fixed spec checks clean");
        (checked, parts)
    })
}

fuzz_target!(|data: &[u8]| {
    let Some((&split, rest)) = data.split_first() else {
        return;
    };
    let rest = &rest[..rest.len().min(MAX_INPUT)];
    let at = rest.len() * split as usize / 255;
    let program = String::from_utf8_lossy(&rest[..at]);
    let deviations = String::from_utf8_lossy(&rest[at..]);
    let (checked, parts) = f2();
    let Some(data) = parts.first().and_then(Option::as_ref) else {
        return;
    };
    let part = &checked.model.parts[0];
    let (program_file, deviations_file) = (FileId(u32::MAX - 1), FileId(u32::MAX - 2));
    let Ok(read) = inspc::dmis::read(program_file, &program) else {
        return;
    };
    let deviations = if deviations.trim().is_empty() {
        Deviations::nominal(data.geometry.faces.len())
    } else {
        match deviation::parse(
            deviations_file,
            &deviations,
            part,
            &data.geometry,
            &data.feature_faces,
        ) {
            Ok(d) => d,
            Err(_) => return,
        }
    };
    let input = Input {
        model: &checked.model,
        geometry: &data.geometry,
        feature_faces: &data.feature_faces,
        fixtures: &data.fixtures,
        program: &read,
        file: program_file,
        text: &program,
        deviations: &deviations,
    };
    let _ = simulate::simulate(&input, &Options::default());
});
