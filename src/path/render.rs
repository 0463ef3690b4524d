//! The LLIP as JSON, beside the HLIP (`inspc build --plan-json`).

use super::Llip;
use crate::access::Contact;
use crate::plan::{Hlip, Names};
use serde_json::{json, Value};

/// Rounds a coordinate to a micrometre so that the JSON is stable across machines.
fn r(x: f64) -> f64 {
    let v = (x * 1e4).round() / 1e4;
    if v == 0.0 {
        0.0
    } else {
        v
    }
}

fn pts(p: &[[f64; 3]]) -> Value {
    Value::Array(
        p.iter()
            .map(|q| json!([r(q[0]), r(q[1]), r(q[2])]))
            .collect(),
    )
}

/// The plan with its paths: the HLIP's JSON with, per setup, the alignment and every
/// group's moves, and a `paths` summary.
pub fn json(hlip: &Hlip, llip: &Llip, names: &Names) -> Value {
    let mut v = crate::plan::json(hlip, names);
    let setups: Vec<Value> = llip
        .setups
        .iter()
        .map(|s| {
            json!({
                "setup": s.setup,
                "alignment": {
                    "steps": s.alignment.steps.iter().map(|a| json!({
                        "group": a.group,
                        "block": a.block,
                        "points": a.points,
                        "fixes": a.keywords,
                    })).collect::<Vec<_>>(),
                    "translate": s.alignment.trans.iter().map(|(k, x)| json!([k.to_string(), r(*x)])).collect::<Vec<_>>(),
                    "missing": s.alignment.missing,
                },
                "groups": s.groups.iter().map(|g| json!({
                    "probe": names.probe(g.probe),
                    "a": g.a,
                    "b": g.b,
                    "direction": [r(g.direction[0]), r(g.direction[1]), r(g.direction[2])],
                    "entry": pts(&g.entry),
                    "blocks": g.blocks.iter().map(|b| json!({
                        "feature": names.feature(b.feature),
                        "face": names.face(b.face),
                        "table": b.contact == Contact::Table,
                        "datum": b.datum.map(|d| names.datum(d)),
                        "touches": b.touches.iter().map(|t| json!({
                            "point": t.point,
                            "via": pts(&t.via),
                            "standoff": pts(&[t.standoff])[0],
                        })).collect::<Vec<_>>(),
                    })).collect::<Vec<_>>(),
                    "exit": pts(&g.exit),
                    "records": g.records.iter().map(|t| names.tolerance(*t)).collect::<Vec<_>>(),
                    "length": r(g.length),
                })).collect::<Vec<_>>(),
            })
        })
        .collect();
    let s = &llip.summary;
    if let Value::Object(m) = &mut v {
        m.insert("paths".into(), Value::Array(setups));
        m.insert(
            "motion".into(),
            json!({
                "prehit": llip.motion.prehit,
                "retract": llip.motion.retract,
                "search": llip.motion.search,
                "clearance": llip.motion.clearance,
            }),
        );
        m.insert(
            "path_summary".into(),
            json!({
                "groups": s.groups,
                "touches": s.touches,
                "length": r(s.length),
                "added_nodes": s.added_nodes,
                "checks": s.checks,
            }),
        );
    }
    v
}
