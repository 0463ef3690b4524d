//! The diagnostic cases that need Rust. A case that is a spec in and its diagnostics out
//! is an annotated spec under `tests/diagnostics/` instead (`diag_files.rs`); these
//! build their input (ten thousand brackets), read no spec (a root file that is not
//! there), hold bytes the repository's `.insp` files may not (`fmt.rs` reads every one
//! as UTF-8), or look at the model rather than at diagnostics.

use crate::common::{check_files, check_src};

const BLOCK: &str = "part p {\n    units mm\n    stock box(50, 40, 20)\n";

fn part(body: &str) -> String {
    format!("{BLOCK}{body}\n}}\n")
}

// ---- syntax ---------------------------------------------------------------------------

#[test]
fn deep_nesting_is_an_error_not_a_crash() {
    let src = format!(
        "part p {{ units mm, stock box({}1{}) }}",
        "(".repeat(5000),
        ")".repeat(5000)
    );
    let d = check_src(&src);
    assert_eq!(d.only().code, "insp::syntax::too_deep");
}

// ---- loading --------------------------------------------------------------------------

#[test]
fn unreadable_root_file() {
    let world = inspc::source::MemoryWorld::new();
    let checked = inspc::check(&world, &[std::path::PathBuf::from("missing.insp")]);
    assert_eq!(checked.diagnostics.len(), 1);
    assert_eq!(checked.diagnostics[0].code(), "insp::load::unreadable");
}

#[test]
fn non_utf8_file_points_at_the_bad_byte() {
    let d = check_files(&[
        ("main.insp", b"use \"b.insp\"\n"),
        ("b.insp", b"// ok\n// caf\xe9\n"),
    ]);
    let e = d
        .iter()
        .find(|x| x.code == "insp::load::not_utf8")
        .expect("not_utf8 reported");
    assert_eq!(e.file, "b.insp");
}

// ---- units and values -------------------------------------------------------------------

#[test]
fn units_convert_to_millimetres_and_degrees() {
    let world = {
        let mut w = inspc::source::MemoryWorld::new();
        w.insert("m.insp", "stylus s { tip 0.1 in, length 2 cm, stem 1000 um }\nhead h { kind indexable, a 0 rad .. 1.5707963267948966 rad, b -180 deg .. 180 deg, step 7.5 deg, diameter 60 mm, length 0.1 m }");
        w
    };
    let c = inspc::check(&world, &["m.insp".into()]);
    assert!(!c.has_errors());
    let s = c.model.styli.iter().find(|s| s.name == "s").unwrap();
    assert!(
        (s.tip - 2.54).abs() < 1e-12
            && (s.length - 20.0).abs() < 1e-12
            && (s.stem - 1.0).abs() < 1e-12
    );
    let h = c.model.heads.iter().find(|h| h.name == "h").unwrap();
    assert!((h.length - 100.0).abs() < 1e-12);
    assert!(
        matches!(h.kind, inspc::model::HeadKind::Indexable { a, .. } if (a[1] - 90.0).abs() < 1e-9)
    );
}

/// Outside a part a bare number is `insp::resolve::missing_unit`
/// (`tests/diagnostics/resolve/missing_unit.insp`).
#[test]
fn bare_numbers_take_the_part_units() {
    let c = {
        let mut w = inspc::source::MemoryWorld::new();
        w.insert("m.insp", "part p { units in, stock box(2, 3, 1) }");
        inspc::check(&w, &["m.insp".into()])
    };
    assert!(!c.has_errors());
    assert!(
        matches!(c.model.parts[0].geometry, inspc::model::Geometry::Stock(inspc::model::Stock::Box { size }) if (size[0] - 50.8).abs() < 1e-9)
    );
}

#[test]
fn a_ph10_has_720_orientations() {
    let c = {
        let mut w = inspc::source::MemoryWorld::new();
        w.insert("m.insp", "");
        inspc::check(&w, &["m.insp".into()])
    };
    for name in ["PH9", "PH10M", "PH10MQ"] {
        let h = c.model.heads.iter().find(|h| h.name == name).unwrap();
        assert_eq!(h.orientations().len(), 720, "{name}");
    }
    assert!(c
        .model
        .heads
        .iter()
        .find(|h| h.name == "PH6")
        .unwrap()
        .orientations()
        .is_empty());
}

// ---- tolerances -------------------------------------------------------------------------

#[test]
fn size_limits_resolve_to_lower_and_upper() {
    let mut w = inspc::source::MemoryWorld::new();
    w.insert("m.insp", part("cut hole h { at (25, 20, 20), axis -z, diameter 20, depth 5 }\nfeature bore = h.wall\ntolerance D = diameter(bore, 20 mm +0.05 mm -0.1 mm)"));
    let c = inspc::check(&w, &["m.insp".into()]);
    let t = &c.model.parts[0].tolerances[0];
    match t.value {
        inspc::model::TolValue::Size {
            nominal,
            lower,
            upper,
        } => {
            assert_eq!(nominal, 20.0);
            assert!((lower - 19.9).abs() < 1e-12 && (upper - 20.05).abs() < 1e-12);
        }
        _ => panic!("size expected"),
    }
}
