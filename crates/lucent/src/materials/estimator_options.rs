//! The subsurface estimator's options: one value ([`EstimatorOptions`])
//! and one table ([`OPTIONS`]) that gives each option its name (the scene
//! key, and with `-` for `_` the command-line flag), its values, its
//! description and its default. The scene loader, `lucent render`'s flags,
//! `--explain`, the EXR header and a part's identity all read the table
//! (`docs/scene-format.md`, "Subsurface sampling options"; the estimator
//! itself is `docs/bssrdf.md` §4–§7).
//!
//! Research variants (normal-only axes after King et al. 2013, one
//! channel per sample, the uniform and tabulated radius samplers, LOD at
//! every hit) stay accepted for studies and tests but are not offered in
//! the help.

use std::fmt;

use super::lod::{LodMode, DEFAULT_THRESHOLD};
use crate::bssrdf::{ChannelStrategy, ProbeAxes, ProbeOptions, ProfileShape, RadiusSampler};
use crate::error::ParamError;

/// The default of [`EstimatorOptions::regularize`], chosen by time to
/// error with its bias counted (`docs/accuracy.md`, "Real meshes").
pub const DEFAULT_REGULARIZE: f32 = 0.3;

/// The default of [`EstimatorOptions::pair_paths`], chosen by time to
/// error (`docs/accuracy.md`, "Real meshes: where the error lives").
pub const DEFAULT_PAIR_PATHS: u32 = 2;

/// Every sampling option of a subsurface material; `Default` is the
/// recommended setting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimatorOptions {
    /// The probe sampler's options (radius, Rmax quantile, axes, channel,
    /// renormalization).
    pub probe: ProbeOptions,
    /// The normalized Fresnel lobe Sw at the entry point (else 1/π).
    pub exit_sw: bool,
    /// The coat's reflection is rendered (else the path is weighted by the
    /// transmitted fraction and the reflected light is lost).
    pub specular: bool,
    /// The coat's roughness in [0, 1] (α = roughness²); 0 is a mirror.
    pub roughness: f32,
    /// The boundary the random walk simulates.
    pub boundary: WalkBoundary,
    /// The curvature correction of the diffusion weight.
    pub curvature: CurvatureMode,
    pub lod: LodMode,
    /// The footprint-to-Rmax ratio at which [`LodMode::Auto`] switches.
    pub lod_threshold: f32,
    /// At the camera vertex, the plane control variate.
    pub control_variate: bool,
    /// At the camera vertex, an antithetic pair of probes.
    pub probe_pair: bool,
    /// At the camera vertex, with the pair, the paths that go on from its
    /// entry points: 1 (from one, chosen), 2 (one from each) or 4 (two
    /// from each).
    pub pair_paths: u32,
    /// The coat's least roughness once the path has scattered off a
    /// non-specular lobe (0: the coat as given everywhere).
    pub regularize: f32,
    /// The accuracy budget (`super::accuracy`): the largest predicted
    /// relative error allowed; None: the estimator as the options give it.
    pub accuracy: Option<f32>,
}

impl Default for EstimatorOptions {
    fn default() -> Self {
        EstimatorOptions {
            probe: ProbeOptions::default(),
            exit_sw: true,
            specular: true,
            roughness: 0.0,
            boundary: WalkBoundary::DIELECTRIC,
            curvature: CurvatureMode::Auto,
            lod: LodMode::Auto,
            lod_threshold: DEFAULT_THRESHOLD,
            control_variate: false,
            probe_pair: true,
            pair_paths: DEFAULT_PAIR_PATHS,
            regularize: DEFAULT_REGULARIZE,
            accuracy: None,
        }
    }
}

/// The scene's `curvature_correction` setting.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CurvatureMode {
    /// Correct the diffusion weight on convex surfaces (the default).
    #[default]
    Auto,
    /// The half-space profile everywhere.
    Off,
}

impl CurvatureMode {
    /// "auto" or "off" (case-insensitive).
    pub fn parse(s: &str) -> Option<Self> {
        match s.to_ascii_lowercase().as_str() {
            "auto" => Some(CurvatureMode::Auto),
            "off" => Some(CurvatureMode::Off),
            _ => None,
        }
    }

    /// The name [`parse`](Self::parse) reads.
    pub fn name(self) -> &'static str {
        match self {
            CurvatureMode::Auto => "auto",
            CurvatureMode::Off => "off",
        }
    }
}

/// The boundary of a subsurface object in the random walk
/// (`docs/bssrdf.md` §7, `crate::integrator::randomwalk`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WalkBoundary {
    /// The exact smooth dielectric: Fresnel reflection or refraction along
    /// Snell's direction. `connect`: the walk also samples the lights
    /// through the boundary at its scattering points
    /// (`crate::integrator::walk_nee`; the same model, another estimator).
    Dielectric { connect: bool },
    /// The same Fresnel probabilities, but transmission forgets the
    /// direction (`crate::integrator::diffuse_boundary`): a different model,
    /// whose exit point is a vertex where lights are sampled.
    /// `exit_nee: false` renders the same model without light sampling at
    /// the exit (for tests and measurements; not in the scene format).
    Diffuse { exit_nee: bool },
}

impl Default for WalkBoundary {
    fn default() -> Self {
        WalkBoundary::DIELECTRIC
    }
}

impl WalkBoundary {
    /// The exact smooth dielectric without light sampling through it.
    pub const DIELECTRIC: WalkBoundary = WalkBoundary::Dielectric { connect: false };

    /// "dielectric", "dielectric-nee" or "diffuse" (case-insensitive).
    pub fn parse(s: &str) -> Option<Self> {
        match s.to_ascii_lowercase().as_str() {
            "dielectric" => Some(WalkBoundary::Dielectric { connect: false }),
            "dielectric-nee" => Some(WalkBoundary::Dielectric { connect: true }),
            "diffuse" => Some(WalkBoundary::Diffuse { exit_nee: true }),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            WalkBoundary::Dielectric { connect: false } => "dielectric",
            WalkBoundary::Dielectric { connect: true } => "dielectric-nee",
            WalkBoundary::Diffuse { exit_nee: true } => "diffuse",
            WalkBoundary::Diffuse { exit_nee: false } => "diffuse-no-nee",
        }
    }
}

/// A value an option cannot take.
#[derive(Clone, Debug, PartialEq)]
pub enum OptionError {
    /// Not one of the option's names: what it accepts, and what was given.
    Expected { expected: String, found: String },
    /// A parameter out of its domain (the radius sampler's name or table
    /// size), as the BSSRDF math reports it.
    Param(ParamError),
}

impl fmt::Display for OptionError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            OptionError::Expected { expected, found } => {
                write!(f, "expected {expected}, found \"{found}\"")
            }
            OptionError::Param(e) => write!(f, "{}", e.problem()),
        }
    }
}

impl std::error::Error for OptionError {}

/// One option: its name, the values a user picks from (`research`: those
/// kept for studies and tests, accepted but not offered), what it does,
/// and how it is read and written.
pub struct EstimatorOption {
    /// The scene key; the flag is `--` and the name with `-` for `_`.
    pub name: &'static str,
    /// The values offered, as the help lists them.
    pub values: &'static [&'static str],
    /// Values accepted but not offered (research and test variants).
    pub research: &'static [&'static str],
    /// Whether a scene file may give the research values too.
    pub research_in_scenes: bool,
    /// Whether `lucent render` has a flag for it (else scene only).
    pub flag: bool,
    pub description: &'static str,
    /// Sets the option in `o` from its text.
    pub set: fn(&mut EstimatorOptions, &str) -> Result<(), OptionError>,
    /// The option's value in `o`, as the scene format writes it.
    pub get: fn(&EstimatorOptions) -> String,
}

impl EstimatorOption {
    /// The command-line flag, without its dashes.
    pub fn flag_name(&self) -> String {
        self.name.replace('_', "-")
    }

    /// The default value's text.
    pub fn default_text(&self) -> String {
        (self.get)(&EstimatorOptions::default())
    }

    /// The help text: description, values offered, default.
    pub fn help(&self) -> String {
        let values = if self.values.is_empty() {
            String::new()
        } else {
            format!(": {}", self.values.join(" | "))
        };
        format!(
            "{}{values} (default {}).",
            self.description,
            self.default_text()
        )
    }

    /// Whether `s` names one of the research values (case-insensitive).
    pub(crate) fn is_research(&self, s: &str) -> bool {
        let base = s.split(':').next().unwrap_or(s);
        self.research.iter().any(|r| r.eq_ignore_ascii_case(base))
    }

    /// The [`OptionError::Expected`] for `found`, listing the values
    /// offered.
    pub fn expected(&self, found: &str) -> OptionError {
        let quoted: Vec<String> = self.values.iter().map(|v| format!("\"{v}\"")).collect();
        let expected = match quoted.split_last() {
            Some((last, [])) => last.clone(),
            Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
            None => String::new(),
        };
        OptionError::Expected {
            expected,
            found: found.into(),
        }
    }
}

/// The option named `name` (scene key or flag name).
pub fn option(name: &str) -> Option<&'static EstimatorOption> {
    let key = name.replace('-', "_");
    OPTIONS.iter().find(|o| o.name == key)
}

/// `s` as one of `choices` (case-insensitive), else `option`'s error.
fn choose<T: Copy>(name: &str, s: &str, choices: &[(&str, T)]) -> Result<T, OptionError> {
    choices
        .iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(s))
        .map(|&(_, v)| v)
        .ok_or_else(|| option(name).expect("a table option").expected(s))
}

fn boolean(s: &str) -> Result<bool, OptionError> {
    s.parse().map_err(|_| OptionError::Expected {
        expected: "true or false".into(),
        found: s.into(),
    })
}

fn number<T: std::str::FromStr>(s: &str) -> Result<T, OptionError> {
    s.trim().parse().map_err(|_| OptionError::Expected {
        expected: "a number".into(),
        found: s.into(),
    })
}

/// Every option, in the order the EXR header and a part's identity list
/// them.
pub static OPTIONS: [EstimatorOption; 18] = [
    EstimatorOption {
        name: "radius",
        values: &["analytic", "mixture"],
        research: &["uniform", "table", "table-uniform"],
        research_in_scenes: true,
        flag: true,
        description: "Radius sampler",
        set: |o, s| {
            o.probe.radius = RadiusSampler::parse(s).map_err(OptionError::Param)?;
            Ok(())
        },
        get: |o| o.probe.radius.name(),
    },
    EstimatorOption {
        name: "rmax_quantile",
        values: &[],
        research: &[],
        research_in_scenes: true,
        flag: true,
        description: "Probe sphere radius as a quantile of the widest channel's profile, in (0, 1)",
        set: |o, s| {
            o.probe.rmax_quantile = number(s)?;
            Ok(())
        },
        get: |o| o.probe.rmax_quantile.to_string(),
    },
    EstimatorOption {
        name: "axes",
        values: &["curvature", "mis3"],
        research: &["normal"],
        research_in_scenes: true,
        flag: true,
        description: "Probe axes: N/T/B with MIS, T/B probabilities from the curvature; or N/T/B \
                      at ½, ¼, ¼",
        set: |o, s| {
            o.probe.axes = choose("axes", s, &ProbeAxes::ALL.map(|a| (a.name(), a)))?;
            Ok(())
        },
        get: |o| o.probe.axes.name().into(),
    },
    EstimatorOption {
        name: "channel",
        values: &["mis"],
        research: &["single"],
        research_in_scenes: true,
        flag: true,
        description: "Channel choice: all channels with the balance heuristic",
        set: |o, s| {
            let all = [ChannelStrategy::Single, ChannelStrategy::Mis];
            o.probe.channel = choose("channel", s, &all.map(|c| (c.name(), c)))?;
            Ok(())
        },
        get: |o| o.probe.channel.name().into(),
    },
    EstimatorOption {
        name: "renormalize",
        values: &[],
        research: &[],
        research_in_scenes: true,
        flag: true,
        description: "Divide the profile by CDF(Rmax) so truncation loses no energy",
        set: |o, s| {
            o.probe.renormalize = boolean(s)?;
            Ok(())
        },
        get: |o| o.probe.renormalize.to_string(),
    },
    EstimatorOption {
        name: "exit_sw",
        values: &[],
        research: &[],
        research_in_scenes: true,
        flag: true,
        description: "Normalized Fresnel lobe Sw at the entry point (false: cosine lobe)",
        set: |o, s| {
            o.exit_sw = boolean(s)?;
            Ok(())
        },
        get: |o| o.exit_sw.to_string(),
    },
    EstimatorOption {
        name: "specular",
        values: &[],
        research: &[],
        research_in_scenes: true,
        flag: true,
        description: "Specular reflection layer on top",
        set: |o, s| {
            o.specular = boolean(s)?;
            Ok(())
        },
        get: |o| o.specular.to_string(),
    },
    EstimatorOption {
        name: "roughness",
        values: &[],
        research: &[],
        research_in_scenes: true,
        flag: true,
        description: "Roughness of that layer in [0, 1] (0: a mirror; GGX with α = roughness²)",
        set: |o, s| {
            o.roughness = number::<f64>(s)? as f32;
            Ok(())
        },
        get: |o| o.roughness.to_string(),
    },
    EstimatorOption {
        name: "boundary",
        values: &["dielectric", "dielectric-nee", "diffuse"],
        research: &[],
        research_in_scenes: true,
        flag: true,
        description: "Random-walk boundary: exact smooth dielectric; the same with lights \
                      sampled through it from the walk's scattering points; or diffuse \
                      Fresnel transmission with light sampling at the exit (another model)",
        set: |o, s| {
            o.boundary = WalkBoundary::parse(s).ok_or_else(|| OPTIONS[8].expected(s))?;
            Ok(())
        },
        get: |o| o.boundary.name().into(),
    },
    EstimatorOption {
        name: "curvature_correction",
        values: &["auto", "off"],
        research: &[],
        research_in_scenes: true,
        flag: false,
        description: "Correct the diffusion weight on convex surfaces",
        set: |o, s| {
            o.curvature = CurvatureMode::parse(s).ok_or_else(|| OPTIONS[9].expected(s))?;
            Ok(())
        },
        get: |o| o.curvature.name().into(),
    },
    EstimatorOption {
        name: "lod",
        values: &["auto", "off"],
        research: &["force"],
        research_in_scenes: false,
        flag: true,
        description: "Level of detail: albedo A where the path's footprint is wide against the \
                      profile (per material threshold); or always probe",
        set: |o, s| {
            let all = [LodMode::Auto, LodMode::Off, LodMode::Force];
            o.lod = choose("lod", s, &all.map(|l| (l.name(), l)))?;
            Ok(())
        },
        get: |o| o.lod.name().into(),
    },
    EstimatorOption {
        name: "lod_threshold",
        values: &[],
        research: &[],
        research_in_scenes: true,
        flag: false,
        description: "The footprint-to-Rmax ratio from which level of detail applies",
        set: |o, s| {
            o.lod_threshold = number::<f64>(s)? as f32;
            Ok(())
        },
        get: |o| o.lod_threshold.to_string(),
    },
    EstimatorOption {
        name: "control_variate",
        values: &[],
        research: &[],
        research_in_scenes: true,
        flag: true,
        description: "At the camera vertex, the plane control variate on the light sampled at \
                      the entry point",
        set: |o, s| {
            o.control_variate = boolean(s)?;
            Ok(())
        },
        get: |o| o.control_variate.to_string(),
    },
    EstimatorOption {
        name: "probe_pair",
        values: &[],
        research: &[],
        research_in_scenes: true,
        flag: true,
        description: "At the camera vertex, an antithetic pair of probes",
        set: |o, s| {
            o.probe_pair = boolean(s)?;
            Ok(())
        },
        get: |o| o.probe_pair.to_string(),
    },
    EstimatorOption {
        name: "pair_paths",
        values: &["1", "2", "4"],
        research: &[],
        research_in_scenes: true,
        flag: true,
        description: "At the camera vertex, with the pair, the paths that go on from its entry \
                      points: 1 from one of the two, chosen; 2, one from each; 4, two from each \
                      (each weighted by their share)",
        set: |o, s| {
            o.pair_paths = choose("pair_paths", s, &[("1", 1), ("2", 2), ("4", 4)])?;
            Ok(())
        },
        get: |o| o.pair_paths.to_string(),
    },
    EstimatorOption {
        name: "regularize",
        values: &[],
        research: &[],
        research_in_scenes: true,
        flag: true,
        description: "Least roughness in [0, 1] of the coat once the path has scattered off a \
                      non-specular lobe: a smooth coat there reflects as a rough one, \
                      light-sampled, which bounds the caustics its mirror makes (biased, \
                      consistent as it goes to 0; 0: the coat as given everywhere)",
        set: |o, s| {
            o.regularize = number::<f64>(s)? as f32;
            Ok(())
        },
        get: |o| o.regularize.to_string(),
    },
    EstimatorOption {
        name: "profile",
        values: &["burley", "tabulated"],
        research: &[],
        research_in_scenes: true,
        flag: true,
        description: "Diffusion profile: the normalized-diffusion fit; or the half-space's \
                      transfer by the random walk, tabulated (light reaches farther, as under \
                      a key light; sampled by its own inverse CDF)",
        set: |o, s| {
            let all = ProfileShape::ALL.map(|p| (p.name(), p));
            o.probe.profile = choose("profile", s, &all)?;
            Ok(())
        },
        get: |o| o.probe.profile.name().into(),
    },
    EstimatorOption {
        name: "accuracy",
        values: &[],
        research: &[],
        research_in_scenes: true,
        flag: true,
        description: "Accuracy budget: the largest predicted error of the object's image, as \
                      a fraction (0.01) or per cent (1%); lucent picks per object the \
                      cheapest estimator (diffusion with the Burley or the tabulated profile, \
                      or the random walk) the error model predicts within it (off: the \
                      options as given)",
        set: |o, s| {
            o.accuracy = super::accuracy::parse(s).ok_or_else(|| OptionError::Expected {
                expected: super::accuracy::EXPECTED.into(),
                found: s.into(),
            })?;
            Ok(())
        },
        get: |o| super::accuracy::name(o.accuracy),
    },
];

/// Options given by name (the command line's, a study's): applied in
/// order over a material's own.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Assignments(Vec<(&'static EstimatorOption, String)>);

impl PartialEq for EstimatorOption {
    fn eq(&self, o: &Self) -> bool {
        self.name == o.name
    }
}

impl fmt::Debug for EstimatorOption {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(self.name)
    }
}

impl Assignments {
    /// Adds `option = value`, checked to parse.
    pub fn push(
        &mut self,
        option: &'static EstimatorOption,
        value: &str,
    ) -> Result<(), OptionError> {
        (option.set)(&mut EstimatorOptions::default(), value)?;
        self.0.push((option, value.into()));
        Ok(())
    }

    /// These assignments with option `name` set to `value` in place of any
    /// earlier value (for values written from the option's own names, as
    /// a study builds its configurations).
    ///
    /// # Panics
    /// If `name` is not an option of the table or `value` not one it
    /// reads: the caller's mistake, never input.
    pub fn with(mut self, name: &str, value: impl fmt::Display) -> Assignments {
        let row = option(name).unwrap_or_else(|| panic!("no estimator option \"{name}\""));
        let value = value.to_string();
        self.0.retain(|(r, _)| !std::ptr::eq(*r, row));
        if let Err(e) = self.push(row, &value) {
            panic!("{name} = {value}: {e}");
        }
        self
    }

    /// The value given for option `name`, as given (the last one given).
    pub fn value(&self, name: &str) -> Option<&str> {
        let key = name.replace('-', "_");
        self.0
            .iter()
            .rev()
            .find(|(r, _)| r.name == key)
            .map(|(_, v)| v.as_str())
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// `o` with every assignment applied.
    pub fn over(&self, mut o: EstimatorOptions) -> EstimatorOptions {
        for (option, value) in &self.0 {
            (option.set)(&mut o, value).expect("checked when pushed");
        }
        o
    }

    /// Applies the assignments to every subsurface material of
    /// `materials`, textured or not (each over its own options).
    pub fn apply_all(&self, materials: &mut [super::Material]) -> Result<(), ParamError> {
        for m in materials.iter_mut() {
            match m {
                super::Material::Subsurface(ss) => {
                    *ss = std::sync::Arc::new(ss.with_options(&self.over(*ss.options()))?);
                }
                super::Material::Textured(t) => {
                    if let super::Material::Subsurface(ss) = &t.base {
                        let ss = ss.with_options(&self.over(*ss.options()))?;
                        std::sync::Arc::make_mut(t).base =
                            super::Material::Subsurface(std::sync::Arc::new(ss));
                    }
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// The options given, `name=value` in table order with the values as
    /// the scene format writes them (a part's identity).
    pub fn canonical(&self) -> String {
        let o = self.over(EstimatorOptions::default());
        let given: Vec<String> = OPTIONS
            .iter()
            .filter(|row| self.0.iter().any(|(r, _)| std::ptr::eq(*r, *row)))
            .map(|row| format!("{}={}", row.name, (row.get)(&o)))
            .collect();
        given.join(" ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_option_reads_back_its_default_and_has_a_unique_name() {
        for row in &OPTIONS {
            let mut o = EstimatorOptions::default();
            (row.set)(&mut o, &row.default_text()).unwrap();
            assert_eq!(o, EstimatorOptions::default(), "{}", row.name);
            assert_eq!(option(row.name).map(|r| r.name), Some(row.name));
            for v in row.values.iter().chain(row.research) {
                let v = if *v == "table" || *v == "table-uniform" {
                    format!("{v}:64")
                } else {
                    v.to_string()
                };
                assert!((row.set)(&mut o, &v).is_ok(), "{} = {v}", row.name);
            }
        }
    }

    #[test]
    fn an_unknown_value_lists_only_the_values_offered() {
        let e = (option("axes").unwrap().set)(&mut EstimatorOptions::default(), "tangent");
        assert_eq!(
            e.unwrap_err().to_string(),
            "expected \"curvature\" or \"mis3\", found \"tangent\""
        );
        assert!(option("lod").unwrap().is_research("Force"));
        assert!(option("radius").unwrap().is_research("table:8"));
    }

    #[test]
    fn canonical_text_is_in_table_order_with_scene_names() {
        let mut a = Assignments::default();
        a.push(option("probe-pair").unwrap(), "true").unwrap();
        a.push(option("axes").unwrap(), "Normal").unwrap();
        assert_eq!(a.canonical(), "axes=normal probe_pair=true");
        assert!(a.push(option("exit_sw").unwrap(), "yes").is_err());
    }
}
