//! The probe axis rules (`docs/bssrdf.md` §12.1): which axes probes are
//! shot along, and under the curvature rule the probability ε of each
//! tangent axis.

/// Which axes probes are shot along.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum ProbeAxes {
    /// Along the shading normal only: normal-only axes (King et al. 2013),
    /// a research variant.
    Normal,
    /// N, T, B with probabilities ½, ¼, ¼ and the balance heuristic.
    Mis3,
    /// N, T, B with probabilities 1 − 2ε, ε, ε and the balance heuristic,
    /// ε = [`tangent_probability`] of the curvature at xo times the widest
    /// channel's d: ε_min where the profile sees a flat surface, ¼ (mis3)
    /// where it wraps around the surface.
    #[default]
    Curvature,
}

impl ProbeAxes {
    pub const ALL: [ProbeAxes; 3] = [ProbeAxes::Normal, ProbeAxes::Mis3, ProbeAxes::Curvature];

    /// The name the scene format and the command line use.
    pub fn name(self) -> &'static str {
        match self {
            ProbeAxes::Normal => "normal",
            ProbeAxes::Mis3 => "mis3",
            ProbeAxes::Curvature => "curvature",
        }
    }

    /// G in the bound G · n_active · A / CDF(Rmax)^(renormalize) on the
    /// weight of one hit (before the hit count; module docs): 4√3 for
    /// mis3, √3/ε_min for curvature; None for normal-only, whose weights
    /// grow without bound at grazing hits.
    pub fn weight_bound(self) -> Option<f64> {
        match self {
            ProbeAxes::Normal => None,
            ProbeAxes::Mis3 => Some(3f64.sqrt() / 0.25),
            ProbeAxes::Curvature => Some(3f64.sqrt() / TANGENT_PROB_MIN),
        }
    }

    /// The variant named `s` (case-insensitive).
    pub fn parse(s: &str) -> Option<ProbeAxes> {
        ProbeAxes::ALL
            .into_iter()
            .find(|a| a.name().eq_ignore_ascii_case(s))
    }
}

/// The smallest probability of each tangent axis under
/// [`ProbeAxes::Curvature`]: it keeps every surface within Rmax reachable
/// (so the estimator stays unbiased on any geometry) and bounds the weight
/// of a hit by (√3/ε_min)·n_active·A (module docs). 0.005 to suit the plane
/// control variate (`integrator::control_variate`), which models only
/// probes along N, so a smaller ε leaves it more of the probes; the bound
/// grows as 1/ε_min (docs/accuracy.md, "The plane control variate", for the
/// trade measured); the grazing scene keeps ε = ¼.
pub const TANGENT_PROB_MIN: f64 = 0.005;

/// κ·d at and beyond which [`ProbeAxes::Curvature`] uses mis3's ¼.
pub const TANGENT_PROB_FULL_AT: f64 = 1.0;

/// The probability ε of each of T and B under [`ProbeAxes::Curvature`] at
/// an exit point where the surface's curvature times the widest channel's d
/// is `kd` (≥ 0):
///
///   ε = ε_min + (¼ − ε_min) · exp(−(π/6)(1/kd − 1/kd_full)),  kd < kd_full,
///
/// and ¼ beyond kd_full = [`TANGENT_PROB_FULL_AT`]. exp(−π/(6 kd)) is the
/// slow lobe e^{−r/3d} of R at arc length r = π/(2κ), where a sphere of
/// curvature κ has turned 90° from xo and probes along N meet it edge-on:
/// the share of the profile that only T and B probes reach well. It is
/// negligible on a smooth body (e^{−5.5} at kd = 0.087, a 10 mm marble
/// sphere) and reaches ¼ where the profile wraps around the surface
/// (scenes/grazing.toml: kd ≈ 1.2). A NaN kd gives ¼, the robust end.
pub fn tangent_probability(kd: f64) -> f64 {
    let (min, full) = (TANGENT_PROB_MIN, TANGENT_PROB_FULL_AT);
    if kd.is_nan() || kd >= full {
        return 0.25;
    }
    if kd <= 0.0 {
        return min;
    }
    let s = (-(std::f64::consts::PI / 6.0) * (1.0 / kd - 1.0 / full)).exp();
    min + (0.25 - min) * s
}
