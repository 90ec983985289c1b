//! Christensen–Burley normalized diffusion BSSRDF ("Approximate Reflectance
//! Profiles for Efficient Subsurface Scattering", Pixar TR 15-04, 2015),
//! sampled with probe rays (King et al. 2013, "BSSRDF Importance Sampling";
//! pbrt-v3 §15.4). The math is restated, with the seed's errors corrected,
//! in `docs/bssrdf.md`.
//!
//! - [`profile`]: R(r), its CDF and closed-form inverse, the s(A) fits;
//! - [`params`]: presets, measured and artist parameters → per-channel (A, d);
//! - [`albedo_table`]: what a medium behind its boundary reflects, R(α', η),
//!   the A that `params` uses by default;
//! - [`curvature_table`], [`curvature_correction`]: what a convex body
//!   returns beyond the half-space's profile, and the weight factor from
//!   the surface's curvature that restores it;
//! - [`dipole`]: the classical dipole's total diffuse reflectance;
//! - [`radius`]: the four radius samplers with their disk pdfs;
//! - [`probe`]: the probe-ray estimator: samples probe segments and weighs
//!   the hits the integrator finds on them;
//! - [`density`]: the density p(xi) and Rd of an entry point, per channel;
//! - [`fresnel_moment`]: Ft and the normalized exit lobe Sw.
//!
//! The separable BSSRDF is S = C·Ft(xi, wi)·Rd(|xo − xi|)·Ft(xo, wo) with
//! Rd = A·R; the integrator applies the directional factors.
//!
//! Use from an integrator, per material once and per path vertex:
//!
//! ```text
//! let params = SubsurfaceParams::from_preset("marble", units_per_mm, Fit::Searchlight)?;
//! let sampler = ProbeSampler::new(&params, &ProbeOptions::default())?;   // once
//! let c = sw_normalization(params.eta);                                    // once
//! // at exit point xo with shading frame `frame` on mesh `geom`, where the
//! // surface's curvature is `kappa` (geometry::curvature::exit_curvature):
//! let u = ProbeRandoms::from_rng(rng);
//! let seg = sampler.sample_probe(xo, &frame, kappa, &u)?;
//! accel.hits_on_segment(&seg.ray, seg.t_max, geom, u.seed, &mut probe_hits); // the integrator's query
//! let kept = probe_hits.hits();
//! // one hit: weigh it with the count; several: weigh each with a count of
//! // 1, keep one in proportion to its channel sum (pick_by_score), scale
//! let e = sampler.weigh(&seg, kept[0].t, mesh.face_normal(kept[0].prim), probe_hits.total())?;
//! // e.weight = Rd / pdf × hit count (RGB); light arriving at e.point
//! // through the lobe sw(cos, eta, c) contributes
//! // Ft(xo, wo) · e.weight · ∫ Li sw cos dω.
//! ```
//!
//! This module imports nothing from the accel, the integrator or the
//! materials: the integrator's `probe` module runs the query.

pub mod albedo_table;
pub mod curvature_correction;
pub mod curvature_table;
pub mod density;
pub mod dipole;
pub mod fresnel_moment;
pub mod params;
pub mod probe;
pub mod profile;
pub mod radius;

pub use fresnel_moment::{sw, sw_normalization, transmittance};
pub use params::{AlbedoSource, Measured, Preset, SubsurfaceParams, PRESETS};
pub use probe::{
    pick_by_score, ChannelStrategy, PlaneModel, ProbeAxes, ProbeEntry, ProbeOptions, ProbeRandoms,
    ProbeSampler, ProbeSegment,
};
pub use profile::Fit;
pub use radius::{RadialDist, RadiusSampler, TableSpacing};
