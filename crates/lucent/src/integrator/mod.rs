//! Integrators: estimators of the radiance arriving at the camera.
//!
//! [`path`] is the unidirectional path tracer with next-event estimation
//! and multiple importance sampling; [`randomwalk`] the brute-force
//! volumetric reference for subsurface materials ([`kind`] picks one),
//! [`diffuse_boundary`] its optional diffuse Fresnel boundary, [`walk_nee`]
//! its light sampling through the smooth one. Both read a
//! [`context`] built once per render. [`plan`] decides once per scene which
//! effects exist; [`interaction`] turns an accel hit into local surface
//! geometry; [`probe`] runs the BSSRDF's probe query and
//! [`control_variate`] is its plane control variate; [`footprint`] is the
//! path's ray cone; [`culling`] answers rays proven to meet nothing;
//! [`aov`] records what the passes measure; [`effects`] (with [`crate::stats`])
//! tally ray queries and time per effect for `--stats`; `texturing` reads
//! a textured material's parameters at a hit. `probe`,
//! `control_variate`, `randomwalk`, `diffuse_boundary` and `walk_nee` exist only with
//! the `subsurface` feature (the default).

mod analytic_nee;
pub mod aov;
mod branch;
#[cfg(feature = "subsurface")]
mod budgeted;
#[cfg(feature = "subsurface")]
mod coated;
pub mod context;
#[cfg(feature = "subsurface")]
pub mod control_variate;
pub mod culling;
#[cfg(feature = "subsurface")]
pub mod diffuse_boundary;
pub mod effects;
mod env_nee;
pub mod footprint;
mod glossy;
mod hit_material;
pub mod interaction;
pub mod kind;
mod lobe;
mod nee;
pub mod path;
#[cfg(feature = "subsurface")]
pub mod phase;
pub mod plan;
#[cfg(feature = "subsurface")]
pub mod probe;
#[cfg(feature = "subsurface")]
pub mod randomwalk;
mod scatter;
mod state;
#[cfg(feature = "subsurface")]
mod subsurface;
mod texturing;
#[cfg(feature = "subsurface")]
pub mod walk_nee;

pub use crate::stats::{Counters, Effect, EFFECTS};
pub use context::Context;
pub use effects::{Clock, NoClock, Stopwatch};
pub use interaction::Interaction;
pub use kind::IntegratorKind;
pub use plan::Plan;
