//! Room beside the ball: a touch a ball fits only tight goes to a roomier ball of its
//! setup (`plan::roomy`). A 3.2 mm counterbore floor takes a Ø3 ball with 0.1 mm to
//! spare on each side — the wall at its size limit, or the counterbore anywhere in its
//! position zone, would be in its way — so the plan touches it with the Ø1 ball, and
//! keeps the Ø3 ball everywhere it has room.

use std::path::Path;

const SPEC: &str = r#"use std::heads::PH10MQ
use std::probes::{TP20_D3_L50, TP20_D1_L20}
use std::hierarchies::efficient_accuracy

part cb {
    units mm
    stock box(80, 60, 30)
    cut hole cbore { at (40, 30, 30), axis -z, diameter 20, depth 5 }
    cut hole bore  { at (40, 30, 30), axis -z, diameter 13.6, depth 20 }
    feature top   = stock.top
    feature floor = cbore.bottom
    feature wall  = bore.wall
    datum A = top
    tolerance T0 = parallelism(floor, 0.05 mm, A)
    tolerance T1 = perpendicularity(wall, dia 0.05 mm, A)
}

cmm lab {
    table { z 0 mm, size (1000 mm, 700 mm) }
    ram { radius 35 mm, length 600 mm }
    head PH10MQ
    probes [big: TP20_D3_L50, small: TP20_D1_L20]
}

plan cb_plan {
    part cb
    cmm lab
    hierarchy efficient_accuracy
    prefer setup +z weight 1.0
}
"#;

#[test]
fn a_narrow_counterbore_floor_is_touched_with_the_smaller_ball() {
    let dir = std::env::temp_dir().join(format!("inspc_room_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("cb.insp");
    std::fs::write(&path, SPEC).unwrap();
    let hlip = crate::common::first_plan(Path::new(&path), &inspc::plan::PlanOptions::default());
    // Per touch: the probe slot, and whether it is on the floor (z 25, facing up) or
    // the top (z 30).
    let mut floor = Vec::new();
    let mut top = Vec::new();
    for s in &hlip.setups {
        for p in &s.probes {
            for o in &p.orients {
                for visit in o.inspections.iter().flat_map(|i| &i.faces) {
                    for &k in &visit.points {
                        let pt = &hlip.points[k];
                        if pt.normal.z > 0.99 && (pt.position.z - 25.0).abs() < 1e-6 {
                            floor.push(p.probe.0);
                        } else if pt.normal.z > 0.99 && (pt.position.z - 30.0).abs() < 1e-6 {
                            top.push(p.probe.0);
                        }
                    }
                }
            }
        }
    }
    assert!(!floor.is_empty() && !top.is_empty(), "{floor:?} {top:?}");
    assert!(floor.iter().all(|&p| p == 1), "floor touched by {floor:?}");
    assert!(top.iter().all(|&p| p == 0), "top touched by {top:?}");
}
