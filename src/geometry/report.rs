//! Face listings for `inspc faces`.

use super::{PartGeometry, Surface, V3};
use crate::model::fmt_num;
use std::fmt::Write;

fn r(v: f64) -> String {
    fmt_num((v * 1000.0).round() / 1000.0)
}

fn vec3(v: &V3) -> String {
    format!("({}, {}, {})", r(v.x), r(v.y), r(v.z))
}

/// What a face's surface is, in one line.
pub fn describe(s: &Surface) -> String {
    match s {
        Surface::Plane { normal, .. } => format!("normal {}", vec3(normal)),
        Surface::Cylinder {
            origin,
            axis,
            radius,
            convex,
        } => {
            format!(
                "axis {} through {} r {}{}",
                vec3(axis),
                vec3(&origin.coords),
                r(*radius),
                if *convex { "" } else { " (hole)" }
            )
        }
        Surface::Cone {
            apex,
            axis,
            half_angle,
            convex,
        } => format!(
            "axis {} apex {} half-angle {}°{}",
            vec3(axis),
            vec3(&apex.coords),
            r(half_angle.to_degrees()),
            if *convex { "" } else { " (inner)" }
        ),
        Surface::Sphere {
            center,
            radius,
            convex,
        } => format!(
            "centre {} r {}{}",
            vec3(&center.coords),
            r(*radius),
            if *convex { "" } else { " (inner)" }
        ),
        Surface::Freeform => String::new(),
    }
}

/// A table of a geometry's faces.
pub fn faces_table(title: &str, g: &PartGeometry) -> String {
    let mut o = String::new();
    let live = g.faces.iter().filter(|f| f.area > 0.0).count();
    let _ = writeln!(
        o,
        "{title}: {live} faces, {} triangles, {} vertices",
        g.triangles.len(),
        g.vertices.len()
    );
    // A CAD part's faces also show the file's own id (`step_face N`, `qif_face N`).
    let file_id = |k: usize| match &g.cad {
        Some(c) => format!("{:>9}  ", format!("#{}", c.ids[k])),
        None => String::new(),
    };
    let _ = writeln!(
        o,
        "{:>4}  {}{:<20} {:<9} {:>12}  {:<28} surface",
        "id",
        g.cad
            .as_ref()
            .map_or(String::new(), |c| format!("{:>9}  ", c.kind.keyword())),
        "name",
        "type",
        "area mm²",
        "centroid"
    );
    for (k, f) in g.faces.iter().enumerate().filter(|(_, f)| f.area > 0.0) {
        let _ = writeln!(
            o,
            "{:>4}  {}{:<20} {:<9} {:>12}  {:<28} {}",
            k,
            file_id(k),
            f.name,
            f.surface.kind().keyword(),
            r(f.area),
            vec3(&f.centroid.coords),
            describe(&f.surface)
        );
    }
    o
}

/// The faces as JSON objects.
pub fn faces_json(g: &PartGeometry) -> Vec<serde_json::Value> {
    g.faces
        .iter()
        .enumerate()
        .filter(|(_, f)| f.area > 0.0)
        .map(|(k, f)| {
            let mut v = serde_json::json!({
                "id": k,
                "name": f.name,
                "type": f.surface.kind().keyword(),
                "area": f.area,
                "centroid": [f.centroid.x, f.centroid.y, f.centroid.z],
                "surface": describe(&f.surface),
                "fit_rms": f.fit_rms,
                "triangles": f.triangles.len(),
            });
            if let Some(c) = &g.cad {
                v[c.kind.keyword()] = c.ids[k].into();
            }
            v
        })
        .collect()
}
