//! `[environment]`: a constant radiance, or a latitude-longitude HDR image
//! with its rotation, intensity and exposure (`docs/scene-format.md`,
//! "`[environment]`"). An image that cannot be used is refused with the
//! file and, for a bad texel, its column and row; a file that is not a
//! regular file (a FIFO would block the loader) before it is opened for
//! decoding, as textures are.

use std::path::Path;
use std::sync::Arc;

use super::checked::{Cx, Res};
use super::format::{EnvironmentDef, Spanned};
use super::regular_file::open_regular;
use crate::environment::{image, EnvMap, Environment};
use crate::geometry::Vec3;

/// The largest |exposure| accepted (stops).
const MAX_EXPOSURE: f32 = 64.0;

/// The environment `env` describes; None where it is black.
pub(crate) fn environment(
    cx: &Cx,
    scene_dir: &Path,
    env: &Spanned<EnvironmentDef>,
) -> Res<Option<Environment>> {
    let d = env.get_ref();
    let Some(file) = &d.file else {
        for (key, v) in [
            ("rotation", &d.rotation),
            ("intensity", &d.intensity),
            ("exposure", &d.exposure),
        ] {
            if let Some(v) = v {
                return Err(cx.err(
                    v.span(),
                    &format!("environment.{key}"),
                    format!("`{key}` applies to an environment image (`file`)"),
                ));
            }
        }
        let field = "environment.radiance";
        let r = cx.required(&d.radiance, Some(env.span()), field)?;
        let c = cx.rgb(r, field, false)?;
        return Ok((c != Vec3::ZERO).then_some(Environment::Constant(c)));
    };
    if let Some(r) = &d.radiance {
        return Err(cx.err(
            r.span(),
            "environment.radiance",
            "`radiance` and `file` are two forms of the environment: give one",
        ));
    }
    let scale = scale(cx, d)?;
    let rotation = match &d.rotation {
        Some(r) => cx.scalar(r, "environment.rotation")?,
        None => 0.0,
    };
    let path = scene_dir.join(file.get_ref());
    let refuse = |e: &dyn std::fmt::Display| {
        cx.err(
            file.span(),
            "environment.file",
            format!("environment image {}: {e}", path.display()),
        )
    };
    open_regular(&path).map_err(|e| refuse(&image::ImageError::Unreadable(e.to_string())))?;
    let texels = image::read(&path).map_err(|e| refuse(&e))?;
    if scale == 0.0 {
        return Ok(None);
    }
    Ok(Some(Environment::Map(Arc::new(EnvMap::new(
        texels, scale, rotation,
    )))))
}

/// intensity × 2^exposure.
fn scale(cx: &Cx, d: &EnvironmentDef) -> Res<f32> {
    let intensity = match &d.intensity {
        Some(v) => {
            let x = cx.scalar(v, "environment.intensity")?;
            if x < 0.0 {
                return Err(cx.err(
                    v.span(),
                    "environment.intensity",
                    format!("expected a number >= 0, found {x}"),
                ));
            }
            x
        }
        None => 1.0,
    };
    let exposure = match &d.exposure {
        Some(v) => {
            let x = cx.scalar(v, "environment.exposure")?;
            if x.abs() > MAX_EXPOSURE {
                return Err(cx.err(
                    v.span(),
                    "environment.exposure",
                    format!("expected stops in [-{MAX_EXPOSURE}, {MAX_EXPOSURE}], found {x}"),
                ));
            }
            x
        }
        None => 0.0,
    };
    let s = intensity * exposure.exp2();
    if !s.is_finite() {
        return Err(cx.err(
            d.intensity.as_ref().map(|v| v.span()).unwrap_or(0..0),
            "environment.intensity",
            format!("intensity × 2^exposure = {intensity} × 2^{exposure} is not a finite number"),
        ));
    }
    Ok(s)
}
