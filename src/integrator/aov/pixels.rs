//! Per-pixel sums of the samples' passes, and the image's layers and ID
//! coverage made from them (`crate::film::layers`).
//!
//! Per pixel, over its n samples, in sample order (so every pass is
//! bitwise the same for any thread count or tile split):
//!
//! - light paths and light groups: the mean of each sample's part, summed
//!   in f64 like the beauty; a sample whose radiance is not finite is
//!   dropped from them as from the beauty (where it counts as zero);
//! - `albedo`, `N`: the mean over all samples of the first non-specular
//!   hit's albedo and shading normal (zero for a sample that hits none), as
//!   denoisers expect them (filtered like the beauty; N not renormalized);
//! - `P`, `Z`, `object_id`, `material_id`: of the sample whose camera ray
//!   hit nearest (the first such sample on a tie), Arnold's "closest"
//!   filter, since averaging depths or IDs across an edge would invent
//!   values no surface has. Z is the distance along the camera's view axis;
//!   a pixel no sample hit has Z = +∞, P = 0 and IDs 0 (IDs are the object's
//!   or material's index + 1);
//! - coverage: per object name and per material name, the fraction of
//!   samples whose camera ray hit it first;
//! - `sample_count`: n; `variance`: per channel the unbiased estimate
//!   s²/n of the variance of the beauty mean, s² = Σ(x − x̄)²/(n − 1) by
//!   Welford's update in f64 (no cancellation: each step adds a non-negative
//!   term; relative error O(n ε₆₄)), +∞ for n = 1, where it is unknown.

use super::{NoAov, Recorder, SampleAovs, Setup};
use crate::error::Error;
use crate::film::layers::{Coverage, Layer, LayerKind};
use crate::film::out_of_memory;
use crate::film::passes::{Pass, LIGHT_PATHS};
use crate::geometry::Vec3;

/// The per-tile side of the passes, driven by the render's pixel loop:
/// samples in order, then the pixel's end, then the next pixel.
pub trait PixelPasses: Send {
    type Rec: Recorder;
    /// What a finished tile hands back.
    type Tile: Send;
    /// The recorder for the next sample, cleared.
    fn begin_sample(&mut self) -> &mut Self::Rec;
    /// The sample's radiance `l` (`finite` as the beauty judged it).
    fn end_sample(&mut self, l: Vec3, finite: bool);
    /// The pixel's samples are done.
    fn end_pixel(&mut self);
    fn finish(self) -> Self::Tile;
}

impl PixelPasses for NoAov {
    type Rec = NoAov;
    type Tile = ();
    #[inline(always)]
    fn begin_sample(&mut self) -> &mut NoAov {
        self
    }
    #[inline(always)]
    fn end_sample(&mut self, _: Vec3, _: bool) {}
    #[inline(always)]
    fn end_pixel(&mut self) {}
    #[inline(always)]
    fn finish(self) {}
}

/// One output layer: what it holds and where its values sit in a pixel's
/// stride.
#[derive(Clone, Debug)]
struct Slot {
    pass: Pass,
    /// For [`Pass::LightGroups`]: the group.
    group: usize,
    name: String,
    channels: &'static [&'static str],
    kind: LayerKind,
    offset: usize,
}

/// The layers a set of passes makes, in output order, and the floats each
/// pixel holds for them.
#[derive(Clone, Debug)]
pub struct Layout {
    slots: Vec<Slot>,
    stride: usize,
}

const RGB: &[&str] = &["R", "G", "B"];
const XYZ: &[&str] = &["X", "Y", "Z"];

impl Layout {
    pub fn new(setup: &Setup) -> Layout {
        let mut slots = Vec::new();
        let mut offset = 0;
        let mut add = |pass, group, name: String, channels: &'static [&'static str], kind| {
            slots.push(Slot {
                pass,
                group,
                name,
                channels,
                kind,
                offset,
            });
            offset += channels.len();
        };
        for pass in setup.passes.iter() {
            use LayerKind::{Data, Id, Light};
            let name = pass.name().to_string();
            match pass {
                Pass::LightGroups => {
                    for (g, group) in setup.groups.iter().enumerate() {
                        add(pass, g, format!("RGBA_{group}"), RGB, Light);
                    }
                }
                p if LIGHT_PATHS.contains(&p) => add(p, 0, name, RGB, Light),
                Pass::Albedo | Pass::Variance => add(pass, 0, name, RGB, Data),
                Pass::Normal | Pass::Position => add(pass, 0, name, XYZ, Data),
                Pass::Depth => add(pass, 0, name, &["Z"], Data),
                Pass::SampleCount => add(pass, 0, name, &["count"], Data),
                Pass::ObjectId | Pass::MaterialId => add(pass, 0, name, &["id"], Id),
                // Coverage, not layers.
                _ => {}
            }
        }
        Layout {
            slots,
            stride: offset,
        }
    }
}

/// The pixel being summed.
struct Sums {
    n: u32,
    paths: [[f64; 3]; LIGHT_PATHS.len()],
    groups: Vec<[f64; 3]>,
    albedo: [f64; 3],
    normal: [f64; 3],
    /// Depth, point and geom of the nearest camera hit.
    nearest: Option<(f32, Vec3, u32)>,
    /// Welford's running mean and sum of squared deviations of the beauty.
    mean: [f64; 3],
    m2: [f64; 3],
    /// Samples per object-name index and per material index.
    objects: Vec<(u32, u32)>,
    materials: Vec<(u32, u32)>,
}

impl Sums {
    fn new(groups: usize) -> Sums {
        Sums {
            n: 0,
            paths: [[0.0; 3]; LIGHT_PATHS.len()],
            groups: vec![[0.0; 3]; groups],
            albedo: [0.0; 3],
            normal: [0.0; 3],
            nearest: None,
            mean: [0.0; 3],
            m2: [0.0; 3],
            objects: Vec::new(),
            materials: Vec::new(),
        }
    }
    fn clear(&mut self) {
        self.n = 0;
        self.paths = [[0.0; 3]; LIGHT_PATHS.len()];
        self.groups.fill([0.0; 3]);
        self.albedo = [0.0; 3];
        self.normal = [0.0; 3];
        self.nearest = None;
        self.mean = [0.0; 3];
        self.m2 = [0.0; 3];
        self.objects.clear();
        self.materials.clear();
    }
}

fn add(sum: &mut [f64; 3], v: Vec3) {
    sum[0] += v.x as f64;
    sum[1] += v.y as f64;
    sum[2] += v.z as f64;
}

fn count(counts: &mut Vec<(u32, u32)>, id: u32) {
    match counts.iter_mut().find(|(i, _)| *i == id) {
        Some((_, c)) => *c += 1,
        None => counts.push((id, 1)),
    }
}

/// The passes of one tile's pixels, in the order the pixels end.
pub struct TileOut {
    pixels: usize,
    /// Per pixel, [`Layout`]'s stride of values.
    values: Vec<f32>,
    objects: Vec<Vec<(u32, f32)>>,
    materials: Vec<Vec<(u32, f32)>>,
}

/// [`PixelPasses`] of a render with passes.
pub struct TilePasses<'a> {
    setup: &'a Setup,
    layout: &'a Layout,
    /// Which sums the passes need (the rest are skipped per sample).
    variance: bool,
    objects: bool,
    materials: bool,
    rec: SampleAovs<'a>,
    sums: Sums,
    out: TileOut,
}

impl<'a> TilePasses<'a> {
    /// For a tile of `pixels` pixels.
    pub fn new(setup: &'a Setup, layout: &'a Layout, pixels: usize) -> Self {
        let coverage = |p| setup.passes.contains(p).then(|| Vec::with_capacity(pixels));
        TilePasses {
            setup,
            layout,
            variance: setup.passes.contains(Pass::Variance),
            objects: setup.passes.contains(Pass::CryptoObject),
            materials: setup.passes.contains(Pass::CryptoMaterial),
            rec: SampleAovs::new(setup),
            sums: Sums::new(setup.groups.len()),
            out: TileOut {
                pixels: 0,
                values: Vec::with_capacity(pixels * layout.stride),
                objects: coverage(Pass::CryptoObject).unwrap_or_default(),
                materials: coverage(Pass::CryptoMaterial).unwrap_or_default(),
            },
        }
    }
}

impl<'a> PixelPasses for TilePasses<'a> {
    type Rec = SampleAovs<'a>;
    type Tile = TileOut;

    fn begin_sample(&mut self) -> &mut SampleAovs<'a> {
        self.rec.clear();
        &mut self.rec
    }

    fn end_sample(&mut self, l: Vec3, finite: bool) {
        let (s, r, setup) = (&mut self.sums, &self.rec, self.setup);
        s.n += 1;
        if finite {
            for (sum, v) in s.paths.iter_mut().zip(r.paths) {
                add(sum, v);
            }
            for (sum, v) in s.groups.iter_mut().zip(&r.groups) {
                add(sum, *v);
            }
        }
        if self.variance {
            let x = if finite { l } else { Vec3::ZERO };
            for (c, x) in [x.x, x.y, x.z].into_iter().enumerate() {
                let x = x as f64;
                let delta = x - s.mean[c];
                s.mean[c] += delta / s.n as f64;
                s.m2[c] += delta * (x - s.mean[c]);
            }
        }
        if let Some((albedo, normal)) = r.surface {
            add(&mut s.albedo, albedo);
            add(&mut s.normal, normal);
        }
        if let Some((geom, p)) = r.hit {
            let z = (p - setup.origin).dot(setup.forward);
            if s.nearest.is_none_or(|(zn, _, _)| z < zn) {
                s.nearest = Some((z, p, geom));
            }
            if self.objects {
                count(&mut s.objects, setup.object_name[geom as usize]);
            }
            if self.materials {
                count(&mut s.materials, setup.object_material[geom as usize]);
            }
        }
    }

    fn end_pixel(&mut self) {
        let (s, setup, out) = (&mut self.sums, self.setup, &mut self.out);
        let n = s.n.max(1) as f64;
        let mean = |v: [f64; 3]| v.map(|x| (x / n) as f32);
        for slot in &self.layout.slots {
            let values: [f32; 3] = match slot.pass {
                Pass::LightGroups => mean(s.groups[slot.group]),
                p if LIGHT_PATHS.contains(&p) => mean(s.paths[p as usize]),
                Pass::Albedo => mean(s.albedo),
                Pass::Normal => mean(s.normal),
                Pass::Position => s.nearest.map_or([0.0; 3], |(_, p, _)| p.to_array()),
                Pass::Depth => [s.nearest.map_or(f32::INFINITY, |(z, _, _)| z), 0.0, 0.0],
                Pass::ObjectId => [s.nearest.map_or(0.0, |(_, _, g)| (g + 1) as f32), 0.0, 0.0],
                Pass::MaterialId => [
                    s.nearest.map_or(0.0, |(_, _, g)| {
                        (setup.object_material[g as usize] + 1) as f32
                    }),
                    0.0,
                    0.0,
                ],
                Pass::SampleCount => [s.n as f32, 0.0, 0.0],
                Pass::Variance => s.m2.map(|m2| {
                    if s.n < 2 {
                        f32::INFINITY
                    } else {
                        (m2 / (s.n as f64 - 1.0) / s.n as f64) as f32
                    }
                }),
                _ => unreachable!("coverage passes have no layer slot"),
            };
            out.values.extend_from_slice(&values[..slot.channels.len()]);
        }
        let fractions = |counts: &mut Vec<(u32, u32)>| {
            counts.sort_unstable();
            counts
                .iter()
                .map(|&(i, c)| (i, (c as f64 / n) as f32))
                .collect::<Vec<_>>()
        };
        if self.objects {
            out.objects.push(fractions(&mut s.objects));
        }
        if self.materials {
            out.materials.push(fractions(&mut s.materials));
        }
        out.pixels += 1;
        s.clear();
    }

    fn finish(self) -> TileOut {
        self.out
    }
}

/// The image's layers and coverage from its tiles' passes: `tiles` gives
/// each tile's origin and width (pixels in row-major order within it).
pub fn assemble<'t>(
    setup: &Setup,
    layout: &Layout,
    width: u32,
    height: u32,
    tiles: impl Iterator<Item = ((u32, u32), u32, &'t TileOut)>,
) -> Result<(Vec<Layer>, Vec<Coverage>), Error> {
    let pixels = width as usize * height as usize;
    let mut layers = Vec::with_capacity(layout.slots.len());
    for slot in &layout.slots {
        let n = pixels * slot.channels.len();
        let mut values = Vec::new();
        values
            .try_reserve_exact(n)
            .map_err(|_| out_of_memory(&format!("the {} pass", slot.name), n * 4))?;
        values.resize(n, 0.0);
        layers.push(Layer {
            name: slot.name.clone(),
            channels: slot.channels.iter().map(|c| c.to_string()).collect(),
            kind: slot.kind,
            values,
        });
    }
    let coverage_of = |p: Pass, kind: &str, names: &[String]| {
        setup.passes.contains(p).then(|| Coverage {
            kind: kind.to_string(),
            names: names.to_vec(),
            pixels: vec![Vec::new(); pixels],
        })
    };
    let mut objects = coverage_of(Pass::CryptoObject, "object", &setup.object_names);
    let mut materials = coverage_of(Pass::CryptoMaterial, "material", &setup.material_names);
    for ((x0, y0), tw, tile) in tiles {
        for i in 0..tile.pixels {
            let (x, y) = (x0 + i as u32 % tw, y0 + i as u32 / tw);
            let pixel = y as usize * width as usize + x as usize;
            let at = &tile.values[i * layout.stride..(i + 1) * layout.stride];
            for (layer, slot) in layers.iter_mut().zip(&layout.slots) {
                let c = slot.channels.len();
                layer.values[pixel * c..(pixel + 1) * c]
                    .copy_from_slice(&at[slot.offset..slot.offset + c]);
            }
            if let Some(cov) = &mut objects {
                cov.pixels[pixel] = tile.objects[i].clone();
            }
            if let Some(cov) = &mut materials {
                cov.pixels[pixel] = tile.materials[i].clone();
            }
        }
    }
    Ok((layers, objects.into_iter().chain(materials).collect()))
}
