//! Stage 6, the measurement graph (seed ch. 3.2, figs. 3.2 and 3.29): part → tolerance →
//! feature → face → fpoint, the structure the planner clusters.
//!
//! A tolerance's children are the features it tolerances and the features of the datums
//! it refers to. Features no tolerance names hang from the part, so that they are still
//! measured. A face shared by two features is one node with two parents. Datum features
//! are marked with their letters, and a planar datum face the part can rest on — its
//! plane supports the whole part — is marked `on_table` (ch. 3.6.2): the planner may put
//! it on the table instead of probing it.
//!
//! **Architecture Invariant:** node order is deterministic: the part, then tolerances in
//! declaration order with their features as first named, then the remaining features,
//! then faces as their features first list them, then each face's fpoints.
//!
//! **Decision: points where the tolerance looks.** Each face's strategy is the override
//! of the first feature (in declaration order) that lists the face, else the plan's
//! sampling for its surface type. Under `std::sampling::spread`, the default, a face
//! whose form or orientation is toleranced gets points to its usable edges
//! (`spread_for`), because Fan & Leu's fifth-inset points read a bow of twice a
//! flatness zone as half of it and a tilt at 60 % of its span; with a zone under
//! [`TIGHT_ZONE`] it gets at least twice NPL Good Practice Guide No. 41's counts
//! (Flack, *CMM measurement strategies*, 2001). Faces that are only located or sized
//! keep Fan & Leu's points, which a probe reaches more easily (spread on every face,
//! FTC 06 and FTC 08 read from STEP get points by edges no path reaches). Plans that
//! name `fan_leu` (the seed's examples) keep it.
//!
//! **Decision: form needs more than four points.** Under `fan_leu`, a plane whose
//! flatness or straightness is toleranced gets at least [`FORM_POINTS`] (9) unless its
//! feature has its own strategy: four corner points of one rectangle lie on a plane
//! whatever the face does between them, so a bowed face reads flat.
//!
//! **Decision: datum faces on the table.** A planar datum face is `on_table` when no
//! vertex of the part lies more than 1e-6 of the part's size (plus three times a mesh
//! face's fit RMS) outside its plane.
//!
//! [`check_surfaces`] rejects tolerances on faces of the wrong surface type
//! (`insp::graph::wrong_surface`: flatness on a cylinder, a diameter on a plane) before
//! any sampling.

mod errors;
mod render;
pub mod sensors;

pub(crate) use errors::GraphError;
pub use render::{dot, json, mermaid};

use crate::diag::Diagnostics;
use crate::geometry::{FaceId, PartGeometry, Surface};
use crate::model::{Declared, FeatureId, Part, Sampling, Strategy, SurfaceKind, TolKind};
use crate::sample::{Fpoint, Sampler};
use petgraph::graph::{DiGraph, NodeIndex};
use std::collections::{BTreeMap, HashMap};

/// A node of the measurement graph.
#[derive(Debug, Clone, PartialEq)]
pub enum Node {
    /// The part, the root.
    Part,
    /// A tolerance, by index into [`Part::tolerances`].
    Tolerance(usize),
    /// A feature, with the letters of the datums it carries.
    Feature {
        /// The feature.
        feature: FeatureId,
        /// Datum letters it is the feature of.
        datums: Vec<String>,
    },
    /// A face of the geometry.
    Face {
        /// The face.
        face: FaceId,
        /// A planar datum face whose plane supports the part: it can rest on the table.
        on_table: bool,
    },
    /// A measuring point, by index into [`MeasurementGraph::fpoints`].
    Point(usize),
}

/// Why an edge exists.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Edge {
    /// Part → tolerance.
    Tolerance,
    /// Tolerance → a feature it tolerances (or part → an untoleranced feature).
    Target,
    /// Tolerance → the feature of one of its datums.
    Datum,
    /// Feature → face.
    Face,
    /// Face → fpoint.
    Point,
}

/// The measurement graph of one part under one sampling.
#[derive(Debug, Clone)]
pub struct MeasurementGraph {
    /// The plan it was built for, if any.
    pub plan: Option<String>,
    /// The sampling's name.
    pub sampling: String,
    /// The graph.
    pub graph: DiGraph<Node, Edge>,
    /// The part node.
    pub root: NodeIndex,
    /// Every measuring point, in node order.
    pub fpoints: Vec<Fpoint>,
    /// The distance points keep from face boundaries (mm).
    pub margin: f64,
    /// Per feature, its sensor and why, when the plan's machine carries a scanner
    /// ([`sensors::select`]); empty otherwise.
    pub sensors: Vec<sensors::SensorPick>,
    /// Per face sampled with more than [`DENSE_FACE`] points, the same strategy asked
    /// for [`REPRESENTATIVES`] points, where that gives at most half as many: what the
    /// planner decides the face's configurations on (`plan::dense`). Not measured.
    pub representatives: BTreeMap<FaceId, Vec<Fpoint>>,
}

/// The most points a face has and is still planned point by point: the spread
/// sampling gives a toleranced face at most 25.
pub(crate) const DENSE_FACE: usize = 25;

/// How many points of its own strategy a denser face is planned on (`plan::dense`): as
/// many as a face of a typical real program, the same at every density.
pub(crate) const REPRESENTATIVES: u32 = 12;

/// The most measuring points one graph may hold. The path stage keeps a shortest-path
/// tree per point of a group (points × roadmap nodes), so this bounds its memory: at
/// 10,000 points CTC 02 peaks at 1.4 GB and FTC 06 at 2.1 GB. A body-in-white program runs 2,000 and more; dense
/// faces cost the planner their representatives only (`plan::dense`).
pub(crate) const MAX_POINTS: usize = 20_000;

impl MeasurementGraph {
    /// The fpoints of a face, by index.
    pub fn face_points(&self, face: FaceId) -> Vec<usize> {
        (0..self.fpoints.len())
            .filter(|&i| self.fpoints[i].face == face)
            .collect()
    }

    /// The nodes of a kind, in order.
    pub fn nodes(&self) -> impl Iterator<Item = (NodeIndex, &Node)> {
        self.graph.node_indices().map(move |i| (i, &self.graph[i]))
    }

    /// The children of a node, in insertion order.
    pub fn children(&self, n: NodeIndex) -> Vec<(NodeIndex, Edge)> {
        let mut out: Vec<(NodeIndex, Edge)> = self
            .graph
            .edges(n)
            .map(|e| (petgraph::visit::EdgeRef::target(&e), *e.weight()))
            .collect();
        out.sort_by_key(|(i, _)| *i);
        out
    }

    /// Counts: tolerances, features, faces, fpoints.
    pub fn counts(&self) -> [usize; 4] {
        let mut c = [0; 4];
        for (_, n) in self.nodes() {
            match n {
                Node::Part => {}
                Node::Tolerance(_) => c[0] += 1,
                Node::Feature { .. } => c[1] += 1,
                Node::Face { .. } => c[2] += 1,
                Node::Point(_) => c[3] += 1,
            }
        }
        c
    }
}

/// What building a graph needs.
pub struct Input<'a> {
    /// The part.
    pub part: &'a Part,
    /// Its geometry.
    pub geometry: &'a PartGeometry,
    /// Per feature, its faces.
    pub feature_faces: &'a [Vec<FaceId>],
    /// The plan's name, if any.
    pub plan: Option<&'a str>,
    /// The sampling.
    pub sampling: &'a Sampling,
    /// Per-feature strategies.
    pub overrides: &'a [(FeatureId, Strategy)],
    /// The distance points keep from face boundaries (mm).
    pub margin: f64,
    /// The plan's probes as the sampler sees them: a recess floor's points keep clear of
    /// its walls by the probe part standing beside them (`sample::recess_margins`).
    pub shanks: Vec<crate::sample::Shank>,
    /// Where a problem of the whole graph is reported: the plan's name, or the part's.
    pub span: crate::source::Span,
}

/// Builds the measurement graph of a part, sampling every face. The entry point of the
/// graph stage. Faces that get no measuring point are reported as warnings at the
/// feature that names them.
pub fn build(input: &Input, diags: &mut Diagnostics) -> MeasurementGraph {
    let part = input.part;
    let mut graph = DiGraph::new();
    let root = graph.add_node(Node::Part);
    let mut datums_of: HashMap<FeatureId, Vec<String>> = HashMap::new();
    for d in &part.datums {
        datums_of.entry(d.feature).or_default().push(d.name.clone());
    }
    let feature_nodes = add_features(part, &mut graph, root, &datums_of);
    let (face_nodes, owners_of) = add_faces(input, &mut graph, &feature_nodes, &datums_of);
    let (fpoints, representatives) = add_points(input, &mut graph, &face_nodes, owners_of, diags);
    MeasurementGraph {
        plan: input.plan.map(str::to_owned),
        sampling: input.sampling.name.clone(),
        graph,
        root,
        fpoints,
        margin: input.margin,
        sensors: Vec::new(),
        representatives,
    }
}

/// Adds the tolerances under `root`, each with the features it tolerances and the
/// features of its datums, then the features no tolerance names (face aliases aside);
/// returns every feature node in node order.
fn add_features(
    part: &Part,
    graph: &mut DiGraph<Node, Edge>,
    root: NodeIndex,
    datums_of: &HashMap<FeatureId, Vec<String>>,
) -> Vec<(FeatureId, NodeIndex)> {
    // Per feature, its node once made (lookups stay linear in the part's size).
    let mut node_of: Vec<Option<NodeIndex>> = vec![None; part.features.len()];
    let mut feature_node = |graph: &mut DiGraph<Node, Edge>, f: FeatureId| -> NodeIndex {
        if let Some(n) = node_of[f.0] {
            return n;
        }
        let n = graph.add_node(Node::Feature {
            feature: f,
            datums: datums_of.get(&f).cloned().unwrap_or_default(),
        });
        node_of[f.0] = Some(n);
        n
    };
    for (k, t) in part.tolerances.iter().enumerate() {
        let tn = graph.add_node(Node::Tolerance(k));
        graph.add_edge(root, tn, Edge::Tolerance);
        for &f in &t.targets {
            let fnode = feature_node(graph, f);
            graph.update_edge(tn, fnode, Edge::Target);
        }
        for r in &t.datums {
            let f = part.datums[r.datum.0].feature;
            let fnode = feature_node(graph, f);
            if graph.find_edge(tn, fnode).is_none() {
                graph.add_edge(tn, fnode, Edge::Datum);
            }
        }
    }
    let mut named: Vec<bool> = vec![false; part.features.len()];
    for n in graph.node_weights() {
        if let Node::Feature { feature, .. } = n {
            named[feature.0] = true;
        }
    }
    for (k, f) in part.features.iter().enumerate() {
        let id = FeatureId(k);
        let named = named[k];
        // Face aliases (`face top = …`) only name a face for use in features.
        let alias_only = f.declared == Declared::Face && !datums_of.contains_key(&id);
        if !named && !alias_only {
            let fnode = feature_node(graph, id);
            graph.add_edge(root, fnode, Edge::Target);
        }
    }
    graph
        .node_indices()
        .filter_map(|i| match &graph[i] {
            Node::Feature { feature, .. } => Some((*feature, i)),
            _ => None,
        })
        .collect()
}

/// Adds each feature's faces under it, a face two features share once, marked
/// `on_table` when a datum feature lists it and it can rest on the table. Returns the
/// face nodes in order with the first feature that lists each, and per face the
/// features that list it, in declaration order (for its strategy).
fn add_faces(
    input: &Input,
    graph: &mut DiGraph<Node, Edge>,
    feature_nodes: &[(FeatureId, NodeIndex)],
    datums_of: &HashMap<FeatureId, Vec<String>>,
) -> FacesAdded {
    let g = input.geometry;
    let mut face_nodes: Vec<(FaceId, NodeIndex, FeatureId)> = Vec::new();
    let mut face_node_of: HashMap<FaceId, NodeIndex> = HashMap::new();
    let mut owners_of: HashMap<FaceId, Vec<FeatureId>> = HashMap::new();
    for &(f, fnode) in feature_nodes {
        let datum = datums_of.contains_key(&f);
        for &face in &input.feature_faces[f.0] {
            // Each feature comes once and lists each face once.
            owners_of.entry(face).or_default().push(f);
            let node = match face_node_of.get(&face).copied() {
                Some(n) => {
                    if datum && on_table(g, face) {
                        graph[n] = Node::Face {
                            face,
                            on_table: true,
                        };
                    }
                    n
                }
                None => {
                    let n = graph.add_node(Node::Face {
                        face,
                        on_table: datum && on_table(g, face),
                    });
                    face_nodes.push((face, n, f));
                    face_node_of.insert(face, n);
                    n
                }
            };
            graph.update_edge(fnode, node, Edge::Face);
        }
    }
    (face_nodes, owners_of)
}

/// What [`add_faces`] gives: the face nodes (face, node, first feature) and each face's
/// features.
type FacesAdded = (
    Vec<(FaceId, NodeIndex, FeatureId)>,
    HashMap<FaceId, Vec<FeatureId>>,
);

/// Samples each face and adds its fpoints under it, up to [`MAX_POINTS`] in all;
/// reports a face that gets none, and stops with an error past the limit. A face of
/// more than [`DENSE_FACE`] points is also sampled at [`REPRESENTATIVES`] points.
fn add_points(
    input: &Input,
    graph: &mut DiGraph<Node, Edge>,
    face_nodes: &[(FaceId, NodeIndex, FeatureId)],
    mut owners_of: HashMap<FaceId, Vec<FeatureId>>,
    diags: &mut Diagnostics,
) -> (Vec<Fpoint>, BTreeMap<FaceId, Vec<Fpoint>>) {
    let mut representatives = BTreeMap::new();
    let part = input.part;
    let g = input.geometry;
    let sampler = Sampler::new(g, input.margin).with_shanks(&input.shanks);
    let mut fpoints = Vec::new();
    for &(face, fnode, first_feature) in face_nodes {
        let mut owners = owners_of.remove(&face).unwrap_or_default();
        owners.sort();
        let strategy = strategy_for(input, face, &owners);
        let points = sampler.sample(face, &strategy);
        if fpoints.len() + points.len() > MAX_POINTS {
            diags.push(GraphError::TooManyPoints {
                span: input.span,
                what: match input.plan {
                    Some(p) => format!("plan `{p}`"),
                    None => format!("part `{}`", part.name),
                },
                faces: face_nodes.len(),
            });
            break;
        }
        if points.is_empty() {
            let feature = &part.features[first_feature.0];
            diags.push(GraphError::NoPoints {
                span: feature.span,
                face: g.faces[face.0].name.clone(),
                feature: feature.name.clone(),
                margin: crate::model::fmt_num(input.margin),
            });
        }
        if points.len() > DENSE_FACE {
            let few = Strategy {
                points: Some(REPRESENTATIVES),
                spacing: None,
                ..strategy.clone()
            };
            let few = sampler.sample(face, &few);
            // A strategy whose own rules keep the count up (a tight zone's spread) gives
            // no fewer: the face is planned on its own points.
            if few.len() * 2 <= points.len() {
                representatives.insert(face, few);
            }
        }
        for p in points {
            let pn = graph.add_node(Node::Point(fpoints.len()));
            graph.add_edge(fnode, pn, Edge::Point);
            fpoints.push(p);
        }
    }
    (fpoints, representatives)
}

/// The strategy for a face: the override of the first feature (in declaration order)
/// that has one and lists the face (`owners`, sorted), else the sampling's strategy for
/// its surface type, raised to [`FORM_POINTS`] on a plane whose flatness is toleranced.
fn strategy_for(input: &Input, face: FaceId, owners: &[FeatureId]) -> Strategy {
    let s = declared_strategy(input, face, owners);
    let kind = input.geometry.faces[face.0].surface.kind();
    match per_unit_spacing(input, owners) {
        Some(spacing)
            if matches!(
                kind,
                SurfaceKind::Plane | SurfaceKind::Cylinder | SurfaceKind::Cone
            ) =>
        {
            Strategy {
                method: crate::model::SampleMethod::Spread,
                spacing: Some(spacing),
                ..s
            }
        }
        _ => s,
    }
}

/// The rows of a face under a zone per unit length or area are at most a third of the
/// unit apart, whatever the sampling says: a bump as wide as the unit, wherever it
/// stands, has a point within 0.24 of the unit from its top (half the diagonal of a
/// third), where it still stands out 78 % of its height, and a window the program checks
/// ([`crate::dmis`]) holds it whole with at least 3 × 3 points. A deviation narrower
/// than a third of the unit may fall between rows (an independent review found 8 mm
/// bumps missed under a 25 mm unit): finer than that, scan the face.
fn per_unit_spacing(input: &Input, owners: &[FeatureId]) -> Option<f64> {
    input
        .part
        .tolerances
        .iter()
        .filter(|t| t.targets.iter().any(|f| owners.contains(f)))
        .filter_map(|t| t.per_unit.as_ref())
        .map(|p| p.unit.least() / PER_UNIT_ROWS)
        .reduce(f64::min)
}

/// Rows of points per unit stretch under a zone per unit.
pub(crate) const PER_UNIT_ROWS: f64 = 3.0;

/// The strategy the spec declares for a face: see [`strategy_for`].
fn declared_strategy(input: &Input, face: FaceId, owners: &[FeatureId]) -> Strategy {
    if let Some(s) = owners.iter().find_map(|f| {
        input
            .overrides
            .iter()
            .find(|(o, _)| o == f)
            .map(|(_, s)| s.clone())
    }) {
        return s;
    }
    let kind = input.geometry.faces[face.0].surface.kind();
    let base = input.sampling.strategy(kind);
    if base.method == crate::model::SampleMethod::Spread {
        return spread_for(input, kind, owners, base);
    }
    let form = input.part.tolerances.iter().any(|t| {
        matches!(t.kind, TolKind::Flatness | TolKind::Straightness)
            && t.targets.iter().any(|f| owners.contains(f))
    });
    if !form || kind != SurfaceKind::Plane {
        return base;
    }
    // Fan & Leu's 4 points fix a plane's place, not its form: four points at the corners
    // of one rectangle lie on one plane whatever the face does between them (a bowed
    // face reads flat). The sampler fills in points between them up to the count.
    Strategy {
        points: Some(base.points.unwrap_or(0).max(FORM_POINTS)),
        ..base
    }
}

/// `spread` on a face whose tolerances read its form or orientation (elsewhere Fan &
/// Leu's rule); its count: its own rule ([`crate::sample`]), at least twice NPL Good
/// Practice Guide No. 41's counts (18 on a plane, 24 on a cylinder or cone) where a
/// tolerance on the face's features has a zone under [`TIGHT_ZONE`] mm: the tighter the
/// tolerance, the smaller the deviation the points must see.
fn spread_for(input: &Input, kind: SurfaceKind, owners: &[FeatureId], base: Strategy) -> Strategy {
    // Only form and orientation are read across the face: a face whose tolerances
    // locate or size it keeps Fan & Leu's points, which a probe reaches more easily.
    let reads_across = input.part.tolerances.iter().any(|t| {
        matches!(
            t.kind,
            TolKind::Flatness
                | TolKind::Straightness
                | TolKind::ProfileLine
                | TolKind::ProfileSurface
                | TolKind::Perpendicularity
                | TolKind::Parallelism
                | TolKind::Angularity
                | TolKind::Cylindricity
                | TolKind::TotalRunout
        ) && t.targets.iter().any(|f| owners.contains(f))
    });
    if !reads_across {
        return Strategy {
            method: crate::model::SampleMethod::FanLeu,
            ..base
        };
    }
    let tight = input.part.tolerances.iter().any(|t| {
        matches!(t.value, crate::model::TolValue::Zone { width, .. } if width < TIGHT_ZONE)
            && t.targets.iter().any(|f| owners.contains(f))
    });
    let points = match (tight, kind) {
        (true, SurfaceKind::Plane) => Some(18),
        (true, SurfaceKind::Cylinder | SurfaceKind::Cone) => Some(24),
        _ => base.points,
    };
    Strategy { points, ..base }
}

/// A zone under this (mm) doubles `spread`'s points on the face.
pub(crate) const TIGHT_ZONE: f64 = 0.05;

/// The fewest points a plane whose flatness is toleranced gets unless the spec says
/// otherwise for its feature: a 3 × 3 grid, the least that sees a face bow or twist.
pub(crate) const FORM_POINTS: u32 = 9;

/// The surface types a tolerance kind applies to; `None` for kinds that apply to any.
fn surfaces_for(kind: TolKind) -> Option<&'static [SurfaceKind]> {
    use SurfaceKind::*;
    match kind {
        TolKind::Flatness => Some(&[Plane]),
        TolKind::Cylindricity => Some(&[Cylinder]),
        TolKind::Circularity => Some(&[Cylinder, Cone, Sphere]),
        TolKind::Diameter | TolKind::Radius => Some(&[Cylinder, Cone, Sphere]),
        TolKind::Concentricity | TolKind::Coaxiality => Some(&[Cylinder, Cone, Sphere]),
        _ => None,
    }
}

/// Reports tolerances on faces of the wrong surface type: flatness on a cylinder,
/// cylindricity or a diameter on a plane. Free-form faces pass: a mesh patch no surface
/// fits may still be what the drawing calls it.
pub fn check_surfaces(
    part: &Part,
    g: &PartGeometry,
    feature_faces: &[Vec<FaceId>],
    diags: &mut Diagnostics,
) {
    for t in &part.tolerances {
        let Some(allowed) = surfaces_for(t.kind) else {
            continue;
        };
        let wrong = t.targets.iter().find_map(|f| {
            feature_faces[f.0]
                .iter()
                .map(|&face| (f, face))
                .find(|&(_, face)| {
                    let k = g.faces[face.0].surface.kind();
                    k != SurfaceKind::Freeform && !allowed.contains(&k)
                })
        });
        let Some((f, face)) = wrong else {
            if matches!(t.kind, TolKind::Diameter | TolKind::Radius) {
                size_on_freeform(t, part, g, feature_faces, diags);
            }
            continue;
        };
        let names: Vec<&str> = allowed.iter().map(|k| k.keyword()).collect();
        let needs = match names.as_slice() {
            [one] => one.to_string(),
            [init @ .., last] => format!("{} or {last}", init.join(", ")),
            [] => String::new(),
        };
        diags.push(GraphError::WrongSurface {
            span: t.span,
            tolerance: t.kind.keyword().to_string(),
            needs,
            face: g.faces[face.0].name.clone(),
            feature: part.features[f.0].name.clone(),
            found: format!("a {}", g.faces[face.0].surface.kind().keyword()),
            help: "check the feature's faces (`inspc faces` lists their types), or choose a tolerance that fits them".into(),
        });
    }
}

/// Warns where a diameter or radius names free-form faces among its features' faces:
/// the program reads the size on the others only (see [`GraphError::SizeOnFreeform`]).
fn size_on_freeform(
    t: &crate::model::Tolerance,
    part: &Part,
    g: &PartGeometry,
    feature_faces: &[Vec<FaceId>],
    diags: &mut Diagnostics,
) {
    for f in &t.targets {
        let faces = &feature_faces[f.0];
        let free: Vec<&str> = faces
            .iter()
            .filter(|face| g.faces[face.0].surface.kind() == SurfaceKind::Freeform)
            .map(|face| g.faces[face.0].name.as_str())
            .collect();
        if free.is_empty() {
            continue;
        }
        let shown = match free.len() {
            1 => format!("`{}`", free[0]),
            2 => format!("`{}` and `{}`", free[0], free[1]),
            n => format!("`{}`, `{}` and {} more", free[0], free[1], n - 2),
        };
        diags.push(GraphError::SizeOnFreeform {
            span: t.span,
            tolerance: t.kind.keyword().to_string(),
            name: t.name.clone(),
            feature: part.features[f.0].name.clone(),
            read: match faces.len() - free.len() {
                0 => "none".to_string(),
                n => n.to_string(),
            },
            total: faces.len(),
            faces: shown,
            is: if free.len() == 1 { "is" } else { "are" },
        });
    }
}

/// Whether a planar face's plane supports the whole part: no vertex lies outside it.
pub fn on_table(g: &PartGeometry, face: FaceId) -> bool {
    let f = &g.faces[face.0];
    let Surface::Plane { origin, normal } = f.surface else {
        return false;
    };
    let (lo, hi) = g.bounds();
    let tol = 1e-6 * (1.0 + (hi - lo).norm()) + 3.0 * f.fit_rms;
    g.vertices.iter().all(|v| (v - origin).dot(&normal) <= tol)
}
