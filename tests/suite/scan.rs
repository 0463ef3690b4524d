//! Laser line scanners: the catalogue item and the rack, and the scanner's visibility
//! cones against exact ray casts on every example and the NIST parts.

use crate::common::{self, check_src};
use inspc::access::scan::{sees, Optics, LIFT};
use inspc::access::{
    component_hits, scan_cones, Cell, Component, ConeOptions, Cpu, End, Head, ProbeShape,
    ScannerShape,
};
use inspc::geometry::V3;

/// An LC15Dx-like scanner (stdlib figures) on a fixed or an indexable head with a
/// PH10MQ-sized head and a 35 mm ram.
pub(crate) fn scanner(head: Head) -> ScannerShape {
    let (standoff, length) = (60.0, 120.0);
    let base = match head {
        Head::Fixed => standoff + length,
        Head::Indexable => 0.0,
    };
    let flat = |name: &str, a: f64, b: f64, radius: f64| Component {
        name: name.into(),
        a,
        b,
        radius,
        end: End::Flat,
    };
    ScannerShape {
        optics: Optics {
            standoff,
            depth: 15.0,
            stripe: 18.0,
            triangulation: 30f64.to_radians(),
            max_incidence: 75f64.to_radians(),
            spacing: [0.022, 0.022],
        },
        probe: ProbeShape {
            name: "l1".into(),
            tip_radius: 0.0,
            first: vec![flat("housing", standoff, standoff + length, 30.0)],
            second: vec![
                flat("head", base, base + 73.0, 31.0),
                flat("ram", base + 73.0, f64::INFINITY, 35.0),
            ],
            head,
        },
    }
}

/// At `count` fpoints of a spec spread over its faces: every direction the cone calls
/// seen must be seen by exact ray casts, and the housing (with head and ram on a fixed
/// head) must clear the part there. Returns (cells seen by the cone, cells seen exactly).
fn verify(spec: &str, count: usize, n: u32) -> (usize, usize) {
    let (scene, _, fp) = crate::access::loaded(spec);
    let opts = ConeOptions {
        n,
        ..ConeOptions::default()
    };
    let (mut cone_seen, mut exact_seen) = (0, 0);
    let step = (fp.len() / count).max(1);
    for head in [Head::Fixed, Head::Indexable] {
        let s = scanner(head);
        for f in fp.iter().step_by(step).take(count) {
            let cones = scan_cones(&Cpu, &scene, &f.position, &f.normal, &s, &opts);
            let from = f.position + f.normal * LIFT;
            let all = cones.rays.empty_like().not();
            for cell in all.cells() {
                let d = all.direction(cell);
                let exact = sees(&scene, &f.position, &f.normal, &d, &s.optics);
                let cone = cones.rays.get(cell);
                assert!(
                    exact || !cone,
                    "{spec}: the cone sees {d:?} at {:?} (normal {:?}), exact rays do not",
                    f.position,
                    f.normal
                );
                exact_seen += exact as usize;
                cone_seen += cone as usize;
                if cones.visible.get(cell) {
                    assert!(cone, "{spec}: visible outside the rays at {cell:?}");
                    for c in &s.probe.leading() {
                        assert!(
                            !component_hits(&scene, &from, &d, c),
                            "{spec}: the {} hits the part at {:?} from {d:?}",
                            c.name,
                            f.position
                        );
                    }
                }
            }
            assert_eq!(cones.d2.is_some(), head == Head::Indexable);
        }
    }
    (cone_seen, exact_seen)
}

#[test]
fn scanner_cones_never_see_what_exact_rays_block() {
    let mut seen = (0, 0);
    for spec in crate::access::EXAMPLES {
        let (c, e) = verify(spec, 4, 32);
        seen = (seen.0 + c, seen.1 + e);
    }
    common::require_shared_parts();
    for spec in [
        "tests/real/nist_ctc_01.insp",
        "tests/real/nist_ctc_02.insp",
        "tests/real/nist_ftc_06.insp",
        "tests/real/nist_ftc_08.insp",
    ] {
        let (c, e) = verify(spec, 6, 32);
        seen = (seen.0 + c, seen.1 + e);
    }
    let share = seen.0 as f64 / seen.1 as f64;
    println!(
        "scanner rays: the cone sees {} of the {} cells exact rays see ({:.1} %)",
        seen.0,
        seen.1,
        100.0 * share
    );
    // Conservative cells and one pixel of growth cost a little at the cone's rim.
    assert!(share > 0.9, "{share}");
}

#[test]
fn the_laser_needs_the_camera_too() {
    // A point on a floor under a plate that overhangs to +x: the laser straight up passes
    // the plate's edge, the camera 30° towards +x meets the plate. Leaning the scanner
    // towards -x brings the camera's line of sight past the edge too.
    let p = |x: f64, y: f64, z: f64| inspc::geometry::P3::new(x, y, z);
    let scene = inspc::access::Scene::of_triangles(&[
        [
            p(10.0, -10.0, 20.0),
            p(30.0, -10.0, 20.0),
            p(30.0, 10.0, 20.0),
        ],
        [
            p(10.0, -10.0, 20.0),
            p(30.0, 10.0, 20.0),
            p(10.0, 10.0, 20.0),
        ],
    ]);
    let s = scanner(Head::Indexable);
    let opts = ConeOptions {
        n: 32,
        ..ConeOptions::default()
    };
    let (at, n) = (p(0.0, 0.0, 0.0), V3::z());
    let cones = scan_cones(&Cpu, &scene, &at, &n, &s, &opts);
    assert!(scene
        .cast_ray(&(at + n * LIFT), &n, f64::INFINITY)
        .is_none());
    assert!(!sees(&scene, &at, &n, &n, &s.optics));
    assert!(!cones.rays.get(Cell::Preferred(4)), "+z seen");
    let lean = V3::new(-(20f64.to_radians().sin()), 0.0, 20f64.to_radians().cos());
    assert!(sees(&scene, &at, &n, &lean, &s.optics));
    assert!(cones.rays.contains(&lean));
    // Past the incidence limit nothing is seen, however free the rays.
    let grazing = V3::new(-(80f64.to_radians().sin()), 0.0, 80f64.to_radians().cos());
    assert!(!sees(&scene, &at, &n, &grazing, &s.optics));
    assert!(!cones.rays.contains(&grazing));
}

const RACK: &str = r#"
use std::heads::PH10MQ
use std::probes::TP20_D2_L20
use std::scanners::{LC15Dx, LC60Dx}
part p {
    units mm, stock box(50, 50, 20), feature top = stock.top
    tolerance flat = flatness(top, 1 mm)
}
cmm lab {
    table { z 0 mm, size (1000 mm, 700 mm) }
    ram { radius 35 mm, length 600 mm }
    head PH10MQ
    probes [p1: TP20_D2_L20]
    scanners [l1: LC15Dx, l2: LC60Dx]
}
plan q { part p, cmm lab }
"#;

#[test]
fn a_cmm_carries_scanners_beside_its_probes() {
    let d = check_src(RACK);
    assert!(d.unexpected().is_empty());
    // The plan scans the top (no tolerance asks more of it than the scanner gives).
    let d = common::plan_files(&[("main.insp", RACK.as_bytes())]);
    assert!(d.unexpected().is_empty());
    // A scanner's label may not repeat a probe's.
    let src = RACK.replace("l2: LC60Dx", "p1: LC60Dx");
    let d = check_src(&src);
    assert_eq!(d.only().code, "insp::resolve::duplicate_name");
    // A missing optical property is named with an example.
    let src = "scanner s { stripe_width 18 mm, standoff 60 mm, depth_of_field 15 mm, \
               triangulation 30 deg, max_incidence 75 deg, accuracy 0.002 mm, \
               body { diameter 60 mm, length 120 mm } }";
    let d = check_src(src);
    let e = d.only();
    assert_eq!(e.code, "insp::resolve::missing_property");
    assert!(e.message.contains("spacing"), "{}", e.message);
}

#[test]
fn the_summary_and_cone_report_describe_a_scanner() {
    let dir = std::env::temp_dir().join(format!("inspc-scan-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let spec = dir.join("rack.insp");
    std::fs::write(&spec, RACK).unwrap();
    // Runs inspc and checks that it succeeds and prints every needle.
    let expect = |args: &[&str], needles: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_inspc"))
            .args(args)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{text}");
        for needle in needles {
            assert!(text.contains(needle), "no `{needle}` in:\n{text}");
        }
    };
    let (spec, pgm) = (spec.to_str().unwrap(), dir.join("cone.pgm"));
    expect(
        &["check", "--emit", "model", spec],
        &[
            "scanner LC15Dx: stripe 18 at stand-off 60 ± 7.5, triangulation 30°, incidence ≤ 75°",
            "scanners [l1: LC15Dx, l2: LC60Dx]",
        ],
    );
    let face = [
        "--face",
        "stock.top",
        "-n",
        "32",
        "-o",
        pgm.to_str().unwrap(),
    ];
    expect(
        &[&["cones", "--probe", "l1"][..], &face, &[spec]].concat(),
        &[
            "scanner l1: stripe 18 mm at stand-off 60 ± 7.5 mm",
            "laser and camera reach the point",
            "housing clear (D1)",
            "head orientations that see it:",
            "face stock.top: 2500 mm²",
            "100.0 % of its area seen from 1 head orientation",
            "passes of",
        ],
    );
    assert!(std::fs::read(&pgm)
        .unwrap()
        .starts_with(b"P5\n128 96\n255\n"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_face_is_covered_by_few_views_of_parallel_passes() {
    use inspc::access::scan::{face_coverage, Views};
    let (checked, parts, graphs) = inspc::measurement_graphs(
        &inspc::source::FsWorld,
        &[std::path::PathBuf::from("examples/swiss_block.insp")],
    );
    assert!(!checked.has_errors());
    let g = &parts[graphs[0].part].as_ref().unwrap().geometry;
    let scene = inspc::access::Scene::of_part(g);
    let opts = ConeOptions {
        n: 32,
        ..ConeOptions::default()
    };
    let face = |name: &str| g.faces.iter().position(|f| f.name == name).unwrap();
    let fixed = scanner(Head::Fixed);
    let down = Views {
        grid: &[(0.0, 0.0)],
        overlap: 0.2,
        up: inspc::geometry::V3::z(),
        table: (f64::NEG_INFINITY, 0.0),
        fixture: &[],
    };
    // The 120 × 120 mm top around its 100 holes: one view straight down, passes 18 mm
    // wide less 20 % overlap across it, one elevation.
    let top = face_coverage(&Cpu, &scene, g, face("stock.top"), &fixed, &down, &opts);
    assert!(top.covered > 0.99, "{top:?}");
    assert_eq!(top.views.len(), 1, "{top:?}");
    let v = &top.views[0];
    assert!((8..=9).contains(&v.passes) && v.elevations == 1, "{v:?}");
    assert!(v.length > 110.0 && v.length <= 130.0, "{v:?}");
    assert_eq!(v.lines.len(), v.passes);
    // Every pass focuses on the face: midway between its nearest and farthest points
    // along the view, all at z = 30 here (the top).
    for l in &v.lines {
        for p in [l.start, l.end] {
            assert!((p.z - 30.0).abs() < 1e-6, "{l:?}");
        }
    }
    let shares: f64 = top.views.iter().map(|v| v.share).sum();
    assert!((shares - top.covered).abs() < 1e-9);
    // A hole's wall seen only from above meets the laser at 90°: nothing is covered.
    let wall = g
        .faces
        .iter()
        .position(|f| f.name.ends_with(".wall"))
        .unwrap();
    let w = face_coverage(&Cpu, &scene, g, wall, &fixed, &down, &opts);
    assert!(w.views.is_empty() && w.covered == 0.0, "{w:?}");
}

/// A block with a flat top, a deep hole and a side face, on a machine with an LC60Dx
/// (accuracy 9 µm); `plan` is the plan's body after its part and cmm.
pub(crate) fn mixed(plan: &str) -> String {
    format!(
        r#"
use std::heads::PH10MQ
use std::probes::TP20_D2_L20
use std::scanners::LC60Dx
part p {{
    units mm
    stock box(100, 80, 40)
    cut hole h {{ at (50, 40, 40), axis -z, diameter 8, depth 20 }}
    feature top = stock.top
    feature side = stock.front
    feature bore = h.wall
    datum A = top
    tolerance flat = flatness(top, 0.2 mm)
    tolerance side_flat = flatness(side, 0.05 mm)
    tolerance pos = position(bore, dia 0.5 mm, A)
}}
cmm lab {{
    table {{ z 0 mm, size (1000 mm, 700 mm) }}
    ram {{ radius 35 mm, length 600 mm }}
    head PH10MQ
    probes [p1: TP20_D2_L20]
    scanners [l1: LC60Dx]
}}
plan q {{
    part p
    cmm lab
    {plan}
}}
"#
    )
}

/// The sensor each feature of `mixed(plan)` gets, as (feature, sensor, why).
fn picks(plan: &str) -> Vec<(String, String, String)> {
    let mut world = inspc::source::MemoryWorld::new();
    world.insert("main.insp", mixed(plan).into_bytes());
    let (checked, parts, graphs) =
        inspc::measurement_graphs(&world, &[std::path::PathBuf::from("main.insp")]);
    assert!(!checked.has_errors(), "{:?}", checked.summary());
    let g = &parts[graphs[0].part].as_ref().unwrap().geometry;
    let json = inspc::graph::json(&checked.model.parts[0], g, &graphs[0].graph);
    let features = json["features"].as_array().unwrap().clone();
    features
        .iter()
        .map(|f| {
            (
                f["name"].as_str().unwrap().to_string(),
                f["sensor"].as_str().unwrap_or("").to_string(),
                f["sensor_why"].as_str().unwrap_or("").to_string(),
            )
        })
        .collect()
}

#[test]
fn sensors_are_chosen_by_tolerance_over_accuracy_and_by_shape() {
    let p = picks("");
    let get = |name: &str| p.iter().find(|f| f.0 == name).unwrap().clone();
    // 0.2 mm / 0.009 mm = 22 ≥ 10: the scanner.
    assert_eq!(get("top").1, "laser", "{p:?}");
    assert!(
        get("top").2.contains("flat 0.2 mm / 0.009 mm = 22.2 ≥ 10"),
        "{p:?}"
    );
    // 0.05 / 0.009 = 5.6 < 10: touch.
    assert_eq!(get("side").1, "touch", "{p:?}");
    assert!(
        get("side")
            .2
            .contains("side_flat 0.05 mm / 0.009 mm = 5.6 < 10"),
        "{p:?}"
    );
    // A Ø8 hole 20 deep: touch whatever its tolerance.
    assert_eq!(get("bore").1, "touch", "{p:?}");
    assert!(get("bore").2.contains("a bore Ø8 mm, 20 mm deep"), "{p:?}");
    // The 1:5 rule sends the side to the scanner; the plan's word beats the rule.
    let p = picks("sensor_ratio 5\n    sensors { top touch }");
    let get = |name: &str| p.iter().find(|f| f.0 == name).unwrap().clone();
    assert_eq!(get("side").1, "laser", "{p:?}");
    assert_eq!(
        get("top"),
        (
            "top".into(),
            "touch".into(),
            "the plan asks for touch".into()
        )
    );
}

#[test]
fn bad_sensor_statements_are_diagnostics() {
    for (plan, code, span) in [
        (
            "sensors { top lazer }",
            "insp::resolve::unknown_name",
            "lazer",
        ),
        (
            "sensors { tpo laser }",
            "insp::resolve::unknown_name",
            "tpo",
        ),
        (
            "sensors { top laser, top touch }",
            "insp::resolve::duplicate_name",
            "top",
        ),
        ("sensor_ratio 0", "insp::resolve::out_of_range", "0"),
    ] {
        let d = check_src(&mixed(plan));
        let e = d.only();
        assert_eq!(
            (e.code.as_str(), e.span_text.as_str()),
            (code, span),
            "{plan}"
        );
    }
    let d = check_src(&mixed("sensors { top lazer }"));
    assert!(d.only().help.contains("laser"), "{}", d.only().help);
    // Laser on a machine without a scanner.
    let src = mixed("sensors { top laser }").replace("    scanners [l1: LC60Dx]\n", "");
    let d = check_src(&src);
    let e = d.only();
    assert_eq!(
        (e.code.as_str(), e.span_text.as_str()),
        ("insp::resolve::no_scanner", "laser")
    );
}
