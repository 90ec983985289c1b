//! `[[lights]]`: sphere lights (with an optional spot cone) and distant
//! lights, each with its strength in one of two forms: a radiance, or a
//! power (W) for a sphere, an irradiance (W/m²) for a distant light,
//! converted as `docs/scene-format.md`, "Light units", states. `power` on
//! a `[[shapes]]` emitter is read here too.

use std::ops::Range;

use super::checked::{Cx, Res};
use super::format::{LightDef, LightKind, Spanned, Triple3};
use super::MAX_COORDINATE;
use crate::analytic_lights::{units, Cone, DistantLight, Light, SphereLight, Spot};
use crate::geometry::{Mesh, Vec3};

/// The angular diameter of a distant light without `angle`: the Sun's, in
/// degrees.
pub const SUN_ANGLE: f64 = 0.53;

/// Square metres per square scene unit.
fn m2_per_unit2(units_per_mm: f32) -> f64 {
    let m = 1.0 / (1000.0 * units_per_mm as f64);
    m * m
}

/// Light `i` of `[[lights]]`.
pub(super) fn light(cx: &Cx, i: usize, l: &Spanned<LightDef>, units_per_mm: f32) -> Res<Light> {
    let field = format!("lights[{i}]");
    let d = l.get_ref();
    let kind = *cx
        .required(&d.kind, Some(l.span()), &format!("{field}.type"))?
        .get_ref();
    let (name, allowed): (&str, &[&str]) = match kind {
        LightKind::Sphere => (
            "sphere",
            &[
                "position",
                "radius",
                "power",
                "spot_direction",
                "spot_angle",
                "spot_falloff",
            ],
        ),
        LightKind::Distant => ("distant", &["direction", "angle", "irradiance"]),
    };
    cx.only_keys(&field, name, d.present_type_keys(), allowed)?;
    match kind {
        LightKind::Sphere => sphere(cx, &field, l, units_per_mm).map(Light::Sphere),
        LightKind::Distant => distant(cx, &field, l).map(Light::Distant),
    }
}

/// Exactly one of the two forms of a light's strength (`a`, `b`).
fn one_of<'v>(
    cx: &Cx,
    field: &str,
    table: Range<usize>,
    a: (&str, &'v Option<Spanned<Triple3>>),
    b: (&str, &'v Option<Spanned<Triple3>>),
) -> Res<(bool, Vec3)> {
    match (a.1, b.1) {
        (Some(_), Some(y)) => Err(cx.err(
            y.span(),
            &format!("{field}.{}", b.0),
            format!(
                "`{}` and `{}` are two forms of the light's strength: give one",
                a.0, b.0
            ),
        )),
        (None, None) => Err(cx.err(
            table,
            &format!("{field}.{}", a.0),
            format!("missing field: give the light's `{}` or its `{}`", a.0, b.0),
        )),
        (Some(x), None) => Ok((true, cx.rgb(x, &format!("{field}.{}", a.0), false)?)),
        (None, Some(y)) => Ok((false, cx.rgb(y, &format!("{field}.{}", b.0), false)?)),
    }
}

/// A unit direction from a non-zero vector.
fn direction(cx: &Cx, v: &Spanned<Triple3>, field: &str) -> Res<Vec3> {
    let d = cx.vec3(v, field)?;
    let n = d.normalize_or_zero();
    if n == Vec3::ZERO || !n.is_finite() {
        return Err(cx.err(v.span(), field, "expected a non-zero direction"));
    }
    Ok(n)
}

/// An angle in degrees within `[lo, hi]` (`open_lo`: excluding `lo`).
fn degrees(cx: &Cx, v: &Spanned<f64>, field: &str, lo: f32, hi: f32, open_lo: bool) -> Res<f32> {
    let x = cx.scalar(v, field)?;
    let ok = x <= hi && if open_lo { x > lo } else { x >= lo };
    if !ok {
        let open = if open_lo { "(" } else { "[" };
        return Err(cx.err(
            v.span(),
            field,
            format!("expected degrees in {open}{lo}, {hi}], found {x}"),
        ));
    }
    Ok(x)
}

/// A finite radiance, or an error at `span` saying what made it overflow.
fn finite(cx: &Cx, span: Range<usize>, field: &str, l: Vec3) -> Res<Vec3> {
    if !l.is_finite() {
        return Err(cx.err(
            span,
            field,
            "the radiance this stands for is not a finite 32-bit number (the light is too \
             small or too narrow for its strength)",
        ));
    }
    Ok(l)
}

fn sphere(cx: &Cx, field: &str, l: &Spanned<LightDef>, units_per_mm: f32) -> Res<SphereLight> {
    let d = l.get_ref();
    let f = |k: &str| format!("{field}.{k}");
    let p = cx.required(&d.position, Some(l.span()), &f("position"))?;
    let center = cx.vec3(p, &f("position"))?;
    if center.abs().max_element() > MAX_COORDINATE {
        return Err(cx.err(
            p.span(),
            &f("position"),
            format!("expected coordinates within ±{MAX_COORDINATE:e}"),
        ));
    }
    let r = cx.required(&d.radius, Some(l.span()), &f("radius"))?;
    let radius = cx.positive(r, &f("radius"))?;
    if radius > MAX_COORDINATE {
        return Err(cx.err(
            r.span(),
            &f("radius"),
            format!("expected at most {MAX_COORDINATE:e}, found {radius}"),
        ));
    }
    let spot = spot(cx, field, l)?;
    let (is_radiance, value) = one_of(
        cx,
        field,
        l.span(),
        ("radiance", &d.radiance),
        ("power", &d.power),
    )?;
    let radiance = if is_radiance {
        value
    } else {
        let r_m = radius as f64 * m2_per_unit2(units_per_mm).sqrt();
        let span = d.power.as_ref().map_or(l.span(), |p| p.span());
        finite(
            cx,
            span,
            &f("power"),
            units::sphere_radiance(value, r_m, spot.as_ref()),
        )?
    };
    Ok(SphereLight {
        center,
        radius,
        radiance,
        spot,
    })
}

/// The spot cone of a sphere light, if `spot_direction` is given.
fn spot(cx: &Cx, field: &str, l: &Spanned<LightDef>) -> Res<Option<Spot>> {
    let d = l.get_ref();
    let f = |k: &str| format!("{field}.{k}");
    let Some(dir) = &d.spot_direction else {
        for (k, v) in [
            ("spot_angle", &d.spot_angle),
            ("spot_falloff", &d.spot_falloff),
        ] {
            if let Some(v) = v {
                return Err(cx.err(
                    v.span(),
                    &f(k),
                    format!("`{k}` shapes a spot cone: give its axis, `spot_direction`"),
                ));
            }
        }
        return Ok(None);
    };
    let axis = direction(cx, dir, &f("spot_direction"))?;
    let a = cx.required(&d.spot_angle, Some(l.span()), &f("spot_angle"))?;
    let angle = degrees(cx, a, &f("spot_angle"), 0.0, 180.0, true)?;
    let falloff = match &d.spot_falloff {
        Some(v) => degrees(cx, v, &f("spot_falloff"), 0.0, angle, false)?,
        None => 0.0,
    };
    Ok(Some(Spot {
        axis,
        cos_inner: (angle - falloff).to_radians().cos(),
        cos_outer: angle.to_radians().cos(),
    }))
}

fn distant(cx: &Cx, field: &str, l: &Spanned<LightDef>) -> Res<DistantLight> {
    let d = l.get_ref();
    let f = |k: &str| format!("{field}.{k}");
    let v = cx.required(&d.direction, Some(l.span()), &f("direction"))?;
    let travel = direction(cx, v, &f("direction"))?;
    let angle = match &d.angle {
        Some(a) => degrees(cx, a, &f("angle"), 0.0, 179.0, false)?,
        None => SUN_ANGLE as f32,
    };
    let (is_radiance, value) = one_of(
        cx,
        field,
        l.span(),
        ("radiance", &d.radiance),
        ("irradiance", &d.irradiance),
    )?;
    let half = (angle as f64 / 2.0).to_radians();
    let sin2 = half.sin().powi(2);
    let cone = Cone::from_sin2(-travel, sin2 as f32);
    if cone.one_minus_cos <= 0.0 && is_radiance {
        let span = d.radiance.as_ref().map_or(l.span(), |r| r.span());
        return Err(cx.err(
            span,
            &f("radiance"),
            "a distant light of `angle` 0 is a single direction: give its `irradiance` \
             (a radiance would be infinite)",
        ));
    }
    let radiance = if is_radiance || cone.one_minus_cos <= 0.0 {
        value
    } else {
        let span = d.irradiance.as_ref().map_or(l.span(), |r| r.span());
        finite(
            cx,
            span,
            &f("irradiance"),
            units::distant_radiance(value, sin2),
        )?
    };
    Ok(DistantLight { cone, radiance })
}

/// The emission of shape `field` (after its transform), from `emission`
/// (radiance) or `power` (W, over the mesh's area in m²); None for zero.
pub(super) fn shape_emission(
    cx: &Cx,
    field: &str,
    emission: &Option<Spanned<Triple3>>,
    power: &Option<Spanned<Triple3>>,
    mesh: &Mesh,
    units_per_mm: f32,
) -> Res<Option<Vec3>> {
    let le = match (emission, power) {
        (None, None) => return Ok(None),
        (Some(e), None) => cx.rgb(e, &format!("{field}.emission"), false)?,
        (Some(_), Some(p)) => {
            return Err(cx.err(
                p.span(),
                &format!("{field}.power"),
                "`emission` and `power` are two forms of the shape's light: give one",
            ))
        }
        (None, Some(p)) => {
            let field = format!("{field}.power");
            let w = cx.rgb(p, &field, false)?;
            let area: f64 = (0..mesh.triangle_count() as u32)
                .map(|t| mesh.area(t) as f64)
                .sum();
            if area <= 0.0 && w != Vec3::ZERO {
                return Err(cx.err(p.span(), &field, "the shape has no area to emit from"));
            }
            let le = if w == Vec3::ZERO {
                Vec3::ZERO
            } else {
                units::mesh_radiance(w, area * m2_per_unit2(units_per_mm))
            };
            finite(cx, p.span(), &field, le)?
        }
    };
    Ok(Some(le).filter(|e| *e != Vec3::ZERO))
}
