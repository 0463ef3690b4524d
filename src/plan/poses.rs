//! Setups an operator can realise: the part resting on the table in a stable
//! pose. Spitz treats a setup as any direction and assumes a fixture exists; a CMM user
//! has a table and gravity, so the planner chooses among these poses only (and those of
//! the fixtures a plan names, see [`Setups`]).
//!
//! A pose rests the part on a facet of its convex hull. Its *support polygon* is the
//! convex hull of the points that really touch the table there: vertices of part faces
//! lying in the facet's plane (flat contact), and sharp corners — vertices all of whose
//! faces are planes. A cylinder's tessellation facet is not a support: the real cylinder
//! touches the table along a line and rolls. The pose is stable when the centre of mass
//! of the solid projects inside the polygon and the part must tip by at least
//! [`MIN_TIP_DEG`] about the nearest edge before it falls over: `atan(d / h)`, `d` the
//! projection's distance to that edge, `h` the centre's height above the table.
//!
//! **Architecture Invariant:** a function of the geometry alone; poses come out in a
//! fixed order (largest support area first, then by direction).
//!
//! **Decision: setups are physical.** A setup is a stable pose on the table or a named
//! fixture's pose; Spitz's "any direction, a fixture exists" is what a plan says by
//! naming a fixture (the swiss sphere's plans name a chuck). Ten degrees to tip
//! excludes a disc on its rim, a shaft on its end and a thin plate on its edge. The
//! table alone comes first (on the plan's risers where the table hides a face, see
//! [`super::risers`]), then the plan's fixtures in the order it names them: a vise
//! clamps two opposite bounding faces, the part on a flat face square to them; a chuck
//! holds an outer cylinder at the part's end, axis vertical, or a sphere in any
//! direction; V-blocks hold an outer cylinder at the part's bottom, axis horizontal,
//! turned in 15° steps; a sine or angle plate tilts a flat face within its range.
//! Fixtures are solids for validation and moves only — the cones do not see them, so a
//! fixture failure removes the configuration at once, and every other orientation of
//! that setup is validated again then. Their solids are a little larger than real ones
//! (25 mm jaws, a plate 30 mm past the part). A fixture from a mesh (`kind mesh`,
//! `geometry::fixture`) offers its one pose, the mesh a parry obstacle, the table under
//! its lowest point.
//!
//! **Decision: a plate holds a part as an operator clamps it.** A sine or angle plate
//! clamps one of the part's broad flat faces (at least a quarter of the largest one's
//! support; at most the 8 largest), with that face's longest edge against the plate's
//! rail, square to it or at 45° (a parallel or a 45° block), tilted within the plate's
//! range; the planner tries those poses exactly (the range's ends and every 5°). Any
//! cube-map direction at an allowed angle from any flat face is not a pose: it would
//! let plans clamp a plate by a chamfer or tilt a part about an arbitrary axis, which
//! no operator does. The plan says how the part lies in the drawing's axes ("tilted
//! 60°, its y axis along the hinge, its +x side rising", see [`plate_words`]): an
//! independent review read "its longest edge square to the hinge" as the part's longest
//! edge where the support polygon's was meant, a 90° error on a 680 × 860 mm part. A tilted plate's solid runs up its own plane from the table (its
//! hinge the fixture's `height` under the part) to 30 mm past the part's top, so the
//! table lies where the real one does. A plate with a `plate` size holds only a part at
//! most [`PLATE_OVERHANG`] times its top each way (an 800 mm part does not go on a 6 ×
//! 12 in sine plate); inspc does not know the part's material, so no load limit.

use super::support::{polygon_area, tip};
use crate::access::pose::Solid;
use crate::geometry::{FaceId, FixtureMesh, PartGeometry, Surface, P3, V3};
use crate::model::{Fixture, FixtureKind, Model, Plan};
use crate::sample::{convex_hull, perpendicular_basis};

/// The least tipping angle of a stable pose (degrees): a 480 mm shaft on its Ø51 end
/// tips at 6°, a disc on its rim at 3°; a cube on a face at 45°.
pub const MIN_TIP_DEG: f64 = 10.0;

/// How far (mm) the part may stand off the place the prompt gives it on supports set by
/// eye: three risers are put down where the prompt's distances say and the part set on
/// them, each to within what `inspc verify` tries (5 mm), so the planner keeps touches
/// and moves that far clear of the pads ([`Setups::keep_out`]); the virtual CMM puts the
/// pads where they are.
pub(crate) const PLACEMENT_SHIFT: f64 = 5.0;

/// Directions closer than this are one pose (degrees).
const SAME_PLANE_DEG: f64 = 0.5;

/// A way the part can rest on the table.
#[derive(Debug, Clone)]
pub(crate) struct RestPose {
    /// The part frame's up direction in this pose (minus the resting facet's normal).
    pub up: V3,
    /// The planar faces that lie on the table.
    pub faces: Vec<FaceId>,
    /// The support polygon's area (mm²).
    pub area: f64,
    /// How far the part tips before it falls (degrees); negative: the centre of mass
    /// lies outside the support.
    pub tip_deg: f64,
    /// Whether the contact is a polygon of flat contact and corners (not a line or point
    /// of a curved face).
    pub flat: bool,
    /// The direction of the support polygon's longest edge (perpendicular to `up`): what
    /// an operator lines up against a plate's rail or stop.
    pub edge: V3,
}

impl RestPose {
    /// The four directions, square to `up`, a plate clamping this face may tilt it
    /// towards: along its longest edge or square to it, either way.
    pub(crate) fn azimuths(&self) -> [V3; 8] {
        let w = self.up.cross(&self.edge).normalize();
        let (a, b) = ((self.edge + w).normalize(), (self.edge - w).normalize());
        [self.edge, -self.edge, w, -w, a, -a, b, -b]
    }

    /// Whether the part stays in this pose on its own.
    pub fn stable(&self) -> bool {
        self.flat && self.tip_deg >= MIN_TIP_DEG
    }

    /// Why it is not stable, in words; `None` when it is.
    pub(crate) fn excluded(&self) -> Option<String> {
        if !self.flat {
            Some("it would rest on a curved face's line or point and roll".into())
        } else if self.tip_deg < 0.0 {
            Some("its centre of mass lies outside the support".into())
        } else if self.tip_deg < MIN_TIP_DEG {
            Some(format!(
                "it tips over at {:.1}° (a stable pose needs {MIN_TIP_DEG}°)",
                self.tip_deg
            ))
        } else {
            None
        }
    }
}

/// What holds the part in a setup.
#[derive(Debug, Clone, PartialEq)]
pub enum Holder {
    /// It rests on the table on these faces (a stable pose).
    Table {
        /// The planar faces on the table.
        faces: Vec<FaceId>,
    },
    /// A fixture of the CMM holds it.
    Fixture {
        /// The fixture's index in the CMM's list.
        slot: usize,
        /// The faces the fixture grips or the part rests on in it.
        faces: Vec<FaceId>,
        /// How the part lies on a tilted plate, for the operator: which part direction
        /// runs along the plate's hinge and which side rises (see [`plate_words`]).
        placement: Option<String>,
    },
}

/// Jaw thickness of a vise and a chuck, and a sine plate's thickness (mm): the solids
/// stand for the real fixture, a little larger rather than smaller.
const JAW_MM: f64 = 25.0;

/// A V-block's turning steps about the held cylinder's axis (degrees), how many axes it
/// is tried on, and its length along the axis (mm).
const VBLOCK_STEP_DEG: f64 = 15.0;
const VBLOCK_AXES: usize = 4;
const VBLOCK_LENGTH_MM: f64 = 50.0;

/// How far a sine plate reaches past the part on every side (mm).
const PLATE_MARGIN_MM: f64 = 30.0;

/// A sine plate's tilts tried between its limits (degrees), and how many of the part's
/// flat faces (largest first) it is tried under.
const PLATE_STEP_DEG: f64 = 5.0;
const PLATE_RESTS: usize = 8;
/// The least support a face clamped on a plate has, as a share of the largest face's.
const PLATE_MIN_SHARE: f64 = 0.25;
/// How far a part may be larger than a plate's top it is clamped on, as a factor on
/// each side's length: a quarter overhanging at either end.
const PLATE_OVERHANG: f64 = 1.5;

/// The setups a plan may use and what holds the part in each: the stable rest poses
/// first, then the plan's fixtures in the order it names them.
pub struct Setups<'a> {
    geometry: &'a PartGeometry,
    rests: Vec<RestPose>,
    fixtures: Vec<(usize, &'a Fixture)>,
    /// Pairs of opposite planar faces a vise can clamp: (normal of the first, first,
    /// second, distance).
    clamps: Vec<(V3, FaceId, FaceId, f64)>,
    /// The convex hull's vertices: the part's extremes in any direction.
    hull: Vec<P3>,
    /// The same vertices in clusters, for the extremes along one direction.
    extremes: Extremes,
    /// The part's bounding-box diagonal (mm).
    size: f64,
    /// The solid's centre of mass.
    com: P3,
    /// The plan's mesh fixtures placed with the part, by slot, each as a solid.
    meshes: Vec<(usize, &'a FixtureMesh, Solid)>,
    /// The plan's first risers (slot) and, per rest pose, the pads' centres where the
    /// part stands on them in that pose (see [`super::risers`]).
    risers: Option<(usize, Vec<Option<[P3; 3]>>)>,
    /// Per rest pose, the part's extents along its support's longest edge and across
    /// it: what a plate's top must take ([`fits_plate`]).
    spans: Vec<[f64; 2]>,
}

impl<'a> Setups<'a> {
    /// The setups of `plan` on `geometry`, with the mesh fixtures placed with it.
    pub fn new(
        model: &'a Model,
        plan: &Plan,
        geometry: &'a PartGeometry,
        placed: &'a [FixtureMesh],
    ) -> Setups<'a> {
        let cmm = &model.cmms[plan.cmm.0];
        let meshes = plan
            .fixtures
            .iter()
            .filter_map(|&k| {
                let id = cmm.fixtures.get(k)?.1;
                let m = placed.iter().find(|m| m.fixture == id)?;
                Some((k, m, Solid::mesh(&m.vertices, &m.triangles)?))
            })
            .collect();
        let fixtures: Vec<(usize, &Fixture)> = plan
            .fixtures
            .iter()
            .filter_map(|&k| cmm.fixtures.get(k).map(|(_, f)| (k, &model.fixtures[f.0])))
            .collect();
        let (hull, rests) = match parry3d_f64::transformation::try_convex_hull(&geometry.vertices) {
            Ok((v, tris)) => {
                let rests = rest_poses(geometry, &v, &tris);
                (v, rests)
            }
            Err(_) => (geometry.vertices.clone(), vec![]),
        };
        let (lo, hi) = geometry.bounds();
        let mut clamps = Vec::new();
        if fixtures
            .iter()
            .any(|(_, f)| matches!(f.kind, FixtureKind::Vise { .. }))
        {
            clamps = clamp_pairs(geometry, &hull);
        }
        let extremes = Extremes::new(&hull);
        let com = centre_of_mass(geometry);
        let risers = fixtures.iter().find_map(|&(slot, f)| match f.kind {
            FixtureKind::Risers { pads } => Some((
                slot,
                rests
                    .iter()
                    .map(|r| riser_pads(geometry, r, extremes.lowest(&r.up), &com, pads))
                    .collect(),
            )),
            _ => None,
        });
        let spans = rests.iter().map(|r| spans(&hull, r)).collect();
        Setups {
            geometry,
            rests,
            fixtures,
            clamps,
            spans,
            extremes,
            hull,
            size: (hi - lo).norm(),
            com,
            meshes,
            risers,
        }
    }

    /// Directions the cube maps should hold exactly: the rest poses' (stable, or flat
    /// when the plan has fixtures), the outer cylinders' axes a chuck may hold, and the
    /// turns about them a V-block may hold.
    pub fn exact_dirs(&self) -> Vec<V3> {
        let mut out: Vec<V3> = self
            .rests
            .iter()
            .filter(|r| r.stable() || (r.flat && !self.fixtures.is_empty()))
            .map(|r| r.up)
            .collect();
        for (_, f) in &self.fixtures {
            match f.kind {
                FixtureKind::VBlock { diameter } => {
                    // Turned about each cylinder's axis in VBLOCK_STEP_DEG steps.
                    for axis in self.outer_axes(diameter).iter().take(VBLOCK_AXES) {
                        let (e1, e2) = perpendicular_basis(axis);
                        let steps = (360.0 / VBLOCK_STEP_DEG) as usize;
                        for k in 0..steps {
                            let t = (k as f64 * VBLOCK_STEP_DEG).to_radians();
                            out.push(e1 * t.cos() + e2 * t.sin());
                        }
                    }
                }
                FixtureKind::Chuck { diameter, .. } => {
                    for axis in self.outer_axes(diameter) {
                        out.extend([axis, -axis]);
                    }
                }
                FixtureKind::Mesh { up, .. } => out.push(V3::from(up).normalize()),
                FixtureKind::SinePlate { tilt, plate } => {
                    for r in self.plate_rests(plate) {
                        for deg in plate_tilts(tilt) {
                            let t = deg.to_radians();
                            for z in r.azimuths() {
                                out.push((r.up * t.cos() + z * t.sin()).normalize());
                            }
                        }
                    }
                }
                _ => {}
            }
        }
        out
    }

    /// The face a sine plate tilted within `tilt` (degrees) clamps with `up` pointing
    /// up, and how the part lies on it: the part clamped with its face's longest edge
    /// against the plate's rail, square to it or at 45°, the plate tilting it towards
    /// one of the face's [`RestPose::azimuths`].
    fn on_plate(
        &self,
        tilt: [f64; 2],
        plate: Option<[f64; 2]>,
        up: &V3,
    ) -> Option<(&RestPose, Option<String>)> {
        let (lo, hi) = (tilt[0].to_radians(), tilt[1].to_radians());
        self.plate_rests(plate).find_map(|r| {
            let a = r.up.dot(up).clamp(-1.0, 1.0).acos();
            if a < lo - 1e-9 || a > hi + 1e-9 {
                return None;
            }
            if a < 1e-9 {
                return Some((r, None));
            }
            // Within 1e-5 on the sphere (0.0006°): a program's ROTATEs give the
            // simulator the setup to about that.
            let (c, s) = (a.cos(), a.sin());
            let z = r
                .azimuths()
                .into_iter()
                .find(|z| (r.up * c + z * s - up).norm() < 1e-5)?;
            Some((r, Some(plate_words(&r.up.cross(&z), &z))))
        })
    }

    /// The flat faces a sine plate may clamp: the largest [`PLATE_RESTS`] of those with
    /// at least [`PLATE_MIN_SHARE`] of the largest one's support — a plate holds a part
    /// by a broad face, not cantilevered from an end or a chamfer — where the part lying
    /// on that face fits the plate's top (`plate`, see [`fits_plate`]).
    fn plate_rests(&self, plate: Option<[f64; 2]>) -> impl Iterator<Item = &RestPose> {
        let largest = self
            .rests
            .iter()
            .filter(|r| r.flat)
            .map(|r| r.area)
            .fold(0.0, f64::max);
        self.rests
            .iter()
            .zip(&self.spans)
            .filter(move |(r, span)| {
                r.flat
                    && r.area >= PLATE_MIN_SHARE * largest
                    && plate.is_none_or(|p| fits_plate(span, p))
            })
            .map(|(r, _)| r)
            .take(PLATE_RESTS)
    }

    /// The risers' slot and pads under rest pose `k`, where it stands on them.
    fn pads(&self, k: usize) -> Option<(usize, &[P3; 3])> {
        let (slot, pads) = self.risers.as_ref()?;
        pads[k].as_ref().map(|p| (*slot, p))
    }

    /// The placed mesh of the fixture in `slot` and its solid, if it is a mesh fixture.
    fn mesh_of(&self, slot: usize) -> Option<(&'a FixtureMesh, &Solid)> {
        self.meshes
            .iter()
            .find(|(k, _, _)| *k == slot)
            .map(|(_, m, solid)| (*m, solid))
    }

    /// The distinct axes of the part's outer cylinders whose diameter lies in `diameter`.
    fn outer_axes(&self, diameter: [f64; 2]) -> Vec<V3> {
        let mut axes: Vec<V3> = Vec::new();
        for face in &self.geometry.faces {
            if let Surface::Cylinder {
                axis,
                radius,
                convex: true,
                ..
            } = face.surface
            {
                let fits = (diameter[0]..=diameter[1]).contains(&(2.0 * radius));
                if fits && !axes.iter().any(|a| a.cross(&axis).norm() < 1e-9) {
                    axes.push(axis);
                }
            }
        }
        axes
    }

    /// The lowest point of the part along `up`.
    fn low(&self, up: &V3) -> f64 {
        self.extremes.lowest(up)
    }

    /// What holds the part with `up` pointing up, if anything can: resting on the table
    /// when that pose is stable, else the first of the plan's fixtures that can.
    pub fn holder(&self, up: &V3) -> Option<Holder> {
        let same = |a: &V3| (a - up).norm() < 1e-6;
        if let Some((k, r)) = self
            .rests
            .iter()
            .enumerate()
            .find(|(_, r)| r.stable() && same(&r.up))
        {
            if let Some((slot, pads)) = self.pads(k) {
                return Some(Holder::Fixture {
                    slot,
                    faces: r.faces.clone(),
                    placement: Some(super::risers::words(pads, &self.geometry.bounds().0, &r.up)),
                });
            }
            return Some(Holder::Table {
                faces: r.faces.clone(),
            });
        }
        for &(slot, f) in &self.fixtures {
            if let Some((faces, placement)) = self.holds(slot, f, up) {
                return Some(Holder::Fixture {
                    slot,
                    faces,
                    placement,
                });
            }
        }
        None
    }

    /// The faces fixture `f` (in `slot`) holds with `up` pointing up, if it can hold the
    /// part so, and on a plate how the part lies (see [`Holder::Fixture`]).
    fn holds(&self, slot: usize, f: &Fixture, up: &V3) -> Option<(Vec<FaceId>, Option<String>)> {
        if let FixtureKind::SinePlate { tilt, plate } = f.kind {
            // The part clamped with an edge against the plate's rail: the plate tilts it
            // towards one of the face's azimuths, by an angle in its range.
            return self
                .on_plate(tilt, plate, up)
                .map(|(r, placement)| (r.faces.clone(), placement));
        }
        self.grips(slot, f, up).map(|faces| (faces, None))
    }

    /// [`Setups::holds`] for the fixtures other than plates: the faces they hold.
    fn grips(&self, slot: usize, f: &Fixture, up: &V3) -> Option<Vec<FaceId>> {
        let g = self.geometry;
        let same = |a: &V3| (a - up).norm() < 1e-6;
        match f.kind {
            FixtureKind::Mesh { up: its_up, .. } => {
                let (m, _) = self.mesh_of(slot)?;
                same(&V3::from(its_up).normalize()).then(|| m.locating.clone())
            }
            FixtureKind::SinePlate { .. } => None, // `holds` answers for plates
            FixtureKind::Risers { .. } => None,    // `holder` answers for risers
            FixtureKind::Vise { opening, .. } => {
                let base = self.rests.iter().find(|r| r.flat && same(&r.up))?;
                self.clamps
                    .iter()
                    .find(|(n, _, _, w)| n.dot(up).abs() < 1e-6 && *w <= opening)
                    .map(|&(_, a, b, _)| {
                        let mut faces = vec![a, b];
                        faces.extend(&base.faces);
                        faces
                    })
            }
            FixtureKind::VBlock { diameter } => {
                let tol = 1e-3 * self.size.max(1.0);
                // The part's lowest point, once a cylinder lies across `up`.
                let mut low = None;
                g.faces
                    .iter()
                    .enumerate()
                    .find_map(|(k, face)| match face.surface {
                        Surface::Cylinder {
                            origin,
                            axis,
                            radius,
                            convex: true,
                        } if (diameter[0]..=diameter[1]).contains(&(2.0 * radius))
                            && axis.dot(up).abs() < 1e-6
                            && *low.get_or_insert_with(|| self.low(up))
                                >= origin.coords.dot(up) - radius - tol =>
                        {
                            Some(vec![FaceId(k)])
                        }
                        _ => None,
                    })
            }
            FixtureKind::Chuck { diameter, .. } => {
                let tol = 1e-3 * self.size.max(1.0);
                let low = self.low(up);
                for (k, face) in g.faces.iter().enumerate() {
                    let fits = |r: f64| (diameter[0]..=diameter[1]).contains(&(2.0 * r));
                    match face.surface {
                        Surface::Cylinder {
                            axis,
                            radius,
                            convex: true,
                            ..
                        } if fits(radius) && axis.dot(up).abs() > 1.0 - 1e-9 => {
                            let face_low = face
                                .triangles
                                .iter()
                                .flat_map(|&t| g.triangles[t as usize])
                                .map(|v| g.vertices[v as usize].coords.dot(up))
                                .fold(f64::INFINITY, f64::min);
                            if face_low <= low + tol {
                                return Some(vec![FaceId(k)]);
                            }
                        }
                        Surface::Sphere {
                            center,
                            radius,
                            convex: true,
                        } if fits(radius) && low >= center.coords.dot(up) - radius - tol => {
                            return Some(vec![FaceId(k)]);
                        }
                        _ => {}
                    }
                }
                None
            }
        }
    }

    /// Where the table lies along `up` under the part held by `holder` with the
    /// fixture's `solids` (from [`Setups::solids`]).
    pub fn table(&self, holder: &Holder, up: &V3, solids: &[Solid]) -> f64 {
        let low = self.low(up);
        match holder {
            Holder::Table { .. } => low,
            Holder::Fixture { slot, .. } => {
                let f = self.fixture(*slot);
                let base = solids.iter().map(|s| s.lowest(up)).fold(low, f64::min);
                base.min(low - f.height)
            }
        }
    }

    fn fixture(&self, slot: usize) -> &Fixture {
        self.fixtures
            .iter()
            .find(|(k, _)| *k == slot)
            .map(|(_, f)| *f)
            .expect("holders name the plan's fixtures")
    }

    /// What the planner keeps clear of: the fixture's solids, riser pads widened by
    /// [`PLACEMENT_SHIFT`] (pads are set by eye; a part 5 mm off them
    /// brings a touch under it 5 mm nearer one).
    pub fn keep_out(&self, holder: &Holder, up: &V3) -> Vec<Solid> {
        let mut solids = self.solids(holder, up);
        if let Holder::Fixture { slot, .. } = holder {
            if matches!(self.fixture(*slot).kind, FixtureKind::Risers { .. }) {
                for s in &mut solids {
                    s.widen(PLACEMENT_SHIFT);
                }
            }
        }
        solids
    }

    /// The fixture's solids in the part frame with `up` pointing up: obstacles to the
    /// probe like the part itself. None for the table.
    pub fn solids(&self, holder: &Holder, up: &V3) -> Vec<Solid> {
        let Holder::Fixture { slot, faces, .. } = holder else {
            return vec![];
        };
        let g = self.geometry;
        let f = self.fixture(*slot);
        let low = self.low(up);
        let high = -self.extremes.lowest(&-up);
        let height = high - low;
        let size = self.size;
        match f.kind {
            FixtureKind::Mesh { .. } => self
                .mesh_of(*slot)
                .map(|(_, solid)| vec![solid.clone()])
                .unwrap_or_default(),
            FixtureKind::Risers { pads } => {
                let same = |a: &V3| (a - up).norm() < 1e-6;
                (0..self.rests.len())
                    .find(|&k| same(&self.rests[k].up))
                    .and_then(|k| self.pads(k))
                    .map(|(_, c)| super::risers::solids(c, up, f.height, pads))
                    .unwrap_or_default()
            }
            FixtureKind::Chuck { jaws, body, .. } => {
                let Some(face) = faces.first() else {
                    return vec![];
                };
                let (centre, radius) = match g.faces[face.0].surface {
                    Surface::Cylinder { origin, radius, .. } => (origin, radius),
                    Surface::Sphere { center, radius, .. } => (center, radius),
                    _ => return vec![],
                };
                // The axis through the held face, down to the part's lowest point.
                let foot = centre + up * (low - centre.coords.dot(up));
                let grip = jaws.min(0.5 * height);
                vec![
                    Solid::cylinder(foot - up * f.height, *up, f.height, body / 2.0),
                    Solid::cylinder(foot - up * 1e-3, *up, grip, radius + JAW_MM),
                ]
            }
            FixtureKind::VBlock { .. } => {
                let Some(face) = faces.first() else {
                    return vec![];
                };
                let Surface::Cylinder {
                    origin,
                    axis,
                    radius,
                    ..
                } = g.faces[face.0].surface
                else {
                    return vec![];
                };
                // A block under the cylinder's middle up to its V's contact lines (45°
                // each side), as wide as the cylinder and a jaw on each side.
                let c = g.faces[face.0].centroid;
                let along = c.coords - origin.coords;
                let mid = origin + axis * along.dot(&axis);
                let top = mid.coords.dot(up) - radius * std::f64::consts::FRAC_1_SQRT_2;
                let bottom = low - f.height;
                let across = up.cross(&axis).normalize();
                let rot = nalgebra::Rotation3::from_basis_unchecked(&[axis, across, *up]);
                let centre = mid - up * (mid.coords.dot(up) - (top + bottom) / 2.0);
                vec![Solid::cuboid(
                    centre,
                    rot,
                    V3::new(
                        VBLOCK_LENGTH_MM / 2.0,
                        radius + JAW_MM,
                        (top - bottom) / 2.0,
                    ),
                )]
            }
            FixtureKind::Vise { jaw, .. } => {
                let (Some(a), Some(b)) = (faces.first(), faces.get(1)) else {
                    return vec![];
                };
                let (
                    Surface::Plane {
                        origin: oa,
                        normal: n,
                    },
                    Surface::Plane { origin: ob, .. },
                ) = (&g.faces[a.0].surface, &g.faces[b.0].surface)
                else {
                    return vec![];
                };
                let grip = jaw[1].min(0.5 * height);
                // The jaws: boxes outside the two clamped faces from the table to the
                // grip height, centred under the part's middle.
                let mid = g.faces[a.0]
                    .centroid
                    .coords
                    .lerp(&g.faces[b.0].centroid.coords, 0.5);
                let along = up.cross(n).normalize();
                let rot = nalgebra::Rotation3::from_basis_unchecked(&[*n, along, *up]);
                let mut out = Vec::new();
                for (o, s) in [(oa, 1.0), (ob, -1.0)] {
                    let face_plane = o.coords.dot(n);
                    let c_n = face_plane + s * JAW_MM / 2.0;
                    let c_up = low - f.height + (f.height + grip) / 2.0;
                    let c = mid - n * mid.dot(n) - up * mid.dot(up) + n * c_n + up * c_up;
                    out.push(Solid::cuboid(
                        P3::from(c),
                        rot,
                        V3::new(JAW_MM / 2.0, jaw[0] / 2.0, (f.height + grip) / 2.0),
                    ));
                }
                out
            }
            FixtureKind::SinePlate { .. } => {
                // The plate under the face the part is clamped on.
                let Some(r) = self
                    .rests
                    .iter()
                    .find(|r| r.flat && faces.iter().all(|x| r.faces.contains(x)))
                else {
                    return vec![];
                };
                let n = -r.up;
                let plane = -self.extremes.lowest(&-n);
                let com = self.com;
                // Square to the face's longest edge, which lies along the rail.
                let e1 = r.edge;
                let e2 = n.cross(&e1);
                let rot = nalgebra::Rotation3::from_basis_unchecked(&[e1, e2, n]);
                let c = com.coords + n * (plane - com.coords.dot(&n) + JAW_MM / 2.0 + 1e-3);
                let rise = up - n * up.dot(&n);
                if rise.norm() < 1e-9 {
                    // Flat under the part: a square a little larger than the part.
                    let half = size / 2.0 + PLATE_MARGIN_MM;
                    return vec![Solid::cuboid(
                        P3::from(c),
                        rot,
                        V3::new(half, half, JAW_MM / 2.0),
                    )];
                }
                // Tilted: the plate runs up its own plane (`rise`) from the table, where
                // its hinge stands `height` under the part, to a margin past the part's
                // top; across, a margin past the part's sides.
                let rise = rise.normalize();
                // Right-handed: (across, rise, n).
                let across = rise.cross(&n);
                let span = |d: &V3| {
                    self.hull
                        .iter()
                        .map(|v| v.coords.dot(d))
                        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                            (a.min(x), b.max(x))
                        })
                };
                let (q0, q1) = span(&across);
                let (r0, r1) = span(&rise);
                let basis = nalgebra::Rotation3::from_basis_unchecked(&[across, rise, n]);
                let plate = |lo: f64, hi: f64| {
                    let mid = c - across * c.dot(&across) - rise * c.dot(&rise)
                        + across * ((q0 + q1) / 2.0)
                        + rise * ((lo + hi) / 2.0);
                    Solid::cuboid(
                        P3::from(mid),
                        basis,
                        V3::new(
                            (q1 - q0) / 2.0 + PLATE_MARGIN_MM,
                            ((hi - lo) / 2.0).max(1.0),
                            JAW_MM / 2.0,
                        ),
                    )
                };
                let (mut lo, hi) = (r0 - PLATE_MARGIN_MM, r1 + PLATE_MARGIN_MM);
                let floor = low - f.height;
                lo += (floor - plate(lo, hi).lowest(up)) / rise.dot(up);
                vec![plate(lo.min(hi - 2.0), hi)]
            }
        }
    }

    /// The candidate setups in words (`inspc plan --explain-setups`): each pose on the
    /// table with its support and tipping angle, or why it is excluded; then what each
    /// fixture of the plan can hold. `labels` are the CMM's fixture labels.
    pub fn explain(&self, labels: &[String]) -> String {
        use std::fmt::Write as _;
        let g = self.geometry;
        let dir = |v: &V3| {
            let r = |x: f64| {
                let y = (x * 1e3).round() / 1e3;
                if y == 0.0 {
                    0.0
                } else {
                    y
                }
            };
            format!("({}, {}, {})", r(v.x), r(v.y), r(v.z))
        };
        let faces = |fs: &[FaceId]| {
            fs.iter()
                .map(|f| g.faces[f.0].name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        };
        let mut out = String::new();
        let com = self.com;
        let _ = writeln!(out, "  centre of mass {}", dir(&com.coords));
        for r in &self.rests {
            match r.excluded() {
                None => {
                    let _ = writeln!(
                        out,
                        "  up {}: stands on {} (support {:.0} mm², tips at {:.1}°)",
                        dir(&r.up),
                        faces(&r.faces),
                        r.area,
                        r.tip_deg
                    );
                }
                Some(why) => {
                    let on = if r.faces.is_empty() {
                        String::new()
                    } else {
                        format!(" on {}", faces(&r.faces))
                    };
                    let _ = writeln!(out, "  up {}{on}: excluded, {why}", dir(&r.up));
                }
            }
        }
        if self.rests.iter().all(|r| !r.stable()) {
            let _ = writeln!(out, "  no pose stands on the table by itself");
        }
        for &(slot, f) in &self.fixtures {
            let label = labels.get(slot).map_or("?", String::as_str);
            let what = match f.kind {
                FixtureKind::Mesh { up, .. } => match self.mesh_of(slot) {
                    Some((m, _)) => format!(
                        "holds the part with {} up on {} (the faces its mesh touches)",
                        dir(&V3::from(up).normalize()),
                        faces(&m.locating)
                    ),
                    None => "was not placed with the part".into(),
                },
                FixtureKind::Vise { opening, .. } => {
                    let n = self.clamps.iter().filter(|c| c.3 <= opening).count();
                    format!("clamps {n} pairs of opposite faces at most {opening} mm apart, the part on a flat face square to them")
                }
                FixtureKind::Chuck { diameter, .. } => {
                    let round: Vec<&str> = g
                        .faces
                        .iter()
                        .filter(|x| match x.surface {
                            Surface::Cylinder {
                                radius,
                                convex: true,
                                ..
                            }
                            | Surface::Sphere {
                                radius,
                                convex: true,
                                ..
                            } => (diameter[0]..=diameter[1]).contains(&(2.0 * radius)),
                            _ => false,
                        })
                        .map(|x| x.name.as_str())
                        .collect();
                    if round.is_empty() {
                        format!(
                            "grips Ø{}..{} mm, but no outer cylinder or sphere of the part fits",
                            diameter[0], diameter[1]
                        )
                    } else {
                        format!(
                            "grips {} at the part's end, axis vertical",
                            round.join(", ")
                        )
                    }
                }
                FixtureKind::VBlock { diameter } => {
                    let n = g
                        .faces
                        .iter()
                        .filter(|x| matches!(x.surface, Surface::Cylinder { radius, convex: true, .. } if (diameter[0]..=diameter[1]).contains(&(2.0 * radius))))
                        .count();
                    format!("holds one of {n} outer cylinders of Ø{}..{} mm with its axis horizontal, turned in {VBLOCK_STEP_DEG}° steps", diameter[0], diameter[1])
                }
                FixtureKind::Risers { pads } => {
                    let lifted: Vec<String> = (0..self.rests.len())
                        .filter(|&k| self.pads(k).is_some())
                        .map(|k| dir(&self.rests[k].up))
                        .collect();
                    if lifted.is_empty() {
                        "lifts no pose: where the part stands, the table hides none of its faces"
                            .into()
                    } else {
                        format!(
                            "lifts the part {} mm on three Ø{pads} mm pads where the table would hide a face: up {}",
                            f.height,
                            lifted.join(", ")
                        )
                    }
                }
                FixtureKind::SinePlate { tilt, plate } => {
                    let n = self.plate_rests(plate).count();
                    let top = plate.map_or(String::new(), |p| {
                        format!(" that fit its {} × {} mm top", p[0], p[1])
                    });
                    match (n, plate) {
                        (0, Some(p)) => format!(
                            "holds the part on none of its faces: it is more than {PLATE_OVERHANG} times the plate's {} × {} mm top",
                            p[0], p[1]
                        ),
                        _ => format!(
                            "clamps the part on one of its {n} largest flat faces{top}, the face's longest edge along the plate's rail or square to it, tilted {}°..{}° in {PLATE_STEP_DEG}° steps",
                            tilt[0], tilt[1]
                        ),
                    }
                }
            };
            let _ = writeln!(out, "  fixture {label} ({}): {what}", f.kind.word());
        }
        out
    }
}

/// Points in clusters of a few dozen with bounding spheres, split along their widest
/// axis: the lowest point along a direction visits only the clusters whose sphere
/// reaches below the lowest found so far, and is the same number a scan of every point
/// gives (a hull of a tessellated sphere has thousands of vertices and a setup search
/// asks tens of thousands of directions).
#[derive(Debug, Clone)]
struct Extremes {
    /// The points, cluster by cluster.
    pts: Vec<P3>,
    /// (centre, radius plus a rounding margin, start, end) into `pts`.
    clusters: Vec<(P3, f64, usize, usize)>,
}

impl Extremes {
    /// Cluster size at most.
    const LEAF: usize = 32;

    fn new(pts: &[P3]) -> Extremes {
        let mut pts = pts.to_vec();
        let mut clusters = Vec::new();
        Self::split(&mut pts, 0, &mut clusters);
        Extremes { pts, clusters }
    }

    fn split(pts: &mut [P3], start: usize, out: &mut Vec<(P3, f64, usize, usize)>) {
        if pts.is_empty() {
            return;
        }
        let (mut lo, mut hi) = (pts[0], pts[0]);
        for p in pts.iter() {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        if pts.len() <= Self::LEAF {
            let centre = nalgebra::center(&lo, &hi);
            let r = pts.iter().map(|p| (p - centre).norm()).fold(0.0, f64::max);
            // Dot products round: the bound keeps a margin far above their error.
            let margin = 1e-9 * (1.0 + centre.coords.norm() + r);
            out.push((centre, r + margin, start, start + pts.len()));
            return;
        }
        let axis = (hi - lo).imax();
        pts.sort_by(|a, b| a[axis].total_cmp(&b[axis]));
        let mid = pts.len() / 2;
        let (a, b) = pts.split_at_mut(mid);
        Self::split(a, start, out);
        Self::split(b, start + mid, out);
    }

    /// The least `p · d` over the points (+∞ for none).
    fn lowest(&self, d: &V3) -> f64 {
        let scan = |&(_, _, a, b): &(P3, f64, usize, usize)| {
            self.pts[a..b]
                .iter()
                .map(|v| v.coords.dot(d))
                .fold(f64::INFINITY, f64::min)
        };
        // The cluster whose centre is lowest first, then those that can go lower.
        let Some(first) = self
            .clusters
            .iter()
            .min_by(|x, y| x.0.coords.dot(d).total_cmp(&y.0.coords.dot(d)))
        else {
            return f64::INFINITY;
        };
        let mut best = scan(first);
        for c in &self.clusters {
            if c.0.coords.dot(d) - c.1 * d.norm() < best {
                best = best.min(scan(c));
            }
        }
        best
    }
}

/// Pairs of planar faces with opposite normals that bound the part along their normal
/// (nothing sticks out past either), for a vise's jaws: (normal of the first, first,
/// second, distance between them). Largest faces first.
fn clamp_pairs(g: &PartGeometry, hull: &[P3]) -> Vec<(V3, FaceId, FaceId, f64)> {
    let (lo, hi) = g.bounds();
    let tol = 1e-4 * (hi - lo).norm().max(1.0);
    let extent = |n: &V3| {
        hull.iter()
            .map(|v| v.coords.dot(n))
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let mut planes: Vec<(usize, V3, f64)> = g
        .faces
        .iter()
        .enumerate()
        .filter_map(|(k, f)| match f.surface {
            Surface::Plane { origin, normal } if f.area > 0.0 => {
                let d = origin.coords.dot(&normal);
                (d >= extent(&normal) - tol).then_some((k, normal, d))
            }
            _ => None,
        })
        .collect();
    planes.sort_by(|a, b| {
        g.faces[b.0]
            .area
            .total_cmp(&g.faces[a.0].area)
            .then(a.0.cmp(&b.0))
    });
    let mut out = Vec::new();
    for (i, &(a, na, da)) in planes.iter().enumerate() {
        for &(b, nb, db) in &planes[i + 1..] {
            if na.dot(&nb) < -(1.0 - 1e-6) {
                out.push((na, FaceId(a), FaceId(b), da + db));
            }
        }
    }
    out
}

/// The centre of mass of the solid (uniform density), from the signed volumes of the
/// tetrahedra from the origin to each triangle; the area centroid for a mesh without
/// volume.
pub(crate) fn centre_of_mass(g: &PartGeometry) -> P3 {
    let (mut vol, mut m) = (0.0, V3::zeros());
    let (mut area, mut a) = (0.0, V3::zeros());
    for t in &g.triangles {
        let [p, q, r] = t.map(|i| g.vertices[i as usize].coords);
        let v = p.dot(&q.cross(&r)) / 6.0;
        vol += v;
        m += (p + q + r) / 4.0 * v;
        let s = (q - p).cross(&(r - p)).norm() / 2.0;
        area += s;
        a += (p + q + r) / 3.0 * s;
    }
    if vol.abs() > 1e-9 {
        P3::from(m / vol)
    } else if area > 0.0 {
        P3::from(a / area)
    } else {
        P3::origin()
    }
}

/// The poses in which the part can rest on the table, stable or not, largest support
/// first: every facet of the convex hull that holds a planar face of the part (a flat
/// contact a fixture can clamp against), and every facet that may be stable. A facet
/// whose hull polygon alone tips under [`MIN_TIP_DEG`] cannot be stable (no real contact
/// inside it does better), so its support polygon is not computed. `hv` and `hi_tris`
/// are the part's convex hull.
fn rest_poses(g: &PartGeometry, hv: &[P3], hi_tris: &[[u32; 3]]) -> Vec<RestPose> {
    if g.vertices.len() < 4 {
        return vec![];
    }
    let com = centre_of_mass(g);
    let (lo, hi) = g.bounds();
    let size = (hi - lo).norm().max(1.0);
    let tol = 1e-5 * size + 1e-4;
    // Hull facets grouped by plane, largest first.
    struct Plane {
        n: V3,
        d: f64,
        area: f64,
        verts: Vec<P3>,
    }
    let mut tris: Vec<(f64, usize)> = hi_tris
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let [a, b, c] = t.map(|k| hv[k as usize]);
            ((b - a).cross(&(c - a)).norm() / 2.0, i)
        })
        .collect();
    tris.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
    let cos_same = SAME_PLANE_DEG.to_radians().cos();
    let mut planes: Vec<Plane> = Vec::new();
    for (area, i) in tris {
        let [a, b, c] = hi_tris[i].map(|k| hv[k as usize]);
        let Some(mut n) = (b - a).cross(&(c - a)).try_normalize(1e-12) else {
            continue;
        };
        if n.dot(&(a - com)) < 0.0 {
            n = -n;
        }
        let d = n.dot(&a.coords);
        match planes
            .iter_mut()
            .find(|p| p.n.dot(&n) > cos_same && (p.d - d).abs() < 10.0 * tol)
        {
            Some(p) => {
                p.area += area;
                p.verts.extend([a, b, c]);
            }
            None => planes.push(Plane {
                n,
                d,
                area,
                verts: vec![a, b, c],
            }),
        }
    }
    // Per vertex: whether a curved face meets it (then it is no sharp corner).
    let mut curved = vec![false; g.vertices.len()];
    for (t, tri) in g.triangles.iter().enumerate() {
        let face = &g.faces[g.tri_face[t] as usize];
        if !matches!(face.surface, Surface::Plane { .. }) {
            for &v in tri {
                curved[v as usize] = true;
            }
        }
    }
    let edges = face_edges(g);
    let mut out = Vec::new();
    for p in &planes {
        let (e1, e2) = perpendicular_basis(&p.n);
        let flat2 = |x: &P3| (x.coords.dot(&e1), x.coords.dot(&e2));
        let h = p.d - p.n.dot(&com.coords);
        let c = flat2(&com);
        let hull_poly = convex_hull(p.verts.iter().map(flat2).collect());
        let hull_tip = tip(&hull_poly, c, h);
        // Planar faces of the part in the facet's plane.
        let mut faces: Vec<FaceId> = g
            .faces
            .iter()
            .enumerate()
            .filter(|(_, f)| match f.surface {
                Surface::Plane { origin, normal } => {
                    f.area > 0.0
                        && normal.dot(&p.n) > cos_same
                        && (origin.coords.dot(&p.n) - p.d).abs() <= 10.0 * tol
                }
                _ => false,
            })
            .map(|(k, _)| FaceId(k))
            .collect();
        if hull_tip < MIN_TIP_DEG {
            if !faces.is_empty() {
                let area = faces.iter().map(|f| g.faces[f.0].area).sum();
                out.push(RestPose {
                    up: -p.n,
                    faces,
                    area,
                    tip_deg: hull_tip,
                    flat: true,
                    edge: longest_edge(&hull_poly, &e1, &e2),
                });
            }
            continue;
        }
        faces.clear();
        // The real contact: flat triangles in the plane, and sharp corners.
        let in_plane = |v: &P3| (p.n.dot(&v.coords) - p.d).abs() <= 10.0 * tol;
        let mut contact: Vec<(f64, f64)> = Vec::new();
        let mut faces: Vec<FaceId> = Vec::new();
        for (t, tri) in g.triangles.iter().enumerate() {
            let vs = tri.map(|i| g.vertices[i as usize]);
            if !vs.iter().all(in_plane) {
                continue;
            }
            let face = g.tri_face[t] as usize;
            if let Surface::Plane { normal, .. } = g.faces[face].surface {
                if normal.dot(&p.n) > cos_same {
                    contact.extend(vs.iter().map(flat2));
                    if !faces.contains(&FaceId(face)) {
                        faces.push(FaceId(face));
                    }
                }
            }
        }
        for (v, x) in g.vertices.iter().enumerate() {
            if !curved[v] && in_plane(x) {
                contact.push(flat2(x));
            }
        }
        for edge in &edges {
            if edge.iter().all(|&v| in_plane(&g.vertices[v])) {
                contact.extend(edge.iter().map(|&v| flat2(&g.vertices[v])));
            }
        }
        faces.sort();
        let poly = convex_hull(contact);
        let flat = poly.len() >= 3 && polygon_area(&poly) > tol * size;
        out.push(RestPose {
            up: -p.n,
            faces,
            area: if flat { polygon_area(&poly) } else { 0.0 },
            tip_deg: if flat { tip(&poly, c, h) } else { 0.0 },
            flat,
            edge: longest_edge(if flat { &poly } else { &hull_poly }, &e1, &e2),
        });
    }
    out.sort_by(|a, b| {
        b.area
            .total_cmp(&a.area)
            .then(a.up.z.total_cmp(&b.up.z))
            .then(a.up.y.total_cmp(&b.up.y))
            .then(a.up.x.total_cmp(&b.up.x))
    });
    out
}

/// The part's extents (its convex `hull`'s) along rest `r`'s longest support edge and
/// across it.
fn spans(hull: &[P3], r: &RestPose) -> [f64; 2] {
    let across = r.up.cross(&r.edge).normalize();
    [r.edge, across].map(|d| {
        let (lo, hi) = hull
            .iter()
            .map(|v| v.coords.dot(&d))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            });
        hi - lo
    })
}

/// Whether a part of extents `span` fits a plate whose top is `plate` (width, length),
/// either way round: each at most [`PLATE_OVERHANG`] times the plate's.
fn fits_plate(span: &[f64; 2], plate: [f64; 2]) -> bool {
    let k = PLATE_OVERHANG;
    let [a, b] = *span;
    (a <= k * plate[0] && b <= k * plate[1]) || (a <= k * plate[1] && b <= k * plate[0])
}

/// The pads under rest pose `r` where the part stands on risers of pad diameter `pad`
/// in it: a stable pose in which the table hides a face and the pads hold the part.
fn riser_pads(g: &PartGeometry, r: &RestPose, low: f64, com: &P3, pad: f64) -> Option<[P3; 3]> {
    if !r.stable() || !super::risers::needs_lift(g, &r.up, low, &r.faces) {
        return None;
    }
    super::risers::pads(g, &r.up, low, &r.faces, com, pad, MIN_TIP_DEG)
}

/// The edges where two faces meet, each the vertices of one connected chain of mesh
/// edges between the same two faces (a circle where a chamfer meets a side, the line
/// where two planes meet). An edge lying wholly in a resting plane is a contact even
/// between curved faces — a disc on the rim where its side meets a conical recess stands
/// on that ring — while the end circle of a cylinder lying on its side touches the
/// plane of a tessellation facet at two vertices only, its arc between them dipping
/// below: no contact, and the cylinder rolls.
fn face_edges(g: &PartGeometry) -> Vec<Vec<usize>> {
    use std::collections::BTreeMap;
    // Per mesh edge, the faces of its triangles.
    let mut sides: BTreeMap<(u32, u32), Vec<u32>> = BTreeMap::new();
    for (t, tri) in g.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            sides
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push(g.tri_face[t]);
        }
    }
    // Mesh edges between two different faces, grouped by the pair, then by connection.
    let mut by_pair: BTreeMap<(u32, u32), Vec<(u32, u32)>> = BTreeMap::new();
    for (e, f) in sides {
        if let [f1, f2] = f[..] {
            if f1 != f2 {
                by_pair.entry((f1.min(f2), f1.max(f2))).or_default().push(e);
            }
        }
    }
    let mut out = Vec::new();
    for segs in by_pair.values() {
        out.extend(chains(segs));
    }
    out
}

/// The vertex sets of the connected chains of `segs` (union–find over their vertices).
fn chains(segs: &[(u32, u32)]) -> Vec<Vec<usize>> {
    use std::collections::BTreeMap;
    let mut parent: BTreeMap<u32, u32> = BTreeMap::new();
    fn root(parent: &mut BTreeMap<u32, u32>, v: u32) -> u32 {
        let mut r = v;
        while let Some(&p) = parent.get(&r).filter(|&&p| p != r) {
            r = p;
        }
        parent.insert(v, r);
        r
    }
    for &(a, b) in segs {
        parent.entry(a).or_insert(a);
        parent.entry(b).or_insert(b);
        let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
        if ra != rb {
            parent.insert(ra.max(rb), ra.min(rb));
        }
    }
    let vertices: Vec<u32> = parent.keys().copied().collect();
    let mut groups: BTreeMap<u32, Vec<usize>> = BTreeMap::new();
    for v in vertices {
        let r = root(&mut parent, v);
        groups.entry(r).or_default().push(v as usize);
    }
    groups.into_values().collect()
}

/// A sine plate's tilts (degrees): its limits and the multiples of [`PLATE_STEP_DEG`]
/// between them.
fn plate_tilts(tilt: [f64; 2]) -> Vec<f64> {
    let mut out = vec![tilt[0]];
    let mut k = (tilt[0] / PLATE_STEP_DEG).floor() + 1.0;
    while k * PLATE_STEP_DEG < tilt[1] - 1e-9 {
        out.push(k * PLATE_STEP_DEG);
        k += 1.0;
    }
    if tilt[1] > tilt[0] + 1e-9 {
        out.push(tilt[1]);
    }
    out
}

/// The direction of a polygon's longest edge (in the plane of `e1`, `e2`); `e1` when it
/// has none. The first of equal edges, so the choice is the same on every machine.
fn longest_edge(poly: &[(f64, f64)], e1: &V3, e2: &V3) -> V3 {
    let mut best = (0.0, *e1);
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let len = (dx * dx + dy * dy).sqrt();
        if len > best.0 * (1.0 + 1e-9) {
            best = (len, (e1 * dx + e2 * dy) / len);
        }
    }
    best.1
}

/// The part directions along a tilted plate's hinge and up its slope: from the clamped
/// face's outward `normal` and the part's `up` direction (both in part axes); `None`
/// where the plate lies flat.
pub(crate) fn plate_lie(normal: &V3, up: &V3) -> Option<(V3, V3)> {
    let plate = -normal;
    let slope = up - plate * plate.dot(up);
    if slope.norm() < 1e-6 {
        return None;
    }
    let rising = slope.normalize();
    Some((plate.cross(&rising).normalize(), rising))
}

/// How a part lies on a tilted plate, in the drawing's axes: the direction along the
/// `hinge` (either sense: an axis by its name) and the side that `rising` lifts.
pub(crate) fn plate_words(hinge: &V3, rising: &V3) -> String {
    let along = match axis_name(hinge) {
        Some(a) => format!("its {} axis", &a[1..]),
        None => format!("its {} direction", rounded(&(hinge * first_sign(hinge)))),
    };
    let side = axis_name(rising)
        .map(str::to_string)
        .unwrap_or_else(|| rounded(rising));
    format!("{along} along the hinge, its {side} side rising")
}

/// An axis direction's name ("+x"), if `v` is one (`render` names plan directions the
/// same way; `render` imports this module, so not from there).
fn axis_name(v: &V3) -> Option<&'static str> {
    let names = [["+x", "+y", "+z"], ["-x", "-y", "-z"]];
    (0..3)
        .find(|&k| v[k].abs() > 1.0 - 1e-6)
        .map(|k| names[usize::from(v[k] < 0.0)][k])
}

/// The sign that makes a direction's first non-zero component positive.
fn first_sign(v: &V3) -> f64 {
    let c = v.iter().find(|c| c.abs() > 1e-6).copied().unwrap_or(1.0);
    c.signum()
}

/// A direction to three decimals, "(0.707, -0.707, 0)".
fn rounded(v: &V3) -> String {
    let n = |x: f64| crate::model::fmt_num((x * 1e3).round() / 1e3 + 0.0);
    format!("({}, {}, {})", n(v.x), n(v.y), n(v.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clustered_extremes_are_a_scan_of_every_point() {
        // Points on a sphere, as a tessellated sphere's hull has them, and a few inside.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut rand = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let pts: Vec<P3> = (0..3000)
            .map(|k| {
                let v = V3::new(rand(), rand(), rand()).normalize();
                let r = if k % 10 == 0 { 20.0 } else { 25.0 };
                P3::from(v * r + V3::new(3.0, -7.0, 40.0))
            })
            .collect();
        let e = Extremes::new(&pts);
        for _ in 0..500 {
            let d = V3::new(rand(), rand(), rand()).normalize();
            let scan = pts
                .iter()
                .map(|v| v.coords.dot(&d))
                .fold(f64::INFINITY, f64::min);
            assert_eq!(e.lowest(&d).to_bits(), scan.to_bits(), "{d:?}");
        }
        assert_eq!(Extremes::new(&[]).lowest(&V3::z()), f64::INFINITY);
    }

    #[test]
    fn a_tilted_plate_names_the_part_axis_along_its_hinge() {
        // The top face (+z) clamped on a plate tilted 55° with the part's +x end up:
        // the part's up is -z turned 55° towards +x.
        let a = 55f64.to_radians();
        let up = V3::new(a.sin(), 0.0, -a.cos());
        let (hinge, rising) = plate_lie(&V3::z(), &up).unwrap();
        assert!((hinge.y.abs() - 1.0).abs() < 1e-9, "{hinge:?}");
        assert!((rising - V3::x()).norm() < 1e-9, "{rising:?}");
        assert_eq!(
            plate_words(&hinge, &rising),
            "its y axis along the hinge, its +x side rising"
        );
        // At 45° to the part's axes, and a flat plate.
        let d = V3::new(-1.0, 1.0, 0.0).normalize();
        assert_eq!(
            plate_words(&d, &V3::new(-1.0, -1.0, 0.0).normalize()),
            "its (0.707, -0.707, 0) direction along the hinge, its (-0.707, -0.707, 0) side rising"
        );
        assert!(plate_lie(&V3::z(), &-V3::z()).is_none());
    }

    #[test]
    fn tipping_angle_of_a_square() {
        let sq = [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)];
        assert!((tip(&sq, (1.0, 1.0), 1.0) - 45.0).abs() < 1e-9);
        assert!(tip(&sq, (3.0, 1.0), 1.0) < 0.0);
    }

    /// A disc of radius `r` and height `h` whose underside is a conical recess from the
    /// rim up to `apex` at the centre (`apex` 0: a flat underside, as a plane), and
    /// whose side is `n` facets: faces top (plane), side (cylinder), underside.
    fn recessed_disc(r: f64, h: f64, apex: f64, n: usize) -> PartGeometry {
        use crate::geometry::Face;
        let ring = |z: f64| -> Vec<P3> {
            (0..n)
                .map(|k| {
                    let a = k as f64 / n as f64 * std::f64::consts::TAU;
                    P3::new(r * a.cos(), r * a.sin(), z)
                })
                .collect()
        };
        let mut vertices = ring(h);
        vertices.extend(ring(0.0));
        vertices.push(P3::new(0.0, 0.0, h));
        vertices.push(P3::new(0.0, 0.0, apex));
        let (top_c, bot_c) = (2 * n as u32, 2 * n as u32 + 1);
        let mut triangles = Vec::new();
        let mut tri_face = Vec::new();
        for k in 0..n as u32 {
            let j = (k + 1) % n as u32;
            let (t0, t1, b0, b1) = (k, j, n as u32 + k, n as u32 + j);
            triangles.push([top_c, t0, t1]);
            tri_face.push(0);
            triangles.extend([[b0, b1, t1], [b0, t1, t0]]);
            tri_face.extend([1, 1]);
            triangles.push([bot_c, b1, b0]);
            tri_face.push(2);
        }
        let under = if apex > 0.0 {
            Surface::Cone {
                apex: P3::new(0.0, 0.0, apex),
                axis: -V3::z(),
                half_angle: (r / apex).atan(),
                convex: false,
            }
        } else {
            Surface::Plane {
                origin: P3::origin(),
                normal: -V3::z(),
            }
        };
        let surfaces = [
            Surface::Plane {
                origin: P3::new(0.0, 0.0, h),
                normal: V3::z(),
            },
            Surface::Cylinder {
                origin: P3::origin(),
                axis: V3::z(),
                radius: r,
                convex: true,
            },
            under,
        ];
        let faces = surfaces
            .into_iter()
            .enumerate()
            .map(|(f, surface)| Face {
                name: format!("face_{f}"),
                surface,
                triangles: (0..triangles.len() as u32)
                    .filter(|&t| tri_face[t as usize] == f as u32)
                    .collect(),
                area: 1.0,
                centroid: P3::origin(),
                fit_rms: 0.0,
            })
            .collect();
        PartGeometry {
            vertices,
            triangles,
            tri_face,
            faces,
            roles: vec![],
            cad: None,
        }
    }

    fn poses(g: &PartGeometry) -> Vec<RestPose> {
        let (v, tris) = parry3d_f64::transformation::try_convex_hull(&g.vertices).unwrap();
        rest_poses(g, &v, &tris)
    }

    /// The pose with `up` (within a degree).
    fn pose(rests: &[RestPose], up: V3) -> &RestPose {
        let found = rests.iter().find(|r| r.up.dot(&up) > 0.9998);
        found.unwrap_or_else(|| panic!("no pose with up {up:?}: {rests:?}"))
    }

    #[test]
    fn a_disc_stands_on_the_ring_of_its_recess_and_not_on_its_side() {
        // Ø35.2 × 6 with a conical recess 3 deep: upside up it rests on the ring where
        // its side meets the recess, whatever the faces there are.
        let g = recessed_disc(17.6, 6.0, 3.0, 48);
        let rests = poses(&g);
        let ring = pose(&rests, V3::z());
        assert!(ring.stable(), "{:?}", ring.excluded());
        assert!(
            ring.area > 0.95 * std::f64::consts::PI * 17.6 * 17.6,
            "{}",
            ring.area
        );
        // Turned over it lies on its flat top, as before; on its rim it cannot stand.
        assert!(pose(&rests, -V3::z()).stable());
        assert!(rests.iter().all(|r| r.up.z.abs() > 0.1 || !r.stable()));
    }

    #[test]
    fn a_coarse_cylinder_on_its_side_rolls() {
        // 12 facets: a facet's corners on the end circles would make a 0.52 r wide
        // support that tips at 15°, but the end circles' arcs dip below it.
        let g = recessed_disc(20.0, 60.0, 0.0, 12);
        let rests = poses(&g);
        for r in rests.iter().filter(|r| r.up.z.abs() < 0.1) {
            assert!(!r.stable(), "{r:?}");
        }
        assert!(pose(&rests, V3::z()).stable());
    }
}
