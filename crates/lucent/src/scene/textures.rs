//! `[textures.NAME]` → the scene's texture table (each image read once,
//! shared by every material that names it), and the materials that name
//! textures (`albedo_texture`, `normal_map`, `bump`, `roughness_texture`,
//! a subsurface material's `dmfp_texture`) → [`Textured`] materials
//! (`docs/scene-format.md`, "Textures").

use std::collections::{BTreeMap, HashMap};
use std::path::Path;
use std::sync::Arc;

use super::checked::{Cx, Res};
use super::format::{MaterialDef, Spanned, TextureDef};
use super::key_path::{key_segment, quoted};
use super::regular_file::{open_regular, read_regular_bytes};
#[cfg(feature = "subsurface")]
use super::MAX_SUBSURFACE_RADIUS;
use crate::geometry::Vec3;
use crate::materials::roughness_steps::RoughnessSteps;
#[cfg(feature = "subsurface")]
use crate::materials::textured_medium::MediumRecipe;
use crate::materials::{Bump, Conductor, Material, Plastic, RoughnessMap, TextureUse, Textured};
use crate::texture::file::{self, Format, TextureError};
use crate::texture::{ColorSpace, Texture, TextureRef, Wrap};

/// The largest PNG or JPEG file read (bytes); its decoded size is bounded by
/// [`file::MAX_TEXELS`] besides.
const MAX_IMAGE_BYTES: u64 = 1 << 30;

/// A loaded texture and how its values were decoded.
pub(super) struct Entry {
    texture: Arc<Texture>,
    space: ColorSpace,
}

/// The scene's textures by name.
pub(super) type Table = HashMap<String, Entry>;

/// Every `[textures.NAME]` of the scene, read from files relative to `dir`.
pub(super) fn table(
    cx: &Cx,
    dir: &Path,
    defs: &BTreeMap<String, Spanned<TextureDef>>,
) -> Res<Table> {
    let mut out = HashMap::new();
    for (name, d) in defs {
        let field = format!("textures.{}", key_segment(name));
        out.insert(name.clone(), entry(cx, dir, &field, d)?);
    }
    Ok(out)
}

fn entry(cx: &Cx, dir: &Path, field: &str, d: &Spanned<TextureDef>) -> Res<Entry> {
    let t = d.get_ref();
    let file_key = format!("{field}.file");
    let f = cx.required(&t.file, Some(d.span()), &file_key)?;
    let space = choice(
        cx,
        field,
        "color_space",
        &t.color_space,
        ColorSpace::parse,
        "\"srgb\" or \"linear\"",
    )?
    .unwrap_or(ColorSpace::Srgb);
    let wrap = choice(
        cx,
        field,
        "wrap",
        &t.wrap,
        Wrap::parse,
        "\"repeat\" or \"clamp\"",
    )?
    .unwrap_or(Wrap::Repeat);
    let path = dir.join(f.get_ref());
    let refuse = |e: String| {
        cx.err(
            f.span(),
            &file_key,
            format!("texture image {}: {e}", path.display()),
        )
    };
    Ok(Entry {
        texture: load(&path, space, wrap).map_err(refuse)?,
        space,
    })
}

/// The texture of the image at `path`, or why it cannot be used.
pub(super) fn load(path: &Path, space: ColorSpace, wrap: Wrap) -> Result<Arc<Texture>, String> {
    let texels = read(path, space)?;
    Ok(Arc::new(Texture::new(
        texels.width,
        texels.height,
        texels.data,
        wrap,
    )))
}

/// The value of the optional key `key` of table `field`, one of `names`.
fn choice<T>(
    cx: &Cx,
    field: &str,
    key: &str,
    v: &Option<Spanned<String>>,
    parse: fn(&str) -> Option<T>,
    names: &str,
) -> Res<Option<T>> {
    let Some(v) = v else { return Ok(None) };
    parse(v.get_ref()).map(Some).ok_or_else(|| {
        cx.err(
            v.span(),
            &format!("{field}.{key}"),
            format!("expected {names}, found {}", quoted(v.get_ref())),
        )
    })
}

/// The image at `path`, decoded per `space` (PNG only: float images are
/// linear).
fn read(path: &Path, space: ColorSpace) -> Result<crate::environment::image::Texels, String> {
    let format = file::format_of(path).map_err(|e| e.to_string())?;
    let cannot = |e: std::io::Error| format!("cannot read it: {e}");
    match format {
        Format::Png | Format::Jpeg => {
            let bytes = read_regular_bytes(path, MAX_IMAGE_BYTES).map_err(cannot)?;
            file::read_integer_image(&bytes, format, space)
                .map_err(|e| TextureError::from(e).to_string())
        }
        Format::Float => {
            open_regular(path).map_err(cannot)?;
            file::read_float(path).map_err(|e| TextureError::from(e).to_string())
        }
    }
}

/// `base`, the material `name` (table `m`) built from its other keys, with
/// the textures it names; `base` itself when it names none.
pub(super) fn textured(
    cx: &Cx,
    name: &str,
    m: &Spanned<MaterialDef>,
    base: Material,
    table: &Table,
) -> Res<Material> {
    let d = m.get_ref();
    // a subsurface material's textures are read with its parameters
    let field = format!("materials.{}", key_segment(name));
    if matches!(base, Material::Textured(_)) {
        return Ok(base);
    }
    let bump = bump(cx, &field, d, table)?;
    let roughness = roughness(cx, &field, d, &base, table)?;
    if d.albedo_texture.is_none() && d.normal_map.is_none() && bump.is_none() && roughness.is_none()
    {
        return Ok(base);
    }
    let albedo = match &d.albedo_texture {
        Some(t) => {
            let e = lookup(cx, &format!("{field}.albedo_texture"), t, table)?;
            let scale = match &base {
                Material::Diffuse { albedo } => *albedo,
                _ => Vec3::ONE,
            };
            Some(TextureRef {
                texture: e.texture.clone(),
                scale,
            })
        }
        None => None,
    };
    let normal = d
        .normal_map
        .as_ref()
        .map(|t| data(cx, &format!("{field}.normal_map"), t, table, "a normal map"))
        .transpose()?;
    let names = uses(&[
        ("albedo_texture", &d.albedo_texture),
        ("normal_map", &d.normal_map),
        ("bump", &d.bump),
        ("roughness_texture", &d.roughness_texture),
    ]);
    let mut t = Textured::new(base, albedo, normal).named(names);
    t.bump = bump;
    t.roughness = roughness;
    Ok(Material::Textured(Arc::new(t)))
}

/// The roughness map of material `field` (table `d`, built as `base`):
/// its `roughness_texture` (data) times the base's roughness, with the
/// albedo tables of the steps it spans for a conductor, a plastic or a
/// subsurface coat. The loader accepts the key on those and on a
/// dielectric only.
fn roughness(
    cx: &Cx,
    field: &str,
    d: &MaterialDef,
    base: &Material,
    table: &Table,
) -> Res<Option<RoughnessMap>> {
    let Some(t) = &d.roughness_texture else {
        return Ok(None);
    };
    let key = format!("{field}.roughness_texture");
    let texture = data(cx, &key, t, table, "a roughness")?;
    let (scale, steps) = match base {
        Material::Conductor(c) => {
            let (lo, hi) = RoughnessMap::range(&texture, c.roughness);
            let steps = RoughnessSteps::new(lo, hi, Conductor::table);
            (c.roughness, Some(steps))
        }
        Material::Plastic(p) => {
            let (lo, hi) = RoughnessMap::range(&texture, p.roughness);
            let eta = p.eta;
            let steps = RoughnessSteps::new(lo, hi, |r| Plastic::table(r, eta));
            (p.roughness, Some(steps))
        }
        #[cfg(feature = "subsurface")]
        Material::Subsurface(ss) => {
            let scale = ss.roughness();
            let (lo, hi) = RoughnessMap::range(&texture, scale);
            let eta = ss.eta();
            let steps = RoughnessSteps::new(lo, hi, |r| Plastic::table(r, eta));
            (scale, Some(steps))
        }
        Material::RoughDielectric(r) => (r.roughness, None),
        _ => return Err(cx.err(t.span(), &key, "this material has no roughness")),
    };
    Ok(Some(RoughnessMap {
        texture,
        scale,
        steps,
    }))
}

/// The bump map of material `field` (table `d`): its `bump` texture
/// (data) and `bump_scale` (finite, default 1). Refused: `bump_scale`
/// alone, `bump` with `normal_map`.
fn bump(cx: &Cx, field: &str, d: &MaterialDef, table: &Table) -> Res<Option<Bump>> {
    let scale = match &d.bump_scale {
        Some(s) => {
            let key = format!("{field}.bump_scale");
            if d.bump.is_none() {
                return Err(cx.err(s.span(), &key, "`bump_scale` without `bump`"));
            }
            cx.scalar(s, &key)?
        }
        None => 1.0,
    };
    let Some(t) = &d.bump else {
        return Ok(None);
    };
    let key = format!("{field}.bump");
    if d.normal_map.is_some() {
        return Err(cx.err(
            t.span(),
            &key,
            "give either `normal_map` or `bump`: both set the shading normal",
        ));
    }
    let texture = data(cx, &key, t, table, "a height map")?;
    Ok(Some(Bump { texture, scale }))
}

/// The linear texture `t` names (at `key`), refused when declared sRGB:
/// `what` is data.
fn data(cx: &Cx, key: &str, t: &Spanned<String>, table: &Table, what: &str) -> Res<Arc<Texture>> {
    let e = lookup(cx, key, t, table)?;
    if e.space != ColorSpace::Linear {
        return Err(cx.err(
            t.span(),
            key,
            format!(
                "texture {} is declared sRGB, but {what} is data: give it \
                 color_space = \"linear\"",
                quoted(t.get_ref())
            ),
        ));
    }
    Ok(e.texture.clone())
}

/// The subsurface material `base` (`field`, table `m`) with the textures
/// its `albedo_texture` (A, a factor on `albedo`) and `dmfp_texture` (a
/// factor on its lengths, data) name, its parameters at a point following
/// `recipe`; `base` when it names neither.
#[cfg(feature = "subsurface")]
pub(super) fn subsurface(
    cx: &Cx,
    field: &str,
    m: &Spanned<MaterialDef>,
    base: Material,
    recipe: MediumRecipe,
    table: &Table,
) -> Res<Material> {
    let d = m.get_ref();
    if d.albedo_texture.is_none() && d.dmfp_texture.is_none() && d.roughness_texture.is_none() {
        return Ok(base);
    }
    let roughness = roughness(cx, field, d, &base, table)?;
    let unit = |texture| TextureRef {
        texture,
        scale: Vec3::ONE,
    };
    let albedo = match &d.albedo_texture {
        Some(t) => Some(unit(
            lookup(cx, &format!("{field}.albedo_texture"), t, table)?
                .texture
                .clone(),
        )),
        None => None,
    };
    let dmfp = match &d.dmfp_texture {
        Some(t) => {
            let key = format!("{field}.dmfp_texture");
            Some(unit(data(cx, &key, t, table, "a length factor")?))
        }
        None => None,
    };
    let names = uses(&[
        ("albedo_texture", &d.albedo_texture),
        ("dmfp_texture", &d.dmfp_texture),
        ("roughness_texture", &d.roughness_texture),
    ]);
    if let (Some(k), Some(v), Material::Subsurface(ss)) = (&dmfp, &d.dmfp_texture, &base) {
        let key = format!("{field}.dmfp_texture");
        check_longest(cx, &key, v, ss, &recipe, k.texture.max_texel())?;
    }
    let mut t = Textured::new(base, albedo, None).named(names);
    t.dmfp = dmfp;
    t.roughness = roughness;
    t.medium = Some(recipe);
    Ok(Material::Textured(Arc::new(t)))
}

/// Refuses a length texture whose largest texels `max` would make the
/// probe radius of `ss` exceed [`MAX_SUBSURFACE_RADIUS`] (at the
/// material's own albedo).
#[cfg(feature = "subsurface")]
fn check_longest(
    cx: &Cx,
    key: &str,
    v: &Spanned<String>,
    ss: &crate::materials::Subsurface,
    recipe: &MediumRecipe,
    max: Vec3,
) -> Res<()> {
    let params = recipe.params_at(ss.params(), None, Some(max));
    let rmax = ss.at_point(params).map_or(0.0, |p| p.probe().rmax());
    if rmax <= MAX_SUBSURFACE_RADIUS {
        return Ok(());
    }
    Err(cx.err(
        v.span(),
        key,
        format!(
            "texture {}'s largest texels {max} make the subsurface probe radius Rmax = \
             {rmax:e} scene units, beyond {MAX_SUBSURFACE_RADIUS:e}, the supported range \
             (see \"Supported ranges\" in docs/scene-format.md)",
            quoted(v.get_ref())
        ),
    ))
}

/// The texture keys given, with the names they give.
fn uses(keys: &[(&'static str, &Option<Spanned<String>>)]) -> Vec<TextureUse> {
    keys.iter()
        .filter_map(|(key, v)| {
            v.as_ref().map(|v| TextureUse {
                key,
                texture: v.get_ref().clone(),
            })
        })
        .collect()
}

/// The texture `t` names, or an error at `field` listing those defined.
fn lookup<'t>(cx: &Cx, field: &str, t: &Spanned<String>, table: &'t Table) -> Res<&'t Entry> {
    table.get(t.get_ref()).ok_or_else(|| {
        let mut known: Vec<String> = table.keys().map(|k| key_segment(k)).collect();
        known.sort_unstable();
        let known = if known.is_empty() {
            "no [textures] are defined".to_string()
        } else {
            format!("defined: {}", known.join(", "))
        };
        cx.err(
            t.span(),
            field,
            format!("unknown texture {} ({known})", quoted(t.get_ref())),
        )
    })
}
