//! A hit on a textured material: its texture coordinates (the triangle's
//! corners at the hit's barycentrics), the footprint in UV units, and the
//! parameters the textures give there: the shading normal of a normal map,
//! the albedo, a subsurface medium's length factor
//! (`docs/scene-format.md`, "Textures").
//!
//! The footprint is the path's ray cone width w at the hit
//! ([`super::footprint`]), stretched on the surface to w/|cos θ| along the
//! incidence plane; the texture is filtered isotropically over the
//! ellipse's geometric-mean width w/√|cos θ| (less blur at grazing angles
//! than its long axis, less aliasing than its short one), times the
//! triangle's UV per world unit.

use super::interaction::TriUv;
use super::{Context, Interaction};
use crate::geometry::Vec3;
use crate::materials::Textured;

/// Grazing cosines below this count as this, so the footprint stays finite.
const MIN_COS: f32 = 1e-3;

/// What the textures of a hit give: its interaction (with the normal
/// map's shading normal), the albedo and the length factor, when textured.
pub(crate) struct Resolved {
    pub(crate) si: Interaction,
    pub(crate) albedo: Option<Vec3>,
    pub(crate) dmfp: Option<Vec3>,
}

/// The parameters of `t` at `si` (barycentrics `bary`), seen along `wo`
/// by a path whose footprint there is `width` scene units wide.
pub(crate) fn resolve(
    ctx: &Context,
    t: &Textured,
    si: &Interaction,
    bary: [f32; 2],
    wo: Vec3,
    width: f32,
) -> Resolved {
    // The loader gives every mesh of a textured material its coordinates.
    let Some(tri) = ctx.shading[si.geom as usize].uv(si.prim) else {
        return Resolved {
            si: *si,
            albedo: None,
            dmfp: None,
        };
    };
    let uv = tri.at(bary);
    let cos = wo.dot(si.ng).abs().max(MIN_COS);
    let w = width / cos.sqrt() * tri.uv_per_unit;
    let si = match &t.normal {
        Some(map) => si.with_shading_normal(mapped_normal(tri, si.ns, map.lookup(uv, w))),
        None => *si,
    };
    Resolved {
        si,
        albedo: t.albedo.as_ref().map(|a| a.eval(uv, w)),
        dmfp: t.dmfp.as_ref().map(|a| a.eval(uv, w)),
    }
}

/// The shading normal a normal-map texel `c` (RGB in [0, 1]) gives over the
/// interpolated normal `ns`: (2c − 1) in the frame of the tangent made
/// perpendicular to `ns`, the bitangent sign · ns × t, and `ns`; `ns` where
/// that is not a direction.
pub(crate) fn mapped_normal(tri: &TriUv, ns: Vec3, c: Vec3) -> Vec3 {
    let m = c * 2.0 - Vec3::ONE;
    let Some(t) = (tri.tangent - ns * ns.dot(tri.tangent)).try_normalize() else {
        return ns;
    };
    let b = ns.cross(t) * tri.sign;
    (t * m.x + b * m.y + ns * m.z).try_normalize().unwrap_or(ns)
}
