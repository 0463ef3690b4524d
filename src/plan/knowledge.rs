//! The knowledge base (seed ch. 3.3.5 and 4.1): per fpoint and probe, the domain of
//! allowable configurations, refined lazily as generate-and-test finds out more.
//!
//! A setup is the direction of the part frame that points up, towards the ram. For a
//! fixed head the domain of (fpoint, probe) is one cone of setups; for an indexable head
//! it is the pair (D1, D2): probe directions and setups, with D1′ — the A/B grid
//! orientations that work in a chosen setup — computed on demand and cached.
//!
//! Knowledge starts cheap: the bare half-line cone from the tip centre (and, for bent
//! probes, D2 over-approximated by tilting D1 as far as the head's A range allows). When
//! validation rejects a configuration, the point's domain is replaced by the whole
//! probe's cones (every component at contact and retract point, and the weak GAC D2),
//! and the rejected configuration is removed.
//!
//! **Decision: exact directions.** The axes, preferred setups, table setups and up to
//! 48 face axes (±, of cylinders and cones) and plane normals are preferred directions
//! of every cone: a stylus often clears a hole only along its axis, which no pixel
//! centre hits. Rasterized probe cones block a preferred direction conservatively; on
//! acquisition the ones the half-line allowed are re-tested exactly by validation.
//!
//! **Decision: preferences are exact directions.** A preferred setup is a preferred
//! direction of every cone; a forbidden setup removes the setups within `FORBID_ANGLE`
//! (10°) of it.
//!
//! **Decision: the table alternative** (ch. 3.6.2). Datum faces that can rest on the
//! table (`graph`'s `on_table`) get the setup −n in their domain; when it is chosen,
//! four points on the table around the face's footprint replace the face.
//!
//! Every point's setups are masked by the realisable setups (`poses`); the stable
//! poses' directions are exact cells of the cube maps, and the setup cell's `Held`
//! (holder, table, fixture solids) is what validation poses against. D1′ on the A/B
//! grid comes from one depth map per setup (`access::SecondMap`), cached per (point,
//! probe, setup), and keeps the probe off the table.

mod fixture;
mod rescue;

use super::cluster::{Bits, Set};
use super::machine::Machine;
use super::memo::{Dom, DomRow, Memo};
use crate::access::pose::{above_table, frame, table_height, Blocker, Contact, Pose};
use crate::access::{self, tip_fits, Cell, ConeOptions, CubeMap, ProbeShape, Scene, SecondMap};
use crate::geometry::{FaceId, Surface, P3, V3};
use crate::model::{Plan, Stance};
use crate::sample::Fpoint;

use rayon::prelude::*;
use std::collections::{BTreeMap, BTreeSet};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Arc;

/// Putting a planar datum face on the table (ch. 3.6.2).
#[derive(Debug, Clone)]
pub(crate) struct TableAlt {
    /// The datum face.
    pub face: FaceId,
    /// That setup's cell index in the cube maps.
    pub cell: usize,
    /// The table points standing in for the face: indices into [`Knowledge::points`].
    pub points: Vec<usize>,
    /// False once validation found the table points unreachable.
    pub alive: bool,
}

/// The part of the knowledge a search's rounds change (the rest is fixed by the input
/// or a cache of pure results): what [`super::journal`] keeps to resume from.
#[derive(Clone)]
pub(crate) struct Learnt {
    dom: Vec<DomRow>,
    d1p: BTreeMap<(usize, usize, usize), Bits>,
    /// The setup cells whose holding was asked for: `reject` reads a fixture from it.
    held: BTreeSet<usize>,
    /// Per table alternative, whether it is alive.
    alive: Vec<bool>,
    acquired: usize,
}

/// The planner's knowledge base.
pub(crate) struct Knowledge<'a> {
    /// The setups the plan may use and what holds the part in each.
    pub setups: super::poses::Setups<'a>,
    /// Per setup cell used: what holds the part, the table's height and the fixture's
    /// solids.
    held: BTreeMap<usize, Held>,
    /// Cube-map options (resolution, preferred directions, retract distance).
    pub opts: ConeOptions,
    /// The part as obstacle.
    pub scene: Scene,
    /// The graph's fpoints, then the table points.
    pub points: Vec<Fpoint>,
    /// How many of `points` come from the graph.
    pub graph_points: usize,
    /// The margin the plan's moves keep (`motion { margin }`, mm).
    pub motion_margin: f64,
    /// Per point and probe; a point's row is shared with the journal's states until
    /// learning changes it ([`super::journal`]).
    pub dom: Vec<DomRow>,
    /// Setups the plan forbids.
    pub forbidden: CubeMap,
    /// Setups an operator can realise: the part's stable poses and its fixtures'
    /// (see [`super::poses`]); every other setup is out of every point's domain.
    pub realisable: CubeMap,
    /// Preference weight per cube-map cell index (0.5 when unspecified).
    pub setup_weight: BTreeMap<usize, f64>,
    /// Setup preferences in declaration order: (cell index, weight).
    pub setup_prefs: Vec<(usize, f64)>,
    /// Datum faces that may rest on the table.
    pub tables: Vec<TableAlt>,
    /// D1′ on the grid per (point, probe, setup cell).
    d1p: BTreeMap<(usize, usize, usize), Bits>,
    /// Cones and depth maps computed before, and where new ones are kept.
    memo: &'a mut Memo,
    /// Per setup cell, the cube-map bit index of each grid orientation's direction in
    /// that setup's part frame: one `cell_of` per (setup, orientation) at most instead of
    /// one per (point, probe, setup, orientation).
    grid_cells: BTreeMap<usize, GridCells>,
    /// The preferred directions of the knowledge's maps, for `grid_cells`' lookups.
    pref_index: access::PreferredIndex,
    /// How many times the whole probe's cones were computed.
    pub acquired: usize,
}

/// The cube-map cells of the head's grid orientations in one setup, each computed when
/// first asked for: a point reached at its first orientation asks for one.
struct GridCells {
    /// Machine frame → part frame of the setup.
    to_part: nalgebra::Rotation3<f64>,
    /// Per grid orientation, its direction's bit index; `u32::MAX` until asked for. Two
    /// threads asking at once both store the same value.
    cells: Vec<AtomicU32>,
    /// The grid's directions in the part frame, made when first asked for (most setups
    /// of the minimum never are).
    dirs: std::sync::OnceLock<Vec<V3>>,
}

impl GridCells {
    fn new(up: &V3, machine: &Machine) -> GridCells {
        GridCells {
            to_part: frame(up).inverse(),
            cells: (0..machine.grid_dirs.len())
                .map(|_| AtomicU32::new(u32::MAX))
                .collect(),
            dirs: std::sync::OnceLock::new(),
        }
    }

    /// The grid's directions in the part frame.
    fn dirs(&self, machine: &Machine) -> &[V3] {
        self.dirs
            .get_or_init(|| machine.grid_dirs.iter().map(|d| self.to_part * d).collect())
    }

    /// The bit index, in maps shaped `like`, of grid orientation `k` (direction `d` in
    /// the machine frame).
    fn index(&self, k: usize, d: &V3, like: &CubeMap, pref: &access::PreferredIndex) -> usize {
        let known = self.cells[k].load(Ordering::Relaxed);
        if known != u32::MAX {
            return known as usize;
        }
        let cell = like.index(like.cell_of_indexed(pref, &(self.to_part * d)));
        self.cells[k].store(cell as u32, Ordering::Relaxed);
        cell
    }
}

/// The cells within `angle` radians of `axis`, in the shape of `like`.
pub(crate) fn cone_around(like: &CubeMap, axis: &V3, angle: f64) -> CubeMap {
    like.cap(&axis.normalize(), angle.min(std::f64::consts::PI).cos())
}

/// How the part is held in one setup.
#[derive(Debug, Clone)]
pub(crate) struct Held {
    pub holder: super::poses::Holder,
    pub table: f64,
    pub solids: Vec<crate::access::pose::Solid>,
}

impl<'a> Knowledge<'a> {
    /// Validates touching point `f` with probe `p` pointing along `dir` in setup `up`
    /// held as `held` says (one primitive inspection plan, seed ch. 4.1).
    pub(crate) fn pose_check(
        &self,
        machine: &Machine,
        f: usize,
        p: usize,
        dir: V3,
        up: V3,
        held: &Held,
    ) -> Result<(), Blocker> {
        let contact = if f >= self.graph_points {
            Contact::Table
        } else {
            Contact::Part
        };
        let touch = Touch {
            point: &self.points[f],
            contact,
            probe: &machine.probes[p],
            dir,
            up,
        };
        touch_check(
            &self.scene,
            self.opts.retract,
            &touch,
            held.table,
            &held.solids,
        )
    }

    /// The initial knowledge: half-line cones at every fpoint for every probe, table
    /// alternatives for datum faces that can rest on the table.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        plan: &Plan,
        machine: &Machine,
        geometry: &crate::geometry::PartGeometry,
        fpoints: &[Fpoint],
        table_faces: &[FaceId],
        setups: super::poses::Setups<'a>,
        opts: ConeOptions,
        memo: &'a mut Memo,
    ) -> Knowledge<'a> {
        let realisable = setups.exact_dirs();
        let scene = memo.scene(geometry);
        let (pref, table_dirs) =
            preferred_directions(plan, geometry, fpoints, table_faces, &realisable, &opts);
        let opts = ConeOptions {
            preferred: pref.clone(),
            ..opts
        };
        let empty = CubeMap::empty(opts.n, &pref);
        let mut forbidden = empty.clone();
        let mut real = empty.clone();
        let total = 6 * (empty.n() as usize).pow(2) + empty.preferred_len();
        let holds: Vec<bool> = (0..total)
            .into_par_iter()
            .map(|k| setups.holder(&empty.direction(empty.cell(k))).is_some())
            .collect();
        for (k, _) in holds.iter().enumerate().filter(|(_, &h)| h) {
            real.set(empty.cell(k), true);
        }
        let mut setup_weight = BTreeMap::new();
        let mut setup_prefs = Vec::new();
        for s in &plan.setups {
            let d = V3::from(s.direction).normalize();
            let cell = empty.index(empty.cell_of(&d));
            match s.stance {
                Stance::Forbid => {
                    forbidden.or_assign(&cone_around(&empty, &d, FORBID_ANGLE.to_radians()));
                }
                Stance::Prefer(w) => {
                    setup_weight.insert(cell, w);
                    setup_prefs.push((cell, w));
                }
            }
        }
        // Every use of D2 in planning is masked by the setups a plan can take: the cones
        // need be whole only there. With none, D2 stays whole: the diagnostic then names
        // the poses the probe would need.
        let usable = real.and(&forbidden.not());
        let opts = ConeOptions {
            d2_wanted: (!usable.is_empty())
                .then(|| std::sync::Arc::new(access::D2Wanted::new(usable))),
            ..opts
        };
        let mut points = fpoints.to_vec();
        let tables = table_alternatives(
            &scene,
            geometry,
            machine,
            &table_dirs,
            (&empty, &real, &setups),
            &mut points,
        );
        let graph_points = fpoints.len();
        let dom: Vec<DomRow> = match &memo.initial {
            Some(dom) => dom.clone(),
            None => {
                let dom: Vec<DomRow> = initial_domains(&scene, fpoints, machine, &opts)
                    .into_iter()
                    .map(Arc::new)
                    .collect();
                memo.initial = Some(dom.clone());
                dom
            }
        };
        let mut k = Knowledge {
            setups,
            held: BTreeMap::new(),
            opts,
            scene,
            points,
            graph_points,
            motion_margin: plan.motion.margin,
            dom,
            forbidden,
            realisable: real,
            setup_weight,
            setup_prefs,
            tables,
            d1p: BTreeMap::new(),
            memo,
            grid_cells: BTreeMap::new(),
            pref_index: access::PreferredIndex::new(&empty),
            acquired: 0,
        };
        k.drop_tip_on_fixture(machine);
        k
    }

    /// An empty cube map of the knowledge's shape.
    pub(crate) fn empty_cone(&self) -> CubeMap {
        // Shaped like every map of the knowledge, sharing their preferred directions.
        self.forbidden.empty_like()
    }

    /// The up direction of setup cell `s`.
    pub(crate) fn setup_dir(&self, s: usize) -> V3 {
        let shape = &self.forbidden;
        shape.direction(shape.cell(s))
    }

    /// How the part is held in setup cell `s` (cached): what holds it, the table's
    /// height under it and the fixture's solids. A cell outside the realisable setups
    /// (which no plan uses) rests on its lowest point with no fixture.
    pub(crate) fn held(&mut self, s: usize) -> &Held {
        if !self.held.contains_key(&s) {
            let h = self.hold(s);
            self.held.insert(s, h);
        }
        &self.held[&s]
    }

    /// What the search has learnt so far, to resume from ([`super::journal`]).
    pub(crate) fn learnt(&self) -> Learnt {
        Learnt {
            dom: self.dom.clone(),
            d1p: self.d1p.clone(),
            held: self.held.keys().copied().collect(),
            alive: self.tables.iter().map(|t| t.alive).collect(),
            acquired: self.acquired,
        }
    }

    /// About what a copy of every point's domains takes (bytes): per point and probe,
    /// two cube maps of `6 n²` bits.
    pub(crate) fn domain_bytes(&self) -> usize {
        let n = self.opts.n as usize;
        let probes = self.dom.first().map_or(0, |row| row.len());
        self.dom.len() * probes * 2 * (6 * n * n / 8)
    }

    /// Takes up what a search had learnt ([`Knowledge::learnt`] of the same input).
    pub(crate) fn resume(&mut self, l: Learnt) {
        self.dom = l.dom;
        self.d1p = l.d1p;
        self.held.retain(|s, _| l.held.contains(s));
        for &s in &l.held {
            self.held(s);
        }
        for (t, &alive) in self.tables.iter_mut().zip(&l.alive) {
            t.alive = alive;
        }
        self.acquired = l.acquired;
    }

    /// The memo the knowledge reads and fills.
    pub(super) fn memo(&mut self) -> &mut Memo {
        self.memo
    }

    /// [`Knowledge::held`], uncached.
    fn hold(&self, s: usize) -> Held {
        let up = self.setup_dir(s);
        let setups = &self.setups;
        match setups.holder(&up) {
            Some(holder) => {
                let solids = setups.keep_out(&holder, &up);
                Held {
                    table: setups.table(&holder, &up, &solids),
                    solids,
                    holder,
                }
            }
            None => Held {
                holder: super::poses::Holder::Table { faces: vec![] },
                table: table_height(&self.scene, &up),
                solids: vec![],
            },
        }
    }

    /// Computes, in parallel, how the part is held in each setup cell of `cells` and makes
    /// room for their grid orientations' cells: what [`Knowledge::reaches_off_table`]
    /// reads.
    pub(crate) fn prepare(&mut self, cells: &[usize], machine: &Machine) {
        let new: Vec<usize> = cells
            .iter()
            .copied()
            .filter(|s| !self.held.contains_key(s))
            .collect();
        let this = &*self;
        let held: Vec<Held> = new.par_iter().map(|&s| this.hold(s)).collect();
        self.held.extend(new.into_iter().zip(held));
        let fresh: Vec<usize> = cells
            .iter()
            .copied()
            .filter(|s| !self.grid_cells.contains_key(s))
            .collect();
        let this = &*self;
        let grids: Vec<GridCells> = fresh
            .par_iter()
            .map(|&s| GridCells::new(&this.setup_dir(s), machine))
            .collect();
        self.grid_cells.extend(fresh.into_iter().zip(grids));
    }

    /// How the part is held in setup cell `s`, computed by [`Knowledge::prepare`].
    pub(crate) fn held_prepared(&self, s: usize) -> &Held {
        &self.held[&s]
    }

    /// The setups from which some allowed probe reaches graph fpoint `f`.
    pub(crate) fn setups(&self, f: usize, machine: &Machine) -> CubeMap {
        let reached = self.dom[f]
            .iter()
            .enumerate()
            .filter(|&(p, d)| machine.allowed[p] && d.tip)
            .map(|(_, d)| &d.setup);
        CubeMap::union_within(&self.forbidden, reached, &self.realisable, &self.forbidden)
    }

    /// The allowed probes that reach graph fpoint `f` in setup cell `s`.
    pub(crate) fn probes(&self, f: usize, s: usize, machine: &Machine) -> Bits {
        Bits::of(
            machine.probes.len(),
            (0..machine.probes.len()).filter(|&p| {
                machine.allowed[p] && self.dom[f][p].tip && Set::has(&self.dom[f][p].setup, s)
            }),
        )
    }

    /// The grid orientations from which probe `p` reaches point `f` in setup `up` (cell
    /// `s`): D1′ on the A/B grid, kept off the table. Table points take every orientation
    /// that keeps the probe off the table. Fixed heads have the one orientation.
    pub(crate) fn orientations(
        &mut self,
        f: usize,
        p: usize,
        s: usize,
        up: &V3,
        machine: &Machine,
    ) -> Bits {
        if !machine.head.indexable() {
            return Bits::full(1);
        }
        if let Some(b) = self.d1p.get(&(f, p, s)) {
            return b.clone();
        }
        let key = self.orientations_key(f, p, s);
        if let Some(b) = self.memo.orientations.get(&key) {
            self.d1p.insert((f, p, s), b.clone());
            return b.clone();
        }
        self.make_orientations(&[(f, p)], s, up, machine);
        self.d1p[&(f, p, s)].clone()
    }

    /// [`Knowledge::orientations`] of many (point, probe) pairs in setup cell `s`, those
    /// not known yet computed in parallel: the same sets, kept as asking one by one would
    /// keep them, so the sequential queries that follow find them made.
    pub(crate) fn prefetch_orientations(
        &mut self,
        pairs: &[(usize, usize)],
        s: usize,
        machine: &Machine,
    ) {
        if !machine.head.indexable() {
            return;
        }
        let mut todo: Vec<(usize, usize)> = pairs
            .iter()
            .copied()
            .filter(|&(f, p)| {
                !self.d1p.contains_key(&(f, p, s))
                    && !self
                        .memo
                        .orientations
                        .contains_key(&self.orientations_key(f, p, s))
            })
            .collect();
        todo.sort_unstable();
        todo.dedup();
        if todo.len() >= 2 {
            let up = self.setup_dir(s);
            self.make_orientations(&todo, s, &up, machine);
        }
    }

    /// Computes the orientations of (point, probe) pairs not known yet in setup cell `s`
    /// (`up` its direction), in parallel, and keeps them in `d1p` and the memo.
    fn make_orientations(&mut self, todo: &[(usize, usize)], s: usize, up: &V3, machine: &Machine) {
        self.ready(s, up, machine);
        let this = &*self;
        let candidates: Vec<(P3, Vec<usize>)> = todo
            .par_iter()
            .map(|&(f, p)| this.candidates(f, p, s, machine))
            .collect();
        if candidates.iter().any(|(_, c)| !c.is_empty()) {
            self.second_map(s, up, machine);
        }
        let this = &*self;
        let outs: Vec<Bits> = todo
            .par_iter()
            .zip(&candidates)
            .map(|(&(_, p), (c, cands))| this.clear_of(p, s, c, cands, machine))
            .collect();
        for (&(f, p), out) in todo.iter().zip(outs) {
            let key = self.orientations_key(f, p, s);
            self.d1p.insert((f, p, s), out.clone());
            self.memo.orientations.insert(key, out);
        }
    }

    /// The memo's key of (f, p, s)'s orientations: D1 is a function of the pair and of
    /// whether its whole probe's cones are acquired.
    fn orientations_key(&self, f: usize, p: usize, s: usize) -> (usize, usize, usize, bool) {
        (f, p, s, self.dom.get(f).is_some_and(|d| d[p].full))
    }

    /// Makes how setup cell `s` holds the part and its grid cells (`up` its direction),
    /// if not made yet.
    fn ready(&mut self, s: usize, up: &V3, machine: &Machine) {
        self.held(s);
        self.grid_cells
            .entry(s)
            .or_insert_with(|| GridCells::new(up, machine));
    }

    /// Makes setup cell `s`'s depth map of the second component if not made yet.
    fn second_map(&mut self, s: usize, up: &V3, machine: &Machine) {
        if self.memo.second.contains_key(&s) {
            return;
        }
        let radius = machine
            .probes
            .iter()
            .flat_map(|p| p.second.iter().map(|c| c.radius))
            .fold(0.0, f64::max);
        let reach = machine.probes.iter().map(|p| p.reach()).fold(0.0, f64::max);
        let map = SecondMap::new(&self.scene, up, radius, reach + 2.0 * self.opts.retract);
        self.memo.second.insert(s, map);
    }

    /// The candidates (see [`Knowledge::candidates`]) whose articulation point the second
    /// component clears in setup cell `s`, as grid orientations; `s`'s grid cells and,
    /// for any candidate, its depth map must be made.
    fn clear_of(
        &self,
        p: usize,
        s: usize,
        c: &P3,
        candidates: &[usize],
        machine: &Machine,
    ) -> Bits {
        let probe = &machine.probes[p];
        let clear: Vec<bool> = if candidates.is_empty() {
            vec![]
        } else {
            let map = &self.memo.second[&s];
            let dirs = self.grid_cells[&s].dirs(machine);
            candidates
                .iter()
                .map(|&k| map.clear(&(c + dirs[k] * probe.reach())))
                .collect()
        };
        Bits::of(
            machine.grid.len(),
            candidates
                .iter()
                .zip(clear)
                .filter(|(_, ok)| *ok)
                .map(|(&k, _)| k),
        )
    }

    /// Whether probe `p` may have a grid orientation in D1′ that keeps its stylus off the
    /// table when it touches graph fpoint `f` in setup `up` (cell `s`, the table at
    /// height `t0`): the orientations before the second-order clearance test, cheap
    /// enough to ask of every realisable setup. It errs towards yes (a fixed head, a point
    /// higher above the table than the probe is long), so a minimum counted with it stays
    /// a lower bound. `d1_cap` is the point's D1's [`CubeMap::bounding_cap`]. Cell `s`
    /// must have been [`Knowledge::prepare`]d.
    pub(crate) fn reaches_off_table(
        &self,
        f: usize,
        p: usize,
        s: usize,
        (up, t0): (&V3, f64),
        machine: &Machine,
        d1_cap: impl FnOnce() -> Option<(V3, f64)>,
    ) -> bool {
        if !machine.head.indexable() {
            return true;
        }
        let probe = &machine.probes[p];
        let widest = probe
            .first
            .iter()
            .chain(&probe.second)
            .map(|c| c.radius)
            .fold(0.0, f64::max);
        let point = &self.points[f];
        let c = point.tip_centre(probe.tip_radius);
        if c.coords.dot(up) - t0 >= probe.reach() + widest + access::pose::ORIENTATION_TABLE_MARGIN
        {
            return true;
        }
        // `candidates` without the list: the first orientation that passes will do.
        let cells = &self.grid_cells[&s];
        let Some(d1) = self.dom.get(f).and_then(|d| d[p].d1.as_ref()) else {
            return false;
        };
        let Some((centre, spread)) = d1_cap() else {
            return false;
        };
        // Every direction of D1 lies within `spread` of `centre` (its bounding cap), and a
        // grid direction lies at its polar angle from the head's axis: by the triangle
        // inequality on the sphere, one whose polar angle differs from the axis's angle to
        // `centre` by more than `spread` cannot be in D1. Those are passed over unlooked
        // (their cells uncomputed); the answer is the same.
        let axis = cells.to_part * V3::z();
        let phi = axis.dot(&centre).clamp(-1.0, 1.0).acos();
        let reach = spread + 1e-9;
        let (polar, sorted) = &machine.grid_polar;
        let range = if *sorted {
            polar.partition_point(|&a| a < phi - reach)
                ..polar.partition_point(|&a| a <= phi + reach)
        } else {
            0..polar.len()
        };
        // Every component's lowest point rises with cos A (the direction's component
        // along `up`), so once an orientation at some A hits the table, every one at that
        // A or more does: a point low in this setup is ruled out after one test, not 720.
        // Within a ring, the same cap passes over the directions farther from `centre`.
        let least_cos = if reach < std::f64::consts::PI {
            reach.cos() - 1e-12
        } else {
            -2.0
        };
        let mut blocked_from = f64::INFINITY;
        range.into_iter().any(|k| {
            let a = machine.grid[k].0;
            if a >= blocked_from
                || (polar[k] - phi).abs() > reach
                || !Set::has(&machine.grid_allowed, k)
            {
                return false;
            }
            let dir = cells.to_part * machine.grid_dirs[k];
            if dir.dot(&centre) < least_cos
                || !d1.has_index(cells.index(
                    k,
                    &machine.grid_dirs[k],
                    &self.forbidden,
                    &self.pref_index,
                ))
            {
                return false;
            }
            let ok = above_table(probe, &c, &dir, up, t0);
            if !ok {
                blocked_from = a;
            }
            ok
        })
    }

    /// The tip centre of probe `p` on point `f` and the allowed grid orientations in D1′
    /// that keep the stylus above the table in setup cell `s` (whose holding and grid
    /// cells must be made).
    fn candidates(&self, f: usize, p: usize, s: usize, machine: &Machine) -> (P3, Vec<usize>) {
        let t0 = self.held[&s].table;
        let up = &self.setup_dir(s);
        let Knowledge {
            grid_cells,
            dom,
            forbidden: like,
            pref_index,
            ..
        } = self;
        let cells = &grid_cells[&s];
        let probe = &machine.probes[p];
        let point = &self.points[f];
        let c = point.tip_centre(probe.tip_radius);
        let dirs = cells.dirs(machine);
        let table = f >= self.graph_points;
        // A table point's tip touches the table: its stylus comes as near as the stem
        // leaves (the move's own margin still holds), not the orientation margin.
        let table_slack = if table {
            access::pose::ORIENTATION_TABLE_MARGIN - access::pose::TABLE_MARGIN
        } else {
            0.0
        };
        let d1 = dom.get(f).and_then(|d| d[p].d1.as_ref());
        let candidates: Vec<usize> = (0..dirs.len())
            .filter(|&k| {
                Set::has(&machine.grid_allowed, k)
                    && (table
                        || d1.is_some_and(|d1| {
                            d1.has_index(cells.index(k, &machine.grid_dirs[k], like, pref_index))
                        }))
                    && above_table(probe, &c, &dirs[k], up, t0 - table_slack)
                    && (!table || dirs[k].dot(&point.normal) > 0.2)
            })
            .collect();
        (c, candidates)
    }

    /// Learns that probe `p` cannot reach point `f` from setup cell `s` (and, for a bent
    /// probe, orientation `o`): the first time, the point's half-line domain is replaced
    /// by the whole probe's cones; the configuration is then removed. In a setup with a
    /// fixture it is removed at once: the cones do not see fixtures, so better cones
    /// would not change the answer.
    pub(crate) fn reject(
        &mut self,
        f: usize,
        p: usize,
        s: usize,
        o: Option<usize>,
        machine: &Machine,
    ) {
        if f >= self.graph_points {
            if let Some(t) = self.tables.iter_mut().find(|t| t.points.contains(&f)) {
                t.alive = false;
            }
            return;
        }
        let fixture = self.held.get(&s).is_some_and(|h| !h.solids.is_empty());
        if !self.dom[f][p].full && !fixture {
            self.acquire(f, p, machine);
            return;
        }
        if let (Some(o), true) = (o, self.d1p.contains_key(&(f, p, s))) {
            let mut left = self.d1p[&(f, p, s)].clone();
            left.remove(o);
            if fixture {
                // Every other orientation against the fixture now, not one a round.
                let up = self.setup_dir(s);
                let held = self.held[&s].clone();
                let ones: Vec<usize> = left.ones().collect();
                let this = &*self;
                let keep: Vec<usize> = ones
                    .into_par_iter()
                    .filter(|&k| {
                        let (a, b) = machine.grid[k];
                        let dir = access::pose::orientation_dir(&up, a, b);
                        this.pose_check(machine, f, p, dir, up, &held).is_ok()
                    })
                    .collect();
                left = Bits::of(machine.grid.len(), keep);
            }
            let empty = left.is_empty();
            self.d1p.insert((f, p, s), left);
            if !empty {
                return;
            }
        }
        let dom = &mut Arc::make_mut(&mut self.dom[f])[p];
        let cell = dom.setup.cell(s);
        if machine.head.indexable() {
            // No orientation works in this setup: nor, most likely, in setups close by.
            let dir = dom.setup.direction(cell);
            let cap = cone_around(&dom.setup, &dir, REJECT_CAP.to_radians());
            dom.setup.and_not_assign(&cap);
            dom.setup.set(cell, false);
        } else if dom.setup.get(cell) {
            // Rejected although the whole probe's cone holds it: its pixel is on the
            // boundary. Drop it and its neighbours.
            dom.setup.set(cell, false);
            if let Cell::Pixel(px) = cell {
                for nb in dom.setup.neighbours(px) {
                    dom.setup.set(Cell::Pixel(nb), false);
                }
            }
        }
    }

    /// Replaces the half-line knowledge of (f, p) by the whole probe's cones.
    pub(crate) fn acquire(&mut self, f: usize, p: usize, machine: &Machine) {
        self.acquire_many(&[(f, p)], machine);
    }

    /// Acquires the whole probe's cones for many (point, probe) pairs at once, in
    /// parallel; the result does not depend on the thread count.
    pub(crate) fn acquire_many(&mut self, pairs: &[(usize, usize)], machine: &Machine) {
        let todo: Vec<(usize, usize)> = pairs
            .iter()
            .copied()
            .filter(|&(f, p)| f < self.graph_points && !self.dom[f][p].full)
            .collect();
        // D2 is not sampled (the weak GAC costs 16 second-component cones): the cap over
        // the new D1 bounds it, and D1′ in each chosen setup is the exact test.
        let opts = ConeOptions {
            d2_samples: D2_SAMPLES,
            ..self.opts.clone()
        };
        let fresh: Vec<(usize, usize)> = todo
            .iter()
            .copied()
            .filter(|pair| !self.memo.cones.contains_key(pair))
            .collect();
        let items: Vec<(&Fpoint, &ProbeShape)> = fresh
            .iter()
            .map(|&(f, p)| (&self.points[f], &machine.probes[p]))
            .collect();
        let mut fresh = access::point_cones_many(opts.backend.get(), &self.scene, &items, &opts);
        if machine.head.indexable() {
            rescue::rescue_empty(&self.scene, &items, &opts, self.motion_margin, &mut fresh);
        }
        let mut fresh_cones = fresh.into_iter();
        let memo = &self.memo.cones;
        let computed: Vec<access::PointCones> = todo
            .iter()
            .map(|pair| match memo.get(pair) {
                Some(cones) => cones.clone(),
                None => fresh_cones.next().expect("one cone per fresh pair"),
            })
            .collect();
        for (&pair, cones) in todo.iter().zip(&computed) {
            self.memo.cones.entry(pair).or_insert_with(|| cones.clone());
        }
        // Preferred directions the half-line allowed and the rasterized probe did not:
        // its grown pixels err on the blocked side, so test them exactly.
        let shape = self.empty_cone();
        let cells: Vec<usize> = (0..shape.preferred_len())
            .map(|j| shape.index(Cell::Preferred(j)))
            .filter(|&s| self.realisable.get(shape.cell(s)))
            .collect();
        let held: BTreeMap<usize, Held> = cells
            .into_iter()
            .map(|s| (s, self.held(s).clone()))
            .collect();
        let exact: Vec<Vec<usize>> = todo
            .par_iter()
            .zip(&computed)
            .map(|(&(f, p), cones)| {
                if machine.head.indexable() || !cones.tip_fits {
                    return vec![];
                }
                let old = &self.dom[f][p].setup;
                (0..old.preferred_len())
                    .filter(|&j| {
                        let cell = Cell::Preferred(j);
                        old.get(cell) && !cones.approach.get(cell) && !self.forbidden.get(cell)
                    })
                    .filter(|&j| {
                        let up = old.preferred(j);
                        let s = old.index(Cell::Preferred(j));
                        held.get(&s)
                            .is_some_and(|h| self.pose_check(machine, f, p, up, up, h).is_ok())
                    })
                    .collect()
            })
            .collect();
        // D2's cap over the new D1 (the first D1 and the approach cone: a function of the
        // pair, kept in the memo), for the pairs of a bent probe, in parallel.
        let caps: Vec<Option<CubeMap>> = todo
            .par_iter()
            .zip(&computed)
            .map(|(pair, cones)| {
                let d1 = self.dom[pair.0][pair.1].d1.as_ref()?;
                cones.d2.as_ref()?;
                Some(match self.memo.caps.get(pair) {
                    Some(cap) => cap.clone(),
                    None => d2_cap(&d1.and(&cones.approach), machine.a_max),
                })
            })
            .collect();
        let mut done: BTreeSet<(usize, usize)> = BTreeSet::new();
        for (((&(f, p), mut cones), exact), cap) in todo.iter().zip(computed).zip(exact).zip(caps) {
            if self.dom[f][p].full {
                continue;
            }
            for j in exact {
                cones.approach.set(Cell::Preferred(j), true);
            }
            let dom = &mut Arc::make_mut(&mut self.dom[f])[p];
            dom.full = true;
            dom.tip &= cones.tip_fits;
            match (&mut dom.d1, cones.d2, cap) {
                (Some(d1), Some(d2), Some(cap)) => {
                    d1.and_assign(&cones.approach);
                    dom.setup.and_assign(&cap);
                    dom.setup.and_assign(&d2);
                    self.memo.caps.entry((f, p)).or_insert(cap);
                }
                _ => dom.setup.and_assign(&cones.approach),
            }
            self.acquired += 1;
            done.insert((f, p));
        }
        self.d1p.retain(|&(f, p, _), _| !done.contains(&(f, p)));
    }
}

/// One touch as validation poses it: a point, what it lies on, and the probe standing
/// along `dir` in setup `up`.
pub(crate) struct Touch<'p> {
    pub point: &'p Fpoint,
    pub contact: Contact,
    pub probe: &'p ProbeShape,
    pub dir: V3,
    pub up: V3,
}

/// Validates one touch (a primitive inspection plan, seed ch. 4.1): the tip swept from
/// the retract point `retract` mm out (less where the part is nearer behind a point on
/// the part) to the contact, every component along the approach, against the part
/// (`scene`), the table at height `table` and the fixture's `solids`.
pub(crate) fn touch_check(
    scene: &Scene,
    retract: f64,
    t: &Touch,
    table: f64,
    solids: &[crate::access::pose::Solid],
) -> Result<(), Blocker> {
    let travel = match t.contact {
        Contact::Part => access::pose::backoff(
            scene,
            &t.point.position,
            &t.point.normal,
            t.probe.tip_radius,
            retract,
        ),
        Contact::Table => retract,
    };
    Pose::new(scene, t.probe, t.dir, t.up, table)
        .with_fixture(solids)
        .approach(
            &t.point.tip_centre(t.probe.tip_radius),
            &t.point.normal,
            travel,
            t.contact,
        )
}

/// Preferred directions: the axes, the plan's setups, the realisable setups, the table
/// setups, then feature axes and plane normals — a probe often fits a hole only along
/// its axis (at most [`MAX_FACE_DIRECTIONS`] of those). Also each table face with the
/// direction up when it rests on the table.
fn preferred_directions(
    plan: &Plan,
    geometry: &crate::geometry::PartGeometry,
    fpoints: &[Fpoint],
    table_faces: &[FaceId],
    realisable: &[V3],
    opts: &ConeOptions,
) -> (Vec<V3>, Vec<(FaceId, V3)>) {
    let mut pref = opts.preferred.clone();
    fn add(pref: &mut Vec<V3>, d: V3) -> bool {
        let d = d.normalize();
        let new = !pref.iter().any(|p| (p - d).norm() < 1e-9);
        if new {
            pref.push(d);
        }
        new
    }
    for s in &plan.setups {
        add(&mut pref, V3::from(s.direction));
    }
    for d in realisable {
        add(&mut pref, *d);
    }
    let mut table_dirs = Vec::new();
    for &f in table_faces {
        if let Surface::Plane { normal, .. } = geometry.faces[f.0].surface {
            add(&mut pref, -normal);
            table_dirs.push((f, -normal));
        }
    }
    let mut face_dirs = 0;
    let mut seen: BTreeSet<usize> = BTreeSet::new();
    for f in fpoints {
        if face_dirs >= MAX_FACE_DIRECTIONS || !seen.insert(f.face.0) {
            continue;
        }
        let dirs = match geometry.faces[f.face.0].surface {
            Surface::Plane { normal, .. } => vec![normal],
            Surface::Cylinder { axis, .. } | Surface::Cone { axis, .. } => vec![axis, -axis],
            _ => vec![],
        };
        for d in dirs {
            face_dirs += usize::from(add(&mut pref, d));
        }
    }
    (pref, table_dirs)
}

/// The table alternatives of datum faces that can rest on the table (ch. 3.6.2): each
/// face's table points join `points`. A face has one only where its pose stands on the
/// table itself (`real`, and no riser under it: the table points lie in the face's
/// plane); elsewhere the table is not there to stand in for it, and nothing (the
/// planner, the re-measurement of datums) may touch it.
fn table_alternatives(
    scene: &Scene,
    geometry: &crate::geometry::PartGeometry,
    machine: &Machine,
    table_dirs: &[(FaceId, V3)],
    (empty, real, setups): (&CubeMap, &CubeMap, &super::poses::Setups),
    points: &mut Vec<Fpoint>,
) -> Vec<TableAlt> {
    let mut tables = Vec::new();
    for &(face, up) in table_dirs {
        let cell = empty.cell_of(&up);
        let on_table = real.get(cell)
            && matches!(
                setups.holder(&empty.direction(cell)),
                Some(super::poses::Holder::Table { .. })
            );
        if !on_table {
            continue;
        }
        let pts = table_points(scene, geometry, face, &up, machine);
        let first = points.len();
        points.extend(pts.iter().map(|&position| Fpoint {
            face,
            position,
            normal: up,
        }));
        tables.push(TableAlt {
            face,
            cell: empty.index(cell),
            points: (first..points.len()).collect(),
            alive: true,
        });
    }
    tables
}

/// The initial knowledge of every (graph point, probe): the tip's fit and the bare
/// half-line cone, computed once per tip size and shared by the probes of that size.
fn initial_domains(
    scene: &Scene,
    fpoints: &[Fpoint],
    machine: &Machine,
    opts: &ConeOptions,
) -> Vec<Vec<Dom>> {
    // The initial knowledge depends on a probe only through its tip's
    // radius: probes sharing a tip size share it.
    let same_tip: Vec<Option<usize>> = machine
        .probes
        .iter()
        .enumerate()
        .map(|(p, probe)| {
            machine.probes[..p]
                .iter()
                .position(|q| q.tip_radius == probe.tip_radius)
        })
        .collect();
    // The pairs whose knowledge is computed: each point with the first
    // probe of each tip size. Their half-line cones go to the backend in
    // one call.
    let own: Vec<(usize, usize)> = (0..fpoints.len())
        .flat_map(|f| {
            (0..machine.probes.len())
                .filter(|&p| same_tip[p].is_none())
                .map(move |p| (f, p))
        })
        .collect();
    let fits: Vec<bool> = own
        .par_iter()
        .map(|&(f, p)| tip_ok(scene, &fpoints[f], &machine.probes[p], opts))
        .collect();
    let centres: Vec<P3> = own
        .iter()
        .zip(&fits)
        .filter(|(_, &ok)| ok)
        .map(|(&(f, p), _)| fpoints[f].tip_centre(machine.probes[p].tip_radius))
        .collect();
    let mut halves =
        access::gac_halfline_many(opts.backend.get(), scene, &centres, opts.n, &opts.preferred)
            .into_iter();
    let halves: Vec<Option<CubeMap>> = fits
        .iter()
        .map(|&ok| if ok { halves.next() } else { None })
        .collect();
    let mut own_dom = halves
        .into_par_iter()
        .map(|half| initial(half, machine, opts))
        .collect::<Vec<Dom>>()
        .into_iter();
    let dom: Vec<Vec<Dom>> = (0..fpoints.len())
        .map(|_| {
            let mut out: Vec<Dom> = Vec::with_capacity(machine.probes.len());
            for q in same_tip.iter() {
                let d = match q {
                    Some(q) => out[*q].clone(),
                    None => own_dom.next().expect("one dom per own pair"),
                };
                out.push(d);
            }
            out
        })
        .collect();
    dom
}

/// The most face axes and normals added as exact directions.
const MAX_FACE_DIRECTIONS: usize = 48;

/// How far around a forbidden setup direction the setups are forbidden (degrees).
pub(crate) const FORBID_ANGLE: f64 = 10.0;

/// Whether the tip of `probe` fits at `f`: at the contact and at the retract point, with
/// room to touch.
fn tip_ok(scene: &Scene, f: &Fpoint, probe: &ProbeShape, opts: &ConeOptions) -> bool {
    let c = f.tip_centre(probe.tip_radius);
    let r = probe.tip_radius;
    let travel = access::pose::backoff(scene, &f.position, &f.normal, r, opts.retract);
    tip_fits(scene, &c, r)
        && access::pose::room_to_touch(scene, &f.position, &f.normal, r, opts.retract)
        && tip_fits(scene, &(c + f.normal * travel), r)
}

/// The first knowledge of (fpoint, probe) from its tip fit and, where the tip fits, its
/// half-line cone: for a bent probe D1 = that cone and D2 every setup within the head's
/// A range of it.
fn initial(half: Option<CubeMap>, machine: &Machine, opts: &ConeOptions) -> Dom {
    let Some(half) = half else {
        let e = CubeMap::empty(opts.n, &opts.preferred);
        return Dom {
            tip: false,
            setup: e.clone(),
            d1: machine.head.indexable().then_some(e),
            full: true,
        };
    };
    if !machine.head.indexable() {
        return Dom {
            tip: true,
            setup: half,
            d1: None,
            full: false,
        };
    }
    let d2 = d2_cap(&half, machine.a_max);
    Dom {
        tip: true,
        setup: d2,
        d1: Some(half),
        full: false,
    }
}

/// An over-approximation of D2: every setup within the head's A range (`a_max`
/// degrees) of some direction of D1 — the cap around D1's mean axis, widened by D1's
/// angular radius and a pixel.
fn d2_cap(d1: &CubeMap, a_max: f64) -> CubeMap {
    match d1.spread() {
        None => d1.empty_like(),
        Some(None) => d1.not().or(d1),
        Some(Some((m, rho))) => {
            let pixel = 2.0 / d1.n() as f64;
            cone_around(d1, &m, a_max.to_radians() + rho + pixel)
        }
    }
}

/// How many articulation points the weak GAC D2 samples when a bent probe's knowledge
/// is acquired (the seed's 16 cost more than they add here).
const D2_SAMPLES: usize = 6;

/// How far around a setup in which a bent probe found no orientation the setups are
/// dropped too (degrees).
const REJECT_CAP: f64 = 5.0;

/// Points on the table around the part resting on datum face `face`: four points beyond
/// the corners of the part's footprint, far enough out that the probe body clears it.
fn table_points(
    scene: &Scene,
    g: &crate::geometry::PartGeometry,
    face: FaceId,
    up: &V3,
    machine: &Machine,
) -> Vec<P3> {
    let crate::geometry::Surface::Plane { origin, .. } = g.faces[face.0].surface else {
        return vec![];
    };
    let (e1, e2) = crate::sample::perpendicular_basis(up);
    let (mut u0, mut u1, mut v0, mut v1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for v in scene.tris.iter().flat_map(|t| t.v.iter()) {
        let d = v - origin;
        let (u, w) = (d.dot(&e1), d.dot(&e2));
        (u0, u1, v0, v1) = (u0.min(u), u1.max(u), v0.min(w), v1.max(w));
    }
    let body = machine
        .probes
        .iter()
        .flat_map(|p| p.first.iter().map(|c| c.radius))
        .fold(0.0, f64::max);
    let off = 5.0 + body;
    [
        (u0 - off, v0 - off),
        (u1 + off, v0 - off),
        (u1 + off, v1 + off),
        (u0 - off, v1 + off),
    ]
    .iter()
    .map(|&(u, w)| origin + e1 * u + e2 * w)
    .collect()
}
