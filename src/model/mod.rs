//! The model: a resolved, typed, unit-normalised spec.
//!
//! Stage output of `resolve`, input of every later stage. Names are bound (references
//! are indices into the model's vectors), quantities are converted to one internal unit
//! — **millimetres for lengths, degrees for angles** (degrees keep head grids such as
//! 7.5° exact in binary) — and directions are unit vectors in the part frame.
//!
//! **Architecture Invariant:** the model holds no spans except for diagnostics later
//! stages may raise (planning failures point at the face or level at fault), and no
//! `HashMap`: iteration order is declaration order everywhere.
//!
//! **Decision: motion defaults** (`motion { … }` in a plan, [`Motion`]): prehit and
//! retract 2 mm, search 4 mm, clearance 20 mm, margin 1 mm. A TP20's pre-travel is well
//! under a millimetre, and 2 mm keeps touches short. The clearance plane holds the head
//! at `top + clearance + longest reach` in every group of a setup, so any probe in any
//! orientation swings clear when the sensor changes there.

mod part;
mod summary;

pub use summary::{fmt_num, ItemRef};

pub use part::*;

use crate::source::Span;

/// A 3-vector in the part frame (mm for points, unit length for directions).
pub type Vec3 = [f64; 3];

macro_rules! ids {
    ($($(#[$m:meta])* $name:ident),* $(,)?) => {$(
        $(#[$m])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub struct $name(pub usize);
    )*};
}

/// The largest length inspc accepts (mm), in a spec or as a mesh coordinate: no CMM
/// measures beyond 10 m. Every length past the front end (geometry, sampling, paths,
/// DMIS numbers) is bounded by it, so no stage meets a size it cannot handle.
pub const MAX_LENGTH_MM: f64 = 10_000.0;

ids! {
    /// Index into [`Model::parts`].
    PartId,
    /// Index into [`Model::cmms`].
    CmmId,
    /// Index into [`Model::heads`].
    HeadId,
    /// Index into [`Model::probes`].
    ProbeId,
    /// Index into [`Model::styli`].
    StylusId,
    /// Index into [`Model::bodies`].
    BodyId,
    /// Index into [`Model::extensions`].
    ExtensionId,
    /// Index into [`Model::hierarchies`].
    HierarchyId,
    /// Index into [`Model::samplings`].
    SamplingId,
    /// Index into [`Model::plans`].
    PlanId,
    /// Index into [`Model::fixtures`].
    FixtureId,
    /// Index into [`Model::scanners`].
    ScannerId,
    /// Index into a machine's rack, [`Cmm::probes`]: a probe as mounted, with its label.
    SlotId,
}

/// Everything a run declared or imported, in declaration order.
#[derive(Debug, Clone, Default)]
pub struct Model {
    /// Parts.
    pub parts: Vec<Part>,
    /// Machines.
    pub cmms: Vec<Cmm>,
    /// Probe heads.
    pub heads: Vec<Head>,
    /// Probe assemblies.
    pub probes: Vec<Probe>,
    /// Styli.
    pub styli: Vec<Stylus>,
    /// Probe bodies.
    pub bodies: Vec<Body>,
    /// Stylus extensions.
    pub extensions: Vec<Extension>,
    /// Constraint hierarchies.
    pub hierarchies: Vec<Hierarchy>,
    /// Sampling strategy sets.
    pub samplings: Vec<Sampling>,
    /// Fixtures.
    pub fixtures: Vec<Fixture>,
    /// Laser line scanners.
    pub scanners: Vec<Scanner>,
    /// Plans declared in the root files (imported files' plans are not run).
    pub plans: Vec<Plan>,
    /// `std::sampling::spread`, the sampling of a plan that names none and of a part
    /// sampled without a plan.
    pub default_sampling: Option<SamplingId>,
    /// What the resolver learnt about the source text, for the editor (`inspc lsp`).
    pub index: SourceIndex,
}

/// The resolver's knowledge of the source text: which declaration each name binds to and
/// which keys each block accepts.
#[derive(Debug, Clone, Default)]
pub struct SourceIndex {
    /// Every use of a name the resolver bound, with the declaration it names: the
    /// editor's go-to-definition and references. Sorted, no duplicates.
    pub names: Vec<NameUse>,
    /// Every block of properties the resolver read, with the keys it accepts: the
    /// editor's completion of properties.
    pub keys: Vec<KeySet>,
}

/// The keys a block of properties accepts.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KeySet {
    /// What the block's diagnostics point at: the item's name, a nested block's value,
    /// a mesh statement's path or a preference statement.
    pub owner: Span,
    /// The keys, in the order the resolver asks for them.
    pub keys: Vec<&'static str>,
}

/// A name as used (`used`) and the name it binds to where it is declared (`decl`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct NameUse {
    /// The name (or path) where it is used.
    pub used: Span,
    /// The declared name.
    pub decl: Span,
}

/// A coordinate measuring machine.
#[derive(Debug, Clone)]
pub struct Cmm {
    /// Its name.
    pub name: String,
    /// The table's top, in machine z (mm).
    pub table_z: f64,
    /// The table's extent in x and y (mm), if given.
    pub table_size: Option<[f64; 2]>,
    /// The ram's radius (mm).
    pub ram_radius: f64,
    /// The ram's length below the bridge (mm).
    pub ram_length: f64,
    /// The head mounted on the ram.
    pub head: HeadId,
    /// The probes in its rack, by label.
    pub probes: Vec<(String, ProbeId)>,
    /// The fixtures beside it, by label.
    pub fixtures: Vec<(String, FixtureId)>,
    /// The laser line scanners in its rack beside the probes, by label; they mount on
    /// the same head.
    pub scanners: Vec<(String, ScannerId)>,
    /// Where each probe's label is written (a plan's `prefer probe p1` binds to it).
    pub probe_labels: Vec<Span>,
    /// Where each fixture's label is written.
    pub fixture_labels: Vec<Span>,
    /// Where each scanner's label is written.
    pub scanner_labels: Vec<Span>,
    /// Where it was declared.
    pub span: Span,
}

/// A laser line scanner (Álvarez et al., Zhao et al.): a laser plane and a camera at the
/// triangulation angle to it, seeing a stripe `stripe_width` wide across the middle of a
/// depth of field `depth_of_field` deep, `standoff` in front of its window.
#[derive(Debug, Clone)]
pub struct Scanner {
    /// Its name.
    pub name: String,
    /// The stripe's length at the stand-off, across the scan direction (mm).
    pub stripe_width: f64,
    /// From the scanner's window to the middle of the depth of field (mm).
    pub standoff: f64,
    /// How deep the measuring range is along the laser, centred on the stand-off (mm).
    pub depth_of_field: f64,
    /// The angle between the laser plane's axis and the camera's line of sight (degrees).
    pub triangulation: f64,
    /// The largest angle between the laser and a surface's normal it still measures
    /// (degrees): Zhao et al.'s view angle limit θs.
    pub max_incidence: f64,
    /// Point spacing along the stripe and between stripes (mm).
    pub spacing: [f64; 2],
    /// Its accuracy (mm), compared with a tolerance to choose the sensor.
    pub accuracy: f64,
    /// The housing, as a cylinder along the laser: diameter and length (mm).
    pub body: [f64; 2],
    /// Relative cost of a change to it (1 = an ordinary probe change).
    pub cost: f64,
    /// Where it was declared.
    pub span: Span,
}

/// A fixture that holds a part where it would not stand on the table by itself.
#[derive(Debug, Clone)]
pub struct Fixture {
    /// Its name.
    pub name: String,
    /// What it is and its sizes.
    pub kind: FixtureKind,
    /// How high it holds the part's lowest point above the table (mm); 0 for a mesh
    /// fixture, whose mesh says where the part sits.
    pub height: f64,
    /// Where it was declared.
    pub span: Span,
}

/// The kinds of fixture, with their sizes (mm, degrees).
#[derive(Debug, Clone, PartialEq)]
pub enum FixtureKind {
    /// A machine vise: two jaws clamp two opposite parallel faces at most `opening`
    /// apart, the part on parallels on a face square to them.
    Vise {
        /// The widest opening.
        opening: f64,
        /// Jaw width (along the clamped faces) and height.
        jaw: [f64; 2],
    },
    /// A three-jaw chuck: holds a round part (an outer cylinder, or a sphere) with its
    /// axis vertical.
    Chuck {
        /// The diameters it grips.
        diameter: [f64; 2],
        /// How far up the part its jaws reach.
        jaws: f64,
        /// The chuck body's diameter.
        body: f64,
    },
    /// A V-block: holds an outer cylinder with its axis horizontal, turned about the
    /// axis as the plan needs.
    VBlock {
        /// The diameters it holds.
        diameter: [f64; 2],
    },
    /// Three risers (a three-point support): the part stands in one of its stable
    /// poses on three pads `height` above the table, so faces and holes at its bottom
    /// are free of the table.
    Risers {
        /// The pads' diameter.
        pads: f64,
    },
    /// A sine plate (an angle plate at 90°): the part clamped on one of its flat faces to
    /// a plate tilted by an angle within `tilt` about a horizontal axis.
    SinePlate {
        /// The tilt range (degrees).
        tilt: [f64; 2],
        /// The plate's top (width, length), where the spec gives it: a part wider or longer
        /// than half as much again does not go on it.
        plate: Option<[f64; 2]>,
    },
    /// A fixture made for one part, from its mesh in the part's frame (a nest, a wedge,
    /// a cradle): it stands on the table with `up` pointing up and holds the part on
    /// the faces it touches (its locating faces).
    Mesh {
        /// The mesh file (STL or OBJ).
        path: std::path::PathBuf,
        /// Millimetres per mesh unit.
        unit_mm: f64,
        /// The part direction that points up when the fixture stands on the table.
        up: Vec3,
        /// The file name in the spec.
        span: Span,
    },
}

impl FixtureKind {
    /// The keyword.
    pub fn word(&self) -> &'static str {
        match self {
            FixtureKind::Vise { .. } => "vise",
            FixtureKind::Chuck { .. } => "chuck",
            FixtureKind::VBlock { .. } => "vblock",
            FixtureKind::Risers { .. } => "risers",
            FixtureKind::SinePlate { .. } => "sine_plate",
            FixtureKind::Mesh { .. } => "mesh",
        }
    }
}

/// How a head orients its probe.
#[derive(Debug, Clone, PartialEq)]
pub enum HeadKind {
    /// The probe is aligned with the ram (a straight probe in Spitz's terms).
    Fixed,
    /// The probe indexes to A/B angles on a grid (a bent probe).
    Indexable {
        /// A (tilt) range in degrees, inclusive.
        a: [f64; 2],
        /// B (rotation) range in degrees, inclusive.
        b: [f64; 2],
        /// The indexing step in degrees; it divides both ranges.
        step: f64,
    },
}

/// A probe head.
#[derive(Debug, Clone)]
pub struct Head {
    /// Its name.
    pub name: String,
    /// Fixed or indexable.
    pub kind: HeadKind,
    /// Envelope length from the ram face to the probe mount (mm).
    pub length: f64,
    /// Envelope diameter (mm).
    pub diameter: f64,
    /// Where it was declared.
    pub span: Span,
}

impl Head {
    /// The A/B orientations of an indexable head (B = 180° folded onto −180°); empty for
    /// a fixed head.
    pub fn orientations(&self) -> Vec<(f64, f64)> {
        let HeadKind::Indexable { a, b, step } = &self.kind else {
            return vec![];
        };
        let steps = |r: &[f64; 2]| ((r[1] - r[0]) / step).round() as usize;
        let full_turn = (b[1] - b[0] - 360.0).abs() < 1e-9;
        let nb = steps(b) + usize::from(!full_turn);
        (0..=steps(a))
            .flat_map(|i| (0..nb).map(move |j| (a[0] + i as f64 * step, b[0] + j as f64 * step)))
            .collect()
    }
}

/// A stylus: ball tip on a stem.
#[derive(Debug, Clone)]
pub struct Stylus {
    /// Its name.
    pub name: String,
    /// Ball diameter (mm).
    pub tip: f64,
    /// Length from the mounting face to the ball centre (mm).
    pub length: f64,
    /// Stem diameter (mm).
    pub stem: f64,
    /// Where it was declared.
    pub span: Span,
}

/// A probe body (sensor), modelled as a cylinder.
#[derive(Debug, Clone)]
pub struct Body {
    /// Its name.
    pub name: String,
    /// Diameter (mm).
    pub diameter: f64,
    /// Length (mm).
    pub length: f64,
    /// Where it was declared.
    pub span: Span,
}

/// A stylus extension, modelled as a cylinder.
#[derive(Debug, Clone)]
pub struct Extension {
    /// Its name.
    pub name: String,
    /// Diameter (mm).
    pub diameter: f64,
    /// Length (mm).
    pub length: f64,
    /// Where it was declared.
    pub span: Span,
}

/// A probe assembly: body, extensions, stylus.
#[derive(Debug, Clone)]
pub struct Probe {
    /// Its name.
    pub name: String,
    /// The body.
    pub body: BodyId,
    /// Extensions from the body outwards.
    pub extensions: Vec<ExtensionId>,
    /// The stylus.
    pub stylus: StylusId,
    /// Relative cost (1 = ordinary).
    pub cost: f64,
    /// Where it was declared.
    pub span: Span,
}

/// The variable a `same` constraint ties.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum SameVar {
    /// `same_setup`
    Setup,
    /// `same_probe`
    Probe,
    /// `same_orient`
    Orient,
}

/// The measurement group a `same` constraint applies to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Group {
    /// `(T, F, *)`: the measurements of one feature under one tolerance.
    TolFeature,
    /// `(T, *)`: the measurements of one tolerance.
    Tol,
    /// `(*, *)`: all measurements.
    All,
}

/// A soft level of a constraint hierarchy.
#[derive(Debug, Clone)]
pub struct Level {
    /// Which variable.
    pub var: SameVar,
    /// Over which group.
    pub group: Group,
    /// Where it was written.
    pub span: Span,
}

impl Level {
    /// The level as the spec writes it: `same_setup(T, *)`.
    pub fn text(&self) -> String {
        level_text(self.var, self.group)
    }
}

/// The spelling of a level, for messages and reports.
pub fn level_text(var: SameVar, group: Group) -> String {
    let v = match var {
        SameVar::Setup => "same_setup",
        SameVar::Probe => "same_probe",
        SameVar::Orient => "same_orient",
    };
    let g = match group {
        Group::TolFeature => "T, F, *",
        Group::Tol => "T, *",
        Group::All => "*, *",
    };
    format!("{v}({g})")
}

/// A constraint hierarchy: required approachability, then soft levels, most important
/// first.
#[derive(Debug, Clone)]
pub struct Hierarchy {
    /// Its name.
    pub name: String,
    /// The soft levels in order.
    pub levels: Vec<Level>,
    /// Where it was declared.
    pub span: Span,
}

/// A surface type, for sampling.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum SurfaceKind {
    /// Planar face.
    Plane,
    /// Cylindrical face.
    Cylinder,
    /// Conical face.
    Cone,
    /// Spherical face.
    Sphere,
    /// Anything else.
    Freeform,
}

impl SurfaceKind {
    /// All kinds in order.
    pub const ALL: [SurfaceKind; 5] = [
        Self::Plane,
        Self::Cylinder,
        Self::Cone,
        Self::Sphere,
        Self::Freeform,
    ];

    /// The keyword.
    pub fn keyword(self) -> &'static str {
        match self {
            Self::Plane => "plane",
            Self::Cylinder => "cylinder",
            Self::Cone => "cone",
            Self::Sphere => "sphere",
            Self::Freeform => "freeform",
        }
    }
}

/// How points are placed on a face.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleMethod {
    /// Fan & Leu's rules: 4 points on a plane, 8 on a cylinder or cone.
    FanLeu,
    /// Spread to the face's usable edges: a grid on a plane, circles at both ends and
    /// between on a cylinder or cone (`std::sampling::spread`, the default).
    Spread,
    /// A uniform grid.
    Uniform,
    /// A Hammersley sequence.
    Hammersley,
}

/// How far sample points stay from a face's boundary.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Inset {
    /// A distance (mm).
    Length(f64),
    /// A fraction of the face's extent (0..0.5).
    Fraction(f64),
}

/// A sampling strategy for one surface type or feature.
#[derive(Debug, Clone, PartialEq)]
pub struct Strategy {
    /// The method.
    pub method: SampleMethod,
    /// Number of points (the method's own rule when `None`).
    pub points: Option<u32>,
    /// Boundary inset (the method's own rule when `None`).
    pub inset: Option<Inset>,
    /// The most distance between neighbouring rows of a `spread` (mm; its own rule
    /// when `None`): a zone per unit area needs points in every unit stretch.
    pub spacing: Option<f64>,
}

/// A set of strategies per surface type.
#[derive(Debug, Clone)]
pub struct Sampling {
    /// Its name.
    pub name: String,
    /// Strategy per surface type; a type left out gets `uniform(points 9)`.
    pub per_surface: Vec<(SurfaceKind, Strategy)>,
    /// Where it was declared.
    pub span: Span,
}

impl Sampling {
    /// The strategy for a surface type.
    pub fn strategy(&self, kind: SurfaceKind) -> Strategy {
        self.per_surface
            .iter()
            .find(|(k, _)| *k == kind)
            .map(|(_, s)| s.clone())
            .unwrap_or(Strategy {
                method: SampleMethod::Uniform,
                points: Some(9),
                inset: None,
                spacing: None,
            })
    }
}

/// A setup preference: the part orientation that puts `direction` (part frame) towards
/// the ram.
#[derive(Debug, Clone)]
pub struct SetupPref {
    /// Unit direction in the part frame.
    pub direction: Vec3,
    /// Preferred with a weight for the weighted clustering (1 = strong), or forbidden.
    pub stance: Stance<f64>,
    /// Where it was written.
    pub span: Span,
}

/// What a preference says: use this (with a weight or cost), or never use it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stance<T> {
    /// Prefer it, with its weight or cost.
    Prefer(T),
    /// Never use it.
    Forbid,
}

/// A head orientation preference (indexable heads).
#[derive(Debug, Clone)]
pub struct OrientPref {
    /// A angle (degrees).
    pub a: f64,
    /// B angle (degrees).
    pub b: f64,
    /// Preferred with a weight (1 = strong), or forbidden.
    pub stance: Stance<f64>,
    /// Where it was written.
    pub span: Span,
}

impl OrientPref {
    /// Whether it names the head orientation `(a, b)`: the same A, and the same B up to
    /// whole turns (any B at A = 0, where B turns the probe about itself).
    pub fn names(&self, a: f64, b: f64) -> bool {
        let turn = (b - self.b).rem_euclid(360.0);
        (a - self.a).abs() < 1e-6
            && (!(1e-6..=360.0 - 1e-6).contains(&turn) || a.abs() < 1e-9 && self.a.abs() < 1e-9)
    }
}

/// A probe preference: a cost override or a ban.
#[derive(Debug, Clone)]
pub struct ProbePref {
    /// The probe's label in the CMM's rack.
    pub label: String,
    /// Allowed, with a cost override if given, or forbidden.
    pub stance: Stance<Option<f64>>,
    /// Where it was written.
    pub span: Span,
}

/// Which sensor a plan asks for a feature.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SensorChoice {
    /// The rack's touch probes.
    Touch,
    /// A laser line scanner.
    Laser,
    /// The selection rule decides (tolerance to accuracy, the feature's shape).
    Auto,
}

impl SensorChoice {
    /// The keyword.
    pub fn keyword(self) -> &'static str {
        match self {
            SensorChoice::Touch => "touch",
            SensorChoice::Laser => "laser",
            SensorChoice::Auto => "auto",
        }
    }
}

/// What a plan writes.
#[derive(Debug, Clone, Default)]
pub struct Outputs {
    /// The DMIS program path, relative to the spec.
    pub dmis: Option<String>,
    /// The plan as JSON.
    pub plan: Option<String>,
    /// The measurement graph: Mermaid for `.mmd`, JSON for `.json`, else DOT.
    pub graph: Option<String>,
}

/// How the probe moves around a touch and between groups (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motion {
    /// Distance before the nominal point where the touch move starts (DMIS `APPRCH`).
    pub prehit: f64,
    /// Distance the probe backs off along the normal after a touch (DMIS `RETRCT`).
    pub retract: f64,
    /// How far past the nominal point the touch move searches (DMIS `SEARCH`).
    pub search: f64,
    /// Height above the part's top of the clearance plane between groups (DMIS `CLRSRF`).
    pub clearance: f64,
    /// The least distance every move but the touch itself keeps from part, fixture
    /// and table; less only at a stand-off where the feature leaves less room.
    pub margin: f64,
}

impl Default for Motion {
    /// Defaults for a TP20 on a touch-trigger head: 2 mm pre-hit and retract (the
    /// module's pre-travel is well under 1 mm), 4 mm search, 20 mm clearance, 1 mm
    /// margin: more than a machined part's deviation from its nominal.
    fn default() -> Self {
        Motion {
            prehit: 2.0,
            retract: 2.0,
            search: 4.0,
            clearance: 20.0,
            margin: 1.0,
        }
    }
}

/// A plan: which part on which machine, and what a good plan is.
#[derive(Debug, Clone)]
pub struct Plan {
    /// Its name.
    pub name: String,
    /// The part.
    pub part: PartId,
    /// The machine.
    pub cmm: CmmId,
    /// The constraint hierarchy.
    pub hierarchy: HierarchyId,
    /// The sampling strategies.
    pub sampling: SamplingId,
    /// Per-feature strategy overrides.
    pub overrides: Vec<(FeatureId, Strategy)>,
    /// Setup preferences and bans.
    pub setups: Vec<SetupPref>,
    /// Orientation preferences and bans.
    pub orientations: Vec<OrientPref>,
    /// Probe costs and bans.
    pub probes: Vec<ProbePref>,
    /// Output files.
    pub outputs: Outputs,
    /// Approach, retract and clearance distances.
    pub motion: Motion,
    /// The fixtures of the plan's CMM it may use (indices into [`Cmm::fixtures`]); none:
    /// the table alone.
    pub fixtures: Vec<usize>,
    /// The sensor asked for per feature (`sensors { top laser }`); a feature left out is
    /// [`SensorChoice::Auto`].
    pub sensors: Vec<(FeatureId, SensorChoice, Span)>,
    /// A feature goes to a scanner only when its tightest tolerance is at least this many
    /// times the scanner's accuracy (`sensor_ratio 10`; Zhao et al.'s 1:5 or 1:10).
    pub sensor_ratio: f64,
    /// The share of a scanned face's area its passes must see (`scan_coverage 95 %`).
    pub scan_coverage: f64,
    /// Where it was declared.
    pub span: Span,
}
