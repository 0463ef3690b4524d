//! The sampling rules on faces where the answer is known: Fan & Leu's insets, the
//! slender-face shift, the zig-zag search around a hole, the cylinder circles, point
//! counts of uniform and Hammersley sampling, per-feature overrides, and a narrow floor's
//! points kept clear of its wall.

use inspc::source::MemoryWorld;

/// The fpoints of every face of a one-part spec, as (face name, x, y, z) rounded to µm.
fn points(part_body: &str, plan_extra: &str) -> Vec<(String, [f64; 3])> {
    points_on(&["TP20_D2_L20"], part_body, plan_extra)
}

/// [`points`] with a rack of the given stdlib probes (`p1`, `p2`, … in order).
fn points_on(probes: &[&str], part_body: &str, plan_extra: &str) -> Vec<(String, [f64; 3])> {
    let rack: Vec<String> = probes
        .iter()
        .enumerate()
        .map(|(i, p)| format!("p{}: {p}", i + 1))
        .collect();
    let src = format!(
        "use std::heads::PH6\nuse std::probes::{{{}}}\npart p {{\n units mm\n{part_body}\n}}\n\
         cmm lab {{ table {{ z 0 mm }}, ram {{ radius 35 mm, length 600 mm }}, head PH6, probes [{}] }}\n\
         plan q {{ part p, cmm lab\n{plan_extra}\n}}\n",
        probes.join(", "),
        rack.join(", ")
    );
    let mut world = MemoryWorld::new();
    world.insert("main.insp", src.into_bytes());
    let (checked, parts, graphs) = inspc::measurement_graphs(&world, &["main.insp".into()]);
    let msgs: Vec<String> = checked
        .diagnostics
        .iter()
        .map(|d| format!("{}: {}", d.code(), d.message()))
        .collect();
    assert!(msgs.is_empty(), "{msgs:?}");
    let g = &parts[0].as_ref().unwrap().geometry;
    let r = |v: f64| (v * 1e6).round() / 1e6 + 0.0;
    graphs[0]
        .graph
        .fpoints
        .iter()
        .map(|p| {
            (
                g.faces[p.face.0].name.clone(),
                [r(p.position.x), r(p.position.y), r(p.position.z)],
            )
        })
        .collect()
}

fn on(points: &[(String, [f64; 3])], face: &str) -> Vec<[f64; 3]> {
    points
        .iter()
        .filter(|(f, _)| f == face)
        .map(|(_, p)| *p)
        .collect()
}

#[test]
fn fan_leu_plane_is_inset_by_a_fifth() {
    let p = points(" stock box(100, 50, 20)\n feature top = stock.top", "");
    assert_eq!(
        on(&p, "stock.top"),
        vec![
            [20.0, 10.0, 20.0],
            [80.0, 10.0, 20.0],
            [80.0, 40.0, 20.0],
            [20.0, 40.0, 20.0]
        ]
    );
}

#[test]
fn fan_leu_slender_plane_moves_points_two_and_four_inward() {
    // 100 × 10: aspect 10 > 4. The inner rectangle is 60 long; two eighths of it is 15.
    let p = points(" stock box(100, 10, 20)\n feature top = stock.top", "");
    assert_eq!(
        on(&p, "stock.top"),
        vec![
            [20.0, 2.0, 20.0],
            [65.0, 2.0, 20.0],
            [80.0, 8.0, 20.0],
            [35.0, 8.0, 20.0]
        ]
    );
}

#[test]
fn fan_leu_point_in_a_hole_moves_out_by_the_zig_zag_search() {
    // A Ø16 hole right on the first Fan & Leu point (20, 10).
    let p = points(" stock box(100, 50, 20)\n cut hole h { at (20, 10, 20), axis -z, diameter 16, depth through }\n feature top = stock.top", "");
    let top = on(&p, "stock.top");
    assert_eq!(top.len(), 4);
    let first = top[0];
    let from_axis = ((first[0] - 20.0).powi(2) + (first[1] - 10.0).powi(2)).sqrt();
    // Clear of the hole by the margin (the tip radius, 1 mm), and the nearest such
    // candidate of the search: one diagonal step (5, 2.5) with one step across it.
    assert!(
        from_axis >= 8.0 + 1.0 - 1e-9,
        "{first:?} is within a tip radius of the hole"
    );
    assert_eq!(first, [30.0, 10.0, 20.0]);
    assert_eq!(
        &top[1..],
        &[[80.0, 10.0, 20.0], [80.0, 40.0, 20.0], [20.0, 40.0, 20.0]]
    );
}

#[test]
fn fan_leu_cylinder_has_two_circles_of_four() {
    // A Ø20 hole 50 deep; the margin r is the largest tip radius, 1 mm.
    let p = points(" stock box(60, 60, 50)\n cut hole h { at (30, 30, 50), axis -z, diameter 20, depth through }\n feature bore = h.wall", "");
    let wall = on(&p, "h.wall");
    assert_eq!(wall.len(), 8);
    let heights: Vec<f64> = wall.iter().map(|q| q[2]).collect();
    // h1 = r + (H − 2r)/5 = 10.6 and h2 = r + 4(H − 2r)/5 = 39.4 from the hole's end.
    let (h1, h2) = (50.0 - 10.6, 50.0 - 39.4);
    assert!(
        heights[..4].iter().all(|&z| (z - h1).abs() < 1e-9)
            && heights[4..].iter().all(|&z| (z - h2).abs() < 1e-9),
        "{heights:?}"
    );
    for q in &wall {
        let r = ((q[0] - 30.0).powi(2) + (q[1] - 30.0).powi(2)).sqrt();
        assert!((r - 10.0).abs() < 1e-6, "{q:?} is not on the Ø20 cylinder");
    }
    // 90° apart on each circle.
    let mut a: Vec<f64> = wall[..4]
        .iter()
        .map(|q| {
            (q[1] - 30.0)
                .atan2(q[0] - 30.0)
                .to_degrees()
                .rem_euclid(360.0)
                .round()
        })
        .collect();
    a.sort_by(f64::total_cmp);
    assert_eq!(a, vec![0.0, 90.0, 180.0, 270.0]);
}

#[test]
fn uniform_and_hammersley_give_the_requested_counts_and_overrides_win() {
    let body = " stock box(100, 50, 20)\n cut hole h { at (50, 25, 20), axis -z, diameter 20, depth through }\n feature top = stock.top\n feature bore = h.wall";
    let p = points(
        body,
        " sampling std::sampling::uniform\n sample bore with hammersley(points 10)",
    );
    assert_eq!(on(&p, "stock.top").len(), 9);
    assert_eq!(on(&p, "h.wall").len(), 10);
    let p = points(body, " sampling std::sampling::hammersley");
    assert_eq!(on(&p, "stock.top").len(), 12);
    // No point of the top falls into the hole.
    for q in on(&p, "stock.top") {
        assert!(
            ((q[0] - 50.0).powi(2) + (q[1] - 25.0).powi(2)).sqrt() > 10.0,
            "{q:?}"
        );
    }
}

#[test]
fn a_counterbore_floor_narrower_than_the_widest_tip_keeps_its_points_clear_of_the_wall() {
    // A Ø22 × 4 counterbore over a Ø12 through hole: its floor is a ring 5 mm wide, under
    // the 6 mm the rack's widest tip (Ø6, margin 3) needs. Fan & Leu's points sit at the
    // corners of the inset square, r = 9.33, where a Ø2 tip standing off the floor keeps
    // 0.67 mm from the wall. With the margin halved the points keep 1.5 mm from the hole's
    // mouth (r ≥ 7.5) and 1.5 + 1 mm from the wall (r ≤ 8.5): the Ø2 tip keeps 1.5 mm.
    let p = points_on(
        &["TP20_D2_L20", "TP20_D6_L20"],
        " stock box(100, 50, 20)\n cut hole cb { at (50, 25, 20), axis -z, diameter 22, depth 4 }\n \
         cut hole h { at (50, 25, 20), axis -z, diameter 12, depth through }\n feature floor = cb.bottom",
        "",
    );
    let floor = on(&p, "cb.bottom");
    assert_eq!(floor.len(), 4, "{floor:?}");
    for q in &floor {
        let r = ((q[0] - 50.0).powi(2) + (q[1] - 25.0).powi(2)).sqrt();
        assert!(
            (7.5 - 1e-6..=8.5 + 1e-6).contains(&r),
            "{q:?} is {r} mm from the axis"
        );
        assert!((q[2] - 16.0).abs() < 1e-6, "{q:?}");
    }
}
