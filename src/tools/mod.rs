//! The measuring tools: what the renderer costs and how accurate it is,
//! kept apart from the renderer so that it reads on its own.
//!
//! - [`bench`](mod@bench) (`lucent bench`): the ray-query backends side by side on
//!   generated meshes and ray sets, and (`--scene`) a render's own queries
//!   recorded and replayed on the bare backend.
//! - [`study`] (`lucent study`): the subsurface estimator's sampling
//!   choices rendered at a ladder of sample counts against a long
//!   reference: error against time.
//! - [`halfspace`]: the albedo table's generator — the random walk's
//!   physics in a plane-parallel half-space (`docs/bssrdf.md` §9).
//! - [`sphere_albedo`]: the curvature table's generator — the same physics
//!   in a sphere, against the half-space (`docs/bssrdf.md` §10).
//! - [`plot`]: the PNG canvas, font, palette and log axes both draw with.
//!
//! The rule: the tools use the renderer, never the other way round. No
//! module outside `src/tools/` (the binary's `src/main.rs` aside, which
//! runs the tools' commands) names `tools`; `tests/tools_apart.rs` checks
//! it and names the offending file and line.

pub mod bench;
#[cfg(feature = "subsurface")]
pub mod halfspace;
pub mod plot;
#[cfg(feature = "subsurface")]
pub mod sphere_albedo;
#[cfg(feature = "subsurface")]
pub mod study;
