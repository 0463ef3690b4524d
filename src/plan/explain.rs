//! Explaining a failed plan: for a face no configuration inspects, which probe came
//! closest, from where, and what stopped it.

use super::filter::min_points;
use super::knowledge::Knowledge;
use super::machine::Machine;
use super::{poses, solve, Input, PlanError};
use crate::diag::Diagnostics;
use crate::geometry::PartGeometry;
use crate::geometry::{FaceId, V3};
use crate::graph::Node;
use crate::model::fmt_num;
use crate::model::{Model, Plan};

/// The face a point lies on, in words ("the table under ..." for a table point).
pub(super) fn face_name(input: &Input, k: &Knowledge, point: usize) -> String {
    let f = k.points[point].face;
    let name = &input.geometry.faces[f.0].name;
    if point >= k.graph_points {
        format!("the table under {name}")
    } else {
        name.clone()
    }
}

/// The first feature that names a face.
fn owner(input: &Input, face: FaceId) -> Option<crate::model::FeatureId> {
    let g = input.graph;
    g.nodes().find_map(|(n, node)| match node {
        Node::Feature { feature, .. } => g
            .children(n)
            .iter()
            .any(|(c, _)| matches!(g.graph[*c], Node::Face { face: f, .. } if f == face))
            .then_some(*feature),
        _ => None,
    })
}

/// One diagnostic for a face no configuration inspects: which probe came closest, from
/// where, and what stopped it.
pub(super) fn report_face(
    input: &Input,
    k: &Knowledge,
    m: &Machine,
    face: FaceId,
    allowed: bool,
    diags: &mut Diagnostics,
) {
    let part = &input.model.parts[input.plan.part.0];
    let feature = owner(input, face).map(|f| &part.features[f.0]);
    let pts = input.graph.face_points(face);
    let name = input.geometry.faces[face.0].name.clone();
    let need = min_points(input.geometry.faces[face.0].surface.kind()).min(pts.len());
    // Per probe: how many points it reaches in a setup the part can be put in, how
    // many in any direction, and the first blocking component.
    let mut best: Option<(usize, usize, usize, String, String, usize)> = None;
    let usable = k.realisable.and(&k.forbidden.not());
    for (p, probe) in m.probes.iter().enumerate() {
        if !m.allowed[p] {
            continue;
        }
        let reach = pts
            .iter()
            .filter(|&&f| k.dom[f][p].tip && !k.dom[f][p].setup.is_empty())
            .count();
        let real = pts
            .iter()
            .filter(|&&f| k.dom[f][p].tip && !k.dom[f][p].setup.and(&usable).is_empty())
            .count();
        let tips = pts.iter().filter(|&&f| k.dom[f][p].tip).count();
        let (depth, why) = if tips == 0 {
            (
                0,
                format!(
                    "probe {}'s Ø{} mm tip does not fit at any of its {} points with {} mm to back off the surface",
                    probe.name,
                    fmt_num(2.0 * probe.tip_radius),
                    pts.len(),
                    fmt_num(crate::access::pose::MIN_TRAVEL)
                ),
            )
        } else {
            let f = pts
                .iter()
                .copied()
                .find(|&f| k.dom[f][p].tip)
                .unwrap_or(pts[0]);
            blocking(k, m, p, f)
        };
        let cand = (real, reach, depth, why, probe.name.clone(), p);
        if best
            .as_ref()
            .is_none_or(|b| (cand.0, cand.1, cand.2) > (b.0, b.1, b.2))
        {
            best = Some(cand);
        }
    }
    let (real, reach, _, why, probe, p) =
        best.unwrap_or((0, 0, 0, "no probe is allowed".into(), String::new(), 0));
    let mut help = "use a smaller tip, a longer or thinner stylus, an extension, or an indexable head; `inspc cones --face` shows the cones".to_string();
    let why = if probe.is_empty() {
        why
    } else if real < need && reach >= need {
        // The probe gets there, but only with the part in a pose it cannot take.
        let mut any = k.empty_cone();
        for &f in &pts {
            any.or_assign(&k.dom[f][p].setup);
        }
        let d = deepest(&any.and(&k.forbidden.not()));
        help = "name a fixture that holds the part so (`fixtures [vise: VISE_150]` on the CMM, `fixtures [vise]` in the plan: a vise, a chuck, a sine or angle plate from `std::fixtures`); `inspc plan --explain-setups` lists the poses the part can take".into();
        format!(
            "probe {probe} reaches {reach} of its {} points only with the part turned so that ({}, {}, {}) points up, a pose in which it does not stand on the table and no fixture of the plan holds it",
            pts.len(),
            fmt_num((d.x * 1e3).round() / 1e3),
            fmt_num((d.y * 1e3).round() / 1e3),
            fmt_num((d.z * 1e3).round() / 1e3)
        )
    } else {
        format!(
            "probe {probe} reaches {reach} of its {} points (it needs {need}); {why}",
            pts.len()
        )
    };
    let (span, feature) = (
        feature.map_or(part.span, |f| f.span),
        feature.map_or_else(|| part.name.clone(), |f| f.name.clone()),
    );
    // One problem, one code: an error, or a warning where `--allow-unmeasured` plans on
    // without the face.
    let (severity, help) = if allowed {
        (
            miette::Severity::Warning,
            format!("{help}; the program leaves it out"),
        )
    } else {
        (miette::Severity::Error, help)
    };
    diags.push_at(
        severity,
        PlanError::UninspectableFace {
            span,
            face: name,
            feature,
            why,
            help,
        },
    );
}

/// What blocks probe `p` at point `f`: the components' cones from the tip up; the first
/// that leaves no direction is named, with the last direction still open.
fn blocking(k: &Knowledge, m: &Machine, p: usize, f: usize) -> (usize, String) {
    let probe = &m.probes[p];
    let c = k.points[f].tip_centre(probe.tip_radius);
    let (n, pref) = (k.opts.n, &k.opts.preferred[..]);
    let mut open = crate::access::gac_halfline(&k.scene, &c, n, pref);
    if open.is_empty() {
        return (
            1,
            "no straight line leaves the tip centre without meeting the part".into(),
        );
    }
    let comps = probe.leading();
    for (depth, comp) in comps.iter().enumerate() {
        let cone = crate::access::gac(
            &crate::access::Cpu,
            &k.scene,
            &c,
            std::slice::from_ref(comp),
            n,
            pref,
        );
        let next = open.and(&cone);
        if next.is_empty() {
            let d = deepest(&open);
            return (
                2 + depth,
                format!(
                    "its {} (Ø{} mm) meets the part from every direction the parts below it leave open; closest along ({}, {}, {})",
                    comp.name,
                    fmt_num(2.0 * comp.radius),
                    fmt_num((d.x * 1e3).round() / 1e3),
                    fmt_num((d.y * 1e3).round() / 1e3),
                    fmt_num((d.z * 1e3).round() / 1e3)
                ),
            );
        }
        open = next;
    }
    let d = deepest(&open);
    (
        2 + comps.len(),
        format!(
            "every component clears the part at the contact along ({}, {}, {}), but not on the way to the retract point, or the head cannot tilt that far",
            fmt_num((d.x * 1e3).round() / 1e3),
            fmt_num((d.y * 1e3).round() / 1e3),
            fmt_num((d.z * 1e3).round() / 1e3)
        ),
    )
}

/// The direction deepest inside a cone (+z when it is empty).
fn deepest(c: &crate::access::CubeMap) -> V3 {
    solve::deepest(c).map_or(V3::z(), |cell| c.direction(cell))
}

/// One warning for a face some of whose touches never validated when generate-and-test
/// ran out of rounds: how many points the plan leaves out, which probe was tried last and
/// what it hit, and the fix for that cause.
pub(super) fn report_left_out(
    input: &Input,
    face: FaceId,
    left: usize,
    iterations: usize,
    (probe, blocker): (&str, &crate::access::pose::Blocker),
    diags: &mut Diagnostics,
) {
    use crate::access::pose::Blocker;
    let part = &input.model.parts[input.plan.part.0];
    let feature = owner(input, face).map(|f| &part.features[f.0]);
    let total = input.graph.face_points(face).len();
    let help = match blocker {
        Blocker::Tip => "the tip meets the part on its way in or out: shorten `motion { retract }` and `prehit`, or use a smaller tip",
        Blocker::TipOnTable | Blocker::ComponentOnTable(_) => {
            "the probe comes down to the table here: a setup or fixture that lifts this face off the table (`fixtures [..]`), or a probe with a longer stylus"
        }
        Blocker::Component(_) => {
            "a longer or thinner stylus, an extension, or another setup (`prefer setup`) gives the probe room"
        }
        Blocker::Fixture(_) => {
            "another fixture, or a setup on the table, leaves this face free; `inspc plan --explain-setups` lists them"
        }
        Blocker::Path => {
            "a longer stylus, another orientation or a larger `motion { clearance }` may open a way to it"
        }
    };
    diags.push(PlanError::PointsLeftOut {
        span: feature.map_or(part.span, |f| f.span),
        face: input.geometry.faces[face.0].name.clone(),
        left,
        total,
        verb: if left == 1 { "is" } else { "are" },
        iterations,
        why: match blocker {
            Blocker::Tip => {
                format!("the tip of probe {probe} meets the part coming in or backing off")
            }
            Blocker::TipOnTable => format!("the tip of probe {probe} comes too near the table"),
            Blocker::Component(c) => format!("the {c} of probe {probe} meets the part"),
            Blocker::ComponentOnTable(c) => {
                format!("the {c} of probe {probe} comes too near the table")
            }
            Blocker::Fixture(c) => format!("the {c} of probe {probe} meets the fixture"),
            Blocker::Path => format!("no collision-free move brings probe {probe} to it"),
        },
        help: help.into(),
    });
}

/// The setups plan `plan` may use on `geometry`, in words: the poses on the table (and
/// why the others are excluded) and what the plan's fixtures can hold.
pub fn explain_setups(
    model: &Model,
    plan: &Plan,
    geometry: &PartGeometry,
    fixtures: &[crate::geometry::FixtureMesh],
) -> String {
    let labels: Vec<String> = model.cmms[plan.cmm.0]
        .fixtures
        .iter()
        .map(|(l, _)| l.clone())
        .collect();
    format!(
        "setups of plan {} (part {}):\n{}",
        plan.name,
        model.parts[plan.part.0].name,
        poses::Setups::new(model, plan, geometry, fixtures).explain(&labels)
    )
}
