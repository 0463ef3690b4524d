//! The geometry stage's diagnostics.

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
    #[error("STEP file `{path}` is not valid Part 21 text: line {line}: {message}")]
    #[diagnostic(
        code(insp::geometry::step_syntax),
        help("the file is cut short or was edited by hand; re-export it from the CAD system")
    )]
    StepSyntax {
        #[label("this STEP file")]
        span: Span,
        path: String,
        line: usize,
        message: String,
    },
    #[error("STEP file `{path}` holds no solid")]
    #[diagnostic(
        code(insp::geometry::step_no_solid),
        help("export the part as a solid (MANIFOLD_SOLID_BREP); a file of PMI, wireframe or tessellated shapes only has no faces to inspect")
    )]
    StepNoSolid {
        #[label("this STEP file")]
        span: Span,
        path: String,
    },
    #[error("STEP file `{path}` is incomplete: {reason}")]
    #[diagnostic(
        code(insp::geometry::step_missing_entity),
        help("an instance the B-rep needs is not in the file: it was cut short or corrupted; re-export it")
    )]
    StepMissing {
        #[label("this STEP file")]
        span: Span,
        path: String,
        reason: String,
    },
    #[error("STEP file `{path}` has a malformed instance: {reason}")]
    #[diagnostic(
        code(insp::geometry::step_malformed),
        help("the instance's parameters do not fit its type; re-export the file, or report the exporting CAD system")
    )]
    StepMalformed {
        #[label("this STEP file")]
        span: Span,
        path: String,
        reason: String,
    },
    #[error("STEP file `{path}`: {reason}")]
    #[diagnostic(
        code(insp::geometry::step_unsupported),
        help("inspc evaluates planes, cylinders, cones, spheres, tori and B-spline surfaces, and lines, circles, ellipses, B-spline curves and polylines; export this geometry as B-splines")
    )]
    StepUnsupported {
        #[label("this STEP file")]
        span: Span,
        path: String,
        reason: String,
    },
    #[error("STEP file `{path}`: {reason}")]
    #[diagnostic(
        code(insp::geometry::step_unit),
        help("inspc reads SI length units with their prefixes and conversion-based units such as the inch, assigned by the context of the solid's representation")
    )]
    StepUnit {
        #[label("this STEP file")]
        span: Span,
        path: String,
        reason: String,
    },
    #[error("face_{face} (#{id}) of STEP file `{path}` cannot be meshed: {reason}")]
    #[diagnostic(
        code(insp::geometry::step_face),
        help("the face is kept out of nothing: a part with a hole in its mesh cannot be planned; repair the face in the CAD system (its bounds and surface must agree) and re-export")
    )]
    StepFace {
        #[label("this STEP file")]
        span: Span,
        path: String,
        face: usize,
        id: u64,
        reason: String,
    },
    #[error("QIF file `{path}` is not well-formed XML: line {line}: {message}")]
    #[diagnostic(
        code(insp::geometry::qif_syntax),
        help(
            "the file is cut short or was edited by hand; re-export it from the CAD or MBD system"
        )
    )]
    QifSyntax {
        #[label("this QIF file")]
        span: Span,
        path: String,
        line: usize,
        message: String,
    },
    #[error("QIF file `{path}` is not a QIF 3 document: {reason}")]
    #[diagnostic(
        code(insp::geometry::qif_version),
        help("inspc reads QIF 3.x MBD documents (versionQIF=\"3.…\"); export the part as QIF 3, or as STEP AP242")
    )]
    QifVersion {
        #[label("this QIF file")]
        span: Span,
        path: String,
        reason: String,
    },
    #[error("QIF file `{path}` holds no solid")]
    #[diagnostic(
        code(insp::geometry::qif_no_solid),
        help("export the part with its B-rep (Product/TopologySet with a SOLID body); a QIF file of characteristics or results only has no faces to inspect")
    )]
    QifNoSolid {
        #[label("this QIF file")]
        span: Span,
        path: String,
    },
    #[error("QIF file `{path}` is incomplete: {reason}")]
    #[diagnostic(
        code(insp::geometry::qif_missing_entity),
        help("an element the B-rep needs is not in the file: it was cut short or corrupted; re-export it")
    )]
    QifMissing {
        #[label("this QIF file")]
        span: Span,
        path: String,
        reason: String,
    },
    #[error("QIF file `{path}` has a malformed element: {reason}")]
    #[diagnostic(
        code(insp::geometry::qif_malformed),
        help("the element's content does not fit its type; re-export the file, or report the exporting system")
    )]
    QifMalformed {
        #[label("this QIF file")]
        span: Span,
        path: String,
        reason: String,
    },
    #[error("QIF file `{path}`: {reason}")]
    #[diagnostic(
        code(insp::geometry::qif_unsupported),
        help("inspc evaluates QIF planes, cylinders, cones, spheres and tori, and segments, circular arcs, NURBS, polylines and aggregates of them; export the part as STEP AP242 for other surfaces")
    )]
    QifUnsupported {
        #[label("this QIF file")]
        span: Span,
        path: String,
        reason: String,
    },
    #[error("QIF file `{path}`: {reason}")]
    #[diagnostic(
        code(insp::geometry::qif_unit),
        help("inspc reads the primary linear unit of FileUnits: a conversion factor to metres, or mm, cm, m, inch or ft by name")
    )]
    QifUnit {
        #[label("this QIF file")]
        span: Span,
        path: String,
        reason: String,
    },
    #[error("face_{face} (id {id}) of QIF file `{path}` cannot be meshed: {reason}")]
    #[diagnostic(
        code(insp::geometry::qif_face),
        help("the face is kept out of nothing: a part with a hole in its mesh cannot be planned; repair the face (its loops and surface must agree) and re-export")
    )]
    QifFace {
        #[label("this QIF file")]
        span: Span,
        path: String,
        face: usize,
        id: u64,
        reason: String,
    },
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
    StepSyntax,
    StepNoSolid,
    StepMissing,
    StepMalformed,
    StepUnsupported,
    StepUnit,
    StepFace,
    QifSyntax,
    QifVersion,
    QifNoSolid,
    QifMissing,
    QifMalformed,
    QifUnsupported,
    QifUnit,
    QifFace,
    BooleanFailed,
    MissesPart,
    FaceGone,
    UnknownGroup,
    UnknownSegment,
    UnknownFileFace,
    NoMatch,
});

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
    /// A STEP file that cannot be read or meshed.
    Step(super::step::error::StepError),
    /// A QIF file that cannot be read or meshed.
    Qif(super::qif::error::QifError),
}

impl MeshError {
    /// The diagnostics, pointing at the spec's mesh path: one, or one per face of a
    /// STEP file that could not be meshed.
    pub fn at(self, span: Span, path: &std::path::Path) -> Vec<GeometryError> {
        use super::qif::error::QifError as Q;
        use super::step::error::StepError as S;
        let path = shown_path(path);
        vec![match self {
            MeshError::Unreadable(reason) => GeometryError::MeshUnreadable { span, path, reason },
            MeshError::Corrupt(reason) => GeometryError::MeshCorrupt { span, path, reason },
            MeshError::NotClosed(reason) => GeometryError::MeshNotClosed { span, path, reason },
            MeshError::TooLarge(reason) => GeometryError::MeshTooLarge { span, path, reason },
            MeshError::Step(S::Faces(list)) => {
                return list
                    .into_iter()
                    .map(|(face, id, reason)| GeometryError::StepFace {
                        span,
                        path: path.clone(),
                        face,
                        id,
                        reason,
                    })
                    .collect()
            }
            MeshError::Step(e) => {
                let reason = e.to_string();
                match e {
                    S::Syntax { line, message } => GeometryError::StepSyntax {
                        span,
                        path,
                        line,
                        message,
                    },
                    S::NoSolid => GeometryError::StepNoSolid { span, path },
                    S::Missing { .. } => GeometryError::StepMissing { span, path, reason },
                    S::Malformed { .. } => GeometryError::StepMalformed { span, path, reason },
                    S::Unsupported { .. } => GeometryError::StepUnsupported { span, path, reason },
                    S::Unit(_) => GeometryError::StepUnit { span, path, reason },
                    S::Faces(_) => unreachable!("handled above"),
                }
            }
            MeshError::Qif(Q::Faces(list)) => {
                return list
                    .into_iter()
                    .map(|(face, id, reason)| GeometryError::QifFace {
                        span,
                        path: path.clone(),
                        face,
                        id,
                        reason,
                    })
                    .collect()
            }
            MeshError::Qif(e) => {
                let reason = e.to_string();
                match e {
                    Q::Syntax { line, message } => GeometryError::QifSyntax {
                        span,
                        path,
                        line,
                        message,
                    },
                    Q::Version(_) => GeometryError::QifVersion { span, path, reason },
                    Q::NoSolid => GeometryError::QifNoSolid { span, path },
                    Q::Missing { .. } => GeometryError::QifMissing { span, path, reason },
                    Q::Malformed { .. } => GeometryError::QifMalformed { span, path, reason },
                    Q::Unsupported { .. } => GeometryError::QifUnsupported { span, path, reason },
                    Q::Unit(_) => GeometryError::QifUnit { span, path, reason },
                    Q::Faces(_) => unreachable!("handled above"),
                }
            }
        }]
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
