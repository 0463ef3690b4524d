//! Path-planning diagnostics.

use crate::source::Span;
use miette::Diagnostic;
use thiserror::Error;

/// What can stop the path planner.
#[derive(Debug, Error, Diagnostic)]
#[allow(missing_docs)]
pub(crate) enum PathError {
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
    #[error("setup {setup} of plan `{plan}` cannot be aligned on the part: nothing the operator can touch fixes {missing}")]
    #[diagnostic(
        code(insp::path::alignment_incomplete),
        severity(Warning),
        help("the alignment takes 3-2-1 from planes along the part's axes, bores along them and spheres; {missing} stays where the operator puts the part, so a part placed off reads off. Where the part is symmetric about that axis nothing depends on it; else give it a feature to touch (a flat, an end face), or a fixture that locates it")
    )]
    AlignmentIncomplete {
        #[label("setup {setup} of this plan")]
        span: Span,
        plan: String,
        setup: usize,
        missing: String,
    },
}

crate::diag::located!(PathError {
    NoPath,
    SelfAligned,
    AlignmentIncomplete
});
