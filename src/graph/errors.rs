//! The graph stage's diagnostics.

use crate::source::Span;

/// A problem building the measurement graph.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[allow(missing_docs)]
pub(crate) enum GraphError {
    #[error("face `{face}` of feature `{feature}` gets no measuring point")]
    #[diagnostic(
        code(insp::graph::no_points),
        severity(Warning),
        help("no candidate point lies inside the face and {margin} mm (the largest tip radius, at most 45 % of the face's width) from its edges; lower the sampling inset or drop the face from the feature")
    )]
    NoPoints {
        #[label("this feature")]
        span: Span,
        face: String,
        feature: String,
        margin: String,
    },
    #[error(
        "{tolerance} needs {needs} faces, but face `{face}` of feature `{feature}` is {found}"
    )]
    #[diagnostic(code(insp::graph::wrong_surface), help("{help}"))]
    WrongSurface {
        #[label("this tolerance")]
        span: Span,
        tolerance: String,
        needs: String,
        face: String,
        feature: String,
        found: String,
        help: String,
    },
    #[error("{tolerance} `{name}` is read on {read} of the {total} faces of `{feature}`: {faces} {is} free-form, and a free-form face has no size")]
    #[diagnostic(
        code(insp::graph::size_on_freeform),
        severity(Warning),
        help("a free-form face (a torus blend, a spline patch) is measured as a DMIS `GSURF`: points on a surface, with no diameter or radius for `TOL/DIAM` or `TOL/RAD` to judge; a profile tolerance controls its shape, or leave it out of the feature")
    )]
    SizeOnFreeform {
        #[label("this tolerance")]
        span: Span,
        tolerance: String,
        name: String,
        feature: String,
        read: String,
        total: usize,
        faces: String,
        is: &'static str,
    },
    #[error("{what} samples more than {limit} measuring points on its {faces} faces", limit = super::MAX_POINTS)]
    #[diagnostic(
        code(insp::graph::too_many_points),
        help("a plan measures at most {limit} points; give the features fewer points (`sample F with hammersley(points 4)`) or split the part into several plans", limit = super::MAX_POINTS)
    )]
    TooManyPoints {
        #[label("this plan")]
        span: Span,
        what: String,
        faces: usize,
    },
}

crate::diag::located!(GraphError {
    TooManyPoints,
    NoPoints,
    WrongSurface,
    SizeOnFreeform,
});
