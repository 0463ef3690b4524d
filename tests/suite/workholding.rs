//! Workholding on real plans: risers lift a pose only where the table hides a face, their
//! three pads stand wholly under the part's base and hold it (the centre of mass inside
//! their triangle), and the same part with nothing near the table stands on the table.

use inspc::plan::poses::Holder;
use inspc::plan::PlanOptions;
use std::path::Path;

const REBATE: &str = "tests/cases/setup_risers_for_a_base_rebate/main.insp";

/// The pads' centres (x, y) from a riser setup's words: `pads at x 28 y 10, x 68 y 30
/// and x 28 y 50 mm from the corner …`.
fn pads(placement: &str) -> Vec<[f64; 2]> {
    let list = &placement[placement.find("pads at ").expect("pads") + 8..];
    let list = &list[..list.find(" mm from").expect("mm from")];
    list.split([',', ' '])
        .filter(|w| !w.is_empty() && *w != "and")
        .collect::<Vec<_>>()
        .chunks(4)
        .map(|c| {
            assert_eq!((c[0], c[2]), ("x", "y"), "{placement}");
            [c[1].parse().unwrap(), c[3].parse().unwrap()]
        })
        .collect()
}

#[test]
fn risers_lift_the_block_whose_base_rebate_the_table_hides() {
    let hlip = inspc_first_plan(Path::new(REBATE));
    assert_eq!(hlip.setups.len(), 1, "top and rebate wall in one setup");
    let s = &hlip.setups[0];
    let Holder::Fixture {
        placement: Some(words),
        ..
    } = &s.holder
    else {
        panic!("the block stands on risers: {:?}", s.holder);
    };
    let at = pads(words);
    assert_eq!(at.len(), 3, "{words}");
    // Ø20 mm pads wholly under the base: x 10..80 (the rebate takes 0..10), y 0..60,
    // measured from the part's corner (0, 0, 0).
    for [x, y] in &at {
        assert!((20.0 - 1.0..=70.0 + 1.0).contains(x), "{words}");
        assert!((10.0 - 1.0..=50.0 + 1.0).contains(y), "{words}");
    }
    // The centre of mass (about (40.4, 30)) inside the pads' triangle.
    let c = (40.4, 30.0);
    let side =
        |a: &[f64; 2], b: &[f64; 2]| (b[0] - a[0]) * (c.1 - a[1]) - (b[1] - a[1]) * (c.0 - a[0]);
    let s3 = [
        side(&at[0], &at[1]),
        side(&at[1], &at[2]),
        side(&at[2], &at[0]),
    ];
    assert!(
        s3.iter().all(|&v| v > 0.0) || s3.iter().all(|&v| v < 0.0),
        "{words}"
    );
    // Three pads standing on the table, 25 mm under the part.
    assert_eq!(s.fixture.len(), 3);
    for pad in &s.fixture {
        assert!((pad.lowest(&s.up) - s.table).abs() < 1e-6);
    }
    assert!((s.table + 25.0).abs() < 1e-6, "table at {}", s.table);
}

#[test]
fn a_block_with_nothing_near_the_table_stands_on_it() {
    let text = std::fs::read_to_string(REBATE).unwrap();
    let plain = text.replace(
        "    cut step rebate { at (0, 0, 0), along +y, into +z, width 10, depth 4 }\n",
        "",
    );
    let plain = plain.replace("rebate.wall", "stock.left");
    assert_ne!(plain, text);
    let dir = std::env::temp_dir().join(format!("inspc_risers_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("plain.insp");
    std::fs::write(&path, plain).unwrap();
    let hlip = inspc_first_plan(&path);
    let _ = std::fs::remove_dir_all(&dir);
    for s in &hlip.setups {
        assert!(
            matches!(s.holder, Holder::Table { .. }),
            "no face near the table, no risers: {:?}",
            s.holder
        );
    }
}

fn inspc_first_plan(path: &Path) -> inspc::plan::Hlip {
    crate::common::first_plan(path, &PlanOptions::default())
}

/// `inspc plan --explain-setups` of a block `size` on a CMM with the standard sine plate.
fn plate_setups(size: &str) -> String {
    let text = format!(
        "use std::fixtures::SINE_PLATE_60\nuse std::heads::PH10M\nuse std::probes::TP20_D2_L20\n\
         part block {{ units mm, stock box({size}), feature top = stock.top, \
         tolerance flat = flatness(top, 0.05 mm) }}\n\
         cmm lab {{ table {{ z 0 mm, size (2000 mm, 1200 mm) }}, ram {{ radius 35 mm, length 600 mm }}, \
         head PH10M, probes [p1: TP20_D2_L20], fixtures [sine: SINE_PLATE_60] }}\n\
         plan p {{ part block, cmm lab, fixtures [sine] }}\n"
    );
    let dir =
        std::env::temp_dir().join(format!("inspc_plate_{}_{}", std::process::id(), size.len()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("plate.insp");
    std::fs::write(&path, text).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_inspc"))
        .args(["plan", "--explain-setups", path.to_str().unwrap()])
        .env("NO_COLOR", "1")
        .output()
        .expect("inspc runs");
    let _ = std::fs::remove_dir_all(&dir);
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn a_sine_plate_holds_only_a_part_its_top_can_take() {
    // A 6 × 12 in plate takes a 100 mm block on any broad face, up to 225 × 450 mm.
    let small = plate_setups("100, 60, 20");
    assert!(
        small.contains("one of its 4 largest flat faces that fit its 150 × 300 mm top"),
        "{small}"
    );
    // An 800 × 450 mm part (the size of NIST's CTC 01) goes on no such plate.
    let large = plate_setups("800, 450, 150");
    assert!(
        large.contains("none of its faces: it is more than 1.5 times the plate's 150 × 300 mm top"),
        "{large}"
    );
}
