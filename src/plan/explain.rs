//! Explaining a failed plan: for a face no configuration inspects, which probe came
//! closest, from where, and what stopped it.

use super::errors::{Stop, Unreachable};
use super::filter::min_points;
use super::knowledge::Knowledge;
use super::machine::Machine;
use super::{poses, solve, Input, PlanError};
use crate::diag::Diagnostics;
use crate::geometry::PartGeometry;
use crate::geometry::{FaceId, V3};
use crate::graph::Node;
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
    let mut best: Option<(usize, usize, usize, Stop, usize)> = None;
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
        // Where the tip fits at too few points, that is the cause, whatever blocks the
        // probe at the points where it fits.
        let fits = pts.iter().filter(|&&f| k.dom[f][p].tip).count();
        let no_fit = || Stop::TipDoesNotFit {
            probe: probe.name.clone(),
            diameter: 2.0 * probe.tip_radius,
            points: pts.len(),
            fits,
            travel: crate::access::pose::MIN_TRAVEL,
        };
        let (depth, stop) = match pts.iter().copied().find(|&f| k.dom[f][p].tip) {
            None => (0, no_fit()),
            Some(f) if fits < need => (blocking(k, m, p, f).0, no_fit()),
            Some(f) => blocking(k, m, p, f),
        };
        if best
            .as_ref()
            .is_none_or(|b| (real, reach, depth) > (b.0, b.1, b.2))
        {
            best = Some((real, reach, depth, stop, p));
        }
    }
    let why = match best {
        None => Unreachable::NoProbeAllowed,
        Some((real, reach, _, _, p)) if real < need && reach >= need => {
            // The probe gets there, but only with the part in a pose it cannot take.
            let mut any = k.empty_cone();
            for &f in &pts {
                any.or_assign(&k.dom[f][p].setup);
            }
            Unreachable::OnlyInPose {
                probe: m.probes[p].name.clone(),
                reach,
                points: pts.len(),
                up: deepest(&any.and(&k.forbidden.not())),
            }
        }
        Some((_, reach, _, stop, p)) => Unreachable::TooFew {
            probe: m.probes[p].name.clone(),
            reach,
            points: pts.len(),
            need,
            stop,
        },
    };
    let (span, feature) = (
        feature.map_or(part.span, |f| f.span),
        feature.map_or_else(|| part.name.clone(), |f| f.name.clone()),
    );
    // One problem, one code: an error, or a warning where `--allow-unmeasured` plans on
    // without the face.
    let severity = if allowed {
        miette::Severity::Warning
    } else {
        miette::Severity::Error
    };
    diags.push_at(
        severity,
        PlanError::UninspectableFace {
            span,
            face: name,
            feature,
            why,
            allowed,
        },
    );
}

/// What blocks probe `p` at point `f`: the components' cones from the tip up; the first
/// that leaves no direction is named, with the last direction still open.
fn blocking(k: &Knowledge, m: &Machine, p: usize, f: usize) -> (usize, Stop) {
    let probe = &m.probes[p];
    let c = k.points[f].tip_centre(probe.tip_radius);
    let (n, pref) = (k.opts.n, &k.opts.preferred[..]);
    let mut open = crate::access::gac_halfline(&k.scene, &c, n, pref);
    if open.is_empty() {
        return (1, Stop::NoLine);
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
            let stop = Stop::Component {
                name: comp.name.clone(),
                diameter: 2.0 * comp.radius,
                closest: deepest(&open),
            };
            return (2 + depth, stop);
        }
        open = next;
    }
    let closest = deepest(&open);
    (2 + comps.len(), Stop::OnTheWay { closest })
}

/// The direction deepest inside a cone (+z when it is empty).
fn deepest(c: &crate::access::CubeMap) -> V3 {
    solve::deepest(c).map_or(V3::z(), |cell| c.direction(cell))
}

/// One warning for a face some of whose touches never validated when generate-and-test
/// ran out of rounds: how many of its points (distinct points, of the face or of the
/// table under it) the plan leaves out, which probe was tried last and what it hit, and
/// the fix for that cause.
pub(super) fn report_left_out(
    input: &Input,
    (face, on_table): (FaceId, bool),
    (left, total): (usize, usize),
    iterations: usize,
    (probe, blocker): (&str, &crate::access::pose::Blocker),
    diags: &mut Diagnostics,
) {
    let part = &input.model.parts[input.plan.part.0];
    let feature = owner(input, face).map(|f| &part.features[f.0]);
    diags.push(PlanError::PointsLeftOut {
        span: feature.map_or(part.span, |f| f.span),
        face: input.geometry.faces[face.0].name.clone(),
        on_table,
        left,
        total,
        iterations,
        probe: probe.to_string(),
        blocker: blocker.clone(),
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
