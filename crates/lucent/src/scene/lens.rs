//! `[camera]`'s thin lens: the aperture as a radius in scene units or as
//! an f-number, and the focus distance (`docs/scene-format.md`,
//! "`[camera]`").
//!
//! An f-number N is read as a 35 mm film camera's: the focal length that
//! gives `fov_y` on the 24 mm film height is F = 12 mm / tan(fov_y / 2),
//! and the aperture radius F / 2N, in scene units through `units_per_mm`.

use super::camera::ThinLens;
use super::checked::{Cx, Res};
use super::format::CameraDef;

/// The lens `d` describes; None (a pinhole) without an aperture.
/// `view_distance` (from look_from to look_at) is the default focus.
pub(crate) fn lens(
    cx: &Cx,
    d: &CameraDef,
    fov_y_deg: f32,
    view_distance: f32,
    units_per_mm: f32,
) -> Res<Option<ThinLens>> {
    let radius = match (&d.aperture_radius, &d.f_number) {
        (Some(_), Some(f)) => {
            return Err(cx.err(
                f.span(),
                "camera.f_number",
                "`f_number` and `aperture_radius` are two ways to give the aperture: give one",
            ))
        }
        (Some(r), None) => cx.positive(r, "camera.aperture_radius")?,
        (None, Some(n)) => {
            let n = cx.positive(n, "camera.f_number")?;
            let focal_mm = 12.0 / (fov_y_deg.to_radians() * 0.5).tan();
            focal_mm / (2.0 * n) * units_per_mm
        }
        (None, None) => {
            if let Some(f) = &d.focus_distance {
                return Err(cx.err(
                    f.span(),
                    "camera.focus_distance",
                    "`focus_distance` needs an aperture (`aperture_radius` or `f_number`)",
                ));
            }
            return Ok(None);
        }
    };
    let focus_distance = match &d.focus_distance {
        Some(f) => cx.positive(f, "camera.focus_distance")?,
        None => view_distance,
    };
    if !radius.is_finite() || radius <= 0.0 {
        return Err(cx.err(
            d.f_number.as_ref().map(|f| f.span()).unwrap_or(0..0),
            "camera.f_number",
            format!("the aperture radius {radius} is not a positive finite number"),
        ));
    }
    Ok(Some(ThinLens {
        radius,
        focus_distance,
    }))
}
