//! The report's feature rows as QIF features: each row's definition, nominal, item and
//! measurement, and the geometry they carry.
//!
//! **Features** (the DMIS `FEAT` word → the QIF feature): `PLANE` → Plane, `POINT` →
//! Point, `CIRCLE` → Circle, `CYLNDR` → Cylinder, `CONE` → Cone (its angle is the full
//! included angle, at the apex: diameter 0), `SPHERE` → Sphere, `PARPLN` →
//! OppositeParallelPlanes (slot ends UNDEFINED: the report does not say), `GSURF` →
//! OtherSurface, `PATERN` and any other word → OtherShape with a `Description` (QIF's
//! GroupFeature would need its members, which the report does not list); a feature
//! whose nominal lacks the numbers its kind needs is an OtherShape too. `PARPLN` and
//! `PATERN` are `Checked`/`Constructed` (their method is not in the report), the rest
//! `Checked`/`Measured`; each measurement carries its point count as an attribute and
//! its fit's form error as `Form`.

use super::xml::{dec, v3, Ids, Xml};
use crate::simulate::FeatureRow;
use std::collections::BTreeMap;

/// The QIF feature a DMIS feature word is written as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Shape {
    Plane,
    Point,
    Circle,
    Cylinder,
    Cone,
    Sphere,
    Parpln,
    Surface,
    Other,
}

impl Shape {
    pub(super) fn of(word: &str) -> Shape {
        match word {
            "PLANE" => Shape::Plane,
            "POINT" => Shape::Point,
            "CIRCLE" => Shape::Circle,
            "CYLNDR" => Shape::Cylinder,
            "CONE" => Shape::Cone,
            "SPHERE" => Shape::Sphere,
            "PARPLN" => Shape::Parpln,
            "GSURF" => Shape::Surface,
            _ => Shape::Other,
        }
    }

    /// The QIF element stem: `{stem}FeatureDefinition`, `…Nominal`, `…Item`,
    /// `…Measurement`.
    fn stem(self) -> &'static str {
        match self {
            Shape::Plane => "Plane",
            Shape::Point => "Point",
            Shape::Circle => "Circle",
            Shape::Cylinder => "Cylinder",
            Shape::Cone => "Cone",
            Shape::Sphere => "Sphere",
            Shape::Parpln => "OppositeParallelPlanes",
            Shape::Surface => "OtherSurface",
            Shape::Other => "OtherShape",
        }
    }

    /// Its zones are about an axis or a centre (for zone shapes).
    pub(super) fn axial(self) -> bool {
        matches!(
            self,
            Shape::Circle | Shape::Cylinder | Shape::Cone | Shape::Sphere
        )
    }
}

/// A feature's numbers in the `FEAT` layout: location, direction, size.
#[derive(Debug, Clone, Copy)]
pub(super) struct Geom {
    p: [f64; 3],
    pub(super) dir: Option<[f64; 3]>,
    size: Option<f64>,
}

/// The numbers `nums` read for `shape`, when they are all there and finite.
fn geom(shape: Shape, nums: &[f64]) -> Option<Geom> {
    if nums.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let v3 = |k: usize| -> Option<[f64; 3]> { Some([*nums.get(k)?, nums[k + 1], nums[k + 2]]) };
    // Location and direction (`need` 6) and a size (`need` 7).
    let full = |need: usize| -> Option<Geom> {
        (nums.len() >= need).then_some(())?;
        Some(Geom {
            p: v3(0)?,
            dir: v3(3),
            size: nums.get(6).copied(),
        })
    };
    let at = |size: Option<f64>| -> Option<Geom> {
        Some(Geom {
            p: v3(0)?,
            dir: None,
            size,
        })
    };
    match (shape, nums.len()) {
        (Shape::Plane, _) => full(6),
        (Shape::Point, 3..=5) => at(None),
        (Shape::Point, _) => full(6),
        (Shape::Circle | Shape::Cylinder | Shape::Cone | Shape::Parpln, _) => full(7),
        // `x, y, z, d` as inspc writes it; `x, y, z, i, j, k, d` as DMIS allows.
        (Shape::Sphere, 4..=6) => at(Some(nums[3])),
        (Shape::Sphere, _) => full(7),
        (Shape::Surface | Shape::Other, _) => None,
    }
}

/// A feature row and the QIF ids of its four aspects.
pub(super) struct Feat<'a> {
    pub(super) row: &'a FeatureRow,
    pub(super) shape: Shape,
    pub(super) nominal: Option<Geom>,
    actual: Option<Geom>,
    /// Why it is an OtherShape.
    why: String,
    def: u32,
    pub(super) nom: u32,
    pub(super) item: u32,
    pub(super) meas: u32,
}

/// The feature rows, and the first of each label.
pub(super) struct Feats<'a> {
    pub(super) all: Vec<Feat<'a>>,
    by_label: BTreeMap<&'a str, usize>,
}

impl<'a> Feats<'a> {
    pub(super) fn new(rows: &'a [FeatureRow], ids: &mut Ids) -> Feats<'a> {
        let all: Vec<Feat> = rows.iter().map(|row| Feat::new(row, ids)).collect();
        let mut by_label = BTreeMap::new();
        for (k, f) in all.iter().enumerate() {
            by_label.entry(f.row.label.as_str()).or_insert(k);
        }
        Feats { all, by_label }
    }

    pub(super) fn get(&self, label: &str) -> Option<&Feat<'a>> {
        self.by_label.get(label).map(|&k| &self.all[k])
    }

    /// The ids `f` gives of the features of `labels` that are among the rows.
    pub(super) fn ids(&self, labels: &[String], f: fn(&Feat) -> u32) -> Vec<u32> {
        labels.iter().filter_map(|l| self.get(l).map(f)).collect()
    }

    pub(super) fn write(&self, x: &mut Xml) {
        let n = self.all.len();
        x.list("FeatureDefinitions", n, |x| {
            self.all.iter().for_each(|f| f.definition(x))
        });
        x.list("FeatureNominals", n, |x| {
            self.all.iter().for_each(|f| f.nominal(x))
        });
        x.list("FeatureItems", n, |x| {
            self.all.iter().for_each(|f| f.item(x))
        });
    }
}

impl<'a> Feat<'a> {
    fn new(row: &'a FeatureRow, ids: &mut Ids) -> Feat<'a> {
        let mut shape = Shape::of(&row.kind);
        let nominal = geom(shape, &row.nominal);
        let mut why = String::new();
        if shape == Shape::Other {
            why = if row.kind == "PATERN" {
                "a DMIS pattern (FEAT/PATERN) of features; its members are not listed here"
                    .to_string()
            } else {
                format!(
                    "DMIS FEAT/{}: no QIF feature of its own in inspc's mapping",
                    row.kind
                )
            };
        } else if shape != Shape::Surface && nominal.is_none() {
            why = format!(
                "DMIS FEAT/{} whose nominal lacks the numbers a QIF {} needs",
                row.kind,
                shape.stem()
            );
            shape = Shape::Other;
        }
        Feat {
            row,
            shape,
            nominal,
            actual: geom(shape, &row.actual),
            why,
            def: ids.take(),
            nom: ids.take(),
            item: ids.take(),
            meas: ids.take(),
        }
    }

    /// The element `{stem}Feature{aspect}` with its id.
    fn el(&self, x: &mut Xml, aspect: &str, id: u32, body: impl FnOnce(&mut Xml)) {
        let tag = format!("{}Feature{aspect}", self.shape.stem());
        x.el(&tag, &[("id", &id.to_string())], body);
    }

    fn definition(&self, x: &mut Xml) {
        let side = if self.row.inner {
            "INTERNAL"
        } else {
            "EXTERNAL"
        };
        let size = dec(self.nominal.and_then(|g| g.size).unwrap_or(0.0));
        if self.shape == Shape::Other {
            x.comment(&format!(
                "{}: written as an OtherShape feature",
                self.row.label
            ));
        }
        self.el(x, "Definition", self.def, |x| match self.shape {
            Shape::Plane | Shape::Point | Shape::Surface => {}
            Shape::Circle | Shape::Cylinder | Shape::Sphere => {
                x.text("InternalExternal", side);
                x.text("Diameter", &size);
            }
            Shape::Cone => {
                x.text("InternalExternal", side);
                // Located at its apex, where its diameter is 0.
                x.text("Diameter", "0");
                x.text("FullAngle", &size);
            }
            Shape::Parpln => {
                x.text("InternalExternal", side);
                x.text("Width", &size);
                x.wrap("EndType", "SlotEndEnum", "UNDEFINED");
            }
            Shape::Other => x.text("Description", &self.why),
        });
    }

    fn nominal(&self, x: &mut Xml) {
        self.el(x, "Nominal", self.nom, |x| {
            x.text("Name", &self.row.label);
            x.text("FeatureDefinitionId", &self.def.to_string());
            if let Some(g) = self.nominal {
                geometry(x, self.shape, &g, false);
            }
        });
    }

    fn item(&self, x: &mut Xml) {
        // A construction's method and inputs are not in the report: an empty
        // `Constructed` (the schema's choice of method is optional) says only how.
        let how = match self.row.kind.as_str() {
            "PARPLN" | "PATERN" => "Constructed",
            _ => "Measured",
        };
        self.el(x, "Item", self.item, |x| {
            x.text("FeatureNominalId", &self.nom.to_string());
            x.text("FeatureName", &self.row.label);
            x.el("DeterminationMode", &[], |x| {
                x.el("Checked", &[], |x| {
                    x.el("CheckDetails", &[], |x| x.empty(how, &[]))
                })
            });
        });
    }

    pub(super) fn measurement(&self, x: &mut Xml) {
        self.el(x, "Measurement", self.meas, |x| {
            x.list("Attributes", 1, |x| {
                let points = self.row.points.to_string();
                x.empty("AttributeI1", &[("name", "points"), ("value", &points)]);
            });
            x.text("FeatureItemId", &self.item.to_string());
            x.text("FeatureName", &self.row.label);
            if let Some(g) = self.actual {
                geometry(x, self.shape, &g, true);
            }
            let formless = matches!(self.shape, Shape::Point | Shape::Surface | Shape::Other);
            if let (Some(e), false) = (self.row.form.filter(|e| e.is_finite()), formless) {
                x.text("Form", &dec(e));
            }
        });
    }
}

/// A feature's place and size, as a nominal's or (`measured`) a measurement's elements
/// (without the measurement's `Form`, which comes last).
fn geometry(x: &mut Xml, shape: Shape, g: &Geom, measured: bool) {
    let dir = v3(g.dir.unwrap_or([0.0, 0.0, 1.0]));
    let size = g.size.filter(|_| measured).map(dec);
    match shape {
        Shape::Plane | Shape::Point | Shape::Circle => {
            x.text("Location", &v3(g.p));
            if shape != Shape::Point || g.dir.is_some() {
                x.text("Normal", &dir);
            }
            if let (Shape::Circle, Some(d)) = (shape, &size) {
                x.text("Diameter", d);
            }
        }
        Shape::Cylinder | Shape::Cone => {
            x.el("Axis", &[], |x| {
                x.text("AxisPoint", &v3(g.p));
                x.text("Direction", &dir);
            });
            match (shape, &size) {
                (Shape::Cylinder, Some(d)) => x.text("Diameter", d),
                (Shape::Cone, Some(a)) => x.text("FullAngle", a),
                _ => {}
            }
        }
        Shape::Sphere => {
            x.text("Location", &v3(g.p));
            if let Some(d) = &size {
                x.text("Diameter", d);
            }
        }
        Shape::Parpln => {
            x.el("CenterPlane", &[], |x| {
                x.text("Point", &v3(g.p));
                x.text("Normal", &dir);
            });
            if let Some(w) = &size {
                x.text("Width", w);
            }
        }
        Shape::Surface | Shape::Other => {}
    }
}
