//! `inspc cones`: the cones of one fpoint under one probe, as a summary and as an
//! unfolded cube-map image.

use super::errors::AccessError;
use super::{
    axes, gac, gac_halfline, orientations_in, point_cones, scan, scan_cones, tip_fits, Cell,
    ConeOptions, Cpu, CubeMap, Head, ProbeShape, ScannerShape, Scene,
};
use crate::diag::Diagnostics;
use crate::geometry::{PartGeometry, V3};
use crate::model::fmt_num;
use crate::sample::Fpoint;
use std::fmt::Write;

/// Which fpoint, which probe, what resolution.
#[derive(Debug, Clone)]
pub struct ConeRequest {
    /// A face name (as `inspc faces` lists them); all fpoints when absent.
    pub face: Option<String>,
    /// Which of the selected fpoints, from 0.
    pub point: usize,
    /// A probe label of the plan's machine; its first probe when absent.
    pub probe: Option<String>,
    /// Cube-map resolution.
    pub n: u32,
}

/// What `inspc cones` prints and draws.
#[derive(Debug, Clone)]
pub struct ConeReport {
    /// The summary for people.
    pub text: String,
    /// The drawn cone (the probe's, or the half-line's without a machine) as a binary
    /// PGM: an unfolded cube, a cross of 4 × 3 faces centred on +z.
    pub pgm: Vec<u8>,
}

/// The measurement graph a cone report looks into.
pub struct ConeInput<'a> {
    /// The model.
    pub model: &'a crate::model::Model,
    /// The part.
    pub part: &'a crate::model::Part,
    /// Its geometry.
    pub geometry: &'a PartGeometry,
    /// The graph's fpoints.
    pub fpoints: &'a [Fpoint],
    /// The plan the graph was sampled for, whose machine supplies the probes.
    pub plan: Option<&'a crate::model::Plan>,
}

/// Computes the cones the request names, or files a diagnostic saying what does not
/// exist.
pub fn cone_report(
    input: &ConeInput,
    req: &ConeRequest,
    diags: &mut Diagnostics,
) -> Option<ConeReport> {
    let (model, part, g) = (input.model, input.part, input.geometry);
    let chosen = chosen_fpoints(input, req, diags)?;
    let Some(f) = chosen.get(req.point) else {
        diags.push(AccessError::NoPoint {
            span: part.span,
            face: req.face.clone().unwrap_or_else(|| "the part".into()),
            index: req.point,
            count: chosen.len(),
        });
        return None;
    };
    let plan = input.plan;
    if let (Some(plan), Some(label)) = (plan, &req.probe) {
        let cmm = &model.cmms[plan.cmm.0];
        if let Some((l, id)) = cmm.scanners.iter().find(|(l, _)| l == label) {
            let shape = ScannerShape::new(model, cmm, l, &model.scanners[id.0]);
            return Some(scanner_report(input, req, f, chosen.len(), &shape));
        }
    }
    let probe = requested_probe(input, req, diags)?;
    let scene = Scene::of_part(g);
    let n = req.n;
    let prefs = axes();
    let mut text = fpoint_line(g, req, f, chosen.len());
    let _ = writeln!(
        text,
        "part {}: {} triangles, {}",
        part.name,
        scene.tris.len(),
        if scene.closed {
            "closed"
        } else {
            "open (no back-face culling)"
        }
    );
    text.push_str(&cells_line(n, &prefs));
    let r = probe.as_ref().map_or(1.0, |p| p.tip_radius);
    let c = f.tip_centre(r);
    let half = gac_halfline(&scene, &c, n, &prefs);
    let _ = writeln!(text, "  half-line at the tip centre      {}", share(&half));
    let drawn = match &probe {
        None => half,
        Some(probe) => probe_cones(input, (&scene, n, &prefs), f, probe, &mut text),
    };
    Some(ConeReport {
        text,
        pgm: pgm(&drawn),
    })
}

/// The fpoints a request chooses among: the named face's, or the part's; `None`, with a
/// diagnostic, for a face the part does not have.
fn chosen_fpoints<'a>(
    input: &ConeInput<'a>,
    req: &ConeRequest,
    diags: &mut Diagnostics,
) -> Option<Vec<&'a Fpoint>> {
    let (part, g) = (input.part, input.geometry);
    Some(match &req.face {
        Some(name) => {
            let Some(face) = g.faces.iter().position(|f| &f.name == name) else {
                let mut known: Vec<&str> = g.faces.iter().map(|f| f.name.as_str()).collect();
                known.truncate(12);
                diags.push(AccessError::UnknownFace {
                    span: part.span,
                    face: name.clone(),
                    part: part.name.clone(),
                    known: known.join(", "),
                });
                return None;
            };
            input.fpoints.iter().filter(|f| f.face.0 == face).collect()
        }
        None => input.fpoints.iter().collect(),
    })
}

/// The touch probe a request names (the plan machine's first without a label), or
/// `Some(None)` without a plan; `None`, with a diagnostic, for a label the machine does
/// not carry or a probe asked for without a machine.
fn requested_probe(
    input: &ConeInput,
    req: &ConeRequest,
    diags: &mut Diagnostics,
) -> Option<Option<ProbeShape>> {
    let model = input.model;
    Some(match input.plan {
        Some(plan) => {
            let cmm = &model.cmms[plan.cmm.0];
            let shapes = ProbeShape::of_cmm(model, cmm);
            let found = match &req.probe {
                Some(label) => shapes.into_iter().find(|s| &s.name == label),
                None => shapes.into_iter().next(),
            };
            if found.is_none() {
                diags.push(AccessError::UnknownProbe {
                    span: cmm.span,
                    probe: req.probe.clone().unwrap_or_default(),
                    cmm: cmm.name.clone(),
                    known: cmm
                        .probes
                        .iter()
                        .map(|(l, _)| l.as_str())
                        .chain(cmm.scanners.iter().map(|(l, _)| l.as_str()))
                        .collect::<Vec<_>>()
                        .join(", "),
                });
                return None;
            }
            found
        }
        None if req.probe.is_some() => {
            diags.push(AccessError::NoMachine {
                span: input.part.span,
                part: input.part.name.clone(),
            });
            return None;
        }
        None => None,
    })
}

/// The report's lines for a touch probe at fpoint `f` — its shape, whether its tip
/// fits, each leading component's cone, the approach cone (D1) and the axes and head
/// orientations in it — written to `text`, in `scene` at cube-map resolution `n` with
/// preferred directions `prefs`. Returns the approach cone, the one drawn.
fn probe_cones(
    input: &ConeInput,
    (scene, n, prefs): (&Scene, u32, &[V3]),
    f: &Fpoint,
    probe: &ProbeShape,
    text: &mut String,
) -> CubeMap {
    let model = input.model;
    let c = f.tip_centre(probe.tip_radius);
    let head = match probe.head {
        Head::Indexable => "indexable head",
        Head::Fixed => "fixed head",
    };
    let _ = writeln!(
        text,
        "probe {}: tip radius {} mm, reach {} mm, {head}",
        probe.name,
        fmt_num(probe.tip_radius),
        fmt_num(probe.reach())
    );
    if !tip_fits(scene, &c, probe.tip_radius) {
        let _ = writeln!(
            text,
            "  the tip does not fit: the part is {} mm from its centre",
            fmt_num(scene.distance(&c))
        );
    }
    for comp in &probe.leading() {
        let cone = gac(&Cpu, scene, &c, std::slice::from_ref(comp), n, prefs);
        let _ = writeln!(
            text,
            "  {:<32} {}",
            format!("{} (r {} mm)", comp.name, fmt_num(comp.radius)),
            share(&cone)
        );
    }
    let opts = ConeOptions {
        n,
        preferred: prefs.to_vec(),
        ..ConeOptions::default()
    };
    let cones = point_cones(&Cpu, scene, f, probe, &opts);
    let what = match probe.head {
        Head::Indexable => "D1, approach and retract",
        Head::Fixed => "probe, approach and retract",
    };
    let _ = writeln!(text, "  {what:<32} {}", share(&cones.approach));
    let axes_free: Vec<&str> = ["+x", "-x", "+y", "-y", "+z", "-z"]
        .into_iter()
        .enumerate()
        .filter(|(k, _)| cones.approach.get(Cell::Preferred(*k)))
        .map(|(_, s)| s)
        .collect();
    let _ = writeln!(
        text,
        "  axes in the cone: {}",
        if axes_free.is_empty() {
            "none".to_string()
        } else {
            axes_free.join(" ")
        }
    );
    if let Some(d2) = &cones.d2 {
        let _ = writeln!(text, "  D2 (setup directions)           {}", share(d2));
        let cmm = &model.cmms[input.plan.map(|p| p.cmm.0).unwrap_or(0)];
        let grid = model.heads[cmm.head.0].orientations();
        let inside = orientations_in(&cones.approach, &grid);
        let _ = writeln!(
            text,
            "  head orientations in D1: {} of {}",
            inside.len(),
            grid.len()
        );
    }
    cones.approach
}

/// The report of a scanner's cones at one point: the share of directions each condition
/// leaves, the head orientations that see it, and the visible cone drawn.
fn scanner_report(
    input: &ConeInput,
    req: &ConeRequest,
    f: &Fpoint,
    of: usize,
    shape: &ScannerShape,
) -> ConeReport {
    let g = input.geometry;
    let scene = Scene::of_part(g);
    let n = req.n;
    let prefs = axes();
    let face = &g.faces[f.face.0];
    let o = &shape.optics;
    let mut text = fpoint_line(g, req, f, of);
    let _ = writeln!(
        text,
        "scanner {}: stripe {} mm at stand-off {} ± {} mm, triangulation {}°, incidence ≤ {}°",
        shape.probe.name,
        fmt_num(o.stripe),
        fmt_num(o.standoff),
        fmt_num(o.depth / 2.0),
        fmt_num(o.triangulation.to_degrees()),
        fmt_num(o.max_incidence.to_degrees())
    );
    text.push_str(&cells_line(n, &prefs));
    let opts = ConeOptions {
        n,
        preferred: prefs.clone(),
        ..ConeOptions::default()
    };
    let cones = scan_cones(&Cpu, &scene, &f.position, &f.normal, shape, &opts);
    let within = cones.rays.cap(&f.normal, o.max_incidence.cos());
    let _ = writeln!(
        text,
        "  within the incidence limit       {}",
        share(&within)
    );
    let _ = writeln!(
        text,
        "  laser and camera reach the point {}",
        share(&cones.rays)
    );
    let what = match shape.probe.head {
        Head::Indexable => "housing clear (D1)",
        Head::Fixed => "housing, head and ram clear",
    };
    let _ = writeln!(text, "  {what:<32} {}", share(&cones.visible));
    // The head's orientations; none for a fixed head or without a plan.
    let grid = input.plan.map_or(Vec::new(), |plan| {
        input.model.heads[input.model.cmms[plan.cmm.0].head.0].orientations()
    });
    if let Some(d2) = &cones.d2 {
        let _ = writeln!(text, "  D2 (setup directions)           {}", share(d2));
        if !grid.is_empty() {
            let inside = orientations_in(&cones.visible, &grid);
            let _ = writeln!(
                text,
                "  head orientations that see it: {} of {}",
                inside.len(),
                grid.len()
            );
        }
    }
    if req.face.is_some() {
        let grid = if grid.is_empty() {
            vec![(0.0, 0.0)]
        } else {
            grid
        };
        let overlap = 0.2;
        let views = scan::Views {
            up: crate::geometry::V3::z(),
            table: (f64::NEG_INFINITY, 0.0),
            fixture: &[],
            grid: &grid,
            overlap,
        };
        let fc = scan::face_coverage(&Cpu, &scene, g, f.face.0, shape, &views, &opts);
        let _ = writeln!(
            text,
            "face {}: {} mm², judged on {} samples, the part in its own frame (+z up): \
             {:.1} % of its area seen from {} head orientation{}",
            face.name,
            fmt_num((fc.area * 10.0).round() / 10.0),
            fc.samples,
            100.0 * fc.covered,
            fc.views.len(),
            if fc.views.len() == 1 { "" } else { "s" }
        );
        for v in &fc.views {
            let _ = writeln!(
                text,
                "  A {} B {}: {:5.1} % of the area, {} pass{} of {} mm at {} elevation{} \
                 ({} % overlap)",
                fmt_num(v.a),
                fmt_num(v.b),
                100.0 * v.share,
                v.passes,
                if v.passes == 1 { "" } else { "es" },
                fmt_num(v.length.round()),
                v.elevations,
                if v.elevations == 1 { "" } else { "s" },
                fmt_num(100.0 * overlap)
            );
        }
    }
    ConeReport {
        text,
        pgm: pgm(&cones.visible),
    }
}

/// A report's first line: which fpoint, where, its normal.
fn fpoint_line(g: &PartGeometry, req: &ConeRequest, f: &Fpoint, of: usize) -> String {
    let v = |x: &V3| format!("({}, {}, {})", fmt_num(x.x), fmt_num(x.y), fmt_num(x.z));
    let face = &g.faces[f.face.0];
    format!(
        "fpoint {} of {of} on face {} ({}): at {}, normal {}\n",
        req.point,
        face.name,
        face.surface.kind().keyword(),
        v(&f.position.coords),
        v(&f.normal)
    )
}

/// The line that introduces the shares: the resolution and the cells counted.
fn cells_line(n: u32, preferred: &[V3]) -> String {
    let total = 6 * (n as usize) * (n as usize) + preferred.len();
    format!("cube map N = {n}: {total} cells (pixels and 6 axes); free share:\n")
}

/// The share of a cone's cells that are free, as the reports print it.
fn share(c: &CubeMap) -> String {
    let total = 6 * (c.n() as usize) * (c.n() as usize) + c.preferred_len();
    format!("{:5.1} %", 100.0 * c.count() as f64 / total as f64)
}

/// The cone as a binary PGM: free white, blocked black, the unused corners of the cross
/// grey. Tiles (column, row): +y (1, 0); −x (0, 1), +z (1, 1), +x (2, 1), −z (3, 1);
/// −y (1, 2). Seen from outside with +z up front, x to the right and y up the image.
pub fn pgm(cone: &CubeMap) -> Vec<u8> {
    let n = cone.n() as usize;
    let (w, h) = (4 * n, 3 * n);
    let mut out = format!("P5\n{w} {h}\n255\n").into_bytes();
    for row in 0..h {
        for col in 0..w {
            let (tx, ty) = (col / n, row / n);
            let s = 2.0 * ((col % n) as f64 + 0.5) / n as f64 - 1.0;
            let t = 1.0 - 2.0 * ((row % n) as f64 + 0.5) / n as f64;
            let d = match (tx, ty) {
                (1, 1) => Some(V3::new(s, t, 1.0)),
                (2, 1) => Some(V3::new(1.0, t, -s)),
                (0, 1) => Some(V3::new(-1.0, t, s)),
                (3, 1) => Some(V3::new(-s, t, -1.0)),
                (1, 0) => Some(V3::new(s, 1.0, -t)),
                (1, 2) => Some(V3::new(s, -1.0, t)),
                _ => None,
            };
            out.push(match d {
                Some(d) if cone.get(Cell::Pixel(cone.pixel_of(&d))) => 255,
                Some(_) => 0,
                None => 128,
            });
        }
    }
    out
}
