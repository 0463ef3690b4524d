//! Path-planning diagnostics.

use crate::source::Span;
use miette::Diagnostic;
use thiserror::Error;

/// What can stop the path planner.
#[derive(Debug, Error, Diagnostic)]
#[allow(missing_docs)]
pub enum PathError {
    #[error("no collision-free move reaches face `{face}` of feature `{feature}` with probe `{probe}`{orient}: {blocker} hits the part on the way")]
    #[diagnostic(
        code(insp::path::no_path),
        help("the touch itself is clear, but no path the local planner or the roadmap found gets there; a longer stylus, another orientation or a larger `motion {{ clearance }}` may open one")
    )]
    NoPath {
        #[label("`{face}` is part of this feature")]
        span: Span,
        face: String,
        feature: String,
        probe: String,
        orient: String,
        blocker: String,
    },
}

crate::located!(PathError { NoPath });
