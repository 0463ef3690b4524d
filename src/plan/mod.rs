//! Stage 8, the planner (seed ch. 3 and 4): measurement graph + machine → high-level
//! inspection plan (HLIP): setups, probes, probe orientations, and what each inspects.
//!
//! Generate and test: the knowledge base ([`domain`]) holds each fpoint's domain per
//! probe, starting from cheap half-line cones; the solver ([`solve`]) clusters up the
//! graph under the plan's constraint hierarchy with several deterministic clustering
//! strategies ([`cluster`]) and keeps the best plan by the hierarchy's violation counts;
//! every primitive inspection plan of it is validated with parry ([`validate`]); what
//! fails teaches the knowledge base (the whole probe's cones, then removal of the
//! configuration) and the loop repeats. The entry point is [`plan`].
//!
//! **Architecture Invariant:** the result is a function of the input alone: clustering
//! visits sets in graph order, ties go to the lower index, and parallel work (cones,
//! validation) is collected in input order.

pub mod cluster;
mod domain;
mod errors;
mod render;
mod solve;
mod validate;

pub(crate) use domain::lowest;
pub use errors::PlanError;
pub use render::{json, text};

use crate::diag::Diagnostics;
use crate::geometry::{FaceId, PartGeometry, V3};
use crate::graph::{MeasurementGraph, Node};
use crate::model::{fmt_num, Model, Plan, SurfaceKind};
use cluster::{min_hitting_set, Strategy};
use domain::{Knowledge, Machine};
use rayon::prelude::*;
use solve::{Branch, Inst, Kind};
use std::collections::{BTreeMap, BTreeSet};
use validate::Pip;

/// Planner settings.
#[derive(Debug, Clone)]
pub struct PlanOptions {
    /// Cube-map resolution of the cones.
    pub n: u32,
    /// The most generate-and-test rounds before giving up.
    pub max_iterations: usize,
    /// Search nodes for the exact minimum number of setups.
    pub exact_budget: usize,
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            n: 64,
            max_iterations: 40,
            exact_budget: 200_000,
        }
    }
}

/// A high-level inspection plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Hlip {
    /// The plan's name.
    pub plan: String,
    /// The part.
    pub part: String,
    /// The machine.
    pub cmm: String,
    /// The constraint hierarchy.
    pub hierarchy: String,
    /// Whether the head indexes.
    pub indexable: bool,
    /// The setups, in the order they are done.
    pub setups: Vec<SetupNode>,
    /// Every point the plan touches, by index (graph fpoints, then table points).
    pub points: Vec<PointInfo>,
    /// Counts.
    pub summary: Summary,
}

/// One setup: the part resting so that `up` (part frame) points to the ram.
#[derive(Debug, Clone, PartialEq)]
pub struct SetupNode {
    /// The part-frame direction pointing up.
    pub up: [f64; 3],
    /// The rotation part frame → machine frame (rows).
    pub rotation: [[f64; 3]; 3],
    /// Datum faces resting on the table in this setup.
    pub on_table: Vec<String>,
    /// The probes used, in order.
    pub probes: Vec<ProbeNode>,
}

/// One probe in a setup.
#[derive(Debug, Clone, PartialEq)]
pub struct ProbeNode {
    /// The probe's label in the rack.
    pub probe: String,
    /// The orientations used, in order.
    pub orients: Vec<OrientNode>,
}

/// One probe orientation.
#[derive(Debug, Clone, PartialEq)]
pub struct OrientNode {
    /// Head angle A (degrees); 0 for a fixed head.
    pub a: f64,
    /// Head angle B (degrees).
    pub b: f64,
    /// The probe direction, tip to head, in the part frame.
    pub direction: [f64; 3],
    /// What is inspected.
    pub inspections: Vec<Inspection>,
}

/// Inspecting one feature in one configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct Inspection {
    /// The feature.
    pub feature: String,
    /// Its faces (or the table standing in for one) and their points.
    pub faces: Vec<FaceVisit>,
    /// The tolerances whose measurement this records.
    pub records: Vec<String>,
}

/// Points taken on one face.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceVisit {
    /// The face's name.
    pub face: String,
    /// Whether the table is probed instead of the face.
    pub table: bool,
    /// Indices into [`Hlip::points`].
    pub points: Vec<usize>,
}

/// A point of the plan.
#[derive(Debug, Clone, PartialEq)]
pub struct PointInfo {
    /// The face (for table points, the datum face resting on the table).
    pub face: String,
    /// A table point.
    pub table: bool,
    /// Contact position (part frame, mm).
    pub position: [f64; 3],
    /// Surface normal at the contact.
    pub normal: [f64; 3],
}

/// The plan in numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// Setups.
    pub setups: usize,
    /// Distinct probes.
    pub probes_used: usize,
    /// Probe changes in the linear plan (the first load not counted).
    pub probe_changes: usize,
    /// Distinct head orientations (A, B).
    pub orientations: usize,
    /// Orientation changes in the linear plan.
    pub orientation_changes: usize,
    /// Features inspected.
    pub features: usize,
    /// Points touched.
    pub points: usize,
    /// Generate-and-test rounds.
    pub iterations: usize,
    /// Per hierarchy level, violated binary same-constraints.
    pub violations: Vec<(String, u64)>,
    /// Fpoints filtered out as inaccessible or poorly accessible.
    pub dropped_points: usize,
    /// Whole-probe cone computations the validation called for.
    pub cones_acquired: usize,
    /// The fewest setups any plan could have, and whether that is proven (else a lower
    /// bound).
    pub min_setups: (usize, bool),
    /// The clustering strategy of the plan kept.
    pub strategy: String,
}

/// What planning needs.
pub struct Input<'a> {
    /// The model.
    pub model: &'a Model,
    /// The plan.
    pub plan: &'a Plan,
    /// The part's geometry.
    pub geometry: &'a PartGeometry,
    /// The plan's measurement graph.
    pub graph: &'a MeasurementGraph,
}

/// The fewest points a face of a kind needs to be fitted.
fn min_points(kind: SurfaceKind) -> usize {
    match kind {
        SurfaceKind::Plane => 3,
        SurfaceKind::Cylinder => 5,
        SurfaceKind::Cone => 6,
        SurfaceKind::Sphere => 4,
        SurfaceKind::Freeform => 3,
    }
}

/// Plans one plan: the entry point of the planner. Faces that cannot be inspected, and
/// a search that does not settle, are reported in `diags` and give `None`.
pub fn plan(input: &Input, opts: &PlanOptions, diags: &mut Diagnostics) -> Option<Hlip> {
    let (model, plan, g) = (input.model, input.plan, input.graph);
    let hierarchy = &model.hierarchies[plan.hierarchy.0];
    let machine = Machine::new(model, plan);
    // Datum faces that can rest on the table.
    let mut table_faces: Vec<FaceId> = Vec::new();
    for (n, node) in g.nodes() {
        if let Node::Feature { datums, .. } = node {
            if datums.is_empty() {
                continue;
            }
            for (c, _) in g.children(n) {
                if let Node::Face {
                    face,
                    on_table: true,
                } = g.graph[c]
                {
                    if !table_faces.contains(&face) {
                        table_faces.push(face);
                    }
                }
            }
        }
    }
    let cone_opts = crate::access::ConeOptions {
        n: opts.n,
        // The approach validated is the longer of the pre-hit and retract moves.
        retract: input.plan.motion.prehit.max(input.plan.motion.retract),
        ..Default::default()
    };
    let mut k = Knowledge::new(
        plan,
        &machine,
        input.geometry,
        &g.fpoints,
        &table_faces,
        cone_opts,
    );
    let mut validated: BTreeSet<Pip> = BTreeSet::new();
    let mut last = String::from("no round was run");
    for iteration in 1..=opts.max_iterations {
        let (dropped, bad) = filter(g, input.geometry, &k, &machine);
        if !bad.is_empty() {
            // Know the whole probe before blaming a face.
            let pairs: Vec<(usize, usize)> = bad
                .iter()
                .flat_map(|f| face_points(g, *f))
                .flat_map(|f| (0..machine.probes.len()).map(move |p| (f, p)))
                .collect();
            let before = k.acquired;
            k.acquire_many(&pairs, &machine);
            if k.acquired > before && iteration < opts.max_iterations {
                let (_, bad2) = filter(g, input.geometry, &k, &machine);
                if bad2.is_empty() {
                    continue;
                }
            }
            let (_, bad) = filter(g, input.geometry, &k, &machine);
            for face in bad {
                report_face(input, &k, &machine, face, diags);
            }
            return None;
        }
        let Some(root) = solve::unfold(g, &k, &machine, &dropped) else {
            return Some(build(
                input,
                &k,
                &machine,
                &[],
                iteration,
                dropped.len(),
                "—",
            ));
        };
        let mut results: Vec<(Strategy, Vec<Branch>)> = Vec::new();
        let mut failures = Vec::new();
        for strategy in Strategy::ALL {
            match solve::solve(&root, &mut k, &machine, hierarchy, strategy) {
                Ok(b) => results.push((strategy, b)),
                Err(f) => failures.extend(f),
            }
        }
        if results.is_empty() {
            last = format!("{} points found no probe orientation", failures.len());
            learn(
                &mut k,
                &machine,
                failures
                    .iter()
                    .map(|f| (f.point, f.probe, f.setup, f.orient))
                    .collect(),
            );
            continue;
        }
        let best = results
            .iter()
            .min_by_key(|(_, b)| score(b, &machine, hierarchy))
            .map(|(s, b)| (*s, b.clone()))
            .expect("at least one result");
        let mut pips: Vec<(Pip, V3)> = Vec::new();
        for b in &best.1 {
            let mut pts = Vec::new();
            solve::leaves(&b.tree, &mut pts);
            for p in pts {
                pips.push((
                    Pip {
                        point: p,
                        probe: b.probe,
                        setup: b.setup,
                        orient: b.orient,
                    },
                    b.up,
                ));
            }
        }
        pips.sort_by_key(|(p, _)| *p);
        pips.dedup_by_key(|(p, _)| *p);
        pips.retain(|(p, _)| !validated.contains(p));
        let heights: BTreeMap<usize, f64> = pips
            .iter()
            .map(|(p, _)| (p.setup, k.table_height(p.setup)))
            .collect();
        let checked: Vec<(Pip, Option<String>)> = pips
            .par_iter()
            .map(|(p, up)| (*p, validate::check(&k, &machine, p, up, heights[&p.setup])))
            .collect();
        let mut invalid = Vec::new();
        for (p, what) in checked {
            match what {
                None => {
                    validated.insert(p);
                }
                Some(w) => {
                    last = format!(
                        "probe {} at a point of {} hits {}",
                        machine.probes[p.probe].name,
                        face_name(input, &k, p.point),
                        w
                    );
                    invalid.push((p.point, p.probe, p.setup, machine.bent.then_some(p.orient)));
                }
            }
        }
        if invalid.is_empty() {
            debug_assert!(
                audit(&mut k, &machine, &best.1).is_empty(),
                "{:?}",
                audit(&mut k, &machine, &best.1)
            );
            return Some(build(
                input,
                &k,
                &machine,
                &best.1,
                iteration,
                dropped.len(),
                best.0.name(),
            ));
        }
        learn(&mut k, &machine, invalid);
    }
    diags.push(
        plan.span.file,
        PlanError::NoConvergence {
            span: plan.span,
            plan: plan.name.clone(),
            iterations: opts.max_iterations,
            last,
        },
    );
    None
}

/// The configurations of a plan that lie outside their point's domain (there should be
/// none): setup in the point's setups (or its table alternative), probe among those
/// reaching it there, orientation in D1′.
fn audit(k: &mut Knowledge, m: &Machine, branches: &[Branch]) -> Vec<String> {
    let mut out = Vec::new();
    for b in branches {
        let mut pts = Vec::new();
        solve::leaves(&b.tree, &mut pts);
        for f in pts {
            let ok = if f >= k.graph_points {
                k.tables
                    .iter()
                    .any(|t| t.points.contains(&f) && t.cell == b.setup && t.alive)
            } else {
                cluster::Set::has(&k.setups(f, m), b.setup)
                    && cluster::Set::has(&k.probes(f, b.setup, m), b.probe)
            };
            let o_ok = cluster::Set::has(&k.orientations(f, b.probe, b.setup, &b.up, m), b.orient);
            if !ok || !o_ok {
                out.push(format!(
                    "point {f}: setup {} probe {} orientation {}",
                    b.setup, b.probe, b.orient
                ));
            }
        }
    }
    out
}

/// What makes one plan better than another: the hierarchy's violations level by level,
/// then fewer setups, probe changes and orientation changes.
fn score(
    b: &[Branch],
    m: &Machine,
    h: &crate::model::Hierarchy,
) -> (Vec<u64>, usize, usize, usize) {
    let v = solve::violations(b, m, h);
    let setups: BTreeSet<usize> = b.iter().map(|x| x.setup).collect();
    let (pc, oc) = changes(b, m);
    (v, setups.len(), pc, oc)
}

/// Probe and orientation changes of branches taken in order.
fn changes(b: &[Branch], m: &Machine) -> (usize, usize) {
    let mut pc = 0;
    let mut oc = 0;
    for w in b.windows(2) {
        pc += usize::from(w[0].probe != w[1].probe);
        oc += usize::from(m.bent && m.grid[w[0].orient] != m.grid[w[1].orient]);
    }
    (pc, oc)
}

/// Teaches the knowledge base what failed: whole-probe cones for points known only by
/// half-lines (in parallel), removal of the configuration for the others.
fn learn(k: &mut Knowledge, m: &Machine, mut fails: Vec<(usize, usize, usize, Option<usize>)>) {
    fails.sort();
    fails.dedup();
    let full: Vec<bool> = fails
        .iter()
        .map(|&(f, p, _, _)| f >= k.graph_points || k.dom[f][p].full)
        .collect();
    // Neighbours on a face fail together and are clustered together (ch. 4.2): better
    // knowledge of a few of them usually moves the whole face, so acquire at most
    // ACQUIRE_PER_FACE points per face and probe in a round.
    let mut per_face: BTreeMap<(usize, usize), usize> = BTreeMap::new();
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    for (&(f, p, _, _), &full) in fails.iter().zip(&full) {
        let n = per_face.entry((k.points[f].face.0, p)).or_default();
        if !full && *n < ACQUIRE_PER_FACE && !pairs.contains(&(f, p)) {
            *n += 1;
            pairs.push((f, p));
        }
    }
    k.acquire_many(&pairs, m);
    for (&(f, p, s, o), full) in fails.iter().zip(full) {
        if full {
            k.reject(f, p, s, o, m);
        }
    }
}

/// How many points per face and probe get the whole probe's cones in one round.
const ACQUIRE_PER_FACE: usize = 2;

/// The fpoints of a face, by index.
fn face_points(g: &MeasurementGraph, face: FaceId) -> Vec<usize> {
    (0..g.fpoints.len())
        .filter(|&i| g.fpoints[i].face == face)
        .collect()
}

/// Drops fpoints no probe reaches and, while a face keeps enough, those reached from
/// under a twentieth of the face's median count of setups (ch. 3.6.3). Returns the
/// dropped fpoints and the faces left with too few.
fn filter(
    g: &MeasurementGraph,
    geo: &PartGeometry,
    k: &Knowledge,
    m: &Machine,
) -> (BTreeSet<usize>, Vec<FaceId>) {
    let mut by_face: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (i, f) in g.fpoints.iter().enumerate() {
        by_face.entry(f.face.0).or_default().push(i);
    }
    let mut dropped = BTreeSet::new();
    let mut bad = Vec::new();
    for (face, pts) in by_face {
        let on_table = k.tables.iter().any(|t| t.face.0 == face && t.alive);
        if on_table {
            // The table can stand in for the whole face where it is a datum; elsewhere
            // the unreachable points drop out when the graph is unfolded.
            continue;
        }
        let need = min_points(geo.faces[face].surface.kind()).min(pts.len());
        let sizes: Vec<usize> = pts.iter().map(|&p| k.setups(p, m).count()).collect();
        let mut keep: Vec<(usize, usize)> = pts
            .iter()
            .zip(&sizes)
            .filter(|(_, &s)| s > 0)
            .map(|(&p, &s)| (p, s))
            .collect();
        for (&p, &s) in pts.iter().zip(&sizes) {
            if s == 0 {
                dropped.insert(p);
            }
        }
        if keep.len() < need {
            bad.push(FaceId(face));
            continue;
        }
        let mut sorted: Vec<usize> = keep.iter().map(|x| x.1).collect();
        sorted.sort_unstable();
        let median = sorted[sorted.len() / 2];
        let floor = need.max(pts.len().div_ceil(2));
        keep.sort_by_key(|&(p, s)| (s, p));
        let mut left = keep.len();
        for &(p, s) in &keep {
            if left <= floor || s * 20 >= median {
                break;
            }
            dropped.insert(p);
            left -= 1;
        }
    }
    (dropped, bad)
}

fn face_name(input: &Input, k: &Knowledge, point: usize) -> String {
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
fn report_face(input: &Input, k: &Knowledge, m: &Machine, face: FaceId, diags: &mut Diagnostics) {
    let part = &input.model.parts[input.plan.part.0];
    let feature = owner(input, face).map(|f| &part.features[f.0]);
    let pts = face_points(input.graph, face);
    let name = input.geometry.faces[face.0].name.clone();
    let need = min_points(input.geometry.faces[face.0].surface.kind()).min(pts.len());
    // Per probe: how many points it reaches, and the first blocking component.
    let mut best: Option<(usize, usize, String, String)> = None;
    for (p, probe) in m.probes.iter().enumerate() {
        if !m.allowed[p] {
            continue;
        }
        let reach = pts
            .iter()
            .filter(|&&f| k.dom[f][p].tip && !k.dom[f][p].setup.is_empty())
            .count();
        let tips = pts.iter().filter(|&&f| k.dom[f][p].tip).count();
        let (depth, why) = if tips == 0 {
            (
                0,
                format!(
                    "probe {}'s Ø{} mm tip does not fit at any of its {} points",
                    probe.name,
                    fmt_num(2.0 * probe.tip_radius),
                    pts.len()
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
        let cand = (reach, depth, why, probe.name.clone());
        if best.as_ref().is_none_or(|b| (cand.0, cand.1) > (b.0, b.1)) {
            best = Some(cand);
        }
    }
    let (reach, _, why, probe) =
        best.unwrap_or((0, 0, "no probe is allowed".into(), String::new()));
    let why = if probe.is_empty() {
        why
    } else {
        format!(
            "probe {probe} reaches {reach} of its {} points (it needs {need}); {why}",
            pts.len()
        )
    };
    let help = "use a smaller tip, a longer or thinner stylus, an extension, or an indexable head; `inspc cones --face` shows the cones".to_string();
    diags.push(
        feature.map_or(part.span.file, |f| f.span.file),
        PlanError::UninspectableFace {
            span: feature.map_or(part.span, |f| f.span),
            face: name,
            feature: feature.map_or_else(|| part.name.clone(), |f| f.name.clone()),
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
    let comps = if m.bent {
        probe.first.clone()
    } else {
        probe.straight()
    };
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

/// Assembles the HLIP tree from the branches.
fn build(
    input: &Input,
    k: &Knowledge,
    m: &Machine,
    branches: &[Branch],
    iterations: usize,
    dropped: usize,
    strategy: &str,
) -> Hlip {
    let model = input.model;
    let part = &model.parts[input.plan.part.0];
    let geo = input.geometry;
    let hierarchy = &model.hierarchies[input.plan.hierarchy.0];
    // Group branches by setup (first appearance), then probe, then orientation.
    // (setup, up, [(probe, [(orientation, trees)])])
    type Probes<'a> = Vec<(usize, Vec<(usize, Vec<&'a Inst>)>)>;
    let mut setups: Vec<(usize, V3, Probes)> = Vec::new();
    for b in branches {
        let si = match setups.iter().position(|s| s.0 == b.setup) {
            Some(i) => i,
            None => {
                setups.push((b.setup, b.up, vec![]));
                setups.len() - 1
            }
        };
        let probes = &mut setups[si].2;
        let pi = match probes.iter().position(|p| p.0 == b.probe) {
            Some(i) => i,
            None => {
                probes.push((b.probe, vec![]));
                probes.len() - 1
            }
        };
        let orients = &mut probes[pi].1;
        match orients.iter_mut().find(|o| o.0 == b.orient) {
            Some(o) => o.1.push(&b.tree),
            None => orients.push((b.orient, vec![&b.tree])),
        }
    }
    // Start each setup with the probe the last one ended with.
    let mut last_probe: Option<usize> = None;
    for s in setups.iter_mut() {
        if let Some(lp) = last_probe {
            if let Some(i) = s.2.iter().position(|p| p.0 == lp) {
                let p = s.2.remove(i);
                s.2.insert(0, p);
            }
        }
        last_probe = s.2.last().map(|p| p.0);
    }
    let mut used_points: BTreeSet<usize> = BTreeSet::new();
    let mut features: BTreeSet<String> = BTreeSet::new();
    let mut seq: Vec<(usize, (u64, u64))> = Vec::new();
    let mut out_setups = Vec::new();
    for (_, up, probes) in &setups {
        let rot = domain::frame(up);
        let mut on_table = Vec::new();
        let mut pnodes = Vec::new();
        for (p, orients) in probes {
            let mut onodes = Vec::new();
            for (o, trees) in orients {
                let (a, b) = m.grid[*o];
                let dir = if m.bent {
                    domain::orientation_dir(up, a, b)
                } else {
                    *up
                };
                seq.push((*p, (a.to_bits(), b.to_bits())));
                let mut insp: Vec<Inspection> = Vec::new();
                for t in trees {
                    collect(t, None, None, &mut |tol, feat, face, table, pts| {
                        let fname = feat
                            .map_or_else(|| "—".to_string(), |f| part.features[f.0].name.clone());
                        features.insert(fname.clone());
                        used_points.extend(pts.iter().copied());
                        let fcname = geo.faces[face.0].name.clone();
                        if table && !on_table.contains(&fcname) {
                            on_table.push(fcname.clone());
                        }
                        let i = match insp.iter().position(|x| x.feature == fname) {
                            Some(i) => i,
                            None => {
                                insp.push(Inspection {
                                    feature: fname.clone(),
                                    faces: vec![],
                                    records: vec![],
                                });
                                insp.len() - 1
                            }
                        };
                        let x = &mut insp[i];
                        match x
                            .faces
                            .iter_mut()
                            .find(|v| v.face == fcname && v.table == table)
                        {
                            Some(v) => {
                                v.points.extend(pts.iter().copied());
                                v.points.sort_unstable();
                                v.points.dedup();
                            }
                            None => x.faces.push(FaceVisit {
                                face: fcname,
                                table,
                                points: pts.to_vec(),
                            }),
                        }
                        if let Some(t) = tol {
                            let tn = part.tolerances[t].name.clone();
                            if !x.records.contains(&tn) {
                                x.records.push(tn);
                            }
                        }
                    });
                }
                onodes.push(OrientNode {
                    a,
                    b,
                    direction: round3(&dir),
                    inspections: insp,
                });
            }
            pnodes.push(ProbeNode {
                probe: m.probes[*p].name.clone(),
                orients: onodes,
            });
        }
        let r = rot.matrix();
        out_setups.push(SetupNode {
            up: round3(up),
            rotation: [0, 1, 2].map(|i| [0, 1, 2].map(|j| round(r[(i, j)]))),
            on_table,
            probes: pnodes,
        });
    }
    let probe_changes = seq.windows(2).filter(|w| w[0].0 != w[1].0).count();
    let orientation_changes = if m.bent {
        seq.windows(2).filter(|w| w[0].1 != w[1].1).count()
    } else {
        0
    };
    let orientations: BTreeSet<(u64, u64)> = seq.iter().map(|s| s.1).collect();
    let probes_used: BTreeSet<usize> = seq.iter().map(|s| s.0).collect();
    let v = solve::violations(branches, m, hierarchy);
    // The fewest setups: a hitting set of the points' setup sets.
    let mut sets: Vec<crate::access::CubeMap> = Vec::new();
    let mut faces_seen = BTreeSet::new();
    for (i, f) in k.points[..k.graph_points].iter().enumerate() {
        if !used_points.contains(&i) {
            continue;
        }
        let mut s = k.setups(i, m);
        if let Some(t) = k.tables.iter().find(|t| t.face == f.face && t.alive) {
            let c = s.cell(t.cell);
            s.set(c, true);
        }
        if !s.is_empty() && !sets.contains(&s) {
            sets.push(s);
        }
        faces_seen.insert(f.face);
    }
    let refs: Vec<&crate::access::CubeMap> = sets.iter().collect();
    let min_setups = min_hitting_set(&refs, 200_000);
    let points = k
        .points
        .iter()
        .enumerate()
        .map(|(i, f)| PointInfo {
            face: geo.faces[f.face.0].name.clone(),
            table: i >= k.graph_points,
            position: round3(&f.position.coords),
            normal: round3(&f.normal),
        })
        .collect();
    Hlip {
        plan: input.plan.name.clone(),
        part: part.name.clone(),
        cmm: model.cmms[input.plan.cmm.0].name.clone(),
        hierarchy: hierarchy.name.clone(),
        indexable: m.bent,
        summary: Summary {
            setups: out_setups.len(),
            probes_used: probes_used.len(),
            probe_changes,
            orientations: orientations.len(),
            orientation_changes,
            features: features.len(),
            points: used_points.len(),
            iterations,
            violations: hierarchy
                .levels
                .iter()
                .zip(v)
                .map(|(l, c)| (crate::resolve::level_text(l.var, l.group), c))
                .collect(),
            dropped_points: dropped,
            cones_acquired: k.acquired,
            min_setups,
            strategy: strategy.to_string(),
        },
        setups: out_setups,
        points,
    }
}

/// A face visit: (tolerance, feature, face, on the table, points).
type Visit<'a> =
    dyn FnMut(Option<usize>, Option<crate::model::FeatureId>, FaceId, bool, &[usize]) + 'a;

/// Walks an instance tree, calling `f(tolerance, feature, face, table, points)` for every
/// face or table visit.
fn collect(i: &Inst, tol: Option<usize>, feat: Option<crate::model::FeatureId>, f: &mut Visit) {
    match &i.kind {
        Kind::Tol(t) => i
            .children
            .iter()
            .for_each(|c| collect(c, Some(*t), feat, f)),
        Kind::Feature(x) => i.children.iter().for_each(|c| collect(c, tol, Some(*x), f)),
        Kind::Face { face, .. } | Kind::Table { face } => {
            let mut pts = Vec::new();
            solve::leaves(i, &mut pts);
            pts.sort_unstable();
            pts.dedup();
            f(tol, feat, *face, matches!(i.kind, Kind::Table { .. }), &pts);
        }
        _ => i.children.iter().for_each(|c| collect(c, tol, feat, f)),
    }
}

fn round(x: f64) -> f64 {
    let r = (x * 1e6).round() / 1e6;
    if r == 0.0 {
        0.0
    } else {
        r
    }
}

fn round3(v: &V3) -> [f64; 3] {
    [round(v.x), round(v.y), round(v.z)]
}
