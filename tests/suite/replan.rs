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

/// A re-plan takes up the search where a new ban first matters (`plan::journal`): its
/// plan is the one a search from the first round gives, for a ban on the first touch
/// (validated early) and on the last (validated late).
#[test]
fn a_replan_that_resumes_plans_as_a_search_from_the_start() {
    use inspc::plan::{plan_with, Input, Memo};
    for spec in ["examples/f3_indexed.insp", "examples/f2.insp"] {
        let (checked, parts, graphs, planned) = inspc::plans(
            &inspc::source::FsWorld,
            &[spec.into()],
            &PlanOptions::default(),
        );
        let model = &checked.model;
        let p = &planned[0];
        let plan = &model.plans[p.plan];
        let g = graphs
            .iter()
            .find(|g| g.graph.plan.as_deref() == Some(&plan.name))
            .expect("the plan's graph");
        let data = parts[g.part].as_ref().expect("the part");
        let input = Input {
            model,
            plan,
            geometry: &data.geometry,
            fixtures: &data.fixtures,
            graph: &g.graph,
        };
        let touched = configurations(p.hlip.as_ref().expect("a plan"));
        for ban in [&touched[0], touched.last().expect("a touch")] {
            let mut memo = Memo::default();
            let mut diags = inspc::diag::Diagnostics::new();
            plan_with(&input, &PlanOptions::default(), &mut memo, &mut diags);
            let banned = PlanOptions {
                bans: vec![ban.clone()],
                ..PlanOptions::default()
            };
            let resumed = plan_with(&input, &banned, &mut memo, &mut diags);
            let fresh = plan_with(&input, &banned, &mut Memo::default(), &mut diags);
            assert!(fresh.is_some(), "{spec}: no plan with {ban:?}");
            assert_eq!(resumed, fresh, "{spec}: banned {ban:?}");
        }
    }
}
