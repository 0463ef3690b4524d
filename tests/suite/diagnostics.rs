//! Many small diagnostic cases, each with its expected code, span and message; the
//! cases that are a spec in and its diagnostics out are annotated specs under
//! `tests/diagnostics/` (`diag_files.rs`).

use crate::common;

use common::{check_files, check_src, Diags, Flat};

/// Asserts that a diagnostic with `code` labels exactly `span` and its message contains
/// `message`, and marks it expected: a test that expects any diagnostic must expect
/// them all (see `common::Diags`).
#[track_caller]
fn expect(diags: &Diags, code: &str, span: &str, message: &str) {
    let found = diags.saw(|d| d.code == code && d.span_text == span && d.message.contains(message));
    let found = found.or_else(|| diags.saw(|d| d.code == code && d.span_text == span));
    let Some(d) = found else {
        panic!("no `{code}` on `{span}`; got:\n{}", render(diags));
    };
    assert!(
        d.message.contains(message),
        "`{code}` message {:?} lacks {message:?}",
        d.message
    );
    assert!(!d.help.is_empty(), "`{code}` has no help");
}

#[track_caller]
fn expect_src(src: &str, code: &str, span: &str, message: &str) {
    expect(&check_src(src), code, span, message);
}

fn render(diags: &[Flat]) -> String {
    diags
        .iter()
        .map(|d| format!("  {} `{}`: {} ({})", d.code, d.span_text, d.message, d.help))
        .collect::<Vec<_>>()
        .join("\n")
}

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

// ---- measurement graph ----

#[test]
fn tolerance_on_the_wrong_surface_type() {
    let src = format!(
        "{BLOCK}    cut hole bore {{ at (25, 20, 20), axis -z, diameter 10, depth through }}\n    feature hole = bore.wall\n    feature top = stock.top\n    tolerance cyl = cylindricity(top, 0.01 mm)\n    tolerance ok = cylindricity(hole, 0.01 mm)\n}}\n"
    );
    let diags = check_src(&src);
    expect(
        &diags,
        "insp::graph::wrong_surface",
        "cyl",
        "face `stock.top` of feature `top` is a plane",
    );
    assert_eq!(
        diags
            .iter()
            .filter(|d| d.code == "insp::graph::wrong_surface")
            .count(),
        1,
        "{}",
        render(&diags)
    );
}

#[test]
fn face_with_no_room_for_points() {
    let src = "use std::heads::PH6\nuse std::probes::TP20_D2_L20\npart p {\n    units mm\n    stock box(100, 100, 20)\n    cut hole bore { at (50, 50, 20), axis -z, diameter 40, depth through }\n    feature top = stock.top\n}\ncmm lab { table { z 0 mm }, ram { radius 35 mm, length 600 mm }, head PH6, probes [p1: TP20_D2_L20] }\nplan q { part p, cmm lab, sample top with uniform(points 4, inset 45 %) }\n";
    let diags = check_src(src);
    expect(
        &diags,
        "insp::graph::no_points",
        "top",
        "face `stock.top` of feature `top` gets no measuring point",
    );
    assert!(diags.iter().all(|d| d.warning), "{}", render(&diags));
}

#[test]
fn no_points_in_an_imported_part_points_into_the_part_file() {
    let part: &[u8] = b"part p {\n    units mm\n    stock box(100, 100, 20)\n    cut hole bore { at (50, 50, 20), axis -z, diameter 40, depth through }\n    feature top = stock.top\n}\n";
    let main: &[u8] = b"use \"part.insp\"\nuse std::heads::PH6\nuse std::probes::TP20_D2_L20\ncmm lab { table { z 0 mm }, ram { radius 35 mm, length 600 mm }, head PH6, probes [p1: TP20_D2_L20] }\nplan q { part p, cmm lab, sample top with uniform(points 4, inset 45 %) }\n";
    let diags = check_files(&[("main.insp", main), ("part.insp", part)]);
    expect(
        &diags,
        "insp::graph::no_points",
        "top",
        "gets no measuring point",
    );
    let d = diags
        .iter()
        .find(|d| d.code == "insp::graph::no_points")
        .unwrap();
    assert!(d.file.ends_with("part.insp"), "filed under {}", d.file);
}

#[test]
fn lengths_past_ten_metres_are_refused() {
    // A box of 1e200 mm used to panic inside the boolean library; a clearance of 1e9 mm
    // ran the path stage for hours; a search of 1e300 mm wrote a 301-character line.
    expect_src(
        &part("cut hole h { at (0, 0, 20), axis -z, diameter 5, depth 1.7e308 }"),
        "insp::resolve::out_of_range",
        "1.7e308",
        "at most 10 m",
    );
    let d = check_src(
        "use std::cmms::bridge_fixed\npart p { units mm, stock box(1e200, 60, 40) }\nplan q { part p, cmm bridge_fixed, motion { search 1e300 mm, clearance 1e9 mm } }\n",
    );
    expect(
        &d,
        "insp::resolve::out_of_range",
        "1e200",
        "1e200 mm is out of range",
    );
    expect(
        &d,
        "insp::resolve::out_of_range",
        "1e300 mm",
        "at most 10 m",
    );
    expect(&d, "insp::resolve::out_of_range", "1e9 mm", "at most 10 m");
}

#[test]
fn a_negative_corner_radius_is_an_error() {
    expect_src(
        &part("cut pocket q { at (25, 20, 20), along +x, into -z, size (10, 10), depth 5, corner_radius -3 }"),
        "insp::resolve::out_of_range",
        "-3",
        "cannot be negative",
    );
}

#[test]
fn huge_direction_components_do_not_vanish() {
    // (1e300, 0, 0) used to overflow into a zero vector that passed as a direction.
    let d = check_src(&part(
        "cut hole h { at (25, 20, 20), axis (0, 0, -1e300), diameter 5, depth 5 }\nfeature w = h.wall",
    ));
    assert!(
        d.iter().all(|x| x.warning),
        "{:?}",
        d.iter().map(|x| &x.code).collect::<Vec<_>>()
    );
}

#[test]
fn a_part_has_at_most_two_thousand_instances_in_all() {
    // Each pattern is within its limit; together they are not.
    let d = check_src(&part(
        "cut hole a { at (5, 5, 20), axis -z, diameter 0.1, depth 5, pattern grid(40, 30, 0.4, 0.4) }\ncut hole b { at (5, 30, 20), axis -z, diameter 0.1, depth 5, pattern grid(40, 25, 0.4, 0.4) }",
    ));
    expect(
        &d,
        "insp::resolve::out_of_range",
        "b",
        "brings the part to 2200 instances",
    );
}

#[test]
fn a_face_gets_at_most_a_thousand_points() {
    expect_src(
        "sampling s { plane uniform(points 10000) }",
        "insp::resolve::out_of_range",
        "10000",
        "at most 1000 points",
    );
}

#[test]
fn a_hole_pointing_out_of_the_part_misses_it() {
    // It used to cut a phantom 1.7 mm hole: the overlap its tool keeps behind the entry.
    let d = common::plan_files(&[(
        "main.insp",
        part("cut hole h { at (25, 20, 20), axis +z, diameter 5, depth 10 }").as_bytes(),
    )]);
    expect(&d, "insp::geometry::misses_part", "h", "misses the part");
}

#[test]
fn a_pattern_missing_the_part_is_one_error_and_its_faces_are_not_gone() {
    // 1,600 instances used to give 1,600 errors, and every face naming them one more.
    let d = common::plan_files(&[(
        "main.insp",
        part("cut hole h { at (-500, -500, 20), axis -z, diameter 2, depth 5, pattern grid(40, 40, 5, 5) }\nfeature holes = h.wall")
            .as_bytes(),
    )]);
    expect(
        &d,
        "insp::geometry::misses_part",
        "h",
        "1600 of the 1600 instances of `h` miss it",
    );
}

#[test]
fn a_bore_just_wider_than_the_tip_is_measured_and_a_tip_as_wide_is_not() {
    // The 2 mm retract point used to land past the far wall of a Ø2.5 bore, so a Ø2 tip
    // "did not fit" at any point; it waits on the axis now. A Ø4 tip in a 4 mm slot has
    // no room to back off and is refused (it used to pass the 0.9 × radius clearance).
    let spec = |d: &str| {
        format!("use std::heads::PH6\nuse std::probes::TP20_D2_L20\n{}\ncmm lab {{ table {{ z 0 mm }}, ram {{ radius 35 mm, length 600 mm }}, head PH6, probes [p1: TP20_D2_L20] }}\nplan q {{ part p, cmm lab }}\n",
            part(&format!("cut hole h {{ at (25, 20, 20), axis -z, diameter {d}, depth 6 }}\nfeature bore = h.wall\ntolerance t = diameter(bore, {d} mm ± 0.02 mm)")))
    };
    let d = common::plan_files(&[("main.insp", spec("2.5").as_bytes())]);
    assert_eq!(d.len(), 0, "{}", render(&d));
    let d = common::plan_files(&[("main.insp", spec("2").as_bytes())]);
    expect(
        &d,
        "insp::plan::uninspectable_face",
        "bore",
        "to back off the surface",
    );
}

#[test]
fn a_negative_margin_is_refused() {
    let d = check_src(&format!(
        "{}\nuse std::cmms::bridge_fixed\nplan q {{ part p, cmm bridge_fixed, motion {{ margin -1 mm }} }}\n",
        part("feature top = stock.top")
    ));
    expect(&d, "insp::resolve::out_of_range", "-1 mm", "`margin`");
}

#[test]
fn fixtures_are_checked_by_kind_and_by_label() {
    let d = check_src(&format!(
        "{}\nfixture f {{ kind clamp, height 10 mm }}\nfixture g {{ kind sine_plate, tilt 0 deg .. 120 deg, height 10 mm }}\ncmm lab {{ table {{ z 0 mm }}, ram {{ radius 35 mm, length 600 mm }}, head std::heads::PH6, probes [p1: std::probes::TP20_D2_L20], fixtures [f: f, g: g] }}\nplan q {{ part p, cmm lab, fixtures [h] }}\n",
        part("feature top = stock.top")
    ));
    expect(&d, "insp::resolve::unknown_name", "clamp", "fixture kind");
    expect(
        &d,
        "insp::resolve::out_of_range",
        "0 deg .. 120 deg",
        "`tilt` range",
    );
    expect(&d, "insp::resolve::unknown_name", "h", "fixture");
}

#[test]
fn a_plan_samples_at_most_five_thousand_points() {
    let d = check_src(&format!(
        "{}\ncmm lab {{ table {{ z 0 mm }}, ram {{ radius 35 mm, length 600 mm }}, head std::heads::PH6, probes [p1: std::probes::TP20_D2_L20] }}\nplan q {{ part p, cmm lab, sample all with uniform(points 1000) }}\n",
        part("feature all = stock.top + stock.bottom + stock.front + stock.back + stock.left + stock.right")
    ));
    expect(
        &d,
        "insp::graph::too_many_points",
        "q",
        "more than 5000 measuring points",
    );
}

#[test]
fn a_pocket_pointing_out_of_the_part_misses_it() {
    let d = common::plan_files(&[(
        "main.insp",
        part("cut pocket q { at (25, 20, 20), along +x, into +z, size (10, 10), depth 5 }")
            .as_bytes(),
    )]);
    expect(&d, "insp::geometry::misses_part", "q", "misses the part");
}
