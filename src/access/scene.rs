//! The obstacle a cone is computed against: the part's triangles (and the table, once a
//! setup places one), with what culling needs, and a parry mesh for exact queries.
//!
//! The bounding-volume hierarchy ([`Bvh`]): median splits, four triangles a leaf, per
//! node a box, a ball holding its triangles' balls and, on a closed mesh, a cone of
//! normals; triangles over a quarter of the scene (a table) are kept apart and drawn
//! first.
//!
//! **Decision: capsules and cylinders decided by our own tests.** parry 0.25's
//! capsule–triangle intersection test answers "no" for about 1 in 1,500 pairs with a
//! corner well inside the capsule (either order of the shapes; tested), so `meets_axis`
//! decides a capsule by the exact segment–triangle distance and a cylinder's triangles
//! with a corner inside, or wholly past an end's plane, itself; only a cylinder
//! crossing a triangle with no corner inside still rests on parry's test. `meets` asks
//! parry only about triangles near the shape's core (its axis, or a swept
//! parallelogram), posed as parry's own mesh test poses them, so its answers are
//! parry's.

use crate::geometry::{PartGeometry, P3, V3};
use parry3d_f64::bounding_volume::BoundingVolume;
use parry3d_f64::math::Isometry;
use parry3d_f64::query::{DefaultQueryDispatcher, PointQuery, QueryDispatcher, Ray, RayCast};
use parry3d_f64::shape::{Shape, TriMesh};

/// One obstacle triangle.
#[derive(Debug, Clone)]
pub struct Tri {
    /// Corners, counter-clockwise seen from outside.
    pub v: [P3; 3],
    /// Outward unit normal; zero for a degenerate triangle.
    pub normal: V3,
    /// Centre and radius of a sphere around it.
    pub centre: P3,
    /// Radius of that sphere.
    pub radius: f64,
    /// Whether it bounds a closed solid, so that it can be culled when facing away.
    pub closed: bool,
}

/// The obstacle. Cloning shares its triangles and hierarchy.
#[derive(Clone)]
pub struct Scene {
    /// Its triangles (shared with the scenes [`Scene::above`] makes of it).
    pub tris: std::sync::Arc<Vec<Tri>>,
    /// Where the backends' drawing skips what lies wholly under a plane: the plane's
    /// point, unit normal and the height above it a triangle must reach to be drawn.
    pub floor: Option<(P3, V3, f64)>,
    /// Whether the part's mesh is closed (every edge shared by exactly two triangles).
    pub closed: bool,
    /// The diagonal of its bounds (mm).
    pub size: f64,
    /// Shared with the scenes [`Scene::above`] makes of it.
    mesh: Option<std::sync::Arc<TriMesh>>,
    /// The triangles' bounding-volume hierarchy, for the backends' drawing.
    pub bvh: std::sync::Arc<Bvh>,
}

impl Scene {
    /// The part as obstacle.
    pub fn of_part(g: &PartGeometry) -> Scene {
        let edges = crate::geometry::edge_triangles(&g.triangles);
        let closed = edges.values().all(|users| users.len() == 2);
        let tris = g
            .triangles
            .iter()
            .map(|t| make_tri(t.map(|i| g.vertices[i as usize]), closed))
            .collect();
        Scene::new(tris, closed)
    }

    /// A scene of free triangles (nothing is culled), as for tests.
    pub fn of_triangles(tris: &[[P3; 3]]) -> Scene {
        Scene::new(tris.iter().map(|&t| make_tri(t, false)).collect(), false)
    }

    fn new(tris: Vec<Tri>, closed: bool) -> Scene {
        let (mut lo, mut hi) = (P3::origin(), P3::origin());
        for (k, t) in tris.iter().flat_map(|t| t.v.iter()).enumerate() {
            if k == 0 {
                (lo, hi) = (*t, *t);
            }
            lo = lo.inf(t);
            hi = hi.sup(t);
        }
        let vertices: Vec<P3> = tris.iter().flat_map(|t| t.v).collect();
        let indices: Vec<[u32; 3]> = (0..tris.len() as u32)
            .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
            .collect();
        let mesh = if tris.is_empty() {
            None
        } else {
            TriMesh::new(vertices, indices)
                .ok()
                .map(std::sync::Arc::new)
        };
        let size = (hi - lo).norm();
        Scene {
            bvh: std::sync::Arc::new(Bvh::new(&tris, size)),
            tris: std::sync::Arc::new(tris),
            floor: None,
            closed,
            size,
            mesh,
        }
    }

    /// The scene with a table under the part: the plane through `point` with upward
    /// normal `up`, a square reaching well past the part. Its triangles are never culled.
    pub fn with_table(&self, point: &P3, up: &V3) -> Scene {
        let up = up.normalize();
        let (e1, e2) = crate::sample::perpendicular_basis(&up);
        let s = 4.0 * self.size.max(1.0);
        let c = |a: f64, b: f64| point + e1 * (a * s) + e2 * (b * s);
        let (p00, p10, p11, p01) = (c(-1.0, -1.0), c(1.0, -1.0), c(1.0, 1.0), c(-1.0, 1.0));
        let mut tris: Vec<Tri> = self.tris.as_ref().clone();
        tris.push(make_tri([p00, p10, p11], false));
        tris.push(make_tri([p00, p11, p01], false));
        Scene::new(tris, self.closed)
    }

    /// The scene for cones asked only where nothing wholly under the plane through
    /// `at` with unit normal `n`, offset by `height`, can reach: the backends' drawing
    /// skips those triangles ([`Scene::skips`]), so cones drawn on it are the whole
    /// scene's only there. Exact queries ([`Scene::cast_ray`], [`Scene::distance`])
    /// still answer for the whole scene. Shares the triangles and the mesh.
    pub fn above(&self, at: &P3, n: &V3, height: f64) -> Scene {
        Scene {
            tris: self.tris.clone(),
            floor: Some((*at, *n, height)),
            closed: self.closed,
            size: self.size,
            mesh: self.mesh.clone(),
            bvh: self.bvh.clone(),
        }
    }

    /// Whether drawing leaves out every triangle within `radius` of `centre`: the ball
    /// lies wholly under the floor, with a margin for rounding, so that [`Scene::skips`]
    /// leaves out each of them.
    #[inline]
    pub(crate) fn skips_ball(&self, centre: &P3, radius: f64) -> bool {
        self.floor.as_ref().is_some_and(|(at, n, h)| {
            let c = (centre - at).dot(n);
            c + radius < h - 1e-9 * (1.0 + h.abs() + c.abs() + radius)
        })
    }

    /// Whether drawing leaves `t` out: wholly under the floor (see [`Scene::above`]).
    #[inline]
    pub(crate) fn skips(&self, t: &Tri) -> bool {
        self.floor.as_ref().is_some_and(|(at, n, h)| {
            // The bounding sphere first: most triangles are decided by it.
            let c = (t.centre - at).dot(n);
            if c - t.radius >= *h {
                return false;
            }
            if c + t.radius < *h {
                return true;
            }
            t.v.iter().all(|v| (v - at).dot(n) < *h)
        })
    }

    /// The first hit of the ray `from + t·d` (t > 0, `d` unit), if within `max`.
    pub fn cast_ray(&self, from: &P3, d: &V3, max: f64) -> Option<f64> {
        let mesh = self.mesh.as_ref()?;
        mesh.cast_ray(&Isometry::identity(), &Ray::new(*from, *d), max, false)
    }

    /// Distance from a point to the nearest triangle.
    pub fn distance(&self, p: &P3) -> f64 {
        match &self.mesh {
            Some(m) => m.distance_to_point(&Isometry::identity(), p, false),
            None => f64::INFINITY,
        }
    }

    /// The parry mesh, for exact shape queries.
    pub fn mesh(&self) -> Option<&TriMesh> {
        self.mesh.as_deref()
    }

    /// Whether `shape` at `pos`, which lies within `radius` of the triangles `core`,
    /// meets the mesh: what `intersection_test(pos, shape, identity, mesh)` answers —
    /// parry's traversal of the boxes that meet the shape's, and its test of each
    /// triangle, posed as there — asked only of the triangles whose balls come within
    /// `radius` of the core: most of those a long, slanted shape's box overlaps are far
    /// from the shape. A segment is a triangle with two corners equal.
    pub fn meets(
        &self,
        shape: &dyn Shape,
        pos: &Isometry<f64>,
        core: &[[P3; 3]],
        radius: f64,
    ) -> bool {
        self.meets_deciding(shape, pos, core, radius, |_| None)
    }

    /// [`Scene::meets`] for the capsule (`flat` false) or cylinder (`flat`) of radius `r`
    /// whose axis runs from `a` to `b`, `shape` at `pos` being that solid, deciding
    /// triangles without parry's test where it can: a capsule by the exact distance from
    /// its axis; a cylinder misses a triangle wholly past either end's plane and meets
    /// one with a corner inside it (each by the margin). The others are tested as
    /// [`Scene::meets`] tests them.
    pub(crate) fn meets_axis(
        &self,
        (shape, pos): (&dyn Shape, &Isometry<f64>),
        a: &P3,
        b: &P3,
        r: f64,
        flat: bool,
    ) -> bool {
        let len = (b - a).norm();
        let margin = 1e-6 * (1.0 + self.size + r);
        if !(len > 0.0 && r > margin) {
            return self.meets(shape, pos, &[[*a, *b, *b]], r);
        }
        let d = (b - a) / len;
        let inner = (r - margin) * (r - margin);
        let decide = |t: &Tri| {
            if !flat {
                // A capsule meets a triangle exactly when the axis comes within r of it.
                let gap = segment_triangle_distance(a, b, &t.v);
                return if gap < r - margin {
                    Some(true)
                } else if gap > r + margin {
                    Some(false)
                } else {
                    None
                };
            }
            let s = t.v.map(|v| (v - a).dot(&d));
            if s.iter().all(|&x| x < -margin) || s.iter().all(|&x| x > len + margin) {
                return Some(false);
            }
            let inside = t.v.iter().zip(s).any(|(v, x)| {
                x > margin && x < len - margin && (v - a - d * x).norm_squared() < inner
            });
            inside.then_some(true)
        };
        self.meets_deciding(shape, pos, &[[*a, *b, *b]], r, decide)
    }

    /// [`Scene::meets`], asking `decide` of each triangle first: Some(answer) for a
    /// triangle it can answer for parry's test.
    fn meets_deciding(
        &self,
        shape: &dyn Shape,
        pos: &Isometry<f64>,
        core: &[[P3; 3]],
        radius: f64,
        decide: impl Fn(&Tri) -> Option<bool>,
    ) -> bool {
        let Some(mesh) = self.mesh() else {
            return false;
        };
        let margin = 1e-6 * (1.0 + self.size + radius);
        // A distance that is not a number (a core triangle degenerate in a way the
        // distance does not handle) counts as near.
        let near = |c: &P3, r: f64| {
            core.iter().any(|t| {
                let d = point_triangle_distance(c, t);
                d.is_nan() || d <= radius + r + margin
            })
        };
        // The shape's pose relative to each triangle, as parry's composite test makes it.
        let pose = pos.inv_mul(&Isometry::identity()).inverse();
        let bounds = shape.compute_aabb(&pose);
        mesh.bvh()
            .leaves(|node| node.aabb().intersects(&bounds))
            .any(|k| {
                let t = &self.tris[k as usize];
                near(&t.centre, t.radius)
                    && decide(t).unwrap_or_else(|| {
                        DefaultQueryDispatcher.intersection_test(&pose, &mesh.triangle(k), shape)
                            == Ok(true)
                    })
            })
    }
}

/// A bounding-volume hierarchy over a scene's triangles, so that drawing decides whole
/// groups of them at once: too far, under the floor, or hidden where the map is already
/// marked (`access::cpu`). Each node holds a box around its triangles' corners and a
/// ball around their bounding balls, so a test passed by the node's ball is passed by
/// each triangle's.
pub struct Bvh {
    /// Triangles larger than a quarter of the scene (a table), outside every node; drawn
    /// first, their large shadows hide the most.
    pub large: Vec<u32>,
    /// The nodes, the root first (none for a scene without other triangles).
    pub nodes: Vec<BvhNode>,
    /// Triangle indices; a leaf holds a range of them.
    pub order: Vec<u32>,
}

/// One node of a [`Bvh`].
pub struct BvhNode {
    /// The box around its triangles' corners.
    pub lo: P3,
    /// Its upper corner.
    pub hi: P3,
    /// A ball holding every triangle's bounding ball.
    pub centre: P3,
    /// Its radius.
    pub radius: f64,
    /// Its triangles' normals when all bound a closed solid and lie within 90° of one
    /// axis: the axis and the cosine and sine of the widest angle to it, so a viewpoint
    /// all of them face away from passes the node over.
    pub normals: Option<(V3, f64, f64)>,
    /// Inner node: its two children; leaf: none.
    pub kids: Option<(u32, u32)>,
    /// A leaf's triangles: `order[first..first + count]`.
    pub first: u32,
    /// How many (0 for an inner node).
    pub count: u32,
}

/// Most triangles in a leaf.
const LEAF: usize = 4;

impl Bvh {
    fn new(tris: &[Tri], size: f64) -> Bvh {
        let (large, mut order): (Vec<u32>, Vec<u32>) =
            (0..tris.len() as u32).partition(|&k| tris[k as usize].radius > size / 4.0);
        let mut nodes = Vec::new();
        if !order.is_empty() {
            let len = order.len();
            build(tris, &mut order, 0, len, &mut nodes);
        }
        Bvh {
            large,
            nodes,
            order,
        }
    }
}

/// Appends the node of `order[first..first + count]` (and its subtree), returning its
/// index. Splits at the median of the longest axis of the centres' box, ties by index,
/// so the tree is the same on every machine.
fn build(
    tris: &[Tri],
    order: &mut [u32],
    first: usize,
    count: usize,
    nodes: &mut Vec<BvhNode>,
) -> u32 {
    let ids = &mut order[first..first + count];
    let (mut lo, mut hi) = (tris[ids[0] as usize].v[0], tris[ids[0] as usize].v[0]);
    let (mut clo, mut chi) = (tris[ids[0] as usize].centre, tris[ids[0] as usize].centre);
    for &k in ids.iter() {
        let t = &tris[k as usize];
        for v in &t.v {
            lo = lo.inf(v);
            hi = hi.sup(v);
        }
        clo = clo.inf(&t.centre);
        chi = chi.sup(&t.centre);
    }
    let centre = P3::from((lo.coords + hi.coords) / 2.0);
    let radius = ids
        .iter()
        .map(|&k| (tris[k as usize].centre - centre).norm() + tris[k as usize].radius)
        .fold(0.0, f64::max)
        * (1.0 + 1e-12);
    let normals = if ids
        .iter()
        .all(|&k| tris[k as usize].closed && tris[k as usize].normal != V3::zeros())
    {
        let sum: V3 = ids.iter().map(|&k| tris[k as usize].normal).sum();
        let axis = sum.try_normalize(1e-9);
        axis.and_then(|a| {
            let cos = ids
                .iter()
                .map(|&k| tris[k as usize].normal.dot(&a))
                .fold(1.0, f64::min);
            (cos > 1e-6).then(|| (a, cos, (1.0 - cos * cos).max(0.0).sqrt()))
        })
    } else {
        None
    };
    let at = nodes.len();
    nodes.push(BvhNode {
        lo,
        hi,
        centre,
        radius,
        normals,
        kids: None,
        first: first as u32,
        count: count as u32,
    });
    if count > LEAF {
        let ext = chi - clo;
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        let half = count / 2;
        ids.select_nth_unstable_by(half, |&a, &b| {
            let (ca, cb) = (tris[a as usize].centre[axis], tris[b as usize].centre[axis]);
            ca.total_cmp(&cb).then(a.cmp(&b))
        });
        let left = build(tris, order, first, half, nodes);
        let right = build(tris, order, first + half, count - half, nodes);
        let node = &mut nodes[at];
        node.kids = Some((left, right));
        node.count = 0;
    }
    at as u32
}

fn make_tri(v: [P3; 3], closed: bool) -> Tri {
    let n = (v[1] - v[0]).cross(&(v[2] - v[0]));
    let len = n.norm();
    let scale = (v[1] - v[0])
        .norm_squared()
        .max((v[2] - v[0]).norm_squared());
    let normal = if len > 1e-12 * scale && len > 0.0 {
        n / len
    } else {
        V3::zeros()
    };
    let centre = P3::from((v[0].coords + v[1].coords + v[2].coords) / 3.0);
    let radius = v.iter().map(|p| (p - centre).norm()).fold(0.0, f64::max);
    Tri {
        v,
        normal,
        centre,
        radius,
        closed,
    }
}

/// The distance between the segments p1–q1 and p2–q2 (Ericson, *Real-Time Collision
/// Detection*, 5.1.9), degenerate segments included.
fn segment_segment_distance(p1: &P3, q1: &P3, p2: &P3, q2: &P3) -> f64 {
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.norm_squared(), d2.norm_squared(), d2.dot(&r));
    let tiny = 1e-24;
    let (s, t) = if a <= tiny && e <= tiny {
        (0.0, 0.0)
    } else if a <= tiny {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= tiny {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s = if denom > tiny * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    ((p1 + d1 * s) - (p2 + d2 * t)).norm()
}

/// The distance between the segment a–b and the triangle `t`: nought where the segment
/// pierces it, else the least of its ends' distances to the triangle and its distances
/// to the triangle's edges.
pub(crate) fn segment_triangle_distance(a: &P3, b: &P3, t: &[P3; 3]) -> f64 {
    let d = b - a;
    if d.norm_squared() > 0.0 {
        if let Some(s) = crate::geometry::line_triangle(a, &d, &t[0], &t[1], &t[2]) {
            if (0.0..=1.0).contains(&s) {
                return 0.0;
            }
        }
    }
    let ends = point_triangle_distance(a, t).min(point_triangle_distance(b, t));
    (0..3).fold(ends, |m, k| {
        m.min(segment_segment_distance(a, b, &t[k], &t[(k + 1) % 3]))
    })
}

/// Distance from `p` to the triangle (Ericson, Real-Time Collision Detection 5.1.5).
pub(crate) fn point_triangle_distance(p: &P3, t: &[P3; 3]) -> f64 {
    let [a, b, c] = t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.norm();
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return bp.norm();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (p - (a + ab * v)).norm();
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return cp.norm();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (p - (a + ac * w)).norm();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (p - (b + (c - b) * w)).norm();
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (p - (a + ab * v + ac * w)).norm()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pseudo-random numbers in [0, 1) from `seed` (a 64-bit LCG): the same every run.
    fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    #[test]
    fn point_triangle_distances() {
        let t = [
            P3::new(0.0, 0.0, 0.0),
            P3::new(2.0, 0.0, 0.0),
            P3::new(0.0, 2.0, 0.0),
        ];
        let d = |x, y, z| point_triangle_distance(&P3::new(x, y, z), &t);
        assert!((d(0.5, 0.5, 3.0) - 3.0).abs() < 1e-12);
        assert!((d(-1.0, -1.0, 0.0) - 2f64.sqrt()).abs() < 1e-12);
        assert!((d(1.0, -2.0, 0.0) - 2.0).abs() < 1e-12);
        assert!((d(2.0, 2.0, 0.0) - 2f64.sqrt()).abs() < 1e-12);
    }

    /// `meets` answers what parry's test of the whole mesh answers, for capsules and
    /// posed cylinders, hitting and missing: its filter by the core never drops a
    /// triangle parry would find. `meets_axis` agrees with the exact distance for
    /// capsules and, for cylinders, with parry save where a corner is inside.
    #[test]
    fn meeting_the_mesh_is_parrys_answer() {
        use parry3d_f64::na::{Translation3, UnitQuaternion};
        use parry3d_f64::query::intersection_test;
        use parry3d_f64::shape::{Capsule, Cylinder};
        let mut next = uniform(11);
        let mut tris = Vec::new();
        for _ in 0..400 {
            let c = P3::new(100.0 * next(), 100.0 * next(), 20.0 * next());
            let corner = |c: &P3, r: &mut dyn FnMut() -> f64| {
                c + V3::new(r() - 0.5, r() - 0.5, r() - 0.5) * 8.0
            };
            tris.push([c, corner(&c, &mut next), corner(&c, &mut next)]);
        }
        let scene = Scene::of_triangles(&tris);
        let mesh = scene.mesh().expect("a mesh");
        let id = Isometry::identity();
        let (mut hits, mut misses) = (0, 0);
        for k in 0..3000 {
            let a = P3::new(
                120.0 * next() - 10.0,
                120.0 * next() - 10.0,
                60.0 * next() - 20.0,
            );
            let d = V3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
            let (len, r) = (80.0 * next(), 0.5 + 6.0 * next());
            let b = a + d * len;
            let core = [[a, b, b]];
            let (got, by_axis, want) = if k % 2 == 0 {
                let cap = Capsule::new(a, b, r);
                (
                    scene.meets(&cap, &id, &core, r),
                    scene.meets_axis((&cap, &id), &a, &b, r, false),
                    intersection_test(&id, &cap, &id, mesh).unwrap_or(true),
                )
            } else {
                let cyl = Cylinder::new(len / 2.0, r);
                let rot = UnitQuaternion::rotation_between(&V3::y(), &d).expect("a turn");
                let centre = a + d * (len / 2.0);
                let pos = Isometry::from_parts(Translation3::from(centre.coords), rot);
                (
                    scene.meets(&cyl, &pos, &core, r),
                    scene.meets_axis((&cyl, &pos), &a, &b, r, true),
                    intersection_test(&pos, &cyl, &id, mesh).unwrap_or(true),
                )
            };
            assert_eq!(got, want, "shape {k}");
            // parry's test misses a few triangles with a corner well inside the shape
            // (see `parrys_test_misses_triangles_with_a_corner_inside`); `meets_axis`
            // finds them, and agrees everywhere else.
            if k % 2 == 0 {
                // A capsule is decided by the exact distance from its axis.
                let gap = scene
                    .tris
                    .iter()
                    .map(|t| segment_triangle_distance(&a, &b, &t.v))
                    .fold(f64::INFINITY, f64::min);
                if (gap - r).abs() > 1e-3 {
                    assert_eq!(by_axis, gap < r, "capsule {k} by its axis");
                }
            } else {
                let sure = scene.tris.iter().any(|t| {
                    t.v.iter().any(|v| {
                        let x = (v - a).dot(&d);
                        x > 1e-3 && x < len - 1e-3 && (v - a - d * x).norm() < r - 1e-3
                    })
                });
                assert_eq!(by_axis, want || sure, "cylinder {k} by its axis");
            }
            if want {
                hits += 1;
            } else {
                misses += 1;
            }
        }
        assert!(hits > 50 && misses > 50, "{hits} hits, {misses} misses");
    }

    /// The segment–triangle distance is the least distance of points along the segment,
    /// sampled finely (never more than it, and within the sampling's step).
    #[test]
    fn segment_triangle_distance_is_the_sampled_least() {
        let mut uniform = uniform(3);
        let mut next = move || uniform() - 0.5;
        let mut pierced = 0;
        for _ in 0..2000 {
            let mut p = || P3::new(10.0 * next(), 10.0 * next(), 10.0 * next());
            let t = [p(), p(), p()];
            let (a, b) = (p(), p());
            let got = segment_triangle_distance(&a, &b, &t);
            let steps = 4000;
            let sampled = (0..=steps)
                .map(|i| point_triangle_distance(&(a + (b - a) * (i as f64 / steps as f64)), &t))
                .fold(f64::INFINITY, f64::min);
            let step = (b - a).norm() / steps as f64;
            assert!(got <= sampled + 1e-9, "{got} > {sampled}");
            assert!(sampled - got <= step + 1e-9, "{got} ≪ {sampled}");
            pierced += usize::from(got == 0.0);
        }
        assert!(pierced > 50, "{pierced}");
    }

    /// Why [`Scene::meets_axis`] decides a triangle with a corner inside the shape itself:
    /// parry's intersection test (0.25, either order of its shapes) answers "no" for a
    /// few capsule–triangle pairs where a corner lies well inside the capsule — a
    /// collision a validation would miss. `meets_axis` misses none.
    #[test]
    fn parrys_test_misses_triangles_with_a_corner_inside() {
        use parry3d_f64::query::intersection_test;
        use parry3d_f64::shape::{Capsule, Triangle};
        let mut next = uniform(5);
        let id = Isometry::identity();
        let (mut sure, mut parry_missed, mut missed) = (0, 0, 0);
        for _ in 0..60000 {
            let c = P3::new(10.0 * next(), 10.0 * next(), 10.0 * next());
            let mut corner = || c + V3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 8.0;
            let v = [corner(), corner(), corner()];
            let a = P3::new(10.0 * next(), 10.0 * next(), 10.0 * next());
            let d = V3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
            let len = 60.0 * next();
            let (b, r) = (a + d * len, 0.5 + 6.0 * next());
            let inside = v.iter().any(|p| {
                let x = (p - a).dot(&d).clamp(0.0, len);
                (p - a - d * x).norm() < r - 1e-3
            });
            if !inside {
                continue;
            }
            sure += 1;
            let cap = Capsule::new(a, b, r);
            let tri = Triangle::new(v[0], v[1], v[2]);
            if intersection_test(&id, &tri, &id, &cap) != Ok(true) {
                parry_missed += 1;
            }
            let scene = Scene::of_triangles(&[v]);
            if !scene.meets_axis((&cap, &id), &a, &b, r, false) {
                missed += 1;
            }
        }
        assert!(sure > 10000, "{sure}");
        assert_eq!(missed, 0, "meets_axis missed {missed} of {sure}");
        eprintln!("parry missed {parry_missed} of {sure} sure hits");
    }
}
