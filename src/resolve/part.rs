//! Parts: units, geometry source, faces, features, datums, frames (machining operations
//! and patterns: `ops.rs`).

use super::datum::{check_unique_datums, datum, datum_ref};
use super::errors::ResolveError as E;
use super::faces::face_expr;
use super::props::{call_args, path_text, Cx, Dim, Props, UNITS};
use super::scope::{Local, PartCx};
use super::{ops, tolerance, Resolver};
use crate::diag::suggest;
use crate::model::*;
use crate::source::Span;
use crate::syntax::ast::{self, NamedKind, PartStmt};
use std::collections::BTreeMap;

pub(super) fn lower(r: &Resolver, cx: &mut Cx, p: &ast::Part) -> Part {
    let mut part = Part {
        name: p.name.name.clone(),
        unit_mm: 1.0,
        geometry: Geometry::Stock(Stock::Box { size: [1.0; 3] }),
        ops: vec![],
        features: vec![],
        datums: vec![],
        frames: vec![],
        tolerances: vec![],
        span: p.name.span,
    };
    // Units first: they give bare numbers their meaning.
    if let Some(f) = part_units(cx, p) {
        part.unit_mm = f;
    }
    cx.unit_mm = Some(part.unit_mm);
    let is_mesh = read_geometry(r, cx, p, &mut part);

    // Declare every local name so references can say what a name is.
    let mut pc = PartCx {
        part,
        names: BTreeMap::new(),
        lowered_features: 0,
        stmts: &p.stmts,
    };
    declare_locals(cx, &mut pc);

    ops::lower(cx, &mut pc, is_mesh);
    features_and_datums(cx, &mut pc, is_mesh);
    frames(cx, &mut pc);
    tolerances(cx, &mut pc);
    cx.unit_mm = None;
    pc.part
}

/// The part's `units`, said once; None (after saying why) where it is missing or not a
/// length unit.
fn part_units(cx: &mut Cx, p: &ast::Part) -> Option<f64> {
    let units: Vec<&ast::Ident> = p
        .stmts
        .iter()
        .filter_map(|s| {
            if let PartStmt::Units(u) = s {
                Some(u)
            } else {
                None
            }
        })
        .collect();
    match units.as_slice() {
        [] => {
            cx.err(E::MissingProperty {
                span: p.name.span,
                key: "units".into(),
                item: format!("part `{}`", p.name.name),
                help: "add `units mm` (or cm, m, um, in): bare numbers in the part are read in these units".into(),
            });
            None
        }
        [u, rest @ ..] => {
            let f = length_unit(cx, u);
            for dup in rest {
                cx.err(E::DuplicateProperty {
                    span: dup.span,
                    first: u.span,
                    key: "units".into(),
                });
            }
            f
        }
    }
}

/// The part's one geometry source, a stock or a mesh, into `part.geometry`; whether it
/// is a mesh (false where there is none).
fn read_geometry(r: &Resolver, cx: &mut Cx, p: &ast::Part, part: &mut Part) -> bool {
    let mut source_span: Option<Span> = None;
    let mut have_stock = false;
    for s in &p.stmts {
        let (span, geometry) = match s {
            PartStmt::Stock(call) => (call.span, stock(cx, call)),
            PartStmt::Mesh { path, props, span } => (*span, mesh(r, cx, path, props, part.unit_mm)),
            _ => continue,
        };
        if let Some(first) = source_span {
            cx.err(E::DuplicateGeometry {
                span,
                first,
                part: part.name.clone(),
            });
            continue;
        }
        source_span = Some(span);
        have_stock = matches!(s, PartStmt::Stock(_));
        if let Some(g) = geometry {
            part.geometry = g;
        }
    }
    if source_span.is_none() {
        cx.err(E::NoGeometry {
            span: p.name.span,
            part: part.name.clone(),
        });
    }
    source_span.is_some() && !have_stock
}

/// Faces, features and datums in declaration order (a feature may use those above it).
fn features_and_datums(cx: &mut Cx, pc: &mut PartCx, is_mesh: bool) {
    for s in pc.stmts {
        match s {
            PartStmt::Named {
                what: what @ (NamedKind::Face | NamedKind::Feature),
                name,
                expr,
                ..
            } => feature(cx, pc, *what, name, expr.as_ref(), is_mesh),
            PartStmt::Named {
                what: NamedKind::Datum,
                name,
                expr,
                span,
            } => {
                datum(cx, pc, name, expr.as_ref(), *span, is_mesh);
            }
            _ => {}
        }
    }
}

/// `face name = …` or `feature name = …`: its faces, reported empty when it names none.
fn feature(
    cx: &mut Cx,
    pc: &mut PartCx,
    what: NamedKind,
    name: &ast::Ident,
    expr: Option<&ast::FaceExpr>,
    is_mesh: bool,
) {
    let faces = match expr {
        Some(e) => face_expr(cx, pc, e, is_mesh),
        None => vec![],
    };
    if faces.is_empty() && expr.is_none() {
        cx.err(E::EmptyFeature {
            span: name.span,
            name: name.name.clone(),
        });
    }
    pc.part.features.push(Feature {
        name: name.name.clone(),
        faces,
        declared: if what == NamedKind::Face {
            Declared::Face
        } else {
            Declared::Feature
        },
        span: name.span,
    });
    pc.lowered_features += 1;
}

/// Every `frame name = [A, B, C]`, each datum once.
fn frames(cx: &mut Cx, pc: &mut PartCx) {
    for s in pc.stmts {
        if let PartStmt::Frame { name, refs, .. } = s {
            let refs = refs
                .iter()
                .filter_map(|e| datum_ref(cx, pc, &e.value))
                .collect::<Vec<_>>();
            check_unique_datums(cx, &pc.part, &refs);
            pc.part.frames.push(Frame {
                name: name.name.clone(),
                refs: refs.into_iter().map(|(d, _)| d).collect(),
                span: name.span,
            });
        }
    }
}

/// Every `tolerance name = kind(…)` that checks out.
fn tolerances(cx: &mut Cx, pc: &mut PartCx) {
    for s in pc.stmts {
        if let PartStmt::Tolerance { name, call, .. } = s {
            if let Some(t) = tolerance::lower(cx, pc, name, call) {
                pc.part.tolerances.push(t);
            }
        }
    }
}

pub(super) fn length_unit(cx: &mut Cx, u: &ast::Ident) -> Option<f64> {
    if let Some(f) = super::props::length_unit_mm(&u.name) {
        return Some(f);
    }
    match UNITS.iter().find(|(n, _, _)| *n == u.name) {
        Some(_) => {
            cx.err(E::UnitMismatch {
                span: u.span,
                expected: "a length unit".into(),
                found: "another unit".into(),
                unit: u.name.clone(),
                help: "part units are mm, cm, m, um or in".into(),
            });
            None
        }
        None => {
            let lengths = UNITS
                .iter()
                .filter(|(_, d, _)| *d == Dim::Length)
                .map(|(n, _, _)| *n);
            let help = suggest::help_for_unknown("unit", &u.name, lengths);
            cx.err(E::UnknownUnit {
                span: u.span,
                unit: u.name.clone(),
                help,
            });
            None
        }
    }
}

fn declare_locals(cx: &mut Cx, pc: &mut PartCx) {
    let mut counts = [0usize; 4];
    for s in pc.stmts {
        let (name, local) = match s {
            PartStmt::Cut { name, .. } => {
                counts[0] += 1;
                (name, Local::Op(counts[0] - 1))
            }
            PartStmt::Named {
                what: NamedKind::Face | NamedKind::Feature,
                name,
                ..
            } => {
                counts[1] += 1;
                (name, Local::Feature(counts[1] - 1))
            }
            PartStmt::Named {
                what: NamedKind::Datum,
                name,
                ..
            } => {
                counts[2] += 1;
                (name, Local::Datum(counts[2] - 1))
            }
            PartStmt::Frame { name, .. } => {
                counts[3] += 1;
                (name, Local::Frame(counts[3] - 1))
            }
            PartStmt::Tolerance { name, .. } => (name, Local::Tolerance),
            _ => continue,
        };
        if name.name == "stock" {
            cx.err(E::DuplicateName {
                span: name.span,
                first: None,
                name: "stock".into(),
                help: "`stock` names the part's stock; choose another name".into(),
            });
            continue;
        }
        if let Some((_, first)) = pc.names.get(&name.name) {
            cx.err(E::DuplicateName { span: name.span, first: Some(*first), name: name.name.clone(), help: "names inside a part are shared by operations, faces, features, datums, frames and tolerances".into() });
            continue;
        }
        pc.names.insert(name.name.clone(), (local, name.span));
    }
    pc.names
        .insert("stock".into(), (Local::Stock, Span::new(cx.file, 0, 0)));
}

fn stock(cx: &mut Cx, call: &ast::Call) -> Option<Geometry> {
    let Some(shape) = call.callee.as_ident() else {
        cx.err(E::UnknownName {
            span: call.callee.span,
            what: "stock shape".into(),
            name: path_text(&call.callee),
            help: "stock is `box(x, y, z)`, `cylinder(diameter, height)` or `sphere(diameter)`"
                .into(),
        });
        return None;
    };
    let pos = |cx: &mut Cx, v: Option<&ast::Value>, what: &str| {
        v.and_then(|v| cx.positive(v, Dim::Length, what))
    };
    let s = match shape.name.as_str() {
        "box" => {
            let a = call_args(cx, call, &["x", "y", "z"], "a box");
            let (x, y, z) = (pos(cx, a[0], "x"), pos(cx, a[1], "y"), pos(cx, a[2], "z"));
            Stock::Box { size: [x?, y?, z?] }
        }
        "cylinder" => {
            let a = call_args(cx, call, &["diameter", "height"], "a cylinder");
            let (d, h) = (pos(cx, a[0], "diameter"), pos(cx, a[1], "height"));
            Stock::Cylinder {
                diameter: d?,
                height: h?,
            }
        }
        "sphere" => {
            let a = call_args(cx, call, &["diameter"], "a sphere");
            Stock::Sphere {
                diameter: pos(cx, a[0], "diameter")?,
            }
        }
        other => {
            let help =
                suggest::help_for_unknown("stock shape", other, ["box", "cylinder", "sphere"]);
            cx.err(E::UnknownName {
                span: shape.span,
                what: "stock shape".into(),
                name: other.into(),
                help,
            });
            return None;
        }
    };
    Some(Geometry::Stock(s))
}

fn mesh(
    r: &Resolver,
    cx: &mut Cx,
    path: &ast::Str,
    props: &[ast::Prop],
    part_unit: f64,
) -> Option<Geometry> {
    let cad = CadKind::of_path(std::path::Path::new(&path.value))
        .map(|k| format!("a {} file (it states its own length unit)", k.file()));
    let item = cad.clone().unwrap_or_else(|| "a mesh".into());
    let mut p = Props::new(cx, item, path.span, props);
    let mut unit_mm = part_unit;
    let mut chord_mm = None;
    if cad.is_some() {
        // The B-rep is exact; the chord says how closely its mesh follows it.
        chord_mm = p.get("chord").and_then(|v| {
            let c = cx.positive(v, Dim::Length, "chord")?;
            if !(MIN_CHORD_MM..=MAX_CHORD_MM).contains(&c) {
                cx.err(E::OutOfRange {
                    span: v.span,
                    what: "the chord tolerance".into(),
                    value: format!("{} mm", crate::model::fmt_num(c)),
                    range: format!("{MIN_CHORD_MM} mm to {MAX_CHORD_MM} mm"),
                    help: "0.1 mm (the default) follows the surfaces as the NIST reference meshes do; finer costs triangles, coarser misplaces points".into(),
                });
                return None;
            }
            Some(c)
        });
    } else {
        unit_mm = p
            .get("units")
            .and_then(|v| cx.name(v).cloned())
            .and_then(|u| length_unit(cx, &u))
            .unwrap_or(part_unit);
    }
    // After the file's unit, a factor for a file modelled at another size (the MFCAD
    // parts are 10-unit cubes of 100 mm blocks).
    let scale = p.get("scale").and_then(|v| {
        let s = cx.number(v)?;
        if !(MIN_SCALE..=MAX_SCALE).contains(&s) {
            cx.err(E::OutOfRange {
                span: v.span,
                what: "the scale".into(),
                value: crate::model::fmt_num(s),
                range: format!("{MIN_SCALE} to {MAX_SCALE}"),
                help: "`scale` multiplies the file's geometry after its unit: 10 reads a 10 mm model as a 100 mm part".into(),
            });
            return None;
        }
        Some(s)
    });
    p.finish(cx);
    let full = mesh_file(r, cx, path)?;
    Some(Geometry::Mesh {
        path: full,
        unit_mm,
        chord_mm,
        scale: scale.unwrap_or(1.0),
        span: path.span,
    })
}

/// The least and greatest factor a mesh may be scaled by.
const MIN_SCALE: f64 = 0.001;
const MAX_SCALE: f64 = 1000.0;

/// The finest and coarsest chord tolerance a CAD part may be meshed to (mm).
const MIN_CHORD_MM: f64 = 0.01;
const MAX_CHORD_MM: f64 = 1.0;

/// The full path of a mesh file a spec names (relative to the spec's folder): an STL,
/// OBJ or STEP file that exists. A missing file is reported and still gives its path.
pub(super) fn mesh_file(r: &Resolver, cx: &mut Cx, path: &ast::Str) -> Option<std::path::PathBuf> {
    let ext = std::path::Path::new(&path.value)
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if !matches!(ext.as_str(), "stl" | "obj" | "stp" | "step" | "qif") {
        cx.err(E::MeshFormat {
            span: path.span,
            ext: if ext.is_empty() {
                "(none)".into()
            } else {
                format!(".{ext}")
            },
        });
        return None;
    }
    let base = r
        .sources
        .get(cx.file)
        .dir()
        .map(|d| d.to_path_buf())
        .unwrap_or_default();
    let full = crate::source::normalize_path(&base.join(&path.value));
    if !r.world.exists(&full) {
        cx.err(E::FileNotFound {
            span: path.span,
            path: path.value.clone(),
        });
    }
    Some(full)
}
