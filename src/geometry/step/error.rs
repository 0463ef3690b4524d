//! Why a STEP file could not be read: the one definition of each `insp::geometry::step_*`
//! diagnostic (code, message, help). The reader returns it bare; the geometry stage
//! wraps it with the span and path of the spec that names the file
//! (`GeometryError::Step`), so its message reads after "STEP file `part.stp`: ".

/// Why a STEP file could not be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error, miette::Diagnostic)]
pub enum StepError {
    /// Not valid Part 21 text.
    #[error("not valid Part 21 text: line {line}: {message}")]
    #[diagnostic(
        code(insp::geometry::step_syntax),
        help("the file is cut short or was edited by hand; re-export it from the CAD system")
    )]
    Syntax {
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// No solid or sheet body.
    #[error("it holds no solid (MANIFOLD_SOLID_BREP) and no sheet body")]
    #[diagnostic(
        code(insp::geometry::step_no_solid),
        help("export the part as a solid (MANIFOLD_SOLID_BREP); a file of PMI, wireframe or tessellated shapes only has no faces to inspect")
    )]
    NoSolid,
    /// An assembly: several parts placed by an assembly structure.
    #[error("it is an assembly: {occurrences} part occurrences of {solids} solids (NEXT_ASSEMBLY_USAGE_OCCURRENCE)")]
    #[diagnostic(
        code(insp::geometry::step_assembly),
        help("inspc inspects one part, and an assembly's parts stand where its placements put them, which the part's own B-rep does not say; export the part to be inspected on its own")
    )]
    Assembly {
        /// Part occurrences the assembly structure places.
        occurrences: usize,
        /// Solids the file holds.
        solids: usize,
    },
    /// A reference to an instance the file does not define.
    #[error("{}", missing(*id, *from))]
    #[diagnostic(
        code(insp::geometry::step_missing_entity),
        help("an instance the B-rep needs is not in the file: it was cut short or corrupted; re-export it")
    )]
    Missing {
        /// The missing instance.
        id: u64,
        /// The instance that refers to it.
        from: Option<u64>,
    },
    /// An instance whose parameters are not what its type needs.
    #[error("malformed instance #{id} (line {line}): {message}")]
    #[diagnostic(
        code(insp::geometry::step_malformed),
        help("the instance's parameters do not fit its type; re-export the file, or report the exporting CAD system")
    )]
    Malformed {
        /// The instance.
        id: u64,
        /// Its line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// Instances that refer to each other round a circle.
    #[error("{}", cycle(ids, *line))]
    #[diagnostic(
        code(insp::geometry::step_cycle),
        help("an instance cannot be made of itself: the file is corrupt or was edited by hand; re-export it")
    )]
    Cycle {
        /// The instances of the circle, the first referred to again by the last.
        ids: Vec<u64>,
        /// The first one's line.
        line: usize,
    },
    /// A curve or surface type inspc does not evaluate.
    #[error("#{id} (line {line}) is a {what}, which inspc does not evaluate")]
    #[diagnostic(
        code(insp::geometry::step_unsupported),
        help("inspc evaluates planes, cylinders, cones, spheres, tori, B-spline, extruded, revolved and offset surfaces, and lines, conics, B-spline curves, polylines, composite and offset curves (README, \"CAD files\"); export this geometry as B-splines")
    )]
    Unsupported {
        /// The instance.
        id: u64,
        /// Its line.
        line: usize,
        /// `surface SURFACE_OF_REVOLUTION`.
        what: String,
    },
    /// The length or angle unit cannot be determined.
    #[error("{0}")]
    #[diagnostic(
        code(insp::geometry::step_unit),
        help("inspc reads SI length units with their prefixes and conversion-based units such as the inch, assigned by the context of the solid's representation")
    )]
    Unit(String),
    /// Faces that could not be meshed: (1-based face number, instance, why).
    #[error("{}", faces(_0))]
    #[diagnostic(
        code(insp::geometry::step_face),
        help("inspc meshes each face in its surface's parameters, and this face's bounds could not be laid out there for the reason given; it is reported rather than dropped, since a hole in the mesh would let probes see through the part")
    )]
    Faces(Vec<(usize, u64, String)>),
}

impl StepError {
    /// One error per face that could not be meshed (one diagnostic each), the others
    /// as they are.
    pub(crate) fn one_per_face(self) -> Vec<StepError> {
        match self {
            StepError::Faces(list) => list
                .into_iter()
                .map(|f| StepError::Faces(vec![f]))
                .collect(),
            e => vec![e],
        }
    }
}

fn missing(id: u64, from: Option<u64>) -> String {
    match from {
        Some(from) => format!("#{from} refers to #{id}, which the file does not define"),
        None => format!("#{id} is referred to but not defined"),
    }
}

fn cycle(ids: &[u64], line: usize) -> String {
    let mut path: Vec<String> = ids.iter().map(|i| format!("#{i}")).collect();
    path.extend(ids.first().map(|i| format!("#{i}")));
    format!(
        "instances refer to each other round a circle: {} (line {line})",
        path.join(" → ")
    )
}

fn faces(list: &[(usize, u64, String)]) -> String {
    let Some((n, id, why)) = list.first() else {
        return "a face cannot be meshed".into();
    };
    let more = match list.len() {
        1 => String::new(),
        k => format!(" (and {} more faces)", k - 1),
    };
    format!("face_{n} (#{id}) cannot be meshed: {why}{more}")
}
