//! Sensor selection (Zhao et al. sec. 3): per feature of a plan whose machine carries a
//! laser line scanner, touch or laser, and why. The plan's `sensors { … }` decides where
//! it says so; elsewhere the rule is the paper's: a deep bore goes to the touch probe
//! (the camera does not see down its wall), and a feature goes to the scanner when its
//! tightest tolerance is at least `sensor_ratio` times the scanner's accuracy (1:10 by
//! default), since scanning is the faster of the two.

use crate::geometry::{FaceId, PartGeometry, Surface};
use crate::model::{fmt_num, FeatureId, Model, Plan, SensorChoice, TolKind, TolValue};

/// The sensor chosen for a feature.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sensor {
    /// The rack's touch probes.
    Touch,
    /// The scanner at this index of the machine's `scanners`.
    Laser(usize),
}

impl Sensor {
    /// The sensor's word, as the plan's `sensors { … }` spells it.
    pub fn word(self) -> &'static str {
        match self {
            Sensor::Touch => "touch",
            Sensor::Laser(_) => "laser",
        }
    }
}

/// One feature's sensor and the reason, in words for the plan's reader.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorPick {
    /// The feature.
    pub feature: FeatureId,
    /// Its sensor.
    pub sensor: Sensor,
    /// Why: `flatness 0.2 mm / 0.009 mm = 22 ≥ 10`.
    pub why: String,
}

/// The sensor of every feature of the plan's part, in feature order; empty when the
/// plan's machine has no scanner (every feature is touched, nothing to choose).
pub fn select(
    model: &Model,
    plan: &Plan,
    geometry: &PartGeometry,
    feature_faces: &[Vec<FaceId>],
) -> Vec<SensorPick> {
    let cmm = &model.cmms[plan.cmm.0];
    // The most accurate scanner of the rack (the first of equals).
    let Some((best, scanner)) = cmm
        .scanners
        .iter()
        .enumerate()
        .map(|(k, (_, id))| (k, &model.scanners[id.0]))
        .min_by(|a, b| a.1.accuracy.total_cmp(&b.1.accuracy))
    else {
        return Vec::new();
    };
    let part = &model.parts[plan.part.0];
    let mut out = Vec::new();
    for f in 0..part.features.len() {
        let asked = plan
            .sensors
            .iter()
            .find(|(g, _, _)| g.0 == f)
            .map_or(SensorChoice::Auto, |s| s.1);
        let pick = |sensor: Sensor, why: String| SensorPick {
            feature: FeatureId(f),
            sensor,
            why,
        };
        match asked {
            SensorChoice::Touch => out.push(pick(Sensor::Touch, "the plan asks for touch".into())),
            SensorChoice::Laser => out.push(pick(
                Sensor::Laser(best),
                "the plan asks for the laser".into(),
            )),
            SensorChoice::Auto => {
                let faces = feature_faces.get(f).map_or(&[][..], |v| &v[..]);
                if let Some(why) = deep_bore(geometry, faces) {
                    out.push(pick(Sensor::Touch, why));
                    continue;
                }
                match tightest(model, plan, f) {
                    None => out.push(pick(
                        Sensor::Laser(best),
                        "no tolerance asks more of it than the scanner gives".into(),
                    )),
                    Some((name, band)) => {
                        let ratio = band / scanner.accuracy;
                        let text = format!(
                            "{name} {} mm / {} mm = {}",
                            fmt_num(band),
                            fmt_num(scanner.accuracy),
                            fmt_num((ratio * 10.0).round() / 10.0)
                        );
                        if ratio >= plan.sensor_ratio {
                            let why = format!("{text} ≥ {}", fmt_num(plan.sensor_ratio));
                            out.push(pick(Sensor::Laser(best), why));
                        } else {
                            let why = format!("{text} < {}", fmt_num(plan.sensor_ratio));
                            out.push(pick(Sensor::Touch, why));
                        }
                    }
                }
            }
        }
    }
    out
}

/// Why a feature is a bore the scanner cannot see into: a hole's wall (an inner
/// cylinder) at least as deep as its radius.
fn deep_bore(g: &PartGeometry, faces: &[FaceId]) -> Option<String> {
    for face in faces {
        let f = &g.faces[face.0];
        let (origin, axis, radius) = match &f.surface {
            Surface::Cylinder {
                origin,
                axis,
                radius,
                convex: false,
            } => (*origin, *axis, *radius),
            _ => continue,
        };
        let (lo, hi) = f
            .triangles
            .iter()
            .flat_map(|&t| g.triangles[t as usize])
            .map(|v| (g.vertices[v as usize] - origin).dot(&axis))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            });
        let depth = hi - lo;
        if depth >= radius {
            return Some(format!(
                "a bore Ø{} mm, {} mm deep: the camera does not see down its wall",
                fmt_num((2.0 * radius * 1000.0).round() / 1000.0),
                fmt_num((depth * 1000.0).round() / 1000.0)
            ));
        }
    }
    None
}

/// The tightest tolerance reading feature `f` (as a target, or through a datum it
/// carries): its name and its band (mm). Angle sizes are in degrees and left out.
fn tightest(model: &Model, plan: &Plan, f: usize) -> Option<(String, f64)> {
    let part = &model.parts[plan.part.0];
    part.tolerances
        .iter()
        .filter(|t| {
            t.targets.iter().any(|g| g.0 == f)
                || t.datums
                    .iter()
                    .any(|r| part.datums[r.datum.0].feature.0 == f)
        })
        .filter_map(|t| {
            let band = match t.value {
                TolValue::Zone { width, .. } => width,
                TolValue::Size { .. } if t.kind == TolKind::Angle => return None,
                TolValue::Size { lower, upper, .. } => upper - lower,
            };
            Some((t.name.clone(), band))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
}
