//! Triangulated primitives whose faces carry exact surfaces: prisms of convex profiles
//! made of lines and arcs (boxes, cylinders, slots, pockets, holes, bosses) and spheres.
//!
//! Curved faces are tessellated within `CHORD_MM` (0.05 mm) of the true surface;
//! `csg.rs` classifies triangles with the same tolerance.

use super::{Surface, P3, V3};
use std::f64::consts::{PI, TAU};

/// Largest distance between a tessellated arc and the true circle (mm).
pub(crate) const CHORD_MM: f64 = 0.05;

/// How many segments an arc of `radius` sweeping `sweep` radians needs: within
/// [`CHORD_MM`] of the circle, and at least 16 per turn so neighbouring facets of a
/// curved face meet at less than 22.5° (segmentation tells curved from sharp by that).
pub(crate) fn segments(radius: f64, sweep: f64) -> usize {
    let step = 2.0 * (1.0 - (CHORD_MM / radius).min(1.0)).acos();
    let by_chord = (sweep / step.max(1e-6)).ceil() as usize;
    let by_angle = (sweep / (TAU / 16.0)).ceil() as usize;
    by_chord.max(by_angle).clamp(1, 512)
}

/// A right-handed frame: `u × v = w`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Frame {
    pub o: P3,
    pub u: V3,
    pub v: V3,
    pub w: V3,
}

impl Frame {
    /// A frame whose `w` is the given direction.
    pub fn along(o: P3, w: V3) -> Frame {
        let w = w.normalize();
        let helper = if w.x.abs() < 0.9 { V3::x() } else { V3::y() };
        let u = helper.cross(&w).normalize();
        let v = w.cross(&u);
        Frame { o, u, v, w }
    }

    /// A frame from `u` and `w` (made orthogonal).
    pub(crate) fn from_uw(o: P3, u: V3, w: V3) -> Frame {
        let w = w.normalize();
        let u = (u - w * u.dot(&w)).normalize();
        Frame {
            o,
            u,
            v: w.cross(&u),
            w,
        }
    }

    pub fn at(&self, x: f64, y: f64, z: f64) -> P3 {
        self.o + self.u * x + self.v * y + self.w * z
    }
}

/// A profile segment, counter-clockwise around the profile.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Seg {
    Line {
        a: [f64; 2],
    },
    Arc {
        c: [f64; 2],
        r: f64,
        a0: f64,
        a1: f64,
    },
}

/// A rectangle `[x0, x1] × [y0, y1]`: bottom, right, top, left edges in that order.
pub(crate) fn rectangle(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<Seg> {
    vec![
        Seg::Line { a: [x0, y0] },
        Seg::Line { a: [x1, y0] },
        Seg::Line { a: [x1, y1] },
        Seg::Line { a: [x0, y1] },
    ]
}

/// A rectangle centred on the origin with rounded corners: 4 lines (bottom, right, top,
/// left) and, when `r > 0`, 4 corner arcs between them.
pub(crate) fn rounded_rectangle(l: f64, w: f64, r: f64) -> Vec<Seg> {
    let (hx, hy) = (l / 2.0, w / 2.0);
    if r <= 0.0 {
        return rectangle(-hx, -hy, hx, hy);
    }
    let r = r.min(hx).min(hy);
    vec![
        Seg::Line { a: [-hx + r, -hy] },
        Seg::Arc {
            c: [hx - r, -hy + r],
            r,
            a0: -PI / 2.0,
            a1: 0.0,
        },
        Seg::Line { a: [hx, -hy + r] },
        Seg::Arc {
            c: [hx - r, hy - r],
            r,
            a0: 0.0,
            a1: PI / 2.0,
        },
        Seg::Line { a: [hx - r, hy] },
        Seg::Arc {
            c: [-hx + r, hy - r],
            r,
            a0: PI / 2.0,
            a1: PI,
        },
        Seg::Line { a: [-hx, hy - r] },
        Seg::Arc {
            c: [-hx + r, -hy + r],
            r,
            a0: PI,
            a1: 1.5 * PI,
        },
    ]
}

/// A full circle.
pub(crate) fn circle(r: f64) -> Vec<Seg> {
    vec![Seg::Arc {
        c: [0.0, 0.0],
        r,
        a0: 0.0,
        a1: TAU,
    }]
}

/// A triangulated primitive: `tri_part[t]` says which of the primitive's faces triangle
/// `t` belongs to, indexing `surfaces`.
#[derive(Debug, Clone, Default)]
pub(crate) struct Prim {
    pub verts: Vec<P3>,
    pub tris: Vec<[u32; 3]>,
    pub tri_part: Vec<u32>,
    pub surfaces: Vec<Surface>,
}

impl Prim {
    pub(crate) fn bounds_of_part(&self, part: u32) -> (P3, P3) {
        let mut lo = P3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY);
        let mut hi = -lo;
        for (t, tri) in self.tris.iter().enumerate() {
            if self.tri_part[t] == part {
                for &i in tri {
                    lo = lo.inf(&self.verts[i as usize]);
                    hi = hi.sup(&self.verts[i as usize]);
                }
            }
        }
        (lo, hi)
    }

    pub fn bounds(&self) -> (P3, P3) {
        let mut lo = P3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY);
        let mut hi = -lo;
        for v in &self.verts {
            lo = lo.inf(v);
            hi = hi.sup(v);
        }
        (lo, hi)
    }

    /// Applies a rigid motion to vertices and surfaces.
    pub(crate) fn transform(&mut self, m: &nalgebra::Isometry3<f64>) {
        for v in &mut self.verts {
            *v = m * *v;
        }
        for s in &mut self.surfaces {
            *s = s.moved(m);
        }
    }
}

/// Extrudes a convex counter-clockwise profile (in the frame's u, v) along w from `z0`
/// to `z1`. Parts: one per profile segment (its side wall), then the bottom cap (at
/// `z0`), then the top cap (at `z1`). Normals point out of the prism.
pub(crate) fn prism(f: &Frame, profile: &[Seg], z0: f64, z1: f64) -> Prim {
    // The ring of profile points, each with the segment its outgoing edge belongs to.
    let mut ring: Vec<([f64; 2], u32)> = Vec::new();
    let mut surfaces = Vec::new();
    for (k, seg) in profile.iter().enumerate() {
        match *seg {
            Seg::Line { a } => {
                let b = match profile[(k + 1) % profile.len()] {
                    Seg::Line { a } => a,
                    Seg::Arc { c, r, a0, .. } => [c[0] + r * a0.cos(), c[1] + r * a0.sin()],
                };
                ring.push((a, k as u32));
                let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
                let n2 = [dy, -dx];
                let normal = (f.u * n2[0] + f.v * n2[1]).normalize();
                surfaces.push(Surface::Plane {
                    origin: f.at(a[0], a[1], 0.0),
                    normal,
                });
            }
            Seg::Arc { c, r, a0, a1 } => {
                let n = segments(r, a1 - a0);
                for i in 0..n {
                    let t = a0 + (a1 - a0) * i as f64 / n as f64;
                    ring.push(([c[0] + r * t.cos(), c[1] + r * t.sin()], k as u32));
                }
                surfaces.push(Surface::Cylinder {
                    origin: f.at(c[0], c[1], 0.0),
                    axis: f.w,
                    radius: r,
                    convex: true,
                });
            }
        }
    }
    let n = ring.len() as u32;
    let nseg = profile.len() as u32;
    let mut p = Prim {
        surfaces,
        ..Prim::default()
    };
    for &(q, _) in &ring {
        p.verts.push(f.at(q[0], q[1], z0));
    }
    for &(q, _) in &ring {
        p.verts.push(f.at(q[0], q[1], z1));
    }
    let (cx, cy) = ring
        .iter()
        .fold((0.0, 0.0), |s, (q, _)| (s.0 + q[0], s.1 + q[1]));
    let (cx, cy) = (cx / n as f64, cy / n as f64);
    p.verts.push(f.at(cx, cy, z0));
    p.verts.push(f.at(cx, cy, z1));
    let (cb, ct) = (2 * n, 2 * n + 1);
    for i in 0..n {
        let j = (i + 1) % n;
        let part = ring[i as usize].1;
        p.tris.push([i, j, n + j]);
        p.tris.push([i, n + j, n + i]);
        p.tri_part.extend([part, part]);
        p.tris.push([cb, j, i]);
        p.tri_part.push(nseg);
        p.tris.push([ct, n + i, n + j]);
        p.tri_part.push(nseg + 1);
    }
    p.surfaces.push(Surface::Plane {
        origin: f.at(0.0, 0.0, z0),
        normal: -f.w,
    });
    p.surfaces.push(Surface::Plane {
        origin: f.at(0.0, 0.0, z1),
        normal: f.w,
    });
    p
}

/// A UV sphere: one part.
pub(crate) fn sphere(center: P3, r: f64) -> Prim {
    let nlon = segments(r, TAU).max(16);
    let nlat = (nlon / 2).max(8);
    let mut p = Prim {
        surfaces: vec![Surface::Sphere {
            center,
            radius: r,
            convex: true,
        }],
        ..Prim::default()
    };
    p.verts.push(center + V3::new(0.0, 0.0, -r));
    for i in 1..nlat {
        let th = PI * i as f64 / nlat as f64 - PI / 2.0;
        for j in 0..nlon {
            let ph = TAU * j as f64 / nlon as f64;
            p.verts.push(
                center
                    + V3::new(
                        r * th.cos() * ph.cos(),
                        r * th.cos() * ph.sin(),
                        r * th.sin(),
                    ),
            );
        }
    }
    p.verts.push(center + V3::new(0.0, 0.0, r));
    let ring = |i: usize, j: usize| (1 + (i - 1) * nlon + j % nlon) as u32;
    let top = (p.verts.len() - 1) as u32;
    for j in 0..nlon {
        p.tris.push([0, ring(1, j + 1), ring(1, j)]);
        p.tris.push([top, ring(nlat - 1, j), ring(nlat - 1, j + 1)]);
    }
    for i in 1..nlat - 1 {
        for j in 0..nlon {
            p.tris
                .push([ring(i, j), ring(i, j + 1), ring(i + 1, j + 1)]);
            p.tris
                .push([ring(i, j), ring(i + 1, j + 1), ring(i + 1, j)]);
        }
    }
    p.tri_part = vec![0; p.tris.len()];
    p
}
