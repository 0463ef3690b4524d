//! The accessibility stage's diagnostics: asking `inspc cones` for what is not there.

use crate::source::Span;

/// A cone request that names nothing the spec has.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[allow(missing_docs)]
pub(crate) enum AccessError {
    #[error("part `{part}` has no face `{face}`")]
    #[diagnostic(
        code(insp::access::unknown_face),
        help("`inspc faces` lists the part's faces; some are: {known}")
    )]
    UnknownFace {
        #[label("this part")]
        span: Span,
        face: String,
        part: String,
        known: String,
    },
    #[error("{face} has {count} measuring points; there is no point {index}")]
    #[diagnostic(
        code(insp::access::no_point),
        help("points count from 0; `inspc graph --points` lists them per face")
    )]
    NoPoint {
        #[label("this part")]
        span: Span,
        face: String,
        index: usize,
        count: usize,
    },
    #[error("machine `{cmm}` has no probe `{probe}`")]
    #[diagnostic(code(insp::access::unknown_probe), help("its probes are: {known}"))]
    UnknownProbe {
        #[label("this machine")]
        span: Span,
        probe: String,
        cmm: String,
        known: String,
    },
    #[error("no plan puts part `{part}` on a machine, so it has no probes")]
    #[diagnostic(
        code(insp::access::no_machine),
        help("add a plan naming a cmm, or leave out --probe for the bare half-line cone")
    )]
    NoMachine {
        #[label("this part")]
        span: Span,
        part: String,
    },
}

crate::diag::located!(AccessError {
    UnknownFace,
    NoPoint,
    UnknownProbe,
    NoMachine,
});
