//! The command line and the library entry points end to end: `render`,
//! `plan`, `bench`, `study`, scene errors, the EXR outputs and passes,
//! the farm split and merge, sessions, and what each feature set accepts.
//! One test binary; a module whose theme is a feature is built with it.

#[path = "../common/mod.rs"]
mod common;

#[cfg(feature = "subsurface")]
mod aov;
mod bench_cli;
#[cfg(feature = "subsurface")]
mod budget;
mod cli;
mod denoise;
mod denoise_layers;
mod environment_image;
mod exr_oiio;
mod farm;
mod obj_mtl;
#[cfg(feature = "subsurface")]
mod plan;
mod region;
#[cfg(feature = "subsurface")]
mod regularize;
mod scene_errors;
mod session;
#[cfg(feature = "subsurface")]
mod study;
#[cfg(feature = "subsurface")]
mod study_convergence;
mod subsurface_feature;
mod textures;
mod transparent;
