//! The battery's trials: per tolerance, the deviation its zone forbids, written as the
//! lines of a deviations file (`inspc simulate --deviations`), so that every trial the
//! battery reports can be rerun by hand.
//!
//! What each tolerance forbids follows the zone definitions of ASME Y14.5-2018 (cited by
//! chapter; ISO 1101:2017 agrees for these cases):
//!
//! | tolerance | zone (Y14.5-2018) | deviation tried at `k` × the zone `t` |
//! | --- | --- | --- |
//! | flatness, straightness | two parallel planes `t` apart (ch. 8, form) | each plane of the feature bowed by `k·t` (its centre stands out `k·t`, its farthest corner not at all: true flatness `k·t`) |
//! | the same per unit length or area | the zone `u` in every unit stretch (§ 5.4.1.4, § 5.4.2.2) | each plane bumped `k·u` as wide as the unit, near its middle (the whole-feature zone, where there is one, bowed as above) |
//! | profile with datums | a uniform boundary `t` wide about the true profile, located by the datums (ch. 11, profile) | each plane shifted `k·t/2` out, each curved face grown `k·t` in diameter |
//! | profile without datums | the same zone, free to float: form only (ch. 11) | each plane bowed `k·t` |
//! | perpendicularity, parallelism, angularity | two planes (or a cylinder for Ø) `t` apart at the basic orientation (ch. 9, orientation) | the feature tilted so that its far ends differ by `k·t` across its extent, about each of the two axes across it |
//! | position, concentricity, coaxiality, symmetry, runout | a zone `t` wide (Ø `t`) centred at the true position or on the datum axis (ch. 10, location; ch. 12, runout) | the feature moved `k·t/2` off its true position, along each direction across it |
//! | size (Ø, R, width) | its limits (ch. 5, Rule #1) | the size grown by `k` × the upper and `k` × the lower deviation |
//! | distance, angle | its limits | the second feature moved (turned) by `k` × each deviation |
//!
//! `t` is the zone as the program judges it on the nominal part: with a material
//! modifier, the zone plus the bonus the nominal size gives (ch. 10), read from the
//! nominal run. Circularity and cylindricity need lobed or tapered surfaces, which the
//! virtual part does not model, and a zone of 0 at MMC on a feature whose nominal size
//! is its MMC has no `t` to scale: they are listed as not tried.
//!
//! A datum frame's free turn and moves are not tried (`Frame`): a position to datum A
//! alone does not locate a bore across A.

use crate::geometry::{FaceId, PartGeometry, Surface, P3, V3};
use crate::model::{Part, TolKind, TolValue, Tolerance};

/// One way of breaking a tolerance, at a factor of its zone.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Variant {
    /// In words: `bow on stock.top`, `tilt about (1, 0, 0)`, `upper limit`.
    pub what: String,
    /// The deviations file at factor `k`.
    pub lines: Vec<String>,
    /// What the tolerance reads for this deviation at factor 1: the zone, or for a size
    /// the limit's deviation (signed).
    pub unit: f64,
}

/// The variants of tolerance `t` at factor `k` of `zone` (a zone's width, or for a size
/// the deviation that `k` multiplies: the variant's own limit). Empty: no deviation the
/// virtual part can model breaks it.
pub(crate) fn forbidden(
    part: &Part,
    g: &PartGeometry,
    feature_faces: &[Vec<FaceId>],
    t: &Tolerance,
    zone: f64,
    k: f64,
) -> Vec<Variant> {
    let frame = Frame::of(part, g, feature_faces, t);
    let b = Breaking {
        part,
        g,
        feature_faces,
        t,
        zone,
        k,
    };
    match t.kind {
        TolKind::Flatness | TolKind::Straightness => match &t.per_unit {
            None => b.bow_variants(),
            Some(p) => {
                let mut v = if p.overall {
                    b.bow_variants()
                } else {
                    Vec::new()
                };
                v.extend(b.bump_variants(p));
                v
            }
        },
        TolKind::ProfileSurface | TolKind::ProfileLine => b.profile_variants(),
        TolKind::Perpendicularity | TolKind::Parallelism | TolKind::Angularity => {
            b.tilt_variants(&frame)
        }
        TolKind::Position
        | TolKind::Concentricity
        | TolKind::Coaxiality
        | TolKind::Symmetry
        | TolKind::CircularRunout
        | TolKind::TotalRunout => b.move_variants(&frame),
        TolKind::Diameter | TolKind::Radius | TolKind::Width => b.size_variants(),
        TolKind::Distance => b.distance_variants(),
        TolKind::Angle => b.angle_variants(),
        TolKind::Circularity | TolKind::Cylindricity => Vec::new(),
    }
}

/// A tolerance to break at factor `k` of `zone`, on its part.
struct Breaking<'a> {
    part: &'a Part,
    g: &'a PartGeometry,
    feature_faces: &'a [Vec<FaceId>],
    t: &'a Tolerance,
    zone: f64,
    k: f64,
}

impl<'a> Breaking<'a> {
    /// The tolerance's `i`th feature: its name and faces.
    fn feature(&self, i: usize) -> Option<(&'a String, &'a [FaceId])> {
        self.t
            .targets
            .get(i)
            .map(|f| (&self.part.features[f.0].name, &self.feature_faces[f.0][..]))
    }

    /// Its features in order: their names and faces.
    fn features(&self) -> impl Iterator<Item = (&'a String, &'a [FaceId])> + '_ {
        (0..self.t.targets.len()).filter_map(|i| self.feature(i))
    }

    /// A zone per unit: each feature's planes bumped, as wide as the unit's least side.
    fn bump_variants(&self, p: &crate::model::PerUnit) -> Vec<Variant> {
        let mut out = Vec::new();
        for (name, faces) in self.features() {
            let lines = bumps(self.g, faces, self.k * p.zone, p.unit.least());
            if !lines.is_empty() {
                out.push(Variant {
                    what: format!("bump per {} on {name}", p.unit.text()),
                    lines,
                    unit: p.zone,
                });
            }
        }
        out
    }

    /// Form (flatness, straightness): each feature's planes bowed.
    fn bow_variants(&self) -> Vec<Variant> {
        let (g, zone, k) = (self.g, self.zone, self.k);
        let mut out = Vec::new();
        for (name, faces) in self.features() {
            let lines = bows(g, faces, k * zone);
            if !lines.is_empty() {
                out.push(Variant {
                    what: format!("bow on {name}"),
                    lines,
                    unit: zone,
                });
            }
        }
        out
    }

    /// A profile: without datums, the surfaces' planes bowed (form only); with them,
    /// every surface moved out by half the zone.
    fn profile_variants(&self) -> Vec<Variant> {
        let (g, t, zone, k) = (self.g, self.t, self.zone, self.k);
        let faces: Vec<FaceId> = t
            .targets
            .iter()
            .flat_map(|f| self.feature_faces[f.0].iter().copied())
            .collect();
        let (what, lines) = if t.datums.is_empty() {
            ("bow", bows(g, &faces, k * zone))
        } else {
            ("surface out", offsets(g, &faces, k * zone / 2.0))
        };
        if lines.is_empty() {
            return Vec::new();
        }
        vec![Variant {
            what: what.into(),
            lines,
            unit: zone,
        }]
    }

    /// An orientation: each feature tilted about each axis across it that `frame`
    /// fixes the turn about, its far ends `k`·zone apart.
    fn tilt_variants(&self, frame: &Frame) -> Vec<Variant> {
        let (g, zone, k) = (self.g, self.zone, self.k);
        let mut out = Vec::new();
        for (name, faces) in self.features() {
            for (axis, across, length) in tilts(g, faces, frame.free_turn) {
                if !frame.fixes_turn(&axis) {
                    continue;
                }
                let deg = (k * zone / length).clamp(-1.0, 1.0).asin().to_degrees();
                out.push(Variant {
                    what: format!("{name} tilted across {}", vec_text(&across)),
                    lines: vec![format!(
                        "feature {name} tilt {} about {}",
                        num(deg),
                        vec_text(&axis)
                    )],
                    unit: zone,
                });
            }
        }
        out
    }

    /// A location or runout: each feature moved half `k`·zone along each direction
    /// across it that `frame` fixes.
    fn move_variants(&self, frame: &Frame) -> Vec<Variant> {
        let (g, zone, k) = (self.g, self.zone, self.k);
        let mut out = Vec::new();
        for (name, faces) in self.features() {
            for dir in across(g, faces) {
                if !frame.fixes_move(&dir) {
                    continue;
                }
                let d = dir * (k * zone / 2.0);
                out.push(Variant {
                    what: format!("{name} moved along {}", vec_text(&dir)),
                    lines: vec![format!("feature {name} move {}", vec_text(&d))],
                    unit: zone,
                });
            }
        }
        out
    }

    /// A size: each feature grown to its drawing size plus `k` × each limit's deviation
    /// (a radius's twice): a CAD model modelled off the drawing's nominal
    /// ([`Tolerance::drawing_diameter`]) is grown by the difference too.
    fn size_variants(&self) -> Vec<Variant> {
        let t = self.t;
        let scale = if t.kind == TolKind::Radius { 2.0 } else { 1.0 };
        let mut out = Vec::new();
        for (name, faces) in self.features() {
            let off_drawing = off_drawing(self.g, faces, t);
            for (side, dev) in size_sides(&t.value) {
                let grow = off_drawing + self.k * dev * scale;
                out.push(Variant {
                    what: format!("{name} {side}"),
                    lines: vec![format!("feature {name} grow {}", num(grow))],
                    unit: dev,
                });
            }
        }
        out
    }

    /// A distance: the second feature moved the way that lengthens it by `k` × each
    /// limit's deviation.
    fn distance_variants(&self) -> Vec<Variant> {
        let (Some((_, f1)), Some((n2, f2))) = (self.feature(0), self.feature(1)) else {
            return Vec::new();
        };
        let dir = apart(self.g, f1, f2);
        size_sides(&self.t.value)
            .into_iter()
            .map(|(side, dev)| Variant {
                what: format!("{n2} moved to the {side}"),
                lines: vec![format!(
                    "feature {n2} move {}",
                    vec_text(&(dir * (self.k * dev)))
                )],
                unit: dev,
            })
            .collect()
    }

    /// An angle: the second feature turned about the hinge between the two by `k` ×
    /// each limit's deviation.
    fn angle_variants(&self) -> Vec<Variant> {
        let (Some((_, f1)), Some((n2, f2))) = (self.feature(0), self.feature(1)) else {
            return Vec::new();
        };
        let Some(axis) = hinge(self.g, f1, f2) else {
            return Vec::new();
        };
        size_sides(&self.t.value)
            .into_iter()
            .map(|(side, dev)| Variant {
                what: format!("{n2} turned to the {side}"),
                lines: vec![format!(
                    "feature {n2} tilt {} about {}",
                    num(self.k * dev),
                    vec_text(&axis)
                )],
                unit: dev,
            })
            .collect()
    }
}

/// What a tolerance's datum reference frame holds: a frame leaves free the turn about a
/// lone datum's normal or axis and every move it has no datum against (ASME Y14.5-2018
/// ch. 7, datum reference frames: the degrees of freedom a datum reference frame constrains are those its datum
/// features arrest; a zone is oriented and located only in those).
struct Frame {
    /// Directions the datum features arrest moves along (orthonormal).
    held: Vec<V3>,
    /// The axis the frame leaves the turn free about, when one datum sets it alone.
    free_turn: Option<V3>,
    /// No datums: the zone is the features' own (a pattern, a form); nothing is free.
    none: bool,
}

impl Frame {
    fn of(part: &Part, g: &PartGeometry, feature_faces: &[Vec<FaceId>], t: &Tolerance) -> Frame {
        let mut held: Vec<V3> = Vec::new();
        let mut hold = |v: V3| {
            let mut w = v;
            for h in &held {
                w -= h * h.dot(&w);
            }
            if let Some(w) = w.try_normalize(1e-6) {
                held.push(w);
            }
        };
        let mut dirs = Vec::new();
        for d in &t.datums {
            let faces = &feature_faces[part.datums[d.datum.0].feature.0];
            match main_face(g, faces).map(|f| &f.surface) {
                Some(Surface::Plane { normal, .. }) => {
                    hold(*normal);
                    dirs.push(*normal);
                }
                Some(Surface::Cylinder { axis, .. }) | Some(Surface::Cone { axis, .. }) => {
                    for a in across_of(axis) {
                        hold(a);
                    }
                    dirs.push(*axis);
                }
                Some(Surface::Sphere { .. }) => {
                    for a in [V3::x(), V3::y(), V3::z()] {
                        hold(a);
                    }
                }
                _ => {}
            }
        }
        let free_turn = match dirs.as_slice() {
            [d] => Some(*d),
            [d, rest @ ..] if rest.iter().all(|e| e.cross(d).norm() < 1e-6) => Some(*d),
            _ => None,
        };
        Frame {
            held,
            free_turn,
            none: t.datums.is_empty(),
        }
    }

    /// Turning about `axis` changes the feature's orientation in the frame.
    fn fixes_turn(&self, axis: &V3) -> bool {
        self.none || self.free_turn.is_none_or(|f| f.cross(axis).norm() > 1e-3)
    }

    /// Moving along `dir` changes the feature's location in the frame.
    fn fixes_move(&self, dir: &V3) -> bool {
        self.none || self.held.iter().map(|h| h.dot(dir).powi(2)).sum::<f64>() > 1.0 - 1e-3
    }
}

/// How much a feature's CAD diameter must grow to the size tolerance `t`'s nominal:
/// that of its first round face the tolerance controls ([`Tolerance::drawing_diameter`]);
/// 0 where the model is at the drawing's size.
pub(crate) fn off_drawing(g: &PartGeometry, faces: &[FaceId], t: &Tolerance) -> f64 {
    faces
        .iter()
        .find_map(|f| match g.faces[f.0].surface {
            Surface::Cylinder { radius, .. } | Surface::Sphere { radius, .. } => {
                t.drawing_diameter(2.0 * radius).map(|d| d - 2.0 * radius)
            }
            _ => None,
        })
        .unwrap_or(0.0)
}

/// The size changes that take a size to its limits: `("upper limit", +0.1)`,
/// `("lower limit", -0.1)`; a side without room is left out.
pub(crate) fn size_sides(v: &TolValue) -> Vec<(&'static str, f64)> {
    let TolValue::Size {
        nominal,
        lower,
        upper,
    } = v
    else {
        return Vec::new();
    };
    let mut out = Vec::new();
    if upper - nominal > 1e-9 {
        out.push(("upper limit", upper - nominal));
    }
    if lower - nominal < -1e-9 {
        out.push(("lower limit", lower - nominal));
    }
    out
}

/// `face NAME bow h` for each plane of `faces`.
fn bows(g: &PartGeometry, faces: &[FaceId], h: f64) -> Vec<String> {
    faces
        .iter()
        .filter(|f| matches!(g.faces[f.0].surface, Surface::Plane { .. }))
        .map(|f| format!("face {} bow {}", g.faces[f.0].name, num(h)))
        .collect()
}

/// Every plane of `faces` bumped `h` high and `across` wide, at the centre of its
/// triangle nearest its centroid (on the face, where the centroid of a ring is not).
fn bumps(g: &PartGeometry, faces: &[FaceId], h: f64, across: f64) -> Vec<String> {
    faces
        .iter()
        .filter(|f| matches!(g.faces[f.0].surface, Surface::Plane { .. }))
        .filter_map(|f| {
            let face = &g.faces[f.0];
            let at = face
                .triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = g.triangles[*t as usize].map(|i| g.vertices[i as usize]);
                    P3::from((a.coords + b.coords + c.coords) / 3.0)
                })
                .min_by(|a, b| {
                    (a - face.centroid)
                        .norm()
                        .total_cmp(&(b - face.centroid).norm())
                })?;
            Some(format!(
                "face {} bump {} at ({}, {}, {}) across {}",
                face.name,
                num(h),
                num(at.x),
                num(at.y),
                num(at.z),
                num(across)
            ))
        })
        .collect()
}

/// Every face of `faces` moved `d` out along its outward normal, as if material `d`
/// deep were added: planes shifted, curved faces grown or shrunk.
fn offsets(g: &PartGeometry, faces: &[FaceId], d: f64) -> Vec<String> {
    faces
        .iter()
        .filter_map(|f| {
            let face = &g.faces[f.0];
            match &face.surface {
                Surface::Plane { .. } => Some(format!("face {} shift {}", face.name, num(d))),
                Surface::Cylinder { convex, .. }
                | Surface::Sphere { convex, .. }
                | Surface::Cone { convex, .. } => {
                    // Material added `d` deep: a boss's diameter grows, a hole's
                    // shrinks.
                    let s = if *convex { 2.0 * d } else { -2.0 * d };
                    Some(format!("face {} grow {}", face.name, num(s)))
                }
                Surface::Freeform => None,
            }
        })
        .collect()
}

/// The feature's main surface: its largest face.
fn main_face<'g>(g: &'g PartGeometry, faces: &[FaceId]) -> Option<&'g crate::geometry::Face> {
    faces
        .iter()
        .map(|f| &g.faces[f.0])
        .max_by(|a, b| a.area.total_cmp(&b.area))
}

/// The direction a feature is oriented by: a plane's normal, an axis.
fn orientation(g: &PartGeometry, faces: &[FaceId]) -> Option<(V3, bool)> {
    match &main_face(g, faces)?.surface {
        Surface::Plane { normal, .. } => Some((*normal, true)),
        Surface::Cylinder { axis, .. } | Surface::Cone { axis, .. } => Some((*axis, false)),
        _ => None,
    }
}

/// Two unit vectors across `n`, along part axes where `n` lies along one.
fn across_of(n: &V3) -> [V3; 2] {
    let k = (0..3)
        .min_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
        .unwrap_or(0);
    let u = (V3::ith(k, 1.0) - n * n[k]).normalize();
    let v = n.cross(&u).normalize();
    [u, v]
}

/// The extent of `faces` along `dir`: the spread of their vertices.
fn extent(g: &PartGeometry, faces: &[FaceId], dir: &V3) -> f64 {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for f in faces {
        for t in &g.faces[f.0].triangles {
            for v in g.triangles[*t as usize] {
                let x = g.vertices[v as usize].coords.dot(dir);
                lo = lo.min(x);
                hi = hi.max(x);
            }
        }
    }
    (hi - lo).max(0.0)
}

/// A feature's tilts: (axis of the turn, the direction across which its far ends part,
/// the feature's extent that way). A plane turns about each of two axes in it; an axis
/// about each of two directions across it, over its length.
///
/// Where one datum direction `free` orients the zone alone (a lone primary plane or
/// axis), the zone may turn about `free` (ASME Y14.5-2018 § 7.11, the degrees of freedom
/// a primary datum arrests; § 9.5, an orientation zone is basic to the datums given): a
/// turn changes the feature's angle to `free` only by its share about `n × free`, so
/// the feature tilts about that one axis. CTC 03's datum E, at 45° to A, tilted about
/// the other axis in its plane (one that keeps its angle to A) read 0.008 of a 1.016
/// angularity zone, as the standard says it should.
fn tilts(g: &PartGeometry, faces: &[FaceId], free: Option<V3>) -> Vec<(V3, V3, f64)> {
    let Some((n, plane)) = orientation(g, faces) else {
        return Vec::new();
    };
    let [u, v] = across_of(&n);
    let tilted = free.and_then(|d| n.cross(&d).try_normalize(1e-6));
    // Turning about `v` lifts the ends along `u` apart; a turn about `tilted` as one of
    // those two where it lies along one.
    let pairs = match tilted {
        None => vec![(v, u), (u, v)],
        Some(t) => vec![[(v, u), (u, v)]
            .into_iter()
            .find(|(axis, _)| axis.cross(&t).norm() < 1e-9)
            .unwrap_or((t, n.cross(&t)))],
    };
    if plane {
        pairs
            .into_iter()
            .map(|(axis, along)| (axis, along, extent(g, faces, &along)))
            .filter(|x| x.2 > 1e-6)
            .collect()
    } else {
        let length = extent(g, faces, &n);
        if length < 1e-6 {
            return Vec::new();
        }
        pairs
            .into_iter()
            .map(|(axis, along)| (axis, along, length))
            .collect()
    }
}

/// Directions a feature is located along: across an axis, along a plane's normal, or
/// the part axes for a sphere.
fn across(g: &PartGeometry, faces: &[FaceId]) -> Vec<V3> {
    match main_face(g, faces).map(|f| &f.surface) {
        Some(Surface::Plane { normal, .. }) => vec![*normal],
        Some(Surface::Cylinder { axis, .. }) | Some(Surface::Cone { axis, .. }) => {
            across_of(axis).to_vec()
        }
        Some(Surface::Sphere { .. }) => vec![V3::x(), V3::y(), V3::z()],
        _ => Vec::new(),
    }
}

/// The centroid of `faces`, weighted by area.
fn centroid(g: &PartGeometry, faces: &[FaceId]) -> P3 {
    let (mut sum, mut area) = (V3::zeros(), 0.0);
    for f in faces {
        let face = &g.faces[f.0];
        sum += face.centroid.coords * face.area;
        area += face.area;
    }
    P3::from(sum / area.max(1e-12))
}

/// The direction the second feature moves to lengthen a distance, the direction the
/// distance is measured in: the second's plane normal, else the first's (the distance
/// from a plane to a hole's axis is the perpendicular one, so the hole moves square to
/// the plane: moved along the line from the plane's centroid, FTC 06's drilled hole went
/// 2.5 mm along and 0.57 mm across and hit the probe), else the line between their
/// centroids across the second's axis (between two axes, square to them), turned away
/// from the first.
fn apart(g: &PartGeometry, f1: &[FaceId], f2: &[FaceId]) -> V3 {
    let d = centroid(g, f2) - centroid(g, f1);
    let away = |n: V3| if n.dot(&d) < 0.0 { -n } else { n };
    match (orientation(g, f1), orientation(g, f2)) {
        (_, Some((n, true))) | (Some((n, true)), _) => away(n),
        (_, Some((axis, false))) => (d - axis * axis.dot(&d))
            .try_normalize(1e-9)
            .or_else(|| d.try_normalize(1e-9))
            .unwrap_or_else(V3::x),
        _ => d.try_normalize(1e-9).unwrap_or_else(V3::x),
    }
}

/// The axis about which turning the second feature opens the angle between two.
fn hinge(g: &PartGeometry, f1: &[FaceId], f2: &[FaceId]) -> Option<V3> {
    let (a, _) = orientation(g, f1)?;
    let (b, _) = orientation(g, f2)?;
    a.cross(&b).try_normalize(1e-9)
}

/// A vector as a deviations file writes it.
fn vec_text(v: &V3) -> String {
    format!("({}, {}, {})", num(v.x), num(v.y), num(v.z))
}

/// A number to a tenth of a nanometre, without trailing zeros.
pub fn num(x: f64) -> String {
    let s = format!("{x:.7}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.to_string()
    }
}
