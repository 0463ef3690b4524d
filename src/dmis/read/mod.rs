//! A reader for DMIS as the language is written, not only as inspc writes it: any case,
//! blanks between tokens, `$` continuation, trailing `$$` comments ([`lex`]); and the
//! checks a controller makes before it runs a program ([`check`]) — legal and unique
//! labels, names defined before use, `MEAS` blocks with as many touches as they announce,
//! blocks (`IF`, `DO`, `SELECT`, `MACRO`) closed, a program or module header first and
//! `ENDFIL` last. Statements inspc's virtual CMM does not run, vendor extensions and
//! words DMIS does not have are warnings on the statement ([`words`]), never skipped
//! without a word.
//!
//! Three kinds of file read: a program (`DMISMN` first), a module (`DMISMD` first) and a
//! results file (`FILNAM` first, as NIST's `output.dms`: actuals follow the `OUTPUT`
//! that names them, so names are not checked before use there).

mod check;
mod lex;
mod words;

pub use words::{word, Word};

use crate::source::{FileId, Span};
use miette::Diagnostic;
use thiserror::Error;

/// One statement.
#[derive(Debug, Clone, PartialEq)]
pub enum Statement {
    /// `$$ text`.
    Comment(String),
    /// `[KIND(label)=]MAJOR[/params]`.
    Command {
        /// `F`, `S`, `T`, `DAT`, `D` and the label.
        label: Option<(String, String)>,
        /// `FEAT`, `GOTO`, `PTMEAS`, ….
        major: String,
        /// The parameters, as written.
        params: Vec<String>,
        /// Byte offset of the statement in the text.
        at: usize,
    },
}

/// A command's label, major word, parameters and offset.
pub type Command<'a> = (&'a Option<(String, String)>, &'a str, &'a [String], usize);

impl Statement {
    /// The command it is, if it is not a comment.
    pub fn command(&self) -> Option<Command<'_>> {
        match self {
            Statement::Command {
                label,
                major,
                params,
                at,
            } => Some((label, major.as_str(), &params[..], *at)),
            Statement::Comment(_) => None,
        }
    }
}

/// A program read.
#[derive(Debug)]
pub struct Program {
    /// Its statements in order.
    pub statements: Vec<Statement>,
    /// What it holds that inspc reads but does not run, or does not know.
    pub warnings: Vec<DmisError>,
}

impl Program {
    /// The commands with a given major word.
    pub fn commands<'a>(&'a self, major: &'a str) -> impl Iterator<Item = &'a [String]> + 'a {
        self.statements.iter().filter_map(move |s| match s {
            Statement::Command {
                major: m, params, ..
            } if m == major => Some(&params[..]),
            _ => None,
        })
    }

    /// The text again, through the writer's line rules: byte-identical to what inspc
    /// wrote.
    pub fn to_text(&self) -> String {
        let mut out = String::new();
        for s in &self.statements {
            match s {
                Statement::Comment(c) => {
                    out.push_str("$$ ");
                    out.push_str(c);
                    out.push('\n');
                }
                Statement::Command {
                    label,
                    major,
                    params,
                    ..
                } => {
                    let mut t = String::new();
                    if let Some((k, l)) = label {
                        t.push_str(&format!("{k}({l})="));
                    }
                    t.push_str(major);
                    if !params.is_empty() {
                        t.push('/');
                        t.push_str(&params.join(","));
                    }
                    for line in super::text::wrap(&t) {
                        out.push_str(&line);
                        out.push('\n');
                    }
                }
            }
        }
        out
    }
}

/// What is wrong with a DMIS program.
#[derive(Debug, Error, Diagnostic)]
#[allow(missing_docs)]
pub enum DmisError {
    #[error("line {line} is {len} characters long; DMIS lines hold at most {LINE_MAX}")]
    #[diagnostic(
        code(insp::dmis::long_line),
        help("break the statement after a comma and end the line with `$`")
    )]
    LongLine {
        #[label("this line")]
        span: Span,
        line: usize,
        len: usize,
    },
    #[error("`{text}` is not a DMIS statement")]
    #[diagnostic(
        code(insp::dmis::syntax),
        help("statements read `[KIND(label)=]MAJOR/param,param,…`, comments start with `$$`")
    )]
    Syntax {
        #[label("here")]
        span: Span,
        text: String,
    },
    #[error("`{label}` is not a legal label")]
    #[diagnostic(
        code(insp::dmis::bad_label),
        help("labels are 1 to 16 characters: an upper-case letter, then letters, digits or `_`")
    )]
    BadLabel {
        #[label("this label")]
        span: Span,
        label: String,
    },
    #[error("{kind}({label}) is defined twice")]
    #[diagnostic(
        code(insp::dmis::duplicate_label),
        help("every feature, sensor and tolerance needs a label of its own")
    )]
    Duplicate {
        #[label("defined again here")]
        span: Span,
        kind: String,
        label: String,
    },
    #[error("{kind}({label}) is used but never defined")]
    #[diagnostic(
        code(insp::dmis::undefined),
        help("define it with `{kind}({label})=…` before this statement")
    )]
    Undefined {
        #[label("used here")]
        span: Span,
        kind: String,
        label: String,
    },
    #[error("{what}")]
    #[diagnostic(code(insp::dmis::structure), help("{help}"))]
    Structure {
        #[label("here")]
        span: Span,
        what: String,
        help: String,
    },
    #[error(
        "`DAT({datum})=DATDEF/…` is not DMIS: a datum is defined by the statement's last parameter"
    )]
    #[diagnostic(
        code(insp::dmis::datdef_form),
        help("write `DATDEF/{feature},DAT({datum})`, the form of ANSI/DMIS 105.2 and of NIST's and the QIF bindings' programs; a controller stops on this one")
    )]
    DatdefForm {
        #[label("this datum")]
        span: Span,
        datum: String,
        feature: String,
    },
    #[error("{major} is DMIS that inspc's virtual CMM does not run")]
    #[diagnostic(
        code(insp::dmis::not_run),
        severity(Warning),
        help("the statement is read and checked; `inspc simulate` passes over it, so whatever depends on it is not simulated")
    )]
    NotRun {
        #[label("passed over")]
        span: Span,
        major: String,
    },
    #[error("{major} is a vendor extension ({what}), not DMIS 5.3")]
    #[diagnostic(
        code(insp::dmis::vendor_extension),
        severity(Warning),
        help("a controller of another vendor stops here; `inspc simulate` passes over it")
    )]
    VendorExtension {
        #[label("extension")]
        span: Span,
        major: String,
        what: String,
    },
    #[error("{major} is not a DMIS 5.3 statement")]
    #[diagnostic(
        code(insp::dmis::unknown_statement),
        severity(Warning),
        help("check the spelling against the standard's major words; if it is a vendor's own statement, only that vendor's controller runs it")
    )]
    UnknownStatement {
        #[label("unknown")]
        span: Span,
        major: String,
    },
}

crate::diag::located!(DmisError {
    LongLine,
    Syntax,
    BadLabel,
    Duplicate,
    Undefined,
    Structure,
    DatdefForm,
    NotRun,
    VendorExtension,
    UnknownStatement,
});

/// Parses and checks a program (the text of `file`): the program with its warnings, or
/// every error found (and the warnings), in text order.
pub fn read(file: FileId, text: &str) -> Result<Program, Vec<DmisError>> {
    let mut errors = Vec::new();
    let mut statements = Vec::new();
    let first_line = |at: usize| -> Span {
        let end = text[at..].find('\n').map_or(text.len(), |e| at + e);
        Span::new(file, at, end.max(at))
    };
    let mut offset = 0;
    for (k, line) in text.split_inclusive('\n').enumerate() {
        let body = line.trim_end_matches(['\n', '\r']);
        if body.chars().count() > LINE_MAX {
            errors.push(DmisError::LongLine {
                span: Span::new(file, offset, offset + body.len()),
                line: k + 1,
                len: body.chars().count(),
            });
        }
        offset += line.len();
    }
    for l in lex::lines(text) {
        match l {
            lex::Line::Comment { text, .. } => statements.push(Statement::Comment(text)),
            lex::Line::Statement { text: s, at } => {
                let parsed = lex::canonical(&s).and_then(|c| lex::parse(&c));
                match parsed {
                    Some((label, major, params)) => statements.push(Statement::Command {
                        label,
                        major,
                        params,
                        at,
                    }),
                    None => errors.push(DmisError::Syntax {
                        span: first_line(at),
                        text: s.trim().chars().take(40).collect(),
                    }),
                }
            }
            lex::Line::Unfinished { at } => errors.push(DmisError::Syntax {
                span: first_line(at),
                text: "a statement continued with `$` past the end of the file".into(),
            }),
        }
    }
    let mut warnings = Vec::new();
    check::check(&statements, &first_line, &mut errors, &mut warnings);
    if errors.is_empty() {
        Ok(Program {
            statements,
            warnings,
        })
    } else {
        errors.extend(warnings);
        errors.sort_by_key(|e| {
            miette::Diagnostic::labels(e)
                .and_then(|mut l| l.next())
                .map_or(0, |l| l.offset())
        });
        Err(errors)
    }
}

/// The longest line a controller takes (characters): DMIS breaks longer statements
/// with `$`.
const LINE_MAX: usize = super::text::LINE_MAX;

#[cfg(test)]
mod tests {
    use super::*;

    fn codes(text: &str) -> Vec<String> {
        match read(FileId(0), text) {
            Ok(_) => vec![],
            Err(es) => es
                .iter()
                .map(|e| e.code().map(|c| c.to_string()).unwrap_or_default())
                .collect(),
        }
    }

    #[test]
    fn a_clean_program_reads_and_prints_back() {
        let text = "$$ a comment\nDMISMN/'X',05.3\nF(P)=FEAT/PLANE,CART,0,0,0,0,0,1\nS(S1)=SNSDEF/PROBE,FIXED,CART,0,0,-50,0,0,1,2\nSNSLCT/S(S1)\nMEAS/PLANE,F(P),1\nGOTO/0,0,3\nPTMEAS/CART,0,0,0,0,0,1\nENDMES\nT(T1)=TOL/FLAT,0.1\nOUTPUT/FA(P),TA(T1)\nENDFIL\n";
        let p = read(FileId(0), text).unwrap();
        assert_eq!(p.to_text(), text);
        assert_eq!(p.commands("PTMEAS").count(), 1);
    }

    #[test]
    fn statements_after_an_early_endfil_are_an_error() {
        assert_eq!(
            codes("DMISMN/'X',05.3\nENDFIL\nTEXT/OPER,'after the end'\nENDFIL\n"),
            ["insp::dmis::structure"]
        );
    }

    #[test]
    fn each_problem_has_its_code() {
        let long = format!("DMISMN/'X',05.3\nTEXT/OPER,'{}'\nENDFIL\n", "A".repeat(80));
        assert_eq!(codes(&long), ["insp::dmis::long_line"]);
        assert_eq!(
            codes("DMISMN/'X',05.3\nF(=FEAT/POINT\nENDFIL\n"),
            ["insp::dmis::syntax"]
        );
        assert_eq!(
            codes("DMISMN/'X',05.3\nF(P)=FEAT/POINT,CART,0,0,0,0,0,1\nF(P)=FEAT/POINT,CART,0,0,0,0,0,1\nENDFIL\n"),
            ["insp::dmis::duplicate_label"]
        );
        assert_eq!(
            codes("DMISMN/'X',05.3\nSNSLCT/S(NONE)\nENDFIL\n"),
            ["insp::dmis::undefined"]
        );
        assert_eq!(
            codes("DMISMN/'X',05.3\nF(A-B)=FEAT/POINT,CART,0,0,0,0,0,1\nENDFIL\n"),
            ["insp::dmis::bad_label"]
        );
        assert_eq!(
            codes("GOTO/1,2,3\n"),
            ["insp::dmis::structure", "insp::dmis::structure"]
        );
        // A continued statement reads as one.
        let wrapped = "DMISMN/'X',05.3\nF(P)=FEAT/PLANE,CART,$\n0,0,0,0,0,1\nENDFIL\n";
        assert!(codes(wrapped).is_empty());
    }

    #[test]
    fn unterminated_quotes_and_odd_numbers_are_rejected() {
        assert_eq!(
            codes("DMISMN/'X',05.3\nTEXT/OPER,'never closed\nENDFIL\n"),
            ["insp::dmis::syntax"]
        );
        for bad in [
            "nan", "inf", "-inf", "1e999", "1e3", "1.2.3", "+", "0x10", "",
        ] {
            let text = format!(
                "DMISMN/'X',05.3\nF(P)=FEAT/PLANE,CART,0,0,0,0,0,1\nMEAS/PLANE,F(P),1\nGOTO/{bad},0,3\nPTMEAS/CART,0,0,0,0,0,1\nENDMES\nENDFIL\n"
            );
            assert_eq!(codes(&text), ["insp::dmis::structure"], "{bad:?}");
        }
        for good in ["1", "-1.5", "+0.25", "10.", ".5"] {
            assert!(check::decimal(good).is_some(), "{good}");
        }
    }
}
