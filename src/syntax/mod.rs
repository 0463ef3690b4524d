//! Stage 1, syntax: text → [`ast::File`].
//!
//! The grammar lives in `grammar/insp.pest`; this module runs it and lowers pest's pairs
//! into the typed [`ast`] with a [`Span`] on every node. Syntax errors name what was
//! expected in words (see `words.rs`), never a raw grammar rule.
//!
//! **Architecture Invariant:** `syntax` knows nothing about names, units, geometry or
//! DMIS; it accepts any text and either returns a tree or one [`SyntaxError`].

pub mod ast;
mod keywords;
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
pub(crate) use keywords::KEYWORDS;

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
    #[diagnostic(
        code(insp::syntax::invalid_number),
        help("numbers must be finite; indices must be whole numbers below 4294967296")
    )]
    InvalidNumber {
        /// Where.
        #[label("not a usable number")]
        span: Span,
        /// The text.
        text: String,
    },
    /// Brackets nested deeper than any spec needs (and than the parser's stack allows).
    #[error("brackets nested more than {limit} deep")]
    #[diagnostic(
        code(insp::syntax::too_deep),
        help("no spec needs this nesting; check for a missing closing bracket")
    )]
    TooDeep {
        /// The bracket past the limit.
        #[label("too deep")]
        span: Span,
        /// The limit.
        limit: usize,
    },
    /// An unknown escape in a string.
    #[error("unknown escape `{text}` in a string")]
    #[diagnostic(
        code(insp::syntax::invalid_escape),
        help("strings know `\\\\`, `\\\"`, `\\n`, `\\t` and `\\u{{…}}` (1 to 6 hex digits)")
    )]
    InvalidEscape {
        /// Where.
        #[label("unknown escape")]
        span: Span,
        /// The escape.
        text: String,
    },
}

crate::diag::located!(SyntaxError {
    Unexpected,
    InvalidNumber,
    TooDeep,
    InvalidEscape,
});

/// The parse tree of `text` as a list — each rule's name, and each leaf's text — or None
/// when it does not parse. Two spellings of one spec (other spaces, comments, layout)
/// have the same outline; `inspc fmt` checks this before it writes.
pub fn outline(text: &str) -> Option<Vec<String>> {
    use pest::Parser;
    fn walk(pair: pest::iterators::Pair<Rule>, out: &mut Vec<String>) {
        out.push(format!("{:?}", pair.as_rule()));
        let mut inner = pair.clone().into_inner().peekable();
        if inner.peek().is_none() {
            out.push(pair.as_str().to_string());
        }
        for p in inner {
            walk(p, out);
        }
    }
    let pairs = InspParser::parse(Rule::file, text).ok()?;
    let mut out = Vec::new();
    for p in pairs {
        walk(p, &mut out);
    }
    Some(out)
}

/// Parses one file. The entry point of the syntax stage.
pub fn parse(file: FileId, text: &str) -> Result<ast::File, SyntaxError> {
    use pest::Parser;
    check_depth(file, text)?;
    let mut pairs = match InspParser::parse(Rule::file, text) {
        Ok(pairs) => pairs,
        Err(_) => {
            // Tracking every attempt is slow, so only a failed parse is run again with
            // pest's error detail on (a process-wide flag, hence the lock: the error a
            // file gets never depends on what other threads parse meanwhile).
            static DETAIL: std::sync::Mutex<()> = std::sync::Mutex::new(());
            let _guard = DETAIL.lock().unwrap_or_else(|e| e.into_inner());
            pest::set_error_detail(true);
            let err = InspParser::parse(Rule::file, text).err();
            pest::set_error_detail(false);
            return Err(words::syntax_error(
                file,
                text,
                err.expect("a failed parse fails again"),
            ));
        }
    };
    let root = pairs
        .next()
        .expect("pest returns the `file` pair on success");
    lower::file(file, root)
}

/// How deep brackets may nest; pest recurses per level.
const MAX_DEPTH: usize = 64;

/// Rejects bracket nesting deeper than [`MAX_DEPTH`] before pest recurses into it.
/// Strings and comments are skipped; unbalanced brackets are left to the parser.
fn check_depth(file: FileId, text: &str) -> Result<(), SyntaxError> {
    let bytes = text.as_bytes();
    let (mut i, mut depth) = (0, 0usize);
    while i < bytes.len() {
        match bytes[i] {
            b'"' => {
                i += 1;
                while i < bytes.len() && bytes[i] != b'"' && bytes[i] != b'\n' {
                    i += if bytes[i] == b'\\' { 2 } else { 1 };
                }
            }
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                while i < bytes.len() && bytes[i] != b'\n' {
                    i += 1;
                }
            }
            b'/' if bytes.get(i + 1) == Some(&b'*') => {
                i += 2;
                while i + 1 < bytes.len() && !(bytes[i] == b'*' && bytes[i + 1] == b'/') {
                    i += 1;
                }
                i += 1;
            }
            b'(' | b'[' | b'{' => {
                depth += 1;
                if depth > MAX_DEPTH {
                    return Err(SyntaxError::TooDeep {
                        span: Span::new(file, i, i + 1),
                        limit: MAX_DEPTH,
                    });
                }
            }
            b')' | b']' | b'}' => depth = depth.saturating_sub(1),
            _ => {}
        }
        i += 1;
    }
    Ok(())
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
        let e = parse(
            FileId(0),
            "part p { units mm\n stock box(1, 2, 3)\n tolerance T = }",
        )
        .unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("expected a name, found `}`"), "{msg}");
        assert!(!msg.contains("Rule") && !msg.contains('_'), "{msg}");
    }
}
