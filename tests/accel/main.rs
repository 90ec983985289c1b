//! Ray-query backends: our BVH against brute force, Embree 3 and 4
//! against our BVH (queries and whole renders), and the Embree bindings
//! (struct layouts). One test binary; the Embree modules exist only with
//! their feature (without it they do not exist, rather than pass). Scene
//! lifetime (process-wide counters and RSS) is its own binary,
//! tests/embree_lifetime.rs.

#[path = "../common/mod.rs"]
mod common;

#[cfg(feature = "embree")]
mod backend_equivalence;
#[cfg(feature = "embree")]
mod backend_render;
mod bvh_brute_force;
#[cfg(feature = "embree4")]
mod embree4_layout;
#[cfg(feature = "embree")]
mod embree_layout;
