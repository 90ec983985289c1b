//! The material a hit scatters as. An untextured material is itself; a
//! textured one is its base with the parameters its textures give at the
//! hit (`docs/scene-format.md`, "Textures"; for a subsurface base
//! `docs/bssrdf.md` §13), kept in a per-path slot while the hit's
//! scattering is in use. The bounce loop scatters what this gives and
//! never looks at textures itself.

use super::texturing;
use super::{Context, Interaction};
use crate::geometry::Vec3;
#[cfg(feature = "subsurface")]
use crate::materials::Subsurface;
use crate::materials::{Conductor, Material, Plastic, RoughDielectric, Textured};

/// A material with its parameters fixed at one hit.
pub(crate) enum HitMaterial<'s> {
    Diffuse(Vec3),
    /// A smooth dielectric of this index.
    Dielectric(f32),
    RoughDielectric(RoughDielectric),
    Conductor(&'s Conductor),
    Plastic(&'s Plastic),
    #[cfg(feature = "subsurface")]
    Subsurface(&'s Subsurface),
}

impl<'s> HitMaterial<'s> {
    /// `m` with its constant parameters; a textured material's base
    /// without its textures (the loader never nests them).
    #[inline(always)]
    pub(crate) fn untextured(m: &'s Material) -> Self {
        match m {
            Material::Diffuse { albedo } => HitMaterial::Diffuse(*albedo),
            Material::Dielectric { eta } => HitMaterial::Dielectric(*eta),
            Material::RoughDielectric(d) => HitMaterial::RoughDielectric(*d),
            Material::Conductor(c) => HitMaterial::Conductor(c),
            Material::Plastic(p) => HitMaterial::Plastic(p),
            #[cfg(feature = "subsurface")]
            Material::Subsurface(ss) => HitMaterial::Subsurface(ss),
            Material::Textured(t) => HitMaterial::untextured(&t.base),
        }
    }
}

/// Where the bounce loop keeps the material a textured one is at a hit,
/// while that hit's scattering is in use: one of each kind per path,
/// replaced at each such hit.
#[derive(Default)]
pub(crate) struct PointMaterial {
    #[cfg(feature = "subsurface")]
    subsurface: Option<Subsurface>,
    conductor: Option<Conductor>,
    plastic: Option<Plastic>,
}

/// A hit on a textured material: its interaction (the shading normal a
/// normal or bump map gives) and the material there.
pub(crate) struct TexturedHit<'s> {
    pub(crate) si: Interaction,
    pub(crate) material: HitMaterial<'s>,
}

/// The textured material `t` hit at `si` (barycentrics `bary`, seen from
/// `wo`, footprint width `width`), its point material kept in `point`.
#[inline(never)]
pub(crate) fn textured<'s>(
    ctx: &Context,
    t: &'s Textured,
    si: &Interaction,
    bary: [f32; 2],
    wo: Vec3,
    width: f32,
    point: &'s mut PointMaterial,
) -> TexturedHit<'s> {
    let r = texturing::resolve(ctx, t, si, bary, wo, width);
    let material = match (&t.base, r.albedo) {
        (Material::Diffuse { albedo }, a) => HitMaterial::Diffuse(a.unwrap_or(*albedo)),
        #[cfg(feature = "subsurface")]
        (Material::Subsurface(ss), _) => HitMaterial::Subsurface(subsurface(t, ss, &r, point)),
        (base, _) => match (&t.roughness, r.roughness) {
            (Some(map), Some(rough)) => rough_base(base, map, rough, point),
            _ => HitMaterial::untextured(base),
        },
    };
    TexturedHit { si: r.si, material }
}

/// The subsurface base `ss` of `t` with the medium and coat roughness its
/// textures give at the hit (`r`), kept in `point`; `ss` itself where they
/// give neither (`docs/bssrdf.md` §13).
#[cfg(feature = "subsurface")]
fn subsurface<'s>(
    t: &Textured,
    ss: &'s Subsurface,
    r: &texturing::Resolved,
    point: &'s mut PointMaterial,
) -> &'s Subsurface {
    let medium = match &t.medium {
        Some(m) if r.albedo.is_some() || r.dmfp.is_some() => {
            ss.at_point(m.params_at(ss.params(), r.albedo, r.dmfp))
        }
        _ => None,
    };
    let coat = t
        .roughness
        .as_ref()
        .and_then(|map| map.steps.as_ref())
        .zip(r.roughness);
    match (medium, coat) {
        (m, Some((steps, rough))) => {
            let p = m.unwrap_or_else(|| ss.clone());
            point
                .subsurface
                .insert(p.with_point_coat(rough, steps, ss.least_coat()))
        }
        (Some(p), None) => point.subsurface.insert(p),
        (None, None) => ss,
    }
}

/// The glossy `base` at the roughness `rough` its map gives (kept in
/// `point`); a rough dielectric below the smooth threshold is the smooth
/// interface. A base the loader gives no roughness steps is as it is.
fn rough_base<'s>(
    base: &'s Material,
    map: &crate::materials::RoughnessMap,
    rough: f32,
    point: &'s mut PointMaterial,
) -> HitMaterial<'s> {
    match (base, &map.steps) {
        (Material::Conductor(c), Some(steps)) => {
            HitMaterial::Conductor(point.conductor.insert(c.at_roughness(rough, steps)))
        }
        (Material::Plastic(p), Some(steps)) => {
            HitMaterial::Plastic(point.plastic.insert(p.at_roughness(rough, steps)))
        }
        (Material::RoughDielectric(d), _) => match d.at_roughness(rough) {
            Some(d) => HitMaterial::RoughDielectric(d),
            None => HitMaterial::Dielectric(d.eta),
        },
        _ => HitMaterial::untextured(base),
    }
}
