//! Material parameters of the normalized diffusion BSSRDF: per channel the
//! surface albedo A and the profile parameter d (scene units), plus the
//! relative index of refraction η (Christensen & Burley 2015, §5;
//! `docs/bssrdf.md` §3). Three ways in: a named preset (Jensen et al. 2001,
//! Fig. 5), measured coefficients, or the artist form (A, ℓ).
//!
//! Every constructor also records the volumetric [`Medium`] that the random
//! walk simulates. A comes from [`super::albedo_table`] by default
//! ([`AlbedoSource`], `docs/bssrdf.md` §9). The hard cases decided here
//! (σa = 0, A = 0, units), the artist form's medium and the albedo sources:
//! `docs/bssrdf.md` §12.3.

use super::albedo_table::AlbedoTable;
pub use super::dipole::dipole_reflectance;
use super::profile::Fit;
use crate::error::{Constraint, Param, ParamError};

/// Where a material's surface albedo A comes from; see the module docs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AlbedoSource {
    /// What the medium and its boundary reflect: R(α', η) from the albedo
    /// table (the artist form inverts it).
    #[default]
    Table,
    /// The A given (preset Rd column, measured `albedo`); the artist form
    /// inverts the classical dipole.
    Given,
}

impl AlbedoSource {
    /// Parses "table" or "given" (case-insensitive).
    pub fn parse(name: &str) -> Result<AlbedoSource, ParamError> {
        match name.to_ascii_lowercase().as_str() {
            "table" => Ok(AlbedoSource::Table),
            "given" => Ok(AlbedoSource::Given),
            other => Err(ParamError::new(
                Param::AlbedoSource,
                format!("\"{other}\""),
                Constraint::Named {
                    what: "albedo source",
                    names: "expected table or given".into(),
                },
            )),
        }
    }
}

/// The embedded albedo table. It is compiled in and checked by the unit
/// tests of `albedo_table`, so a failure here is a build defect, not bad
/// input; the message names the file, line and field.
fn table() -> &'static AlbedoTable {
    AlbedoTable::get().unwrap_or_else(|e| panic!("embedded albedo table: {e}"))
}

/// The total diffuse reflectance of a semi-infinite medium of reduced
/// albedo α' behind a boundary of index η: the albedo table, or the dipole
/// outside its η range.
pub(crate) fn medium_reflectance(alpha_reduced: f64, eta: f64) -> f64 {
    table()
        .reflectance(alpha_reduced, eta)
        .unwrap_or_else(|| dipole_reflectance(alpha_reduced, eta))
}

/// The α' whose reflectance is `a` under `source` (table or dipole), capped
/// at 1 − [`MIN_ABSORPTION_FRACTION`].
pub(crate) fn invert_reflectance(a: f64, eta: f64, source: AlbedoSource) -> f64 {
    match source {
        AlbedoSource::Table => table()
            .invert(a, eta)
            .map(|x| x.min(1.0 - MIN_ABSORPTION_FRACTION))
            .unwrap_or_else(|| invert_dipole_reflectance(a, eta)),
        AlbedoSource::Given => invert_dipole_reflectance(a, eta),
    }
}

/// Lower bound on σa / σt' used for σa = 0 media; see the module docs.
pub const MIN_ABSORPTION_FRACTION: f64 = 1e-6;

/// One row of the Jensen et al. 2001 table (mm⁻¹).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Preset {
    pub name: &'static str,
    /// Reduced scattering coefficient σs' (RGB, mm⁻¹).
    pub sigma_s_reduced: [f64; 3],
    /// Absorption coefficient σa (RGB, mm⁻¹).
    pub sigma_a: [f64; 3],
    /// Measured diffuse reflectance, used as the surface albedo A.
    pub albedo: [f64; 3],
    pub eta: f32,
}

const fn p(name: &'static str, s: [f64; 3], a: [f64; 3], rd: [f64; 3], eta: f32) -> Preset {
    Preset {
        name,
        sigma_s_reduced: s,
        sigma_a: a,
        albedo: rd,
        eta,
    }
}

/// Jensen et al. 2001, Fig. 5 (σs', σa as in pbrt-v4's table); η = 1.3
/// except Marble (1.5).
pub const PRESETS: [Preset; 12] = [
    p(
        "Apple",
        [2.29, 2.39, 1.97],
        [0.0030, 0.0034, 0.046],
        [0.85, 0.84, 0.53],
        1.3,
    ),
    p(
        "Chicken1",
        [0.15, 0.21, 0.38],
        [0.015, 0.077, 0.19],
        [0.31, 0.15, 0.10],
        1.3,
    ),
    p(
        "Chicken2",
        [0.19, 0.25, 0.32],
        [0.018, 0.088, 0.20],
        [0.32, 0.16, 0.10],
        1.3,
    ),
    p(
        "Cream",
        [7.38, 5.47, 3.15],
        [0.0002, 0.0028, 0.0163],
        [0.98, 0.90, 0.73],
        1.3,
    ),
    p(
        "Ketchup",
        [0.18, 0.07, 0.03],
        [0.061, 0.97, 1.45],
        [0.16, 0.01, 0.00],
        1.3,
    ),
    p(
        "Marble",
        [2.19, 2.62, 3.00],
        [0.0021, 0.0041, 0.0071],
        [0.83, 0.79, 0.75],
        1.5,
    ),
    p(
        "Potato",
        [0.68, 0.70, 0.55],
        [0.0024, 0.0090, 0.12],
        [0.77, 0.62, 0.21],
        1.3,
    ),
    p(
        "Skimmilk",
        [0.70, 1.22, 1.90],
        [0.0014, 0.0025, 0.0142],
        [0.81, 0.81, 0.69],
        1.3,
    ),
    p(
        "Skin1",
        [0.74, 0.88, 1.01],
        [0.032, 0.17, 0.48],
        [0.44, 0.22, 0.13],
        1.3,
    ),
    p(
        "Skin2",
        [1.09, 1.59, 1.79],
        [0.013, 0.070, 0.145],
        [0.63, 0.44, 0.34],
        1.3,
    ),
    p(
        "Spectralon",
        [11.6, 20.4, 14.9],
        [0.0, 0.0, 0.0],
        [1.00, 1.00, 1.00],
        1.3,
    ),
    p(
        "Wholemilk",
        [2.55, 3.21, 3.77],
        [0.0011, 0.0024, 0.014],
        [0.91, 0.88, 0.76],
        1.3,
    ),
];

/// The preset with this name, case-insensitively.
pub fn preset(name: &str) -> Option<&'static Preset> {
    PRESETS.iter().find(|p| p.name.eq_ignore_ascii_case(name))
}

/// Measured coefficients in mm⁻¹. With `g = 0`, `sigma_s` is taken to be the
/// reduced coefficient σs' already (as in the Jensen table).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measured {
    pub sigma_s: [f64; 3],
    pub sigma_a: [f64; 3],
    /// Henyey–Greenstein mean cosine; σs' = σs (1 − g).
    pub g: f64,
    pub albedo: [f64; 3],
    pub eta: f32,
}

/// What the renderer needs per material: per channel A and d (scene units),
/// and η. Build with one of the constructors, which validate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubsurfaceParams {
    pub albedo: [f64; 3],
    /// Profile parameter d per channel, in scene units.
    pub d: [f64; 3],
    /// Relative index of refraction (inside / outside).
    pub eta: f32,
    /// The homogeneous medium the profile approximates, for the random-walk
    /// reference; None only for hand-built parameters.
    pub medium: Option<Medium>,
}

/// A homogeneous scattering medium in scene units (coefficients per scene
/// unit = mm⁻¹ / units_per_mm), with a Henyey–Greenstein phase function.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Medium {
    /// Scattering coefficient σs (not reduced): σs' = σs (1 − g).
    pub sigma_s: [f64; 3],
    pub sigma_a: [f64; 3],
    /// Henyey–Greenstein mean cosine.
    pub g: f64,
}

/// Optically thick stand-in for a zero-length (artist ℓ = 0) channel: a
/// purely absorbing medium this many times denser than the shortest
/// non-zero length (or 1e9 per scene unit when every length is 0).
const ZERO_LENGTH_DENSITY: f64 = 1e6;

impl Medium {
    /// σt = σs + σa per channel.
    pub fn sigma_t(&self) -> [f64; 3] {
        std::array::from_fn(|c| self.sigma_s[c] + self.sigma_a[c])
    }

    /// The medium whose total diffuse reflectance (under `source`: the
    /// albedo table or the dipole) is `albedo` and whose diffuse mean free
    /// path (or, with `volume_mfp`, volume mean free path 1/σt') is `mfp`
    /// (scene units), g = 0. See the module docs. (The loader goes through
    /// [`SubsurfaceParams::from_artist_with`], which inverts the same way.)
    #[cfg(test)]
    pub(crate) fn from_reflectance(
        albedo: [f64; 3],
        mfp: [f64; 3],
        eta: f32,
        volume_mfp: bool,
        source: AlbedoSource,
    ) -> Medium {
        let alpha = |c: usize| invert_reflectance(albedo[c], eta as f64, source);
        Self::from_reduced_albedo(alpha, mfp, volume_mfp)
    }

    /// [`Self::from_reflectance`] with the reduced albedo α' of each
    /// channel given by `alpha` (read only for channels with ℓ > 0).
    pub(crate) fn from_reduced_albedo(
        alpha: impl Fn(usize) -> f64,
        mfp: [f64; 3],
        volume_mfp: bool,
    ) -> Medium {
        let shortest = mfp
            .iter()
            .copied()
            .filter(|&l| l > 0.0)
            .fold(f64::INFINITY, f64::min);
        let dense = if shortest.is_finite() {
            ZERO_LENGTH_DENSITY / shortest
        } else {
            1e9
        };
        let mut m = Medium {
            sigma_s: [0.0; 3],
            sigma_a: [0.0; 3],
            g: 0.0,
        };
        for (c, &l) in mfp.iter().enumerate() {
            if l <= 0.0 {
                m.sigma_a[c] = dense;
                continue;
            }
            let a = alpha(c);
            let st = if volume_mfp {
                1.0 / l
            } else {
                // σtr = σt' √(3(1 − α')) = 1/ℓd
                1.0 / (l * (3.0 * (1.0 - a)).sqrt())
            };
            m.sigma_s[c] = a * st;
            m.sigma_a[c] = (1.0 - a) * st;
        }
        m
    }
}

/// The α' with `dipole_reflectance(α', η) = rd` (bisection to f64 precision),
/// capped at 1 − [`MIN_ABSORPTION_FRACTION`] like the diffusion side.
pub fn invert_dipole_reflectance(rd: f64, eta: f64) -> f64 {
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if dipole_reflectance(mid, eta) < rd {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (0.5 * (lo + hi)).min(1.0 - MIN_ABSORPTION_FRACTION)
}

fn check_finite_nonneg(param: Param, v: [f64; 3]) -> Result<(), ParamError> {
    for (c, x) in v.iter().enumerate() {
        if !x.is_finite() || *x < 0.0 {
            return Err(ParamError::new(param, x, Constraint::FiniteNonNegative).channel(c));
        }
    }
    Ok(())
}

fn check_albedo(v: [f64; 3]) -> Result<(), ParamError> {
    for (c, x) in v.iter().enumerate() {
        if !(0.0..=1.0).contains(x) {
            return Err(ParamError::new(Param::Albedo, x, Constraint::UnitInterval).channel(c));
        }
    }
    Ok(())
}

fn check_eta(eta: f32) -> Result<(), ParamError> {
    if !(eta.is_finite() && eta > 0.0) {
        return Err(ParamError::new(Param::Eta, eta, Constraint::FinitePositive));
    }
    Ok(())
}

fn check_units(units_per_mm: f64) -> Result<(), ParamError> {
    if !(units_per_mm.is_finite() && units_per_mm > 0.0) {
        return Err(ParamError::new(
            Param::UnitsPerMm,
            units_per_mm,
            Constraint::FinitePositive,
        ));
    }
    Ok(())
}

/// The diffuse mean free path ℓd = 1/σtr (mm) of one channel, with σa
/// floored as described in the module docs.
pub fn diffuse_mfp(sigma_s_reduced: f64, sigma_a: f64) -> f64 {
    let st = sigma_s_reduced + sigma_a;
    let sa = sigma_a.max(MIN_ABSORPTION_FRACTION * st);
    let st = sigma_s_reduced + sa;
    1.0 / (3.0 * sa * st).sqrt()
}

impl SubsurfaceParams {
    /// A named Jensen 2001 preset (case-insensitive), lengths converted with
    /// `units_per_mm`, d from the chosen fit.
    pub fn from_preset(name: &str, units_per_mm: f64, fit: Fit) -> Result<Self, ParamError> {
        Self::from_preset_with(name, units_per_mm, fit, AlbedoSource::default(), None)
    }

    /// [`Self::from_preset`] with the albedo taken from `source`, and the
    /// preset's η replaced by `eta` if given (before A is derived: under
    /// [`AlbedoSource::Table`] A depends on η).
    pub fn from_preset_with(
        name: &str,
        units_per_mm: f64,
        fit: Fit,
        source: AlbedoSource,
        eta: Option<f32>,
    ) -> Result<Self, ParamError> {
        let pr = preset(name).ok_or_else(|| {
            let names: Vec<&str> = PRESETS.iter().map(|p| p.name).collect();
            ParamError::new(
                Param::Preset,
                format!("\"{name}\""),
                Constraint::Named {
                    what: "material",
                    names: format!("known: {}", names.join(", ")),
                },
            )
        })?;
        Self::from_measured_with(
            &Measured {
                sigma_s: pr.sigma_s_reduced,
                sigma_a: pr.sigma_a,
                g: 0.0,
                albedo: pr.albedo,
                eta: eta.unwrap_or(pr.eta),
            },
            units_per_mm,
            fit,
            source,
        )
    }

    /// Measured coefficients (mm⁻¹) → per-channel (A, d). The length fed to
    /// the fit is ℓd = 1/σtr, or 1/σt' for [`Fit::VolumeMfp`]. A is the
    /// albedo table's R(α', η) (see the module docs).
    pub fn from_measured(m: &Measured, units_per_mm: f64, fit: Fit) -> Result<Self, ParamError> {
        Self::from_measured_with(m, units_per_mm, fit, AlbedoSource::default())
    }

    /// [`Self::from_measured`] with the albedo taken from `source`.
    pub(crate) fn from_measured_with(
        m: &Measured,
        units_per_mm: f64,
        fit: Fit,
        source: AlbedoSource,
    ) -> Result<Self, ParamError> {
        check_finite_nonneg(Param::SigmaS, m.sigma_s)?;
        check_finite_nonneg(Param::SigmaA, m.sigma_a)?;
        check_albedo(m.albedo)?;
        check_eta(m.eta)?;
        check_units(units_per_mm)?;
        if !(m.g.is_finite() && m.g > -1.0 && m.g < 1.0) {
            return Err(ParamError::new(Param::G, m.g, Constraint::Open(-1.0, 1.0)));
        }
        let mut d = [0.0; 3];
        let mut albedo = m.albedo;
        for (c, dc) in d.iter_mut().enumerate() {
            let ss = m.sigma_s[c] * (1.0 - m.g);
            let sa = m.sigma_a[c];
            if ss + sa <= 0.0 {
                return Err(ParamError::new(Param::SigmaS, 0, Constraint::SomeMedium).channel(c));
            }
            if source == AlbedoSource::Table {
                albedo[c] = medium_reflectance(ss / (ss + sa), m.eta as f64);
            }
            let len_mm = if fit.uses_volume_mfp() {
                1.0 / (ss + sa)
            } else {
                diffuse_mfp(ss, sa)
            };
            *dc = len_mm * units_per_mm / fit.s(albedo[c]);
        }
        let medium = Medium {
            sigma_s: m.sigma_s.map(|s| s / units_per_mm),
            sigma_a: m.sigma_a.map(|s| s / units_per_mm),
            g: m.g,
        };
        Self::checked(albedo, d, m.eta, medium)
    }

    /// Artist form: albedo A and mean free path ℓ (scene units; diffuse mean
    /// free path for the dmfp fits, volume mean free path for
    /// [`Fit::VolumeMfp`]), d = ℓ / s(A). ℓ = 0 makes a channel inactive.
    pub fn from_artist(
        albedo: [f64; 3],
        mfp: [f64; 3],
        eta: f32,
        fit: Fit,
    ) -> Result<Self, ParamError> {
        Self::from_artist_with(albedo, mfp, eta, fit, AlbedoSource::default())
    }

    /// [`Self::from_artist`] with the random-walk medium derived by
    /// inverting `source`'s reflectance (the table, or the dipole).
    pub(crate) fn from_artist_with(
        albedo: [f64; 3],
        mfp: [f64; 3],
        eta: f32,
        fit: Fit,
        source: AlbedoSource,
    ) -> Result<Self, ParamError> {
        let alpha = |c: usize| invert_reflectance(albedo[c], eta as f64, source);
        Self::from_artist_reduced(albedo, mfp, eta, fit, alpha)
    }

    /// [`Self::from_artist_with`] with the random-walk medium's reduced
    /// albedo per channel given by `alpha` (the inversion of A, done by
    /// the caller: a textured material tabulates it, `docs/bssrdf.md` §13).
    pub(crate) fn from_artist_reduced(
        albedo: [f64; 3],
        mfp: [f64; 3],
        eta: f32,
        fit: Fit,
        alpha: impl Fn(usize) -> f64,
    ) -> Result<Self, ParamError> {
        check_albedo(albedo)?;
        check_finite_nonneg(Param::Mfp, mfp)?;
        check_eta(eta)?;
        let d = std::array::from_fn(|c| mfp[c] / fit.s(albedo[c]));
        let medium = Medium::from_reduced_albedo(alpha, mfp, fit.uses_volume_mfp());
        Self::checked(albedo, d, eta, medium)
    }

    fn checked(
        albedo: [f64; 3],
        d: [f64; 3],
        eta: f32,
        medium: Medium,
    ) -> Result<Self, ParamError> {
        let p = SubsurfaceParams {
            albedo,
            d,
            eta,
            medium: Some(medium),
        };
        p.validate()?;
        Ok(p)
    }

    /// Checks the invariants every consumer relies on.
    pub fn validate(&self) -> Result<(), ParamError> {
        check_albedo(self.albedo)?;
        check_finite_nonneg(Param::D, self.d)?;
        check_eta(self.eta)
    }

    /// Whether channel `c` scatters at all (A > 0 and d > 0). Inactive
    /// channels are never sampled and always contribute exactly 0.
    #[inline]
    pub fn active(&self, c: usize) -> bool {
        self.albedo[c] > 0.0 && self.d[c] > 0.0
    }

    /// The largest d among active channels (0 if none is active).
    pub(crate) fn max_active_d(&self) -> f64 {
        (0..3)
            .filter(|&c| self.active(c))
            .map(|c| self.d[c])
            .fold(0.0, f64::max)
    }

    /// Scales channel c's lengths by `k[c]` (finite, > 0): d, and the
    /// medium's mean free paths (a textured length, `docs/bssrdf.md` §13).
    pub fn scaled_channels(&self, k: [f64; 3]) -> Self {
        SubsurfaceParams {
            d: std::array::from_fn(|c| self.d[c] * k[c]),
            medium: self.medium.map(|m| Medium {
                sigma_s: std::array::from_fn(|c| m.sigma_s[c] / k[c]),
                sigma_a: std::array::from_fn(|c| m.sigma_a[c] / k[c]),
                g: m.g,
            }),
            ..*self
        }
    }

    /// Scales all lengths (e.g. an object instanced at a different scale).
    pub fn scaled(&self, k: f64) -> Self {
        SubsurfaceParams {
            d: self.d.map(|d| d * k),
            medium: self.medium.map(|m| Medium {
                sigma_s: m.sigma_s.map(|s| s / k),
                sigma_a: m.sigma_a.map(|s| s / k),
                g: m.g,
            }),
            ..*self
        }
    }
}

#[cfg(test)]
// Tests index parallel per-channel arrays by channel number.
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;

    /// An albedo the dipole reaches only without absorption (A = 1, or
    /// above its value at α' = 1) inverts to the cap 1 − 10⁻⁶, not to 1:
    /// the medium keeps σa ≥ 10⁻⁶·σt' like the diffusion side; below the
    /// cap the inversion is exact.
    #[test]
    fn inverting_an_albedo_without_absorption_stops_at_the_cap() {
        let cap = 1.0 - MIN_ABSORPTION_FRACTION;
        for eta in [1.0, 1.3, 1.5] {
            for a in [
                1.0,
                dipole_reflectance(1.0, eta),
                0.9999 + 0.0001 * dipole_reflectance(1.0, eta),
            ] {
                let alpha = invert_dipole_reflectance(a, eta);
                assert!(alpha <= cap, "η {eta}, A {a}: α' = {alpha}");
                assert!(alpha > cap - 1e-6, "η {eta}, A {a}: α' = {alpha}");
            }
            let below = dipole_reflectance(0.999, eta);
            assert!((invert_dipole_reflectance(below, eta) - 0.999).abs() < 1e-9);
        }
    }

    /// Lengths carry the scene's unit, so scaling every given length by k
    /// scales every coefficient by 1/k — the zero-length channel's
    /// optically thick stand-in included (it is tied to the shortest given
    /// length, not to the unit).
    #[test]
    fn the_artist_medium_scales_with_its_lengths_zero_length_channel_included() {
        let albedo = [0.6, 0.4, 0.2];
        let mfp = [0.5, 0.0, 2.0];
        for volume_mfp in [false, true] {
            let m = Medium::from_reflectance(albedo, mfp, 1.3, volume_mfp, AlbedoSource::Table);
            // the zero-length channel absorbs only, far denser than the rest
            assert_eq!(m.sigma_s[1], 0.0);
            assert!(m.sigma_a[1] >= 1e5 * (m.sigma_s[0] + m.sigma_a[0]));
            for k in [1e-3, 0.25, 40.0] {
                let scaled = mfp.map(|l| l * k);
                let mk =
                    Medium::from_reflectance(albedo, scaled, 1.3, volume_mfp, AlbedoSource::Table);
                for c in 0..3 {
                    for (a, b) in [(m.sigma_s[c], mk.sigma_s[c]), (m.sigma_a[c], mk.sigma_a[c])] {
                        assert!(
                            (b * k - a).abs() <= 1e-12 * a.abs(),
                            "channel {c}, k {k}: {a} vs {b}·k"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn presets_are_complete_and_case_insensitive() {
        assert_eq!(PRESETS.len(), 12);
        for pr in &PRESETS {
            let eta = if pr.name == "Marble" { 1.5 } else { 1.3 };
            assert_eq!(pr.eta, eta);
            let up = SubsurfaceParams::from_preset(&pr.name.to_uppercase(), 1.0, Fit::Searchlight)
                .unwrap();
            let lo = SubsurfaceParams::from_preset(&pr.name.to_lowercase(), 1.0, Fit::Searchlight)
                .unwrap();
            assert_eq!(up, lo);
            for c in 0..3 {
                assert!(
                    up.d[c].is_finite() && up.d[c] > 0.0,
                    "{} d {:?}",
                    pr.name,
                    up.d
                );
            }
        }
        let e = SubsurfaceParams::from_preset("jade", 1.0, Fit::Searchlight).unwrap_err();
        assert_eq!(e.param, Param::Preset);
        assert!(
            e.to_string().starts_with("preset:") && e.to_string().contains("Marble"),
            "{e}"
        );
    }

    /// A preset with the Jensen table's own A ([`AlbedoSource::Given`]), so the formulas can be checked with the tabulated numbers.
    fn given(name: &str, units: f64, fit: Fit) -> SubsurfaceParams {
        SubsurfaceParams::from_preset_with(name, units, fit, AlbedoSource::Given, None).unwrap()
    }

    #[test]
    fn measured_form_follows_the_formulas() {
        // Marble red by hand: σtr = √(3 σa (σs' + σa)), d = ℓd / s(A).
        let m = given("marble", 1.0, Fit::Searchlight);
        let (ss, sa, a) = (2.19f64, 0.0021f64, 0.83f64);
        let ld = 1.0 / (3.0 * sa * (ss + sa)).sqrt();
        let d = ld / (3.5 + 100.0 * (a - 0.33f64).powi(4));
        assert!((m.d[0] - d).abs() < 1e-12 * d);
        assert_eq!(m.albedo, [0.83, 0.79, 0.75]);
        assert_eq!(m.eta, 1.5);
        // units: a scene in metres
        let mm = given("marble", 1e-3, Fit::Searchlight);
        assert!((mm.d[0] - d * 1e-3).abs() < 1e-15);
        // g: σs = σs'/(1 − g) gives the same result
        let g = SubsurfaceParams::from_measured_with(
            &Measured {
                sigma_s: [2.19 / 0.2, 2.62 / 0.2, 3.0 / 0.2],
                sigma_a: [0.0021, 0.0041, 0.0071],
                g: 0.8,
                albedo: [0.83, 0.79, 0.75],
                eta: 1.5,
            },
            1.0,
            Fit::Searchlight,
            AlbedoSource::Given,
        )
        .unwrap();
        for c in 0..3 {
            assert!((g.d[c] - m.d[c]).abs() < 1e-9 * m.d[c]);
        }
        // volume mfp fit uses 1/σt'
        let v = given("marble", 1.0, Fit::VolumeMfp);
        assert!((v.d[0] - 1.0 / (ss + sa) / Fit::VolumeMfp.s(a)).abs() < 1e-12);
        let t = given("marble", 1.0, Fit::DiffuseTransmission);
        assert!((t.d[0] - ld / Fit::DiffuseTransmission.s(a)).abs() < 1e-12 * ld);
    }

    /// The default albedo source: A = R(α', η) of the albedo table for
    /// presets and measured media (whatever `albedo` says), d = ℓd / s(A)
    /// with that A, η overrides applied before A; the artist form's medium
    /// reflects the A asked for; `given` keeps the Jensen table's numbers.
    #[test]
    fn table_albedo_replaces_the_given_one() {
        let t = SubsurfaceParams::from_preset("marble", 1.0, Fit::Searchlight).unwrap();
        let old = given("marble", 1.0, Fit::Searchlight);
        let pr = preset("marble").unwrap();
        for c in 0..3 {
            let (ss, sa) = (pr.sigma_s_reduced[c], pr.sigma_a[c]);
            let a = medium_reflectance(ss / (ss + sa), 1.5);
            assert_eq!(t.albedo[c], a);
            assert_ne!(t.albedo[c], old.albedo[c]);
            let ld = diffuse_mfp(ss, sa);
            assert!((t.d[c] - ld / Fit::Searchlight.s(a)).abs() < 1e-12 * ld);
        }
        assert_eq!(t.medium, old.medium);
        assert_eq!(old.albedo, [0.83, 0.79, 0.75]);
        // η = 1.0 lets more light out than η = 1.5
        let e1 = SubsurfaceParams::from_preset_with(
            "marble",
            1.0,
            Fit::Searchlight,
            AlbedoSource::Table,
            Some(1.0),
        )
        .unwrap();
        assert_eq!(e1.eta, 1.0);
        assert!((0..3).all(|c| e1.albedo[c] > t.albedo[c]), "{e1:?} {t:?}");
        // the measured form ignores `albedo` under the table
        let m = Measured {
            sigma_s: [1.0, 2.0, 3.0],
            sigma_a: [0.1, 0.01, 0.001],
            g: 0.0,
            albedo: [0.5; 3],
            eta: 1.3,
        };
        let p = SubsurfaceParams::from_measured(&m, 1.0, Fit::Searchlight).unwrap();
        assert!(
            p.albedo[0] < p.albedo[1] && p.albedo[1] < p.albedo[2],
            "{p:?}"
        );
        // artist form: the derived medium reflects A by the table, and
        // differs from the dipole's medium
        let a = [0.2, 0.5, 0.9];
        let art = SubsurfaceParams::from_artist(a, [1.0; 3], 1.4, Fit::Searchlight).unwrap();
        let dip = SubsurfaceParams::from_artist_with(
            a,
            [1.0; 3],
            1.4,
            Fit::Searchlight,
            AlbedoSource::Given,
        )
        .unwrap();
        let (mt, md) = (art.medium.unwrap(), dip.medium.unwrap());
        let eta = 1.4f32 as f64; // η is stored as f32
        for c in 0..3 {
            let alpha = mt.sigma_s[c] / mt.sigma_t()[c];
            let r = medium_reflectance(alpha, eta);
            assert!((r - a[c]).abs() < 1e-9, "{c}: {r} vs {}", a[c]);
            let alpha_d = md.sigma_s[c] / md.sigma_t()[c];
            assert!((dipole_reflectance(alpha_d, eta) - a[c]).abs() < 1e-9);
            assert_ne!(alpha, alpha_d);
            // σtr = 1/ℓd in both
            let st = mt.sigma_t()[c];
            assert!(((3.0 * mt.sigma_a[c] * st).sqrt() - 1.0).abs() < 1e-9);
        }
        // outside the table's η range: the dipole
        let out = SubsurfaceParams::from_artist(a, [1.0; 3], 2.4, Fit::Searchlight).unwrap();
        assert_eq!(
            out.medium,
            SubsurfaceParams::from_artist_with(
                a,
                [1.0; 3],
                2.4,
                Fit::Searchlight,
                AlbedoSource::Given
            )
            .unwrap()
            .medium
        );
        assert!(AlbedoSource::parse("TABLE") == Ok(AlbedoSource::Table));
        let e = AlbedoSource::parse("dipole").unwrap_err();
        assert!(e.to_string().starts_with("albedo_source:"), "{e}");
    }

    #[test]
    fn spectralon_sigma_a_zero_is_finite() {
        let s = SubsurfaceParams::from_preset("Spectralon", 1.0, Fit::Searchlight).unwrap();
        for c in 0..3 {
            assert!(s.active(c) && s.d[c].is_finite() && s.d[c] > 0.0);
            let ld = diffuse_mfp(PRESETS[10].sigma_s_reduced[c], 0.0);
            // capped at 1/√(3·1e-6) volume mean free paths
            let cap = 1.0 / (3.0 * MIN_ABSORPTION_FRACTION).sqrt() / PRESETS[10].sigma_s_reduced[c];
            assert!((ld / cap - 1.0).abs() < 1e-5, "{ld} vs {cap}");
        }
        // and no table material is touched by the floor
        for pr in PRESETS.iter().filter(|p| p.name != "Spectralon") {
            for c in 0..3 {
                let (ss, sa) = (pr.sigma_s_reduced[c], pr.sigma_a[c]);
                let exact = 1.0 / (3.0 * sa * (ss + sa)).sqrt();
                assert_eq!(diffuse_mfp(ss, sa), exact, "{}", pr.name);
            }
        }
    }

    /// Ketchup blue: the Jensen table's A = 0 makes the channel inactive
    /// (`given`). The albedo table gives what the medium reflects instead,
    /// α' = 0.02 → A ≈ 0.005 (single scattering out of a strong absorber),
    /// small but not 0, so the channel is active by default.
    #[test]
    fn ketchup_blue_is_inactive() {
        let k = given("ketchup", 1.0, Fit::Searchlight);
        assert!(k.active(0) && k.active(1) && !k.active(2));
        assert!(k.d[2].is_finite());
        assert_eq!(k.max_active_d(), k.d[0].max(k.d[1]));
        let t = SubsurfaceParams::from_preset("ketchup", 1.0, Fit::Searchlight).unwrap();
        assert!(
            t.active(2) && t.albedo[2] > 0.0 && t.albedo[2] < 0.02,
            "{t:?}"
        );
    }

    #[test]
    fn validation_names_the_field() {
        let e = SubsurfaceParams::from_artist([0.5, 1.2, 0.5], [1.0; 3], 1.3, Fit::Searchlight)
            .unwrap_err();
        assert_eq!(
            (e.param, e.channel, e.found.as_str()),
            (Param::Albedo, Some(1), "1.2")
        );
        assert!(e.to_string().starts_with("albedo.g"), "{e}");
        let e =
            SubsurfaceParams::from_artist([0.5; 3], [1.0, f64::NAN, 1.0], 1.3, Fit::Searchlight)
                .unwrap_err();
        assert_eq!((e.param, e.channel), (Param::Mfp, Some(1)));
        assert!(e.to_string().starts_with("mfp.g"), "{e}");
        let e =
            SubsurfaceParams::from_artist([0.5; 3], [1.0; 3], 0.0, Fit::Searchlight).unwrap_err();
        assert_eq!(e.param, Param::Eta);
        let e = SubsurfaceParams::from_preset("apple", -1.0, Fit::Searchlight).unwrap_err();
        assert_eq!(e.param, Param::UnitsPerMm);
        let base = Measured {
            sigma_s: [1.0; 3],
            sigma_a: [0.1; 3],
            g: 0.0,
            albedo: [0.5; 3],
            eta: 1.3,
        };
        let e = SubsurfaceParams::from_measured(
            &Measured {
                sigma_a: [0.1, -0.1, 0.1],
                ..base
            },
            1.0,
            Fit::Searchlight,
        )
        .unwrap_err();
        assert_eq!((e.param, e.channel), (Param::SigmaA, Some(1)));
        let e =
            SubsurfaceParams::from_measured(&Measured { g: 1.0, ..base }, 1.0, Fit::Searchlight)
                .unwrap_err();
        assert_eq!(
            (e.param, &e.constraint),
            (Param::G, &Constraint::Open(-1.0, 1.0))
        );
        let e = SubsurfaceParams::from_measured(
            &Measured {
                sigma_s: [0.0; 3],
                sigma_a: [0.0, 1.0, 1.0],
                ..base
            },
            1.0,
            Fit::Searchlight,
        )
        .unwrap_err();
        assert_eq!((e.param, e.channel), (Param::SigmaS, Some(0)));
        assert!(e.to_string().contains("no medium"), "{e}");
        // artist form: ℓ = 0 is allowed and makes the channel inactive
        let a = SubsurfaceParams::from_artist([0.5; 3], [1.0, 0.0, 2.0], 1.3, Fit::Searchlight)
            .unwrap();
        assert!(a.active(0) && !a.active(1) && a.active(2));
        assert!((a.d[2] - 2.0 / Fit::Searchlight.s(0.5)).abs() < 1e-15);
    }
}
