//! The virtual CMM's report as a QIF 3.0 Results document (ISO 23952:2020, the DMSC's
//! `QIFDocument.xsd` 3.0.0): what `inspc simulate … --report OUT.qif` writes, so that a
//! QIF consumer (statistics, a first-article report) reads the simulated run as it
//! would a CMM's.
//!
//! The document is self-contained: header, units (mm, degrees), the datums and datum
//! reference frames the tolerances name, the part, then per feature output its
//! definition, nominal and item (`Features`) and per tolerance its definition, nominal
//! and item (`Characteristics`), and the run itself (`Results`: one
//! `MeasurementResults` with a `…FeatureMeasurement` per feature row and a
//! `…CharacteristicMeasurement` per tolerance row, each with its PASS/FAIL status).
//! Element names and order follow the schema types (`Features.xsd`,
//! `Characteristics.xsd`, `QIFResults.xsd`, `IntermediatesPMI.xsd`); the shape of each
//! block follows the QIF community's sample results, `samples/QIFwidget/
//! WIDGET_QIF_RESULTS.QIF` in `github.com/QualityInformationFramework/qif-community`
//! (its `PlaneFeatureMeasurement`, `CylinderFeatureMeasurement`,
//! `…CharacteristicDefinition`/`Nominal`/`Item`/`Measurement` chains, `DeterminationMode`
//! `Checked`/`Measured`, `DatumReferenceFrame`s of `SimpleDatum`s, `InspectionStatus`).
//! One definition per tolerance, one nominal and item per tolerance and feature list,
//! one measurement per row (a tolerance output in two setups is measured twice); the
//! definitions follow ASME Y14.5-2018 (the `FormalStandardId`), as inspc reads
//! drawings. The run's numbers (setups, touches, noise, seed) are the results'
//! `Attributes`, the program and spec its `ExternalFileReferences`, the program's
//! `FILNAM` its `ReportNumber`.
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
//! measurement's `Description`. The document's status is FAIL when a tolerance fails,
//! else UNKNOWN when one was not judged, else PASS.
//!
//! **Zones and modifiers** come from the program's `TOL` statements ([`QifMeta`]): the
//! tolerance value as stated, `MMC`/`LMC`/`RFS` (QIF's MAXIMUM/LEAST/REGARDLESS, NONE
//! without a word), `2D`/`3D` for a position (a diametrical or a width zone) and a
//! datum's modifier. A tolerance the program does not define falls back on the report:
//! its upper limit (the zone plus any bonus) is the tolerance value and the zone shape
//! follows the feature (an axis or a circle: diametrical). A position's MMC bonus is
//! the measurement's `Bonus`.
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
//!
//! **Determinism:** no clock (no `Version`/`TimeCreated`, no time stamps), file names
//! without folders, ids numbered in report order, and the document's `QPId` is a
//! 128-bit FNV-1a hash of the rest of the document written as a UUID (version 8,
//! RFC 9562's custom form). Every text from the report is escaped.

use super::evaluate::TolDef;
use super::report::{FeatureRow, Report, Row};
use std::collections::BTreeMap;
use std::path::Path;

/// What the document says about the run beyond the report.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct QifMeta {
    /// The spec's file name, without folders.
    pub spec: String,
    /// The program's file name, without folders.
    pub program: String,
    /// The program's `TOL` statements by tolerance label: their parameters as written
    /// (`["POS", "2D", "0.1", "MMC", "DAT(A)"]`). A tolerance not here is written from
    /// the report alone.
    pub tolerances: BTreeMap<String, Vec<String>>,
}

impl QifMeta {
    /// The names of `spec` and `program` (their folders dropped) and the `TOL`
    /// statements of `program_text`; a program the DMIS reader rejects gives none.
    pub fn new(spec: &Path, program: &Path, program_text: &str) -> QifMeta {
        let name = |p: &Path| {
            p.file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default()
        };
        let mut tolerances = BTreeMap::new();
        if let Ok(p) = crate::dmis::read(crate::source::FileId(0), program_text) {
            for s in &p.statements {
                if let crate::dmis::Statement::Command {
                    label: Some((kind, label)),
                    major,
                    params,
                    ..
                } = s
                {
                    if kind == "T" && major == "TOL" {
                        tolerances
                            .entry(label.clone())
                            .or_insert_with(|| params.clone());
                    }
                }
            }
        }
        QifMeta {
            spec: name(spec),
            program: name(program),
            tolerances,
        }
    }
}

/// The run as a QIF 3.0 Results document (ISO 23952): features, characteristics and
/// their measurements, valid against the DMSC's `QIFDocument.xsd` (see the module's
/// notes for how each DMIS tolerance and feature maps).
pub fn qif_results(report: &Report, meta: &QifMeta) -> String {
    let mut ids = Ids(0);
    let part = ids.take();
    let feats = Feats::new(&report.features, &mut ids);
    let datums = Datums::new(report, meta, &mut ids);
    let chars = Chars::new(report, meta, &datums, &mut ids);
    let (results, component) = (ids.take(), ids.take());
    let status = if report.failed() > 0 {
        "FAIL"
    } else if report.unjudged() > 0 {
        "UNKNOWN"
    } else {
        "PASS"
    };

    let mut x = Xml::default();
    header(&mut x, report, meta);
    if !chars.rows.is_empty() {
        x.el("StandardsDefinitions", &[("n", "1")], |x| {
            x.el("Standard", &[("id", &chars.standard.to_string())], |x| {
                x.wrap("Organization", "StandardsOrganizationEnum", "ASME");
                x.text("Designator", "Y14.5");
                x.text("Year", "2018");
            })
        });
    }
    units(&mut x);
    datums.write(&mut x);
    x.el("Product", &[], |x| {
        x.el("PartSet", &[("n", "1")], |x| {
            x.el("Part", &[("id", &part.to_string())], |x| {
                x.wrap("Header", "Name", &report.part)
            })
        });
        x.wrap("RootPart", "Id", &part.to_string());
    });
    if !feats.all.is_empty() {
        x.el("Features", &[], |x| feats.write(x));
    }
    if !chars.rows.is_empty() {
        x.el("Characteristics", &[], |x| {
            x.text("FormalStandardId", &chars.standard.to_string());
            chars.write(x, &feats);
        });
    }
    x.el("Results", &[], |x| {
        x.el("MeasurementResultsSet", &[("n", "1")], |x| {
            x.el("MeasurementResults", &[("id", &results.to_string())], |x| {
                run(x, report, meta);
                if !feats.all.is_empty() {
                    x.list("MeasuredFeatures", feats.all.len(), |x| {
                        for f in &feats.all {
                            f.measurement(x);
                        }
                    });
                }
                if !chars.rows.is_empty() {
                    x.el("MeasuredCharacteristics", &[], |x| {
                        x.list("CharacteristicMeasurements", chars.rows.len(), |x| {
                            for r in &chars.rows {
                                r.measurement(x, &feats);
                            }
                        })
                    });
                }
                x.wrap("InspectionStatus", "InspectionStatusEnum", status);
                x.ids("ActualComponentIds", &[component]);
            })
        });
        x.el("ActualComponentSets", &[("n", "1")], |x| {
            x.el("ActualComponentSet", &[("n", "1")], |x| {
                x.el("ActualComponent", &[("id", &component.to_string())], |x| {
                    x.wrap("Status", "InspectionStatusEnum", status)
                })
            })
        });
    });

    let body = x.out;
    let uuid = qpid(&format!("{}\n{body}", ids.0));
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n\
         <!-- Written by inspc from a run of its virtual CMM: simulated measurements, not a real part's. -->\n\
         <QIFDocument xmlns=\"http://qifstandards.org/xsd/qif3\" \
         xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" \
         xsi:schemaLocation=\"http://qifstandards.org/xsd/qif3 QIFDocument.xsd\" \
         versionQIF=\"3.0.0\" idMax=\"{}\">\n  <QPId>{uuid}</QPId>\n{body}</QIFDocument>\n",
        ids.0
    )
}

/// QIF ids, numbered from 1 in the order they are handed out.
struct Ids(u32);

impl Ids {
    fn take(&mut self) -> u32 {
        self.0 += 1;
        self.0
    }
}

/// The document's header: who wrote it, from what.
fn header(x: &mut Xml, report: &Report, meta: &QifMeta) {
    let r = report;
    x.el("Header", &[], |x| {
        x.wrap("Application", "Name", "inspc");
        x.text(
            "Description",
            &format!(
                "Results of DMIS program {} ({}) run on inspc's virtual CMM against spec \
                 {}: plan {}, part {}; {} setups, {} touches, {} points scanned, {} moves \
                 checked; noise {} mm (seed {})",
                r.program,
                meta.program,
                meta.spec,
                r.plan,
                r.part,
                r.setups,
                r.touches,
                r.scanned,
                r.moves,
                dec(r.noise),
                r.seed
            ),
        );
        x.text("Scope", "Results");
    });
}

/// Units: millimetres and degrees, as the program's `UNITS/MM,ANGDEC`.
fn units(x: &mut Xml) {
    x.el("FileUnits", &[], |x| {
        x.el("PrimaryUnits", &[], |x| {
            for (tag, si, name, factor) in [
                ("AngularUnit", "radian", "degree", "0.017453292519943"),
                ("LinearUnit", "meter", "mm", "0.001"),
            ] {
                x.el(tag, &[], |x| {
                    x.text("SIUnitName", si);
                    x.text("UnitName", name);
                    x.wrap("UnitConversion", "Factor", factor);
                });
            }
        })
    });
}

/// The run's numbers, its report's name and the files it ran (a `MeasurementResults`'s
/// elements before its measurements).
fn run(x: &mut Xml, report: &Report, meta: &QifMeta) {
    x.list("Attributes", 6, |x| {
        for (name, value) in [
            ("setups", report.setups as u64),
            ("touches", report.touches as u64),
            ("points scanned", report.scanned as u64),
            ("moves checked", report.moves as u64),
            ("seed", report.seed),
        ] {
            x.empty(
                "AttributeI1",
                &[("name", name), ("value", &value.to_string())],
            );
        }
        x.empty(
            "AttributeD1",
            &[("name", "noise (mm)"), ("value", &dec(report.noise))],
        );
    });
    x.wrap("InspectionTraceability", "ReportNumber", &report.filnam);
    x.list("ExternalFileReferences", 2, |x| {
        for (file, spec, what) in [
            (&meta.program, "DMIS", "the DMIS program run"),
            (&meta.spec, "inspc spec", "the inspection spec of the part"),
        ] {
            x.el("ExternalFileReference", &[], |x| {
                x.text("URI", &uri(file));
                x.wrap("FileSpec", "OtherFileSpec", spec);
                x.text("Description", what);
            });
        }
    });
}

// ---------------------------------------------------------------------------------
// Features

/// The QIF feature a DMIS feature word is written as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Shape {
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
    fn of(word: &str) -> Shape {
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
    fn axial(self) -> bool {
        matches!(
            self,
            Shape::Circle | Shape::Cylinder | Shape::Cone | Shape::Sphere
        )
    }
}

/// A feature's numbers in the `FEAT` layout: location, direction, size.
#[derive(Debug, Clone, Copy)]
struct Geom {
    p: [f64; 3],
    dir: Option<[f64; 3]>,
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
struct Feat<'a> {
    row: &'a FeatureRow,
    shape: Shape,
    nominal: Option<Geom>,
    actual: Option<Geom>,
    /// Why it is an OtherShape.
    why: String,
    def: u32,
    nom: u32,
    item: u32,
    meas: u32,
}

/// The feature rows, and the first of each label.
struct Feats<'a> {
    all: Vec<Feat<'a>>,
    by_label: BTreeMap<&'a str, usize>,
}

impl<'a> Feats<'a> {
    fn new(rows: &'a [FeatureRow], ids: &mut Ids) -> Feats<'a> {
        let all: Vec<Feat> = rows.iter().map(|row| Feat::new(row, ids)).collect();
        let mut by_label = BTreeMap::new();
        for (k, f) in all.iter().enumerate() {
            by_label.entry(f.row.label.as_str()).or_insert(k);
        }
        Feats { all, by_label }
    }

    fn get(&self, label: &str) -> Option<&Feat<'a>> {
        self.by_label.get(label).map(|&k| &self.all[k])
    }

    /// The ids `f` gives of the features of `labels` that are among the rows.
    fn ids(&self, labels: &[String], f: fn(&Feat) -> u32) -> Vec<u32> {
        labels.iter().filter_map(|l| self.get(l).map(f)).collect()
    }

    fn write(&self, x: &mut Xml) {
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

    fn measurement(&self, x: &mut Xml) {
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

// ---------------------------------------------------------------------------------
// Datums

/// The datum labels and the datum reference frames (a list of datums with their
/// material modifiers) the tolerances name, with their ids.
struct Datums {
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
    fn new(report: &Report, meta: &QifMeta, ids: &mut Ids) -> Datums {
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

    fn write(&self, x: &mut Xml) {
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

// ---------------------------------------------------------------------------------
// Characteristics

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
struct CharRow<'a> {
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
struct Chars<'a> {
    rows: Vec<CharRow<'a>>,
    standard: u32,
}

impl<'a> Chars<'a> {
    fn new(report: &'a Report, meta: &QifMeta, datums: &Datums, ids: &mut Ids) -> Chars<'a> {
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

    fn write(&self, x: &mut Xml, feats: &Feats) {
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

    fn measurement(&self, x: &mut Xml, feats: &Feats) {
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

// ---------------------------------------------------------------------------------
// Text

/// The XML text being written, indented two spaces a level (the root's children one).
#[derive(Default)]
struct Xml {
    out: String,
    depth: usize,
}

impl Xml {
    fn start(&mut self, tag: &str, attrs: &[(&str, &str)]) {
        self.out.push_str(&"  ".repeat(self.depth + 1));
        self.out.push('<');
        self.out.push_str(tag);
        for (k, v) in attrs {
            self.out.push_str(&format!(" {k}=\"{}\"", escape(v)));
        }
    }

    /// `<tag attrs>` … `</tag>` around what `body` writes (`<tag attrs/>` when it
    /// writes nothing).
    fn el(&mut self, tag: &str, attrs: &[(&str, &str)], body: impl FnOnce(&mut Xml)) {
        self.start(tag, attrs);
        let open = self.out.len();
        self.out.push_str(">\n");
        self.depth += 1;
        body(self);
        self.depth -= 1;
        if self.out.len() == open + 2 {
            self.out.truncate(open);
            self.out.push_str("/>\n");
            return;
        }
        self.out.push_str(&"  ".repeat(self.depth + 1));
        self.out.push_str(&format!("</{tag}>\n"));
    }

    /// An element with `n` children (the schema's `n` attribute).
    fn list(&mut self, tag: &str, n: usize, body: impl FnOnce(&mut Xml)) {
        self.el(tag, &[("n", &n.to_string())], body);
    }

    /// A list of id references, none when `ids` is empty.
    fn ids(&mut self, tag: &str, ids: &[u32]) {
        if !ids.is_empty() {
            self.list(tag, ids.len(), |x| {
                ids.iter().for_each(|id| x.text("Id", &id.to_string()))
            });
        }
    }

    fn empty(&mut self, tag: &str, attrs: &[(&str, &str)]) {
        self.start(tag, attrs);
        self.out.push_str("/>\n");
    }

    /// `<tag>text</tag>`, the text escaped.
    fn text(&mut self, tag: &str, text: &str) {
        self.start(tag, &[]);
        self.out.push_str(&format!(">{}</{tag}>\n", escape(text)));
    }

    /// `<outer><inner>text</inner></outer>`.
    fn wrap(&mut self, outer: &str, inner: &str, text: &str) {
        self.el(outer, &[], |x| x.text(inner, text));
    }

    /// A comment: no `--` inside it, nor a `-` at its end, as XML asks.
    fn comment(&mut self, text: &str) {
        let mut t = xml_chars(text);
        while t.contains("--") {
            t = t.replace("--", "- -");
        }
        self.out.push_str(&"  ".repeat(self.depth + 1));
        self.out
            .push_str(&format!("<!-- {} -->\n", t.trim_end_matches('-')));
    }
}

/// Characters XML 1.0 allows (a control character becomes `?`).
fn xml_chars(s: &str) -> String {
    s.chars()
        .map(|c| match c {
            '\t' | '\n' | '\r' => c,
            c if (c as u32) < 0x20 || c == '\u{FFFE}' || c == '\u{FFFF}' => '?',
            c => c,
        })
        .collect()
}

/// Text safe in an element or attribute.
fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in xml_chars(s).chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' => out.push_str("&#9;"),
            '\n' => out.push_str("&#10;"),
            '\r' => out.push_str("&#13;"),
            c => out.push(c),
        }
    }
    out
}

/// A label as an `xs:NMTOKEN` (letters, digits, `.-_:`; anything else `_`).
fn nmtoken(s: &str) -> String {
    let t: String = s
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || matches!(c, '.' | '-' | '_' | ':') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if t.is_empty() {
        "_".into()
    } else {
        t
    }
}

/// A file name as a relative URI (percent-encoded but for unreserved characters).
fn uri(name: &str) -> String {
    let mut out = String::new();
    for b in name.bytes() {
        if b.is_ascii_alphanumeric() || matches!(b, b'-' | b'.' | b'_' | b'~' | b'/') {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

/// A number as an `xs:decimal`: to the nanometre (or nano-degree), no exponent, no
/// `-0`; not-a-number is written as 0 (callers leave such values out).
fn dec(x: f64) -> String {
    if !x.is_finite() {
        return "0".into();
    }
    let s = format!("{x:.9}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" || s.is_empty() {
        "0".into()
    } else {
        s.into()
    }
}

fn v3(v: [f64; 3]) -> String {
    format!("{} {} {}", dec(v[0]), dec(v[1]), dec(v[2]))
}

/// A UUID (version 8, RFC 9562) from a 128-bit FNV-1a hash of `text`.
fn qpid(text: &str) -> String {
    const PRIME: u128 = 0x0000000001000000000000000000013B;
    let mut h: u128 = 0x6c62272e07bb014262b821756295c58d;
    for b in text.bytes() {
        h ^= b as u128;
        h = h.wrapping_mul(PRIME);
    }
    let mut b = h.to_be_bytes();
    b[6] = (b[6] & 0x0f) | 0x80;
    b[8] = (b[8] & 0x3f) | 0x80;
    let hex: String = b.iter().map(|x| format!("{x:02x}")).collect();
    format!(
        "{}-{}-{}-{}-{}",
        &hex[0..8],
        &hex[8..12],
        &hex[12..16],
        &hex[16..20],
        &hex[20..32]
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulate::evaluate::Outcome;
    use quick_xml::events::Event;

    /// An element: its name, attributes and text.
    type El = (String, Vec<(String, String)>, String);

    /// Every element of `doc`, in document order of their ends; panics where the
    /// document is not well-formed XML.
    fn elements(doc: &str) -> Vec<El> {
        let mut reader = quick_xml::Reader::from_str(doc);
        let mut stack: Vec<El> = Vec::new();
        let mut out = Vec::new();
        let start = |e: &quick_xml::events::BytesStart| {
            let attrs = e
                .attributes()
                .map(|a| {
                    let a = a.expect("an attribute");
                    let v = a.unescape_value().expect("an attribute's value");
                    (
                        String::from_utf8_lossy(a.key.as_ref()).into_owned(),
                        v.into_owned(),
                    )
                })
                .collect();
            (
                String::from_utf8_lossy(e.name().as_ref()).into_owned(),
                attrs,
                String::new(),
            )
        };
        loop {
            match reader.read_event().expect("well-formed XML") {
                Event::Start(e) => stack.push(start(&e)),
                Event::Empty(e) => out.push(start(&e)),
                Event::End(_) => out.push(stack.pop().expect("an open element")),
                Event::Text(t) => {
                    if let Some(top) = stack.last_mut() {
                        top.2.push_str(&t.decode().expect("text"));
                    }
                }
                Event::GeneralRef(r) => {
                    let name = r.decode().expect("a reference").into_owned();
                    let c = match name.as_str() {
                        "amp" => '&',
                        "lt" => '<',
                        "gt" => '>',
                        "quot" => '"',
                        "apos" => '\'',
                        _ => r
                            .resolve_char_ref()
                            .ok()
                            .flatten()
                            .unwrap_or_else(|| panic!("unknown entity &{name};")),
                    };
                    if let Some(top) = stack.last_mut() {
                        top.2.push(c);
                    }
                }
                Event::Eof => break,
                _ => {}
            }
        }
        assert!(stack.is_empty(), "unclosed elements");
        out
    }

    fn outcome(nominal: f64, actual: f64, limits: (f64, f64)) -> Outcome {
        Outcome {
            nominal,
            actual,
            limits,
            note: None,
        }
    }

    fn row(t: &str, kind: &str, features: &[&str], datums: &[&str], o: Outcome) -> Row {
        Row {
            tolerance: t.into(),
            kind: kind.into(),
            features: features.iter().map(|s| s.to_string()).collect(),
            datums: datums.iter().map(|s| s.to_string()).collect(),
            outcome: o,
        }
    }

    fn feature(label: &str, kind: &str, nominal: &[f64], actual: &[f64]) -> FeatureRow {
        FeatureRow {
            label: label.into(),
            kind: kind.into(),
            inner: kind != "SPHERE",
            nominal: nominal.to_vec(),
            actual: actual.to_vec(),
            form: Some(0.0012),
            points: 8,
        }
    }

    /// A run with every feature kind and every tolerance kind, labels that need
    /// escaping, a tolerance failed, one not judged and one of a kind QIF has no
    /// element for.
    fn report() -> Report {
        let pl = [0.0, 0.0, 10.0, 0.0, 0.0, 1.0];
        let cyl = [20.0, 20.0, 5.0, 0.0, 0.0, 1.0, 8.0];
        let features = vec![
            feature(
                "A&<PLANE>",
                "PLANE",
                &pl,
                &[0.0, 0.0, 10.001, 0.0, 0.0, 1.0],
            ),
            feature(
                "HOLE",
                "CYLNDR",
                &cyl,
                &[20.01, 20.0, 5.0, 0.0, 0.0, 1.0, 8.02],
            ),
            feature(
                "RIM",
                "CIRCLE",
                &cyl,
                &[20.0, 20.0, 5.0, 0.0, 0.0, 1.0, 8.01],
            ),
            feature("TIP", "CONE", &cyl, &cyl),
            feature(
                "BALL",
                "SPHERE",
                &[1.0, 2.0, 3.0, 10.0],
                &[1.0, 2.0, 3.0, 10.0],
            ),
            feature("PT", "POINT", &pl, &pl),
            feature("SLOT", "PARPLN", &cyl, &cyl),
            feature("GRID", "PATERN", &[], &[]),
            feature("FREE", "GSURF", &[1.0, 2.0, 3.0], &[]),
            feature("ODD", "CIRCLE", &[1.0], &[]),
        ];
        let z = |a: f64, w: f64| outcome(0.0, a, (0.0, w));
        let mut rows = vec![
            row("FL", "FLAT", &["A&<PLANE>"], &[], z(0.01, 0.05)),
            row("ST", "STRGHT", &["HOLE"], &[], z(0.01, 0.05)),
            row("CI", "CIRLTY", &["RIM"], &[], z(0.01, 0.05)),
            row("CY", "CYLCTY", &["HOLE"], &[], z(0.01, 0.05)),
            row("PL", "PROFL", &["A&<PLANE>"], &["A"], z(0.01, 0.05)),
            row("PS", "PROFS", &["FREE"], &["A", "B"], z(0.01, 0.05)),
            row("PE", "PERP", &["HOLE"], &["A"], z(0.01, 0.05)),
            row("PA", "PARLEL", &["A&<PLANE>"], &["B"], z(0.01, 0.05)),
            row("AN", "ANGLR", &["A&<PLANE>"], &["B"], z(0.01, 0.05)),
            row(
                "PO",
                "POS",
                &["HOLE"],
                &["A", "B", "C"],
                z(0.12, 0.1 + 0.04),
            ),
            row("PO", "POS", &["RIM"], &["A", "B", "C"], z(0.2, 0.1)),
            row("CO", "CONCEN", &["RIM"], &["D"], z(0.01, 0.05)),
            row("CX", "COAXL", &["HOLE"], &["D"], z(0.01, 0.05)),
            row("SY", "SYM", &["SLOT"], &["A"], z(0.01, 0.05)),
            row("CR", "CRNOUT", &["TIP"], &["D"], z(0.01, 0.05)),
            row("TR", "TRNOUT", &["HOLE"], &["D"], z(0.01, 0.05)),
            row(
                "DI",
                "DIAM",
                &["HOLE"],
                &[],
                outcome(8.0, 8.02, (-0.1, 0.1)),
            ),
            row("RA", "RAD", &["BALL"], &[], outcome(5.0, 5.0, (-0.1, 0.1))),
            row(
                "WI",
                "WIDTH",
                &["SLOT"],
                &[],
                outcome(8.0, 8.0, (-0.1, 0.1)),
            ),
            row(
                "DB",
                "DISTB",
                &["A&<PLANE>", "PT"],
                &[],
                outcome(10.0, 10.3, (-0.1, 0.1)),
            ),
            row(
                "AB",
                "ANGLB",
                &["A&<PLANE>", "HOLE"],
                &[],
                outcome(90.0, 90.01, (-0.5, 0.5)),
            ),
            row("WEIRD", "CORTOL", &["PT"], &[], z(0.01, 0.05)),
            row("T<1>&\"x\"", "FLAT", &["GONE"], &[], z(0.0, 0.05)),
        ];
        rows.push(Row {
            outcome: Outcome {
                nominal: 0.0,
                actual: f64::NAN,
                limits: (0.0, 0.0),
                note: Some("runout needs a <datum> & \"axis\"".into()),
            },
            ..row("NA", "TRNOUT", &["HOLE"], &[], z(0.0, 0.0))
        });
        Report {
            program: "P&<1>".into(),
            filnam: "P1 <RESULTS>".into(),
            plan: "plan's".into(),
            part: "part \"A\" & <B>".into(),
            setups: 1,
            touches: 100,
            scanned: 0,
            moves: 200,
            noise: 0.001,
            seed: 7,
            rows,
            features,
        }
    }

    fn meta() -> QifMeta {
        let mut tolerances = BTreeMap::new();
        tolerances.insert(
            "PO".to_string(),
            [
                "POS", "2D", "0.1", "MMC", "DAT(A)", "DAT(B)", "MMC", "DAT(C)",
            ]
            .map(String::from)
            .to_vec(),
        );
        tolerances.insert(
            "AN".to_string(),
            ["ANGLR", "30", "0.05", "RFS", "DAT(B)"]
                .map(String::from)
                .to_vec(),
        );
        QifMeta {
            spec: "a b&c.insp".into(),
            program: "p<1>.dmi".into(),
            tolerances,
        }
    }

    #[test]
    fn every_text_from_the_report_is_escaped() {
        let r = report();
        let doc = qif_results(&r, &meta());
        for raw in [
            "T<1>",
            "A&<PLANE>",
            "<datum>",
            "<B>",
            "p<1>",
            "P&<1>",
            "<RESULTS>",
        ] {
            assert!(!doc.contains(raw), "`{raw}` is written unescaped");
        }
        let els = elements(&doc);
        let texts = |name: &str| texts_of(&els, name);
        assert!(texts("Name").contains(&"T<1>&\"x\"".to_string()));
        assert!(texts("Name").contains(&"part \"A\" & <B>".to_string()));
        assert!(texts("FeatureName").contains(&"A&<PLANE>".to_string()));
        assert!(texts("Description").contains(&"runout needs a <datum> & \"axis\"".to_string()));
        assert!(texts("ReportNumber").contains(&"P1 <RESULTS>".to_string()));
        assert!(texts("URI").contains(&"p%3C1%3E.dmi".to_string()));
        assert!(texts("URI").contains(&"a%20b%26c.insp".to_string()));
    }

    #[test]
    fn the_document_is_deterministic_and_its_id_follows_its_content() {
        let (r, m) = (report(), meta());
        let a = qif_results(&r, &m);
        assert_eq!(a, qif_results(&r, &m));
        let id = |d: &str| texts_of(&elements(d), "QPId").remove(0);
        let q = id(&a);
        let b: Vec<&[u8]> = q.split('-').map(str::as_bytes).collect();
        assert_eq!(
            b.iter().map(|g| g.len()).collect::<Vec<_>>(),
            [8, 4, 4, 4, 12]
        );
        assert!(q.chars().all(|c| c == '-' || c.is_ascii_hexdigit()), "{q}");
        let mut moved = r.clone();
        moved.rows[0].outcome.actual += 0.001;
        assert_ne!(id(&qif_results(&moved, &m)), q);
        // No clock, no folders.
        assert!(!a.contains("TimeCreated") && !a.contains("TimeStamp"));
        let m2 = QifMeta::new(Path::new("/abs/dir/x.insp"), Path::new("/abs/y.dmi"), "");
        assert_eq!((m2.spec.as_str(), m2.program.as_str()), ("x.insp", "y.dmi"));
        assert!(!qif_results(&r, &m2).contains("/abs"));
    }

    #[test]
    fn each_row_and_feature_is_measured_once_and_every_id_resolves() {
        let r = report();
        let doc = qif_results(&r, &meta());
        let els = elements(&doc);
        let count = |suffix: &str| els.iter().filter(|e| e.0.ends_with(suffix)).count();
        assert_eq!(count("CharacteristicMeasurement"), r.rows.len());
        assert_eq!(count("FeatureMeasurement"), r.features.len());
        // Two rows of one tolerance share its definition.
        assert_eq!(count("CharacteristicDefinition"), r.rows.len() - 1);
        assert_eq!(count("CharacteristicItem"), r.rows.len());
        let mut ids = std::collections::BTreeSet::new();
        for e in &els {
            if let Some((_, v)) = e.1.iter().find(|(k, _)| k == "id") {
                assert!(ids.insert(v.clone()), "id {v} twice");
            }
        }
        let max = els[els.len() - 1]
            .1
            .iter()
            .find(|(k, _)| k == "idMax")
            .map(|(_, v)| v.clone());
        assert_eq!(max, Some(ids.len().to_string()));
        for e in &els {
            if (e.0.ends_with("Id") && e.0 != "QPId") || e.0 == "Id" {
                assert!(ids.contains(&e.2), "{} {} names no element", e.0, e.2);
            }
        }
        let statuses = texts_of(&els, "CharacteristicStatusEnum");
        let n = |s: &str| statuses.iter().filter(|x| *x == s).count();
        assert_eq!(n("FAIL"), r.failed());
        assert_eq!(n("NOT_ANALYZED"), r.unjudged());
        assert_eq!(n("PASS"), r.rows.len() - r.failed() - r.unjudged());
        assert_eq!(texts_of(&els, "InspectionStatusEnum"), ["FAIL", "FAIL"]);
        // Each kind as its QIF element.
        for tag in [
            "FlatnessCharacteristicDefinition",
            "StraightnessCharacteristicDefinition",
            "CircularityCharacteristicDefinition",
            "CylindricityCharacteristicDefinition",
            "LineProfileCharacteristicDefinition",
            "SurfaceProfileCharacteristicDefinition",
            "PerpendicularityCharacteristicDefinition",
            "ParallelismCharacteristicDefinition",
            "AngularityCharacteristicDefinition",
            "PositionCharacteristicDefinition",
            "ConcentricityCharacteristicDefinition",
            "CoaxialityCharacteristicDefinition",
            "SymmetryCharacteristicDefinition",
            "CircularRunoutCharacteristicDefinition",
            "TotalRunoutCharacteristicDefinition",
            "DiameterCharacteristicDefinition",
            "RadiusCharacteristicDefinition",
            "WidthCharacteristicDefinition",
            "DistanceBetweenCharacteristicDefinition",
            "AngleBetweenCharacteristicDefinition",
            "UserDefinedLinearCharacteristicDefinition",
            "PlaneFeatureMeasurement",
            "CylinderFeatureMeasurement",
            "CircleFeatureMeasurement",
            "ConeFeatureMeasurement",
            "SphereFeatureMeasurement",
            "PointFeatureMeasurement",
            "OppositeParallelPlanesFeatureMeasurement",
            "OtherSurfaceFeatureMeasurement",
            "OtherShapeFeatureMeasurement",
        ] {
            assert!(count(tag) > 0, "no {tag}");
        }
        // The kind QIF lacks is said to be generic, in the document itself.
        assert!(doc.contains("<!-- DMIS TOL/CORTOL has no QIF characteristic"));
    }

    fn texts_of(els: &[El], name: &str) -> Vec<String> {
        els.iter()
            .filter(|e| e.0 == name)
            .map(|e| e.2.clone())
            .collect()
    }

    #[test]
    fn tol_statements_give_modifiers_zones_and_bonus() {
        let doc = qif_results(&report(), &meta());
        let els = elements(&doc);
        // POS 2D at MMC on a datum frame A, B at MMC, C.
        let pos = doc
            .split("<PositionCharacteristicDefinition")
            .nth(1)
            .expect("a position");
        let pos = &pos[..pos
            .find("</PositionCharacteristicDefinition>")
            .expect("closed")];
        assert!(
            pos.contains("<ToleranceValue>0.1</ToleranceValue>"),
            "{pos}"
        );
        assert!(pos.contains("<MaterialCondition>MAXIMUM</MaterialCondition>"));
        assert!(pos.contains("<DiametricalZone/>"));
        let modifiers = texts_of(&els, "MaterialModifier");
        assert!(modifiers.contains(&"MAXIMUM".to_string()), "{modifiers:?}");
        // The hole's position was judged with 0.04 of bonus.
        assert_eq!(texts_of(&els, "Bonus"), ["0.04"]);
        // The basic angle of the angularity.
        assert_eq!(texts_of(&els, "Angle"), ["30"]);
        // A tolerance the program does not define: the report's limit.
        assert!(doc.contains("<ToleranceValue>0.05</ToleranceValue>"));
    }

    #[test]
    fn the_program_s_tol_statements_are_read() {
        let text = "DMISMN/'P',05.3\nUNITS/MM,ANGDEC\n\
                    F(A)=FEAT/PLANE,CART,0,0,0,0,0,1\nMEAS/PLANE,F(A),3\n\
                    PTMEAS/CART,0,0,0,0,0,1\nPTMEAS/CART,9,0,0,0,0,1\nPTMEAS/CART,0,9,0,0,0,1\n\
                    ENDMES\nDATDEF/FA(A),DAT(A)\n\
                    T(P1)=TOL/POS,2D,0.1,MMC,DAT(A),MMC\nT(F1)=TOL/FLAT,0.05\nENDFIL\n";
        assert!(
            crate::dmis::read(crate::source::FileId(0), text).is_ok(),
            "{:?}",
            crate::dmis::read(crate::source::FileId(0), text).err()
        );
        let m = QifMeta::new(Path::new("s.insp"), Path::new("p.dmi"), text);
        assert_eq!(
            m.tolerances.get("P1").map(Vec::as_slice),
            Some(&["POS", "2D", "0.1", "MMC", "DAT(A)", "MMC"].map(String::from)[..]),
            "{m:?}"
        );
        assert!(m.tolerances.contains_key("F1"), "{m:?}");
        assert!(
            QifMeta::new(Path::new("s"), Path::new("p"), "not DMIS at all")
                .tolerances
                .is_empty()
        );
    }

    #[test]
    fn numbers_are_decimals_without_exponent_or_negative_zero() {
        assert_eq!(dec(-0.0), "0");
        assert_eq!(dec(-1e-12), "0");
        assert_eq!(dec(1e-7), "0.0000001");
        assert_eq!(dec(1e21), "1000000000000000000000");
        assert_eq!(dec(0.1 + 0.2), "0.3");
        assert_eq!(dec(f64::NAN), "0");
        assert_eq!(nmtoken("A B<1>"), "A_B_1_");
    }
}
