//! Parts: geometry source, faces, features, datums and tolerances.

use super::Vec3;
use crate::source::Span;
pub use crate::syntax::ast::CadKind;

/// Index into [`Part::features`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct FeatureId(pub usize);

/// Index into [`Part::datums`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct DatumId(pub usize);

/// Index into [`Part::tolerances`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ToleranceId(pub usize);

/// Index into [`Part::ops`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct OpId(pub usize);

/// A toleranced part.
#[derive(Debug, Clone)]
pub struct Part {
    /// Its name.
    pub name: String,
    /// The unit its bare numbers were written in (mm per unit).
    pub unit_mm: f64,
    /// Where its geometry comes from.
    pub geometry: Geometry,
    /// Machining operations applied to the stock, in order.
    pub ops: Vec<Op>,
    /// Features (groups of faces to be measured).
    pub features: Vec<Feature>,
    /// Datums.
    pub datums: Vec<Datum>,
    /// Datum reference frames.
    pub frames: Vec<Frame>,
    /// Tolerances.
    pub tolerances: Vec<Tolerance>,
    /// Where it was declared.
    pub span: Span,
}

/// The chord tolerance a STEP or QIF part is meshed to when its spec gives none (mm):
/// the reference meshes' (OpenCASCADE, linear deflection 0.1 mm), so that a CAD part
/// plans as its mesh did.
pub const DEFAULT_CHORD_MM: f64 = 0.1;

/// The geometry source.
#[derive(Debug, Clone)]
pub enum Geometry {
    /// Stock, with `ops` applied.
    Stock(Stock),
    /// A mesh file.
    Mesh {
        /// The path as resolved against the spec's folder.
        path: std::path::PathBuf,
        /// mm per file unit (STL, OBJ; a STEP or QIF file states its own).
        unit_mm: f64,
        /// For a STEP or QIF file, the chord tolerance it is meshed to (mm), when the
        /// spec gives one ([`DEFAULT_CHORD_MM`] when it does not).
        chord_mm: Option<f64>,
        /// The factor the file's geometry is scaled by after its unit (`scale 10`: a
        /// file modelled at a tenth of the part's size); 1 when the spec gives none.
        scale: f64,
        /// Where the path was written.
        span: Span,
    },
}

/// A stock shape; boxes span `[0, x] × [0, y] × [0, z]`, cylinders stand on the origin
/// along +z, spheres are centred on the origin.
#[derive(Debug, Clone, PartialEq)]
pub enum Stock {
    /// A box.
    Box {
        /// Extent (mm).
        size: Vec3,
    },
    /// A cylinder along +z.
    Cylinder {
        /// Diameter (mm).
        diameter: f64,
        /// Height (mm).
        height: f64,
    },
    /// A sphere.
    Sphere {
        /// Diameter (mm).
        diameter: f64,
    },
}

/// Where an operation sits.
#[derive(Debug, Clone, PartialEq)]
pub enum Placement {
    /// At a point (mm).
    At(Vec3),
    /// Where a ray from the stock's centre in this unit direction leaves the stock.
    Radial(Vec3),
}

/// How deep a hole goes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Depth {
    /// Through the part.
    Through,
    /// To this depth (mm).
    Blind(f64),
}

/// A machining operation's shape.
#[derive(Debug, Clone, PartialEq)]
pub enum OpKind {
    /// A drilled hole.
    Hole {
        /// Entry point.
        at: Placement,
        /// Drilling direction (into the material).
        axis: Vec3,
        /// Diameter (mm).
        diameter: f64,
        /// Depth.
        depth: Depth,
    },
    /// A slot cut from `at` along a direction.
    Slot {
        /// Start of the slot's centre line on the surface.
        at: Vec3,
        /// Direction of the slot.
        along: Vec3,
        /// Direction into the material.
        into: Vec3,
        /// Width (mm).
        width: f64,
        /// Depth (mm).
        depth: f64,
        /// Length (mm), through the part when `None`.
        length: Option<f64>,
    },
    /// A rectangular pocket centred on `at`.
    Pocket {
        /// Centre of the opening.
        at: Vec3,
        /// Direction of the pocket's length.
        along: Vec3,
        /// Direction into the material.
        into: Vec3,
        /// Length and width (mm).
        size: [f64; 2],
        /// Depth (mm).
        depth: f64,
        /// Corner radius (mm).
        corner_radius: f64,
    },
    /// A step milled along an edge: one wall and one floor.
    Step {
        /// A point on the edge.
        at: Vec3,
        /// Direction of the edge.
        along: Vec3,
        /// Direction into the material.
        into: Vec3,
        /// Width removed from the edge (mm).
        width: f64,
        /// Depth (mm).
        depth: f64,
    },
    /// A cylindrical boss (material added).
    Boss {
        /// Centre of its base.
        at: Vec3,
        /// Direction it grows in.
        axis: Vec3,
        /// Diameter (mm).
        diameter: f64,
        /// Height (mm).
        height: f64,
    },
}

impl OpKind {
    /// The operation's name: `hole`, `slot`, `pocket`, `step`, `boss`.
    pub fn word(&self) -> &'static str {
        match self {
            OpKind::Hole { .. } => "hole",
            OpKind::Slot { .. } => "slot",
            OpKind::Pocket { .. } => "pocket",
            OpKind::Step { .. } => "step",
            OpKind::Boss { .. } => "boss",
        }
    }
}

/// Copies of an operation.
#[derive(Debug, Clone, PartialEq)]
pub enum Pattern {
    /// `count` copies, each `step` further.
    Linear {
        /// Number of copies.
        count: u32,
        /// Offset between copies (mm).
        step: Vec3,
    },
    /// A grid of `nx × ny` copies along the part's x and y.
    Grid {
        /// Copies along x.
        nx: u32,
        /// Copies along y.
        ny: u32,
        /// Pitch along x and y (mm).
        pitch: [f64; 2],
    },
    /// `count` copies rotated evenly about an axis through a centre.
    Polar {
        /// Number of copies.
        count: u32,
        /// Rotation axis.
        axis: Vec3,
        /// A point on the axis.
        center: Vec3,
    },
}

impl Pattern {
    /// Number of instances.
    pub fn count(&self) -> u32 {
        match self {
            Pattern::Linear { count, .. } | Pattern::Polar { count, .. } => *count,
            Pattern::Grid { nx, ny, .. } => nx.saturating_mul(*ny),
        }
    }
}

/// What an operation does to the material.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// `cut`: removes material.
    Cut,
    /// `add`: adds material.
    Add,
}

impl Action {
    /// The spec's keyword.
    pub fn keyword(self) -> &'static str {
        match self {
            Action::Cut => "cut",
            Action::Add => "add",
        }
    }
}

/// A named machining operation.
#[derive(Debug, Clone)]
pub struct Op {
    /// Its name.
    pub name: String,
    /// Whether it removes material (`cut`) or adds it (`add`).
    pub action: Action,
    /// The shape.
    pub kind: OpKind,
    /// Copies, if patterned.
    pub pattern: Option<Pattern>,
    /// Where it was declared.
    pub span: Span,
}

/// Which faces of the stock or of an operation a reference names.
#[derive(Debug, Clone, PartialEq)]
pub enum FaceSource {
    /// The stock.
    Stock,
    /// An operation, optionally one instance of its pattern.
    Op(OpId, Option<u32>),
}

/// A criterion picking faces of a mesh by their fitted surface.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Selector {
    /// The surface type.
    pub surface: Option<super::SurfaceKind>,
    /// A plane's outward normal (unit).
    pub normal: Option<Vec3>,
    /// A cylinder's or cone's axis (unit, either sense).
    pub axis: Option<Vec3>,
    /// Radius (mm).
    pub radius: Option<f64>,
    /// Keep the face with the highest (`true`) or lowest centroid coordinate on an axis.
    /// (Still a flag: the model summary prints selectors with `Debug`, and golden model
    /// files hold that text.)
    pub extreme: Option<(u8, bool)>,
    /// Keep the face whose centroid is nearest this point (mm).
    pub nearest: Option<Vec3>,
}

/// A face's role on the stock or an operation: what `stock.top` or `slot.walls` names.
/// The geometry stage tags the faces it makes with these; the resolver checks names
/// against [`Role::of_stock`] and [`Role::of_op`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[allow(missing_docs)]
pub enum Role {
    Top,
    Bottom,
    Left,
    Right,
    Front,
    Back,
    Side,
    Surface,
    Wall,
    Walls,
    LeftWall,
    RightWall,
    Floor,
    Ends,
}

impl Role {
    /// Every role.
    pub const ALL: [Role; 14] = [
        Role::Top,
        Role::Bottom,
        Role::Left,
        Role::Right,
        Role::Front,
        Role::Back,
        Role::Side,
        Role::Surface,
        Role::Wall,
        Role::Walls,
        Role::LeftWall,
        Role::RightWall,
        Role::Floor,
        Role::Ends,
    ];

    /// Its name in the spec language.
    pub fn name(self) -> &'static str {
        match self {
            Role::Top => "top",
            Role::Bottom => "bottom",
            Role::Left => "left",
            Role::Right => "right",
            Role::Front => "front",
            Role::Back => "back",
            Role::Side => "side",
            Role::Surface => "surface",
            Role::Wall => "wall",
            Role::Walls => "walls",
            Role::LeftWall => "left_wall",
            Role::RightWall => "right_wall",
            Role::Floor => "floor",
            Role::Ends => "ends",
        }
    }

    /// The role a name spells.
    pub fn from_name(name: &str) -> Option<Role> {
        Role::ALL.into_iter().find(|r| r.name() == name)
    }

    /// The roles a stock's faces answer to.
    pub fn of_stock(stock: &Stock) -> &'static [Role] {
        match stock {
            Stock::Box { .. } => &[
                Role::Top,
                Role::Bottom,
                Role::Left,
                Role::Right,
                Role::Front,
                Role::Back,
            ],
            Stock::Cylinder { .. } => &[Role::Top, Role::Bottom, Role::Side],
            Stock::Sphere { .. } => &[Role::Surface],
        }
    }

    /// The roles an operation's faces answer to.
    pub fn of_op(op: &OpKind) -> &'static [Role] {
        match op {
            OpKind::Hole {
                depth: Depth::Through,
                ..
            } => &[Role::Wall],
            OpKind::Hole { .. } => &[Role::Wall, Role::Bottom],
            OpKind::Slot {
                length: Some(_), ..
            } => &[
                Role::Walls,
                Role::LeftWall,
                Role::RightWall,
                Role::Floor,
                Role::Ends,
            ],
            OpKind::Slot { .. } => &[Role::Walls, Role::LeftWall, Role::RightWall, Role::Floor],
            OpKind::Pocket { .. } => &[Role::Walls, Role::Floor],
            OpKind::Step { .. } => &[Role::Wall, Role::Floor],
            OpKind::Boss { .. } => &[Role::Wall, Role::Top],
        }
    }
}

impl std::fmt::Display for Role {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A reference to faces of the part geometry.
#[derive(Debug, Clone, PartialEq)]
pub enum FaceRef {
    /// A role of the stock or an operation: `stock.top`, `grid[2].wall`.
    Role {
        /// Whose face.
        source: FaceSource,
        /// The role.
        role: Role,
        /// Where it was written.
        span: Span,
    },
    /// A group of a mesh file.
    Group(String, Span),
    /// A segment of an unlabelled mesh.
    Segment(u32, Span),
    /// A CAD file's face by the file's own id.
    FileFace(CadKind, u64, Span),
    /// A selector over a mesh's faces.
    Select(Selector, Span),
}

impl FaceRef {
    /// Where the reference is written.
    pub fn span(&self) -> Span {
        match self {
            FaceRef::Role { span, .. }
            | FaceRef::Group(_, span)
            | FaceRef::Segment(_, span)
            | FaceRef::FileFace(_, _, span)
            | FaceRef::Select(_, span) => *span,
        }
    }
}

/// How a feature came to be.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Declared {
    /// `feature x = …`, or the feature of a datum on a face expression.
    Feature,
    /// `face x = …`: a named face, measured only when a tolerance or datum uses it.
    Face,
}

/// A feature: faces measured together.
#[derive(Debug, Clone)]
pub struct Feature {
    /// Its name.
    pub name: String,
    /// Its faces (with repeats removed).
    pub faces: Vec<FaceRef>,
    /// Declared with `feature`, or with `face` (a named face reused in features).
    pub declared: Declared,
    /// Where it was declared.
    pub span: Span,
}

/// A datum.
#[derive(Debug, Clone)]
pub struct Datum {
    /// Its letter(s).
    pub name: String,
    /// The datum feature.
    pub feature: FeatureId,
    /// Where it was declared.
    pub span: Span,
}

/// Material condition modifiers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Material {
    /// Maximum material condition, Ⓜ.
    Mmc,
    /// Least material condition, Ⓛ.
    Lmc,
    /// Regardless of feature size.
    Rfs,
}

/// A datum in a tolerance's reference frame.
#[derive(Debug, Clone)]
pub struct DatumRef {
    /// The datum.
    pub datum: DatumId,
    /// Its modifier.
    pub modifier: Option<Material>,
}

/// A named datum reference frame.
#[derive(Debug, Clone)]
pub struct Frame {
    /// Its name.
    pub name: String,
    /// Primary, secondary, tertiary.
    pub refs: Vec<DatumRef>,
    /// Where it was declared.
    pub span: Span,
}

/// Tolerance types a CMM checks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum TolKind {
    /// ⏥
    Flatness,
    /// ⏤
    Straightness,
    /// ○
    Circularity,
    /// ⌭
    Cylindricity,
    /// ⌒
    ProfileLine,
    /// ⌓
    ProfileSurface,
    /// ⟂
    Perpendicularity,
    /// ∥
    Parallelism,
    /// ∠
    Angularity,
    /// ⌖
    Position,
    /// ◎ (concentricity)
    Concentricity,
    /// ◎ (coaxiality)
    Coaxiality,
    /// ⌯
    Symmetry,
    /// ↗
    CircularRunout,
    /// ⌰
    TotalRunout,
    /// Ø size
    Diameter,
    /// R size
    Radius,
    /// Width of a slot or tab.
    Width,
    /// Distance between features.
    Distance,
    /// Angle between features.
    Angle,
}

impl TolKind {
    /// Its keyword in the spec language (`flatness`, `position`, …).
    pub fn keyword(self) -> &'static str {
        match self {
            TolKind::Flatness => "flatness",
            TolKind::Straightness => "straightness",
            TolKind::Circularity => "circularity",
            TolKind::Cylindricity => "cylindricity",
            TolKind::ProfileLine => "profile_line",
            TolKind::ProfileSurface => "profile_surface",
            TolKind::Perpendicularity => "perpendicularity",
            TolKind::Parallelism => "parallelism",
            TolKind::Angularity => "angularity",
            TolKind::Position => "position",
            TolKind::Concentricity => "concentricity",
            TolKind::Coaxiality => "coaxiality",
            TolKind::Symmetry => "symmetry",
            TolKind::CircularRunout => "circular_runout",
            TolKind::TotalRunout => "total_runout",
            TolKind::Diameter => "diameter",
            TolKind::Radius => "radius",
            TolKind::Width => "width",
            TolKind::Distance => "distance",
            TolKind::Angle => "angle",
        }
    }
}

/// A tolerance's value.
#[derive(Debug, Clone, PartialEq)]
pub enum TolValue {
    /// A geometric tolerance zone width (mm); `diameter` for a cylindrical zone (Ø).
    Zone {
        /// Width (mm).
        width: f64,
        /// Cylindrical zone.
        diameter: bool,
    },
    /// A size with limits (mm, or degrees for `angle`).
    Size {
        /// Nominal.
        nominal: f64,
        /// Lower limit.
        lower: f64,
        /// Upper limit.
        upper: f64,
    },
}

impl TolValue {
    /// The value as reports print it: `Ø0.1` for a zone, `10 [9.9, 10.1]` for a size.
    pub fn text(&self) -> String {
        use super::fmt_num;
        match self {
            TolValue::Zone { width, diameter } => {
                format!("{}{}", if *diameter { "Ø" } else { "" }, fmt_num(*width))
            }
            TolValue::Size {
                nominal,
                lower,
                upper,
            } => format!(
                "{} [{}, {}]",
                fmt_num(*nominal),
                fmt_num(*lower),
                fmt_num(*upper)
            ),
        }
    }
}

/// A tolerance.
#[derive(Debug, Clone)]
pub struct Tolerance {
    /// Its name.
    pub name: String,
    /// Its type.
    pub kind: TolKind,
    /// The toleranced features.
    pub targets: Vec<FeatureId>,
    /// Zone or limits.
    pub value: TolValue,
    /// Material condition of the toleranced feature.
    pub modifier: Option<Material>,
    /// The datum reference frame.
    pub datums: Vec<DatumRef>,
    /// Basic angle for angularity (degrees).
    pub basic_angle: Option<f64>,
    /// A zone that applies to every unit length or area of the feature.
    pub per_unit: Option<PerUnit>,
    /// Where it was declared.
    pub span: Span,
}

impl Tolerance {
    /// The drawing's nominal diameter for a round surface of the toleranced feature whose
    /// CAD diameter is `cad`: the size tolerance's nominal (twice it for a radius) where
    /// `cad` lies within the tolerance's limits, so that the surface is the one the
    /// dimension controls; `None` for other tolerances and other surfaces. The drawing
    /// governs (ASME Y14.5-2018 §1.4: dimensions define the part; a CAD model is
    /// modelled at some size within the limits, NIST FTC 08's Ø6.0452 +0.127/−0.0254
    /// holes at Ø6.0325). A DMIS `TOL/DIAM` gives its limits as deviations from the
    /// `FEAT`'s nominal (ANSI/DMIS 105.2 `TOL/DIAM,lotol,uptol`), so the program's
    /// `FEAT` and the verification's size trials both start from this nominal.
    pub fn drawing_diameter(&self, cad: f64) -> Option<f64> {
        let scale = match self.kind {
            TolKind::Diameter => 1.0,
            TolKind::Radius => 2.0,
            _ => return None,
        };
        let TolValue::Size {
            nominal,
            lower,
            upper,
        } = self.value
        else {
            return None;
        };
        let within = (lower * scale - 1e-9..=upper * scale + 1e-9).contains(&cad);
        within.then_some(nominal * scale)
    }
}

/// A form zone that applies to every stretch of the feature of one size: ASME
/// Y14.5-2018 § 5.4.1.4 (straightness per unit length) and § 5.4.2.2 (flatness per unit
/// area), ISO 1101 `0.02/25`, `0.02/25×25`. It keeps an abrupt change within a short
/// stretch smaller than the feature's whole form may be.
#[derive(Debug, Clone, PartialEq)]
pub struct PerUnit {
    /// The zone (mm) every unit stretch keeps.
    pub zone: f64,
    /// The stretch.
    pub unit: UnitOf,
    /// Whether the tolerance's [`Tolerance::value`] also bounds the whole feature (a
    /// frame of two lines); `false`: the unit zone alone, and `value` is that zone.
    pub overall: bool,
}

/// The size of a per-unit stretch (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum UnitOf {
    /// A length along the feature (straightness).
    Length(f64),
    /// A rectangle on the surface, length × width (a square where they are equal).
    Rectangle(f64, f64),
    /// A circle of this diameter on the surface.
    Circle(f64),
}

impl UnitOf {
    /// As a drawing writes it after the slash: `25`, `25×50`, `Ø25`.
    pub fn text(self) -> String {
        use super::fmt_num;
        match self {
            UnitOf::Length(l) => fmt_num(l),
            UnitOf::Rectangle(a, b) => format!("{}×{}", fmt_num(a), fmt_num(b)),
            UnitOf::Circle(d) => format!("Ø{}", fmt_num(d)),
        }
    }

    /// The shortest extent of the stretch (mm): the sampling density follows it.
    pub fn least(self) -> f64 {
        match self {
            UnitOf::Length(l) | UnitOf::Circle(l) => l,
            UnitOf::Rectangle(a, b) => a.min(b),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::source::{FileId, Span};

    fn size(kind: TolKind, nominal: f64, lower: f64, upper: f64) -> Tolerance {
        Tolerance {
            name: "size".into(),
            kind,
            targets: vec![],
            value: TolValue::Size {
                nominal,
                lower,
                upper,
            },
            modifier: None,
            datums: vec![],
            basic_angle: None,
            per_unit: None,
            span: Span::new(FileId(0), 0, 0),
        }
    }

    #[test]
    fn a_cad_size_within_the_limits_takes_the_drawings_nominal() {
        // NIST FTC 08's datum holes: Ø6.0452 +0.127/−0.0254 on the drawing, Ø6.0325 in CAD.
        let hole = size(TolKind::Diameter, 6.0452, 6.0198, 6.1722);
        assert_eq!(hole.drawing_diameter(6.0325), Some(6.0452));
        // A counterbore of the same feature, another size: not the dimensioned surface.
        assert_eq!(hole.drawing_diameter(10.0), None);
        // A radius gives a diameter.
        let fillet = size(TolKind::Radius, 3.175, 2.667, 3.683);
        assert_eq!(fillet.drawing_diameter(6.3), Some(6.35));
        // Not a size.
        let width = size(TolKind::Width, 10.0, 9.9, 10.1);
        assert_eq!(width.drawing_diameter(10.0), None);
    }
}
