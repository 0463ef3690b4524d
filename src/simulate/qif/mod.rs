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
//! The children: `features` maps each DMIS feature, `characteristics` each tolerance
//! with its zone, modifiers and datums, and `xml` writes the text. The document's
//! status is FAIL when a tolerance fails, else UNKNOWN when one was not judged, else
//! PASS.
//!
//! **Determinism:** no clock (no `Version`/`TimeCreated`, no time stamps), file names
//! without folders, ids numbered in report order, and the document's `QPId` is a
//! 128-bit FNV-1a hash of the rest of the document written as a UUID (version 8,
//! RFC 9562's custom form). Every text from the report is escaped.

mod characteristics;
mod features;
#[cfg(test)]
mod tests;
mod xml;

use super::Report;
use characteristics::{Chars, Datums};
use features::Feats;
use std::collections::BTreeMap;
use std::path::Path;
use xml::{dec, qpid, uri, Ids, Xml};

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
/// their measurements, valid against the DMSC's `QIFDocument.xsd` (see the notes of
/// the `features` and `characteristics` modules for how each DMIS feature and
/// tolerance maps).
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
