//! Property tests over random constructive parts (a box with blind and through holes from
//! the top and from the front): the booleans keep every named face that survives, with
//! its area; every triangle lies on its face's exact surface; every fpoint lies on its
//! face with an outward normal; and segmenting the part's bare mesh recovers its planar
//! and cylindrical faces.

use inspc::geometry::{segment, PartGeometry, RawMesh, Surface, V3};
use inspc::source::MemoryWorld;
use proptest::prelude::*;
use std::f64::consts::PI;
use std::fmt::Write;

#[derive(Debug, Clone)]
struct Hole {
    x: f64,
    y: f64,
    d: f64,
    depth: Option<f64>,
}

#[derive(Debug, Clone)]
struct Block {
    size: [f64; 3],
    top: Vec<Hole>,
    front: Vec<Hole>,
}

/// Top holes sit in the back half, front holes stop short of it, so no two meet.
fn block() -> impl Strategy<Value = Block> {
    (3usize..6, 60.0f64..100.0, 20.0f64..40.0).prop_flat_map(|(cells, w, h)| {
        let l = cells as f64 * 30.0;
        let hole = move |depth_max: f64| (4.0f64..12.0, prop::option::of(3.0f64..depth_max));
        (
            prop::collection::vec(prop::option::of(hole(h - 4.0)), cells),
            prop::collection::vec(
                prop::option::of((4.0f64..8.0, 3.0f64..(w / 2.0 - 10.0))),
                cells,
            ),
        )
            .prop_map(move |(top, front)| {
                let top = top
                    .into_iter()
                    .enumerate()
                    .filter_map(|(i, o)| {
                        o.map(|(d, depth)| Hole {
                            x: 15.0 + 30.0 * i as f64,
                            y: w * 0.75,
                            d,
                            depth,
                        })
                    })
                    .collect();
                let front = front
                    .into_iter()
                    .enumerate()
                    .filter_map(|(i, o)| {
                        o.map(|(d, depth)| Hole {
                            x: 15.0 + 30.0 * i as f64,
                            y: h / 2.0,
                            d,
                            depth: Some(depth),
                        })
                    })
                    .collect();
                Block {
                    size: [l, w, h],
                    top,
                    front,
                }
            })
    })
}

fn spec(b: &Block) -> String {
    let [l, w, h] = b.size;
    let mut s = format!("use std::heads::PH6\nuse std::probes::TP20_D2_L20\npart p {{\n units mm\n stock box({l}, {w}, {h})\n");
    let mut features = vec!["stock.top".to_string()];
    for (k, t) in b.top.iter().enumerate() {
        let depth = t.depth.map_or("through".into(), |d| d.to_string());
        let _ = writeln!(
            s,
            " cut hole t{k} {{ at ({}, {}, {h}), axis -z, diameter {}, depth {depth} }}",
            t.x, t.y, t.d
        );
        features.push(format!("t{k}.wall"));
    }
    for (k, f) in b.front.iter().enumerate() {
        let _ = writeln!(
            s,
            " cut hole f{k} {{ at ({}, 0, {}), axis +y, diameter {}, depth {} }}",
            f.x,
            f.y,
            f.d,
            f.depth.unwrap()
        );
        features.push(format!("f{k}.wall"));
    }
    let _ = writeln!(
        s,
        " feature all = {}\n datum A = stock.bottom\n}}",
        features.join(" + ")
    );
    s + "cmm lab { table { z 0 mm }, ram { radius 35 mm, length 600 mm }, head PH6, probes [p1: TP20_D2_L20] }\n\
         plan q { part p, cmm lab, sampling std::sampling::fan_leu }\n"
}

fn area(g: &PartGeometry, name: &str) -> f64 {
    g.faces
        .iter()
        .filter(|f| f.name == name)
        .map(|f| f.area)
        .sum()
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1.0)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn constructive_parts_keep_their_faces_and_points(b in block()) {
        let mut world = MemoryWorld::new();
        world.insert("main.insp", spec(&b).into_bytes());
        let (checked, parts, graphs) = inspc::measurement_graphs(&world, &["main.insp".into()]);
        let msgs: Vec<String> = checked.diagnostics.iter().map(|d| d.message()).collect();
        prop_assert!(!checked.has_errors(), "{msgs:?}");
        let g = &parts[0].as_ref().unwrap().geometry;
        let [l, w, h] = b.size;

        // Every named face that survives is there, with its area: chords of at most
        // 0.05 mm lose under 1 % of a wall and under 3 % of a small disc.
        let top_holes: f64 = b.top.iter().map(|t| PI * t.d * t.d / 4.0).sum();
        prop_assert!(close(area(g, "stock.top"), l * w - top_holes, 0.01), "top {}", area(g, "stock.top"));
        let through: f64 = b.top.iter().filter(|t| t.depth.is_none()).map(|t| PI * t.d * t.d / 4.0).sum();
        prop_assert!(close(area(g, "stock.bottom"), l * w - through, 0.01));
        let front: f64 = b.front.iter().map(|f| PI * f.d * f.d / 4.0).sum();
        prop_assert!(close(area(g, "stock.front"), l * h - front, 0.01));
        for side in ["stock.back", "stock.left", "stock.right"] {
            prop_assert!(area(g, side) > 0.0, "{side} lost");
        }
        for (k, t) in b.top.iter().enumerate() {
            let depth = t.depth.unwrap_or(h);
            prop_assert!(close(area(g, &format!("t{k}.wall")), PI * t.d * depth, 0.01), "t{k}.wall");
            if t.depth.is_some() {
                prop_assert!(close(area(g, &format!("t{k}.bottom")), PI * t.d * t.d / 4.0, 0.03), "t{k}.bottom");
            }
        }
        for (k, f) in b.front.iter().enumerate() {
            prop_assert!(close(area(g, &format!("f{k}.wall")), PI * f.d * f.depth.unwrap(), 0.01), "f{k}.wall");
        }

        // Every triangle lies on its face's exact surface, up to the chord tolerance.
        for (t, tri) in g.triangles.iter().enumerate() {
            let face = &g.faces[g.tri_face[t] as usize];
            for &v in tri {
                let d = face.surface.distance(&g.vertices[v as usize]).unwrap();
                prop_assert!(d < 0.06, "a vertex of {} is {d} mm off its surface", face.name);
            }
        }

        // Every fpoint is on its face, inside it, with an outward normal.
        let points = &graphs[0].graph.fpoints;
        // Top and bottom (datum A) get 4 points each, every hole wall 8.
        prop_assert_eq!(points.len(), 8 + 8 * (b.top.len() + b.front.len()), "every face gets its Fan & Leu points");
        for p in points {
            let face = &g.faces[p.face.0];
            prop_assert!(face.surface.distance(&p.position).unwrap() <= 1e-6);
            prop_assert!(g.face_covers(p.face, &p.position, &p.normal, 1.0), "outside {}", face.name);
            prop_assert!(g.winding_number(&(p.position + p.normal * 0.2)) < 0.5, "normal into the solid on {}", face.name);
            prop_assert!(g.winding_number(&(p.position - p.normal * 0.2)) > 0.5, "normal out of nothing on {}", face.name);
        }

        // Segmenting the bare mesh finds the stock's planes and every hole's cylinder.
        let raw = RawMesh {
            vertices: g.vertices.clone(),
            triangles: g.triangles.clone(),
            tri_group: vec![0; g.triangles.len()],
            groups: vec![],
            open_edges: 0,
            nonmanifold_edges: 0,
            exact: vec![],
            cad: None,
        };
        let seg = segment::segment(&raw);
        let has_plane = |n: V3, offset: f64| seg.faces.iter().any(|f| matches!(f.surface, Surface::Plane { origin, normal } if normal.dot(&n) > 0.9998 && (origin.coords.dot(&n) - offset).abs() < 0.01));
        for (n, offset) in [(V3::z(), h), (-V3::z(), 0.0), (-V3::y(), 0.0), (V3::y(), w), (-V3::x(), 0.0), (V3::x(), l)] {
            prop_assert!(has_plane(n, offset), "no segment on the plane {n:?} at {offset}");
        }
        let has_cylinder = |axis: V3, d: f64| seg.faces.iter().any(|f| matches!(f.surface, Surface::Cylinder { axis: a, radius, convex: false, .. } if a.dot(&axis).abs() > 0.9998 && close(2.0 * radius, d, 0.01)));
        for t in &b.top {
            prop_assert!(has_cylinder(V3::z(), t.d), "no cylinder of Ø{}", t.d);
        }
        for f in &b.front {
            prop_assert!(has_cylinder(V3::y(), f.d), "no cylinder of Ø{}", f.d);
        }
    }
}
