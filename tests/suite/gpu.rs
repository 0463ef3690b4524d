//! The GPU backend against the CPU's, on every example and NIST part: for every probe's
//! components (and the bare half-line) at pseudo-random fpoints, and the second
//! components at articulation points, the GPU never reports free a pixel the CPU finds
//! blocked, and the two agree on ≥ 99.9 % of the cells.
//!
//! Runs wherever wgpu finds an adapter: Mesa's lavapipe, which `.ci/run` installs, or a
//! real GPU. Without one the tests say so and pass, unless `INSPC_REQUIRE_GPU` is set
//! (`.ci/run` sets it, so CI cannot skip them silently).

use inspc::access::{axes, gpu, Backend, Component, Cpu, CubeMap, ProbeShape, Query, Scene};
use inspc::geometry::{P3, V3};
use inspc::source::FsWorld;
use std::path::PathBuf;

fn device() -> Option<&'static inspc::access::Gpu> {
    match gpu() {
        Ok(g) => Some(g),
        Err(why) => {
            assert!(
                std::env::var_os("INSPC_REQUIRE_GPU").is_none(),
                "INSPC_REQUIRE_GPU is set and wgpu found no adapter: {why}"
            );
            eprintln!("no GPU adapter ({why}): GPU tests skipped");
            None
        }
    }
}

/// The scene, `count` fpoints' tip centres per probe, and the plan's probes.
fn case(spec: &str, count: usize) -> (Scene, Vec<ProbeShape>, Vec<(usize, P3)>) {
    let (checked, parts, graphs) = inspc::measurement_graphs(&FsWorld, &[PathBuf::from(spec)]);
    assert!(!checked.has_errors(), "{spec}");
    let gr = &graphs[0];
    let g = &parts[gr.part].as_ref().unwrap().geometry;
    let model = &checked.model;
    let probes = model
        .plans
        .first()
        .map(|p| ProbeShape::of_cmm(model, &model.cmms[p.cmm.0]))
        .unwrap_or_default();
    let fp = &gr.graph.fpoints;
    let mut state = 41u64;
    let mut points = Vec::new();
    for (k, probe) in probes.iter().enumerate() {
        for _ in 0..count {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            points.push((
                k,
                fp[(state >> 33) as usize % fp.len()].tip_centre(probe.tip_radius),
            ));
        }
    }
    (Scene::of_part(g), probes, points)
}

/// (cells, agreeing cells, GPU-only blocked cells) over every query; panics where the
/// GPU reports free what the CPU blocks.
fn compare(spec: &str, count: usize, n: u32) -> (usize, usize, usize) {
    let Some(gpu) = device() else {
        return (0, 0, 0);
    };
    let (scene, probes, points) = case(spec, count);
    let half = Component::half_line();
    let mut queries: Vec<Query> = Vec::new();
    for (k, c) in &points {
        let probe = &probes[*k];
        queries.push(Query {
            from: *c,
            comp: &half,
        });
        for comp in probe.first.iter().chain(&probe.second) {
            queries.push(Query { from: *c, comp });
        }
        // The second components standing on an articulation point above the tip.
        let x = c + V3::new(0.3, -0.2, 1.0).normalize() * probe.reach();
        for comp in &probe.second {
            queries.push(Query { from: x, comp });
        }
    }
    let pref = axes();
    let on_gpu = gpu.blocked_many(&scene, &queries, n, &pref);
    let on_cpu: Vec<CubeMap> = queries
        .iter()
        .map(|q| Cpu.blocked(&scene, &q.from, q.comp, n, &pref))
        .collect();
    assert_eq!(on_gpu.len(), queries.len());
    let (mut total, mut agree, mut extra) = (0, 0, 0);
    for ((q, g), c) in queries.iter().zip(&on_gpu).zip(&on_cpu) {
        for cell in c.cells() {
            assert!(
                g.get(cell),
                "{spec}: the GPU reports {cell:?} free for {} at {:?}; the CPU finds it blocked",
                q.comp.name,
                q.from
            );
        }
        let cells = 6 * (n as usize) * (n as usize) + pref.len();
        let (gc, cc) = (g.count(), c.count());
        total += cells;
        agree += cells - (gc - cc);
        extra += gc - cc;
    }
    eprintln!(
        "{spec}: {} queries, {agree}/{total} cells agree, {extra} blocked on the GPU only",
        queries.len()
    );
    assert!(
        agree as f64 >= 0.999 * total as f64,
        "{spec}: the GPU agrees with the CPU on {:.4} % of cells",
        100.0 * agree as f64 / total as f64
    );
    (total, agree, extra)
}

#[test]
fn gpu_cones_match_the_cpu_on_the_examples() {
    for spec in [
        "examples/f2.insp",
        "examples/f3_fixed.insp",
        "examples/f3_indexed.insp",
        "examples/f4.insp",
        "examples/swiss_block.insp",
        "examples/swiss_sphere_fixed.insp",
        "examples/swiss_sphere_indexed.insp",
    ] {
        compare(spec, 4, 32);
    }
}

#[test]
fn gpu_cones_match_the_cpu_on_the_nist_parts() {
    crate::common::require_shared_parts();
    for spec in [
        "tests/real/nist_ctc_01.insp",
        "tests/real/nist_ctc_02.insp",
        "tests/real/nist_ftc_06.insp",
        "tests/real/nist_ftc_08.insp",
    ] {
        compare(spec, 2, 64);
    }
}
