//! Stage 8, the planner (seed ch. 3 and 4): measurement graph + machine → high-level
//! inspection plan (HLIP): setups, probes, probe orientations, and what each inspects.
//!
//! The four strategies are weighted, smallest first, graph order and reverse; the round
//! keeps the best plan by the hierarchy's violations, then setups and changes, and
//! validates its PIPs in parallel, each once. [`plan_with`] and a [`Memo`] keep the
//! pure results (cones, D2 caps, depth maps, grid orientations, the scene) for a
//! re-plan of the same input; the path stage's attempts share its scene.
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
//!
//! **Decision: learning.** A failed PIP first buys its point the whole probe's cones
//! (at most two points per face and probe a round: neighbours cluster together, ch.
//! 4.2); once the point has them, the failing setup is removed (its pixel and
//! neighbours for a fixed head; a 5° cap for a bent probe with no orientation left
//! there) (`learn`).
//!
//! **Decision: filtering** (ch. 3.6.3, `filter`) drops fpoints no probe reaches, and
//! those reached from under a twentieth of the face's median setups while the face
//! keeps half its points and its minimum (3 on a plane, 5 on a cylinder, 6 on a cone, 4
//! on a sphere); a face below its minimum is `insp::plan::uninspectable_face`. The end
//! circles of a round face whose axis a tolerance or datum reads are spared
//! (`axes::end_circles`). Where points drop, or a datum is measured again on the points
//! one setup reaches (`remeasure`), a plane keeps points spread across an area
//! (`spans_area`: a second principal spread of at least 0.5 mm), never a row a plane
//! cannot be fitted to.
//!
//! **Decision: how plans are compared** (`score`): the hierarchy's levels first
//! (violated same-constraints, level by level), then setups, probe changes, orientation
//! changes. Preferences act inside clustering: a preferred setup is picked for a
//! cluster whenever its underlying set holds it (`solve::pick_setup`), so it is used
//! whenever a plan there costs no more than one elsewhere at every level above.
//!
//! **Decision: robust to the part set off square** (`plan_placed`). The program follows
//! the part (its alignment finds it), but an indexed probe keeps its machine direction:
//! with the part turned about the vertical the stylus stands turned in the part's
//! frame, and a stylus deep in a bore with little room beside its stem touches the
//! wall. Every touch is validated also with the part turned `validate::PLACEMENT_TURN`
//! (3°, a part set by eye) either way; a point whose configurations collide only turned
//! takes one clear at the nominal pose after `FRAGILE_AFTER` (6) tries, and where no
//! turned plan settles (or none the path stage routes after its re-plans,
//! `Memo::give_up_turned`) the plan is made at the nominal pose. A setup with touches
//! clear only nearer square says by how much in its prompt and warns
//! `insp::plan::placement_sensitive` (`placement`). The turned validation triples the
//! pose checks, and a part no turned plan settles for is planned twice.
//!
//! **Decision: unmeasured tolerances are errors** (`account`). After planning, every
//! face of every feature and datum feature of each tolerance must be touched; one that
//! is not fails the build (`insp::plan::unmeasured`) unless `--allow-unmeasured`, which
//! also plans around a face no probe inspects
//! (`insp::plan::uninspectable_face_allowed`) instead of stopping.

mod axes;
pub mod cluster;
mod domain;
mod errors;
mod explain;
mod fallback;
mod hlip;
mod machine;
mod placement;
pub mod poses;
mod remeasure;
mod render;
mod scan;
mod solve;
mod validate;

pub use errors::PlanError;
pub use hlip::{
    FaceVisit, Hlip, Inspection, OrientNode, PlanPoint, PointRef, ProbeNode, SetupNode, Summary,
    STEPS_PER_MM,
};
pub use machine::check_machine;
pub use render::{json, text, Names};

use crate::diag::Diagnostics;
use crate::geometry::{FaceId, PartGeometry, V3};
use crate::graph::{MeasurementGraph, Node};
use crate::model::{Model, Plan, PlanId, SurfaceKind};
use cluster::Strategy;
pub use domain::Memo;
use domain::{Knowledge, Machine};
use explain::{face_name, report_face};
use fallback::Fallback;
use hlip::{assemble, Round};
use rayon::prelude::*;
use solve::Branch;
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
    /// Tolerances the plan cannot measure are warnings, not errors.
    pub allow_unmeasured: bool,
    /// Configurations the path stage found no move to: validation fails them.
    pub bans: Vec<Ban>,
    /// Which backend computes the cones.
    pub backend: crate::access::BackendKind,
}

/// A touch configuration the path stage could not reach: the point (index into
/// [`Hlip::points`]), the probe (rack index), the setup's up direction and the probe's
/// direction, both in the part frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Ban {
    /// The point.
    pub point: usize,
    /// The probe's rack index.
    pub probe: usize,
    /// The setup: the part direction facing the ram.
    pub up: V3,
    /// The probe direction, tip to head.
    pub dir: V3,
}

impl Ban {
    /// Whether the configuration is this one (directions to within the plan's
    /// quantisation, [`STEPS_PER_MM`]).
    pub(crate) fn is(&self, point: usize, probe: usize, up: &V3, dir: &V3) -> bool {
        let eps = 10.0 / STEPS_PER_MM;
        self.point == point
            && self.probe == probe
            && (self.up - up).norm() < eps
            && (self.dir - dir).norm() < eps
    }
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            n: 64,
            max_iterations: 40,
            exact_budget: 200_000,
            allow_unmeasured: false,
            bans: Vec::new(),
            backend: crate::access::BackendKind::Cpu,
        }
    }
}

/// What planning needs.
pub struct Input<'a> {
    /// The model.
    pub model: &'a Model,
    /// The plan.
    pub plan: &'a Plan,
    /// The part's geometry.
    pub geometry: &'a PartGeometry,
    /// The mesh fixtures placed with the part.
    pub fixtures: &'a [crate::geometry::FixtureMesh],
    /// The plan's measurement graph.
    pub graph: &'a MeasurementGraph,
}

impl Input<'_> {
    /// The plan's id in the model.
    pub fn plan_id(&self) -> PlanId {
        PlanId(
            self.model
                .plans
                .iter()
                .position(|p| std::ptr::eq(p, self.plan))
                .unwrap_or(0),
        )
    }
}

/// The fewest points a face of a kind needs to be fitted.
pub(crate) fn min_points(kind: SurfaceKind) -> usize {
    match kind {
        SurfaceKind::Plane => 3,
        SurfaceKind::Cylinder => 5,
        SurfaceKind::Cone => 6,
        SurfaceKind::Sphere => 4,
        SurfaceKind::Freeform => 3,
    }
}

/// Counts the tolerances the plan measures — every face of their features and datum
/// features touched or scanned — and reports each one it does not (an error unless
/// `allow_unmeasured`), naming the first face it misses and why; `uncovered` are the
/// faces the plan asked the scanner for that it cannot cover enough.
fn account(
    input: &Input,
    mut hlip: Hlip,
    opts: &PlanOptions,
    uncovered: &[scan::Uncovered],
    diags: &mut Diagnostics,
) -> Hlip {
    let part = &input.model.parts[input.plan.part.0];
    let g = input.graph;
    // Per face the distinct points the plan touches on it (or on the table under it).
    let mut touches: BTreeMap<FaceId, BTreeSet<usize>> = BTreeMap::new();
    for s in &hlip.setups {
        for p in &s.probes {
            for o in &p.orients {
                for i in &o.inspections {
                    for f in &i.faces {
                        touches.entry(f.face).or_default().extend(&f.points);
                    }
                }
            }
        }
    }
    // Per feature its faces, per face whether sampling gave it points.
    let mut faces_of: BTreeMap<crate::model::FeatureId, Vec<FaceId>> = BTreeMap::new();
    let mut sampled: BTreeSet<FaceId> = BTreeSet::new();
    for (n, node) in g.nodes() {
        match node {
            Node::Feature { feature, .. } => {
                for (c, _) in g.children(n) {
                    if let Node::Face { face, .. } = g.graph[c] {
                        faces_of.entry(*feature).or_default().push(face);
                    }
                }
            }
            Node::Face { face, .. } if !g.children(n).is_empty() => {
                sampled.insert(*face);
            }
            _ => {}
        }
    }
    // A face is measured with as many points as its surface's fit needs (fewer only
    // where sampling gave it fewer).
    let mut touched: BTreeSet<FaceId> = touches
        .iter()
        .filter(|(face, pts)| {
            let sampled = face_points(g, **face).len();
            let need = min_points(input.geometry.faces[face.0].surface.kind()).min(sampled.max(1));
            pts.len() >= need
        })
        .map(|(face, _)| *face)
        .collect();
    // A scanned face is measured: the scan stage placed it only where its passes reach
    // the plan's coverage.
    touched.extend(hlip.scans.iter().map(|s| s.face));
    let mut measured = 0;
    for t in &part.tolerances {
        let features = t
            .targets
            .iter()
            .copied()
            .chain(t.datums.iter().map(|d| part.datums[d.datum.0].feature));
        let missing = features.into_iter().find_map(|f| {
            faces_of
                .get(&f)
                .into_iter()
                .flatten()
                .find(|face| !touched.contains(face))
                .map(|&face| (f, face))
        });
        let Some((f, face)) = missing else {
            measured += 1;
            continue;
        };
        let few = touches.get(&face).map_or(0, |p| p.len());
        let short = uncovered.iter().find(|u| u.feature == f);
        let (why, help) = if let Some(u) = short {
            (
                format!(
                    "is asked of the laser scanner, which sees {} % of {} at best (the plan asks {} %)",
                    crate::model::fmt_num((u.best * 1000.0).round() / 10.0),
                    if u.face == face {
                        "it".to_string()
                    } else {
                        format!("face {}", input.geometry.faces[u.face.0].name)
                    },
                    crate::model::fmt_num((input.plan.scan_coverage * 1000.0).round() / 10.0)
                ),
                "touch it instead (`sensors { … touch }`), hold the part so the scanner sees more of it (a fixture), or lower `scan_coverage`".to_string(),
            )
        } else if few > 0 {
            (
                format!(
                    "gets {few} {} in the plan, fewer than its surface's fit needs",
                    if few == 1 { "touch" } else { "touches" }
                ),
                "its other points were left out as hard to reach; a probe that reaches more of them, or more points (`sample`), keeps it".to_string(),
            )
        } else if sampled.contains(&face) {
            (
                "gets no touch in the plan".to_string(),
                "its points were dropped as hard to reach; a probe that reaches more of them, or more points (`sample`), keeps it".to_string(),
            )
        } else {
            (
                "gets no measuring point".to_string(),
                "no point of it keeps the sampling margin from its edges; lower the sampling inset"
                    .to_string(),
            )
        };
        let (tolerance, feature, face) = (
            t.name.clone(),
            part.features[f.0].name.clone(),
            input.geometry.faces[face.0].name.clone(),
        );
        if opts.allow_unmeasured {
            diags.push(PlanError::UnmeasuredAllowed {
                span: t.span,
                tolerance,
                feature,
                face,
                why,
                help,
            });
        } else {
            diags.push(PlanError::Unmeasured {
                span: t.span,
                tolerance,
                feature,
                face,
                why,
                help,
            });
        }
    }
    hlip.summary.tolerances = (measured, part.tolerances.len());
    axes::short_axes(input, &touches, &faces_of, diags);
    hlip
}

/// Why a plan has more setups than the proven minimum, when the hierarchy is the cause:
/// clustered again without its per-tolerance and per-feature `same_setup` levels (the
/// `(*, *)` level kept), the plan needs fewer setups; those levels are named.
fn forcing_levels(
    root: &solve::Inst,
    k: &mut Knowledge,
    m: &Machine,
    h: &crate::model::Hierarchy,
    branches: &[Branch],
) -> Option<String> {
    use crate::model::{Group, SameVar};
    let count = |b: &[Branch]| b.iter().map(|x| x.setup).collect::<BTreeSet<_>>().len();
    let used = count(branches);
    let grouped = |l: &&crate::model::Level| l.var == SameVar::Setup && l.group != Group::All;
    let names: Vec<String> = h.levels.iter().filter(grouped).map(|l| l.text()).collect();
    if names.is_empty() {
        return None;
    }
    let mut relaxed = h.clone();
    relaxed.levels.retain(|l| !grouped(&l));
    let sets = solve::setup_sets(root, k, m);
    let trees = solve::setup_trees(root, k, &relaxed, &sets);
    let fewest = Strategy::ALL
        .into_iter()
        .zip(trees)
        .filter_map(|(s, tree)| solve::solve(root, k, m, &relaxed, s, tree).ok())
        .map(|b| count(&b))
        .min()?;
    (fewest < used).then(|| {
        format!(
            "{} {} for {used} setups; without {} {fewest} would do",
            names.join(", "),
            if names.len() == 1 { "asks" } else { "ask" },
            if names.len() == 1 { "it" } else { "them" }
        )
    })
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

/// Plans one plan: the entry point of the planner. Faces that cannot be inspected, and
/// a search that never gets a plan to validate, are reported in `diags` and give `None`;
/// a search that does not settle ends with the best plan found ([`fallback`]).
pub fn plan(input: &Input, opts: &PlanOptions, diags: &mut Diagnostics) -> Option<Hlip> {
    plan_with(input, opts, &mut Memo::default(), diags)
}

/// [`plan`], keeping in `memo` the cones and depth maps it computes and reusing those a
/// previous planning of the same `input` left there (the re-plans after the path stage's
/// bans). The plan is the one [`plan`] gives.
///
/// The features the sensor selection gave a laser scanner are left out of the touch plan
/// and scanned in its setups ([`scan`]); those the selection chose by its rule and no
/// setup lets the scanner cover go back to the touch probes, and the plan is made again
/// with them until none is sent back. A feature sent back that the scanner covers in
/// the final plan's setups is scanned after all, its touches dropped.
pub fn plan_with(
    input: &Input,
    opts: &PlanOptions,
    memo: &mut Memo,
    diags: &mut Diagnostics,
) -> Option<Hlip> {
    let all = scan::lasers(input);
    let mut lasers = all.clone();
    let mut back: Vec<scan::Uncovered> = Vec::new();
    loop {
        let skip: BTreeSet<FaceId> = lasers.iter().flat_map(|l| l.faces.clone()).collect();
        let mut own = Diagnostics::new();
        let Some(mut hlip) = plan_placed(input, opts, memo, &skip, &mut own) else {
            diags.extend(own);
            return None;
        };
        // The features sent back are offered to the scanner again: this plan's setups are
        // not the ones that left them short.
        let offered: Vec<scan::Laser> = all
            .iter()
            .filter(|l| {
                lasers.iter().any(|x| x.feature == l.feature)
                    || back.iter().any(|u| u.feature == l.feature)
            })
            .cloned()
            .collect();
        let uncovered = scan::plan_scans(input, &mut hlip, &offered, opts, &mut memo.scans);
        let asked = |f: crate::model::FeatureId| all.iter().any(|l| l.feature == f && l.asked);
        let to_touch: Vec<&scan::Uncovered> = uncovered
            .iter()
            .filter(|u| !asked(u.feature) && !back.iter().any(|b| b.feature == u.feature))
            .collect();
        // Until none is left: the plan made again holds other setups, where other faces
        // may fall short. Each round sends at least one feature back, so this ends.
        if !to_touch.is_empty() {
            back.extend(to_touch.into_iter().cloned());
            lasers.retain(|l| !back.iter().any(|u| u.feature == l.feature));
            continue;
        }
        // A feature sent back that the scanner covers in this plan's setups is scanned
        // there: its touches leave the plan.
        let rescanned: BTreeSet<(crate::model::FeatureId, FaceId)> = hlip
            .scans
            .iter()
            .filter(|x| back.iter().any(|u| u.feature == x.feature))
            .map(|x| (x.feature, x.face))
            .collect();
        if !rescanned.is_empty() {
            hlip.drop_touches(&rescanned);
            let head = hlip.head;
            scan::recount(&mut hlip, head);
        }
        back.retain(|u| !hlip.scans.iter().any(|x| x.feature == u.feature));
        // The best coverage any round's setups gave.
        for u in back.iter_mut() {
            if let Some(now) = uncovered.iter().find(|x| x.face == u.face) {
                u.best = u.best.max(now.best);
            }
        }
        diags.extend(own);
        hlip.to_touch = back.iter().map(|u| (u.feature, u.face, u.best)).collect();
        return Some(account(input, hlip, opts, &uncovered, diags));
    }
}

/// How many configurations of a point may collide with the part turned (and not at its
/// nominal pose) before the point takes one clear at the nominal pose alone: an
/// indexed head offers the next orientation 7.5° away, which seldom clears what the
/// first did not.
const FRAGILE_AFTER: usize = 6;

/// The touch plan of every face but `skip`, robust to the part set turned about the
/// vertical: first with every touch validated at [`validate::PLACEMENT_TURN`] either way
/// as well as at the nominal pose, but for points [`FRAGILE_AFTER`] configurations of
/// which collided only turned; where that finds no plan (the configurations it turned
/// down were a point's last), the plan validated at the nominal pose. The setups say how
/// square the operator must set the part ([`hlip::SetupNode::square_within`]) and the
/// warning `insp::plan::placement_sensitive` which touches ask it.
fn plan_placed(
    input: &Input,
    opts: &PlanOptions,
    memo: &mut Memo,
    skip: &BTreeSet<FaceId>,
    diags: &mut Diagnostics,
) -> Option<Hlip> {
    if !memo.unturnable {
        let mut robust = Diagnostics::new();
        let turn = validate::PLACEMENT_TURN;
        if let Some(hlip) = plan_touch(input, opts, memo, skip, turn, &mut robust) {
            diags.extend(robust);
            return Some(hlip);
        }
        memo.unturnable = true;
    }
    plan_touch(input, opts, memo, skip, 0.0, diags)
}

/// The touch plan of every face but `skip` (those a scanner measures), each touch
/// validated with the part turned `turn` degrees either way about the vertical. With a
/// turn, a search that does not settle gives no plan (the caller plans again without).
fn plan_touch(
    input: &Input,
    opts: &PlanOptions,
    memo: &mut Memo,
    skip: &BTreeSet<FaceId>,
    turn: f64,
    diags: &mut Diagnostics,
) -> Option<Hlip> {
    let (model, plan, g) = (input.model, input.plan, input.graph);
    let hierarchy = &model.hierarchies[plan.hierarchy.0];
    let machine = Machine::new(model, plan);
    let setups = poses::Setups::new(model, plan, input.geometry, input.fixtures);
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
        backend: opts.backend,
        ..Default::default()
    };
    let mut k = Knowledge::new(
        plan,
        &machine,
        input.geometry,
        &g.fpoints,
        &table_faces,
        setups,
        cone_opts,
        memo,
    );
    let mut validated: BTreeSet<Pip> = BTreeSet::new();
    // Per point, the configurations that collided only with the part turned: after
    // FRAGILE_AFTER of them the point takes one clear at the nominal pose alone.
    let mut turned_fails: BTreeMap<usize, usize> = BTreeMap::new();
    let mut last = String::from("no round was run");
    // The round whose plan had the fewest touches that failed validation: what the plan
    // falls back on, less those touches, if no round settles.
    let mut fallback: Option<Fallback> = None;
    // Faces no probe inspects, left out under `allow_unmeasured`, and those a scanner
    // measures.
    let mut skipped: BTreeSet<FaceId> = skip.clone();
    let read_axes = axes::axis_faces(g, &input.model.parts[input.plan.part.0]);
    for iteration in 1..=opts.max_iterations {
        let (dropped, bad) = filter(g, input.geometry, &k, &machine, &skipped, &read_axes);
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
                let (_, bad2) = filter(g, input.geometry, &k, &machine, &skipped, &read_axes);
                if bad2.is_empty() {
                    continue;
                }
            }
            let (_, bad) = filter(g, input.geometry, &k, &machine, &skipped, &read_axes);
            for &face in &bad {
                report_face(input, &k, &machine, face, opts.allow_unmeasured, diags);
            }
            if !opts.allow_unmeasured {
                return None;
            }
            // Plan the rest; the tolerances on these faces are reported unmeasured.
            skipped.extend(bad);
            continue;
        }
        let Some(root) = solve::unfold(g, &k, &machine, &dropped) else {
            let round = Round {
                branches: &[],
                iterations: iteration,
                dropped: dropped.len(),
                strategy: None,
                exact_budget: opts.exact_budget,
            };
            return Some(assemble(input, &mut k, &machine, &round));
        };
        let mut results: Vec<(Strategy, Vec<Branch>)> = Vec::new();
        let mut failures = Vec::new();
        let sets = solve::setup_sets(&root, &k, &machine);
        let trees = solve::setup_trees(&root, &k, hierarchy, &sets);
        for (strategy, tree) in Strategy::ALL.into_iter().zip(trees) {
            match solve::solve(&root, &mut k, &machine, hierarchy, strategy, tree) {
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
        let held: BTreeMap<usize, domain::Held> = pips
            .iter()
            .map(|(p, _)| (p.setup, k.held(p.setup).clone()))
            .collect();
        // (touch, result, whether it failed only with the part turned)
        let checked: Vec<(Pip, Result<(), _>, bool)> = pips
            .par_iter()
            .map(|(p, up)| {
                let tries = turned_fails.get(&p.point).copied().unwrap_or(0);
                let t = if tries < FRAGILE_AFTER { turn } else { 0.0 };
                let held = &held[&p.setup];
                match validate::check(&k, &machine, p, up, held, &opts.bans) {
                    Err(e) => (*p, Err(e), false),
                    Ok(()) => {
                        let turned = validate::clear_turned(&k, &machine, p, up, held, t);
                        let turned_only = turned.is_err();
                        (*p, turned, turned_only)
                    }
                }
            })
            .collect();
        let mut invalid = Vec::new();
        let mut left: BTreeSet<Pip> = BTreeSet::new();
        // Per face, the touches that failed and the first cause, for the diagnostic.
        let mut failed: BTreeMap<String, (usize, String)> = BTreeMap::new();
        let mut causes: BTreeMap<FaceId, (usize, usize, crate::access::pose::Blocker)> =
            BTreeMap::new();
        for (p, what, turned_only) in checked {
            if turned_only {
                *turned_fails.entry(p.point).or_default() += 1;
            }
            match what {
                Ok(()) => {
                    validated.insert(p);
                }
                Err(w) => {
                    left.insert(p);
                    causes
                        .entry(k.points[p.point].face)
                        .or_insert_with(|| (0, p.probe, w.clone()))
                        .0 += 1;
                    let e = failed
                        .entry(face_name(input, &k, p.point))
                        .or_insert_with(|| {
                            (
                                0,
                                format!("probe {} hits {w}", machine.probes[p.probe].name),
                            )
                        });
                    e.0 += 1;
                    invalid.push((
                        p.point,
                        p.probe,
                        p.setup,
                        machine.head.indexable().then_some(p.orient),
                    ));
                }
            }
        }
        if invalid.is_empty() {
            debug_assert!(
                audit(&mut k, &machine, &best.1).is_empty(),
                "{:?}",
                audit(&mut k, &machine, &best.1)
            );
            // Datums measured again where the tolerances read against them are.
            let again = remeasure::datums_where_read(
                input, &mut k, &machine, &best.1, turn, &opts.bans, diags,
            );
            let branches: Vec<Branch> = best.1.iter().cloned().chain(again).collect();
            let round = Round {
                branches: &branches,
                iterations: iteration,
                dropped: dropped.len(),
                strategy: Some(best.0),
                exact_budget: opts.exact_budget,
            };
            let mut hlip = assemble(input, &mut k, &machine, &round);
            // Touches validated turned are clear turned; the others are measured.
            let fragile =
                |p: &Pip| turn == 0.0 || turned_fails.get(&p.point) >= Some(&FRAGILE_AFTER);
            placement::square_within(
                input, &mut k, &machine, &branches, &fragile, &mut hlip, diags,
            );
            if hlip.summary.setups > hlip.summary.min_setups.0 {
                let forcing = forcing_levels(&root, &mut k, &machine, hierarchy, &best.1);
                hlip.summary.more_setups = Some(forcing.unwrap_or_else(|| {
                    "no clustering found fewer; the minimum may need setups the hierarchy's order does not reach".into()
                }));
            }
            return Some(hlip);
        }
        if !failed.is_empty() {
            let faces: Vec<String> = failed
                .iter()
                .take(4)
                .map(|(face, (n, why))| format!("{face} ({n} touches; {why})"))
                .collect();
            let more = failed.len().saturating_sub(4);
            last = format!(
                "in the last round touches failed on {}{}",
                faces.join(", "),
                if more > 0 {
                    format!(" and {more} more faces")
                } else {
                    String::new()
                }
            );
        }
        if fallback.as_ref().is_none_or(|f| left.len() <= f.left.len()) {
            fallback = Some(Fallback {
                branches: best.1.clone(),
                left,
                causes,
                strategy: best.0,
                dropped: dropped.len(),
            });
        }
        learn(&mut k, &machine, invalid);
    }
    if turn > 0.0 {
        return None;
    }
    if let Some(f) = fallback {
        if let Some(hlip) = f.settle(input, &mut k, &machine, opts, diags) {
            return Some(hlip);
        }
    }
    diags.push(PlanError::NoConvergence {
        span: plan.span,
        plan: plan.name.clone(),
        iterations: opts.max_iterations,
        last,
    });
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
        oc += usize::from(m.head.indexable() && m.grid[w[0].orient] != m.grid[w[1].orient]);
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

/// Whether points spread across an area, not along a line: a plane fitted to them is
/// determined. The second principal spread must be at least [`LEAST_SPREAD`].
pub(super) fn spans_area(points: &[&crate::geometry::P3]) -> bool {
    if points.len() < 3 {
        return false;
    }
    let n = points.len() as f64;
    let c = points.iter().fold(V3::zeros(), |s, p| s + p.coords) / n;
    let cov = points.iter().fold(nalgebra::Matrix3::zeros(), |m, p| {
        let d = p.coords - c;
        m + d * d.transpose()
    }) / n;
    let mut e: Vec<f64> = cov.symmetric_eigenvalues().iter().copied().collect();
    e.sort_by(|a, b| b.total_cmp(a));
    e[1].max(0.0).sqrt() >= LEAST_SPREAD
}

/// The least spread (mm, standard deviation across the points' main direction) a
/// plane's points keep when points drop out.
const LEAST_SPREAD: f64 = 0.5;

/// How many points per face and probe get the whole probe's cones in one round.
const ACQUIRE_PER_FACE: usize = 2;

/// The fpoints of a face, by index.
pub(crate) fn face_points(g: &MeasurementGraph, face: FaceId) -> Vec<usize> {
    (0..g.fpoints.len())
        .filter(|&i| g.fpoints[i].face == face)
        .collect()
}

/// Drops fpoints no probe reaches and, while a face keeps enough, those reached from
/// under a twentieth of the face's median count of setups (ch. 3.6.3) — but not the end
/// circles of a face in `read_axes` ([`axes::end_circles`]). Returns the dropped fpoints
/// and the faces left with too few. The `skipped` faces (left out under
/// `allow_unmeasured`) drop all their points.
fn filter(
    g: &MeasurementGraph,
    geo: &PartGeometry,
    k: &Knowledge,
    m: &Machine,
    skipped: &BTreeSet<FaceId>,
    read_axes: &BTreeSet<FaceId>,
) -> (BTreeSet<usize>, Vec<FaceId>) {
    let mut by_face: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (i, f) in g.fpoints.iter().enumerate() {
        by_face.entry(f.face.0).or_default().push(i);
    }
    let mut dropped = BTreeSet::new();
    let mut bad = Vec::new();
    for (face, pts) in by_face {
        if skipped.contains(&FaceId(face)) {
            dropped.extend(pts);
            continue;
        }
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
        let floor = need.max(pts.len().div_ceil(2));
        // Those left must still fix the face's surface (never a plane on a line).
        let plane = matches!(
            geo.faces[face].surface,
            crate::geometry::Surface::Plane { .. }
        );
        let mut sorted: Vec<usize> = keep.iter().map(|x| x.1).collect();
        sorted.sort_unstable();
        let median = sorted[sorted.len() / 2];
        let ends = if read_axes.contains(&FaceId(face)) {
            axes::end_circles(g, &geo.faces[face].surface, &keep)
        } else {
            BTreeSet::new()
        };
        keep.sort_by_key(|&(p, s)| (s, p));
        let mut kept: Vec<usize> = keep.iter().map(|&(p, _)| p).collect();
        for &(p, s) in &keep {
            if kept.len() <= floor || s * 20 >= median {
                break;
            }
            if ends.contains(&p) {
                continue;
            }
            if plane {
                let rest: Vec<&crate::geometry::P3> = kept
                    .iter()
                    .filter(|&&q| q != p)
                    .map(|&q| &g.fpoints[q].position)
                    .collect();
                if !spans_area(&rest) {
                    continue;
                }
            }
            kept.retain(|&q| q != p);
            dropped.insert(p);
        }
    }
    (dropped, bad)
}
