//! Evaluation of a tolerance from the features as measured: datum reference frames and
//! each tolerance type, simplified where a full ASME Y14.5 evaluation is out of reach.
//!
//! - **Datum reference frame.** Datum features in order: the first direction (a plane's
//!   normal, an axis) is matched exactly, the next one not parallel to it fixes the
//!   rotation about it (or, failing one, two located datums after the primary: holes
//!   of a pattern); each datum then fixes the translation along what it locates (a
//!   plane along its normal, an axis across it, a point in full) where earlier datums
//!   left it free. Datum features are their least-squares fits, not tangent planes
//!   (a real datum simulator would use the constrained L∞ fit); modifiers on datums are
//!   read as RFS. What the datums leave free is held by the program's alignment, as a
//!   CMM reports in its current alignment (so a pattern located from datum A alone
//!   still has its holes' places): only an orientation zone turns freely about a lone
//!   primary direction, and a profile's zone floats (least squares over the touches'
//!   deviations, never less than the minimax float) in every degree of freedom its
//!   datums leave free — all six with none — as ASME Y14.5-2018 ch. 11 locates and
//!   orients a profile zone only as far as its datum reference frame constrains it.
//! - **Form** (flatness, straightness, circularity, cylindricity) is the range of the
//!   touches' residuals from the least-squares fit: never less than the minimum zone.
//!   Straightness uses the whole surface; circularity takes each circle of touches.
//! - **Orientation** (perpendicularity, parallelism, angularity): the zone is oriented
//!   by the datum frame (turned about a lone primary direction to suit the feature);
//!   a plane's value is the range of its touches across the zone, an axis's the
//!   diameter of the zone holding its ends over the measured length.
//! - **Location** (position, concentricity, coaxiality, symmetry): the distance of the
//!   axis ends (or centre, or plane touches) from the true position in the datum frame,
//!   doubled (a Ø zone); MMC adds the bonus of the feature's departure from its MMC
//!   size when the program outputs the feature's size tolerance too, else it is RFS.
//! - **Profile**: each touch's deviation along its nominal vector from its nominal
//!   point, in the datum frame, over every feature the `OUTPUT` names (the surfaces
//!   of one profile are one zone); the zone is equal-bilateral (twice the largest).
//! - **Runout**: radial (or, for a face across the axis, axial) deviations about the
//!   primary datum's axis; circular runout is taken as total (over every circle).
//! - **Size**: least-squares diameter, radius or width; distances between planes along
//!   the first's normal, from a plane to an axis or point, between parallel axes, or
//!   between points; angles between directions.

use super::fit::Shape;
use crate::geometry::drf::{drf, Drf};
use crate::geometry::{P3, V3};
use nalgebra::{Isometry3, Rotation3, Unit};

/// A feature as measured, in some frame.
#[derive(Debug, Clone)]
pub struct Measured {
    /// Its fitted shape.
    pub shape: Shape,
    /// Its touches: (nominal point, nominal vector — program frame —, measured point).
    pub touches: Vec<(P3, V3, P3)>,
    /// For a constructed centre plane, the touches of its walls moved onto it.
    pub median: Vec<P3>,
}

impl Measured {
    /// The same feature moved rigidly (the nominal points stay).
    pub fn moved(&self, m: &Isometry3<f64>) -> Measured {
        Measured {
            shape: self.shape.moved(m),
            touches: self
                .touches
                .iter()
                .map(|(p, n, q)| (*p, *n, m * q))
                .collect(),
            median: self.median.iter().map(|q| m * q).collect(),
        }
    }

    fn points(&self) -> Vec<P3> {
        if !self.median.is_empty() {
            return self.median.clone();
        }
        self.touches.iter().map(|t| t.2).collect()
    }
}

/// A tolerance as the program states it.
#[derive(Debug, Clone, PartialEq)]
pub struct TolDef {
    /// The DMIS word: `FLAT`, `POS`, `DIAM`, ….
    pub word: String,
    /// A zone's width or diameter (zone tolerances).
    pub zone: Option<f64>,
    /// `2D` (a Ø zone about an axis) or `3D`.
    pub dims: Option<String>,
    /// Angularity's basic angle, a distance's or angle's nominal.
    pub nominal: Option<f64>,
    /// Size limits as deviations from nominal.
    pub limits: Option<(f64, f64)>,
    /// `MMC`, `LMC` or `RFS` on the feature.
    pub material: Option<String>,
    /// Datum labels in order.
    pub datums: Vec<String>,
}

const SIZE_WORDS: &[&str] = &["DIAM", "RAD", "WIDTH", "DISTB", "ANGLB"];

impl TolDef {
    /// Reads `TOL/…` parameters; `None` when they do not make a tolerance.
    pub fn parse(params: &[String]) -> Option<TolDef> {
        let word = params.first()?.clone();
        let mut rest = params[1..].iter().peekable();
        let mut def = TolDef {
            word: word.clone(),
            zone: None,
            dims: None,
            nominal: None,
            limits: None,
            material: None,
            datums: Vec::new(),
        };
        let num = |s: &String| super::number::value(s);
        if SIZE_WORDS.contains(&word.as_str()) {
            if rest.peek().map(|s| s.as_str()) == Some("NOMINL") {
                rest.next();
            }
            if matches!(word.as_str(), "DISTB" | "ANGLB") {
                def.nominal = Some(num(rest.next()?)?);
            }
            let lo = num(rest.next()?)?;
            let hi = num(rest.next()?)?;
            def.limits = Some((lo, hi));
        } else {
            if let Some(d) = rest
                .peek()
                .filter(|s| s.as_str() == "2D" || s.as_str() == "3D")
            {
                def.dims = Some((*d).clone());
                rest.next();
            }
            if word == "ANGLR" {
                def.nominal = Some(num(rest.next()?)?);
            }
            def.zone = Some(num(rest.next()?)?);
            // A profile's zone is written as its lower and upper limits about the true
            // profile (`TOL/PROFS,-0.25,0.25,…`, as PC-DMIS's surface profile has a minus
            // and a plus tolerance); one value is the whole width, centred. The virtual
            // CMM judges a zone centred on the true profile: an unequal one is not run.
            if matches!(word.as_str(), "PROFS" | "PROFL" | "PROFP") {
                if let Some(hi) = rest.peek().and_then(|s| num(s)) {
                    rest.next();
                    let lo = def.zone.unwrap_or(0.0);
                    if (lo + hi).abs() > 1e-9 || hi < lo {
                        return None;
                    }
                    def.zone = Some(hi - lo);
                }
            }
        }
        for p in rest {
            if let Some(l) = p.strip_prefix("DAT(").and_then(|s| s.strip_suffix(')')) {
                def.datums.push(l.to_string());
            } else if matches!(p.as_str(), "MMC" | "LMC" | "RFS") {
                if def.datums.is_empty() {
                    def.material = Some(p.clone());
                }
            } else {
                return None;
            }
        }
        Some(def)
    }

    /// What leaves this tolerance nothing to hold a part in, if anything: a zone of
    /// width 0 or less, or size limits whose lower is not below their upper. DMIS 5.3
    /// (ANSI/DMIS 105.2 part 1) gives a zone tolerance (`TOL/FLAT,tolzon`,
    /// `TOL/POS,2D,tolzon,…`) by its width and a size (`TOL/DIAM,lotol,uptol`) by its
    /// lower and upper deviation; ASME Y14.5-2018 and ISO 1101 define a zone by a
    /// positive width `t`. Judging a part against an empty zone would fail every part
    /// for the program's sake, not the part's. The exception is a zone of 0 at MMC or
    /// LMC (ASME Y14.5-2018 § 10.3.4, zero tolerance at MMC): the feature's departure
    /// from that size is its whole zone.
    pub(crate) fn empty_zone(&self) -> Option<(String, &'static str)> {
        let at_material =
            self.word == "POS" && matches!(self.material.as_deref(), Some("MMC" | "LMC"));
        if let Some(z) = self
            .zone
            .filter(|z| *z < 0.0 || (*z == 0.0 && !at_material))
        {
            return Some((
                format!(
                    "TOL/{} with a zone of {z} mm, which holds nothing",
                    self.word
                ),
                "a tolerance zone has a positive width: write it as `TOL/FLAT,0.05`",
            ));
        }
        if let Some((lo, hi)) = self.limits.filter(|(lo, hi)| lo >= hi) {
            return Some((
                format!(
                    "TOL/{} with limits {lo} to {hi}, which leave no size",
                    self.word
                ),
                "the lower deviation comes first and lies below the upper: `TOL/DIAM,-0.1,0.1`",
            ));
        }
        None
    }
}

/// The result of one tolerance on its features.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// The nominal value (a size, a distance, an angle; 0 for a zone).
    pub nominal: f64,
    /// The value measured (a size; a zone's width or diameter).
    pub actual: f64,
    /// Allowed deviation from nominal: (lower, upper). A zone's is (0, width + bonus).
    pub limits: (f64, f64),
    /// What the evaluation simplified or could not do.
    pub note: Option<String>,
}

impl Outcome {
    /// The deviation from nominal.
    pub fn deviation(&self) -> f64 {
        self.actual - self.nominal
    }

    /// Within its limits (to a nanometre).
    pub fn pass(&self) -> bool {
        let d = self.deviation();
        d >= self.limits.0 - 1e-6 && d <= self.limits.1 + 1e-6
    }
}

/// One target: the feature measured (program frame), its nominal and whether it is
/// convex (a pin, not a hole).
pub struct Target<'a> {
    /// As measured.
    pub measured: &'a Measured,
    /// The nominal shape.
    pub nominal: &'a Shape,
    /// A shaft, tab or ball rather than a hole or slot.
    pub convex: bool,
    /// Its size tolerance's limits and nominal, when the program outputs one (for MMC).
    pub size: Option<(f64, f64, f64)>,
}

fn range(v: impl Iterator<Item = f64>) -> f64 {
    let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
        (l.min(x), h.max(x))
    });
    if hi >= lo {
        hi - lo
    } else {
        0.0
    }
}

/// Least-squares removal of the free motions from deviations `e` along vectors `n` at
/// points `q`: what is left once the part may slide along `free_t` and turn about
/// `free_r` (through the points' centroid).
fn best_fit(e: &mut [f64], n: &[V3], q: &[P3], free_t: &[V3], free_r: &[V3]) {
    let k = free_t.len() + free_r.len();
    if k == 0 || e.is_empty() {
        return;
    }
    let c = q.iter().fold(V3::zeros(), |s, p| s + p.coords) / q.len() as f64;
    let rows = e.len();
    let mut a = nalgebra::DMatrix::zeros(rows, k);
    for i in 0..rows {
        for (j, t) in free_t.iter().enumerate() {
            a[(i, j)] = n[i].dot(t);
        }
        for (j, w) in free_r.iter().enumerate() {
            a[(i, free_t.len() + j)] = w.cross(&(q[i].coords - c)).dot(&n[i]);
        }
    }
    let b = nalgebra::DVector::from_column_slice(e);
    let svd = a.clone().svd(true, true);
    let Ok(x) = svd.solve(&b, 1e-9) else {
        return;
    };
    let fit = a * x;
    for i in 0..rows {
        e[i] -= fit[i];
    }
}

/// The axis ends over the touches' extent.
fn axis_ends(s: &Shape, pts: &[P3]) -> Option<(P3, P3)> {
    let (p, a) = match s {
        Shape::Cylinder { p, a, .. } => (*p, *a),
        Shape::Cone { apex, a, .. } => (*apex, *a),
        _ => return None,
    };
    let (lo, hi) = pts
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), q| {
            let t = (q - p).dot(&a);
            (l.min(t), h.max(t))
        });
    if lo > hi {
        return Some((p, p));
    }
    Some((p + a * lo, p + a * hi))
}

fn zone(value: f64, width: f64, note: Option<String>) -> Outcome {
    Outcome {
        nominal: 0.0,
        actual: value,
        limits: (0.0, width),
        note,
    }
}

/// Evaluates `def` on its targets (program frame) with its datum features (measured,
/// nominal, program frame).
pub fn evaluate(def: &TolDef, targets: &[Target], datums: &[(Shape, Shape)]) -> Outcome {
    let Some(first) = targets.first() else {
        return na("no feature");
    };
    let mut drf = drf(datums);
    let moved = first.measured.moved(&drf.to_nominal);
    // A profile's zone floats in what its datums leave free; for the other kinds free
    // translations and, but for orientation, free rotations stay the alignment's.
    let float = (drf.free_t.clone(), drf.free_r.clone());
    let free_r = std::mem::take(&mut drf.free_r);
    drf.free_t.clear();
    if datums.is_empty() {
        drf.free_t = vec![V3::x(), V3::y(), V3::z()];
        drf.free_r = free_r.clone();
    }
    let width = def.zone.unwrap_or(0.0);
    match def.word.as_str() {
        "FLAT" | "STRGHT" | "CYLCTY" => {
            let s = &first.measured.shape;
            let pts = first.measured.points();
            zone(range(pts.iter().map(|q| s.signed(q))), width, None)
        }
        "CIRLTY" => circularity(first.measured, width),
        "PROFS" | "PROFL" => profile(targets, &drf, &float, width),
        "PERP" | "PARLEL" | "ANGLR" => {
            let o = Drf {
                free_r,
                ..drf.clone()
            };
            orientation(&o, &moved, first.nominal, width)
        }
        "POS" | "CONCEN" | "COAXL" | "SYM" => position(def, first, &drf, &moved, width),
        "CRNOUT" | "TRNOUT" => runout(def, first, datums, &moved, width),
        "DIAM" | "RAD" | "WIDTH" => {
            let (Some(a), Some(n)) = (first.measured.shape.size(), first.nominal.size()) else {
                return na("the feature has no size");
            };
            let k = if def.word == "RAD" { 0.5 } else { 1.0 };
            size(n * k, a * k, def)
        }
        "DISTB" => distance_between(def, targets),
        "ANGLB" => angle_between(def, targets),
        other => na(&format!("`{other}` is not evaluated")),
    }
}

/// Circularity: the worst range of the points' distances from the shape over the
/// circles they lie on (points grouped by their height along its axis, to 0.01 mm);
/// over all points for a shape without an axis.
fn circularity(m: &Measured, width: f64) -> Outcome {
    let s = &m.shape;
    let Some(a) = s.direction() else {
        return zone(range(m.points().iter().map(|q| s.signed(q))), width, None);
    };
    let mut circles: std::collections::BTreeMap<i64, Vec<f64>> = Default::default();
    for q in m.points() {
        let h = (q.coords.dot(&a) * 100.0).round() as i64;
        circles.entry(h).or_default().push(s.signed(&q));
    }
    let worst = circles
        .values()
        .filter(|v| v.len() >= 3)
        .map(|v| range(v.iter().copied()))
        .fold(0.0, f64::max);
    zone(worst, width, None)
}

/// A profile: one zone over every surface the statement names (a boss's six sides is
/// one zone, floating as one) in the motions `float` (translations, rotations) its
/// datums leave free.
fn profile(targets: &[Target], drf: &Drf, float: &(Vec<V3>, Vec<V3>), width: f64) -> Outcome {
    let (mut e, mut n, mut q) = (Vec::new(), Vec::new(), Vec::new());
    for target in targets {
        let moved = target.measured.moved(&drf.to_nominal);
        for (p, v, x) in &moved.touches {
            e.push((x - p).dot(v));
            n.push(*v);
            q.push(*x);
        }
    }
    best_fit(&mut e, &n, &q, &float.0, &float.1);
    let worst = e.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    zone(2.0 * worst, width, None)
}

/// A location (position, concentricity, coaxiality, symmetry) of `moved`, the first
/// target in its datums' frame; a position at MMC or LMC gains its bonus from the
/// feature's departure from that size toward the other limit (ASME Y14.5-2018
/// § 10.3.4, § 10.3.5): MMC is a boss's largest size and a hole's smallest, LMC the
/// other way round. The size is the least-squares fit's, not the actual mating
/// envelope's: the simulator's simplification, as most CMM software reports it.
fn position(def: &TolDef, first: &Target, drf: &Drf, moved: &Measured, width: f64) -> Outcome {
    let mut out = location(drf, moved, first.nominal, width);
    let material = def
        .material
        .as_deref()
        .filter(|m| matches!(*m, "MMC" | "LMC"));
    if let (true, Some(m)) = (def.word == "POS", material) {
        match (first.size, first.measured.shape.size()) {
            (Some((nom, lo, hi)), Some(actual)) => {
                // The bonus is the departure from the condition toward the other
                // limit; a size beyond the condition earns none (its size fails).
                let largest = first.convex == (m == "MMC");
                let bonus = if largest {
                    nom + hi - actual
                } else {
                    actual - (nom + lo)
                };
                out.limits.1 += bonus.max(0.0);
            }
            _ => {
                out.note = Some(format!(
                    "{m} read as RFS: the program outputs no size tolerance of this feature"
                ));
            }
        }
    }
    out
}

/// Runout about the first datum's axis (or the feature's own): radial, or axial on a
/// face square to the axis; circular runout is taken as total.
fn runout(
    def: &TolDef,
    first: &Target,
    datums: &[(Shape, Shape)],
    moved: &Measured,
    width: f64,
) -> Outcome {
    let axis = datums
        .first()
        .and_then(|(_, n)| match n {
            Shape::Cylinder { p, a, .. } => Some((*p, *a)),
            Shape::Cone { apex, a, .. } => Some((*apex, *a)),
            _ => None,
        })
        .or(match first.nominal {
            Shape::Cylinder { p, a, .. } => Some((*p, *a)),
            _ => None,
        });
    let Some((o, a)) = axis else {
        return na("runout needs a datum axis");
    };
    let radial = |q: &P3| {
        let d = q - o;
        (d - a * d.dot(&a)).norm()
    };
    let axial = matches!(first.nominal, Shape::Plane { n, .. } if n.dot(&a).abs() > 0.9);
    let e = moved.touches.iter().map(|(p, _, q)| {
        if axial {
            (q - p).dot(&a)
        } else {
            radial(q) - radial(p)
        }
    });
    zone(
        range(e),
        width,
        (def.word == "CRNOUT")
            .then(|| "circular runout taken over every circle at once (total)".to_string()),
    )
}

/// `DISTB`: the distance between two features, or one feature's size, against the
/// tolerance's nominal (noted where that differs from the geometry's).
fn distance_between(def: &TolDef, targets: &[Target]) -> Outcome {
    let (nom, act) = match targets {
        [a, b] => (
            distance(
                a.nominal,
                b.nominal,
                Some(&b.measured.touches.iter().map(|t| t.0).collect::<Vec<_>>()),
            ),
            distance(
                &a.measured.shape,
                &b.measured.shape,
                Some(&b.measured.points()),
            ),
        ),
        [a] => (a.nominal.size(), a.measured.shape.size()),
        _ => (None, None),
    };
    match (nom, act) {
        (Some(n), Some(a)) => {
            let mut o = size(def.nominal.unwrap_or(n), a, def);
            if (def.nominal.unwrap_or(n) - n).abs() > 1e-3 {
                o.note = Some(format!(
                    "the nominal {} differs from the geometry's {}",
                    crate::dmis::text::num(o.nominal),
                    crate::dmis::text::num(n)
                ));
            }
            o
        }
        _ => na("no distance between these features"),
    }
}

/// `ANGLB`: the angle between two features' directions, taken the way round nearer
/// the nominal.
fn angle_between(def: &TolDef, targets: &[Target]) -> Outcome {
    let [a, b] = targets else {
        return na("an angle takes two features");
    };
    let (Some(na_), Some(nb), Some(ma), Some(mb)) = (
        a.nominal.direction(),
        b.nominal.direction(),
        a.measured.shape.direction(),
        b.measured.shape.direction(),
    ) else {
        return na("an angle takes two features with directions");
    };
    let nominal = def.nominal.unwrap_or_else(|| angle(&na_, &nb));
    let raw = angle(&ma, &mb);
    let actual = if (raw - nominal).abs() <= (180.0 - raw - nominal).abs() {
        raw
    } else {
        180.0 - raw
    };
    size(nominal, actual, def)
}

fn na(why: &str) -> Outcome {
    Outcome {
        nominal: 0.0,
        actual: f64::NAN,
        limits: (0.0, 0.0),
        note: Some(why.to_string()),
    }
}

fn size(nominal: f64, actual: f64, def: &TolDef) -> Outcome {
    Outcome {
        nominal,
        actual,
        limits: def.limits.unwrap_or((0.0, 0.0)),
        note: None,
    }
}

/// The angle between two directions (degrees).
fn angle(a: &V3, b: &V3) -> f64 {
    a.dot(b).clamp(-1.0, 1.0).acos().to_degrees()
}

/// The distance between two features: planes along the first's normal (at the second's
/// touches' centroid when given), a plane and an axis or point, parallel axes, points.
fn distance(a: &Shape, b: &Shape, b_points: Option<&[P3]>) -> Option<f64> {
    let centroid = |pts: &[P3]| -> Option<P3> {
        (!pts.is_empty())
            .then(|| P3::from(pts.iter().fold(V3::zeros(), |s, p| s + p.coords) / pts.len() as f64))
    };
    let at_b = b_points.and_then(centroid).or_else(|| b.location())?;
    match (a, b) {
        (Shape::Plane { p, n } | Shape::Parpln { p, n, .. }, _) => {
            let q = match b {
                Shape::Plane { p: pb, n: nb } | Shape::Parpln { p: pb, n: nb, .. } => {
                    // The second plane's point nearest the touches' centroid.
                    at_b - nb * (at_b - pb).dot(nb)
                }
                Shape::Cylinder { p: pb, a: ab, .. } => pb + ab * (at_b - pb).dot(ab),
                other => other.location()?,
            };
            Some((q - p).dot(n).abs())
        }
        (Shape::Cylinder { .. }, Shape::Plane { .. } | Shape::Parpln { .. }) => {
            distance(b, a, None)
        }
        (Shape::Cylinder { p, a: ax, .. }, _) => {
            let q = b.location()?;
            let d = q - p;
            Some((d - ax * d.dot(ax)).norm())
        }
        _ => Some((a.location()? - b.location()?).norm()),
    }
}

/// Orientation of a plane (its touches across the zone) or an axis (its ends).
fn orientation(drf: &Drf, m: &Measured, nominal: &Shape, width: f64) -> Outcome {
    let (Some(dn), Some(da)) = (nominal.direction(), m.shape.direction()) else {
        return na("the feature has no direction");
    };
    let da = if da.dot(&dn) < 0.0 { -da } else { da };
    let z = match drf.free_r.len() {
        0 => dn,
        1 => {
            let d = drf.free_r[0];
            let (c, s) = (dn.dot(&d), (1.0 - dn.dot(&d).powi(2)).max(0.0).sqrt());
            let w = (da - d * da.dot(&d))
                .try_normalize(1e-9)
                .or_else(|| (dn - d * dn.dot(&d)).try_normalize(1e-9))
                .unwrap_or(dn);
            d * c + w * s
        }
        _ => da,
    };
    let pts = m.points();
    match &m.shape {
        Shape::Cylinder { .. } | Shape::Cone { .. } => {
            let Some((e1, e2)) = axis_ends(&m.shape, &pts) else {
                return na("no axis");
            };
            let d = e2 - e1;
            // An axis along the primary direction (or with the rotation fixed) lies in a
            // Ø zone about its nominal; one across it between two planes square to the
            // primary direction's component across the axis.
            match drf.free_r.first() {
                Some(p) if dn.dot(p).abs() < 0.999 => {
                    let Some(mz) = (p - dn * dn.dot(p)).try_normalize(1e-9) else {
                        return na("no zone direction");
                    };
                    zone(d.dot(&mz).abs(), width, None)
                }
                _ => zone((d - dn * d.dot(&dn)).norm(), width, None),
            }
        }
        _ => zone(range(pts.iter().map(|q| q.coords.dot(&z))), width, None),
    }
}

/// Location against the true position in the datum frame.
fn location(drf: &Drf, m: &Measured, nominal: &Shape, width: f64) -> Outcome {
    let drop_free = |mut d: V3| {
        for f in &drf.free_t {
            d -= f * d.dot(f);
        }
        d
    };
    let pts = m.points();
    match (nominal, &m.shape) {
        (
            Shape::Cylinder { p: pn, a: an, .. }
            | Shape::Cone {
                apex: pn, a: an, ..
            },
            s,
        ) => {
            let Some((e1, e2)) = axis_ends(s, &pts) else {
                return na("no axis");
            };
            let off = |e: P3| {
                let d = e - pn;
                drop_free(d - an * d.dot(an)).norm()
            };
            zone(2.0 * off(e1).max(off(e2)), width, None)
        }
        (Shape::Sphere { c: cn, .. } | Shape::Point { p: cn, .. }, s) => {
            let Some(c) = s.location() else {
                return na("no centre");
            };
            zone(2.0 * drop_free(c - cn).norm(), width, None)
        }
        (Shape::Plane { p: pn, n: nn } | Shape::Parpln { p: pn, n: nn, .. }, _) => {
            let mut e: Vec<f64> = pts.iter().map(|q| (q - pn).dot(nn)).collect();
            let n = vec![*nn; e.len()];
            best_fit(&mut e, &n, &pts, &drf.free_t, &[]);
            zone(
                2.0 * e.iter().fold(0.0f64, |a, x| a.max(x.abs())),
                width,
                None,
            )
        }
        (Shape::Surface | Shape::Line { .. }, _) => {
            let t = &m.touches;
            let mut e: Vec<f64> = t.iter().map(|(p, n, q)| (q - p).dot(n)).collect();
            let n: Vec<V3> = t.iter().map(|x| x.1).collect();
            let q: Vec<P3> = t.iter().map(|x| x.2).collect();
            best_fit(&mut e, &n, &q, &drf.free_t, &drf.free_r);
            zone(
                2.0 * e.iter().fold(0.0f64, |a, x| a.max(x.abs())),
                width,
                None,
            )
        }
    }
}

/// A rotation about `axis` by `deg` degrees (for tests and placements).
pub fn turn(axis: &V3, deg: f64) -> Rotation3<f64> {
    Rotation3::from_axis_angle(&Unit::new_normalize(*axis), deg.to_radians())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    #[test]
    fn a_frame_of_three_planes_takes_out_a_small_motion() {
        let planes = [
            (P3::new(0.0, 0.0, 10.0), V3::z()),
            (P3::new(0.0, 0.0, 0.0), -V3::x()),
            (P3::new(0.0, 0.0, 0.0), -V3::y()),
        ];
        let m = Isometry3::from_parts(
            Translation3::new(0.3, -0.2, 0.1),
            UnitQuaternion::from_axis_angle(&Unit::new_normalize(V3::new(1.0, 2.0, 3.0)), 0.01),
        );
        let datums: Vec<(Shape, Shape)> = planes
            .iter()
            .map(|(p, n)| {
                let nominal = Shape::Plane { p: *p, n: *n };
                (nominal.moved(&m), nominal)
            })
            .collect();
        let f = drf(&datums);
        assert!(f.free_t.is_empty() && f.free_r.is_empty());
        let back = f.to_nominal * m;
        assert!((back.translation.vector).norm() < 1e-9, "{back:?}");
        assert!(back.rotation.angle() < 1e-9);
    }

    #[test]
    fn one_plane_leaves_its_plane_free() {
        let nominal = Shape::Plane {
            p: P3::origin(),
            n: V3::z(),
        };
        let f = drf(&[(nominal.clone(), nominal)]);
        assert_eq!(f.free_t.len(), 2);
        assert_eq!(f.free_r, vec![V3::z()]);
    }
}
