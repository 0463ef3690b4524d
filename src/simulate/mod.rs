//! Stage 11, the virtual CMM (`inspc simulate`): runs a DMIS program — one inspc wrote
//! or one written elsewhere, as [`crate::dmis::read`] reads it, passing over what the
//! reader warned it does not run — against the part of its spec, moved and deformed by a
//! deviations file, and reports every feature and tolerance the program outputs (as
//! text, JSON, a DMIS results file, or QIF 3 Results: [`qif_results`]).
//!
//! The machine: per setup, the frame the program's `RECALL` of the machine's frame and
//! `ROTATE`s give before its `PAUSE` is the part's nominal place; the operator places
//! the part there,
//! off by the deviations' placement. Manual touches land on the part where the program
//! shows them; every move under `MODE/PROG` is swept with the real probe against part,
//! table and fixture ([`crate::access::Pose`]); each `PTMEAS` searches along its vector
//! from the approach point up to `SNSET/SEARCH` past the nominal for the actual
//! surface. Features are fitted to the tip centres and offset by the tip radius;
//! `DATSET` and `TRANS` build the alignments; `DATDEF`, `TOL` and `OUTPUT` evaluate
//! ([`evaluate`]). Measurement noise is Gaussian along each touch's vector, from a
//! seeded generator: the same seed gives the same report.
//!
//! Entry point: [`simulate`].

pub mod deviation;
mod errors;
pub mod evaluate;
mod machine;
mod number;
mod qif;
mod report;

/// The fits of measured points, shared with the path stage's alignment.
pub(crate) use crate::geometry::cmm_fit as fit;
pub use deviation::Deviations;
pub use errors::SimError;
pub use machine::{plan_of, simulate};
pub use qif::{qif_results, QifMeta};
pub use report::{FeatureRow, Report, Row};

use crate::geometry::{FaceId, FixtureMesh, PartGeometry};
use crate::model::Model;
use crate::source::FileId;

/// What the virtual CMM needs.
pub struct Input<'a> {
    /// The spec's model.
    pub model: &'a Model,
    /// The part's geometry.
    pub geometry: &'a PartGeometry,
    /// Per feature of the part, its faces.
    pub feature_faces: &'a [Vec<FaceId>],
    /// The plan's mesh fixtures placed with the part.
    pub fixtures: &'a [FixtureMesh],
    /// The program read.
    pub program: &'a crate::dmis::Program,
    /// The program's file, for spans.
    pub file: FileId,
    /// The program's text.
    pub text: &'a str,
    /// How the part and its placement differ from nominal.
    pub deviations: &'a Deviations,
}

/// How the virtual CMM measures.
#[derive(Debug, Clone, Copy, Default)]
pub struct Options {
    /// Standard deviation of each touch along its vector (mm).
    pub noise: f64,
    /// Seed of the noise.
    pub seed: u64,
}
