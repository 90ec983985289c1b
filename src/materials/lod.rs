//! Subsurface level of detail: where a path's sample stands for a patch of
//! surface far wider than the subsurface profile, shade the hit as a
//! Lambertian-like lobe with albedo A at xo instead of probing for xi.
//!
//! **Why the image is the same.** The diffusion estimator at an exit point
//! xo (`crate::integrator::path`) is, after the coat,
//!
//! ```text
//! L(xo) = Ft(xo, ωo) ∫_A Rd(|xo − xi|) E(xi) dA(xi),
//! E(xi) = ∫ Sw(ωi) L(xi, ωi) cos θi dωi,
//! ```
//!
//! the entry lobe Sw (or 1/π, or the rough coat's (1 − E(μ))/((1 − Ē)π))
//! integrating to 1 against cos θ. Where E is the same over the profile's
//! support (flat surface, light that does not change within Rmax) E comes
//! out of the integral and what is left is the profile's plane integral,
//! ∫_A Rd dA = 2π ∫₀^Rmax Rd(r) r dr = A·CDF(Rmax) per channel (A exactly
//! when renormalizing; `ProbeSampler::planar_reflectance`). So
//!
//! ```text
//! L_lod(xo) = Ft(xo, ωo) · A_plane · E(xo)
//! ```
//!
//! is the full estimator's mean: the same coat at xo (Fr or E(μo) and its
//! complement, untouched), the same entry lobe, now at xo, and the probe
//! weight Rd/p — whose mean is A_plane on a plane — replaced by A_plane
//! itself. On a flat, uniformly lit surface the two agree exactly (the
//! slab tests check it, smooth and rough coat). Where E varies within the
//! profile they differ by how much light the profile carries across the
//! footprint's edge: with mean radius r̄ = 2.5·d of the Burley profile
//! (∫ r · (e^{−r/d} + e^{−r/3d})/(4d) dr), a pixel of width W ≫ r̄ collects
//! the same light but for a fraction ~ r̄/W that moved in or out through
//! its border, and that fraction also cancels in the mean wherever light
//! changes linearly. Rmax = 19.86·d (quantile 0.999), so at the default
//! threshold W ≥ ¼ Rmax ≈ 5d = 2 r̄ that fraction is ≲ ½ of the light step
//! at a hard shadow edge crossing the footprint, and far less under smooth
//! light; measured on the marble bunny close-up the default changes the
//! image's mean by 0.02 % (its 2σ noise: 0.16 %), docs/accuracy.md.
//!
//! **Curvature.** On a convex body the full estimator's mean is f(κ)·g(R)
//! times A_plane (`crate::bssrdf::curvature_correction`): g(R) =
//! CDF(min(2R, Rmax))/CDF(Rmax) is the part of the profile the body is too
//! small to hold, f the correction for what the medium really returns. The
//! LOD rule only fires where κ·Rmax ≤ [`MAX_KAPPA_RMAX`] = 2, i.e. 2R ≥
//! Rmax, where g = 1 exactly, and multiplies A_plane by f(κo) when the
//! correction is on: the LOD weight is then the full estimator's mean on a
//! sphere as well. At the scales LOD is for f is ≈ 1 anyway: κ·d ≤ 2/19.86
//! ≈ 0.1, where the sphere returns within a few per cent of the half-space.
//! κ here is the probe's exit curvature (floored at 1/bounding radius), so
//! a flat-shaded small object counts as curved.
//!
//! **The footprint** ([`Cone`]): the width of the surface one sample of a
//! path stands for, carried along the path as a ray cone (Amanatides 1984;
//! Akenine-Möller et al. 2019, "Texture level of detail strategies for
//! real-time ray tracing"): width w and spread angle γ, w(t) = w₀ + γ·t.
//! - Camera rays: w₀ = 0 (pinhole), γ = the angle one pixel subtends along
//!   the ray, 2·tan(fov/2)/height · cos²θ at angle θ off the axis (the
//!   film's pixel pitch seen obliquely; the cos² is the smaller of the two
//!   directions' factors cos² and cos, so the cone is never wider than the
//!   pixel).
//! - Specular and dielectric bounces (the smooth coat's mirror, and the
//!   rough coat's reflection too): the cone continues with the same γ from
//!   the width it reached. This ignores the surface's curvature, which
//!   widens the cone off a convex mirror and narrows it off a concave one
//!   (the approximation of Akenine-Möller et al.'s "ray cones" without the
//!   curvature term); refraction's change of angle is ignored likewise.
//! - Non-specular bounces (diffuse, the subsurface entry lobe, LOD itself):
//!   γ becomes max(γ, [`ROUGH_SPREAD`]). A cosine lobe spreads the
//!   directions one sample stands for over ~1 rad (the mean angle of its
//!   directions to the normal is ∫ θ sin 2θ dθ = π/4 ≈ 0.79 rad); the
//!   radiance it gathers is blurred by that lobe, so detail
//!   narrower than ~1 rad × distance cannot show. [`ROUGH_SPREAD`] takes a
//!   tenth of that, 0.1 rad: conservative, it underestimates the footprint
//!   by ~10×, so LOD after a bounce triggers less, never more, than the
//!   lobe's blur would justify. The width never shrinks: w continues from
//!   the vertex and γ only grows.
//!
//! **Cost.** Two f32 per path (w, γ), one multiply-add per hit; the rule
//! at a subsurface hit is two comparisons. Under LOD a hit casts no probe
//! ray, adds no control variate and samples no antithetic pair: light is
//! sampled once at xo.

use crate::geometry::Vec3;

/// The footprint-to-Rmax ratio above which [`LodMode::Auto`] shades a
/// subsurface hit with the LOD lobe, unless the material sets its own
/// (`lod_threshold`). Chosen by measurement (`docs/accuracy.md`, "Subsurface
/// level of detail").
pub const DEFAULT_THRESHOLD: f32 = 0.25;

/// LOD only where the surface's curvature κ (the probe's exit curvature)
/// satisfies κ·Rmax ≤ this: 2R ≥ Rmax, so the whole profile fits on the
/// body and the flat-surface argument holds up to f(κ) (module docs).
pub const MAX_KAPPA_RMAX: f32 = 2.0;

/// The spread angle (radians) a non-specular bounce gives the footprint
/// cone at least: a tenth of a cosine lobe's ~1 rad (module docs).
pub const ROUGH_SPREAD: f32 = 0.1;

/// Whether a subsurface material may be shaded with the LOD lobe.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LodMode {
    /// Where the footprint is at least `lod_threshold` × Rmax and the
    /// surface is flat at the profile's scale (the default).
    #[default]
    Auto,
    /// Never: always the probe estimator.
    Off,
    /// At every hit (for tests and measurements; command line only).
    Force,
}

impl LodMode {
    /// "auto" or "off" (case-insensitive), as a scene may give it.
    pub fn parse_scene(s: &str) -> Option<Self> {
        match s.to_ascii_lowercase().as_str() {
            "auto" => Some(LodMode::Auto),
            "off" => Some(LodMode::Off),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            LodMode::Auto => "auto",
            LodMode::Off => "off",
            LodMode::Force => "force",
        }
    }
}

/// A material's LOD rule, built once with it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LodRule {
    pub mode: LodMode,
    /// The footprint-to-Rmax ratio at which `Auto` switches.
    pub threshold: f32,
    /// The footprint width (scene units) from which `Auto` switches:
    /// threshold × Rmax.
    min_width: f32,
    /// The largest curvature at which `Auto` switches:
    /// [`MAX_KAPPA_RMAX`] / Rmax.
    max_kappa: f32,
    /// What LOD multiplies the throughput by: the profile's plane
    /// integral per channel, A·CDF(Rmax) (A when renormalizing).
    pub albedo: Vec3,
}

impl LodRule {
    /// The rule for a material whose probe sphere has radius `rmax` and
    /// whose probe estimator converges to `planar` on a plane.
    pub fn new(mode: LodMode, threshold: f32, rmax: f64, planar: [f64; 3]) -> Self {
        let rmax = rmax as f32;
        LodRule {
            mode,
            threshold,
            min_width: threshold * rmax,
            max_kappa: if rmax > 0.0 {
                MAX_KAPPA_RMAX / rmax
            } else {
                f32::INFINITY
            },
            albedo: Vec3::new(planar[0] as f32, planar[1] as f32, planar[2] as f32),
        }
    }

    /// Whether a hit whose footprint is `width` wide, on a surface of exit
    /// curvature `kappa`, is shaded with the LOD lobe.
    #[inline]
    pub fn applies(&self, width: f32, kappa: f32) -> bool {
        match self.mode {
            LodMode::Off => false,
            LodMode::Force => true,
            LodMode::Auto => width >= self.min_width && kappa <= self.max_kappa,
        }
    }

    /// What the render plan says about this rule: whether LOD can trigger,
    /// the footprint width (scene units) it triggers from, and why.
    pub fn decision(&self) -> LodDecision {
        let (can_trigger, min_width, reason) = match self.mode {
            LodMode::Off => (false, None, "lod = \"off\"".to_string()),
            LodMode::Force => (
                true,
                Some(0.0),
                "--lod force: every hit shaded as albedo A".to_string(),
            ),
            LodMode::Auto if self.albedo == Vec3::ZERO => (
                false,
                None,
                "no active channel (A = 0): nothing to shade".to_string(),
            ),
            LodMode::Auto => (
                true,
                Some(self.min_width),
                format!(
                    "auto: where the path's footprint is ≥ {} × Rmax = {:e} scene units \
                     and the surface's curvature ≤ {:e}",
                    self.threshold, self.min_width, self.max_kappa
                ),
            ),
        };
        LodDecision {
            can_trigger,
            min_width,
            reason,
        }
    }
}

/// The LOD part of a material's render plan.
#[derive(Clone, Debug, PartialEq)]
pub struct LodDecision {
    /// Whether any hit on the material can be shaded with the LOD lobe.
    pub can_trigger: bool,
    /// The footprint width (scene units) from which it is, when it can.
    pub min_width: Option<f32>,
    /// Why, for the plan's text.
    pub reason: String,
}

/// A ray cone: the footprint one path sample stands for (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    /// Width at the ray's origin (scene units).
    pub width: f32,
    /// Spread angle (radians): the width grows by this per unit distance.
    pub spread: f32,
}

impl Cone {
    /// The cone of a camera ray with unit direction `d`: from a point,
    /// spreading by the pixel's angle along `d`.
    pub fn camera(cam: &CameraSpread, d: Vec3) -> Cone {
        let c = d.dot(cam.forward).max(0.0);
        Cone {
            width: 0.0,
            spread: cam.pixel_angle * c * c,
        }
    }

    /// The footprint width at distance `t` along the ray (unit direction).
    #[inline]
    pub fn width_at(&self, t: f32) -> f32 {
        self.width + self.spread * t
    }

    /// The cone after a specular bounce at distance `t`: same spread.
    #[inline]
    pub fn specular(&self, t: f32) -> Cone {
        Cone {
            width: self.width_at(t),
            spread: self.spread,
        }
    }

    /// The cone after a non-specular bounce at distance `t`: the spread
    /// becomes at least [`ROUGH_SPREAD`]; never narrower.
    #[inline]
    pub fn rough(&self, t: f32) -> Cone {
        Cone {
            width: self.width_at(t),
            spread: self.spread.max(ROUGH_SPREAD),
        }
    }
}

/// What a camera ray's cone is built from: the angle one pixel subtends on
/// the axis and the axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSpread {
    pub pixel_angle: f32,
    pub forward: Vec3,
}

impl CameraSpread {
    /// For a pinhole camera with vertical field of view `fov_y` degrees and
    /// `height` pixels looking along `forward`: the pixel pitch on a film
    /// at unit distance, 2·tan(fov/2)/height.
    pub fn new(fov_y: f32, height: u32, forward: Vec3) -> Self {
        CameraSpread {
            pixel_angle: 2.0 * (fov_y.to_radians() * 0.5).tan() / height.max(1) as f32,
            forward: forward.normalize(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The names the EXR header records (`sampling_description`) are the
    /// values the scene format (auto, off) and the command line
    /// (`--lod force`) take: a scene's `lod` read back gives its mode.
    #[test]
    fn mode_names_are_the_values_a_scene_and_the_command_line_take() {
        for m in [LodMode::Auto, LodMode::Off] {
            assert_eq!(LodMode::parse_scene(m.name()), Some(m));
            assert_eq!(LodMode::parse_scene(&m.name().to_uppercase()), Some(m));
        }
        assert_eq!(LodMode::Force.name(), "force");
        assert_eq!(LodMode::parse_scene("force"), None);
    }

    #[test]
    fn primary_footprint_is_the_pixel_cone_width() {
        // 90° fov, 100 px high: one pixel at distance 1 is 2/100 wide; a
        // plane 7 units down the axis is seen with footprint 0.14.
        let cam = CameraSpread::new(90.0, 100, Vec3::new(0.0, 0.0, -2.0));
        let cone = Cone::camera(&cam, Vec3::new(0.0, 0.0, -1.0));
        assert!((cone.width_at(7.0) - 0.14).abs() < 1e-6);
        // 60° off axis the pixel subtends cos²60° = ¼ of that angle
        let d = Vec3::new(60f32.to_radians().sin(), 0.0, -60f32.to_radians().cos());
        let off = Cone::camera(&cam, d);
        assert!((off.width_at(7.0) - 0.14 * 0.25).abs() < 1e-6);
    }

    #[test]
    fn a_diffuse_bounce_grows_the_footprint_and_never_shrinks_it() {
        let narrow = Cone {
            width: 0.01,
            spread: 0.002,
        };
        let after = narrow.rough(5.0);
        assert_eq!(after.width, narrow.width_at(5.0));
        assert_eq!(after.spread, ROUGH_SPREAD);
        assert!(after.width_at(3.0) > narrow.specular(5.0).width_at(3.0));
        // already wider than a rough lobe: kept
        let wide = Cone {
            width: 0.5,
            spread: 0.3,
        };
        assert_eq!(wide.rough(2.0).spread, 0.3);
        for t in [0.0, 0.5, 10.0] {
            assert!(wide.rough(2.0).width_at(t) >= wide.width_at(2.0));
            assert!(narrow.rough(1.0).width_at(t) >= narrow.specular(1.0).width_at(t));
        }
        // a specular bounce keeps the spread
        assert_eq!(narrow.specular(5.0).spread, narrow.spread);
    }

    #[test]
    fn the_rule_switches_at_threshold_times_rmax_on_flat_enough_surfaces() {
        let r = LodRule::new(LodMode::Auto, 2.0, 0.5, [0.5, 0.25, 0.0]);
        assert!(!r.applies(0.99, 0.0));
        assert!(r.applies(1.0, 0.0));
        // curvature: κ·Rmax ≤ 2
        assert!(r.applies(5.0, 4.0));
        assert!(!r.applies(5.0, 4.1));
        let off = LodRule {
            mode: LodMode::Off,
            ..r
        };
        assert!(!off.applies(1e9, 0.0));
        let force = LodRule {
            mode: LodMode::Force,
            ..r
        };
        assert!(force.applies(0.0, 1e9));
        assert_eq!(r.albedo, Vec3::new(0.5, 0.25, 0.0));
        let d = r.decision();
        assert!(d.can_trigger && d.min_width == Some(1.0), "{d:?}");
        assert!(!off.decision().can_trigger);
    }
}
