//! Why a QIF file could not be read: its own error, below the geometry stage's
//! `MeshError` that wraps it, so that the reader and the error report do not import
//! each other.

/// Why a QIF file could not be read.
#[derive(Debug, Clone, PartialEq)]
pub enum QifError {
    /// Not well-formed XML.
    Syntax {
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// Not a QIF 3 document: the version it states, or what it is instead.
    Version(String),
    /// No solid or visible sheet body with faces.
    NoSolid,
    /// A reference to an id the document does not define.
    Missing {
        /// The missing id.
        id: u64,
        /// The element that refers to it.
        from: Option<u64>,
        /// That element's line.
        line: usize,
    },
    /// An element whose content is not what its type needs.
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
    /// A curve or surface type inspc does not evaluate.
    Unsupported {
        /// The element's id.
        id: Option<u64>,
        /// Its line.
        line: usize,
        /// `surface Nurbs23`.
        what: String,
    },
    /// The length unit cannot be determined.
    Unit(String),
    /// Faces that could not be meshed: (1-based face number, id, why).
    Faces(Vec<(usize, u64, String)>),
}

impl std::fmt::Display for QifError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            QifError::Syntax { line, message } => write!(f, "line {line}: {message}"),
            QifError::Version(v) => write!(f, "{v}"),
            QifError::NoSolid => write!(f, "it holds no solid body with faces"),
            QifError::Missing { id, from, line } => match from {
                Some(from) => write!(
                    f,
                    "element {from} (line {line}) refers to id {id}, which the file does not define"
                ),
                None => write!(
                    f,
                    "line {line} refers to id {id}, which the file does not define"
                ),
            },
            QifError::Malformed {
                id,
                element,
                line,
                message,
            } => match id {
                Some(id) => write!(f, "<{element}> {id} (line {line}): {message}"),
                None => write!(f, "<{element}> (line {line}): {message}"),
            },
            QifError::Unsupported { id, line, what } => match id {
                Some(id) => write!(
                    f,
                    "element {id} (line {line}) is a {what}, which inspc does not evaluate"
                ),
                None => write!(
                    f,
                    "line {line} holds a {what}, which inspc does not evaluate"
                ),
            },
            QifError::Unit(m) => write!(f, "{m}"),
            QifError::Faces(list) => {
                let (n, id, why) = &list[0];
                write!(f, "face_{n} (id {id}) cannot be meshed: {why}")?;
                if list.len() > 1 {
                    write!(f, " (and {} more faces)", list.len() - 1)?;
                }
                Ok(())
            }
        }
    }
}
