//! The command line's subsurface sampling options, applied to every
//! subsurface material of a scene; a build without the `subsurface`
//! feature has none.

use crate::error::Error;
use crate::materials::Material;

/// Sampling options that replace every subsurface material's own, by
/// name (`crate::materials::estimator_options`).
#[cfg(feature = "subsurface")]
pub use crate::materials::estimator_options::Assignments as Overrides;

/// Sampling options that replace every subsurface material's own: none
/// without the `subsurface` feature.
#[cfg(not(feature = "subsurface"))]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Overrides;

/// Applies `o` to every subsurface material of `materials`; returns the
/// options as a part's identity records them (canonical names).
#[cfg(feature = "subsurface")]
pub fn apply(o: &Overrides, materials: &mut [Material]) -> Result<String, Error> {
    o.apply_all(materials).map_err(option_error)?;
    Ok(o.canonical())
}

/// No subsurface materials, nothing to apply.
#[cfg(not(feature = "subsurface"))]
pub fn apply(_: &Overrides, _: &mut [Material]) -> Result<String, Error> {
    Ok(String::new())
}

/// A subsurface override out of its domain, named by its option.
#[cfg(feature = "subsurface")]
fn option_error(e: crate::error::ParamError) -> Error {
    use crate::error::Param;
    let (argument, problem) = match e.param {
        Param::RmaxQuantile => ("--rmax-quantile", e.problem()),
        Param::RadiusSampler => ("--radius", e.problem()),
        Param::TableSize => ("--radius", format!("table size {}", e.problem())),
        _ => ("subsurface option", e.to_string()),
    };
    Error::Argument {
        argument: argument.into(),
        problem,
    }
}
