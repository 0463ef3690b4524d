//! An orthographic depth map along a direction (seed ch. 2.5.3, after Spyridi): per
//! texel of a plane perpendicular to `v`, the highest the obstacle reaches along `v`,
//! dilated by a radius. A cylinder of that radius standing on a point x and reaching to
//! infinity along `v` clears the obstacle iff the dilated height under x is below x.

use super::scene::Scene;
use crate::geometry::{P3, V3};
use rayon::prelude::*;

/// Texels per side.
const M: usize = 96;

/// Triangles drawn per task: each task fills a map of its own (72 KiB).
const TRIS_PER_CHUNK: usize = 2048;

pub(crate) struct HeightMap {
    origin: P3,
    e1: V3,
    e2: V3,
    v: V3,
    half: f64,
    texel: f64,
    /// Dilated heights, row-major; −∞ where nothing is.
    h: Vec<f64>,
}

impl HeightMap {
    /// The map around `centre`, covering `half` mm to each side, along `v`, dilated by
    /// `radius`.
    pub(crate) fn new(scene: &Scene, centre: &P3, half: f64, v: &V3, radius: f64) -> HeightMap {
        let v = v.normalize();
        let (e1, e2) = crate::sample::perpendicular_basis(&v);
        let texel = 2.0 * half / M as f64;
        let to_uv = |p: &P3| {
            let d = p - centre;
            (
                (d.dot(&e1) + half) / texel,
                (d.dot(&e2) + half) / texel,
                d.dot(&v),
            )
        };
        // Each texel takes the highest of the triangles over it: chunks of triangles are
        // drawn in parallel and their maps joined by `max`, exact and in any order.
        let raw = scene
            .tris
            .par_chunks(TRIS_PER_CHUNK)
            .map(|tris| {
                let mut raw = vec![f64::NEG_INFINITY; M * M];
                for t in tris {
                    draw(&mut raw, t.v.map(|p| to_uv(&p)));
                }
                raw
            })
            .reduce_with(|mut a, b| {
                for (x, y) in a.iter_mut().zip(b) {
                    *x = x.max(y);
                }
                a
            })
            .unwrap_or_else(|| vec![f64::NEG_INFINITY; M * M]);
        // Dilate by the radius plus a texel diagonal, over a disc of texels.
        let k = ((radius / texel) + std::f64::consts::SQRT_2).ceil() as i64;
        let mut h = vec![f64::NEG_INFINITY; M * M];
        h.par_chunks_mut(M).enumerate().for_each(|(j, out)| {
            let mut wide = [f64::NEG_INFINITY; M];
            for dj in -k..=k {
                let jj = j as i64 + dj;
                if jj < 0 || jj >= M as i64 {
                    continue;
                }
                let w = ((k * k - dj * dj) as f64).sqrt().floor() as i64;
                let row = &raw[jj as usize * M..jj as usize * M + M];
                window_max(row, w as usize, &mut wide);
                for (cell, &m) in out.iter_mut().zip(&wide) {
                    *cell = cell.max(m);
                }
            }
        });
        HeightMap {
            origin: *centre,
            e1,
            e2,
            v,
            half,
            texel,
            h,
        }
    }

    /// Whether the dilated obstacle stays below `x` along the map's direction.
    pub(crate) fn clear(&self, x: &P3) -> bool {
        let d = x - self.origin;
        let (u, w) = (
            (d.dot(&self.e1) + self.half) / self.texel,
            (d.dot(&self.e2) + self.half) / self.texel,
        );
        if u < 0.0 || w < 0.0 || u >= M as f64 || w >= M as f64 {
            return false;
        }
        self.h[w as usize * M + u as usize] < d.dot(&self.v)
    }
}

/// Raises the texels under the triangle `q` (texel units and height) to its highest
/// point over each.
fn draw(raw: &mut [f64], q: [(f64, f64, f64); 3]) {
    let (umin, umax) = (
        q[0].0.min(q[1].0).min(q[2].0),
        q[0].0.max(q[1].0).max(q[2].0),
    );
    let (vmin, vmax) = (
        q[0].1.min(q[1].1).min(q[2].1),
        q[0].1.max(q[1].1).max(q[2].1),
    );
    if umax < 0.0 || vmax < 0.0 || umin > M as f64 || vmin > M as f64 {
        return;
    }
    let hmax = q[0].2.max(q[1].2).max(q[2].2);
    let hmin = q[0].2.min(q[1].2).min(q[2].2);
    // Height over the plane as a function of (u, v), when the triangle is not
    // seen edge-on; otherwise its highest corner.
    let (a, b) = (
        (q[1].0 - q[0].0, q[1].1 - q[0].1),
        (q[2].0 - q[0].0, q[2].1 - q[0].1),
    );
    let det = a.0 * b.1 - a.1 * b.0;
    let plane = (det.abs() > 1e-9).then(|| {
        let (dh1, dh2) = (q[1].2 - q[0].2, q[2].2 - q[0].2);
        let gu = (dh1 * b.1 - dh2 * a.1) / det;
        let gv = (dh2 * a.0 - dh1 * b.0) / det;
        (gu, gv)
    });
    let clampi = |x: f64| (x.floor().max(0.0) as usize).min(M - 1);
    for j in clampi(vmin)..=clampi(vmax) {
        for i in clampi(umin)..=clampi(umax) {
            if !touches(&q, i as f64, j as f64) {
                continue;
            }
            let top = match plane {
                Some((gu, gv)) => {
                    let at = |x: f64, y: f64| q[0].2 + gu * (x - q[0].0) + gv * (y - q[0].1);
                    let corners = [
                        at(i as f64, j as f64),
                        at(i as f64 + 1.0, j as f64),
                        at(i as f64, j as f64 + 1.0),
                        at(i as f64 + 1.0, j as f64 + 1.0),
                    ];
                    corners
                        .iter()
                        .fold(f64::NEG_INFINITY, |m, &x| m.max(x))
                        .clamp(hmin, hmax)
                }
                None => hmax,
            };
            let cell = &mut raw[j * M + i];
            *cell = cell.max(top);
        }
    }
}

/// Per index i, the largest of `row[i − w ..= i + w]` (clipped to the row; NaN counts
/// for nothing, as in a fold of `f64::max` from −∞), in O(len) whatever `w`: the row is
/// cut into blocks of 2w + 1, each with its running maxima from either end, and a window
/// spans one block or the end of one and the start of the next (van Herk, Gil and
/// Werman). `max` is exact, so the result is the fold's, to the bit.
fn window_max(row: &[f64], w: usize, out: &mut [f64]) {
    let len = row.len().min(M);
    let size = 2 * w + 1;
    let mut from_start = [f64::NEG_INFINITY; M];
    let mut to_end = [f64::NEG_INFINITY; M];
    for start in (0..len).step_by(size) {
        let end = (start + size).min(len);
        let mut m = f64::NEG_INFINITY;
        for x in start..end {
            m = m.max(row[x]);
            from_start[x] = m;
        }
        let mut m = f64::NEG_INFINITY;
        for x in (start..end).rev() {
            m = m.max(row[x]);
            to_end[x] = m;
        }
    }
    for (i, o) in out.iter_mut().enumerate().take(len) {
        let (a, b) = (i.saturating_sub(w), (i + w).min(len - 1));
        *o = if a / size == b / size {
            // One block: the window starts it or ends it (a full window lies in one
            // block only when it starts it; a clipped one touches the row's end).
            if a % size == 0 {
                from_start[b]
            } else {
                to_end[a]
            }
        } else {
            to_end[a].max(from_start[b])
        };
    }
}

/// Whether the triangle's projection (texel units) touches texel (i, j): separating axes
/// of the texel square and the triangle's edges.
fn touches(q: &[(f64, f64, f64); 3], i: f64, j: f64) -> bool {
    let corners = [(i, j), (i + 1.0, j), (i, j + 1.0), (i + 1.0, j + 1.0)];
    for k in 0..3 {
        let (a, b, c) = (q[k], q[(k + 1) % 3], q[(k + 2) % 3]);
        let (ex, ey) = (b.0 - a.0, b.1 - a.1);
        let side = |p: (f64, f64)| ex * (p.1 - a.1) - ey * (p.0 - a.0);
        let s = side((c.0, c.1));
        if s == 0.0 {
            return true; // degenerate in projection: keep (conservative)
        }
        if corners.iter().all(|&p| side(p) * s < 0.0) {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dilation's windows give what folding each window gives, bit for bit.
    #[test]
    fn window_maxima_are_the_folds() {
        let mut row = [f64::NEG_INFINITY; M];
        let mut seed = 7u64;
        for x in row.iter_mut() {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            *x = match seed >> 60 {
                0 => f64::NEG_INFINITY,
                1 => f64::NAN,
                _ => (seed >> 11) as f64 / (1u64 << 53) as f64 * 200.0 - 100.0,
            };
        }
        let mut out = [0.0; M];
        for w in 0..=M + 3 {
            window_max(&row, w, &mut out);
            for (i, &got) in out.iter().enumerate() {
                let (lo, hi) = (i.saturating_sub(w), (i + w).min(M - 1));
                let want = row[lo..=hi]
                    .iter()
                    .fold(f64::NEG_INFINITY, |m, &x| m.max(x));
                assert_eq!(got.to_bits(), want.to_bits(), "w = {w}, i = {i}");
            }
        }
    }
}
