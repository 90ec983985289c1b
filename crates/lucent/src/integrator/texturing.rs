//! A hit on a textured material: its texture coordinates (the triangle's
//! corners at the hit's barycentrics), the footprint in UV units, and the
//! parameters the textures give there: the shading normal of a normal map
//! or a bump map,
//! the albedo, a subsurface medium's length factor, the roughness
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
    /// Read by subsurface materials only.
    #[cfg_attr(not(feature = "subsurface"), allow(dead_code))]
    pub(crate) dmfp: Option<Vec3>,
    /// The roughness of a glossy base or a coat.
    pub(crate) roughness: Option<f32>,
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
            roughness: None,
        };
    };
    let uv = tri.at(bary);
    let cos = wo.dot(si.ng).abs().max(MIN_COS);
    let w = width / cos.sqrt() * tri.uv_per_unit;
    let si = match (&t.normal, &t.bump) {
        (Some(map), _) => si.with_shading_normal(mapped_normal(tri, si.ns, map.lookup(uv, w))),
        (None, Some(b)) => si.with_shading_normal(bumped_normal(tri, si.ns, b, uv, w)),
        (None, None) => *si,
    };
    Resolved {
        si,
        albedo: t.albedo.as_ref().map(|a| a.eval(uv, w)),
        dmfp: t.dmfp.as_ref().map(|a| a.eval(uv, w)),
        roughness: t.roughness.as_ref().map(|r| r.at(uv, w)),
    }
}

/// The shading normal the bump map `b` gives at `uv` (footprint `w`) over
/// the interpolated normal `ns`: the surface displaced by the height h
/// (the texels' channel mean × `b.scale`) along ns has the normal
///
///   n' ∝ ns − s (∂h/∂u t + ∂h/∂v b),
///
/// t and b the tangent frame of [`mapped_normal`] (b along increasing v)
/// and s the triangle's UV units per scene unit (the UV map taken as
/// locally isotropic, as the footprint does). The slopes are forward
/// differences over the footprint, at least half a texel of the full
/// image. `ns` itself where the slopes are 0 or the frame is degenerate.
pub(crate) fn bumped_normal(
    tri: &TriUv,
    ns: Vec3,
    b: &crate::materials::Bump,
    uv: glam::Vec2,
    w: f32,
) -> Vec3 {
    let (tw, th) = b.texture.size();
    let du = (0.5 * w).max(0.5 / tw.max(th) as f32);
    let h = |d: glam::Vec2| {
        let c = b.texture.lookup(uv + d, w);
        (c.x + c.y + c.z) / 3.0
    };
    let h0 = h(glam::Vec2::ZERO);
    let k = b.scale * tri.uv_per_unit / du;
    let (su, sv) = (
        (h(glam::Vec2::new(du, 0.0)) - h0) * k,
        (h(glam::Vec2::new(0.0, du)) - h0) * k,
    );
    if su == 0.0 && sv == 0.0 {
        return ns;
    }
    let Some(t) = (tri.tangent - ns * ns.dot(tri.tangent)).try_normalize() else {
        return ns;
    };
    let bt = ns.cross(t) * tri.sign;
    (ns - t * su - bt * sv).try_normalize().unwrap_or(ns)
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

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::Vec2;

    use super::*;
    use crate::materials::Bump;
    use crate::texture::{Texture, Wrap};

    /// A right triangle in the xy plane with uv = xy: tangent +x, v along
    /// +y, one UV unit per scene unit.
    fn tri() -> TriUv {
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y];
        TriUv::new(p, [Vec2::ZERO, Vec2::X, Vec2::Y])
    }

    /// A `w` × `h` height map whose texel (i, j) is `f(u, v)` at its
    /// centre, `scale` scene units per unit value.
    fn bump(w: u32, h: u32, scale: f32, f: impl Fn(f32, f32) -> f32) -> Bump {
        let texels = (0..h)
            .flat_map(|j| (0..w).map(move |i| (i, j)))
            .map(|(i, j)| {
                let (u, v) = (
                    (i as f32 + 0.5) / w as f32,
                    1.0 - (j as f32 + 0.5) / h as f32,
                );
                Vec3::splat(f(u, v))
            })
            .collect();
        Bump {
            texture: Arc::new(Texture::new(w, h, texels, Wrap::Clamp)),
            scale,
        }
    }

    /// Caught: a slope with the wrong sign (the normal tilting uphill), u
    /// and v (t and b) swapped, the bitangent's handedness ignored, the
    /// scale or the UV density left out. A height h = k·u tilts the normal
    /// to (−k s, 0, 1) normalized, h = k·v to (0, −k s, 1).
    #[test]
    fn a_ramp_tilts_the_normal_downhill() {
        let uv = Vec2::new(0.4, 0.6);
        let n = Vec3::Z;
        for (b, want) in [
            (bump(64, 1, 0.1, |u, _| u), Vec3::new(-0.1, 0.0, 1.0)),
            (bump(1, 64, 0.1, |_, v| v), Vec3::new(0.0, -0.1, 1.0)),
            (
                bump(64, 64, -0.5, |u, v| u + 2.0 * v),
                Vec3::new(0.5, 1.0, 1.0),
            ),
        ] {
            let got = bumped_normal(&tri(), n, &b, uv, 0.0);
            let want = want.normalize();
            assert!((got - want).length() < 1e-4, "{got} against {want}");
        }
        // mirrored UVs (v running down the triangle): the tilt follows v
        let mirrored = TriUv::new(
            [Vec3::ZERO, Vec3::X, Vec3::Y],
            [Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::ZERO],
        );
        let got = bumped_normal(&mirrored, n, &bump(1, 64, 0.1, |_, v| v), uv, 0.0);
        let want = Vec3::new(0.0, 0.1, 1.0).normalize();
        assert!((got - want).length() < 1e-4, "mirrored: {got}");
    }

    /// Caught: a flat height map that moves the normal (by renormalizing
    /// it, or by a one-sided difference at a texel edge).
    #[test]
    fn a_flat_height_map_leaves_the_normal_bit_for_bit() {
        let n = Vec3::new(0.3, -0.2, 0.9).normalize();
        let b = bump(8, 8, 3.0, |_, _| 0.7);
        for uv in [
            Vec2::new(0.01, 0.99),
            Vec2::new(0.5, 0.5),
            Vec2::new(1.3, -0.2),
        ] {
            for w in [0.0, 0.01, 0.5, 4.0] {
                assert_eq!(bumped_normal(&tri(), n, &b, uv, w), n);
            }
        }
    }
}
