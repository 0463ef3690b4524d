//! Semantic PMI: the datums, geometric tolerances and dimensions an AP242 file states,
//! each linked to the B-rep faces it applies to.
//!
//! The links run `GEOMETRIC_ITEM_SPECIFIC_USAGE` (or `ITEM_IDENTIFIED_REPRESENTATION_USAGE`)
//! → `SHAPE_ASPECT` → `ADVANCED_FACE`, through composite aspects
//! (`SHAPE_ASPECT_RELATIONSHIP`, relating → related), datum features (the datum is the
//! related side), datum targets (`FEATURE_FOR_DATUM_TARGET_RELATIONSHIP`) and dimensional
//! sizes used as toleranced aspects. Reading never fails: what cannot be linked or read
//! is a line in [`Pmi::notes`], so a caller can say so instead of guessing.
//!
//! **Decision: links followed, gaps said, targets located.**
//! `ITEM_IDENTIFIED_REPRESENTATION_USAGE` is followed with its
//! `SET_REPRESENTATION_ITEM` (where CTC 01 links datums B and C, which the NIST
//! reference JSON lost). An aspect named by an edge (CTC 02's holes by their rims) is
//! the edge's curved faces. Datum systems read compartments with common datums
//! (`COMMON_DATUM_LIST`) and their modifiers, or AP214's `DATUM_REFERENCE` by
//! precedence. Measures go through their own unit (FTC 06's PMI is in inches in a
//! millimetre model). Datums set up only by targets on supplemental geometry (FTC 06's
//! G, H, J, K; CTC 02's A, B, C, K) are located by sampling each target (point, line,
//! circle, circular curve, rectangle) from its placement and size and taking the faces
//! within 0.5 mm; when the sizes in their stated unit put the target off the part and
//! in the model's unit on it (FTC 06 writes Ø25.4 mm with an inch unit), the model's
//! unit is used and a note says so. Nothing is dropped silently: `inspc import` writes
//! every note into the spec's header.

use super::brep::unit_factor;
use super::p21::{Instance, Param, P21};
use super::refs::{Memo, Trail};
use super::StepError;
use crate::model::{Material, TolKind};
use std::cell::Cell;
use std::collections::{BTreeSet, HashMap};

/// The PMI of a STEP file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Pmi {
    /// Datums, in the file's order.
    pub datums: Vec<Datum>,
    /// Geometric tolerances, in the file's order.
    pub tolerances: Vec<GeoTolerance>,
    /// Dimensions (sizes and locations), in the file's order.
    pub dimensions: Vec<Dimension>,
    /// What could not be read or linked, one sentence each.
    pub notes: Vec<String>,
}

/// A datum: its letter and the faces of its datum features (or targets).
#[derive(Debug, Clone, PartialEq)]
pub struct Datum {
    /// The `DATUM` instance.
    pub id: u64,
    /// `A`, `B`, …
    pub letter: String,
    /// 0-based face indices, sorted.
    pub faces: Vec<usize>,
    /// Datum targets that establish it.
    pub targets: Vec<Target>,
    /// Whether the faces were found by locating the targets on the part (the file links
    /// the targets to supplemental geometry only).
    pub located: bool,
}

/// A datum target: its kind, label and where it sits.
#[derive(Debug, Clone, PartialEq)]
pub struct Target {
    /// `point`, `line`, `circle`, `circular curve`, `rectangle`, `area`.
    pub kind: String,
    /// `A1`.
    pub label: String,
    /// Points on the target (mm): its origin, and for lines, curves and areas points
    /// along them; empty when the file places it nowhere.
    pub points: Vec<[f64; 3]>,
    /// The same points with the target's sizes read in the model's length unit, where
    /// that differs from the unit the sizes state (some files write millimetre values
    /// with an inch unit); empty otherwise.
    pub model_unit_points: Vec<[f64; 3]>,
}

/// One compartment of a datum reference frame.
#[derive(Debug, Clone, PartialEq)]
pub struct DatumRef {
    /// One letter, or several for a common datum (`A-B`).
    pub letters: Vec<String>,
    /// Its material modifier, if any.
    pub material: Option<Material>,
    /// Other modifiers, lower case (`free state`, `translation`).
    pub other: Vec<String>,
}

/// A geometric tolerance.
#[derive(Debug, Clone, PartialEq)]
pub struct GeoTolerance {
    /// The tolerance's instance.
    pub id: u64,
    /// The name the file gives it (`Feature Control Frame (11)`).
    pub name: String,
    /// Its type; `None` for a bare `GEOMETRIC_TOLERANCE`.
    pub kind: Option<TolKind>,
    /// The zone's width, mm.
    pub value_mm: f64,
    /// A cylindrical (Ø) or spherical (SØ) zone.
    pub diameter: bool,
    /// The zone is spherical (SØ).
    pub spherical: bool,
    /// The material modifier on the toleranced feature.
    pub material: Option<Material>,
    /// Other modifiers, lower case (`tangent plane`, `free state`).
    pub other: Vec<String>,
    /// The datum reference frame, primary first.
    pub datums: Vec<DatumRef>,
    /// 0-based face indices of the toleranced feature, sorted.
    pub faces: Vec<usize>,
    /// For the lower segment of a composite frame: the upper segment's instance.
    pub composite_of: Option<u64>,
    /// An unequally disposed profile's displacement (mm).
    pub unequal_mm: Option<f64>,
    /// A zone per unit length or area (ISO 10303-47
    /// `geometric_tolerance_with_defined_unit`; QIF `ToleranceZonePerUnit…`): the zone
    /// applies to every such stretch of the feature, not to all of it at once.
    pub per_unit: Option<PerUnitZone>,
}

/// A zone per unit length or area as the file gives it.
#[derive(Debug, Clone, PartialEq)]
pub struct PerUnitZone {
    /// The zone per unit (mm) where the file gives it apart from the tolerance's value
    /// (QIF `ToleranceValuePerUnit`, the value then bounding the whole feature); `None`
    /// where the tolerance's value is the zone per unit (STEP).
    pub zone_mm: Option<f64>,
    /// The stretch; `None` where its size cannot be read.
    pub unit: Option<crate::model::UnitOf>,
    /// In words: `per 25 mm length`, `per 25 × 25 mm square area`.
    pub text: String,
}

/// What a dimension measures.
#[derive(Debug, Clone, PartialEq)]
pub enum DimKind {
    /// A size (`diameter`, `radius`, `thickness`, …), as the file names it.
    Size(String),
    /// A location between two features (`linear distance`, `angle`, …).
    Location(String),
}

/// A dimension with its limits.
#[derive(Debug, Clone, PartialEq)]
pub struct Dimension {
    /// The `DIMENSIONAL_SIZE` or `DIMENSIONAL_LOCATION` instance.
    pub id: u64,
    /// Size or location.
    pub kind: DimKind,
    /// Whether the values are angles (degrees) rather than lengths (mm).
    pub angular: bool,
    /// The nominal value, if the file gives one.
    pub nominal: Option<f64>,
    /// Upper deviation (signed), if toleranced.
    pub upper: Option<f64>,
    /// Lower deviation (signed), if toleranced.
    pub lower: Option<f64>,
    /// A fit designation (`H7`), if the tolerance is one.
    pub fit: Option<String>,
    /// Faces of the size, or of the location's origin feature.
    pub faces: Vec<usize>,
    /// Faces of the location's target feature (empty for a size).
    pub to_faces: Vec<usize>,
}

/// Geometric tolerance types by their AP242 entity.
const KINDS: &[(&str, TolKind)] = &[
    ("FLATNESS_TOLERANCE", TolKind::Flatness),
    ("STRAIGHTNESS_TOLERANCE", TolKind::Straightness),
    ("ROUNDNESS_TOLERANCE", TolKind::Circularity),
    ("CYLINDRICITY_TOLERANCE", TolKind::Cylindricity),
    ("LINE_PROFILE_TOLERANCE", TolKind::ProfileLine),
    ("SURFACE_PROFILE_TOLERANCE", TolKind::ProfileSurface),
    ("PERPENDICULARITY_TOLERANCE", TolKind::Perpendicularity),
    ("PARALLELISM_TOLERANCE", TolKind::Parallelism),
    ("ANGULARITY_TOLERANCE", TolKind::Angularity),
    ("POSITION_TOLERANCE", TolKind::Position),
    ("CONCENTRICITY_TOLERANCE", TolKind::Concentricity),
    ("COAXIALITY_TOLERANCE", TolKind::Coaxiality),
    ("SYMMETRY_TOLERANCE", TolKind::Symmetry),
    ("CIRCULAR_RUNOUT_TOLERANCE", TolKind::CircularRunout),
    ("TOTAL_RUNOUT_TOLERANCE", TolKind::TotalRunout),
];

/// The instance tables the links are followed through.
struct Links<'a> {
    f: &'a P21,
    /// Face instance → 0-based face index.
    face_index: HashMap<u64, usize>,
    /// Edge instance → the faces it names: its curved faces when it bounds any (a hole
    /// named by its rim is the hole), else all.
    edge_faces: &'a HashMap<u64, Vec<usize>>,
    /// Aspect → the representation items a usage names for it.
    usage: HashMap<u64, Vec<u64>>,
    /// Relating aspect → related aspects (composites, derived features).
    down: HashMap<u64, Vec<u64>>,
    /// Related aspect → relating aspects (datum → its features and targets).
    up: HashMap<u64, Vec<u64>>,
    /// Property definition's subject → its shape representation (datum targets).
    shape_of: HashMap<u64, u64>,
    /// Tolerance → its zone's form (`cylindrical or circular`, `spherical`).
    zones: HashMap<u64, String>,
    /// Lower segment of a composite frame → its upper segment.
    composite: HashMap<u64, u64>,
    /// Dimension → the representation of its nominal value.
    nominal_of: HashMap<u64, u64>,
    /// Dimension → its plus-minus range.
    limits_of: HashMap<u64, u64>,
    /// File length unit, mm (for a measure whose unit cannot be read).
    unit_mm: f64,
    /// Datum references being read (a common datum lists others).
    trail: Trail,
    /// Datum reference compartments read.
    compartments: Memo<Option<DatumRef>>,
    /// How many more aspects the links may pass through ([`link_budget`]).
    visits: Cell<usize>,
}

/// Reads the PMI of a parsed file whose faces (in numbering order) are `faces`; an
/// aspect named by an edge is the edge's curved faces, or all its faces when none is
/// curved (`edge_faces`).
///
/// A datum reference that lists itself (round any circle) is a `step_cycle` error.
pub fn read(
    f: &P21,
    faces: &[u64],
    edge_faces: &HashMap<u64, Vec<usize>>,
    unit_mm: f64,
) -> Result<Pmi, StepError> {
    let mut l = Links {
        f,
        face_index: faces.iter().enumerate().map(|(i, id)| (*id, i)).collect(),
        edge_faces,
        usage: HashMap::new(),
        down: HashMap::new(),
        up: HashMap::new(),
        shape_of: HashMap::new(),
        zones: HashMap::new(),
        composite: HashMap::new(),
        nominal_of: HashMap::new(),
        limits_of: HashMap::new(),
        unit_mm,
        trail: Trail::default(),
        compartments: Memo::default(),
        visits: Cell::new(link_budget(f)),
    };
    let mut subject_of: HashMap<u64, u64> = HashMap::new();
    let mut shape_reps: Vec<(u64, u64)> = Vec::new();
    for id in &f.order {
        let inst = &f.instances[id];
        let Some(r) = inst.records.first() else {
            continue;
        };
        let p = &r.params;
        let at = |i: usize| p.get(i).and_then(Param::reference);
        match r.name.as_str() {
            "GEOMETRIC_ITEM_SPECIFIC_USAGE" | "ITEM_IDENTIFIED_REPRESENTATION_USAGE"
                if inst.records.len() == 1 =>
            {
                if let (Some(def), Some(item)) = (at(2), p.get(4)) {
                    let entry = l.usage.entry(def).or_default();
                    collect_refs(item, entry);
                }
            }
            "SHAPE_ASPECT_RELATIONSHIP"
            | "SHAPE_ASPECT_DERIVING_RELATIONSHIP"
            | "FEATURE_FOR_DATUM_TARGET_RELATIONSHIP"
                if inst.records.len() == 1 =>
            {
                if let (Some(a), Some(b)) = (at(2), at(3)) {
                    l.down.entry(a).or_default().push(b);
                    l.up.entry(b).or_default().push(a);
                }
            }
            "TOLERANCE_ZONE" => {
                let form = at(5)
                    .and_then(|z| f.instances.get(&z))
                    .and_then(|z| z.record("TOLERANCE_ZONE_FORM"))
                    .and_then(|z| z.params.first())
                    .and_then(Param::string)
                    .unwrap_or("")
                    .to_string();
                for t in p.get(4).and_then(Param::list).unwrap_or(&[]) {
                    if let Some(t) = t.reference() {
                        l.zones.insert(t, form.clone());
                    }
                }
            }
            "GEOMETRIC_TOLERANCE_RELATIONSHIP" => {
                let is_composite = p.first().and_then(Param::string) == Some("composite");
                if let (true, Some(upper), Some(lower)) = (is_composite, at(2), at(3)) {
                    l.composite.insert(lower, upper);
                }
            }
            "PROPERTY_DEFINITION" => {
                if let Some(of) = at(2) {
                    subject_of.insert(*id, of);
                }
            }
            "SHAPE_DEFINITION_REPRESENTATION" => {
                if let (Some(pd), Some(rep)) = (at(0), at(1)) {
                    shape_reps.push((pd, rep));
                }
            }
            "DIMENSIONAL_CHARACTERISTIC_REPRESENTATION" => {
                if let (Some(d), Some(rep)) = (at(0), at(1)) {
                    l.nominal_of.insert(d, rep);
                }
            }
            "PLUS_MINUS_TOLERANCE" => {
                if let (Some(range), Some(d)) = (at(0), at(1)) {
                    l.limits_of.insert(d, range);
                }
            }
            _ => {}
        }
    }

    // A target's placement: SHAPE_DEFINITION_REPRESENTATION(property, rep) with
    // PROPERTY_DEFINITION(.., target).
    for (pd, rep) in shape_reps {
        if let Some(&subject) = subject_of.get(&pd) {
            l.shape_of.insert(subject, rep);
        }
    }
    let mut pmi = Pmi::default();
    for id in &f.order {
        let inst = &f.instances[id];
        if inst.is("DATUM") {
            pmi.datums.push(l.datum(*id, &mut pmi.notes));
        } else if inst.is("GEOMETRIC_TOLERANCE") || KINDS.iter().any(|(n, _)| inst.is(n)) {
            if let Some(t) = l.tolerance(*id, inst, &mut pmi.notes)? {
                pmi.tolerances.push(t);
            }
        } else if let Some(d) = l.dimension(*id, inst, &mut pmi.notes) {
            pmi.dimensions.push(d);
        }
    }
    if l.visits.get() == 0 {
        pmi.notes.push(format!(
            "the PMI's links run through more than {} aspects in all: the rest are not followed, and what they link is missing",
            link_budget(f)
        ));
    }
    Ok(pmi)
}

/// How many aspects the links may pass through in all: a few times the file's
/// instances, so that reading the PMI takes time in proportion to the file however
/// its aspects name each other.
fn link_budget(f: &P21) -> usize {
    4 * f.order.len() + 10_000
}

/// The references in a usage's identified item: one, a list, or a typed set.
fn collect_refs(p: &Param, out: &mut Vec<u64>) {
    match p {
        Param::Ref(r) => out.push(*r),
        Param::List(v) => v.iter().for_each(|q| collect_refs(q, out)),
        Param::Typed(t) => t.params.iter().for_each(|q| collect_refs(q, out)),
        _ => {}
    }
}

impl Links<'_> {
    /// The faces of a shape aspect: what usages name for it and its members, through
    /// composites, derived features, datum target features and dimensional sizes.
    fn faces(&self, aspect: u64) -> Vec<usize> {
        // A tolerance on the product definition shape itself applies all over the
        // part (a general profile "all over", ASME Y14.5-2018 § 11.3.1.4).
        if self
            .f
            .instances
            .get(&aspect)
            .is_some_and(|i| i.is("PRODUCT_DEFINITION_SHAPE"))
        {
            let mut all: Vec<usize> = self.face_index.values().copied().collect();
            all.sort_unstable();
            all.dedup();
            return all;
        }
        let mut seen = BTreeSet::new();
        let mut out = BTreeSet::new();
        let mut stack = vec![aspect];
        while let Some(a) = stack.pop() {
            if !seen.insert(a) {
                continue;
            }
            match self.visits.get() {
                0 => break,
                n => self.visits.set(n - 1),
            }
            for item in self.usage.get(&a).into_iter().flatten() {
                if let Some(i) = self.face_index.get(item) {
                    out.insert(*i);
                } else if let Some(faces) = self.edge_faces.get(item) {
                    out.extend(faces);
                }
            }
            stack.extend(self.down.get(&a).into_iter().flatten());
            let Some(inst) = self.f.instances.get(&a) else {
                continue;
            };
            // A size is the faces it applies to; a datum target the feature it sits on.
            if inst.is("DIMENSIONAL_SIZE") || inst.is("ANGULAR_SIZE") {
                let applies = inst.records[0].params.first().and_then(Param::reference);
                stack.extend(applies);
            }
            if inst.is("PLACED_DATUM_TARGET_FEATURE") || inst.is("DATUM_TARGET") {
                stack.extend(self.up.get(&a).into_iter().flatten());
            }
        }
        out.into_iter().collect()
    }

    /// The faces of the aspect a record's parameter `i` refers to (none when absent).
    fn faces_at(&self, params: &[Param], i: usize) -> Vec<usize> {
        params
            .get(i)
            .and_then(Param::reference)
            .map(|a| self.faces(a))
            .unwrap_or_default()
    }

    fn datum(&self, id: u64, notes: &mut Vec<String>) -> Datum {
        let letter = self.letter(id).unwrap_or_else(|| "?".into());
        let mut faces = BTreeSet::new();
        let mut targets = Vec::new();
        for &feature in self.up.get(&id).into_iter().flatten() {
            let Some(fi) = self.f.instances.get(&feature) else {
                continue;
            };
            if let Some(t) = fi.record("PLACED_DATUM_TARGET_FEATURE") {
                let kind = t.params.get(1).and_then(Param::string).unwrap_or("target");
                let n = t.params.get(4).and_then(Param::string).unwrap_or("");
                let (points, model_unit_points) = self.target_points(feature, kind);
                targets.push(Target {
                    kind: kind.to_string(),
                    label: format!("{letter}{n}"),
                    points,
                    model_unit_points,
                });
            }
            faces.extend(self.faces(feature));
        }
        targets.sort_by(|a, b| a.label.cmp(&b.label));
        if faces.is_empty() && targets.iter().all(|t| t.points.is_empty()) {
            notes.push(format!("datum {letter} (#{id}) is linked to no face"));
        }
        Datum {
            id,
            letter,
            faces: faces.into_iter().collect(),
            targets,
            located: false,
        }
    }

    /// Points on a datum target, from its placement (origin, z normal, x along) and its
    /// size parameters (`target diameter`, `target length`, `target width`), in mm; and
    /// again with the sizes in the model's unit where their stated unit differs.
    fn target_points(&self, target: u64, kind: &str) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        let Some(rep) = self
            .shape_of
            .get(&target)
            .and_then(|r| self.f.instances.get(r))
        else {
            return (Vec::new(), Vec::new());
        };
        let items = rep.records[0]
            .params
            .get(1)
            .and_then(Param::list)
            .unwrap_or(&[]);
        let mut frame = None;
        let mut size = HashMap::new();
        let mut model_size = HashMap::new();
        for item in items.iter().filter_map(Param::reference) {
            let Some(i) = self.f.instances.get(&item) else {
                continue;
            };
            if let Some(a) = i.record("AXIS2_PLACEMENT_3D") {
                frame = self.placement(a.params.get(1), a.params.get(2), a.params.get(3));
            } else if let Some(name) = i
                .record("REPRESENTATION_ITEM")
                .and_then(|r| r.params.first())
                .and_then(Param::string)
            {
                if let Some((v, false)) = self.measure(item) {
                    size.insert(name.to_string(), v);
                    let raw = self.raw_value(item).map_or(v, |r| tidy(r * self.unit_mm));
                    model_size.insert(name.to_string(), raw);
                }
            }
        }
        let Some((o, z, x)) = frame else {
            return (Vec::new(), Vec::new());
        };
        let y = [
            z[1] * x[2] - z[2] * x[1],
            z[2] * x[0] - z[0] * x[2],
            z[0] * x[1] - z[1] * x[0],
        ];
        let at = |a: f64, b: f64| {
            [
                o[0] + a * x[0] + b * y[0],
                o[1] + a * x[1] + b * y[1],
                o[2] + a * x[2] + b * y[2],
            ]
        };
        let points = |size: &HashMap<String, f64>| {
            let mut pts = Vec::new();
            match kind {
                "line" => {
                    // A line target runs along x from its origin; its ends often sit
                    // on an edge, so points inside it decide the face.
                    let len = size.get("target length").copied().unwrap_or(0.0);
                    pts.extend((0..4).map(|k| at(len * (f64::from(k) + 0.5) / 4.0, 0.0)));
                }
                "circle" | "circular curve" => {
                    let r = size.get("target diameter").copied().unwrap_or(0.0) / 2.0;
                    if kind == "circle" {
                        pts.push(o);
                    }
                    pts.extend((0..8).map(|k| {
                        let t = f64::from(k) * std::f64::consts::FRAC_PI_4;
                        at(r * t.cos(), r * t.sin())
                    }));
                }
                "rectangle" => {
                    let (lx, ly) = (
                        size.get("target length").copied().unwrap_or(0.0) / 2.0,
                        size.get("target width").copied().unwrap_or(0.0) / 2.0,
                    );
                    pts.push(o);
                    pts.extend([(-lx, -ly), (lx, -ly), (lx, ly), (-lx, ly)].map(|(a, b)| at(a, b)));
                }
                _ => pts.push(o),
            }
            pts
        };
        let stated = points(&size);
        let model = if model_size == size {
            Vec::new()
        } else {
            points(&model_size)
        };
        (stated, model)
    }

    /// A measure's number as written, without its unit.
    fn raw_value(&self, id: u64) -> Option<f64> {
        let inst = self.f.instances.get(&id)?;
        inst.records
            .iter()
            .find(|r| r.params.len() >= 2 && r.params[1].reference().is_some())
            .and_then(|r| r.params[0].real())
    }

    /// An axis placement's origin (mm) and unit z and x directions.
    fn placement(
        &self,
        o: Option<&Param>,
        z: Option<&Param>,
        x: Option<&Param>,
    ) -> Option<([f64; 3], [f64; 3], [f64; 3])> {
        let coords = |p: Option<&Param>, name: &str| -> Option<[f64; 3]> {
            let inst = self.f.instances.get(&p?.reference()?)?;
            let v: Vec<f64> = inst
                .record(name)?
                .params
                .get(1)?
                .list()?
                .iter()
                .filter_map(Param::real)
                .collect();
            (v.len() == 3).then(|| [v[0], v[1], v[2]])
        };
        let o = coords(o, "CARTESIAN_POINT")?.map(|c| c * self.unit_mm);
        let unit = |v: [f64; 3]| {
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            (n > 1e-12).then(|| v.map(|c| c / n))
        };
        let z = coords(z, "DIRECTION")
            .and_then(unit)
            .unwrap_or([0.0, 0.0, 1.0]);
        let x = coords(x, "DIRECTION")
            .and_then(unit)
            .unwrap_or(if z[0].abs() < 0.9 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 1.0, 0.0]
            });
        // x made perpendicular to z.
        let d = x[0] * z[0] + x[1] * z[1] + x[2] * z[2];
        let x = unit([x[0] - d * z[0], x[1] - d * z[1], x[2] - d * z[2]])?;
        Some((o, z, x))
    }

    fn tolerance(
        &self,
        id: u64,
        inst: &Instance,
        notes: &mut Vec<String>,
    ) -> Result<Option<GeoTolerance>, StepError> {
        let kind = KINDS.iter().find(|(n, _)| inst.is(n)).map(|(_, k)| *k);
        // The common attributes: the GEOMETRIC_TOLERANCE record of a complex instance,
        // else the one record of a simple subtype.
        let Some(base) = inst
            .record("GEOMETRIC_TOLERANCE")
            .or_else(|| inst.records.first())
        else {
            return Ok(None);
        };
        let name = base
            .params
            .first()
            .and_then(Param::string)
            .unwrap_or("")
            .to_string();
        let value_mm = base
            .params
            .get(2)
            .and_then(Param::reference)
            .and_then(|m| self.measure(m))
            .map(|(v, _)| v);
        let Some(value_mm) = value_mm else {
            notes.push(format!(
                "tolerance `{name}` (#{id}) has no value that can be read"
            ));
            return Ok(None);
        };
        let faces = self.faces_at(&base.params, 3);
        let mut systems = Vec::new();
        if let Some(r) = inst.record("GEOMETRIC_TOLERANCE_WITH_DATUM_REFERENCE") {
            r.params
                .first()
                .into_iter()
                .for_each(|p| collect_refs(p, &mut systems));
        } else if inst.records.len() == 1 {
            // A simple subtype with datums carries them as its fifth attribute.
            base.params
                .get(4)
                .into_iter()
                .for_each(|p| collect_refs(p, &mut systems));
        }
        let datums = self.datum_frame(&systems)?;
        let mut material = None;
        let mut other = Vec::new();
        if let Some(r) = inst.record("GEOMETRIC_TOLERANCE_WITH_MODIFIERS") {
            let mut modifiers = Vec::new();
            r.params
                .first()
                .into_iter()
                .for_each(|p| collect_enums(p, &mut modifiers));
            sort_modifiers(&modifiers, &mut material, &mut other);
        }
        let unequal_mm = inst
            .record("UNEQUALLY_DISPOSED_GEOMETRIC_TOLERANCE")
            .and_then(|r| r.params.first())
            .and_then(Param::reference)
            .and_then(|m| self.measure(m))
            .map(|(v, _)| v);
        let per_unit = self.per_unit(inst);
        let zone = self.zones.get(&id).map(String::as_str);
        if faces.is_empty() {
            notes.push(format!("tolerance `{name}` (#{id}) is linked to no face"));
        }
        if kind.is_none() {
            notes.push(format!(
                "tolerance `{name}` (#{id}) states no type (a bare GEOMETRIC_TOLERANCE)"
            ));
        }
        Ok(Some(GeoTolerance {
            id,
            name,
            kind,
            value_mm,
            diameter: matches!(zone, Some("cylindrical or circular") | Some("spherical")),
            spherical: zone == Some("spherical"),
            material,
            other,
            datums,
            faces,
            composite_of: self.composite.get(&id).copied(),
            unequal_mm,
            per_unit,
        }))
    }

    /// A zone per unit length or area (ISO 10303-47: `unit_size`, and for an area its
    /// `area_type` and, for a rectangle, `second_unit_size`; a circle's `unit_size` is
    /// its diameter).
    fn per_unit(&self, inst: &Instance) -> Option<PerUnitZone> {
        use crate::model::UnitOf;
        let unit = inst.record("GEOMETRIC_TOLERANCE_WITH_DEFINED_UNIT")?;
        let size = |p: Option<&Param>| {
            p.and_then(Param::reference)
                .and_then(|m| self.measure(m))
                .map(|(v, _)| v)
                .filter(|v| v.is_finite() && *v > 0.0)
        };
        let text = |v: Option<f64>| v.map_or("?".to_string(), crate::model::fmt_num);
        let first = size(unit.params.first());
        let (unit, words) = match inst.record("GEOMETRIC_TOLERANCE_WITH_DEFINED_AREA_UNIT") {
            Some(area) => {
                let shape = area
                    .params
                    .first()
                    .and_then(Param::enumeration)
                    .unwrap_or("SQUARE")
                    .to_lowercase();
                let second = size(area.params.get(1));
                match shape.as_str() {
                    "circular" => (
                        first.map(UnitOf::Circle),
                        format!("per Ø{} mm circular area", text(first)),
                    ),
                    _ => {
                        let second = second.or(first);
                        (
                            first.zip(second).map(|(a, b)| UnitOf::Rectangle(a, b)),
                            format!("per {} × {} mm {shape} area", text(first), text(second)),
                        )
                    }
                }
            }
            None => (
                first.map(UnitOf::Length),
                format!("per {} mm length", text(first)),
            ),
        };
        Some(PerUnitZone {
            zone_mm: None,
            unit,
            text: words,
        })
    }

    /// The compartments of the datum systems (or old-style datum references) a
    /// tolerance names, primary first.
    fn datum_frame(&self, systems: &[u64]) -> Result<Vec<DatumRef>, StepError> {
        let mut out = Vec::new();
        let mut precedence = Vec::new();
        for &s in systems {
            let Some(inst) = self.f.instances.get(&s) else {
                continue;
            };
            if let Some(r) = inst.record("DATUM_SYSTEM") {
                for c in r.params.get(4).and_then(Param::list).unwrap_or(&[]) {
                    if let Some(d) = c.reference().map(|c| self.compartment(c)).transpose()? {
                        out.extend(d);
                    }
                }
            } else if let Some(r) = inst.record("DATUM_REFERENCE") {
                // AP214 style: (precedence, datum).
                let p = r.params.first().and_then(Param::real).unwrap_or(0.0);
                let letter = r
                    .params
                    .get(1)
                    .and_then(Param::reference)
                    .and_then(|d| self.letter(d));
                if let Some(letter) = letter {
                    precedence.push((
                        p as i64,
                        DatumRef {
                            letters: vec![letter],
                            material: None,
                            other: Vec::new(),
                        },
                    ));
                }
            } else {
                out.extend(self.compartment(s)?);
            }
        }
        precedence.sort_by_key(|(p, _)| *p);
        out.extend(precedence.into_iter().map(|(_, d)| d));
        Ok(out)
    }

    /// A datum reference compartment (or element) `id`: its datum or common datums
    /// and modifiers, read once; `None` when it is none or names no datum. A common
    /// datum lists further elements: followed on the trail, so one that lists itself
    /// is a `step_cycle` error.
    fn compartment(&self, id: u64) -> Result<Option<DatumRef>, StepError> {
        let Some(inst) = self.f.instances.get(&id) else {
            return Ok(None);
        };
        self.compartments.get_or(id, || {
            self.trail
                .follow(id, inst.line, || self.read_compartment(inst))
        })
    }

    fn read_compartment(&self, inst: &Instance) -> Result<Option<DatumRef>, StepError> {
        let Some(r) = inst
            .record("DATUM_REFERENCE_COMPARTMENT")
            .or_else(|| inst.record("DATUM_REFERENCE_ELEMENT"))
            .or_else(|| inst.record("GENERAL_DATUM_REFERENCE"))
        else {
            return Ok(None);
        };
        let mut d = DatumRef {
            letters: Vec::new(),
            material: None,
            other: Vec::new(),
        };
        match r.params.get(4) {
            Some(Param::Ref(datum)) => d.letters.extend(self.letter(*datum)),
            // A common datum: a list of elements, bare or as COMMON_DATUM_LIST((..)).
            Some(p @ (Param::List(_) | Param::Typed(..))) => {
                let mut elements = Vec::new();
                collect_refs(p, &mut elements);
                for e in elements {
                    if let Some(sub) = self.compartment(e)? {
                        d.letters.extend(sub.letters);
                        d.material = d.material.or(sub.material);
                        d.other.extend(sub.other);
                    }
                }
            }
            _ => {}
        }
        let mut modifiers = Vec::new();
        if let Some(p) = r.params.get(5) {
            collect_enums(p, &mut modifiers);
        }
        sort_modifiers(&modifiers, &mut d.material, &mut d.other);
        // An element named twice is one datum: the lists stay as long as the file's
        // distinct letters, however the elements share each other.
        first_of_each(&mut d.letters);
        first_of_each(&mut d.other);
        Ok((!d.letters.is_empty()).then_some(d))
    }

    fn letter(&self, datum: u64) -> Option<String> {
        self.f
            .instances
            .get(&datum)?
            .record("DATUM")?
            .params
            .get(4)
            .and_then(Param::string)
            .map(str::to_string)
    }

    fn dimension(&self, id: u64, inst: &Instance, notes: &mut Vec<String>) -> Option<Dimension> {
        let (kind, faces, to_faces) = if let Some(r) = inst
            .record("DIMENSIONAL_SIZE")
            .or_else(|| inst.record("ANGULAR_SIZE"))
        {
            let name = r.params.get(1).and_then(Param::string).unwrap_or("size");
            let faces = self.faces_at(&r.params, 0);
            (DimKind::Size(name.to_string()), faces, Vec::new())
        } else if let Some(r) = inst
            .record("DIMENSIONAL_LOCATION")
            .or_else(|| inst.record("ANGULAR_LOCATION"))
            // ISO 10303-47: a location measured from its first feature to its second;
            // the distance between them is the same dimension.
            .or_else(|| inst.record("DIRECTED_DIMENSIONAL_LOCATION"))
        {
            let name = r
                .params
                .first()
                .and_then(Param::string)
                .unwrap_or("location");
            let (from, to) = (self.faces_at(&r.params, 2), self.faces_at(&r.params, 3));
            (DimKind::Location(name.to_string()), from, to)
        } else {
            return None;
        };
        let angular = inst.is("ANGULAR_SIZE") || inst.is("ANGULAR_LOCATION");
        let mut nominal = None;
        let mut upper = None;
        let mut lower = None;
        if let Some(rep) = self
            .nominal_of
            .get(&id)
            .and_then(|r| self.f.instances.get(r))
        {
            let items = rep.records[0]
                .params
                .get(1)
                .and_then(Param::list)
                .unwrap_or(&[]);
            for item in items.iter().filter_map(Param::reference) {
                let Some(i) = self.f.instances.get(&item) else {
                    continue;
                };
                let role = i
                    .record("REPRESENTATION_ITEM")
                    .and_then(|r| r.params.first())
                    .and_then(Param::string)
                    .unwrap_or("");
                let v = self.measure(item).map(|(v, _)| v);
                match role {
                    "upper limit" => upper = v,
                    "lower limit" => lower = v,
                    _ if nominal.is_none() => nominal = v,
                    _ => {}
                }
            }
            if let (Some(n), Some(u), Some(l)) = (nominal, upper, lower) {
                // Limits given as values: keep them as deviations from the nominal.
                upper = Some(tidy(u - n));
                lower = Some(tidy(l - n));
            }
        }
        let mut fit = None;
        if let Some(range) = self
            .limits_of
            .get(&id)
            .and_then(|r| self.f.instances.get(r))
        {
            if let Some(tv) = range.record("TOLERANCE_VALUE") {
                let bound = |i: usize| {
                    tv.params
                        .get(i)
                        .and_then(Param::reference)
                        .and_then(|m| self.measure(m))
                        .map(|(v, _)| v)
                };
                lower = bound(0);
                upper = bound(1);
            } else if let Some(lf) = range.record("LIMITS_AND_FITS") {
                let s = |i: usize| lf.params.get(i).and_then(Param::string).unwrap_or("");
                fit = Some(format!("{}{}", s(1), s(2)).trim().to_string());
            }
        }
        let dim = Dimension {
            id,
            kind,
            angular,
            nominal,
            upper,
            lower,
            fit,
            faces,
            to_faces,
        };
        if dim.faces.is_empty() {
            notes.push(format!("dimension #{id} is linked to no face"));
        }
        Some(dim)
    }

    /// A measure's value in mm (lengths) or degrees (plane angles), and whether it is
    /// an angle ([`measure_value`]).
    fn measure(&self, id: u64) -> Option<(f64, bool)> {
        measure_value(self.f, id, self.unit_mm)
    }
}

/// A measure's value in mm (lengths) or degrees (plane angles), and whether it is an
/// angle: `…_MEASURE_WITH_UNIT(value, unit)` or `MEASURE_REPRESENTATION_ITEM(name,
/// value, unit)`, simple or in a complex instance.
///
/// **Decision: the unit says what a value measures.** ISO 10303-41 types a measure's
/// value (`LENGTH_MEASURE(…)`, `PLANE_ANGLE_MEASURE(…)`) and names its unit; the two
/// should agree, and where an exporter writes them apart (a size limit typed as a plane
/// angle with the inch as its unit) the unit wins: a number in inches is a length
/// whatever its type says, and taking it raw read a limit 25.4 times too tight. Only a
/// value whose unit cannot be read falls back on its type, in the file's length unit or
/// in degrees.
fn measure_value(f: &P21, id: u64, unit_mm: f64) -> Option<(f64, bool)> {
    let inst = f.instances.get(&id)?;
    let (value, kind, unit) = inst.records.iter().find_map(|r| {
        let at = |i: usize| -> Option<(f64, &str, u64)> {
            let v = r.params.get(i)?;
            let kind = match v {
                Param::Typed(t) => t.name.as_str(),
                _ => "",
            };
            Some((v.real()?, kind, r.params.get(i + 1)?.reference()?))
        };
        at(0).or_else(|| at(1))
    })?;
    let unit = f.instances.get(&unit);
    let length = unit.and_then(|u| unit_factor(f, u, "METRE", 1000.0, 0).ok());
    let angle = unit.and_then(|u| unit_factor(f, u, "RADIAN", 1.0, 0).ok());
    match (length, angle) {
        (Some((mm, _)), _) => Some((tidy(value * mm), false)),
        (None, Some((rad, _))) => Some((tidy((value * rad).to_degrees()), true)),
        _ if kind.contains("ANGLE") => Some((tidy(value), true)),
        _ => Some((tidy(value * unit_mm), false)),
    }
}

/// Modifiers by their enumeration: the material ones to `material`, the rest, in words,
/// to `other` (`tangent plane`, `free state`).
fn sort_modifiers(modifiers: &[String], material: &mut Option<Material>, other: &mut Vec<String>) {
    for m in modifiers {
        match m.as_str() {
            "MAXIMUM_MATERIAL_REQUIREMENT" => *material = Some(Material::Mmc),
            "LEAST_MATERIAL_REQUIREMENT" => *material = Some(Material::Lmc),
            e => other.push(e.to_lowercase().replace('_', " ")),
        }
    }
}

/// The enumerations in a modifier list (`SIMPLE_DATUM_REFERENCE_MODIFIER(.X.)`).
fn collect_enums(p: &Param, out: &mut Vec<String>) {
    match p {
        Param::Enum(e) => out.push(e.to_string()),
        Param::List(v) => v.iter().for_each(|q| collect_enums(q, out)),
        Param::Typed(t) => t.params.iter().for_each(|q| collect_enums(q, out)),
        _ => {}
    }
}

/// Keeps the first of each repeated string, in order.
fn first_of_each(v: &mut Vec<String>) {
    let mut seen = std::collections::HashSet::new();
    v.retain(|s| seen.insert(s.clone()));
}

/// A converted value rounded to 1e-9 of its unit, so that 0.015 in reads 0.381 mm.
fn tidy(x: f64) -> f64 {
    (x * 1e9).round() / 1e9
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One measure per case exporters write, against a millimetre and an inch unit,
    /// a radian and a degree.
    const MEASURES: &str = "ISO-10303-21;
HEADER;
FILE_SCHEMA(('AP242_MANAGED_MODEL_BASED_3D_ENGINEERING_MIM_LF'));
ENDSEC;
DATA;
#1=(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.));
#2=(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.));
#3=DIMENSIONAL_EXPONENTS(1.,0.,0.,0.,0.,0.,0.);
#4=LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4),#1);
#5=(CONVERSION_BASED_UNIT('INCH',#4)LENGTH_UNIT()NAMED_UNIT(#3));
#6=DIMENSIONAL_EXPONENTS(0.,0.,0.,0.,0.,0.,0.);
#7=PLANE_ANGLE_MEASURE_WITH_UNIT(PLANE_ANGLE_MEASURE(0.0174532925199433),#2);
#8=(CONVERSION_BASED_UNIT('DEGREE',#7)NAMED_UNIT(#6)PLANE_ANGLE_UNIT());
#10=LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(0.5),#1);
#11=LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(0.015),#5);
#12=(MEASURE_REPRESENTATION_ITEM()MEASURE_WITH_UNIT(PLANE_ANGLE_MEASURE(0.015),#5)REPRESENTATION_ITEM('upper limit'));
#13=PLANE_ANGLE_MEASURE_WITH_UNIT(PLANE_ANGLE_MEASURE(30.),#8);
#14=PLANE_ANGLE_MEASURE_WITH_UNIT(PLANE_ANGLE_MEASURE(0.5235987755982988),#2);
#15=MEASURE_REPRESENTATION_ITEM('angle',LENGTH_MEASURE(45.),#8);
#16=MEASURE_REPRESENTATION_ITEM('size',POSITIVE_LENGTH_MEASURE(2.),#99);
#17=MEASURE_REPRESENTATION_ITEM('angle',PLANE_ANGLE_MEASURE(10.),#99);
ENDSEC;
END-ISO-10303-21;
";

    #[test]
    fn measures_take_the_dimension_of_their_unit() {
        let f = super::super::p21::parse(MEASURES.as_bytes()).unwrap();
        let at = |id| measure_value(&f, id, 25.4).unwrap();
        // Millimetres and inches.
        assert_eq!(at(10), (0.5, false));
        assert_eq!(at(11), (0.381, false));
        // Typed as a plane angle with the inch as its unit: a length in inches.
        assert_eq!(at(12), (0.381, false));
        // Degrees and radians.
        assert_eq!(at(13), (30.0, true));
        assert_eq!(at(14), (30.0, true));
        // Typed as a length with the degree as its unit: an angle.
        assert_eq!(at(15), (45.0, true));
        // A unit that cannot be read: the type says, in the file's length unit.
        assert_eq!(at(16), (50.8, false));
        assert_eq!(at(17), (10.0, true));
    }
}
