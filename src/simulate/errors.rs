//! What stops the virtual CMM, and what is wrong in a deviations file.

use crate::source::Span;
use miette::Diagnostic;
use thiserror::Error;

/// A problem running a program on the virtual CMM, or reading its deviations.
#[derive(Debug, Error, Diagnostic)]
#[allow(missing_docs)]
pub enum SimError {
    #[error("the probe's {what} hits {obstacle} {during}")]
    #[diagnostic(
        code(insp::simulate::collision),
        help("on a machine this stops the run; the program was planned against the nominal part: a deviation that large, or a part placed this far off, leaves no room here")
    )]
    Collision {
        #[label("this statement")]
        span: Span,
        what: String,
        obstacle: String,
        during: String,
    },

    #[error("the touch finds no surface within {travel} mm of its approach point")]
    #[diagnostic(
        code(insp::simulate::no_surface),
        help("the part is not where the program expects it: an alignment that leaves a direction free and a part placed off in it, or a feature moved beyond `SNSET/SEARCH`")
    )]
    NoSurface {
        #[label("searched along this touch's vector")]
        span: Span,
        travel: String,
    },

    #[error("the approach point of this touch lies inside the part")]
    #[diagnostic(
        code(insp::simulate::inside_part),
        help("the surface stands more than `SNSET/APPRCH` proud of its nominal: the probe would crash on its way to the approach point")
    )]
    InsidePart {
        #[label("approach point inside the material")]
        span: Span,
    },

    #[error("sensor `{label}` matches no probe of cmm `{cmm}`")]
    #[diagnostic(
        code(insp::simulate::unknown_sensor),
        help("simulate the program with the spec it was built from: its probes are {probes}")
    )]
    UnknownSensor {
        #[label("defined here")]
        span: Span,
        label: String,
        cmm: String,
        probes: String,
    },

    #[error("the virtual CMM does not run `{what}`")]
    #[diagnostic(
        code(insp::simulate::unsupported),
        help("it runs the DMIS inspc writes: {supported}")
    )]
    Unsupported {
        #[label("here")]
        span: Span,
        what: String,
        supported: String,
    },

    #[error("program `{program}` names no plan of the spec, which holds several")]
    #[diagnostic(
        code(insp::simulate::no_plan),
        help("the spec holds several plans: name one of them in the program's DMISMN (with one plan, any program runs on it); its plans are: {plans}")
    )]
    NoPlan {
        #[label("the program's name")]
        span: Span,
        program: String,
        plans: String,
    },

    #[error("nothing holds the part in setup {setup}: no rest pose or fixture of plan `{plan}` has the part's ({up}) up")]
    #[diagnostic(
        code(insp::simulate::no_setup),
        help("the `ROTATE`s before a setup's `PAUSE` say how the part stands; build the program again from the spec")
    )]
    NoSetup {
        #[label("the setup starts here")]
        span: Span,
        setup: usize,
        plan: String,
        up: String,
    },

    #[error("{what}")]
    #[diagnostic(code(insp::simulate::bad_statement), help("{help}"))]
    BadStatement {
        #[label("here")]
        span: Span,
        what: String,
        help: String,
    },

    #[error("{what}")]
    #[diagnostic(code(insp::simulate::bad_deviation), help("{help}"))]
    BadDeviation {
        #[label("{label}")]
        span: Span,
        what: String,
        label: String,
        help: String,
    },
}

crate::diag::located!(SimError {
    Collision,
    NoSurface,
    InsidePart,
    UnknownSensor,
    Unsupported,
    NoPlan,
    NoSetup,
    BadStatement,
    BadDeviation
});
