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
    /// Its zone's `2D`/`3D` (a position) and its material-condition words and datum
    /// references, as its `TOL` statement wrote them (`MMC`, `DAT(A)`, `DAT(B)`, `MMC`):
    /// what a results file repeats around the actual.
    pub words: Vec<String>,
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

/// One feature measured or constructed, as the program output it (`OUTPUT/FA(x)`) or
/// as the run left it: the nominal the program declared (`FEAT/…`) beside the actual.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureRow {
    /// The feature's DMIS label.
    pub label: String,
    /// Its DMIS feature word: `PLANE`, `CIRCLE`, `CYLNDR`, `CONE`, `SPHERE`, `POINT`,
    /// `PARPLN`, `PATERN`, `GSURF`.
    pub kind: String,
    /// `INNER` (a hole, a slot) rather than `OUTER` (a boss, a block).
    pub inner: bool,
    /// The nominal's numbers in the `FEAT` statement's order after `CART`: a location
    /// `x, y, z`, a direction `i, j, k`, then the size (diameter, width, or the full
    /// included angle in degrees for a cone) where the kind has one. Empty for `PATERN`
    /// and `GSURF`.
    pub nominal: Vec<f64>,
    /// The actual in the same layout, in the alignment current when it was output.
    pub actual: Vec<f64>,
    /// Form error of the fit (mm): the spread of the points about it, when the kind has
    /// one; `None` for a point or a pattern.
    pub form: Option<f64>,
    /// Points it was fitted to (touches, or scanned points kept).
    pub points: usize,
}

/// A run of the virtual CMM.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// The program's name.
    pub program: String,
    /// The name of its results (the program's `FILNAM`, else its name).
    pub filnam: String,
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
    /// Every feature measured or constructed, in the order it was first finished.
    pub features: Vec<FeatureRow>,
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
            "simulated program {} (plan {}, part {}): {} setup{}, {} touch{}{}, {} moves checked{}\n",
            self.program,
            self.plan,
            self.part,
            self.setups,
            if self.setups == 1 { "" } else { "s" },
            self.touches,
            if self.touches == 1 { "" } else { "es" },
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
        if !rows.is_empty() {
            out.push_str(&line(&head.map(String::from)));
        }
        for r in &rows {
            out.push_str(&line(r));
        }
        for f in &self.features {
            let nums: Vec<String> = f.actual.iter().map(|x| val(*x)).collect();
            out.push_str(&format!(
                "feature {} ({}{}): {}; {} points{}\n",
                f.label,
                f.kind,
                match f.kind.as_str() {
                    "PLANE" | "POINT" => "",
                    _ if f.inner => ", inner",
                    _ => ", outer",
                },
                if nums.is_empty() {
                    "-".to_string()
                } else {
                    nums.join(", ")
                },
                f.points,
                f.form
                    .map_or(String::new(), |e| format!(", form {}", val(e)))
            ));
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

    /// The results as a DMIS output file, in the form of NIST's `output.dms`: the
    /// program's `FILNAM` and units, then per feature output `OUTPUT/FA(x)` and its
    /// actual `FA(x)=FEAT/…`, per tolerance output `OUTPUT/FA(…),TA(t)` and
    /// `TA(t)=TOL/…,actual,INTOL|OUTOL`; tolerances not judged are comments.
    pub fn dmis(&self) -> String {
        use crate::dmis::text::{ascii, real, wrap};
        let mut out = String::new();
        let mut stmt = |s: &str| {
            if s.starts_with("$$") {
                out.push_str(s);
                out.push('\n');
                return;
            }
            for line in wrap(s) {
                out.push_str(&line);
                out.push('\n');
            }
        };
        stmt(&format!("FILNAM/'{}'", ascii(&self.filnam, 60)));
        stmt("UNITS/MM,ANGDEC");
        for f in &self.features {
            if f.actual.is_empty() {
                continue;
            }
            let side = match f.kind.as_str() {
                "PLANE" | "POINT" => String::new(),
                _ => format!("{},", if f.inner { "INNER" } else { "OUTER" }),
            };
            let nums: Vec<String> = f.actual.iter().map(|x| real(round4(*x))).collect();
            stmt(&format!("OUTPUT/FA({})", f.label));
            stmt(&format!(
                "FA({})=FEAT/{},{side}CART,{}",
                f.label,
                f.kind,
                nums.join(",")
            ));
        }
        for r in &self.rows {
            let fa: Vec<String> = r.features.iter().map(|l| format!("FA({l})")).collect();
            let o = &r.outcome;
            if r.unjudged() {
                stmt(&format!("$$ TA({}) NOT JUDGED", r.tolerance));
                continue;
            }
            let verdict = if r.pass() { "INTOL" } else { "OUTOL" };
            stmt(&format!("OUTPUT/{},TA({})", fa.join(","), r.tolerance));
            // The actual, then the verdict, then the zone's modifiers and datums: the
            // form the QIF community's DMIS bindings write (`TA(DIAM1)=TOL/DIAM,6.2,OUTOL`,
            // `TA(POSN2)=TOL/POS,3D,0.0618,INTOL,MMC,DAT(A),DAT(B),MMC,DAT(C),MMC`,
            // `bindings/Python/demoQIFin.py`).
            let (dims, rest): (Vec<&String>, Vec<&String>) =
                r.words.iter().partition(|w| *w == "2D" || *w == "3D");
            let mut params = vec![r.kind.clone()];
            params.extend(dims.into_iter().cloned());
            params.push(real(round4(o.actual)));
            params.push(verdict.to_string());
            params.extend(rest.into_iter().cloned());
            stmt(&format!("TA({})=TOL/{}", r.tolerance, params.join(",")));
        }
        stmt("ENDFIL");
        out
    }
}

/// To the 0.1 µm the program's numbers carry.
fn round4(x: f64) -> f64 {
    (x * 1e4).round() / 1e4
}
