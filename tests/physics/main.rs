//! Physics: closed-form and reference answers the renderer must meet
//! (furnaces, slabs, dielectrics, coats, curvature, the random walk, the
//! probe estimator, level of detail, hard cases). One test binary, one
//! module per theme; a module whose theme is a feature is built with it.

#[path = "../common/mod.rs"]
mod common;

#[cfg(feature = "subsurface")]
mod albedo_table;
#[cfg(feature = "subsurface")]
mod bunny_seeds;
#[cfg(feature = "subsurface")]
mod coat;
#[cfg(feature = "subsurface")]
mod culling;
#[cfg(feature = "subsurface")]
mod curvature;
mod dielectric;
mod environment_map;
mod furnace;
mod glossy;
#[cfg(feature = "subsurface")]
mod hard_cases;
#[cfg(feature = "subsurface")]
mod heavy_tails;
#[cfg(feature = "subsurface")]
mod keylight;
mod lights;
#[cfg(feature = "subsurface")]
mod lod;
#[cfg(feature = "subsurface")]
mod non_negative;
#[cfg(feature = "subsurface")]
mod pair_on_meshes;
#[cfg(feature = "subsurface")]
mod pair_paths;
#[cfg(feature = "subsurface")]
mod params_edges;
#[cfg(feature = "subsurface")]
mod probe_pair;
#[cfg(feature = "subsurface")]
mod randomwalk;
mod roughness_textures;
#[cfg(feature = "subsurface")]
mod sampler;
#[cfg(feature = "subsurface")]
mod slab;
#[cfg(feature = "subsurface")]
mod specular_coat;
#[cfg(feature = "subsurface")]
mod subsurface_textures;
mod textures;
