//! The CPU rasterizer: projects obstacle polygons onto the cube around a point and marks
//! the pixels of their shadows.
//!
//! Central projection maps a polygon's straight edges to straight lines on each cube
//! face, so a convex polygon's shadow on a face is a convex polygon: the polygon clipped
//! by the face's pyramid (|u| ≤ w, |v| ≤ w), divided by w. A polygon whose corners all
//! lie inside one face's pyramid needs no clipping (the pyramid is convex); that is the
//! common case and the fast path.
//!
//! Two coverage rules ([`Coverage`]): `Centres` marks a pixel when its centre direction is
//! in the shadow (within a hair, so rays through shared edges and corners are caught by
//! both neighbours) — the cone then samples the exact GAC at pixel centres. `Cells` marks
//! every pixel whose cell the shadow touches, so a blocked direction anywhere in a pixel
//! blocks the pixel; the pessimistic abstractions grow from it.
//!
//! A shadow whose bounding box is already all marked is not drawn (OR is idempotent),
//! nor one whose box misses the pixels that matter when a caller names them, and a
//! `Cells` shadow inside one pixel marks it without the row walk.

use super::cubemap::{floor_i, CubeMap};
use crate::geometry::V3;

/// Which pixels a shadow marks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Coverage {
    /// Pixels whose centre direction is in the shadow.
    Centres,
    /// Pixels whose cell the shadow touches.
    Cells,
}

/// Slack in cube-face coordinates: a pixel centre this close to a shadow counts as in it.
const HAIR: f64 = 1e-9;

/// How far past a polygon's corners a span's end may round: the bounding box a shadow
/// is skipped by is widened so, and holds every pixel the shadow could mark.
const SLACK: f64 = 1e-12;

/// A small convex polygon in a cube face's frame (u, v, w).
#[derive(Clone, Copy)]
struct Poly {
    pts: [[f64; 3]; 16],
    len: usize,
}

impl Poly {
    fn new() -> Poly {
        Poly {
            pts: [[0.0; 3]; 16],
            len: 0,
        }
    }

    fn push(&mut self, p: [f64; 3]) {
        if self.len < self.pts.len() {
            self.pts[self.len] = p;
            self.len += 1;
        }
    }

    /// Sutherland–Hodgman: the part where `f ≥ 0`, into `out` (whose corners it
    /// replaces: the buffers are reused, not zeroed per clip).
    fn clip_into(&self, out: &mut Poly, f: impl Fn(&[f64; 3]) -> f64) {
        out.len = 0;
        for k in 0..self.len {
            let (a, b) = (&self.pts[k], &self.pts[(k + 1) % self.len]);
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
    }
}

/// The cube face a direction falls in (ties to the lower axis).
fn face_of(x: &V3) -> u8 {
    let (ax, ay, az) = (x.x.abs(), x.y.abs(), x.z.abs());
    let a = if ax >= ay && ax >= az {
        0
    } else if ay >= az {
        1
    } else {
        2
    };
    (2 * a + usize::from(x[a] < 0.0)) as u8
}

/// (u, v, w) of a direction in a face's frame.
#[inline]
fn in_frame(face: u8, x: &V3) -> [f64; 3] {
    let a = (face / 2) as usize;
    let s = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
    [x[(a + 1) % 3], x[(a + 2) % 3], s * x[a]]
}

/// Marks in `out` the shadow, seen from the origin, of the convex planar polygon with
/// corners `q` (relative to the viewpoint, at most 12), drawn only if it could mark a
/// pixel of `matter` (when given): a shadow whose rectangle on every face misses those
/// pixels is passed over.
pub(crate) fn shadow_polygon_where(
    out: &mut CubeMap,
    q: &[V3],
    cov: Coverage,
    matter: Option<&CubeMap>,
) {
    debug_assert!(q.len() >= 3 && q.len() <= 12);
    // Fast path: every corner strictly inside one face's pyramid.
    let f0 = face_of(&q[0]);
    if q[1..].iter().all(|x| face_of(x) == f0) {
        let mut flat = [(0.0, 0.0); 12];
        let mut ok = true;
        for (k, x) in q.iter().enumerate() {
            let [u, v, w] = in_frame(f0, x);
            if w <= 0.0 {
                ok = false;
                break;
            }
            flat[k] = (u / w, v / w);
        }
        if ok {
            raster_convex(out, f0, &flat[..q.len()], cov, matter);
            return;
        }
    }
    let scale = q.iter().map(|x| x.norm()).fold(0.0, f64::max);
    let (mut poly, mut other) = (Poly::new(), Poly::new());
    for face in 0..6u8 {
        poly.len = 0;
        for x in q {
            poly.push(in_frame(face, x));
        }
        let pts = &poly.pts[..poly.len];
        // Quick reject: every corner outside one side of the pyramid.
        if pts.iter().all(|x| x[2] < x[0])
            || pts.iter().all(|x| x[2] < -x[0])
            || pts.iter().all(|x| x[2] < x[1])
            || pts.iter().all(|x| x[2] < -x[1])
        {
            continue;
        }
        poly.clip_into(&mut other, |x| x[2] - x[0]);
        other.clip_into(&mut poly, |x| x[2] + x[0]);
        poly.clip_into(&mut other, |x| x[2] - x[1]);
        other.clip_into(&mut poly, |x| x[2] + x[1]);
        if poly.len == 0 {
            continue;
        }
        let pts = &poly.pts[..poly.len];
        if pts.iter().any(|x| x[2] <= 1e-12 * scale.max(1e-300)) {
            // The polygon passes through the viewpoint: it blocks the whole face.
            for j in 0..out.n() {
                out.set_span(face, j, 0, out.n() - 1);
            }
            continue;
        }
        let mut flat = [(0.0, 0.0); 16];
        for (k, x) in pts.iter().enumerate() {
            flat[k] = (x[0] / x[2], x[1] / x[2]);
        }
        raster_convex(out, face, &flat[..poly.len], cov, matter);
    }
}

/// The pixels that may be marked by the shadow of any polygon drawn with `cov` whose
/// corners lie in the convex hull of `corners` (relative to the viewpoint; a box, a
/// triangle): a face and the rows j0..=j1 and columns i0..=i1 of a rectangle on it, as
/// (face, j0, j1, i0, i1). None unless the hull lies strictly inside one face's
/// pyramid: then every such polygon takes [`shadow_polygon_where`]'s fast path on that face,
/// and its projection lies in the hull's (central projection keeps it convex), so the
/// rectangle holds every span [`raster_convex`] would set.
pub fn footprint(corners: &[V3], cov: Coverage, n: u32) -> Option<(u8, u32, u32, u32, u32)> {
    let face = face_of(&corners[0]);
    let (mut umin, mut umax) = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut vmin, mut vmax) = (f64::INFINITY, f64::NEG_INFINITY);
    for c in corners {
        let [u, v, w] = in_frame(face, c);
        if !(w > 0.0 && u.abs() < w && v.abs() < w) {
            return None;
        }
        let (u, v) = (u / w, v / w);
        umin = umin.min(u);
        umax = umax.max(u);
        vmin = vmin.min(v);
        vmax = vmax.max(v);
    }
    let n = n as i64;
    let h = 2.0 / n as f64;
    let slack = 1e-9
        + match cov {
            Coverage::Cells => SLACK,
            Coverage::Centres => HAIR + SLACK,
        };
    let cell = |x: f64| clamped_floor((x + 1.0) / h, n) as u32;
    Some((
        face,
        cell(vmin - slack),
        cell(vmax + slack),
        cell(umin - slack),
        cell(umax + slack),
    ))
}

/// Marks the pixels of a cube face that a convex polygon in (u, v) ∈ [−1, 1]² covers.
fn raster_convex(
    out: &mut CubeMap,
    face: u8,
    poly: &[(f64, f64)],
    cov: Coverage,
    matter: Option<&CubeMap>,
) {
    let n = out.n() as i64;
    let h = 2.0 / n as f64;
    let (mut vmin, mut vmax) = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut umin, mut umax) = (f64::INFINITY, f64::NEG_INFINITY);
    for p in poly {
        vmin = vmin.min(p.1);
        vmax = vmax.max(p.1);
        umin = umin.min(p.0);
        umax = umax.max(p.0);
    }
    let clampi = |k: i64| k.clamp(0, n - 1);
    let floor = |y: f64| clamped_floor(y, n);
    // A shadow whose bounding box (widened past any rounding of the spans below) is
    // already all marked adds nothing: on a fine mesh most shadows fall where others did.
    let slack = match cov {
        Coverage::Cells => SLACK,
        Coverage::Centres => HAIR + SLACK,
    };
    let (j0, j1) = (
        floor((vmin - slack + 1.0) / h),
        floor((vmax + slack + 1.0) / h),
    );
    let (i0, i1) = (
        floor((umin - slack + 1.0) / h),
        floor((umax + slack + 1.0) / h),
    );
    let finite = [umin, umax, vmin, vmax].iter().all(|x| x.is_finite());
    if finite {
        let (j0, j1, i0, i1) = (j0 as u32, j1 as u32, i0 as u32, i1 as u32);
        if out.spans_set(face, j0, j1, i0, i1)
            || matter.is_some_and(|m| !m.spans_meet(face, j0, j1, i0, i1))
        {
            return;
        }
    }
    if finite && cov == Coverage::Cells && j0 == j1 && i0 == i1 {
        // Within one pixel even with the slack (most far triangles of a fine mesh): the
        // rows below would mark just it.
        out.set_span(face, j0 as u32, i0 as u32, i0 as u32);
        return;
    }
    match cov {
        Coverage::Cells => {
            let cell = |x: f64| floor((x + 1.0) / h);
            // Where the edges cross the line v = border: the extent of those crossings.
            let crossings = |border: f64| {
                let (mut umin, mut umax) = (f64::INFINITY, f64::NEG_INFINITY);
                for k in 0..poly.len() {
                    let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
                    if (a.1 - border) * (b.1 - border) < 0.0 {
                        let t = (border - a.1) / (b.1 - a.1);
                        let u = a.0 + t * (b.0 - a.0);
                        umin = umin.min(u);
                        umax = umax.max(u);
                    }
                }
                (umin, umax)
            };
            let (ja, jb) = (cell(vmin), cell(vmax));
            let mut lo = -1.0 + ja as f64 * h;
            let mut below = crossings(lo);
            for j in ja..=jb {
                // The polygon's u extent over the strip lo ≤ v ≤ hi: at corners inside the
                // strip and where edges cross its borders (a row's upper border is the
                // next one's lower, crossed once).
                let hi = -1.0 + (j + 1) as f64 * h;
                let above = crossings(hi);
                let (mut umin, mut umax) = (below.0.min(above.0), below.1.max(above.1));
                for a in poly {
                    if a.1 >= lo && a.1 <= hi {
                        umin = umin.min(a.0);
                        umax = umax.max(a.0);
                    }
                }
                if umin <= umax {
                    out.set_span(face, j as u32, cell(umin) as u32, cell(umax) as u32);
                }
                (lo, below) = (hi, above);
            }
        }
        Coverage::Centres => {
            // Rows whose centre line is within a hair of the polygon.
            let j0 = ceil_i((vmin - HAIR + 1.0) / h - 0.5);
            let j1 = floor_i((vmax + HAIR + 1.0) / h - 0.5);
            for j in j0.max(0)..=j1.min(n - 1) {
                let v = (-1.0 + (j as f64 + 0.5) * h).clamp(vmin, vmax);
                let (mut umin, mut umax) = (f64::INFINITY, f64::NEG_INFINITY);
                for k in 0..poly.len() {
                    let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
                    if (a.1 <= v && v <= b.1) || (b.1 <= v && v <= a.1) {
                        let u = if a.1 == b.1 {
                            umin = umin.min(a.0.min(b.0));
                            umax = umax.max(a.0.max(b.0));
                            continue;
                        } else {
                            a.0 + (v - a.1) / (b.1 - a.1) * (b.0 - a.0)
                        };
                        umin = umin.min(u);
                        umax = umax.max(u);
                    }
                }
                if umin > umax {
                    continue;
                }
                let i0 = ceil_i((umin - HAIR + 1.0) / h - 0.5);
                let i1 = floor_i((umax + HAIR + 1.0) / h - 0.5);
                if i0 <= i1 && i1 >= 0 && i0 < n {
                    out.set_span(face, j as u32, clampi(i0) as u32, clampi(i1) as u32);
                }
            }
        }
    }
}

/// `floor_i(y).clamp(0, n - 1)`, clamped before it is rounded: on [0, n − 1] the floor
/// is the truncating cast, and below 0, past n − 1, at the infinities and at NaN (0) the
/// two agree. Cheaper than the floor and the integer clamp, and called per span.
#[inline]
fn clamped_floor(y: f64, n: i64) -> i64 {
    y.max(0.0).min((n - 1) as f64) as i64
}

/// `x.ceil() as i64`, as [`floor_i`].
#[inline]
pub(super) fn ceil_i(x: f64) -> i64 {
    let i = x as i64;
    if (i as f64) < x {
        i.saturating_add(1)
    } else {
        i
    }
}

#[cfg(test)]
mod rounding {
    use super::{ceil_i, clamped_floor, floor_i};

    #[test]
    fn fast_floor_and_ceil_match_the_library() {
        let mut xs = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            1.5,
            -1.5,
            63.999999,
            -63.999999,
            1e-300,
            -1e-300,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            9.3e18,
            -9.3e18,
            4503599627370497.0,
        ];
        let mut s = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..100_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            xs.push((s as f64 / u64::MAX as f64 - 0.5) * 300.0);
        }
        for x in xs {
            for n in [1, 2, 16, 32, 48, 64, 128] {
                assert_eq!(
                    clamped_floor(x, n),
                    (x.floor() as i64).clamp(0, n - 1),
                    "clamped floor {x} {n}"
                );
            }
            assert_eq!(floor_i(x), x.floor() as i64, "floor {x}");
            assert_eq!(ceil_i(x), x.ceil() as i64, "ceil {x}");
        }
    }
}
