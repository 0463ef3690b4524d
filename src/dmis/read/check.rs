//! The checks a controller makes before it runs a program: the file's first and last
//! statements, labels, names defined before use, `MEAS` blocks and the other blocks, and
//! what inspc does not run.
//!
//! Names (ANSI/DMIS 105.2 §3.3): `F(x)` a nominal feature and `FA(x)` its actual (usable
//! once `MEAS` or `CONST` made it), `S(x)`/`SA(x)` a sensor, `T(x)`/`TA(x)` a tolerance,
//! `DAT(x)` a datum (defined by `DATDEF/FA(f),DAT(x)`, the label last), `D(x)` an
//! alignment (`D(MCS)` always there; `SAVE/DA(x)` keeps one for `RECALL/DA(x)`), `DID(x)`
//! a device.

use super::words::{word, Word};
use super::{DmisError, Statement};
use crate::dmis::text::is_label;
use crate::source::Span;
use std::collections::{BTreeMap, BTreeSet};

/// Statements that may appear between `MEAS` and `ENDMES` in what inspc runs.
const IN_MEAS: &[&str] = &["GOTO", "PTMEAS", "PAMEAS"];

/// Kinds that may not be defined twice (an alignment, a datum or an actual may).
const ONCE: &[&str] = &["F", "S", "T", "DID"];

/// Opening and closing words of the blocks DMIS nests (ANSI/DMIS 105.2 §5).
const BLOCKS: &[(&str, &str)] = &[
    ("IF", "ENDIF"),
    ("DO", "ENDDO"),
    ("SELECT", "ENDSEL"),
    ("CASE", "ENDCAS"),
    ("DFTCAS", "ENDCAS"),
    ("MACRO", "ENDMAC"),
    ("GOTARG", "ENDGO"),
    ("SIMREQT", "ENDSIMREQT"),
    ("EXTENS", "ENDXTN"),
];

/// A command as the checks see it: label, major word, parameters, offset.
type Cmd<'a> = super::Command<'a>;

/// The `KIND(label)` references in a parameter list.
pub(super) fn refs(params: &[String]) -> Vec<(String, String)> {
    params
        .iter()
        .filter_map(|p| {
            let (k, rest) = p.split_once('(')?;
            let l = rest.strip_suffix(')')?;
            (!k.is_empty() && k.bytes().all(|c| c.is_ascii_uppercase()) && !l.contains('('))
                .then(|| (k.to_string(), l.to_string()))
        })
        .collect()
}

/// A plain decimal number as DMIS writes it — an optional sign, digits, at most one
/// point — and finite: not `nan`, `inf`, an exponent or a number past `f64`.
pub(super) fn decimal(s: &str) -> Option<f64> {
    let body = s.strip_prefix(['-', '+']).unwrap_or(s);
    let digits = body.bytes().filter(u8::is_ascii_digit).count();
    let points = body.bytes().filter(|&c| c == b'.').count();
    if digits == 0 || points > 1 || digits + points != body.len() {
        return None;
    }
    s.parse::<f64>().ok().filter(|x| x.is_finite())
}

/// The label a `DATDEF` defines: its last parameter, `DAT(x)`.
fn datdef_label(params: &[String]) -> Option<String> {
    let (k, l) = refs(params.last().map(std::slice::from_ref)?).pop()?;
    (k == "DAT").then_some(l)
}

/// Every check, in text order.
pub(super) fn check(
    statements: &[Statement],
    span: &dyn Fn(usize) -> Span,
    errors: &mut Vec<DmisError>,
    warnings: &mut Vec<DmisError>,
) {
    let commands: Vec<Cmd> = statements.iter().filter_map(Statement::command).collect();
    let results_file = matches!(commands.first(), Some((_, "FILNAM", _, _)));
    first_and_last(&commands, span, errors);
    let defined = definitions(&commands, span, errors);
    let mut walk = Walk {
        span,
        errors,
        measured: BTreeSet::new(),
        saved: BTreeSet::new(),
        meas: None,
        blocks: Vec::new(),
    };
    for (label, major, params, at) in &commands {
        let at = *at;
        warnings.extend(not_run(major, at, span));
        if *major == "DATDEF" {
            if let Some(("DAT", d)) = label.as_ref().map(|(k, l)| (k.as_str(), l)) {
                walk.errors.push(DmisError::DatdefForm {
                    span: span(at),
                    datum: d.clone(),
                    feature: params.first().cloned().unwrap_or_default(),
                });
            }
        }
        if !results_file {
            undefined(
                major,
                params,
                at,
                &defined,
                &walk.measured,
                &walk.saved,
                span,
                walk.errors,
            );
        }
        if *major == "SAVE" {
            for (k, l) in refs(params) {
                if k == "DA" {
                    walk.saved.insert(l);
                }
            }
        }
        walk.nesting(major, at);
        walk.measurement(major, params, at);
        if matches!(*major, "GOTO" | "PTMEAS") && !numbers_or_words(params) {
            walk.errors.push(structure(
                span,
                at,
                &format!("{major} with a parameter that is not a number"),
                "coordinates are plain decimal numbers",
            ));
        }
    }
    walk.unclosed();
}

/// A structural error at `at`.
fn structure(span: &dyn Fn(usize) -> Span, at: usize, what: &str, help: &str) -> DmisError {
    DmisError::Structure {
        span: span(at),
        what: what.into(),
        help: help.into(),
    }
}

/// The program's first statement names it (`DMISMN`, `DMISMD`, or `FILNAM` for a
/// results file) and its last is `ENDFIL`.
fn first_and_last(commands: &[Cmd], span: &dyn Fn(usize) -> Span, errors: &mut Vec<DmisError>) {
    match commands.first() {
        Some((_, "DMISMN" | "DMISMD" | "FILNAM", _, _)) => {}
        Some((_, _, _, at)) => errors.push(structure(
            span,
            *at,
            "the program does not start with DMISMN",
            "start a program with `DMISMN/'name',05.3` (a module with DMISMD)",
        )),
        None => errors.push(structure(
            span,
            0,
            "the program is empty",
            "start with `DMISMN/'name',05.3` and end with `ENDFIL`",
        )),
    }
    // ENDFIL ends the input file (ANSI/DMIS 105.2, ENDFIL): statements after an early one
    // are no part of the program, and a controller that ran them would run another one.
    let early = commands.iter().rev().skip(1).rfind(|c| c.1 == "ENDFIL");
    if let Some((_, _, _, at)) = early {
        errors.push(structure(
            span,
            *at,
            "statements follow ENDFIL",
            "ENDFIL ends the program: remove it, or the statements after it",
        ));
    }
    if let Some((_, m, _, at)) = commands.last() {
        if *m != "ENDFIL" {
            errors.push(structure(
                span,
                *at,
                "the program does not end with ENDFIL",
                "end the program with `ENDFIL`",
            ));
        }
    }
}

/// The warning for a statement inspc reads but does not run, a vendor's extension,
/// or a word that is not DMIS.
fn not_run(major: &str, at: usize, span: &dyn Fn(usize) -> Span) -> Option<DmisError> {
    match word(major) {
        Word::Runs => None,
        Word::Reads => Some(DmisError::NotRun {
            span: span(at),
            major: major.to_string(),
        }),
        Word::Vendor(what) => Some(DmisError::VendorExtension {
            span: span(at),
            major: major.to_string(),
            what: what.to_string(),
        }),
        Word::Unknown => Some(DmisError::UnknownStatement {
            span: span(at),
            major: major.to_string(),
        }),
    }
}

/// What the checks carry from statement to statement.
struct Walk<'w> {
    span: &'w dyn Fn(usize) -> Span,
    errors: &'w mut Vec<DmisError>,
    /// The features measured or constructed so far (`FA(x)` usable).
    measured: BTreeSet<String>,
    /// The alignments saved so far (`DA(x)` usable).
    saved: BTreeSet<String>,
    /// The open `MEAS` block: where, the points it announces, the touches so far.
    meas: Option<(usize, Option<usize>, usize)>,
    /// The open blocks: the word that closes each, and where it opened.
    blocks: Vec<(&'static str, usize)>,
}

impl Walk<'_> {
    fn structure(&mut self, at: usize, what: &str, help: &str) {
        self.errors.push(structure(self.span, at, what, help));
    }

    /// Blocks (`IF`/`ENDIF`, `DO`/`ENDDO`, …) close in the order they opened.
    fn nesting(&mut self, major: &str, at: usize) {
        if let Some(&(_, close)) = BLOCKS.iter().find(|(open, _)| *open == major) {
            // `IF` opens a block only in its block form: `IF/(expr)` alone.
            self.blocks.push((close, at));
        } else if BLOCKS.iter().any(|(_, close)| *close == major) {
            match self.blocks.pop() {
                Some((close, _)) if close == major => {}
                Some((close, open_at)) => {
                    self.structure(
                        at,
                        &format!("{major} closes a block that {close} should close"),
                        "close blocks in the order they were opened",
                    );
                    self.blocks.push((close, open_at));
                }
                None => self.structure(
                    at,
                    &format!("{major} without the statement that opens its block"),
                    "remove it or open the block",
                ),
            }
        }
    }

    /// `MEAS` blocks: opened once, holding only moves and touches, as many touches as
    /// they announce; what `MEAS` and `CONST` make measured.
    fn measurement(&mut self, major: &str, params: &[String], at: usize) {
        match (major, &mut self.meas) {
            ("MEAS" | "RMEAS", None) => {
                let n = params.last().and_then(|n| n.parse::<usize>().ok());
                if n.is_none() {
                    self.structure(
                        at,
                        "MEAS without a point count",
                        "write `MEAS/type,F(label),n`",
                    );
                }
                self.meas = Some((at, n, 0));
                if let Some((_, l)) = refs(params).first() {
                    self.measured.insert(l.clone());
                }
            }
            ("CONST", None) => {
                // A constructed feature is measured once its sources are.
                if let Some((_, l)) = refs(params).first() {
                    self.measured.insert(l.clone());
                }
            }
            ("MEAS" | "RMEAS", Some(_)) => self.structure(
                at,
                "MEAS inside a MEAS block",
                "close the block with ENDMES first",
            ),
            ("PTMEAS", Some(m)) => m.2 = m.2.saturating_add(1),
            // A block that scans announces the cloud's size, which DMIS leaves to the
            // machine: its count is not checked.
            ("PAMEAS", Some(m)) => m.2 = usize::MAX,
            ("PAMEAS", None) => self.structure(
                at,
                "PAMEAS outside a MEAS block",
                "put scan passes between MEAS and ENDMES",
            ),
            ("ENDMES", Some((start, n, got))) => {
                if let Some(n) = *n {
                    if *got != usize::MAX && n != *got {
                        let (start, got) = (*start, *got);
                        self.structure(
                            start,
                            &format!("MEAS announces {n} points but takes {got}"),
                            "make the count match the PTMEAS statements",
                        );
                    }
                }
                self.meas = None;
            }
            ("ENDMES", None) => {
                self.structure(at, "ENDMES without MEAS", "open the block with MEAS")
            }
            (m, Some(_)) if !IN_MEAS.contains(&m) => self.structure(
                at,
                &format!("{m} inside a MEAS block"),
                "only moves (GOTO) and touches (PTMEAS, PAMEAS) belong between MEAS and ENDMES",
            ),
            ("PTMEAS", None) => self.structure(
                at,
                "PTMEAS outside a MEAS block",
                "put touches between MEAS and ENDMES",
            ),
            _ => {}
        }
    }

    /// At the program's end: a `MEAS` block and any other block left open.
    fn unclosed(self) {
        if let Some((at, _, _)) = self.meas {
            self.errors.push(structure(
                self.span,
                at,
                "MEAS block without ENDMES",
                "close the block with ENDMES",
            ));
        }
        for (close, at) in self.blocks {
            self.errors.push(structure(
                self.span,
                at,
                &format!("a block that is never closed with {close}"),
                &format!("close it with {close}"),
            ));
        }
    }
}

/// A move's or touch's parameters: numbers, after a leading keyword (`CART`, `POL`,
/// `INCR`) or with a variable (`V(x)`, which the controller evaluates).
fn numbers_or_words(params: &[String]) -> bool {
    params.iter().enumerate().all(|(k, p)| {
        decimal(p).is_some()
            || (k == 0 && matches!(p.as_str(), "CART" | "POL" | "INCR"))
            || refs(std::slice::from_ref(p))
                .first()
                .is_some_and(|(k, _)| k == "V")
    })
}

/// Every label defined anywhere in the program (a tolerance may name a datum defined
/// later), with errors for illegal and twice-defined ones.
fn definitions(
    commands: &[Cmd],
    span: &dyn Fn(usize) -> Span,
    errors: &mut Vec<DmisError>,
) -> BTreeMap<(String, String), usize> {
    let mut defined: BTreeMap<(String, String), usize> = BTreeMap::new();
    defined.insert(("D".into(), "MCS".into()), 0);
    for (label, major, params, at) in commands {
        let key = match (label, *major) {
            (Some((k, l)), _) => (k.clone(), l.clone()),
            (None, "DATDEF") => match datdef_label(params) {
                Some(l) => ("DAT".to_string(), l),
                None => {
                    errors.push(DmisError::Structure {
                        span: span(*at),
                        what: "DATDEF without the datum it defines".into(),
                        help: "write `DATDEF/FA(feature),DAT(letter)`".into(),
                    });
                    continue;
                }
            },
            _ => continue,
        };
        if !is_label(&key.1) {
            errors.push(DmisError::BadLabel {
                span: span(*at),
                label: key.1.clone(),
            });
        }
        if defined.contains_key(&key) && ONCE.contains(&key.0.as_str()) {
            errors.push(DmisError::Duplicate {
                span: span(*at),
                kind: key.0.clone(),
                label: key.1.clone(),
            });
        }
        defined.entry(key).or_insert(*at);
    }
    defined
}

/// Names a statement uses that nothing defines (or, for `FA`, nothing measured yet).
#[allow(clippy::too_many_arguments)]
fn undefined(
    major: &str,
    params: &[String],
    at: usize,
    defined: &BTreeMap<(String, String), usize>,
    measured: &BTreeSet<String>,
    saved: &BTreeSet<String>,
    span: &dyn Fn(usize) -> Span,
    errors: &mut Vec<DmisError>,
) {
    let mut uses = refs(params);
    if major == "DATDEF" {
        uses.pop();
    }
    for (k, l) in uses {
        let ok = match k.as_str() {
            "F" => defined.contains_key(&("F".into(), l.clone())),
            "FA" => measured.contains(&l) && defined.contains_key(&("F".into(), l.clone())),
            "S" | "SA" => defined.contains_key(&("S".into(), l.clone())),
            "T" | "TA" => defined.contains_key(&("T".into(), l.clone())),
            "DAT" | "D" | "DID" => defined.contains_key(&(k.clone(), l.clone())),
            "DA" => major == "SAVE" || saved.contains(&l),
            _ => true,
        };
        if !ok {
            errors.push(DmisError::Undefined {
                span: span(at),
                kind: k,
                label: l,
            });
        }
    }
}
