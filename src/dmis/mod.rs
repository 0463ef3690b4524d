//! Stage 10, DMIS (ANSI/DMIS 105.2, 5.3): the LLIP as a program the CMM runs
//! ([`write`]), and a reader for the statements we write ([`read`]) that checks what a
//! controller would. `text.rs` holds the lexical rules both share — the one number
//! formatter, labels, quoted text and line continuation.
//!
//! **Architecture Invariant:** output depends on the input alone: labels are handed out
//! in program order, numbers go through [`text::num`], and nothing reads the clock, the
//! environment or an absolute path.

mod read;
pub mod text;
mod units;
mod write;

pub use read::{read, word, Command, DmisError, Program, Statement, Word};
pub use write::{tol_word, tolerance_labels};

use crate::geometry::PartGeometry;
use crate::model::{Model, Plan};

/// What the writer needs.
pub struct Input<'a> {
    /// The model.
    pub model: &'a Model,
    /// The plan.
    pub plan: &'a Plan,
    /// The part's geometry.
    pub geometry: &'a PartGeometry,
    /// The high-level plan.
    pub hlip: &'a crate::plan::Hlip,
    /// Its moves.
    pub llip: &'a crate::path::Llip,
    /// The spec's file name (no folders), for the header.
    pub source: String,
}

/// Writes the DMIS program of a plan.
pub fn write(input: &Input) -> String {
    write::write(input)
}
