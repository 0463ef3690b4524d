//! From a Part 21 instance table to a boundary representation: the faces of the file's
//! solids (and sheet bodies) in shell order, each with its exact surface, sense and
//! bounds; edges with their curves; lengths in millimetres and angles in radians
//! through the units of the representation that holds the solid.
//!
//! References whose depth the file decides (a shell wrapping a shell, a curve wrapping
//! a curve) are followed through `refs::Trail` (circles are `step_cycle` errors);
//! curves and surfaces are read once each and shared by every edge and face on them,
//! and a face a shell lists twice is one face, so that the B-rep grows with the file,
//! not with how often the file names an instance.

use super::canon::{canonical, revolution_axis};
use super::curve::{BSplineCurve, Curve, Frame, Knots};
use super::geom::{BSplineSurface, Offset, Surf};
use super::p21::{Instance, Param, Record, P21};
use super::refs::{Memo, Trail};
use super::swept::{Extrusion, Revolution};
use super::StepError;
use crate::geometry::{P3, V3};
use std::collections::{HashMap, HashSet};
use std::sync::Arc;

/// An edge: its end vertices, its curve, and whether it runs along the curve's sense.
#[derive(Debug, Clone)]
pub struct Edge {
    /// The `EDGE_CURVE`'s instance number.
    pub id: u64,
    /// Start vertex (mm).
    pub start: P3,
    /// End vertex (mm).
    pub end: P3,
    /// The curve.
    pub curve: Curve,
    /// Whether the edge runs in the curve's parameter sense.
    pub same_sense: bool,
}

/// A face bound: a loop of edges, each used forward or backward, or a single vertex
/// (a cone's apex, a sphere's pole).
#[derive(Debug, Clone)]
pub(crate) enum Bound {
    /// Edges (index into [`Brep::edges`], forward?).
    Edges(Vec<(usize, bool)>),
    /// A vertex loop.
    Vertex,
}

impl Bound {
    /// Its edges (none for a vertex loop).
    pub(crate) fn edges(&self) -> &[(usize, bool)] {
        match self {
            Bound::Edges(list) => list,
            Bound::Vertex => &[],
        }
    }
}

/// A face.
#[derive(Debug, Clone)]
pub struct Face {
    /// The `ADVANCED_FACE`'s instance number.
    pub id: u64,
    /// Its surface.
    pub surface: Surf,
    /// Whether the face's outward normal is the surface's natural normal.
    pub same_sense: bool,
    /// Its bounds.
    pub bounds: Vec<Bound>,
}

/// A file's B-rep.
#[derive(Debug, Clone)]
pub(crate) struct Brep {
    /// Faces in shell order: solids first, then sheet bodies, in file order.
    pub faces: Vec<Face>,
    /// Edges.
    pub edges: Vec<Edge>,
    /// Millimetres per file length unit.
    pub unit_mm: f64,
    /// The file's length unit, as named (`mm`, `inch`).
    pub unit_name: String,
    /// How many of the faces belong to sheet (open-shell) bodies.
    pub sheet_faces: usize,
}

/// The reader of one file's B-rep (its curves made of curves are `compound.rs`'s).
pub(super) struct Reader<'a> {
    pub(super) f: &'a P21,
    /// Millimetres per file length unit.
    pub(super) unit: f64,
    /// Radians per file plane angle unit.
    pub(super) angle: f64,
    edges: Vec<Edge>,
    edge_index: HashMap<u64, usize>,
    /// Faces already read: a shell listing one again adds nothing.
    seen_faces: HashSet<u64>,
    pub(super) trail: Trail,
    curves: Memo<Curve>,
    surfaces: Memo<Surf>,
}

/// Reads the B-rep of a parsed file.
pub fn read(f: &P21) -> Result<Brep, StepError> {
    let mut solids = Vec::new();
    let mut sheets = Vec::new();
    for id in &f.order {
        let inst = &f.instances[id];
        if inst.is("MANIFOLD_SOLID_BREP") || inst.is("BREP_WITH_VOIDS") {
            solids.push(*id);
        } else if inst.is("SHELL_BASED_SURFACE_MODEL") {
            sheets.push(*id);
        }
    }
    let Some(&first) = solids.first().or(sheets.first()) else {
        return Err(StepError::NoSolid);
    };
    // An assembly places its parts' solids by transforms its B-reps do not carry:
    // read as they stand, they would overlap (AP203/AP214 product structure).
    let occurrences = f
        .order
        .iter()
        .filter(|id| f.instances[id].is("NEXT_ASSEMBLY_USAGE_OCCURRENCE"))
        .count();
    if occurrences > 0 && solids.len() > 1 {
        return Err(StepError::Assembly {
            occurrences,
            solids: solids.len(),
        });
    }
    let (unit, unit_name, angle) = units(f, first)?;
    let mut r = Reader {
        f,
        unit,
        angle,
        edges: Vec::new(),
        edge_index: HashMap::new(),
        seen_faces: HashSet::new(),
        trail: Trail::default(),
        curves: Memo::default(),
        surfaces: Memo::default(),
    };
    let mut faces = Vec::new();
    for &s in &solids {
        let inst = r.inst(s, None)?;
        let rec = &inst.records[0];
        let mut shells = vec![r.reference(s, rec, 1)?];
        if rec.name == "BREP_WITH_VOIDS" {
            for v in r.list(s, rec, 2)? {
                shells.push(r.ref_of(s, v)?);
            }
        }
        for sh in shells {
            r.shell(sh, s, &mut faces)?;
        }
    }
    let solid_faces = faces.len();
    for &s in &sheets {
        let rec = &r.inst(s, None)?.records[0];
        for sh in r.list(s, rec, 1)? {
            let sh = r.ref_of(s, sh)?;
            r.shell(sh, s, &mut faces)?;
        }
    }
    Ok(Brep {
        sheet_faces: faces.len() - solid_faces,
        faces,
        edges: r.edges,
        unit_mm: unit,
        unit_name,
    })
}

/// The length unit (mm per unit, name) and the plane angle unit (radians per unit) of
/// the representation that holds `item`.
fn units(f: &P21, item: u64) -> Result<(f64, String, f64), StepError> {
    let holds = |inst: &Instance| {
        inst.records.iter().any(|r| {
            r.params.len() == 3
                && r.params[1]
                    .list()
                    .is_some_and(|l| l.iter().any(|p| p.reference() == Some(item)))
        })
    };
    let rep = f
        .order
        .iter()
        .map(|id| &f.instances[id])
        .find(|i| holds(i))
        .ok_or(StepError::Unit(
            "no shape representation holds the solid, so its units are unknown".into(),
        ))?;
    let ctx = rep
        .records
        .iter()
        .find_map(|r| r.params.get(2).and_then(Param::reference))
        .and_then(|c| f.instances.get(&c))
        .and_then(|c| c.record("GLOBAL_UNIT_ASSIGNED_CONTEXT"))
        .and_then(|r| r.params.first().and_then(Param::list))
        .ok_or(StepError::Unit(
            "the solid's representation context assigns no units".into(),
        ))?;
    let mut length = None;
    let mut angle = 1.0;
    for u in ctx.iter().filter_map(Param::reference) {
        let Some(inst) = f.instances.get(&u) else {
            return Err(StepError::Missing { id: u, from: None });
        };
        if inst.is("LENGTH_UNIT") {
            length = Some(unit_factor(f, inst, "METRE", 1000.0, 0)?);
        } else if inst.is("PLANE_ANGLE_UNIT") {
            angle = unit_factor(f, inst, "RADIAN", 1.0, 0)?.0;
        }
    }
    let (mm, name) = length.ok_or(StepError::Unit(
        "the solid's representation context has no length unit".into(),
    ))?;
    // The same unit reads the same however the file spells it.
    let name = match mm {
        x if (x - 1.0).abs() < 1e-9 => "mm".to_string(),
        x if (x - 25.4).abs() < 1e-9 => "inch".to_string(),
        _ => name,
    };
    Ok((mm, name, angle))
}

/// The size of a unit in `base` units scaled by `base_scale` (mm for `METRE`), and its
/// name: an SI unit with its prefix, or a conversion-based unit (an inch as 25.4 mm).
pub(super) fn unit_factor(
    f: &P21,
    inst: &Instance,
    base: &str,
    base_scale: f64,
    depth: usize,
) -> Result<(f64, String), StepError> {
    if depth > 8 {
        return Err(StepError::Unit(
            "the unit definitions refer to each other".into(),
        ));
    }
    if let Some(si) = inst.record("SI_UNIT") {
        let prefix = si.params.first().and_then(Param::enumeration);
        let name = si.params.get(1).and_then(Param::enumeration).unwrap_or("");
        if name != base {
            return Err(StepError::Unit(format!(
                "unit {} where {} was expected",
                name.to_lowercase(),
                base.to_lowercase()
            )));
        }
        let scale = match prefix {
            None => 1.0,
            Some("KILO") => 1e3,
            Some("HECTO") => 1e2,
            Some("DECA") => 1e1,
            Some("DECI") => 1e-1,
            Some("CENTI") => 1e-2,
            Some("MILLI") => 1e-3,
            Some("MICRO") => 1e-6,
            Some("NANO") => 1e-9,
            Some(p) => {
                return Err(StepError::Unit(format!(
                    "the SI prefix {} is not one inspc knows",
                    p.to_lowercase()
                )))
            }
        };
        let shown = match (prefix, base) {
            (Some("MILLI"), "METRE") => "mm".to_string(),
            (None, "RADIAN") => "rad".to_string(),
            (p, b) => format!("{}{}", p.unwrap_or("").to_lowercase(), b.to_lowercase()),
        };
        return Ok((scale * base_scale, shown));
    }
    if let Some(cb) = inst.record("CONVERSION_BASED_UNIT") {
        let name = cb.params.first().and_then(Param::string).unwrap_or("?");
        let measure = cb
            .params
            .get(1)
            .and_then(Param::reference)
            .and_then(|m| f.instances.get(&m))
            .ok_or(StepError::Unit(format!(
                "the conversion of unit `{name}` is missing"
            )))?;
        let mwu = measure
            .records
            .iter()
            .find(|r| r.params.len() >= 2 && r.params[0].real().is_some())
            .ok_or(StepError::Unit(format!(
                "the conversion of unit `{name}` has no value"
            )))?;
        let value = mwu.params[0].real().unwrap_or(1.0);
        let of = mwu
            .params
            .get(1)
            .and_then(Param::reference)
            .and_then(|u| f.instances.get(&u))
            .ok_or(StepError::Unit(format!(
                "the conversion of unit `{name}` names no unit"
            )))?;
        let (k, _) = unit_factor(f, of, base, base_scale, depth + 1)?;
        if !(value.is_finite() && value > 0.0) {
            return Err(StepError::Unit(format!(
                "unit `{name}` converts by {value}"
            )));
        }
        return Ok((value * k, name.to_lowercase()));
    }
    Err(StepError::Unit(format!(
        "the unit {} is neither an SI unit nor conversion-based",
        inst.type_name().to_lowercase()
    )))
}

impl<'a> Reader<'a> {
    pub(super) fn inst(&self, id: u64, from: Option<u64>) -> Result<&'a Instance, StepError> {
        self.f
            .instances
            .get(&id)
            .ok_or(StepError::Missing { id, from })
    }

    pub(super) fn bad(&self, id: u64, message: impl Into<String>) -> StepError {
        StepError::Malformed {
            id,
            line: self.f.instances.get(&id).map_or(0, |i| i.line),
            message: message.into(),
        }
    }

    pub(super) fn param<'r>(
        &self,
        id: u64,
        rec: &'r Record,
        i: usize,
    ) -> Result<&'r Param, StepError> {
        rec.params
            .get(i)
            .ok_or_else(|| self.bad(id, format!("{} has too few parameters", rec.name)))
    }

    pub(super) fn reference(&self, id: u64, rec: &Record, i: usize) -> Result<u64, StepError> {
        let p = self.param(id, rec, i)?;
        self.ref_of(id, p)
    }

    pub(super) fn ref_of(&self, id: u64, p: &Param) -> Result<u64, StepError> {
        p.reference()
            .ok_or_else(|| self.bad(id, "a reference `#n` was expected"))
    }

    pub(super) fn list<'r>(
        &self,
        id: u64,
        rec: &'r Record,
        i: usize,
    ) -> Result<&'r [Param], StepError> {
        self.param(id, rec, i)?
            .list()
            .ok_or_else(|| self.bad(id, format!("{}: a list was expected", rec.name)))
    }

    pub(super) fn real(&self, id: u64, rec: &Record, i: usize) -> Result<f64, StepError> {
        self.param(id, rec, i)?
            .real()
            .ok_or_else(|| self.bad(id, format!("{}: a number was expected", rec.name)))
    }

    pub(super) fn boolean(&self, id: u64, rec: &Record, i: usize) -> Result<bool, StepError> {
        self.param(id, rec, i)?
            .boolean()
            .ok_or_else(|| self.bad(id, format!("{}: .T. or .F. was expected", rec.name)))
    }

    /// The record named `name` of instance `id`.
    pub(super) fn rec(&self, id: u64, from: u64, name: &str) -> Result<&'a Record, StepError> {
        let inst = self.inst(id, Some(from))?;
        inst.record(name).ok_or_else(|| {
            self.bad(
                id,
                format!("{} where {name} was expected", inst.type_name()),
            )
        })
    }

    fn triple(&self, id: u64, rec: &Record) -> Result<[f64; 3], StepError> {
        let l = self.list(id, rec, 1)?;
        let c: Vec<f64> = l.iter().filter_map(Param::real).collect();
        match c.len() {
            3 => Ok([c[0], c[1], c[2]]),
            2 => Ok([c[0], c[1], 0.0]),
            _ => Err(self.bad(id, "a point or direction needs three coordinates")),
        }
    }

    pub(super) fn point(&self, id: u64, from: u64) -> Result<P3, StepError> {
        let rec = self.rec(id, from, "CARTESIAN_POINT")?;
        let [x, y, z] = self.triple(id, rec)?;
        Ok(P3::new(x, y, z) * self.unit)
    }

    pub(super) fn direction(&self, id: u64, from: u64) -> Result<V3, StepError> {
        let rec = self.rec(id, from, "DIRECTION")?;
        let [x, y, z] = self.triple(id, rec)?;
        Ok(V3::new(x, y, z))
    }

    /// A `VECTOR`: its direction times its magnitude (a length).
    fn vector(&self, id: u64, from: u64) -> Result<V3, StepError> {
        let rec = self.rec(id, from, "VECTOR")?;
        let d = self
            .direction(self.reference(id, rec, 1)?, id)?
            .try_normalize(1e-300)
            .ok_or_else(|| self.bad(id, "a vector's direction is zero"))?;
        Ok(d * self.length(id, rec, 2)?)
    }

    /// An `AXIS1_PLACEMENT`: a point and its axis (z when left out).
    fn axis1(&self, id: u64, from: u64) -> Result<(P3, V3), StepError> {
        let rec = self.rec(id, from, "AXIS1_PLACEMENT")?;
        let o = self.point(self.reference(id, rec, 1)?, id)?;
        let z = match self.param(id, rec, 2)? {
            Param::Ref(d) => self.direction(*d, id)?,
            _ => V3::z(),
        };
        Ok((o, z))
    }

    fn frame(&self, id: u64, from: u64) -> Result<Frame, StepError> {
        let rec = self.rec(id, from, "AXIS2_PLACEMENT_3D")?;
        let o = self.point(self.reference(id, rec, 1)?, id)?;
        let opt = |i: usize| -> Result<Option<V3>, StepError> {
            match self.param(id, rec, i)? {
                Param::Ref(d) => self.direction(*d, id).map(Some),
                _ => Ok(None),
            }
        };
        Frame::new(o, opt(2)?, opt(3)?).ok_or_else(|| {
            self.bad(
                id,
                "the placement's axis is zero or parallel to its reference",
            )
        })
    }

    pub(super) fn length(&self, id: u64, rec: &Record, i: usize) -> Result<f64, StepError> {
        let x = self.real(id, rec, i)? * self.unit;
        if !x.is_finite() || x < 0.0 {
            return Err(self.bad(id, format!("{}: a length cannot be {x}", rec.name)));
        }
        Ok(x)
    }

    fn shell(&mut self, sh: u64, from: u64, faces: &mut Vec<Face>) -> Result<(), StepError> {
        let inst = self.inst(sh, Some(from))?;
        // An ORIENTED_CLOSED_SHELL wraps its shell in the third parameter.
        let rec = &inst.records[0];
        if rec.name == "ORIENTED_CLOSED_SHELL" || rec.name == "ORIENTED_OPEN_SHELL" {
            let inner = self.reference(sh, rec, 2)?;
            self.trail.enter(sh, inst.line)?;
            let out = self.shell(inner, sh, faces);
            self.trail.leave();
            return out;
        }
        for fp in self.list(sh, rec, 1)? {
            let fid = self.ref_of(sh, fp)?;
            if self.seen_faces.insert(fid) {
                faces.push(self.face(fid, sh)?);
            }
        }
        Ok(())
    }

    fn face(&mut self, id: u64, from: u64) -> Result<Face, StepError> {
        let inst = self.inst(id, Some(from))?;
        let rec = inst
            .record("ADVANCED_FACE")
            .or(inst.record("FACE_SURFACE"))
            .ok_or_else(|| {
                self.bad(
                    id,
                    format!("{} where a face was expected", inst.type_name()),
                )
            })?;
        let surface = self.surface(self.reference(id, rec, 2)?, id)?;
        let same_sense = self.boolean(id, rec, 3)?;
        let mut bounds = Vec::new();
        for b in self.list(id, rec, 1)? {
            let bid = self.ref_of(id, b)?;
            let brec = self.inst(bid, Some(id))?;
            let brec = brec
                .record("FACE_OUTER_BOUND")
                .or(brec.record("FACE_BOUND"))
                .ok_or_else(|| self.bad(bid, "a face bound was expected"))?;
            let lid = self.reference(bid, brec, 1)?;
            let orientation = self.boolean(bid, brec, 2)?;
            bounds.push(self.bound(lid, bid, orientation)?);
        }
        let (surface, flip) = canonical(&surface, &self.bound_points(&bounds));
        Ok(Face {
            id,
            surface,
            same_sense: same_sense != flip,
            bounds,
        })
    }

    /// The vertices of a face's bounds, where its sense can be compared.
    fn bound_points(&self, bounds: &[Bound]) -> Vec<P3> {
        bounds
            .iter()
            .flat_map(Bound::edges)
            .flat_map(|(e, _)| [self.edges[*e].start, self.edges[*e].end])
            .collect()
    }

    fn bound(&mut self, lid: u64, from: u64, orientation: bool) -> Result<Bound, StepError> {
        let inst = self.inst(lid, Some(from))?;
        if let Some(v) = inst.record("VERTEX_LOOP") {
            self.vertex(self.reference(lid, v, 1)?, lid)?;
            return Ok(Bound::Vertex);
        }
        let rec = inst.record("EDGE_LOOP").ok_or_else(|| {
            self.bad(
                lid,
                format!("{} is not a loop inspc reads", inst.type_name()),
            )
        })?;
        let mut edges = Vec::new();
        for oe in self.list(lid, rec, 1)? {
            let oid = self.ref_of(lid, oe)?;
            let orec = self.rec(oid, lid, "ORIENTED_EDGE")?;
            let eid = self.reference(oid, orec, 3)?;
            let forward = self.boolean(oid, orec, 4)?;
            let e = self.edge(eid, oid)?;
            edges.push((e, forward));
        }
        if !orientation {
            edges.reverse();
            for e in &mut edges {
                e.1 = !e.1;
            }
        }
        Ok(Bound::Edges(edges))
    }

    fn vertex(&self, id: u64, from: u64) -> Result<P3, StepError> {
        let rec = self.rec(id, from, "VERTEX_POINT")?;
        self.point(self.reference(id, rec, 1)?, id)
    }

    fn edge(&mut self, id: u64, from: u64) -> Result<usize, StepError> {
        if let Some(&i) = self.edge_index.get(&id) {
            return Ok(i);
        }
        let rec = self.rec(id, from, "EDGE_CURVE")?;
        let start = self.vertex(self.reference(id, rec, 1)?, id)?;
        let end = self.vertex(self.reference(id, rec, 2)?, id)?;
        let curve = self.curve(self.reference(id, rec, 3)?, id)?;
        let same_sense = self.boolean(id, rec, 4)?;
        self.edges.push(Edge {
            id,
            start,
            end,
            curve,
            same_sense,
        });
        self.edge_index.insert(id, self.edges.len() - 1);
        Ok(self.edges.len() - 1)
    }

    /// The curve `id`, read once ([`Reader::read_curve`]).
    pub(super) fn curve(&self, id: u64, from: u64) -> Result<Curve, StepError> {
        self.curves.get_or(id, || self.read_curve(id, from))
    }

    fn read_curve(&self, id: u64, from: u64) -> Result<Curve, StepError> {
        let inst = self.inst(id, Some(from))?;
        if let Some(r) = inst.record("LINE") {
            let o = self.point(self.reference(id, r, 1)?, id)?;
            return Ok(Curve::Line(o, self.vector(self.reference(id, r, 2)?, id)?));
        }
        if let Some(r) = inst.record("CIRCLE") {
            let f = self.frame(self.reference(id, r, 1)?, id)?;
            return Ok(Curve::Circle(f, self.length(id, r, 2)?));
        }
        if let Some(r) = inst.record("ELLIPSE") {
            let f = self.frame(self.reference(id, r, 1)?, id)?;
            return Ok(Curve::Ellipse(
                f,
                self.length(id, r, 2)?,
                self.length(id, r, 3)?,
            ));
        }
        if let Some(r) = inst.record("PARABOLA") {
            let f = self.frame(self.reference(id, r, 1)?, id)?;
            return Ok(Curve::Parabola(f, self.length(id, r, 2)?));
        }
        if let Some(r) = inst.record("HYPERBOLA") {
            let f = self.frame(self.reference(id, r, 1)?, id)?;
            return Ok(Curve::Hyperbola(
                f,
                self.length(id, r, 2)?,
                self.length(id, r, 3)?,
            ));
        }
        if [
            "B_SPLINE_CURVE_WITH_KNOTS",
            "UNIFORM_CURVE",
            "QUASI_UNIFORM_CURVE",
            "BEZIER_CURVE",
        ]
        .iter()
        .any(|k| inst.is(k))
        {
            return self
                .bspline_curve(id, inst)
                .map(|c| Curve::BSpline(Arc::new(c)));
        }
        if let Some(c) = self.compound(id, inst) {
            return c;
        }
        for wrapper in [
            "TRIMMED_CURVE",
            "SURFACE_CURVE",
            "SEAM_CURVE",
            "INTERSECTION_CURVE",
        ] {
            if let Some(r) = inst.record(wrapper) {
                let inner = self.reference(id, r, 1)?;
                return self.trail.follow(id, inst.line, || self.curve(inner, id));
            }
        }
        if let Some(r) = inst.record("POLYLINE") {
            let pts = self
                .list(id, r, 1)?
                .iter()
                .map(|p| self.point(self.ref_of(id, p)?, id))
                .collect::<Result<Vec<_>, _>>()?;
            return Ok(Curve::Polyline(pts.into()));
        }
        Err(StepError::Unsupported {
            id,
            line: inst.line,
            what: format!("curve {}", inst.type_name()),
        })
    }

    /// The curve a surface sweeps: any curve inspc evaluates but a polyline, whose
    /// sweep has no exact inverse here.
    fn swept_curve(&self, id: u64, line: usize, curve: u64) -> Result<Curve, StepError> {
        let c = self.trail.follow(id, line, || self.curve(curve, id))?;
        if matches!(c, Curve::Polyline(_)) {
            return Err(StepError::Unsupported {
                id,
                line,
                what: "surface swept from a polyline".into(),
            });
        }
        Ok(c)
    }

    fn points(&self, id: u64, l: &[Param]) -> Result<Vec<P3>, StepError> {
        l.iter()
            .map(|p| self.point(self.ref_of(id, p)?, id))
            .collect()
    }

    fn ints(&self, id: u64, p: &Param) -> Result<Vec<i64>, StepError> {
        let l = p
            .list()
            .ok_or_else(|| self.bad(id, "a list of multiplicities was expected"))?;
        l.iter()
            .map(|x| match x {
                Param::Int(i) => Ok(*i),
                _ => Err(self.bad(id, "a multiplicity must be an integer")),
            })
            .collect()
    }

    fn reals(&self, id: u64, p: &Param) -> Result<Vec<f64>, StepError> {
        let l = p
            .list()
            .ok_or_else(|| self.bad(id, "a list of numbers was expected"))?;
        l.iter()
            .map(|x| {
                x.real()
                    .ok_or_else(|| self.bad(id, "a number was expected"))
            })
            .collect()
    }

    /// A B-spline's own parameters (degree, control points, form, closure; `head` of
    /// them) and its knot parameters (`tail`): in the simple form both follow the name in
    /// `…_WITH_KNOTS`; in the complex form `base` holds the first, `…_WITH_KNOTS` the
    /// second.
    fn bspline_parts<'r>(
        &self,
        id: u64,
        inst: &'r Instance,
        base: &str,
        head: usize,
        tail: usize,
    ) -> Result<(&'r [Param], &'r [Param]), StepError> {
        let with_knots = format!("{base}_WITH_KNOTS");
        let too_few = || self.bad(id, format!("{with_knots} has too few parameters"));
        let wk = inst.record(&with_knots).ok_or_else(too_few)?;
        let (h, k): (&[Param], &[Param]) = match inst.record(base) {
            Some(b) => (&b.params, &wk.params),
            None if wk.params.len() > head => (&wk.params[1..=head], &wk.params[head + 1..]),
            None => return Err(too_few()),
        };
        // The knot parameters end in the knot type, which is not read.
        if h.len() < head || k.len() + 1 < tail {
            return Err(too_few());
        }
        Ok((h, k))
    }

    fn degree(&self, id: u64, p: &Param) -> Result<usize, StepError> {
        match p {
            Param::Int(d) if *d >= 1 => Ok(*d as usize),
            _ => Err(self.bad(id, "a B-spline degree must be a positive integer")),
        }
    }

    /// The knots of a B-spline whose subtype implies them (ISO 10303-42 § 4.4:
    /// `uniform_curve`, `quasi_uniform_curve`, `bezier_curve` and their surface
    /// forms), for `n` control points of this degree along one direction: the
    /// multiplicities and the distinct values. `None` for `…_WITH_KNOTS`.
    fn implied_knots(
        inst: &Instance,
        form: &str,
        degree: usize,
        n: usize,
    ) -> Option<(Vec<i64>, Vec<f64>)> {
        let d = degree as i64;
        let k = n as i64 - 1;
        if inst.is(&format!("UNIFORM_{form}")) {
            // Single knots −d, −d+1, …, k+1.
            let values: Vec<f64> = (-d..=k + 1).map(|v| v as f64).collect();
            Some((vec![1; values.len()], values))
        } else if inst.is(&format!("QUASI_UNIFORM_{form}")) {
            // 0, 1, …, k−d+1, the ends d+1 times.
            let last = (k - d + 1).max(1);
            let values: Vec<f64> = (0..=last).map(|v| v as f64).collect();
            let mut mults = vec![1; values.len()];
            mults[0] = d + 1;
            *mults.last_mut()? = d + 1;
            Some((mults, values))
        } else if inst.is(&format!("BEZIER_{form}")) {
            // Piecewise Bézier: 0, 1, …, k/d, the ends d+1 times, the rest d times.
            let last = (k / d).max(1);
            let values: Vec<f64> = (0..=last).map(|v| v as f64).collect();
            let mut mults = vec![d; values.len()];
            mults[0] = d + 1;
            *mults.last_mut()? = d + 1;
            Some((mults, values))
        } else {
            None
        }
    }

    /// A B-spline's degree-and-points parameters and its knot parameters (`None` when
    /// its subtype implies the knots).
    fn bspline_head<'r>(
        &self,
        id: u64,
        inst: &'r Instance,
        base: &str,
        form: &str,
        head: usize,
        tail: usize,
    ) -> Result<(&'r [Param], Option<&'r [Param]>), StepError> {
        if inst.is(&format!("{base}_WITH_KNOTS")) {
            let (h, k) = self.bspline_parts(id, inst, base, head, tail)?;
            return Ok((h, Some(k)));
        }
        let too_few = || self.bad(id, format!("{base} has too few parameters"));
        let h: &[Param] = match inst.record(base) {
            Some(b) => &b.params,
            None => {
                let r = ["UNIFORM_", "QUASI_UNIFORM_", "BEZIER_"]
                    .iter()
                    .find_map(|p| inst.record(&format!("{p}{form}")))
                    .ok_or_else(too_few)?;
                r.params.get(1..).ok_or_else(too_few)?
            }
        };
        if h.len() < head {
            return Err(too_few());
        }
        Ok((h, None))
    }

    fn bspline_curve(&self, id: u64, inst: &Instance) -> Result<BSplineCurve, StepError> {
        let (head, knots) = self.bspline_head(id, inst, "B_SPLINE_CURVE", "CURVE", 5, 3)?;
        let degree = self.degree(id, &head[0])?;
        let points = self.points(
            id,
            head[1]
                .list()
                .ok_or_else(|| self.bad(id, "control points expected"))?,
        )?;
        let (mults, values) = match knots {
            Some(k) => (self.ints(id, &k[0])?, self.reals(id, &k[1])?),
            None => Self::implied_knots(inst, "CURVE", degree, points.len())
                .ok_or_else(|| self.bad(id, "the B-spline's knots are not given"))?,
        };
        let knots = Knots::new(degree, &mults, &values, points.len())
            .ok_or_else(|| self.bad(id, "the knots do not fit the control points and degree"))?;
        let weights = match inst.record("RATIONAL_B_SPLINE_CURVE") {
            Some(r) => self.reals(id, self.param(id, r, 0)?)?,
            None => vec![1.0; points.len()],
        };
        if weights.len() != points.len() || weights.iter().any(|w| !w.is_finite() || *w <= 0.0) {
            return Err(self.bad(
                id,
                "a rational B-spline needs one positive weight per point",
            ));
        }
        Ok(BSplineCurve {
            knots,
            points,
            weights,
        })
    }

    /// The surface `id`, read once ([`Reader::read_surface`]).
    fn surface(&self, id: u64, from: u64) -> Result<Surf, StepError> {
        self.surfaces.get_or(id, || self.read_surface(id, from))
    }

    fn read_surface(&self, id: u64, from: u64) -> Result<Surf, StepError> {
        let inst = self.inst(id, Some(from))?;
        let frame = |r: &Record| self.frame(self.reference(id, r, 1)?, id);
        if let Some(r) = inst.record("PLANE") {
            return Ok(Surf::Plane(frame(r)?));
        }
        if let Some(r) = inst.record("CYLINDRICAL_SURFACE") {
            return Ok(Surf::Cylinder(frame(r)?, self.length(id, r, 2)?));
        }
        if let Some(r) = inst.record("CONICAL_SURFACE") {
            let a = self.real(id, r, 3)? * self.angle;
            if !(a > 0.0 && a < std::f64::consts::FRAC_PI_2) {
                return Err(self.bad(id, format!("a cone's semi-angle cannot be {a} rad")));
            }
            return Ok(Surf::Cone(frame(r)?, self.length(id, r, 2)?, a));
        }
        if let Some(r) = inst.record("SPHERICAL_SURFACE") {
            return Ok(Surf::Sphere(frame(r)?, self.length(id, r, 2)?));
        }
        if let Some(r) = inst
            .record("TOROIDAL_SURFACE")
            .or(inst.record("DEGENERATE_TOROIDAL_SURFACE"))
        {
            return Ok(Surf::Torus(
                frame(r)?,
                self.length(id, r, 2)?,
                self.length(id, r, 3)?,
            ));
        }
        if [
            "B_SPLINE_SURFACE_WITH_KNOTS",
            "UNIFORM_SURFACE",
            "QUASI_UNIFORM_SURFACE",
            "BEZIER_SURFACE",
        ]
        .iter()
        .any(|k| inst.is(k))
        {
            return self
                .bspline_surface(id, inst)
                .map(|s| Surf::BSpline(Arc::new(s)));
        }
        if let Some(r) = inst.record("SURFACE_OF_LINEAR_EXTRUSION") {
            let curve = self.swept_curve(id, inst.line, self.reference(id, r, 1)?)?;
            let dir = self
                .vector(self.reference(id, r, 2)?, id)?
                .try_normalize(1e-300)
                .ok_or_else(|| self.bad(id, "the extrusion's vector is zero"))?;
            return Ok(Surf::Extrusion(Arc::new(Extrusion { curve, dir })));
        }
        if let Some(r) = inst.record("SURFACE_OF_REVOLUTION") {
            let curve = self.swept_curve(id, inst.line, self.reference(id, r, 1)?)?;
            let (o, z) = self.axis1(self.reference(id, r, 2)?, id)?;
            let axis = revolution_axis(o, z, &curve).ok_or_else(|| {
                self.bad(
                    id,
                    "the revolved curve lies on its axis, or the axis is zero",
                )
            })?;
            return Ok(Surf::Revolution(Arc::new(Revolution { curve, axis })));
        }
        if let Some(r) = inst.record("OFFSET_SURFACE") {
            let inner = self.reference(id, r, 1)?;
            let base = self
                .trail
                .follow(id, inst.line, || self.surface(inner, id))?;
            let distance = self.real(id, r, 2)? * self.unit;
            if !distance.is_finite() {
                return Err(self.bad(id, format!("an offset cannot be {distance} mm")));
            }
            return Ok(Surf::Offset(Arc::new(Offset { base, distance })));
        }
        if let Some(r) = inst.record("RECTANGULAR_TRIMMED_SURFACE") {
            // The face's bounds trim it: the basis surface is the geometry.
            let inner = self.reference(id, r, 1)?;
            return self.trail.follow(id, inst.line, || self.surface(inner, id));
        }
        Err(StepError::Unsupported {
            id,
            line: inst.line,
            what: format!("surface {}", inst.type_name()),
        })
    }

    fn bspline_surface(&self, id: u64, inst: &Instance) -> Result<BSplineSurface, StepError> {
        let (head, knots) = self.bspline_head(id, inst, "B_SPLINE_SURFACE", "SURFACE", 7, 5)?;
        let (du, dv) = (self.degree(id, &head[0])?, self.degree(id, &head[1])?);
        let rows = head[2]
            .list()
            .ok_or_else(|| self.bad(id, "control points expected"))?;
        let points = rows
            .iter()
            .map(|row| {
                self.points(
                    id,
                    row.list()
                        .ok_or_else(|| self.bad(id, "a row of control points expected"))?,
                )
            })
            .collect::<Result<Vec<_>, _>>()?;
        let nv = points.first().map_or(0, Vec::len);
        if points.is_empty() || points.iter().any(|r| r.len() != nv) {
            return Err(self.bad(id, "the control points are not a rectangular grid"));
        }
        let ((mu, ku), (mv, kv)) = match knots {
            Some(k) => (
                (self.ints(id, &k[0])?, self.reals(id, &k[2])?),
                (self.ints(id, &k[1])?, self.reals(id, &k[3])?),
            ),
            None => {
                let implied = |d, n| {
                    Self::implied_knots(inst, "SURFACE", d, n)
                        .ok_or_else(|| self.bad(id, "the B-spline's knots are not given"))
                };
                (implied(du, points.len())?, implied(dv, nv)?)
            }
        };
        let u = Knots::new(du, &mu, &ku, points.len())
            .ok_or_else(|| self.bad(id, "the u knots do not fit the control points and degree"))?;
        let v = Knots::new(dv, &mv, &kv, nv)
            .ok_or_else(|| self.bad(id, "the v knots do not fit the control points and degree"))?;
        let weights = match inst.record("RATIONAL_B_SPLINE_SURFACE") {
            Some(r) => self
                .list(id, r, 0)?
                .iter()
                .map(|row| self.reals(id, row))
                .collect::<Result<Vec<_>, _>>()?,
            None => vec![vec![1.0; nv]; points.len()],
        };
        if weights.len() != points.len()
            || weights
                .iter()
                .any(|r| r.len() != nv || r.iter().any(|w| !w.is_finite() || *w <= 0.0))
        {
            return Err(self.bad(
                id,
                "a rational B-spline needs one positive weight per point",
            ));
        }
        let closed = [
            head.get(4).and_then(Param::boolean).unwrap_or(false),
            head.get(5).and_then(Param::boolean).unwrap_or(false),
        ];
        Ok(BSplineSurface {
            u,
            v,
            points,
            weights,
            closed,
        })
    }
}
