//! The exact per-pixel sums of a region of the frame over a range of
//! sample indices: the beauty's, in the fixed point of
//! [`super::accumulate`], and the passes' ([`super::pass_sums`]), both in
//! one tile-major pixel order; the image and the pass layers are made from
//! them once the samples are summed (docs/farm.md, "Why the merge is
//! exact").

use super::accumulate::FixedPoint;
use super::layers::{Coverage, Layer};
use super::out_of_memory;
use super::pass_layout::Layout;
use super::pass_sums::{self, AovSums, Passes};
use super::region::Region;
use super::Film;
use crate::error::Error;
use crate::geometry::Vec3;
use crate::stats::Counters;

/// The side of the square tiles a render works in, and in which
/// [`Sums::index`] orders the pixels.
pub const TILE: u32 = 16;

/// The exact per-pixel sums of a region's samples `start..done`: beauty
/// RGB, [`Sums::CHANNELS`] values a pixel in the format
/// [`Sums::FORMAT`], stored tile by tile, and the passes' sums in
/// the same pixel order.
#[derive(Clone, Debug, PartialEq)]
pub struct Sums {
    pub region: Region,
    /// The first sample index summed.
    pub start: u32,
    /// One past the last sample index summed (`start` when none is).
    pub done: u32,
    /// Tallies of the summed samples.
    pub counters: Counters,
    sums: Vec<i128>,
    /// The passes, when any is summed.
    pub passes: Option<Passes>,
}

impl Sums {
    /// Channels a pixel: R, G, B.
    pub const CHANNELS: usize = 3;
    /// Their fixed-point format.
    pub const FORMAT: FixedPoint = FixedPoint::RADIANCE;

    /// Zero sums over `region`, no sample yet (from `start`); fails with a
    /// runtime error, not an abort, when the memory is not there.
    pub fn new(region: Region, start: u32) -> Result<Sums, Error> {
        Self::with_passes(region, start, None)
    }

    /// [`new`](Self::new), with zero sums for the passes of `layout` too.
    pub(crate) fn with_passes(
        region: Region,
        start: u32,
        layout: Option<&Layout>,
    ) -> Result<Sums, Error> {
        let n = region.area() as usize * Self::CHANNELS;
        let mut sums = Vec::new();
        sums.try_reserve_exact(n).map_err(|_| {
            out_of_memory(
                &format!(
                    "the sums of a {}×{} region",
                    region.width(),
                    region.height()
                ),
                n.saturating_mul(16),
            )
        })?;
        sums.resize(n, 0);
        Ok(Sums {
            region,
            start,
            done: start,
            counters: Counters::default(),
            sums,
            passes: match layout {
                Some(l) => Some(Passes {
                    layout: l.clone(),
                    sums: AovSums::new(l, region.area() as usize)?,
                }),
                None => None,
            },
        })
    }

    /// Samples summed in each pixel.
    pub fn count(&self) -> u32 {
        self.done - self.start
    }

    /// Pixel (x, y)'s index in the sums (tile-major layout: the tiles of
    /// `tiles` in order, each row-major); its beauty sums start at
    /// index · [`CHANNELS`](Self::CHANNELS).
    pub fn index(&self, x: u32, y: u32) -> usize {
        let r = &self.region;
        let (lx, ly) = (x - r.x0, y - r.y0);
        let (tx, ty) = (lx / TILE * TILE, ly / TILE * TILE);
        // full rows of tiles above, then full tiles to the left in this row
        let above = ty as usize * r.width() as usize;
        let th = TILE.min(r.height() - ty) as usize;
        let left = tx as usize * th;
        let tw = TILE.min(r.width() - tx) as usize;
        above + left + (ly - ty) as usize * tw + (lx - tx) as usize
    }

    /// Every pixel's beauty sums, in [`index`](Self::index) order.
    pub fn beauty(&self) -> &[i128] {
        &self.sums
    }

    /// The beauty's and the passes' sums, to set.
    pub(crate) fn sums_mut(&mut self) -> (&mut [i128], Option<&mut Passes>) {
        (&mut self.sums, self.passes.as_mut())
    }

    /// Exchanges the beauty's and the passes' sums with `o`'s (region,
    /// samples and counters stay).
    pub(crate) fn swap_sums(&mut self, o: &mut Sums) {
        std::mem::swap(&mut self.sums, &mut o.sums);
        std::mem::swap(&mut self.passes, &mut o.passes);
    }

    /// Pixel (x, y)'s sums (frame coordinates, inside the region).
    pub fn pixel(&self, x: u32, y: u32) -> &[i128] {
        let o = self.index(x, y) * Self::CHANNELS;
        &self.sums[o..o + Self::CHANNELS]
    }

    /// The beauty sums of the pixel of index `i` ([`index`](Self::index)).
    pub(crate) fn pixel_at(&self, i: usize) -> &[i128] {
        &self.sums[i * Self::CHANNELS..(i + 1) * Self::CHANNELS]
    }

    /// [`pixel_at`](Self::pixel_at), to set.
    pub(crate) fn pixel_at_mut(&mut self, i: usize) -> &mut [i128] {
        &mut self.sums[i * Self::CHANNELS..(i + 1) * Self::CHANNELS]
    }

    /// Pixel (x, y)'s sums, to set (merging, reading a part back).
    pub(crate) fn pixel_mut(&mut self, x: u32, y: u32) -> &mut [i128] {
        let o = self.index(x, y) * Self::CHANNELS;
        &mut self.sums[o..o + Self::CHANNELS]
    }

    /// The region's image: each pixel the mean of its [`count`](Self::count)
    /// samples ([`FixedPoint::mean`]).
    pub fn film(&self) -> Result<Film, Error> {
        let r = self.region;
        let mut film = Film::try_new(r.width(), r.height())?;
        let n = self.count() as u64;
        for y in r.y0..r.y1 {
            for x in r.x0..r.x1 {
                let s = self.pixel(x, y);
                let m = |c: usize| Self::FORMAT.mean(s[c], n);
                film.set(x - r.x0, y - r.y0, Vec3::new(m(0), m(1), m(2)));
            }
        }
        Ok(film)
    }

    /// The region's passes (layers in output order, and ID coverage) from
    /// their sums and the [`count`](Self::count): none without passes.
    /// With `alpha` (a transparent film, whose passes keep the object
    /// coverage), a layer `A` too: the fraction of samples whose camera
    /// ray hit, which the light groups' `A` repeat.
    pub fn layers(&self, alpha: bool) -> Result<(Vec<Layer>, Vec<Coverage>), Error> {
        let Some(p) = &self.passes else {
            return Ok((Vec::new(), Vec::new()));
        };
        let r = self.region;
        pass_sums::layers(
            &p.layout,
            &p.sums,
            r.width(),
            r.height(),
            self.count() as u64,
            alpha,
            |x, y| {
                let (x, y) = (x + r.x0, y + r.y0);
                (self.index(x, y), self.pixel(x, y))
            },
        )
    }
}
