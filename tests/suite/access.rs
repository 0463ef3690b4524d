//! Cones against brute force with parry, at fpoints of every example and both NIST parts:
//! one exact ray per pixel centre for the half-line, one exact capsule or cylinder
//! intersection test per pixel centre for the grown abstractions (stylus, ram). The
//! grown cones must never call a blocked direction free; the half-line cone must agree
//! with the rays on ≥ 99 % of pixels and never call a blocked one free either.

use crate::common;

use inspc::access::{
    component_hits, cones, gac_halfline, Backend, Cell, Component, ConeOptions, Cpu, CubeMap, End,
    ProbeShape, Scene,
};
use inspc::geometry::{P3, V3};
use inspc::source::FsWorld;
use std::path::PathBuf;

/// Every example (the GPU tests use them too).
pub(crate) const EXAMPLES: [&str; 7] = [
    "examples/f2.insp",
    "examples/f3_fixed.insp",
    "examples/f3_indexed.insp",
    "examples/f4.insp",
    "examples/swiss_block.insp",
    "examples/swiss_sphere_fixed.insp",
    "examples/swiss_sphere_indexed.insp",
];
const NIST: [&str; 2] = ["tests/real/nist_ctc_01.insp", "tests/real/nist_ftc_08.insp"];

struct Case {
    scene: Scene,
    /// (tip centre, fpoint index) at pseudo-random fpoints.
    points: Vec<P3>,
    probes: Vec<ProbeShape>,
}

/// A spec's part as obstacle, its first plan's probes (none without a plan) and its
/// fpoints.
pub(crate) fn loaded(spec: &str) -> (Scene, Vec<ProbeShape>, Vec<inspc::sample::Fpoint>) {
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
    (Scene::of_part(g), probes, gr.graph.fpoints.clone())
}

/// The scene, `count` pseudo-random tip centres (for the first probe's tip, 1 mm
/// without a plan) and the plan's probes.
fn case(spec: &str, count: usize, seed: u64) -> Case {
    let (scene, probes, fp) = loaded(spec);
    let r = probes.first().map_or(1.0, |p| p.tip_radius);
    let mut state = seed;
    let points = (0..count)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            fp[(state >> 33) as usize % fp.len()].tip_centre(r)
        })
        .collect();
    Case {
        scene,
        points,
        probes,
    }
}

fn every_direction(n: u32) -> Vec<(Cell, V3)> {
    let c = CubeMap::full(n, &inspc::access::axes());
    c.cells().map(|cell| (cell, c.direction(cell))).collect()
}

/// Compares one component's cone with the exact test at every pixel centre and preferred
/// direction: (cells, agreeing cells); panics on a blocked direction reported free.
fn compare(scene: &Scene, p: &P3, comp: &Component, n: u32, what: &str) -> (usize, usize) {
    compare_map(scene, p, comp, n, what, false)
}

fn compare_map(
    scene: &Scene,
    p: &P3,
    comp: &Component,
    n: u32,
    what: &str,
    refined: bool,
) -> (usize, usize) {
    let mut blocked = Cpu.blocked(scene, p, comp, n, &inspc::access::axes());
    if refined {
        inspc::access::refine(scene, p, comp, &mut blocked);
    }
    let (mut total, mut agree) = (0, 0);
    for (cell, d) in every_direction(n) {
        let exact = component_hits(scene, p, &d, comp);
        assert!(
            !exact || blocked.get(cell),
            "{what}: {} blocks {d:?} at {p:?}, reported free",
            comp.name
        );
        total += 1;
        agree += usize::from(exact == blocked.get(cell));
    }
    (total, agree)
}

fn verify_halfline(spec: &str, count: usize, n: u32) {
    let c = case(spec, count, 17);
    let (mut total, mut agree) = (0, 0);
    for p in &c.points {
        let (t, a) = compare(&c.scene, p, &Component::half_line(), n, spec);
        total += t;
        agree += a;
    }
    let ratio = agree as f64 / total as f64;
    eprintln!(
        "{spec}: half-line {agree}/{total} cells agree ({:.3} %)",
        100.0 * ratio
    );
    assert!(ratio >= 0.99, "{spec}: only {:.3} % agree", 100.0 * ratio);
}

/// Every component of the plan's first probe (as mounted: the whole chain for a fixed
/// head, the first component for an indexable one), each on its own, and a bare
/// half-line grown by 0.8 mm.
fn verify_grown(spec: &str, count: usize, n: u32) {
    let c = case(spec, count, 29);
    let probe = &c.probes[0];
    let mut comps = probe.leading();
    comps.push(Component {
        name: "grown half-line".into(),
        a: 0.0,
        b: f64::INFINITY,
        radius: 0.8,
        end: End::Round,
    });
    let (mut all, mut all_agree) = (0, 0);
    for comp in &comps {
        let (mut total, mut agree, mut refined) = (0, 0, 0);
        for p in &c.points {
            let (t, a) = compare(&c.scene, p, comp, n, spec);
            total += t;
            agree += a;
            refined += compare_map(&c.scene, p, comp, n, spec, true).1;
        }
        eprintln!(
            "{spec}: {} {agree}/{total} cells agree ({:.2} %), refined {:.2} %",
            comp.name,
            100.0 * agree as f64 / total as f64,
            100.0 * refined as f64 / total as f64
        );
        all += total;
        all_agree += refined;
    }
    let ratio = all_agree as f64 / all as f64;
    assert!(
        ratio >= 0.99,
        "{spec}: refined cones agree on {:.2} %",
        100.0 * ratio
    );
}

#[test]
fn halfline_cones_match_exact_rays_on_the_examples() {
    for spec in EXAMPLES {
        verify_halfline(spec, 6, 32);
    }
}

#[test]
fn halfline_cones_match_exact_rays_on_the_nist_parts() {
    common::require_shared_parts();
    for spec in NIST {
        verify_halfline(spec, 6, 32);
    }
    verify_halfline(NIST[0], 2, 64);
}

#[test]
fn grown_cones_are_pessimistic_on_the_examples() {
    for spec in EXAMPLES {
        verify_grown(spec, 3, 32);
    }
}

#[test]
fn grown_cones_are_pessimistic_on_the_nist_parts() {
    common::require_shared_parts();
    for spec in NIST {
        verify_grown(spec, 3, 32);
    }
}

#[test]
fn halfline_gac_is_the_complement_of_its_blocked_map() {
    let c = case("examples/f4.insp", 1, 3);
    let gac = gac_halfline(&c.scene, &c.points[0], 32, &[]);
    let blocked = Cpu.blocked(&c.scene, &c.points[0], &Component::half_line(), 32, &[]);
    assert_eq!(gac, blocked.not());
    assert!(!gac.is_empty() && gac.count() < 6 * 32 * 32);
}

/// Drawing walks the scene's bounding-volume hierarchy and passes over nodes whose
/// shadows are already marked; the maps must be those of drawing every triangle in
/// order, bit for bit: every component of every probe (second components too), bare,
/// truncated and grown half-lines, with a table and with a floor, on the examples and
/// two real parts.
#[test]
fn the_hierarchy_draws_the_same_maps_as_every_triangle() {
    use inspc::access::blocked_plain;
    let specs = EXAMPLES.iter().chain(NIST.iter());
    for spec in specs {
        let c = case(spec, if spec.contains("nist") { 3 } else { 4 }, 41);
        let lo = c
            .scene
            .tris
            .iter()
            .flat_map(|t| t.v)
            .reduce(|a, b| a.inf(&b));
        let mut comps = vec![
            Component::half_line(),
            Component::half_line().shifted(5.0),
            Component {
                name: "grown half-line".into(),
                a: 0.0,
                b: f64::INFINITY,
                radius: 0.8,
                end: End::Round,
            },
        ];
        for p in &c.probes {
            comps.extend(p.first.iter().cloned());
            comps.extend(p.second.iter().cloned());
        }
        let table = c.scene.with_table(&lo.unwrap(), &V3::z());
        for (k, p) in c.points.iter().enumerate() {
            let floor = c.scene.above(p, &V3::new(0.0, 0.6, 0.8), -3.0);
            let scenes = [&c.scene, &table, &floor];
            for comp in &comps {
                let scene = scenes[k % 3];
                for n in [32, 64] {
                    let axes = inspc::access::axes();
                    let fast = Cpu.blocked(scene, p, comp, n, &axes);
                    let plain = blocked_plain(scene, p, comp, n, &axes);
                    assert!(
                        fast == plain,
                        "{spec}: {} at {p:?}, n = {n}: the hierarchy's map differs",
                        comp.name
                    );
                }
            }
        }
    }
}

/// Drawing that waits for some cells (D2's samples) is the whole map on those cells
/// (pixels and preferred directions), whether it stopped early or not, and decides no
/// other: never more blocked than the whole map, and blocked only there.
#[test]
fn drawing_that_waits_for_cells_is_the_whole_map_there() {
    let c = case("tests/real/nist_ctc_01.insp", 6, 53);
    let axes = inspc::access::axes();
    let n = 32;
    let mut blocked = 0;
    for (k, p) in c.points.iter().enumerate() {
        for comp in c.probes.iter().flat_map(|p| p.second.iter()) {
            let whole = Cpu.blocked(&c.scene, p, comp, n, &axes);
            // A few cells around one direction, and a preferred direction.
            let d = V3::new(1.0, 0.3 * k as f64 - 0.7, 0.5).normalize();
            let mut stop = whole.cap(&d, 0.995);
            stop.set(Cell::Preferred(k % axes.len()), true);
            let got = Cpu.blocked_until(&c.scene, p, comp, n, &axes, &stop);
            assert_eq!(
                got.and(&stop),
                whole.and(&stop),
                "{}: not the whole map there",
                comp.name
            );
            assert!(
                stop.covers(&got),
                "{}: cells decided past those waited for",
                comp.name
            );
            blocked += usize::from(got.covers(&stop));
        }
    }
    assert!(blocked > 0, "never were all the cells waited for blocked");
}

/// A map drawn for some cells alone (the later components of a probe, the retract
/// point) is the whole map on those cells and on the pixels holding their preferred
/// directions, never more blocked anywhere, and on a real part it does pass shadows
/// over.
#[test]
fn drawing_for_some_cells_is_the_whole_map_there() {
    for spec in [
        "tests/real/nist_ctc_01.insp",
        "examples/swiss_sphere_fixed.insp",
    ] {
        let c = case(spec, 6, 59);
        let axes = inspc::access::axes();
        let mut fewer = 0;
        for (k, p) in c.points.iter().enumerate() {
            let comps = c
                .probes
                .iter()
                .flat_map(|p| p.first.iter().chain(&p.second));
            for (j, comp) in comps.enumerate() {
                for n in [32, 64] {
                    let whole = Cpu.blocked(&c.scene, p, comp, n, &axes);
                    // A cap around some direction, a preferred direction, and the
                    // cells the stylus leaves free.
                    let d = V3::new(0.4 * k as f64 - 1.0, 0.5, 0.3 * j as f64 - 0.6).normalize();
                    let mut within = whole.cap(&d, 0.9);
                    within.set(Cell::Preferred((k + j) % axes.len()), true);
                    if j > 0 {
                        let stylus = Cpu.blocked(&c.scene, p, &c.probes[0].first[0], n, &axes);
                        within.or_assign(&stylus.not());
                    }
                    let got = Cpu.blocked_within(&c.scene, p, comp, n, &axes, &within);
                    assert!(
                        whole.covers(&got),
                        "{spec}: {}: more than the whole map",
                        comp.name
                    );
                    for cell in within.cells() {
                        assert_eq!(
                            got.get(cell),
                            whole.get(cell),
                            "{spec}: {} at {p:?}, n = {n}: {cell:?} differs",
                            comp.name
                        );
                        if let Cell::Preferred(q) = cell {
                            for px in whole.pixels_holding(&whole.preferred(q)) {
                                let px = Cell::Pixel(px);
                                assert_eq!(got.get(px), whole.get(px), "{spec}: {}", comp.name);
                            }
                        }
                    }
                    fewer += usize::from(got != whole);
                }
            }
        }
        assert!(fewer > 0, "{spec}: never passed a shadow over");
    }
}

#[test]
fn cones_are_the_same_for_any_thread_count() {
    let (checked, parts, graphs) =
        inspc::measurement_graphs(&FsWorld, &[PathBuf::from("examples/f3_indexed.insp")]);
    let gr = &graphs[0];
    let scene = Scene::of_part(&parts[gr.part].as_ref().unwrap().geometry);
    let model = &checked.model;
    let probes = ProbeShape::of_cmm(model, &model.cmms[model.plans[0].cmm.0]);
    let opts = ConeOptions {
        n: 32,
        d2_samples: 4,
        ..ConeOptions::default()
    };
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| cones(&Cpu, &scene, &gr.graph.fpoints, &probes[0], &opts))
    };
    let one = run(1);
    assert_eq!(one, run(3));
    assert!(
        one.iter().all(|c| c.d2.is_some()),
        "an indexable head gives D2 cones"
    );
    assert!(one.iter().any(|c| !c.approach.is_empty()));
}

/// D2 asked about some setups only (the planner's realisable ones) is the same there as
/// the whole D2 and holds nothing elsewhere, on the indexable example and a real part.
#[test]
fn d2_for_wanted_setups_is_the_whole_d2_there() {
    use inspc::access::point_cones;
    for spec in ["examples/f3_indexed.insp", "tests/real/nist_ctc_01.insp"] {
        let (scene, probes, fp) = loaded(spec);
        let probe = probes
            .iter()
            .find(|p| p.head.indexable())
            .expect("an indexable head");
        let whole = ConeOptions {
            n: 32,
            d2_samples: 6,
            ..ConeOptions::default()
        };
        // A few setup directions, as a part's stable poses are: the axes and a tilt.
        let mut wanted = CubeMap::empty(32, &whole.preferred);
        for d in [
            V3::z(),
            -V3::z(),
            V3::x(),
            V3::new(0.0, 0.5, 0.8).normalize(),
        ] {
            let cell = wanted.cell_of(&d);
            wanted.set(cell, true);
        }
        let some = ConeOptions {
            d2_wanted: Some(std::sync::Arc::new(inspc::access::D2Wanted::new(
                wanted.clone(),
            ))),
            ..whole.clone()
        };
        // D2 is drawn at half the resolution: the wanted cells' coarse pixels, refined.
        let coarse_wanted = wanted.coarsened(16).refined(32);
        for f in fp.iter().step_by(fp.len().div_ceil(40)) {
            let a = point_cones(&Cpu, &scene, f, probe, &whole).d2.unwrap();
            let b = point_cones(&Cpu, &scene, f, probe, &some).d2.unwrap();
            assert_eq!(a.and(&wanted), b.and(&wanted), "{spec} at {:?}", f.position);
            assert!(
                coarse_wanted.covers(&b),
                "{spec}: D2 for some setups holds none of the others"
            );
        }
    }
}

/// D1′ for the vertical: every direction it keeps lets a cylinder of the head's and ram's
/// largest radius stand on the articulation point and clear the part (parry), and it
/// keeps most of the directions that do.
#[test]
fn d1_prime_is_pessimistic() {
    use inspc::access::{d1, d1_prime};
    let c = case("examples/f3_indexed.insp", 4, 5);
    let probe = &c.probes[0];
    assert_eq!(probe.head, inspc::access::Head::Indexable);
    let radius = probe.second.iter().map(|s| s.radius).fold(0.0, f64::max);
    let up = V3::z();
    let stand = Component {
        name: "second".into(),
        a: 0.0,
        b: f64::INFINITY,
        radius,
        end: End::Flat,
    };
    let (mut kept, mut free) = (0, 0);
    for p in &c.points {
        let first = d1(&Cpu, &c.scene, p, probe, 32, &[]);
        let prime = d1_prime(&c.scene, p, probe, &first, &up);
        assert_eq!(prime.and(&first), prime, "D1′ ⊆ D1");
        for cell in first.cells() {
            let x = p + first.direction(cell) * probe.reach();
            let clear = !component_hits(&c.scene, &x, &up, &stand);
            assert!(
                clear || !prime.get(cell),
                "D1′ keeps {cell:?} at {p:?}, but the head hits"
            );
            free += usize::from(clear);
            kept += usize::from(prime.get(cell));
        }
    }
    eprintln!("D1′ keeps {kept} of {free} directions that clear");
    assert!(kept > 0 && kept * 10 >= free * 7, "{kept} of {free}");
}

/// Approach cones hold at the retract point too; a feature's cone is the intersection of
/// its points'; D2 is empty exactly when D1 is.
#[test]
fn approach_feature_and_d2_cones() {
    use inspc::access::{feature_cone, gac, point_cones};
    let (checked, parts, graphs) =
        inspc::measurement_graphs(&FsWorld, &[PathBuf::from("examples/f3_fixed.insp")]);
    let gr = &graphs[0];
    let scene = Scene::of_part(&parts[gr.part].as_ref().unwrap().geometry);
    let model = &checked.model;
    let probe = ProbeShape::of_cmm(model, &model.cmms[model.plans[0].cmm.0]).remove(0);
    assert_eq!(probe.head, inspc::access::Head::Fixed);
    let opts = ConeOptions {
        n: 32,
        ..ConeOptions::default()
    };
    let face = gr.graph.fpoints[0].face;
    let pts: Vec<_> = gr.graph.fpoints.iter().filter(|f| f.face == face).collect();
    let mut each = Vec::new();
    for f in &pts {
        let cones = point_cones(&Cpu, &scene, f, &probe, &opts);
        assert!(cones.tip_fits && cones.d2.is_none());
        let at_contact = gac(
            &Cpu,
            &scene,
            &f.tip_centre(probe.tip_radius),
            &probe.straight(),
            32,
            &opts.preferred,
        );
        assert_eq!(cones.approach.and(&at_contact), cones.approach);
        each.push(cones.approach);
    }
    let feature = feature_cone(&each).unwrap();
    for c in &each {
        assert_eq!(feature.and(c), feature);
    }
    assert!(feature_cone(std::iter::empty::<&CubeMap>()).is_none());

    let (checked, parts, graphs) =
        inspc::measurement_graphs(&FsWorld, &[PathBuf::from("examples/f3_indexed.insp")]);
    let gr = &graphs[0];
    let scene = Scene::of_part(&parts[gr.part].as_ref().unwrap().geometry);
    let model = &checked.model;
    let probe = ProbeShape::of_cmm(model, &model.cmms[model.plans[0].cmm.0]).remove(0);
    for f in gr.graph.fpoints.iter().step_by(5) {
        let cones = point_cones(&Cpu, &scene, f, &probe, &opts);
        let d2 = cones.d2.unwrap();
        assert_eq!(cones.approach.is_empty(), d2.is_empty());
        // With an indexable head the part can stand upright: +z is a setup direction.
        if !d2.is_empty() {
            assert!(d2.contains(&V3::z()), "{:?}", f.position);
        }
    }
}

/// A table under the part blocks the directions that pass beneath it.
#[test]
fn the_table_blocks_directions_under_the_part() {
    let (_, parts, graphs) =
        inspc::measurement_graphs(&FsWorld, &[PathBuf::from("examples/f2.insp")]);
    let gr = &graphs[0];
    let g = &parts[gr.part].as_ref().unwrap().geometry;
    let scene = Scene::of_part(g);
    let table = scene.with_table(&g.bounds().0, &V3::z());
    // Beside the +x side, half-way up: looking outwards and steeply down misses the part
    // but hits the table.
    let (lo, hi) = g.bounds();
    let c = P3::new(hi.x + 1.0, (lo.y + hi.y) / 2.0, (lo.z + hi.z) / 2.0);
    let down = V3::new(0.3, 0.0, -1.0).normalize();
    let without = gac_halfline(&scene, &c, 32, &[]);
    let with = gac_halfline(&table, &c, 32, &[]);
    assert!(without.contains(&down));
    assert!(!with.contains(&down));
    assert_eq!(with.and(&without), with);
    assert!(with.contains(&V3::new(1.0, 0.0, 0.2)));
}
