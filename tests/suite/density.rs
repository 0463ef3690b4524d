//! Planning at density (issue 47): a face sampled densely is planned on its strategy's
//! representatives, and its own points take their configurations. The plan's setups,
//! probes and setup directions are the same at every density, every point sampled is
//! either touched or counted as dropped, and no representative is left in the plan.

use crate::common::first_plan;
use inspc::plan::{Hlip, PlanOptions, PointRef};
use std::collections::BTreeSet;

/// The spec with every surface kind sampled at `n` Hammersley points, planned.
fn plan_at(spec: &str, n: usize) -> Hlip {
    let text = std::fs::read_to_string(spec).unwrap();
    // The plan's own sampling gives way to the dense one.
    let text: String = text
        .lines()
        .filter(|l| !l.trim_start().starts_with("sampling "))
        .map(|l| format!("{l}\n"))
        .collect();
    let at = text.find("\nplan ").unwrap();
    let open = at + text[at..].find('{').unwrap();
    let kinds = ["plane", "cylinder", "cone", "sphere", "freeform"];
    let block: String = kinds
        .iter()
        .map(|k| format!("    {k} hammersley(points {n})\n"))
        .collect();
    let dense = format!(
        "{}\n    sampling dense{}\nsampling dense {{\n{block}}}\n",
        &text[..=open],
        &text[open + 1..]
    );
    // In a folder of its own (the examples' folder is read by other tests), with the
    // part files its `use` paths name.
    let dir = std::env::temp_dir().join(format!("inspc-density-{}-{n}", std::process::id()));
    let parts = dir.join("parts");
    std::fs::create_dir_all(&parts).unwrap();
    for f in std::fs::read_dir("examples/parts").unwrap() {
        let f = f.unwrap().path();
        std::fs::copy(&f, parts.join(f.file_name().unwrap())).unwrap();
    }
    let path = dir.join("dense.insp");
    std::fs::write(&path, dense).unwrap();
    let plan = first_plan(&path, &PlanOptions::default());
    std::fs::remove_dir_all(&dir).ok();
    plan
}

/// Every point the plan touches.
fn touched(h: &Hlip) -> BTreeSet<usize> {
    h.setups
        .iter()
        .flat_map(|s| &s.probes)
        .flat_map(|p| &p.orients)
        .flat_map(|o| &o.inspections)
        .flat_map(|i| &i.faces)
        .flat_map(|v| v.points.iter().copied())
        .collect()
}

/// Setup directions and the probes each loads.
fn shape(h: &Hlip) -> Vec<(String, Vec<usize>)> {
    h.setups
        .iter()
        .map(|s| {
            let up = format!("{:.3} {:.3} {:.3}", s.up.x, s.up.y, s.up.z);
            let mut probes: Vec<usize> = s.probes.iter().map(|p| p.probe.0).collect();
            probes.sort_unstable();
            (up, probes)
        })
        .collect()
}

#[test]
fn a_dense_plan_keeps_its_setups_and_probes_at_every_density() {
    for spec in ["examples/f2.insp", "examples/f3_indexed.insp"] {
        let plans: Vec<Hlip> = [40, 120].into_iter().map(|n| plan_at(spec, n)).collect();
        assert_eq!(
            shape(&plans[0]),
            shape(&plans[1]),
            "{spec}: setups and probes at 40 and at 120 points a face"
        );
        for (h, n) in plans.iter().zip([40, 120]) {
            let graph = h
                .points
                .iter()
                .filter(|p| matches!(p.at, PointRef::Graph(_)))
                .count();
            for (i, p) in h.points.iter().enumerate().take(graph) {
                assert_eq!(
                    p.at,
                    PointRef::Graph(i),
                    "{spec} at {n}: points in graph order"
                );
            }
            let t = touched(h);
            assert!(
                t.iter().all(|&i| i < h.points.len()),
                "{spec} at {n}: a representative left in the plan"
            );
            assert_eq!(h.summary.points, t.len(), "{spec} at {n}: counted");
            // On every face the plan touches, a point not touched is counted dropped.
            let faces: BTreeSet<_> = t
                .iter()
                .filter(|&&i| i < graph)
                .map(|&i| h.points[i].face)
                .collect();
            let missed = (0..graph)
                .filter(|i| faces.contains(&h.points[*i].face) && !t.contains(i))
                .count();
            assert!(
                missed <= h.summary.dropped_points,
                "{spec} at {n}: {missed} points untouched, {} counted dropped",
                h.summary.dropped_points
            );
        }
    }
}
