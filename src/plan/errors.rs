//! The planner's diagnostics.

use crate::source::Span;

/// Why a plan could not be made.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[allow(missing_docs)]
pub enum PlanError {
    #[error("face `{face}` of feature `{feature}` cannot be inspected: {why}")]
    #[diagnostic(code(insp::plan::uninspectable_face), help("{help}"))]
    UninspectableFace {
        #[label("`{face}` is part of this feature")]
        span: Span,
        face: String,
        feature: String,
        why: String,
        help: String,
    },
    #[error("planning `{plan}` did not settle after {iterations} rounds of generate-and-test")]
    #[diagnostic(
        code(insp::plan::no_convergence),
        help("{last}; a probe with more clearance, or a preferred setup, usually settles it")
    )]
    NoConvergence {
        #[label("this plan")]
        span: Span,
        plan: String,
        iterations: usize,
        last: String,
    },
    #[error("part `{part}` has no plan, so there is no machine to plan for")]
    #[diagnostic(
        code(insp::plan::no_plan),
        help("add `plan <name> {{ part {part}, cmm <machine> }}` to the spec")
    )]
    NoPlan {
        #[label("this part")]
        span: Span,
        part: String,
    },
}

crate::located!(PlanError {
    UninspectableFace,
    NoConvergence,
    NoPlan,
});
