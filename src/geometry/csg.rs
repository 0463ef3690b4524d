//! Constructive parts: stock and machining operations combined by boolean operations,
//! then every output triangle classified onto the named face whose exact surface it
//! lies on.
//!
//! **Decision: mesh booleans by boolmesh** (a pure-Rust port of Manifold, pinned
//! `=0.1.10`; MPL-2.0; glam inside, converted at its boundary only). Manifold's C++
//! bindings would keep face provenance but need a C++ build in CI; csgrs is BSP-based
//! and slower. boolmesh returns no provenance, so this file recovers it: a triangle
//! belongs to the named face whose exact surface holds all its corners (within the 0.05
//! mm tessellation tolerance for curved faces), whose outward normal agrees with the
//! triangle's, and whose primitive bounds contain it. Consecutive disjoint tools of one
//! kind are batched into one boolean: swiss_block's 100 holes are one subtraction, an
//! order of magnitude faster than one at a time.

use super::errors::GeometryError as E;
use super::primitives::{
    circle, prism, rectangle, rounded_rectangle, sphere, Frame, Prim, CHORD_MM,
};
use super::{PartGeometry, Surface, P3, V3};
use crate::diag::Diagnostics;
use crate::model::{
    self, Action, Depth, FaceSource, OpId, OpKind, Pattern, Placement, Role, Stock,
};
use boolmesh::prelude::{compute_boolean, Manifold, OpType};
use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion};

/// A named face before booleans: its surface, the roles it answers to, and where its
/// triangles can be (bounds of the primitive face, slightly grown).
pub(crate) struct Spec {
    pub name: String,
    pub surface: Surface,
    pub source: FaceSource,
    pub roles: Vec<Role>,
    lo: P3,
    hi: P3,
}

/// One primitive to add or remove, with its bounds.
struct Tool {
    prim: Prim,
    bounds: (P3, P3),
    action: Action,
    op: usize,
}

pub(super) fn build(
    part: &model::Part,
    stock: &Stock,
    diags: &mut Diagnostics,
) -> Option<PartGeometry> {
    let (stock_prim, stock_roles) = stock_primitive(stock);
    let size = StockSize::of(&stock_prim);
    let mut specs = stock_specs(&stock_prim, &stock_roles, size.grow);
    let material = material_bounds(part, stock, &size);
    let tools = place_tools(part, stock, &size, material, &mut specs, diags);
    let current = apply_tools(part, &stock_prim, &tools, diags)?;
    Some(classified(&current, specs, size.diag))
}

/// The stock as a primitive, with the role of each of its faces in order.
fn stock_primitive(stock: &Stock) -> (Prim, Vec<Role>) {
    match stock {
        Stock::Box { size } => {
            let f = Frame {
                o: P3::origin(),
                u: V3::x(),
                v: V3::y(),
                w: V3::z(),
            };
            (
                prism(&f, &rectangle(0.0, 0.0, size[0], size[1]), 0.0, size[2]),
                vec![
                    Role::Front,
                    Role::Right,
                    Role::Back,
                    Role::Left,
                    Role::Bottom,
                    Role::Top,
                ],
            )
        }
        Stock::Cylinder { diameter, height } => {
            let f = Frame {
                o: P3::origin(),
                u: V3::x(),
                v: V3::y(),
                w: V3::z(),
            };
            (
                prism(&f, &circle(diameter / 2.0), 0.0, *height),
                vec![Role::Side, Role::Bottom, Role::Top],
            )
        }
        Stock::Sphere { diameter } => (sphere(P3::origin(), diameter / 2.0), vec![Role::Surface]),
    }
}

/// The lengths a build takes from the stock's bounds.
struct StockSize {
    /// The stock's bounds.
    lo: P3,
    hi: P3,
    /// Their middle.
    center: P3,
    /// Their diagonal (mm).
    diag: f64,
    /// How far a cutter reaches back behind its entry (mm).
    ext: f64,
    /// A length past anything of the part (mm): a through cut's, an open slot's.
    big: f64,
    /// How far a face's bounds are grown to hold its triangles (mm).
    grow: f64,
}

impl StockSize {
    fn of(stock_prim: &Prim) -> StockSize {
        let (lo, hi) = stock_prim.bounds();
        let diag = (hi - lo).norm();
        StockSize {
            lo,
            hi,
            center: P3::from((lo.coords + hi.coords) / 2.0),
            diag,
            ext: 1.0 + 0.01 * diag,
            big: 2.0 * diag + 10.0,
            grow: 2.0 * CHORD_MM + 1e-6 * diag.max(1.0),
        }
    }
}

/// The specs of the stock's faces, `stock.<role>`, their bounds grown by `grow`.
fn stock_specs(stock_prim: &Prim, stock_roles: &[Role], grow: f64) -> Vec<Spec> {
    let mut specs = Vec::new();
    for (k, role) in stock_roles.iter().enumerate() {
        let (lo, hi) = stock_prim.bounds_of_part(k as u32);
        specs.push(Spec {
            name: format!("stock.{role}"),
            surface: stock_prim.surfaces[k].clone(),
            source: FaceSource::Stock,
            roles: vec![*role],
            lo: lo - V3::repeat(grow),
            hi: hi + V3::repeat(grow),
        });
    }
    specs
}

/// Where material may be: the bounds of the stock and of every added instance.
fn material_bounds(part: &model::Part, stock: &Stock, size: &StockSize) -> (P3, P3) {
    let (mut mlo, mut mhi) = (size.lo, size.hi);
    for op in part.ops.iter().filter(|o| o.action == Action::Add) {
        let Some((prim, _)) = cutter(op, stock, size.center, size.ext, size.big) else {
            continue;
        };
        for m in op
            .pattern
            .as_ref()
            .map_or_else(|| vec![Isometry3::identity()], pattern)
        {
            let mut prim = prim.clone();
            prim.transform(&m);
            let (lo, hi) = prim.bounds();
            mlo = mlo.inf(&lo);
            mhi = mhi.sup(&hi);
        }
    }
    (mlo, mhi)
}

/// Every operation's instances as tools, in order, with the specs of their faces added
/// to `specs`; an instance that misses the part (outside the stock, or cutting from
/// outside the material `(mlo, mhi)`) is left out, with one error per operation.
fn place_tools(
    part: &model::Part,
    stock: &Stock,
    size: &StockSize,
    (mlo, mhi): (P3, P3),
    specs: &mut Vec<Spec>,
    diags: &mut Diagnostics,
) -> Vec<Tool> {
    let (slo, shi, center) = (size.lo, size.hi, size.center);
    let mut tools: Vec<Tool> = Vec::new();
    for (oi, op) in part.ops.iter().enumerate() {
        let Some((prim, roles)) = cutter(op, stock, center, size.ext, size.big) else {
            continue;
        };
        let instances: Vec<(Option<u32>, Isometry3<f64>)> = match &op.pattern {
            None => vec![(None, Isometry3::identity())],
            Some(p) => pattern(p)
                .into_iter()
                .enumerate()
                .map(|(i, m)| (Some(i as u32), m))
                .collect(),
        };
        let total = instances.len();
        let mut missed: Vec<String> = Vec::new();
        for (inst, m) in instances {
            let mut prim = prim.clone();
            prim.transform(&m);
            let (lo, hi) = prim.bounds();
            // A cut goes into the material from its entry: just past the entry along its
            // direction there must be material, or it points out of the part (its tool
            // would only cut the overlap kept behind the entry).
            let points_out = cut_start(op, stock, center).is_some_and(|p| {
                let p = m * p;
                (0..3).any(|k| p[k] < mlo[k] || p[k] > mhi[k])
            });
            if points_out || (0..3).any(|k| hi[k] < slo[k] || lo[k] > shi[k]) {
                missed.push(inst.map_or(op.name.clone(), |i| format!("{}[{i}]", op.name)));
                continue;
            }
            specs.extend(instance_specs(op, (oi, inst), &prim, &roles, size.grow));
            tools.push(Tool {
                bounds: (lo, hi),
                prim,
                action: op.action,
                op: oi,
            });
        }
        // One error per operation, however many of its instances miss.
        if let Some(first) = missed.first() {
            diags.push(E::MissesPart {
                span: op.span,
                what: op.kind.word().into(),
                name: first.clone(),
                more: match missed.len() {
                    _ if total == 1 => String::new(),
                    1 => format!(" (one of the {total} instances of `{}`)", op.name),
                    n => format!(" ({n} of the {total} instances of `{}` miss it)", op.name),
                },
            });
        }
    }
    tools
}

/// The specs of the faces of instance `inst` of operation `op` (index `oi`), placed as
/// `prim`: one per face with roles, `<op>[<inst>].<role>`, a cut's facing out of the
/// material.
fn instance_specs(
    op: &model::Op,
    (oi, inst): (usize, Option<u32>),
    prim: &Prim,
    roles: &[Vec<Role>],
    grow: f64,
) -> Vec<Spec> {
    let mut specs = Vec::new();
    for (k, rs) in roles.iter().enumerate() {
        if rs.is_empty() {
            continue;
        }
        let (lo, hi) = prim.bounds_of_part(k as u32);
        let mut surface = prim.surfaces[k].clone();
        if op.action == Action::Cut {
            surface = flip(surface);
        }
        let base = inst.map_or(op.name.clone(), |i| format!("{}[{i}]", op.name));
        let role_name = rs[0];
        specs.push(Spec {
            name: format!("{base}.{role_name}"),
            surface,
            source: FaceSource::Op(OpId(oi), inst),
            roles: rs.clone(),
            lo: lo - V3::repeat(grow),
            hi: hi + V3::repeat(grow),
        });
    }
    specs
}

/// The stock with every tool added or cut in order, consecutive disjoint tools of the
/// same kind batched into one boolean. `None`, with a diagnostic, when a boolean fails.
fn apply_tools(
    part: &model::Part,
    stock_prim: &Prim,
    tools: &[Tool],
    diags: &mut Diagnostics,
) -> Option<Manifold> {
    let mut current = to_manifold(&[stock_prim]).ok()?;
    let mut i = 0;
    while i < tools.len() {
        let mut batch = vec![i];
        let mut j = i + 1;
        while j < tools.len()
            && tools[j].action == tools[i].action
            && batch
                .iter()
                .all(|&b| disjoint(tools[b].bounds, tools[j].bounds))
        {
            batch.push(j);
            j += 1;
        }
        let prims: Vec<&Prim> = batch.iter().map(|&b| &tools[b].prim).collect();
        let op = if tools[i].action == Action::Add {
            OpType::Add
        } else {
            OpType::Subtract
        };
        let result = to_manifold(&prims).and_then(|cutter| compute_boolean(&current, &cutter, op));
        match result {
            Ok(m) => current = m,
            Err(reason) => {
                let op = &part.ops[tools[i].op];
                diags.push(E::BooleanFailed {
                    span: op.span,
                    part: part.name.clone(),
                    reason,
                });
                return None;
            }
        }
        i = j;
    }
    Some(current)
}

/// The geometry of the result: its triangles, each on the face of the spec it is
/// classified onto (tolerances scaled by the stock's diagonal `diag`).
fn classified(current: &Manifold, specs: Vec<Spec>, diag: f64) -> PartGeometry {
    let vertices: Vec<P3> = current.ps.iter().map(|p| P3::new(p.x, p.y, p.z)).collect();
    let triangles: Vec<[u32; 3]> = current
        .hs
        .chunks(3)
        .map(|h| [h[0].tail as u32, h[1].tail as u32, h[2].tail as u32])
        .collect();
    let plane_tol = 1e-6 * diag.max(1.0) * 10.0;
    let curved_tol = 1.5 * CHORD_MM + plane_tol;
    let tri_face: Vec<u32> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            let g = P3::from((a.coords + b.coords + c.coords) / 3.0);
            let n = (b - a)
                .cross(&(c - a))
                .try_normalize(0.0)
                .unwrap_or_else(V3::zeros);
            classify(&specs, [a, b, c], g, n, plane_tol, curved_tol) as u32
        })
        .collect();
    let geometry = PartGeometry::new(
        vertices,
        triangles,
        tri_face,
        specs
            .iter()
            .map(|s| (s.name.clone(), s.surface.clone()))
            .collect(),
    );
    let mut geometry = geometry;
    geometry.roles = specs.into_iter().map(|s| (s.source, s.roles)).collect();
    geometry
}

/// The spec a triangle belongs to: every corner on its surface (within the tessellation
/// tolerance for curved surfaces), its normal agreeing with the surface's, its centroid
/// inside the spec's bounds. The best normal agreement wins; ties go to the first spec.
/// A triangle that fits no spec (which the tolerances make rare) goes to the spec that
/// is nearest and best aligned.
fn classify(
    specs: &[Spec],
    corners: [P3; 3],
    g: P3,
    n: V3,
    plane_tol: f64,
    curved_tol: f64,
) -> usize {
    let fit = |s: &Spec| -> Option<(f64, f64)> {
        let sn = s.surface.normal_at(&g)?;
        let dist = corners
            .iter()
            .map(|c| s.surface.distance(c).unwrap_or(f64::INFINITY))
            .fold(0.0, f64::max);
        Some((n.dot(&sn), dist))
    };
    let mut best: Option<(f64, usize)> = None;
    for (k, s) in specs.iter().enumerate() {
        // The bounds test is cheap and rules out almost every spec.
        if !(0..3).all(|i| g[i] >= s.lo[i] && g[i] <= s.hi[i]) {
            continue;
        }
        let Some((agree, dist)) = fit(s) else {
            continue;
        };
        let (tol, min_agree) = if matches!(s.surface, Surface::Plane { .. }) {
            (plane_tol, 0.999)
        } else {
            (curved_tol, 0.7)
        };
        if dist <= tol && agree >= min_agree && best.is_none_or(|(b, _)| agree > b + 1e-9) {
            best = Some((agree, k));
        }
    }
    if let Some((_, k)) = best {
        return k;
    }
    let mut fallback: Option<(f64, usize)> = None;
    for (k, s) in specs.iter().enumerate() {
        if let Some((agree, dist)) = fit(s) {
            if fallback.is_none_or(|(b, _)| dist - agree < b) {
                fallback = Some((dist - agree, k));
            }
        }
    }
    fallback.map_or(0, |(_, k)| k)
}

fn flip(s: Surface) -> Surface {
    match s {
        Surface::Plane { origin, normal } => Surface::Plane {
            origin,
            normal: -normal,
        },
        Surface::Cylinder {
            origin,
            axis,
            radius,
            convex,
        } => Surface::Cylinder {
            origin,
            axis,
            radius,
            convex: !convex,
        },
        Surface::Cone {
            apex,
            axis,
            half_angle,
            convex,
        } => Surface::Cone {
            apex,
            axis,
            half_angle,
            convex: !convex,
        },
        Surface::Sphere {
            center,
            radius,
            convex,
        } => Surface::Sphere {
            center,
            radius,
            convex: !convex,
        },
        Surface::Freeform => Surface::Freeform,
    }
}

fn disjoint((alo, ahi): (P3, P3), (blo, bhi): (P3, P3)) -> bool {
    (0..3).any(|k| ahi[k] + 1e-6 < blo[k] || bhi[k] + 1e-6 < alo[k])
}

fn to_manifold(prims: &[&Prim]) -> Result<Manifold, String> {
    let mut pos = Vec::new();
    let mut idx = Vec::new();
    for p in prims {
        let base = pos.len() / 3;
        for v in &p.verts {
            pos.extend([v.x, v.y, v.z]);
        }
        for t in &p.tris {
            idx.extend(t.iter().map(|&i| base + i as usize));
        }
    }
    Manifold::new(&pos, &idx)
}

fn v3(a: &model::Vec3) -> V3 {
    V3::new(a[0], a[1], a[2])
}

/// Where a ray from the stock's centre along `d` leaves the stock.
fn radial_entry(stock: &Stock, center: P3, d: V3) -> P3 {
    match stock {
        Stock::Sphere { diameter } => P3::origin() + d * (diameter / 2.0),
        Stock::Box { size } => {
            let t = (0..3)
                .filter(|&k| d[k].abs() > 1e-12)
                .map(|k| (size[k] / 2.0) / d[k].abs())
                .fold(f64::INFINITY, f64::min);
            center + d * t
        }
        Stock::Cylinder { diameter, height } => {
            let radial = (d.x * d.x + d.y * d.y).sqrt();
            let t_side = if radial > 1e-12 {
                diameter / 2.0 / radial
            } else {
                f64::INFINITY
            };
            let t_cap = if d.z.abs() > 1e-12 {
                height / 2.0 / d.z.abs()
            } else {
                f64::INFINITY
            };
            center + d * t_side.min(t_cap)
        }
    }
}

/// The primitive an operation adds or removes, and for each primitive part the roles
/// its face answers to (empty: the part lies outside the finished solid).
/// For a hole or a pocket, the point a little past where it enters, along the direction
/// it goes into the part: inside the material when it does. (A slot's or a step's
/// `at` lies on the part's edge, where this test would be unreliable; not checked.)
fn cut_start(op: &model::Op, stock: &Stock, center: P3) -> Option<P3> {
    let (entry, dir, reach) = match &op.kind {
        OpKind::Hole {
            at, axis, depth, ..
        } => {
            let entry = hole_entry(at, stock, center);
            let reach = match depth {
                Depth::Through => f64::INFINITY,
                Depth::Blind(d) => *d,
            };
            (entry, v3(axis), reach)
        }
        OpKind::Pocket {
            at, into, depth, ..
        } => (P3::new(at[0], at[1], at[2]), v3(into), *depth),
        OpKind::Slot { .. } | OpKind::Step { .. } | OpKind::Boss { .. } => return None,
    };
    Some(entry + dir.normalize() * (reach / 2.0).min(0.1))
}

/// Where a hole enters the part: its given point, or where its radial direction meets the
/// stock.
fn hole_entry(at: &Placement, stock: &Stock, center: P3) -> P3 {
    match at {
        Placement::At(p) => P3::new(p[0], p[1], p[2]),
        Placement::Radial(d) => radial_entry(stock, center, v3(d)),
    }
}

fn cutter(
    op: &model::Op,
    stock: &Stock,
    center: P3,
    ext: f64,
    big: f64,
) -> Option<(Prim, Vec<Vec<Role>>)> {
    Some(match &op.kind {
        OpKind::Hole {
            at,
            axis,
            diameter,
            depth,
        } => {
            let f = Frame::along(hole_entry(at, stock, center), v3(axis));
            let (z1, bottom) = match depth {
                Depth::Through => (big, vec![]),
                Depth::Blind(d) => (*d, vec![Role::Bottom]),
            };
            (
                prism(&f, &circle(diameter / 2.0), -ext, z1),
                vec![vec![Role::Wall], vec![], bottom],
            )
        }
        OpKind::Slot {
            at,
            along,
            into,
            width,
            depth,
            length,
        } => {
            let f = Frame::from_uw(P3::new(at[0], at[1], at[2]), v3(along), v3(into));
            let (x0, x1, ends) = match length {
                Some(l) => (0.0, *l, vec![Role::Ends]),
                None => (-big, big, vec![]),
            };
            let prof = rectangle(x0, -width / 2.0, x1, width / 2.0);
            (
                prism(&f, &prof, -ext, *depth),
                vec![
                    vec![Role::LeftWall, Role::Walls],
                    ends.clone(),
                    vec![Role::RightWall, Role::Walls],
                    ends,
                    vec![],
                    vec![Role::Floor],
                ],
            )
        }
        OpKind::Pocket {
            at,
            along,
            into,
            size,
            depth,
            corner_radius,
        } => {
            let f = Frame::from_uw(P3::new(at[0], at[1], at[2]), v3(along), v3(into));
            let prof = rounded_rectangle(size[0], size[1], *corner_radius);
            let mut roles = vec![vec![Role::Walls]; prof.len()];
            roles.push(vec![]);
            roles.push(vec![Role::Floor]);
            (prism(&f, &prof, -ext, *depth), roles)
        }
        OpKind::Step {
            at,
            along,
            into,
            width,
            depth,
        } => {
            let a = P3::new(at[0], at[1], at[2]);
            let mut f = Frame::from_uw(a, v3(along), v3(into));
            if (center - a).dot(&f.v) < 0.0 {
                f = Frame::from_uw(a, -v3(along), v3(into));
            }
            let prof = rectangle(-big, -big, big, *width);
            (
                prism(&f, &prof, -ext, *depth),
                vec![
                    vec![],
                    vec![],
                    vec![Role::Wall],
                    vec![],
                    vec![],
                    vec![Role::Floor],
                ],
            )
        }
        OpKind::Boss {
            at,
            axis,
            diameter,
            height,
        } => {
            let f = Frame::along(P3::new(at[0], at[1], at[2]), v3(axis));
            (
                prism(&f, &circle(diameter / 2.0), -ext, *height),
                vec![vec![Role::Wall], vec![], vec![Role::Top]],
            )
        }
    })
}

/// The rigid motion of each pattern instance.
fn pattern(p: &Pattern) -> Vec<Isometry3<f64>> {
    match p {
        Pattern::Linear { count, step } => (0..*count)
            .map(|k| {
                Isometry3::from_parts(
                    Translation3::from(v3(step) * k as f64),
                    UnitQuaternion::identity(),
                )
            })
            .collect(),
        Pattern::Grid { nx, ny, pitch } => (0..*ny)
            .flat_map(|j| {
                (0..*nx).map(move |i| {
                    Isometry3::from_parts(
                        Translation3::new(i as f64 * pitch[0], j as f64 * pitch[1], 0.0),
                        UnitQuaternion::identity(),
                    )
                })
            })
            .collect(),
        Pattern::Polar {
            count,
            axis,
            center,
        } => {
            let c = v3(center);
            let ax = Unit::new_normalize(v3(axis));
            (0..*count)
                .map(|k| {
                    let r = UnitQuaternion::from_axis_angle(
                        &ax,
                        std::f64::consts::TAU * k as f64 / *count as f64,
                    );
                    // Rotate about the axis through `center`: x ↦ c + R (x − c).
                    Isometry3::from_parts(Translation3::from(c - r * c), r)
                })
                .collect()
        }
    }
}
