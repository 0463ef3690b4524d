//! A laser line scanner's visibility (Álvarez et al. sec. V.B, Zhao et al. sec. 5.1): a
//! surface point is measured from a scanner direction d when the laser reaches it along
//! d, the camera sees it along its own line of sight at the triangulation angle to d, the
//! laser meets the surface within the incidence limit, and the scanner's housing, head and
//! ram clear the part with the point at the stand-off (the middle of the depth of field).
//!
//! Computed on the touch probes' cube maps and backends: the rays from one half-line map
//! drawn cell-conservatively, the housing as a flat component from the stand-off out, a
//! second component (head and ram) as a bent probe's D2. At every pixel centre the cone
//! never calls visible what exact ray casts block ([`sees`] is the exact test;
//! `tests/suite/access.rs` compares the two).
//!
//! **Decision:** the camera's line of sight is d turned by the triangulation angle
//! towards the surface normal, in the plane of d and the normal (about any axis square to
//! d where d is the normal). That is the camera on the side that sees the point more
//! squarely: a scanner indexed to d can put its camera on either side of the stripe by
//! the direction it scans in, which the scan planner chooses per pass.

use super::pose::Head;
use super::probe::{Component, End, ProbeShape};
use super::{d2, gac, Backend, ConeOptions, CubeMap};
use crate::geometry::{P3, V3};
use crate::model::{Cmm, HeadKind, Model, Scanner};

/// How far above the surface a scanned point's rays start (mm): past the mesh's chordal
/// error (0.05 mm), so a concave face's own facets do not block its points.
pub const LIFT: f64 = 0.1;

/// The radius the rays' half-line is drawn with: any radius above zero makes the
/// rasterizer mark every pixel a shadow touches (cells, not centres), so a pixel left
/// free is free in every direction it holds — which the camera's line of sight needs, as
/// it rarely falls on a pixel centre.
const RAY_RADIUS: f64 = 1e-6;

/// The optics of a scanner, in millimetres and radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Optics {
    /// From the window to the middle of the depth of field.
    pub standoff: f64,
    /// The depth of field, centred on the stand-off.
    pub depth: f64,
    /// The stripe's length at the stand-off.
    pub stripe: f64,
    /// Laser to camera.
    pub triangulation: f64,
    /// The largest angle between the laser and the surface normal.
    pub max_incidence: f64,
    /// Point spacing along the stripe and between stripes.
    pub spacing: [f64; 2],
}

/// A scanner as mounted on a machine's head: its optics and its solid parts as a probe
/// with no tip — the housing from the stand-off out, then the head and ram.
#[derive(Debug, Clone, PartialEq)]
pub struct ScannerShape {
    /// The optics.
    pub optics: Optics,
    /// The housing (first component) and head and ram (second), along the laser from
    /// the scanned point; `tip_radius` is 0.
    pub probe: ProbeShape,
}

impl ScannerShape {
    /// A scanner as mounted on a machine's head, labelled `name`.
    pub fn new(model: &Model, cmm: &Cmm, name: &str, s: &Scanner) -> ScannerShape {
        let head = &model.heads[cmm.head.0];
        let kind = match head.kind {
            HeadKind::Fixed => Head::Fixed,
            HeadKind::Indexable { .. } => Head::Indexable,
        };
        let body_end = s.standoff + s.body[1];
        let first = vec![Component {
            name: "housing".into(),
            a: s.standoff,
            b: body_end,
            radius: s.body[0] / 2.0,
            end: End::Flat,
        }];
        let base = match kind {
            Head::Indexable => 0.0,
            Head::Fixed => body_end,
        };
        let second = vec![
            Component {
                name: "head".into(),
                a: base,
                b: base + head.length,
                radius: head.diameter / 2.0,
                end: End::Flat,
            },
            Component {
                name: "ram".into(),
                a: base + head.length,
                b: f64::INFINITY,
                radius: cmm.ram_radius,
                end: End::Flat,
            },
        ];
        ScannerShape {
            optics: Optics {
                standoff: s.standoff,
                depth: s.depth_of_field,
                stripe: s.stripe_width,
                triangulation: s.triangulation.to_radians(),
                max_incidence: s.max_incidence.to_radians(),
                spacing: s.spacing,
            },
            probe: ProbeShape {
                name: name.into(),
                tip_radius: 0.0,
                first,
                second,
                head: kind,
            },
        }
    }

    /// The scanners of a machine's rack.
    pub fn of_cmm(model: &Model, cmm: &Cmm) -> Vec<ScannerShape> {
        cmm.scanners
            .iter()
            .map(|(label, id)| ScannerShape::new(model, cmm, label, &model.scanners[id.0]))
            .collect()
    }
}

/// The camera's line of sight to a point seen along `d` (unit, towards the scanner) on a
/// surface with outward normal `n`: `d` turned by `angle` towards `n` (see the module's
/// decision).
pub fn camera_dir(d: &V3, n: &V3, angle: f64) -> V3 {
    let mut axis = d.cross(n);
    if axis.norm() < 1e-9 {
        let e = if d.x.abs() < 0.9 { V3::x() } else { V3::y() };
        axis = d.cross(&e);
    }
    let k = axis.normalize();
    // Rodrigues: k ⊥ d, so d turns to d cos θ + (k × d) sin θ, and k × d points to n.
    (d * angle.cos() + k.cross(d) * angle.sin()).normalize()
}

/// Whether a point is measured from direction `d` by the optics alone, by exact ray
/// casts: the incidence within the limit, and the laser's and the camera's rays from the
/// point (lifted by [`LIFT`]) reaching out unblocked.
pub fn sees(scene: &super::Scene, p: &P3, n: &V3, d: &V3, optics: &Optics) -> bool {
    if n.dot(d) < optics.max_incidence.cos() {
        return false;
    }
    let from = p + n * LIFT;
    let c = camera_dir(d, n, optics.triangulation);
    scene.cast_ray(&from, d, f64::INFINITY).is_none()
        && scene.cast_ray(&from, &c, f64::INFINITY).is_none()
}

/// The directions a scanner sees one surface point from.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanCones {
    /// Where the laser and the camera both reach the point within the incidence limit.
    pub rays: CubeMap,
    /// `rays` where the housing also clears the part with the point at the stand-off
    /// (and, on a fixed head, the head and ram): the scanner directions for an
    /// indexable head's D1, or the setups for a fixed head.
    pub visible: CubeMap,
    /// Indexable head only: D2, the setups from which the head and ram reach some
    /// direction of `visible` (a lower bound, as for touch probes).
    pub d2: Option<CubeMap>,
}

/// The scanner cones of the surface point `p` with outward unit normal `n`.
pub fn scan_cones(
    backend: &dyn Backend,
    scene: &super::Scene,
    p: &P3,
    n: &V3,
    scanner: &ScannerShape,
    opts: &ConeOptions,
) -> ScanCones {
    let (res, pref) = (opts.n, &opts.preferred[..]);
    let from = p + n * LIFT;
    let ray = Component {
        name: "laser".into(),
        a: 0.0,
        b: f64::INFINITY,
        radius: RAY_RADIUS,
        end: End::Round,
    };
    // The laser at pixel centres (exact there), the camera's lines of sight in whole
    // free pixels.
    let laser = backend
        .blocked(scene, &from, &Component::half_line(), res, pref)
        .not();
    let free = backend.blocked(scene, &from, &ray, res, pref).not();
    let optics = &scanner.optics;
    let mut rays = laser.and(&laser.cap(n, optics.max_incidence.cos()));
    let cells: Vec<_> = rays.cells().collect();
    for cell in cells {
        let d = rays.direction(cell);
        if !free.contains(&camera_dir(&d, n, optics.triangulation)) {
            rays.set(cell, false);
        }
    }
    let mut visible = rays.clone();
    if !visible.is_empty() {
        visible.and_assign(&gac(
            backend,
            scene,
            &from,
            &scanner.probe.leading(),
            res,
            pref,
        ));
    }
    let d2 = scanner.probe.head.indexable().then(|| {
        d2(
            backend,
            scene,
            &from,
            &scanner.probe,
            &visible,
            pref,
            opts.d2_samples,
        )
    });
    ScanCones { rays, visible, d2 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_camera_leans_towards_the_normal_by_the_triangulation_angle() {
        let n = V3::z();
        let d = V3::new(0.5, 0.0, 0.8).normalize();
        let c = camera_dir(&d, &n, 30f64.to_radians());
        assert!((c.dot(&d) - 30f64.to_radians().cos()).abs() < 1e-12);
        assert!(c.dot(&n) > d.dot(&n));
        // Along the normal itself the camera still leans by the angle.
        let c = camera_dir(&n, &n, 30f64.to_radians());
        assert!((c.dot(&n) - 30f64.to_radians().cos()).abs() < 1e-12);
    }
}
