//! QIF parts: the three NIST QIF files read from their own B-rep and PMI, checked
//! against the same parts read from STEP. QIF numbers faces in another order, so each
//! QIF face is matched to its STEP face by geometry; then every face must agree in
//! surface type, area, place and sense (QIF states no sense: it is found from the
//! topology), and every characteristic must be a STEP tolerance on the same faces.
//! The imported specs are golden (`tests/imported/*_qif.insp`, bless with `INSPC_BLESS=1`).

use crate::common::require_shared_parts;
use inspc::geometry::step::{pmi::GeoTolerance, CadPart, RESOLUTION};
use inspc::geometry::{qif, segment, step, PartGeometry, Surface};
use inspc::import::{identifier, import, ImportOptions};
use std::collections::BTreeSet;
use std::path::PathBuf;

/// (part, QIF file stem): FTC 08's QIF was made from the `-1` edition of the STEP file
/// and draws the part at twice its size (`ScaleCoefficient` 2).
const PARTS: [(&str, &str); 3] = [
    ("ctc_01", "nist_ctc_01_asme1_ap242"),
    ("ftc_06", "nist_ftc_06_asme1_ap242"),
    ("ftc_08", "nist_ftc_08_asme1_ap242-1"),
];

fn read_both(part: &str, stem: &str) -> (CadPart, CadPart) {
    require_shared_parts();
    let q = std::fs::read(format!("../shared/parts/{stem}.qif")).unwrap();
    let s = std::fs::read(format!("../shared/parts/nist_{part}_asme1_ap242-e1.stp")).unwrap();
    (
        qif::read(&q, RESOLUTION).unwrap_or_else(|e| panic!("{part}: {e:?}")),
        step::read(&s, RESOLUTION).unwrap(),
    )
}

/// For each QIF face, the STEP face nearest by centroid and area.
fn matched(q: &PartGeometry, s: &PartGeometry) -> Vec<usize> {
    crate::common::nearest_faces(q, s)
}

/// Whether two exact surfaces face the same way (outward normal, convexity).
fn same_sense(a: &Surface, b: &Surface) -> bool {
    match (a, b) {
        (Surface::Plane { normal: n, .. }, Surface::Plane { normal: m, .. }) => n.dot(m) > 0.999,
        (Surface::Cylinder { convex: x, .. }, Surface::Cylinder { convex: y, .. })
        | (Surface::Cone { convex: x, .. }, Surface::Cone { convex: y, .. })
        | (Surface::Sphere { convex: x, .. }, Surface::Sphere { convex: y, .. }) => x == y,
        (Surface::Freeform, Surface::Freeform) => true,
        _ => false,
    }
}

#[test]
fn qif_parts_are_their_step_parts_face_for_face() {
    for (part, stem) in PARTS {
        let (q, s) = read_both(part, stem);
        assert_eq!(q.mesh.open_edges, 0, "{part}: the QIF mesh is closed");
        let (gq, gs) = (segment::from_groups(&q.mesh), segment::from_groups(&s.mesh));
        let m = matched(&gq, &gs);
        // Every QIF face is a distinct face of the STEP part (FTC 08's STEP file adds one
        // sheet face, which its QIF keeps in a hidden construction body: both leave it out).
        let distinct: BTreeSet<usize> = m.iter().copied().collect();
        assert_eq!(distinct.len(), gq.faces.len(), "{part}: one STEP face each");
        assert_eq!(gq.faces.len(), gs.faces.len(), "{part}: face count");
        for (i, f) in gq.faces.iter().enumerate() {
            let g = &gs.faces[m[i]];
            let what = format!("{part}: QIF {} / STEP {}", f.name, g.name);
            assert!((f.centroid - g.centroid).norm() < 0.05, "{what}: centroid");
            assert!(
                (f.area - g.area).abs() < 0.005 * g.area.max(1.0),
                "{what}: area"
            );
            assert_eq!(f.surface.kind(), g.surface.kind(), "{what}: surface");
            assert!(
                same_sense(&q.mesh.exact[i], &s.mesh.exact[m[i]]),
                "{what}: sense"
            );
        }
    }
}

/// A tolerance as compared across the two files: type, value (µm), zone, datum letters
/// and faces (in STEP's numbering).
fn key(t: &GeoTolerance, faces: impl Fn(usize) -> usize) -> String {
    let mut f: Vec<usize> = t.faces.iter().map(|&i| faces(i)).collect();
    f.sort_unstable();
    let datums: Vec<String> = t.datums.iter().map(|d| d.letters.join("-")).collect();
    format!(
        "{:?} {} {}{} [{}] {:?}{}",
        t.kind,
        (t.value_mm * 1000.0).round(),
        if t.diameter { "dia " } else { "" },
        datums.join(","),
        f.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(","),
        t.material,
        if t.composite_of.is_some() {
            " lower"
        } else {
            ""
        }
    )
}

#[test]
fn qif_characteristics_are_the_step_files_tolerances() {
    for (part, stem) in PARTS {
        let (q, s) = read_both(part, stem);
        let m = matched(
            &segment::from_groups(&q.mesh),
            &segment::from_groups(&s.mesh),
        );
        let qk: BTreeSet<String> = q
            .pmi
            .tolerances
            .iter()
            .filter(|t| !t.faces.is_empty())
            .map(|t| key(t, |i| m[i]))
            .collect();
        let unlinked = q
            .pmi
            .tolerances
            .iter()
            .filter(|t| t.faces.is_empty())
            .count();
        let sk: BTreeSet<String> = s.pmi.tolerances.iter().map(|t| key(t, |i| i)).collect();
        let only_q: Vec<&String> = qk.difference(&sk).collect();
        let only_s: Vec<&String> = sk.difference(&qk).collect();
        match part {
            // FTC 08: the QIF gives the five lower segments of its composite positions no
            // material modifier where the STEP file gives Ⓜ, and puts one flatness on a
            // face of a hidden construction body (the STEP file's sheet face).
            "ftc_08" => {
                assert_eq!(unlinked, 1, "{part}: unlinked characteristics");
                assert_eq!(only_q.len(), 5, "{part}: only in QIF {only_q:#?}");
                assert!(
                    only_q.iter().all(|k| k.ends_with("None lower")),
                    "{only_q:#?}"
                );
                assert_eq!(only_s.len(), 6, "{part}: only in STEP {only_s:#?}");
                for k in &only_q {
                    let mmc = k.replace("None lower", "Some(Mmc) lower");
                    assert!(only_s.contains(&&mmc), "{part}: {k} has no Ⓜ twin");
                }
                assert!(only_s.iter().any(|k| k.starts_with("Some(Flatness) 381")));
                assert!(q.pmi.notes.iter().any(|n| n.contains("linked to no face")));
            }
            _ => {
                assert_eq!(unlinked, 0, "{part}: unlinked characteristics");
                assert!(only_q.is_empty(), "{part}: only in QIF {only_q:#?}");
                assert!(only_s.is_empty(), "{part}: only in STEP {only_s:#?}");
            }
        }
        // Datums: the same letters on the same faces.
        for d in &q.pmi.datums {
            let faces: BTreeSet<usize> = d.faces.iter().map(|&i| m[i]).collect();
            let sd = s.pmi.datums.iter().find(|x| x.letter == d.letter).unwrap();
            let sf: BTreeSet<usize> = sd.faces.iter().copied().collect();
            assert!(!faces.is_empty(), "{part}: datum {}", d.letter);
            // STEP locates FTC 06's target datums G, H, J, K on more faces than QIF names.
            if sd.located {
                assert!(
                    faces.is_subset(&sf),
                    "{part}: datum {} {faces:?} {sf:?}",
                    d.letter
                );
            } else {
                assert_eq!(faces, sf, "{part}: datum {}", d.letter);
            }
        }
    }
}

fn imported(stem: &str) -> String {
    require_shared_parts();
    let path = format!("../shared/parts/{stem}.qif");
    let bytes = std::fs::read(&path).unwrap();
    let opts = ImportOptions {
        cad_path: format!("../../{path}"),
        part_name: identifier(stem),
        scale: 1.0,
    };
    import(&bytes, &opts).unwrap().text
}

#[test]
fn imported_qif_specs_match_their_goldens_and_check_clean() {
    for (part, stem) in PARTS {
        let text = imported(stem);
        assert_eq!(text, imported(stem), "{part}: importing twice");
        let golden = PathBuf::from(format!("tests/imported/nist_{part}_qif.insp"));
        crate::common::check_imported_golden(&text, &golden);
    }
}

#[test]
fn a_damaged_qif_file_is_an_error_never_a_panic() {
    require_shared_parts();
    let text = std::fs::read_to_string("../shared/parts/nist_ctc_01_asme1_ap242.qif").unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let mut errors = 0;
    // Cut short, and with one line left out (an id, a number list, a start tag) in turn.
    for k in 1..60 {
        let cut = text.len() * k / 60;
        let cut = (0..=cut).rev().find(|&i| text.is_char_boundary(i)).unwrap();
        assert!(
            qif::read(&text.as_bytes()[..cut], RESOLUTION).is_err(),
            "cut at {cut}"
        );
        let skip = lines.len() * k / 60;
        let damaged: Vec<&str> = lines
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != skip)
            .map(|(_, l)| *l)
            .collect();
        errors += usize::from(qif::read(damaged.join("\n").as_bytes(), RESOLUTION).is_err());
    }
    assert!(errors > 0, "some left-out line must break the part");
}

/// A QIF flatness with a whole-face value and a zone per unit area (QIF 3
/// `ToleranceZonePerUnitArea`, its `ToleranceValuePerUnit`) is written as both; one with
/// the zone per unit alone as that zone alone, never as a flatness of 0 mm.
#[test]
fn a_qif_flatness_per_unit_area_keeps_both_zones() {
    require_shared_parts();
    let path = "../shared/parts/nist_ctc_01_asme1_ap242.qif";
    let text = std::fs::read_to_string(path).unwrap();
    let whole = "<ToleranceValue linearUnit=\"mm\">0.2</ToleranceValue>\n      </FlatnessCharacteristicDefinition>";
    assert!(text.contains(whole), "CTC 01's flatness changed");
    let unit = "<ToleranceZonePerUnitArea><ToleranceValuePerUnit linearUnit=\"mm\">0.05</ToleranceValuePerUnit>\
                <RectangularUnitArea><RectangularUnitAreaLength linearUnit=\"mm\">30</RectangularUnitAreaLength>\
                <RectangularUnitAreaWidth linearUnit=\"mm\">20</RectangularUnitAreaWidth></RectangularUnitArea>\
                </ToleranceZonePerUnitArea>";
    let opts = ImportOptions {
        cad_path: "part.qif".into(),
        part_name: "part".into(),
        scale: 1.0,
    };
    let both = text.replace(
        whole,
        &format!("<ToleranceValue linearUnit=\"mm\">0.2</ToleranceValue>{unit}\n      </FlatnessCharacteristicDefinition>"),
    );
    let spec = import(both.as_bytes(), &opts).unwrap().text;
    assert!(
        spec.contains(", 0.2 mm, per_unit(0.05 mm, 30 mm, 20 mm))"),
        "{spec}"
    );
    let alone = text.replace(
        whole,
        &format!("{unit}\n      </FlatnessCharacteristicDefinition>"),
    );
    let spec = import(alone.as_bytes(), &opts).unwrap().text;
    assert!(
        spec.contains(", per_unit(0.05 mm, 30 mm, 20 mm))"),
        "{spec}"
    );
    assert!(!spec.contains("0 mm, per_unit"), "{spec}");
}
