//! The QIF reader on any bytes, as `check` calls it: the file read, its B-rep meshed
//! by the tessellator, its PMI read, the mesh segmented into its faces, and an error's
//! diagnostics rendered. No panic, no stack overflow, and the work bounded by the
//! reader's own budgets (nesting, references, points, triangles).
#![no_main]

use inspc::geometry::{qif, segment};
use inspc::source::{SourceMap, Span};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    match qif::read(data, inspc::geometry::step::RESOLUTION) {
        Ok(part) => {
            let _ = segment::from_groups(&part.mesh);
            let _ = part.pmi.notes.len();
        }
        Err(e) => {
            let mut sources = SourceMap::new();
            let id = sources.add("part".into(), None, "part".into());
            for d in e.at(Span::new(id, 0, 4), Path::new("part.qif")) {
                let _ = d.to_string();
            }
        }
    }
});
