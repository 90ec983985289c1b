//! lucent: a CPU path tracer for translucent materials.
//!
//! Data flows one way: [`scene::load()`] → [`accel::build`] →
//! [`integrator`] (rendered in tiles by [`render`]) → [`film`] output.

pub mod accel;
pub mod bench;
pub mod bssrdf;
pub mod film;
pub mod fresnel;
pub mod geometry;
pub mod integrator;
pub mod kernels;
pub mod lights;
pub mod materials;
pub mod plot;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod study;
