//! `[materials.NAME]` tables → [`Material`]s: the keys each `type` accepts,
//! the three parameter forms of a subsurface material (preset; measured
//! σs', σa, A; artist A, dmfp) and its sampling options.
//!
//! Values are range-checked by the bssrdf module, which reports a
//! [`ParamError`] naming the parameter and channel as data;
//! [`locate_param`] turns that into an error at the scene key that holds
//! the parameter (`sigma_s` is given as `sigma_s_prime`, `mfp` as `dmfp`,
//! the radius sampler as `radius`).

#[cfg(feature = "subsurface")]
use std::sync::Arc;

use super::checked::{Cx, Res};
#[cfg(feature = "subsurface")]
use super::format::Triple3;
use super::format::{MaterialDef, MaterialKind, Spanned};
use super::glossy_material;
use super::key_path::key_segment;
#[cfg(feature = "subsurface")]
use super::MAX_SUBSURFACE_RADIUS;
#[cfg(feature = "subsurface")]
use crate::bssrdf::{AlbedoSource, Fit, Measured, SubsurfaceParams};
#[cfg(feature = "subsurface")]
use crate::error::{Constraint, InputError, Param, ParamError};
#[cfg(feature = "subsurface")]
use crate::materials::estimator_options::{EstimatorOptions, OptionError, OPTIONS};
#[cfg(feature = "subsurface")]
use crate::materials::textured_medium::{MediumRecipe, Reduced};
use crate::materials::Material;
#[cfg(feature = "subsurface")]
use crate::materials::Subsurface;

/// The parameter keys a `type = "subsurface"` material accepts; its
/// sampling options are the option table's ([`OPTIONS`]).
#[cfg(feature = "subsurface")]
const PARAMETER_KEYS: &[&str] = &[
    "preset",
    "sigma_s_prime",
    "sigma_a",
    "g",
    "albedo",
    "dmfp",
    "eta",
    "fit",
    "albedo_source",
    "albedo_texture",
    "dmfp_texture",
    "roughness_texture",
];

/// The parameter forms, for messages.
#[cfg(feature = "subsurface")]
const FORMS: &str =
    "give exactly one of: `preset`; `sigma_s_prime` + `sigma_a` + `albedo`; `albedo` + `dmfp`";

/// The material `name` (its table `m`), lengths in scene units given
/// `units_per_mm`.
#[cfg_attr(not(feature = "subsurface"), allow(unused_variables))]
pub(super) fn material(
    cx: &Cx,
    name: &str,
    m: &Spanned<MaterialDef>,
    units_per_mm: f32,
    units_def: Option<&Spanned<f64>>,
    textures: &super::textures::Table,
) -> Res<Material> {
    let field = format!("materials.{}", key_segment(name));
    let d = m.get_ref();
    let kind_def = cx.required(&d.kind, Some(m.span()), &format!("{field}.type"))?;
    let kind = *kind_def.get_ref();
    let missing = |key: &str| {
        cx.err(
            m.span(),
            &format!("{field}.{key}"),
            format!(
                "missing field `{key}` (required for type \"{}\")",
                kind.name()
            ),
        )
    };
    match kind {
        MaterialKind::Diffuse => {
            let keys = [
                "albedo",
                "albedo_texture",
                "normal_map",
                "bump",
                "bump_scale",
            ];
            cx.only_keys(&field, kind.name(), d.present_keys(), &keys)?;
            // With a texture the albedo is a factor on it, 1 by default.
            let albedo = match (&d.albedo, &d.albedo_texture) {
                (Some(a), _) => cx.rgb(a, &format!("{field}.albedo"), true)?,
                (None, Some(_)) => crate::geometry::Vec3::ONE,
                (None, None) => return Err(missing("albedo")),
            };
            Ok(Material::Diffuse { albedo })
        }
        MaterialKind::Dielectric => {
            let keys = ["eta", "roughness", "roughness_texture"];
            cx.only_keys(&field, kind.name(), d.present_keys(), &keys)?;
            let e = d.eta.as_ref().ok_or_else(|| missing("eta"))?;
            let eta = cx.positive(e, &format!("{field}.eta"))?;
            glossy_material::dielectric(cx, &field, d, eta)
        }
        MaterialKind::Conductor => {
            let keys = [
                "metal",
                "n",
                "k",
                "roughness",
                "roughness_texture",
                "normal_map",
                "bump",
                "bump_scale",
            ];
            cx.only_keys(&field, kind.name(), d.present_keys(), &keys)?;
            glossy_material::conductor(cx, &field, m)
        }
        MaterialKind::Plastic => {
            let keys = [
                "albedo",
                "eta",
                "roughness",
                "roughness_texture",
                "normal_map",
                "bump",
                "bump_scale",
            ];
            cx.only_keys(&field, kind.name(), d.present_keys(), &keys)?;
            glossy_material::plastic(cx, &field, m)
        }
        // Refused where the type is named: nothing of the material is read.
        #[cfg(not(feature = "subsurface"))]
        MaterialKind::Subsurface => Err(cx.err(
            kind_def.span(),
            &format!("{field}.type"),
            "this build of lucent has no subsurface support: built without the `subsurface` \
             feature",
        )),
        #[cfg(feature = "subsurface")]
        MaterialKind::Subsurface => {
            let keys: Vec<&str> = PARAMETER_KEYS
                .iter()
                .copied()
                .chain(OPTIONS.iter().map(|o| o.name))
                .collect();
            cx.only_keys(&field, kind.name(), d.present_keys(), &keys)?;
            let (params, recipe) = parameters(cx, &field, m, units_per_mm as f64)?;
            let mut options = estimator_options(cx, &field, m)?;
            // With a texture the coat's roughness is a factor on it, 1 by
            // default.
            if d.roughness.is_none() && d.roughness_texture.is_some() {
                options.roughness = 1.0;
            }
            let ss = Subsurface::from_options(params, &options)
                .map_err(|e| locate_param(cx, &field, m, &e))?;
            check_rmax(cx, &field, m, &ss, units_per_mm, units_def)?;
            let base = Material::Subsurface(Arc::new(ss));
            super::textures::subsurface(cx, &field, m, base, recipe, textures)
        }
    }
}

/// Rejects a probe radius Rmax beyond [`MAX_SUBSURFACE_RADIUS`] scene
/// units, blaming `units_per_mm` when the radius in millimetres would be in
/// range (the scale made it too large), else the material's length key:
/// `dmfp`, `sigma_a` (a small coefficient is a long path), the preset, or
/// `rmax_quantile` when that is given.
#[cfg(feature = "subsurface")]
fn check_rmax(
    cx: &Cx,
    field: &str,
    m: &Spanned<MaterialDef>,
    ss: &Subsurface,
    units_per_mm: f32,
    units_def: Option<&Spanned<f64>>,
) -> Res<()> {
    let rmax = ss.probe().rmax();
    let lim = MAX_SUBSURFACE_RADIUS;
    if rmax <= lim {
        return Ok(());
    }
    let why = format!(
        "Rmax = {rmax:e} scene units, beyond {lim:e}, the supported range (see \
         \"Supported ranges\" in docs/scene-format.md)"
    );
    let in_mm = rmax / units_per_mm as f64;
    if let Some(u) = units_def {
        if units_per_mm > 1.0 && in_mm <= lim {
            return Err(cx.err(
                u.span(),
                "units_per_mm",
                format!(
                    "units_per_mm = {:e} makes the subsurface probe radius of material \
                     `{}` {why}",
                    u.get_ref(),
                    field.trim_start_matches("materials.")
                ),
            ));
        }
    }
    let d = m.get_ref();
    let key = ["dmfp", "sigma_a", "preset", "rmax_quantile"]
        .into_iter()
        .find(|k| match *k {
            "dmfp" => d.dmfp.is_some(),
            "sigma_a" => d.sigma_a.is_some(),
            "preset" => d.preset.is_some(),
            _ => d.rmax_quantile.is_some(),
        });
    let span = key
        .and_then(|k| {
            d.present_keys()
                .into_iter()
                .find(|(p, _)| *p == k)
                .map(|(_, s)| s)
        })
        .unwrap_or(m.span());
    let f = match key {
        Some(k) => format!("{field}.{k}"),
        None => field.to_string(),
    };
    Err(cx.err(span, &f, format!("the subsurface probe radius is {why}")))
}

#[cfg(feature = "subsurface")]
fn text(v: &Option<Spanned<String>>) -> Option<(&str, std::ops::Range<usize>)> {
    v.as_ref().map(|s| (s.get_ref().as_str(), s.span()))
}

/// The scene key of the material table `m` that holds bssrdf parameter
/// `p`, with its span; None for derived values (d, rmax) and for
/// `units_per_mm`, which is not a material key.
#[cfg(feature = "subsurface")]
fn key_of(p: Param, m: &Spanned<MaterialDef>) -> Option<(&'static str, std::ops::Range<usize>)> {
    let key = match p {
        Param::Albedo => "albedo",
        Param::SigmaS => "sigma_s_prime",
        Param::SigmaA => "sigma_a",
        Param::G => "g",
        Param::Mfp => "dmfp",
        Param::Eta => "eta",
        Param::Preset => "preset",
        Param::Fit => "fit",
        Param::AlbedoSource => "albedo_source",
        Param::RadiusSampler | Param::TableSize => "radius",
        Param::RmaxQuantile => "rmax_quantile",
        Param::Roughness => "roughness",
        Param::Regularize => "regularize",
        Param::D | Param::Rmax | Param::UnitsPerMm => return None,
    };
    let present = m.get_ref().present_keys();
    let span = present.into_iter().find(|(k, _)| *k == key).map(|(_, s)| s);
    Some((key, span.unwrap_or(m.span())))
}

/// `e` located at the key of material `field` (table `m`) that holds the
/// parameter, and named as that key; at the table itself for derived
/// values.
#[cfg(feature = "subsurface")]
fn locate_param(cx: &Cx, field: &str, m: &Spanned<MaterialDef>, e: &ParamError) -> InputError {
    match key_of(e.param, m) {
        Some((key, span)) => {
            let msg = match e.param {
                Param::TableSize => format!("table size {}", e.problem()),
                Param::RadiusSampler => e.problem(),
                _ => e.describe(key),
            };
            cx.err(span, &format!("{field}.{key}"), msg)
        }
        None => cx.err(m.span(), field, e.to_string()),
    }
}

/// Rejects keys of two parameter forms together: names the first key of
/// each, at the later one's line (`albedo` belongs to the measured and the
/// artist form).
#[cfg(feature = "subsurface")]
fn one_form(cx: &Cx, field: &str, m: &Spanned<MaterialDef>) -> Res<()> {
    let present = m.get_ref().present_keys();
    let span_of = |k: &str| {
        present
            .iter()
            .find(|(p, _)| *p == k)
            .map(|(_, s)| s.clone())
    };
    let groups: [&[&str]; 3] = [
        &["preset"],
        &["sigma_s_prime", "sigma_a", "g"],
        &["dmfp", "albedo"],
    ];
    let firsts: Vec<&str> = groups
        .iter()
        .filter_map(|g| g.iter().copied().find(|k| span_of(k).is_some()))
        .collect();
    if let [a, b, ..] = firsts[..] {
        if a == "preset" || b == "dmfp" {
            let msg = format!("`{a}` cannot be combined with `{b}`; {FORMS}");
            return Err(cx.err(span_of(b).unwrap_or(m.span()), &format!("{field}.{b}"), msg));
        }
    }
    Ok(())
}

/// A triple checked as f32 and kept as written (no 1.2000000476837158).
#[cfg(feature = "subsurface")]
fn triple(cx: &Cx, field: &str, v: &Option<Spanned<Triple3>>, k: &str) -> Res<Option<[f64; 3]>> {
    v.as_ref()
        .map(|t| cx.vec3(t, &format!("{field}.{k}")).map(|_| t.get_ref().0))
        .transpose()
}

/// The medium parameters of a subsurface material, from whichever of the
/// three forms its table uses, and how they follow from textures.
#[cfg(feature = "subsurface")]
fn parameters(
    cx: &Cx,
    field: &str,
    m: &Spanned<MaterialDef>,
    units: f64,
) -> Res<(SubsurfaceParams, MediumRecipe)> {
    let d = m.get_ref();
    let f = |k: &str| format!("{field}.{k}");
    let located = |e: ParamError| locate_param(cx, field, m, &e);
    let fit = match text(&d.fit) {
        Some((s, _)) => Fit::parse(s).map_err(located)?,
        None => Fit::Searchlight,
    };
    let source = match text(&d.albedo_source) {
        Some((s, _)) => AlbedoSource::parse(s).map_err(located)?,
        None => AlbedoSource::default(),
    };
    let eta = d
        .eta
        .as_ref()
        .map(|e| cx.positive(e, &f("eta")))
        .transpose()?;
    let mut albedo = triple(cx, field, &d.albedo, "albedo")?;
    let (sigma_s, sigma_a, dmfp) = (
        triple(cx, field, &d.sigma_s_prime, "sigma_s_prime")?,
        triple(cx, field, &d.sigma_a, "sigma_a")?,
        triple(cx, field, &d.dmfp, "dmfp")?,
    );
    one_form(cx, field, m)?;
    if let Some(t) = &d.albedo_texture {
        if dmfp.is_none() {
            return Err(cx.err(
                t.span(),
                &f("albedo_texture"),
                "a textured albedo needs the artist form (`albedo_texture` with `dmfp`): a \
                 preset's or measured medium's A follows from its coefficients",
            ));
        }
        // With a texture the albedo is a factor on it, 1 by default.
        albedo = albedo.or(Some([1.0; 3]));
    }
    let missing_albedo = |form: &str| {
        cx.err(
            m.span(),
            &f("albedo"),
            format!("missing field `albedo` for {form}; {FORMS}"),
        )
    };
    match (text(&d.preset), sigma_s.or(sigma_a), dmfp) {
        (Some((name, _)), None, None) if albedo.is_none() && d.g.is_none() => {
            SubsurfaceParams::from_preset_with(name, units, fit, source, eta)
                .map(|p| (p, MediumRecipe::Lengths))
                .map_err(located)
        }
        (None, Some(_), None) => {
            let (Some(ss), Some(sa)) = (sigma_s, sigma_a) else {
                let missing = if sigma_s.is_none() {
                    "sigma_s_prime"
                } else {
                    "sigma_a"
                };
                return Err(cx.err(
                    m.span(),
                    &f(missing),
                    format!("missing field `{missing}`: measured parameters need `sigma_s_prime`, `sigma_a` and `albedo`"),
                ));
            };
            let albedo = albedo.ok_or_else(|| missing_albedo("measured parameters"))?;
            let measured = measured(ss, sa, d.g.as_ref().map(|g| *g.get_ref()), albedo, eta);
            measured
                .and_then(|ms| SubsurfaceParams::from_measured_with(&ms, units, fit, source))
                .map(|p| (p, MediumRecipe::Lengths))
                .map_err(located)
        }
        (None, None, Some(mfp)) if d.g.is_none() => {
            let albedo = albedo.ok_or_else(|| missing_albedo("the artist form"))?;
            let (dmfp, eta) = (mfp.map(|x| x * units), eta.unwrap_or(1.3));
            let reduced = Reduced::new(albedo, eta, source, d.albedo_texture.is_some());
            let recipe = MediumRecipe::Artist {
                albedo,
                dmfp,
                eta,
                fit,
                reduced,
            };
            SubsurfaceParams::from_artist_with(albedo, dmfp, eta, fit, source)
                .map(|p| (p, recipe))
                .map_err(located)
        }
        _ => Err(cx.err(m.span(), field, format!("subsurface parameters: {FORMS}"))),
    }
}

/// The measured form as given in a scene: σs' (reduced), σa, g, A, η.
/// g and σs' as written are checked here, before σs = σs'/(1 − g) (g = 1
/// would make that infinite), so that the loader's σs(1 − g) is σs' again.
#[cfg(feature = "subsurface")]
fn measured(
    sigma_s_prime: [f64; 3],
    sigma_a: [f64; 3],
    g: Option<f64>,
    albedo: [f64; 3],
    eta: Option<f32>,
) -> Result<Measured, ParamError> {
    let g = g.unwrap_or(0.0);
    if !(g > -1.0 && g < 1.0) {
        return Err(ParamError::new(Param::G, g, Constraint::Open(-1.0, 1.0)));
    }
    if let Some((c, x)) = sigma_s_prime
        .iter()
        .enumerate()
        .find(|(_, x)| !x.is_finite() || **x < 0.0)
    {
        return Err(ParamError::new(Param::SigmaS, x, Constraint::FiniteNonNegative).channel(c));
    }
    Ok(Measured {
        sigma_s: sigma_s_prime.map(|x| x / (1.0 - g)),
        sigma_a,
        g,
        albedo,
        eta: eta.unwrap_or(1.3),
    })
}

/// The value of option `key` in the material table `d`, as text, and its
/// span.
#[cfg(feature = "subsurface")]
fn option_value(d: &MaterialDef, key: &str) -> Option<(String, std::ops::Range<usize>)> {
    let s = |v: &Option<Spanned<String>>| v.as_ref().map(|v| (v.get_ref().clone(), v.span()));
    let b = |v: &Option<Spanned<bool>>| v.as_ref().map(|v| (v.get_ref().to_string(), v.span()));
    let f = |v: &Option<Spanned<f64>>| v.as_ref().map(|v| (v.get_ref().to_string(), v.span()));
    let i = |v: &Option<Spanned<i64>>| v.as_ref().map(|v| (v.get_ref().to_string(), v.span()));
    match key {
        "radius" => s(&d.radius),
        "rmax_quantile" => f(&d.rmax_quantile),
        "axes" => s(&d.axes),
        "channel" => s(&d.channel),
        "renormalize" => b(&d.renormalize),
        "exit_sw" => b(&d.exit_sw),
        "specular" => b(&d.specular),
        "roughness" => f(&d.roughness),
        "boundary" => s(&d.boundary),
        "curvature_correction" => s(&d.curvature_correction),
        "lod" => s(&d.lod),
        "lod_threshold" => f(&d.lod_threshold),
        "control_variate" => b(&d.control_variate),
        "probe_pair" => b(&d.probe_pair),
        "pair_paths" => i(&d.pair_paths),
        "regularize" => f(&d.regularize),
        "accuracy" => f(&d.accuracy),
        "profile" => s(&d.profile),
        _ => None,
    }
}

/// The sampling options of a subsurface material, read through the
/// option table (defaults for the keys it does not give).
#[cfg(feature = "subsurface")]
fn estimator_options(cx: &Cx, field: &str, m: &Spanned<MaterialDef>) -> Res<EstimatorOptions> {
    let d = m.get_ref();
    let mut o = EstimatorOptions::default();
    for row in &OPTIONS {
        let Some((v, span)) = option_value(d, row.name) else {
            continue;
        };
        let f = format!("{field}.{}", row.name);
        if !row.research_in_scenes && row.is_research(&v) {
            return Err(cx.err(span, &f, row.expected(&v).to_string()));
        }
        check_number(cx, &f, d, row.name)?;
        (row.set)(&mut o, &v).map_err(|e| match e {
            OptionError::Param(e) => locate_param(cx, field, m, &e),
            e => cx.err(span, &f, e.to_string()),
        })?;
    }
    Ok(o)
}

/// The scene's own range checks of the numeric options (finite, in their
/// domain), located at their key.
#[cfg(feature = "subsurface")]
fn check_number(cx: &Cx, f: &str, d: &MaterialDef, key: &str) -> Res<()> {
    match key {
        "rmax_quantile" => {
            let q = d.rmax_quantile.as_ref().expect("present");
            let v = cx.scalar(q, f)? as f64;
            if !(v > 0.0 && v < 1.0) {
                return Err(cx.err(
                    q.span(),
                    f,
                    format!("expected a number in (0, 1), found {v}"),
                ));
            }
        }
        "lod_threshold" => {
            let t = d.lod_threshold.as_ref().expect("present");
            let v = *t.get_ref();
            if !(v.is_finite() && v > 0.0 && v <= f32::MAX as f64) {
                return Err(cx.err(
                    t.span(),
                    f,
                    format!("expected a finite number > 0 (footprint / Rmax), found {v}"),
                ));
            }
        }
        _ => {}
    }
    Ok(())
}
