//! The values a part's pixels may hold: what a render of its header could
//! have summed (docs/farm.md, "Parts as untrusted input"). A part's pixels
//! are checked as they are read, and a value no render makes is bad input
//! naming the file, the channel (`layer.channel`) and the pixel.
//!
//! - A sum of `n` samples: every term is at most 2^95 in magnitude
//!   ([`crate::film::accumulate`]), so |sum| ≤ n · 2^95 (0 for n = 0).
//! - The nearest hit: none ([`Nearest::NONE`]), or a finite depth ≥ 0 and
//!   position, one of the part's sample indices, and object and material
//!   numbers (index + 1) within the scene's names (when the passes name
//!   them: a number no pass names is never shown).
//! - ID coverage: each ID within the names, and at most `n` samples in all
//!   (one ID a sample).

use crate::film::pass_layout::Layout;
use crate::film::pass_sums::Nearest;
use crate::film::region::Region;

use super::header::Header;
use crate::film::accumulate::TERM_BITS;

/// Where pixel `j` of a part's channels is, and the bounds its values keep.
pub(crate) struct PixelAt<'a> {
    region: Region,
    samples: &'a std::ops::Range<u32>,
    objects: usize,
    materials: usize,
}

impl<'a> PixelAt<'a> {
    pub fn new(header: &'a Header, layout: Option<&Layout>) -> PixelAt<'a> {
        PixelAt {
            region: header.region,
            samples: &header.samples,
            objects: layout.map_or(0, |l| l.object_names.len()),
            materials: layout.map_or(0, |l| l.material_names.len()),
        }
    }

    /// Pixel `j` (row by row in the region), for messages.
    pub fn pixel(&self, j: usize) -> String {
        let w = self.region.width() as usize;
        let (x, y) = (
            self.region.x0 as usize + j % w,
            self.region.y0 as usize + j / w,
        );
        format!("pixel ({x}, {y})")
    }

    /// Samples summed.
    fn n(&self) -> u128 {
        self.samples.len() as u128
    }

    /// That `v` is a sum of the part's samples.
    pub fn check_sum(&self, v: i128, j: usize) -> Result<(), Unmade> {
        if v.unsigned_abs() <= self.n() << TERM_BITS {
            return Ok(());
        }
        Err(Unmade::Sum {
            pixel: self.pixel(j),
            sum: v,
            samples: self.n(),
        })
    }

    /// The channel (`depth`, `sample`, …) at fault in nearest hit `h` of
    /// pixel `j`, and the problem; `(None, _)`: none is.
    pub fn check_nearest(&self, h: &Nearest, j: usize) -> (Option<&'static str>, String) {
        if h.z == f32::INFINITY && *h == Nearest::NONE {
            return (None, String::new());
        }
        let fault = if !(h.z.is_finite() && h.z >= 0.0) {
            Some(("depth", format!("depth {}", h.z)))
        } else if !self.samples.contains(&h.sample) {
            Some(("sample", format!("sample {}", h.sample)))
        } else if !h.p.iter().all(|c| c.is_finite()) {
            Some(("px", format!("position {:?}", h.p)))
        } else if self.objects > 0 && h.object as usize > self.objects {
            Some(("object", format!("object number {}", h.object)))
        } else if self.materials > 0 && h.material as usize > self.materials {
            Some(("material", format!("material number {}", h.material)))
        } else {
            None
        };
        match fault {
            Some((channel, what)) => (
                Some(channel),
                format!(
                    "{}: {what} is not a hit of samples {}..{} in a scene of {} objects \
                     and {} materials",
                    self.pixel(j),
                    self.samples.start,
                    self.samples.end,
                    self.objects,
                    self.materials
                ),
            ),
            None => (None, String::new()),
        }
    }

    /// That `total` samples covering pixel `j` is at most its samples.
    pub fn check_coverage(&self, total: u64, j: usize) -> Result<(), Unmade> {
        if total as u128 <= self.n() {
            return Ok(());
        }
        Err(Unmade::Coverage {
            pixel: self.pixel(j),
            total,
            samples: self.n(),
        })
    }
}

/// A value of a pixel that no render of the part's header makes.
#[derive(Debug, thiserror::Error)]
pub(crate) enum Unmade {
    /// A sum beyond what the part's samples can add up to.
    #[error(
        "{pixel}: sum {sum} is beyond what {samples} samples can add up to \
         (each at most 2^{TERM_BITS})"
    )]
    Sum {
        pixel: String,
        sum: i128,
        samples: u128,
    },
    /// IDs covering more samples than the part has.
    #[error("{pixel}: IDs cover {total} samples of {samples} (coverage above 1)")]
    Coverage {
        pixel: String,
        total: u64,
        samples: u128,
    },
}
