//! CAD in, PMI and `inspc import`: the semantic PMI of the four NIST STEP files against
//! the reference reading in `../shared/parts/*.pmi.json` (same tolerances, values, frames
//! and faces; more links where the reference lost them), and the imported specs against
//! their goldens in `tests/imported/` (bless with `INSPC_BLESS=1`): the same text twice,
//! and every one checks clean.

use crate::common::require_shared_parts;
use inspc::geometry::step::{pmi::Pmi, read, RESOLUTION};
use inspc::import::{identifier, import, ImportOptions};
use inspc::model::TolKind;
use serde_json::Value;
use std::path::PathBuf;

const PARTS: [&str; 4] = ["ctc_01", "ctc_02", "ftc_06", "ftc_08"];

fn file(part: &str, ext: &str) -> String {
    format!("../shared/parts/nist_{part}_asme1_ap242-e1.{ext}")
}

fn pmi(part: &str) -> Pmi {
    require_shared_parts();
    let bytes = std::fs::read(file(part, "stp")).unwrap();
    read(&bytes, RESOLUTION).unwrap().pmi
}

fn reference(part: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(file(part, "pmi.json")).unwrap()).unwrap()
}

fn kind_of(reference: &str) -> Option<TolKind> {
    Some(match reference.trim_start_matches("GeomToleranceType_") {
        "Flatness" => TolKind::Flatness,
        "ProfileOfSurface" => TolKind::ProfileSurface,
        "ProfileOfLine" => TolKind::ProfileLine,
        "Perpendicularity" => TolKind::Perpendicularity,
        "Parallelism" => TolKind::Parallelism,
        "Position" => TolKind::Position,
        _ => return None,
    })
}

/// Tolerances in file order against the reference's, one for one: type, value, Ø zone,
/// material modifier, datum letters, and faces wherever the reference has them (and the
/// face numbering is the file's, `same_faces`).
fn check_tolerances(part: &str, same_faces: bool) -> Pmi {
    let p = pmi(part);
    let r = reference(part);
    let rt = r["tolerances"].as_array().unwrap();
    assert_eq!(p.tolerances.len(), rt.len(), "{part}: tolerance count");
    for (t, rt) in p.tolerances.iter().zip(rt) {
        let what = format!("{part}: `{}`", t.name);
        assert_eq!(
            t.kind,
            kind_of(rt["type"].as_str().unwrap()),
            "{what}: type"
        );
        assert!(
            (t.value_mm - rt["value"].as_f64().unwrap()).abs() < 1e-6,
            "{what}: value {}",
            t.value_mm
        );
        // The reference reads no spherical zone (SØ); the file states one.
        assert_eq!(
            t.diameter && !t.spherical,
            rt["zone"] == "GeomToleranceTypeValue_Diameter",
            "{what}: Ø zone"
        );
        let material = match rt["material"].as_str().unwrap() {
            "GeomToleranceMatReqModif_M" => Some(inspc::model::Material::Mmc),
            "GeomToleranceMatReqModif_L" => Some(inspc::model::Material::Lmc),
            _ => None,
        };
        assert_eq!(t.material, material, "{what}: material modifier");
        // The reference lists a datum once per reference to it (targets repeat it).
        let mut letters: Vec<String> = rt["datums"]
            .as_array()
            .unwrap()
            .iter()
            .map(|d| d.as_str().unwrap().to_string())
            .collect();
        letters.dedup();
        // It also flattens a common datum (E-F) into its letters.
        let ours: Vec<String> = t.datums.iter().flat_map(|d| d.letters.clone()).collect();
        assert_eq!(ours, letters, "{what}: datums");
        let faces: Vec<usize> = rt["faces"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f.as_u64().unwrap() as usize - 1)
            .collect();
        if faces.is_empty() {
            continue;
        }
        if same_faces {
            assert_eq!(t.faces, faces, "{what}: faces");
        } else {
            assert_eq!(t.faces.len(), faces.len(), "{what}: face count");
        }
    }
    p
}

/// Datums: the reference's faces where it has them; and every datum linked.
fn check_datums(part: &str, p: &Pmi) {
    let r = reference(part);
    for rd in r["datums"].as_array().unwrap() {
        let letter = rd["name"].as_str().unwrap();
        let d = p
            .datums
            .iter()
            .find(|d| d.letter == letter)
            .unwrap_or_else(|| panic!("{part}: datum {letter} not read"));
        let faces: Vec<usize> = rd["faces"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f.as_u64().unwrap() as usize - 1)
            .collect();
        if !faces.is_empty() {
            assert_eq!(d.faces.len(), faces.len(), "{part}: datum {letter}");
        }
        assert!(!d.faces.is_empty(), "{part}: datum {letter} has no faces");
    }
}

#[test]
fn ctc_01_pmi_matches_the_reference_and_links_datums_b_and_c() {
    let p = check_tolerances("ctc_01", true);
    check_datums("ctc_01", &p);
    // The reference lost B and C; the file links them (ITEM_IDENTIFIED_REPRESENTATION_
    // USAGE) to the two Ø35 bores.
    let faces = |l: &str| {
        p.datums
            .iter()
            .find(|d| d.letter == l)
            .unwrap()
            .faces
            .clone()
    };
    assert_eq!(faces("A"), vec![97]);
    assert_eq!(faces("B"), vec![89, 90]);
    assert_eq!(faces("C"), vec![75, 76]);
    // Sizes: nominal and limits, signed.
    let size = p
        .dimensions
        .iter()
        .find(|d| d.faces == vec![89, 90] && d.nominal.is_some())
        .unwrap();
    assert_eq!(
        (size.nominal, size.upper, size.lower),
        (Some(35.0), Some(0.0), Some(-0.2))
    );
    let angle = p.dimensions.iter().find(|d| d.angular).unwrap();
    assert_eq!(
        (angle.nominal, angle.upper, angle.lower),
        (Some(60.0), Some(0.5), Some(-0.5))
    );
}

#[test]
fn ftc_08_pmi_in_inches_reads_in_mm_with_composite_frames() {
    let p = check_tolerances("ftc_08", true);
    check_datums("ftc_08", &p);
    assert_eq!(p.datums.len(), 11);
    // Six composite frames: each lower segment points at its upper one.
    assert_eq!(
        p.tolerances
            .iter()
            .filter(|t| t.composite_of.is_some())
            .count(),
        6
    );
    let d = p
        .dimensions
        .iter()
        .find(|d| d.faces == vec![66, 67])
        .unwrap();
    assert_eq!(
        (d.nominal, d.upper, d.lower),
        (Some(6.35), Some(0.1524), Some(-0.0254))
    );
}

#[test]
fn ftc_06_pmi_locates_datums_set_up_by_targets() {
    let p = check_tolerances("ftc_06", true);
    check_datums("ftc_06", &p);
    // G, H, J and K are set up by targets on supplemental geometry only: each is located
    // on the faces its targets lie on, and marked so.
    for (letter, faces) in [
        ("H", vec![60, 61]),
        ("G", vec![123, 124]),
        ("K", vec![48, 52]),
        ("J", vec![37, 41]),
    ] {
        let d = p.datums.iter().find(|d| d.letter == letter).unwrap();
        assert!(d.located, "datum {letter}");
        assert_eq!(d.faces, faces, "datum {letter}");
    }
}

#[test]
fn ctc_02_pmi_links_what_the_reference_lost() {
    // Its reference numbers faces in OpenCASCADE's order: counts only.
    let p = check_tolerances("ctc_02", false);
    check_datums("ctc_02", &p);
    let unlinked: Vec<&str> = p
        .tolerances
        .iter()
        .filter(|t| t.faces.is_empty())
        .map(|t| t.name.as_str())
        .collect();
    // One profile of a line names a curve of the drawing, not the part.
    assert_eq!(unlinked, vec!["Feature Control Frame (14)"]);
    assert!(p.notes.iter().any(|n| n.contains("(14)")));
}

fn imported(part: &str) -> String {
    require_shared_parts();
    let bytes = std::fs::read(file(part, "stp")).unwrap();
    let opts = ImportOptions {
        cad_path: format!("../../{}", file(part, "stp")),
        part_name: identifier(&format!("nist_{part}_asme1_ap242-e1")),
        scale: 1.0,
    };
    import(&bytes, &opts).unwrap().text
}

#[test]
fn imported_specs_match_their_goldens_and_import_twice_the_same() {
    for part in PARTS {
        let text = imported(part);
        assert_eq!(text, imported(part), "{part}: importing twice");
        let golden = PathBuf::from(format!("tests/imported/nist_{part}.insp"));
        crate::common::check_imported_golden(&text, &golden);
    }
}

/// Names a hostile file may hold: quotes, backslashes, newlines, a smuggled item, a
/// comment closer, unicode (a bidirectional override among it), nothing, keywords.
const HOSTILE_NAMES: &[&str] = &[
    "a\"b",
    "back\\slash\\",
    "two\nlines",
    "}\npart evil {\n  units mm\n}\n//",
    "*/ /* \r\u{2028}",
    "Ø 5 ±0.1 \u{202e}txet",
    "",
    "part",
    "use",
    "A",
    "a",
];

/// Where the imported spec and its STEP or QIF file are written: a folder of its own
/// and a file name with a quote, a backslash and a space, which the spec must name.
fn hostile_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("inspc-hostile-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Imports `bytes` as `name` (beside the spec), writes the spec and checks it: it parses,
/// resolves with no error and no warning about a name, and holds one part with exactly
/// the datums and tolerances the import says it wrote, one CMM and one plan — nothing
/// the file smuggled in.
fn import_checks_clean(dir: &std::path::Path, name: &str, bytes: &[u8]) -> inspc::import::Imported {
    std::fs::write(dir.join(name), bytes).unwrap();
    let opts = ImportOptions {
        cad_path: name.to_string(),
        part_name: identifier(name),
        scale: 1.0,
    };
    let imported = import(bytes, &opts).unwrap();
    let spec = dir.join("spec.insp");
    std::fs::write(&spec, &imported.text).unwrap();
    let checked = inspc::check(&inspc::source::FsWorld, std::slice::from_ref(&spec));
    let errors: Vec<String> = checked
        .diagnostics
        .iter()
        .filter(|d| {
            d.severity() == miette::Severity::Error || d.code() == "insp::resolve::datum_letter"
        })
        .map(|d| format!("{}: {}", d.code(), d.message()))
        .collect();
    assert!(errors.is_empty(), "{errors:?}\n{}", imported.text);
    let own = |span: &inspc::source::Span| checked.roots.contains(&span.file);
    let parts: Vec<_> = checked
        .model
        .parts
        .iter()
        .filter(|p| own(&p.span))
        .collect();
    assert_eq!(parts.len(), 1, "{}", imported.text);
    let part = parts[0];
    assert_eq!(part.datums.len(), imported.datums.1, "{}", imported.text);
    assert_eq!(
        part.tolerances.len(),
        imported.tolerances.1 + imported.dimensions.1,
        "{}",
        imported.text
    );
    assert_eq!(checked.model.plans.len(), 1);
    assert!(
        !imported
            .text
            .lines()
            .any(|l| l.trim_start().starts_with("part evil")),
        "{}",
        imported.text
    );
    imported
}

/// `s` as a STEP string's inside: a quote doubled.
fn p21(s: &str) -> String {
    s.replace('\'', "''")
}

/// The class of hostile STEP files: every datum letter and tolerance name replaced by
/// one of [`HOSTILE_NAMES`] in turn (three rotations), and tolerance values that are
/// huge, zero, negative or below what six decimals write; the file's own name holds
/// a quote and a backslash. Each import writes a spec that checks clean and holds what
/// the file has, and each value left out is a warning and a comment.
#[test]
fn hostile_step_names_and_values_write_a_spec_that_checks_clean() {
    require_shared_parts();
    let text = std::fs::read_to_string(file("ctc_01", "stp")).unwrap();
    // (A STEP real past `f64` is a syntax error of the file.)
    let bad_values = ["1.E300", "0.", "-0.05", "1.E-9"];
    for turn in 0..3 {
        let mut k = turn;
        let mut next = || {
            k += 1;
            p21(HOSTILE_NAMES[k % HOSTILE_NAMES.len()])
        };
        let mut out = String::new();
        let mut values = 0;
        for line in text.split_inclusive('\n') {
            let line = if let Some(rest) = line.split_once("=DATUM('',$,").map(|x| x.1) {
                // `#37=DATUM('',$,#4269,.F.,'A');`
                let (head, _) = rest.rsplit_once(",'").unwrap();
                format!(
                    "{}=DATUM('',$,{head},'{}');\n",
                    line.split('=').next().unwrap(),
                    next()
                )
            } else if let Some((head, rest)) = line.split_once("TOLERANCE('") {
                let (_, tail) = rest.split_once('\'').unwrap();
                format!("{head}TOLERANCE('{}'{tail}", next())
            } else if line.starts_with("MEASURE_WITH_UNIT(LENGTH_MEASURE(0.") && values < 8 {
                values += 1;
                let v = bad_values[(values + turn) % bad_values.len()];
                let (_, tail) = line.split_once("),").unwrap();
                format!("MEASURE_WITH_UNIT(LENGTH_MEASURE({v}),{tail}")
            } else {
                line.to_string()
            };
            out.push_str(&line);
        }
        let dir = hostile_dir(&format!("step{turn}"));
        let imported = import_checks_clean(&dir, "we\"ird \\name.stp", out.as_bytes());
        assert!(!imported.warnings.is_empty(), "values left out warn");
        for w in &imported.warnings {
            assert!(
                imported.text.contains("not written"),
                "{w:?} has no comment"
            );
        }
        assert!(
            imported.text.contains("mesh \"we\\\"ird \\\\name.stp\""),
            "{}",
            imported.text
        );
    }
}

/// XML text: the markup characters as entities.
fn xml(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The class of hostile QIF files: datum labels, characteristic names and tolerance
/// values patched as for STEP; the spec checks clean and holds what the file has.
#[test]
fn hostile_qif_labels_and_values_write_a_spec_that_checks_clean() {
    require_shared_parts();
    let text = std::fs::read_to_string("../shared/parts/nist_ctc_01_asme1_ap242.qif").unwrap();
    let bad_values = ["INF", "0", "-0.5", "NaN", "1e-9", "1e400"];
    for turn in 0..3 {
        let mut k = turn;
        let mut next = || {
            k += 1;
            xml(HOSTILE_NAMES[k % HOSTILE_NAMES.len()])
        };
        let mut values = turn;
        let mut out = String::new();
        for line in text.split_inclusive('\n') {
            let patched = |tag: &str, with: String| -> Option<String> {
                let open = format!("<{tag}");
                let start = line.find(&open)?;
                let inner = start + line[start..].find('>')? + 1;
                let end = line.find(&format!("</{tag}>"))?;
                Some(format!("{}{with}{}", &line[..inner], &line[end..]))
            };
            let line = if let Some(l) = patched("DatumLabel", next()) {
                l
            } else if line.contains("<Name>Nominal") {
                patched("Name", next()).unwrap()
            } else if line.contains("<ToleranceValue") && values < turn + 6 {
                values += 1;
                patched(
                    "ToleranceValue",
                    bad_values[values % bad_values.len()].into(),
                )
                .unwrap()
            } else {
                line.to_string()
            };
            out.push_str(&line);
        }
        let dir = hostile_dir(&format!("qif{turn}"));
        import_checks_clean(&dir, "odd\\\"name.qif", out.as_bytes());
    }
}

/// A NIST part's STEP text with `from` replaced by `to` (which must be there), and the
/// part's own text.
fn patched(part: &str, from: &str, to: &str) -> (String, String) {
    require_shared_parts();
    let text = std::fs::read_to_string(file(part, "stp")).unwrap();
    let patched = text.replace(from, to);
    assert_ne!(patched, text, "{part}: `{from}` is not in the file");
    (patched, text)
}

/// The spec `inspc import` writes from STEP text.
fn spec_of(text: &str) -> String {
    let opts = ImportOptions {
        cad_path: "part.stp".into(),
        part_name: "part".into(),
        scale: 1.0,
    };
    import(text.as_bytes(), &opts).unwrap().text
}

/// A diameter toleranced by a fit (ISO 10303-45 `limits_and_fits`: the zone's letter
/// and grade) gets ISO 286's limits: CTC 01's first plus-minus range made `H7`.
#[test]
fn a_fit_reads_as_its_iso_286_limits() {
    let (text, _) = patched(
        "ctc_01",
        "#58=TOLERANCE_VALUE(#72,#71);",
        "#58=LIMITS_AND_FITS('','H','7','ISO 286');",
    );
    let spec = spec_of(&text);
    let line = spec
        .lines()
        .find(|l| l.contains("// fit H7"))
        .unwrap_or_else(|| panic!("no size written from the fit:\n{spec}"));
    // Ø35 H7: IT7 over 30 up to 50 mm is 25 µm, H's lower deviation 0.
    assert!(line.contains("35 mm +0.025 mm -0 mm"), "{line}");
}

/// An angularity whose basic angle the file does not give takes it from the model:
/// CTC 01's perpendicularity of f25 to A made an angularity reads `basic 90 deg`, the
/// angle the two modelled faces make (the arithmetic is unit-tested in
/// `import/angles.rs`).
#[test]
fn an_angularity_takes_its_basic_angle_from_the_model() {
    let (text, _) = patched(
        "ctc_01",
        "#56=PERPENDICULARITY_TOLERANCE('Perpendicularity.1'",
        "#56=ANGULARITY_TOLERANCE('Perpendicularity.1'",
    );
    let spec = spec_of(&text);
    let line = spec
        .lines()
        .find(|l| l.contains("= angularity("))
        .unwrap_or_else(|| panic!("no angularity written:\n{spec}"));
    assert!(line.ends_with("basic 90 deg)"), "{line}");
}

/// A directed location (ISO 10303-47 `directed_dimensional_location`: from its first
/// feature to its second) is the same distance as an undirected one: FTC 06's first
/// location written directed imports the same line.
#[test]
fn a_directed_location_is_read_as_its_distance() {
    let (text, original) = patched(
        "ftc_06",
        "#16436=DIMENSIONAL_LOCATION('linear distance'",
        "#16436=DIRECTED_DIMENSIONAL_LOCATION('linear distance'",
    );
    let distances = |t: &str| -> Vec<String> {
        spec_of(t)
            .lines()
            .filter(|l| l.contains("= distance("))
            .map(String::from)
            .collect()
    };
    assert_eq!(distances(&text), distances(&original));
}

/// A profile toleranced on the product definition shape itself applies all over the
/// part (the reader links it to every face), and the spec keeps it as a comment with a
/// warning: a general tolerance is not inspected face by face. CTC 02's first profile
/// moved onto its shape.
#[test]
fn an_all_over_profile_is_read_on_every_face_and_kept_as_a_comment() {
    let (text, _) = patched(
        "ctc_02",
        "'Geometric tolerance for feature',#182,#615);",
        "'Geometric tolerance for feature',#182,#45643);",
    );
    let part =
        inspc::geometry::step::read(text.as_bytes(), inspc::geometry::step::RESOLUTION).unwrap();
    let all_over = part
        .pmi
        .tolerances
        .iter()
        .find(|t| t.faces.len() >= part.solid_faces())
        .expect("no tolerance read on every face");
    assert!((all_over.value_mm - 0.1).abs() < 1e-9);
    let opts = ImportOptions {
        cad_path: "part.stp".into(),
        part_name: "part".into(),
        scale: 1.0,
    };
    let imported = import(text.as_bytes(), &opts).unwrap();
    let spec = &imported.text;
    assert!(
        !spec
            .lines()
            .any(|l| l.contains("= profile_surface(") && l.contains("0.1 mm")),
        "the general profile is written as a tolerance:\n{spec}"
    );
    let comment = format!(
        "a general tolerance, profile_surface 0.1 mm on all {} faces",
        part.solid_faces()
    );
    assert!(spec.contains(&comment), "no comment `{comment}`:\n{spec}");
    assert!(
        imported.warnings.iter().any(|w| w.general),
        "{:?}",
        imported.warnings
    );
}

/// A flatness per unit area (ISO 10303-47 `geometric_tolerance_with_defined_area_unit`)
/// is written as one, not converted into a flatness of the whole face: CTC 01's flatness
/// made 0.2 mm per 25 × 25 mm square; a per-unit zone on a type the language has none
/// for (perpendicularity) is said in a comment.
#[test]
fn a_flatness_per_unit_area_is_written_as_one() {
    let (text, _) = patched(
        "ctc_01",
        "#57=FLATNESS_TOLERANCE('Flatness.1','',#82,#297);",
        "#57=(FLATNESS_TOLERANCE()GEOMETRIC_TOLERANCE('Flatness.1','',#82,#297)\
         GEOMETRIC_TOLERANCE_WITH_DEFINED_AREA_UNIT(.SQUARE.,$)\
         GEOMETRIC_TOLERANCE_WITH_DEFINED_UNIT(#990001));\n\
         #990001=LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.),#4360);",
    );
    let spec = spec_of(&text);
    assert!(
        spec.contains("= flatness(") && spec.contains(", per_unit(0.2 mm, 25 mm))"),
        "no per-unit flatness:\n{spec}"
    );
    assert!(!spec.contains(", 0.2 mm, per_unit"), "{spec}");
    let rect = text.replace(
        "GEOMETRIC_TOLERANCE_WITH_DEFINED_AREA_UNIT(.SQUARE.,$)",
        "GEOMETRIC_TOLERANCE_WITH_DEFINED_AREA_UNIT(.RECTANGULAR.,#990002)",
    ) + "";
    let rect = rect.replace(
        "#990001=LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.),#4360);",
        "#990001=LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.),#4360);\n\
         #990002=LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(50.),#4360);",
    );
    let spec = spec_of(&rect);
    assert!(spec.contains("per_unit(0.2 mm, 25 mm, 50 mm))"), "{spec}");
    // The spec it writes resolves, the tolerance's zone per unit alone.
    let dir = hostile_dir("per-unit");
    import_checks_clean(&dir, "ctc_01_per_unit.stp", rect.as_bytes());
    let perp = text.replace(
        "#57=(FLATNESS_TOLERANCE()GEOMETRIC_TOLERANCE(",
        "#57=(PERPENDICULARITY_TOLERANCE()GEOMETRIC_TOLERANCE(",
    );
    let spec = spec_of(&perp);
    assert!(
        spec.contains(
            "which the language has only for straightness per length and flatness per area"
        ),
        "{spec}"
    );
}
