//! The HLIP as text (the seed's operator listing: change-setup, change-probe,
//! change-orient, inspect, record) and as JSON (the tree plus a summary).

use super::{Hlip, Summary};
use crate::model::fmt_num;
use serde_json::{json as j, Value};
use std::fmt::Write;

fn v3(v: &[f64; 3]) -> String {
    format!("({}, {}, {})", fmt_num(v[0]), fmt_num(v[1]), fmt_num(v[2]))
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

fn dir_text(v: &[f64; 3]) -> String {
    match axis(v) {
        Some(a) => format!("{a} {}", v3(v)),
        None => v3(v),
    }
}

/// The plan as an indented operator listing with a summary.
pub fn text(h: &Hlip) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "plan {}: part {} on {}, hierarchy {}",
        h.plan, h.part, h.cmm, h.hierarchy
    );
    let mut o_count = 0;
    for (si, s) in h.setups.iter().enumerate() {
        let _ = writeln!(out, "change-setup s{} up {}", si + 1, dir_text(&s.up));
        for t in &s.on_table {
            let _ = writeln!(out, "  rest {t} on the table");
        }
        for p in &s.probes {
            let _ = writeln!(out, "  change-probe {}", p.probe);
            for o in &p.orients {
                o_count += 1;
                if h.indexable {
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
                            if f.table {
                                format!("table under {} ({n} point{s})", f.face)
                            } else {
                                format!("{} ({n} point{s})", f.face)
                            }
                        })
                        .collect();
                    let _ = writeln!(out, "      inspect {}: {}", i.feature, faces.join(", "));
                    for r in &i.records {
                        let _ = writeln!(out, "        record {r}({})", i.feature);
                    }
                }
            }
        }
    }
    out += &summary_text(&h.summary);
    out
}

fn summary_text(s: &Summary) -> String {
    let mut out = String::from("summary\n");
    let (min, exact) = s.min_setups;
    let _ = writeln!(
        out,
        "  setups {} ({} {min})",
        s.setups,
        if exact { "minimum" } else { "at least" }
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
    let _ = writeln!(
        out,
        "  iterations {}, whole-probe cones {}, clustering {}",
        s.iterations, s.cones_acquired, s.strategy
    );
    for (l, v) in &s.violations {
        let _ = writeln!(out, "  violated {l}: {v}");
    }
    out
}

/// The plan as JSON: the tree, the points and a `summary` object.
pub fn json(h: &Hlip) -> Value {
    let setups: Vec<Value> = h
        .setups
        .iter()
        .map(|s| {
            j!({
                "up": s.up,
                "rotation": s.rotation,
                "on_table": s.on_table,
                "probes": s.probes.iter().map(|p| j!({
                    "probe": p.probe,
                    "orientations": p.orients.iter().map(|o| j!({
                        "a": o.a,
                        "b": o.b,
                        "direction": o.direction,
                        "inspect": o.inspections.iter().map(|i| j!({
                            "feature": i.feature,
                            "faces": i.faces.iter().map(|f| j!({
                                "face": f.face,
                                "table": f.table,
                                "points": f.points,
                            })).collect::<Vec<_>>(),
                            "record": i.records,
                        })).collect::<Vec<_>>(),
                    })).collect::<Vec<_>>(),
                })).collect::<Vec<_>>(),
            })
        })
        .collect();
    let s = &h.summary;
    let violations: serde_json::Map<String, Value> = s
        .violations
        .iter()
        .map(|(l, v)| (l.clone(), j!(v)))
        .collect();
    j!({
        "plan": h.plan,
        "part": h.part,
        "cmm": h.cmm,
        "hierarchy": h.hierarchy,
        "indexable": h.indexable,
        "setups": setups,
        "points": h.points.iter().map(|p| j!({
            "face": p.face,
            "table": p.table,
            "position": p.position,
            "normal": p.normal,
        })).collect::<Vec<_>>(),
        "summary": {
            "setups": s.setups,
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
            "strategy": s.strategy,
        },
    })
}
