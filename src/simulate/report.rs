//! The virtual CMM's report: per tolerance the program outputs, its nominal, actual,
//! deviation and verdict — as text for people, JSON for tools, and DMIS output
//! statements (`TA(label)=TOL/…,INTOL|OUTOL`) as a controller's results file has them.

use super::evaluate::Outcome;
use crate::dmis::text::num;
use serde_json::json;

/// One `OUTPUT` of a tolerance judged.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The tolerance's label.
    pub tolerance: String,
    /// Its DMIS word.
    pub kind: String,
    /// The features output, by label.
    pub features: Vec<String>,
    /// Its datums' labels.
    pub datums: Vec<String>,
    /// What it measured.
    pub outcome: Outcome,
}

impl Row {
    /// Judged and within its limits.
    pub fn pass(&self) -> bool {
        self.outcome.actual.is_finite() && self.outcome.pass()
    }

    /// Not judged: the virtual CMM could not evaluate it.
    pub fn unjudged(&self) -> bool {
        !self.outcome.actual.is_finite()
    }
}

/// A run of the virtual CMM.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// The program's name.
    pub program: String,
    /// The plan and part.
    pub plan: String,
    /// The part.
    pub part: String,
    /// Setups run.
    pub setups: usize,
    /// Touches and moves made.
    pub touches: usize,
    /// Points the scan passes kept.
    pub scanned: usize,
    /// Moves checked.
    pub moves: usize,
    /// The noise (mm) and its seed.
    pub noise: f64,
    /// The seed.
    pub seed: u64,
    /// Every tolerance output, in program order.
    pub rows: Vec<Row>,
}

/// Four decimals, like the program's numbers (a micrometre is 0.001).
fn val(x: f64) -> String {
    if x.is_finite() {
        num((x * 1e4).round() / 1e4)
    } else {
        "-".into()
    }
}

impl Report {
    /// Tolerances out of their limits.
    pub fn failed(&self) -> usize {
        self.rows
            .iter()
            .filter(|r| !r.unjudged() && !r.pass())
            .count()
    }

    /// Tolerances the virtual CMM could not judge.
    pub fn unjudged(&self) -> usize {
        self.rows.iter().filter(|r| r.unjudged()).count()
    }

    /// The report for people.
    pub fn text(&self) -> String {
        let mut out = format!(
            "simulated program {} (plan {}, part {}): {} setups, {} touches{}, {} moves checked{}\n",
            self.program,
            self.plan,
            self.part,
            self.setups,
            self.touches,
            if self.scanned > 0 {
                format!(", {} points scanned", self.scanned)
            } else {
                String::new()
            },
            self.moves,
            if self.noise > 0.0 {
                format!(", noise {} mm (seed {})", num(self.noise), self.seed)
            } else {
                String::new()
            }
        );
        let rows: Vec<[String; 7]> = self
            .rows
            .iter()
            .map(|r| {
                let o = &r.outcome;
                let limits = if o.nominal == 0.0 && o.limits.0 == 0.0 {
                    val(o.limits.1)
                } else {
                    format!("{}/+{}", val(o.limits.0), val(o.limits.1)).replace("+-", "-")
                };
                let verdict = if r.unjudged() {
                    "n/a"
                } else if r.pass() {
                    "in"
                } else {
                    "OUT"
                };
                [
                    r.tolerance.clone(),
                    r.kind.clone(),
                    r.features.join(","),
                    val(o.nominal),
                    val(o.actual),
                    limits,
                    match &o.note {
                        Some(n) => format!("{verdict}  ({n})"),
                        None => verdict.to_string(),
                    },
                ]
            })
            .collect();
        let head = [
            "TOLERANCE",
            "TYPE",
            "FEATURES",
            "NOMINAL",
            "ACTUAL",
            "LIMITS",
            "RESULT",
        ];
        let mut w = head.map(str::len);
        for r in &rows {
            for k in 0..6 {
                w[k] = w[k].max(r[k].len());
            }
        }
        let line = |c: &[String; 7]| {
            let mut s = String::new();
            for k in 0..6 {
                s.push_str(&format!("{:<1$}  ", c[k], w[k]));
            }
            s.push_str(&c[6]);
            s.trim_end().to_string() + "\n"
        };
        out.push_str(&line(&head.map(String::from)));
        for r in &rows {
            out.push_str(&line(r));
        }
        let n = self.rows.len();
        out.push_str(&format!(
            "{} tolerance outputs: {} in, {} out{}\n",
            n,
            n - self.failed() - self.unjudged(),
            self.failed(),
            if self.unjudged() > 0 {
                format!(", {} not judged", self.unjudged())
            } else {
                String::new()
            }
        ));
        out
    }

    /// The report as JSON.
    pub fn json(&self) -> serde_json::Value {
        let f = |x: f64| {
            if x.is_finite() {
                json!((x * 1e6).round() / 1e6)
            } else {
                json!(null)
            }
        };
        json!({
            "program": self.program,
            "plan": self.plan,
            "part": self.part,
            "setups": self.setups,
            "touches": self.touches,
            "scanned": self.scanned,
            "moves": self.moves,
            "noise": self.noise,
            "seed": self.seed,
            "in": self.rows.len() - self.failed() - self.unjudged(),
            "out": self.failed(),
            "not_judged": self.unjudged(),
            "tolerances": self.rows.iter().map(|r| {
                let o = &r.outcome;
                json!({
                    "tolerance": r.tolerance,
                    "type": r.kind,
                    "features": r.features,
                    "datums": r.datums,
                    "nominal": f(o.nominal),
                    "actual": f(o.actual),
                    "deviation": f(o.deviation()),
                    "lower": f(o.limits.0),
                    "upper": f(o.limits.1),
                    "result": if r.unjudged() { "not judged" } else if r.pass() { "in" } else { "out" },
                    "note": o.note,
                })
            }).collect::<Vec<_>>(),
        })
    }

    /// The results as DMIS output statements, one `TA` per tolerance output.
    pub fn dmis(&self) -> String {
        let mut out = format!(
            "DMISMN/'{}',05.3\n",
            crate::dmis::text::plain(&self.program, 60)
        );
        for r in &self.rows {
            let o = &r.outcome;
            let verdict = if r.unjudged() {
                continue;
            } else if r.pass() {
                "INTOL"
            } else {
                "OUTOL"
            };
            let fa: Vec<String> = r.features.iter().map(|l| format!("FA({l})")).collect();
            let stmt = format!(
                "TA({})=TOL/{},{},{},{verdict}",
                r.tolerance,
                r.kind,
                val(o.actual),
                val(o.deviation()),
            );
            for line in
                crate::dmis::text::wrap(&format!("OUTPUT/{},TA({})", fa.join(","), r.tolerance))
            {
                out.push_str(&line);
                out.push('\n');
            }
            for line in crate::dmis::text::wrap(&stmt) {
                out.push_str(&line);
                out.push('\n');
            }
        }
        out.push_str("ENDFIL\n");
        out
    }
}
