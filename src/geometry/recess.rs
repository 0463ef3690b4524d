//! How deep a plane face lies in a recess: the floor of a pocket or a blind hole, walled
//! on every side, which a probe can only reach straight down its opening.
//!
//! The floor of a pocket 57 mm deep and 17 mm across is touched by a stylus that stands
//! in the pocket along its axis: whatever part of the probe is still below the opening
//! (the stem, an extension, the body) must keep clear of the walls, so the floor's points
//! keep that part's radius from its edges, not only the tip's (`sample`), and an imported
//! part's rack carries a probe long enough for its deepest floor (`import`).
//!
//! The measure is a plain ray test on the mesh: from a point of the face, up its normal,
//! the face is in a recess as long as eight rays across the normal all meet the part
//! within the floor's own reach;
//! the recess ends at the first height where one escapes. A face whose normal meets the
//! part above it (under an overhang) is not a recess floor, nor is one wider than its
//! recess is deep: there the probe leans away from the walls.

use super::query::line_triangle;
use super::{P3, V3};

/// Heights tried up a face's normal: one every `STEP_MM`, at most `MAX_STEPS` of them
/// (the step grows on a tall part).
const STEP_MM: f64 = 2.0;
const MAX_STEPS: usize = 64;
/// Directions across the normal whose rays must all meet a wall.
const RAYS: usize = 8;

/// The depth (mm) of the narrow recess whose floor is the plane face made of `own`
/// triangles with outward normal `normal`: how far up the normal the face stays walled
/// on every side. `None` when the face is not walled just above itself, its normal meets
/// the part, or the recess is wider than it is deep (the floor's width taken as twice
/// its farthest corner from the point tested).
pub fn recess_depth(
    vertices: &[P3],
    triangles: &[[u32; 3]],
    own: &[u32],
    normal: &V3,
) -> Option<f64> {
    let n = normal.try_normalize(1e-12)?;
    let start = point_on(vertices, triangles, own)?;
    let (lo, hi) = bounds(vertices)?;
    let exit = box_exit(&lo, &hi, &start, &n)?;
    let hits = |o: &P3, d: &V3, reach: f64| {
        triangles.iter().any(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            line_triangle(o, d, &a, &b, &c).is_some_and(|s| s > 1e-6 && s < reach)
        })
    };
    if hits(&(start + n * 1e-6), &n, exit) {
        return None;
    }
    let (u, v) = across(&n);
    // The walls stand at the floor's edges: material farther than the floor reaches
    // (a boss across an open plate) does not wall it in.
    let reach = own
        .iter()
        .flat_map(|&t| triangles[t as usize])
        .map(|i| (vertices[i as usize] - start).norm())
        .fold(0.0, f64::max)
        + 1.0;
    let walled = |h: f64| {
        let o = start + n * h;
        (0..RAYS).all(|k| {
            let a = std::f64::consts::TAU * k as f64 / RAYS as f64;
            hits(&o, &(u * a.cos() + v * a.sin()), reach)
        })
    };
    let step = STEP_MM.max(exit / MAX_STEPS as f64);
    let mut depth = None;
    let mut h = step.min(exit) / 2.0;
    while h < exit && walled(h) {
        depth = Some(h);
        h += step;
    }
    // The opening lies between the last walled height and the next: halve the gap.
    if let Some(mut low) = depth {
        let mut high = h.min(exit);
        for _ in 0..5 {
            let mid = (low + high) / 2.0;
            if walled(mid) {
                low = mid;
            } else {
                high = mid;
            }
        }
        depth = Some(low);
    }
    // A recess wider than it is deep lets the probe lean away from its walls.
    let width = 2.0 * (reach - 1.0);
    depth.filter(|&d| d >= width)
}

/// A point on the face: the centroid of its triangle nearest the face's centroid.
fn point_on(vertices: &[P3], triangles: &[[u32; 3]], own: &[u32]) -> Option<P3> {
    let centroid_of = |t: u32| {
        let [a, b, c] = triangles[t as usize].map(|i| vertices[i as usize].coords);
        P3::from((a + b + c) / 3.0)
    };
    let n = own.len() as f64;
    let mean = P3::from(own.iter().map(|&t| centroid_of(t).coords).sum::<V3>() / n);
    own.iter()
        .map(|&t| centroid_of(t))
        .min_by(|a, b| (a - mean).norm().total_cmp(&(b - mean).norm()))
}

/// How far from `p` along unit `d` the ray leaves the box from `lo` to `hi`.
pub(crate) fn box_exit(lo: &P3, hi: &P3, p: &P3, d: &V3) -> Option<f64> {
    (0..3)
        .filter(|&i| d[i].abs() > 1e-9)
        .map(|i| {
            let wall = if d[i] > 0.0 { hi[i] } else { lo[i] };
            (wall - p[i]) / d[i]
        })
        .min_by(f64::total_cmp)
}

fn bounds(vertices: &[P3]) -> Option<(P3, P3)> {
    let first = *vertices.first()?;
    Some(
        vertices
            .iter()
            .fold((first, first), |(lo, hi), v| (lo.inf(v), hi.sup(v))),
    )
}

/// Two unit vectors square to `n` and to each other.
pub(crate) fn across(n: &V3) -> (V3, V3) {
    let seed = if n.x.abs() < 0.9 { V3::x() } else { V3::y() };
    let u = n.cross(&seed).normalize();
    (u, n.cross(&u))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 100 mm cube with a square pocket `w` wide and `d` deep in its top, as triangles
    /// (two per quad), and the floor's triangle indices.
    fn pocket(w: f64, d: f64) -> (Vec<P3>, Vec<[u32; 3]>, Vec<u32>) {
        let mut v = Vec::new();
        let mut t = Vec::new();
        let mut quad = |q: [P3; 4]| {
            let k = v.len() as u32;
            v.extend(q);
            t.push([k, k + 1, k + 2]);
            t.push([k, k + 2, k + 3]);
            t.len() as u32 - 2
        };
        let (a, b) = (50.0 - w / 2.0, 50.0 + w / 2.0);
        let z = 100.0 - d;
        let floor = quad([
            P3::new(a, a, z),
            P3::new(b, a, z),
            P3::new(b, b, z),
            P3::new(a, b, z),
        ]);
        // The pocket's four walls and the cube's bottom; the top ring is left out (a ray
        // up the floor's normal leaves through the opening either way).
        let corners = [(a, a), (b, a), (b, b), (a, b)];
        for k in 0..4 {
            let ((x0, y0), (x1, y1)) = (corners[k], corners[(k + 1) % 4]);
            quad([
                P3::new(x0, y0, z),
                P3::new(x1, y1, z),
                P3::new(x1, y1, 100.0),
                P3::new(x0, y0, 100.0),
            ]);
        }
        quad([
            P3::new(0.0, 0.0, 0.0),
            P3::new(100.0, 0.0, 0.0),
            P3::new(100.0, 100.0, 0.0),
            P3::new(0.0, 100.0, 0.0),
        ]);
        (v, t, vec![floor, floor + 1])
    }

    #[test]
    fn a_pocket_floor_is_as_deep_as_the_pocket() {
        let (v, t, floor) = pocket(17.0, 57.0);
        let depth = recess_depth(&v, &t, &floor, &V3::z()).unwrap();
        assert!((depth - 57.0).abs() <= 0.1, "{depth}");
    }

    #[test]
    fn the_cube_bottom_and_an_overhung_face_are_not_recesses() {
        let (v, t, _) = pocket(17.0, 57.0);
        let bottom = [t.len() as u32 - 2, t.len() as u32 - 1];
        assert_eq!(recess_depth(&v, &t, &bottom, &-V3::z()), None);
        // The floor read as facing down: the cube's bottom lies under it.
        let (v, t, floor) = pocket(17.0, 57.0);
        assert_eq!(recess_depth(&v, &t, &floor, &-V3::z()), None);
    }
}
