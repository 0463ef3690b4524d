//! The HLIP as text (the seed's operator listing: change-setup, change-probe,
//! change-orient, inspect, record) and as JSON (the tree plus a summary).

use super::{Hlip, SetupNode, Summary};
use crate::access::pose::{Contact, Head};
use crate::geometry::{FaceId, PartGeometry, V3};
use crate::model::{fmt_num, DatumId, FeatureId, Model, Part, Plan, PlanId, SlotId, ToleranceId};
use serde_json::{json as j, Value};
use std::fmt::Write;

/// The names a plan's ids stand for: where the plan meets people (listings, JSON,
/// DMIS labels and comments, diagnostics).
#[derive(Clone, Copy)]
pub struct Names<'a> {
    /// The model.
    pub model: &'a Model,
    /// The plan's part geometry.
    pub geometry: &'a PartGeometry,
    /// The plan.
    pub plan: &'a Plan,
}

impl<'a> Names<'a> {
    /// The names of plan `plan` over its part's geometry.
    pub fn new(model: &'a Model, geometry: &'a PartGeometry, plan: PlanId) -> Names<'a> {
        Names {
            model,
            geometry,
            plan: &model.plans[plan.0],
        }
    }

    /// The plan's part.
    pub fn part(&self) -> &'a Part {
        &self.model.parts[self.plan.part.0]
    }

    /// A feature's name; `—` for faces that hang from the part itself.
    pub fn feature(&self, f: Option<FeatureId>) -> &'a str {
        f.map_or("—", |f| self.part().features[f.0].name.as_str())
    }

    /// A face's name.
    pub fn face(&self, f: FaceId) -> &'a str {
        &self.geometry.faces[f.0].name
    }

    /// A probe's label in the rack.
    pub fn probe(&self, p: SlotId) -> &'a str {
        let cmm = &self.model.cmms[self.plan.cmm.0];
        match cmm.probes.get(p.0) {
            Some(x) => &x.0,
            None => cmm
                .scanners
                .get(p.0 - cmm.probes.len())
                .map_or("?", |x| &x.0),
        }
    }

    /// Whether a sensor slot is a laser scanner (after the rack's probes).
    pub fn is_scanner(&self, p: SlotId) -> bool {
        p.0 >= self.model.cmms[self.plan.cmm.0].probes.len()
    }

    /// A tolerance's name.
    pub fn tolerance(&self, t: ToleranceId) -> &'a str {
        &self.part().tolerances[t.0].name
    }

    /// A datum's letter.
    pub fn datum(&self, d: DatumId) -> &'a str {
        &self.part().datums[d.0].name
    }

    /// A fixture's label beside the CMM, and its kind's keyword.
    pub fn fixture(&self, slot: usize) -> (&'a str, &'static str) {
        let (label, id) = &self.model.cmms[self.plan.cmm.0].fixtures[slot];
        (label, self.model.fixtures[id.0].kind.word())
    }

    /// What holds the part in a setup with `up` pointing up, in words: `the table on
    /// …`, `vise v (vise): jaws on … and …, resting on …`, `chuck c (chuck) gripping …`,
    /// `plate p (sine_plate) under …, tilted 30°`.
    pub fn holder(&self, h: &super::poses::Holder, up: &V3) -> String {
        self.holder_naming(h, up, &|f| self.face(f).to_string())
    }

    /// [`Names::holder`] with the faces named by `face` (the DMIS writer names them by
    /// the datum or feature measured on them, for the operator).
    pub fn holder_naming(
        &self,
        h: &super::poses::Holder,
        up: &V3,
        face: &dyn Fn(FaceId) -> String,
    ) -> String {
        use crate::model::FixtureKind;
        // Each name once: faces named by what holds them (a datum, a side) can share one.
        let faces = |fs: &[FaceId]| {
            let mut words: Vec<String> = Vec::new();
            for w in fs.iter().map(|f| face(*f)) {
                if !words.contains(&w) {
                    words.push(w);
                }
            }
            words.join(", ")
        };
        match h {
            super::poses::Holder::Table { faces: fs } => format!("the table on {}", faces(fs)),
            super::poses::Holder::Fixture {
                slot,
                faces: fs,
                placement,
            } => {
                let (label, id) = &self.model.cmms[self.plan.cmm.0].fixtures[*slot];
                // The fixture as the rack names it (an angle plate is a sine plate at
                // 90°: its own name, not its kind's, is what the operator fetches).
                let fixture = &self.model.fixtures[id.0];
                let kind = &fixture.kind;
                let name = format!("fixture {label} ({})", fixture.name);
                match kind {
                    FixtureKind::Vise { .. } if fs.len() >= 2 => format!(
                        "{name}: jaws on {} and {}, resting on {}",
                        face(fs[0]),
                        face(fs[1]),
                        faces(&fs[2..])
                    ),
                    FixtureKind::Chuck { .. } => format!("{name} gripping {}", faces(fs)),
                    FixtureKind::VBlock { .. } => {
                        format!("{name} under {}, its axis horizontal", faces(fs))
                    }
                    FixtureKind::SinePlate { .. } => {
                        let tilt = fs
                            .first()
                            .and_then(|f| match self.geometry.faces[f.0].surface {
                                crate::geometry::Surface::Plane { normal, .. } => {
                                    Some((-normal).dot(up).clamp(-1.0, 1.0).acos().to_degrees())
                                }
                                _ => None,
                            })
                            .unwrap_or(0.0);
                        format!(
                            "{name} under {}, tilted {}°{}",
                            faces(fs),
                            fmt_num((tilt * 10.0).round() / 10.0),
                            placement
                                .as_ref()
                                .map_or(String::new(), |p| format!(", {p}"))
                        )
                    }
                    FixtureKind::Mesh { .. } => format!("{name} located on {}", faces(fs)),
                    FixtureKind::Risers { .. } => format!(
                        "{name}: standing on {} on three {} mm risers{}",
                        faces(fs),
                        fmt_num(fixture.height),
                        placement
                            .as_ref()
                            .map_or(String::new(), |p| format!(", {p}"))
                    ),
                    _ => format!("{name} on {}", faces(fs)),
                }
            }
        }
    }
}

/// A plan coordinate triple in words.
fn v3(v: &[f64; 3]) -> String {
    format!("({}, {}, {})", fmt_num(v[0]), fmt_num(v[1]), fmt_num(v[2]))
}

fn arr(v: &V3) -> [f64; 3] {
    [v.x, v.y, v.z]
}

/// A direction's name when it is an axis.
fn axis(v: &[f64; 3]) -> Option<&'static str> {
    let names = [
        ([1.0, 0.0, 0.0], "+x"),
        ([-1.0, 0.0, 0.0], "-x"),
        ([0.0, 1.0, 0.0], "+y"),
        ([0.0, -1.0, 0.0], "-y"),
        ([0.0, 0.0, 1.0], "+z"),
        ([0.0, 0.0, -1.0], "-z"),
    ];
    names
        .iter()
        .find(|(a, _)| a.iter().zip(v).all(|(x, y)| (x - y).abs() < 1e-6))
        .map(|(_, n)| *n)
}

fn dir_text(v: &V3) -> String {
    let v = &arr(v);
    match axis(v) {
        Some(a) => format!("{a} {}", v3(v)),
        None => v3(v),
    }
}

/// Why setup `si` is in the plan, in words: the features measured in it and in no other
/// setup, then those it shares, with the setups it shares them with —
/// `datum_a, f12 and 3 more: measured in no other setup; part of f7 (with s1)`.
fn setup_reason(h: &Hlip, si: usize, names: &Names) -> String {
    let features_of = |s: &SetupNode| {
        let mut out: Vec<Option<FeatureId>> = Vec::new();
        for i in s
            .probes
            .iter()
            .flat_map(|p| &p.orients)
            .flat_map(|o| &o.inspections)
        {
            if !out.contains(&i.feature) {
                out.push(i.feature);
            }
        }
        out
    };
    let all: Vec<Vec<Option<FeatureId>>> = h.setups.iter().map(features_of).collect();
    let (mut own, mut shared) = (Vec::new(), Vec::new());
    for f in &all[si] {
        let others: Vec<String> = (0..all.len())
            .filter(|&k| k != si && all[k].contains(f))
            .map(|k| format!("s{}", k + 1))
            .collect();
        if others.is_empty() {
            own.push(names.feature(*f));
        } else {
            shared.push(format!(
                "{} (with {})",
                names.feature(*f),
                others.join(", ")
            ));
        }
    }
    let list = |items: Vec<String>| {
        const MOST: usize = 6;
        let n = items.len();
        let mut words: Vec<String> = items.into_iter().take(MOST).collect();
        if n > MOST {
            words.push(format!("{} more", n - MOST));
        }
        match words.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
            Some((last, _)) => last.clone(),
            None => String::new(),
        }
    };
    let own = list(own.into_iter().map(str::to_string).collect());
    let shared = list(shared);
    match (own.is_empty(), shared.is_empty()) {
        (false, true) => format!("{own}: measured in no other setup"),
        (false, false) => format!("{own}: measured in no other setup; part of {shared}"),
        (true, false) => format!("part of {shared}"),
        (true, true) => "nothing".to_string(),
    }
}

/// The plan as an indented operator listing with a summary.
pub fn text(h: &Hlip, names: &Names) -> String {
    let (model, plan) = (names.model, names.plan);
    let mut out = String::new();
    let _ = writeln!(
        out,
        "plan {}: part {} on {}, hierarchy {}",
        plan.name,
        names.part().name,
        model.cmms[plan.cmm.0].name,
        model.hierarchies[plan.hierarchy.0].name
    );
    let mut o_count = 0;
    for (si, s) in h.setups.iter().enumerate() {
        let _ = writeln!(out, "change-setup s{} up {}", si + 1, dir_text(&s.up));
        let _ = writeln!(out, "  held by {}", names.holder(&s.holder, &s.up));
        let _ = writeln!(out, "  for {}", setup_reason(h, si, names));
        for t in &s.on_table {
            let _ = writeln!(out, "  rest {} on the table", names.face(*t));
        }
        for p in &s.probes {
            let kind = if names.is_scanner(p.probe) {
                "scanner"
            } else {
                "probe"
            };
            let _ = writeln!(out, "  change-{kind} {}", names.probe(p.probe));
            for o in &p.orients {
                o_count += 1;
                if h.head == Head::Indexable {
                    let _ = writeln!(
                        out,
                        "    change-orient o{o_count} A {}° B {}° along {}",
                        fmt_num(o.a),
                        fmt_num(o.b),
                        dir_text(&o.direction)
                    );
                } else {
                    let _ = writeln!(out, "    change-orient o{o_count} with the ram");
                }
                for i in &o.inspections {
                    let faces: Vec<String> = i
                        .faces
                        .iter()
                        .map(|f| {
                            let n = f.points.len();
                            let s = if n == 1 { "" } else { "s" };
                            let face = names.face(f.face);
                            if !f.passes.is_empty() {
                                let k = f.passes.len();
                                let es = if k == 1 { "" } else { "es" };
                                return format!("{face} ({k} pass{es})");
                            }
                            match f.contact {
                                Contact::Table => format!("table under {face} ({n} point{s})"),
                                Contact::Part => format!("{face} ({n} point{s})"),
                            }
                        })
                        .collect();
                    let feature = names.feature(i.feature);
                    let _ = writeln!(out, "      inspect {feature}: {}", faces.join(", "));
                    for r in &i.records {
                        let _ = writeln!(out, "        record {}({feature})", names.tolerance(*r));
                    }
                }
            }
        }
    }
    if !h.scans.is_empty() || !h.to_touch.is_empty() {
        out += "sensors\n";
    }
    for sc in &h.scans {
        let feature = names.feature(Some(sc.feature));
        let _ = writeln!(
            out,
            "  scan {feature} ({}) in s{} with {}: {} % of its area, {} view{}, {} pass{}; {}",
            names.face(sc.face),
            sc.setup + 1,
            names.probe(sc.scanner),
            fmt_num((sc.coverage * 1000.0).floor() / 10.0),
            sc.views,
            if sc.views == 1 { "" } else { "s" },
            sc.passes,
            if sc.passes == 1 { "" } else { "es" },
            sc.why
        );
    }
    for (f, face, best) in &h.to_touch {
        let _ = writeln!(
            out,
            "  touch {} instead of scanning it: the scanner sees {} % of {} at best, the plan asks {} %",
            names.feature(Some(*f)),
            fmt_num((best * 1000.0).floor() / 10.0),
            names.face(*face),
            fmt_num((plan.scan_coverage * 1000.0).round() / 10.0)
        );
    }
    out += &summary_text(&h.summary, names);
    out
}

/// The hierarchy's levels in words, beside their violation counts.
fn violations<'a>(s: &'a Summary, names: &Names) -> impl Iterator<Item = (String, u64)> + 'a {
    let h = &names.model.hierarchies[names.plan.hierarchy.0];
    let levels: Vec<String> = h.levels.iter().map(|l| l.text()).collect();
    levels.into_iter().zip(s.violations.iter().copied())
}

fn strategy(s: &Summary) -> &'static str {
    s.strategy.map_or("—", |x| x.name())
}

fn summary_text(s: &Summary, names: &Names) -> String {
    let mut out = String::from("summary\n");
    let (min, exact) = s.min_setups;
    let _ = writeln!(
        out,
        "  setups {} ({} {min})",
        s.setups,
        if exact { "minimum" } else { "at least" }
    );
    if let Some(why) = &s.more_setups {
        let _ = writeln!(out, "  more setups than the minimum: {why}");
    }
    if let Some((moved, left)) = s.unsettled {
        let _ = writeln!(
            out,
            "  generate-and-test did not settle in {} rounds: the best plan found, {moved} of its touches moved to configurations that validate, {left} left out",
            s.iterations
        );
    }
    let _ = writeln!(
        out,
        "  tolerances measured {} of {}",
        s.tolerances.0, s.tolerances.1
    );
    let _ = writeln!(
        out,
        "  probes used {}, probe changes {}",
        s.probes_used, s.probe_changes
    );
    let _ = writeln!(
        out,
        "  orientations {}, orientation changes {}",
        s.orientations, s.orientation_changes
    );
    let _ = writeln!(
        out,
        "  features {}, points {} ({} dropped)",
        s.features, s.points, s.dropped_points
    );
    if s.scanned.0 > 0 {
        let _ = writeln!(
            out,
            "  faces scanned {}, passes {}",
            s.scanned.0, s.scanned.1
        );
    }
    let _ = writeln!(
        out,
        "  iterations {}, whole-probe cones {}, clustering {}",
        s.iterations,
        s.cones_acquired,
        strategy(s)
    );
    for (l, v) in violations(s, names) {
        let _ = writeln!(out, "  violated {l}: {v}");
    }
    out
}

/// The plan as JSON: the tree, the points and a `summary` object.
pub fn json(h: &Hlip, names: &Names) -> Value {
    let (model, plan) = (names.model, names.plan);
    let setups: Vec<Value> = h
        .setups
        .iter()
        .enumerate()
        .map(|(si, s)| {
            j!({
                "up": arr(&s.up),
                "rotation": s.rotation,
                "on_table": s.on_table.iter().map(|f| names.face(*f)).collect::<Vec<_>>(),
                "held_by": names.holder(&s.holder, &s.up),
                "for": setup_reason(h, si, names),
                "probes": s.probes.iter().map(|p| j!({
                    "probe": names.probe(p.probe),
                    "orientations": p.orients.iter().map(|o| j!({
                        "a": o.a,
                        "b": o.b,
                        "direction": arr(&o.direction),
                        "inspect": o.inspections.iter().map(|i| j!({
                            "feature": names.feature(i.feature),
                            "faces": i.faces.iter().map(|f| {
                                let mut v = j!({
                                    "face": names.face(f.face),
                                    "table": f.contact == Contact::Table,
                                    "points": f.points,
                                });
                                if !f.passes.is_empty() {
                                    v["passes"] = f.passes.iter().map(|x| j!([
                                        arr(&x.start.coords),
                                        arr(&x.end.coords),
                                    ])).collect();
                                }
                                v
                            }).collect::<Vec<_>>(),
                            "record": i.records.iter().map(|t| names.tolerance(*t)).collect::<Vec<_>>(),
                        })).collect::<Vec<_>>(),
                    })).collect::<Vec<_>>(),
                })).collect::<Vec<_>>(),
            })
        })
        .collect();
    let s = &h.summary;
    let violations: serde_json::Map<String, Value> =
        violations(s, names).map(|(l, v)| (l, j!(v))).collect();
    let mut out = j!({
        "plan": plan.name,
        "part": names.part().name,
        "cmm": model.cmms[plan.cmm.0].name,
        "hierarchy": model.hierarchies[plan.hierarchy.0].name,
        "indexable": h.head == Head::Indexable,
        "setups": setups,
        "points": h.points.iter().map(|p| j!({
            "face": names.face(p.face),
            "table": p.at.contact() == Contact::Table,
            "position": arr(&p.position.coords),
            "normal": arr(&p.normal),
        })).collect::<Vec<_>>(),
        "summary": {
            "setups": s.setups,
            "tolerances_measured": s.tolerances.0,
            "tolerances": s.tolerances.1,
            "probes_used": s.probes_used,
            "probe_changes": s.probe_changes,
            "orientations": s.orientations,
            "orientation_changes": s.orientation_changes,
            "features": s.features,
            "points": s.points,
            "iterations": s.iterations,
            "violations": violations,
            "dropped_points": s.dropped_points,
            "cones_acquired": s.cones_acquired,
            "min_setups": s.min_setups.0,
            "min_setups_proven": s.min_setups.1,
            "more_setups": s.more_setups,
            "unsettled": s.unsettled.map(|(moved, left)| serde_json::json!({"moved": moved, "left_out": left})),
            "strategy": strategy(s),
        },
    });
    if !h.scans.is_empty() {
        out["scans"] = h
            .scans
            .iter()
            .map(|sc| {
                j!({
                    "feature": names.feature(Some(sc.feature)),
                    "face": names.face(sc.face),
                    "setup": sc.setup + 1,
                    "scanner": names.probe(sc.scanner),
                    "coverage": sc.coverage,
                    "views": sc.views,
                    "passes": sc.passes,
                    "why": sc.why,
                })
            })
            .collect::<Vec<_>>()
            .into();
    }
    out
}
