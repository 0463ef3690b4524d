//! `inspc import`: a starter spec written from a STEP or QIF file's B-rep and semantic PMI.
//!
//! Entry point [`import`]: the file's bytes in, the text of an `.insp` spec out. The spec
//! names the STEP file as its part, declares one feature per PMI feature (the faces a
//! datum, tolerance or dimension applies to), every datum and every tolerance and size
//! the language can express, a comment for each one it cannot and why, a CMM and probe
//! rack sized to the part from the stdlib, and a plan. It is a pure function of its
//! input: importing twice gives the same text.
//!
//! **Architecture Invariant:** the importer writes only what the language accepts: each
//! tolerance is checked against `resolve::accepts` (datums, modifiers, Ø zones) and the
//! reference rules resolve enforces (a datum feature never referenced by its own
//! tolerance, a datum once per frame) before it is written; what fails is a comment.
//! Nothing the file says reaches the text but through `text::source` (identifiers,
//! string literals, comments; datum letters through its `DatumLetters`) and
//! `values::written` (numbers): a name, label or path cannot end a string or a comment
//! or open an item, and an item whose value the spec cannot hold is left out with a
//! comment and a warning ([`LeftOut`]).

mod angles;
mod errors;
mod fits;
mod levels;
mod reach;
mod recognise;
mod text;
mod touch;
mod values;
mod write;

use crate::geometry::step;
use crate::geometry::MeshError;
pub use errors::{ImportError, LeftOut};
use write::write_spec;

/// What to write where the spec refers outside itself.
#[derive(Debug, Clone)]
pub struct ImportOptions {
    /// The STEP or QIF file as the spec should name it (relative to the spec's
    /// folder); its extension says which it is.
    pub cad_path: String,
    /// The part's name (an identifier).
    pub part_name: String,
    /// The factor the file's geometry is scaled by after its unit (1: as modelled);
    /// the spec's `mesh` says it again, so the spec reads the part at this size.
    pub scale: f64,
}

/// A spec written from a STEP file, and what went into it.
#[derive(Debug, Clone)]
pub struct Imported {
    /// The `.insp` text.
    pub text: String,
    /// Faces read.
    pub faces: usize,
    /// Datums read, and written.
    pub datums: (usize, usize),
    /// Geometric tolerances read, and written.
    pub tolerances: (usize, usize),
    /// Dimensions read, and written as size or location tolerances.
    pub dimensions: (usize, usize),
    /// The items left out for a value the spec cannot hold, each also a comment in
    /// the spec: warnings for the caller to place on the file's path.
    pub warnings: Vec<LeftOut>,
    /// For a file without PMI, the tolerances of the default inspection written
    /// (general tolerances in place of the drawing's); 0 when the file has PMI.
    pub defaults: usize,
}

/// A file stem as an identifier: letters, digits and `_`, lower case, starting with a
/// letter, and no keyword (`part.stp` gives `part_`).
pub fn identifier(stem: &str) -> String {
    let mut id: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    if !id.starts_with(|c: char| c.is_ascii_alphabetic()) {
        id.insert_str(0, "part_");
    }
    text::source(&id, text::Place::Identifier)
}

/// Reads a STEP or QIF file (by `opts.cad_path`'s extension) and writes a spec for it.
pub fn import(bytes: &[u8], opts: &ImportOptions) -> Result<Imported, MeshError> {
    let qif = opts.cad_path.to_ascii_lowercase().ends_with(".qif");
    // The chord is the part's: a model scaled up is meshed finer in its own unit.
    let res = step::Resolution {
        chord_mm: step::RESOLUTION.chord_mm / opts.scale,
        ..step::RESOLUTION
    };
    let mut part = if qif {
        crate::geometry::qif::read(bytes, res)?
    } else {
        step::read(bytes, res)?
    };
    if opts.scale != 1.0 {
        scale(&mut part, opts.scale);
    }
    Ok(write_spec(&part, opts))
}

/// The part scaled by `s`: its geometry, and the nominal lengths of its dimensions
/// (their limits are the drawing's deviations and stay).
fn scale(part: &mut step::CadPart, s: f64) {
    part.mesh.scale(s);
    for d in part.pmi.dimensions.iter_mut().filter(|d| !d.angular) {
        d.nominal = d.nominal.map(|n| n * s);
    }
}
