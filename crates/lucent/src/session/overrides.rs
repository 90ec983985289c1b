//! The command line's subsurface sampling options, applied to every
//! subsurface material of a scene, and then the accuracy budgets' choices
//! (`crate::integrator::plan::budget`); a build without the `subsurface`
//! feature has none.

use crate::error::Error;
use crate::scene::Scene;

/// Sampling options that replace every subsurface material's own, by
/// name (`crate::materials::estimator_options`).
#[cfg(feature = "subsurface")]
pub use crate::materials::estimator_options::Assignments as Overrides;

/// Sampling options that replace every subsurface material's own: none
/// without the `subsurface` feature.
#[cfg(not(feature = "subsurface"))]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Overrides;

/// Applies `o` to every subsurface material of `scene`, then makes the
/// choice of every material with an accuracy budget; returns the options
/// as a part's identity records them (canonical names).
#[cfg(feature = "subsurface")]
pub fn apply(o: &Overrides, scene: &mut Scene) -> Result<String, Error> {
    o.apply_all(&mut scene.materials).map_err(option_error)?;
    crate::integrator::plan::budget::resolve(scene).map_err(option_error)?;
    Ok(o.canonical())
}

/// No subsurface materials, nothing to apply.
#[cfg(not(feature = "subsurface"))]
pub fn apply(_: &Overrides, _: &mut Scene) -> Result<String, Error> {
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
