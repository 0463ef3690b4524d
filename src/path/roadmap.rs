//! The roadmap of one group (seed ch. 5.3–5.4): nodes are the goals (each point's
//! stand-off position, where the touch starts and ends) and whatever the enhancement
//! step adds; edges are paths of the CMM local planner, every segment checked by
//! [`Pose::segment`].
//!
//! The local planner tries, in order (ch. 5.4.2): the straight segment; up the probe
//! axis, across, down; up the probe axis, then up the ram axis to the clearance height,
//! across, and back down both. The enhancement step (ch. 5.4.3) adds, while goals are in
//! more than one component: goals lifted along the probe and ram axes, points on the
//! faces of the goals left out, then random points (a fixed seed). Shortest paths between
//! goals come from Dijkstra on the result (the all-pairs step of ch. 5.3.2).

use crate::access::pose::{Blocker, Pose};
use crate::geometry::{P3, V3};
use rayon::prelude::*;
use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

/// Neighbours each new node is connected to.
const K: usize = 8;

/// How many of the closest node pairs [`Roadmap::bridge`] tries between a component
/// left out and the main one.
const BRIDGES: usize = 16;

/// How a local path between two nodes runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Route {
    /// The straight segment.
    Straight,
    /// Up the probe axis by `h`, across, down.
    Probe(f64),
    /// Up the probe axis by `h`, up the ram axis to the clearance height, across, down.
    ProbeRam(f64),
}

/// An edge.
#[derive(Debug, Clone, Copy)]
struct Edge {
    to: usize,
    length: f64,
    route: Route,
}

/// The roadmap of one group.
pub(crate) struct Roadmap<'a> {
    pose: &'a Pose<'a>,
    /// Node positions (tip centre, part frame); the first `goals` are the goals.
    pub nodes: Vec<P3>,
    goals: usize,
    adj: Vec<Vec<Edge>>,
    dir: V3,
    up: V3,
    /// The tip-centre height along `up` of the clearance plane.
    pub height: f64,
    /// How far the part reaches along the probe axis.
    top_dir: f64,
    /// Segments checked.
    pub checks: usize,
}

/// Why goals could not be connected: the goals left out and what blocked the first.
#[derive(Debug, Clone)]
pub(crate) struct Disconnected {
    /// The first goal left out.
    pub goal: usize,
    /// Every goal left out, `goal` first.
    pub stray: Vec<usize>,
    /// What hit on `goal`'s straight move towards the nearest connected goal; `None`
    /// when that move is clear but every route the roadmap tried is not.
    pub blocker: Option<crate::access::Blocker>,
}

impl<'a> Roadmap<'a> {
    /// A roadmap over `goals`; `vertices` bound the part (for lift heights); `height` is
    /// the clearance plane's tip height along the ram axis.
    pub fn new(
        pose: &'a Pose<'a>,
        goals: Vec<P3>,
        dir: V3,
        vertices: &[P3],
        height: f64,
    ) -> Roadmap<'a> {
        let top_dir = vertices
            .iter()
            .map(|v| v.coords.dot(&dir))
            .fold(f64::NEG_INFINITY, f64::max);
        let n = goals.len();
        Roadmap {
            pose,
            nodes: goals,
            goals: n,
            adj: vec![Vec::new(); n],
            dir,
            up: pose.up(),
            height,
            top_dir,
            checks: 0,
        }
    }

    /// The waypoints of a route from `p` to `q`, without `p`, with `q`.
    pub(crate) fn waypoints(&self, p: &P3, q: &P3, route: Route) -> Vec<P3> {
        match route {
            Route::Straight => vec![*q],
            Route::Probe(h) => vec![p + self.dir * h, q + self.dir * h, *q],
            Route::ProbeRam(h) => {
                let (p1, q1) = (p + self.dir * h, q + self.dir * h);
                let (p2, q2) = (self.raised(&p1), self.raised(&q1));
                let mut w = vec![p1, p2, q2, q1, *q];
                w.dedup_by(|a, b| (*a - *b).norm() < 1e-9);
                w
            }
        }
    }

    /// `x` moved up the ram axis to the clearance height (or left where it is above).
    fn raised(&self, x: &P3) -> P3 {
        let h = self.height - x.coords.dot(&self.up);
        if h > 0.0 {
            x + self.up * h
        } else {
            *x
        }
    }

    /// The routes the local planner tries between `p` and `q`, simplest first.
    fn routes(&self, p: &P3, q: &P3) -> Vec<Route> {
        let mut out = vec![Route::Straight];
        // Up the probe axis: a short hop, then far enough to clear the part's extent
        // along the axis.
        let clear = (self.top_dir - p.coords.dot(&self.dir))
            .max(self.top_dir - q.coords.dot(&self.dir))
            + (self.height - self.top_dir.min(self.height)).max(5.0);
        for h in [5.0, 20.0, clear] {
            if h <= clear + 1e-9 && !out.contains(&Route::Probe(h)) {
                out.push(Route::Probe(h));
            }
        }
        if (self.dir - self.up).norm() > 1e-9 {
            for h in [0.0, 5.0, 20.0] {
                out.push(Route::ProbeRam(h));
            }
        }
        out
    }

    /// Checks a route; its length when every segment is clear, else what hit first.
    fn check(&self, p: &P3, q: &P3, route: Route) -> (Result<f64, Blocker>, usize) {
        let mut at = *p;
        let mut length = 0.0;
        let mut checks = 0;
        for w in self.waypoints(p, q, route) {
            checks += 1;
            if let Err(e) = self.pose.segment(&at, &w) {
                return (Err(e), checks);
            }
            length += (w - at).norm();
            at = w;
        }
        (Ok(length), checks)
    }

    /// The local planner: the first route that is clear.
    fn connect(&self, p: &P3, q: &P3) -> (Result<(Route, f64), Option<Blocker>>, usize) {
        let mut first_err = None;
        let mut checks = 0;
        for route in self.routes(p, q) {
            let (r, c) = self.check(p, q, route);
            checks += c;
            match r {
                Ok(l) => return (Ok((route, l)), checks),
                Err(e) => {
                    first_err.get_or_insert(e);
                }
            }
        }
        (Err(first_err), checks)
    }

    /// The k nearest other nodes of node `i` among the first `limit` nodes, nearest first
    /// (ties by index). A bounded max-heap of the K best so far: no list of every node
    /// per node (those lists, kept at full capacity, held 2.4 GB on NIST FTC 06 at
    /// 10,000 points).
    fn nearest(&self, i: usize, limit: usize) -> Vec<usize> {
        let mut best: BinaryHeap<Near> = BinaryHeap::with_capacity(K + 1);
        for j in (0..limit).filter(|&j| j != i) {
            let pair = Near((self.nodes[j] - self.nodes[i]).norm(), j, 0);
            if best.len() < K {
                best.push(pair);
            } else if best.peek().is_some_and(|worst| pair < *worst) {
                best.pop();
                best.push(pair);
            }
        }
        best.into_sorted_vec().iter().map(|n| n.1).collect()
    }

    /// Connects nodes `from..` to their neighbours (in parallel, applied in order).
    fn link(&mut self, from: usize) {
        let n = self.nodes.len();
        let near: Vec<Vec<usize>> = (from..n)
            .into_par_iter()
            .map(|i| self.nearest(i, n))
            .collect();
        let mut pairs: Vec<(usize, usize)> = Vec::new();
        for (i, js) in (from..n).zip(near) {
            for j in js {
                pairs.push((i.min(j), i.max(j)));
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        self.join(pairs);
    }

    /// Adds the edges between the `pairs` of nodes the local planner connects; returns
    /// how many.
    fn join(&mut self, mut pairs: Vec<(usize, usize)>) -> usize {
        pairs.retain(|&(i, j)| !self.adj[i].iter().any(|e| e.to == j));
        let mut joined = 0;
        let results: Vec<_> = pairs
            .par_iter()
            .map(|&(i, j)| self.connect(&self.nodes[i], &self.nodes[j]))
            .collect();
        for (&(i, j), (r, c)) in pairs.iter().zip(results) {
            self.checks += c;
            if let Ok((route, length)) = r {
                joined += 1;
                self.adj[i].push(Edge {
                    to: j,
                    length,
                    route,
                });
                // The reverse route mirrors the waypoints; the same checks cover it.
                self.adj[j].push(Edge {
                    to: i,
                    length,
                    route,
                });
            }
        }
        joined
    }

    /// Tries to join each component holding stray goals to the main one through its
    /// `BRIDGES` closest pairs of nodes. K-nearest linking can leave a dense cluster
    /// linked only to itself: the stand-offs of a bore sampled densely all sit near its
    /// axis, and their lifted copies are one another's nearest neighbours.
    fn bridge(&mut self) -> usize {
        let comp = self.components();
        let main = self.main_component(&comp);
        let mut islands: Vec<usize> = (0..self.goals)
            .map(|g| comp[g])
            .filter(|&c| c != main)
            .collect();
        islands.sort_unstable();
        islands.dedup();
        let main_nodes: Vec<usize> = (0..self.nodes.len()).filter(|&j| comp[j] == main).collect();
        let mut pairs = Vec::new();
        for island in islands {
            // The BRIDGES closest pairs, by distance and then index: a bounded max-heap,
            // not every pair sorted (an island of a hundred nodes against a main
            // component of forty thousand).
            let mut near: BinaryHeap<Near> = BinaryHeap::with_capacity(BRIDGES + 1);
            for i in (0..self.nodes.len()).filter(|&i| comp[i] == island) {
                for &j in &main_nodes {
                    let pair = Near((self.nodes[i] - self.nodes[j]).norm(), i, j);
                    if near.len() < BRIDGES {
                        near.push(pair);
                    } else if near.peek().is_some_and(|worst| pair < *worst) {
                        near.pop();
                        near.push(pair);
                    }
                }
            }
            pairs.extend(
                near.into_sorted_vec()
                    .iter()
                    .map(|&Near(_, i, j)| (i.min(j), i.max(j))),
            );
        }
        pairs.sort_unstable();
        pairs.dedup();
        self.join(pairs)
    }

    /// Adds the nodes that are clear; returns how many.
    fn insert(&mut self, candidates: Vec<P3>) -> usize {
        let free: Vec<bool> = candidates
            .par_iter()
            .map(|x| self.pose.free(x).is_ok())
            .collect();
        self.checks += candidates.len();
        let from = self.nodes.len();
        let mut taken = Cells::new(&self.nodes);
        for (x, ok) in candidates.into_iter().zip(free) {
            if ok && !taken.holds_near(&self.nodes, &x) {
                taken.add(&x, self.nodes.len());
                self.nodes.push(x);
                self.adj.push(Vec::new());
            }
        }
        let added = self.nodes.len() - from;
        if added > 0 {
            self.link(from);
        }
        added
    }

    /// The component of every node (the lowest node index in it).
    fn components(&self) -> Vec<usize> {
        let n = self.nodes.len();
        let mut comp = vec![usize::MAX; n];
        for s in 0..n {
            if comp[s] != usize::MAX {
                continue;
            }
            comp[s] = s;
            let mut stack = vec![s];
            while let Some(u) = stack.pop() {
                for e in &self.adj[u] {
                    if comp[e.to] == usize::MAX {
                        comp[e.to] = s;
                        stack.push(e.to);
                    }
                }
            }
        }
        comp
    }

    /// Goals outside the component holding the most goals (ties: the lower index).
    fn stray_goals(&self) -> Vec<usize> {
        let comp = self.components();
        let main = self.main_component(&comp);
        (0..self.goals).filter(|&g| comp[g] != main).collect()
    }

    /// The component holding the most goals (ties: the lower index), given each node's.
    fn main_component(&self, comp: &[usize]) -> usize {
        let mut count = vec![0usize; self.nodes.len()];
        for g in 0..self.goals {
            count[comp[g]] += 1;
        }
        let mut main = 0;
        for c in 0..count.len() {
            if count[c] > count[main] {
                main = c;
            }
        }
        main
    }

    /// Builds the roadmap: initialisation, then enhancement until the goals are
    /// connected. `face_points(goal)` gives extra stand-off positions on a goal's face.
    pub fn build(&mut self, face_points: impl Fn(usize) -> Vec<P3>) -> Result<usize, Disconnected> {
        self.link(0);
        let mut added = 0;
        let mut rng = 0x9E37_79B9_7F4A_7C15u64;
        for round in 0..8 {
            let stray = self.stray_goals();
            if stray.is_empty() {
                return Ok(added);
            }
            let mut cands = Vec::new();
            match round {
                // Goals lifted along the probe axis and then the ram axis.
                0 => {
                    for g in 0..self.goals {
                        let x = self.nodes[g];
                        for h in [5.0, 20.0] {
                            cands.push(x + self.dir * h);
                            cands.push(self.raised(&(x + self.dir * h)));
                        }
                        cands.push(self.raised(&x));
                    }
                }
                // Points on the faces of the goals left out.
                1 | 2 => {
                    for &g in &stray {
                        cands.extend(face_points(g));
                    }
                }
                // Random points around the part.
                _ => {
                    let (lo, hi) = self.bounds();
                    for _ in 0..64 {
                        let mut r = || {
                            rng ^= rng << 13;
                            rng ^= rng >> 7;
                            rng ^= rng << 17;
                            (rng >> 11) as f64 / (1u64 << 53) as f64
                        };
                        let (a, b, c) = (r(), r(), r());
                        cands.push(P3::new(
                            lo.x + a * (hi.x - lo.x),
                            lo.y + b * (hi.y - lo.y),
                            lo.z + c * (hi.z - lo.z),
                        ));
                    }
                }
            }
            added += self.insert(cands);
        }
        self.bridge();
        let stray = self.stray_goals();
        match stray.first() {
            None => Ok(added),
            Some(&goal) => {
                let main: Vec<usize> = (0..self.goals).filter(|g| !stray.contains(g)).collect();
                let near = main
                    .iter()
                    .min_by(|&&a, &&b| {
                        let d = |k: usize| (self.nodes[k] - self.nodes[goal]).norm();
                        d(a).total_cmp(&d(b))
                    })
                    .copied();
                let blocker =
                    near.and_then(|m| self.pose.segment(&self.nodes[goal], &self.nodes[m]).err());
                Err(Disconnected {
                    goal,
                    stray,
                    blocker,
                })
            }
        }
    }

    /// The box around the nodes, grown by the clearance margin.
    fn bounds(&self) -> (P3, P3) {
        let mut lo = self.nodes[0];
        let mut hi = self.nodes[0];
        for x in &self.nodes {
            lo = lo.inf(x);
            hi = hi.sup(x);
        }
        let m = V3::repeat(10.0);
        (lo - m, hi + m)
    }

    /// Dijkstra from goal `s` on `scratch` until `stop` says the search may end (given
    /// the node just settled and how many goals are settled), leaving each reached
    /// node's distance and predecessor (with the index of the edge from it) there. The
    /// nodes settle in one order (by distance, ties by index), so a search stopped early
    /// agrees with the whole one on every node it settled.
    fn search(&self, s: usize, scratch: &mut Scratch, stop: impl Fn(usize, usize) -> bool) {
        let Scratch {
            dist,
            prev,
            heap,
            set,
        } = scratch;
        let mut settled_goals = 0;
        dist[s] = 0.0;
        set.push(s);
        heap.push(Reverse(Near(0.0, s, 0)));
        while let Some(Reverse(Near(d, u, _))) = heap.pop() {
            if d > dist[u] {
                continue;
            }
            if u < self.goals {
                settled_goals += 1;
            }
            if stop(u, settled_goals) {
                break;
            }
            for (k, e) in self.adj[u].iter().enumerate() {
                let nd = d + e.length;
                if nd < dist[e.to] - 1e-12 {
                    if dist[e.to] == f64::INFINITY {
                        set.push(e.to);
                    }
                    dist[e.to] = nd;
                    prev[e.to] = (u as u32, k as u32);
                    heap.push(Reverse(Near(nd, e.to, 0)));
                }
            }
        }
    }

    /// The shortest-path distances between goals. The paths themselves are found again
    /// when asked for ([`Paths::path`]): a group visits each goal once, so it asks for
    /// about as many paths as it has goals, and a tree per goal is goals × nodes
    /// entries.
    pub(crate) fn shortest_paths(&self) -> Paths {
        let goals = self.goals;
        let dist: Vec<Vec<f64>> = (0..goals)
            .into_par_iter()
            .map_init(
                || Scratch::new(self.nodes.len()),
                |scratch, g| {
                    self.search(g, scratch, |_, settled| settled == goals);
                    let d = scratch.dist[..goals].to_vec();
                    scratch.reset();
                    d
                },
            )
            .collect();
        Paths {
            dist,
            scratch: std::sync::Mutex::new(Scratch::new(self.nodes.len())),
        }
    }
}

/// What searches reuse: distances and predecessors (unset but where the search under
/// way set them), the heap, and the nodes set. A search per goal over tens of thousands
/// of nodes, each on fresh arrays, was mostly page faults.
struct Scratch {
    dist: Vec<f64>,
    prev: Vec<(u32, u32)>,
    heap: BinaryHeap<Reverse<Near>>,
    set: Vec<usize>,
}

impl Scratch {
    fn new(n: usize) -> Scratch {
        Scratch {
            dist: vec![f64::INFINITY; n],
            prev: vec![NO_EDGE; n],
            heap: BinaryHeap::new(),
            set: Vec::new(),
        }
    }

    /// Unsets what the last search set.
    fn reset(&mut self) {
        for &k in &self.set {
            self.dist[k] = f64::INFINITY;
            self.prev[k] = NO_EDGE;
        }
        self.set.clear();
        self.heap.clear();
    }
}

/// No predecessor.
const NO_EDGE: (u32, u32) = (u32::MAX, u32::MAX);

/// Shortest-path distances between the goals of a roadmap, and a scratch to find a path
/// on (taken one path at a time).
pub(crate) struct Paths {
    dist: Vec<Vec<f64>>,
    scratch: std::sync::Mutex<Scratch>,
}

impl Paths {
    /// The length of the shortest path between goals `a` and `b`.
    pub fn d(&self, a: usize, b: usize) -> f64 {
        self.dist[a][b]
    }

    /// The waypoints from goal `a` to goal `b` (without `a`, with `b`): Dijkstra from
    /// `a` again, until `b` settles.
    pub fn path(&self, map: &Roadmap, a: usize, b: usize) -> Vec<P3> {
        // Walk back from b to a in a's tree; each edge's route runs from its
        // predecessor towards the node.
        let mut scratch = self.scratch.lock().unwrap_or_else(|e| e.into_inner());
        map.search(a, &mut scratch, |u, _| u == b);
        let mut chain = Vec::new();
        let mut at = b;
        while at != a {
            let (p, k) = scratch.prev[at];
            if (p, k) == NO_EDGE {
                break;
            }
            let (p, k) = (p as usize, k as usize);
            chain.push((p, at, map.adj[p][k].route));
            at = p;
        }
        scratch.reset();
        drop(scratch);
        chain.reverse();
        let mut out = Vec::new();
        for (p, q, route) in chain {
            out.extend(map.waypoints(&map.nodes[p], &map.nodes[q], route));
        }
        out
    }
}

/// Two nodes less than this apart are one (mm).
const SAME_NODE: f64 = 1e-6;

/// Nodes hashed by the cell of a grid they lie in, to find a node within
/// [`SAME_NODE`] of a new one among tens of thousands without comparing them all.
struct Cells(std::collections::HashMap<[i64; 3], Vec<usize>>);

/// The side of a [`Cells`] cell (mm): a node within [`SAME_NODE`] of a point lies in the
/// point's cell or one of its neighbours.
const CELL: f64 = 1e-3;

impl Cells {
    fn new(nodes: &[P3]) -> Cells {
        let mut c = Cells(std::collections::HashMap::with_capacity(nodes.len()));
        for (i, x) in nodes.iter().enumerate() {
            c.add(x, i);
        }
        c
    }

    fn key(x: &P3) -> [i64; 3] {
        [x.x, x.y, x.z].map(|v| (v / CELL).floor() as i64)
    }

    fn add(&mut self, x: &P3, i: usize) {
        self.0.entry(Cells::key(x)).or_default().push(i);
    }

    /// Whether some node lies within [`SAME_NODE`] of `x`.
    fn holds_near(&self, nodes: &[P3], x: &P3) -> bool {
        let [a, b, c] = Cells::key(x);
        (-1..=1).any(|i| {
            (-1..=1).any(|j| {
                (-1..=1).any(|k| {
                    self.0
                        .get(&[a + i, b + j, c + k])
                        .is_some_and(|v| v.iter().any(|&n| (nodes[n] - x).norm() < SAME_NODE))
                })
            })
        })
    }
}

/// A pair of nodes `(distance, i, j)` (or one node, `j` 0), ordered by distance and then
/// by index.
#[derive(Clone, Copy)]
struct Near(f64, usize, usize);

impl PartialEq for Near {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}

impl Eq for Near {}

impl PartialOrd for Near {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl Ord for Near {
    fn cmp(&self, o: &Self) -> Ordering {
        self.0
            .total_cmp(&o.0)
            .then((self.1, self.2).cmp(&(o.1, o.2)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::access::{ProbeShape, Scene};

    /// The 12 triangles of a box, outward.
    fn cuboid(lo: P3, hi: P3) -> Vec<[P3; 3]> {
        let solid = crate::access::pose::Solid {
            at: nalgebra::Isometry3::translation(
                (lo.x + hi.x) / 2.0,
                (lo.y + hi.y) / 2.0,
                (lo.z + hi.z) / 2.0,
            ),
            shape: crate::access::pose::SolidShape::Box((hi - lo) / 2.0),
        };
        let (vs, ts) = solid.triangles();
        ts.iter()
            .map(|t| [vs[t[0] as usize], vs[t[1] as usize], vs[t[2] as usize]])
            .collect()
    }

    #[test]
    fn a_goal_sealed_in_a_box_is_reported() {
        let tris = cuboid(P3::new(-10.0, -10.0, -10.0), P3::new(10.0, 10.0, 10.0));
        let verts: Vec<P3> = tris.iter().flatten().copied().collect();
        let scene = Scene::of_triangles(&tris);
        let probe = ProbeShape::bare_stylus(30.0, crate::access::Head::Fixed);
        let pose = Pose::new(&scene, &probe, V3::z(), V3::z(), -100.0);
        let goals = vec![
            P3::origin(),
            P3::new(30.0, 0.0, 0.0),
            P3::new(40.0, 0.0, 0.0),
        ];
        let mut map = Roadmap::new(&pose, goals, V3::z(), &verts, 40.0);
        match map.build(|_| vec![P3::new(0.0, 5.0, 0.0)]) {
            Err(Disconnected {
                goal,
                stray,
                blocker,
            }) => {
                assert_eq!(goal, 0);
                assert_eq!(stray, [0]);
                assert_eq!(
                    blocker,
                    Some(crate::access::Blocker::Tip),
                    "the straight move out crosses the wall"
                );
            }
            Ok(_) => panic!("a sealed goal was connected"),
        }
    }

    #[test]
    fn goals_either_side_of_a_wall_are_joined_over_it() {
        let tris = cuboid(P3::new(-1.0, -20.0, 0.0), P3::new(1.0, 20.0, 20.0));
        let verts: Vec<P3> = tris.iter().flatten().copied().collect();
        let scene = Scene::of_triangles(&tris);
        let probe = ProbeShape::bare_stylus(30.0, crate::access::Head::Fixed);
        let pose = Pose::new(&scene, &probe, V3::z(), V3::z(), -100.0);
        let (a, b) = (P3::new(-5.0, 0.0, 5.0), P3::new(5.0, 0.0, 5.0));
        assert_eq!(pose.segment(&a, &b), Err(Blocker::Tip));
        let mut map = Roadmap::new(&pose, vec![a, b], V3::z(), &verts, 40.0);
        assert_eq!(map.build(|_| vec![]).ok(), Some(0));
        let paths = map.shortest_paths();
        // Up 20 mm along the probe axis (5 mm is not enough), across, down.
        assert!((paths.d(0, 1) - 50.0).abs() < 1e-9, "{}", paths.d(0, 1));
        let w = paths.path(&map, 0, 1);
        assert_eq!(w.len(), 3);
        for s in std::iter::once(a)
            .chain(w.iter().copied())
            .collect::<Vec<_>>()
            .windows(2)
        {
            assert!(pose.segment(&s[0], &s[1]).is_ok());
        }
    }
}
