//! QIF 3 Results from the virtual CMM (`inspc simulate … --report OUT.qif`): the golden
//! programs of the examples run as `simulate.rs` runs them (at nominal, and with a
//! deviation that fails a tolerance), and a hand-built run with every tolerance and
//! feature kind, are each written as a QIF document that must validate against the
//! QIF 3.0 schemas in `../shared/qif3-schema` with `xmllint` and hold one measured
//! characteristic per tolerance row and one measured feature per feature row. Without
//! `xmllint` the schema check is skipped (and said so), unless `INSPC_REQUIRE_XMLLINT`
//! is set, as CI sets it.

use inspc::simulate::evaluate::Outcome;
use inspc::simulate::{qif_results, FeatureRow, Options, QifMeta, Report, Row};
use std::path::{Path, PathBuf};
use std::process::Command;

const SCHEMA: &str = "../shared/qif3-schema/QIFDocument.xsd";

/// Validates `doc` against the QIF 3 schemas; false when `xmllint` is missing and not
/// required.
pub(crate) fn validate(name: &str, doc: &str) -> bool {
    let found = Command::new("xmllint")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !found {
        assert!(
            std::env::var_os("INSPC_REQUIRE_XMLLINT").is_none(),
            "INSPC_REQUIRE_XMLLINT is set but xmllint is missing (apt-get install libxml2-utils)"
        );
        eprintln!("qif_results: xmllint is missing: {name} not validated against the QIF 3 schemas (install libxml2-utils)");
        return false;
    }
    assert!(
        Path::new(SCHEMA).exists(),
        "the QIF 3 schemas are expected in ../shared/qif3-schema beside the repository, as CI has them"
    );
    let dir = std::env::temp_dir().join(format!("inspc-qif-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let file = dir.join(format!("{name}.qif"));
    std::fs::write(&file, doc).expect("write the document");
    // `--nonet`: the schema's import of xmldsig from w3.org is skipped with a warning.
    let out = Command::new("xmllint")
        .args(["--nonet", "--noout", "--schema", SCHEMA])
        .arg(&file)
        .output()
        .expect("xmllint runs");
    let errors: Vec<String> = String::from_utf8_lossy(&out.stderr)
        .lines()
        .filter(|l| !l.contains("xmldsig") && !l.ends_with(" validates"))
        .map(String::from)
        .collect();
    assert!(
        out.status.success(),
        "{name}: the QIF document does not validate ({}):\n{}",
        file.display(),
        errors.join("\n")
    );
    true
}

/// The elements of `doc` whose name ends with `suffix`.
fn count(doc: &str, suffix: &str) -> usize {
    doc.lines()
        .filter_map(|l| l.trim_start().strip_prefix('<'))
        .filter_map(|l| l.split([' ', '>', '/']).next())
        .filter(|name| name.ends_with(suffix))
        .count()
}

/// The texts of the elements named `tag` (on one line each, as written).
fn texts<'a>(doc: &'a str, tag: &str) -> Vec<&'a str> {
    let (open, close) = (format!("<{tag}>"), format!("</{tag}>"));
    doc.lines()
        .filter_map(|l| {
            l.trim()
                .strip_prefix(open.as_str())?
                .strip_suffix(close.as_str())
        })
        .collect()
}

/// What every document of a run must say: one measurement per row and per feature,
/// their statuses, the document's.
pub(crate) fn check(name: &str, r: &Report, doc: &str) {
    assert_eq!(
        count(doc, "CharacteristicMeasurement"),
        r.rows.len(),
        "{name}: one measured characteristic per tolerance row"
    );
    assert_eq!(
        count(doc, "FeatureMeasurement"),
        r.features.len(),
        "{name}: one measured feature per feature row"
    );
    let status = texts(doc, "CharacteristicStatusEnum");
    let n = |s: &str| status.iter().filter(|x| **x == s).count();
    assert_eq!(n("FAIL"), r.failed(), "{name}");
    assert_eq!(n("NOT_ANALYZED"), r.unjudged(), "{name}");
    let whole = if r.failed() > 0 {
        "FAIL"
    } else if r.unjudged() > 0 {
        "UNKNOWN"
    } else {
        "PASS"
    };
    assert_eq!(texts(doc, "InspectionStatusEnum"), [whole, whole], "{name}");
    validate(name, doc);
}

/// Runs `program` against `spec` with the deviations `dev` (file text), as
/// `simulate.rs` runs it.
fn run(spec: &str, program: &str, dev: Option<&str>) -> Report {
    super::simulate::run(spec, program, dev, Options::default())
        .unwrap_or_else(|codes| panic!("{program}: the run stopped: {codes:?}"))
}

fn meta(spec: &str, program: &str) -> QifMeta {
    let text = std::fs::read_to_string(program).expect("the program");
    QifMeta::new(Path::new(spec), Path::new(program), &text)
}

/// The examples' golden programs at nominal — a perpendicularity to a datum on slots
/// (f2), a hundred holes positioned from datum A (the swiss block), touched and scanned
/// features (mixed sensors) — and f2 with its large slot tilted past its zone.
#[test]
fn example_runs_are_valid_qif_results() {
    let cases = [
        (
            "f2",
            "examples/f2.insp",
            "tests/cases/example_f2/program.dmi",
            None,
        ),
        (
            "f2_tilted",
            "examples/f2.insp",
            "tests/cases/example_f2/program.dmi",
            Some("feature large_slot tilt 0.4 about (0, 1, 0)"),
        ),
        (
            "swiss_block",
            "examples/swiss_block.insp",
            "tests/cases/example_swiss_block/program.dmi",
            None,
        ),
        (
            "mixed_sensors",
            "examples/mixed_sensors.insp",
            "tests/cases/example_mixed_sensors/program.dmi",
            None,
        ),
    ];
    for (name, spec, program, dev) in cases {
        let r = run(spec, program, dev);
        let m = meta(spec, program);
        let doc = qif_results(&r, &m);
        check(name, &r, &doc);
        if dev.is_some() {
            assert!(r.failed() > 0, "{name}: the deviation fails nothing");
        }
        if name == "swiss_block" {
            // The datum-referenced position: a frame of datum A, a diametrical zone.
            let pos = doc
                .split("<PositionCharacteristicDefinition ")
                .nth(1)
                .expect("a position");
            let pos = &pos[..pos
                .find("</PositionCharacteristicDefinition>")
                .expect("closed")];
            assert!(pos.contains("<DatumReferenceFrameId>"), "{pos}");
            assert!(pos.contains("<DiametricalZone/>"), "{pos}");
            assert_eq!(texts(&doc, "DatumLabel"), ["A"]);
            // Its TOL statement is read from the program.
            let p1 = m
                .tolerances
                .get("P1")
                .expect("T(P1) is read from the program");
            assert_eq!(&p1[..2], ["POS", "2D"], "{p1:?}");
        }
    }
}

/// `--report OUT.qif` writes the same document as the library (the same seed: the
/// CLI's default is 1).
#[test]
fn the_cli_writes_qif_for_a_qif_report() {
    let (spec, program) = ("examples/f2.insp", "tests/cases/example_f2/program.dmi");
    let dir = std::env::temp_dir().join(format!("inspc-qif-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let out: PathBuf = dir.join("f2.qif");
    let status = Command::new(env!("CARGO_BIN_EXE_inspc"))
        .args(["simulate", program, spec, "--seed", "0", "--report"])
        .arg(&out)
        .output()
        .expect("inspc runs");
    assert!(status.status.success(), "{status:?}");
    let written = std::fs::read_to_string(&out).expect("the report is written");
    let r = run(spec, program, None);
    let expected = qif_results(&r, &meta(spec, program));
    let differ = written.lines().zip(expected.lines()).find(|(a, b)| a != b);
    assert!(
        written == expected,
        "the CLI's document differs: {differ:?}"
    );
}

fn feature(label: &str, kind: &str, nominal: &[f64], actual: &[f64]) -> FeatureRow {
    FeatureRow {
        label: label.into(),
        kind: kind.into(),
        inner: true,
        nominal: nominal.to_vec(),
        actual: actual.to_vec(),
        form: (!actual.is_empty()).then_some(0.002),
        points: 12,
    }
}

fn row(t: &str, kind: &str, features: &[&str], datums: &[&str], o: (f64, f64, f64, f64)) -> Row {
    Row {
        tolerance: t.into(),
        kind: kind.into(),
        features: features.iter().map(|s| s.to_string()).collect(),
        datums: datums.iter().map(|s| s.to_string()).collect(),
        words: datums.iter().map(|d| format!("DAT({d})")).collect(),
        outcome: Outcome {
            nominal: o.0,
            actual: o.1,
            limits: (o.2, o.3),
            note: None,
        },
    }
}

/// Every tolerance kind inspc writes or reads, every feature kind, a failure, a
/// tolerance not judged, one of a kind QIF lacks and text that needs escaping: all in
/// one valid document.
#[test]
fn every_kind_is_a_valid_qif_element() {
    let plane = [0.0, 0.0, 10.0, 0.0, 0.0, 1.0];
    let axis = [20.0, 20.0, 5.0, 0.0, 0.0, 1.0, 8.0];
    let features = vec![
        feature("A", "PLANE", &plane, &plane),
        feature("B<&>", "PLANE", &plane, &plane),
        feature(
            "BORE",
            "CYLNDR",
            &axis,
            &[20.01, 20.0, 5.0, 0.0, 0.0, 1.0, 8.01],
        ),
        feature("RIM", "CIRCLE", &axis, &axis),
        feature("TAPER", "CONE", &axis, &axis),
        feature(
            "BALL",
            "SPHERE",
            &[0.0, 0.0, 0.0, 12.0],
            &[0.0, 0.0, 0.0, 12.01],
        ),
        feature("TOUCH", "POINT", &plane, &plane),
        feature("SLOT", "PARPLN", &axis, &axis),
        feature("HOLES", "PATERN", &[], &[]),
        feature("SKIN", "GSURF", &[1.0, 2.0, 3.0], &[]),
    ];
    let zone = |a: f64, w: f64| (0.0, a, 0.0, w);
    let size = |n: f64, a: f64| (n, a, -0.1, 0.1);
    let rows = vec![
        row("FLAT_A", "FLAT", &["A"], &[], zone(0.01, 0.05)),
        row("STR", "STRGHT", &["BORE"], &[], zone(0.01, 0.05)),
        row("CIR", "CIRLTY", &["RIM"], &[], zone(0.01, 0.05)),
        row("CYL", "CYLCTY", &["BORE"], &[], zone(0.01, 0.05)),
        row("PRL", "PROFL", &["B<&>"], &["A"], zone(0.01, 0.05)),
        row("PRS", "PROFS", &["SKIN"], &["A", "B"], zone(0.01, 0.05)),
        row("PRP", "PROFP", &["TOUCH"], &["A"], zone(0.01, 0.05)),
        row("PERP", "PERP", &["BORE"], &["A"], zone(0.01, 0.05)),
        row("PAR", "PARLEL", &["B<&>"], &["A"], zone(0.01, 0.05)),
        row("ANG", "ANGLR", &["B<&>"], &["A"], zone(0.01, 0.05)),
        row("POS", "POS", &["BORE"], &["A", "B"], zone(0.3, 0.1)),
        row("POS_PAT", "POS", &["HOLES"], &["A"], zone(0.03, 0.1)),
        row("POS_BALL", "POS", &["BALL"], &[], zone(0.03, 0.1)),
        row("CON", "CONCEN", &["RIM"], &["A"], zone(0.01, 0.05)),
        row("COA", "COAXL", &["BORE"], &["A"], zone(0.01, 0.05)),
        row("SYM", "SYM", &["SLOT"], &["A"], zone(0.01, 0.05)),
        row("CRN", "CRNOUT", &["TAPER"], &["A"], zone(0.01, 0.05)),
        row("TRN", "TRNOUT", &["BORE"], &["A"], zone(0.01, 0.05)),
        row("DIA", "DIAM", &["BORE"], &[], size(8.0, 8.01)),
        row("RAD", "RAD", &["BALL"], &[], size(6.0, 6.005)),
        row("WID", "WIDTH", &["SLOT"], &[], size(8.0, 8.0)),
        row("DST", "DISTB", &["A", "B<&>"], &[], size(10.0, 10.02)),
        row("DST_AX", "DISTB", &["BORE", "TAPER"], &[], size(0.0, 0.0)),
        row("ANB", "ANGLB", &["A", "BORE"], &[], size(90.0, 90.01)),
        row("ODD", "ANGLWRT", &["A"], &[], size(45.0, 45.0)),
        row("NA", "TRNOUT", &["SLOT"], &[], (0.0, f64::NAN, 0.0, 0.0)),
        row("LOST", "FLAT", &["NOT_OUTPUT"], &[], zone(0.01, 0.05)),
    ];
    let r = Report {
        program: "ALL&KINDS".into(),
        filnam: "ALL <KINDS>".into(),
        plan: "all".into(),
        part: "block \"7\"".into(),
        setups: 2,
        touches: 120,
        scanned: 300,
        moves: 240,
        noise: 0.0,
        seed: 1,
        rows,
        features,
    };
    let meta = QifMeta {
        spec: "all kinds.insp".into(),
        program: "all.dmi".into(),
        ..QifMeta::default()
    };
    let doc = qif_results(&r, &meta);
    assert!(r.failed() == 1 && r.unjudged() == 1, "{}", r.text());
    check("every_kind", &r, &doc);
    for tag in [
        "PointProfileCharacteristicDefinition",
        "UserDefinedLinearCharacteristicDefinition",
        "ConeFeatureMeasurement",
        "SphereFeatureMeasurement",
        "OtherShapeFeatureMeasurement",
        "OtherSurfaceFeatureMeasurement",
    ] {
        assert_eq!(count(&doc, tag), 1, "{tag}");
    }
    assert!(doc.contains("<!-- DMIS TOL/ANGLWRT has no QIF characteristic"));
}
