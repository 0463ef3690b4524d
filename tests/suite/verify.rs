//! `inspc verify` where the answer is known: a clean program, a program that cannot see
//! a tilt (the feature sets its own frame), the sampling that decides whether a bow is
//! seen, the one tilt an angle to a lone datum forbids, and the same report on every run.

use inspc::source::FsWorld;
use inspc::verify::{Options, Verification};
use std::path::Path;

fn verify(spec: &Path, placements: usize) -> Vec<Verification> {
    verify_program(spec, None, placements)
}

fn verify_program(spec: &Path, program: Option<&Path>, placements: usize) -> Vec<Verification> {
    let opts = Options {
        placements,
        ..Default::default()
    };
    let run = inspc::verify(
        &FsWorld,
        spec,
        program,
        &inspc::plan::PlanOptions::default(),
        &opts,
    );
    assert!(
        !run.checked.has_errors(),
        "{}: {:?}",
        spec.display(),
        run.checked
            .diagnostics
            .iter()
            .map(|d| d.message())
            .collect::<Vec<_>>()
    );
    run.results
}

/// F2 (the seed's slots, perpendicular to the top): found wherever it lies, both
/// tilts read out at twice the zone and in at half.
#[test]
fn f2_reads_right_wherever_it_lies() {
    let v = verify(Path::new("examples/f2.insp"), 8);
    assert_eq!(v.len(), 1);
    let text = v[0].text();
    assert_eq!(v[0].problems(), 0, "{text}");
    assert!(
        text.contains("8 within ±5 mm and ±3°: 0 stopped, 0 changed a verdict"),
        "{text}"
    );
}

/// F3's side hole has a setup of its own where no programmed touch reaches datum A. The
/// plan aligns that setup on the stock's faces; a program that aligns it again on the
/// hole itself (as inspc's did) makes the hole set its own frame, and a tilted hole
/// reads parallel. The battery says so.
#[test]
fn a_feature_that_sets_its_own_frame_is_caught() {
    let spec = Path::new("examples/f3_fixed.insp");
    assert_eq!(verify(spec, 1)[0].problems(), 0);
    let golden = std::fs::read_to_string("tests/cases/example_f3_fixed/program.dmi").unwrap();
    let own = "DATDEF/FA(AL2_STOCK_FRON_2),DAT(AL2_DCC_3)\n\
               D(SETUP2_DCC)=DATSET/DAT(AL2_DCC_1),XDIR,XORIG,DAT(AL2_DCC_2),YDIR,ZORIG,$\n\
               DAT(AL2_DCC_3),YORIG\n\
               D(PART2_DCC)=TRANS/XORIG,-100.0,ZORIG,-50.0,YORIG,0.0\n";
    let on_hole = "DATDEF/FA(SIDE_HOLE),DAT(AL2_DCC_3)\n\
                   D(SETUP2_DCC)=DATSET/DAT(AL2_DCC_3),-XDIR,YORIG,ZORIG,DAT(AL2_DCC_2),YDIR,$\n\
                   DAT(AL2_DCC_1),XORIG\n\
                   D(PART2_DCC)=TRANS/YORIG,-30.0,ZORIG,-25.0,XORIG,-100.0\n";
    assert!(golden.contains(own), "the golden program's setup 2 changed");
    let dir = std::env::temp_dir().join(format!("inspc_self_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let program = dir.join("on_hole.dmi");
    std::fs::write(&program, golden.replace(own, on_hole)).unwrap();
    let v = verify_program(spec, Some(&program), 2);
    std::fs::remove_dir_all(&dir).ok();
    let text = v[0].text();
    assert!(v[0].problems() > 0, "{text}");
    assert!(
        text.contains("T2 side_hole tilted across") && text.contains("at 2x"),
        "{text}"
    );
}

/// A block whose top has a flatness tolerance: Fan & Leu's four points (and the fill
/// inside its fifth inset) miss most of a bow, the default `spread` grid sees it.
#[test]
fn spread_points_see_a_bow_that_fan_and_leu_miss() {
    let dir = std::env::temp_dir().join(format!("inspc_verify_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let spec = |sampling: &str| {
        format!(
            "use std::heads::PH6\nuse std::probes::TP20_D2_L20\n{sampling}\n\
             part block {{\n    units mm\n    stock box(100, 80, 40)\n    feature top = stock.top\n    \
             tolerance flat = flatness(top, 0.02 mm)\n}}\n\
             cmm lab {{\n    table {{ z 0 mm, size (1000 mm, 700 mm) }}\n    ram {{ radius 35 mm, length 600 mm }}\n    \
             head PH6\n    probes [p1: TP20_D2_L20]\n}}\n\
             plan block_plan {{\n    part block\n    cmm lab\n{}}}\n",
            if sampling.is_empty() { "" } else { "    sampling fan_leu\n" }
        )
    };
    let fan = dir.join("fan.insp");
    let spread = dir.join("spread.insp");
    std::fs::write(&fan, spec("use std::sampling::fan_leu")).unwrap();
    std::fs::write(&spread, spec("")).unwrap();
    let f = verify(&fan, 1);
    let s = verify(&spread, 1);
    let (ft, st) = (f[0].text(), s[0].text());
    assert!(
        ft.contains("bow on top at 2x"),
        "Fan & Leu should miss the bow:\n{ft}"
    );
    assert_eq!(s[0].problems(), 0, "spread should see it:\n{st}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The report is a function of the spec: two runs print the same bytes.
#[test]
fn the_report_is_the_same_every_run() {
    let spec = Path::new("examples/f4.insp");
    let a: Vec<String> = verify(spec, 3).iter().map(|v| v.text()).collect();
    let b: Vec<String> = verify(spec, 3).iter().map(|v| v.text()).collect();
    assert_eq!(a, b);
}

/// Zones per unit area (ASME Y14.5-2018 § 5.4.2.2): a bump as wide as the unit, twice
/// the unit zone high, reads out though the whole face stays within its own zone; half
/// as high reads in. The program checks each unit stretch as a feature of its own.
#[test]
fn a_bump_within_a_unit_area_is_seen() {
    let dir = std::env::temp_dir().join(format!("inspc_per_unit_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let spec = dir.join("plate.insp");
    std::fs::write(&spec, PER_UNIT_PLATE).unwrap();
    let v = verify(&spec, 2);
    // Off the windows' centres too (an independent review's case: a 0.037 mm bump 25 mm
    // across whose top fell on the edge of every window of a half-unit step read 0.02),
    // and a bump on the front as wide as its short side.
    let (_, built, _) = inspc::build(
        &FsWorld,
        std::slice::from_ref(&spec),
        &inspc::plan::PlanOptions::default(),
        &|_, _, _| {},
    );
    let program = dir.join("plate.dmi");
    std::fs::write(&program, &built[0].dmis).unwrap();
    let (spec_s, program_s) = (spec.to_str().unwrap(), program.to_str().unwrap());
    for (dev, target) in [
        (
            "face stock.top bump 0.037 at (32.7, 32.3, 20) across 25",
            "TOP_FLAT_UNIT",
        ),
        (
            "face stock.front bump 0.034 at (38, 0, 8.5) across 10",
            "FRONT_FLAT",
        ),
    ] {
        let opts = inspc::simulate::Options::default();
        let r = crate::simulate::run(spec_s, program_s, Some(dev), opts).unwrap();
        let out: Vec<&str> = r
            .rows
            .iter()
            .filter(|x| !x.pass())
            .map(|x| x.tolerance.as_str())
            .collect();
        assert!(
            !out.is_empty() && out.iter().all(|t| *t == target),
            "{dev}: {out:?}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
    let text = v[0].text();
    assert_eq!(v[0].problems(), 0, "{text}");
    let json = v[0].json().to_string();
    for what in [
        "bump per 25×25 on top",
        "bump per 20×10 on front",
        "bow on top",
    ] {
        assert!(json.contains(what), "no trial `{what}`: {json}");
    }
    // The unit zone alone is not a whole-face zone: no bow is tried on the front.
    assert!(!json.contains("bow on front"), "{json}");
    assert!(
        text.contains("0.1, 0.02/25×25") && text.contains("0.03/20×10"),
        "{text}"
    );
}

const PER_UNIT_PLATE: &str = "use std::heads::PH10MQ
use std::probes::TP20_D2_L20
use std::hierarchies::efficient_accuracy

part plate {
    units mm
    stock box(120, 80, 20)
    cut hole bore_a { at (60, 40, 20), axis -z, diameter 16, depth 20 }
    feature top = stock.top
    feature front = stock.front
    tolerance top_flat = flatness(top, 0.1 mm, per_unit(0.02 mm, 25 mm))
    tolerance front_flat = flatness(front, per_unit(0.03 mm, 20 mm, 10 mm))
}

cmm lab {
    table { z 0 mm, size (1000 mm, 700 mm) }
    ram { radius 35 mm, length 600 mm }
    head PH10MQ
    probes [p1: TP20_D2_L20]
}

plan plate_plan {
    part plate
    cmm lab
    hierarchy efficient_accuracy
}
";

/// A 100 × 50 × 60 block whose top-right edge is cut at 45° (the chamfer's normal is
/// (0.707, 0, 0.707)), faces grouped by name; its bottom is datum A.
const CHAMFERED_BLOCK: &str = "v 0 0 0\nv 100 0 0\nv 100 0 30\nv 70 0 60\nv 0 0 60\n\
    v 0 50 0\nv 100 50 0\nv 100 50 30\nv 70 50 60\nv 0 50 60\n\
    g bottom\nf 1 7 2\nf 1 6 7\ng right\nf 2 8 3\nf 2 7 8\ng chamfer\nf 3 9 4\nf 3 8 9\n\
    g top\nf 4 10 5\nf 4 9 10\ng left\nf 5 6 1\nf 5 10 6\n\
    g front\nf 1 2 3\nf 1 3 4\nf 1 4 5\ng back\nf 6 8 7\nf 6 9 8\nf 6 10 9\n";

/// Angularity to a lone primary plane (ASME Y14.5-2018 § 7.11: the plane leaves the
/// zone free to turn about its normal): only a tilt that changes the chamfer's 45° to A
/// is forbidden. A tilt about the chamfer's other in-plane axis keeps the angle (to the
/// first order) and reads in, as it should; the battery tries the one tilt that
/// matters, which reads out at twice the zone and in at half.
#[test]
fn an_angle_to_a_lone_datum_is_broken_by_the_tilt_that_changes_it() {
    let dir = std::env::temp_dir().join(format!("inspc_angle_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("block.obj"), CHAMFERED_BLOCK).unwrap();
    let spec = dir.join("block.insp");
    std::fs::write(
        &spec,
        "use std::heads::PH10MQ\nuse std::probes::TP20_D2_L20\n\
         part block {\n    units mm\n    mesh \"block.obj\"\n    \
         feature base = group \"bottom\"\n    feature slope = group \"chamfer\"\n    \
         datum A = base\n    tolerance ang = angularity(slope, 0.1 mm, A, basic 45 deg)\n}\n\
         cmm lab {\n    table { z 0 mm, size (1000 mm, 700 mm) }\n    ram { radius 35 mm, length 600 mm }\n    \
         head PH10MQ\n    probes [p1: TP20_D2_L20]\n}\n\
         plan block_plan {\n    part block\n    cmm lab\n}\n",
    )
    .unwrap();
    let v = verify(&spec, 1);
    std::fs::remove_dir_all(&dir).ok();
    let text = v[0].text();
    assert_eq!(v[0].problems(), 0, "{text}");
    let ang = text
        .lines()
        .find(|l| l.starts_with("ANG "))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(ang.contains(" in ") && ang.contains(" out "), "{ang}");
}
