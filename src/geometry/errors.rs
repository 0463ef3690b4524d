//! The geometry stage's diagnostics.

use super::qif::error::QifError;
use super::step::error::StepError;
use crate::source::Span;

/// A problem evaluating a part's geometry.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[allow(missing_docs)]
pub enum GeometryError {
    #[error("cannot read mesh `{path}`: {reason}")]
    #[diagnostic(
        code(insp::geometry::mesh_unreadable),
        help("check the path and that the file is a binary or ASCII STL, or an OBJ")
    )]
    MeshUnreadable {
        #[label("named here")]
        span: Span,
        path: String,
        reason: String,
    },
    #[error("mesh `{path}` is corrupt: {reason}")]
    #[diagnostic(
        code(insp::geometry::mesh_corrupt),
        help("re-export the mesh from the CAD system; inspc needs a closed triangle mesh")
    )]
    MeshCorrupt {
        #[label("this mesh")]
        span: Span,
        path: String,
        reason: String,
    },
    #[error("mesh `{path}` is not closed: {reason}")]
    #[diagnostic(code(insp::geometry::mesh_not_closed), help("accessibility needs a watertight solid: every edge shared by exactly two triangles; repair the mesh or re-export it"))]
    MeshNotClosed {
        #[label("this mesh")]
        span: Span,
        path: String,
        reason: String,
    },
    #[error("part `{part}` falls apart into {bodies} separate bodies")]
    #[diagnostic(
        code(insp::geometry::several_bodies),
        severity(Warning),
        help("an operation cuts right through the part (a slot or step deeper than the stock?); a CMM measures one body at a time, and loose pieces cannot be fixtured as one")
    )]
    SeveralBodies {
        #[label("this part")]
        span: Span,
        part: String,
        bodies: usize,
    },
    #[error("mesh `{path}` has {open} open and {nonmanifold} non-manifold edges")]
    #[diagnostic(code(insp::geometry::mesh_defects), severity(Warning), help("the mesh is used as it is; collision checks near those edges may be off; repair or re-export it for a watertight solid"))]
    MeshDefects {
        #[label("this mesh")]
        span: Span,
        path: String,
        open: usize,
        nonmanifold: usize,
    },
    #[error("fixture `{fixture}` cuts {depth} mm into part `{part}`")]
    #[diagnostic(
        code(insp::geometry::fixture_overlaps_part),
        help("a mesh fixture is given in the part's frame, touching the part where it holds it; export the fixture and the part from one assembly, in the same units")
    )]
    FixtureOverlapsPart {
        #[label("this fixture mesh")]
        span: Span,
        fixture: String,
        part: String,
        depth: String,
    },
    #[error(
        "fixture `{fixture}` touches no face of part `{part}`: it comes no nearer than {gap} mm"
    )]
    #[diagnostic(
        code(insp::geometry::fixture_misses_part),
        help("a mesh fixture is given in the part's frame, touching the part where it holds it (within 0.05 mm); export the fixture and the part from one assembly, in the same units")
    )]
    FixtureMissesPart {
        #[label("this fixture mesh")]
        span: Span,
        fixture: String,
        part: String,
        gap: String,
    },
    /// A STEP file that cannot be read or meshed: its own diagnostic, located.
    #[error(transparent)]
    #[diagnostic(transparent)]
    Step(InFile<StepError>),
    /// A QIF file that cannot be read or meshed: its own diagnostic, located.
    #[error(transparent)]
    #[diagnostic(transparent)]
    Qif(InFile<QifError>),
    #[error("mesh `{path}` is too large: {reason}")]
    #[diagnostic(
        code(insp::geometry::mesh_too_large),
        help("decimate the mesh; inspc accepts up to 2000000 triangles")
    )]
    MeshTooLarge {
        #[label("this mesh")]
        span: Span,
        path: String,
        reason: String,
    },
    #[error("the part in `{path}` spans {metres} m: no CMM measures a part over 10 m")]
    #[diagnostic(
        code(insp::geometry::part_too_large),
        help("a part this size is a wrong length unit in the file (it says `{unit}`), or coordinates off by powers of ten; re-export the part in millimetres or inches")
    )]
    PartTooLarge {
        #[label("this CAD file")]
        span: Span,
        path: String,
        metres: String,
        unit: String,
    },
    #[error("the boolean operations of part `{part}` failed: {reason}")]
    #[diagnostic(code(insp::geometry::boolean_failed), help("check that every operation overlaps the stock and that no two operations touch in a single edge or point"))]
    BooleanFailed {
        #[label("this part")]
        span: Span,
        part: String,
        reason: String,
    },
    #[error("{what} `{name}` misses the part{more}")]
    #[diagnostic(code(insp::geometry::misses_part), help("move it onto the part: its position and direction are in the part frame (boxes span from the origin)"))]
    MissesPart {
        #[label("removes nothing")]
        span: Span,
        what: String,
        name: String,
        more: String,
    },
    #[error("face `{face}` does not survive the booleans")]
    #[diagnostic(
        code(insp::geometry::face_gone),
        help("a later operation removes it entirely; name a face that is still there")
    )]
    FaceGone {
        #[label("no triangle of the part lies on this face")]
        span: Span,
        face: String,
    },
    #[error("mesh has no group `{group}`")]
    #[diagnostic(code(insp::geometry::unknown_group))]
    UnknownGroup {
        #[label("not in the mesh")]
        span: Span,
        group: String,
        #[help]
        help: String,
    },
    #[error("mesh has no segment {segment}")]
    #[diagnostic(code(insp::geometry::unknown_segment))]
    UnknownSegment {
        #[label("no such segment")]
        span: Span,
        segment: u32,
        #[help]
        help: String,
    },
    #[error("{what}")]
    #[diagnostic(code(insp::geometry::unknown_file_face))]
    UnknownFileFace {
        #[label("no such face")]
        span: Span,
        what: String,
        #[help]
        help: String,
    },
    #[error("no face matches this selector")]
    #[diagnostic(code(insp::geometry::no_match))]
    NoMatch {
        #[label("matches nothing")]
        span: Span,
        #[help]
        help: String,
    },
}

crate::diag::located!(GeometryError {
    MeshUnreadable,
    MeshCorrupt,
    MeshNotClosed,
    MeshDefects,
    FixtureOverlapsPart,
    FixtureMissesPart,
    SeveralBodies,
    MeshTooLarge,
    PartTooLarge,
    BooleanFailed,
    MissesPart,
    FaceGone,
    UnknownGroup,
    UnknownSegment,
    UnknownFileFace,
    NoMatch,
} wrapping { Step, Qif });

/// A mesh-reading failure, located later at the spec's path.
#[derive(Debug, Clone)]
pub enum MeshError {
    /// Could not read.
    Unreadable(String),
    /// Not a valid mesh.
    Corrupt(String),
    /// Not watertight.
    NotClosed(String),
    /// Over the size limit.
    TooLarge(String),
    /// A CAD part larger than any CMM measures.
    Extent {
        /// The diagonal of its box (mm).
        span_mm: f64,
        /// The file's length unit, as named.
        unit: String,
    },
    /// A STEP file that cannot be read or meshed.
    Step(super::step::error::StepError),
    /// A QIF file that cannot be read or meshed.
    Qif(super::qif::error::QifError),
}

impl MeshError {
    /// The diagnostics, pointing at the spec's mesh path: one, or one per face of a
    /// CAD file that could not be meshed.
    pub fn at(self, span: Span, path: &std::path::Path) -> Vec<GeometryError> {
        let path = shown_path(path);
        match self {
            MeshError::Unreadable(reason) => {
                vec![GeometryError::MeshUnreadable { span, path, reason }]
            }
            MeshError::Corrupt(reason) => vec![GeometryError::MeshCorrupt { span, path, reason }],
            MeshError::NotClosed(reason) => {
                vec![GeometryError::MeshNotClosed { span, path, reason }]
            }
            MeshError::TooLarge(reason) => vec![GeometryError::MeshTooLarge { span, path, reason }],
            MeshError::Extent { span_mm, unit } => vec![GeometryError::PartTooLarge {
                span,
                path,
                metres: crate::model::fmt_num((span_mm / 1000.0 * 10.0).round() / 10.0),
                unit,
            }],
            MeshError::Step(e) => e
                .one_per_face()
                .into_iter()
                .map(|error| GeometryError::Step(InFile::new(span, &path, error)))
                .collect(),
            MeshError::Qif(e) => e
                .one_per_face()
                .into_iter()
                .map(|error| GeometryError::Qif(InFile::new(span, &path, error)))
                .collect(),
        }
    }
}

/// A CAD file's own error ([`StepError`], [`QifError`]) where a spec (or the command
/// line) names the file: the message after the file's format and name, the code and
/// help the inner error's, the label on the path.
#[derive(Debug)]
pub struct InFile<E> {
    /// The path as the spec wrote it.
    pub span: Span,
    /// The file's name, as messages show it ([`shown_path`]).
    pub path: String,
    /// What is wrong with it.
    pub error: E,
}

impl<E> InFile<E> {
    fn new(span: Span, path: &str, error: E) -> Self {
        InFile {
            span,
            path: path.to_string(),
            error,
        }
    }
}

/// The exchange format of a CAD file error, as messages name it.
pub trait CadFormat {
    /// `STEP`, `QIF`.
    const FORMAT: &'static str;
}

impl CadFormat for StepError {
    const FORMAT: &'static str = "STEP";
}

impl CadFormat for QifError {
    const FORMAT: &'static str = "QIF";
}

impl<E: CadFormat + std::fmt::Display> std::fmt::Display for InFile<E> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} file `{}`: {}", E::FORMAT, self.path, self.error)
    }
}

impl<E: CadFormat + std::fmt::Debug + std::fmt::Display> std::error::Error for InFile<E> {}

impl<E: CadFormat + miette::Diagnostic> miette::Diagnostic for InFile<E> {
    fn code<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        self.error.code()
    }
    fn severity(&self) -> Option<miette::Severity> {
        self.error.severity()
    }
    fn help<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        self.error.help()
    }
    fn url<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        self.error.url()
    }
    fn labels(&self) -> Option<Box<dyn Iterator<Item = miette::LabeledSpan> + '_>> {
        let label = miette::LabeledSpan::new_with_span(
            Some(format!("this {} file", E::FORMAT)),
            miette::SourceSpan::from(self.span),
        );
        Some(Box::new(std::iter::once(label)))
    }
}

impl<E> crate::diag::Located for InFile<E> {
    fn file(&self) -> crate::source::FileId {
        crate::diag::primary_file(&self.span)
    }
}

/// How a mesh path appears in a message: its file name, so that messages read the same on
/// every machine (the label points at the path as the spec wrote it).
pub(crate) fn shown_path(path: &std::path::Path) -> String {
    path.file_name()
        .unwrap_or(path.as_os_str())
        .to_string_lossy()
        .into_owned()
}
