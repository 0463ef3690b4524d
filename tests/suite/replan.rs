//! Generate-and-test with the path stage as a test: a touch configuration no
//! collision-free move reaches is banned, and the planner plans that touch elsewhere.

use inspc::plan::{Ban, Hlip, PlanOptions};

/// Every (point, probe, up, direction) the plan touches.
fn configurations(h: &Hlip) -> Vec<Ban> {
    let mut out = Vec::new();
    for s in &h.setups {
        for p in &s.probes {
            for o in &p.orients {
                for f in o.inspections.iter().flat_map(|i| &i.faces) {
                    for &point in &f.points {
                        out.push(Ban {
                            point,
                            probe: p.probe.0,
                            up: s.up,
                            dir: o.direction,
                            any_dir: false,
                        });
                    }
                }
            }
        }
    }
    out
}

fn plan(spec: &str, opts: &PlanOptions) -> Hlip {
    crate::common::first_plan(std::path::Path::new(spec), opts)
}

fn same(a: &Ban, b: &Ban) -> bool {
    a.point == b.point
        && a.probe == b.probe
        && (a.up - b.up).norm() < 1e-5
        && (a.dir - b.dir).norm() < 1e-5
}

/// The first touch of the first group banned: the new plan still touches that point,
/// never in the banned configuration, and measures every tolerance.
#[test]
fn a_banned_configuration_is_planned_elsewhere() {
    for spec in ["examples/f3_indexed.insp", "examples/f2.insp"] {
        let first = plan(spec, &PlanOptions::default());
        let ban = configurations(&first)[0].clone();
        let opts = PlanOptions {
            bans: vec![ban.clone()],
            ..PlanOptions::default()
        };
        let again = plan(spec, &opts);
        let touched = configurations(&again);
        assert!(
            touched.iter().any(|c| c.point == ban.point),
            "{spec}: point {} is no longer touched",
            ban.point
        );
        assert!(
            !touched.iter().any(|c| same(c, &ban)),
            "{spec}: the banned configuration is planned again: {ban:?}"
        );
        assert_eq!(again.summary.tolerances, first.summary.tolerances, "{spec}");
    }
}
