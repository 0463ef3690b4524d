//! The report's tolerance rows as QIF characteristics (definition, nominal, item and
//! measurement), and the datums and datum reference frames they name.
//!
//! **Tolerances** (the DMIS word → the QIF characteristic): `FLAT` → Flatness, `STRGHT`
//! → Straightness, `CIRLTY` → Circularity, `CYLCTY` → Cylindricity, `PROFL` →
//! LineProfile, `PROFS` → SurfaceProfile, `PROFP` → PointProfile, `PERP` →
//! Perpendicularity, `PARLEL` → Parallelism, `ANGLR` → Angularity, `POS` → Position,
//! `CONCEN` → Concentricity, `COAXL` → Coaxiality, `SYM` → Symmetry, `CRNOUT` →
//! CircularRunout, `TRNOUT` → TotalRunout, `DIAM` → Diameter, `RAD` → Radius, `WIDTH`
//! → Width, `DISTB` → DistanceBetween, `ANGLB` → AngleBetween. Any other word has no
//! counterpart inspc knows: it is written as a UserDefinedLinear characteristic whose
//! `WhatToMeasure` names the DMIS word, with an XML comment saying so — no row is ever
//! left out. A tolerance not judged (its actual is not a number) is measured with
//! status `NOT_ANALYZED` (`CharacteristicStatusEnumType` has no NOT_MEASURED; that
//! word is the document's `InspectionStatusEnumType`) and no value; its note is the
//! measurement's `Description`.
//!
//! **Zones and modifiers** come from the program's `TOL` statements ([`QifMeta`]): the
//! tolerance value as stated, `MMC`/`LMC`/`RFS` (QIF's MAXIMUM/LEAST/REGARDLESS, NONE
//! without a word), `2D`/`3D` for a position (a diametrical or a width zone) and a
//! datum's modifier. A tolerance the program does not define falls back on the report:
//! its upper limit (the zone plus any bonus) is the tolerance value and the zone shape
//! follows the feature (an axis or a circle: diametrical). A position's MMC bonus is
//! the measurement's `Bonus`.

use super::features::{Feats, Shape};
use super::xml::{dec, nmtoken, v3, Ids, Xml};
use super::QifMeta;
use crate::simulate::evaluate::TolDef;
use crate::simulate::{Report, Row};
use std::collections::BTreeMap;

/// The datum labels and the datum reference frames (a list of datums with their
/// material modifiers) the tolerances name, with their ids.
pub(super) struct Datums {
    labels: Vec<(String, u32)>,
    frames: Vec<(Vec<(String, &'static str)>, u32)>,
}

/// A datum's or a zone's DMIS material word as QIF's `MaterialModifierEnumType`.
fn modifier(word: Option<&str>) -> &'static str {
    match word {
        Some("MMC") => "MAXIMUM",
        Some("LMC") => "LEAST",
        Some("RFS") => "REGARDLESS",
        _ => "NONE",
    }
}

/// A row's datums with their modifiers, from its `TOL` statement where there is one.
fn frame_of(row: &Row, meta: &QifMeta) -> Vec<(String, &'static str)> {
    let params = meta.tolerances.get(&row.tolerance);
    row.datums
        .iter()
        .map(|d| {
            let word = params.and_then(|p| {
                let k = p.iter().position(|s| *s == format!("DAT({d})"))?;
                p.get(k + 1).map(String::as_str)
            });
            (d.clone(), modifier(word))
        })
        .collect()
}

impl Datums {
    pub(super) fn new(report: &Report, meta: &QifMeta, ids: &mut Ids) -> Datums {
        let mut d = Datums {
            labels: Vec::new(),
            frames: Vec::new(),
        };
        for row in &report.rows {
            for l in &row.datums {
                if !d.labels.iter().any(|(m, _)| m == l) {
                    d.labels.push((l.clone(), ids.take()));
                }
            }
        }
        for row in &report.rows {
            if row.datums.is_empty() || !Kind::of(&row.kind).class.has_drf() {
                continue;
            }
            let f = frame_of(row, meta);
            if !d.frames.iter().any(|(g, _)| *g == f) {
                d.frames.push((f, ids.take()));
            }
        }
        d
    }

    fn frame_id(&self, row: &Row, meta: &QifMeta) -> Option<u32> {
        if row.datums.is_empty() {
            return None;
        }
        let f = frame_of(row, meta);
        self.frames.iter().find(|(g, _)| *g == f).map(|(_, id)| *id)
    }

    pub(super) fn write(&self, x: &mut Xml) {
        if self.labels.is_empty() {
            return;
        }
        x.list("DatumDefinitions", self.labels.len(), |x| {
            for (l, id) in &self.labels {
                x.el("DatumDefinition", &[("id", &id.to_string())], |x| {
                    x.text("DatumLabel", &nmtoken(l))
                });
            }
        });
        if self.frames.is_empty() {
            return;
        }
        const PRECEDENCE: [&str; 5] = ["PRIMARY", "SECONDARY", "TERTIARY", "QUATERNARY", "QUINARY"];
        let label_id = |l: &str| self.labels.iter().find(|(m, _)| m == l).map_or(0, |d| d.1);
        x.list("DatumReferenceFrames", self.frames.len(), |x| {
            for (f, id) in &self.frames {
                x.el("DatumReferenceFrame", &[("id", &id.to_string())], |x| {
                    // QIF takes at most five datums in a frame.
                    let kept = &f[..f.len().min(PRECEDENCE.len())];
                    x.list("Datums", kept.len(), |x| {
                        for ((l, m), precedence) in kept.iter().zip(PRECEDENCE) {
                            x.el("Datum", &[], |x| {
                                x.el("SimpleDatum", &[], |x| {
                                    x.text("DatumDefinitionId", &label_id(l).to_string());
                                    x.text("MaterialModifier", m);
                                    x.text("ReferencedComponent", "ACTUAL");
                                });
                                x.wrap("Precedence", "PrecedenceEnum", precedence);
                            });
                        }
                    });
                    if f.len() > kept.len() {
                        let names: Vec<&str> = f.iter().map(|(l, _)| l.as_str()).collect();
                        x.text(
                            "Description",
                            &format!("datums {} (QIF keeps the first five)", names.join(", ")),
                        );
                    }
                });
            }
        });
    }
}

/// What a characteristic's definition holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Class {
    /// Flatness, straightness, circularity, cylindricity: a zone, no datums.
    Form,
    /// Line, surface, point profile: a zone, datums.
    Profile,
    /// Perpendicularity, parallelism, angularity: a zone, datums, a material condition
    /// and a planar or diametrical zone.
    Orientation,
    /// Position, concentricity, coaxiality, symmetry.
    Location,
    /// Circular and total runout.
    Runout,
    /// A size or distance with limits (mm).
    Linear,
    /// An angle with limits (degrees).
    Angular,
    /// No QIF counterpart: a user-defined linear characteristic.
    Generic,
}

impl Class {
    /// Whether its definition names a datum reference frame.
    fn has_drf(self) -> bool {
        matches!(
            self,
            Class::Profile | Class::Orientation | Class::Location | Class::Runout
        )
    }
}

/// A DMIS tolerance word as a QIF characteristic: `{stem}Characteristic…`.
#[derive(Debug, Clone, Copy)]
struct Kind {
    stem: &'static str,
    class: Class,
}

impl Kind {
    fn of(word: &str) -> Kind {
        let (stem, class) = match word {
            "FLAT" => ("Flatness", Class::Form),
            "STRGHT" => ("Straightness", Class::Form),
            "CIRLTY" => ("Circularity", Class::Form),
            "CYLCTY" => ("Cylindricity", Class::Form),
            "PROFL" => ("LineProfile", Class::Profile),
            "PROFS" => ("SurfaceProfile", Class::Profile),
            "PROFP" => ("PointProfile", Class::Profile),
            "PERP" => ("Perpendicularity", Class::Orientation),
            "PARLEL" => ("Parallelism", Class::Orientation),
            "ANGLR" => ("Angularity", Class::Orientation),
            "POS" => ("Position", Class::Location),
            "CONCEN" => ("Concentricity", Class::Location),
            "COAXL" => ("Coaxiality", Class::Location),
            "SYM" => ("Symmetry", Class::Location),
            "CRNOUT" => ("CircularRunout", Class::Runout),
            "TRNOUT" => ("TotalRunout", Class::Runout),
            "DIAM" => ("Diameter", Class::Linear),
            "RAD" => ("Radius", Class::Linear),
            "WIDTH" => ("Width", Class::Linear),
            "DISTB" => ("DistanceBetween", Class::Linear),
            "ANGLB" => ("AngleBetween", Class::Angular),
            _ => ("UserDefinedLinear", Class::Generic),
        };
        Kind { stem, class }
    }
}

/// One tolerance row with the ids of its definition (shared by the rows of one
/// tolerance), its nominal and item (shared by its rows on the same features) and its
/// measurement.
pub(super) struct CharRow<'a> {
    row: &'a Row,
    kind: Kind,
    /// As the program states it, else as the report judged it.
    def: TolDef,
    /// The first row of its tolerance: it writes the definition.
    writes_def: bool,
    /// The first row of its tolerance on its features: it writes nominal and item.
    writes_item: bool,
    def_id: u32,
    nom_id: u32,
    item_id: u32,
    meas_id: u32,
    drf: Option<u32>,
}

/// The tolerance rows, and the id of the standard their definitions follow.
pub(super) struct Chars<'a> {
    pub(super) rows: Vec<CharRow<'a>>,
    pub(super) standard: u32,
}

impl<'a> Chars<'a> {
    pub(super) fn new(
        report: &'a Report,
        meta: &QifMeta,
        datums: &Datums,
        ids: &mut Ids,
    ) -> Chars<'a> {
        let standard = ids.take();
        let mut defs: BTreeMap<(&str, &str), u32> = BTreeMap::new();
        let mut items: BTreeMap<(&str, &str, &[String]), (u32, u32)> = BTreeMap::new();
        let mut rows = Vec::new();
        for row in &report.rows {
            let key = (row.tolerance.as_str(), row.kind.as_str());
            let writes_def = !defs.contains_key(&key);
            let def_id = *defs.entry(key).or_insert_with(|| ids.take());
            let ikey = (key.0, key.1, row.features.as_slice());
            let writes_item = !items.contains_key(&ikey);
            let (nom_id, item_id) = *items
                .entry(ikey)
                .or_insert_with(|| (ids.take(), ids.take()));
            let def = meta
                .tolerances
                .get(&row.tolerance)
                .and_then(|p| TolDef::parse(p))
                .filter(|d| d.word == row.kind)
                .unwrap_or_else(|| from_outcome(row));
            let kind = Kind::of(&row.kind);
            let drf = kind.class.has_drf().then(|| datums.frame_id(row, meta));
            rows.push(CharRow {
                row,
                kind,
                def,
                writes_def,
                writes_item,
                def_id,
                nom_id,
                item_id,
                meas_id: 0,
                drf: drf.flatten(),
            });
        }
        for r in &mut rows {
            r.meas_id = ids.take();
        }
        Chars { rows, standard }
    }

    pub(super) fn write(&self, x: &mut Xml, feats: &Feats) {
        let defs: Vec<&CharRow> = self.rows.iter().filter(|r| r.writes_def).collect();
        let items: Vec<&CharRow> = self.rows.iter().filter(|r| r.writes_item).collect();
        x.list("CharacteristicDefinitions", defs.len(), |x| {
            defs.iter().for_each(|r| r.definition(x, feats))
        });
        x.list("CharacteristicNominals", items.len(), |x| {
            items.iter().for_each(|r| r.nominal(x, feats))
        });
        x.list("CharacteristicItems", items.len(), |x| {
            items.iter().for_each(|r| r.item(x, feats))
        });
    }
}

/// A tolerance the program does not define, as the report judged it: its limits, or
/// for a zone its upper limit (which holds any bonus).
fn from_outcome(row: &Row) -> TolDef {
    let o = &row.outcome;
    let size = matches!(
        Kind::of(&row.kind).class,
        Class::Linear | Class::Angular | Class::Generic
    );
    TolDef {
        word: row.kind.clone(),
        zone: (!size).then_some(o.limits.1),
        dims: None,
        nominal: size.then_some(o.nominal),
        limits: size.then_some(o.limits),
        material: None,
        datums: row.datums.clone(),
    }
}

impl CharRow<'_> {
    /// The element `{stem}Characteristic{aspect}` with its id.
    fn el(&self, x: &mut Xml, aspect: &str, id: u32, body: impl FnOnce(&mut Xml)) {
        let tag = format!("{}Characteristic{aspect}", self.kind.stem);
        x.el(&tag, &[("id", &id.to_string())], body);
    }

    /// The shape of its first feature, when the report has it (an OtherShape's by its
    /// DMIS word).
    fn shape(&self, feats: &Feats) -> Option<Shape> {
        let f = feats.get(self.row.features.first()?)?;
        Some(match f.shape {
            Shape::Other => Shape::of(&f.row.kind),
            s => s,
        })
    }

    /// The zone value as the program states it (the report's limit without one).
    fn zone(&self) -> f64 {
        self.def
            .zone
            .filter(|z| z.is_finite())
            .unwrap_or(self.row.outcome.limits.1)
    }

    fn definition(&self, x: &mut Xml, feats: &Feats) {
        if self.kind.class == Class::Generic {
            x.comment(&format!(
                "DMIS TOL/{} has no QIF characteristic in inspc's mapping: written as the \
                 generic UserDefinedLinearCharacteristic",
                self.row.kind
            ));
        }
        let shape = self.shape(feats);
        let axial = shape.is_some_and(Shape::axial);
        let material = modifier(self.def.material.as_deref());
        let zone_shape = |x: &mut Xml, zone: &str| x.el("ZoneShape", &[], |x| x.empty(zone, &[]));
        self.el(x, "Definition", self.def_id, |x| {
            x.text("Description", &format!("DMIS TOL/{}", self.row.kind));
            if matches!(
                self.kind.class,
                Class::Linear | Class::Angular | Class::Generic
            ) {
                // A generic kind the program states as a zone: within (0, zone).
                let (lo, hi) = self
                    .def
                    .limits
                    .or(self.def.zone.map(|z| (0.0, z)))
                    .filter(|(a, b)| a.is_finite() && b.is_finite())
                    .unwrap_or((0.0, 0.0));
                x.el("Tolerance", &[], |x| {
                    x.text("MaxValue", &dec(hi));
                    x.text("MinValue", &dec(lo));
                    x.text("DefinedAsLimit", "false");
                });
                if self.kind.class == Class::Generic {
                    x.text(
                        "WhatToMeasure",
                        &format!("DMIS tolerance TOL/{}", self.row.kind),
                    );
                }
                return;
            }
            x.text("ToleranceValue", &dec(self.zone()));
            if let (true, Some(id)) = (self.kind.class != Class::Form, self.drf) {
                x.text("DatumReferenceFrameId", &id.to_string());
            }
            match self.kind.stem {
                "Straightness" if axial => zone_shape(x, "DiametricalZone"),
                "Straightness" => zone_shape(x, "NonDiametricalZone"),
                "Perpendicularity" | "Parallelism" | "Angularity" => {
                    x.text("MaterialCondition", material);
                    zone_shape(
                        x,
                        if axial {
                            "DiametricalZone"
                        } else {
                            "PlanarZone"
                        },
                    );
                }
                "Position" => {
                    x.text("MaterialCondition", material);
                    zone_shape(
                        x,
                        match (self.def.dims.as_deref(), shape) {
                            (Some("2D"), _) => "DiametricalZone",
                            (Some(_), _) => "NonDiametricalZone",
                            (None, Some(Shape::Sphere)) => "SphericalZone",
                            (None, _) if axial => "DiametricalZone",
                            (None, _) => "NonDiametricalZone",
                        },
                    );
                }
                "Concentricity" | "Coaxiality" => zone_shape(x, "DiametricalZone"),
                _ => {}
            }
        });
    }

    fn nominal(&self, x: &mut Xml, feats: &Feats) {
        let target = [self.def.nominal, Some(self.row.outcome.nominal)]
            .into_iter()
            .flatten()
            .find(|v| v.is_finite())
            .unwrap_or(0.0);
        self.el(x, "Nominal", self.nom_id, |x| {
            x.text("CharacteristicDefinitionId", &self.def_id.to_string());
            x.ids(
                "FeatureNominalIds",
                &feats.ids(&self.row.features, |f| f.nom),
            );
            x.text("Name", &self.row.tolerance);
            match self.kind.stem {
                "DistanceBetween" => {
                    x.text("TargetValue", &dec(target));
                    // Planes: along the first's normal; two axes: across them; else in
                    // space (as evaluate.rs measures DISTB).
                    let shapes: Vec<Option<Shape>> = (self.row.features.iter())
                        .map(|l| feats.get(l).map(|f| f.shape))
                        .collect();
                    let axis = |s: &Option<Shape>| matches!(s, Some(Shape::Cylinder | Shape::Cone));
                    let mode = match shapes.as_slice() {
                        [Some(Shape::Plane | Shape::Parpln), ..] => "ONEDIMENSIONAL",
                        [a, b] if axis(a) && axis(b) => "TWODIMENSIONAL",
                        _ => "THREEDIMENSIONAL",
                    };
                    x.text("AnalysisMode", mode);
                }
                "AngleBetween" => {
                    x.text("TargetValue", &dec(target));
                    x.text("AnalysisMode", "THREEDIMENSIONAL");
                }
                "LineProfile" => {
                    // The plane the profile's lines lie in: across the feature's
                    // direction where the report has it.
                    let dir = (self.row.features.first()).and_then(|l| feats.get(l)?.nominal?.dir);
                    if dir.is_none() {
                        x.comment("the section plane is not in the report: Z assumed");
                    }
                    x.text("Vector", &v3(dir.unwrap_or([0.0, 0.0, 1.0])));
                }
                "Angularity" => {
                    if let Some(a) = self.def.nominal.filter(|v| v.is_finite()) {
                        x.text("Angle", &dec(a));
                    }
                }
                _ if matches!(self.kind.class, Class::Linear | Class::Generic) => {
                    x.text("TargetValue", &dec(target))
                }
                _ => {}
            }
        });
    }

    fn item(&self, x: &mut Xml, feats: &Feats) {
        let r = self.row;
        let mut desc = format!("DMIS T({})=TOL/{}", r.tolerance, r.kind);
        if !r.features.is_empty() {
            desc.push_str(&format!(" on {}", r.features.join(", ")));
        }
        let missing: Vec<&str> = (r.features.iter())
            .filter(|l| feats.get(l).is_none())
            .map(String::as_str)
            .collect();
        if !missing.is_empty() {
            desc.push_str(&format!(
                " (not among the features output: {})",
                missing.join(", ")
            ));
        }
        self.el(x, "Item", self.item_id, |x| {
            x.text("Description", &desc);
            x.text("Name", &r.tolerance);
            x.ids("FeatureItemIds", &feats.ids(&r.features, |f| f.item));
            x.text("CharacteristicNominalId", &self.nom_id.to_string());
        });
    }

    pub(super) fn measurement(&self, x: &mut Xml, feats: &Feats) {
        let o = &self.row.outcome;
        let status = if self.row.unjudged() {
            "NOT_ANALYZED"
        } else if self.row.pass() {
            "PASS"
        } else {
            "FAIL"
        };
        self.el(x, "Measurement", self.meas_id, |x| {
            if let Some(note) = &o.note {
                x.text("Description", note);
            }
            x.wrap("Status", "CharacteristicStatusEnum", status);
            x.text("CharacteristicItemId", &self.item_id.to_string());
            x.ids(
                "FeatureMeasurementIds",
                &feats.ids(&self.row.features, |f| f.meas),
            );
            if self.row.unjudged() {
                return;
            }
            x.text("Value", &dec(o.actual));
            // A position's MMC bonus: the limit it was judged against beyond its zone.
            let bonus = o.limits.1 - self.zone();
            let mmc = self.def.material.as_deref() == Some("MMC");
            if self.kind.stem == "Position" && mmc && bonus > 0.0 {
                x.text("Bonus", &dec(bonus));
            }
        });
    }
}
