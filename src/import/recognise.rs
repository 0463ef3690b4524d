//! A default inspection for a CAD part whose file carries no PMI: the features a
//! metrologist would check on a machined block, found from the B-rep's exact surfaces,
//! with general tolerances in place of the drawing's.
//!
//! **What is recognised** (faces of the solid only, from `CadPart::mesh.exact`):
//! - *planes*: coplanar faces are one feature (a top split by a slot is one top);
//! - *the datum reference frame*: A the largest plane, B the largest plane
//!   perpendicular to A, C the largest perpendicular to both — the faces an operator
//!   would clamp against (ASME Y14.5-2018 §7: primary, secondary, tertiary in order of
//!   contact);
//! - *holes and bosses*: coaxial cylindrical faces of one radius that go round at least
//!   300° (a fillet or a slot's rounded end does not);
//! - *slots and pockets*: two parallel planes facing each other, overlapping when
//!   projected onto one another; *outer sizes*: the outermost planes along a datum's
//!   normal, facing apart;
//! - *steps and floors*: other planes parallel to a datum plane.
//!
//! **What it asks**: flatness of every plane at least a tenth the area of the largest;
//! the diameter of each hole and boss and its position to the frame; the width of each
//! slot and of the part along each datum's normal; each step's distance from the datum
//! plane it is parallel to.
//!
//! **The values are general tolerances, not the drawing's**, and the spec says so: sizes
//! and distances ± ISO 2768-1 class *m* for their nominal length; flatness ISO 2768-2
//! class *K* for the plane's longest side; a position zone of Ø2t, t being ISO 2768-1 *m*
//! for the hole's larger distance to datums B and C — the circle inscribed in the ±t
//! square that coordinate tolerances would give, so no part the coordinate tolerances
//! reject passes it.

use crate::geometry::step::CadPart;
use crate::geometry::{Surface, P3, V3};
use crate::model::fmt_num;

/// The default inspection: features by faces, datums, tolerances, and what was not
/// inspected.
pub(super) struct DefaultInspection {
    /// Each feature's faces (0-based) and its preferred name.
    pub features: Vec<(Vec<usize>, String)>,
    /// Datum letters on features (indices into `features`).
    pub datums: Vec<(char, usize)>,
    pub tolerances: Vec<DefaultTol>,
    /// What the spec should say of the faces left uninspected.
    pub notes: Vec<String>,
}

/// One default tolerance: `keyword(features…, value, datums…)`.
pub(super) struct DefaultTol {
    pub keyword: &'static str,
    /// Indices into [`DefaultInspection::features`].
    pub features: Vec<usize>,
    /// The value as the language writes it: `0.2 mm`, `dia 0.6 mm`, `20 mm ± 0.2 mm`.
    pub value: String,
    pub datums: Vec<char>,
}

/// ISO 2768-1 class m: the permissible deviation (± mm) of a linear size by nominal.
pub(super) fn iso2768_m(nominal: f64) -> f64 {
    const ROWS: [(f64, f64); 8] = [
        (3.0, 0.1),
        (6.0, 0.1),
        (30.0, 0.2),
        (120.0, 0.3),
        (400.0, 0.5),
        (1000.0, 0.8),
        (2000.0, 1.2),
        (4000.0, 2.0),
    ];
    ROWS.iter()
        .find(|(upto, _)| nominal <= *upto)
        .map_or(3.0, |r| r.1)
}

/// ISO 2768-2 class K: the straightness and flatness tolerance (mm) by nominal length.
pub(super) fn iso2768_k_flatness(length: f64) -> f64 {
    const ROWS: [(f64, f64); 6] = [
        (10.0, 0.05),
        (30.0, 0.1),
        (100.0, 0.2),
        (300.0, 0.4),
        (1000.0, 0.6),
        (3000.0, 0.8),
    ];
    ROWS.iter()
        .find(|(upto, _)| length <= *upto)
        .map_or(0.8, |r| r.1)
}

/// One face of the solid: its exact surface, area, centroid and triangles.
struct FaceInfo {
    surface: Surface,
    area: f64,
    centroid: P3,
    triangles: Vec<[P3; 3]>,
}

fn faces_of(part: &CadPart) -> Vec<FaceInfo> {
    let m = &part.mesh;
    let n = part.solid_faces().min(m.exact.len());
    let mut out: Vec<FaceInfo> = (0..n)
        .map(|k| FaceInfo {
            surface: m.exact[k].clone(),
            area: 0.0,
            centroid: P3::origin(),
            triangles: Vec::new(),
        })
        .collect();
    let mut weighted = vec![V3::zeros(); n];
    for (t, &g) in m.triangles.iter().zip(&m.tri_group) {
        let Some(f) = out.get_mut(g as usize) else {
            continue;
        };
        let p = t.map(|i| m.vertices[i as usize]);
        let a = (p[1] - p[0]).cross(&(p[2] - p[0])).norm() / 2.0;
        f.area += a;
        weighted[g as usize] += (p[0].coords + p[1].coords + p[2].coords) * (a / 3.0);
        f.triangles.push(p);
    }
    for (f, w) in out.iter_mut().zip(weighted) {
        if f.area > 0.0 {
            f.centroid = P3::from(w / f.area);
        }
    }
    out
}

/// A plane feature: coplanar faces.
struct PlaneGroup {
    faces: Vec<usize>,
    normal: V3,
    /// A point on the plane.
    origin: P3,
    area: f64,
    vertices: Vec<P3>,
}

impl PlaneGroup {
    /// Signed offset of the plane along `n`.
    fn offset(&self, n: &V3) -> f64 {
        self.origin.coords.dot(n)
    }
}

/// A hole or boss: coaxial cylindrical faces of one radius.
struct CylGroup {
    faces: Vec<usize>,
    origin: P3,
    axis: V3,
    radius: f64,
    convex: bool,
    triangles: Vec<[P3; 3]>,
}

const PARALLEL: f64 = 0.999_999;
const PERPENDICULAR: f64 = 1e-3;

fn plane_groups(faces: &[FaceInfo], tol: f64) -> Vec<PlaneGroup> {
    let mut out: Vec<PlaneGroup> = Vec::new();
    for (k, f) in faces.iter().enumerate() {
        let Surface::Plane { origin, normal } = f.surface else {
            continue;
        };
        if f.area <= 0.0 {
            continue;
        }
        let same = out.iter_mut().find(|g| {
            g.normal.dot(&normal) > PARALLEL && (origin - g.origin).dot(&g.normal).abs() < tol
        });
        match same {
            Some(g) => {
                g.faces.push(k);
                g.area += f.area;
                g.vertices.extend(f.triangles.iter().flatten());
            }
            None => out.push(PlaneGroup {
                faces: vec![k],
                normal,
                origin,
                area: f.area,
                vertices: f.triangles.iter().flatten().copied().collect(),
            }),
        }
    }
    out
}

fn cylinder_groups(faces: &[FaceInfo], tol: f64) -> Vec<CylGroup> {
    let mut out: Vec<CylGroup> = Vec::new();
    for (k, f) in faces.iter().enumerate() {
        let Surface::Cylinder {
            origin,
            axis,
            radius,
            convex,
        } = f.surface
        else {
            continue;
        };
        if f.area <= 0.0 {
            continue;
        }
        let same = out.iter_mut().find(|g| {
            let d = origin - g.origin;
            g.axis.dot(&axis).abs() > PARALLEL
                && (radius - g.radius).abs() < tol
                && g.convex == convex
                && (d - g.axis * d.dot(&g.axis)).norm() < tol
        });
        match same {
            Some(g) => {
                g.faces.push(k);
                g.triangles.extend(&f.triangles);
            }
            None => out.push(CylGroup {
                faces: vec![k],
                origin,
                axis,
                radius,
                convex,
                triangles: f.triangles.clone(),
            }),
        }
    }
    out
}

/// How far round its axis a cylinder group goes (degrees, in whole degrees covered).
fn coverage_deg(g: &CylGroup) -> usize {
    let u = any_perpendicular(&g.axis);
    let v = g.axis.cross(&u);
    let angle = |p: &P3| {
        let d = p - g.origin;
        d.dot(&v).atan2(d.dot(&u)).to_degrees().rem_euclid(360.0)
    };
    let mut bins = [false; 360];
    for t in &g.triangles {
        let a: Vec<f64> = t.iter().map(angle).collect();
        // A triangle spans the shorter arc between its corners.
        let (lo, hi) = (
            a.iter().copied().fold(f64::MAX, f64::min),
            a.iter().copied().fold(f64::MIN, f64::max),
        );
        let (from, span) = if hi - lo <= 180.0 {
            (lo, hi - lo)
        } else {
            let wrapped: Vec<f64> = a
                .iter()
                .map(|x| if *x < 180.0 { x + 360.0 } else { *x })
                .collect();
            let lo = wrapped.iter().copied().fold(f64::MAX, f64::min);
            let hi = wrapped.iter().copied().fold(f64::MIN, f64::max);
            (lo, hi - lo)
        };
        let steps = span.ceil() as usize;
        for s in 0..=steps {
            let deg = (from + s as f64).min(from + span);
            bins[(deg.floor() as usize) % 360] = true;
        }
    }
    bins.iter().filter(|b| **b).count()
}

fn any_perpendicular(n: &V3) -> V3 {
    let pick = if n.x.abs() < 0.9 { V3::x() } else { V3::y() };
    n.cross(&pick).normalize()
}

/// The largest span of `points` along any of the plane's two in-plane directions, and
/// their extents there (for overlap tests).
fn in_plane_box(points: &[P3], normal: &V3) -> ([f64; 2], [f64; 2]) {
    let u = any_perpendicular(normal);
    let v = normal.cross(&u);
    let mut lo = [f64::MAX; 2];
    let mut hi = [f64::MIN; 2];
    for p in points {
        let c = [p.coords.dot(&u), p.coords.dot(&v)];
        for i in 0..2 {
            lo[i] = lo[i].min(c[i]);
            hi[i] = hi[i].max(c[i]);
        }
    }
    (lo, hi)
}

fn longest_side(points: &[P3], normal: &V3) -> f64 {
    let (lo, hi) = in_plane_box(points, normal);
    (hi[0] - lo[0]).max(hi[1] - lo[1])
}

/// Whether two parallel planes overlap when one is projected onto the other (by more
/// than `tol` each way).
fn overlap(a: &PlaneGroup, b: &PlaneGroup, tol: f64) -> bool {
    let (alo, ahi) = in_plane_box(&a.vertices, &a.normal);
    let (blo, bhi) = in_plane_box(&b.vertices, &a.normal);
    (0..2).all(|i| ahi[i].min(bhi[i]) - alo[i].max(blo[i]) > tol)
}

/// The name of a plane by the way it faces and where it lies: `top_40` faces +z at
/// z = 40; a plane facing no axis is `plane_<n>`.
fn plane_name(g: &PlaneGroup, k: usize) -> String {
    const AXES: [(V3, &str); 6] = [
        (V3::new(0.0, 0.0, 1.0), "top"),
        (V3::new(0.0, 0.0, -1.0), "bottom"),
        (V3::new(1.0, 0.0, 0.0), "right"),
        (V3::new(-1.0, 0.0, 0.0), "left"),
        (V3::new(0.0, 1.0, 0.0), "back"),
        (V3::new(0.0, -1.0, 0.0), "front"),
    ];
    match AXES.iter().find(|(a, _)| a.dot(&g.normal) > PARALLEL) {
        Some((a, word)) => {
            let at = g.origin.coords.dot(&a.map(f64::abs));
            let at = fmt_num((at * 100.0).round() / 100.0)
                .replace('-', "m")
                .replace('.', "_");
            format!("{word}_{at}")
        }
        None => format!("plane_{}", k + 1),
    }
}

fn size(nominal: f64) -> String {
    let n = (nominal * 1e4).round() / 1e4;
    format!("{} mm ± {} mm", fmt_num(n), fmt_num(iso2768_m(n)))
}

/// The default inspection of `part`, `None` when its faces carry no exact surfaces.
pub(super) fn default_inspection(part: &CadPart) -> Option<DefaultInspection> {
    let faces = faces_of(part);
    if faces.is_empty() || faces.iter().all(|f| matches!(f.surface, Surface::Freeform)) {
        return None;
    }
    let (mut lo, mut hi) = (P3::from([f64::MAX; 3]), P3::from([f64::MIN; 3]));
    for v in &part.mesh.vertices {
        lo = lo.inf(v);
        hi = hi.sup(v);
    }
    let tol = 1e-5 * (hi - lo).norm().max(1e-3) + 1e-6;
    let mut planes = plane_groups(&faces, tol);
    // Largest first; a stable sort keeps the file's order among equals.
    planes.sort_by(|a, b| b.area.total_cmp(&a.area));
    let mut found = Found {
        plane_feature: vec![None; planes.len()],
        planes,
        tol,
        frame: Vec::new(),
        paired: Vec::new(),
        out: DefaultInspection {
            features: Vec::new(),
            datums: Vec::new(),
            tolerances: Vec::new(),
            notes: Vec::new(),
        },
    };
    found.frame();
    found.flatness();
    found.slots();
    found.sizes_and_steps();
    found.holes(&cylinder_groups(&faces, tol));
    let others = faces
        .iter()
        .filter(|f| !matches!(f.surface, Surface::Plane { .. } | Surface::Cylinder { .. }))
        .count();
    if others > 0 {
        found.out.notes.push(format!(
            "{others} face{} neither plane nor cylinder not inspected",
            if others == 1 { "" } else { "s" }
        ));
    }
    Some(found.out)
}

/// The recognition under way: the plane groups, largest first, and what is written.
struct Found {
    planes: Vec<PlaneGroup>,
    /// Per plane group, its feature once one is written.
    plane_feature: Vec<Option<usize>>,
    tol: f64,
    /// The planes of datums A, B, C.
    frame: Vec<usize>,
    /// Per plane group, whether it is a wall of a slot.
    paired: Vec<bool>,
    out: DefaultInspection,
}

impl Found {
    /// The feature of plane group `k`, written the first time it is asked for.
    fn feature_of(&mut self, k: usize) -> usize {
        if let Some(f) = self.plane_feature[k] {
            return f;
        }
        let name = plane_name(&self.planes[k], k);
        self.out.features.push((self.planes[k].faces.clone(), name));
        let f = self.out.features.len() - 1;
        self.plane_feature[k] = Some(f);
        f
    }

    fn push(
        &mut self,
        keyword: &'static str,
        features: Vec<usize>,
        value: String,
        datums: &[char],
    ) {
        self.out.tolerances.push(DefaultTol {
            keyword,
            features,
            value,
            datums: datums.to_vec(),
        });
    }

    /// The frame: A the largest plane, B the largest ⟂ A, C the largest ⟂ both.
    fn frame(&mut self) {
        for k in 0..self.planes.len() {
            let n = self.planes[k].normal;
            let square = self
                .frame
                .iter()
                .all(|&j| self.planes[j].normal.dot(&n).abs() < PERPENDICULAR);
            if self.frame.len() < 3 && square {
                self.frame.push(k);
            }
        }
        for (i, k) in self.frame.clone().into_iter().enumerate() {
            let f = self.feature_of(k);
            self.out.datums.push((LETTERS[i], f));
        }
    }

    /// Flatness of every plane at least a tenth the area of the largest.
    fn flatness(&mut self) {
        let largest = self.planes.first().map_or(0.0, |p| p.area);
        for k in 0..self.planes.len() {
            let g = &self.planes[k];
            if g.area >= largest / 10.0 {
                let zone = iso2768_k_flatness(longest_side(&g.vertices, &g.normal));
                let f = self.feature_of(k);
                self.push("flatness", vec![f], format!("{} mm", fmt_num(zone)), &[]);
            }
        }
    }

    /// Slots and pockets: each plane with the nearest parallel plane that faces it and
    /// overlaps it, as one feature with a width.
    fn slots(&mut self) {
        let planes = &self.planes;
        let tol = self.tol;
        let mut paired = vec![false; planes.len()];
        let mut widths = Vec::new();
        for i in 0..planes.len() {
            if paired[i] {
                continue;
            }
            let n = planes[i].normal;
            let gap = |j: usize| (planes[j].origin - planes[i].origin).dot(&n);
            let partner = (0..planes.len())
                .filter(|&j| !paired[j] && planes[j].normal.dot(&n) < -PARALLEL)
                .filter(|&j| gap(j) > tol && overlap(&planes[i], &planes[j], tol))
                .min_by(|&a, &b| gap(a).total_cmp(&gap(b)));
            if let Some(j) = partner {
                paired[i] = true;
                paired[j] = true;
                let mut faces = planes[i].faces.clone();
                faces.extend(&planes[j].faces);
                faces.sort_unstable();
                widths.push((faces, gap(j)));
            }
        }
        for (k, (faces, width)) in widths.into_iter().enumerate() {
            self.out.features.push((faces, format!("slot_{}", k + 1)));
            let f = self.out.features.len() - 1;
            self.push("width", vec![f], size(width), &[]);
        }
        self.paired = paired;
    }

    /// Along each datum's normal: the part's size between its outermost planes, and the
    /// distance from the datum plane to every other plane parallel to it (steps, floors).
    fn sizes_and_steps(&mut self) {
        for d in self.frame.clone() {
            let n = self.planes[d].normal;
            let along: Vec<usize> = (0..self.planes.len())
                .filter(|&j| self.planes[j].normal.dot(&n).abs() > PARALLEL)
                .collect();
            let outer = |sign: f64| {
                let planes = &self.planes;
                along
                    .iter()
                    .copied()
                    .filter(|&j| planes[j].normal.dot(&n) * sign > 0.0)
                    .max_by(|&a, &b| {
                        (planes[a].offset(&n) * sign).total_cmp(&(planes[b].offset(&n) * sign))
                    })
            };
            let (hi, lo) = (outer(1.0), outer(-1.0));
            if let (Some(hi), Some(lo)) = (hi, lo) {
                let width = self.planes[hi].offset(&n) - self.planes[lo].offset(&n);
                let (fl, fh) = (self.feature_of(lo), self.feature_of(hi));
                self.push("distance", vec![fl, fh], size(width), &[]);
            }
            for &j in &along {
                let gap = (self.planes[j].offset(&n) - self.planes[d].offset(&n)).abs();
                let outermost = Some(j) == hi || Some(j) == lo;
                if j == d || outermost || self.paired[j] || gap <= self.tol {
                    continue;
                }
                let (fd, fj) = (self.feature_of(d), self.feature_of(j));
                self.push("distance", vec![fd, fj], size(gap), &[]);
            }
        }
    }

    /// Holes and bosses: the diameter, and the position to the frame with a zone from
    /// the axis's larger distance to the datum planes B and C.
    fn holes(&mut self, cylinders: &[CylGroup]) {
        let letters: Vec<char> = LETTERS[..self.frame.len()].to_vec();
        let (mut partial, mut holes, mut bosses) = (0, 0, 0);
        for g in cylinders {
            if coverage_deg(g) < 300 {
                partial += g.faces.len();
                continue;
            }
            let name = if g.convex {
                bosses += 1;
                format!("boss_{bosses}")
            } else {
                holes += 1;
                format!("hole_{holes}")
            };
            self.out.features.push((g.faces.clone(), name));
            let f = self.out.features.len() - 1;
            self.push("diameter", vec![f], size(2.0 * g.radius), &[]);
            if letters.is_empty() {
                continue;
            }
            let reach = self
                .frame
                .iter()
                .skip(1)
                .map(|&d| {
                    (g.origin - self.planes[d].origin)
                        .dot(&self.planes[d].normal)
                        .abs()
                })
                .fold(0.0, f64::max);
            let zone = 2.0 * iso2768_m(reach);
            self.push(
                "position",
                vec![f],
                format!("dia {} mm", fmt_num(zone)),
                &letters,
            );
        }
        if partial > 0 {
            self.out.notes.push(format!(
                "{partial} partial cylindrical face{} (fillets, rounded ends) not inspected",
                if partial == 1 { "" } else { "s" }
            ));
        }
    }
}

/// The letters of the frame's datums, in order.
const LETTERS: [char; 3] = ['A', 'B', 'C'];

#[cfg(test)]
mod tests {
    use super::*;

    fn read(path: &str) -> CadPart {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
        let bytes = std::fs::read(&path).expect("the shared parts beside the repository");
        crate::geometry::step::read(&bytes, crate::geometry::step::RESOLUTION).unwrap()
    }

    /// NIST CTC 01 without its PMI: a plate with Ø35 bores made of two half-cylinder
    /// faces each (faces 90/91 and 76/77), found as holes with a size and a position.
    #[test]
    fn half_cylinders_make_one_hole_with_a_size_and_a_position() {
        let part = read("../shared/parts/nist_ctc_01_asme1_ap242-e1.stp");
        let d = default_inspection(&part).unwrap();
        let hole = |faces: &[usize]| d.features.iter().position(|(f, _)| f == faces);
        let bore_1 = hole(&[89, 90]).expect("faces 90 and 91 as one hole");
        assert!(d.features[bore_1].1.starts_with("hole_"));
        assert!(hole(&[75, 76]).is_some());
        let of = |k: &str| {
            d.tolerances
                .iter()
                .find(|t| t.keyword == k && t.features == [bore_1])
                .map(|t| t.value.clone())
        };
        assert_eq!(of("diameter").as_deref(), Some("35 mm ± 0.3 mm"));
        assert!(of("position").is_some_and(|v| v.starts_with("dia ")));
        let letters: Vec<char> = d.datums.iter().map(|x| x.0).collect();
        assert_eq!(letters, ['A', 'B', 'C']);
    }

    /// An MFCAD block (planes only): the facing walls of its slots pair up as widths,
    /// its outer faces give its size along each datum's normal.
    #[test]
    fn facing_walls_are_slots_and_outer_faces_the_size() {
        let mut part = read("../shared/parts/mfcad/0-0-0-2-5-23.step");
        part.mesh.scale(10.0);
        let d = default_inspection(&part).unwrap();
        let widths = d.tolerances.iter().filter(|t| t.keyword == "width").count();
        assert_eq!(widths, 3);
        let sizes: Vec<&str> = d
            .tolerances
            .iter()
            .filter(|t| t.keyword == "distance" && t.value.starts_with("100 mm"))
            .map(|t| t.value.as_str())
            .collect();
        assert_eq!(sizes, ["100 mm ± 0.3 mm"; 3]);
    }

    /// ISO 2768-1 table 1, class m, and ISO 2768-2 table 1, class K.
    #[test]
    fn general_tolerances_follow_the_standard_tables() {
        assert_eq!(iso2768_m(2.0), 0.1);
        assert_eq!(iso2768_m(20.0), 0.2);
        assert_eq!(iso2768_m(100.0), 0.3);
        assert_eq!(iso2768_m(120.0), 0.3);
        assert_eq!(iso2768_m(121.0), 0.5);
        assert_eq!(iso2768_k_flatness(8.0), 0.05);
        assert_eq!(iso2768_k_flatness(100.0), 0.2);
        assert_eq!(iso2768_k_flatness(250.0), 0.4);
    }
}
