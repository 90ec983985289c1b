//! The per-pixel side of the passes, driven by the render's tile loop: a
//! [`PixelPasses`] takes each sample's recorded passes ([`SampleAovs`])
//! and adds them into the film's sums of its pixels
//! (`crate::film::pass_sums`); [`NoAov`]'s instance adds nothing.

use super::{NoAov, Recorder, SampleAovs, Setup};
use crate::film::accumulate::FixedPoint;
use crate::film::pass_layout::Layout;
use crate::film::pass_sums::{add_counts, AovView, AovViewMut, Nearest};
use crate::film::passes::{Pass, LIGHT_PATHS};
use crate::film::variance::{square_words, SQUARE_WORDS};
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
                .slots()
                .iter()
                .find(|s| s.pass == Pass::Variance)
                .map(|s| s.offset),
            rec: SampleAovs::new(setup),
            sums: vec![0; layout.stride()],
            nearest: Nearest::NONE,
            objects: Vec::new(),
            materials: Vec::new(),
        }
    }
}

impl<'a> PixelPasses for TilePasses<'a> {
    type Rec = SampleAovs<'a>;

    fn begin_pixel(&mut self, i: usize) {
        let st = self.layout.stride();
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
        for slot in self.layout.slots() {
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
        let st = self.layout.stride();
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
