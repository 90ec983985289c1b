//! Per-pixel sums of the samples' passes, exact and order-free like the
//! beauty's, and the image's layers and ID coverage made from them
//! (`crate::film::layers`).
//!
//! A pass is not computed at the end of a pixel's samples but *summed*
//! over them, in a representation whose addition is associative and
//! commutative, so that the sums of disjoint sample ranges, tiles, parts or
//! resumed runs add up to exactly the sums of one uninterrupted run (the
//! beauty's argument, `crate::film::accumulate`, docs/farm.md). The layers
//! are a function of the final sums and the sample count n alone, computed
//! once at the end ([`layers`]): a merged frame's passes are bitwise the
//! uncut render's.
//!
//! Per pixel, over its n samples:
//!
//! - **light paths and light groups**: Σ of each sample's part, in
//!   [`FixedPoint::RADIANCE`] (Q63.64, the beauty's format: the same
//!   quantities, the same range and resolution); a sample whose radiance is
//!   not finite is dropped from them as from the beauty (where it counts as
//!   zero). Layer: Σ/n by [`FixedPoint::mean`].
//! - **`albedo`, `N`**: Σ of the first non-specular hit's albedo and
//!   shading normal (zero for a sample that hits none), also Q63.64:
//!   normals are within [−1, 1] and albedos within [0, 1] (at most a few
//!   units for a user's odd material), far inside the ±2^31 range, and
//!   every value above 2^−41 ≈ 4.5·10^−13 converts exactly. Layer: Σ/n, as
//!   denoisers expect them (filtered like the beauty; N not renormalized).
//! - **`P`, `Z`, `object_id`, `material_id`**: of the sample whose camera
//!   ray hit nearest, Arnold's "closest" filter, since averaging depths or
//!   IDs across an edge would invent values no surface has. Not a sum but a
//!   minimum ([`Nearest`]): the minimum of the key (Z, sample index) —
//!   unique per sample, so the minimum is order-free and a tie in Z goes
//!   to the lowest sample index, as the former in-order scan did. Stored
//!   as the f32 bits themselves (exact). Z is the distance along the
//!   camera's view axis; a pixel no sample hit has Z = +∞, P = 0 and IDs 0
//!   (IDs are the object's or material's index + 1).
//! - **coverage**: per object name and per material name, the *count* of
//!   samples whose camera ray hit it first (integers: exact under any
//!   split); the fractions count/n, and from them the Cryptomatte ranks
//!   (`crate::film::cryptomatte`, with its deterministic tie-break), are
//!   computed from the final counts only.
//! - **`sample_count`**: n, known from the sample range: nothing stored.
//! - **`variance`**: per channel, the unbiased estimate s²/n of the
//!   variance of the beauty mean, s² = Σ(x − x̄)²/(n − 1), from Σq (the
//!   beauty's own sum, q = round(x·2^64) the integer each sample added)
//!   and Σq², both exact integers:
//!
//!   s²/n = (n·Σq² − (Σq)²) · 2^−128 / (n²(n − 1)),
//!
//!   with the numerator computed exactly in 256-bit integers (it is ≥ 0 by
//!   Cauchy–Schwarz, and exactly 0 for a pixel whose samples are all
//!   equal), so there is no cancellation: the only roundings are the
//!   numerator's conversion to f64 (2^−52 relative) and one division.
//!   q² < 2^190 does not fit an i128, so Σq² is carried as three i128 sums
//!   of its 64-bit words (each word < 2^64, so ≤ 2^32 samples sum below
//!   2^96: no overflow, no carry, plain integer sums that merge by
//!   addition like every other channel). +∞ for n = 1, where it is
//!   unknown.

use super::{NoAov, Recorder, SampleAovs, Setup};
use crate::error::Error;
use crate::film::accumulate::FixedPoint;
use crate::film::layers::{Coverage, Layer, LayerKind};
use crate::film::out_of_memory;
use crate::film::passes::{Pass, PassSet, LIGHT_PATHS};
use crate::geometry::Vec3;

/// The per-pixel side of the passes, driven by the render's tile loop:
/// per pixel, `begin_pixel`, then per sample `begin_sample` and
/// `end_sample`, then `end_pixel`.
pub trait PixelPasses: Send {
    type Rec: Recorder;
    /// Pixel `i` of the tile starts: its sums so far are loaded.
    fn begin_pixel(&mut self, i: usize);
    /// The recorder for the next sample, cleared.
    fn begin_sample(&mut self) -> &mut Self::Rec;
    /// Sample index `s` is done: its radiance `l` (`finite` as the beauty
    /// judged it).
    fn end_sample(&mut self, s: u32, l: Vec3, finite: bool);
    /// Pixel `i`'s samples are done: its sums are stored.
    fn end_pixel(&mut self, i: usize);
}

impl PixelPasses for NoAov {
    type Rec = NoAov;
    #[inline(always)]
    fn begin_pixel(&mut self, _: usize) {}
    #[inline(always)]
    fn begin_sample(&mut self) -> &mut NoAov {
        self
    }
    #[inline(always)]
    fn end_sample(&mut self, _: u32, _: Vec3, _: bool) {}
    #[inline(always)]
    fn end_pixel(&mut self, _: usize) {}
}

/// The fixed-point format of Σq² words (each an integer: q² is in units
/// of 2^−128; the words are the fraction bits' 64-bit pieces).
pub const SQUARE_BITS: u32 = 128;

/// i128 sums a channel of the variance pass keeps: Σq²'s 64-bit words.
pub const SQUARE_WORDS: usize = 3;

/// One output layer: what it holds and, for summed layers, where its sums
/// sit in a pixel's stride.
#[derive(Clone, Debug, PartialEq)]
struct Slot {
    pass: Pass,
    /// For [`Pass::LightGroups`]: the group.
    group: usize,
    name: String,
    channels: &'static [&'static str],
    kind: LayerKind,
    /// First i128 of its sums in the pixel's stride (summed layers and
    /// the variance's squares).
    offset: usize,
}

/// The layers a set of passes makes, in output order, what each pixel
/// sums for them, and the names they need (light groups, matted objects
/// and materials). A function of the pass set and the scene's names alone,
/// so a merge rebuilds it from a part's header.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    pub passes: PassSet,
    pub groups: Vec<String>,
    pub object_names: Vec<String>,
    pub material_names: Vec<String>,
    slots: Vec<Slot>,
    /// i128 sums per pixel.
    stride: usize,
}

const RGB: &[&str] = &["R", "G", "B"];
const XYZ: &[&str] = &["X", "Y", "Z"];

/// A layer of summed channels, as a part lists it: name, channels, and
/// the fixed-point fraction bits of their sums.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SumLayer {
    pub name: String,
    pub channels: Vec<String>,
    pub frac_bits: u32,
}

impl Layout {
    /// The layout of `passes` with these names (light groups, object names,
    /// material names; unused ones are dropped, so the layout says only
    /// what the passes need).
    pub fn new(
        passes: PassSet,
        groups: &[String],
        object_names: &[String],
        material_names: &[String],
    ) -> Layout {
        let mut slots = Vec::new();
        let mut offset = 0;
        let mut add = |pass, group, name: String, channels: &'static [&'static str], kind| {
            let sums = match pass {
                Pass::Variance => channels.len() * SQUARE_WORDS,
                p if LIGHT_PATHS.contains(&p) => channels.len(),
                Pass::LightGroups | Pass::Albedo | Pass::Normal => channels.len(),
                _ => 0,
            };
            slots.push(Slot {
                pass,
                group,
                name,
                channels,
                kind,
                offset,
            });
            offset += sums;
        };
        for pass in passes.iter() {
            use LayerKind::{Data, Id, Light};
            let name = pass.name().to_string();
            match pass {
                Pass::LightGroups => {
                    for (g, group) in groups.iter().enumerate() {
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
        let keep = |p: Pass, names: &[String]| {
            if passes.contains(p) {
                names.to_vec()
            } else {
                Vec::new()
            }
        };
        Layout {
            passes,
            groups: keep(Pass::LightGroups, groups),
            object_names: keep(Pass::CryptoObject, object_names),
            material_names: keep(Pass::CryptoMaterial, material_names),
            slots,
            stride: offset,
        }
    }

    /// The layout of `passes` over `setup`'s names.
    pub fn of(setup: &Setup) -> Layout {
        Layout::new(
            setup.passes,
            &setup.groups,
            &setup.object_names,
            &setup.material_names,
        )
    }

    /// i128 sums per pixel.
    pub fn stride(&self) -> usize {
        self.stride
    }

    /// Whether the nearest camera hit is kept (P, Z, IDs).
    pub fn nearest(&self) -> bool {
        [
            Pass::Position,
            Pass::Depth,
            Pass::ObjectId,
            Pass::MaterialId,
        ]
        .iter()
        .any(|p| self.passes.contains(*p))
    }

    /// The summed layers, in stride order (a part's `lucent.layers` after
    /// the beauty).
    pub fn sum_layers(&self) -> Vec<SumLayer> {
        let mut v = Vec::new();
        for s in &self.slots {
            match s.pass {
                Pass::Variance => v.push(SumLayer {
                    name: "variance.sq".into(),
                    channels: s
                        .channels
                        .iter()
                        .flat_map(|c| (0..SQUARE_WORDS).map(move |k| format!("{c}{k}")))
                        .collect(),
                    frac_bits: SQUARE_BITS,
                }),
                p if p == Pass::LightGroups
                    || p == Pass::Albedo
                    || p == Pass::Normal
                    || LIGHT_PATHS.contains(&p) =>
                {
                    v.push(SumLayer {
                        name: s.name.clone(),
                        channels: s.channels.iter().map(|c| c.to_string()).collect(),
                        frac_bits: FixedPoint::RADIANCE.frac_bits,
                    })
                }
                _ => {}
            }
        }
        v
    }
}

/// The camera hit nearest to the camera among a pixel's samples, with the
/// sample index as tie-break: the minimum of (Z, sample) is unique, so it
/// does not depend on the order the samples are met.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest {
    pub z: f32,
    pub sample: u32,
    pub p: [f32; 3],
    /// The object's index + 1 (0: no sample hit).
    pub object: u32,
    /// Its material's index + 1.
    pub material: u32,
}

impl Nearest {
    /// No hit: loses to every hit.
    pub const NONE: Nearest = Nearest {
        z: f32::INFINITY,
        sample: u32::MAX,
        p: [0.0; 3],
        object: 0,
        material: 0,
    };

    /// The order: Z in f32's total order, then the sample index.
    fn order(&self, o: &Nearest) -> std::cmp::Ordering {
        self.z.total_cmp(&o.z).then(self.sample.cmp(&o.sample))
    }

    /// The nearer of the two.
    pub fn nearer(self, o: Nearest) -> Nearest {
        if self.object == 0 || (o.object != 0 && o.order(&self).is_lt()) {
            o
        } else {
            self
        }
    }
}

/// Adds `o`'s counts (sorted by ID) to `into` (sorted by ID), keeping it
/// sorted.
pub fn add_counts(into: &mut Vec<(u32, u32)>, o: &[(u32, u32)]) -> Option<()> {
    for &(id, c) in o {
        match into.binary_search_by_key(&id, |e| e.0) {
            Ok(i) => into[i].1 = into[i].1.checked_add(c)?,
            Err(i) => into.insert(i, (id, c)),
        }
    }
    Some(())
}

/// The passes' sums of a region's pixels (the beauty's pixel order:
/// tile-major, `crate::render::Accumulated`).
#[derive(Clone, Debug, PartialEq)]
pub struct AovSums {
    /// [`Layout::stride`] i128 a pixel.
    pub sums: Vec<i128>,
    /// Per pixel, if the layout keeps it.
    pub nearest: Vec<Nearest>,
    /// Per pixel, (object name index, samples) sorted by index; empty when
    /// not asked for.
    pub objects: Vec<Vec<(u32, u32)>>,
    pub materials: Vec<Vec<(u32, u32)>>,
}

impl AovSums {
    /// Zero sums for `pixels` pixels.
    pub fn new(layout: &Layout, pixels: usize) -> Result<AovSums, Error> {
        let n = pixels.saturating_mul(layout.stride);
        let mut sums = Vec::new();
        sums.try_reserve_exact(n)
            .map_err(|_| out_of_memory("the passes' sums", n.saturating_mul(16)))?;
        sums.resize(n, 0);
        let per = |on: bool| if on { pixels } else { 0 };
        Ok(AovSums {
            sums,
            nearest: vec![Nearest::NONE; per(layout.nearest())],
            objects: vec![Vec::new(); per(layout.passes.contains(Pass::CryptoObject))],
            materials: vec![Vec::new(); per(layout.passes.contains(Pass::CryptoMaterial))],
        })
    }

    /// Splits into consecutive views of `pixels[k]` pixels each.
    pub fn views<'a>(&'a self, layout: &Layout, pixels: &[usize]) -> Vec<AovView<'a>> {
        let (mut s, mut n, mut o, mut m) = (
            &self.sums[..],
            &self.nearest[..],
            &self.objects[..],
            &self.materials[..],
        );
        pixels
            .iter()
            .map(|&k| {
                let take = |len: usize| if len == 0 { 0 } else { k };
                let (a, b) = s.split_at(k * layout.stride);
                let (c, d) = n.split_at(take(n.len()));
                let (e, f) = o.split_at(take(o.len()));
                let (g, h) = m.split_at(take(m.len()));
                (s, n, o, m) = (b, d, f, h);
                AovView {
                    sums: a,
                    nearest: c,
                    objects: e,
                    materials: g,
                }
            })
            .collect()
    }

    /// Splits into consecutive mutable views of `pixels[k]` pixels each.
    pub fn views_mut<'a>(&'a mut self, layout: &Layout, pixels: &[usize]) -> Vec<AovViewMut<'a>> {
        let (mut s, mut n, mut o, mut m) = (
            &mut self.sums[..],
            &mut self.nearest[..],
            &mut self.objects[..],
            &mut self.materials[..],
        );
        let mut v = Vec::with_capacity(pixels.len());
        for &k in pixels {
            let take = |len: usize| if len == 0 { 0 } else { k };
            let (a, b) = std::mem::take(&mut s).split_at_mut(k * layout.stride);
            let nt = take(n.len());
            let (c, d) = std::mem::take(&mut n).split_at_mut(nt);
            let ot = take(o.len());
            let (e, f) = std::mem::take(&mut o).split_at_mut(ot);
            let mt = take(m.len());
            let (g, h) = std::mem::take(&mut m).split_at_mut(mt);
            (s, n, o, m) = (b, d, f, h);
            v.push(AovViewMut {
                sums: a,
                nearest: c,
                objects: e,
                materials: g,
            });
        }
        v
    }

    /// Adds pixel `j` of `o` to pixel `i` of `self`; None on an overflow
    /// (sums no render makes).
    pub fn add_pixel(&mut self, layout: &Layout, i: usize, o: &AovSums, j: usize) -> Option<()> {
        let st = layout.stride;
        for (a, b) in self.sums[i * st..(i + 1) * st]
            .iter_mut()
            .zip(&o.sums[j * st..(j + 1) * st])
        {
            *a = a.checked_add(*b)?;
        }
        if !self.nearest.is_empty() {
            self.nearest[i] = self.nearest[i].nearer(o.nearest[j]);
        }
        if !self.objects.is_empty() {
            add_counts(&mut self.objects[i], &o.objects[j])?;
        }
        if !self.materials.is_empty() {
            add_counts(&mut self.materials[i], &o.materials[j])?;
        }
        Some(())
    }
}

/// A region's passes: their layout and sums.
#[derive(Clone, Debug, PartialEq)]
pub struct Passes {
    pub layout: Layout,
    pub sums: AovSums,
}

/// A tile's previous sums.
pub struct AovView<'a> {
    sums: &'a [i128],
    nearest: &'a [Nearest],
    objects: &'a [Vec<(u32, u32)>],
    materials: &'a [Vec<(u32, u32)>],
}

/// Where a tile writes its new sums.
pub struct AovViewMut<'a> {
    sums: &'a mut [i128],
    nearest: &'a mut [Nearest],
    objects: &'a mut [Vec<(u32, u32)>],
    materials: &'a mut [Vec<(u32, u32)>],
}

/// q² of a term q (|q| ≤ 2^95) as its three 64-bit words, least
/// significant first (q² < 2^190).
#[inline]
pub fn square_words(q: i128) -> [i128; SQUARE_WORDS] {
    let w = mul_u128(q.unsigned_abs(), q.unsigned_abs());
    [
        w[0] as i128,
        w[1] as i128,
        (w[2] as i128) | (w[3] as i128) << 64,
    ]
}

/// The 256-bit product of two u128, as four u64 limbs, least significant
/// first.
fn mul_u128(a: u128, b: u128) -> [u64; 4] {
    let (a0, a1) = (a as u64 as u128, a >> 64);
    let (b0, b1) = (b as u64 as u128, b >> 64);
    let mut r = [0u64; 4];
    add_at(&mut r, 0, a0 * b0);
    add_at(&mut r, 1, a0 * b1);
    add_at(&mut r, 1, a1 * b0);
    add_at(&mut r, 2, a1 * b1);
    r
}

/// Adds `v` at limb `at` of `r` (a 256-bit unsigned integer), carrying.
fn add_at(r: &mut [u64; 4], at: usize, v: u128) {
    let mut carry = v;
    for limb in r.iter_mut().skip(at) {
        if carry == 0 {
            break;
        }
        let s = *limb as u128 + (carry as u64) as u128;
        *limb = s as u64;
        carry = (carry >> 64) + (s >> 64);
    }
}

/// The variance of the mean of `n` samples whose beauty terms sum to `s1`
/// and whose squared terms' words sum to `sq` (see the module docs), f32.
pub fn variance(s1: i128, sq: &[i128], n: u64) -> f32 {
    if n < 2 {
        return f32::INFINITY;
    }
    // Σq² (each word sum is non-negative and < 2^96)
    let mut sum_sq = [0u64; 4];
    for (k, &w) in sq.iter().enumerate() {
        add_at(&mut sum_sq, k, w as u128);
    }
    // n·Σq² (< 2^254)
    let mut lhs = [0u64; 4];
    for (k, &limb) in sum_sq.iter().enumerate() {
        add_at(&mut lhs, k, limb as u128 * n as u128);
    }
    // − (Σq)², never below 0 (Cauchy–Schwarz); saturate a forged part
    let rhs = mul_u128(s1.unsigned_abs(), s1.unsigned_abs());
    let mut num = [0u64; 4];
    let mut borrow = false;
    for k in 0..4 {
        let (d, b1) = lhs[k].overflowing_sub(rhs[k]);
        let (d, b2) = d.overflowing_sub(borrow as u64);
        num[k] = d;
        borrow = b1 || b2;
    }
    if borrow {
        return 0.0;
    }
    let num: f64 = num
        .iter()
        .enumerate()
        .map(|(k, &l)| l as f64 * (2f64).powi(64 * k as i32 - SQUARE_BITS as i32))
        .sum();
    let n = n as f64;
    (num / (n * n * (n - 1.0))) as f32
}

/// [`PixelPasses`] of a render with passes, for one tile: reads the tile's
/// previous sums, writes previous + this pass's samples.
pub struct TilePasses<'a> {
    setup: &'a Setup,
    layout: &'a Layout,
    prev: AovView<'a>,
    out: AovViewMut<'a>,
    variance: Option<usize>,
    rec: SampleAovs<'a>,
    // the pixel under way
    sums: Vec<i128>,
    nearest: Nearest,
    objects: Vec<(u32, u32)>,
    materials: Vec<(u32, u32)>,
}

impl<'a> TilePasses<'a> {
    pub fn new(
        setup: &'a Setup,
        layout: &'a Layout,
        prev: AovView<'a>,
        out: AovViewMut<'a>,
    ) -> Self {
        TilePasses {
            setup,
            layout,
            prev,
            out,
            variance: layout
                .slots
                .iter()
                .find(|s| s.pass == Pass::Variance)
                .map(|s| s.offset),
            rec: SampleAovs::new(setup),
            sums: vec![0; layout.stride],
            nearest: Nearest::NONE,
            objects: Vec::new(),
            materials: Vec::new(),
        }
    }
}

impl<'a> PixelPasses for TilePasses<'a> {
    type Rec = SampleAovs<'a>;

    fn begin_pixel(&mut self, i: usize) {
        let st = self.layout.stride;
        self.sums
            .copy_from_slice(&self.prev.sums[i * st..(i + 1) * st]);
        if let Some(n) = self.prev.nearest.get(i) {
            self.nearest = *n;
        }
        if let Some(o) = self.prev.objects.get(i) {
            self.objects.clone_from(o);
        }
        if let Some(m) = self.prev.materials.get(i) {
            self.materials.clone_from(m);
        }
    }

    fn begin_sample(&mut self) -> &mut SampleAovs<'a> {
        self.rec.clear();
        &mut self.rec
    }

    fn end_sample(&mut self, s: u32, l: Vec3, finite: bool) {
        const F: FixedPoint = FixedPoint::RADIANCE;
        let (r, setup) = (&self.rec, self.setup);
        for slot in &self.layout.slots {
            let v = match slot.pass {
                Pass::LightGroups if finite => r.groups[slot.group],
                p if finite && LIGHT_PATHS.contains(&p) => r.paths[p as usize],
                Pass::Albedo => match r.surface {
                    Some((albedo, _)) => albedo,
                    None => continue,
                },
                Pass::Normal => match r.surface {
                    Some((_, normal)) => normal,
                    None => continue,
                },
                _ => continue,
            };
            // most of a sample's light is in one or two passes: adding a
            // zero (to_fixed(±0) = 0) is skipped, exactly
            if v == Vec3::ZERO {
                continue;
            }
            F.add(
                &mut self.sums[slot.offset..slot.offset + 3],
                &[v.x, v.y, v.z],
            );
        }
        if let Some(off) = self.variance {
            // the beauty's own terms (0 for a dropped sample)
            if finite {
                for (c, x) in [l.x, l.y, l.z].into_iter().enumerate() {
                    let w = square_words(F.to_fixed(x).0);
                    let at = off + c * SQUARE_WORDS;
                    for (sum, w) in self.sums[at..at + SQUARE_WORDS].iter_mut().zip(w) {
                        *sum += w;
                    }
                }
            }
        }
        if let Some((geom, p)) = r.hit {
            let g = geom as usize;
            if self.layout.nearest() {
                let z = (p - setup.origin).dot(setup.forward);
                self.nearest = self.nearest.nearer(Nearest {
                    z,
                    sample: s,
                    p: p.to_array(),
                    object: geom + 1,
                    material: setup.object_material[g] + 1,
                });
            }
            if self.layout.passes.contains(Pass::CryptoObject) {
                add_counts(&mut self.objects, &[(setup.object_name[g], 1)]);
            }
            if self.layout.passes.contains(Pass::CryptoMaterial) {
                add_counts(&mut self.materials, &[(setup.object_material[g], 1)]);
            }
        }
    }

    fn end_pixel(&mut self, i: usize) {
        let st = self.layout.stride;
        self.out.sums[i * st..(i + 1) * st].copy_from_slice(&self.sums);
        if let Some(n) = self.out.nearest.get_mut(i) {
            *n = self.nearest;
        }
        if let Some(o) = self.out.objects.get_mut(i) {
            o.clone_from(&self.objects);
        }
        if let Some(m) = self.out.materials.get_mut(i) {
            m.clone_from(&self.materials);
        }
    }
}

/// The layers and coverage of a region of `width` × `height` pixels from
/// the final sums: `at(x, y)` is pixel (x, y)'s index in `aov` and its
/// beauty sums; `n` the samples per pixel.
pub fn layers<'b>(
    layout: &Layout,
    aov: &AovSums,
    width: u32,
    height: u32,
    n: u64,
    at: impl Fn(u32, u32) -> (usize, &'b [i128]),
) -> Result<(Vec<Layer>, Vec<Coverage>), Error> {
    const F: FixedPoint = FixedPoint::RADIANCE;
    let pixels = width as usize * height as usize;
    let mut layers = Vec::with_capacity(layout.slots.len());
    for slot in &layout.slots {
        let len = pixels.saturating_mul(slot.channels.len());
        let mut values = Vec::new();
        values.try_reserve_exact(len).map_err(|_| {
            let bytes = len.saturating_mul(std::mem::size_of::<f32>());
            out_of_memory(&format!("the {} pass", slot.name), bytes)
        })?;
        layers.push(Layer {
            name: slot.name.clone(),
            channels: slot.channels.iter().map(|c| c.to_string()).collect(),
            kind: slot.kind,
            values,
        });
    }
    let coverage_of = |p: Pass, kind: &str, names: &[String]| {
        layout.passes.contains(p).then(|| Coverage {
            kind: kind.to_string(),
            names: names.to_vec(),
            pixels: Vec::with_capacity(pixels),
        })
    };
    let mut objects = coverage_of(Pass::CryptoObject, "object", &layout.object_names);
    let mut materials = coverage_of(Pass::CryptoMaterial, "material", &layout.material_names);
    let st = layout.stride;
    for y in 0..height {
        for x in 0..width {
            let (i, beauty) = at(x, y);
            let sums = &aov.sums[i * st..(i + 1) * st];
            let near = aov.nearest.get(i).copied().unwrap_or(Nearest::NONE);
            for (layer, slot) in layers.iter_mut().zip(&layout.slots) {
                let o = slot.offset;
                let mean = |k: usize| F.mean(sums[o + k], n);
                let v: [f32; 3] = match slot.pass {
                    Pass::Position => near.p,
                    Pass::Depth => [near.z, 0.0, 0.0],
                    Pass::ObjectId => [near.object as f32, 0.0, 0.0],
                    Pass::MaterialId => [near.material as f32, 0.0, 0.0],
                    Pass::SampleCount => [n as f32, 0.0, 0.0],
                    Pass::Variance => std::array::from_fn(|c| {
                        let w = o + c * SQUARE_WORDS;
                        variance(beauty[c], &sums[w..w + SQUARE_WORDS], n)
                    }),
                    _ => [mean(0), mean(1), mean(2)],
                };
                layer.values.extend_from_slice(&v[..slot.channels.len()]);
            }
            let fractions = |counts: &[(u32, u32)]| {
                counts
                    .iter()
                    .map(|&(id, c)| (id, (c as f64 / n.max(1) as f64) as f32))
                    .collect::<Vec<_>>()
            };
            if let Some(cov) = &mut objects {
                cov.pixels.push(fractions(&aov.objects[i]));
            }
            if let Some(cov) = &mut materials {
                cov.pixels.push(fractions(&aov.materials[i]));
            }
        }
    }
    Ok((layers, objects.into_iter().chain(materials).collect()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A render pays per pixel only for the stores its passes read: the
    /// nearest hit for P, Z and the IDs, the coverage lists for the
    /// Cryptomatte passes, the sums for the summed layers; a beauty-only
    /// render keeps none of them.
    #[test]
    fn each_pixel_store_exists_only_for_the_passes_that_read_it() {
        use crate::film::passes::ALL;
        let names = [String::from("a")];
        let pixels = 16;
        let sums = |passes: PassSet| {
            let layout = Layout::new(passes, &names, &names, &names);
            AovSums::new(&layout, pixels).unwrap()
        };
        let none = sums(PassSet::EMPTY);
        assert_eq!(
            (none.sums.len(), none.nearest.len(), none.objects.len()),
            (0, 0, 0)
        );
        assert!(none.materials.is_empty());
        for p in ALL {
            let one = sums([p].into_iter().collect());
            let nearest = matches!(
                p,
                Pass::Position | Pass::Depth | Pass::ObjectId | Pass::MaterialId
            );
            assert_eq!(one.nearest.len(), if nearest { pixels } else { 0 }, "{p:?}");
            let objects = p == Pass::CryptoObject;
            assert_eq!(one.objects.len(), if objects { pixels } else { 0 }, "{p:?}");
            let materials = p == Pass::CryptoMaterial;
            assert_eq!(
                one.materials.len(),
                if materials { pixels } else { 0 },
                "{p:?}"
            );
            let summed = LIGHT_PATHS.contains(&p)
                || matches!(
                    p,
                    Pass::LightGroups | Pass::Albedo | Pass::Normal | Pass::Variance
                );
            assert_eq!(one.sums.is_empty(), !summed, "{p:?}");
        }
    }

    /// A pass too large for memory is an error naming the pass and the
    /// size it needed (3 channels of 4 bytes for 2⁶⁰ pixels: 3·2⁴² MB),
    /// however large the image: no overflow, no abort.
    #[test]
    fn a_pass_too_large_for_memory_names_its_size() {
        let names = [String::from("a")];
        let layout = Layout::new([Pass::Albedo].into_iter().collect(), &names, &names, &names);
        let aov = AovSums::new(&layout, 0).unwrap();
        let at = |_: u32, _: u32| -> (usize, &[i128]) { unreachable!("no pixel is read") };
        let e = layers(&layout, &aov, 1 << 30, 1 << 30, 1, at).unwrap_err();
        let text = e.to_string();
        assert!(text.contains(&format!("{} MB", 3u64 << 42)), "{text}");
        assert!(text.contains(Pass::Albedo.name()), "{text}");
        let e = layers(&layout, &aov, u32::MAX, u32::MAX, 1, at).unwrap_err();
        assert!(e.to_string().contains("out of memory"), "{e}");
    }

    #[test]
    fn squares_and_the_variance_numerator_are_exact() {
        let m = u64::MAX as i128;
        for (q, w) in [
            (0i128, [0, 0, 0]),
            (-3, [9, 0, 0]),
            (1 << 95, [0, 0, 1 << 62]),
            ((1 << 64) + 1, [1, 2, 1]),
            (-((1 << 64) - 1), [1, m - 1, 0]),
        ] {
            assert_eq!(square_words(q), w, "{q}");
        }
        // equal samples: exactly zero variance, at any magnitude
        for x in [1.0f32, 0.1, 3.0e9, 1e-30] {
            let q = FixedPoint::RADIANCE.to_fixed(x).0;
            let n = 37u64;
            let sq: Vec<i128> = square_words(q).iter().map(|w| w * n as i128).collect();
            assert_eq!(variance(q * n as i128, &sq, n), 0.0, "{x}");
        }
        // 0 and 1, n = 2: mean 1/2, s² = 1/2, s²/n = 1/4
        let q = FixedPoint::RADIANCE.to_fixed(1.0).0;
        assert_eq!(variance(q, &square_words(q), 2), 0.25);
        // against f64 on small integers: 1, 2, 3, 4 → s² = 5/3, /4
        let mut s1 = 0;
        let mut sq = [0i128; 3];
        for x in [1.0f32, 2.0, 3.0, 4.0] {
            let q = FixedPoint::RADIANCE.to_fixed(x).0;
            s1 += q;
            for (a, b) in sq.iter_mut().zip(square_words(q)) {
                *a += b;
            }
        }
        assert_eq!(variance(s1, &sq, 4), (5.0f64 / 3.0 / 4.0) as f32);
        assert_eq!(variance(s1, &sq, 1), f32::INFINITY);
        // against f64 on fractional samples, whose squares fill every limb,
        // so n·Σq² − (Σq)² borrows across limbs: a borrow dropped between
        // the second and third limb is an error of 1/(n²(n − 1)) in the
        // result, far above f32 rounding
        let mut rng = crate::sampling::Rng::from_key(7);
        for n in [2u64, 3, 5, 16] {
            for _ in 0..20 {
                let xs: Vec<f32> = (0..n).map(|_| rng.uniform_f64() as f32).collect();
                let (mut s1, mut sq) = (0i128, [0i128; 3]);
                for &x in &xs {
                    let q = FixedPoint::RADIANCE.to_fixed(x).0;
                    s1 += q;
                    for (a, b) in sq.iter_mut().zip(square_words(q)) {
                        *a += b;
                    }
                }
                let nf = n as f64;
                let mean = xs.iter().map(|&x| x as f64).sum::<f64>() / nf;
                let s2 = xs.iter().map(|&x| (x as f64 - mean).powi(2)).sum::<f64>() / (nf - 1.0);
                let want = s2 / nf;
                let got = variance(s1, &sq, n) as f64;
                assert!(
                    (got - want).abs() <= 1e-6 * want + 1e-12,
                    "n = {n}, {xs:?}: {got} against {want}"
                );
            }
        }
    }

    #[test]
    fn the_nearest_hit_does_not_depend_on_order() {
        let hit = |z: f32, s: u32| Nearest {
            z,
            sample: s,
            p: [z, 0.0, 0.0],
            object: s + 1,
            material: 1,
        };
        let hits = [hit(2.0, 0), hit(1.0, 3), hit(1.0, 1), hit(5.0, 2)];
        let fwd = hits.iter().fold(Nearest::NONE, |a, &b| a.nearer(b));
        let rev = hits.iter().rev().fold(Nearest::NONE, |a, &b| a.nearer(b));
        assert_eq!(fwd, hit(1.0, 1));
        assert_eq!(rev, fwd);
        assert_eq!(Nearest::NONE.nearer(Nearest::NONE), Nearest::NONE);
    }

    #[test]
    fn counts_add_sorted() {
        let mut a = vec![(1, 2), (5, 1)];
        add_counts(&mut a, &[(0, 1), (5, 3), (7, 1)]).unwrap();
        assert_eq!(a, [(0, 1), (1, 2), (5, 4), (7, 1)]);
    }
}
