//! Tessellation of a B-rep to a chord tolerance, face by face.
//!
//! Every edge is cut into a polyline once (`edges.rs`: the two faces that share it share
//! its points and the mesh closes). A face's bounds are mapped into the surface's parameter
//! plane, scaled to millimetres, and triangulated there with a constrained Delaunay
//! triangulation (spade); triangles outside the bounds are dropped, and on a curved
//! surface points are added inside until every triangle lies within the chord tolerance
//! of the surface and turns by no more than the angle limit.
//!
//! Periodic surfaces: a bound is unwrapped along the loop; a face bounded by two loops
//! that each go once round (a band of a bore with no seam edge) is cut along a line
//! between them; a face bounded by one such loop (a spherical cap, a cone to its apex)
//! is closed at the pole on its side.
//!
//! **Decision: inside by crossings, refined against the exact surface.** Each face is
//! triangulated in its parameter plane by spade's constrained Delaunay triangulation;
//! inside is decided by counting bound crossings from the hull, not by a
//! point-in-polygon test, which slivers between nearly collinear points fool. It is
//! then refined by splitting the longest edge of any triangle whose centroid or edge
//! midpoints stray more than the chord tolerance from the exact surface or whose corner
//! normals differ by more than the angle limit. Two loops that each go round are joined
//! by a cut that is itself cut to the tolerance on both sides; one loop that goes round
//! is closed at the pole on the face's side (its left, seen from the face's normal); a
//! pole inside a loop becomes a run of points along the pole. Cylinders and cones are
//! triangulated with v squeezed `RULED_STRETCH` (8) times, so triangles run along their
//! straight lines.
//!
//! **Decision: a failing face falls back, coarser, rather than fail.** Where refining
//! runs out of points it is redone to ten times the chord, then left out; where the
//! bounds cross in the plane (a wall thinner than the chord), the crossing points are
//! moved apart in the plane only and Delaunay runs again; last, the bounds are
//! ear-clipped (`fallback.rs`). Each keeps every bound point, so the mesh stays closed;
//! a face is an error only when all fail, with the first reason.

use super::brep::{Bound, Brep, Face};
use super::curve::unwrap_near;
use super::edges::{edge_polylines, refine_curve, too_large, Resolution, BATCH};
use super::fallback::{ear_mesh, uncross, Refiner};
use super::geom::Surf;
use crate::geometry::weld::MAX_TRIANGLES;
use crate::geometry::{P3, V3};
use rayon::prelude::*;
use spade::{ConstrainedDelaunayTriangulation, HasPosition, Point2, Triangulation};
use std::f64::consts::TAU;

/// How much longer than wide a triangle may come out along a cylinder's or cone's
/// straight lines, where the surface does not curve.
const RULED_STRETCH: f64 = 8.0;

/// The mesh of a B-rep: triangle corners per face, not yet welded.
#[derive(Debug, Default)]
pub(crate) struct Soup {
    /// Corner positions (mm).
    pub positions: Vec<[f64; 3]>,
    /// Triangles into `positions`, counter-clockwise from outside.
    pub triangles: Vec<[usize; 3]>,
    /// The face (index into the B-rep's faces) of each triangle.
    pub tri_face: Vec<u32>,
}

/// A face that could not be tessellated.
#[derive(Debug, Clone)]
pub(crate) struct FaceFailure {
    /// Index of the face (0-based, shell order).
    pub index: usize,
    /// Its instance number.
    pub id: u64,
    /// Why.
    pub reason: String,
}

/// The closest an inner point may come to a triangle's corner (mm): a hundred times
/// the distance the weld merges points at.
const MIN_SPACING_MM: f64 = 1e-4;

/// The most points one face's bounds may have, and the most it may gain inside.
const MAX_FACE_POINTS: usize = 200_000;

/// Tessellates every face; the failures are every face that could not be meshed. An
/// error, before the work grows past it, when the part needs more than
/// [`MAX_TRIANGLES`] triangles (or its edges more points): the mesh of a file is
/// bounded whatever its curves and faces ask for.
pub(crate) fn tessellate(b: &Brep, res: Resolution) -> Result<(Soup, Vec<FaceFailure>), String> {
    let edges = edge_polylines(b, res)?;
    let mut soup = Soup::default();
    let mut failures = Vec::new();
    // Faces are meshed in parallel batches and gathered in their order: the soup is the
    // same for any thread count.
    for (k, batch) in b.faces.chunks(BATCH).enumerate() {
        let meshes: Vec<_> = batch
            .par_iter()
            .map(|face| face_mesh(face, &edges, res))
            .collect();
        for (j, (face, mesh)) in batch.iter().zip(meshes).enumerate() {
            let index = k * BATCH + j;
            match mesh {
                Ok(tris) => {
                    for t in tris {
                        let base = soup.positions.len();
                        soup.positions.extend(t.iter().map(|p| [p.x, p.y, p.z]));
                        soup.triangles.push([base, base + 1, base + 2]);
                        soup.tri_face.push(index as u32);
                    }
                }
                Err(reason) => failures.push(FaceFailure {
                    index,
                    id: face.id,
                    reason,
                }),
            }
        }
        if soup.triangles.len() > MAX_TRIANGLES {
            return Err(too_large(res));
        }
    }
    Ok((soup, failures))
}

/// A point of a face's parameter-plane polygon: scaled (u, v), and the 3D point when
/// it is a boundary point (so boundary points are shared exactly with the neighbours).
#[derive(Debug, Clone, Copy)]
struct Pt {
    uv: [f64; 2],
    xyz: P3,
}

/// One bound in the parameter plane, unscaled, with how many times it goes round in u
/// and in v.
struct Loop {
    pts: Vec<Pt>,
    wraps: [i64; 2],
}

/// A face's bounds in its surface's parameter plane, unwrapped along each loop; an
/// error past [`MAX_FACE_POINTS`] points (a loop may name one edge many times).
fn face_loops(face: &Face, edges: &[Vec<P3>]) -> Result<Vec<Loop>, String> {
    let s = &face.surface;
    let periods = [s.u_period(), s.v_period()];
    let mut loops = Vec::new();
    let mut hint = None;
    let mut points = 0usize;
    for bound in &face.bounds {
        if let Bound::Edges(list) = bound {
            points += list.iter().map(|(e, _)| edges[*e].len()).sum::<usize>();
            if points > MAX_FACE_POINTS {
                return Err(format!(
                    "its bounds have more than {MAX_FACE_POINTS} points"
                ));
            }
        }
        let pts3: Vec<P3> = match bound {
            Bound::Vertex => continue,
            Bound::Edges(list) => {
                let mut pts: Vec<P3> = Vec::new();
                for &(e, forward) in list {
                    let mut p = edges[e].clone();
                    if !forward {
                        p.reverse();
                    }
                    if pts.last().is_some_and(|l| (l - p[0]).norm() < 1e-9) {
                        pts.pop();
                    }
                    pts.extend(p);
                }
                if pts.len() > 1 && (pts[0] - pts[pts.len() - 1]).norm() < 1e-9 {
                    pts.pop();
                }
                pts
            }
        };
        if pts3.len() < 2 {
            continue;
        }
        loops.push(param_loop(s, &pts3, periods, &mut hint));
    }
    Ok(loops)
}

/// Whether a face lies along its surface's natural normal, told from its bounds alone
/// under the B-rep rule that a face lies left of its bounds seen from outside: the
/// bounds enclose a positive area of the parameter plane. `None` when the bounds cannot
/// tell (one loop going round a sphere: either cap is left of it for one of the senses).
pub(crate) fn bound_sense(face: &Face, edges: &[Vec<P3>]) -> Option<bool> {
    let s = &face.surface;
    let periods = [s.u_period(), s.v_period()];
    let loops = face_loops(face, edges).ok()?;
    let mut wraps = [0i64; 2];
    let mut area = 0.0;
    for l in &loops {
        wraps[0] += l.wraps[0];
        wraps[1] += l.wraps[1];
        let n = l.pts.len();
        for i in 0..n {
            let a = l.pts[i].uv;
            let mut b = l.pts[(i + 1) % n].uv;
            if i + 1 == n {
                // The closing step goes on round the period the loop wraps.
                for k in 0..2 {
                    if let Some(per) = periods[k] {
                        b[k] += l.wraps[k] as f64 * per;
                    }
                }
            }
            // ∮ −v du: the enclosed area, counter-clockwise positive; loops that go
            // round in opposite senses (a band) sum to the area between them.
            area -= 0.5 * (a[1] + b[1]) * (b[0] - a[0]);
        }
    }
    if loops.is_empty() || wraps != [0, 0] || area.abs() < 1e-12 {
        return None;
    }
    Some(area > 0.0)
}

fn face_mesh(face: &Face, edges: &[Vec<P3>], res: Resolution) -> Result<Vec<[P3; 3]>, String> {
    let s = &face.surface;
    let periods = [s.u_period(), s.v_period()];
    let loops = face_loops(face, edges)?;
    if loops.is_empty() {
        return Err("it has no bound with edges".into());
    }
    let sense = if face.same_sense { 1.0 } else { -1.0 };
    let polygons = close_loops(s, loops, periods, sense, res)?;
    let scale = ParamScale::of(s, &polygons);
    delaunay(s, &polygons, &scale, sense, res).or_else(|why| {
        apart(s, &polygons, &scale, sense, res)
            .or_else(|_| ear_clipped(s, &polygons, &scale, sense, res))
            .map_err(|e| format!("{why}; nor by the fallbacks ({e})"))
    })
}

/// Delaunay again with the bound points whose segments cross moved apart in the plane
/// (`fallback::uncross`): by half the chord, then up to four times farther. The bounds'
/// chords of a wall thinner than the chord cross by less than that.
fn apart(
    s: &Surf,
    polygons: &[Vec<Pt>],
    scale: &ParamScale,
    sense: f64,
    res: Resolution,
) -> Result<Vec<[P3; 3]>, String> {
    let mut plane: Vec<Vec<[f64; 2]>> = polygons
        .iter()
        .map(|p| p.iter().map(|pt| scale.scaled(pt.uv)).collect())
        .collect();
    let mut delta = 0.5 * res.chord_mm;
    let mut last = Err("its bounds do not cross".to_string());
    for _ in 0..4 {
        if uncross(&mut plane, delta) == 0 {
            break;
        }
        let moved: Vec<Vec<Pt>> = polygons
            .iter()
            .zip(&plane)
            .map(|(p, q)| {
                p.iter()
                    .zip(q)
                    .map(|(pt, q)| Pt {
                        uv: scale.unscale(*q),
                        xyz: pt.xyz,
                    })
                    .collect()
            })
            .collect();
        last = delaunay(s, &moved, scale, sense, res);
        if last.is_ok() {
            break;
        }
        delta *= 2.0;
    }
    last
}

/// The constrained Delaunay triangulation of a face's bounds, refined on a curved
/// surface; where refining fails (too many points, a point spade refuses), refined
/// again to ten times the chord, then not at all: coarser, but the face's.
fn delaunay(
    s: &Surf,
    polygons: &[Vec<Pt>],
    scale: &ParamScale,
    sense: f64,
    res: Resolution,
) -> Result<Vec<[P3; 3]>, String> {
    let mut cdt = bounds_triangulation(polygons, scale)?;
    if !matches!(s, Surf::Plane(_)) && refine(&mut cdt, s, scale, res).is_err() {
        let coarse = Resolution {
            chord_mm: res.chord_mm * 10.0,
            angle_rad: (res.angle_rad * 2.0).min(1.0),
        };
        cdt = bounds_triangulation(polygons, scale)?;
        if refine(&mut cdt, s, scale, coarse).is_err() {
            cdt = bounds_triangulation(polygons, scale)?;
        }
    }
    inside_triangles(&cdt, sense)
}

/// The fallback when Delaunay fails (`fallback.rs`): the bounds ear-clipped in the
/// scaled plane with every point kept, split inside where a triangle strays from a
/// curved surface; counter-clockwise in the plane is along the natural normal.
fn ear_clipped(
    s: &Surf,
    polygons: &[Vec<Pt>],
    scale: &ParamScale,
    sense: f64,
    res: Resolution,
) -> Result<Vec<[P3; 3]>, String> {
    let plane: Vec<Vec<([f64; 2], P3)>> = polygons
        .iter()
        .map(|p| p.iter().map(|pt| (scale.scaled(pt.uv), pt.xyz)).collect())
        .collect();
    let eval = |q: [f64; 2]| {
        let uv = scale.unscale(q);
        s.eval(uv[0], uv[1])
    };
    let stray = |q: [[f64; 2]; 3], x: [P3; 3]| {
        // Two corners on one pole: nothing to refine.
        if (x[1] - x[0]).cross(&(x[2] - x[0])).norm() < 1e-12 {
            return false;
        }
        let c = [
            (q[0][0] + q[1][0] + q[2][0]) / 3.0,
            (q[0][1] + q[1][1] + q[2][1]) / 3.0,
        ];
        strays(s, scale, res, (q, c), x)
    };
    let refiner = Refiner {
        eval: &eval,
        strays: &stray,
        budget: MAX_FACE_POINTS,
        spacing_mm: MIN_SPACING_MM,
    };
    let curved = !matches!(s, Surf::Plane(_));
    // Bounds cross by less than the chord that cut them.
    let flat = ear_mesh(&plane, res.chord_mm, curved.then_some(&refiner))?;
    Ok(flat
        .tris
        .iter()
        .map(|t| {
            let x = t.map(|i| flat.xyz[i]);
            if sense > 0.0 {
                x
            } else {
                [x[0], x[2], x[1]]
            }
        })
        .collect())
}

/// The triangulation of a face's parameter plane.
type Cdt = ConstrainedDelaunayTriangulation<Vert>;

/// One scale from a face's parameters to the plane it is triangulated in, taken at the
/// mean of its bound points. Along a ruled surface's straight lines (a cylinder's or
/// cone's v) a triangle may be longer: the plane is squeezed along v so that Delaunay
/// triangles come out long and thin.
struct ParamScale {
    su: f64,
    sv: f64,
}

impl ParamScale {
    fn of(s: &Surf, polygons: &[Vec<Pt>]) -> ParamScale {
        let m = mean(&polygons.concat());
        let (su, mut sv) = s.scale(m[0], m[1]);
        if matches!(s, Surf::Cylinder(..) | Surf::Cone(..)) {
            sv /= RULED_STRETCH;
        }
        ParamScale { su, sv }
    }

    /// Parameters to the plane.
    fn scaled(&self, uv: [f64; 2]) -> [f64; 2] {
        [uv[0] * self.su, uv[1] * self.sv]
    }

    /// The plane to parameters.
    fn unscale(&self, q: [f64; 2]) -> [f64; 2] {
        [q[0] / self.su, q[1] / self.sv]
    }
}

/// A point of the scaled parameter plane as the triangulation takes it. spade refuses
/// coordinates below 1.8e-43 in magnitude but not 0 (`InsertionError::TooSmall`); a
/// parameter that small is rounding noise of a zero (MFCAD's files carry such values)
/// and becomes 0.
fn plane_point(q: [f64; 2]) -> Point2<f64> {
    let flush = |x: f64| if x.abs() < 1e-30 { 0.0 } else { x };
    Point2::new(flush(q[0]), flush(q[1]))
}

/// The constrained Delaunay triangulation of a face's bounds (`polygons`) in its
/// scaled parameter plane, every bound segment a constraint; an error when a point
/// cannot be inserted or bounds cross.
fn bounds_triangulation(polygons: &[Vec<Pt>], scale: &ParamScale) -> Result<Cdt, String> {
    let mut cdt: Cdt = ConstrainedDelaunayTriangulation::new();
    for poly in polygons {
        let mut handles = Vec::new();
        for p in poly {
            let q = scale.scaled(p.uv);
            let h = cdt
                .insert(Vert {
                    pos: plane_point(q),
                    xyz: p.xyz,
                })
                .map_err(|e| format!("a bound point cannot be triangulated ({e:?})"))?;
            if handles.last() != Some(&h) {
                handles.push(h);
            }
        }
        if handles.len() > 1 && handles[0] == handles[handles.len() - 1] {
            handles.pop();
        }
        for k in 0..handles.len() {
            let (a, b) = (handles[k], handles[(k + 1) % handles.len()]);
            if a != b && !cdt.exists_constraint(a, b) && cdt.try_add_constraint(a, b).is_empty() {
                return Err(
                    "its bounds cross each other in the surface's parameters (a self-intersecting \
                     or mis-oriented loop)"
                        .into(),
                );
            }
        }
    }
    Ok(cdt)
}

/// Refines a curved face: round by round, adds a point in every triangle that strays
/// from the surface or turns too much ([`refinement_points`]), until none does, after
/// 24 rounds, or with an error past 200,000 points.
fn refine(cdt: &mut Cdt, s: &Surf, scale: &ParamScale, res: Resolution) -> Result<(), String> {
    let mut budget = MAX_FACE_POINTS;
    // Triangles (by their corners) already found close enough: a later round
    // leaves most of them as they are.
    let mut good: std::collections::HashSet<[usize; 3]> = std::collections::HashSet::new();
    for _round in 0..24 {
        let add = refinement_points(cdt, s, scale, res, &mut good);
        if add.is_empty() {
            break;
        }
        if add.len() > budget {
            return Err(format!(
                "it needs more than {MAX_FACE_POINTS} points inside to meet the chord tolerance"
            ));
        }
        budget -= add.len();
        for c in add {
            let uv = scale.unscale(c);
            let xyz = s.eval(uv[0], uv[1]);
            cdt.insert(Vert {
                pos: plane_point(c),
                xyz,
            })
            .map_err(|e| format!("an inner point cannot be triangulated ({e:?})"))?;
        }
    }
    Ok(())
}

/// One round's points to add: in each triangle inside the bounds, not yet found `good`,
/// that strays ([`strays`]), the middle of its longest edge where that is not a bound
/// (a Delaunay refinement keeps triangles well shaped), else its centroid. Triangles
/// close enough join `good`.
fn refinement_points(
    cdt: &Cdt,
    s: &Surf,
    scale: &ParamScale,
    res: Resolution,
    good: &mut std::collections::HashSet<[usize; 3]>,
) -> Vec<[f64; 2]> {
    let mut add = Vec::new();
    let inside = inside_faces(cdt);
    for f in cdt.inner_faces() {
        if !inside[f.fix().index()] {
            continue;
        }
        let mut key = f.vertices().map(|v| v.fix().index());
        key.sort_unstable();
        if good.contains(&key) {
            continue;
        }
        let vs = f.vertices();
        let q = vs.map(|v| [v.position().x, v.position().y]);
        let c = [
            (q[0][0] + q[1][0] + q[2][0]) / 3.0,
            (q[0][1] + q[1][1] + q[2][1]) / 3.0,
        ];
        let x = vs.map(|v| v.data().xyz);
        if (x[1] - x[0]).cross(&(x[2] - x[0])).norm() < 1e-12 {
            // Two corners on one pole: nothing to refine.
            continue;
        }
        if !strays(s, scale, res, (q, c), x) {
            good.insert(key);
        } else {
            let es = f.adjacent_edges();
            let longest = es
                .iter()
                .max_by(|a, b| a.length_2().total_cmp(&b.length_2()))
                .filter(|e| !e.is_constraint_edge());
            let at = match longest {
                Some(e) => {
                    let [a, b] = e.positions();
                    [(a.x + b.x) / 2.0, (a.y + b.y) / 2.0]
                }
                None => c,
            };
            // A point that lands on a corner in space (a sliver along a seam, where
            // the parameter plane is wider than the surface) would be welded into it
            // and fold the mesh: the triangle is as fine as it gets.
            let uv = scale.unscale(at);
            let p = s.eval(uv[0], uv[1]);
            if x.iter().any(|corner| (corner - p).norm() < MIN_SPACING_MM) {
                good.insert(key);
            } else {
                add.push(at);
            }
        }
    }
    add
}

/// Whether a triangle (corners `q` in the scaled plane, centroid `c` there, points `x`)
/// strays from the surface: its centroid or an edge's midpoint farther from it than the
/// chord tolerance, or the surface's normal turning across it by more than the angle
/// limit.
fn strays(
    s: &Surf,
    scale: &ParamScale,
    res: Resolution,
    (q, c): ([[f64; 2]; 3], [f64; 2]),
    x: [P3; 3],
) -> bool {
    // The chord error: how far the flat triangle's centroid and edge
    // midpoints lie from the surface.
    let off = |flat: P3, at: [f64; 2]| {
        let uv = scale.unscale(at);
        s.distance(&flat, (uv[0], uv[1]))
    };
    let flat = P3::from((x[0].coords + x[1].coords + x[2].coords) / 3.0);
    let mut far = off(flat, c) > res.chord_mm;
    if !far {
        for k in 0..3 {
            let m = [
                (q[k][0] + q[(k + 1) % 3][0]) / 2.0,
                (q[k][1] + q[(k + 1) % 3][1]) / 2.0,
            ];
            let mid = P3::from((x[k].coords + x[(k + 1) % 3].coords) / 2.0);
            if off(mid, m) > res.chord_mm {
                far = true;
                break;
            }
        }
    }
    if !far {
        let n: Vec<Option<V3>> = (0..3)
            .map(|k| {
                let uv = scale.unscale(q[k]);
                s.normal(&x[k], uv[0], uv[1])
            })
            .collect();
        if let (Some(a), Some(b), Some(c2)) = (n[0], n[1], n[2]) {
            far = a.angle(&b) > res.angle_rad
                || b.angle(&c2) > res.angle_rad
                || a.angle(&c2) > res.angle_rad;
        }
    }
    far
}

/// The triangles inside the bounds, counter-clockwise from outside: along the natural
/// normal where `sense` is positive; an error when none lies inside.
fn inside_triangles(cdt: &Cdt, sense: f64) -> Result<Vec<[P3; 3]>, String> {
    let mut out = Vec::new();
    let inside = inside_faces(cdt);
    for f in cdt.inner_faces() {
        if !inside[f.fix().index()] {
            continue;
        }
        let vs = f.vertices();
        let q = vs.map(|v| [v.position().x, v.position().y]);
        let area2 =
            (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]);
        let x = vs.map(|v| v.data().xyz);
        // Counter-clockwise in the (scaled) parameters is along the natural normal.
        if area2 * sense > 0.0 {
            out.push([x[0], x[1], x[2]]);
        } else {
            out.push([x[0], x[2], x[1]]);
        }
    }
    if out.is_empty() {
        return Err("no triangle lies inside its bounds".into());
    }
    Ok(out)
}

/// Which faces of the triangulation lie inside the bounds, by face index: a face is
/// inside when every path to the outer face crosses an odd number of bound edges
/// (a breadth-first search that counts crossings). Unlike a point-in-polygon test at a
/// centroid, this holds for the slivers between nearly collinear bound points.
fn inside_faces(cdt: &ConstrainedDelaunayTriangulation<Vert>) -> Vec<bool> {
    let n = cdt.num_all_faces();
    let mut depth = vec![usize::MAX; n];
    let mut queue = std::collections::VecDeque::new();
    depth[0] = 0;
    // Faces on the hull first: entered from the outer face.
    for f in cdt.inner_faces() {
        for e in f.adjacent_edges() {
            if e.rev().face().is_outer() {
                let d = usize::from(e.is_constraint_edge());
                let i = f.fix().index();
                if d < depth[i] {
                    depth[i] = d;
                    if d == 0 {
                        queue.push_front(i);
                    } else {
                        queue.push_back(i);
                    }
                }
            }
        }
    }
    // Fixed handles by index (spade numbers the outer face 0, inner faces from 1).
    let mut handle = vec![None; n];
    for f in cdt.inner_faces() {
        handle[f.fix().index()] = Some(f.fix());
    }
    while let Some(i) = queue.pop_front() {
        let Some(h) = handle[i] else { continue };
        let f = cdt.face(h);
        for e in f.adjacent_edges() {
            let g = e.rev().face();
            if g.is_outer() {
                continue;
            }
            let j = g.fix().index();
            let d = depth[i] + usize::from(e.is_constraint_edge());
            if d < depth[j] {
                depth[j] = d;
                if d == depth[i] {
                    queue.push_front(j);
                } else {
                    queue.push_back(j);
                }
            }
        }
    }
    depth
        .iter()
        .map(|d| *d != usize::MAX && d % 2 == 1)
        .collect()
}

/// A triangulation vertex: its scaled parameters and its 3D point.
#[derive(Debug, Clone, Copy)]
struct Vert {
    pos: Point2<f64>,
    xyz: P3,
}

impl HasPosition for Vert {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.pos
    }
}

/// A bound's points in the parameter plane, unwrapped along the loop. A point at a
/// pole (where u is undefined) becomes two, with the u of the points before and after
/// it: the bound runs along the pole between them. A bound through a pole starts there,
/// so that the pole segment closes it and it goes round zero times in u.
fn param_loop(
    s: &Surf,
    pts: &[P3],
    periods: [Option<f64>; 2],
    hint: &mut Option<(f64, f64)>,
) -> Loop {
    let n = pts.len();
    let mut raw: Vec<(f64, f64)> = pts
        .iter()
        .map(|p| {
            let uv = s.param(p, *hint);
            if s.takes_hint() {
                *hint = Some(uv);
            }
            uv
        })
        .collect();
    let mut pts = pts.to_vec();
    let pole: Vec<bool> = pts
        .iter()
        .zip(&raw)
        .map(|(p, uv)| s.at_pole(p, uv.1))
        .collect();
    let first_pole = pole.iter().position(|&b| b);
    let mut pole = pole;
    if let Some(k) = first_pole {
        raw.rotate_left(k);
        pts.rotate_left(k);
        pole.rotate_left(k);
    }
    let unwrap = |uv: (f64, f64), prev: Option<[f64; 2]>| {
        let mut q = [uv.0, uv.1];
        if let Some(pr) = prev {
            for (k, per) in periods.iter().enumerate() {
                if let Some(per) = per {
                    q[k] = unwrap_near(q[k], pr[k], *per);
                }
            }
        }
        q
    };
    let mut out: Vec<Pt> = Vec::new();
    let mut prev: Option<[f64; 2]> = None;
    for i in 0..n {
        if !pole[i] {
            let q = unwrap(raw[i], prev);
            out.push(Pt { uv: q, xyz: pts[i] });
            prev = Some(q);
            continue;
        }
        let v = raw[i].1;
        if let Some(pr) = prev {
            out.push(Pt {
                uv: [pr[0], v],
                xyz: pts[i],
            });
        }
        if let Some(j) = (i + 1..n).find(|&j| !pole[j]) {
            let u = unwrap(raw[j], prev)[0];
            if let Some(pr) = prev {
                along_pole(&mut out, pr[0], u, v, pts[i]);
            }
            let q = [u, v];
            out.push(Pt { uv: q, xyz: pts[i] });
            prev = Some(q);
        }
    }
    if first_pole.is_some() {
        // The pole again, with the last point's u: the segment back to the start runs
        // along the pole.
        if let (Some(last), Some(first)) =
            (out.last().map(|p| p.uv[0]), out.first().map(|p| p.uv[0]))
        {
            out.push(Pt {
                uv: [last, raw[0].1],
                xyz: pts[0],
            });
            along_pole(&mut out, last, first, raw[0].1, pts[0]);
        }
    }
    dedup(&mut out);
    // How many times the loop goes round: the step from the last point back to the first.
    let mut wraps = [0i64; 2];
    if let (Some(first), Some(last)) = (out.first(), out.last()) {
        for (k, per) in periods.iter().enumerate() {
            if let Some(per) = per {
                if k == 0 && first_pole.is_some() {
                    continue;
                }
                let back = unwrap_near(first.uv[k], last.uv[k], *per);
                wraps[k] = ((back - first.uv[k]) / per).round() as i64;
            }
        }
    }
    Loop { pts: out, wraps }
}

/// Points along a pole from `u0` to `u1` (both ends left out), a tenth of a radian
/// apart: the triangles that meet the pole stay narrow, so that refinement near it ends.
fn along_pole(out: &mut Vec<Pt>, u0: f64, u1: f64, v: f64, xyz: P3) {
    let n = ((u1 - u0).abs() / 0.1).ceil().min(10_000.0) as usize;
    for k in 1..n {
        out.push(Pt {
            uv: [u0 + (u1 - u0) * k as f64 / n as f64, v],
            xyz,
        });
    }
}

/// Drops repeated points and spikes (a segment walked out and straight back, as a seam
/// edge used twice next to a pole), in one pass: each point is pushed on a stack that
/// drops a repeat of its top and folds a spike back to its base; the ends are then
/// joined round the loop the same way.
fn dedup(pts: &mut Vec<Pt>) {
    let same =
        |a: &Pt, b: &Pt| (a.uv[0] - b.uv[0]).abs() < 1e-12 && (a.uv[1] - b.uv[1]).abs() < 1e-12;
    let mut out: Vec<Pt> = Vec::with_capacity(pts.len());
    for p in pts.drain(..) {
        if out.last().is_some_and(|l| same(l, &p)) {
            continue;
        }
        if out.len() >= 2 && same(&out[out.len() - 2], &p) {
            // a → b → a: drop b; the a on the stack stands for both.
            out.pop();
            continue;
        }
        out.push(p);
    }
    // Round the join: the last point repeating the first, or a spike across it.
    loop {
        let n = out.len();
        if n <= 2 {
            break;
        }
        if same(&out[n - 1], &out[0]) {
            out.pop();
        } else if n > 3 && same(&out[n - 2], &out[0]) {
            out.truncate(n - 2);
        } else if n > 3 && same(&out[n - 1], &out[1]) {
            out.pop();
            out.remove(0);
        } else {
            break;
        }
    }
    *pts = out;
}

/// Turns the face's loops into closed polygons of the parameter plane: ordinary loops
/// shifted by whole periods next to the first loop, two loops going round joined by a
/// cut, one loop going round closed at the pole on the face's side.
fn close_loops(
    s: &Surf,
    loops: Vec<Loop>,
    periods: [Option<f64>; 2],
    sense: f64,
    res: Resolution,
) -> Result<Vec<Vec<Pt>>, String> {
    let (round, plain): (Vec<Loop>, Vec<Loop>) = loops.into_iter().partition(|l| l.wraps != [0, 0]);
    let mut polygons: Vec<Vec<Pt>> = Vec::new();
    match round.len() {
        0 => {}
        1 => polygons.push(closed_at_pole(s, &round[0], periods, sense)?),
        2 => polygons.push(band(s, &round, periods, res)?),
        _ => return Err(format!("{} bounds go round the surface", round.len())),
    }
    // Ordinary loops: shift each next to the first polygon (or the first of them).
    let anchor = polygons
        .first()
        .map(|p| mean(p))
        .or_else(|| plain.first().map(|l| mean(&l.pts)))
        .unwrap_or([0.0, 0.0]);
    for l in plain {
        let m = mean(&l.pts);
        let mut shift = [0.0; 2];
        for (k, per) in periods.iter().enumerate() {
            if let Some(per) = per {
                shift[k] = unwrap_near(m[k], anchor[k], *per) - m[k];
            }
        }
        polygons.push(
            l.pts
                .iter()
                .map(|p| Pt {
                    uv: [p.uv[0] + shift[0], p.uv[1] + shift[1]],
                    xyz: p.xyz,
                })
                .collect(),
        );
    }
    Ok(polygons)
}

/// The polygon of a face bounded by one loop `l` that goes once round in u (a
/// spherical cap, a cone to its apex): the loop, then along the pole on the face's side
/// back to its start.
fn closed_at_pole(
    s: &Surf,
    l: &Loop,
    periods: [Option<f64>; 2],
    sense: f64,
) -> Result<Vec<Pt>, String> {
    if l.wraps[1] != 0 || l.wraps[0].abs() != 1 {
        return Err("a bound goes round the surface in a way inspc cannot close".into());
    }
    let dir = l.wraps[0] as f64;
    // The face lies left of its bounds seen from its normal: toward +v when the
    // loop runs toward +u along the natural normal.
    let toward = dir * sense;
    let pole = s
        .poles()
        .into_iter()
        .filter(|p| (p - l.pts[0].uv[1]) * toward > 0.0)
        .min_by(|a, b| {
            (a - l.pts[0].uv[1])
                .abs()
                .total_cmp(&(b - l.pts[0].uv[1]).abs())
        })
        .ok_or("a single bound goes round the surface and there is no pole to close it at")?;
    let mut poly = l.pts.clone();
    let first = poly[0];
    let per = periods[0].unwrap_or(TAU);
    let end_u = first.uv[0] + dir * per;
    let xyz_pole = s.eval(first.uv[0], pole);
    poly.push(Pt {
        uv: [end_u, first.uv[1]],
        xyz: first.xyz,
    });
    poly.push(Pt {
        uv: [end_u, pole],
        xyz: xyz_pole,
    });
    along_pole(&mut poly, end_u, first.uv[0], pole, xyz_pole);
    poly.push(Pt {
        uv: [first.uv[0], pole],
        xyz: xyz_pole,
    });
    Ok(poly)
}

/// The polygon of a band bounded by two loops (`round`) that each go once round (a
/// band of a bore with no seam edge): cut open along a curve between them, one loop
/// forward, the cut, the other loop backward, the cut back.
fn band(
    s: &Surf,
    round: &[Loop],
    periods: [Option<f64>; 2],
    res: Resolution,
) -> Result<Vec<Pt>, String> {
    let k = if round[0].wraps[0] != 0 { 0 } else { 1 };
    let per = periods[k].unwrap_or(TAU);
    if round
        .iter()
        .any(|l| l.wraps[k].abs() != 1 || l.wraps[1 - k] != 0)
    {
        return Err("two bounds go round the surface in different ways".into());
    }
    // Both loops made to run toward +k; the band is A forward, then B backward.
    let forward = |l: &Loop| {
        let mut p = l.pts.clone();
        if l.wraps[k] < 0 {
            p.reverse();
        }
        p
    };
    let a = forward(&round[0]);
    let mut b = forward(&round[1]);
    // B starts where it is nearest A's start, shifted into A's period.
    let a0 = a[0].uv[k];
    let (start, _) = b
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let d = unwrap_near(p.uv[k], a0, per) - a0;
            (i, d.abs())
        })
        .min_by(|x, y| x.1.total_cmp(&y.1))
        .unwrap_or((0, 0.0));
    b.rotate_left(start);
    let mut b2 = Vec::with_capacity(b.len());
    let mut prev = a0;
    for p in &b {
        let mut q = *p;
        q.uv[k] = unwrap_near(q.uv[k], prev, per);
        prev = q.uv[k];
        b2.push(q);
    }
    // A: a[0] .. a[n-1], then a[0] again one period on; B likewise, walked back.
    // The cut from A's start to B's start is a curve on the surface (a
    // meridian of a torus, a profile of a revolved B-spline): it is cut into
    // segments like an edge, the same on both of its sides.
    let (from, to) = (a[0], b2[0]);
    let mut ts = vec![0.0];
    let at = |t: f64| {
        s.eval(
            from.uv[0] + (to.uv[0] - from.uv[0]) * t,
            from.uv[1] + (to.uv[1] - from.uv[1]) * t,
        )
    };
    refine_curve(&at, 0.0, 1.0, res, 0, &mut ts);
    let cut = |shift: f64, t: f64| {
        let mut uv = [
            from.uv[0] + (to.uv[0] - from.uv[0]) * t,
            from.uv[1] + (to.uv[1] - from.uv[1]) * t,
        ];
        uv[k] += shift;
        Pt { uv, xyz: at(t) }
    };
    let inner = &ts[1..ts.len() - 1];
    let mut poly = a.clone();
    let mut a_end = a[0];
    a_end.uv[k] += per;
    poly.push(a_end);
    poly.extend(inner.iter().map(|&t| cut(per, t)));
    let mut b_end = b2[0];
    b_end.uv[k] += per;
    poly.push(b_end);
    poly.extend(b2.iter().rev().copied());
    poly.extend(inner.iter().rev().map(|&t| cut(0.0, t)));
    Ok(poly)
}

fn mean(pts: &[Pt]) -> [f64; 2] {
    let n = pts.len().max(1) as f64;
    let (mut u, mut v) = (0.0, 0.0);
    for p in pts {
        u += p.uv[0];
        v += p.uv[1];
    }
    [u / n, v / n]
}

#[cfg(test)]
mod sense_tests {
    use super::*;

    /// The rule [`bound_sense`] rests on, checked on real files: a STEP face's stated
    /// sense is the one its bounds give wherever they can tell.
    #[test]
    fn bounds_give_each_step_face_its_stated_sense() {
        for part in ["ctc_01", "ftc_06", "ftc_08"] {
            let path = format!("../shared/parts/nist_{part}_asme1_ap242-e1.stp");
            let Ok(bytes) = std::fs::read(&path) else {
                panic!("{path}: the NIST parts are expected beside the repository");
            };
            let f = super::super::p21::parse(&bytes).unwrap();
            let b = super::super::brep::read(&f).unwrap();
            let edges = edge_polylines(&b, super::super::RESOLUTION).unwrap();
            let mut told = 0;
            for (i, face) in b.faces.iter().enumerate() {
                if let Some(s) = bound_sense(face, &edges) {
                    assert_eq!(s, face.same_sense, "{part}: face_{}", i + 1);
                    told += 1;
                }
            }
            assert!(
                told * 10 >= b.faces.len() * 9,
                "{part}: {told} of {}",
                b.faces.len()
            );
        }
    }

    /// The end faces of a ring whose wall is thinner than the chord: their bounds'
    /// chords cross, Delaunay refuses them, and the fallback meshes them with their
    /// area (π (21² − 20²) mm²).
    #[test]
    fn crossing_bounds_fall_back_to_chords_moved_apart() {
        let bytes = std::fs::read("tests/cad/thin_wall.stp").unwrap();
        let f = super::super::p21::parse(&bytes).unwrap();
        let b = super::super::brep::read(&f).unwrap();
        let res = super::super::RESOLUTION;
        let edges = edge_polylines(&b, res).unwrap();
        let mut planes = 0;
        for face in b
            .faces
            .iter()
            .filter(|f| matches!(f.surface, Surf::Plane(_)))
        {
            let s = &face.surface;
            let loops = face_loops(face, &edges).unwrap();
            let sense = if face.same_sense { 1.0 } else { -1.0 };
            let periods = [s.u_period(), s.v_period()];
            let polygons = close_loops(s, loops, periods, sense, res).unwrap();
            let scale = ParamScale::of(s, &polygons);
            let why = delaunay(s, &polygons, &scale, sense, res).unwrap_err();
            assert!(why.contains("cross"), "{why}");

            let area: f64 = face_mesh(face, &edges, res)
                .unwrap()
                .iter()
                .map(|t| 0.5 * (t[1] - t[0]).cross(&(t[2] - t[0])).norm())
                .sum();
            let exact = std::f64::consts::PI * (21.0f64.powi(2) - 20.0f64.powi(2));
            assert!(
                (area - exact).abs() < 0.01 * exact,
                "{area} against {exact}"
            );
            planes += 1;
        }
        assert_eq!(planes, 2);
    }
}
