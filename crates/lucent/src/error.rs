//! The library's one error type, [`Error`], and the structured errors it
//! wraps.
//!
//! Every failure says what the user needs to fix it: bad input names the
//! file, the line (1-based) and the field ([`InputError`]); an invalid
//! parameter of the subsurface model names the parameter, the channel, the
//! value found and the constraint it breaks ([`ParamError`]), as data, so
//! that the scene loader can point at the key in the scene file without
//! reading the message; I/O failures name the path.
//!
//! [`Error::is_input`] splits failures into the user's input (arguments,
//! scene files, meshes: exit code 2 of the CLI) and failures while running
//! or writing output (exit code 1). The CLI maps this in one place.

use std::fmt;
use std::path::PathBuf;

/// Everything the library can fail with.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Bad input located in a file: a scene file or an OBJ mesh.
    #[error(transparent)]
    Located(#[from] InputError),
    /// A subsurface parameter or sampling option out of its domain, not tied
    /// to a file (an API call, a command-line override).
    #[error(transparent)]
    Param(#[from] ParamError),
    /// A command-line argument or option that cannot be used.
    #[error("{argument}: {problem}")]
    Argument { argument: String, problem: String },
    /// A ray-query backend that this build does not have (with how to get it).
    #[error("{0}")]
    Unavailable(String),
    /// The backend refused to build over the scene's meshes (Embree's own
    /// errors, or a mesh it cannot share). Counted as input, as the scene
    /// is what the backend could not take.
    #[error("{0}")]
    Backend(String),
    /// A file could not be read (not a located input error: e.g. an image a
    /// tool reads back).
    #[error("cannot read {}: {problem}", path.display())]
    Read { path: PathBuf, problem: String },
    /// An output file could not be written; nothing was left under `path`.
    #[error("cannot write {}: {problem}", path.display())]
    Write { path: PathBuf, problem: String },
    /// Any other input error, by message (for callers that report their own
    /// checks through this type).
    #[error("{0}")]
    Input(String),
    /// Any other failure while running, by message (e.g. worker threads that
    /// cannot be started).
    #[error("{0}")]
    Runtime(String),
    /// Stopped by a signal (its number) before the outputs were committed;
    /// nothing was written (see [`crate::interrupt`]).
    #[error("interrupted by {}: stopped, no output written", crate::interrupt::signal_name(*.0))]
    Interrupted(i32),
    /// Stopped by a signal after the samples finished so far were written
    /// to a part (`crate::farm`), from which `--resume` continues; nothing
    /// else was written.
    #[error(
        "interrupted by {}: stopped; samples {}..{} of {}..{} kept in {} (continue with --resume {})",
        crate::interrupt::signal_name(*signal), samples.start, samples.end,
        requested.start, requested.end, part.display(), part.display()
    )]
    InterruptedKept {
        signal: i32,
        part: PathBuf,
        samples: std::ops::Range<u32>,
        requested: std::ops::Range<u32>,
    },
}

impl Error {
    /// True for errors in the user's input (arguments, scene, meshes,
    /// parameters, backends this build lacks); false for failures while
    /// running or writing output.
    pub fn is_input(&self) -> bool {
        match self {
            Error::Located(_)
            | Error::Param(_)
            | Error::Argument { .. }
            | Error::Unavailable(_)
            | Error::Backend(_)
            | Error::Input(_) => true,
            Error::Read { .. }
            | Error::Write { .. }
            | Error::Runtime(_)
            | Error::Interrupted(_)
            | Error::InterruptedKept { .. } => false,
        }
    }
}

/// Modules that still report errors as strings (the benchmark and the study
/// tools, with their own input/runtime enums) take the message; they keep
/// the split themselves.
impl From<Error> for String {
    fn from(e: Error) -> String {
        e.to_string()
    }
}

/// Bad input located in the user's files: the file, the line (1-based) when
/// the input has one, the field (a dotted key path such as
/// `shapes[2].material`) when the file is a scene, and what is wrong.
#[derive(Clone, Debug, PartialEq)]
pub struct InputError {
    pub file: PathBuf,
    pub line: Option<usize>,
    pub field: Option<String>,
    /// What was expected and what was found, as one sentence.
    pub message: String,
}

impl InputError {
    pub fn new(file: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        InputError {
            file: file.into(),
            line: None,
            field: None,
            message: message.into(),
        }
    }
    pub(crate) fn at_line(mut self, line: usize) -> Self {
        self.line = Some(line);
        self
    }
    pub(crate) fn in_field(mut self, field: impl Into<String>) -> Self {
        self.field = Some(field.into());
        self
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(l) = self.line {
            write!(f, ":{l}")?;
        }
        write!(f, ": ")?;
        if let Some(field) = &self.field {
            // a control character (a raw newline from a quoted key) shown
            // as its escape, so a message stays on one line
            write!(f, "field `")?;
            for c in field.chars() {
                if c.is_control() {
                    write!(f, "{}", c.escape_default())?;
                } else {
                    write!(f, "{c}")?;
                }
            }
            write!(f, "`: ")?;
        }
        write!(f, "{}", self.message)
    }
}

impl std::error::Error for InputError {}

/// A parameter of the subsurface model, by the name this crate gives it.
/// Scene files name some differently (the loader maps them: `sigma_s` is
/// given as `sigma_s_prime`, `mfp` as `dmfp`, the radius sampler as
/// `radius`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Param {
    Albedo,
    SigmaS,
    SigmaA,
    G,
    Mfp,
    D,
    Eta,
    UnitsPerMm,
    Preset,
    Fit,
    /// Where the surface albedo comes from (`bssrdf::params::AlbedoSource`).
    AlbedoSource,
    RadiusSampler,
    /// The cell count of a tabulated radius sampler.
    TableSize,
    Rmax,
    RmaxQuantile,
    /// The roughness of a subsurface material's coat.
    Roughness,
    /// The least roughness of that coat after a non-specular vertex.
    Regularize,
}

impl Param {
    /// The parameter's name in this crate's API and messages.
    pub fn name(self) -> &'static str {
        match self {
            Param::Albedo => "albedo",
            Param::SigmaS => "sigma_s",
            Param::SigmaA => "sigma_a",
            Param::G => "g",
            Param::Mfp => "mfp",
            Param::D => "d",
            Param::Eta => "eta",
            Param::UnitsPerMm => "units_per_mm",
            Param::Preset => "preset",
            Param::Fit => "fit",
            Param::AlbedoSource => "albedo_source",
            Param::RadiusSampler => "radius_sampler",
            Param::TableSize => "radius_sampler.table_size",
            Param::Rmax => "rmax",
            Param::RmaxQuantile => "rmax_quantile",
            Param::Roughness => "roughness",
            Param::Regularize => "regularize",
        }
    }
}

/// The domain a parameter's value must lie in.
#[derive(Clone, Debug, PartialEq)]
pub enum Constraint {
    /// In [0, 1].
    UnitInterval,
    /// Finite and ≥ 0.
    FiniteNonNegative,
    /// Finite and > 0.
    FinitePositive,
    /// Strictly between the two bounds.
    Open(f64, f64),
    /// An integer in the inclusive range (a value that is not an integer
    /// breaks it too).
    IntegerIn(u64, u64),
    /// σs and σa of the channel are not both zero (there must be a medium).
    SomeMedium,
    /// One of a set of names: `what` is named (`material`, `fit`), `names`
    /// lists them (`known: Apple, …` or `expected …`).
    Named { what: &'static str, names: String },
}

/// A parameter value outside its domain: which parameter (and RGB channel),
/// the value found as written, and the constraint it breaks.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamError {
    pub param: Param,
    /// The channel (0 = r, 1 = g, 2 = b) of a per-channel parameter.
    pub channel: Option<usize>,
    /// The value found, as displayed (`1.2`, `"jade"`).
    pub found: String,
    pub constraint: Constraint,
}

const CHANNELS: [&str; 3] = ["r", "g", "b"];

impl ParamError {
    pub fn new(param: Param, found: impl fmt::Display, constraint: Constraint) -> Self {
        ParamError {
            param,
            channel: None,
            found: found.to_string(),
            constraint,
        }
    }

    /// The same error about channel `c` (0, 1, 2) of the parameter.
    pub fn channel(mut self, c: usize) -> Self {
        self.channel = Some(c);
        self
    }

    /// The message with the parameter called `name` (`name.g: -1 must be …`);
    /// the scene loader passes the scene file's key.
    pub fn describe(&self, name: &str) -> String {
        let label = match self.channel {
            Some(c) => format!("{name}.{}", CHANNELS[c]),
            None => name.to_string(),
        };
        match (&self.constraint, self.channel) {
            (Constraint::SomeMedium, Some(c)) => {
                format!("{label} and sigma_a.{}: {}", CHANNELS[c], self.problem())
            }
            _ => format!("{label}: {}", self.problem()),
        }
    }

    /// The message without the parameter's name: what was found, and what
    /// was expected (for [`Constraint::SomeMedium`], without the value: both
    /// coefficients are zero).
    pub fn problem(&self) -> String {
        let v = &self.found;
        match &self.constraint {
            Constraint::UnitInterval => format!("{v} must be in [0, 1]"),
            Constraint::FiniteNonNegative => format!("{v} must be finite and non-negative"),
            Constraint::FinitePositive => format!("{v} must be finite and positive"),
            Constraint::Open(lo, hi) => format!("{v} must be in ({lo}, {hi})"),
            Constraint::IntegerIn(lo, hi) => format!("{v} must be in [{lo}, {hi}]"),
            Constraint::SomeMedium => "both zero, there is no medium".to_string(),
            Constraint::Named { what, names } => format!("unknown {what} {v} ({names})"),
        }
    }
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.describe(self.param.name()))
    }
}

impl std::error::Error for ParamError {}

/// Bridge for modules that still report errors as strings (see
/// `From<Error> for String`).
impl From<ParamError> for String {
    fn from(e: ParamError) -> String {
        e.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn param_errors_name_parameter_channel_value_and_constraint() {
        let e = ParamError::new(Param::Albedo, 1.2, Constraint::UnitInterval).channel(0);
        assert_eq!(e.to_string(), "albedo.r: 1.2 must be in [0, 1]");
        assert_eq!(e.describe("base"), "base.r: 1.2 must be in [0, 1]");
        let e = ParamError::new(
            Param::Fit,
            "\"dipole\"",
            Constraint::Named {
                what: "fit",
                names: "expected searchlight".into(),
            },
        );
        assert_eq!(
            e.to_string(),
            "fit: unknown fit \"dipole\" (expected searchlight)"
        );
        let e = ParamError::new(Param::SigmaS, 0, Constraint::SomeMedium).channel(1);
        assert_eq!(
            e.to_string(),
            "sigma_s.g and sigma_a.g: both zero, there is no medium"
        );
    }

    #[test]
    fn input_and_runtime_errors_are_told_apart() {
        let located = Error::from(InputError::new("a.toml", "bad").at_line(3).in_field("x"));
        assert_eq!(located.to_string(), "a.toml:3: field `x`: bad");
        let raw = InputError::new("a.toml", "bad").in_field("m.\"a\nb\"");
        assert_eq!(raw.to_string(), "a.toml: field `m.\"a\\nb\"`: bad");
        assert!(located.is_input());
        let param = Error::from(ParamError::new(Param::Eta, 0, Constraint::FinitePositive));
        assert!(param.is_input());
        assert!(Error::Unavailable("no".into()).is_input());
        let write = Error::Write {
            path: "out.exr".into(),
            problem: "disk full".into(),
        };
        assert_eq!(write.to_string(), "cannot write out.exr: disk full");
        assert!(!write.is_input());
        assert!(!Error::Runtime("x".into()).is_input());
    }
}
