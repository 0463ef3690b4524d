//! Hierarchical constraint satisfaction by clustering (seed ch. 3.5): cluster setups up
//! the measurement graph, pick a setup per top cluster and extract its measurement
//! sub-graph; cluster probes in it; then orientations.
//!
//! The graph is unfolded into a tree of *instances* (a feature under two tolerances is
//! two instances), so every leaf is one measurement path (tolerance, feature, face,
//! fpoint) and sub-graph extraction is a pruning of the tree. The hierarchy decides where
//! each variable is clustered: faces always; features for a `(T, F, *)` level; tolerances
//! for `(T, *)`; the part for `(*, *)`. A node without its level passes its children's
//! clusters up unmerged.
//!
//! **Decision: violations** count, per level, pairs of leaf measurements (tolerance,
//! feature, face, fpoint) of one group with different values; an orientation's value is
//! its probe direction in the part frame, so two setups differ in orientation too.
//! Order problems in a hierarchy (a probe level above a setup level) are refused by the
//! resolver, never reordered here.
//!
//! **Decision: selection.** In the weighted strategy a cell weighs its preference's
//! weight, other cells 0.5. A setup is picked (`pick_setup`) among the cluster's
//! underlying set: preferred setups by weight, then the axes (+z, −z, +x, −x, +y, −y),
//! then table setups, then the pixel deepest inside the cluster. Probe costs weigh
//! 1/cost and the cheapest probe of a cluster is chosen; orientation preferences weigh
//! like setups, then the smallest A wins.

use super::cluster::{cluster, Bits, Set, Strategy};
use super::knowledge::Knowledge;
use super::machine::Machine;
use crate::access::{Cell, CubeMap};
use crate::geometry::{FaceId, V3};
use crate::graph::{Edge, MeasurementGraph, Node};
use crate::model::{FeatureId, Group, Hierarchy, SameVar};
use petgraph::graph::NodeIndex;
use std::collections::{BTreeMap, BTreeSet};

/// What an instance stands for.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Kind {
    Part,
    Tol(usize),
    Feature(FeatureId),
    /// A face; `table` is the table alternative (index into [`Knowledge::tables`]) when
    /// the face belongs to a datum, reached as a datum, that can rest on the table.
    Face {
        face: FaceId,
        table: Option<usize>,
    },
    /// A datum face resting on the table: its children are table points.
    Table {
        face: FaceId,
    },
    /// A measuring point (graph fpoint or table point), with the face's table
    /// alternative.
    Point {
        point: usize,
        table: Option<usize>,
    },
}

/// A node of the unfolded measurement graph.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Inst {
    pub kind: Kind,
    pub children: Vec<Inst>,
}

/// Unfolds the measurement graph into instances, leaving out `dropped` fpoints and any
/// node left without leaves.
pub(crate) fn unfold(
    g: &MeasurementGraph,
    k: &Knowledge,
    m: &Machine,
    dropped: &BTreeSet<usize>,
) -> Option<Inst> {
    fn walk(
        g: &MeasurementGraph,
        k: &Knowledge,
        m: &Machine,
        dropped: &BTreeSet<usize>,
        n: NodeIndex,
        datum: bool,
        table: Option<usize>,
    ) -> Option<Inst> {
        let kind = match &g.graph[n] {
            Node::Part => Kind::Part,
            Node::Tolerance(t) => Kind::Tol(*t),
            Node::Feature { feature, .. } => Kind::Feature(*feature),
            Node::Face { face, on_table } => Kind::Face {
                face: *face,
                table: (datum && *on_table)
                    .then(|| k.tables.iter().position(|t| t.face == *face && t.alive))
                    .flatten(),
            },
            Node::Point(i) => {
                let reachable = table.is_some() || !k.setups(*i, m).is_empty();
                return (reachable && !dropped.contains(i)).then_some(Inst {
                    kind: Kind::Point { point: *i, table },
                    children: vec![],
                });
            }
        };
        let is_feature = matches!(kind, Kind::Feature(_));
        let table = match kind {
            Kind::Face { table, .. } => table,
            _ => None,
        };
        let children: Vec<Inst> = g
            .children(n)
            .into_iter()
            .filter_map(|(c, e)| {
                let d = if is_feature { datum } else { e == Edge::Datum };
                walk(g, k, m, dropped, c, d, table)
            })
            .collect();
        (!children.is_empty()).then_some(Inst { kind, children })
    }
    walk(g, k, m, dropped, g.root, false, None)
}

/// One node's clusters and its children's.
struct CNode<S> {
    clusters: Vec<Cl<S>>,
    children: Vec<CNode<S>>,
}

/// A cluster with links to the child clusters it holds.
struct Cl<S> {
    set: S,
    links: Vec<(u32, u32)>,
}

/// Clusters up an instance tree.
fn up<S: Set>(
    inst: &Inst,
    leaf: &dyn Fn(&Inst) -> S,
    merge: &dyn Fn(&Kind) -> bool,
    strategy: Strategy,
    weight: &dyn Fn(usize) -> f64,
) -> CNode<S> {
    if inst.children.is_empty() {
        return CNode {
            clusters: vec![Cl {
                set: leaf(inst),
                links: vec![],
            }],
            children: vec![],
        };
    }
    let children: Vec<CNode<S>> = inst
        .children
        .iter()
        .map(|c| up(c, leaf, merge, strategy, weight))
        .collect();
    let ids: Vec<(u32, u32)> = children
        .iter()
        .enumerate()
        .flat_map(|(c, n)| (0..n.clusters.len()).map(move |j| (c as u32, j as u32)))
        .collect();
    let set_of = |&(c, j): &(u32, u32)| &children[c as usize].clusters[j as usize].set;
    let clusters = if merge(&inst.kind) {
        let w: Vec<&S> = ids.iter().map(set_of).collect();
        cluster(&w, strategy, weight)
            .into_iter()
            .map(|cl| Cl {
                set: cl.set,
                links: cl.members.iter().map(|&m| ids[m]).collect(),
            })
            .collect()
    } else {
        ids.iter()
            .map(|id| Cl {
                set: set_of(id).clone(),
                links: vec![*id],
            })
            .collect()
    };
    CNode { clusters, children }
}

/// The measurement sub-graph of some of a node's clusters (ch. 3.5.2).
fn extract<S>(inst: &Inst, node: &CNode<S>, picks: &[u32]) -> Inst {
    if inst.children.is_empty() {
        return inst.clone();
    }
    let mut per: Vec<Vec<u32>> = vec![vec![]; inst.children.len()];
    for &k in picks {
        for &(c, j) in &node.clusters[k as usize].links {
            per[c as usize].push(j);
        }
    }
    let children = per
        .iter_mut()
        .enumerate()
        .filter(|(_, p)| !p.is_empty())
        .map(|(c, p)| {
            p.sort_unstable();
            p.dedup();
            extract(&inst.children[c], &node.children[c], p)
        })
        .collect();
    Inst {
        kind: inst.kind.clone(),
        children,
    }
}

/// Whether variable `var` is clustered at nodes of this kind under hierarchy `h`.
fn merges(h: &Hierarchy, var: SameVar, kind: &Kind) -> bool {
    let has = |g: Group| h.levels.iter().any(|l| l.var == var && l.group == g);
    match kind {
        Kind::Part => has(Group::All),
        Kind::Tol(_) => has(Group::Tol),
        Kind::Feature(_) => has(Group::TolFeature),
        Kind::Face { .. } | Kind::Table { .. } => true,
        Kind::Point { .. } => false,
    }
}

/// The leaves of a tree, in order.
pub(crate) fn leaves(inst: &Inst, out: &mut Vec<usize>) {
    match inst.kind {
        Kind::Point { point, .. } => out.push(point),
        _ => inst.children.iter().for_each(|c| leaves(c, out)),
    }
}

/// The tree without the leaves `drop` names, and without the nodes that leaves none;
/// `None` when nothing is left.
pub(crate) fn prune(inst: &Inst, drop: &dyn Fn(usize) -> bool) -> Option<Inst> {
    match inst.kind {
        Kind::Point { point, .. } => (!drop(point)).then(|| inst.clone()),
        _ => {
            let children: Vec<Inst> = inst
                .children
                .iter()
                .filter_map(|c| prune(c, drop))
                .collect();
            (!children.is_empty()).then(|| Inst {
                kind: inst.kind.clone(),
                children,
            })
        }
    }
}

/// The leaves of a tree with their table alternatives, in order.
fn leaf_kinds(inst: &Inst, out: &mut Vec<(usize, Option<usize>)>) {
    match inst.kind {
        Kind::Point { point, table } => out.push((point, table)),
        _ => inst.children.iter().for_each(|c| leaf_kinds(c, out)),
    }
}

/// Replaces datum faces by the table where the setup rests them on it.
fn rest_on_table(inst: &Inst, setup: usize, k: &Knowledge) -> Inst {
    if let Kind::Face {
        face,
        table: Some(t),
    } = inst.kind
    {
        let alt = &k.tables[t];
        if alt.cell == setup && alt.alive {
            return Inst {
                kind: Kind::Table { face },
                children: alt
                    .points
                    .iter()
                    .map(|&p| Inst {
                        kind: Kind::Point {
                            point: p,
                            table: None,
                        },
                        children: vec![],
                    })
                    .collect(),
            };
        }
    }
    Inst {
        kind: inst.kind.clone(),
        children: inst
            .children
            .iter()
            .map(|c| rest_on_table(c, setup, k))
            .collect(),
    }
}

/// A configuration and the measurements it takes.
#[derive(Debug, Clone)]
pub(crate) struct Branch {
    /// The setup's cell index.
    pub setup: usize,
    /// The setup's up direction (part frame).
    pub up: V3,
    /// The probe.
    pub probe: usize,
    /// The grid orientation.
    pub orient: usize,
    /// The measurement sub-graph.
    pub tree: Inst,
}

impl Branch {
    /// The touch of fpoint `point` in this branch's configuration.
    pub(crate) fn pip(&self, point: usize) -> super::validate::Pip {
        super::validate::Pip {
            point,
            probe: self.probe,
            setup: self.setup,
            orient: self.orient,
        }
    }
}

/// Something the solver could not place: a point with no orientation in a setup.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) struct Failure {
    pub point: usize,
    pub probe: usize,
    pub setup: usize,
    pub orient: Option<usize>,
}

/// Picks a setup from an underlying set: a preferred setup by weight, else an axis
/// (+z, −z, +x, −x, +y, −y), else a table setup, else the direction deepest inside.
fn pick_setup(mu: &CubeMap, k: &Knowledge) -> usize {
    let mut prefs = k.setup_prefs.clone();
    prefs.sort_by(|a, b| b.1.total_cmp(&a.1));
    if let Some(&(cell, _)) = prefs.iter().find(|(c, w)| *w > 0.0 && Set::has(mu, *c)) {
        return cell;
    }
    for d in [V3::z(), -V3::z(), V3::x(), -V3::x(), V3::y(), -V3::y()] {
        let cell = mu.index(mu.cell_of(&d));
        if matches!(mu.cell(cell), Cell::Preferred(_)) && Set::has(mu, cell) {
            return cell;
        }
    }
    if let Some(t) = k.tables.iter().find(|t| Set::has(mu, t.cell)) {
        return t.cell;
    }
    deepest(mu).map_or(0, |c| mu.index(c))
}

/// The cell deepest inside a cone: the first left by eroding it until one more erosion
/// would empty it (the whole sphere, which erosion never shrinks, gives its first cell).
pub(crate) fn deepest(mu: &CubeMap) -> Option<Cell> {
    let mut cur = mu.clone();
    loop {
        let eroded = cur.and(&cur.not().grow().not());
        if eroded.is_empty() || eroded == cur {
            break;
        }
        cur = eroded;
    }
    let first = cur.cells().next();
    first
}

/// For a bent probe, a setup of the cluster is only as good as the orientations it
/// leaves: among a few candidates (the usual pick, the axes, and cells spread over the
/// underlying set) take the one under which most of the cluster's points keep an
/// orientation for some probe.
fn pick_bent_setup(mu: &CubeMap, sub: &Inst, k: &mut Knowledge, m: &Machine) -> usize {
    let mut cands = vec![pick_setup(mu, k)];
    for d in [V3::z(), -V3::z(), V3::x(), -V3::x(), V3::y(), -V3::y()] {
        let cell = mu.index(mu.cell_of(&d));
        if Set::has(mu, cell) {
            cands.push(cell);
        }
    }
    let cells: Vec<Cell> = mu.cells().collect();
    let step = cells.len().div_ceil(BENT_SETUP_SAMPLES).max(1);
    cands.extend(
        cells
            .iter()
            .skip(step / 2)
            .step_by(step)
            .map(|&c| mu.index(c)),
    );
    let mut seen = BTreeSet::new();
    cands.retain(|c| seen.insert(*c));
    if cands.len() == 1 {
        return cands[0];
    }
    let mut pts = Vec::new();
    leaves(sub, &mut pts);
    pts.sort_unstable();
    pts.dedup();
    let mut best = (0usize, cands[0]);
    for &s in &cands {
        let up = k.setup_dir(s);
        // Each point's first probe is asked first: those in parallel.
        let first: Vec<(usize, usize)> = pts
            .iter()
            .filter_map(|&f| k.probes(f, s, m).ones().next().map(|p| (f, p)))
            .collect();
        k.prefetch_orientations(&first, s, m);
        let mut ok = 0;
        for &f in &pts {
            let probes = k.probes(f, s, m);
            if probes
                .ones()
                .any(|p| !k.orientations(f, p, s, &up, m).is_empty())
            {
                ok += 1;
            }
        }
        if ok > best.0 {
            best = (ok, s);
        }
        if ok == pts.len() {
            break;
        }
    }
    best.1
}

/// How many cells of a cluster's underlying set a bent probe's setup pick tries.
const BENT_SETUP_SAMPLES: usize = 8;

/// Picks the cheapest probe, the lowest rack index on a tie.
fn pick_probe(mu: &Bits, m: &Machine) -> usize {
    mu.ones()
        .min_by(|&a, &b| m.costs[a].total_cmp(&m.costs[b]).then(a.cmp(&b)))
        .unwrap_or(0)
}

/// Picks the preferred orientation by weight, then the smallest tilt A, then the
/// smallest |B|.
fn pick_orient(mu: &Bits, m: &Machine) -> usize {
    mu.ones()
        .min_by(|&x, &y| {
            m.grid_weight[y]
                .total_cmp(&m.grid_weight[x])
                .then(m.grid[x].0.total_cmp(&m.grid[y].0))
                .then(m.grid[x].1.abs().total_cmp(&m.grid[y].1.abs()))
                .then(x.cmp(&y))
        })
        .unwrap_or(0)
}

/// The setups each leaf of a tree may take, by (point, table alternative): the point's
/// setups, and the table's setup for a table point. Solving reads them and changes none
/// of what they come from, so every strategy of a round shares one computation.
pub(crate) type SetupSets = BTreeMap<(usize, Option<usize>), CubeMap>;

/// [`SetupSets`] of the leaves of `root`.
pub(crate) fn setup_sets(root: &Inst, k: &Knowledge, m: &Machine) -> SetupSets {
    let mut pts = Vec::new();
    leaf_kinds(root, &mut pts);
    let mut setup_sets = SetupSets::new();
    for key in pts {
        setup_sets.entry(key).or_insert_with(|| {
            let mut s = k.setups(key.0, m);
            if let Some(t) = key.1 {
                let c = s.cell(k.tables[t].cell);
                s.set(c, true);
            }
            s
        });
    }
    setup_sets
}

/// The clustering of setups (step 1 of [`solve`]) under each strategy of
/// [`Strategy::ALL`], in that order: pure functions of the knowledge, so the four are
/// clustered in parallel before the rounds' sequential steps.
pub(crate) fn setup_trees(
    root: &Inst,
    k: &Knowledge,
    h: &Hierarchy,
    setup_sets: &SetupSets,
) -> Vec<SetupTree> {
    use rayon::prelude::*;
    Strategy::ALL
        .par_iter()
        .map(|&strategy| {
            let sw = |e: usize| k.setup_weight.get(&e).copied().unwrap_or(0.5);
            let leaf_setup = |i: &Inst| match i.kind {
                Kind::Point { point, table } => setup_sets[&(point, table)].clone(),
                _ => unreachable!("leaves are points"),
            };
            SetupTree(up(
                root,
                &leaf_setup,
                &|kind| merges(h, SameVar::Setup, kind),
                strategy,
                &sw,
            ))
        })
        .collect()
}

/// One strategy's clustering of setups ([`setup_trees`]).
pub(crate) struct SetupTree(CNode<CubeMap>);

/// Runs the main algorithm (ch. 3.5.3) with one clustering strategy, its setups
/// clustered ([`setup_trees`]).
pub(crate) fn solve(
    root: &Inst,
    k: &mut Knowledge,
    m: &Machine,
    h: &Hierarchy,
    strategy: Strategy,
    SetupTree(tree): SetupTree,
) -> Result<Vec<Branch>, Vec<Failure>> {
    // 1. Setups (clustered), each cluster's setup picked.
    let mut by_setup: Vec<(usize, Inst)> = Vec::new();
    for (j, cl) in tree.clusters.iter().enumerate() {
        let sub = extract(root, &tree, &[j as u32]);
        let s = if m.head.indexable() {
            pick_bent_setup(&cl.set, &sub, k, m)
        } else {
            pick_setup(&cl.set, k)
        };
        by_setup.push((s, rest_on_table(&sub, s, k)));
    }
    // 2. Probes, 3. orientations.
    let mut out = Vec::new();
    let mut failures = Vec::new();
    let pw = |p: usize| 1.0 / m.costs.get(p).copied().unwrap_or(1.0).max(1e-3);
    for (s, sub) in by_setup {
        let upd = k.setup_dir(s);
        let mut probe_sets: BTreeMap<usize, Bits> = BTreeMap::new();
        let mut pts = Vec::new();
        leaves(&sub, &mut pts);
        for &p in &pts {
            probe_sets.entry(p).or_insert_with(|| {
                if p >= k.graph_points {
                    Bits::of(
                        m.probes.len(),
                        (0..m.probes.len()).filter(|&q| m.allowed[q]),
                    )
                } else {
                    k.probes(p, s, m)
                }
            });
        }
        let leaf_probe = |i: &Inst| match i.kind {
            Kind::Point { point, .. } => probe_sets[&point].clone(),
            _ => unreachable!("leaves are points"),
        };
        let ptree = up(
            &sub,
            &leaf_probe,
            &|kind| merges(h, SameVar::Probe, kind),
            strategy,
            &pw,
        );
        for (j, cl) in ptree.clusters.iter().enumerate() {
            let p = pick_probe(&cl.set, m);
            let psub = extract(&sub, &ptree, &[j as u32]);
            let mut pts = Vec::new();
            leaves(&psub, &mut pts);
            let pairs: Vec<(usize, usize)> = pts.iter().map(|&f| (f, p)).collect();
            k.prefetch_orientations(&pairs, s, m);
            let mut orient_sets: BTreeMap<usize, Bits> = BTreeMap::new();
            for &f in &pts {
                if orient_sets.contains_key(&f) {
                    continue;
                }
                let o = k.orientations(f, p, s, &upd, m);
                if o.is_empty() {
                    failures.push(Failure {
                        point: f,
                        probe: p,
                        setup: s,
                        orient: None,
                    });
                }
                orient_sets.insert(f, o);
            }
            if !failures.is_empty() {
                continue;
            }
            let leaf_orient = |i: &Inst| match i.kind {
                Kind::Point { point, .. } => orient_sets[&point].clone(),
                _ => unreachable!("leaves are points"),
            };
            let ow = |o: usize| m.grid_weight.get(o).copied().unwrap_or(0.5);
            let otree = up(
                &psub,
                &leaf_orient,
                &|kind| merges(h, SameVar::Orient, kind),
                strategy,
                &ow,
            );
            for (j, cl) in otree.clusters.iter().enumerate() {
                out.push(Branch {
                    setup: s,
                    up: upd,
                    probe: p,
                    orient: pick_orient(&cl.set, m),
                    tree: extract(&psub, &otree, &[j as u32]),
                });
            }
        }
    }
    if failures.is_empty() {
        Ok(out)
    } else {
        failures.sort();
        failures.dedup();
        Err(failures)
    }
}

/// One measurement: a leaf path, for counting violations.
struct Meas {
    tol: Option<usize>,
    feature: Option<FeatureId>,
    setup: usize,
    probe: usize,
    dir: [i64; 3],
}

fn measurements(b: &Branch, m: &Machine, out: &mut Vec<Meas>) {
    let dir = if m.head.indexable() {
        crate::access::pose::orientation_dir(&b.up, m.grid[b.orient].0, m.grid[b.orient].1)
    } else {
        b.up
    };
    let key = [dir.x, dir.y, dir.z].map(|c| (c * 1e6).round() as i64);
    fn rec(
        i: &Inst,
        tol: Option<usize>,
        feat: Option<FeatureId>,
        f: &mut dyn FnMut(Option<usize>, Option<FeatureId>),
    ) {
        match i.kind {
            Kind::Point { .. } => f(tol, feat),
            Kind::Tol(t) => i.children.iter().for_each(|c| rec(c, Some(t), feat, f)),
            Kind::Feature(x) => i.children.iter().for_each(|c| rec(c, tol, Some(x), f)),
            _ => i.children.iter().for_each(|c| rec(c, tol, feat, f)),
        }
    }
    rec(&b.tree, None, None, &mut |tol, feature| {
        out.push(Meas {
            tol,
            feature,
            setup: b.setup,
            probe: b.probe,
            dir: key,
        })
    });
}

/// Per level of the hierarchy, the violated binary same-constraints: pairs of
/// measurements of one group with different values.
pub(crate) fn violations(branches: &[Branch], m: &Machine, h: &Hierarchy) -> Vec<u64> {
    let mut all = Vec::new();
    for b in branches {
        measurements(b, m, &mut all);
    }
    h.levels
        .iter()
        .map(|l| {
            // Per group (tolerance, feature), the count of each value.
            type Counts = BTreeMap<Vec<i64>, u64>;
            let mut groups: BTreeMap<(Option<usize>, Option<FeatureId>), Counts> = BTreeMap::new();
            for x in &all {
                let g = match l.group {
                    Group::All => (None, None),
                    Group::Tol => (x.tol, if x.tol.is_none() { x.feature } else { None }),
                    Group::TolFeature => (x.tol, x.feature),
                };
                let v = match l.var {
                    SameVar::Setup => vec![x.setup as i64],
                    SameVar::Probe => vec![x.probe as i64],
                    SameVar::Orient => x.dir.to_vec(),
                };
                *groups.entry(g).or_default().entry(v).or_default() += 1;
            }
            groups
                .values()
                .map(|vals| {
                    let n: u64 = vals.values().sum();
                    let same: u64 = vals.values().map(|c| c * c).sum();
                    (n * n - same) / 2
                })
                .sum()
        })
        .collect()
}
