//! The writer's tests: a made-up run with every feature and tolerance kind, read back
//! as XML.

use super::*;
use crate::simulate::evaluate::Outcome;
use crate::simulate::{FeatureRow, Row};
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
        words: datums.iter().map(|d| format!("DAT({d})")).collect(),
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
