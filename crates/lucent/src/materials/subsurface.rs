//! The subsurface material: a smooth dielectric boundary over a medium whose
//! multiple scattering is the Christensen–Burley normalized-diffusion
//! profile (see [`crate::bssrdf`] and `docs/bssrdf.md`).
//!
//! Following a camera path, light leaves the object at xo (where the path
//! arrives) after entering at xi (found by a probe ray). The separable
//! BSSRDF splits into
//!
//!   S(xi, ωi; xo, ωo) = Ft(xo, ωo) · Rd(|xo − xi|) · Sw(ωi)
//!
//! where Ft = 1 − Fr is always applied at xo, optionally as the complement
//! of a specular reflection layer, and the lobe at xi is either the
//! normalized Fresnel lobe Sw (pbrt-v3 §11.4) or a plain cosine lobe 1/π.
//!
//! **The coat.** The boundary is smooth (`roughness` = 0, a mirror) or a
//! rough GGX dielectric ([`super::microfacet`], α = roughness²). For a rough
//! coat, Fr(μo) becomes the coat's directional albedo E(μo): the coat
//! reflects with its microfacet BRDF, and 1 − E(μo) of the light enters
//! the medium; the entry lobe becomes (1 − E(μi)) / ((1 − Ē) π) with
//! Ē = 2 ∫ E μ dμ, so that S stays reciprocal and the lobe integrates to 1
//! against cos θ. A white medium (A = 1) under a coat therefore reflects
//! E + (1 − E) = 1 of uniform light (`docs/bssrdf.md` §6). `specular`
//! says whether the coat's reflection is rendered; without it the path is
//! weighted by the transmitted fraction (1 − Fr or 1 − E) and the reflected
//! light is lost, for either roughness.

use std::sync::{Arc, OnceLock};

use super::estimator_options::{CurvatureMode, EstimatorOptions, WalkBoundary, OPTIONS};
use super::lod::{LodMode, LodRule};
use super::microfacet::{alpha_from_roughness, RoughCoat, SMOOTH_ALPHA};
use super::roughness_steps::RoughnessSteps;
use crate::bssrdf::curvature_correction::CurvatureCorrection;
use crate::bssrdf::{sw_normalization, ProbeOptions, ProbeSampler, SubsurfaceParams};
use crate::error::{Constraint, Param, ParamError};
use crate::geometry::Vec3;

/// A subsurface material: its medium, its sampling options and what is
/// derived from them once (the probe sampler, the coat, the curvature
/// correction, the LOD rule), private so that they cannot disagree.
#[derive(Clone, Debug)]
pub struct Subsurface {
    params: SubsurfaceParams,
    options: EstimatorOptions,
    probe: ProbeSampler,
    /// The rough coat, when α ≥ [`SMOOTH_ALPHA`]; None: the smooth one.
    /// Shared with the material's values at textured points ([`Self::at_point`]).
    coat: Option<Arc<RoughCoat>>,
    /// The coat after a non-specular vertex, where `regularize` asks for
    /// one rougher than `coat` (`docs/bssrdf.md` §6, "Regularized coat").
    regularized: Option<Arc<RoughCoat>>,
    /// The coat of roughness `regularize` (None when that is smooth), for
    /// the points of a roughness texture smoother than it
    /// ([`Self::least_coat`]).
    least: OnceLock<Option<Arc<RoughCoat>>>,
    /// c = 1 − 2 FM1(1/η), Sw's normalization (for a rough coat, 1 − Ē).
    sw_c: f32,
    /// The correction, when the mode is on and the parameters record a
    /// medium.
    curvature: Option<CurvatureCorrection>,
    /// The level-of-detail rule ([`super::lod`]).
    lod: LodRule,
}

impl PartialEq for Subsurface {
    fn eq(&self, o: &Self) -> bool {
        self.params == o.params && self.options == o.options
    }
}

impl Subsurface {
    /// The material of medium `params` sampled with `options`, everything
    /// derived from them built (an option out of its domain is refused).
    pub(crate) fn from_options(
        params: SubsurfaceParams,
        options: &EstimatorOptions,
    ) -> Result<Self, ParamError> {
        let roughness = options.roughness;
        if !(0.0..=1.0).contains(&roughness) {
            return Err(ParamError::new(
                Param::Roughness,
                roughness,
                Constraint::UnitInterval,
            ));
        }
        let regularize = options.regularize;
        if !(0.0..=1.0).contains(&regularize) {
            return Err(ParamError::new(
                Param::Regularize,
                regularize,
                Constraint::UnitInterval,
            ));
        }
        let probe = ProbeSampler::new(&params, &options.probe)?;
        let curvature = curvature_for(&params, &probe, options.curvature);
        let lod = LodRule::new(
            options.lod,
            options.lod_threshold,
            probe.rmax(),
            probe.planar_reflectance(),
        );
        let alpha = alpha_from_roughness(roughness);
        let coat = (alpha >= SMOOTH_ALPHA).then(|| Arc::new(RoughCoat::new(alpha, params.eta)));
        let alpha_min = alpha_from_roughness(regularize);
        let regularized = (alpha_min >= SMOOTH_ALPHA && alpha_min > alpha)
            .then(|| Arc::new(RoughCoat::new(alpha_min, params.eta)));
        let sw_c = match &coat {
            Some(c) => 1.0 - c.mean_albedo(),
            None => sw_normalization(params.eta),
        };
        Ok(Subsurface {
            params,
            options: *options,
            probe,
            coat,
            regularized,
            least: OnceLock::new(),
            sw_c,
            curvature,
            lod,
        })
    }

    /// The material with probe options `opts`, the lobe `exit_sw` and the
    /// coat's reflection `specular`; every other option its default.
    pub fn new(
        params: SubsurfaceParams,
        opts: &ProbeOptions,
        exit_sw: bool,
        specular: bool,
    ) -> Result<Self, ParamError> {
        let options = EstimatorOptions {
            probe: *opts,
            exit_sw,
            specular,
            ..EstimatorOptions::default()
        };
        Self::from_options(params, &options)
    }

    /// The same medium sampled with `options`.
    pub fn with_options(&self, options: &EstimatorOptions) -> Result<Self, ParamError> {
        Self::from_options(self.params, options)
    }

    /// The material with the medium `params` at one point of a textured
    /// surface (`docs/bssrdf.md` §13): the probe sampler, its Rmax, the
    /// level-of-detail rule and the curvature correction rebuilt from
    /// `params`; the coat, its entry lobe and every option kept. The
    /// correction is the exact one, without the lookup table a constant
    /// material builds once. None if `params` cannot be sampled.
    pub(crate) fn at_point(&self, params: SubsurfaceParams) -> Option<Self> {
        let probe = ProbeSampler::new(&params, &self.options.probe).ok()?;
        let curvature = match self.options.curvature {
            CurvatureMode::Off => None,
            CurvatureMode::Auto => CurvatureCorrection::new_exact(&params, &probe)
                .unwrap_or_else(|e| panic!("embedded curvature table: {e}")),
        };
        let lod = LodRule::new(
            self.options.lod,
            self.options.lod_threshold,
            probe.rmax(),
            probe.planar_reflectance(),
        );
        Some(Subsurface {
            params,
            options: self.options,
            probe,
            coat: self.coat.clone(),
            regularized: self.regularized.clone(),
            least: self.least.clone(),
            sw_c: self.sw_c,
            curvature,
            lod,
        })
    }

    /// The material with its coat of `roughness` ∈ [0, 1] at one point of
    /// a roughness texture (`docs/bssrdf.md` §13): the coat's albedo
    /// blended from the tables of `steps`, the entry lobe's normalization
    /// 1 − Ē from it, and after a non-specular vertex the coat `least`
    /// (of roughness `regularize`, [`Self::least_coat`]) where that is
    /// rougher; the medium and every other option kept.
    pub(crate) fn with_point_coat(
        mut self,
        roughness: f32,
        steps: &RoughnessSteps,
        least: Option<&Arc<RoughCoat>>,
    ) -> Self {
        let alpha = alpha_from_roughness(roughness);
        let eta = self.params.eta;
        self.coat = (alpha >= SMOOTH_ALPHA)
            .then(|| Arc::new(RoughCoat::with_table(alpha, eta, steps.at(roughness))));
        self.regularized = least.filter(|c| c.ggx.alpha > alpha).cloned();
        self.sw_c = match &self.coat {
            Some(c) => 1.0 - c.mean_albedo(),
            None => sw_normalization(eta),
        };
        self.options.roughness = roughness;
        self
    }

    /// The coat of roughness `regularize` (None when that is smooth),
    /// built the first time a point of a roughness texture asks.
    pub(crate) fn least_coat(&self) -> Option<&Arc<RoughCoat>> {
        self.least
            .get_or_init(|| {
                let alpha_min = alpha_from_roughness(self.options.regularize);
                (alpha_min >= SMOOTH_ALPHA)
                    .then(|| Arc::new(RoughCoat::new(alpha_min, self.params.eta)))
            })
            .as_ref()
    }

    /// The material with level-of-detail `mode` and footprint-to-Rmax
    /// `threshold` (finite, > 0; the scene loader checks it).
    pub fn with_lod(self, mode: LodMode, threshold: f32) -> Self {
        let options = EstimatorOptions {
            lod: mode,
            lod_threshold: threshold,
            ..self.options
        };
        self.with_options(&options)
            .expect("options already accepted")
    }

    /// The material with the curvature correction `mode`.
    pub fn with_curvature_mode(self, mode: CurvatureMode) -> Self {
        let options = EstimatorOptions {
            curvature: mode,
            ..self.options
        };
        self.with_options(&options)
            .expect("options already accepted")
    }

    /// The material with a coat of `roughness` ∈ [0, 1] (NaN is refused);
    /// below α = [`SMOOTH_ALPHA`] the coat is the smooth one.
    pub fn with_roughness(self, roughness: f32) -> Result<Self, ParamError> {
        let options = EstimatorOptions {
            roughness,
            ..self.options
        };
        self.with_options(&options)
    }

    /// The medium's parameters.
    #[inline]
    pub fn params(&self) -> &SubsurfaceParams {
        &self.params
    }

    /// Every sampling option.
    #[inline]
    pub fn options(&self) -> &EstimatorOptions {
        &self.options
    }

    /// The probe sampler.
    #[inline]
    pub fn probe(&self) -> &ProbeSampler {
        &self.probe
    }

    /// Whether the entry point's lobe is the normalized Fresnel lobe Sw
    /// (else 1/π).
    #[inline]
    pub fn exit_sw(&self) -> bool {
        self.options.exit_sw
    }

    /// Whether the coat's reflection is rendered (else the path is
    /// weighted by the transmitted fraction and the reflected part lost).
    #[inline]
    pub fn specular(&self) -> bool {
        self.options.specular
    }

    /// The coat's roughness in [0, 1] (α = roughness²); 0 is a mirror.
    #[inline]
    pub fn roughness(&self) -> f32 {
        self.options.roughness
    }

    /// The boundary the random-walk integrator simulates (the diffusion
    /// estimator ignores it).
    #[inline]
    pub fn boundary(&self) -> WalkBoundary {
        self.options.boundary
    }

    /// At the camera vertex, the plane control variate on the entry
    /// point's light sample (`integrator::control_variate`).
    #[inline]
    pub fn control_variate(&self) -> bool {
        self.options.control_variate
    }

    /// At the camera vertex, an antithetic pair of probes instead of one
    /// (`integrator::path`, `PAIR_DEPTH`).
    #[inline]
    pub fn probe_pair(&self) -> bool {
        self.options.probe_pair
    }

    /// With the pair, the paths that go on from its entry points at the
    /// camera vertex: 1, 2 or 4 (`integrator::subsurface`'s split).
    #[inline]
    pub fn pair_paths(&self) -> u32 {
        self.options.pair_paths
    }

    /// The level-of-detail rule.
    #[inline]
    pub fn lod(&self) -> &LodRule {
        &self.lod
    }

    /// The curvature correction of the diffusion weight, if on.
    #[inline]
    pub fn curvature_correction(&self) -> Option<&CurvatureCorrection> {
        self.curvature.as_ref()
    }

    /// The rough coat, or None for a smooth one.
    pub fn rough_coat(&self) -> Option<&RoughCoat> {
        self.coat.as_deref()
    }

    /// The coat a path meets after a non-specular vertex: the regularized
    /// one where `regularize` asks for a rougher coat, else
    /// [`rough_coat`](Self::rough_coat).
    pub fn coat_after_diffuse(&self) -> Option<&RoughCoat> {
        self.regularized.as_deref().or(self.coat.as_deref())
    }

    /// The regularized coat, where `regularize` makes one.
    pub fn regularized_coat(&self) -> Option<&RoughCoat> {
        self.regularized.as_deref()
    }

    pub fn eta(&self) -> f32 {
        self.params.eta
    }

    /// The entry-point lobe value per steradian for a direction with cosine
    /// `cos` to the outward normal: Sw(ω) or 1/π.
    pub fn lobe(&self, cos: f32) -> f32 {
        if cos <= 0.0 {
            return 0.0;
        }
        if self.options.exit_sw {
            match &self.coat {
                Some(c) => (1.0 - c.albedo(cos)) * std::f32::consts::FRAC_1_PI / self.sw_c,
                None => crate::bssrdf::sw(cos, self.params.eta, self.sw_c),
            }
        } else {
            std::f32::consts::FRAC_1_PI
        }
    }

    /// The albedo A per channel (for previews and tests).
    pub fn albedo(&self) -> Vec3 {
        let a = self.params.albedo;
        Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32)
    }
}

/// The correction for `mode`. The table is embedded and checked by the
/// unit tests of `bssrdf::curvature_table`, so a failure to load it is a
/// build defect, not bad input; the message names the file, line and field.
fn curvature_for(
    params: &SubsurfaceParams,
    probe: &ProbeSampler,
    mode: CurvatureMode,
) -> Option<CurvatureCorrection> {
    match mode {
        CurvatureMode::Off => None,
        CurvatureMode::Auto => CurvatureCorrection::new(params, probe)
            .unwrap_or_else(|e| panic!("embedded curvature table: {e}")),
    }
}

impl Subsurface {
    /// Every sampling option, `key=value` separated by spaces, with the
    /// names of the option table (for the EXR header).
    pub(crate) fn sampling_description(&self) -> String {
        let all: Vec<String> = OPTIONS
            .iter()
            .filter(|o| o.name != "curvature_correction")
            .map(|o| format!("{}={}", o.name, (o.get)(&self.options)))
            .collect();
        all.join(" ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bssrdf::{Fit, ProbeAxes, RadiusSampler};
    use crate::materials::estimator_options::Assignments;

    /// Caught: a regularized coat no rougher than the material's own (the
    /// rule would then smooth a rough coat), one built with the option
    /// off, or an option out of [0, 1] accepted.
    #[test]
    fn the_regularized_coat_is_the_rougher_one_and_absent_when_off() {
        let p = SubsurfaceParams::from_preset("marble", 1.0, Fit::Searchlight).unwrap();
        let ss = Subsurface::new(p, &ProbeOptions::default(), true, true).unwrap();
        let with = |ss: &Subsurface, name: &str, v: f32| {
            ss.with_options(&Assignments::default().with(name, v).over(ss.options))
        };
        // smooth coat: α_min = 0.3² after a non-specular vertex
        let on = with(&ss, "regularize", 0.3).unwrap();
        assert!(on.rough_coat().is_none());
        assert_eq!(on.coat_after_diffuse().unwrap().ggx.alpha, 0.3 * 0.3);
        assert_eq!(on.coat_after_diffuse().unwrap().eta, p.eta);
        // off: the coat as given everywhere
        let off = with(&ss, "regularize", 0.0).unwrap();
        assert!(off.regularized_coat().is_none() && off.coat_after_diffuse().is_none());
        // a rough coat rougher than α_min is kept; a smoother one is not
        let rough = with(&on, "roughness", 0.6).unwrap();
        assert!(rough.regularized_coat().is_none());
        assert_eq!(rough.coat_after_diffuse(), rough.rough_coat());
        let fine = with(&on, "roughness", 0.1).unwrap();
        assert_eq!(fine.coat_after_diffuse().unwrap().ggx.alpha, 0.3 * 0.3);
        for bad in [-0.1, 1.5, f32::NAN] {
            let e = with(&ss, "regularize", bad).unwrap_err();
            assert_eq!(e.param, Param::Regularize, "{bad}");
        }
    }

    #[test]
    fn overrides_replace_only_what_they_name() {
        let p = SubsurfaceParams::from_preset("marble", 1.0, Fit::Searchlight).unwrap();
        let ss = Subsurface::new(p, &ProbeOptions::default(), true, true).unwrap();
        let apply = |ov: &Assignments, ss: &Subsurface| ss.with_options(&ov.over(ss.options));
        let ov = Assignments::default()
            .with("axes", "normal")
            .with("specular", false);
        let out = apply(&ov, &ss).unwrap();
        assert_eq!(out.probe().options().axes, ProbeAxes::Normal);
        assert_eq!(out.probe().options().radius, RadiusSampler::Analytic);
        assert!(out.exit_sw() && !out.specular());
        assert_eq!(out.params(), ss.params());
        assert_eq!(out.boundary(), WalkBoundary::DIELECTRIC);
        let walk = apply(&Assignments::default().with("boundary", "Diffuse"), &out).unwrap();
        assert_eq!(walk.boundary(), WalkBoundary::Diffuse { exit_nee: true });
        assert!(walk != out && walk.exit_sw() && !walk.specular());
        assert_eq!(WalkBoundary::parse("lambert"), None);
        let bad = Assignments::default().with("rmax_quantile", 1.5);
        assert!(apply(&bad, &ss).is_err());
        // the identity names options as the scene format does, not as Debug
        assert_eq!(ov.canonical(), "axes=normal specular=false");
        assert_eq!(Assignments::default().canonical(), "");
        // a later value replaces an earlier one
        assert_eq!(ov.clone().with("axes", "mis3").value("axes"), Some("mis3"));
        // lobe: Sw integrates to 1 against cos; the plain lobe is 1/π
        assert_eq!(out.lobe(-0.1), 0.0);
        let plain = apply(&Assignments::default().with("exit_sw", false), &ss).unwrap();
        assert_eq!(plain.lobe(0.3), std::f32::consts::FRAC_1_PI);
    }
}
