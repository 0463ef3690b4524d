//! Many small diagnostic cases, each with its expected code, span and message.

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

// ---- names ----------------------------------------------------------------------------

#[test]
fn unknown_name_with_did_you_mean() {
    let src = "use std::heads::PH6\nuse std::probes::TP20_D2_L20\ncmm lab { ram { radius 35 mm, length 600 mm }, head PH66, probes [p1: TP20_D2_L20] }\n";
    let d = check_src(src);
    expect(
        &d,
        "insp::resolve::unknown_name",
        "PH66",
        "unknown head `PH66`",
    );
    assert!(
        d.iter().any(|x| x.help == "did you mean `PH6`?"),
        "{}",
        render(&d)
    );
}

#[test]
fn failed_import_does_not_cascade() {
    let d = check_src("use std::heads::PH66\ncmm lab { ram { radius 35 mm, length 600 mm }, head PH66, probes [p1: std::probes::TP20_D2_L20] }\n");
    assert_eq!(d.len(), 1, "{}", render(&d));
}

#[test]
fn wrong_kind_of_item() {
    expect_src(
        "use std::probes::TP20_D2_L20\ncmm lab { ram { radius 35 mm, length 600 mm }, head TP20_D2_L20, probes [p1: TP20_D2_L20] }\n",
        "insp::resolve::wrong_kind",
        "TP20_D2_L20",
        "expected a head, found a probe",
    );
}

#[test]
fn duplicate_names_at_top_level_and_in_parts() {
    expect_src(
        "stylus s { tip 2 mm, length 20 mm, stem 1 mm }\nbody s { diameter 13 mm, length 30 mm }\n",
        "insp::resolve::duplicate_name",
        "s",
        "`s` is declared twice",
    );
    expect_src(
        &part("feature top = stock.top\nfeature top = stock.bottom"),
        "insp::resolve::duplicate_name",
        "top",
        "declared twice",
    );
}

#[test]
fn imported_name_clashing_with_a_declaration() {
    expect_src(
        "use std::heads::PH6\nhead PH6 { kind fixed, diameter 20 mm, length 40 mm }\n",
        "insp::resolve::duplicate_name",
        "PH6",
        "declared twice",
    );
}

#[test]
fn unknown_and_duplicate_properties() {
    let d = check_src("stylus s { tip 2 mm, widht 3 mm, length 20 mm, stem 1 mm, tip 3 mm }\n");
    expect(
        &d,
        "insp::resolve::unknown_property",
        "widht",
        "unknown property `widht` for stylus `s`",
    );
    expect(
        &d,
        "insp::resolve::duplicate_property",
        "tip",
        "`tip` is given twice",
    );
}

#[test]
fn missing_property_points_at_the_item_name() {
    expect_src(
        "stylus s { tip 2 mm, stem 1 mm }\n",
        "insp::resolve::missing_property",
        "s",
        "stylus `s` needs `length`",
    );
    expect_src(
        "part p { stock box(1, 2, 3) }\n",
        "insp::resolve::missing_property",
        "p",
        "needs `units`",
    );
}

#[test]
fn datum_on_a_feature_that_does_not_exist() {
    expect_src(
        &part("feature top = stock.top\ndatum A = tpo"),
        "insp::resolve::unknown_name",
        "tpo",
        "unknown face or feature `tpo`",
    );
}

#[test]
fn datum_used_but_not_declared() {
    expect_src(
        &part("feature side = stock.left\ntolerance T = perpendicularity(side, 0.1 mm, B)"),
        "insp::resolve::unknown_name",
        "B",
        "unknown datum `B`",
    );
}

#[test]
fn feature_with_no_faces() {
    expect_src(
        &part("feature nothing"),
        "insp::resolve::empty_feature",
        "nothing",
        "feature `nothing` has no faces",
    );
}

#[test]
fn face_roles_are_checked() {
    expect_src(
        &part("feature f = stock.topp"),
        "insp::resolve::unknown_face",
        "topp",
        "the stock has no face `topp`",
    );
    let d = check_src(&part(
        "cut hole h { at (25, 20, 20), axis -z, diameter 6, depth through }\nfeature f = h.bottom",
    ));
    expect(
        &d,
        "insp::resolve::unknown_face",
        "bottom",
        "hole `h` has no face `bottom`",
    );
    assert!(d[0].help.contains("through hole"), "{}", d[0].help);
}

#[test]
fn pattern_instances_are_checked() {
    let src = part("cut hole g { at (5, 5, 20), axis -z, diameter 2, depth 5, pattern grid(3, 2, 10, 10) }\nfeature a = g[5].wall\nfeature b = g[6].wall");
    let d = check_src(&src);
    assert!(!d.iter().any(|x| x.span_text == "5"), "{}", render(&d));
    expect(
        &d,
        "insp::resolve::out_of_range",
        "6",
        "instance 6 is out of range",
    );
}

#[test]
fn huge_patterns_are_refused() {
    expect_src(&part("cut hole g { at (5, 5, 20), axis -z, diameter 2, depth 5, pattern grid(1000, 1000, 1, 1) }"), "insp::resolve::out_of_range", "grid(1000, 1000, 1, 1)", "pattern of 1000000 instances");
}

#[test]
fn features_cannot_use_features_declared_below() {
    expect_src(
        &part("feature a = b\nfeature b = stock.top"),
        "insp::resolve::unknown_name",
        "b",
        "declared above",
    );
}

#[test]
fn operation_as_a_whole_is_not_a_face() {
    let d = check_src(&part(
        "cut slot s { at (25, 0, 20), along +y, width 5, depth 5 }\nfeature f = s",
    ));
    expect(&d, "insp::resolve::type_mismatch", "s", "expected a face");
    assert!(d[0].help.contains("`s.walls`"), "{}", d[0].help);
}

#[test]
fn mesh_and_stock_only_statements() {
    expect_src(
        &part("feature f = segment 3"),
        "insp::resolve::needs_mesh",
        "segment 3",
        "`segment` needs a mesh part",
    );
    let d = check_files(&[("main.insp", b"part p { units mm, mesh \"p.stl\", cut hole h { at (0, 0, 0), axis -z, diameter 5, depth 5 } }"), ("p.stl", b"solid")]);
    expect(
        &d,
        "insp::resolve::needs_stock",
        "cut hole h { at (0, 0, 0), axis -z, diameter 5, depth 5 }",
        "needs stock",
    );
}

const TETRA_OBJ: &[u8] =
    b"g face_1\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";

#[test]
fn mesh_files_are_found_relative_to_the_spec() {
    let ok = check_files(&[
        (
            "specs/main.insp",
            b"part p { units mm, mesh \"../meshes/p.obj\", feature f = group \"face_1\" }",
        ),
        ("meshes/p.obj", TETRA_OBJ),
    ]);
    assert!(ok.is_empty(), "{}", render(&ok));
    expect_src(
        "part p { units mm, mesh \"p.obj\" }",
        "insp::resolve::file_not_found",
        "\"p.obj\"",
        "mesh file `p.obj` not found",
    );
    expect_src(
        "part p { units mm, mesh \"p.iges\" }",
        "insp::resolve::mesh_format",
        "\"p.iges\"",
        "unsupported mesh format `.iges`",
    );
}

#[test]
fn geometry_sources() {
    expect_src(
        "part p { units mm }",
        "insp::resolve::no_geometry",
        "p",
        "part `p` has no geometry",
    );
    expect_src(
        "part p { units mm, stock box(1, 1, 1), stock sphere(2) }",
        "insp::resolve::duplicate_geometry",
        "sphere(2)",
        "two geometry sources",
    );
    expect_src(
        "part p { units mm, stock cube(1, 1, 1) }",
        "insp::resolve::unknown_name",
        "cube",
        "unknown stock shape `cube`",
    );
}

#[test]
fn cut_and_add_must_match_the_operation() {
    expect_src(
        &part("cut boss b { at (10, 10, 20), diameter 5, height 5 }"),
        "insp::resolve::wrong_operation",
        "boss",
        "a boss adds material",
    );
    expect_src(
        &part("cut hoel h { at (10, 10, 20), axis -z, diameter 5, depth 5 }"),
        "insp::resolve::unknown_name",
        "hoel",
        "unknown machining feature `hoel`",
    );
}

#[test]
fn slot_direction_must_cross_its_depth() {
    expect_src(
        &part("cut slot s { at (25, 0, 20), along -z, width 5, depth 5 }"),
        "insp::resolve::out_of_range",
        "-z",
        "perpendicular to `into`",
    );
}

// ---- units and values -------------------------------------------------------------------

#[test]
fn unknown_units_suggest() {
    let d = check_src("stylus s { tip 2 mmm, length 20 mm, stem 1 mm }");
    expect(
        &d,
        "insp::resolve::unknown_unit",
        "mmm",
        "unknown unit `mmm`",
    );
    assert_eq!(d[0].help, "did you mean `mm`?");
}

#[test]
fn a_length_where_an_angle_belongs_and_back() {
    expect_src(
        "stylus s { tip 2 mm, length 20 deg, stem 1 mm }",
        "insp::resolve::unit_mismatch",
        "20 deg",
        "expected a length, found an angle",
    );
    expect_src(
        "head h { kind indexable, a 0 mm .. 105 deg, b -180 deg .. 180 deg, step 7.5 deg, diameter 60 mm, length 100 mm }",
        "insp::resolve::unit_mismatch",
        "0 mm",
        "expected an angle, found a length",
    );
}

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

#[test]
fn bare_numbers_take_the_part_units_and_nothing_else() {
    let c = {
        let mut w = inspc::source::MemoryWorld::new();
        w.insert("m.insp", "part p { units in, stock box(2, 3, 1) }");
        inspc::check(&w, &["m.insp".into()])
    };
    assert!(!c.has_errors());
    assert!(
        matches!(c.model.parts[0].geometry, inspc::model::Geometry::Stock(inspc::model::Stock::Box { size }) if (size[0] - 50.8).abs() < 1e-9)
    );
    expect_src(
        "stylus s { tip 2, length 20 mm, stem 1 mm }",
        "insp::resolve::missing_unit",
        "2",
        "`2` needs a unit",
    );
}

#[test]
fn non_positive_sizes() {
    expect_src(
        "stylus s { tip 0 mm, length 20 mm, stem 1 mm }",
        "insp::resolve::non_positive",
        "0 mm",
        "`tip` must be greater than zero",
    );
    expect_src(
        "stylus s { tip 2 mm, length -20 mm, stem 1 mm }",
        "insp::resolve::non_positive",
        "-20 mm",
        "`length` must be greater than zero",
    );
    expect_src(
        "body b { diameter 0 mm, length 30 mm }",
        "insp::resolve::non_positive",
        "0 mm",
        "`diameter`",
    );
}

#[test]
fn tolerance_value_must_be_positive() {
    expect_src(
        &part("feature top = stock.top\ntolerance T = flatness(top, 0 mm)"),
        "insp::resolve::non_positive",
        "0 mm",
        "the flatness tolerance must be greater than zero",
    );
    expect_src(
        &part("feature top = stock.top\ntolerance T = flatness(top, -0.1 mm)"),
        "insp::resolve::non_positive",
        "-0.1 mm",
        "greater than zero",
    );
}

#[test]
fn head_ranges_and_steps() {
    expect_src(
        "head h { kind indexable, a 0 deg .. 105 deg, b -180 deg .. 180 deg, step 10 deg, diameter 60 mm, length 100 mm }",
        "insp::resolve::step_not_dividing",
        "10 deg",
        "step 10° does not divide the A range 0°..105°",
    );
    expect_src(
        "head h { kind indexable, a 0 deg .. 105 deg, b -180 deg .. 180 deg, step 0 deg, diameter 60 mm, length 100 mm }",
        "insp::resolve::non_positive",
        "0 deg",
        "`step`",
    );
    expect_src(
        "head h { kind swivel, diameter 60 mm, length 100 mm }",
        "insp::resolve::unknown_name",
        "swivel",
        "unknown head kind `swivel`",
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

#[test]
fn stem_thicker_than_tip_is_a_warning() {
    let d = check_src("stylus s { tip 1 mm, length 20 mm, stem 2 mm }");
    expect(
        &d,
        "insp::resolve::stem_thicker_than_tip",
        "2 mm",
        "is not thinner than its tip",
    );
    assert!(d[0].warning);
}

#[test]
fn zero_direction() {
    expect_src(
        &part("cut hole h { at (25, 20, 20), axis (0, 0, 0), diameter 6, depth 5 }"),
        "insp::resolve::zero_vector",
        "(0, 0, 0)",
        "zero vector",
    );
}

// ---- tolerances -------------------------------------------------------------------------

#[test]
fn tolerances_that_need_datums() {
    expect_src(
        &part("feature side = stock.left\ntolerance T = position(side, 0.1 mm)"),
        "insp::resolve::datums_required",
        "position(side, 0.1 mm)",
        "position needs a datum reference",
    );
}

#[test]
fn tolerances_that_must_not_have_datums() {
    let d = check_src(&part("feature top = stock.top\nfeature bot = stock.bottom\ndatum A = bot\ntolerance T = flatness(top, 0.05 mm, A)"));
    expect(
        &d,
        "insp::resolve::datums_forbidden",
        "A",
        "flatness takes no datum reference",
    );
    let d = check_src(&part("cut hole h { at (25, 20, 20), axis -z, diameter 6, depth 5 }\nfeature bore = h.wall\nfeature bot = stock.bottom\ndatum A = bot\ntolerance T = diameter(bore, 6 mm ± 0.1 mm, A)"));
    expect(
        &d,
        "insp::resolve::datums_forbidden",
        "A",
        "diameter takes no datum",
    );
}

#[test]
fn datum_referencing_its_own_feature() {
    expect_src(
        &part("feature top = stock.top\ndatum A = top\ntolerance T = parallelism(top, 0.05 mm, A)"),
        "insp::resolve::datum_self_reference",
        "A",
        "which is that same feature",
    );
}

#[test]
fn frames_expand_and_duplicates_are_caught() {
    let ok = check_src(&part("feature a = stock.bottom\nfeature b = stock.left\nfeature c = stock.front\nfeature side = stock.right\ndatum A = a\ndatum B = b\ndatum C = c\nframe ABC = [A, B(MMC), C]\ntolerance T = position(side, 0.1 mm, ABC)"));
    assert!(ok.is_empty(), "{}", render(&ok));
    expect_src(&part("feature a = stock.bottom\nfeature side = stock.right\ndatum A = a\ntolerance T = perpendicularity(side, 0.1 mm, A, A)"), "insp::resolve::duplicate_datum", "A", "appears twice");
}

#[test]
fn modifiers_and_zones() {
    expect_src(
        &part("feature top = stock.top\ntolerance T = cylindricity(top, 0.05 mm, LMC)"),
        "insp::resolve::modifier_not_allowed",
        "LMC",
        "cylindricity does not allow the `LMC` modifier",
    );
    expect_src(
        &part("feature top = stock.top\ntolerance T = flatness(top, dia 0.05 mm)"),
        "insp::resolve::diameter_zone",
        "dia",
        "flatness has no diameter",
    );
    let ok = check_src(&part("cut hole h { at (25, 20, 20), axis -z, diameter 6, depth 5 }\nfeature bore = h.wall\nfeature bot = stock.bottom\ndatum A = bot\ntolerance T = position(bore, dia 0.1 mm, MMC, A)"));
    assert!(ok.is_empty(), "{}", render(&ok));
}

#[test]
fn tolerance_shapes() {
    expect_src(
        &part("feature a = stock.left\ntolerance T = angle(a, 90 deg ± 0.5 deg)"),
        "insp::resolve::arity",
        "angle(a, 90 deg ± 0.5 deg)",
        "angle takes 2 features, found 1",
    );
    expect_src(
        &part("feature a = stock.left\ntolerance T = flatness(a)"),
        "insp::resolve::missing_argument",
        "flatness(a)",
        "flatness needs a tolerance value",
    );
    expect_src(&part("feature a = stock.left\nfeature b = stock.bottom\ndatum A = b\ntolerance T = angularity(a, 0.1 mm, A)"), "insp::resolve::missing_argument", "angularity(a, 0.1 mm, A)", "its basic angle");
    expect_src(
        &part("feature a = stock.left\ntolerance T = flatnes(a, 0.1 mm)"),
        "insp::resolve::unknown_name",
        "flatnes",
        "unknown tolerance type `flatnes`",
    );
    expect_src(
        &part("feature a = stock.left\ntolerance T = width(a, 10 mm ± 0 mm)"),
        "insp::resolve::invalid_limits",
        "10 mm ± 0 mm",
        "lower 10 is not below upper 10",
    );
    expect_src(
        &part("feature a = stock.left\ntolerance T = flatness(a, 10 mm ± 0.1 mm)"),
        "insp::resolve::type_mismatch",
        "10 mm ± 0.1 mm",
        "expected a tolerance zone width",
    );
}

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

#[test]
fn datum_letters_warn() {
    let d = check_src(&part("feature top = stock.top\ndatum Q = top"));
    expect(&d, "insp::resolve::datum_letter", "Q", "not a datum letter");
    assert!(d[0].warning);
}

// ---- hierarchies ------------------------------------------------------------------------

#[test]
fn hierarchy_checks() {
    expect_src(
        "hierarchy h { same_setup(T, *) }",
        "insp::resolve::hierarchy_required",
        "h",
        "does not start with `required approachability`",
    );
    expect_src(
        "hierarchy h { required approachability\n same_probe(T, *)\n same_setup(*, *) }",
        "insp::resolve::hierarchy_order",
        "same_setup(*, *)",
        "`same_probe(T, *)` is ranked above `same_setup(*, *)`",
    );
    expect_src(
        "hierarchy h { required approachability\n same_orient(*, *)\n same_probe(*, *) }",
        "insp::resolve::hierarchy_order",
        "same_probe(*, *)",
        "ranked above",
    );
    expect_src(
        "hierarchy h { required approachability\n same_setup(T, *)\n same_setup(T, *, *) }",
        "insp::resolve::duplicate_level",
        "same_setup(T, *, *)",
        "appears twice",
    );
    expect_src(
        "hierarchy h { required approachability\n same_setup(F, *) }",
        "insp::resolve::unknown_group",
        "F, *",
        "unknown measurement group `(F, *)`",
    );
    expect_src(
        "hierarchy h { required approachability\n same_stup(T, *) }",
        "insp::resolve::unknown_name",
        "same_stup",
        "unknown constraint",
    );
    expect_src(
        "hierarchy h { required reachability }",
        "insp::resolve::unknown_name",
        "reachability",
        "unknown required constraint",
    );
}

// ---- plans ------------------------------------------------------------------------------

const PLAN_HEAD: &str = "use std::cmms::{bridge_indexable, bridge_fixed}\npart p { units mm, stock box(50, 50, 20), feature top = stock.top }\n";

#[test]
fn preferred_orientations_are_checked_against_the_head() {
    let src = format!("{PLAN_HEAD}plan q {{ part p, cmm bridge_indexable\n prefer orientation (112.5 deg, 0 deg)\n prefer orientation (30 deg, 200 deg)\n prefer orientation (10 deg, 0 deg) }}");
    let d = check_src(&src);
    expect(
        &d,
        "insp::resolve::angle_out_of_range",
        "112.5 deg",
        "angle A = 112.5° is outside head `PH10MQ`'s range 0°..105°",
    );
    expect(
        &d,
        "insp::resolve::angle_out_of_range",
        "200 deg",
        "angle B = 200°",
    );
    expect(
        &d,
        "insp::resolve::off_grid",
        "10 deg",
        "not on head `PH10MQ`'s 7.5° grid",
    );
    assert!(
        d.iter()
            .any(|x| x.help == "the nearest positions are 7.5° and 15°"),
        "{}",
        render(&d)
    );
    let d = check_src(&format!(
        "{PLAN_HEAD}plan q {{ part p, cmm bridge_fixed, prefer orientation (0 deg, 0 deg) }}"
    ));
    expect(
        &d,
        "insp::resolve::fixed_head",
        "(0 deg, 0 deg)",
        "head `PH6` is fixed",
    );
}

#[test]
fn plan_references() {
    let d = check_src(&format!("{PLAN_HEAD}plan q {{ part p, cmm bridge_fixed\n prefer probe p9 cost 2\n sample topp with uniform(points 4)\n prefer sutup +z }}"));
    expect(
        &d,
        "insp::resolve::unknown_name",
        "p9",
        "unknown probe `p9`",
    );
    assert!(
        d.iter()
            .any(|x| x.help.starts_with("cmm `bridge_fixed` has no probe `p9`")),
        "{}",
        render(&d)
    );
    expect(
        &d,
        "insp::resolve::unknown_name",
        "topp",
        "unknown feature `topp`",
    );
    assert!(
        d.iter()
            .any(|x| x.help == "part `p` has no feature `topp`; did you mean `top`?"),
        "{}",
        render(&d)
    );
    expect(
        &d,
        "insp::resolve::unknown_name",
        "sutup",
        "unknown preference `sutup`",
    );
    expect_src(
        &format!("{PLAN_HEAD}plan q {{ cmm bridge_fixed }}"),
        "insp::resolve::missing_property",
        "q",
        "plan `q` needs `part`",
    );
}

#[test]
fn sampling_strategies() {
    expect_src(
        "sampling s { sphere fan_leu }",
        "insp::resolve::out_of_range",
        "fan_leu",
        "Fan & Leu sampling on a sphere",
    );
    expect_src(
        "sampling s { plane uniform }",
        "insp::resolve::missing_argument",
        "uniform",
        "a number of points",
    );
    expect_src(
        "sampling s { plane uniform(points 2.5) }",
        "insp::resolve::out_of_range",
        "2.5",
        "`points`",
    );
    expect_src(
        "sampling s { plane hammersly(points 5) }",
        "insp::resolve::unknown_name",
        "hammersly",
        "unknown sampling method",
    );
    expect_src(
        "sampling s { plane uniform(points 5, inset 60 %) }",
        "insp::resolve::out_of_range",
        "60 %",
        "`inset`",
    );
}

#[test]
fn one_run_reports_every_error() {
    let d =
        check_src("stylus a { tip 0 mm, length 20 deg, stem 1 mmm }\nbody b { diameter -1 mm }\n");
    let codes: Vec<&str> = d.iter().map(|x| x.code.as_str()).collect();
    assert_eq!(
        codes,
        [
            "insp::resolve::non_positive",
            "insp::resolve::unit_mismatch",
            "insp::resolve::unknown_unit",
            "insp::resolve::missing_property",
            "insp::resolve::non_positive"
        ],
        "{}",
        render(&d)
    );
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
