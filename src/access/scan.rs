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
//! `tests/suite/scan.rs` compares the two on every example and the four NIST parts, and
//! `tests/suite/gpu.rs` the GPU backend's scanner cones with the CPU's).
//!
//! **Decision:** the camera's line of sight is d turned by the triangulation angle
//! towards the surface normal, in the plane of d and the normal (about any axis square to
//! d where d is the normal). That is the camera on the side that sees the point more
//! squarely: a scanner indexed to d can put its camera on either side of the stripe by
//! the direction it scans in, which the scan planner chooses per pass.

use super::probe::{second_components, Component, End, ProbeShape};
use super::{d2, gac, Backend, ConeOptions, CubeMap};
use crate::geometry::{P3, V3};
use crate::model::{Cmm, Model, Scanner};
use rayon::prelude::*;

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
        let body_end = s.standoff + s.body[1];
        let first = vec![Component {
            name: "housing".into(),
            a: s.standoff,
            b: body_end,
            radius: s.body[0] / 2.0,
            end: End::Flat,
        }];
        let (kind, second) = second_components(model, cmm, body_end);
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

/// Every sensor of a machine's rack by slot, as solids that move: the probes, then the
/// scanners (housing, head and ram; no tip).
pub fn sensor_shapes(model: &Model, cmm: &Cmm) -> Vec<ProbeShape> {
    let mut shapes = ProbeShape::of_cmm(model, cmm);
    shapes.extend(
        ScannerShape::of_cmm(model, cmm)
            .into_iter()
            .map(|s| s.probe),
    );
    shapes
}

/// The camera's line of sight to a point seen along `d` (unit, towards the scanner) on a
/// surface with outward normal `n`: `d` turned by `angle` towards `n` (see the module's
/// decision).
pub(crate) fn camera_dir(d: &V3, n: &V3, angle: f64) -> V3 {
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
    let optics = &scanner.optics;
    // Only directions above the tangent plane through `from` are asked of the laser and
    // camera maps (both lie within the incidence limit or the triangulation angle of
    // `n`): a triangle wholly below that plane blocks none of them.
    let above = scene.above(&from, n, f64::MIN_POSITIVE);
    // The laser at pixel centres (exact there), the camera's lines of sight in whole
    // free pixels.
    let laser = backend
        .blocked(&above, &from, &Component::half_line(), res, pref)
        .not();
    let free = backend.blocked(&above, &from, &ray, res, pref).not();
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
        // The housing is asked only in the pixels of `rays`, within the incidence limit
        // α of `n`: each of their directions within α + δ, δ = 3/N rad a pixel's
        // diameter (2√2/N at most), which also bounds the pixels a preferred direction
        // of the cap is judged by. A component from a along d with radius r stays at
        // least a·cos(α + δ) − r above the tangent plane; a triangle wholly below that
        // cannot touch it. (Drawn at D2's coarser resolution it took a sixth less time
        // and cost CTC 01's mixed plan two more head orientations: not taken.)
        let leading = scanner.probe.leading();
        let widest = (optics.max_incidence + 3.0 / res as f64).min(std::f64::consts::FRAC_PI_2);
        let floor = leading
            .iter()
            .map(|c| c.a * widest.cos() - c.radius)
            .fold(f64::INFINITY, f64::min);
        let near = scene.above(&from, n, floor);
        visible.and_assign(&gac(backend, &near, &from, &leading, res, pref));
    }
    let d2 = scanner
        .probe
        .head
        .indexable()
        .then(|| d2(backend, scene, &from, &scanner.probe, &visible, opts));
    ScanCones { rays, visible, d2 }
}

/// How many samples a face's coverage is judged on, at most.
const FACE_SAMPLES: usize = 300;

/// One head orientation a face is scanned from, with what it covers.
#[derive(Debug, Clone, PartialEq)]
pub struct View {
    /// Head angles (degrees); (0, 0) on a fixed head.
    pub a: f64,
    /// B angle (degrees).
    pub b: f64,
    /// The scanner's direction in the part frame: from the surface towards the scanner.
    pub dir: V3,
    /// The share of the face's area this view adds.
    pub share: f64,
    /// Parallel passes of the stripe (Zhao et al. eq. 15), one per strip and elevation.
    pub passes: usize,
    /// How long the longest pass is (mm).
    pub length: f64,
    /// Heights of the scanner along the view for the depth of field (Zhao et al. 5.2).
    pub elevations: usize,
    /// The passes: the line the middle of the depth of field runs along, part frame.
    pub lines: Vec<Pass>,
}

/// One pass of the stripe: the middle of the depth of field runs from `start` to `end`
/// (part frame), the stripe square to the motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pass {
    /// Where the pass starts.
    pub start: P3,
    /// Where it ends.
    pub end: P3,
}

/// Where a face may be scanned from and how passes lie.
#[derive(Debug, Clone, Copy)]
pub struct Views<'a> {
    /// The head's orientations (degrees); one (0, 0) for a fixed head.
    pub grid: &'a [(f64, f64)],
    /// The share of a stripe's width neighbouring passes overlap.
    pub overlap: f64,
    /// The setup: the part direction facing the ram (`+z` for the part in its own
    /// frame).
    pub up: V3,
    /// The table's height along `up` and the margin the housing keeps above it and
    /// from the fixture (`f64::NEG_INFINITY` for no table).
    pub table: (f64, f64),
    /// The fixture holding the part in this setup (part frame).
    pub fixture: &'a [super::pose::Solid],
}

/// How a scanner covers one face from a head's orientations (Zhao et al. 5.1–5.3),
/// judged on area-weighted samples of the face.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceCoverage {
    /// The face's area (mm²).
    pub area: f64,
    /// How many samples judged it.
    pub samples: usize,
    /// The orientations chosen, most area first (greedy cover).
    pub views: Vec<View>,
    /// The share of the area some view sees.
    pub covered: f64,
}

/// Area-weighted samples of a face: each triangle cut into k² similar pieces, the
/// pieces' centroids with their areas and the surface's outward normal there.
fn face_samples(g: &crate::geometry::PartGeometry, face: usize) -> Vec<(P3, V3, f64)> {
    let f = &g.faces[face];
    let h = (2.0 * f.area / FACE_SAMPLES as f64).sqrt().max(1e-3);
    let mut out = Vec::new();
    for &t in &f.triangles {
        let v = g.triangles[t as usize].map(|i| g.vertices[i as usize]);
        let tn = (v[1] - v[0]).cross(&(v[2] - v[0]));
        let area = tn.norm() / 2.0;
        if area < 1e-12 {
            continue;
        }
        // k² pieces of about h²/2 each: the face's area decides the count, not how long
        // and thin its triangles are.
        let k = (((2.0 * area).sqrt() / h).ceil() as usize).clamp(1, 16);
        let piece = area / (k * k) as f64;
        let at =
            |i: f64, j: f64| v[0] + (v[1] - v[0]) * (i / k as f64) + (v[2] - v[0]) * (j / k as f64);
        for i in 0..k {
            for j in 0..k - i {
                let (fi, fj) = (i as f64, j as f64);
                let mut pieces = vec![[at(fi, fj), at(fi + 1.0, fj), at(fi, fj + 1.0)]];
                if i + j + 1 < k {
                    pieces.push([at(fi + 1.0, fj), at(fi + 1.0, fj + 1.0), at(fi, fj + 1.0)]);
                }
                for q in pieces {
                    let c = P3::from((q[0].coords + q[1].coords + q[2].coords) / 3.0);
                    let n = f.surface.normal_at(&c).unwrap_or_else(|| tn.normalize());
                    out.push((c, n, piece));
                }
            }
        }
    }
    out
}

/// A face's area-weighted samples and, per sample, the directions the scanner sees it
/// from ([`ScanCones::visible`]): what a face's coverage needs that does not depend on
/// the setup, so a planner trying the face in several setups draws its cones once.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceCones {
    /// Samples: point, outward normal, the area it stands for.
    samples: Vec<(P3, V3, f64)>,
    /// Per sample, where the laser, the camera and the housing clear the part.
    visible: Vec<CubeMap>,
}

impl FaceCones {
    /// The cones of `face`'s samples for `scanner`.
    pub fn new(
        backend: &dyn Backend,
        scene: &super::Scene,
        g: &crate::geometry::PartGeometry,
        face: usize,
        scanner: &ScannerShape,
        opts: &ConeOptions,
    ) -> FaceCones {
        let samples = face_samples(g, face);
        // D2 is not asked: the coverage decides the head and ram per orientation from
        // one depth map along the setup's `up`.
        let opts = ConeOptions {
            d2_samples: 0,
            ..opts.clone()
        };
        let visible = samples
            .par_iter()
            .map(|(p, n, _)| scan_cones(backend, scene, p, n, scanner, &opts).visible)
            .collect();
        FaceCones { samples, visible }
    }

    /// The coverage of the face by `scanner` from the head orientations of `views` (one
    /// (0, 0) for a fixed head), the part standing with `views.up` facing the ram. Per
    /// sample, the orientations whose direction the scanner's cone sees it from and
    /// whose head and ram clear the part; then a greedy cover by area until a view would
    /// add less than 1 % of it, taking among the views within 1 % of the best gain the
    /// one nearest the mean normal of what it sees. Per chosen orientation its passes:
    /// the stripe square to the motion, which runs along whichever of 12 directions (15°
    /// apart) in the view's plane makes the passes shortest, the views' overlap between
    /// neighbouring passes, and one elevation per depth of field.
    pub fn coverage(
        &self,
        scene: &super::Scene,
        scanner: &ScannerShape,
        views: &Views,
    ) -> FaceCoverage {
        let samples = &self.samples;
        let (grid, overlap) = (views.grid, views.overlap);
        let area: f64 = samples.iter().map(|s| s.2).sum();
        // How far apart the samples lie.
        let spacing = (2.0 * area / FACE_SAMPLES as f64).sqrt();
        let up = views.up;
        let dirs: Vec<V3> = match scanner.probe.head {
            super::pose::Head::Indexable => grid
                .iter()
                .map(|&(a, b)| super::pose::orientation_dir(&up, a, b))
                .collect(),
            super::pose::Head::Fixed => vec![up; grid.len()],
        };
        let reach = scanner.probe.reach();
        // The head and ram hang straight down from the articulation point: one depth map
        // along `up` answers for every sample and orientation.
        let second = scanner.probe.head.indexable().then(|| {
            let radius = scanner
                .probe
                .second
                .iter()
                .map(|c| c.radius)
                .fold(0.0, f64::max);
            super::SecondMap::new(scene, &up, radius, reach)
        });
        // The housing keeps off the table wherever in the depth of field a pass puts the
        // focus: checked with the focus half the depth nearer the table.
        let (table, margin) = views.table;
        let off_table = |p: &P3, d: &V3| {
            let c = p - d * (scanner.optics.depth / 2.0);
            scanner
                .probe
                .first
                .iter()
                .all(|comp| super::pose::lowest(comp, &c, d, &up) >= table + margin)
        };
        // The fixture, per direction: the scanner posed with its focus at the sample.
        let held: Vec<Option<super::pose::Pose>> = dirs
            .iter()
            .map(|d| {
                (!views.fixture.is_empty()).then(|| {
                    super::pose::Pose::new(scene, &scanner.probe, *d, up, table)
                        .with_fixture(views.fixture)
                        .with_margin(margin)
                })
            })
            .collect();
        // The incidence limit exactly: the cone's pixels are judged at their centres,
        // and a head orientation at the limit lies in a pixel whose centre is inside it
        // as often as not (a view of a boss along its axis saw nothing on the machine).
        let grazing = scanner.optics.max_incidence.cos();
        let sees_from: Vec<Vec<bool>> = samples
            .par_iter()
            .zip(&self.visible)
            .map(|((p, n, _), visible)| {
                let from = p + n * LIFT;
                dirs.iter()
                    .zip(&held)
                    .map(|(d, pose)| {
                        n.dot(d) >= grazing
                            && visible.contains(d)
                            && off_table(p, d)
                            && second.as_ref().is_none_or(|m| m.clear(&(from + d * reach)))
                            && pose.as_ref().is_none_or(|x| x.clear_of_fixture(p))
                    })
                    .collect()
            })
            .collect();
        greedy_cover(
            samples,
            &sees_from,
            &dirs,
            grid,
            &scanner.optics,
            overlap,
            spacing,
        )
    }
}

/// The coverage of `face` by a scanner from the head orientations of `views`:
/// [`FaceCones::coverage`] of the face's cones.
pub fn face_coverage(
    backend: &dyn Backend,
    scene: &super::Scene,
    g: &crate::geometry::PartGeometry,
    face: usize,
    scanner: &ScannerShape,
    views: &Views,
    opts: &ConeOptions,
) -> FaceCoverage {
    FaceCones::new(backend, scene, g, face, scanner, opts).coverage(scene, scanner, views)
}

/// The greedy cover of [`FaceCones::coverage`]: `sees_from[i][j]` says whether sample
/// `i` is seen from direction `dirs[j]` (head angles `grid[j]`).
fn greedy_cover(
    samples: &[(P3, V3, f64)],
    sees_from: &[Vec<bool>],
    dirs: &[V3],
    grid: &[(f64, f64)],
    optics: &Optics,
    overlap: f64,
    spacing: f64,
) -> FaceCoverage {
    let area: f64 = samples.iter().map(|s| s.2).sum();
    let mut left: Vec<bool> = vec![true; samples.len()];
    let mut views = Vec::new();
    let mut covered = 0.0;
    loop {
        let gain = |j: usize| -> f64 {
            (0..samples.len())
                .filter(|&i| left[i] && sees_from[i][j])
                .map(|i| samples[i].2)
                .sum()
        };
        let gains: Vec<f64> = (0..dirs.len()).map(gain).collect();
        let top = gains.iter().copied().fold(0.0, f64::max);
        // A view that adds less than 1 % of the area is not worth a head move.
        if top < 0.01 * area {
            break;
        }
        // Among the views within 1 % of the best's gain, the one nearest the mean normal
        // of what the first of them sees (Zhao et al.'s step 4).
        let first = (0..dirs.len()).find(|&j| gains[j] == top).unwrap_or(0);
        let mean: V3 = (0..samples.len())
            .filter(|&i| left[i] && sees_from[i][first])
            .map(|i| samples[i].1 * samples[i].2)
            .sum();
        let mean = mean.try_normalize(1e-12).unwrap_or(dirs[first]);
        let mut j = first;
        for k in 0..dirs.len() {
            if gains[k] >= 0.99 * top && dirs[k].dot(&mean) > dirs[j].dot(&mean) + 1e-12 {
                j = k;
            }
        }
        let mine: Vec<usize> = (0..samples.len())
            .filter(|&i| left[i] && sees_from[i][j])
            .collect();
        for &i in &mine {
            left[i] = false;
        }
        covered += gains[j];
        let pts: Vec<P3> = mine.iter().map(|&i| samples[i].0).collect();
        let (lines, elevations) = passes(&pts, &dirs[j], optics, overlap, spacing / 2.0);
        views.push(View {
            a: grid[j].0,
            b: grid[j].1,
            dir: dirs[j],
            share: gains[j] / area,
            passes: lines.len(),
            length: lines
                .iter()
                .map(|l| (l.end - l.start).norm())
                .fold(0.0, f64::max),
            elevations,
            lines,
        });
    }
    FaceCoverage {
        area,
        samples: samples.len(),
        views,
        covered: if area > 0.0 { covered / area } else { 0.0 },
    }
}

/// The passes over points seen along `d`, and how many elevations they take. The
/// motion runs along whichever of 12 directions (15° apart) square to `d` makes the
/// strips' total length least, each strip charged a stand-off more for its way in and
/// out; the strips are the stripe's width less the overlap apart; the depth of field
/// cuts the points into elevations from the highest down. Each (elevation, strip)
/// holding points is one pass, from its first point to its last along the motion
/// lengthened by `pad` at both ends (the samples' spacing: a sample stands for the area
/// around it), its focus midway between its nearest and farthest points along `d`.
fn passes(pts: &[P3], d: &V3, optics: &Optics, overlap: f64, pad: f64) -> (Vec<Pass>, usize) {
    let e1 = if d.x.abs() < 0.9 { V3::x() } else { V3::y() };
    let e1 = (e1 - d * d.dot(&e1)).normalize();
    let e2 = d.cross(&e1);
    let width = optics.stripe * (1.0 - overlap);
    let range = |v: &V3| {
        pts.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                let x = p.coords.dot(v);
                (lo.min(x), hi.max(x))
            })
    };
    let mut best = (V3::x(), f64::INFINITY);
    for k in 0..12 {
        let t = (k as f64 * 15.0).to_radians();
        let m = e1 * t.cos() + e2 * t.sin();
        let across = d.cross(&m);
        let ((lo, hi), (alo, ahi)) = (range(&m), range(&across));
        let n = (((ahi - alo).max(0.0) / width).ceil()).max(1.0);
        // Each pass also costs its way in and out: about a stand-off.
        let total = n * ((hi - lo).max(0.0) + optics.standoff);
        if total < best.1 - 1e-9 {
            best = (m, total);
        }
    }
    let m = best.0;
    let across = d.cross(&m);
    // Elevations: from the highest point down, a new one wherever the depth of field
    // ends; each keeps the height of its first (highest) point.
    let mut depth: Vec<f64> = pts.iter().map(|p| p.coords.dot(d)).collect();
    depth.sort_by(|a, b| b.total_cmp(a));
    let mut tops: Vec<f64> = Vec::new();
    for x in depth {
        if tops.last().is_none_or(|t| t - x > optics.depth) {
            tops.push(x);
        }
    }
    let (alo, ahi) = range(&across);
    let strips = (((ahi - alo).max(0.0) / width).ceil() as usize).max(1);
    // A strip centred on the points it holds: the first strip's edge on the first point.
    let spare = strips as f64 * width - (ahi - alo).max(0.0);
    let a0 = alo - spare / 2.0;
    let mut lines = Vec::new();
    for &top in &tops {
        for s in 0..strips {
            let (lo, hi) = (a0 + s as f64 * width, a0 + (s + 1) as f64 * width);
            let mine: Vec<&P3> = pts
                .iter()
                .filter(|p| {
                    let (x, h) = (p.coords.dot(&across), p.coords.dot(d));
                    x >= lo - 1e-9 && x <= hi + 1e-9 && h <= top + 1e-9 && h > top - optics.depth
                })
                .collect();
            if mine.is_empty() {
                continue;
            }
            let span = |v: &V3| {
                mine.iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                        let x = p.coords.dot(v);
                        (a.min(x), b.max(x))
                    })
            };
            let (along, height) = (span(&m), span(d));
            let mid = (height.0 + height.1) / 2.0;
            let at = |t: f64| P3::from(m * t + across * ((lo + hi) / 2.0) + d * mid);
            lines.push(Pass {
                start: at(along.0 - pad),
                end: at(along.1 + pad),
            });
        }
    }
    (lines, tops.len())
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
