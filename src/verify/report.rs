//! The battery's results, judged, as text for people and JSON for tools.

use super::{Options, IN_AT, OUT_AT};
use crate::model::{fmt_num, TolKind, TolValue, Tolerance};
use crate::simulate::Report;
use serde_json::json;

/// One run of the program.
#[derive(Debug, Clone)]
pub struct Tried {
    /// Its report, when it ran to its end.
    pub report: Option<Report>,
    /// Why it stopped, when it did.
    pub stopped: Option<String>,
    /// The virtual part cannot take the deviation (a size change on faces that have no
    /// size to grow): not tried, and no fault of the program.
    pub rejected: Option<String>,
}

/// One placement tried.
#[derive(Debug, Clone)]
pub struct Placed {
    /// Its deviations file.
    pub lines: Vec<String>,
    /// Why it stopped, when it did.
    pub stopped: Option<String>,
    /// Tolerances whose verdict differs from nominal's, by label.
    pub changed: Vec<String>,
    /// The largest change of any tolerance's actual from nominal's (mm).
    pub drift: f64,
}

impl Placed {
    /// Compares a placement's run with the nominal run, row by row.
    pub fn judge(lines: Vec<String>, tried: Tried, nominal: &Tried) -> Placed {
        let mut changed = Vec::new();
        let mut drift = 0.0f64;
        if let (Some(r), Some(n)) = (&tried.report, &nominal.report) {
            for (a, b) in r.rows.iter().zip(&n.rows) {
                if a.pass() != b.pass() && !changed.contains(&a.tolerance) {
                    changed.push(a.tolerance.clone());
                }
                let d = (a.outcome.actual - b.outcome.actual).abs();
                if d.is_finite() {
                    drift = drift.max(d);
                }
            }
        }
        Placed {
            lines,
            stopped: tried.stopped,
            changed,
            drift,
        }
    }

    fn ok(&self) -> bool {
        self.stopped.is_none() && self.changed.is_empty()
    }
}

/// One way of breaking a tolerance, tried at both factors.
#[derive(Debug, Clone)]
pub struct VariantResult {
    /// In words.
    pub what: String,
    /// What the tolerance reads at factor 1 (see [`super::trials::Variant::unit`]).
    pub unit: f64,
    /// At [`IN_AT`]: the deviations, the run, what the tolerance read.
    pub at_in: Option<(Vec<String>, Tried, Option<Reading>)>,
    /// At [`OUT_AT`].
    pub at_out: Option<(Vec<String>, Tried, Option<Reading>)>,
}

/// What a tolerance read in one run: its value, and whether every output was in.
#[derive(Debug, Clone, Copy)]
pub struct Reading {
    /// The zone's width, or a size's deviation (the one farthest from nominal).
    pub value: f64,
    /// Every output of it judged and in.
    pub pass: bool,
}

impl VariantResult {
    pub fn new(what: String, unit: f64) -> VariantResult {
        VariantResult {
            what,
            unit,
            at_in: None,
            at_out: None,
        }
    }

    fn read(at: &Option<(Vec<String>, Tried, Option<Reading>)>) -> Option<Reading> {
        at.as_ref().and_then(|x| x.2)
    }

    /// Read in at half the zone.
    fn in_ok(&self) -> bool {
        Self::read(&self.at_in).is_some_and(|r| r.pass)
    }

    /// Read out at twice the zone.
    fn out_ok(&self) -> bool {
        Self::read(&self.at_out).is_some_and(|r| !r.pass)
    }

    /// The factor of the zone from which the program reads this deviation out, by
    /// linear interpolation between the two readings; infinite when the reading does
    /// not grow.
    pub(crate) fn detects_from(&self) -> f64 {
        let (Some(a), Some(b)) = (Self::read(&self.at_in), Self::read(&self.at_out)) else {
            return f64::INFINITY;
        };
        // By magnitude: a turn or a move may read on either side of nominal.
        let (fa, fb) = ((a.value / self.unit).abs(), (b.value / self.unit).abs());
        if fb - fa > 1e-9 {
            IN_AT + (OUT_AT - IN_AT) * (1.0 - fa) / (fb - fa)
        } else {
            f64::INFINITY
        }
    }
}

/// One tolerance's trials.
#[derive(Debug, Clone)]
pub struct TolResult {
    /// Its index in the part.
    pub index: usize,
    /// Its DMIS label.
    pub label: String,
    /// Its unit zone's label, where it has one besides the whole feature's.
    pub unit_label: Option<String>,
    /// Its zone per unit as a drawing writes it (`0.02/25×25`).
    pub per_unit: Option<String>,
    /// Its type, as DMIS names it.
    pub kind: TolKind,
    /// Its value, as written.
    pub value: String,
    /// Size (not zone).
    pub size: bool,
    /// The zone judged at nominal (with any bonus).
    pub zone: f64,
    /// The program outputs it.
    pub output: bool,
    /// Ways of breaking it.
    pub variants: Vec<VariantResult>,
    /// Sizes at their limits: (what, deviations, the run).
    pub limits: Vec<(String, Vec<String>, Option<Tried>)>,
}

impl TolResult {
    pub fn new(
        index: usize,
        (label, unit_label): (String, Option<String>),
        t: &Tolerance,
        zone: f64,
        output: bool,
    ) -> TolResult {
        let per_unit = t
            .per_unit
            .as_ref()
            .map(|p| format!("{}/{}", crate::model::fmt_num(p.zone), p.unit.text()));
        TolResult {
            index,
            label,
            unit_label,
            per_unit,
            kind: t.kind,
            value: t.value.text(),
            size: matches!(t.value, TolValue::Size { .. }),
            zone,
            output,
            variants: Vec::new(),
            limits: Vec::new(),
        }
    }

    /// What this tolerance read in a run.
    pub(crate) fn reading(&self, tried: &Tried) -> Option<Reading> {
        let rows: Vec<_> = tried.rows().filter(|r| self.reads(&r.tolerance)).collect();
        if rows.is_empty() {
            return None;
        }
        let value = if self.size {
            rows.iter()
                .map(|r| r.outcome.deviation())
                .max_by(|a, b| a.abs().total_cmp(&b.abs()))
                .unwrap_or(0.0)
        } else {
            rows.iter().map(|r| r.outcome.actual).fold(0.0, f64::max)
        };
        Some(Reading {
            value,
            pass: rows.iter().all(|r| r.pass()),
        })
    }

    /// Whether a results row of label `tolerance` is this tolerance's: its own or its
    /// unit zone's.
    pub(crate) fn reads(&self, tolerance: &str) -> bool {
        tolerance == self.label || self.unit_label.as_deref() == Some(tolerance)
    }

    /// Tried, and every trial as it should be.
    fn ok(&self) -> bool {
        self.output
            && self.variants.iter().all(|v| v.in_ok() && v.out_ok())
            && self
                .limits
                .iter()
                .all(|l| l.2.as_ref().is_some_and(|t| t.stopped.is_none()))
    }

    /// Drops the trials the virtual part could not take.
    pub(crate) fn drop_rejected(&mut self) {
        let rejected = |t: &Option<(Vec<String>, Tried, Option<Reading>)>| {
            t.as_ref().is_some_and(|x| x.1.rejected.is_some())
        };
        self.variants
            .retain(|v| !rejected(&v.at_in) && !rejected(&v.at_out));
        self.limits
            .retain(|l| l.2.as_ref().is_none_or(|t| t.rejected.is_none()));
    }

    /// The worst factor any of its deviations is detected from.
    fn detects_from(&self) -> f64 {
        self.variants
            .iter()
            .map(VariantResult::detects_from)
            .fold(0.0, f64::max)
    }
}

/// The battery's results.
#[derive(Debug, Clone)]
pub struct Verification {
    /// The plan the program carries.
    pub plan: String,
    /// The part.
    pub part: String,
    /// How hard it tried.
    pub options: Options,
    /// The nominal run.
    pub nominal: Tried,
    /// The placements.
    pub placed: Vec<Placed>,
    /// Per tolerance of the part.
    pub tolerances: Vec<TolResult>,
}

impl Verification {
    /// Problems found: a nominal part read out or stopped, a placement that changed a
    /// verdict or stopped, a deviation not seen or seen where it should not be, a size
    /// limit that collides. Tolerances the program does not output, and those no
    /// deviation of the virtual part can break, are listed but are no problem here.
    pub fn problems(&self) -> usize {
        let nominal = match &self.nominal.report {
            None => 1,
            Some(r) => r.rows.iter().filter(|r| !r.pass()).count(),
        };
        nominal
            + self.placed.iter().filter(|p| !p.ok()).count()
            + self
                .tolerances
                .iter()
                .filter(|t| t.output && !t.variants.is_empty() || !t.limits.is_empty())
                .filter(|t| !t.ok())
                .count()
    }

    /// The report for people.
    pub fn text(&self) -> String {
        let mut s = String::new();
        s += &format!("verify plan {} (part {})\n", self.plan, self.part);
        match &self.nominal.report {
            None => {
                s += &format!(
                    "nominal: stopped: {}\n",
                    self.nominal.stopped.as_deref().unwrap_or("")
                );
                return s;
            }
            Some(r) => s += &nominal_line(r),
        }
        s += &self.placements_line();
        s += "\n";
        let rows: Vec<[String; 8]> = self.tolerances.iter().map(tolerance_row).collect();
        s += &table(&rows);
        let problems = self.problem_lines();
        if !problems.is_empty() {
            s += "\nproblems (each with the deviations that rerun it):\n";
            for p in &problems {
                s += &format!("  {p}\n");
            }
        }
        let judged = self
            .tolerances
            .iter()
            .filter(|t| t.output && !(t.variants.is_empty() && t.limits.is_empty()))
            .count();
        let ok = self
            .tolerances
            .iter()
            .filter(|t| t.output && !(t.variants.is_empty() && t.limits.is_empty()) && t.ok())
            .count();
        s += &format!(
            "\n{ok} of {judged} tolerances tried read their forbidden deviations right; {} problems\n",
            self.problems()
        );
        s
    }

    /// The placements' line: how many were tried within what, how many stopped or
    /// changed a verdict, and the largest change of an actual.
    fn placements_line(&self) -> String {
        let o = &self.options;
        let stopped = self.placed.iter().filter(|p| p.stopped.is_some()).count();
        let changed = self.placed.iter().filter(|p| !p.changed.is_empty()).count();
        let drift = self
            .placed
            .iter()
            .filter(|p| p.stopped.is_none())
            .map(|p| p.drift)
            .fold(0.0, f64::max);
        format!(
            "placements: {} within ±{} mm and ±{}°: {} stopped, {} changed a verdict; largest change of an actual {} mm\n",
            self.placed.len(),
            fmt_num(o.shift),
            fmt_num(o.turn),
            stopped,
            changed,
            fmt_num(round(drift))
        )
    }

    /// Each problem in a line, with the deviations that reproduce it.
    fn problem_lines(&self) -> Vec<String> {
        let mut out = Vec::new();
        let dev = |lines: &[String]| lines.join("; ");
        if let Some(r) = &self.nominal.report {
            for row in r.rows.iter().filter(|r| !r.pass()) {
                out.push(format!(
                    "{} reads {} on the nominal part",
                    row.tolerance,
                    if row.unjudged() { "nothing" } else { "out" }
                ));
            }
        }
        for p in &self.placed {
            if let Some(why) = &p.stopped {
                out.push(format!("placement [{}]: stopped: {why}", dev(&p.lines)));
            } else if !p.changed.is_empty() {
                out.push(format!(
                    "placement [{}]: verdict changed for {}",
                    dev(&p.lines),
                    p.changed.join(", ")
                ));
            }
        }
        for t in &self.tolerances {
            for v in &t.variants {
                for (at, want_pass, factor) in [(&v.at_in, true, IN_AT), (&v.at_out, false, OUT_AT)]
                {
                    let Some((lines, tried, reading)) = at else {
                        continue;
                    };
                    let what = format!("{} {} at {}x [{}]", t.label, v.what, factor, dev(lines));
                    match (reading, &tried.stopped) {
                        (_, Some(why)) => out.push(format!("{what}: stopped: {why}")),
                        (None, None) => out.push(format!("{what}: not output")),
                        (Some(r), None) if r.pass != want_pass => out.push(format!(
                            "{what}: reads {} ({}, limit {})",
                            if r.pass { "in" } else { "out" },
                            fmt_num(round(r.value)),
                            fmt_num(round(v.unit.abs()))
                        )),
                        _ => {}
                    }
                }
            }
            for (what, lines, tried) in &t.limits {
                if let Some(why) = tried.as_ref().and_then(|t| t.stopped.as_ref()) {
                    out.push(format!(
                        "{} {what} [{}]: stopped: {why}",
                        t.label,
                        dev(lines)
                    ));
                }
            }
        }
        out
    }

    /// The report for tools.
    pub fn json(&self) -> serde_json::Value {
        let tried = |t: &Tried| {
            json!({
                "stopped": t.stopped,
                "finished": t.report.is_some(),
            })
        };
        json!({
            "plan": self.plan,
            "part": self.part,
            "placements": {
                "shift_mm": self.options.shift,
                "turn_deg": self.options.turn,
                "runs": self.placed.iter().map(|p| json!({
                    "deviations": p.lines,
                    "stopped": p.stopped,
                    "changed": p.changed,
                    "drift_mm": p.drift,
                })).collect::<Vec<_>>(),
            },
            "nominal": tried(&self.nominal),
            "tolerances": self.tolerances.iter().map(|t| json!({
                "label": t.label,
                "type": crate::dmis::tol_word(t.kind),
                "value": t.value,
                "per_unit": t.per_unit,
                "zone": t.zone,
                "output": t.output,
                "ok": t.ok(),
                "detected_from": finite(t.detects_from()),
                "variants": t.variants.iter().map(|v| json!({
                    "what": v.what,
                    "in_at_half": v.in_ok(),
                    "out_at_twice": v.out_ok(),
                    "detected_from": finite(v.detects_from()),
                })).collect::<Vec<_>>(),
                "size_limits": t.limits.iter().map(|(what, lines, r)| json!({
                    "what": what,
                    "deviations": lines,
                    "stopped": r.as_ref().and_then(|r| r.stopped.clone()),
                })).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
            "problems": self.problems(),
        })
    }
}

/// The nominal run's line: its setups and touches, the tolerances it outputs, those
/// read out on the nominal part and those not judged.
fn nominal_line(r: &Report) -> String {
    let mut out: Vec<&str> = r
        .rows
        .iter()
        .filter(|r| !r.pass() && !r.unjudged())
        .map(|r| r.tolerance.as_str())
        .collect();
    out.dedup();
    let unjudged = r.rows.iter().filter(|r| r.unjudged()).count();
    format!(
        "nominal: {} setups, {} touches, {} tolerance outputs, {} read out{}, {} not judged\n",
        r.setups,
        r.touches,
        r.rows.len(),
        out.len(),
        if out.is_empty() {
            String::new()
        } else {
            format!(" ({})", out.join(", "))
        },
        unjudged
    )
}

/// A tolerance's row of the table: label, kind, zone (or size), the verdicts inside
/// and outside the zone, the factor it detects from, the size limits' collisions, and
/// the result.
fn tolerance_row(t: &TolResult) -> [String; 8] {
    let verdicts = |f: &dyn Fn(&VariantResult) -> bool, word: [&str; 2]| {
        if t.variants.is_empty() {
            "-".to_string()
        } else {
            let bad = t.variants.iter().filter(|v| !f(v)).count();
            if bad == 0 {
                word[0].to_string()
            } else {
                format!("{bad} of {} {}", t.variants.len(), word[1])
            }
        }
    };
    let result = if !t.output {
        "not output"
    } else if t.variants.is_empty() && t.limits.is_empty() {
        "not tried"
    } else if t.ok() {
        "ok"
    } else {
        "PROBLEM"
    };
    let from = t.detects_from();
    [
        t.label.clone(),
        crate::dmis::tol_word(t.kind).to_string(),
        if t.size {
            t.value.clone()
        } else {
            match (&t.per_unit, t.unit_label.is_some()) {
                // The unit zone alone is the tolerance's zone.
                (Some(unit), false) => unit.clone(),
                (Some(unit), true) => format!("{}, {unit}", fmt_num(round(t.zone))),
                (None, _) => fmt_num(round(t.zone)),
            }
        },
        verdicts(&|v| v.in_ok(), ["in", "out"]),
        verdicts(&|v| v.out_ok(), ["out", "in"]),
        if t.variants.is_empty() {
            "-".into()
        } else if from.is_finite() {
            format!("{:.2}x", from)
        } else {
            "never".into()
        },
        if t.limits.is_empty() {
            "-".into()
        } else {
            let hit = t
                .limits
                .iter()
                .filter(|l| l.2.as_ref().is_none_or(|r| r.stopped.is_some()))
                .count();
            if hit == 0 {
                "clear".into()
            } else {
                format!("{hit} stopped")
            }
        },
        result.into(),
    ]
}

/// A number, or null when it is infinite.
fn finite(x: f64) -> serde_json::Value {
    if x.is_finite() {
        json!(x)
    } else {
        serde_json::Value::Null
    }
}

/// To a tenth of a micrometre.
fn round(x: f64) -> f64 {
    (x * 1e4).round() / 1e4
}

/// Columns padded to their widest cell, two blanks apart.
fn table(rows: &[[String; 8]]) -> String {
    let head = [
        "TOLERANCE",
        "TYPE",
        "ZONE",
        "AT 0.5x",
        "AT 2x",
        "DETECTED FROM",
        "SIZE LIMITS",
        "RESULT",
    ];
    let mut width = head.map(|h| h.chars().count());
    for r in rows {
        for (k, c) in r.iter().enumerate() {
            width[k] = width[k].max(c.chars().count());
        }
    }
    let line = |cells: Vec<&str>| {
        let mut l: String = cells
            .iter()
            .enumerate()
            .map(|(k, c)| format!("{c:<w$}", w = width[k]))
            .collect::<Vec<_>>()
            .join("  ");
        l.truncate(l.trim_end().len());
        l + "\n"
    };
    let mut s = line(head.to_vec());
    for r in rows {
        s += &line(r.iter().map(String::as_str).collect());
    }
    s
}
