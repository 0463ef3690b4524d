//! The GPU backend against the CPU's, on every example and NIST part: for every probe's
//! components (and the bare half-line) at pseudo-random fpoints, and the second
//! components at articulation points, the GPU never reports free a pixel the CPU finds
//! blocked, and the two agree on ≥ 99.9 % of the cells.
//!
//! Runs wherever wgpu finds an adapter: Mesa's lavapipe, which `.ci/run` installs, or a
//! real GPU, under `INSPC_SLOW=1` (`.ci/run` sets it). Without an adapter the tests say so and
//! pass, unless `INSPC_REQUIRE_GPU` is set (`.ci/run` sets it, so CI cannot skip them
//! silently).

use inspc::access::{axes, gpu, Backend, Component, Cpu, CubeMap, ProbeShape, Query, Scene};
use inspc::geometry::{P3, V3};

fn device() -> Option<&'static inspc::access::Gpu> {
    if crate::common::skip_unless_slow("the GPU backend's tests") {
        return None;
    }
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

/// The scene, the plan's probes, and `count` fpoints' tip centres per probe.
fn case(spec: &str, count: usize) -> (Scene, Vec<ProbeShape>, Vec<(usize, P3)>) {
    let (scene, probes, fp) = crate::access::loaded(spec);
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
    (scene, probes, points)
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
    for spec in crate::access::EXAMPLES {
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

/// The CPU, claiming to batch: drives the batched code paths with exact CPU maps.
struct BatchingCpu;

impl Backend for BatchingCpu {
    fn blocked(&self, scene: &Scene, from: &P3, comp: &Component, n: u32, pref: &[V3]) -> CubeMap {
        Cpu.blocked(scene, from, comp, n, pref)
    }

    fn batches(&self) -> bool {
        true
    }
}

/// The batched cones (all approach queries in one call, all D2 samples in another) are
/// the per-point cones, on a fixed and an indexable head; on the GPU they are those
/// cones or more pessimistic, pixel for pixel.
#[test]
fn batched_point_cones_are_the_per_point_cones() {
    use inspc::access::{gac_halfline, gac_halfline_many, point_cones, point_cones_many};
    for spec in ["examples/f3_fixed.insp", "examples/f3_indexed.insp"] {
        let (scene, probes, fpoints) = crate::access::loaded(spec);
        let opts = inspc::access::ConeOptions {
            n: 32,
            d2_samples: 4,
            ..Default::default()
        };
        let items: Vec<_> = fpoints
            .iter()
            .step_by(3)
            .flat_map(|f| probes.iter().map(move |p| (f, p)))
            .collect();
        let batched = point_cones_many(&BatchingCpu, &scene, &items, &opts);
        for ((f, p), b) in items.iter().zip(&batched) {
            assert_eq!(*b, point_cones(&Cpu, &scene, f, p, &opts), "{spec}");
        }
        assert!(batched.iter().any(|c| !c.approach.is_empty()));
        let centres: Vec<P3> = items
            .iter()
            .map(|(f, p)| f.tip_centre(p.tip_radius))
            .collect();
        let halves = gac_halfline_many(&BatchingCpu, &scene, &centres, 32, &opts.preferred);
        for (c, h) in centres.iter().zip(&halves) {
            assert_eq!(*h, gac_halfline(&scene, c, 32, &opts.preferred));
        }
        let Some(gpu) = device() else { continue };
        for (g, c) in point_cones_many(gpu, &scene, &items, &opts)
            .iter()
            .zip(&batched)
        {
            assert_eq!(g.tip_fits, c.tip_fits);
            // The GPU's approach cone lies inside the CPU's.
            assert_eq!(g.approach.and(&c.approach), g.approach, "{spec}");
        }
    }
}

/// `inspc build --backend gpu` writes a program that measures what the CPU's does, and
/// says which adapter it used; `--backend auto` builds wherever it runs.
#[test]
fn build_on_the_gpu_backend() {
    if crate::common::skip_unless_slow("inspc build on the GPU backend") {
        return;
    }
    let dir = std::env::temp_dir().join(format!("inspc-gpu-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let run = |backend: &str| {
        let out = dir.join(format!("f3_indexed_{backend}.dmi"));
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_inspc"))
            .args([
                "build",
                "examples/f3_indexed.insp",
                "--backend",
                backend,
                "-o",
            ])
            .arg(&out)
            .output()
            .expect("inspc runs");
        let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
        let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
        (o.status.code(), stdout, stderr, out)
    };
    let (code, cpu, _, _) = run("cpu");
    assert_eq!(code, Some(0));
    let (code, _, stderr, _) = run("auto");
    assert_eq!(code, Some(0), "{stderr}");
    let (code, stdout, stderr, out) = run("gpu");
    if device().is_none() {
        assert_eq!(code, Some(2), "{stderr}");
        assert!(
            stderr.contains("--backend gpu: wgpu found no adapter"),
            "{stderr}"
        );
        assert!(!out.exists(), "nothing written");
        return;
    }
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stderr.contains("cones on the GPU: "), "{stderr}");
    assert!(std::fs::read_to_string(&out).unwrap().contains("PTMEAS"));
    let first = |s: &str| s.lines().next().unwrap_or("").to_string();
    // f3_indexed: both tolerances measured in one setup on either backend.
    assert!(
        first(&stdout).contains("tolerances measured 2 of 2, 1 setup"),
        "{stdout}"
    );
    assert_eq!(first(&stdout), first(&cpu));
}

#[test]
fn gpu_scanner_cones_match_the_cpu() {
    let Some(gpu) = device() else {
        return;
    };
    let opts = inspc::access::ConeOptions {
        n: 32,
        ..Default::default()
    };
    let (mut total, mut agree) = (0, 0);
    for spec in ["examples/f4.insp", "examples/swiss_block.insp"] {
        let (scene, _, fp) = crate::access::loaded(spec);
        for head in [inspc::access::Head::Fixed, inspc::access::Head::Indexable] {
            let s = crate::scan::scanner(head);
            for f in fp.iter().step_by((fp.len() / 5).max(1)).take(5) {
                let on_gpu =
                    inspc::access::scan_cones(gpu, &scene, &f.position, &f.normal, &s, &opts);
                let on_cpu =
                    inspc::access::scan_cones(&Cpu, &scene, &f.position, &f.normal, &s, &opts);
                for (g, c) in [
                    (&on_gpu.rays, &on_cpu.rays),
                    (&on_gpu.visible, &on_cpu.visible),
                ] {
                    let all = c.empty_like().not();
                    for cell in all.cells() {
                        assert!(
                            !g.get(cell) || c.get(cell),
                            "{spec}: the GPU sees {cell:?} at {:?}, the CPU does not",
                            f.position
                        );
                        total += 1;
                        agree += (g.get(cell) == c.get(cell)) as usize;
                    }
                }
            }
        }
    }
    let share = agree as f64 / total as f64;
    println!("scanner cones, GPU against CPU: {agree} of {total} cells agree");
    assert!(share > 0.995, "{share}");
}
