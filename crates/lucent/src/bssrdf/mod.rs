//! Christensen–Burley normalized diffusion BSSRDF ("Approximate Reflectance
//! Profiles for Efficient Subsurface Scattering", Pixar TR 15-04, 2015),
//! sampled with probe rays (King et al. 2013; pbrt-v3 §15.4). The math is
//! restated, with the course report's errors corrected, in `docs/bssrdf.md`;
//! how an integrator calls this module, step by step: §12.4.
//!
//! [`profile`] R(r) and its inverse; [`profile_table`] and [`tabulated`]
//! the half-space's own R(r), by the random walk, in its place; [`params`] parameters → per-channel
//! (A, d); [`albedo_table`] and [`dipole`] the A a medium reflects;
//! [`curvature_table`] and [`curvature_correction`] the convex-body factor;
//! [`radius`] the radius samplers; [`probe`] probe segments and hit
//! weights; [`density`] the density of an entry point; [`fresnel_moment`]
//! Ft and the exit lobe Sw. S = C·Ft(xi, wi)·Rd(|xo − xi|)·Ft(xo, wo) with
//! Rd = A·R; the integrator applies the directional factors. This module
//! imports nothing from the accel, the integrator or the materials: the
//! integrator's `probe` module runs the query.

pub mod albedo_table;
pub mod curvature_correction;
pub mod curvature_table;
pub mod density;
pub mod dipole;
pub mod error_model;
pub mod fresnel_moment;
pub mod params;
pub mod probe;
pub mod profile;
pub mod profile_table;
pub mod radius;
pub mod tabulated;

pub use fresnel_moment::{sw, sw_normalization, transmittance};
pub use params::{AlbedoSource, Measured, Preset, SubsurfaceParams, PRESETS};
pub use probe::{
    pick_by_score, ChannelStrategy, PlaneModel, ProbeAxes, ProbeEntry, ProbeOptions, ProbeRandoms,
    ProbeSampler, ProbeSegment, ProfileShape,
};
pub use profile::Fit;
pub use radius::{RadialDist, RadiusSampler, TableSpacing};
