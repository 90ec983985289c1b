//! The configuration matrix of a study: a baseline and, for every sampling
//! choice of the subsurface estimator, variations that change that one
//! choice and nothing else (one axis at a time, not the cross product: the
//! cross product of the axes below is thousands of renders, and the axes
//! interact little enough that one-at-a-time answers "what does this choice
//! cost and buy").
//!
//! A configuration is applied by rebuilding every subsurface material of
//! the scene with the new options ([`apply`]); the ray-query backend and the
//! integrator are chosen at render time.

use lucent::accel::Backend;
use lucent::bssrdf::{ChannelStrategy, ProbeAxes, ProbeOptions, RadiusSampler, TableSpacing};
use lucent::error::ParamError;
use lucent::integrator::IntegratorKind;
use lucent::materials::{LodMode, Material, WalkBoundary};
use lucent::sampling::SamplerKind;
use lucent::scene::Scene;

/// Which choice a configuration varies from the baseline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Axis {
    Baseline,
    Radius,
    RmaxQuantile,
    Axes,
    Channel,
    Renormalize,
    ExitSw,
    Specular,
    Backend,
    Integrator,
    /// The random walk with the diffuse Fresnel boundary (another model).
    Boundary,
    /// Subsurface level of detail off (the baseline keeps the scene's,
    /// `auto` by default; `lucent::materials::lod`).
    Lod,
    /// The variance reduction at the camera vertex: the scene's (by
    /// default the plane control variate, which the baseline keeps)
    /// against the others of none, the control variate, the antithetic
    /// probe pair and both
    /// (`lucent::integrator::control_variate`).
    Variance,
    /// The other sampler than the scene's (by default the pseudo-random
    /// stream against the Sobol' sequence), for the diffusion estimator
    /// and for the random walk: sampler × estimator.
    Sampler,
    /// The baseline with its guides (albedo, normal) rendered too and
    /// every rung's image denoised by Open Image Denoise; its time
    /// includes the denoise.
    Denoise,
}

impl Axis {
    pub const ALL: [Axis; 15] = [
        Axis::Baseline,
        Axis::Radius,
        Axis::RmaxQuantile,
        Axis::Axes,
        Axis::Channel,
        Axis::Renormalize,
        Axis::ExitSw,
        Axis::Specular,
        Axis::Backend,
        Axis::Integrator,
        Axis::Boundary,
        Axis::Lod,
        Axis::Variance,
        Axis::Sampler,
        Axis::Denoise,
    ];

    /// The name used in configuration names and the CSV.
    pub fn name(self) -> &'static str {
        match self {
            Axis::Baseline => "baseline",
            Axis::Radius => "radius",
            Axis::RmaxQuantile => "rmax",
            Axis::Axes => "axes",
            Axis::Channel => "channel",
            Axis::Renormalize => "renormalize",
            Axis::ExitSw => "exit_sw",
            Axis::Specular => "specular",
            Axis::Backend => "backend",
            Axis::Integrator => "integrator",
            Axis::Boundary => "boundary",
            Axis::Lod => "lod",
            Axis::Variance => "variance",
            Axis::Sampler => "sampler",
            Axis::Denoise => "denoise",
        }
    }

    pub fn parse(s: &str) -> Option<Axis> {
        Axis::ALL.into_iter().find(|a| a.name() == s)
    }
}

/// Sampling choices for every subsurface material, by the option table's
/// names; an option not given keeps the material's own setting (the same
/// overrides `lucent render` takes).
pub use lucent::materials::estimator_options::Assignments as Overrides;

/// One row group of the study: what is rendered and how.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    /// Unique, stable name: "baseline" or "axis=value"; the CSV key.
    pub name: String,
    pub axis: Axis,
    /// The varied value as text (the baseline's own value on the baseline).
    pub value: String,
    pub overrides: Overrides,
    pub backend: Backend,
    pub integrator: IntegratorKind,
    /// The sampler (the scene's but on the sampler axis).
    pub sampler: SamplerKind,
    /// Each rung's image denoised (with the guides rendered beside it).
    pub denoise: bool,
}

/// "uniform", "table:N" (tail-spaced), "table-uniform:N", "analytic",
/// "mixture": the names [`RadiusSampler::parse`] reads.
pub(crate) fn radius_name(r: RadiusSampler) -> String {
    r.name()
}

pub(crate) fn integrator_name(i: IntegratorKind) -> &'static str {
    match i {
        IntegratorKind::Path => "diffusion",
        IntegratorKind::RandomWalk => "randomwalk",
    }
}

pub(crate) fn parse_integrator(s: &str) -> Option<IntegratorKind> {
    match s {
        "diffusion" | "path" => Some(IntegratorKind::Path),
        "randomwalk" | "random-walk" => Some(IntegratorKind::RandomWalk),
        _ => None,
    }
}

/// The baseline's probe options: the recommended defaults (exact analytic
/// radius sampling, N/T/B probes with MIS, all channels per sample, Rmax at
/// the 0.999 quantile, no renormalization).
pub(crate) fn baseline_probe() -> ProbeOptions {
    ProbeOptions::default()
}

/// The Rmax quantile of the diffusion reference: far enough out that the
/// truncation of the configurations (0.999 by default) shows as bias.
pub(crate) const REFERENCE_RMAX_QUANTILE: f64 = 0.99999;

/// Every probe option of `o` given (the scene's Fresnel, random-walk and
/// variance choices are not).
fn full_probe(o: ProbeOptions) -> Overrides {
    Overrides::default()
        .with("radius", o.radius.name())
        .with("rmax_quantile", o.rmax_quantile)
        .with("axes", o.axes.name())
        .with("channel", o.channel.name())
        .with("renormalize", o.renormalize)
}

/// The overrides of the diffusion reference: the exact sampler, MIS axes
/// and channels, Rmax at [`REFERENCE_RMAX_QUANTILE`], no level of detail
/// (the full estimator at every hit); Fresnel choices are the scene's (they
/// change the model, not the estimator).
pub(crate) fn reference_overrides() -> Overrides {
    full_probe(ProbeOptions {
        rmax_quantile: REFERENCE_RMAX_QUANTILE,
        ..baseline_probe()
    })
    .with("lod", LodMode::Off.name())
}

/// The first subsurface material's (exit_sw, specular): the scene's model
/// choices, which the baseline keeps and the Fresnel axes flip.
fn scene_fresnel(scene: &Scene) -> Option<(bool, bool)> {
    scene.materials.iter().find_map(|m| match m {
        Material::Subsurface(ss) => Some((ss.exit_sw(), ss.specular())),
        _ => None,
    })
}

/// The first subsurface material's (control_variate, probe_pair).
fn scene_variance(scene: &Scene) -> (bool, bool) {
    scene
        .materials
        .iter()
        .find_map(|m| match m {
            Material::Subsurface(ss) => Some((ss.control_variate(), ss.probe_pair())),
            _ => None,
        })
        .unwrap_or((true, false))
}

/// The first subsurface material's random-walk boundary.
fn scene_boundary(scene: &Scene) -> WalkBoundary {
    scene
        .materials
        .iter()
        .find_map(|m| match m {
            Material::Subsurface(ss) => Some(ss.boundary()),
            _ => None,
        })
        .unwrap_or_default()
}

/// The configurations being built: the baseline first, then one per value
/// of each axis in the order they are added.
struct Matrix {
    out: Vec<Config>,
    /// The baseline's overrides, which every variation starts from.
    base: Overrides,
    base_backend: Backend,
    /// The scene's sampler, which every configuration but the sampler
    /// axis's keeps.
    sampler: SamplerKind,
}

impl Matrix {
    fn add(
        &mut self,
        axis: Axis,
        value: String,
        ov: Overrides,
        backend: Backend,
        integrator: IntegratorKind,
    ) {
        self.out.push(Config {
            name: format!("{}={value}", axis.name()),
            axis,
            value,
            overrides: ov,
            backend,
            integrator,
            sampler: self.sampler,
            denoise: false,
        });
    }

    /// A variation of the estimator: other overrides, the baseline's
    /// backend, the path tracer.
    fn vary(&mut self, axis: Axis, value: String, ov: Overrides) {
        let backend = self.base_backend;
        self.add(axis, value, ov, backend, IntegratorKind::Path);
    }
}

/// The radius samplers of the radius axis.
fn radius_values(quick: bool) -> Vec<RadiusSampler> {
    let tu = |size| RadiusSampler::Table {
        size,
        spacing: TableSpacing::Uniform,
    };
    let tt = |size| RadiusSampler::Table {
        size,
        spacing: TableSpacing::Tail,
    };
    if quick {
        vec![
            RadiusSampler::Uniform,
            tu(16),
            tu(1024),
            RadiusSampler::Mixture,
        ]
    } else {
        vec![
            RadiusSampler::Uniform,
            tu(16),
            tu(64),
            tu(256),
            tu(1024),
            tt(16),
            tt(256),
            tt(1024),
            RadiusSampler::Mixture,
        ]
    }
}

/// Why a study's configurations cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// There is nothing the study could vary.
    #[error("the scene has no subsurface material: nothing to study")]
    NoSubsurface,
    /// A configuration's options do not fit a material of the scene.
    #[error(transparent)]
    Param(#[from] ParamError),
}

/// The configurations of a study of `scene`. `quick` keeps a few values per
/// axis (enough for the ordering facts the tests check). `backends[0]` is
/// the baseline's backend; each further one gets a backend row.
pub fn matrix(
    scene: &Scene,
    quick: bool,
    backends: &[Backend],
) -> Result<Vec<Config>, ConfigError> {
    let (exit_sw, specular) = scene_fresnel(scene).ok_or(ConfigError::NoSubsurface)?;
    let base_probe = baseline_probe();
    let base_backend = backends[0];
    let base_ov = full_probe(base_probe)
        .with("exit_sw", exit_sw)
        .with("specular", specular);
    let mut m = Matrix {
        out: vec![Config {
            name: "baseline".into(),
            axis: Axis::Baseline,
            value: String::new(),
            overrides: base_ov.clone(),
            backend: base_backend,
            integrator: IntegratorKind::Path,
            sampler: scene.settings.sampler,
            denoise: false,
        }],
        base: base_ov.clone(),
        base_backend,
        sampler: scene.settings.sampler,
    };
    for r in radius_values(quick) {
        m.vary(
            Axis::Radius,
            radius_name(r),
            m.base.clone().with("radius", r.name()),
        );
    }
    let quantiles: &[f64] = if quick {
        &[0.99]
    } else {
        &[0.9, 0.99, 0.997, 0.9999]
    };
    for &q in quantiles {
        m.vary(
            Axis::RmaxQuantile,
            format!("{q}"),
            m.base.clone().with("rmax_quantile", q),
        );
    }
    // every other axis rule (normal-only and mis3 for the default)
    for other_axes in ProbeAxes::ALL.into_iter().filter(|&a| a != base_probe.axes) {
        m.vary(
            Axis::Axes,
            other_axes.name().into(),
            m.base.clone().with("axes", other_axes.name()),
        );
    }
    let other_channel = match base_probe.channel {
        ChannelStrategy::Single => ChannelStrategy::Mis,
        ChannelStrategy::Mis => ChannelStrategy::Single,
    };
    m.vary(
        Axis::Channel,
        other_channel.name().into(),
        m.base.clone().with("channel", other_channel.name()),
    );
    if !quick {
        let r = !base_probe.renormalize;
        m.vary(
            Axis::Renormalize,
            r.to_string(),
            m.base.clone().with("renormalize", r),
        );
    }
    m.vary(
        Axis::ExitSw,
        (!exit_sw).to_string(),
        m.base.clone().with("exit_sw", !exit_sw),
    );
    if !quick {
        m.vary(
            Axis::Specular,
            (!specular).to_string(),
            m.base.clone().with("specular", !specular),
        );
    }
    // Level of detail off: what the probe estimator costs where the
    // baseline shades with albedo A (the same configuration when LOD never
    // triggers).
    m.vary(
        Axis::Lod,
        LodMode::Off.name().into(),
        m.base.clone().with("lod", LodMode::Off.name()),
    );
    // The variance reduction at the camera vertex, each choice other than
    // the scene's (the default: the pair); the quick study keeps one
    // plain probe or the pair, whichever the scene does not use.
    let own = scene_variance(scene);
    let variance: &[(&str, bool, bool)] = if quick {
        &[("none", false, false), ("pair", false, true)]
    } else {
        &[
            ("none", false, false),
            ("control-variate", true, false),
            ("pair", false, true),
            ("pair+control-variate", true, true),
        ]
    };
    for &(name, cv, pair) in variance.iter().filter(|v| (v.1, v.2) != own) {
        m.vary(
            Axis::Variance,
            name.into(),
            m.base
                .clone()
                .with("control_variate", cv)
                .with("probe_pair", pair),
        );
    }
    for &b in &backends[1..] {
        m.add(
            Axis::Backend,
            b.name().into(),
            base_ov.clone(),
            b,
            IntegratorKind::Path,
        );
    }
    m.add(
        Axis::Integrator,
        integrator_name(IntegratorKind::RandomWalk).into(),
        base_ov.clone(),
        base_backend,
        IntegratorKind::RandomWalk,
    );
    if !quick {
        // The random walk with the other boundary model (the scene's own is
        // in the integrator row): a different model, so its "bias" against
        // a random-walk reference of the scene's boundary is the models'
        // difference.
        let other = match scene_boundary(scene) {
            WalkBoundary::Dielectric { .. } => WalkBoundary::Diffuse { exit_nee: true },
            WalkBoundary::Diffuse { .. } => WalkBoundary::DIELECTRIC,
        };
        m.add(
            Axis::Boundary,
            other.name().into(),
            base_ov.clone().with("boundary", other.name()),
            base_backend,
            IntegratorKind::RandomWalk,
        );
    }
    sampler_and_denoise(&mut m, quick);
    Ok(m.out)
}

/// The sampler axis (the other sampler, for the diffusion estimator and,
/// unless `quick`, for the random walk) and the denoised baseline.
fn sampler_and_denoise(m: &mut Matrix, quick: bool) {
    let other = match m.sampler {
        SamplerKind::Sobol => SamplerKind::Random,
        SamplerKind::Random => SamplerKind::Sobol,
    };
    let base = m.base.clone();
    let estimators = [
        (IntegratorKind::Path, ""),
        (IntegratorKind::RandomWalk, "+randomwalk"),
    ];
    for &(integrator, suffix) in &estimators[..if quick { 1 } else { 2 }] {
        m.add(
            Axis::Sampler,
            format!("{}{suffix}", other.name()),
            base.clone(),
            m.base_backend,
            integrator,
        );
        m.out.last_mut().expect("just added").sampler = other;
    }
    m.add(
        Axis::Denoise,
        "oidn".into(),
        base,
        m.base_backend,
        IntegratorKind::Path,
    );
    m.out.last_mut().expect("just added").denoise = true;
}

/// `scene` with every subsurface material rebuilt with `ov` applied to its
/// own options (its medium parameters unchanged), and the accuracy
/// budgets' choices made.
pub fn apply(scene: &Scene, ov: &Overrides) -> Result<Scene, ConfigError> {
    let mut out = scene.clone();
    ov.apply_all(&mut out.materials)?;
    lucent::integrator::plan::budget::resolve(&mut out)?;
    Ok(out)
}

/// A one-line description of overrides for the report: `name=value` in
/// the option table's order and names.
pub(crate) fn describe(ov: &Overrides) -> String {
    ov.canonical()
}
