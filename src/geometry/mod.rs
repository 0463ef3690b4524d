//! Stage 4, geometry: a resolved part → a closed triangle mesh whose every triangle knows
//! its named face, and every face its analytic surface.
//!
//! Constructive parts are built by boolean operations (boolmesh, a pure-Rust port of
//! Manifold) on primitives whose faces carry exact surfaces; since boolmesh does not
//! report which input face an output triangle came from, each output triangle is
//! classified against the exact surfaces of the inputs (`csg.rs`). Mesh parts are read
//! from STL or OBJ (`mesh_io.rs`) and welded (`weld.rs`); their faces come from OBJ
//! groups or from segmentation (`segment.rs`), with surfaces fitted by least squares
//! (`fit.rs`). CAD parts are read from STEP (`step/`) or QIF (`qif/`) with each face's
//! exact surface. Mesh fixtures are placed by `fixture.rs`; `query.rs` answers point
//! questions. `cmm_fit.rs` fits measured points as a CMM's software does and `drf.rs`
//! builds a datum reference frame from them: the simulator evaluates with both, and the
//! path stage asks what a frame leaves free.
//!
//! **Architecture Invariant:** face numbering is deterministic: stock faces, then each
//! operation's faces in declaration order, pattern instances in order; for meshes, the
//! file's group order or the segmentation's seed order; for STEP and QIF, `face_<n>` in
//! shell order.

pub mod cmm_fit;
mod csg;
pub mod drf;
mod errors;
pub mod fit;
mod fixture;
mod mesh_io;
mod primitives;
pub mod qif;
mod query;
mod recess;
mod report;
pub mod segment;
mod select;
pub mod step;
mod weld;

pub use errors::{GeometryError, MeshError};
pub use fixture::{place_fixture, FixtureMesh};
pub use mesh_io::read_mesh;
pub use query::{edge_triangles, line_triangle, FaceIndex};
pub(crate) use recess::across;
pub(crate) use recess::box_exit;
pub use recess::recess_depth;
pub use report::{describe, faces_json, faces_table};
pub use select::resolve_faces;
pub use weld::RawMesh;

use crate::diag::Diagnostics;
use crate::model::{self, Geometry as Source};
use crate::source::World;
use nalgebra::{Point3, Vector3};

/// A point in the part frame (mm).
pub type P3 = Point3<f64>;
/// A vector in the part frame.
pub type V3 = Vector3<f64>;

/// The analytic surface a face lies on.
#[derive(Debug, Clone, PartialEq)]
pub enum Surface {
    /// A plane through `origin`; `normal` is the solid's outward normal.
    Plane {
        /// A point on the plane.
        origin: P3,
        /// Outward unit normal.
        normal: V3,
    },
    /// A cylinder around the line through `origin` along `axis`.
    Cylinder {
        /// A point on the axis.
        origin: P3,
        /// Unit axis.
        axis: V3,
        /// Radius (mm).
        radius: f64,
        /// The outward normal points away from the axis (a shaft) rather than toward it (a hole).
        convex: bool,
    },
    /// A cone with `apex`, unit `axis` (from the apex into the cone) and half angle.
    Cone {
        /// The apex.
        apex: P3,
        /// Unit axis from the apex.
        axis: V3,
        /// Half angle (radians).
        half_angle: f64,
        /// The outward normal points away from the axis.
        convex: bool,
    },
    /// A sphere.
    Sphere {
        /// Centre.
        center: P3,
        /// Radius (mm).
        radius: f64,
        /// The outward normal points away from the centre.
        convex: bool,
    },
    /// No analytic surface fits; the triangles are the geometry.
    Freeform,
}

/// Two faces lie on one surface when their axes or normals agree within this angle
/// (degrees) ...
const SAME_SURFACE_DEG: f64 = 0.1;
/// ... and their positions and radii within this distance (mm): fitted halves of one
/// mesh bore differ by about a hundredth.
const SAME_SURFACE_MM: f64 = 0.02;

impl Surface {
    /// The surface scaled by `s` about the origin (a spec's `mesh "…" { scale s }`):
    /// points and radii scale, directions and angles stay.
    pub fn scaled(&self, s: f64) -> Surface {
        self.mapped(|p| p * s, |v| v, s)
    }

    /// The surface under a rigid motion `m`.
    pub fn moved(&self, m: &nalgebra::Isometry3<f64>) -> Surface {
        self.mapped(|p| m * p, |v| m * v, 1.0)
    }

    /// The surface under a similarity: `point` maps its points, `dir` its directions,
    /// and lengths (radii) are multiplied by `length`; angles and sense stay.
    fn mapped(&self, point: impl Fn(P3) -> P3, dir: impl Fn(V3) -> V3, length: f64) -> Surface {
        match self.clone() {
            Surface::Plane { origin, normal } => Surface::Plane {
                origin: point(origin),
                normal: dir(normal),
            },
            Surface::Cylinder {
                origin,
                axis,
                radius,
                convex,
            } => Surface::Cylinder {
                origin: point(origin),
                axis: dir(axis),
                radius: radius * length,
                convex,
            },
            Surface::Cone {
                apex,
                axis,
                half_angle,
                convex,
            } => Surface::Cone {
                apex: point(apex),
                axis: dir(axis),
                half_angle,
                convex,
            },
            Surface::Sphere {
                center,
                radius,
                convex,
            } => Surface::Sphere {
                center: point(center),
                radius: radius * length,
                convex,
            },
            Surface::Freeform => Surface::Freeform,
        }
    }

    /// Whether two faces' surfaces are one surface (the halves of a bore, the pieces of
    /// a plane the CAD split): same type, sense and shape, an axis either way for a
    /// cylinder. Free-form faces are never one surface.
    pub(crate) fn same_as(&self, other: &Surface) -> bool {
        let cos = SAME_SURFACE_DEG.to_radians().cos();
        let tol = SAME_SURFACE_MM;
        // The distance from `p` to the line through `o` along unit `a`.
        let off_line = |p: &P3, o: &P3, a: &V3| (p - o).cross(a).norm();
        match (self, other) {
            (
                Surface::Plane { origin, normal },
                Surface::Plane {
                    origin: o2,
                    normal: n2,
                },
            ) => normal.dot(n2) >= cos && (o2 - origin).dot(normal).abs() <= tol,
            (
                Surface::Cylinder {
                    origin,
                    axis,
                    radius,
                    convex,
                },
                Surface::Cylinder {
                    origin: o2,
                    axis: a2,
                    radius: r2,
                    convex: c2,
                },
            ) => {
                convex == c2
                    && axis.dot(a2).abs() >= cos
                    && (radius - r2).abs() <= tol
                    && off_line(o2, origin, axis) <= tol
            }
            (
                Surface::Cone {
                    apex,
                    axis,
                    half_angle,
                    convex,
                },
                Surface::Cone {
                    apex: p2,
                    axis: a2,
                    half_angle: h2,
                    convex: c2,
                },
            ) => {
                convex == c2
                    && axis.dot(a2) >= cos
                    && (half_angle - h2).abs() <= SAME_SURFACE_DEG.to_radians()
                    && (apex - p2).norm() <= tol
            }
            (
                Surface::Sphere {
                    center,
                    radius,
                    convex,
                },
                Surface::Sphere {
                    center: c2,
                    radius: r2,
                    convex: x2,
                },
            ) => convex == x2 && (radius - r2).abs() <= tol && (center - c2).norm() <= tol,
            _ => false,
        }
    }

    /// The surface type.
    pub fn kind(&self) -> model::SurfaceKind {
        match self {
            Surface::Plane { .. } => model::SurfaceKind::Plane,
            Surface::Cylinder { .. } => model::SurfaceKind::Cylinder,
            Surface::Cone { .. } => model::SurfaceKind::Cone,
            Surface::Sphere { .. } => model::SurfaceKind::Sphere,
            Surface::Freeform => model::SurfaceKind::Freeform,
        }
    }

    /// Distance from a point to the surface (mm); `None` for free-form faces.
    pub fn distance(&self, p: &P3) -> Option<f64> {
        Some(match self {
            Surface::Plane { origin, normal } => (p - origin).dot(normal).abs(),
            Surface::Cylinder {
                origin,
                axis,
                radius,
                ..
            } => {
                let d = p - origin;
                ((d - axis * d.dot(axis)).norm() - radius).abs()
            }
            Surface::Cone {
                apex,
                axis,
                half_angle,
                ..
            } => {
                let d = p - apex;
                let h = d.dot(axis);
                let r = (d - axis * h).norm();
                // Distance to the cone's generator line in the (h, r) half-plane.
                (r * half_angle.cos() - h * half_angle.sin()).abs()
            }
            Surface::Sphere { center, radius, .. } => ((p - center).norm() - radius).abs(),
            Surface::Freeform => return None,
        })
    }

    /// The solid's outward unit normal at (the projection of) `p`; `None` for free-form
    /// faces or on an axis.
    pub fn normal_at(&self, p: &P3) -> Option<V3> {
        let flip = |v: V3, convex: bool| if convex { v } else { -v };
        match self {
            Surface::Plane { normal, .. } => Some(*normal),
            Surface::Cylinder {
                origin,
                axis,
                convex,
                ..
            } => {
                let d = p - origin;
                let radial = d - axis * d.dot(axis);
                radial.try_normalize(1e-12).map(|r| flip(r, *convex))
            }
            Surface::Cone {
                apex,
                axis,
                half_angle,
                convex,
            } => {
                let d = p - apex;
                let radial = (d - axis * d.dot(axis)).try_normalize(1e-12)?;
                let n = radial * half_angle.cos() - axis * half_angle.sin();
                Some(flip(n, *convex))
            }
            Surface::Sphere { center, convex, .. } => {
                (p - center).try_normalize(1e-12).map(|r| flip(r, *convex))
            }
            Surface::Freeform => None,
        }
    }
}

/// Identifies a face of a [`PartGeometry`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct FaceId(pub usize);

/// One face: a named, connected set of triangles on one surface.
#[derive(Debug, Clone)]
pub struct Face {
    /// `stock.top`, `grid[3].wall`, `face_12` or `segment_4`.
    pub name: String,
    /// Its surface.
    pub surface: Surface,
    /// Indices into [`PartGeometry::triangles`].
    pub triangles: Vec<u32>,
    /// Area (mm²).
    pub area: f64,
    /// Area-weighted centroid.
    pub centroid: P3,
    /// For mesh faces: RMS distance of the vertices to the fitted surface (mm).
    pub fit_rms: f64,
}

/// A part's evaluated geometry.
#[derive(Debug, Clone)]
pub struct PartGeometry {
    /// Vertex positions (mm, part frame).
    pub vertices: Vec<P3>,
    /// Triangles, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
    /// The face of each triangle.
    pub tri_face: Vec<u32>,
    /// The faces.
    pub faces: Vec<Face>,
    /// For constructive parts, per face: whose face it is and the roles it answers to
    /// (`walls`, `left_wall`, …); empty for mesh parts.
    pub roles: Vec<(model::FaceSource, Vec<model::Role>)>,
    /// For parts read from a CAD file, each face's id in the file.
    pub cad: Option<CadFaces>,
}

/// The ids a CAD file gives its faces, one per face of the part in order: STEP instance
/// numbers or QIF ids (what `step_face N` and `qif_face N` name).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CadFaces {
    /// The kind of file.
    pub kind: model::CadKind,
    /// Per face, its id.
    pub ids: Vec<u64>,
}

impl PartGeometry {
    /// Whether faces `a` and `b` lie on one surface (the same face, or
    /// [`Surface::same_as`]): the faces a feature measures as one.
    pub fn same_surface(&self, a: FaceId, b: FaceId) -> bool {
        a == b || self.faces[a.0].surface.same_as(&self.faces[b.0].surface)
    }

    /// Whether two faces of one feature are pieces of one surface to measure: coplanar
    /// planes (pads at one height are one plane), and a curved surface's pieces that
    /// touch (a bore the B-rep splits in two halves along a seam) — not two holes that
    /// are merely coaxial (blind holes facing each other across a sphere: each a hole of
    /// its own, with its own size).
    pub fn one_surface(&self, a: FaceId, b: FaceId) -> bool {
        a == b
            || (self.same_surface(a, b)
                && (matches!(self.faces[a.0].surface, Surface::Plane { .. })
                    || self.faces_touch(a, b)))
    }

    /// Whether two faces share a point of their boundaries (to 1 µm).
    fn faces_touch(&self, a: FaceId, b: FaceId) -> bool {
        let key = |p: &P3| {
            (
                (p.x * 1e3).round() as i64,
                (p.y * 1e3).round() as i64,
                (p.z * 1e3).round() as i64,
            )
        };
        let corners = |f: FaceId| {
            self.faces[f.0]
                .triangles
                .iter()
                .flat_map(|&t| self.triangles[t as usize])
                .map(|v| key(&self.vertices[v as usize]))
                .collect::<std::collections::HashSet<_>>()
        };
        let (ca, cb) = (corners(a), corners(b));
        ca.iter().any(|k| cb.contains(k))
    }

    /// Assembles faces from per-triangle face indices, computing areas and centroids.
    pub(crate) fn new(
        vertices: Vec<P3>,
        triangles: Vec<[u32; 3]>,
        tri_face: Vec<u32>,
        specs: Vec<(String, Surface)>,
    ) -> Self {
        let mut faces: Vec<Face> = specs
            .into_iter()
            .map(|(name, surface)| Face {
                name,
                surface,
                triangles: vec![],
                area: 0.0,
                centroid: P3::origin(),
                fit_rms: 0.0,
            })
            .collect();
        let mut sums = vec![V3::zeros(); faces.len()];
        for (t, tri) in triangles.iter().enumerate() {
            let f = tri_face[t] as usize;
            let [a, b, c] = tri.map(|i| vertices[i as usize]);
            let area = (b - a).cross(&(c - a)).norm() / 2.0;
            faces[f].triangles.push(t as u32);
            faces[f].area += area;
            sums[f] += (a.coords + b.coords + c.coords) / 3.0 * area;
        }
        for (f, face) in faces.iter_mut().enumerate() {
            if face.area > 0.0 {
                face.centroid = P3::from(sums[f] / face.area);
            }
        }
        PartGeometry {
            vertices,
            triangles,
            tri_face,
            faces,
            roles: Vec::new(),
            cad: None,
        }
    }

    /// The axis-aligned bounds of all vertices.
    pub fn bounds(&self) -> (P3, P3) {
        let mut lo = P3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY);
        let mut hi = P3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY);
        for v in &self.vertices {
            lo = lo.inf(v);
            hi = hi.sup(v);
        }
        (lo, hi)
    }
}

/// Evaluates a part's geometry. The entry point of the geometry stage. Diagnostics
/// point at the part's declaration (or the mesh path).
pub fn build(
    part: &model::Part,
    world: &dyn World,
    diags: &mut Diagnostics,
) -> Option<PartGeometry> {
    match &part.geometry {
        Source::Stock(stock) => {
            let g = csg::build(part, stock, diags)?;
            let bodies = bodies(&g);
            if bodies > 1 {
                diags.push(GeometryError::SeveralBodies {
                    span: part.span,
                    part: part.name.clone(),
                    bodies,
                });
            }
            Some(g)
        }
        Source::Mesh {
            path,
            unit_mm,
            chord_mm,
            scale,
            span,
        } => {
            // The chord is the part's: a model scaled up is meshed finer in its own unit.
            let res = step::Resolution {
                chord_mm: chord_mm.unwrap_or(step::RESOLUTION.chord_mm) / scale,
                ..step::RESOLUTION
            };
            let mut raw = read_reported(world, path, *unit_mm, res, *span, diags)?;
            if *scale != 1.0 {
                raw.scale(*scale);
            }
            let uses_groups = part
                .features
                .iter()
                .flat_map(|f| &f.faces)
                .any(|r| matches!(r, model::FaceRef::Group(..)));
            let geometry = if raw.cad.is_some()
                || raw.groups.len() > 1
                || (uses_groups && !raw.groups.is_empty())
            {
                segment::from_groups(&raw)
            } else {
                segment::segment(&raw)
            };
            Some(geometry)
        }
    }
}

/// Reads a mesh file a spec names at `span`: an unreadable or corrupt file is reported
/// and gives `None`, open or non-manifold edges a warning.
pub(crate) fn read_reported(
    world: &dyn World,
    path: &std::path::Path,
    unit_mm: f64,
    res: step::Resolution,
    span: crate::source::Span,
    diags: &mut Diagnostics,
) -> Option<RawMesh> {
    let raw = match mesh_io::read_mesh_at(world, path, unit_mm, res) {
        Ok(m) => m,
        Err(e) => {
            for d in e.at(span, path) {
                diags.push(d);
            }
            return None;
        }
    };
    if raw.open_edges + raw.nonmanifold_edges > 0 {
        diags.push(GeometryError::MeshDefects {
            span,
            path: errors::shown_path(path),
            open: raw.open_edges,
            nonmanifold: raw.nonmanifold_edges,
        });
    }
    Some(raw)
}

/// How many separate bodies a part's triangles make: groups of triangles joined by
/// shared vertices (union-find over the welded vertices).
fn bodies(g: &PartGeometry) -> usize {
    let mut parent: Vec<u32> = (0..g.vertices.len() as u32).collect();
    fn root(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            parent[x as usize] = parent[parent[x as usize] as usize];
            x = parent[x as usize];
        }
        x
    }
    for t in &g.triangles {
        let a = root(&mut parent, t[0]);
        for &v in &t[1..] {
            let b = root(&mut parent, v);
            if a != b {
                parent[b as usize] = a;
            }
        }
    }
    let mut roots: Vec<u32> = g
        .triangles
        .iter()
        .map(|t| root(&mut parent, t[0]))
        .collect();
    roots.sort_unstable();
    roots.dedup();
    roots.len()
}
