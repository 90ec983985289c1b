//! Per-pixel sums of the passes (AOVs), exact and order-free like the
//! beauty's (`super::accumulate`), and the layers and ID coverage made from
//! them once, from the final sums and the sample count alone ([`layers`]):
//! so the sums of disjoint tiles, sample ranges, parts or resumed runs add
//! up to one uninterrupted run's, and a merged frame's passes are bitwise
//! the uncut render's. Summed layers are fixed-point sums; P, Z and the
//! IDs are the nearest camera hit ([`Nearest`], a minimum, not a sum);
//! Cryptomatte keeps sample counts per ID. docs/farm.md, "Passes in
//! parts", tables what each pass keeps and why.

use super::accumulate::FixedPoint;
use super::layers::{Coverage, Layer};
use super::out_of_memory;
use super::pass_layout::{Layout, Slot};
use super::passes::Pass;
use super::variance::{variance, SQUARE_WORDS};
use crate::error::Error;

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
    pub(crate) const NONE: Nearest = Nearest {
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
    pub(crate) fn nearer(self, o: Nearest) -> Nearest {
        if self.object == 0 || (o.object != 0 && o.order(&self).is_lt()) {
            o
        } else {
            self
        }
    }
}

/// Adds `o`'s counts (sorted by ID) to `into` (sorted by ID), keeping it
/// sorted.
pub(crate) fn add_counts(into: &mut Vec<(u32, u32)>, o: &[(u32, u32)]) -> Option<()> {
    for &(id, c) in o {
        match into.binary_search_by_key(&id, |e| e.0) {
            Ok(i) => into[i].1 = into[i].1.checked_add(c)?,
            Err(i) => into.insert(i, (id, c)),
        }
    }
    Some(())
}

/// The passes' sums of a region's pixels (the beauty's pixel order:
/// tile-major, [`super::sums::Sums`]).
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
        let n = pixels.saturating_mul(layout.stride());
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
    pub(crate) fn views<'a>(&'a self, layout: &Layout, pixels: &[usize]) -> Vec<AovView<'a>> {
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
                let (a, b) = s.split_at(k * layout.stride());
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
    pub(crate) fn views_mut<'a>(
        &'a mut self,
        layout: &Layout,
        pixels: &[usize],
    ) -> Vec<AovViewMut<'a>> {
        let (mut s, mut n, mut o, mut m) = (
            &mut self.sums[..],
            &mut self.nearest[..],
            &mut self.objects[..],
            &mut self.materials[..],
        );
        let mut v = Vec::with_capacity(pixels.len());
        for &k in pixels {
            let take = |len: usize| if len == 0 { 0 } else { k };
            let (a, b) = std::mem::take(&mut s).split_at_mut(k * layout.stride());
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
    pub(crate) fn add_pixel(
        &mut self,
        layout: &Layout,
        i: usize,
        o: &AovSums,
        j: usize,
    ) -> Option<()> {
        let st = layout.stride();
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

/// A tile's previous sums (the fields of [`AovSums`], for its pixels).
pub struct AovView<'a> {
    pub sums: &'a [i128],
    pub nearest: &'a [Nearest],
    pub objects: &'a [Vec<(u32, u32)>],
    pub materials: &'a [Vec<(u32, u32)>],
}

/// Where a tile writes its new sums.
pub struct AovViewMut<'a> {
    pub sums: &'a mut [i128],
    pub nearest: &'a mut [Nearest],
    pub objects: &'a mut [Vec<(u32, u32)>],
    pub materials: &'a mut [Vec<(u32, u32)>],
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
    alpha: bool,
    at: impl Fn(u32, u32) -> (usize, &'b [i128]),
) -> Result<(Vec<Layer>, Vec<Coverage>), Error> {
    let pixels = width as usize * height as usize;
    let mut layers = empty_layers(layout, pixels)?;
    let alpha = alpha && !aov.objects.is_empty();
    let mut a_layer = alpha.then(|| Layer {
        name: "A".into(),
        channels: vec!["A".into()],
        kind: super::layers::LayerKind::Data,
        values: Vec::with_capacity(pixels),
    });
    let coverage_of = |p: Pass, kind: &str, names: &[String]| {
        layout.passes.contains(p).then(|| Coverage {
            kind: kind.to_string(),
            names: names.to_vec(),
            pixels: Vec::with_capacity(pixels),
        })
    };
    let mut objects = coverage_of(Pass::CryptoObject, "object", &layout.object_names);
    let mut materials = coverage_of(Pass::CryptoMaterial, "material", &layout.material_names);
    let st = layout.stride();
    for y in 0..height {
        for x in 0..width {
            let (i, beauty) = at(x, y);
            let sums = &aov.sums[i * st..(i + 1) * st];
            let near = aov.nearest.get(i).copied().unwrap_or(Nearest::NONE);
            let a = match &mut a_layer {
                Some(l) => {
                    let hits: u64 = aov.objects[i].iter().map(|&(_, c)| c as u64).sum();
                    let a = (hits as f64 / n.max(1) as f64) as f32;
                    l.values.push(a);
                    a
                }
                None => 1.0,
            };
            for (layer, slot) in layers.iter_mut().zip(layout.slots()) {
                let v = slot_value(slot, sums, beauty, near, n, a);
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
    layers.extend(a_layer);
    Ok((layers, objects.into_iter().chain(materials).collect()))
}

/// The layers of `layout`, named, with room for `pixels` pixels' values;
/// an error naming the pass that does not fit in memory.
fn empty_layers(layout: &Layout, pixels: usize) -> Result<Vec<Layer>, Error> {
    let mut layers = Vec::with_capacity(layout.slots().len());
    for slot in layout.slots() {
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
    Ok(layers)
}

/// The depth `Z` of a pixel no camera ray hit: a large finite value (as
/// Cycles writes), so filters and blurs over an edge stay finite.
pub const DEPTH_MISS: f32 = 1e10;

/// A pixel's value of the layer of `slot` (its first channels), from the
/// pixel's pass sums, its beauty sums, its nearest hit, `n` samples and
/// the frame's alpha there.
fn slot_value(
    slot: &Slot,
    sums: &[i128],
    beauty: &[i128],
    near: Nearest,
    n: u64,
    alpha: f32,
) -> [f32; 4] {
    const F: FixedPoint = FixedPoint::RADIANCE;
    let o = slot.offset;
    let mean = |k: usize| F.mean(sums[o + k], n);
    let [x, y, z] = match slot.pass {
        Pass::Position => near.p,
        Pass::Depth if near.object == 0 => [DEPTH_MISS, 0.0, 0.0],
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
    [x, y, z, alpha]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::passes::{PassSet, LIGHT_PATHS};

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
        let e = layers(&layout, &aov, 1 << 30, 1 << 30, 1, false, at).unwrap_err();
        let text = e.to_string();
        assert!(text.contains(&format!("{} MB", 3u64 << 42)), "{text}");
        assert!(text.contains(Pass::Albedo.name()), "{text}");
        let e = layers(&layout, &aov, u32::MAX, u32::MAX, 1, false, at).unwrap_err();
        assert!(e.to_string().contains("out of memory"), "{e}");
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
