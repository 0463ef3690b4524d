//! Why a STEP file could not be read: its own error, below the geometry stage's
//! `MeshError` that wraps it, so that the reader and the error report do not import
//! each other.

/// Why a STEP file could not be read.
#[derive(Debug, Clone, PartialEq)]
pub enum StepError {
    /// Not valid Part 21 text.
    Syntax {
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// No solid or sheet body.
    NoSolid,
    /// A reference to an instance the file does not define.
    Missing {
        /// The missing instance.
        id: u64,
        /// The instance that refers to it.
        from: Option<u64>,
    },
    /// An instance whose parameters are not what its type needs.
    Malformed {
        /// The instance.
        id: u64,
        /// Its line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A curve or surface type inspc does not evaluate.
    Unsupported {
        /// The instance.
        id: u64,
        /// Its line.
        line: usize,
        /// `surface SURFACE_OF_REVOLUTION`.
        what: String,
    },
    /// The length or angle unit cannot be determined.
    Unit(String),
    /// Faces that could not be meshed: (1-based face number, instance, why).
    Faces(Vec<(usize, u64, String)>),
}

impl std::fmt::Display for StepError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StepError::Syntax { line, message } => write!(f, "line {line}: {message}"),
            StepError::NoSolid => write!(
                f,
                "it holds no solid (MANIFOLD_SOLID_BREP) and no sheet body"
            ),
            StepError::Missing {
                id,
                from: Some(from),
            } => {
                write!(f, "#{from} refers to #{id}, which the file does not define")
            }
            StepError::Missing { id, from: None } => {
                write!(f, "#{id} is referred to but not defined")
            }
            StepError::Malformed { id, line, message } => {
                write!(f, "#{id} (line {line}): {message}")
            }
            StepError::Unsupported { id, line, what } => {
                write!(
                    f,
                    "#{id} (line {line}) is a {what}, which inspc does not evaluate"
                )
            }
            StepError::Unit(m) => write!(f, "{m}"),
            StepError::Faces(list) => {
                let (n, id, why) = &list[0];
                write!(f, "face_{n} (#{id}) cannot be meshed: {why}")?;
                if list.len() > 1 {
                    write!(f, " (and {} more faces)", list.len() - 1)?;
                }
                Ok(())
            }
        }
    }
}
