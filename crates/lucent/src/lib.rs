//! lucent: a CPU path tracer for translucent materials.
//!
//! Data flows one way: [`scene::load()`] → [`accel::build`] →
//! [`integrator`] (rendered in tiles by [`render`]) → [`film`] output.
//!
//! The measuring tools — `lucent bench`, `lucent study` and their plots —
//! are the crate `lucent-tools`; the command line is the package
//! `lucent-cli`. This library draws nothing on the terminal: a render
//! reports its progress through [`progress::Progress`].

pub mod accel;
pub mod analytic_lights;
#[cfg(feature = "subsurface")]
pub mod bssrdf;
pub mod denoise;
mod dynlib;
pub mod environment;
pub mod error;
pub mod farm;
pub mod film;
pub mod fresnel;
pub mod geometry;
pub mod integrator;
pub mod interrupt;
pub mod kernels;
pub mod lights;
pub mod materials;
pub mod memory;
pub mod progress;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod session;
pub mod stats;
pub mod texture;

pub use error::Error;
