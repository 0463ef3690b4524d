//! The high-level inspection plan (HLIP): setups → probes → orientations → what each
//! inspects, in typed ids. Names appear only when the plan is printed ([`super::text`],
//! [`super::json`]); the path stage and the DMIS writer follow the ids.
//!
//! Coordinates are *quantised* to 1 / [`STEPS_PER_MM`] once, here: the plan that is
//! printed and the plan the path stage moves by are the same numbers.
//!
//! **Decision: setups are named by the part direction that faces the ram** (`prefer
//! setup +z` puts the part's +z up), as in the seed's listings.
//!
//! **Decision: the proven minimum** of setups (`min_setups`, a line of the summary)
//! counts only realisable setups in which some probe reaches a point with its stylus
//! off the table (the cones do not see the table); a point higher above the table than
//! the probe is long is assumed reached, so it stays a lower bound. For a plan of one
//! or two setups it is proven from the plan's own setups and the cells every point
//! shares, without every point's whole setup set.

use super::cluster::{min_hitting_set, Strategy};
use super::knowledge::Knowledge;
use super::machine::Machine;
use super::poses::Holder;
use super::solve::{self, Branch, Inst, Kind};
use super::Input;
use crate::access::pose::{frame, orientation_dir, Contact, Head, Solid};
use crate::geometry::{FaceId, P3, V3};
use crate::model::{FeatureId, PlanId, SlotId, ToleranceId};
use rayon::prelude::*;
use std::collections::BTreeSet;

/// The resolution of the plan's coordinates and directions: steps per millimetre (or
/// per unit of a direction's components), a nanometre.
pub(crate) const STEPS_PER_MM: f64 = 1e6;

/// A high-level inspection plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Hlip {
    /// The plan it realises.
    pub plan: PlanId,
    /// The head: fixed or indexable.
    pub head: Head,
    /// The setups, in the order they are done.
    pub setups: Vec<SetupNode>,
    /// Every point the plan may touch (graph fpoints, then table points).
    pub points: Vec<PlanPoint>,
    /// The faces a laser scanner measures, in feature order ([`super::scan`]).
    pub scans: Vec<ScannedFace>,
    /// Features the selection gave the scanner that went back to the touch probes: a
    /// face of theirs and the most of its area any setup let the scanner see.
    pub to_touch: Vec<(FeatureId, FaceId, f64)>,
    /// Counts.
    pub summary: Summary,
}

/// A face the plan gives a laser scanner: where, how much of it, and why the scanner.
#[derive(Debug, Clone, PartialEq)]
pub struct ScannedFace {
    /// The feature.
    pub feature: FeatureId,
    /// The face.
    pub face: FaceId,
    /// The scanner's slot (after the rack's probes, see [`ProbeNode::probe`]).
    pub scanner: SlotId,
    /// The setup, by index into [`Hlip::setups`].
    pub setup: usize,
    /// The share of its area the passes see.
    pub coverage: f64,
    /// Head orientations it is scanned from.
    pub views: usize,
    /// Passes over it.
    pub passes: usize,
    /// Why the scanner measures it (the sensor selection's reason).
    pub why: String,
}

/// Which point of the knowledge base a plan point is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum PointRef {
    /// An fpoint of the measurement graph, by index into its `fpoints`.
    Graph(usize),
    /// The k-th point on the table, standing in for a datum face resting on it.
    Table(usize),
}

impl PointRef {
    /// What the touch touches.
    pub fn contact(self) -> Contact {
        match self {
            PointRef::Graph(_) => Contact::Part,
            PointRef::Table(_) => Contact::Table,
        }
    }
}

/// A point of the plan.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanPoint {
    /// Which point it is.
    pub at: PointRef,
    /// Its face (for table points, the datum face resting on the table).
    pub face: FaceId,
    /// Contact position (part frame, mm).
    pub position: P3,
    /// Surface normal at the contact.
    pub normal: V3,
}

/// One setup: the part resting so that `up` (part frame) points to the ram.
#[derive(Debug, Clone, PartialEq)]
pub struct SetupNode {
    /// The part-frame direction pointing up.
    pub up: V3,
    /// The rotation part frame → machine frame (rows).
    pub rotation: [[f64; 3]; 3],
    /// Datum faces resting on the table in this setup.
    pub on_table: Vec<FaceId>,
    /// What holds the part: the table (a stable pose) or a fixture.
    pub holder: Holder,
    /// The table's height along `up` (part frame, mm).
    pub table: f64,
    /// The fixture's solids in the part frame: obstacles like the part.
    pub fixture: Vec<Solid>,
    /// The probes used, in order.
    pub probes: Vec<ProbeNode>,
    /// How square to the machine axes (degrees about the vertical) the operator must
    /// set the part, where some touch collides with it turned less than the placement
    /// every program is validated for ([`super::placement`]); `None` when it runs
    /// anywhere within that.
    pub square_within: Option<f64>,
}

/// One sensor in a setup: a touch probe, or a laser scanner.
#[derive(Debug, Clone, PartialEq)]
pub struct ProbeNode {
    /// The sensor's slot: a probe by its index in the machine's rack, a scanner by the
    /// rack's probe count plus its index among the machine's scanners.
    pub probe: SlotId,
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
    pub direction: V3,
    /// What is inspected.
    pub inspections: Vec<Inspection>,
}

/// Inspecting one feature in one configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct Inspection {
    /// The feature (`None` for faces hanging from the part itself).
    pub feature: Option<FeatureId>,
    /// Its faces (or the table standing in for one) and their points.
    pub faces: Vec<FaceVisit>,
    /// The tolerances whose measurement this records.
    pub records: Vec<ToleranceId>,
}

/// Points taken on one face.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceVisit {
    /// The face.
    pub face: FaceId,
    /// The face itself, or the table it rests on.
    pub contact: Contact,
    /// Indices into [`Hlip::points`].
    pub points: Vec<usize>,
    /// A scanner's passes over the face (none for a touch probe).
    pub passes: Vec<ScanPass>,
}

/// One pass of a laser scanner: the middle of its depth of field runs from `start` to
/// `end` (part frame, quantised), the stripe square to the motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanPass {
    /// Where the pass starts.
    pub start: P3,
    /// Where it ends.
    pub end: P3,
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
    /// Faces scanned, and the scanner's passes over them.
    pub scanned: (usize, usize),
    /// Generate-and-test rounds.
    pub iterations: usize,
    /// Violated binary same-constraints, per level of the plan's hierarchy.
    pub violations: Vec<u64>,
    /// Fpoints filtered out as inaccessible or poorly accessible.
    pub dropped_points: usize,
    /// Whole-probe cone computations the validation called for.
    pub cones_acquired: usize,
    /// The fewest setups any plan could have, and whether that is proven (else a lower
    /// bound).
    pub min_setups: (usize, bool),
    /// Why the plan has more setups than the minimum, when it has.
    pub more_setups: Option<String>,
    /// When generate-and-test did not settle: the touches of the best plan found that
    /// failed validation and moved to another configuration, and those left out.
    pub unsettled: Option<(usize, usize)>,
    /// The clustering strategy of the plan kept (`None` when nothing needed clustering).
    pub strategy: Option<Strategy>,
    /// Tolerances whose every face (of their features and datum features) the plan
    /// touches, and the part's tolerances in all.
    pub tolerances: (usize, usize),
}

/// How a round ended, for [`assemble`].
pub(crate) struct Round<'a> {
    /// The branches of the plan kept.
    pub branches: &'a [Branch],
    /// Generate-and-test rounds run.
    pub iterations: usize,
    /// Fpoints filtered out.
    pub dropped: usize,
    /// The clustering strategy that made the branches.
    pub strategy: Option<Strategy>,
    /// Search nodes for the exact minimum number of setups.
    pub exact_budget: usize,
}

impl Hlip {
    /// Drops the touches of the (feature, face) pairs `scanned`, which a scanner now
    /// measures: their visits, and the inspections, orientations and probes left empty;
    /// the touched features and points are counted again. Setups stay (a scan needs its
    /// setup), as do scanned visits and another feature's touches of the same face.
    pub(crate) fn drop_touches(&mut self, scanned: &BTreeSet<(FeatureId, FaceId)>) {
        for s in &mut self.setups {
            for p in &mut s.probes {
                for o in &mut p.orients {
                    for i in &mut o.inspections {
                        let Some(f) = i.feature else { continue };
                        i.faces.retain(|v| {
                            !(scanned.contains(&(f, v.face))
                                && v.contact == Contact::Part
                                && v.passes.is_empty())
                        });
                    }
                }
            }
        }
        self.prune();
    }

    /// Drops the visits with nothing to touch or scan, and the inspections, orientations
    /// and probes left empty (setups stay); counts the touched features and points again.
    pub(crate) fn prune(&mut self) {
        for s in &mut self.setups {
            for p in &mut s.probes {
                for o in &mut p.orients {
                    for i in &mut o.inspections {
                        i.faces
                            .retain(|v| !v.points.is_empty() || !v.passes.is_empty());
                    }
                    o.inspections.retain(|i| !i.faces.is_empty());
                }
                p.orients.retain(|o| !o.inspections.is_empty());
            }
            s.probes.retain(|p| !p.orients.is_empty());
        }
        let touches = || {
            self.setups
                .iter()
                .flat_map(|s| &s.probes)
                .flat_map(|p| &p.orients)
                .flat_map(|o| &o.inspections)
                .flat_map(|i| i.faces.iter().map(move |v| (i.feature, v)))
                .filter(|(_, v)| v.passes.is_empty())
        };
        let features: BTreeSet<Option<FeatureId>> = touches().map(|(f, _)| f).collect();
        let points: BTreeSet<usize> = touches()
            .flat_map(|(_, v)| v.points.iter().copied())
            .collect();
        self.summary.features = features.len();
        self.summary.points = points.len();
    }
}

/// (probe, [(orientation, instance trees)]) of one setup.
type Probes<'a> = Vec<(usize, Vec<(usize, Vec<&'a Inst>)>)>;

/// Assembles the HLIP tree from the branches of the plan kept.
pub(crate) fn assemble(input: &Input, k: &mut Knowledge, m: &Machine, run: &Round) -> Hlip {
    let setups = group(run.branches);
    let mut used_points: BTreeSet<usize> = BTreeSet::new();
    let mut features: BTreeSet<Option<FeatureId>> = BTreeSet::new();
    let mut seq: Vec<(usize, (u64, u64))> = Vec::new();
    let mut out_setups = Vec::new();
    for (cell, up, probes) in &setups {
        let held = k.held(*cell).clone();
        let mut on_table = Vec::new();
        let mut pnodes = Vec::new();
        for (p, orients) in probes {
            let mut onodes = Vec::new();
            for (o, trees) in orients {
                let (a, b) = m.grid[*o];
                let dir = match m.head {
                    Head::Indexable => orientation_dir(up, a, b),
                    Head::Fixed => *up,
                };
                seq.push((*p, (a.to_bits(), b.to_bits())));
                let mut insp: Vec<Inspection> = Vec::new();
                for t in trees {
                    collect(t, None, None, &mut |tol, feat, face, contact, pts| {
                        features.insert(feat);
                        used_points.extend(pts.iter().copied());
                        if contact == Contact::Table && !on_table.contains(&face) {
                            on_table.push(face);
                        }
                        let i = match insp.iter().position(|x| x.feature == feat) {
                            Some(i) => i,
                            None => {
                                insp.push(Inspection {
                                    feature: feat,
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
                            .find(|v| v.face == face && v.contact == contact)
                        {
                            Some(v) => {
                                v.points.extend(pts.iter().copied());
                                v.points.sort_unstable();
                                v.points.dedup();
                            }
                            None => x.faces.push(FaceVisit {
                                face,
                                contact,
                                points: pts.to_vec(),
                                passes: vec![],
                            }),
                        }
                        if let Some(t) = tol {
                            if !x.records.contains(&t) {
                                x.records.push(t);
                            }
                        }
                    });
                }
                onodes.push(OrientNode {
                    a,
                    b,
                    direction: quantise(&dir),
                    inspections: insp,
                });
            }
            pnodes.push(ProbeNode {
                probe: SlotId(*p),
                orients: onodes,
            });
        }
        let r = frame(up).into_inner();
        out_setups.push(SetupNode {
            up: quantise(up),
            rotation: [0, 1, 2].map(|i| [0, 1, 2].map(|j| round(r[(i, j)]))),
            on_table,
            holder: held.holder,
            table: round(held.table),
            fixture: held.solids,
            probes: pnodes,
            square_within: None,
        });
    }
    let probe_changes = seq.windows(2).filter(|w| w[0].0 != w[1].0).count();
    let orientation_changes = match m.head {
        Head::Indexable => seq.windows(2).filter(|w| w[0].1 != w[1].1).count(),
        Head::Fixed => 0,
    };
    let orientations: BTreeSet<(u64, u64)> = seq.iter().map(|s| s.1).collect();
    let probes_used: BTreeSet<usize> = seq.iter().map(|s| s.0).collect();
    let hierarchy = &input.model.hierarchies[input.plan.hierarchy.0];
    let violations = solve::violations(run.branches, m, hierarchy);
    let plan_cells: Vec<usize> = setups.iter().map(|s| s.0).collect();
    let min_setups = min_setups(k, m, &used_points, &plan_cells, run.exact_budget);
    let points = k
        .points
        .iter()
        .enumerate()
        .map(|(i, f)| PlanPoint {
            at: if i < k.graph_points {
                PointRef::Graph(i)
            } else {
                PointRef::Table(i - k.graph_points)
            },
            face: f.face,
            position: P3::from(quantise(&f.position.coords)),
            normal: quantise(&f.normal),
        })
        .collect();
    Hlip {
        plan: input.plan_id(),
        head: m.head,
        summary: Summary {
            more_setups: None,
            unsettled: None,
            tolerances: (0, 0),
            setups: out_setups.len(),
            probes_used: probes_used.len(),
            probe_changes,
            orientations: orientations.len(),
            orientation_changes,
            features: features.len(),
            points: used_points.len(),
            scanned: (0, 0),
            iterations: run.iterations,
            violations,
            dropped_points: run.dropped,
            cones_acquired: k.acquired,
            min_setups,
            strategy: run.strategy,
        },
        setups: out_setups,
        points,
        scans: vec![],
        to_touch: vec![],
    }
}

/// Groups branches by setup (first appearance), then probe, then orientation; each setup
/// starts with the probe the last one ended with.
fn group(branches: &[Branch]) -> Vec<(usize, V3, Probes<'_>)> {
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
    setups
}

/// The fewest setups any plan of the used points could have: a hitting set of the
/// points' setup sets. A point's set holds the realisable setups in which some probe has
/// an orientation that reaches it with its stylus off the table (or the fixture's
/// table), so the minimum is one a real plan can meet.
fn min_setups(
    k: &mut Knowledge,
    m: &Machine,
    used_points: &BTreeSet<usize>,
    plan_cells: &[usize],
    budget: usize,
) -> (usize, bool) {
    let points: Vec<usize> = (0..k.graph_points)
        .filter(|i| used_points.contains(i))
        .collect();
    let candidates: Vec<crate::access::CubeMap> = points.iter().map(|&i| k.setups(i, m)).collect();
    if let Some(found) = few_setups(k, m, &points, &candidates, plan_cells) {
        return found;
    }
    // Every candidate setup cell of a bent probe, once, ascending (a fixed head asks
    // nothing per setup).
    let cells: Vec<usize> = match candidates.split_first() {
        Some((first, rest)) if m.head.indexable() => {
            let mut all = first.clone();
            for s in rest {
                all.or_assign(s);
            }
            all.cells().map(|c| all.index(c)).collect()
        }
        _ => Vec::new(),
    };
    k.prepare(&cells, m);
    let k = &*k;
    // Each candidate setup's direction and table height, by cell index: asked per point
    // and probe, looked up in a slice rather than computed or searched for each.
    let mut setup_at: Vec<Option<(V3, f64)>> = vec![None; cells.last().map_or(0, |&c| c + 1)];
    for &cell in &cells {
        setup_at[cell] = Some((k.setup_dir(cell), k.held_prepared(cell).table));
    }
    let reached: Vec<crate::access::CubeMap> = points
        .par_iter()
        .zip(candidates)
        .map(|(&i, mut s)| {
            let cells: Vec<usize> = s.cells().map(|c| s.index(c)).collect();
            let caps = d1_caps(k, i);
            for cell in cells {
                let at = setup_at.get(cell).copied().flatten();
                if !reaches(k, m, i, cell, at, &caps) {
                    let c = s.cell(cell);
                    s.set(c, false);
                }
            }
            let face = k.points[i].face;
            if let Some(t) = k.tables.iter().find(|t| t.face == face && t.alive) {
                let c = s.cell(t.cell);
                s.set(c, true);
            }
            s
        })
        .collect();
    let mut sets: Vec<crate::access::CubeMap> = Vec::new();
    let mut seen: BTreeSet<Vec<u64>> = BTreeSet::new();
    for s in reached {
        if !s.is_empty() && seen.insert(s.words().to_vec()) {
            sets.push(s);
        }
    }
    let refs: Vec<&crate::access::CubeMap> = sets.iter().collect();
    min_hitting_set(&refs, budget)
}

/// D1's bounding cap per probe of a graph point, as [`Knowledge::reaches_off_table`]
/// takes it: computed when first asked for (a point high above the table never is).
type Caps = Vec<std::sync::OnceLock<Option<(V3, f64)>>>;

fn d1_caps(k: &Knowledge, i: usize) -> Caps {
    (0..k.dom[i].len())
        .map(|_| std::sync::OnceLock::new())
        .collect()
}

/// Whether some allowed probe reaches graph point `i` in candidate setup cell `cell`
/// with its stylus off the table: `at` is the setup's direction and table height for a
/// bent probe (None asks only for a probe).
fn reaches(
    k: &Knowledge,
    m: &Machine,
    i: usize,
    cell: usize,
    at: Option<(V3, f64)>,
    caps: &Caps,
) -> bool {
    let probes = k.probes(i, cell, m);
    match at {
        Some((up, t0)) => probes.ones().any(|p| {
            let cap = || {
                *caps[p].get_or_init(|| k.dom[i][p].d1.as_ref().and_then(|d1| d1.bounding_cap()))
            };
            k.reaches_off_table(i, p, cell, (&up, t0), m, cap)
        }),
        None => probes.ones().next().is_some(),
    }
}

/// [`min_setups`] without every point's whole setup set when the plan has one or two
/// setups: the plan's setups reach every point (so every set is non-empty and the
/// minimum is at most theirs), and the minimum is 1 exactly when a setup in every
/// point's candidates reaches them all — each looked at until a point it misses. The
/// same answer as the hitting set of the whole sets, proven; None when the plan has
/// more setups or some point is reached in none of them (the whole sets decide then).
fn few_setups(
    k: &mut Knowledge,
    m: &Machine,
    points: &[usize],
    candidates: &[crate::access::CubeMap],
    plan_cells: &[usize],
) -> Option<(usize, bool)> {
    if points.is_empty() || plan_cells.is_empty() || plan_cells.len() > 2 {
        return None;
    }
    // Each point's possible cells: its candidates, and its table face's cell (always
    // in its set, as in `min_setups`).
    let table: Vec<Option<usize>> = points
        .iter()
        .map(|&i| {
            let face = k.points[i].face;
            k.tables
                .iter()
                .find(|t| t.face == face && t.alive)
                .map(|t| t.cell)
        })
        .collect();
    let mut common = candidates[0].clone();
    if let Some(t) = table[0] {
        let c = common.cell(t);
        common.set(c, true);
    }
    for (s, t) in candidates.iter().zip(&table).skip(1) {
        let mut possible = s.clone();
        if let Some(t) = *t {
            let c = possible.cell(t);
            possible.set(c, true);
        }
        common.and_assign(&possible);
    }
    let shared: Vec<usize> = common.cells().map(|c| common.index(c)).collect();
    let mut look = shared.clone();
    look.extend_from_slice(plan_cells);
    look.sort_unstable();
    look.dedup();
    // A cell is a setup the bent probe's test needs held when some point has it as a
    // candidate (the cells `min_setups` prepares).
    let bent = m.head.indexable();
    let prepared: Vec<usize> = look
        .iter()
        .copied()
        .filter(|&c| bent && candidates.iter().any(|s| s.has_index(c)))
        .collect();
    k.prepare(&prepared, m);
    let k = &*k;
    let at = |cell: usize| {
        prepared
            .binary_search(&cell)
            .is_ok()
            .then(|| (k.setup_dir(cell), k.held_prepared(cell).table))
    };
    let caps: Vec<Caps> = points.iter().map(|&i| d1_caps(k, i)).collect();
    let reached = |j: usize, cell: usize| {
        table[j] == Some(cell)
            || (candidates[j].has_index(cell) && reaches(k, m, points[j], cell, at(cell), &caps[j]))
    };
    // Every point in some setup of the plan, or the whole sets decide.
    let in_plan: Vec<bool> = (0..points.len())
        .into_par_iter()
        .map(|j| plan_cells.iter().any(|&c| reached(j, c)))
        .collect();
    if in_plan.contains(&false) {
        return None;
    }
    if plan_cells.len() == 1 {
        return Some((1, true));
    }
    // One setup for all: a cell that every point's set holds. Most cells are missed by
    // a few points, so the point that missed the last cell is asked first.
    let one = shared.par_chunks(16).any(|chunk| {
        let mut order: Vec<usize> = (0..points.len()).collect();
        chunk.iter().any(|&cell| {
            let Some(at) = order.iter().position(|&j| !reached(j, cell)) else {
                return true;
            };
            let j = order.remove(at);
            order.insert(0, j);
            false
        })
    });
    Some((if one { 1 } else { 2 }, true))
}

/// A face visit: (tolerance, feature, face, contact, points).
type Visit<'a> = dyn FnMut(Option<ToleranceId>, Option<FeatureId>, FaceId, Contact, &[usize]) + 'a;

/// Walks an instance tree, calling `f(tolerance, feature, face, contact, points)` for
/// every face or table visit.
pub(super) fn collect(i: &Inst, tol: Option<ToleranceId>, feat: Option<FeatureId>, f: &mut Visit) {
    match &i.kind {
        Kind::Tol(t) => i
            .children
            .iter()
            .for_each(|c| collect(c, Some(ToleranceId(*t)), feat, f)),
        Kind::Feature(x) => i.children.iter().for_each(|c| collect(c, tol, Some(*x), f)),
        Kind::Face { face, .. } | Kind::Table { face } => {
            let mut pts = Vec::new();
            solve::leaves(i, &mut pts);
            pts.sort_unstable();
            pts.dedup();
            let contact = match i.kind {
                Kind::Table { .. } => Contact::Table,
                _ => Contact::Part,
            };
            f(tol, feat, *face, contact, &pts);
        }
        _ => i.children.iter().for_each(|c| collect(c, tol, feat, f)),
    }
}

/// A number at the plan's resolution, without `-0`.
pub(crate) fn round(x: f64) -> f64 {
    let r = (x * STEPS_PER_MM).round() / STEPS_PER_MM;
    if r == 0.0 {
        0.0
    } else {
        r
    }
}

/// A vector at the plan's resolution.
pub(crate) fn quantise(v: &V3) -> V3 {
    V3::new(round(v.x), round(v.y), round(v.z))
}
