//! Rays, orthonormal frames and triangle meshes: the geometric vocabulary
//! shared by the scene loader, both ray-query backends and the integrators;
//! and what is learned from a mesh's shape alone: its per-triangle
//! curvature ([`curvature`]), its sharp edges ([`sharp_edges`]) and which
//! of its sides is the outside of a convex body ([`convex`]), which
//! triangles share an edge ([`adjacency`]); and how far a
//! point is from the nearest triangle ([`distance`]). Nothing here
//! knows of ray-query backends, materials or the BSSRDF.
//! `adjacency`, `curvature`, `sharp_edges` and `distance` exist only with the
//! `subsurface` feature.

#[cfg(feature = "subsurface")]
pub mod adjacency;
pub mod convex;
#[cfg(feature = "subsurface")]
pub mod curvature;
#[cfg(feature = "subsurface")]
pub mod distance;
mod frame;
mod mesh;
mod ray;
#[cfg(feature = "subsurface")]
pub mod sharp_edges;

pub use frame::Frame;
pub use glam::Vec3;
pub use mesh::Mesh;
pub use ray::Ray;
