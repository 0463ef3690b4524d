//! The CPU backend: projects obstacle triangles onto the cube around a point and marks,
//! conservatively, every pixel their shadow touches.
//!
//! Central projection maps a triangle's straight edges to straight lines on each cube
//! face, so its shadow on a face is a convex polygon: the triangle clipped by the face's
//! pyramid (|u| ≤ w, |v| ≤ w), divided by w. Each pixel row takes the polygon clipped to
//! the row's strip and marks from its least to its greatest u: every pixel the shadow
//! touches, so a blocked direction is never reported free.

use super::cubemap::{Cell, CubeMap, Pixel};
use crate::geometry::{P3, V3};

/// Marks in `out` every direction d for which the ray `p + t·d`, t > 0, may meet the
/// triangle `tri`.
pub fn shadow_triangle(out: &mut CubeMap, p: &P3, tri: &[P3; 3]) {
    let q = tri.map(|v| v - p);
    for face in 0..6u8 {
        let a = (face / 2) as usize;
        let s = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
        let (ua, va) = ((a + 1) % 3, (a + 2) % 3);
        // (u, v, w) per vertex in the face's frame.
        let pts: Vec<[f64; 3]> = q.iter().map(|x| [x[ua], x[va], s * x[a]]).collect();
        // Quick reject: all vertices outside one side of the pyramid.
        let planes: [fn(&[f64; 3]) -> f64; 4] = [
            |x| x[2] - x[0],
            |x| x[2] + x[0],
            |x| x[2] - x[1],
            |x| x[2] + x[1],
        ];
        if planes.iter().any(|f| pts.iter().all(|x| f(x) < 0.0)) {
            continue;
        }
        let mut poly = pts;
        for f in planes {
            poly = clip(&poly, f);
            if poly.is_empty() {
                break;
            }
        }
        if poly.is_empty() {
            continue;
        }
        let scale = q.iter().map(|x| x.norm()).fold(0.0, f64::max);
        if poly.iter().any(|x| x[2] <= 1e-12 * scale.max(1e-300)) {
            // The triangle passes through the point: block the whole face.
            mark_rect(out, face, 0, out.n() - 1, 0, out.n() - 1);
            continue;
        }
        let flat: Vec<(f64, f64)> = poly.iter().map(|x| (x[0] / x[2], x[1] / x[2])).collect();
        raster_convex(out, face, &flat);
    }
}

/// Sutherland–Hodgman: the part of a convex polygon where `f ≥ 0`.
fn clip(poly: &[[f64; 3]], f: fn(&[f64; 3]) -> f64) -> Vec<[f64; 3]> {
    let mut out = Vec::with_capacity(poly.len() + 1);
    for k in 0..poly.len() {
        let (a, b) = (&poly[k], &poly[(k + 1) % poly.len()]);
        let (fa, fb) = (f(a), f(b));
        if fa >= 0.0 {
            out.push(*a);
        }
        if (fa >= 0.0) != (fb >= 0.0) {
            let t = fa / (fa - fb);
            out.push([
                a[0] + t * (b[0] - a[0]),
                a[1] + t * (b[1] - a[1]),
                a[2] + t * (b[2] - a[2]),
            ]);
        }
    }
    out
}

fn mark_rect(out: &mut CubeMap, face: u8, i0: u32, i1: u32, j0: u32, j1: u32) {
    for j in j0..=j1 {
        for i in i0..=i1 {
            out.set(Cell::Pixel(Pixel { face, i, j }), true);
        }
    }
}

/// Marks every pixel of a cube face that a convex polygon in (u, v) ∈ [−1, 1]² touches.
fn raster_convex(out: &mut CubeMap, face: u8, poly: &[(f64, f64)]) {
    let n = out.n();
    let h = 2.0 / n as f64;
    let cell = |x: f64| (((x + 1.0) / h).floor() as i64).clamp(0, n as i64 - 1) as u32;
    let (vmin, vmax) = poly
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.1), hi.max(p.1))
        });
    let (j0, j1) = (cell(vmin), cell(vmax));
    for j in j0..=j1 {
        let (lo, hi) = (-1.0 + j as f64 * h, -1.0 + (j + 1) as f64 * h);
        // The polygon's u extent over the strip lo ≤ v ≤ hi: at vertices inside the strip
        // and where edges cross its borders.
        let (mut umin, mut umax) = (f64::INFINITY, f64::NEG_INFINITY);
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            if a.1 >= lo && a.1 <= hi {
                umin = umin.min(a.0);
                umax = umax.max(a.0);
            }
            for border in [lo, hi] {
                if (a.1 - border) * (b.1 - border) < 0.0 {
                    let t = (border - a.1) / (b.1 - a.1);
                    let u = a.0 + t * (b.0 - a.0);
                    umin = umin.min(u);
                    umax = umax.max(u);
                }
            }
        }
        if umin <= umax {
            mark_rect(out, face, cell(umin), cell(umax), j, j);
        }
    }
}

/// The directions blocked for a half-line from `p` by any of the triangles.
pub fn blocked_halfline(p: &P3, triangles: &[[P3; 3]], n: u32, preferred: &[V3]) -> CubeMap {
    let mut out = CubeMap::empty(n, preferred);
    for t in triangles {
        shadow_triangle(&mut out, p, t);
    }
    // Preferred directions are tested exactly.
    for k in 0..out.preferred_len() {
        let d = out.preferred(k);
        let hit = triangles.iter().any(|t| {
            crate::geometry::line_triangle(p, &d, &t[0], &t[1], &t[2]).is_some_and(|s| s > 0.0)
        });
        out.set(Cell::Preferred(k), hit);
    }
    out
}
