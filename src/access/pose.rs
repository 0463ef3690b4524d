//! The pose of a probe and its collision rules: the one owner of how a probe stands in a
//! setup (the part frame's `up` towards the ram, the table under the part), which way it
//! points (a fixed head along the ram, an indexable head at A/B), where its components
//! sit for a tip centre, and what it may not touch.
//!
//! The planner's validation ([`Pose::approach`]) and the path stage's move checks
//! ([`Pose::segment`]) both pose the probe here, so the two agree on every rule: the tip's
//! clearance at the contact ([`TIP_CLEARANCE`]), the table's margin ([`TABLE_MARGIN`]),
//! the components' lowest points ([`lowest`]) and the table's height ([`table_height`]).
//!
//! **Architecture Invariant:** no other module poses a probe or states a clearance to
//! part or table; `tests/suite/cases.rs` re-checks every move of every golden program through
//! [`Pose::segment`].
//!
//! **Decision: tip fit.** The ball fits when the mesh is at least [`TIP_CLEARANCE`]
//! (0.9) r from its centre: the fpoint lies on the exact surface, and the facets of a
//! concave face are up to the tessellation's chord error nearer.
//!
//! **Decision: moves keep a margin** (`motion { margin }`, 1 mm). Every shape of the
//! probe is grown by it for part and fixture, and the table is kept at least that far,
//! on every move but the touch itself (the sweep from stand-off to contact, which
//! validation checks at 0.9 r). A stand-off its feature leaves less room around keeps
//! the largest of 1, ½, ¼, ⅛ or 0 of the margin that fits (`Pose::set_tight`); a move
//! keeps the smaller margin of its two ends, so validation, path search and the golden
//! re-check use one rule.
//!
//! **Decision: backing off in narrow features.** The tip backs off a contact by the
//! pre-hit/retract distance, or by half the free space in front of it when that is less
//! (it waits on a small bore's axis, not past the far wall), and needs [`MIN_TRAVEL`]
//! (0.25 mm) to back off at all: a Ø4 ball does not "fit" a 4 mm slot. The cones,
//! validation and the path stage all call [`backoff`].

use super::{component_hits, head_direction, Component, End, ProbeShape, Scene};
use crate::geometry::{P3, V3};
use nalgebra::{Rotation3, Unit};
use parry3d_f64::math::Isometry;
use parry3d_f64::query::intersection_test;
use parry3d_f64::shape::{Capsule, Cuboid, Cylinder, RoundShape, Shape, TriMesh, Triangle};

/// The share of the tip radius the mesh may come closer than the radius at a contact:
/// fpoints lie on the exact surface and a concave face's facets are up to the
/// tessellation's chord error nearer (a tenth of the radius at most).
pub(crate) const TIP_CLEARANCE: f64 = 0.9;

/// The table may come no closer to the probe than this during a move (mm).
pub const TABLE_MARGIN: f64 = 0.1;

/// The margin an indexable probe's orientation keeps from the table when the planner
/// chooses it (mm): more than a move's, so that the moves around it have room.
pub const ORIENTATION_TABLE_MARGIN: f64 = 0.5;

/// The spacing of the positions tested along an approach (mm).
const SWEEP_STEP: f64 = 0.25;

/// Sides of the polygon standing in for a cylinder's disc in a swept hull.
const DISC_SIDES: usize = 16;

/// The kind of head a probe hangs from, as posing sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Head {
    /// The probe runs along the ram (a straight probe in the seed's terms).
    Fixed,
    /// The probe indexes to A/B angles (a bent probe): its first component along the
    /// orientation, its second (head, ram) along the ram from the articulation point.
    Indexable,
}

impl Head {
    /// Whether the head indexes.
    pub fn indexable(self) -> bool {
        self == Head::Indexable
    }
}

/// What a pose meets.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Blocker {
    /// The tip meets the part.
    Tip,
    /// The tip comes too near the table.
    TipOnTable,
    /// A named component (stylus, extension, body, head, ram) meets the part.
    Component(String),
    /// A named component comes too near the table.
    ComponentOnTable(String),
    /// A named component (or the tip) meets the fixture holding the part.
    Fixture(String),
    /// The touch is clear, but the path stage found no collision-free move to it.
    Path,
}

impl std::fmt::Display for Blocker {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Blocker::Tip => write!(f, "the tip"),
            Blocker::TipOnTable => write!(f, "the tip (on the table)"),
            Blocker::Component(c) => write!(f, "the {c}"),
            Blocker::ComponentOnTable(c) => write!(f, "the {c} (on the table)"),
            Blocker::Fixture(c) => write!(f, "the {c} (on the fixture)"),
            Blocker::Path => write!(f, "no collision-free move (on the way to it)"),
        }
    }
}

/// What a touch touches: the part, or the table standing in for a datum face resting on
/// it (ch. 3.6.2), where the tip is meant to reach the table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Contact {
    /// A point of the part.
    Part,
    /// A point of the table.
    Table,
}

/// The least travel a touch needs before and after its contact (mm): a tip that cannot
/// back off this far from the surface (a 4 mm ball in a 4 mm slot) does not fit.
pub const MIN_TRAVEL: f64 = 0.25;

/// Whether the tip at contact `p` can back off as far as a touch needs
/// ([`MIN_TRAVEL`], or `travel` when that is less).
pub fn room_to_touch(scene: &Scene, p: &P3, n: &V3, tip_radius: f64, travel: f64) -> bool {
    backoff(scene, p, n, tip_radius, travel) >= MIN_TRAVEL.min(travel) - 1e-9
}

/// Whether the tip of radius `r`, on its approach from the retract point `c + n · travel`
/// to the contact's tip centre `c`, meets one of a fixture's `solids`: the tip's part of
/// [`Pose::approach`]'s fixture test, which no orientation of the probe changes.
pub fn tip_meets_fixture(solids: &[Solid], c: &P3, n: &V3, travel: f64, r: f64) -> bool {
    let q = c + n * travel;
    let mid = P3::from((c.coords + q.coords) / 2.0);
    solids
        .iter()
        .any(|s| s.distance_at_least(&mid) <= travel / 2.0 + r && s.hits(&Capsule::new(*c, q, r)))
}

/// How far the tip backs off contact `p` (normal `n`) before and after a touch: `travel`,
/// or half the free space in front of the point when that is less (a small bore: the
/// tip waits on its axis rather than past the far wall). The planner validates a touch
/// over this distance and the path stage moves by it.
pub fn backoff(scene: &Scene, p: &P3, n: &V3, tip_radius: f64, travel: f64) -> f64 {
    // Rays start past the tessellation's deviation from the exact surface (0.05 mm).
    const SKIN: f64 = 0.1;
    let from = p + n * SKIN;
    match scene.cast_ray(&from, n, 2.0 * (travel + tip_radius) + 1.0) {
        Some(hit) => travel.min(((hit + SKIN - 2.0 * tip_radius) / 2.0).max(0.0)),
        None => travel,
    }
}

/// The rotation taking the part frame to the machine frame of setup `up` (up ↦ +z).
pub fn frame(up: &V3) -> Rotation3<f64> {
    Rotation3::rotation_between(up, &V3::z()).unwrap_or_else(|| {
        Rotation3::from_axis_angle(&Unit::new_normalize(V3::x()), std::f64::consts::PI)
    })
}

/// The probe direction (tip towards head, part frame) of head orientation (A, B) in
/// setup `up`.
pub fn orientation_dir(up: &V3, a: f64, b: f64) -> V3 {
    frame(up).inverse() * head_direction(a, b)
}

/// The height of the table under the part in setup `up`: the lowest vertex along `up`.
pub fn table_height(scene: &Scene, up: &V3) -> f64 {
    scene
        .tris
        .iter()
        .flat_map(|t| t.v.iter())
        .map(|v| v.coords.dot(up))
        .fold(f64::INFINITY, f64::min)
}

/// The lowest point along `up` of a component whose axis runs from `from` along unit `d`
/// over [a, b].
pub fn lowest(comp: &Component, from: &P3, d: &V3, up: &V3) -> f64 {
    let b = if comp.b.is_finite() { comp.b } else { comp.a };
    let h = |t: f64| (from + d * t).coords.dot(up);
    let ends = h(comp.a).min(h(b));
    let side = match comp.end {
        End::Round => comp.radius,
        End::Flat => comp.radius * (1.0 - d.dot(up).powi(2)).max(0.0).sqrt(),
    };
    ends - side
}

/// Whether an indexable probe at tip centre `c`, along `o`, with the head above its
/// articulation point, keeps [`ORIENTATION_TABLE_MARGIN`] off the table at height `t0`
/// in setup `up`.
pub fn above_table(probe: &ProbeShape, c: &P3, o: &V3, up: &V3, t0: f64) -> bool {
    let art = c + o * probe.reach();
    probe
        .first
        .iter()
        .all(|comp| lowest(comp, c, o, up) >= t0 + ORIENTATION_TABLE_MARGIN)
        && probe
            .second
            .iter()
            .all(|comp| lowest(comp, &art, up, up) >= t0 + ORIENTATION_TABLE_MARGIN)
}

/// A solid of a fixture, placed in the part frame of one setup: a box, or a cylinder
/// (along its local y axis, as parry's).
#[derive(Debug, Clone, PartialEq)]
pub struct Solid {
    /// Where it stands: local frame → part frame.
    pub at: Isometry<f64>,
    /// Its shape.
    pub shape: SolidShape,
}

/// The shapes fixtures are made of.
#[derive(Debug, Clone)]
pub enum SolidShape {
    /// A box with these half extents.
    Box(V3),
    /// A cylinder of this half height (along local y) and radius.
    Cylinder {
        /// Half its height.
        half_height: f64,
        /// Its radius.
        radius: f64,
    },
    /// A triangle mesh (a fixture from a mesh file), shared between setups.
    Mesh(std::sync::Arc<TriMesh>),
}

impl PartialEq for SolidShape {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (SolidShape::Box(a), SolidShape::Box(b)) => a == b,
            (
                SolidShape::Cylinder {
                    half_height: h1,
                    radius: r1,
                },
                SolidShape::Cylinder {
                    half_height: h2,
                    radius: r2,
                },
            ) => h1 == h2 && r1 == r2,
            (SolidShape::Mesh(a), SolidShape::Mesh(b)) => std::sync::Arc::ptr_eq(a, b),
            _ => false,
        }
    }
}

impl Solid {
    /// A box centred at `centre` with its local axes turned by `rot`.
    pub fn cuboid(centre: P3, rot: Rotation3<f64>, half: V3) -> Solid {
        Solid {
            at: Isometry::from_parts(centre.coords.into(), rot.into()),
            shape: SolidShape::Box(half.map(|x| x.max(1e-3))),
        }
    }

    /// The same solid `by` wider across: a cylinder's radius, a box's half extents
    /// across its local y (a mesh as it is).
    pub fn widen(&mut self, by: f64) {
        match &mut self.shape {
            SolidShape::Cylinder { radius, .. } => *radius += by,
            SolidShape::Box(half) => {
                half.x += by;
                half.z += by;
            }
            SolidShape::Mesh(_) => {}
        }
    }

    /// A cylinder around the axis from `base` along unit `axis` over `height`.
    pub fn cylinder(base: P3, axis: V3, height: f64, radius: f64) -> Solid {
        let rot = Rotation3::rotation_between(&V3::y(), &axis).unwrap_or_else(|| {
            Rotation3::from_axis_angle(&Unit::new_normalize(V3::x()), std::f64::consts::PI)
        });
        let centre = base + axis * (height / 2.0);
        Solid {
            at: Isometry::from_parts(centre.coords.into(), rot.into()),
            shape: SolidShape::Cylinder {
                half_height: (height / 2.0).max(1e-3),
                radius: radius.max(1e-3),
            },
        }
    }

    /// A mesh in the part frame (vertices in mm); `None` when the triangles do not make
    /// a mesh (the geometry stage refuses those).
    pub fn mesh(vertices: &[P3], triangles: &[[u32; 3]]) -> Option<Solid> {
        let mesh = TriMesh::new(vertices.to_vec(), triangles.to_vec()).ok()?;
        Some(Solid {
            at: Isometry::identity(),
            shape: SolidShape::Mesh(std::sync::Arc::new(mesh)),
        })
    }

    /// The solid as triangles in the part frame, for drawing (`inspc view`): a box's
    /// twelve, a cylinder as a 24-sided prism, a mesh's own.
    pub fn triangles(&self) -> (Vec<P3>, Vec<[u32; 3]>) {
        let (local, tris): (Vec<P3>, Vec<[u32; 3]>) = match &self.shape {
            SolidShape::Box(h) => {
                let corner = |k: u32| {
                    let s = |bit: u32| if k & bit == 0 { -1.0 } else { 1.0 };
                    P3::new(s(1) * h.x, s(2) * h.y, s(4) * h.z)
                };
                let quads = [
                    [0, 2, 3, 1],
                    [4, 5, 7, 6],
                    [0, 1, 5, 4],
                    [2, 6, 7, 3],
                    [0, 4, 6, 2],
                    [1, 3, 7, 5],
                ];
                let tris = quads
                    .iter()
                    .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
                    .collect();
                ((0..8).map(corner).collect(), tris)
            }
            SolidShape::Cylinder {
                half_height,
                radius,
            } => {
                const SIDES: u32 = 24;
                let mut vs = Vec::new();
                for k in 0..SIDES {
                    let t = std::f64::consts::TAU * k as f64 / SIDES as f64;
                    let (x, z) = (radius * t.cos(), radius * t.sin());
                    vs.push(P3::new(x, -half_height, z));
                    vs.push(P3::new(x, *half_height, z));
                }
                let (bottom, top) = (2 * SIDES, 2 * SIDES + 1);
                vs.push(P3::new(0.0, -half_height, 0.0));
                vs.push(P3::new(0.0, *half_height, 0.0));
                let mut tris = Vec::new();
                for k in 0..SIDES {
                    let (a, b) = (2 * k, 2 * ((k + 1) % SIDES));
                    tris.extend([
                        [a, b, b + 1],
                        [a, b + 1, a + 1],
                        [bottom, b, a],
                        [top, a + 1, b + 1],
                    ]);
                }
                (vs, tris)
            }
            SolidShape::Mesh(m) => (m.vertices().to_vec(), m.indices().to_vec()),
        };
        (local.iter().map(|p| self.at * p).collect(), tris)
    }

    /// A sphere around it (part frame): centre and radius.
    pub(crate) fn bounding_sphere(&self) -> (P3, f64) {
        match &self.shape {
            SolidShape::Box(h) => (P3::from(self.at.translation.vector), h.norm()),
            SolidShape::Cylinder {
                half_height,
                radius,
            } => (
                P3::from(self.at.translation.vector),
                half_height.hypot(*radius),
            ),
            SolidShape::Mesh(m) => {
                let b = m.local_aabb();
                (self.at * b.center(), b.half_extents().norm())
            }
        }
    }

    /// A lower bound of the distance from `p` (part frame) to this solid: exact for a
    /// box, from the bounding sphere otherwise.
    fn distance_at_least(&self, p: &P3) -> f64 {
        match &self.shape {
            SolidShape::Box(h) => {
                let local = self.at.inverse_transform_point(p);
                local
                    .coords
                    .abs()
                    .zip_map(h, |x, h| (x - h).max(0.0))
                    .norm()
            }
            _ => {
                let (c, r) = self.bounding_sphere();
                (p - c).norm() - r
            }
        }
    }

    /// Whether a shape given in the part frame meets this solid.
    pub fn hits(&self, shape: &dyn Shape) -> bool {
        let id = Isometry::identity();
        match &self.shape {
            SolidShape::Box(h) => intersection_test(&self.at, &Cuboid::new(*h), &id, shape),
            SolidShape::Cylinder {
                half_height,
                radius,
            } => intersection_test(&self.at, &Cylinder::new(*half_height, *radius), &id, shape),
            SolidShape::Mesh(m) => intersection_test(&self.at, &**m, &id, shape),
        }
        .unwrap_or(true)
    }

    /// The lowest point along unit `up`.
    pub fn lowest(&self, up: &V3) -> f64 {
        let local = self.at.rotation.inverse() * up;
        let c = self.at.translation.vector.dot(up);
        match &self.shape {
            SolidShape::Box(h) => {
                c - (h.x * local.x.abs() + h.y * local.y.abs() + h.z * local.z.abs())
            }
            SolidShape::Cylinder {
                half_height,
                radius,
            } => {
                c - half_height * local.y.abs() - radius * (1.0 - local.y * local.y).max(0.0).sqrt()
            }
            SolidShape::Mesh(m) => {
                c + m
                    .vertices()
                    .iter()
                    .map(|v| v.coords.dot(&local))
                    .fold(f64::INFINITY, f64::min)
            }
        }
    }
}

/// One component of a posed probe: its shape along `dir` from `offset` past the tip
/// centre.
#[derive(Debug, Clone)]
struct Posed {
    comp: Component,
    dir: V3,
    offset: V3,
}

/// A probe posed in the part frame — setup, orientation — with the obstacles of its
/// setup: the part, the table under it and the fixture holding it.
pub struct Pose<'a> {
    scene: &'a Scene,
    tip_radius: f64,
    parts: Vec<Posed>,
    up: V3,
    table: f64,
    fixture: &'a [Solid],
    /// A sphere around each solid of `fixture` ([`Solid::bounding_sphere`]).
    spheres: Vec<(P3, f64)>,
    /// The margin moves keep ([`Pose::segment`]).
    margin: f64,
    /// Stand-offs where the margin is less (quantised position → margin).
    tight: std::collections::HashMap<[i64; 3], f64>,
}

impl<'a> Pose<'a> {
    /// `probe` pointing along `dir` (tip to head, part frame) with the ram along `up`;
    /// the table lies at height `table` along `up`.
    pub fn new(scene: &'a Scene, probe: &ProbeShape, dir: V3, up: V3, table: f64) -> Pose<'a> {
        let mut parts = Vec::new();
        match probe.head {
            Head::Indexable => {
                for comp in &probe.first {
                    parts.push(Posed {
                        comp: comp.clone(),
                        dir,
                        offset: V3::zeros(),
                    });
                }
                for comp in &probe.second {
                    parts.push(Posed {
                        comp: comp.clone(),
                        dir: up,
                        offset: dir * probe.reach(),
                    });
                }
            }
            Head::Fixed => {
                for comp in probe.straight() {
                    parts.push(Posed {
                        comp,
                        dir: up,
                        offset: V3::zeros(),
                    });
                }
            }
        }
        Pose {
            scene,
            tip_radius: probe.tip_radius,
            parts,
            up,
            table,
            fixture: &[],
            spheres: Vec::new(),
            margin: 0.0,
            tight: Default::default(),
        }
    }

    /// The same pose with the indexed probe's components also standing along each of
    /// `turned` (the part set off square turns the stylus about the tip, in the part's
    /// frame, while the ram stays along `up`): every test then holds for them all. A
    /// fixed head's probe stands along `up` and turns into itself.
    pub fn with_turned(mut self, probe: &ProbeShape, turned: &[V3]) -> Pose<'a> {
        if probe.head != Head::Indexable {
            return self;
        }
        for t in turned {
            for comp in &probe.first {
                self.parts.push(Posed {
                    comp: comp.clone(),
                    dir: *t,
                    offset: V3::zeros(),
                });
            }
            for comp in &probe.second {
                self.parts.push(Posed {
                    comp: comp.clone(),
                    dir: self.up,
                    offset: t * probe.reach(),
                });
            }
        }
        self
    }

    /// The same pose with moves keeping `margin` (mm) from part, fixture and table.
    pub fn with_margin(mut self, margin: f64) -> Pose<'a> {
        self.margin = margin.max(0.0);
        self
    }

    /// Lets moves from and to stand-off `at` keep only `margin`: a narrow feature
    /// leaves no more room there.
    pub fn set_tight(&mut self, at: &P3, margin: f64) {
        self.tight.insert(spot(at), margin.max(0.0));
    }

    /// The margin a move from or to `x` keeps.
    pub(crate) fn margin_at(&self, x: &P3) -> f64 {
        if self.tight.is_empty() {
            return self.margin;
        }
        self.tight.get(&spot(x)).copied().unwrap_or(self.margin)
    }

    /// The same pose with the fixture's solids as obstacles too.
    pub fn with_fixture(mut self, solids: &'a [Solid]) -> Pose<'a> {
        self.fixture = solids;
        self.spheres = solids.iter().map(Solid::bounding_sphere).collect();
        self
    }

    /// The part it poses the probe against.
    pub fn scene(&self) -> &Scene {
        self.scene
    }

    /// The ram direction.
    pub fn up(&self) -> V3 {
        self.up
    }

    /// The lowest point along `up` of a posed component with the tip centre at `c`.
    fn low(&self, part: &Posed, c: &P3) -> f64 {
        lowest(&part.comp, &(c + part.offset), &part.dir, &self.up)
    }

    /// Validation of one touch (seed ch. 4.1): the tip sweeps from the retract point
    /// `c + n · travel` to the contact's tip centre `c` as an exact capsule of
    /// [`TIP_CLEARANCE`] times its radius; every other component is tested at both ends
    /// with its radius grown to cover the motion, and where that is not clear, at
    /// positions every 0.25 mm along the approach. A table contact may reach the table.
    pub fn approach(&self, c: &P3, n: &V3, travel: f64, contact: Contact) -> Result<(), Blocker> {
        let Some(mesh) = self.scene.mesh() else {
            return Ok(());
        };
        let id = Isometry::identity();
        let r = self.tip_radius;
        let tip = Capsule::new(*c, c + n * travel, TIP_CLEARANCE * r);
        if intersection_test(&id, &tip, &id, mesh).unwrap_or(true) {
            return Err(Blocker::Tip);
        }
        let t0 = self.table;
        let up = &self.up;
        if contact == Contact::Part
            && (c.coords.dot(up).min((c + n * travel).coords.dot(up))) - r < t0 - 1e-9
        {
            return Err(Blocker::TipOnTable);
        }
        for part in &self.parts {
            let comp = &part.comp;
            let d = &part.dir;
            let origin = |t: f64| -> P3 { c + n * t + part.offset };
            // The table: the lowest point is linear along the approach, so the ends decide.
            let low = self.low(part, c).min(self.low(part, &(c + n * travel)));
            if low < t0 + TABLE_MARGIN {
                return Err(Blocker::ComponentOnTable(comp.name.clone()));
            }
            if component_hits(self.scene, &origin(0.0), d, comp)
                || component_hits(self.scene, &origin(travel), d, comp)
            {
                return Err(Blocker::Component(comp.name.clone()));
            }
            let lateral = (n - d * n.dot(d)).norm();
            let grown = |extra: f64| Component {
                radius: comp.radius + extra,
                ..comp.clone()
            };
            // Two ends, radius grown by half the travel: covers every position between.
            let coarse = grown(travel / 2.0 * lateral);
            if !component_hits(self.scene, &origin(0.0), d, &coarse)
                && !component_hits(self.scene, &origin(travel), d, &coarse)
            {
                continue;
            }
            // Positions every SWEEP_STEP, radius grown by half a step.
            let steps = (travel / SWEEP_STEP).ceil().max(1.0) as usize;
            let fine = grown(travel / steps as f64 / 2.0 * lateral);
            for s in 0..=steps {
                let at = origin(travel * s as f64 / steps as f64);
                if component_hits(self.scene, &at, d, &fine) {
                    return Err(Blocker::Component(comp.name.clone()));
                }
            }
        }
        self.sweep_fixture(c, &(c + n * travel), 0.0)
    }

    /// Whether the probe standing with its tip centre at `p`, grown by the margin there,
    /// clears the fixture (the part and the table not asked).
    pub(crate) fn clear_of_fixture(&self, p: &P3) -> bool {
        self.sweep_fixture(p, p, self.margin_at(p)).is_ok()
    }

    /// Whether the probe, grown by `grow`, meets the fixture anywhere on the move from
    /// tip centre `p` to `q`.
    fn sweep_fixture(&self, p: &P3, q: &P3, grow: f64) -> Result<(), Blocker> {
        if self.fixture.is_empty() {
            return Ok(());
        }
        let hits = |s: &dyn Shape, _: &Core| self.fixture.iter().any(|f| f.hits(s));
        self.sweep(p, q, &hits, grow, Some(&self.spheres))
            .map_err(|b| match b {
                Blocker::Component(c) => Blocker::Fixture(c),
                _ => Blocker::Fixture("tip".into()),
            })
    }

    /// Whether the probe standing with its tip centre at `p` is clear by the margin
    /// there.
    pub fn free(&self, p: &P3) -> Result<(), Blocker> {
        self.segment(p, p)
    }

    /// Whether the probe can move from tip centre `p` to `q` keeping the margin: the
    /// smaller of the margins at the two ends (see [`Pose::set_tight`]).
    pub fn segment(&self, p: &P3, q: &P3) -> Result<(), Blocker> {
        self.segment_with(p, q, self.margin_at(p).min(self.margin_at(q)))
    }

    /// Whether the probe can translate from tip centre `p` to `q` (seed ch. 5.4.2); else
    /// what hits. Each component is swept on its own: the tip ball as an exact capsule,
    /// a stylus or extension capsule as the exact union of two rounded triangles, a
    /// body, head or ram cylinder as the convex hull of its two end positions (its discs
    /// as circumscribed 16-gons, so a little larger than the cylinder). A component's
    /// lowest point moves linearly along a segment, so the two ends decide the table.
    /// Every shape is grown by `margin`, and the table kept at least that far.
    pub fn segment_with(&self, p: &P3, q: &P3, margin: f64) -> Result<(), Blocker> {
        let table = self.table + TABLE_MARGIN.max(margin);
        // A scanner has no tip: the point it moves by is the focus of its optics.
        let lo = p.coords.dot(&self.up).min(q.coords.dot(&self.up)) - self.tip_radius;
        if self.tip_radius > 0.0 && lo < table {
            return Err(Blocker::TipOnTable);
        }
        for part in &self.parts {
            if self.low(part, p).min(self.low(part, q)) < table {
                return Err(Blocker::ComponentOnTable(part.comp.name.clone()));
            }
        }
        if self.scene.mesh().is_some() {
            let hits = |shape: &dyn Shape, core: &Core| {
                let id = Isometry::identity();
                self.scene
                    .meets(shape, &id, &core.tris[..core.len], core.radius)
            };
            self.sweep(p, q, &hits, margin, None)?;
        }
        self.sweep_fixture(p, q, margin)
    }

    /// Sweeps every component from tip centre `p` to `q` against what `hits` tests:
    /// the tip as an exact capsule, a stylus or extension capsule as the exact union of
    /// two rounded triangles, a body, head or ram cylinder as the convex hull of its two
    /// end positions (its discs as circumscribed 16-gons). `hits` gets each shape with a
    /// [`Core`] it lies within.
    fn sweep(
        &self,
        p: &P3,
        q: &P3,
        hits: &dyn Fn(&dyn Shape, &Core) -> bool,
        grow: f64,
        spheres: Option<&[(P3, f64)]>,
    ) -> Result<(), Blocker> {
        let v = q - p;
        let moving = v.norm() > 1e-9;
        // Whether a shape within `r` of `c` may meet the obstacle: with `spheres` (one
        // around each of its solids), only when one of them is that near.
        let near = |c: &P3, r: f64| {
            spheres.is_none_or(|s| s.iter().any(|(x, rx)| (x - c).norm() <= r + rx))
        };
        let tip = self.tip_radius + grow;
        if self.tip_radius > 0.0
            && near(&(p + v / 2.0), v.norm() / 2.0 + tip)
            && hits(&Capsule::new(*p, *q, tip), &Core::segment(p, q, tip))
        {
            return Err(Blocker::Tip);
        }
        let far = 4.0 * self.scene.size + 10.0;
        for part in &self.parts {
            let c = &part.comp;
            let radius = c.radius + grow;
            let b = c.b.min(c.a + far);
            let a0 = p + part.offset + part.dir * c.a;
            let b0 = p + part.offset + part.dir * b;
            // A sphere around the swept component (its discs' circumscribed polygons
            // included): the middle of the move, out to its farthest end.
            let mid = P3::from((a0.coords + b0.coords + v) / 2.0);
            let reach = ((b0 - a0).norm() + v.norm()) / 2.0
                + radius / (std::f64::consts::PI / DISC_SIDES as f64).cos();
            let hit = match (c.end, moving) {
                (_, _) if c.radius == 0.0 => false,
                _ if !near(&mid, reach) => false,
                (End::Round, false) => hits(
                    &Capsule::new(a0, b0, radius),
                    &Core::segment(&a0, &b0, radius),
                ),
                (End::Round, true) => {
                    let round = |t: [P3; 3]| {
                        let shape = RoundShape {
                            inner_shape: Triangle::new(t[0], t[1], t[2]),
                            border_radius: radius,
                        };
                        hits(
                            &shape,
                            &Core {
                                tris: [t, t],
                                len: 1,
                                radius,
                            },
                        )
                    };
                    round([a0, b0, a0 + v]) || round([b0, b0 + v, a0 + v])
                }
                (End::Flat, _) => {
                    let (e1, e2) = crate::sample::perpendicular_basis(&part.dir);
                    let r = radius / (std::f64::consts::PI / DISC_SIDES as f64).cos();
                    let mut points = Vec::with_capacity(2 * DISC_SIDES);
                    for k in 0..DISC_SIDES {
                        let t = std::f64::consts::TAU * k as f64 / DISC_SIDES as f64;
                        let e = (e1 * t.cos() + e2 * t.sin()) * r;
                        points.push(a0 + e);
                        points.push(b0 + e);
                    }
                    let v = if moving { v } else { V3::zeros() };
                    // Every corner lies r from the axis's ends, moved along v at most.
                    let core = Core {
                        tris: [[a0, b0, a0 + v], [b0, b0 + v, a0 + v]],
                        len: 2,
                        radius: r,
                    };
                    hits(&super::swept::SweptHull { points, v }, &core)
                }
            };
            if hit {
                return Err(Blocker::Component(c.name.clone()));
            }
        }
        Ok(())
    }
}

/// Where a swept shape lies: within `radius` of its first `len` triangles (a segment
/// is a triangle with two corners equal).
struct Core {
    tris: [[P3; 3]; 2],
    len: usize,
    radius: f64,
}

impl Core {
    fn segment(a: &P3, b: &P3, radius: f64) -> Core {
        Core {
            tris: [[*a, *b, *b]; 2],
            len: 1,
            radius,
        }
    }
}

/// A stand-off's key: its position to 0.1 µm (the plan's coordinates are quantised to
/// 1 nm, so a stand-off read back from a program finds its own key).
fn spot(x: &P3) -> [i64; 3] {
    [x.x, x.y, x.z].map(|c| (c * 1e4).round() as i64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A plate 20 × 20 × 10 mm whose top lies at z = 0.
    fn plate() -> Vec<Solid> {
        vec![Solid::cuboid(
            P3::new(0.0, 0.0, -5.0),
            Rotation3::identity(),
            V3::new(10.0, 10.0, 5.0),
        )]
    }

    #[test]
    fn a_tip_sweeping_along_the_plate_meets_it() {
        let c = P3::new(0.0, 0.0, 0.5);
        assert!(tip_meets_fixture(&plate(), &c, &V3::x(), 5.0, 1.0));
    }

    /// A wall in the plane y = 0, x from 0 to 100, z from -50 to 50, as two triangles.
    fn wall() -> Scene {
        let (a, b) = (P3::new(0.0, 0.0, -50.0), P3::new(100.0, 0.0, -50.0));
        let (c, d) = (P3::new(100.0, 0.0, 50.0), P3::new(0.0, 0.0, 50.0));
        Scene::of_triangles(&[[a, b, c], [a, c, d]])
    }

    #[test]
    fn a_stylus_beside_a_wall_meets_it_once_the_part_is_turned() {
        // The stylus lies along +x, 2.5 mm from the wall: a move along it clears by 1
        // mm. The part set 3° off square turns the stylus about the tip in the part's
        // frame, and its far end swings 50 · sin 3° = 2.6 mm towards the wall.
        let scene = wall();
        let probe = ProbeShape::bare_stylus(50.0, Head::Indexable);
        let (dir, up) = (V3::x(), V3::z());
        let (p, q) = (P3::new(10.0, 2.5, 0.0), P3::new(20.0, 2.5, 0.0));
        let plain = Pose::new(&scene, &probe, dir, up, -1000.0);
        assert!(plain.segment_with(&p, &q, 0.5).is_ok());
        let turned = crate::plan::turned_dirs(dir, &up, 3.0);
        let posed = Pose::new(&scene, &probe, dir, up, -1000.0).with_turned(&probe, &turned);
        assert!(posed.segment_with(&p, &q, 0.5).is_err());
        // A probe standing along the vertical turns into itself: there is nothing to add.
        assert!(crate::plan::turned_dirs(up, &up, 3.0).is_empty());
    }

    #[test]
    fn a_tip_backing_off_the_plate_clears_it() {
        let c = P3::new(0.0, 0.0, 1.5);
        assert!(!tip_meets_fixture(&plate(), &c, &V3::z(), 5.0, 1.0));
        let far = P3::new(50.0, 0.0, 0.5);
        assert!(!tip_meets_fixture(&plate(), &far, &V3::x(), 5.0, 1.0));
    }
}
