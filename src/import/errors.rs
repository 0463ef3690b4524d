//! What `inspc import` reports beside the spec it writes: an item of the file's PMI left
//! out because a value of it cannot be written as the language holds it. The spec says
//! the same in a comment; the diagnostic makes sure nobody misses it.

use crate::source::Span;
use miette::Diagnostic;
use thiserror::Error;

/// A PMI item left out for a value, as plain data: `import` is a pure function of the
/// file's bytes and knows no spans; the caller places it with [`LeftOut::at`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LeftOut {
    /// The item as the spec's comment names it: ``tolerance `Position (3)` (#128)``.
    pub item: String,
    /// What is wrong with its value (`a zone of inf mm`), or for a general tolerance,
    /// what it applies to.
    pub value: String,
    /// A general tolerance (one on the whole part), not a value the spec cannot hold.
    pub general: bool,
}

impl LeftOut {
    /// The diagnostic, labelled on `span`: the file's path as the command line named it.
    pub fn at(&self, span: Span) -> ImportError {
        let (item, value) = (self.item.clone(), self.value.clone());
        if self.general {
            ImportError::GeneralTolerance { span, item, value }
        } else {
            ImportError::ValueLeftOut { span, item, value }
        }
    }
}

/// A problem importing a STEP or QIF file.
#[derive(Debug, Error, Diagnostic)]
#[allow(missing_docs)]
pub enum ImportError {
    #[error("{item} is left out of the spec: {value}")]
    #[diagnostic(
        code(insp::import::value_left_out),
        severity(Warning),
        help("a spec holds finite values, zones wider than 0 and limits with the lower below the upper; the spec names the item in a comment: check it in the CAD system and export again, or write it by hand")
    )]
    ValueLeftOut {
        #[label("read from this file")]
        span: Span,
        item: String,
        value: String,
    },

    #[error("{item} is a general tolerance ({value}): the spec keeps it as a comment")]
    #[diagnostic(
        code(insp::import::general_tolerance),
        severity(Warning),
        help("a tolerance on the whole part is the drawing's \"unless otherwise specified\" note: the program inspects the features toleranced one by one; to check it on chosen surfaces, write a `profile_surface` on a feature of those faces")
    )]
    GeneralTolerance {
        #[label("read from this file")]
        span: Span,
        item: String,
        value: String,
    },
}

crate::diag::located!(ImportError {
    ValueLeftOut,
    GeneralTolerance
});
