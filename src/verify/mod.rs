//! `inspc verify`: whether a program can see what it claims to measure. The program runs
//! on the virtual CMM ([`crate::simulate`]) as a battery of trials:
//!
//! 1. **nominal** — the perfect part where the program expects it: every tolerance must
//!    read in;
//! 2. **placements** — the perfect part off by a random shift in x and y and a turn about
//!    the vertical (within `±shift` mm and `±turn`°, seeded): the run must finish without
//!    a collision and give every tolerance the verdict it gave at nominal;
//! 3. **forbidden deviations** — per tolerance, each deviation its zone forbids
//!    ([`trials`] says which and cites the zone definitions), at twice the zone (must read
//!    out) and at half of it (must read in). From the two readings, the factor of the zone
//!    from which the program reads the deviation out (linear between them);
//! 4. **size limits** — each size at its upper and its lower limit: the run must finish
//!    without a collision (a bore at its least material limit is where a stand-off meets
//!    the wall).
//!
//! Every trial is a deviations file; the report prints the lines of each trial that
//! failed, for `inspc simulate --deviations` to rerun. Trials run in parallel and their
//! results are collected in order: the report is the same on any number of threads.

mod report;
pub mod trials;

pub use report::Verification;

use crate::model::TolValue;
use crate::simulate::{self, Report};
use rayon::prelude::*;
use report::{Placed, TolResult, Tried};

/// What the battery runs against: a spec's part and one program of it, as the virtual
/// CMM takes them (its deviations are each trial's own).
pub struct Bench<'a> {
    /// The part (index into the model's parts).
    pub part: usize,
    /// The program on the nominal part.
    pub sim: simulate::Input<'a>,
}

/// How hard the battery tries.
#[derive(Debug, Clone, Copy)]
pub struct Options {
    /// Random placements tried.
    pub placements: usize,
    /// Largest shift in x and y (mm).
    pub shift: f64,
    /// Largest turn about the vertical (degrees).
    pub turn: f64,
}

impl Default for Options {
    /// The target: ±5 mm, ±3°, 20 placements.
    fn default() -> Self {
        Options {
            placements: 20,
            shift: 5.0,
            turn: 3.0,
        }
    }
}

/// The factors of the zone tried: the one that must read out, the one that must read in.
const OUT_AT: f64 = 2.0;
const IN_AT: f64 = 0.5;

/// Runs the battery.
pub fn verify(bench: &Bench, opts: &Options) -> Verification {
    let part = &bench.sim.model.parts[bench.part];
    let nominal = run(bench, &[]);
    let labels = crate::dmis::tolerance_labels(part);
    // The placements.
    let placements: Vec<Vec<String>> = (0..opts.placements)
        .map(|i| placement(i as u64, opts))
        .collect();
    let placed: Vec<Tried> = placements.par_iter().map(|l| run(bench, l)).collect();
    let placed: Vec<Placed> = placements
        .into_iter()
        .zip(placed)
        .map(|(lines, tried)| Placed::judge(lines, tried, &nominal))
        .collect();
    // Per tolerance: its zone as judged at nominal, its variants at both factors, its
    // size limits.
    let mut jobs: Vec<(usize, usize, f64, Vec<String>)> = Vec::new();
    let mut tols: Vec<TolResult> = Vec::new();
    for (ti, t) in part.tolerances.iter().enumerate() {
        let (label, unit_label) = labels[ti].clone();
        let rows: Vec<&simulate::Row> = nominal
            .report
            .iter()
            .flat_map(|r| r.rows.iter())
            .filter(|r| r.tolerance == label || unit_label.as_ref() == Some(&r.tolerance))
            .collect();
        let zone = match &t.value {
            TolValue::Zone { width, .. } => rows
                .iter()
                .map(|r| r.outcome.limits.1)
                .fold(*width, f64::max),
            // A size's variants carry their own deviation.
            TolValue::Size { .. } => 1.0,
        };
        let mut result = TolResult::new(ti, (label, unit_label), t, zone, !rows.is_empty());
        // A zone of 0 at MMC on a feature made at MMC leaves nothing to scale: the
        // trials need a zone, so it is listed as not tried.
        if !rows.is_empty() && zone > 0.0 {
            for k in [IN_AT, OUT_AT] {
                let variants = trials::forbidden(
                    part,
                    bench.sim.geometry,
                    bench.sim.feature_faces,
                    t,
                    zone,
                    k,
                );
                for (vi, v) in variants.into_iter().enumerate() {
                    if k == IN_AT {
                        result
                            .variants
                            .push(report::VariantResult::new(v.what.clone(), v.unit));
                    }
                    jobs.push((tols.len(), vi, k, v.lines));
                }
            }
            if matches!(
                t.kind,
                crate::model::TolKind::Diameter
                    | crate::model::TolKind::Radius
                    | crate::model::TolKind::Width
            ) {
                let scale = if t.kind == crate::model::TolKind::Radius {
                    2.0
                } else {
                    1.0
                };
                for f in &t.targets {
                    let name = &part.features[f.0].name;
                    let faces = &bench.sim.feature_faces[f.0];
                    let off = trials::off_drawing(bench.sim.geometry, faces, t);
                    for (side, dev) in trials::size_sides(&t.value) {
                        let grow = trials::num(off + dev * scale);
                        result.limits.push((
                            format!("{name} at its {side}"),
                            vec![format!("feature {name} grow {grow}")],
                            None,
                        ));
                    }
                }
            }
        }
        tols.push(result);
    }
    let tried: Vec<Tried> = jobs.par_iter().map(|j| run(bench, &j.3)).collect();
    for ((ti, vi, k, lines), tried) in jobs.into_iter().zip(tried) {
        let reading = tols[ti].reading(&tried);
        let v = &mut tols[ti].variants[vi];
        if k == IN_AT {
            v.at_in = Some((lines, tried, reading));
        } else {
            v.at_out = Some((lines, tried, reading));
        }
    }
    let limit_jobs: Vec<(usize, usize)> = tols
        .iter()
        .enumerate()
        .flat_map(|(ti, t)| (0..t.limits.len()).map(move |li| (ti, li)))
        .collect();
    let limit_runs: Vec<Tried> = limit_jobs
        .par_iter()
        .map(|&(ti, li)| run(bench, &tols[ti].limits[li].1))
        .collect();
    for ((ti, li), tried) in limit_jobs.into_iter().zip(limit_runs) {
        tols[ti].limits[li].2 = Some(tried);
    }
    for t in &mut tols {
        t.drop_rejected();
    }
    Verification {
        plan: nominal
            .report
            .as_ref()
            .map(|r| r.plan.clone())
            .unwrap_or_default(),
        part: part.name.clone(),
        options: *opts,
        nominal,
        placed,
        tolerances: tols,
    }
}

/// Placement `i`: a shift and a turn drawn from a seeded generator (SplitMix64).
fn placement(i: u64, opts: &Options) -> Vec<String> {
    // Each placement's own stream: its index through one round of the mixer.
    let mut state = mix(i.wrapping_add(0x632B_E59B_D9B4_E019));
    let mut next = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        // Uniform in [-1, 1].
        (mix(state) >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let (x, y, turn) = (next() * opts.shift, next() * opts.shift, next() * opts.turn);
    vec![
        format!("part move ({}, {})", trials::num(x), trials::num(y)),
        format!("part turn {}", trials::num(turn)),
    ]
}

/// SplitMix64's finaliser.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// One run of the program with the deviations `lines`.
fn run(bench: &Bench, lines: &[String]) -> Tried {
    let text = lines.join("\n");
    let part = &bench.sim.model.parts[bench.part];
    // No lines parse to the nominal part.
    let deviations = match simulate::deviation::parse(
        bench.sim.file,
        &text,
        part,
        bench.sim.geometry,
        bench.sim.feature_faces,
    ) {
        Ok(d) => d,
        Err(e) => {
            let why = e.first().map(|e| e.to_string()).unwrap_or_default();
            return Tried {
                report: None,
                stopped: Some(format!("the virtual part cannot take it: {why}")),
                rejected: Some(why),
            };
        }
    };
    let input = simulate::Input {
        deviations: &deviations,
        ..bench.sim
    };
    match simulate::simulate(&input, &simulate::Options::default()) {
        Ok(r) => Tried {
            report: Some(r),
            stopped: None,
            rejected: None,
        },
        Err(errors) => Tried {
            report: None,
            stopped: Some(stop_text(&errors, bench.sim.text)),
            rejected: None,
        },
    }
}

/// Why a run stopped: the first error and the program line it stopped on.
fn stop_text(errors: &[simulate::SimError], text: &str) -> String {
    let Some(e) = errors.first() else {
        return "the run stopped".into();
    };
    let at = miette::Diagnostic::labels(e)
        .and_then(|mut l| l.next())
        .map(|l| l.offset());
    match at {
        Some(o) if o <= text.len() => {
            let line = text[..o].matches('\n').count() + 1;
            let stmt = text.lines().nth(line - 1).unwrap_or("").trim();
            format!("{e} (line {line}: {stmt})")
        }
        _ => e.to_string(),
    }
}

/// The report of a run, if it finished.
impl Tried {
    fn rows(&self) -> impl Iterator<Item = &simulate::Row> {
        self.report.iter().flat_map(|r: &Report| r.rows.iter())
    }
}
