//! lucent: a CPU path tracer for translucent materials.
//!
//! Data flows one way: [`scene::load()`] → [`accel::build`] →
//! [`integrator`] (rendered in tiles by [`render`]) → [`film`] output.
//!
//! The measuring tools — `lucent bench`, `lucent study` and their plots —
//! live apart in [`tools`]; the renderer modules never use them.

pub mod accel;
#[cfg(feature = "subsurface")]
pub mod bssrdf;
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
pub mod render;
pub mod sampling;
pub mod scene;
pub mod session;
pub mod stats;
pub mod tools;

pub use error::Error;
