//! A reader for the DMIS we write: statements with their labels and parameters, and the
//! checks a controller would make before running a program — line length, legal and
//! unique labels, names defined before use, `MEAS` blocks with as many touches as they
//! announce and nothing but moves inside, `DMISMN` first and `ENDFIL` last.

use super::text::{is_label, split_params, LINE_MAX};
use crate::source::{FileId, Span};
use miette::Diagnostic;
use std::collections::{BTreeMap, BTreeSet};
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

/// A program read.
#[derive(Debug, Clone, PartialEq)]
pub struct Program {
    /// Its statements in order.
    pub statements: Vec<Statement>,
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
}

crate::located!(DmisError {
    LongLine,
    Syntax,
    BadLabel,
    Duplicate,
    Undefined,
    Structure,
});

/// Statements that may appear between `MEAS` and `ENDMES`.
const IN_MEAS: &[&str] = &["GOTO", "PTMEAS", "PAMEAS"];

/// Parses and checks a program (the text of `file`); every problem found, in text order.
pub fn read(file: FileId, text: &str) -> Result<Program, Vec<DmisError>> {
    let at_len = |start: usize, len: usize| Span::new(file, start, start + len);
    let mut errors = Vec::new();
    let mut statements = Vec::new();
    // Physical lines → logical statements.
    let mut offset = 0;
    let mut pending: Option<(usize, String)> = None;
    for (k, line) in text.split_inclusive('\n').enumerate() {
        let at = offset;
        offset += line.len();
        let line = line.trim_end_matches('\n').trim_end_matches('\r');
        if line.chars().count() > LINE_MAX {
            errors.push(DmisError::LongLine {
                span: at_len(at, line.len()),
                line: k + 1,
                len: line.chars().count(),
            });
        }
        if pending.is_none() {
            if let Some(c) = line.strip_prefix("$$") {
                statements.push(Statement::Comment(
                    c.strip_prefix(' ').unwrap_or(c).to_string(),
                ));
                continue;
            }
            if line.trim().is_empty() {
                continue;
            }
        }
        let (start, mut acc) = pending.take().unwrap_or((at, String::new()));
        if let Some(body) = line.strip_suffix('$') {
            acc.push_str(body);
            pending = Some((start, acc));
            continue;
        }
        acc.push_str(line);
        match parse(&acc, start) {
            Some(s) => statements.push(s),
            None => errors.push(DmisError::Syntax {
                span: at_len(start, acc.len().min(text.len() - start)),
                text: acc.chars().take(40).collect(),
            }),
        }
    }
    if let Some((start, acc)) = pending {
        errors.push(DmisError::Syntax {
            span: at_len(start, 0),
            text: acc.chars().take(40).collect(),
        });
    }
    check(&statements, text, file, &mut errors);
    if errors.is_empty() {
        Ok(Program { statements })
    } else {
        Err(errors)
    }
}

/// One logical statement.
fn parse(s: &str, at: usize) -> Option<Statement> {
    let (label, rest) = match s.split_once('=') {
        Some((l, r)) if l.ends_with(')') && !l.contains('\'') => {
            let (kind, name) = l.trim_end_matches(')').split_once('(')?;
            (Some((kind.to_string(), name.to_string())), r)
        }
        _ => (None, s),
    };
    let (major, params) = match rest.split_once('/') {
        Some((m, p)) => (m, split_params(p).into_iter().map(String::from).collect()),
        None => (rest, vec![]),
    };
    if major.is_empty() || !major.bytes().all(|c| c.is_ascii_uppercase()) {
        return None;
    }
    // A quote opened and never closed swallows the rest of the statement.
    if rest.matches('\'').count() % 2 == 1 {
        return None;
    }
    Some(Statement::Command {
        label,
        major: major.to_string(),
        params,
        at,
    })
}

/// A plain decimal number as DMIS writes it — an optional sign, digits, at most one
/// point — and finite: not `nan`, `inf`, an exponent or a number past `f64`.
fn decimal(s: &str) -> Option<f64> {
    let body = s.strip_prefix(['-', '+']).unwrap_or(s);
    let digits = body.bytes().filter(u8::is_ascii_digit).count();
    let points = body.bytes().filter(|&c| c == b'.').count();
    if digits == 0 || points > 1 || digits + points != body.len() {
        return None;
    }
    s.parse::<f64>().ok().filter(|x| x.is_finite())
}

/// The `KIND(label)` references in a parameter list.
fn refs(params: &[String]) -> Vec<(String, String)> {
    params
        .iter()
        .filter_map(|p| {
            let (k, rest) = p.split_once('(')?;
            let l = rest.strip_suffix(')')?;
            (!k.is_empty() && k.bytes().all(|c| c.is_ascii_uppercase()))
                .then(|| (k.to_string(), l.to_string()))
        })
        .collect()
}

/// A command as the checks see it: label, major word, parameters, offset.
type Cmd<'a> = (&'a Option<(String, String)>, &'a str, &'a [String], usize);

fn check(statements: &[Statement], text: &str, file: FileId, errors: &mut Vec<DmisError>) {
    let span = |at: usize| -> Span {
        let end = text[at..].find('\n').map_or(text.len(), |e| at + e);
        Span::new(file, at, end)
    };
    let commands: Vec<Cmd> = statements
        .iter()
        .filter_map(|s| match s {
            Statement::Command {
                label,
                major,
                params,
                at,
            } => Some((label, major.as_str(), &params[..], *at)),
            _ => None,
        })
        .collect();
    let structure = |at: usize, what: &str, help: &str| DmisError::Structure {
        span: span(at),
        what: what.into(),
        help: help.into(),
    };
    match commands.first() {
        Some((_, "DMISMN", _, _)) => {}
        Some((_, _, _, at)) => errors.push(structure(
            *at,
            "the program does not start with DMISMN",
            "start with `DMISMN/'name',05.3`",
        )),
        None => errors.push(structure(
            0,
            "the program is empty",
            "start with `DMISMN/'name',05.3` and end with `ENDFIL`",
        )),
    }
    if let Some((_, m, _, at)) = commands.last() {
        if *m != "ENDFIL" {
            errors.push(structure(
                *at,
                "the program does not end with ENDFIL",
                "end the program with `ENDFIL`",
            ));
        }
    }
    // Definitions (any position: a tolerance may name a datum defined later).
    let mut defined: BTreeMap<(String, String), usize> = BTreeMap::new();
    // The machine's own coordinate system is always there.
    defined.insert(("D".into(), "MCS".into()), 0);
    for (label, major, _, at) in &commands {
        let Some((kind, l)) = label else { continue };
        if !is_label(l) {
            errors.push(DmisError::BadLabel {
                span: span(*at),
                label: l.clone(),
            });
        }
        // Datums are redefined each time their feature is measured again.
        let key = (kind.clone(), l.clone());
        if defined.contains_key(&key) && *major != "DATDEF" {
            errors.push(DmisError::Duplicate {
                span: span(*at),
                kind: kind.clone(),
                label: l.clone(),
            });
        }
        defined.entry(key).or_insert(*at);
    }
    let mut measured: BTreeSet<String> = BTreeSet::new();
    let mut meas: Option<(usize, usize, usize)> = None; // (at, announced, touches)
    for (_, major, params, at) in &commands {
        // References: F/FA to features, S to sensors, TA/T to tolerances, DAT to datums.
        for (k, l) in refs(params) {
            let kind = match k.as_str() {
                "F" | "FA" => "F",
                "TA" | "T" => "T",
                other => other,
            };
            let ok = match kind {
                "F" if k == "FA" => measured.contains(&l),
                _ => defined.contains_key(&(kind.to_string(), l.clone())),
            };
            let ok = ok && (kind != "F" || defined.contains_key(&("F".to_string(), l.clone())));
            if !ok {
                errors.push(DmisError::Undefined {
                    span: span(*at),
                    kind: k.clone(),
                    label: l,
                });
            }
        }
        match (*major, &mut meas) {
            ("MEAS", None) => {
                let n = params.last().and_then(|n| n.parse::<usize>().ok());
                match n {
                    Some(n) => meas = Some((*at, n, 0)),
                    None => errors.push(structure(
                        *at,
                        "MEAS without a point count",
                        "write `MEAS/type,F(label),n`",
                    )),
                }
                if let Some((_, l)) = refs(params).first() {
                    measured.insert(l.clone());
                }
            }
            ("CONST", None) => {
                // A constructed feature is measured once its sources are.
                if let Some((_, l)) = refs(params).first() {
                    measured.insert(l.clone());
                }
            }
            ("MEAS", Some(_)) => errors.push(structure(
                *at,
                "MEAS inside a MEAS block",
                "close the block with ENDMES first",
            )),
            ("PTMEAS", Some(m)) => m.2 = m.2.saturating_add(1),
            // A block that scans announces the cloud's size, which DMIS leaves to the
            // machine: its count is not checked.
            ("PAMEAS", Some(m)) => m.2 = usize::MAX,
            ("PAMEAS", None) => errors.push(structure(
                *at,
                "PAMEAS outside a MEAS block",
                "put scan passes between MEAS and ENDMES",
            )),
            ("ENDMES", Some((start, n, got))) => {
                if *got != usize::MAX && n != got {
                    errors.push(structure(
                        *start,
                        &format!("MEAS announces {n} points but takes {got}"),
                        "make the count match the PTMEAS statements",
                    ));
                }
                meas = None;
            }
            ("ENDMES", None) => errors.push(structure(
                *at,
                "ENDMES without MEAS",
                "open the block with MEAS",
            )),
            (m, Some(_)) if !IN_MEAS.contains(&m) => errors.push(structure(
                *at,
                &format!("{m} inside a MEAS block"),
                "only GOTO, PTMEAS and PAMEAS belong between MEAS and ENDMES",
            )),
            ("PTMEAS", None) => errors.push(structure(
                *at,
                "PTMEAS outside a MEAS block",
                "put touches between MEAS and ENDMES",
            )),
            _ => {}
        }
        if matches!(*major, "GOTO" | "PTMEAS") {
            let nums = params.iter().filter(|p| *p != "CART");
            if nums.clone().any(|p| decimal(p).is_none()) {
                errors.push(structure(
                    *at,
                    &format!("{major} with a parameter that is not a number"),
                    "coordinates are plain decimal numbers",
                ));
            }
        }
    }
    if let Some((at, _, _)) = meas {
        errors.push(structure(
            at,
            "MEAS block without ENDMES",
            "close the block with ENDMES",
        ));
    }
}

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
    fn each_problem_has_its_code() {
        let long = format!("DMISMN/'X',05.3\nTEXT/OPER,'{}'\nENDFIL\n", "A".repeat(80));
        assert_eq!(codes(&long), ["insp::dmis::long_line"]);
        assert_eq!(
            codes("DMISMN/'X',05.3\ngoto 1 2 3\nENDFIL\n"),
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
            codes("DMISMN/'X',05.3\nF(a)=FEAT/POINT,CART,0,0,0,0,0,1\nENDFIL\n"),
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
            assert!(decimal(good).is_some(), "{good}");
        }
    }
}
