//! Path-planning diagnostics.

use crate::access::Blocker;
use crate::model::fmt_num;
use crate::source::Span;
use miette::Diagnostic;
use std::fmt;
use thiserror::Error;

/// What can stop the path planner.
#[derive(Debug, Error, Diagnostic)]
#[allow(missing_docs)]
pub(crate) enum PathError {
    #[error("no collision-free move reaches face `{face}` of feature `{feature}` with probe `{probe}`{}: {why}", at_angles(.orient))]
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
        /// The head's (A, B) where it indexes.
        orient: Option<(f64, f64)>,
        /// What hits the part on the way.
        why: NoWay,
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

/// Which move of a group finds no way, and what hits where one is known.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum NoWay {
    /// A component hits the part on the way between touches.
    OnTheWay(Blocker),
    /// A component hits the part along a scanning pass.
    AlongPass(Blocker),
    /// The roadmap found no route around the part.
    RoadmapBlocked,
    /// No way down to a scanning pass.
    DownToPass,
    /// No move between two scanning passes.
    BetweenPasses,
    /// No way up from the last scanning pass.
    UpFromLastPass,
    /// No way up to the clearance plane.
    UpToClearance,
}

impl fmt::Display for NoWay {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NoWay::OnTheWay(b) => write!(f, "{b} hits the part on the way"),
            NoWay::AlongPass(b) => write!(f, "{b} hits the part along a pass"),
            NoWay::RoadmapBlocked => {
                write!(
                    f,
                    "every route the roadmap tried around the part is blocked"
                )
            }
            NoWay::DownToPass => write!(f, "the way down to a pass"),
            NoWay::BetweenPasses => write!(f, "the move between passes"),
            NoWay::UpFromLastPass => write!(f, "the way up from the last pass"),
            NoWay::UpToClearance => write!(f, "the way up to the clearance plane"),
        }
    }
}

/// ` at A90 B-45` for an indexing head's orientation, nothing for a fixed head.
fn at_angles(orient: &Option<(f64, f64)>) -> String {
    orient.map_or(String::new(), |(a, b)| {
        format!(" at A{} B{}", fmt_num(a), fmt_num(b))
    })
}

crate::diag::located!(PathError {
    NoPath,
    SelfAligned,
    AlignmentIncomplete
});
