//! Accessibility speed: cones per fpoint for the bare half-line, the grown half-line
//! (the plan's first stylus, ρ = stem radius, reaching to infinity) and the ram (its
//! cylinder from the head up), by the CPU backend, each beside the plain baseline of one
//! parry ray cast per pixel centre (parry's own BVH), in the same run, at N = 32 and 64,
//! on swiss_block and the NIST CTC 01 mesh. Each iteration computes the cones of 16
//! fpoints spread over the part; divide by 16 for one cone. `grown_exact_boundary` adds
//! the exact refinement of the grown cone's boundary.
//!
//! `halfline_plain`, `grown_plain` and `ram_plain` draw the same cones triangle by
//! triangle, without the scene's bounding-volume hierarchy (the maps are equal bit for
//! bit): the hierarchy's gain.
//!
//! `batch_cpu` and `batch_gpu` compare the two backends on the same batch of queries.
//!
//! `scanner` computes a laser line scanner's cones (LC15Dx optics on a fixed head: laser,
//! camera, incidence, housing, head and ram) at 16 surface points; `scanner_exact_rays`
//! is its plain baseline for the rays alone: `access::scan::sees` (two parry ray casts)
//! at every pixel centre within the incidence limit; `scanner_rays` is the cone's share
//! of that same work (a scanner without solid parts).
//!
//! Run with `cargo bench --bench access`.

use inspc::access::{Backend, Cell, Component, Cpu, CubeMap, End, ProbeShape, Scene};
use inspc::geometry::P3;
use inspc::source::FsWorld;
use std::path::PathBuf;

fn main() {
    divan::main();
}

const CASES: [(&str, u32); 4] = [
    ("examples/swiss_block.insp", 32),
    ("examples/swiss_block.insp", 64),
    ("tests/real/nist_ctc_01.insp", 32),
    ("tests/real/nist_ctc_01.insp", 64),
];

const POINTS: usize = 16;

/// The scene, 16 tip centres spread over the fpoints, and the plan's first probe.
fn scene(spec: &str) -> (Scene, Vec<P3>, ProbeShape) {
    let (checked, parts, graphs) = inspc::measurement_graphs(&FsWorld, &[PathBuf::from(spec)]);
    let g = &parts[graphs[0].part].as_ref().unwrap().geometry;
    let model = &checked.model;
    let probe = ProbeShape::of_cmm(model, &model.cmms[model.plans[0].cmm.0]).remove(0);
    let fp = &graphs[0].graph.fpoints;
    let pts = (0..POINTS)
        .map(|k| fp[k * fp.len() / POINTS].tip_centre(probe.tip_radius))
        .collect();
    (Scene::of_part(g), pts, probe)
}

fn component(kind: &str, probe: &ProbeShape) -> Component {
    match kind {
        "halfline" => Component::half_line(),
        "grown" => Component {
            name: "grown".into(),
            a: 0.0,
            b: f64::INFINITY,
            radius: probe.first[0].radius,
            end: End::Round,
        },
        _ => probe.straight().last().unwrap().clone(),
    }
}

fn run(bencher: divan::Bencher, (spec, n): (&str, u32), kind: &str) {
    run_with(bencher, (spec, n), kind, |s, p, c, n| {
        Cpu.blocked(s, p, c, n, &[])
    });
}

/// The same cones drawn triangle by triangle, without the scene's hierarchy.
fn run_plain(bencher: divan::Bencher, (spec, n): (&str, u32), kind: &str) {
    run_with(bencher, (spec, n), kind, |s, p, c, n| {
        inspc::access::blocked_plain(s, p, c, n, &[])
    });
}

fn run_with(
    bencher: divan::Bencher,
    (spec, n): (&str, u32),
    kind: &str,
    blocked: impl Fn(&Scene, &P3, &Component, u32) -> CubeMap + Sync,
) {
    let (scene, pts, probe) = scene(spec);
    let comp = component(kind, &probe);
    bencher.bench(|| {
        pts.iter()
            .map(|p| blocked(&scene, divan::black_box(p), &comp, n).count())
            .sum::<usize>()
    });
}

#[divan::bench(args = CASES)]
fn halfline(bencher: divan::Bencher, case: (&str, u32)) {
    run(bencher, case, "halfline");
}

#[divan::bench(args = CASES)]
fn grown(bencher: divan::Bencher, case: (&str, u32)) {
    run(bencher, case, "grown");
}

#[divan::bench(args = CASES)]
fn ram(bencher: divan::Bencher, case: (&str, u32)) {
    run(bencher, case, "ram");
}

#[divan::bench(args = CASES)]
fn halfline_plain(bencher: divan::Bencher, case: (&str, u32)) {
    run_plain(bencher, case, "halfline");
}

#[divan::bench(args = CASES)]
fn grown_plain(bencher: divan::Bencher, case: (&str, u32)) {
    run_plain(bencher, case, "grown");
}

#[divan::bench(args = CASES)]
fn ram_plain(bencher: divan::Bencher, case: (&str, u32)) {
    run_plain(bencher, case, "ram");
}

/// The grown half-line with its boundary refined by exact parry capsule tests (opt-in and
/// slow: a few samples only).
#[divan::bench(args = CASES, sample_count = 3, sample_size = 1)]
fn grown_exact_boundary(bencher: divan::Bencher, (spec, n): (&str, u32)) {
    let (scene, pts, probe) = scene(spec);
    let comp = component("grown", &probe);
    bencher.bench(|| {
        pts.iter()
            .map(|p| {
                let mut b = Cpu.blocked(&scene, divan::black_box(p), &comp, n, &[]);
                inspc::access::refine(&scene, p, &comp, &mut b);
                b.count()
            })
            .sum::<usize>()
    });
}

/// The baseline: one parry ray cast per pixel centre.
#[divan::bench(args = CASES)]
fn parry_ray_per_pixel(bencher: divan::Bencher, (spec, n): (&str, u32)) {
    let (scene, pts, _) = scene(spec);
    let dirs: Vec<_> = {
        let c = CubeMap::full(n, &[]);
        c.cells()
            .filter(|c| matches!(c, Cell::Pixel(_)))
            .map(|cell| (cell, c.direction(cell)))
            .collect()
    };
    bencher.bench(|| {
        pts.iter()
            .map(|p| {
                let mut out = CubeMap::empty(n, &[]);
                for (cell, d) in &dirs {
                    out.set(*cell, scene.cast_ray(p, d, f64::MAX).is_some());
                }
                out.count()
            })
            .sum::<usize>()
    });
}

/// The CPU backend and the GPU backend on the same queries, in the same run: the three
/// components (half-line, grown half-line, ram) at the 16 fpoints, 48 cones per
/// iteration, as the planner hands them over — one `blocked_many` call. The CPU answers
/// them one by one on all cores (rayon); the GPU (`access::Gpu`: lavapipe on a machine
/// without one) rasterizes the polygons of 32 at a time. Divide by 16 for one fpoint's
/// three cones. Without a Vulkan adapter `batch_gpu` says so and measures nothing.
fn batch(bencher: divan::Bencher, (spec, n): (&str, u32), backend: &dyn Backend) {
    use rayon::prelude::*;
    let (scene, pts, probe) = scene(spec);
    let comps: Vec<Component> = ["halfline", "grown", "ram"]
        .iter()
        .map(|k| component(k, &probe))
        .collect();
    let queries: Vec<inspc::access::Query> = pts
        .iter()
        .flat_map(|p| {
            comps
                .iter()
                .map(|comp| inspc::access::Query { from: *p, comp })
        })
        .collect();
    bencher.bench(|| {
        let maps: Vec<CubeMap> = if backend.batches() {
            backend.blocked_many(&scene, divan::black_box(&queries), n, &[])
        } else {
            queries
                .par_iter()
                .map(|q| backend.blocked(&scene, &q.from, q.comp, n, &[]))
                .collect()
        };
        maps.iter().map(CubeMap::count).sum::<usize>()
    });
}

#[divan::bench(args = CASES)]
fn batch_cpu(bencher: divan::Bencher, case: (&str, u32)) {
    batch(bencher, case, &Cpu);
}

#[divan::bench(args = CASES)]
fn batch_gpu(bencher: divan::Bencher, case: (&str, u32)) {
    match inspc::access::gpu() {
        Ok(g) => batch(bencher, case, g),
        Err(why) => {
            eprintln!("batch_gpu: no adapter ({why})");
            bencher.bench(|| 0);
        }
    }
}

/// 16 surface points (position, normal) spread over the fpoints, and an LC15Dx-like
/// scanner on a fixed head.
fn scan_case(
    spec: &str,
) -> (
    Scene,
    Vec<(P3, inspc::geometry::V3)>,
    inspc::access::ScannerShape,
) {
    use inspc::access::scan::Optics;
    let (_, parts, graphs) = inspc::measurement_graphs(&FsWorld, &[PathBuf::from(spec)]);
    let g = &parts[graphs[0].part].as_ref().unwrap().geometry;
    let fp = &graphs[0].graph.fpoints;
    let pts = (0..POINTS)
        .map(|k| {
            let f = &fp[k * fp.len() / POINTS];
            (f.position, f.normal)
        })
        .collect();
    let flat = |name: &str, a: f64, b: f64, radius: f64| Component {
        name: name.into(),
        a,
        b,
        radius,
        end: End::Flat,
    };
    let shape = inspc::access::ScannerShape {
        optics: Optics {
            standoff: 60.0,
            depth: 15.0,
            stripe: 18.0,
            triangulation: 30f64.to_radians(),
            max_incidence: 75f64.to_radians(),
            spacing: [0.022, 0.022],
        },
        probe: ProbeShape {
            name: "l1".into(),
            tip_radius: 0.0,
            first: vec![flat("housing", 60.0, 180.0, 30.0)],
            second: vec![
                flat("head", 180.0, 253.0, 31.0),
                flat("ram", 253.0, f64::INFINITY, 35.0),
            ],
            head: inspc::access::Head::Fixed,
        },
    };
    (Scene::of_part(g), pts, shape)
}

/// The scanner's cones at the case's points: the visible cones, or the rays alone (a
/// scanner without solid parts).
fn scan_run(bencher: divan::Bencher, (spec, n): (&str, u32), rays_only: bool) {
    let (scene, pts, mut shape) = scan_case(spec);
    if rays_only {
        shape.probe.first.clear();
        shape.probe.second.clear();
    }
    let opts = inspc::access::ConeOptions {
        n,
        ..Default::default()
    };
    bencher.bench(|| {
        pts.iter()
            .map(|(p, nrm)| {
                inspc::access::scan_cones(&Cpu, &scene, divan::black_box(p), nrm, &shape, &opts)
                    .visible
                    .count()
            })
            .sum::<usize>()
    });
}

#[divan::bench(args = CASES)]
fn scanner(bencher: divan::Bencher, case: (&str, u32)) {
    scan_run(bencher, case, false);
}

#[divan::bench(args = CASES, sample_count = 3, sample_size = 1)]
fn scanner_exact_rays(bencher: divan::Bencher, (spec, n): (&str, u32)) {
    let (scene, pts, shape) = scan_case(spec);
    let all = CubeMap::full(n, &[]);
    let dirs: Vec<_> = all.cells().map(|c| all.direction(c)).collect();
    bencher.bench(|| {
        pts.iter()
            .map(|(p, nrm)| {
                dirs.iter()
                    .filter(|d| {
                        inspc::access::scan::sees(
                            &scene,
                            divan::black_box(p),
                            nrm,
                            d,
                            &shape.optics,
                        )
                    })
                    .count()
            })
            .sum::<usize>()
    });
}

#[divan::bench(args = CASES)]
fn scanner_rays(bencher: divan::Bencher, case: (&str, u32)) {
    scan_run(bencher, case, true);
}
