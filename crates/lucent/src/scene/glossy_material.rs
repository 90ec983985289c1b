//! The keys of the glossy material types (`docs/scene-format.md`,
//! "Materials"): `conductor` (a named metal or n + ik, roughness),
//! `plastic` (albedo, eta, roughness) and a `dielectric`'s optional
//! roughness.

use std::sync::Arc;

use super::checked::{Cx, Res};
use super::format::{MaterialDef, Spanned};
use crate::materials::metals::{metal, names};
use crate::materials::{Conductor, Material, Plastic, RoughDielectric};

/// The coat's index a plastic gets without `eta`.
const PLASTIC_ETA: f32 = 1.5;

/// `roughness` ∈ [0, 1]; without the key 0, or 1 with a
/// `roughness_texture` (the key is a factor on it).
fn roughness(cx: &Cx, field: &str, d: &MaterialDef) -> Res<f32> {
    let Some(r) = &d.roughness else {
        return Ok(if d.roughness_texture.is_some() {
            1.0
        } else {
            0.0
        });
    };
    let f = format!("{field}.roughness");
    let x = cx.scalar(r, &f)?;
    if !(0.0..=1.0).contains(&x) {
        return Err(cx.err(
            r.span(),
            &f,
            format!("expected a number in [0, 1], found {x}"),
        ));
    }
    Ok(x)
}

/// A dielectric: smooth (the specular interface) unless `roughness` > 0
/// or a `roughness_texture` is given.
pub(super) fn dielectric(cx: &Cx, field: &str, d: &MaterialDef, eta: f32) -> Res<Material> {
    let r = roughness(cx, field, d)?;
    Ok(if r > 0.0 || d.roughness_texture.is_some() {
        Material::RoughDielectric(RoughDielectric::new(eta, r))
    } else {
        Material::Dielectric { eta }
    })
}

/// A conductor: `metal = "<name>"`, or `n` and `k` (RGB), and `roughness`.
pub(super) fn conductor(cx: &Cx, field: &str, m: &Spanned<MaterialDef>) -> Res<Material> {
    let d = m.get_ref();
    let r = roughness(cx, field, d)?;
    let (eta, k) = match (&d.metal, &d.n, &d.k) {
        (Some(name), None, None) => {
            let found = metal(name.get_ref()).ok_or_else(|| {
                cx.err(
                    name.span(),
                    &format!("{field}.metal"),
                    format!(
                        "unknown metal \"{}\"; expected one of {}",
                        name.get_ref(),
                        names()
                    ),
                )
            })?;
            (found.eta(), found.k())
        }
        (None, Some(n), Some(k)) => (
            positive_rgb(cx, n, &format!("{field}.n"))?,
            cx.rgb(k, &format!("{field}.k"), false)?,
        ),
        (Some(name), _, _) => {
            return Err(cx.err(
                name.span(),
                &format!("{field}.metal"),
                "`metal` cannot be combined with `n` and `k`; give one or the other",
            ))
        }
        (None, n, _) => {
            let missing = if n.is_none() { "n" } else { "k" };
            return Err(cx.err(
                m.span(),
                &format!("{field}.{missing}"),
                format!(
                    "missing field `{missing}`: a conductor needs `metal` (one of {}) or both `n` and `k`",
                    names()
                ),
            ));
        }
    };
    Ok(Material::Conductor(Arc::new(Conductor::new(eta, k, r))))
}

/// A plastic: `albedo` (required), `eta` (1.5 without it), `roughness`.
pub(super) fn plastic(cx: &Cx, field: &str, m: &Spanned<MaterialDef>) -> Res<Material> {
    let d = m.get_ref();
    let a = d.albedo.as_ref().ok_or_else(|| {
        cx.err(
            m.span(),
            &format!("{field}.albedo"),
            "missing field `albedo` (required for type \"plastic\")",
        )
    })?;
    let albedo = cx.rgb(a, &format!("{field}.albedo"), true)?;
    let eta = match &d.eta {
        Some(e) => cx.positive(e, &format!("{field}.eta"))?,
        None => PLASTIC_ETA,
    };
    let r = roughness(cx, field, d)?;
    Ok(Material::Plastic(Arc::new(Plastic::new(albedo, eta, r))))
}

/// RGB with every component > 0 (a conductor's n).
fn positive_rgb(
    cx: &Cx,
    v: &Spanned<super::format::Triple3>,
    field: &str,
) -> Res<crate::geometry::Vec3> {
    let c = cx.vec3(v, field)?;
    if c.min_element() <= 0.0 {
        return Err(cx.err(
            v.span(),
            field,
            format!(
                "expected RGB components > 0, found [{}, {}, {}]",
                c.x, c.y, c.z
            ),
        ));
    }
    Ok(c)
}
