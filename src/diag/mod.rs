//! Diagnostics: collecting them, ordering them, rendering them.
//!
//! Stage: shared. Each stage defines its own error enum deriving [`miette::Diagnostic`]
//! with a stable code `insp::<stage>::<name>`, a label on the span at fault and a help
//! line. Errors are plain data; this module renders them, either as miette's graphical
//! report (for people) or as one JSON object per line (for editors).
//!
//! **Architecture Invariant:** a diagnostic is filed under the file of its primary span,
//! by construction: [`Diagnostics::push`] takes no file, it asks the error ([`Located`]).
//! Its other labels lie in that file too; a related place in another file is named in
//! the message or help instead.

mod render;
pub mod suggest;

pub use render::{render_human, to_json, RenderOptions};

use crate::source::{FileId, Span};
use miette::Severity;

/// Where a diagnostic belongs: the file of its primary span.
pub trait Located {
    /// The file its primary label points into.
    fn file(&self) -> FileId;
}

/// Implements [`Located`] for an error enum whose every variant has a primary
/// `span: Span` field: `located!(PlanError { UninspectableFace, NoConvergence, NoPlan })`;
/// variants that wrap another located error (`Step(InFile<StepError>)`) are listed after
/// `wrapping` and ask it. A variant added without a `span` does not compile, nor does
/// one left out of the list.
macro_rules! located {
    ($ty:ty { $($variant:ident),* $(,)? } $(wrapping { $($wrap:ident),* $(,)? })?) => {
        impl $crate::diag::Located for $ty {
            fn file(&self) -> $crate::source::FileId {
                match self {
                    $(Self::$variant { span, .. } => $crate::diag::primary_file(span),)*
                    $($(Self::$wrap(inner) => $crate::diag::Located::file(inner),)*)?
                }
            }
        }
    };
}
pub(crate) use located;

/// An IO error belongs to the file it could not read or write.
impl Located for crate::source::io::IoError {
    fn file(&self) -> FileId {
        match self {
            crate::source::io::IoError::Unreadable { file, .. }
            | crate::source::io::IoError::Unwritable { file, .. }
            | crate::source::io::IoError::NotAFile { file, .. }
            | crate::source::io::IoError::OverwritesInput { file, .. }
            | crate::source::io::IoError::SameOutput { file, .. } => *file,
        }
    }
}

/// A diagnostic at another severity than its type's ([`Diagnostics::push_at`]): all
/// else — code, message, labels, help — is the inner one's.
struct AtSeverity {
    inner: Box<dyn miette::Diagnostic + Send + Sync + 'static>,
    severity: Severity,
}

impl std::fmt::Debug for AtSeverity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        std::fmt::Debug::fmt(&self.inner, f)
    }
}

impl std::fmt::Display for AtSeverity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        std::fmt::Display::fmt(&self.inner, f)
    }
}

impl std::error::Error for AtSeverity {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.inner.source()
    }
}

impl miette::Diagnostic for AtSeverity {
    fn code<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        self.inner.code()
    }
    fn severity(&self) -> Option<Severity> {
        Some(self.severity)
    }
    fn help<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        self.inner.help()
    }
    fn url<'a>(&'a self) -> Option<Box<dyn std::fmt::Display + 'a>> {
        self.inner.url()
    }
    fn source_code(&self) -> Option<&dyn miette::SourceCode> {
        self.inner.source_code()
    }
    fn labels(&self) -> Option<Box<dyn Iterator<Item = miette::LabeledSpan> + '_>> {
        self.inner.labels()
    }
    fn related<'a>(&'a self) -> Option<Box<dyn Iterator<Item = &'a dyn miette::Diagnostic> + 'a>> {
        self.inner.related()
    }
    fn diagnostic_source(&self) -> Option<&dyn miette::Diagnostic> {
        self.inner.diagnostic_source()
    }
}

/// The file of a primary span (for [`located!`]).
pub(crate) fn primary_file(span: &Span) -> FileId {
    span.file
}

/// One diagnostic, filed under the file its labels point into.
pub struct Diagnostic {
    /// The file the labels point into.
    pub file: FileId,
    /// The typed error.
    pub inner: Box<dyn miette::Diagnostic + Send + Sync + 'static>,
}

impl Diagnostic {
    /// The stable code, e.g. `insp::resolve::unknown_name`.
    pub fn code(&self) -> String {
        self.inner.code().map(|c| c.to_string()).unwrap_or_default()
    }

    /// Error unless the diagnostic says otherwise.
    pub fn severity(&self) -> Severity {
        self.inner.severity().unwrap_or(Severity::Error)
    }

    /// The message.
    pub fn message(&self) -> String {
        self.inner.to_string()
    }

    /// The byte offset of the first label, used to order diagnostics.
    pub fn offset(&self) -> usize {
        self.inner
            .labels()
            .and_then(|mut l| l.next())
            .map_or(0, |l| l.offset())
    }
}

impl std::fmt::Debug for Diagnostic {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: {} (file {:?} @{})",
            self.code(),
            self.message(),
            self.file,
            self.offset()
        )
    }
}

/// The diagnostics of one run.
#[derive(Debug, Default)]
pub struct Diagnostics {
    items: Vec<Diagnostic>,
}

impl Diagnostics {
    /// An empty sink.
    pub fn new() -> Self {
        Self::default()
    }

    /// Files a diagnostic under the file of its primary span.
    pub fn push(&mut self, err: impl miette::Diagnostic + Located + Send + Sync + 'static) {
        self.items.push(Diagnostic {
            file: err.file(),
            inner: Box::new(err),
        });
    }

    /// Files `err` at `severity` instead of its type's: one problem, one code, an error
    /// by default and a warning where the user allowed it (`--allow-unmeasured`), as
    /// rustc's lints keep their name at any level.
    pub fn push_at(
        &mut self,
        severity: Severity,
        err: impl miette::Diagnostic + Located + Send + Sync + 'static,
    ) {
        self.items.push(Diagnostic {
            file: err.file(),
            inner: Box::new(AtSeverity {
                inner: Box::new(err),
                severity,
            }),
        });
    }

    /// Files an already boxed diagnostic.
    pub fn push_boxed(&mut self, d: Diagnostic) {
        self.items.push(d);
    }

    /// Whether nothing was filed.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Whether any error (not just warnings) was filed.
    pub fn has_errors(&self) -> bool {
        self.items.iter().any(|d| d.severity() == Severity::Error)
    }

    /// All diagnostics in a stable order: by file, then position, then code.
    pub fn sorted(mut self) -> Vec<Diagnostic> {
        self.items.sort_by(|a, b| {
            (a.file, a.offset(), a.code(), a.message()).cmp(&(
                b.file,
                b.offset(),
                b.code(),
                b.message(),
            ))
        });
        self.items
    }

    /// Moves every diagnostic of `other` into this sink.
    pub fn extend(&mut self, other: Diagnostics) {
        self.items.extend(other.items);
    }
}
