//! No mesh file, however broken, makes reading, segmentation or sampling panic: random
//! OBJ soups (bad indices, NaN, huge and degenerate triangles), random binary STL, and
//! corrupted copies of a good mesh.

use inspc::geometry::{read_mesh, segment, FaceId, RawMesh, P3};
use inspc::model::{SampleMethod, Strategy as Sampling};
use inspc::sample::Sampler;
use inspc::source::MemoryWorld;
use proptest::prelude::*;
use std::path::Path;

/// Reads `bytes` as `name`, then segments and samples every face with every method.
fn run(name: &str, bytes: Vec<u8>) {
    let mut world = MemoryWorld::new();
    world.insert(name, bytes);
    if let Ok(raw) = read_mesh(&world, Path::new(name), 1.0) {
        segment_and_sample(&raw);
    }
}

fn segment_and_sample(raw: &RawMesh) {
    for g in [segment::segment(raw), segment::from_groups(raw)] {
        let sampler = Sampler::new(&g, 1.0);
        for f in 0..g.faces.len() {
            for method in [
                SampleMethod::FanLeu,
                SampleMethod::Uniform,
                SampleMethod::Hammersley,
            ] {
                let _ = sampler.sample(
                    FaceId(f),
                    &Sampling {
                        method,
                        points: Some(5),
                        inset: None,
                        spacing: None,
                    },
                );
            }
        }
    }
}

fn coord() -> impl Strategy<Value = String> {
    prop_oneof![
        (-3i32..4).prop_map(|v| v.to_string()),
        (-1000.0f64..1000.0).prop_map(|v| format!("{v}")),
        Just("nan".to_string()),
        Just("1e300".to_string()),
        Just("-0".to_string()),
    ]
}

fn obj_line() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => (coord(), coord(), coord()).prop_map(|(x, y, z)| format!("v {x} {y} {z}")),
        4 => prop::collection::vec(-3i32..12, 3..5).prop_map(|ix| format!("f {}", ix.iter().map(|i| i.to_string()).collect::<Vec<_>>().join(" "))),
        1 => (0u8..4).prop_map(|g| format!("g face_{g}")),
        1 => Just("vn 0 0 1".to_string()),
        1 => Just("f 1/1/1 2//2 3/3".to_string()),
    ]
}

/// A closed cube as OBJ, one group per side.
fn cube_obj() -> String {
    let mut s = String::new();
    for v in 0..8 {
        s += &format!("v {} {} {}\n", v & 1, (v >> 1) & 1, (v >> 2) & 1);
    }
    let quads = [
        [1, 3, 4, 2],
        [5, 6, 8, 7],
        [1, 2, 6, 5],
        [3, 7, 8, 4],
        [1, 5, 7, 3],
        [2, 4, 8, 6],
    ];
    for (k, q) in quads.iter().enumerate() {
        s += &format!(
            "g side_{k}\nf {} {} {}\nf {} {} {}\n",
            q[0], q[1], q[2], q[0], q[2], q[3]
        );
    }
    s
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn obj_soup(lines in prop::collection::vec(obj_line(), 0..40)) {
        run("m.obj", lines.join("\n").into_bytes());
    }

    #[test]
    fn binary_stl(count in 0u32..12, floats in prop::collection::vec(prop_oneof![-50.0f32..50.0, Just(f32::NAN), Just(0.0f32)], 0..200), cut in 0usize..600) {
        let mut b = vec![0u8; 80];
        b.extend(count.to_le_bytes());
        let mut it = floats.into_iter().cycle();
        for _ in 0..count {
            for _ in 0..12 {
                b.extend(it.next().unwrap_or(0.0).to_le_bytes());
            }
            b.extend([0u8, 0]);
        }
        b.truncate(b.len().min(84 + cut));
        run("m.stl", b);
    }

    #[test]
    fn corrupted_cube(edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8)) {
        let mut b = cube_obj().into_bytes();
        for (at, byte) in edits {
            let i = at.index(b.len());
            b[i] = byte;
        }
        run("m.obj", b);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// The cube with its corners moved anywhere, even onto each other: it still reads
    /// (the topology is closed), so the degenerate geometry reaches sampling.
    #[test]
    fn cube_with_moved_corners(moves in prop::collection::vec((0usize..8, -2i32..3, -2i32..3, -2i32..3), 1..6)) {
        let mut v: Vec<[i32; 3]> = (0..8).map(|k| [k & 1, (k >> 1) & 1, (k >> 2) & 1]).collect();
        for (k, x, y, z) in moves {
            v[k] = [x, y, z];
        }
        let text = cube_obj();
        let faces: String = text.lines().filter(|l| !l.starts_with("v ")).map(|l| format!("{l}\n")).collect();
        let verts: String = v.iter().map(|[x, y, z]| format!("v {x} {y} {z}\n")).collect();
        run("m.obj", (verts + &faces).into_bytes());
    }

    /// Segmentation and sampling on any triangle soup, past the reader's checks.
    #[test]
    fn raw_soup(points in prop::collection::vec((-5i32..6, -5i32..6, -5i32..6), 3..12), tris in prop::collection::vec((0u32..12, 0u32..12, 0u32..12, 0u32..3), 1..24)) {
        let vertices: Vec<P3> = points.iter().map(|&(x, y, z)| P3::new(x as f64, y as f64, z as f64)).collect();
        let n = vertices.len() as u32;
        let triangles: Vec<[u32; 3]> = tris.iter().map(|&(a, b, c, _)| [a % n, b % n, c % n]).collect();
        let tri_group: Vec<u32> = tris.iter().map(|t| t.3).collect();
        let raw = RawMesh { vertices, triangles, tri_group, groups: vec!["a".into(), "b".into(), "c".into()], open_edges: 0, nonmanifold_edges: 0, exact: vec![], cad: None };
        segment_and_sample(&raw);
    }
}

#[test]
fn the_cube_itself_samples() {
    run("m.obj", cube_obj().into_bytes());
}

/// The NIST CTC 01 STEP file, read once for the corruption cases.
fn ctc_01_step() -> &'static [u8] {
    static BYTES: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    BYTES.get_or_init(|| {
        crate::common::require_shared_parts();
        std::fs::read("../shared/parts/nist_ctc_01_asme1_ap242-e1.stp").unwrap()
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// A real STEP file cut short anywhere, or with bytes overwritten (digits, signs,
    /// `#`, `(`, `;`, letters), is read or refused, never a panic or a hang.
    #[test]
    fn corrupted_step(cut in any::<prop::sample::Index>(), edits in prop::collection::vec((any::<prop::sample::Index>(), prop::sample::select(b"0123456789-.#();,E$*'AZ ".to_vec())), 0..6), truncate in any::<bool>()) {
        let mut bytes = ctc_01_step().to_vec();
        for (at, b) in edits {
            let i = at.index(bytes.len());
            bytes[i] = b;
        }
        if truncate {
            bytes.truncate(cut.index(bytes.len()));
        }
        run("part.stp", bytes);
    }
}
