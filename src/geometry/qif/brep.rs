//! From a QIF document's product geometry and topology to the B-rep the STEP reader
//! builds: faces of the solid bodies in shell order with their exact surfaces, edges with
//! their curves, all in millimetres.
//!
//! QIF gives a face no sense flag, and its loops do not say which side the material is
//! on: the senses come from the topology in [`super::read`] (the module's decision).

use super::xml::Node;
use super::QifError;
use crate::geometry::step::brep::{Bound, Brep, Edge, Face};
use crate::geometry::step::geom::{BSplineCurve, Curve, Frame, Knots, Surf};
use crate::geometry::{P3, V3};
use std::cell::{Cell, RefCell};
use std::collections::{HashMap, HashSet};
use std::f64::consts::TAU;

/// Lookups over the document.
pub struct Doc<'a> {
    /// Every element with an id.
    pub ids: HashMap<u64, &'a Node>,
    /// Millimetres of the part per length of its geometry: the file's unit divided by
    /// the product's scale coefficient.
    pub unit: f64,
    /// Millimetres per file length unit, for stated values (tolerances, sizes).
    pub value_unit: f64,
    /// How many more points the aggregates' sub-curves may be sampled at
    /// ([`MAX_SAMPLES`] for the document).
    pub samples: Cell<usize>,
    /// Curves read, by id: every edge on one shares it.
    pub curves: RefCell<HashMap<u64, (Curve, Option<P3>)>>,
}

/// How many points all the aggregate curves of a document may be sampled at together:
/// an aggregate's sub-curves become one polyline, so its points are what the file
/// costs to mesh (a million-triangle part has far fewer bound points).
pub(crate) const MAX_SAMPLES: usize = 4_000_000;

impl<'a> Doc<'a> {
    /// The element `id` refers to, from the element `from`.
    pub fn get(&self, id: u64, from: &Node) -> Result<&'a Node, QifError> {
        self.ids.get(&id).copied().ok_or(QifError::Missing {
            id,
            from: from.id(),
            line: from.line,
        })
    }

    /// The id in `<name><Id>…</Id></name>` under `n`.
    pub(crate) fn ref_id(&self, n: &Node, name: &str) -> Result<u64, QifError> {
        n.at(&[name, "Id"])
            .and_then(|i| i.text.trim().parse().ok())
            .ok_or_else(|| malformed(n, &format!("it has no <{name}><Id>")))
    }

    /// The ids listed under `n`'s child `name` (`<FaceIds><Id>…`).
    pub(crate) fn id_list(n: &Node, name: &str) -> Vec<u64> {
        n.child(name)
            .map(|l| {
                l.all("Id")
                    .filter_map(|i| i.text.trim().parse().ok())
                    .collect()
            })
            .unwrap_or_default()
    }
}

/// The error for an element whose content does not fit its type.
pub(crate) fn malformed(n: &Node, message: &str) -> QifError {
    QifError::Malformed {
        id: n.id(),
        element: n.name.to_string(),
        line: n.line,
        message: message.to_string(),
    }
}

/// The numbers of a child's text, exactly `len` of them.
fn nums(n: &Node, name: &str, len: usize) -> Result<Vec<f64>, QifError> {
    let c = n
        .child(name)
        .ok_or_else(|| malformed(n, &format!("it has no <{name}>")))?;
    match c.numbers() {
        Some(v) if v.len() == len => Ok(v),
        _ => Err(malformed(c, &format!("<{name}> is not {len} numbers"))),
    }
}

fn num(n: &Node, name: &str) -> Result<f64, QifError> {
    Ok(nums(n, name, 1)?[0])
}

fn vec3(n: &Node, name: &str) -> Result<V3, QifError> {
    let v = nums(n, name, 3)?;
    Ok(V3::new(v[0], v[1], v[2]))
}

impl Doc<'_> {
    fn point(&self, n: &Node, name: &str) -> Result<P3, QifError> {
        Ok(P3::from(vec3(n, name)? * self.unit))
    }

    fn length(&self, n: &Node, name: &str) -> Result<f64, QifError> {
        let x = num(n, name)? * self.unit;
        if x < 0.0 {
            return Err(malformed(n, &format!("<{name}> is negative")));
        }
        Ok(x)
    }
}

fn frame(n: &Node, o: P3, z: V3, x: Option<V3>) -> Result<Frame, QifError> {
    Frame::new(o, Some(z), x).ok_or_else(|| malformed(n, "its directions are zero or parallel"))
}

/// The core element of a geometry element (`Plane23` → `Plane23Core`).
fn core(n: &Node) -> Result<&Node, QifError> {
    let name = format!("{}Core", n.name);
    n.child(&name)
        .ok_or_else(|| malformed(n, &format!("it has no <{name}>")))
}

/// A surface.
fn surface(d: &Doc, n: &Node) -> Result<Surf, QifError> {
    let unsupported = || QifError::Unsupported {
        id: n.id(),
        line: n.line,
        what: format!("surface {}", n.name),
    };
    match n.name.as_str() {
        "Plane23" => {
            let c = core(n)?;
            let o = d.point(c, "Origin")?;
            let u = c.child("DirU").map(|_| vec3(c, "DirU")).transpose()?;
            let z = match (c.child("Normal"), u, c.child("DirV")) {
                (Some(_), _, _) => vec3(c, "Normal")?,
                (None, Some(u), Some(_)) => u.cross(&vec3(c, "DirV")?),
                _ => {
                    return Err(malformed(
                        c,
                        "it has neither <Normal> nor <DirU> and <DirV>",
                    ))
                }
            };
            Ok(Surf::Plane(frame(c, o, z, u)?))
        }
        "Cylinder23" => {
            let c = core(n)?;
            let r = d.length(c, "Diameter")? / 2.0;
            let axis = c
                .child("Axis")
                .ok_or_else(|| malformed(c, "it has no <Axis>"))?;
            let beg = sweep_start(c)?;
            let f = frame(
                c,
                d.point(axis, "AxisPoint")?,
                vec3(axis, "Direction")?,
                beg,
            )?;
            positive(c, r, "its diameter")?;
            Ok(Surf::Cylinder(f, r))
        }
        "Cone23" => {
            let c = core(n)?;
            let bottom = d.length(c, "DiameterBottom")? / 2.0;
            let top = d.length(c, "DiameterTop")? / 2.0;
            let len = d.length(c, "Length")?;
            positive(c, len, "its length")?;
            let axis = c
                .child("Axis")
                .ok_or_else(|| malformed(c, "it has no <Axis>"))?;
            let p = d.point(axis, "AxisPoint")?;
            let dir = vec3(axis, "Direction")?
                .try_normalize(1e-12)
                .ok_or_else(|| malformed(axis, "its direction is zero"))?;
            let beg = sweep_start(c)?;
            if (top - bottom).abs() < 1e-12 {
                return Ok(Surf::Cylinder(frame(c, p, dir, beg)?, top));
            }
            // inspc's cone opens along its axis: start at the narrow end.
            let (o, z, r) = if top > bottom {
                (p, dir, bottom)
            } else {
                (p + dir * len, -dir, top)
            };
            let a = ((top - bottom).abs() / len).atan();
            Ok(Surf::Cone(frame(c, o, z, beg)?, r, a))
        }
        "Sphere23" => {
            let c = core(n)?;
            let r = d.length(c, "Diameter")? / 2.0;
            positive(c, r, "its diameter")?;
            let o = d.point(c, "Location")?;
            let (x, z) = match c.child("LatitudeLongitudeSweep") {
                Some(s) => (
                    s.child("DirMeridianPrime")
                        .map(|_| vec3(s, "DirMeridianPrime"))
                        .transpose()?,
                    s.child("DirNorthPole")
                        .map(|_| vec3(s, "DirNorthPole"))
                        .transpose()?,
                ),
                None => (None, None),
            };
            Ok(Surf::Sphere(frame(c, o, z.unwrap_or(V3::z()), x)?, r))
        }
        "Torus23" => {
            let c = core(n)?;
            let big = d.length(c, "DiameterMajor")? / 2.0;
            let small = d.length(c, "DiameterMinor")? / 2.0;
            positive(c, small, "its minor diameter")?;
            let axis = c
                .child("Axis")
                .ok_or_else(|| malformed(c, "it has no <Axis>"))?;
            let x = match c.child("LatitudeLongitudeSweep") {
                Some(s) => s
                    .child("DirMeridianPrime")
                    .map(|_| vec3(s, "DirMeridianPrime"))
                    .transpose()?,
                None => None,
            };
            let f = frame(c, d.point(axis, "AxisPoint")?, vec3(axis, "Direction")?, x)?;
            Ok(Surf::Torus(f, big, small))
        }
        _ => Err(unsupported()),
    }
}

fn positive(n: &Node, x: f64, what: &str) -> Result<(), QifError> {
    if x > 0.0 {
        Ok(())
    } else {
        Err(malformed(n, &format!("{what} is zero")))
    }
}

/// Where a surface of revolution's angle starts (`<Sweep><DirBeg>`), if it says.
fn sweep_start(c: &Node) -> Result<Option<V3>, QifError> {
    match c.child("Sweep") {
        Some(s) if s.child("DirBeg").is_some() => Ok(Some(vec3(s, "DirBeg")?)),
        _ => Ok(None),
    }
}

/// The `domain="a b"` of a curve core.
fn domain(c: &Node) -> Option<(f64, f64)> {
    let v: Vec<f64> = c
        .attr("domain")?
        .split_ascii_whitespace()
        .map(|t| t.parse().ok())
        .collect::<Option<_>>()?;
    (v.len() == 2).then(|| (v[0], v[1]))
}

/// A curve from its core element (`ArcCircular13Core`, …), and where it starts.
fn curve_core(d: &Doc, c: &Node, owner: &Node) -> Result<(Curve, Option<P3>), QifError> {
    let unsupported = || QifError::Unsupported {
        id: owner.id(),
        line: c.line,
        what: format!("curve {}", c.name.trim_end_matches("Core")),
    };
    match c.name.as_str() {
        "Segment13Core" => {
            let (a, b) = (d.point(c, "StartPoint")?, d.point(c, "EndPoint")?);
            Ok((Curve::Line(a, b - a), Some(a)))
        }
        "ArcCircular13Core" => {
            let r = d.length(c, "Radius")?;
            positive(c, r, "its radius")?;
            let f = frame(
                c,
                d.point(c, "Center")?,
                vec3(c, "Normal")?,
                Some(vec3(c, "DirBeg")?),
            )?;
            let t0 = domain(c).map_or(0.0, |dm| dm.0);
            let curve = Curve::Circle(f, r);
            let start = curve.eval(t0);
            Ok((curve, Some(start)))
        }
        "ArcConic13Core" => {
            let curve = conic(d, c)?;
            let start = curve.eval(domain(c).map_or(0.0, |dm| dm.0));
            Ok((curve, Some(start)))
        }
        "Nurbs13Core" => {
            let order = num(c, "Order")?;
            let knots = c
                .child("Knots")
                .and_then(|k| k.numbers())
                .ok_or_else(|| malformed(c, "its <Knots> are not numbers"))?;
            let cps = c
                .child("CPs")
                .and_then(|k| k.numbers())
                .ok_or_else(|| malformed(c, "its <CPs> are not numbers"))?;
            if cps.len() % 3 != 0 || cps.is_empty() {
                return Err(malformed(c, "its <CPs> are not x y z triples"));
            }
            let points: Vec<P3> = cps
                .chunks(3)
                .map(|p| P3::new(p[0], p[1], p[2]) * d.unit)
                .collect();
            let weights = match c.child("Weights") {
                Some(w) => w
                    .numbers()
                    .filter(|w| w.len() == points.len() && w.iter().all(|x| *x > 0.0))
                    .ok_or_else(|| {
                        malformed(
                            c,
                            "its <Weights> are not one positive number per control point",
                        )
                    })?,
                None => vec![1.0; points.len()],
            };
            // The order is checked before it sizes anything: a whole number no
            // higher than the highest degree read, plus one.
            let max_order = (crate::geometry::step::geom::MAX_DEGREE + 1) as f64;
            let fits = order.fract() == 0.0 && (2.0..=max_order).contains(&order);
            let knots = Some(knots)
                .filter(|k| fits && k.len() == points.len() + order as usize)
                .and_then(|k| Knots::checked(order as usize - 1, k))
                .ok_or_else(|| {
                    malformed(c, "its order, knots and control points do not fit together")
                })?;
            let curve = BSplineCurve {
                knots,
                points,
                weights,
            };
            let start = curve.eval(curve.knots.range().0);
            Ok((Curve::BSpline(std::sync::Arc::new(curve)), Some(start)))
        }
        "Polyline13Core" => {
            let v = c
                .child("Points")
                .and_then(|p| p.numbers())
                .filter(|v| v.len() >= 6 && v.len() % 3 == 0)
                .ok_or_else(|| malformed(c, "its <Points> are not x y z triples"))?;
            let pts: Vec<P3> = v
                .chunks(3)
                .map(|p| P3::new(p[0], p[1], p[2]) * d.unit)
                .collect();
            let start = pts[0];
            Ok((Curve::Polyline(pts.into()), Some(start)))
        }
        "Aggregate13Core" => {
            let mut pts: Vec<P3> = Vec::new();
            let subs = c
                .child("SubCurves")
                .ok_or_else(|| malformed(c, "it has no <SubCurves>"))?;
            for sc in subs.all("SubCurve") {
                let inner = sc
                    .children
                    .iter()
                    .find(|k| k.name.ends_with("Core"))
                    .ok_or_else(|| malformed(sc, "it has no curve"))?;
                let (curve, _) = curve_core(d, inner, owner)?;
                let mut p = sample(&curve, inner, d)?;
                if sc.attr("turned") == Some("true") {
                    p.reverse();
                }
                if pts.last().is_some_and(|l| (l - p[0]).norm() < 1e-9) {
                    pts.pop();
                }
                pts.extend(p);
            }
            if pts.len() < 2 {
                return Err(malformed(c, "its sub-curves are empty"));
            }
            let start = pts[0];
            Ok((Curve::Polyline(pts.into()), Some(start)))
        }
        _ => Err(unsupported()),
    }
}

/// A conic arc's curve. QIF 3's schema (Geometry.xsd, `ArcConic13CoreType`) names `A`
/// and `B` the conic's "major" and "minor diameter", as its circles, cylinders and tori
/// give diameters, and puts the conic in the plane of `Normal` starting along `DirBeg`;
/// it gives no formula, so ISO 10303-42's parametrisations are taken with the
/// semi-axes (for a parabola the focal distance) `A/2` and `B/2`. The edge's vertices
/// must then lie on the curve ([`edge`] checks): a reading that disagrees with the
/// file's own topology stops instead of meshing a wrong face.
fn conic(d: &Doc, c: &Node) -> Result<Curve, QifError> {
    let a = d.length(c, "A")? / 2.0;
    positive(c, a, "its A")?;
    let f = frame(
        c,
        d.point(c, "Center")?,
        vec3(c, "Normal")?,
        Some(vec3(c, "DirBeg")?),
    )?;
    match c.attr("form") {
        Some("PARABOLA") => Ok(Curve::Parabola(f, a)),
        Some(form @ ("ELLIPSE" | "HYPERBOLA")) => {
            let b = d.length(c, "B")? / 2.0;
            positive(c, b, "its B")?;
            Ok(if form == "ELLIPSE" {
                Curve::Ellipse(f, a, b)
            } else {
                Curve::Hyperbola(f, a, b)
            })
        }
        _ => Err(malformed(
            c,
            "its form is not PARABOLA, ELLIPSE or HYPERBOLA",
        )),
    }
}

/// A sub-curve of an aggregate as points along its domain, fine enough for any chord
/// tolerance the tessellator is asked for (a 0.02 rad step on arcs, 32 points a span on
/// B-splines).
///
/// Every point is charged to the document's [`Doc::samples`] before it is made: an
/// arc's domain is at most a turn, and all aggregates together take at most
/// [`MAX_SAMPLES`] points, so their cost follows the file's size.
fn sample(curve: &Curve, c: &Node, d: &Doc) -> Result<Vec<P3>, QifError> {
    let count = match curve {
        Curve::Line(..) => 2,
        Curve::Polyline(p) => p.len(),
        Curve::Parabola(..) | Curve::Hyperbola(..) => 65,
        Curve::Circle(..) | Curve::Ellipse(..) => {
            let (a, b) = domain(c).ok_or_else(|| malformed(c, "it has no domain"))?;
            let sweep = (b - a).abs();
            if sweep.is_nan() || sweep > TAU + 1e-9 {
                return Err(malformed(c, "its domain spans more than a full turn"));
            }
            ((b - a).abs() / 0.02).ceil().max(1.0) as usize + 1
        }
        Curve::BSpline(s) => 32 * s.knots.breaks().len() + 1,
    };
    match d.samples.get().checked_sub(count) {
        Some(left) => d.samples.set(left),
        None => {
            return Err(malformed(
                c,
                &format!("the aggregate curves need more than {MAX_SAMPLES} points in all"),
            ))
        }
    }
    Ok(match curve {
        Curve::Line(a, d) => vec![*a, a + d],
        Curve::Polyline(p) => p.to_vec(),
        Curve::Circle(..) | Curve::Ellipse(..) | Curve::Parabola(..) | Curve::Hyperbola(..) => {
            let (a, b) = domain(c).ok_or_else(|| malformed(c, "it has no domain"))?;
            let n = count - 1;
            (0..=n)
                .map(|k| curve.eval(a + (b - a) * k as f64 / n as f64))
                .collect()
        }
        Curve::BSpline(s) => {
            let br = s.knots.breaks();
            let mut out = vec![s.eval(br[0])];
            for w in br.windows(2) {
                for k in 1..=32 {
                    out.push(s.eval(w[0] + (w[1] - w[0]) * k as f64 / 32.0));
                }
            }
            out
        }
    })
}

/// Reads the B-rep of the solid bodies (or, when there is none, the visible sheet
/// bodies) of a document.
pub fn read(d: &Doc, root: &Node) -> Result<Brep, QifError> {
    let topo = root.at(&["Product", "TopologySet"]);
    let bodies: Vec<&Node> = topo
        .and_then(|t| t.child("BodySet"))
        .map(|b| b.all("Body").collect())
        .unwrap_or_default();
    let visible = |b: &&&Node| b.attr("hidden") != Some("true");
    let solids: Vec<&Node> = bodies
        .iter()
        .filter(visible)
        .filter(|b| b.attr("form") == Some("SOLID"))
        .copied()
        .collect();
    let sheets: Vec<&Node> = bodies
        .iter()
        .filter(visible)
        .filter(|b| b.attr("form") != Some("SOLID"))
        .copied()
        .collect();
    let body_faces = |list: &[&Node]| -> Result<Vec<u64>, QifError> {
        let mut out = Vec::new();
        let mut seen = HashSet::new();
        for b in list {
            let shells = Doc::id_list(b, "ShellIds");
            let mut ids = Vec::new();
            for s in &shells {
                ids.extend(Doc::id_list(d.get(*s, b)?, "FaceIds"));
            }
            if shells.is_empty() {
                ids = Doc::id_list(b, "FaceIds");
            }
            out.extend(ids.into_iter().filter(|id| seen.insert(*id)));
        }
        Ok(out)
    };
    let mut face_ids = body_faces(&solids)?;
    let solid_faces = face_ids.len();
    if solid_faces == 0 {
        face_ids = body_faces(&sheets)?;
    }
    if face_ids.is_empty() {
        return Err(QifError::NoSolid);
    }

    let mut edges: Vec<Edge> = Vec::new();
    let mut edge_index: HashMap<u64, usize> = HashMap::new();
    let mut surfaces: HashMap<u64, Surf> = HashMap::new();
    let mut faces = Vec::new();
    for fid in face_ids {
        let f = d.get(fid, root)?;
        if f.name != "Face" {
            return Err(if f.name == "FaceMesh" {
                QifError::Unsupported {
                    id: Some(fid),
                    line: f.line,
                    what: "face given as a mesh (FaceMesh)".into(),
                }
            } else {
                malformed(f, "a body lists it as a face")
            });
        }
        let sid = d.ref_id(f, "Surface")?;
        let surf = match surfaces.get(&sid) {
            Some(s) => s.clone(),
            None => {
                let s = surface(d, d.get(sid, f)?)?;
                surfaces.insert(sid, s.clone());
                s
            }
        };
        let mut bounds = Vec::new();
        for lid in Doc::id_list(f, "LoopIds") {
            let l = d.get(lid, f)?;
            let mut list = Vec::new();
            if let Some(ces) = l.child("CoEdges") {
                for ce in ces.all("CoEdge") {
                    let eo = ce
                        .child("EdgeOriented")
                        .ok_or_else(|| malformed(l, "a co-edge has no <EdgeOriented>"))?;
                    let eid: u64 = eo
                        .text_at(&["Id"])
                        .and_then(|t| t.trim().parse().ok())
                        .ok_or_else(|| malformed(l, "a co-edge names no edge"))?;
                    let idx = match edge_index.get(&eid) {
                        Some(i) => *i,
                        None => {
                            let e = edge(d, d.get(eid, l)?)?;
                            edges.push(e);
                            edge_index.insert(eid, edges.len() - 1);
                            edges.len() - 1
                        }
                    };
                    list.push((idx, eo.attr("turned") != Some("true")));
                }
            }
            bounds.push(if list.is_empty() {
                Bound::Vertex
            } else {
                Bound::Edges(list)
            });
        }
        faces.push(Face {
            id: fid,
            surface: surf,
            same_sense: true,
            bounds,
        });
    }
    Ok(Brep {
        sheet_faces: faces.len() - solid_faces.min(faces.len()),
        faces,
        edges,
        unit_mm: d.unit,
        unit_name: String::new(),
    })
}

/// An edge: its vertices, its curve, and whether it runs along the curve (the vertex
/// it begins at is the curve's start).
fn edge(d: &Doc, e: &Node) -> Result<Edge, QifError> {
    if e.name != "Edge" {
        return Err(malformed(e, "a co-edge names it as an edge"));
    }
    let vertex = |name: &str| -> Result<P3, QifError> {
        let v = d.get(d.ref_id(e, name)?, e)?;
        let p = d.get(d.ref_id(v, "Point")?, v)?;
        d.point(p, "XYZ")
    };
    let (start, end) = (vertex("VertexBeg")?, vertex("VertexEnd")?);
    let cid = d.ref_id(e, "Curve")?;
    let cached = d.curves.borrow().get(&cid).cloned();
    let (curve, curve_start) = match cached {
        Some(read) => read,
        None => {
            let c = d.get(cid, e)?;
            let read = curve_core(d, core(c)?, c)?;
            d.curves.borrow_mut().insert(cid, read.clone());
            read
        }
    };
    if let Curve::Ellipse(..) | Curve::Parabola(..) | Curve::Hyperbola(..) = curve {
        for p in [start, end] {
            let off = (curve.eval(curve.param(&p)) - p).norm();
            if off > 1e-3 {
                return Err(malformed(
                    e,
                    &format!("its vertex lies {off:.3} mm off its conic arc (semi-axes read as half of <A> and <B>)"),
                ));
            }
        }
    }
    let same_sense = match curve_start {
        Some(s) => (s - start).norm() <= (s - end).norm() + 1e-9,
        None => true,
    };
    Ok(Edge {
        id: e.id().unwrap_or(0),
        start,
        end,
        curve,
        same_sense,
    })
}
