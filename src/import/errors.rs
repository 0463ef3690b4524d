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
    /// What is wrong with its value: `a zone of inf mm`.
    pub value: String,
}

impl LeftOut {
    /// The diagnostic, labelled on `span`: the file's path as the command line named it.
    pub fn at(&self, span: Span) -> ImportError {
        ImportError::ValueLeftOut {
            span,
            item: self.item.clone(),
            value: self.value.clone(),
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
}

crate::diag::located!(ImportError { ValueLeftOut });
