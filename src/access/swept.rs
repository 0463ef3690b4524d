//! A flat-ended cylinder swept along a straight move, as a parry support map.
//!
//! The path stage sweeps the body, head and ram as the convex hull of their two end
//! positions (the discs as circumscribed polygons). That hull is the Minkowski sum of the
//! polygonal prism and the move's segment, whose support function is the prism's plus
//! the segment's: no hull needs building. Building one with parry's quickhull for every
//! move and component was half of the path stage on the NIST parts; the support map
//! answers the same GJK tests with the same geometry.

use crate::geometry::{P3, V3};
use parry3d_f64::bounding_volume::{Aabb, BoundingSphere};
use parry3d_f64::mass_properties::MassProperties;
use parry3d_f64::math::{Isometry, Real};
use parry3d_f64::query::details::local_ray_intersection_with_support_map_with_params;
use parry3d_f64::query::gjk::VoronoiSimplex;
use parry3d_f64::query::point::local_point_projection_on_support_map;
use parry3d_f64::query::{PointProjection, PointQuery, Ray, RayCast, RayIntersection};
use parry3d_f64::shape::{ConvexPolyhedron, FeatureId, Shape, ShapeType, SupportMap, TypedShape};

/// The convex hull of a point set and that set moved by `v`: the points' support plus
/// the move's.
#[derive(Debug, Clone)]
pub(crate) struct SweptHull {
    /// The shape at the start of the move (its vertices; interior points do no harm).
    pub points: Vec<P3>,
    /// The move.
    pub v: V3,
}

impl SweptHull {
    fn all_points(&self) -> Vec<P3> {
        let mut all = self.points.clone();
        all.extend(self.points.iter().map(|p| p + self.v));
        all
    }
}

impl SupportMap for SweptHull {
    fn local_support_point(&self, dir: &V3) -> P3 {
        let mut best = self.points[0];
        let mut at = best.coords.dot(dir);
        for p in &self.points[1..] {
            let d = p.coords.dot(dir);
            if d > at {
                at = d;
                best = *p;
            }
        }
        if self.v.dot(dir) > 0.0 {
            best + self.v
        } else {
            best
        }
    }
}

impl RayCast for SweptHull {
    fn cast_local_ray_and_get_normal(
        &self,
        ray: &Ray,
        max_time_of_impact: Real,
        solid: bool,
    ) -> Option<RayIntersection> {
        local_ray_intersection_with_support_map_with_params(
            self,
            &mut VoronoiSimplex::new(),
            ray,
            max_time_of_impact,
            solid,
        )
    }
}

impl PointQuery for SweptHull {
    fn project_local_point(&self, point: &P3, solid: bool) -> PointProjection {
        local_point_projection_on_support_map(self, &mut VoronoiSimplex::new(), point, solid)
    }

    fn project_local_point_and_get_feature(&self, point: &P3) -> (PointProjection, FeatureId) {
        (self.project_local_point(point, false), FeatureId::Unknown)
    }
}

impl Shape for SweptHull {
    fn compute_local_aabb(&self) -> Aabb {
        let mut aabb = Aabb::from_points(self.points.iter().copied());
        aabb.take_point(aabb.mins + self.v);
        aabb.take_point(aabb.maxs + self.v);
        aabb
    }

    fn compute_local_bounding_sphere(&self) -> BoundingSphere {
        self.compute_local_aabb().bounding_sphere()
    }

    fn clone_dyn(&self) -> Box<dyn Shape> {
        Box::new(self.clone())
    }

    fn scale_dyn(
        &self,
        scale: &parry3d_f64::math::Vector<Real>,
        _num_subdivisions: u32,
    ) -> Option<Box<dyn Shape>> {
        Some(Box::new(SweptHull {
            points: self
                .points
                .iter()
                .map(|p| P3::from(p.coords.component_mul(scale)))
                .collect(),
            v: self.v.component_mul(scale),
        }))
    }

    /// The hull's own (queries never ask; built on demand, so it costs nothing there).
    fn mass_properties(&self, density: Real) -> MassProperties {
        match ConvexPolyhedron::from_convex_hull(&self.all_points()) {
            Some(hull) => hull.mass_properties(density),
            None => MassProperties::from_cuboid(density, self.compute_local_aabb().half_extents()),
        }
    }

    fn is_convex(&self) -> bool {
        true
    }

    fn shape_type(&self) -> ShapeType {
        ShapeType::Custom
    }

    fn as_typed_shape(&self) -> TypedShape<'_> {
        TypedShape::Custom(self)
    }

    fn ccd_thickness(&self) -> Real {
        self.compute_local_aabb().half_extents().min()
    }

    fn ccd_angular_thickness(&self) -> Real {
        std::f64::consts::FRAC_PI_4
    }

    fn as_support_map(&self) -> Option<&dyn SupportMap> {
        Some(self as &dyn SupportMap)
    }

    fn compute_aabb(&self, position: &Isometry<Real>) -> Aabb {
        self.compute_local_aabb().transform_by(position)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d_f64::query::intersection_test;
    use parry3d_f64::shape::Cuboid;

    /// The support map answers what the built hull answers.
    #[test]
    fn same_as_the_hull() {
        let points: Vec<P3> = (0..16)
            .flat_map(|k| {
                let t = std::f64::consts::TAU * k as f64 / 16.0;
                let e = V3::new(t.cos(), t.sin(), 0.0) * 3.0;
                [P3::from(e), P3::from(e) + V3::z() * 10.0]
            })
            .collect();
        let swept = SweptHull {
            points,
            v: V3::new(20.0, 5.0, 0.0),
        };
        let hull = ConvexPolyhedron::from_convex_hull(&swept.all_points()).unwrap();
        let id = Isometry::identity();
        let cube = Cuboid::new(V3::new(1.0, 1.0, 1.0));
        for x in -6..30 {
            for y in -6..12 {
                let at = Isometry::translation(x as f64, y as f64, 5.0);
                let a = intersection_test(&at, &cube, &id, &swept).unwrap();
                let b = intersection_test(&at, &cube, &id, &hull).unwrap();
                assert_eq!(a, b, "box at ({x}, {y})");
            }
        }
    }
}
