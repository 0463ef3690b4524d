//! Planning at density (issue 47): the search decides a dense face's configurations on
//! representatives, and the face's own points take the configurations of their nearest
//! representatives, each validated as the search validates a touch.
//!
//! Setups, probes and orientations are decided per face where the face's points agree:
//! neighbouring points on one face are reached from the same configurations (Spitz, ch.
//! 4.2: neighbouring fpoints cluster together), so planning five hundred points of a face
//! where a dozen decide it only multiplies the cones, the clustering and the validation
//! — and the clustering's answer moves with every point added. A face sampled with more
//! than `graph::DENSE_FACE` points is planned on its strategy's own
//! `graph::REPRESENTATIVES` points, which the graph samples beside the face's
//! (`graph::add_points`): the same representatives at any density, so the same search.
//! The plan of the representatives is then [`extend`]ed: each of the face's points,
//! nearest representative first, joins every visit of that representative whose
//! configuration it validates in (at the nominal pose, with the part turned as the
//! plan's touches were validated, and not banned by the path stage); the
//! representatives then leave the plan ([`strip`]), and an orientation, probe or setup
//! left with nothing to touch goes with them. A point that validates with no
//! representative's configuration is where the points of a face differ: it is
//! *promoted*, planned by the next search beside the representatives ([`PROMOTIONS`]
//! searches at most; the knowledge is numbered per point, so a search over other points
//! starts its cones anew). A point still unreached after the last is dropped and
//! counted as the filter's are (`dropped_points`).
//!
//! **Decision: the cost of density.** The search costs about 15 ms a point on CTC 02
//! (cones, clustering, validation); a dense face's points cost one to three pose checks
//! each.
//!
//! **Decision: what is not extended.** The points of a face the plan puts on the table
//! (its table points stand in for it, ch. 3.6.2), and of a face the plan does not touch
//! (scanned, or left out under `allow_unmeasured`), stay as the search left them: no
//! configuration of theirs is a reason to search again.

use super::hlip::{
    quantise, FaceVisit, Hlip, Inspection, OrientNode, PlanPoint, PointRef, SetupNode,
};
use super::knowledge::{touch_check, Touch};
use super::machine::Machine;
use super::validate::PLACEMENT_TURN;
use super::{Ban, Input, Memo, PlanOptions};
use crate::access::pose::Contact;
use crate::access::pose::{orientation_dir, Head};
use crate::access::Scene;
use crate::diag::Diagnostics;
use crate::geometry::{FaceId, P3, V3};
use crate::graph::{Edge, MeasurementGraph, Node};
use crate::sample::Fpoint;
use rayon::prelude::*;
use std::collections::{BTreeMap, BTreeSet};

/// How many searches a planning runs at most: the first, and one for each round of
/// points promoted because no representative's configuration reached them.
pub(super) const PROMOTIONS: usize = 3;

/// A measurement graph whose dense faces hold their representatives.
pub(super) struct Thinned {
    /// The graph the search plans: the part's, each dense face's points replaced by its
    /// representatives and its promoted points.
    pub graph: MeasurementGraph,
    /// Per real point of `graph` (the first `full.len()`), its index in the full graph;
    /// the representatives follow them.
    pub full: Vec<usize>,
    /// The points of dense faces left out, by index in the full graph.
    pub dormant: Vec<usize>,
}

/// The graph with each dense face's points replaced by its representatives and the
/// `promoted` points; `None` where no face is dense.
pub(super) fn thin(g: &MeasurementGraph, promoted: &BTreeSet<usize>) -> Option<Thinned> {
    if g.representatives.is_empty() {
        return None;
    }
    let keep: Vec<bool> = g
        .fpoints
        .iter()
        .enumerate()
        .map(|(i, f)| !g.representatives.contains_key(&f.face) || promoted.contains(&i))
        .collect();
    let full: Vec<usize> = (0..keep.len()).filter(|&i| keep[i]).collect();
    let dormant: Vec<usize> = (0..keep.len()).filter(|&i| !keep[i]).collect();
    let mut new_index = vec![usize::MAX; keep.len()];
    for (n, &i) in full.iter().enumerate() {
        new_index[i] = n;
    }
    let mut graph = g.graph.filter_map(
        |_, node| match node {
            Node::Point(i) => keep[*i].then(|| Node::Point(new_index[*i])),
            other => Some(other.clone()),
        },
        |_, e| Some(*e),
    );
    let mut fpoints: Vec<Fpoint> = full.iter().map(|&i| g.fpoints[i].clone()).collect();
    let faces: Vec<(petgraph::graph::NodeIndex, FaceId)> = graph
        .node_indices()
        .filter_map(|n| match graph[n] {
            Node::Face { face, .. } => Some((n, face)),
            _ => None,
        })
        .collect();
    for (n, face) in faces {
        for r in g.representatives.get(&face).into_iter().flatten() {
            let pn = graph.add_node(Node::Point(fpoints.len()));
            graph.add_edge(n, pn, Edge::Point);
            fpoints.push(r.clone());
        }
    }
    let root = graph
        .node_indices()
        .find(|&n| matches!(graph[n], Node::Part))
        .unwrap_or(g.root);
    Some(Thinned {
        graph: MeasurementGraph {
            plan: g.plan.clone(),
            sampling: g.sampling.clone(),
            graph,
            root,
            fpoints,
            margin: g.margin,
            sensors: g.sensors.clone(),
            representatives: BTreeMap::new(),
        },
        full,
        dormant,
    })
}

/// The search's options for the thinned graph: the path stage's bans on representatives
/// and table points, renumbered.
pub(super) fn thinned_options(opts: &PlanOptions, t: &Thinned, all: usize) -> PlanOptions {
    let mut out = opts.clone();
    out.bans = opts
        .bans
        .iter()
        .filter_map(|b| {
            let point = if b.point >= all {
                Some(b.point - all + t.graph.fpoints.len())
            } else {
                t.full.binary_search(&b.point).ok()
            }?;
            Some(Ban { point, ..b.clone() })
        })
        .collect();
    out
}

/// The plan of the thinned graph renumbered to the full graph: its points every fpoint
/// of `g`, the table points, then the representatives (until [`strip`]); its visits'
/// indices mapped. Returns where the representatives start.
pub(super) fn renumber(hlip: &mut Hlip, t: &Thinned, g: &MeasurementGraph) -> usize {
    let (real, all) = (t.full.len(), g.fpoints.len());
    let searched = t.graph.fpoints.len();
    let tables = hlip.points.len() - searched;
    let map = |i: usize| match i {
        i if i < real => t.full[i],
        i if i < searched => all + tables + i - real,
        i => all + i - searched,
    };
    let mut old: Vec<PlanPoint> = std::mem::take(&mut hlip.points);
    let table_points = old.split_off(searched);
    let representatives = old.split_off(real);
    hlip.points = g
        .fpoints
        .iter()
        .enumerate()
        .map(|(i, f)| PlanPoint {
            at: PointRef::Graph(i),
            face: f.face,
            position: P3::from(quantise(&f.position.coords)),
            normal: quantise(&f.normal),
        })
        .chain(table_points)
        .chain(representatives)
        .collect();
    for v in visits_mut(hlip) {
        for p in &mut v.points {
            *p = map(*p);
        }
    }
    all + tables
}

/// Takes the representatives (points from `cut` on) out of the plan: out of its visits,
/// and the visits, inspections, orientations, probes and setups left with nothing to
/// touch with them; the plan is counted again.
pub(super) fn strip(hlip: &mut Hlip, cut: usize) {
    hlip.points.truncate(cut);
    for v in visits_mut(hlip) {
        v.points.retain(|&x| x < cut);
    }
    hlip.prune();
    hlip.setups.retain(|s| !s.probes.is_empty());
    let head = hlip.head;
    super::scan::recount(hlip, head);
}

/// Where a visit is in the plan: setup, probe, orientation, inspection and visit.
type At = (usize, usize, usize, usize, usize);

/// What [`extend`] could not place.
pub(super) struct Left {
    /// Points no configuration of the plan reached, on faces it touches: promoted.
    pub unreached: Vec<usize>,
    /// Points the path stage found no move to twice: dropped (`PATH_FAILURES`).
    pub unroutable: usize,
}

/// How many times the path stage may find no move to a dense face's point before the
/// point is dropped, as the filter drops a point few setups reach (ch. 3.6.3): its
/// neighbours measure the face, and each re-plan costs a search.
const PATH_FAILURES: usize = 2;

/// Extends the plan of the representatives to the `dormant` points.
pub(super) fn extend(
    input: &Input,
    opts: &PlanOptions,
    machine: &Machine,
    scene: &Scene,
    turned: bool,
    hlip: &mut Hlip,
    dormant: &[usize],
) -> Left {
    let g = input.graph;
    let failures = |q: usize| opts.bans.iter().filter(|b| b.point == q).count();
    let (dormant, unroutable): (Vec<usize>, Vec<usize>) =
        dormant.iter().partition(|&&q| failures(q) < PATH_FAILURES);
    let dormant = &dormant;
    // Per face, each touched point and the visits it is touched in.
    let mut reps: BTreeMap<FaceId, BTreeMap<usize, Vec<At>>> = BTreeMap::new();
    let mut on_table: BTreeSet<FaceId> = BTreeSet::new();
    for (at, v) in visits(hlip) {
        if !v.passes.is_empty() {
            continue;
        }
        if v.contact == Contact::Table {
            on_table.insert(v.face);
            continue;
        }
        let face = reps.entry(v.face).or_default();
        for &p in &v.points {
            face.entry(p).or_default().push(at);
        }
    }
    let v = Validator {
        scene,
        retract: input.plan.motion.prehit.max(input.plan.motion.retract),
        machine,
        opts,
        turned,
    };
    let (setups, points) = (&hlip.setups, &hlip.points);
    let placed: Vec<(usize, Placed)> = dormant
        .par_iter()
        .filter_map(|&q| {
            let f = &g.fpoints[q];
            if on_table.contains(&f.face) {
                return None;
            }
            let face = reps.get(&f.face)?;
            let check = |c: Config| v.config(setups, q, f, c);
            Some((q, place(f.position, face, points, setups, &check)))
        })
        .collect();
    let mut unreached = Vec::new();
    let mut changed: BTreeSet<At> = BTreeSet::new();
    for (q, placed) in placed {
        let placed = match placed {
            Placed::Nowhere => repair(hlip, &reps[&g.fpoints[q].face], &v, q, &g.fpoints[q]),
            other => other,
        };
        let ats = match placed {
            Placed::Join(ats) => ats,
            Placed::Elsewhere(config, like) => vec![visit_for(hlip, config, like)],
            Placed::Nowhere => {
                unreached.push(q);
                Vec::new()
            }
        };
        for at in ats {
            let (s, p, o, i, v) = at;
            hlip.setups[s].probes[p].orients[o].inspections[i].faces[v]
                .points
                .push(q);
            changed.insert(at);
        }
    }
    for (s, p, o, i, v) in changed {
        hlip.setups[s].probes[p].orients[o].inspections[i].faces[v]
            .points
            .sort_unstable();
    }
    Left {
        unreached,
        unroutable: unroutable.len(),
    }
}

/// Where a point no configuration of the plan reached at first goes: a configuration
/// points placed before it opened, else a new orientation ([`open_orientation`]).
fn repair(
    hlip: &mut Hlip,
    face: &BTreeMap<usize, Vec<At>>,
    v: &Validator,
    q: usize,
    f: &Fpoint,
) -> Placed {
    let check = |c: Config| v.config(&hlip.setups, q, f, c);
    match place(f.position, face, &hlip.points, &hlip.setups, &check) {
        Placed::Nowhere => {
            let Some(like) = nearest_visit(f.position, face, &hlip.points) else {
                return Placed::Nowhere;
            };
            let clear = |setup: &SetupNode, slot: usize, dir: V3| v.clear(setup, q, f, slot, dir);
            match open_orientation(hlip, v.machine, f, like, &clear) {
                Some(config) => Placed::Elsewhere(config, like),
                None => Placed::Nowhere,
            }
        }
        other => other,
    }
}

/// The first visit of the representative of `face` nearest to `at`.
fn nearest_visit(at: P3, face: &BTreeMap<usize, Vec<At>>, points: &[PlanPoint]) -> Option<At> {
    let (_, r) = face
        .keys()
        .map(|&r| ((points[r].position - at).norm(), r))
        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))?;
    face[&r].first().copied()
}

/// A new orientation for point `f` in the setup of visit `like`, where no configuration
/// of the plan reaches it: per probe the setup loads, the head's allowed orientations
/// nearest in direction to `like`'s, the first that `clear` passes. Added to the plan,
/// it is returned; `None` where none is clear. Another probe, or another setup, is the
/// search's to weigh (the hierarchy's costs): the point is promoted instead.
fn open_orientation(
    hlip: &mut Hlip,
    machine: &Machine,
    f: &Fpoint,
    like: At,
    clear: &dyn Fn(&SetupNode, usize, V3) -> bool,
) -> Option<Config> {
    let s = like.0;
    let setup = &hlip.setups[s];
    let toward = setup.probes[like.1].orients[like.2].direction;
    let up = setup.up;
    let loaded: Vec<usize> = setup.probes.iter().map(|p| p.probe.0).collect();
    let mut grid: Vec<(f64, usize, V3)> = (0..machine.grid.len())
        .filter(|&k| super::cluster::Set::has(&machine.grid_allowed, k))
        .map(|k| {
            let (a, b) = machine.grid[k];
            let dir = match machine.head {
                Head::Indexable => orientation_dir(&up, a, b),
                Head::Fixed => up,
            };
            (-dir.dot(&toward), k, dir)
        })
        // A stylus never stands below the surface it touches.
        .filter(|(_, _, dir)| dir.dot(&f.normal) > -1e-9)
        .collect();
    grid.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    for slot in loaded {
        let Some(&(_, k, dir)) = grid.iter().find(|(_, _, dir)| clear(setup, slot, *dir)) else {
            continue;
        };
        let (a, b) = machine.grid[k];
        let setup = &mut hlip.setups[s];
        let p = setup.probes.iter().position(|p| p.probe.0 == slot)?;
        let orients = &mut setup.probes[p].orients;
        let o = match orients.iter().position(|o| o.a == a && o.b == b) {
            Some(o) => o,
            None => {
                orients.push(OrientNode {
                    a,
                    b,
                    direction: quantise(&dir),
                    inspections: Vec::new(),
                });
                orients.len() - 1
            }
        };
        return Some((s, p, o));
    }
    None
}

/// A configuration of the plan: setup, probe and orientation, by index.
type Config = (usize, usize, usize);

/// Where a point of a dense face goes.
enum Placed {
    /// Into these visits of its representatives.
    Join(Vec<At>),
    /// Into this configuration of a setup that touches its face, as the visit `like`
    /// (its nearest representative's) measures the face.
    Elsewhere(Config, At),
    /// Nowhere the plan goes.
    Nowhere,
}

/// The visit of the configuration `config` that measures the face of visit `like` for
/// the same feature, made (with `like`'s records) where there is none.
fn visit_for(hlip: &mut Hlip, (s, p, o): Config, like: At) -> At {
    let (ls, lp, lo, li, lv) = like;
    let template = &hlip.setups[ls].probes[lp].orients[lo].inspections[li];
    let (feature, records) = (template.feature, template.records.clone());
    let face = template.faces[lv].face;
    let orient = &mut hlip.setups[s].probes[p].orients[o];
    let i = match orient.inspections.iter().position(|x| x.feature == feature) {
        Some(i) => i,
        None => {
            orient.inspections.push(Inspection {
                feature,
                faces: Vec::new(),
                records,
            });
            orient.inspections.len() - 1
        }
    };
    let faces = &mut orient.inspections[i].faces;
    let v = match faces
        .iter()
        .position(|x| x.face == face && x.contact == Contact::Part && x.passes.is_empty())
    {
        Some(v) => v,
        None => {
            faces.push(FaceVisit {
                face,
                contact: Contact::Part,
                points: Vec::new(),
                passes: Vec::new(),
            });
            faces.len() - 1
        }
    };
    (s, p, o, i, v)
}

/// Where a point at `at` goes: into the visits of its nearest representative (of
/// `face`'s, by distance, ties to the lower index) whose configuration `check` passes,
/// the next nearest representative's where none does; failing every representative,
/// into the first configuration `check` passes of the setups that touch the face,
/// nearest in direction to the nearest representative's first (an orientation the plan
/// already uses, so the plan gains no setup, probe or orientation).
fn place(
    at: P3,
    face: &BTreeMap<usize, Vec<At>>,
    points: &[PlanPoint],
    setups: &[SetupNode],
    check: &(dyn Fn(Config) -> bool + Sync),
) -> Placed {
    let mut near: Vec<(f64, usize)> = face
        .keys()
        .map(|&r| ((points[r].position - at).norm(), r))
        .collect();
    near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    // A configuration is checked once.
    let mut tried: BTreeMap<Config, bool> = BTreeMap::new();
    for &(_, r) in &near {
        let joined: Vec<At> = face[&r]
            .iter()
            .filter(|at| {
                let c = (at.0, at.1, at.2);
                *tried.entry(c).or_insert_with(|| check(c))
            })
            .copied()
            .collect();
        if !joined.is_empty() {
            let mut joined = joined;
            joined.extend(again(face, &near, &joined, &mut |c| {
                *tried.entry(c).or_insert_with(|| check(c))
            }));
            return Placed::Join(joined);
        }
    }
    let Some(&like) = near.first().and_then(|(_, r)| face[r].first()) else {
        return Placed::Nowhere;
    };
    let toward = setups[like.0].probes[like.1].orients[like.2].direction;
    let touching: BTreeSet<usize> = face.values().flatten().map(|at| at.0).collect();
    let mut others: Vec<(f64, Config)> = touching
        .iter()
        .flat_map(|&s| {
            setups[s]
                .probes
                .iter()
                .enumerate()
                .flat_map(move |(p, probe)| {
                    probe
                        .orients
                        .iter()
                        .enumerate()
                        .map(move |(o, orient)| (-orient.direction.dot(&toward), (s, p, o)))
                })
        })
        .filter(|(_, c)| !tried.contains_key(c))
        .collect();
    others.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    match others.into_iter().find(|&(_, c)| check(c)) {
        Some((_, c)) => Placed::Elsewhere(c, like),
        None => Placed::Nowhere,
    }
}

/// The visits, besides `joined`, of setups that measure the face again
/// (`remeasure`: a datum measured where it is read): in a setup each of whose
/// representatives is also touched in another setup, the point joins the visits of the
/// nearest representative touched there whose configuration `check` passes, as the
/// search measures there every point of the face the setup reaches.
fn again(
    face: &BTreeMap<usize, Vec<At>>,
    near: &[(f64, usize)],
    joined: &[At],
    check: &mut dyn FnMut(Config) -> bool,
) -> Vec<At> {
    let setups_of = |r: usize| face[&r].iter().map(|at| at.0).collect::<BTreeSet<usize>>();
    let mut all: BTreeSet<usize> = BTreeSet::new();
    for &r in face.keys() {
        all.extend(setups_of(r));
    }
    let done: BTreeSet<usize> = joined.iter().map(|at| at.0).collect();
    let mut out = Vec::new();
    for s in all.difference(&done) {
        let measured_again = face
            .keys()
            .filter(|&&r| setups_of(r).contains(s))
            .all(|&r| setups_of(r).len() > 1);
        if !measured_again {
            continue;
        }
        for &(_, r) in near.iter().filter(|(_, r)| setups_of(*r).contains(s)) {
            let here: Vec<At> = face[&r]
                .iter()
                .filter(|at| at.0 == *s && check((at.0, at.1, at.2)))
                .copied()
                .collect();
            if !here.is_empty() {
                out.extend(here);
                break;
            }
        }
    }
    out
}

/// What a touch of a dense face's point is validated against.
struct Validator<'a> {
    scene: &'a Scene,
    /// The approach validated: the longer of the pre-hit and retract moves.
    retract: f64,
    machine: &'a Machine,
    /// The path stage's bans.
    opts: &'a PlanOptions,
    /// Whether the plan's touches were validated with the part turned.
    turned: bool,
}

impl Validator<'_> {
    /// Whether point `q` (`f`) is clear touched in configuration `(s, p, o)` of the plan.
    fn config(&self, setups: &[SetupNode], q: usize, f: &Fpoint, (s, p, o): Config) -> bool {
        let setup = &setups[s];
        let probe = &setup.probes[p];
        self.clear(setup, q, f, probe.probe.0, probe.orients[o].direction)
    }

    /// Whether point `q` (`f`) is clear touched with probe `slot` along `dir` in
    /// `setup`: at the nominal pose, not banned, and with the part turned as the plan's
    /// own touches were validated — [`PLACEMENT_TURN`] either way, or as square as the
    /// setup already asks (`square_within`).
    fn clear(&self, setup: &SetupNode, q: usize, f: &Fpoint, slot: usize, dir: V3) -> bool {
        let up = setup.up;
        if self.opts.bans.iter().any(|b| b.is(q, slot, &up, &dir)) {
            return false;
        }
        let probe = &self.machine.probes[slot];
        let ok = |dir: V3| {
            let touch = Touch {
                point: f,
                contact: Contact::Part,
                probe,
                dir,
                up,
            };
            touch_check(
                self.scene,
                self.retract,
                &touch,
                setup.table,
                &setup.fixture,
            )
            .is_ok()
        };
        if !ok(dir) {
            return false;
        }
        let turn = match setup.square_within {
            Some(w) => w,
            None if self.turned => PLACEMENT_TURN,
            None => 0.0,
        };
        super::validate::turned_dirs(dir, &up, turn)
            .into_iter()
            .all(ok)
    }
}

/// Every visit of the plan, with where it is.
fn visits(hlip: &Hlip) -> impl Iterator<Item = (At, &FaceVisit)> {
    hlip.setups.iter().enumerate().flat_map(|(s, setup)| {
        setup.probes.iter().enumerate().flat_map(move |(p, probe)| {
            probe
                .orients
                .iter()
                .enumerate()
                .flat_map(move |(o, orient)| {
                    orient
                        .inspections
                        .iter()
                        .enumerate()
                        .flat_map(move |(i, insp)| {
                            insp.faces
                                .iter()
                                .enumerate()
                                .map(move |(v, visit)| ((s, p, o, i, v), visit))
                        })
                })
        })
    })
}

/// Every visit of the plan, to change.
fn visits_mut(hlip: &mut Hlip) -> impl Iterator<Item = &mut FaceVisit> {
    hlip.setups
        .iter_mut()
        .flat_map(|s| &mut s.probes)
        .flat_map(|p| &mut p.orients)
        .flat_map(|o| &mut o.inspections)
        .flat_map(|i| &mut i.faces)
}

/// Plans with the search `search` on each face's representatives and extends the plan to
/// the other points, promoting those it leaves unreached ([`PROMOTIONS`] searches at
/// most); the search as it is where no face is dense.
pub(super) fn plan_dense(
    input: &Input,
    opts: &PlanOptions,
    memo: &mut Memo,
    diags: &mut Diagnostics,
    search: &mut dyn FnMut(&Input, &PlanOptions, &mut Memo, &mut Diagnostics) -> Option<Hlip>,
) -> Option<Hlip> {
    let g = input.graph;
    let machine = Machine::new(input.model, input.plan);
    for round in 1..=PROMOTIONS {
        let Some(t) = thin(g, &memo.promoted) else {
            return search(input, opts, memo, diags);
        };
        memo.retarget(&t.full);
        let thinned = Input {
            graph: &t.graph,
            ..*input
        };
        let topts = thinned_options(opts, &t, g.fpoints.len());
        let mut own = Diagnostics::new();
        let Some(mut hlip) = search(&thinned, &topts, memo, &mut own) else {
            diags.extend(own);
            return None;
        };
        let cut = renumber(&mut hlip, &t, g);
        let scene = memo.scene(input.geometry);
        let turned = memo.turned();
        let left = extend(input, opts, &machine, &scene, turned, &mut hlip, &t.dormant);
        strip(&mut hlip, cut);
        if left.unreached.is_empty() || round == PROMOTIONS {
            hlip.summary.dropped_points += left.unreached.len() + left.unroutable;
            diags.extend(own);
            return Some(hlip);
        }
        memo.promoted.extend(left.unreached);
    }
    None
}
