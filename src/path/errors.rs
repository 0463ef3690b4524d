//! Path-planning diagnostics.

use crate::source::Span;
use miette::Diagnostic;
use thiserror::Error;

/// What can stop the path planner.
#[derive(Debug, Error, Diagnostic)]
#[allow(missing_docs)]
pub enum PathError {
    #[error("no collision-free move reaches face `{face}` of feature `{feature}` with probe `{probe}`{orient}: {why}")]
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
        /// What hits the part on the way, in words.
        why: String,
    },
    #[error("tolerance `{tolerance}` reads `{feature}` as measured in setup {setup}, whose alignment stands on `{feature}` itself: a misplaced `{feature}` reads in place")]
    #[diagnostic(
        code(insp::path::self_aligned),
        severity(Warning),
        help("{datums} measured in setup {setup}, so the setup's frame, which `{feature}` fixes, stands in for them; make a datum feature reachable in that setup (a fixture, another pose) or measure `{feature}` where its datums are")
    )]
    SelfAligned {
        #[label("read against the frame `{feature}` sets")]
        span: Span,
        tolerance: String,
        feature: String,
        setup: usize,
        datums: String,
    },
}

crate::located!(PathError {
    NoPath,
    SelfAligned
});
