//! Moves checked with parry (seed ch. 5.4.2): the probe of one group — fixed setup,
//! probe and orientation — translated along a segment. Each component is swept on its
//! own, as the seed does: the tip ball sweeps an exact capsule, a stylus or extension
//! capsule the exact union of two rounded triangles, a body, head or ram cylinder the
//! convex hull of its two end positions (its discs as circumscribed 16-gons, so a
//! little larger than the cylinder). The table is a plane under the part; a component's
//! lowest point moves linearly along a segment, so the two ends decide.

use crate::access::{Component, End, ProbeShape, Scene};
use crate::geometry::{P3, V3};
use parry3d_f64::math::Isometry;
use parry3d_f64::query::intersection_test;
use parry3d_f64::shape::{Ball, Capsule, ConvexPolyhedron, RoundShape, Shape, Triangle};

/// The table may come no closer to the probe than this (mm).
const TABLE_MARGIN: f64 = 0.1;

/// Sides of the polygon standing in for a cylinder's disc.
const DISC_SIDES: usize = 16;

/// One component of a posed probe: its shape along `dir` from `offset` past the tip
/// centre.
#[derive(Debug, Clone)]
struct Posed {
    comp: Component,
    dir: V3,
    offset: V3,
}

/// The probe of one group, posed in the part frame, with the obstacles of its setup.
pub struct Pose<'a> {
    scene: &'a Scene,
    tip_radius: f64,
    parts: Vec<Posed>,
    up: V3,
    table: f64,
}

impl<'a> Pose<'a> {
    /// `probe` pointing along `dir` (tip to head, part frame) with the ram along `up`;
    /// the table lies at height `table` along `up`.
    pub fn new(scene: &'a Scene, probe: &ProbeShape, dir: V3, up: V3, table: f64) -> Pose<'a> {
        let mut parts = Vec::new();
        if probe.bent {
            for comp in &probe.first {
                parts.push(Posed {
                    comp: comp.clone(),
                    dir,
                    offset: V3::zeros(),
                });
            }
            for comp in &probe.second {
                parts.push(Posed {
                    comp: comp.clone(),
                    dir: up,
                    offset: dir * probe.reach(),
                });
            }
        } else {
            for comp in probe.straight() {
                parts.push(Posed {
                    comp,
                    dir: up,
                    offset: V3::zeros(),
                });
            }
        }
        Pose {
            scene,
            tip_radius: probe.tip_radius,
            parts,
            up,
            table,
        }
    }

    /// The ram direction.
    pub fn up(&self) -> V3 {
        self.up
    }

    /// Whether the probe standing with its tip centre at `p` is clear.
    pub fn free(&self, p: &P3) -> Result<(), String> {
        self.segment(p, p)
    }

    /// Whether the probe can translate from tip centre `p` to `q`; else what hits.
    pub fn segment(&self, p: &P3, q: &P3) -> Result<(), String> {
        let lo = p.coords.dot(&self.up).min(q.coords.dot(&self.up)) - self.tip_radius;
        if lo < self.table + TABLE_MARGIN {
            return Err("the tip (on the table)".into());
        }
        for part in &self.parts {
            let low =
                |x: &P3| crate::plan::lowest(&part.comp, &(x + part.offset), &part.dir, &self.up);
            if low(p).min(low(q)) < self.table + TABLE_MARGIN {
                return Err(format!("the {} (on the table)", part.comp.name));
            }
        }
        let Some(mesh) = self.scene.mesh() else {
            return Ok(());
        };
        let id = Isometry::identity();
        let hits = |shape: &dyn Shape| intersection_test(&id, shape, &id, mesh).unwrap_or(true);
        let v = q - p;
        let moving = v.norm() > 1e-9;
        let tip = if moving {
            hits(&Capsule::new(*p, *q, self.tip_radius))
        } else {
            let at = Isometry::translation(p.x, p.y, p.z);
            intersection_test(&at, &Ball::new(self.tip_radius), &id, mesh).unwrap_or(true)
        };
        if tip {
            return Err("the tip".into());
        }
        let far = 4.0 * self.scene.size + 10.0;
        for part in &self.parts {
            let c = &part.comp;
            let b = c.b.min(c.a + far);
            let a0 = p + part.offset + part.dir * c.a;
            let b0 = p + part.offset + part.dir * b;
            let hit = match (c.end, moving) {
                (_, _) if c.radius == 0.0 => false,
                (End::Round, false) => hits(&Capsule::new(a0, b0, c.radius)),
                (End::Round, true) => {
                    let round = |t: Triangle| RoundShape {
                        inner_shape: t,
                        border_radius: c.radius,
                    };
                    hits(&round(Triangle::new(a0, b0, a0 + v)))
                        || hits(&round(Triangle::new(b0, b0 + v, a0 + v)))
                }
                (End::Flat, _) => {
                    let (e1, e2) = crate::sample::perpendicular_basis(&part.dir);
                    let r = c.radius / (std::f64::consts::PI / DISC_SIDES as f64).cos();
                    let mut pts = Vec::with_capacity(4 * DISC_SIDES);
                    for k in 0..DISC_SIDES {
                        let t = std::f64::consts::TAU * k as f64 / DISC_SIDES as f64;
                        let e = (e1 * t.cos() + e2 * t.sin()) * r;
                        pts.push(a0 + e);
                        pts.push(b0 + e);
                        if moving {
                            pts.push(a0 + e + v);
                            pts.push(b0 + e + v);
                        }
                    }
                    match ConvexPolyhedron::from_convex_hull(&pts) {
                        Some(hull) => hits(&hull),
                        // A hull parry cannot build (a degenerate move): test positions
                        // along the move with the radius grown to cover the gaps.
                        None => sampled(self.scene, &a0, &v, part),
                    }
                }
            };
            if hit {
                return Err(format!("the {}", c.name));
            }
        }
        Ok(())
    }
}

/// The fallback sweep: positions every millimetre, radius grown by half a step.
fn sampled(scene: &Scene, from: &P3, v: &V3, part: &Posed) -> bool {
    let steps = v.norm().ceil().max(1.0) as usize;
    let grown = Component {
        radius: part.comp.radius + v.norm() / steps as f64 / 2.0,
        a: 0.0,
        b: part.comp.b - part.comp.a,
        ..part.comp.clone()
    };
    (0..=steps).any(|s| {
        let at = from + v * (s as f64 / steps as f64);
        crate::access::component_hits(scene, &at, &part.dir, &grown)
    })
}
