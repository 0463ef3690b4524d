//! The coarser triangulation a face falls back to when its constrained Delaunay
//! triangulation fails (`tess.rs`): ear clipping of its bounds in the scaled parameter
//! plane, then, on a curved surface, edge splits where a triangle strays from it.
//!
//! **Decision: every bound point kept, whatever the bounds do.** A face's bound points
//! are its edges', shared with the neighbouring faces, so a triangulation that keeps
//! them all keeps the mesh closed. Delaunay fails where the bounds cross each other in
//! the parameter plane: a wall thinner than the chord tolerance, whose two sides' chords
//! cross, or a bound that touches itself. Ear clipping needs no constraint to hold: the
//! holes are bridged into the outer bound (earcut's way: from a hole's rightmost point
//! to the nearest bound point it sees), ears are cut where they are clean, and where no
//! ear is clean (the bounds cross there) the flattest convex corner is cut anyway, so
//! that it always ends; the crossing's few triangles then overlap by less than the
//! chord tolerance, which made the bounds cross. Inside points come from splitting the
//! longest inner edge of each triangle that strays, both triangles on it at once, so
//! the triangulation stays conforming; bound segments are never split.

use crate::geometry::P3;
use std::collections::HashMap;

/// The most bound points the fallback clips (its cost grows with their square).
pub(super) const MAX_POINTS: usize = 20_000;

/// A face's triangulation in its scaled parameter plane: points (plane, space) and
/// counter-clockwise triangles into them.
#[derive(Debug, Default)]
pub(super) struct Flat {
    /// Plane coordinates.
    pub q: Vec<[f64; 2]>,
    /// Points in space.
    pub xyz: Vec<P3>,
    /// Triangles, counter-clockwise in the plane.
    pub tris: Vec<[usize; 3]>,
}

/// How a curved surface is refined: its point at plane coordinates, whether a triangle
/// (plane corners, space corners) strays from it, how many points may be added, and
/// the closest a new point may come to a corner (mm).
pub(super) struct Refiner<'a> {
    /// The surface's point at plane coordinates.
    pub eval: &'a dyn Fn([f64; 2]) -> P3,
    /// Whether a triangle strays from the surface.
    pub strays: &'a dyn Fn([[f64; 2]; 3], [P3; 3]) -> bool,
    /// How many points may be added inside.
    pub budget: usize,
    /// The closest a new point may come to the ends of the edge it splits (mm).
    pub spacing_mm: f64,
}

/// Ear clipping of `polygons` (each a closed loop of plane and space points: the
/// largest the outer bound, the others holes), where bounds may cross by up to `slack`,
/// refined on the surface when `refiner` is given. An error only for bounds with fewer than three points, more than
/// [`MAX_POINTS`], or coordinates that are not numbers.
pub(super) fn ear_mesh(
    polygons: &[Vec<([f64; 2], P3)>],
    slack: f64,
    refiner: Option<&Refiner>,
) -> Result<Flat, String> {
    let mut flat = Flat::default();
    let mut loops: Vec<Vec<usize>> = Vec::new();
    for poly in polygons {
        let mut l = Vec::new();
        for (q, x) in poly {
            if !(q[0].is_finite() && q[1].is_finite()) {
                return Err("a bound point has no parameters".into());
            }
            l.push(flat.q.len());
            flat.q.push(*q);
            flat.xyz.push(*x);
        }
        if l.len() >= 3 {
            loops.push(l);
        }
    }
    if flat.q.len() > MAX_POINTS {
        return Err(format!("its bounds have more than {MAX_POINTS} points"));
    }
    if loops.is_empty() {
        return Err("no bound has three points".into());
    }
    let q = flat.q.clone();
    let area = |l: &[usize]| signed_area(&q, l);
    // The outer bound counter-clockwise, the holes clockwise.
    loops.sort_by(|a, b| area(b).abs().total_cmp(&area(a).abs()));
    for (k, l) in loops.iter_mut().enumerate() {
        if (area(l) > 0.0) != (k == 0) {
            l.reverse();
        }
    }
    let ring = bridge(&q, loops);
    flat.tris = clip(&q, ring, slack);
    // Where the bounds cross, forced ears may overlap: more than the crossings can
    // account for is no triangulation of the face.
    let (signed, total) = flat.tris.iter().fold((0.0, 0.0), |(s, t), tri| {
        let a = cross(q[tri[0]], q[tri[1]], q[tri[2]]) / 2.0;
        (s + a, t + a.abs())
    });
    if total > 1.01 * signed.abs() + 1e-9 {
        return Err(format!(
            "its ear-clipped triangles overlap ({total:.3} against {:.3} in the scaled parameters)",
            signed.abs()
        ));
    }
    if let Some(r) = refiner {
        split_refine(&mut flat, r);
    }
    Ok(flat)
}

/// Moves the plane points of bound segments that cross another away from the face by
/// `delta` (along the bisector of their segments' normals; the face lies inside the
/// largest loop and outside the others), so that bounds whose chords cross by less
/// than `delta` no longer do. Their points in space stay: the mesh keeps the edges'
/// points, its triangles lean by the move. Returns how many points moved.
pub(super) fn uncross(polygons: &mut [Vec<[f64; 2]>], delta: f64) -> usize {
    let areas: Vec<f64> = polygons
        .iter()
        .map(|p| signed_area(p, &(0..p.len()).collect::<Vec<_>>()))
        .collect();
    let outer = (0..polygons.len())
        .max_by(|&a, &b| areas[a].abs().total_cmp(&areas[b].abs()))
        .unwrap_or(0);
    // Every segment: (loop, index of its first point).
    let mut segs: Vec<(usize, usize)> = polygons
        .iter()
        .enumerate()
        .flat_map(|(l, p)| (0..p.len()).map(move |i| (l, i)))
        .collect();
    let ends = |&(l, i): &(usize, usize)| {
        let p = &polygons[l];
        (p[i], p[(i + 1) % p.len()])
    };
    let lo = |s: &(usize, usize)| {
        let (a, b) = ends(s);
        a[0].min(b[0])
    };
    segs.sort_by(|a, b| lo(a).total_cmp(&lo(b)));
    let mut hit: std::collections::BTreeSet<(usize, usize)> = Default::default();
    for (k, s) in segs.iter().enumerate() {
        let (a, b) = ends(s);
        let hi = a[0].max(b[0]);
        for t in segs[k + 1..].iter().take_while(|t| lo(t) <= hi) {
            let (c, d) = ends(t);
            if crosses(a, b, c, d) {
                for (l, i) in [*s, *t] {
                    hit.insert((l, i));
                    hit.insert((l, (i + 1) % polygons[l].len()));
                }
            }
        }
    }
    let moves: Vec<(usize, usize, [f64; 2])> = hit
        .iter()
        .map(|&(l, i)| {
            let p = &polygons[l];
            let n = p.len();
            // Away from the face: right of a loop that runs with the face on its left.
            let face_left = (areas[l] > 0.0) == (l == outer);
            let away = |a: [f64; 2], b: [f64; 2]| {
                let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
                let len = dx.hypot(dy).max(1e-300);
                let side = if face_left { 1.0 } else { -1.0 };
                [side * dy / len, -side * dx / len]
            };
            let (u, v) = (away(p[(i + n - 1) % n], p[i]), away(p[i], p[(i + 1) % n]));
            let m = [u[0] + v[0], u[1] + v[1]];
            let len = m[0].hypot(m[1]);
            let dir = if len > 1e-9 {
                [m[0] / len, m[1] / len]
            } else {
                v
            };
            (l, i, [p[i][0] + delta * dir[0], p[i][1] + delta * dir[1]])
        })
        .collect();
    for (l, i, q) in &moves {
        polygons[*l][*i] = *q;
    }
    moves.len()
}

/// Twice the signed area of a loop.
fn signed_area(q: &[[f64; 2]], l: &[usize]) -> f64 {
    let n = l.len();
    (0..n)
        .map(|i| {
            let (a, b) = (q[l[i]], q[l[(i + 1) % n]]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum()
}

/// Twice the signed area of a triangle: positive counter-clockwise.
fn cross(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Whether segments `ab` and `cd` cross at a point inside both.
fn crosses(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let (d1, d2) = (cross(a, b, c), cross(a, b, d));
    let (d3, d4) = (cross(c, d, a), cross(c, d, b));
    d1 * d2 < 0.0 && d3 * d4 < 0.0
}

/// The outer loop with each hole spliced in along a bridge: from the hole's rightmost
/// point to the nearest point of the ring built so far whose segment crosses no bound
/// (the nearest of all where every one does), and back.
fn bridge(q: &[[f64; 2]], mut loops: Vec<Vec<usize>>) -> Vec<usize> {
    let mut ring = loops.remove(0);
    let rightmost = |l: &[usize]| {
        (0..l.len())
            .max_by(|&i, &j| q[l[i]][0].total_cmp(&q[l[j]][0]))
            .unwrap_or(0)
    };
    loops.sort_by(|a, b| q[b[rightmost(b)]][0].total_cmp(&q[a[rightmost(a)]][0]));
    for (h, hole) in loops.iter().enumerate() {
        let m = rightmost(hole);
        let pm = q[hole[m]];
        let others: Vec<&Vec<usize>> = loops[h..].iter().collect();
        let segments = |l: &[usize]| -> Vec<([f64; 2], [f64; 2])> {
            (0..l.len())
                .map(|i| (q[l[i]], q[l[(i + 1) % l.len()]]))
                .collect()
        };
        let mut walls = segments(&ring);
        for o in &others {
            walls.extend(segments(o));
        }
        let mut order: Vec<usize> = (0..ring.len()).collect();
        let dist = |i: &usize| {
            let p = q[ring[*i]];
            (p[0] - pm[0]).hypot(p[1] - pm[1])
        };
        order.sort_by(|a, b| dist(a).total_cmp(&dist(b)));
        let seen = order
            .iter()
            .copied()
            .find(|&i| {
                let p = q[ring[i]];
                walls.iter().all(|&(a, b)| !crosses(pm, p, a, b))
            })
            .unwrap_or(order[0]);
        // ring[..=seen], hole from m round to m, back to ring[seen], the rest.
        let mut spliced = ring[..=seen].to_vec();
        spliced.extend(hole[m..].iter().chain(&hole[..=m]));
        spliced.extend(&ring[seen..]);
        ring = spliced;
    }
    ring
}

/// Ear clipping of a counter-clockwise ring: each round cuts the first clean ear (a
/// convex corner whose triangle holds no other point of the ring); where there is none,
/// the first ear clean within `slack` (a corner concave by less, a point inside by
/// less: where bounds cross, by less than the chord that made them cross); where there
/// is none either, the flattest convex corner (the least concave one when none is
/// convex).
fn clip(q: &[[f64; 2]], mut ring: Vec<usize>, slack: f64) -> Vec<[usize; 3]> {
    let mut tris = Vec::with_capacity(ring.len());
    let mut start = 0;
    while ring.len() > 3 {
        let n = ring.len();
        let corner = |i: usize| (ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n]);
        let area = |i: usize| {
            let (a, b, c) = corner(i);
            cross(q[a], q[b], q[c])
        };
        let ear = |slack: f64| {
            (0..n).map(|k| (start + k) % n).find(|&i| {
                let (a, b, c) = corner(i);
                let base = dist(q[a], q[c]).max(1e-300);
                area(i) > -slack * base && !holds_any(q, &ring, (a, b, c), slack)
            })
        };
        let i = ear(0.0).or_else(|| ear(slack)).unwrap_or_else(|| {
            let convex = (0..n)
                .filter(|&i| area(i) > 0.0)
                .min_by(|&x, &y| area(x).total_cmp(&area(y)));
            convex
                .or_else(|| (0..n).max_by(|&x, &y| area(x).total_cmp(&area(y))))
                .unwrap_or(0)
        });
        let (a, b, c) = corner(i);
        tris.push([a, b, c]);
        ring.remove(i);
        start = i.saturating_sub(1);
    }
    if let [a, b, c] = ring[..] {
        tris.push([a, b, c]);
    }
    tris
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Whether a point of the ring other than the triangle's corners (by place: a bridge
/// repeats its ends) lies in the triangle deeper than `slack` from its sides (on them
/// counts, without slack); a corner with no area holds nothing.
fn holds_any(q: &[[f64; 2]], ring: &[usize], (a, b, c): (usize, usize, usize), slack: f64) -> bool {
    let (pa, pb, pc) = (q[a], q[b], q[c]);
    if cross(pa, pb, pc) <= 0.0 {
        return false;
    }
    let sides = [(pa, pb), (pb, pc), (pc, pa)].map(|(u, v)| (u, v, dist(u, v).max(1e-300)));
    ring.iter().any(|&p| {
        let x = q[p];
        if x == pa || x == pb || x == pc {
            return false;
        }
        sides.iter().all(|(u, v, l)| {
            let d = cross(*u, *v, x) / l;
            if slack > 0.0 {
                d > slack
            } else {
                d >= 0.0
            }
        })
    })
}

/// Round by round, splits the longest inner edge of each triangle that strays (one
/// edge per triangle a round, both its triangles cut in two), until none strays, 24
/// rounds pass or the budget is spent. Bound segments (edges of one triangle only) are
/// never split.
fn split_refine(flat: &mut Flat, r: &Refiner) {
    let mut budget = r.budget;
    for _ in 0..24 {
        let mut uses: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
        for (t, tri) in flat.tris.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                uses.entry((a.min(b), a.max(b))).or_default().push(t);
            }
        }
        let mut busy = vec![false; flat.tris.len()];
        let mut splits: Vec<((usize, usize), usize)> = Vec::new();
        for (t, tri) in flat.tris.iter().enumerate() {
            if busy[t] {
                continue;
            }
            let qs = tri.map(|i| flat.q[i]);
            if !(r.strays)(qs, tri.map(|i| flat.xyz[i])) {
                continue;
            }
            let len = |k: usize| {
                let (a, b) = (qs[k], qs[(k + 1) % 3]);
                (a[0] - b[0]).hypot(a[1] - b[1])
            };
            let Some(k) = (0..3).max_by(|&x, &y| len(x).total_cmp(&len(y))) else {
                continue;
            };
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let key = (a.min(b), a.max(b));
            let pair = &uses[&key];
            if pair.len() != 2 || pair.iter().any(|&o| busy[o]) || budget == 0 {
                continue;
            }
            let m = [
                (flat.q[a][0] + flat.q[b][0]) / 2.0,
                (flat.q[a][1] + flat.q[b][1]) / 2.0,
            ];
            let x = (r.eval)(m);
            let close = |i: usize| (flat.xyz[i] - x).norm() < r.spacing_mm;
            if close(a) || close(b) {
                continue;
            }
            pair.iter().for_each(|&o| busy[o] = true);
            budget -= 1;
            flat.q.push(m);
            flat.xyz.push(x);
            splits.push((key, flat.q.len() - 1));
        }
        if splits.is_empty() {
            break;
        }
        let at: HashMap<(usize, usize), usize> = splits.into_iter().collect();
        let mut next = Vec::with_capacity(flat.tris.len() + 2 * at.len());
        for tri in &flat.tris {
            let cut = (0..3).find_map(|k| {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                at.get(&(a.min(b), a.max(b))).map(|&m| (k, m))
            });
            match cut {
                Some((k, m)) => {
                    let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
                    next.push([a, m, c]);
                    next.push([m, b, c]);
                }
                None => next.push(*tri),
            }
        }
        flat.tris = next;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn loop_of(pts: &[[f64; 2]]) -> Vec<([f64; 2], P3)> {
        pts.iter().map(|p| (*p, P3::new(p[0], p[1], 0.0))).collect()
    }

    fn area(f: &Flat) -> f64 {
        f.tris
            .iter()
            .map(|t| cross(f.q[t[0]], f.q[t[1]], f.q[t[2]]) / 2.0)
            .sum()
    }

    #[test]
    fn a_square_with_a_hole_keeps_every_point() {
        let outer = loop_of(&[[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]);
        // The hole given counter-clockwise too: it is turned.
        let hole = loop_of(&[[3.0, 3.0], [6.0, 3.0], [6.0, 6.0], [3.0, 6.0]]);
        let f = ear_mesh(&[hole, outer], 0.0, None).unwrap();
        assert!((area(&f) - 91.0).abs() < 1e-9, "{}", area(&f));
        let used: std::collections::HashSet<usize> = f.tris.iter().flatten().copied().collect();
        assert_eq!(used.len(), 8);
        assert!(f
            .tris
            .iter()
            .all(|t| cross(f.q[t[0]], f.q[t[1]], f.q[t[2]]) >= 0.0));
    }

    #[test]
    fn overlapping_ears_are_refused() {
        // A hole far through the outer bound: the clipping ends, and says it overlaps.
        let outer = loop_of(&[[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]);
        let hole = loop_of(&[[2.0, 2.0], [14.0, 5.0], [2.0, 8.0]]);
        assert!(ear_mesh(&[outer, hole], 0.05, None).is_err());
    }

    #[test]
    fn crossing_chords_are_moved_apart() {
        // A hole whose corner pokes 0.05 past the outer bound's side.
        let mut polys = vec![
            vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]],
            vec![[2.0, 2.0], [10.05, 5.0], [2.0, 8.0]],
        ];
        assert_eq!(uncross(&mut polys, 0.1), 5);
        // The outer side moved out, the hole's corner into the hole.
        assert!(polys[0][1][0] > 10.0 && polys[0][2][0] > 10.0);
        assert!(polys[1][1][0] < 10.0);
        assert_eq!(uncross(&mut polys, 0.1), 0);
    }

    #[test]
    fn refinement_splits_inner_edges_only() {
        let outer = loop_of(&[[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]);
        let eval = |q: [f64; 2]| P3::new(q[0], q[1], 0.0);
        // Every triangle longer than 3 strays.
        let strays = |q: [[f64; 2]; 3], _: [P3; 3]| {
            (0..3).any(|k| {
                let (a, b) = (q[k], q[(k + 1) % 3]);
                (a[0] - b[0]).hypot(a[1] - b[1]) > 3.0
            })
        };
        let r = Refiner {
            eval: &eval,
            strays: &strays,
            budget: 1000,
            spacing_mm: 1e-4,
        };
        let f = ear_mesh(&[outer], 0.0, Some(&r)).unwrap();
        assert!(f.tris.len() > 2);
        assert!((area(&f) - 100.0).abs() < 1e-9);
        // Conforming: every inner edge has two triangles, every bound segment one.
        let mut uses: HashMap<(usize, usize), usize> = HashMap::new();
        for t in &f.tris {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *uses.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        assert!(uses.values().all(|&u| u <= 2));
        assert_eq!(uses.values().filter(|&&u| u == 1).count(), 4);
    }
}
