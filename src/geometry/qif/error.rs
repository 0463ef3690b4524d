//! Why a QIF file could not be read: the one definition of each `insp::geometry::qif_*`
//! diagnostic (code, message, help). The reader returns it bare; the geometry stage
//! wraps it with the span and path of the spec that names the file
//! (`GeometryError::Qif`), so its message reads after "QIF file `part.qif`: ".

/// Why a QIF file could not be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error, miette::Diagnostic)]
pub enum QifError {
    /// Not well-formed XML.
    #[error("not well-formed XML: line {line}: {message}")]
    #[diagnostic(
        code(insp::geometry::qif_syntax),
        help(
            "the file is cut short or was edited by hand; re-export it from the CAD or MBD system"
        )
    )]
    Syntax {
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// Not a QIF 3 document: the version it states, or what it is instead.
    #[error("not a QIF 3 document: {0}")]
    #[diagnostic(
        code(insp::geometry::qif_version),
        help("inspc reads QIF 3.x MBD documents (versionQIF=\"3.…\"); export the part as QIF 3, or as STEP AP242")
    )]
    Version(String),
    /// No solid or visible sheet body with faces.
    #[error("it holds no solid body with faces")]
    #[diagnostic(
        code(insp::geometry::qif_no_solid),
        help("export the part with its B-rep (Product/TopologySet with a SOLID body); a QIF file of characteristics or results only has no faces to inspect")
    )]
    NoSolid,
    /// A reference to an id the document does not define.
    #[error("{}", missing(*id, *from, *line))]
    #[diagnostic(
        code(insp::geometry::qif_missing_entity),
        help("an element the B-rep needs is not in the file: it was cut short or corrupted; re-export it")
    )]
    Missing {
        /// The missing id.
        id: u64,
        /// The element that refers to it.
        from: Option<u64>,
        /// That element's line.
        line: usize,
    },
    /// An element whose content is not what its type needs.
    #[error("{}", malformed(*id, element, *line, message))]
    #[diagnostic(
        code(insp::geometry::qif_malformed),
        help("the element's content does not fit its type; re-export the file, or report the exporting system")
    )]
    Malformed {
        /// Its id.
        id: Option<u64>,
        /// Its name.
        element: String,
        /// Its line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// Elements that name each other round a circle.
    #[error("{}", cycle(ids, *line))]
    #[diagnostic(
        code(insp::geometry::qif_cycle),
        help("a feature cannot be made of itself: the file is corrupt or was edited by hand; re-export it")
    )]
    Cycle {
        /// The ids of the circle, the first named again by the last.
        ids: Vec<u64>,
        /// The first one's line.
        line: usize,
    },
    /// A curve or surface type inspc does not evaluate.
    #[error("{}", unsupported(*id, *line, what))]
    #[diagnostic(
        code(insp::geometry::qif_unsupported),
        help("inspc evaluates every QIF 3 curve and surface kind (README, \"CAD files\"), with control points given as text, and faces given by their surfaces; export the part with text control points and B-rep faces, or as STEP AP242")
    )]
    Unsupported {
        /// The element's id.
        id: Option<u64>,
        /// Its line.
        line: usize,
        /// `surface Nurbs23`.
        what: String,
    },
    /// The length unit cannot be determined.
    #[error("{0}")]
    #[diagnostic(
        code(insp::geometry::qif_unit),
        help("inspc reads the primary linear unit of FileUnits: a conversion factor to metres, or mm, cm, m, inch or ft by name")
    )]
    Unit(String),
    /// Faces that could not be meshed: (1-based face number, id, why).
    #[error("{}", faces(_0))]
    #[diagnostic(
        code(insp::geometry::qif_face),
        help("inspc meshes each face in its surface's parameters, and this face's loops could not be laid out there for the reason given; it is reported rather than dropped, since a hole in the mesh would let probes see through the part")
    )]
    Faces(Vec<(usize, u64, String)>),
}

impl QifError {
    /// One error per face that could not be meshed (one diagnostic each), the others
    /// as they are.
    pub(crate) fn one_per_face(self) -> Vec<QifError> {
        match self {
            QifError::Faces(list) => list.into_iter().map(|f| QifError::Faces(vec![f])).collect(),
            e => vec![e],
        }
    }
}

fn missing(id: u64, from: Option<u64>, line: usize) -> String {
    match from {
        Some(from) => format!(
            "element {from} (line {line}) refers to id {id}, which the file does not define"
        ),
        None => format!("line {line} refers to id {id}, which the file does not define"),
    }
}

fn malformed(id: Option<u64>, element: &str, line: usize, message: &str) -> String {
    match id {
        Some(id) => format!("malformed element <{element}> {id} (line {line}): {message}"),
        None => format!("malformed element <{element}> (line {line}): {message}"),
    }
}

fn unsupported(id: Option<u64>, line: usize, what: &str) -> String {
    match id {
        Some(id) => {
            format!("element {id} (line {line}) is a {what}, which inspc does not evaluate")
        }
        None => format!("line {line} holds a {what}, which inspc does not evaluate"),
    }
}

fn cycle(ids: &[u64], line: usize) -> String {
    let mut path: Vec<String> = ids.iter().map(u64::to_string).collect();
    path.extend(ids.first().map(u64::to_string));
    format!(
        "elements name each other round a circle: ids {} (line {line})",
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
    format!("face_{n} (id {id}) cannot be meshed: {why}{more}")
}
