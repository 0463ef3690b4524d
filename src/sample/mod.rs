//! Stage 5, sampling: measuring points (the seed's fpoints) on each face, by the plan's
//! strategy.
//!
//! Points lie on the face's exact surface, found through a [`Chart`] of the face's
//! parameters; a candidate counts only if the line along its normal crosses one of the
//! face's triangles (it is inside the face's boundary, not in a hole) and it keeps
//! [`Sampler::margin`] from that boundary. Strategies:
//!
//! - **Fan & Leu** (1998): a plane gets 4 points inset by a fifth of each side of its
//!   minimum-area rectangle; past an aspect ratio of 4, points 2 and 4 move inward by a
//!   quarter of the inner rectangle's length. A plane whose flatness is toleranced gets
//!   more (the graph asks for 9): the rest are Hammersley candidates inside the inset,
//!   each farthest from those chosen. A cylinder or cone gets 4 points on each of
//!   two circles at h₁ = r + (H − 2r)/5 and h₂ = r + 4(H − 2r)/5, r being the margin. A
//!   point that falls outside the face or into a hole moves by the diagonal or normal
//!   zig-zag search until it is inside. Spheres and free-form faces, which the rules do
//!   not cover, get Hammersley points (9 and 16).
//! - **Uniform**: a grid of about `points` points, its outer rows at the inset.
//! - **Hammersley** (Zhao et al. 2011): `x = i/N, y = Φ₂(i)`, area-uniform on the face.
//! - **Spread** (`std::sampling::spread`, the default where a face's form or
//!   orientation is toleranced: `graph::spread_for`): on a plane a grid whose outer
//!   rows keep the margin and [`EDGE_CLEARANCE`] from the edges, a row every
//!   [`SPREAD_SPACING`] mm, at least 3 × 3; on a cylinder or cone circles at both ends
//!   and between, the margin and [`EDGE_CLEARANCE`] in from an open end (a through
//!   bore's mouth) and [`END_CLEARANCE`] from a closed one (a blind bore's floor, a
//!   boss's shoulder: material past the end where the tip's centre would be, told by
//!   the solid's winding number).
//!
//! Where a grid or sequence loses points to holes, a denser one is drawn and `points` of
//! its accepted points are kept, evenly by index. Free-form faces are sampled on their
//! triangles, by area.
//!
//! **Architecture Invariant:** sampling is a pure function of the geometry, the face,
//! the strategy and the margin; the same inputs give the same points in the same order.
//!
//! **Decision: Fan & Leu beyond their paper.** Their rules cover planes, cylinders and
//! cones; a sphere or free-form face under `fan_leu` gets Hammersley points (9 and 16).
//! On a partial cylinder (a half bore of a mesh, a slot end) the 4 points of a circle
//! spread over the face's arc rather than 90° apart.
//!
//! **Decision: narrow faces still get points.** The margin is at most `NARROW_SHARE`
//! (0.45) of the face's smaller extent on each side, so a face narrower than the tip
//! keeps its points towards its mid-line; a face no point of which keeps the margin is
//! sampled again with the margin halved, down to [`MIN_MARGIN_MM`] (a 1 mm ring gets
//! its mid-line). Which probe fits there is the planner's question, not the sampler's.
//!
//! **Decision: a narrow plane's points keep clear of its walls.** With the margin
//! halved, a plane's points first keep [`WALL_CLEARANCE`] more from its walls (edges
//! where the next face rises on the outward side: [`FaceIndex::wall`]) than from its
//! open edges (a hole's mouth, an outer edge), and only where no point does so the
//! margin alone. A counterbore floor between a hole and its wall is where this matters:
//! Fan & Leu's corners of the inset square put FTC 06's floor points (a ring 2.7 mm
//! wide) 0.2 mm from the wall for a Ø2 tip at its stand-off, and an alignment 0.5 mm
//! off (a datum plane at twice its tolerance) drove the tip into the wall. The plan's
//! moves keep `motion { margin }` (1 mm by default) from the part, and a stand-off
//! should as well. Toward the hole's mouth the ball only overhangs empty space.

mod chart;
mod recess;

pub(crate) use chart::convex_hull;
pub use chart::{perpendicular_basis, Chart};
pub use recess::{recess_margins, Shank};

use crate::geometry::{FaceId, FaceIndex, PartGeometry, Surface, P3, V3};
use crate::model::{Inset, SampleMethod, Strategy};

/// A measuring point: where the stylus tip touches the face.
#[derive(Debug, Clone, PartialEq)]
pub struct Fpoint {
    /// The face it lies on.
    pub face: FaceId,
    /// The contact point, on the face's exact surface (mm, part frame).
    pub position: P3,
    /// The outward unit normal of the solid there.
    pub normal: V3,
}

impl Fpoint {
    /// The centre of a tip of radius `r` touching the point: p + r·n, the point whose
    /// accessibility the tip's is (seed ch. 2.4).
    pub fn tip_centre(&self, r: f64) -> P3 {
        self.position + self.normal * r
    }
}

/// Samples the faces of one geometry.
pub struct Sampler<'a> {
    g: &'a PartGeometry,
    index: FaceIndex,
    /// The distance points keep from a face's boundary (mm): the largest tip radius the
    /// plan's machine carries, so that every probe's tip fits; Fan & Leu's `r`.
    pub margin: f64,
    /// Per face, a larger margin where it is the floor of a deep recess
    /// ([`recess_margins`]); empty: `margin` everywhere.
    floors: Vec<f64>,
}

/// How many search steps span a face in each parameter.
const STEPS: f64 = 20.0;

impl<'a> Sampler<'a> {
    /// A sampler for a geometry, keeping `margin` from face boundaries.
    pub fn new(g: &'a PartGeometry, margin: f64) -> Sampler<'a> {
        Sampler {
            g,
            index: FaceIndex::new(g),
            margin,
            floors: Vec::new(),
        }
    }

    /// The sampler with a margin per face from the probes that reach it: a recess
    /// floor's points keep clear of its walls by the radius of the probe part standing
    /// beside them ([`recess_margins`]).
    pub fn with_shanks(mut self, shanks: &[Shank]) -> Sampler<'a> {
        self.floors = recess_margins(self.g, shanks, self.margin);
        self
    }

    /// The margin face `face`'s points keep from its boundary.
    pub fn margin_of(&self, face: FaceId) -> f64 {
        self.floors.get(face.0).copied().unwrap_or(self.margin)
    }

    /// The measuring points of one face. The entry point of the sampling stage. A face
    /// no point of which keeps the margin (a ring narrower than the tip's diameter) is
    /// sampled again with the margin halved, down to [`MIN_MARGIN_MM`]: its points gather
    /// on its mid-line, and the planner decides which probe fits there.
    pub fn sample(&self, face: FaceId, strategy: &Strategy) -> Vec<Fpoint> {
        let mut margin = self.margin_of(face);
        let plane = matches!(self.g.faces[face.0].surface, Surface::Plane { .. });
        loop {
            let pts = self.sample_with_margin(face, strategy, margin, margin);
            if !pts.is_empty() || margin <= MIN_MARGIN_MM {
                return pts;
            }
            margin = (margin / 2.0).max(MIN_MARGIN_MM);
            if plane {
                let pts = self.sample_with_margin(face, strategy, margin, margin + WALL_CLEARANCE);
                if !pts.is_empty() {
                    return pts;
                }
            }
        }
    }

    /// Points keeping `margin` from the face's open edges and `wall` from its walls.
    fn sample_with_margin(
        &self,
        face: FaceId,
        strategy: &Strategy,
        margin: f64,
        wall: f64,
    ) -> Vec<Fpoint> {
        let f = &self.g.faces[face.0];
        if f.area <= 0.0 {
            return Vec::new();
        }
        let Some(chart) = Chart::of(self.g, face) else {
            let n = strategy.points.unwrap_or(16) as usize;
            return self.freeform(face, strategy.method, n, margin);
        };
        let (eu, ev) = chart.extent_mm();
        // A face narrower than the tip keeps as much of the margin as it can: its points
        // gather towards the mid-line (a 1 mm ring gets a row on its middle, not none).
        // Walls keep what they keep beyond it.
        let beyond = (wall - margin).max(0.0);
        let margin = margin.min(NARROW_SHARE * eu.min(ev));
        let place = Place {
            s: self,
            chart: &chart,
            face,
            margin,
            wall: margin + beyond,
        };
        match (strategy.method, &f.surface) {
            (SampleMethod::FanLeu, Surface::Plane { .. }) => {
                let mut pts = place.fan_leu_plane(strategy.inset);
                if let Some(n) = strategy.points {
                    place.fill(&mut pts, n as usize);
                }
                pts
            }
            (SampleMethod::FanLeu, Surface::Cylinder { .. } | Surface::Cone { .. }) => {
                place.fan_leu_round(strategy.points.map_or(4, |n| n.div_ceil(2).max(1)) as usize)
            }
            (SampleMethod::Spread, Surface::Plane { .. }) => {
                place.spread_plane(strategy.points.map(|n| n as usize), strategy.spacing)
            }
            (SampleMethod::Spread, Surface::Cylinder { .. } | Surface::Cone { .. }) => {
                place.spread_round(strategy.points.map(|n| n as usize), strategy.spacing)
            }
            (SampleMethod::FanLeu | SampleMethod::Spread, _) => place.pool(
                SampleMethod::Hammersley,
                strategy.points.unwrap_or(9) as usize,
                None,
            ),
            (SampleMethod::Uniform, _) => place.pool(
                SampleMethod::Uniform,
                strategy.points.unwrap_or(9) as usize,
                Some(strategy.inset.unwrap_or(Inset::Fraction(0.1))),
            ),
            (SampleMethod::Hammersley, _) => place.pool(
                SampleMethod::Hammersley,
                strategy.points.unwrap_or(12) as usize,
                strategy.inset,
            ),
        }
    }

    /// Points on a free-form face's triangles, chosen by area.
    fn freeform(&self, face: FaceId, method: SampleMethod, n: usize, margin: f64) -> Vec<Fpoint> {
        let g = self.g;
        let f = &g.faces[face.0];
        let margin = margin.min(0.1 * f.area.sqrt());
        let mut cdf = Vec::with_capacity(f.triangles.len());
        let mut total = 0.0;
        for &t in &f.triangles {
            let [a, b, c] = g.triangles[t as usize].map(|i| g.vertices[i as usize]);
            total += (b - a).cross(&(c - a)).norm() / 2.0;
            cdf.push(total);
        }
        let mut best = Vec::new();
        for m in [1, 2, 4, 8] {
            let count = n * m;
            let mut got = Vec::new();
            for i in 0..count {
                let s = (i as f64 + 0.5) / count as f64 * total;
                let k = cdf.partition_point(|&c| c < s).min(cdf.len() - 1);
                let [a, b, c] =
                    g.triangles[f.triangles[k] as usize].map(|i| g.vertices[i as usize]);
                let (mut x, mut y) = match method {
                    SampleMethod::Uniform => (1.0 / 3.0, 1.0 / 3.0),
                    _ => (radical_inverse(i as u32, 2), radical_inverse(i as u32, 3)),
                };
                if x + y > 1.0 {
                    (x, y) = (1.0 - x, 1.0 - y);
                }
                let p = a + (b - a) * x + (c - a) * y;
                let Some(normal) = (b - a).cross(&(c - a)).try_normalize(0.0) else {
                    continue;
                };
                if self.index.boundary_distance(g, face, &p) >= margin {
                    got.push(Fpoint {
                        face,
                        position: p,
                        normal,
                    });
                }
            }
            let enough = got.len() >= n;
            best = got;
            if enough {
                break;
            }
        }
        pick_evenly(best, n)
    }
}

/// How far beyond the tip's radius `spread` keeps its outer points from a plane's
/// edges (mm): a chamfer or burr stays clear of the ball.
pub(crate) const EDGE_CLEARANCE: f64 = 0.5;

/// How far beyond the tip's radius `spread` keeps a cylinder's or cone's end circles
/// from its ends (mm): the default `motion { margin }` and half a millimetre more, so
/// that a ball at a blind bore's last circle keeps more than the plan's margin from its
/// floor.
pub(crate) const END_CLEARANCE: f64 = 1.5;

/// `spread`'s distance between rows (mm).
pub(crate) const SPREAD_SPACING: f64 = 25.0;

/// `spread`'s most rows along one side.
pub(crate) const SPREAD_MAX_ROWS: usize = 7;

/// Rows of a `spread` grid over a usable `a` × `b` mm: one every [`SPREAD_SPACING`], at
/// least 3 each way (2 on a strip under 4 mm: points in one row fix no plane), denser
/// until there are `want` points. A `spacing` the strategy asks for (a zone per unit
/// area) is kept however many rows it takes.
fn spread_rows(a: f64, b: f64, want: Option<usize>, spacing: Option<f64>) -> (usize, usize) {
    let least = |x: f64| {
        if x < 1e-6 {
            1
        } else if x < 4.0 {
            2
        } else {
            3
        }
    };
    let most = |x: f64| match spacing {
        Some(s) => ((x / s).ceil() as usize + 1).max(least(x)),
        None => SPREAD_MAX_ROWS.max(least(x)),
    };
    let rows = |x: f64, s: f64| ((x / s).ceil() as usize + 1).clamp(least(x), most(x));
    let mut s = spacing.map_or(SPREAD_SPACING, |w| w.min(SPREAD_SPACING));
    loop {
        let (na, nb) = (rows(a, s), rows(b, s));
        let full = (na >= most(a) || a < 4.0) && (nb >= most(b) || b < 4.0);
        if want.is_none_or(|w| na * nb >= w) || full || s < 0.5 {
            return (na, nb);
        }
        s *= 0.8;
    }
}

/// How much farther than the margin a narrow plane's points keep from its walls (mm):
/// the default `motion { margin }`, so that a tip the margin's size, standing off the
/// point before its touch, keeps the plan's clearance from the wall beside it.
pub(crate) const WALL_CLEARANCE: f64 = 1.0;

/// The least margin a face is sampled with (mm), however narrow it is.
pub(crate) const MIN_MARGIN_MM: f64 = 0.1;

/// The most of a face's width the margin may take on each side: a face narrower than
/// twice the margin keeps its points in the middle tenth.
const NARROW_SHARE: f64 = 0.45;

/// Placing points on one analytic face.
struct Place<'s, 'a> {
    s: &'s Sampler<'a>,
    chart: &'s Chart,
    face: FaceId,
    /// The distance points keep from the face's open edges.
    margin: f64,
    /// The distance points keep from its walls ([`FaceIndex::wall`]): the margin, or more
    /// on a narrow face ([`WALL_CLEARANCE`]).
    wall: f64,
}

impl Place<'_, '_> {
    /// The point at (u, v), if it is on the face, keeps the margin, and is not within
    /// `min_sep` of a point already taken.
    fn accept(&self, u: f64, v: f64, taken: &[Fpoint], min_sep: f64) -> Option<Fpoint> {
        let (position, normal) = self.chart.eval(u, v);
        if taken
            .iter()
            .any(|f| (f.position - position).norm() < min_sep)
        {
            return None;
        }
        let g = self.s.g;
        if !g.face_covers(self.face, &position, &normal, self.chart.cover_tolerance()) {
            return None;
        }
        let (open, wall) = self.s.index.edge_distances(g, self.face, &position);
        if open < self.margin || wall < self.wall {
            return None;
        }
        Some(Fpoint {
            face: self.face,
            position,
            normal,
        })
    }

    fn steps(&self) -> (f64, f64) {
        let c = self.chart;
        ((c.u.1 - c.u.0) / STEPS, (c.v.1 - c.v.0) / STEPS)
    }

    fn min_sep(&self) -> f64 {
        let (eu, ev) = self.chart.extent_mm();
        0.5 * eu.min(ev) / STEPS
    }

    /// Fan & Leu's zig-zag search from (u0, v0): step towards the middle of the face —
    /// diagonally from a corner, along the normal from an edge — and at the k-th step try
    /// offsets 0, +1, −1, …, ±k across that direction; the first acceptable point wins.
    fn search(&self, u0: f64, v0: f64, taken: &[Fpoint]) -> Option<Fpoint> {
        let c = self.chart;
        let (du, dv) = self.steps();
        let min_sep = self.min_sep();
        let toward = |x: f64, (lo, hi): (f64, f64), step: f64| {
            let mid = (lo + hi) / 2.0;
            if (mid - x).abs() <= step / 2.0 {
                0.0
            } else {
                (mid - x).signum()
            }
        };
        let mut d = (
            if c.periodic_u {
                0.0
            } else {
                toward(u0, c.u, du)
            },
            toward(v0, c.v, dv),
        );
        if d == (0.0, 0.0) {
            d = (1.0, 0.0);
        }
        let t = (-d.1, d.0);
        let limit = 2 * STEPS as i32;
        for k in 0..=limit {
            for j in (0..=k).flat_map(|j| if j == 0 { vec![0] } else { vec![j, -j] }) {
                let (k, j) = (k as f64, j as f64);
                let mut u = u0 + (k * d.0 + j * t.0) * du;
                let v = v0 + (k * d.1 + j * t.1) * dv;
                if c.periodic_u {
                    u = c.u.0 + (u - c.u.0).rem_euclid(c.u.1 - c.u.0);
                } else if u < c.u.0 || u > c.u.1 {
                    continue;
                }
                if v < c.v.0 || v > c.v.1 {
                    continue;
                }
                if let Some(p) = self.accept(u, v, taken, min_sep) {
                    return Some(p);
                }
            }
        }
        None
    }

    /// Places points at parameter positions, each moved by the zig-zag search if needed.
    fn place_all(&self, targets: &[(f64, f64)]) -> Vec<Fpoint> {
        let mut taken = Vec::new();
        for &(u, v) in targets {
            if let Some(p) = self.search(u, v, &taken) {
                taken.push(p);
            }
        }
        taken
    }

    fn fan_leu_plane(&self, inset: Option<Inset>) -> Vec<Fpoint> {
        let c = self.chart;
        let (l, w) = (c.u.1 - c.u.0, c.v.1 - c.v.0);
        let (fu, fv) = match inset {
            None => (0.2, 0.2),
            Some(Inset::Fraction(f)) => (f, f),
            Some(Inset::Length(mm)) => ((mm / l.max(1e-12)).min(0.5), (mm / w.max(1e-12)).min(0.5)),
        };
        let (a, b) = (fu, 1.0 - fu);
        // Slender faces: points 2 and 4 move inward by two eighths of the inner length.
        let shift = if l > 4.0 * w {
            2.0 * (b - a) / 8.0
        } else {
            0.0
        };
        let at = |x: f64, y: f64| (c.u.0 + x * l, c.v.0 + y * w);
        self.place_all(&[
            at(a, fv),
            at(b - shift, fv),
            at(b, 1.0 - fv),
            at(a + shift, 1.0 - fv),
        ])
    }

    fn fan_leu_round(&self, per_circle: usize) -> Vec<Fpoint> {
        let c = self.chart;
        let h = c.v.1 - c.v.0;
        let (_, sv) = c.scale();
        let r = (self.margin / sv).min(NARROW_SHARE * h);
        let heights = [
            c.v.0 + r + (h - 2.0 * r) / 5.0,
            c.v.0 + r + 4.0 * (h - 2.0 * r) / 5.0,
        ];
        let span = c.u.1 - c.u.0;
        let mut targets = Vec::new();
        for v in heights {
            for k in 0..per_circle {
                let f = if c.periodic_u {
                    k as f64 / per_circle as f64
                } else {
                    (k as f64 + 0.5) / per_circle as f64
                };
                targets.push((c.u.0 + f * span, v));
            }
        }
        self.place_all(&targets)
    }

    /// `std::sampling::spread` on a plane: a grid over the face's rectangle whose outer
    /// rows keep [`EDGE_CLEARANCE`] beyond the margin from its edges, a row every
    /// [`SPREAD_SPACING`] mm, at least 3 rows each way where the face is wide enough
    /// (2, then 1, on a narrower strip), at most [`SPREAD_MAX_ROWS`]; denser until the
    /// grid holds `want` points where the graph asks for more. Points that fall off the
    /// face (a hole, an L-shaped face) move inwards by Fan & Leu's search.
    fn spread_plane(&self, want: Option<usize>, spacing: Option<f64>) -> Vec<Fpoint> {
        let c = self.chart;
        let (eu, ev) = c.extent_mm();
        let edge = self.margin + EDGE_CLEARANCE;
        let (iu, iv) = (edge.min(NARROW_SHARE * eu), edge.min(NARROW_SHARE * ev));
        let (uu, uv) = (eu - 2.0 * iu, ev - 2.0 * iv);
        let (nu, nv) = spread_rows(uu, uv, want, spacing);
        let at = |i: usize, n: usize| {
            if n == 1 {
                0.5
            } else {
                i as f64 / (n - 1) as f64
            }
        };
        let (su, sv) = c.scale();
        let mut targets = Vec::new();
        for j in 0..nv {
            for i in 0..nu {
                targets.push((
                    c.u.0 + (iu + at(i, nu) * uu) / su,
                    c.v.0 + (iv + at(j, nv) * uv) / sv,
                ));
            }
        }
        self.place_all(&targets)
    }

    /// `std::sampling::spread` on a cylinder or cone: circles at both usable ends of
    /// its length (the margin and [`Place::end_clearance`] in) and between, a circle every
    /// [`SPREAD_SPACING`] mm, at least 3 where the length allows; at least 4 points a
    /// circle, more on a large one.
    fn spread_round(&self, want: Option<usize>, spacing: Option<f64>) -> Vec<Fpoint> {
        let c = self.chart;
        let (eu, ev) = c.extent_mm();
        let (_, sv) = c.scale();
        let end = |v_end: f64, beyond: f64| {
            (self.margin + self.end_clearance(v_end, beyond)).min(NARROW_SHARE * ev)
        };
        let (first, last) = (end(c.v.0, -1.0), end(c.v.1, 1.0));
        let usable = ev - first - last;
        let (around, heights) = spread_rows(eu, usable, want, spacing);
        let around = around.max(4);
        let span = c.u.1 - c.u.0;
        let mut targets = Vec::new();
        for j in 0..heights {
            let t = if heights == 1 {
                0.5
            } else {
                j as f64 / (heights - 1) as f64
            };
            let v = c.v.0 + (first + t * usable) / sv;
            for k in 0..around {
                // Circles turned against each other by half a step: the points of two
                // circles do not line up along the axis.
                let f = if c.periodic_u {
                    (k as f64 + 0.5 * (j % 2) as f64) / around as f64
                } else {
                    (k as f64 + 0.5) / around as f64
                };
                targets.push((c.u.0 + f * span, v));
            }
        }
        self.place_all(&targets)
    }

    /// How far beyond the tip's radius a round face's end circle keeps from its end at
    /// `v_end` (`beyond`: the sign of v past that end): [`END_CLEARANCE`] where material
    /// closes the end where the tip's centre would pass it (a blind bore's floor, the
    /// shoulder a boss stands on), [`EDGE_CLEARANCE`] where the end opens (a through
    /// bore's mouth, a step into a wider counterbore). A tilt is read over the length
    /// between the end circles: on a Ø6 × 10 through bore, 1.5 mm more at each end
    /// reads a tilt over 41 % of the bore instead of 61 %. A bore narrower than the
    /// margin's tip keeps [`END_CLEARANCE`] at both ends: only a smaller tip enters it,
    /// its stem close to the wall, and a circle by the mouth is one few orientations
    /// reach (Spitz's F4, a Ø3 bore for a Ø1 ball: the planner did not settle).
    fn end_clearance(&self, v_end: f64, beyond: f64) -> f64 {
        let c = self.chart;
        let (su, sv) = c.scale();
        let narrow = match self.s.g.faces[self.face.0].surface {
            Surface::Cylinder { convex, .. } | Surface::Cone { convex, .. } => {
                !convex && su <= self.s.margin
            }
            _ => false,
        };
        if narrow {
            return END_CLEARANCE;
        }
        let v = v_end + beyond * EDGE_CLEARANCE / sv;
        let closed = (0..4).any(|k| {
            let u = c.u.0 + (k as f64 + 0.5) / 4.0 * (c.u.1 - c.u.0);
            let (p, n) = c.eval(u, v);
            self.s.g.winding_number(&(p + n * self.margin)) > 0.5
        });
        if closed {
            END_CLEARANCE
        } else {
            EDGE_CLEARANCE
        }
    }

    /// Uniform grids or Hammersley sequences, denser until `n` points are accepted.
    /// Adds points to `pts` up to `n`, each the Hammersley candidate farthest from the
    /// points it joins: a plane's form read between Fan & Leu's corners.
    fn fill(&self, pts: &mut Vec<Fpoint>, n: usize) {
        if pts.len() >= n {
            return;
        }
        // Inside Fan & Leu's inset: a point by an edge may be one the probe reaches
        // only along the table.
        let mut cands = self.pool(SampleMethod::Hammersley, 8 * n, Some(Inset::Fraction(0.2)));
        while pts.len() < n && !cands.is_empty() {
            let gap = |c: &Fpoint| {
                pts.iter()
                    .map(|p| (p.position - c.position).norm())
                    .fold(f64::INFINITY, f64::min)
            };
            let (k, d) = cands
                .iter()
                .enumerate()
                .map(|(k, c)| (k, gap(c)))
                .fold((0, f64::NEG_INFINITY), |b, x| if x.1 > b.1 { x } else { b });
            if d < 1e-6 {
                break;
            }
            pts.push(cands.swap_remove(k));
        }
    }

    fn pool(&self, method: SampleMethod, n: usize, inset: Option<Inset>) -> Vec<Fpoint> {
        let c = self.chart;
        let (eu, ev) = c.extent_mm();
        let frac = |extent: f64| match inset {
            None => 0.0,
            Some(Inset::Fraction(f)) => f.min(0.49),
            Some(Inset::Length(mm)) => (mm / extent.max(1e-12)).min(0.49),
        };
        let (iu, iv) = (if c.periodic_u { 0.0 } else { frac(eu) }, frac(ev));
        let u_at = |s: f64| c.u.0 + (iu + s * (1.0 - 2.0 * iu)) * (c.u.1 - c.u.0);
        let v_at = |t: f64| c.v_by_area(iv + t * (1.0 - 2.0 * iv));
        let mut best = Vec::new();
        for m in [1, 2, 4, 8] {
            let count = n * m;
            let params: Vec<(f64, f64)> = match method {
                SampleMethod::Uniform => {
                    let aspect = (eu / ev.max(1e-12)).clamp(1e-3, 1e3);
                    let nu = ((count as f64 * aspect).sqrt().round() as usize).clamp(1, count);
                    let nv = count.div_ceil(nu);
                    let at = |i: usize, n: usize, periodic: bool| match (n, periodic) {
                        (_, true) => i as f64 / n as f64,
                        (1, false) => 0.5,
                        _ => i as f64 / (n - 1) as f64,
                    };
                    (0..nv)
                        .flat_map(|j| (0..nu).map(move |i| (i, j)))
                        .map(|(i, j)| (u_at(at(i, nu, c.periodic_u)), v_at(at(j, nv, false))))
                        .collect()
                }
                _ => (0..count)
                    .map(|i| {
                        (
                            u_at((i as f64 + 0.5) / count as f64),
                            v_at(radical_inverse(i as u32, 2)),
                        )
                    })
                    .collect(),
            };
            let got: Vec<Fpoint> = params
                .into_iter()
                .filter_map(|(u, v)| self.accept(u, v, &[], 0.0))
                .collect();
            let enough = got.len() >= n;
            best = got;
            if enough {
                break;
            }
        }
        pick_evenly(best, n)
    }
}

/// `n` of the points, evenly spread by index; all of them if there are no more than `n`.
fn pick_evenly(points: Vec<Fpoint>, n: usize) -> Vec<Fpoint> {
    if points.len() <= n {
        return points;
    }
    let len = points.len();
    (0..n).map(|k| points[k * len / n].clone()).collect()
}

/// The van der Corput radical inverse of `i` in `base`: its digits mirrored after the
/// point, a low-discrepancy sequence in [0, 1).
pub(crate) fn radical_inverse(mut i: u32, base: u32) -> f64 {
    let (mut inv, mut f) = (0.0, 1.0 / base as f64);
    while i > 0 {
        inv += (i % base) as f64 * f;
        i /= base;
        f /= base as f64;
    }
    inv
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radical_inverse_base_2() {
        let xs: Vec<f64> = (0..5).map(|i| radical_inverse(i, 2)).collect();
        assert_eq!(xs, vec![0.0, 0.5, 0.25, 0.75, 0.125]);
    }
}
