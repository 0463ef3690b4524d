//! The PMI of a QIF document in the same terms as the STEP reader's: datums (from
//! feature nominals or datum targets), geometric characteristics with their datum
//! reference frames, and sizes and distances with their limits, each linked to faces.
//!
//! QIF links a characteristic nominal to feature nominals, and a feature nominal to the
//! topology by `EntityInternalIds`: faces, or edges (a hole named by its rim is its
//! curved faces, as in the STEP reader). Reading never fails; what cannot be linked is a
//! note.

use super::doc::Doc;
use super::refs;
use super::xml::Node;
use super::QifError;
use crate::geometry::step::pmi::{
    Datum, DatumRef, DimKind, Dimension, GeoTolerance, PerUnitZone, Pmi, Target,
};
use crate::model::{Material, TolKind};
use std::cell::Cell;
use std::collections::{BTreeSet, HashMap};

/// Geometric characteristics by their QIF element, without `CharacteristicDefinition`.
const KINDS: &[(&str, TolKind)] = &[
    ("Flatness", TolKind::Flatness),
    ("Straightness", TolKind::Straightness),
    ("Circularity", TolKind::Circularity),
    ("Cylindricity", TolKind::Cylindricity),
    ("LineProfile", TolKind::ProfileLine),
    ("SurfaceProfile", TolKind::ProfileSurface),
    ("SurfaceProfileNonUniform", TolKind::ProfileSurface),
    ("Perpendicularity", TolKind::Perpendicularity),
    ("Parallelism", TolKind::Parallelism),
    ("Angularity", TolKind::Angularity),
    ("Position", TolKind::Position),
    ("Concentricity", TolKind::Concentricity),
    ("Coaxiality", TolKind::Coaxiality),
    ("Symmetry", TolKind::Symmetry),
    ("CircularRunout", TolKind::CircularRunout),
    ("TotalRunout", TolKind::TotalRunout),
];

/// Sizes by their QIF element, as the STEP reader names them.
const SIZES: &[(&str, &str, bool)] = &[
    ("Diameter", "diameter", false),
    ("Radius", "radius", false),
    ("SphericalDiameter", "spherical diameter", false),
    ("SphericalRadius", "spherical radius", false),
    ("Width", "width", false),
    ("Length", "length", false),
    ("Height", "height", false),
    ("Depth", "depth", false),
    ("Thickness", "thickness", false),
    ("Angle", "angle", true),
];

/// Locations between two features, as the STEP reader names them.
const LOCATIONS: &[(&str, &str, bool)] = &[
    ("DistanceBetween", "linear distance", false),
    ("DistanceFrom", "linear distance", false),
    ("AngleBetween", "angle", true),
    ("AngleFrom", "angle", true),
];

struct Reader<'a> {
    d: &'a Doc<'a>,
    /// Face id → 0-based face index.
    face_index: HashMap<u64, usize>,
    /// Edge id → the faces it names.
    edge_faces: &'a HashMap<u64, Vec<usize>>,
    /// Length unit name → millimetres.
    units: HashMap<String, f64>,
    notes: Vec<String>,
    /// Feature nominal → its faces, once walked.
    features: HashMap<u64, BTreeSet<usize>>,
    /// How many more elements the feature walks may enter ([`refs::budget`]).
    visits: Cell<usize>,
    /// Whether a walk stopped at the budget.
    out_of_budget: bool,
    /// The first circle of features found: the document's error.
    error: Option<QifError>,
}

/// Reads the PMI of a document whose faces (in numbering order) have the ids `faces`;
/// features that name each other round a circle are a `qif_cycle` error.
pub fn read(
    d: &Doc,
    root: &Node,
    faces: &[u64],
    edge_faces: &HashMap<u64, Vec<usize>>,
) -> Result<Pmi, QifError> {
    let mut r = Reader {
        d,
        face_index: faces.iter().enumerate().map(|(i, id)| (*id, i)).collect(),
        edge_faces,
        units: length_units(root),
        notes: Vec::new(),
        features: HashMap::new(),
        visits: refs::budget(d.ids.len()),
        out_of_budget: false,
        error: None,
    };
    let mut pmi = Pmi::default();
    let letters = r.datums(root, &mut pmi.datums);
    let frames: HashMap<u64, Vec<DatumRef>> = root
        .child("DatumReferenceFrames")
        .into_iter()
        .flat_map(|n| n.all("DatumReferenceFrame"))
        .filter_map(|f| Some((f.id()?, frame(f, &letters))))
        .collect();

    let defs: HashMap<u64, &Node> = root
        .at(&["Characteristics", "CharacteristicDefinitions"])
        .map(|n| {
            n.children
                .iter()
                .filter_map(|c| Some((c.id()?, c)))
                .collect()
        })
        .unwrap_or_default();
    let nominals = root
        .at(&["Characteristics", "CharacteristicNominals"])
        .map(|n| &n.children[..])
        .unwrap_or_default();
    for nom in nominals {
        r.characteristic(nom, &defs, &frames, &mut pmi);
    }
    if let Some(e) = r.error {
        return Err(e);
    }
    if r.out_of_budget {
        r.notes.push(
            "the features name each other more often than the document has elements: the rest of their links are not followed".into(),
        );
    }
    pmi.notes = r.notes;
    Ok(pmi)
}

/// A characteristic nominal being read: its id, name, node, definition and the feature
/// nominals it names.
struct Nominal<'n> {
    id: u64,
    name: String,
    node: &'n Node,
    def: &'n Node,
    feats: Vec<u64>,
}

impl Reader<'_> {
    /// Reads the datum definitions into `datums`, each linked to the faces of its
    /// feature nominals and targets; returns each definition's letter by its id.
    fn datums(&mut self, root: &Node, datums: &mut Vec<Datum>) -> HashMap<u64, String> {
        let mut letters: HashMap<u64, String> = HashMap::new();
        let targets: HashMap<u64, &Node> = root
            .child("DatumTargetDefinitions")
            .map(|t| {
                t.children
                    .iter()
                    .filter_map(|n| Some((n.id()?, n)))
                    .collect()
            })
            .unwrap_or_default();
        for dd in root
            .child("DatumDefinitions")
            .into_iter()
            .flat_map(|n| n.all("DatumDefinition"))
        {
            let letter = dd.text_at(&["DatumLabel"]).unwrap_or("").trim().to_string();
            let id = dd.id().unwrap_or(0);
            letters.insert(id, letter.clone());
            let mut faces = BTreeSet::new();
            for f in Doc::id_list(dd, "FeatureNominalIds") {
                faces.extend(self.feature_faces(f, &format!("datum {letter}")));
            }
            let mut tlist = Vec::new();
            for t in Doc::id_list(dd, "DatumTargetIds") {
                let Some(tn) = targets.get(&t) else {
                    self.notes
                        .push(format!("datum {letter}: target {t} is not in the file"));
                    continue;
                };
                if let Some(f) = tn
                    .text_at(&["FeatureNominalId"])
                    .and_then(|x| x.trim().parse().ok())
                {
                    faces.extend(self.feature_faces(f, &format!("datum {letter}")));
                }
                tlist.push(self.target(tn));
            }
            if faces.is_empty() {
                self.notes
                    .push(format!("datum {letter} is linked to no face"));
            }
            datums.push(Datum {
                id,
                letter,
                faces: faces.into_iter().collect(),
                targets: tlist,
                located: false,
            });
        }
        letters
    }

    /// Reads one characteristic nominal into `pmi`: a geometric tolerance, a size or a
    /// location by its element's name; a note for one whose definition is not in the
    /// file or whose kind inspc does not read.
    fn characteristic(
        &mut self,
        nom: &Node,
        defs: &HashMap<u64, &Node>,
        frames: &HashMap<u64, Vec<DatumRef>>,
        pmi: &mut Pmi,
    ) {
        let Some(kind) = nom.name.strip_suffix("CharacteristicNominal") else {
            return;
        };
        let name = nom.text_at(&["Name"]).unwrap_or(kind).trim().to_string();
        let id = nom.id().unwrap_or(0);
        let Some(def) = nom
            .text_at(&["CharacteristicDefinitionId"])
            .and_then(|t| t.trim().parse().ok())
            .and_then(|i| defs.get(&i))
        else {
            self.notes
                .push(format!("{name}: its definition is not in the file"));
            return;
        };
        let n = Nominal {
            id,
            name,
            node: nom,
            def,
            feats: Doc::id_list(nom, "FeatureNominalIds"),
        };
        if let Some((_, tk)) = KINDS.iter().find(|(k, _)| *k == kind) {
            pmi.tolerances.extend(self.geometric(&n, *tk, frames));
        } else if let Some((_, label, angular)) = SIZES.iter().find(|(k, _, _)| *k == kind) {
            pmi.dimensions.push(self.size(&n, label, *angular));
        } else if let Some((_, label, angular)) = LOCATIONS.iter().find(|(k, _, _)| *k == kind) {
            pmi.dimensions.push(self.location(&n, label, *angular));
        } else {
            self.notes.push(format!(
                "{}: a {kind} characteristic, which inspc does not read",
                n.name
            ));
        }
    }

    /// A geometric tolerance of kind `tk`, and the lower segment of a composite one.
    fn geometric(
        &mut self,
        n: &Nominal,
        tk: TolKind,
        frames: &HashMap<u64, Vec<DatumRef>>,
    ) -> Vec<GeoTolerance> {
        let faces = self.features_faces(&n.feats, &n.name);
        let upper = self.tolerance(n.id, &n.name, tk, n.def, frames, faces.clone());
        let mut out = vec![upper];
        if let Some(lower) = n
            .def
            .children
            .iter()
            .find(|c| c.name.starts_with("SecondCompositeSegment"))
        {
            let mut t = self.tolerance(
                n.id,
                &format!("{} (lower segment)", n.name),
                tk,
                lower,
                frames,
                faces,
            );
            t.composite_of = Some(n.id);
            out.push(t);
        }
        out
    }

    /// A size named `label` (angular or not).
    fn size(&mut self, n: &Nominal, label: &str, angular: bool) -> Dimension {
        let faces = self.features_faces(&n.feats, &n.name);
        // The angle of a feature of two planes (a V) is the angle between them, as
        // STEP files state it.
        let (kind, from, to) = match (label, faces.as_slice()) {
            ("angle", [a, rest @ ..]) if !rest.is_empty() => (
                DimKind::Location("angle".to_string()),
                vec![*a],
                rest.to_vec(),
            ),
            _ => (DimKind::Size(label.to_string()), faces, Vec::new()),
        };
        self.dimension(n.id, kind, angular, n.node, n.def, from, to)
    }

    /// A location named `label` (angular or not) from the first feature to the second.
    fn location(&mut self, n: &Nominal, label: &str, angular: bool) -> Dimension {
        let (from, to) = match n.feats.as_slice() {
            [a, b, ..] => (
                self.feature_faces(*a, &n.name),
                self.feature_faces(*b, &n.name),
            ),
            [a] => (self.feature_faces(*a, &n.name), BTreeSet::new()),
            [] => (BTreeSet::new(), BTreeSet::new()),
        };
        self.dimension(
            n.id,
            DimKind::Location(label.to_string()),
            angular,
            n.node,
            n.def,
            from.into_iter().collect(),
            to.into_iter().collect(),
        )
    }
}

/// The length units the document names, in millimetres.
fn length_units(root: &Node) -> HashMap<String, f64> {
    let mut out = HashMap::new();
    let Some(fu) = root.child("FileUnits") else {
        return out;
    };
    let mut all = Vec::new();
    fu.walk(&mut all);
    for u in all
        .into_iter()
        .filter(|n| n.name == "LinearUnit" || n.name == "PMILinearUnit")
    {
        let Some(name) = u.text_at(&["UnitName"]) else {
            continue;
        };
        if let Some(mm) = super::unit_mm(u) {
            out.insert(name.trim().to_string(), mm);
        }
    }
    out
}

/// One datum reference frame, primary first.
fn frame(f: &Node, letters: &HashMap<u64, String>) -> Vec<DatumRef> {
    let mut out: Vec<(i64, DatumRef)> = Vec::new();
    let Some(ds) = f.child("Datums") else {
        return Vec::new();
    };
    for (k, d) in ds.all("Datum").enumerate() {
        let rank = match d.text_at(&["Precedence", "PrecedenceEnum"]).map(str::trim) {
            Some("PRIMARY") => 0,
            Some("SECONDARY") => 1,
            Some("TERTIARY") => 2,
            _ => 3 + k as i64,
        };
        let simple = |s: &Node| -> (Option<String>, Option<Material>) {
            let letter = s
                .text_at(&["DatumDefinitionId"])
                .and_then(|t| t.trim().parse::<u64>().ok())
                .and_then(|i| letters.get(&i).cloned());
            (letter, material(s.text_at(&["MaterialModifier"])))
        };
        let r = if let Some(s) = d.child("SimpleDatum") {
            let (l, m) = simple(s);
            DatumRef {
                letters: l.into_iter().collect(),
                material: m,
                other: Vec::new(),
            }
        } else if let Some(c) = d.child("CompoundDatum") {
            let parts: Vec<_> = c
                .all("Datum")
                .filter_map(|x| x.child("SimpleDatum"))
                .map(simple)
                .collect();
            DatumRef {
                letters: parts.iter().filter_map(|p| p.0.clone()).collect(),
                material: parts.iter().find_map(|p| p.1),
                other: Vec::new(),
            }
        } else {
            continue;
        };
        out.push((rank, r));
    }
    out.sort_by_key(|(rank, _)| *rank);
    out.into_iter().map(|(_, r)| r).collect()
}

fn material(m: Option<&str>) -> Option<Material> {
    match m.map(str::trim) {
        Some("MAXIMUM") => Some(Material::Mmc),
        Some("LEAST") => Some(Material::Lmc),
        Some("REGARDLESS") => Some(Material::Rfs),
        _ => None,
    }
}

impl Reader<'_> {
    /// The faces of several feature nominals together, sorted.
    fn features_faces(&mut self, ids: &[u64], who: &str) -> Vec<usize> {
        let all: BTreeSet<usize> = ids
            .iter()
            .flat_map(|f| self.feature_faces(*f, who))
            .collect();
        all.into_iter().collect()
    }

    /// The faces of a feature nominal (through compound features, walked by
    /// [`refs::reachable`] and remembered by id), noting one that names nothing on the
    /// part. A circle of features is the document's error ([`Reader::error`]).
    fn feature_faces(&mut self, id: u64, who: &str) -> BTreeSet<usize> {
        let out = match self.features.get(&id) {
            Some(faces) => faces.clone(),
            None => {
                let faces = self.walk_feature(id);
                self.features.insert(id, faces.clone());
                faces
            }
        };
        if out.is_empty() {
            self.notes.push(format!(
                "{who}: feature {id} is linked to no face of the part"
            ));
        }
        out
    }

    fn walk_feature(&mut self, id: u64) -> BTreeSet<usize> {
        let next = |n: u64| -> Vec<u64> {
            if self.face_index.contains_key(&n) || self.edge_faces.contains_key(&n) {
                return Vec::new();
            }
            let Some(node) = self.d.ids.get(&n) else {
                return Vec::new();
            };
            let mut ids = Doc::id_list(node, "EntityInternalIds");
            ids.extend(Doc::id_list(node, "FeatureNominalIds"));
            ids
        };
        let line_of = |n: u64| self.d.ids.get(&n).map_or(0, |e| e.line);
        let ids = match refs::reachable(id, next, line_of, &self.visits) {
            Ok(Some(ids)) => ids,
            Ok(None) => {
                self.out_of_budget = true;
                return BTreeSet::new();
            }
            Err(e) => {
                self.error.get_or_insert(e);
                return BTreeSet::new();
            }
        };
        let mut out = BTreeSet::new();
        for n in ids {
            if let Some(i) = self.face_index.get(&n) {
                out.insert(*i);
            } else if let Some(fs) = self.edge_faces.get(&n) {
                out.extend(fs.iter().copied());
            }
        }
        out
    }

    /// A length value in millimetres, through its `linearUnit` attribute (else the
    /// file's unit).
    fn length(&mut self, n: &Node) -> Option<f64> {
        let x: f64 = n.text.trim().parse().ok().filter(|x: &f64| x.is_finite())?;
        let unit = match n.attr("linearUnit") {
            Some(u) => match self
                .units
                .get(u.trim())
                .copied()
                .or_else(|| super::named_unit_mm(u.trim()))
            {
                Some(mm) => mm,
                None => {
                    self.notes.push(format!(
                        "a value in `{u}`, a unit the file does not define, is read in the file's unit"
                    ));
                    self.d.value_unit
                }
            },
            None => self.d.value_unit,
        };
        Some(x * unit)
    }

    fn target(&self, t: &Node) -> Target {
        let label = t
            .text_at(&["DatumTargetLabel"])
            .unwrap_or("")
            .trim()
            .to_string();
        let zone = t
            .text_at(&["TargetZoneId"])
            .and_then(|z| z.trim().parse().ok())
            .and_then(|z| self.d.ids.get(&z).copied());
        let mut points = Vec::new();
        let kind = match zone {
            Some(z) => {
                let mut all = Vec::new();
                z.walk(&mut all);
                for n in all {
                    if matches!(
                        n.name.as_str(),
                        "StartPoint" | "EndPoint" | "Point" | "Location" | "Center"
                    ) {
                        if let Some(v) = n.numbers().filter(|v| v.len() == 3) {
                            points.push([v[0], v[1], v[2]].map(|c| c * self.d.unit));
                        }
                    }
                }
                let k = z
                    .name
                    .trim_start_matches("FeatureZone")
                    .to_ascii_lowercase();
                if k.contains("line") {
                    "line".to_string()
                } else if k.contains("point") {
                    "point".to_string()
                } else if k.contains("circ") {
                    "circle".to_string()
                } else {
                    "area".to_string()
                }
            }
            None => "area".to_string(),
        };
        Target {
            kind,
            label,
            points,
            model_unit_points: Vec::new(),
        }
    }

    fn tolerance(
        &mut self,
        id: u64,
        name: &str,
        kind: TolKind,
        def: &Node,
        frames: &HashMap<u64, Vec<DatumRef>>,
        faces: Vec<usize>,
    ) -> GeoTolerance {
        let mut value = def.child("ToleranceValue").and_then(|v| self.length(v));
        let mut per_unit = self.per_unit(def);
        // A zone per unit alone: the tolerance's value is that zone (as in STEP).
        if let (None, Some(p)) = (value, per_unit.as_mut()) {
            value = p.zone_mm.take();
        }
        // A zone per unit alone (the schema's second choice) has no whole-feature value.
        if value.is_none() && per_unit.is_none() {
            self.notes
                .push(format!("{name}: its tolerance value cannot be read"));
        }
        let zone = def.child("ZoneShape").and_then(|z| z.children.first());
        let zone = zone.map(|z| z.name.as_str()).unwrap_or("");
        let mut other = Vec::new();
        if def.text_at(&["FreeState"]).map(str::trim) == Some("true") {
            other.push("free state".to_string());
        }
        if def.text_at(&["TangentPlane"]).map(str::trim) == Some("true") {
            other.push("tangent plane".to_string());
        }
        let datums = match def
            .text_at(&["DatumReferenceFrameId"])
            .and_then(|t| t.trim().parse::<u64>().ok())
        {
            Some(f) => match frames.get(&f) {
                Some(d) => d.clone(),
                None => {
                    self.notes.push(format!(
                        "{name}: its datum reference frame {f} is not in the file"
                    ));
                    Vec::new()
                }
            },
            None => Vec::new(),
        };
        GeoTolerance {
            id,
            name: name.to_string(),
            kind: Some(kind),
            value_mm: value.unwrap_or(0.0),
            diameter: zone == "DiametricalZone" || zone == "SphericalZone",
            spherical: zone == "SphericalZone",
            material: material(def.text_at(&["MaterialCondition"])),
            other,
            datums,
            faces,
            composite_of: None,
            unequal_mm: None,
            per_unit,
        }
    }

    /// A zone per unit length or area (`ToleranceZonePerUnitLength`, `…PerUnitArea`:
    /// QIF 3 IntermediatesPMI.xsd, its zone `ToleranceValuePerUnit`).
    fn per_unit(&mut self, def: &Node) -> Option<PerUnitZone> {
        use crate::model::UnitOf;
        let fmt = |v: Option<f64>| v.map_or("?".to_string(), crate::model::fmt_num);
        let positive = |v: Option<f64>| v.filter(|x| x.is_finite() && *x > 0.0);
        let (node, unit, text) = if let Some(u) = def.child("ToleranceZonePerUnitLength") {
            let l = positive(u.child("UnitLength").and_then(|v| self.length(v)));
            (
                u,
                l.map(UnitOf::Length),
                format!("per {} mm length", fmt(l)),
            )
        } else {
            let a = def.child("ToleranceZonePerUnitArea")?;
            if let Some(r) = a.child("RectangularUnitArea") {
                let length = positive(
                    r.child("RectangularUnitAreaLength")
                        .and_then(|v| self.length(v)),
                );
                let width = positive(
                    r.child("RectangularUnitAreaWidth")
                        .and_then(|v| self.length(v)),
                );
                (
                    a,
                    length.zip(width).map(|(l, w)| UnitOf::Rectangle(l, w)),
                    format!("per {} × {} mm rectangular area", fmt(length), fmt(width)),
                )
            } else {
                let d = positive(
                    a.child("CircularUnitArea")
                        .and_then(|c| c.child("CircularUnitAreaDiameter"))
                        .and_then(|v| self.length(v)),
                );
                (
                    a,
                    d.map(UnitOf::Circle),
                    format!("per Ø{} mm circular area", fmt(d)),
                )
            }
        };
        let zone_mm = node
            .child("ToleranceValuePerUnit")
            .and_then(|v| self.length(v));
        Some(PerUnitZone {
            zone_mm,
            unit,
            text,
        })
    }

    #[allow(clippy::too_many_arguments)]
    fn dimension(
        &mut self,
        id: u64,
        kind: DimKind,
        angular: bool,
        nom: &Node,
        def: &Node,
        faces: Vec<usize>,
        to_faces: Vec<usize>,
    ) -> Dimension {
        let value = |r: &mut Self, n: &Node| -> Option<f64> {
            if angular {
                n.text.trim().parse().ok().filter(|x: &f64| x.is_finite())
            } else {
                r.length(n)
            }
        };
        let nominal = nom.child("TargetValue").and_then(|v| value(self, v));
        let (mut upper, mut lower) = (None, None);
        if let Some(t) = def.child("Tolerance") {
            let hi = t.child("MaxValue").and_then(|v| value(self, v));
            let lo = t.child("MinValue").and_then(|v| value(self, v));
            let limit = t.text_at(&["DefinedAsLimit"]).map(str::trim) == Some("true");
            match (hi, lo, nominal) {
                (Some(h), Some(l), Some(n)) if limit => {
                    upper = Some(h - n);
                    lower = Some(l - n);
                }
                (Some(h), Some(l), _) if !limit => {
                    upper = Some(h);
                    lower = Some(l);
                }
                _ => {}
            }
        }
        Dimension {
            id,
            kind,
            angular,
            nominal,
            upper,
            lower,
            fit: None,
            faces,
            to_faces,
        }
    }
}
