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
    #[error("{left} of the {total} points of face `{face}` {verb} left out: generate-and-test did not settle after {iterations} rounds, and in the best plan found {why}")]
    #[diagnostic(code(insp::plan::points_left_out), severity(Warning), help("{help}"))]
    PointsLeftOut {
        #[label("`{face}` is part of this feature")]
        span: Span,
        face: String,
        left: usize,
        total: usize,
        verb: &'static str,
        iterations: usize,
        why: String,
        help: String,
    },
    #[error("tolerance `{tolerance}` reads the axis of `{feature}` over {touched} mm of the {sampled} mm its points on face `{face}` span: the points beyond no probe reaches, so a tilt reads at {share} % of its size")]
    #[diagnostic(
        code(insp::plan::short_axis),
        severity(Warning),
        help("a longer stylus or an extension in the rack reaches the far end, or a fixture that presents the bore along one of the head's orientations; until then a tilt of the axis reads smaller than it is by that share")
    )]
    ShortAxis {
        #[label("this tolerance")]
        span: Span,
        tolerance: String,
        feature: String,
        face: String,
        touched: String,
        sampled: String,
        share: String,
    },
    #[error("setup {setup} of `{plan}` runs only with the part set square to the machine axes {within}, not within {full}°: turned more, the stylus hits the part at {touches}")]
    #[diagnostic(
        code(insp::plan::placement_sensitive),
        severity(Warning),
        help("the setup's prompt asks the operator to square the part {within}; a stop or fixture that squares it, or a stylus with more room beside its stem at these faces, lets the program find the part anywhere within {full}°")
    )]
    PlacementSensitive {
        #[label("this plan")]
        span: Span,
        plan: String,
        setup: usize,
        within: String,
        full: String,
        touches: String,
    },
    #[error("tolerance `{tolerance}` reads its feature in setup {setup} against {datums}, which no probe reaches there: the plan measures {measured}")]
    #[diagnostic(
        code(insp::plan::datum_in_other_setup),
        severity(Warning),
        help("setup {setup}'s alignment, built on that setup's own features, carries the datum over as drawn, so an error between the feature and the datum can read as none; give the head an orientation or the rack a probe that reaches the datum in setup {setup}, or hold the part so that one setup presents both")
    )]
    DatumInOtherSetup {
        #[label("read against a datum measured in another setup")]
        span: Span,
        tolerance: String,
        datums: String,
        setup: usize,
        measured: String,
    },
    #[error("part `{part}` does not fit on the table of `{cmm}`: its smallest footprint is {footprint}, the table {table}")]
    #[diagnostic(
        code(insp::plan::part_off_table),
        help("plan it on a machine with a larger table (`table {{ size (…) }}`), or check the part's units")
    )]
    PartOffTable {
        #[label("this plan")]
        span: Span,
        part: String,
        cmm: String,
        footprint: String,
        table: String,
    },
    #[error("probe `{probe}` of `{cmm}` reaches {reach} mm below the head, as far as the ram travels ({ram} mm) or more")]
    #[diagnostic(
        code(insp::plan::probe_too_long),
        help("a probe longer than the ram cannot be lifted clear of the table; use a shorter stylus or extension")
    )]
    ProbeTooLong {
        #[label("this plan")]
        span: Span,
        probe: String,
        cmm: String,
        reach: String,
        ram: String,
    },
    #[error("tolerance `{tolerance}` is not measured: face `{face}` of feature `{feature}` {why}")]
    #[diagnostic(code(insp::plan::unmeasured), help("{help}"))]
    Unmeasured {
        #[label("this tolerance")]
        span: Span,
        tolerance: String,
        feature: String,
        face: String,
        why: String,
        help: String,
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

crate::diag::located!(PlanError {
    Unmeasured,
    UninspectableFace,
    NoConvergence,
    PointsLeftOut,
    ShortAxis,
    PlacementSensitive,
    DatumInOtherSetup,
    NoPlan,
    PartOffTable,
    ProbeTooLong,
});
