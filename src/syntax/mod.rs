//! Stage 1, syntax: text → [`ast::File`].
//!
//! The grammar lives in `grammar/insp.pest`; this module runs it and lowers pest's pairs
//! into the typed [`ast`] with a [`Span`] on every node. Syntax errors name what was
//! expected in words (see `words.rs`), never a raw grammar rule.
//!
//! **Architecture Invariant:** `syntax` knows nothing about names, units, geometry or
//! DMIS; it accepts any text and either returns a tree or one [`SyntaxError`].

pub mod ast;
mod lower;
mod words;

use crate::source::{FileId, Span};

mod grammar {
    #![allow(missing_docs)]
    #[derive(pest_derive::Parser)]
    #[grammar = "../grammar/insp.pest"]
    pub(crate) struct InspParser;
}
pub(crate) use grammar::{InspParser, Rule};

/// A syntax error.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
pub enum SyntaxError {
    /// The parser met something it did not expect.
    #[error("expected {expected}, found {found}")]
    #[diagnostic(code(insp::syntax::unexpected))]
    Unexpected {
        /// Where.
        #[label("expected {expected}")]
        span: Span,
        /// What would have been accepted, in words.
        expected: String,
        /// What was found, in words.
        found: String,
        /// A hint.
        #[help]
        help: String,
    },
    /// A number that does not fit.
    #[error("invalid number `{text}`")]
    #[diagnostic(code(insp::syntax::invalid_number), help("numbers must be finite; indices must be whole numbers below 4294967296"))]
    InvalidNumber {
        /// Where.
        #[label("not a usable number")]
        span: Span,
        /// The text.
        text: String,
    },
    /// An unknown escape in a string.
    #[error("unknown escape `{text}` in a string")]
    #[diagnostic(code(insp::syntax::invalid_escape), help("strings know `\\\\`, `\\\"`, `\\n` and `\\t`"))]
    InvalidEscape {
        /// Where.
        #[label("unknown escape")]
        span: Span,
        /// The escape.
        text: String,
    },
}

impl SyntaxError {
    /// The span at fault.
    pub fn span(&self) -> Span {
        match self {
            SyntaxError::Unexpected { span, .. }
            | SyntaxError::InvalidNumber { span, .. }
            | SyntaxError::InvalidEscape { span, .. } => *span,
        }
    }
}

/// Parses one file. The entry point of the syntax stage.
pub fn parse(file: FileId, text: &str) -> Result<ast::File, SyntaxError> {
    use pest::Parser;
    let mut pairs = InspParser::parse(Rule::file, text).map_err(|e| words::syntax_error(file, text, e))?;
    let root = pairs.next().expect("pest returns the `file` pair on success");
    lower::file(file, root)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_f2() {
        let text = include_str!("../../examples/f2.insp");
        let f = parse(FileId(0), text).unwrap_or_else(|e| panic!("{e:?}"));
        assert_eq!(f.items.len(), 7);
    }

    #[test]
    fn errors_name_words() {
        let e = parse(FileId(0), "part p { units mm\n stock box(1, 2, 3)\n tolerance T = }").unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("expected a name, found `}`"), "{msg}");
        assert!(!msg.contains("Rule") && !msg.contains('_'), "{msg}");
    }
}
