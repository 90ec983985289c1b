//! lucent's measuring tools: what the renderer costs and how accurate it
//! is, in a crate of their own so the renderer library reads (and builds)
//! without them.
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
//! - [`sphere_transfer`]: where light entering a sphere at one point
//!   leaves it, by chord distance — the diffusion profile's ground truth
//!   on a curved body (`docs/bssrdf.md` §10).
//! - [`profile_table`]: the tabulated profile's generator — where light
//!   entering the half-space leaves it, by distance (`docs/bssrdf.md` §10).
//! - [`table_file`]: the command line and the CSV output the table
//!   generators share.
//! - [`plot`]: the PNG canvas, font, palette and log axes both draw with.
//! - [`progress`]: a render's [`lucent::progress::Progress`] drawn as a bar
//!   on stderr (indicatif).
//!
//! The tools use the renderer, never the other way round: the library
//! `lucent` does not depend on this crate.

pub mod bench;
#[cfg(feature = "subsurface")]
pub mod halfspace;
pub mod image_sets;
pub mod plot;
#[cfg(feature = "subsurface")]
pub mod profile_table;
pub mod progress;
#[cfg(feature = "subsurface")]
pub mod sphere_albedo;
#[cfg(feature = "subsurface")]
pub mod sphere_transfer;
#[cfg(feature = "subsurface")]
pub mod study;
pub mod table_file;
