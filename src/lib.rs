//! inspc: a compiler for CMM inspection.
//!
//! `.insp` specs in, DMIS programs out. See `ARCHITECTURE.md` for the pipeline; each
//! stage is a module with one documented entry point.
#![warn(missing_docs)]

pub mod diag;
pub mod source;
pub mod syntax;
