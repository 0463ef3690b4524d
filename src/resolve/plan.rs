//! Plans: which part, which machine, which hierarchy and sampling, and the preferences.

use super::catalogue::strategy;
use super::errors::ResolveError as E;
use super::props::{num, path_text, Cx, Dim, Props};
use super::{Kind, Resolver};
use crate::diag::suggest;
use crate::load::ModuleId;
use crate::model::*;
use crate::source::Span;
use crate::syntax::ast::{self, PlanStmt, ValueKind};

pub(super) fn lower(
    r: &Resolver,
    cx: &mut Cx,
    module: ModuleId,
    p: &ast::Plan,
    model: &Model,
) -> Option<Plan> {
    let props = plan_props(p);
    let mut pp = Props::new(cx, format!("plan `{}`", p.name.name), p.name.span, &props);
    let part = pp
        .req(cx, "part", "f2")
        .and_then(|v| r.lookup_value(cx, module, v, Kind::Part));
    let cmm = pp
        .req(cx, "cmm", "lab")
        .and_then(|v| r.lookup_value(cx, module, v, Kind::Cmm));
    let hierarchy = match pp.get("hierarchy") {
        Some(v) => r.lookup_value(cx, module, v, Kind::Hierarchy),
        None => r.std_item("std::hierarchies", "efficient_accuracy", Kind::Hierarchy),
    };
    let sampling = match pp.get("sampling") {
        Some(v) => r.lookup_value(cx, module, v, Kind::Sampling),
        None => r.std_item("std::sampling", "spread", Kind::Sampling),
    };
    let outputs = pp
        .get("output")
        .map(|v| output_paths(cx, v))
        .unwrap_or_default();
    let motion = pp
        .get("motion")
        .map(|v| motion_distances(cx, v))
        .unwrap_or_default();
    let fixtures_v = pp.get("fixtures");
    let sensors_v = pp.get("sensors");
    let sensor_ratio = pp
        .get("sensor_ratio")
        .and_then(|v| sensor_ratio_value(cx, v))
        .unwrap_or(10.0);
    let scan_coverage = pp
        .get("scan_coverage")
        .and_then(|v| scan_coverage_value(cx, v))
        .unwrap_or(0.95);
    pp.finish(cx);
    let (part, cmm, hierarchy, sampling) = (part?, cmm?, hierarchy?, sampling?);
    let the_part = &model.parts[part];
    let the_cmm = &model.cmms[cmm];
    let head = model.heads.get(the_cmm.head.0);

    let mut plan = Plan {
        name: p.name.name.clone(),
        part: PartId(part),
        cmm: CmmId(cmm),
        hierarchy: HierarchyId(hierarchy),
        sampling: SamplingId(sampling),
        overrides: vec![],
        setups: vec![],
        orientations: vec![],
        probes: vec![],
        outputs,
        motion,
        fixtures: vec![],
        sensors: vec![],
        sensor_ratio,
        scan_coverage,
        span: p.name.span,
    };
    if let Some(v) = fixtures_v {
        plan.fixtures = plan_fixtures(cx, v, the_cmm);
    }
    if let Some(v) = sensors_v {
        plan.sensors = plan_sensors(cx, v, the_part, the_cmm);
    }
    for s in &p.stmts {
        match s {
            PlanStmt::Prop(_) => {}
            PlanStmt::Sample {
                feature,
                strategy: sv,
                ..
            } => sample_override(cx, &mut plan, the_part, feature, sv),
            PlanStmt::Pref {
                forbid,
                kind,
                value,
                opts,
                span,
            } => {
                let pref = PrefStmt {
                    forbid: *forbid,
                    kind,
                    value,
                    opts,
                    span: *span,
                };
                preference(cx, &mut plan, the_cmm, head, &pref);
            }
        }
    }
    Some(plan)
}

/// The plan's `key value` properties, without its preferences and overrides.
fn plan_props(p: &ast::Plan) -> Vec<ast::Prop> {
    p.stmts
        .iter()
        .filter_map(|s| {
            if let PlanStmt::Prop(pr) = s {
                Some(pr.clone())
            } else {
                None
            }
        })
        .collect()
}

/// `output { dmis "out.dmi", plan "…", graph "…" }`: paths inside the spec's folder.
fn output_paths(cx: &mut Cx, v: &ast::Value) -> Outputs {
    let mut outputs = Outputs::default();
    match &v.kind {
        ValueKind::Block(ops) => {
            let mut o = Props::new(cx, "`output`", v.span, ops);
            let mut path = |key: &'static str| {
                let s = o.get(key).and_then(|x| cx.string(x))?;
                if !stays_inside(&s.value) {
                    cx.err(E::OutputOutside {
                        span: s.span,
                        path: s.value.clone(),
                    });
                    return None;
                }
                Some(s.value.clone())
            };
            outputs.dmis = path("dmis");
            outputs.plan = path("plan");
            outputs.graph = path("graph");
            o.finish(cx);
        }
        _ => cx.mismatch(v, "a block `{ dmis \"out.dmi\" }`", ""),
    }
    outputs
}

/// `motion { prehit 2 mm, retract 2 mm, … }`: the defaults where a distance is left out
/// or wrong.
fn motion_distances(cx: &mut Cx, v: &ast::Value) -> Motion {
    let mut motion = Motion::default();
    match &v.kind {
        ValueKind::Block(ops) => {
            let mut o = Props::new(cx, "`motion`", v.span, ops);
            for (key, slot) in [
                ("prehit", &mut motion.prehit),
                ("retract", &mut motion.retract),
                ("search", &mut motion.search),
                ("clearance", &mut motion.clearance),
            ] {
                if let Some(x) = o.get(key).and_then(|x| cx.positive(x, Dim::Length, key)) {
                    *slot = x;
                }
            }
            let m = o.get("margin");
            if let Some((x, v)) = m.and_then(|v| Some((cx.dim(v, Dim::Length)?, v))) {
                if x < 0.0 {
                    cx.err(E::OutOfRange {
                        span: v.span,
                        what: "`margin`".into(),
                        value: format!("{} mm", num(x)),
                        range: "it must be 0 mm or more".into(),
                        help: "the least distance moves keep from the part; 0 mm keeps none".into(),
                    });
                } else {
                    motion.margin = x;
                }
            }
            o.finish(cx);
        }
        _ => cx.mismatch(v, "a block `{ prehit 2 mm, retract 2 mm }`", ""),
    }
    motion
}

/// `sensor_ratio 10`: a number above 0, or None after saying why.
fn sensor_ratio_value(cx: &mut Cx, v: &ast::Value) -> Option<f64> {
    let x = cx.number(v)?;
    if x <= 0.0 {
        cx.err(E::OutOfRange {
            span: v.span,
            what: "`sensor_ratio`".into(),
            value: num(x),
            range: "it must be more than 0".into(),
            help: "tolerance over accuracy: 10 for the usual 1:10 rule, 5 for 1:5".into(),
        });
        return None;
    }
    Some(x)
}

/// `scan_coverage 95 %`: a share above 0 and at most 1, or None after saying why.
fn scan_coverage_value(cx: &mut Cx, v: &ast::Value) -> Option<f64> {
    let x = cx.dim(v, Dim::Ratio)?;
    if x <= 0.0 || x > 1.0 {
        cx.err(E::OutOfRange {
            span: v.span,
            what: "`scan_coverage`".into(),
            value: format!("{} %", num(x * 100.0)),
            range: "a share of the area above 0 % and at most 100 %".into(),
            help: "the share of a scanned face's area its passes must see; 95 % is usual".into(),
        });
        return None;
    }
    Some(x)
}

/// `sample feature with strategy`: a per-feature override of the plan's sampling.
fn sample_override(
    cx: &mut Cx,
    plan: &mut Plan,
    part: &Part,
    feature: &ast::Path,
    sv: &ast::Value,
) {
    let name = path_text(feature);
    match part.features.iter().position(|f| f.name == name) {
        Some(i) => {
            cx.bind(feature.span, part.features[i].span);
            if let Some(st) = strategy(cx, sv, None) {
                plan.overrides.push((FeatureId(i), st));
            }
        }
        None => {
            let help = format!(
                "part `{}` has no feature `{name}`; {}",
                part.name,
                suggest::help_for_unknown(
                    "feature",
                    &name,
                    part.features.iter().map(|f| f.name.as_str())
                )
            );
            cx.err(E::UnknownName {
                span: feature.span,
                what: "feature".into(),
                name,
                help,
            });
        }
    }
}

/// One `prefer …` or `forbid …` statement of a plan, as written.
struct PrefStmt<'a> {
    forbid: bool,
    kind: &'a ast::Ident,
    value: &'a ast::Value,
    opts: &'a [ast::Prop],
    span: Span,
}

/// A setup, orientation or probe preference, added to the plan when it checks out.
fn preference(cx: &mut Cx, plan: &mut Plan, cmm: &Cmm, head: Option<&Head>, s: &PrefStmt) {
    let verb = if s.forbid { "forbid" } else { "prefer" };
    let mut o = Props::new(cx, format!("`{verb} {}`", s.kind.name), s.span, s.opts);
    match s.kind.name.as_str() {
        "setup" => {
            let weight = weight(cx, &mut o, s.forbid, "weight");
            if let Some(direction) = cx.direction(s.value) {
                plan.setups.push(SetupPref {
                    direction,
                    stance: stance(s.forbid, weight.unwrap_or(1.0)),
                    span: s.span,
                });
            }
        }
        "orientation" => {
            let weight = weight(cx, &mut o, s.forbid, "weight");
            if let Some((a, b)) = orientation(cx, s.value, head) {
                plan.orientations.push(OrientPref {
                    a,
                    b,
                    stance: stance(s.forbid, weight.unwrap_or(1.0)),
                    span: s.span,
                });
            }
        }
        "probe" => {
            let cost = weight(cx, &mut o, s.forbid, "cost");
            if let Some(p) = probe_pref(cx, cmm, s, cost) {
                plan.probes.push(p);
            }
        }
        other => {
            let help =
                suggest::help_for_unknown("preference", other, ["setup", "orientation", "probe"]);
            cx.err(E::UnknownName {
                span: s.kind.span,
                what: "preference".into(),
                name: other.into(),
                help,
            });
        }
    }
    o.finish(cx);
}

/// A preference's `weight` or `cost` (≥ 0); a ban takes none, so there it is no key.
fn weight(cx: &mut Cx, o: &mut Props, forbid: bool, key: &'static str) -> Option<f64> {
    if forbid {
        None
    } else {
        o.get(key).and_then(|v| cx.non_negative(v, key))
    }
}

/// `prefer probe p1 cost 2` or `forbid probe p3`: a probe label of the plan's CMM.
fn probe_pref(cx: &mut Cx, cmm: &Cmm, s: &PrefStmt, cost: Option<f64>) -> Option<ProbePref> {
    let label = cx.name(s.value)?;
    let Some(k) = cmm.probes.iter().position(|(l, _)| *l == label.name) else {
        let help = format!(
            "cmm `{}` has no probe `{}`; {}",
            cmm.name,
            label.name,
            suggest::help_for_unknown(
                "probe",
                &label.name,
                cmm.probes.iter().map(|(l, _)| l.as_str())
            )
        );
        cx.err(E::UnknownName {
            span: label.span,
            what: "probe".into(),
            name: label.name.clone(),
            help,
        });
        return None;
    };
    if let Some(&at) = cmm.probe_labels.get(k) {
        cx.bind(label.span, at);
    }
    Some(ProbePref {
        label: label.name.clone(),
        stance: stance(s.forbid, cost),
        span: s.span,
    })
}

/// An `(A, B)` orientation checked against the head's range and grid.
fn orientation(cx: &mut Cx, v: &ast::Value, head: Option<&Head>) -> Option<(f64, f64)> {
    let ValueKind::Tuple(items) = &v.kind else {
        cx.mismatch(
            v,
            "an orientation `(A, B)`",
            "write e.g. `(30 deg, 90 deg)`",
        );
        return None;
    };
    if items.len() != 2 {
        cx.mismatch(
            v,
            "an orientation `(A, B)`",
            "write e.g. `(30 deg, 90 deg)`",
        );
        return None;
    }
    let a = cx.dim(&items[0], Dim::Angle);
    let b = cx.dim(&items[1], Dim::Angle);
    let (a, b) = (a?, b?);
    let head = head?;
    let HeadKind::Indexable { a: ar, b: br, step } = &head.kind else {
        cx.err(E::FixedHead {
            span: v.span,
            head: head.name.clone(),
        });
        return None;
    };
    let mut ok = true;
    for (axis, val, range, item) in [("A", a, ar, &items[0]), ("B", b, br, &items[1])] {
        let rtxt = format!("{}°..{}°", num(range[0]), num(range[1]));
        if val < range[0] - 1e-9 || val > range[1] + 1e-9 {
            cx.err(E::AngleOutOfRange {
                span: item.span,
                axis: axis.into(),
                value: num(val),
                head: head.name.clone(),
                help: format!(
                    "choose {axis} within {rtxt}, a multiple of {}° from {}°",
                    num(*step),
                    num(range[0])
                ),
                range: rtxt,
            });
            ok = false;
            continue;
        }
        let k = (val - range[0]) / step;
        if (k - k.round()).abs() > 1e-9 {
            let lo = range[0] + k.floor() * step;
            cx.err(E::OffGrid {
                span: item.span,
                axis: axis.into(),
                value: num(val),
                head: head.name.clone(),
                step: num(*step),
                help: format!(
                    "the nearest positions are {}° and {}°",
                    num(lo),
                    num(lo + step)
                ),
            });
            ok = false;
        }
    }
    ok.then_some((a, b))
}

/// `forbid …` or `prefer …` with its weight or cost.
fn stance<T>(forbid: bool, value: T) -> Stance<T> {
    if forbid {
        Stance::Forbid
    } else {
        Stance::Prefer(value)
    }
}

/// Whether a path a spec names for an output stays in the spec's folder: relative, no
/// `..`, not empty.
fn stays_inside(path: &str) -> bool {
    use std::path::Component;
    let p = std::path::Path::new(path);
    !path.is_empty()
        && p.components()
            .all(|c| matches!(c, Component::Normal(_) | Component::CurDir))
}

/// `fixtures [vise, chuck]`: labels of the CMM's fixtures, in the order the plan tries
/// them.
fn plan_fixtures(cx: &mut Cx, v: &ast::Value, cmm: &Cmm) -> Vec<usize> {
    let ValueKind::List(entries) = &v.kind else {
        cx.mismatch(v, "a list of the CMM's fixtures", "write `fixtures [vise]`");
        return vec![];
    };
    let mut out: Vec<usize> = Vec::new();
    for e in entries {
        let Some(id) = cx.name(&e.value) else {
            continue;
        };
        let found = cmm.fixtures.iter().position(|(l, _)| *l == id.name);
        if let Some(&at) = found.and_then(|k| cmm.fixture_labels.get(k)) {
            cx.bind(id.span, at);
        }
        match found {
            Some(k) if !out.contains(&k) => out.push(k),
            Some(_) => {}
            None => {
                let help = format!(
                    "CMM `{}` has no fixture `{}`; {}",
                    cmm.name,
                    id.name,
                    suggest::help_for_unknown(
                        "fixture",
                        &id.name,
                        cmm.fixtures.iter().map(|(l, _)| l.as_str())
                    )
                );
                cx.err(E::UnknownName {
                    span: id.span,
                    what: "fixture".into(),
                    name: id.name.clone(),
                    help,
                });
            }
        }
    }
    out
}

/// `sensors { top laser, bore touch }`: per feature of the plan's part, `laser`, `touch`
/// or `auto`; `laser` needs a scanner in the machine's rack.
fn plan_sensors(
    cx: &mut Cx,
    v: &ast::Value,
    part: &crate::model::Part,
    cmm: &crate::model::Cmm,
) -> Vec<(FeatureId, SensorChoice, crate::source::Span)> {
    let ValueKind::Block(props) = &v.kind else {
        cx.mismatch(v, "a block `{ top laser, bore touch }`", "");
        return vec![];
    };
    let mut out: Vec<(FeatureId, SensorChoice, crate::source::Span)> = Vec::new();
    for prop in props {
        let name = &prop.key.name;
        let Some(f) = part.features.iter().position(|f| &f.name == name) else {
            let help = format!(
                "part `{}` has no feature `{name}`; {}",
                part.name,
                suggest::help_for_unknown(
                    "feature",
                    name,
                    part.features.iter().map(|f| f.name.as_str())
                )
            );
            cx.err(E::UnknownName {
                span: prop.key.span,
                what: "feature".into(),
                name: name.clone(),
                help,
            });
            continue;
        };
        cx.bind(prop.key.span, part.features[f].span);
        let words = ["laser", "touch", "auto"];
        let choice = match cx.name(&prop.value).map(|i| i.name.as_str()) {
            Some("laser") => SensorChoice::Laser,
            Some("touch") => SensorChoice::Touch,
            Some("auto") => SensorChoice::Auto,
            Some(other) => {
                cx.err(E::UnknownName {
                    span: prop.value.span,
                    what: "sensor".into(),
                    name: other.to_string(),
                    help: suggest::help_for_unknown("sensor", other, words),
                });
                continue;
            }
            None => continue,
        };
        if choice == SensorChoice::Laser && cmm.scanners.is_empty() {
            cx.err(E::NoScanner {
                span: prop.value.span,
                feature: name.clone(),
                cmm: cmm.name.clone(),
            });
            continue;
        }
        if out.iter().any(|(g, _, _)| g.0 == f) {
            cx.err(E::DuplicateName {
                span: prop.key.span,
                first: None,
                name: name.clone(),
                help: "say each feature's sensor once".into(),
            });
            continue;
        }
        out.push((FeatureId(f), choice, prop.span));
    }
    out
}
