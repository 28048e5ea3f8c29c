//! Geometric kernels on plain buffers (`&[DVec3]` positions, `&[[u32; 3]]` triangles), written
//! once here and used by every crate: triangle BVH, closest point, ray cast, exact
//! triangle–triangle test, fast winding number, regular face sampling, the `Projector` trait and
//! the `Normalization` into the camera rig's sphere.
//!
//! Conventions shared by every submodule (libigl style): `positions` is #V points, `triangles`
//! is #F index triples into `positions`, a *face* is an index into `triangles`, barycentric
//! coordinates `[w0, w1, w2]` weight a face's corners in order. Functions never panic on bad
//! indices: faces that reference a missing vertex are ignored (each function says how).
//!
//! Modules: [`aabb`] (boxes), [`normalization`] (into the rig sphere and back), [`point_triangle`]
//! (one-triangle closest point and ray hit), [`bvh`] (the triangle tree), [`tri_tri`] (exact
//! triangle–triangle tests), [`filtered_tri_tri`] (the same behind certified floating-point
//! filters, for many pairs), [`self_intersections`], [`sampling`] (area-weighted random samples),
//! [`winding`] (fast winding numbers, and the Morton order batched queries visit points in),
//! [`regular_sampling`] (regular per-face grids), [`projector`] (the `Projector` trait),
//! [`ray_projector`] (exact ray-cast projection), [`triangle`] (one triangle's normal, angles and
//! aspect ratio), [`vertex_normals`](mod@vertex_normals) (vertex normals by named weightings),
//! [`sdf`] (the `Sdf` trait of signed distance inputs), [`isosurface`] (marching tetrahedra over a
//! grid of values).

pub mod aabb;
pub mod bvh;
pub mod filtered_tri_tri;
pub mod isosurface;
pub mod normalization;
pub mod point_triangle;
pub mod projector;
pub mod ray_projector;
pub mod regular_sampling;
pub mod sampling;
pub mod sdf;
pub mod self_intersections;
pub mod tri_tri;
pub mod triangle {
    //! One triangle's shape (normal, angles, aspect ratio, the degenerate-face constants). The
    //! code lives in the crate's private `triangle` module, below both the mesh and these kernels.
    pub use crate::triangle::*;
}
pub mod vertex_normals;
pub mod winding;

pub use aabb::Aabb;
pub use bvh::{CertifiedClosest, ClosestPoint, RayHit, TriangleBvh};
pub use filtered_tri_tri::{
    PreparedFace, certainly_apart, faces_intersect_filtered, fan_is_embedded,
};
pub use isosurface::marching_tetrahedra;
pub use normalization::{Normalization, RIG_RADIUS};
pub use point_triangle::{closest_point_on_triangle, ray_triangle};
pub use projector::{Projector, SphereProjector};
pub use ray_projector::{RayCastProjector, RayProjectorOptions};
pub use regular_sampling::{
    RegularSamples, RegularSamplingError, RegularSamplingOptions, SamplePoints, face_grid,
    grid_point_count, regular_sample_points, regular_sample_points_into, regular_samples,
};
pub use sampling::{SurfaceSamples, sample_surface};
pub use sdf::{
    FnSdf, Sdf, SdfCounter, SdfEvaluations, evaluate_with_gradients, first_order_distances,
    first_order_step, project_to_zero_set,
};
pub use self_intersections::{
    count_intersecting_faces, face_intersects_any, intersecting_pairs, self_intersecting_faces,
};
pub use tri_tri::{faces_intersect, segment_intersects_triangle, triangles_intersect};
pub use triangle::{corner_angles, triangle_normal, triangle_quality};
pub use vertex_normals::{area_angle_weights, area_weighted_vertex_normals, vertex_normals};
pub use winding::{
    TriangleIndexError, WindingNumber, WindingNumberOptions, exact_winding_number, morton_order,
    triangle_solid_angle,
};
