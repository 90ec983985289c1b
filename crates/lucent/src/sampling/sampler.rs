//! Which sampler a render draws its samples from (`[render] sampler`,
//! `--sampler`), and which dimensions of the low-discrepancy sequence each
//! part of a path takes (docs/accuracy.md, "Low-discrepancy sampling").
//!
//! A sample's draws are 2D points, "slots": the camera's first, then a
//! fixed block per bounce, so a bounce that draws more or less does not
//! move the next bounce's points. Each slot is its own Owen-scrambled
//! Sobol' (0,2)-sequence ([`super::sobol`]) over the pixel's samples;
//! draws past a bounce's block, past the first bounces, and of paths that
//! a coat split off come from the sample's pseudo-random stream.

use super::mix::slot_key;
use super::sobol::{self, Point4Seeds, PointSeeds};

/// Where a render's random numbers come from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum SamplerKind {
    /// Owen-scrambled Sobol' points for the camera and the first bounces.
    #[default]
    Sobol,
    /// Every draw from the sample's counter-based pseudo-random stream.
    Random,
}

impl SamplerKind {
    /// Every sampler, the default first.
    pub const ALL: [SamplerKind; 2] = [SamplerKind::Sobol, SamplerKind::Random];

    /// The name in scene files, on the command line and in headers.
    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::Sobol => "sobol",
            SamplerKind::Random => "random",
        }
    }

    /// The sampler named `name`.
    pub fn parse(name: &str) -> Option<SamplerKind> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// One line on what it is.
    pub fn describe(self) -> &'static str {
        match self {
            SamplerKind::Sobol => {
                "Owen-scrambled Sobol' (0,2)-sequences for the camera and the first \
                 bounces, pseudo-random beyond"
            }
            SamplerKind::Random => "a counter-based pseudo-random stream for every draw",
        }
    }

    /// The names, for error messages: `"sobol" or "random"`.
    pub fn expected() -> String {
        let names: Vec<String> = Self::ALL
            .iter()
            .map(|k| format!("\"{}\"", k.name()))
            .collect();
        names.join(" or ")
    }
}

/// Slots of the camera: the position in the pixel, then the lens.
pub const CAMERA_SLOTS: u32 = 2;
/// Slots of one bounce: enough for a subsurface vertex's coat, probe,
/// light and lobe samples and Russian roulette.
pub const BOUNCE_SLOTS: u32 = 16;
/// Bounces (from the camera's hit, depth 0) that draw from the sequence.
pub const SEQUENCE_DEPTHS: u32 = 4;

/// The slots one sample has left: the sample's index in the pixel's
/// sequence, the next slot and the end of the current block.
#[derive(Clone, Debug)]
pub(crate) struct Cursor {
    pixel_key: u64,
    index: u32,
    /// `index`'s bits reversed, for every slot's point.
    reversed: u32,
    next: u32,
    end: u32,
    /// Set once the sample follows a path split off: no slot after that.
    left: bool,
}

impl Cursor {
    /// Sample `index` of the pixel keyed `pixel_key`, at the camera's slots.
    #[inline]
    pub(crate) fn new(pixel_key: u64, index: u32) -> Self {
        Cursor {
            pixel_key,
            index,
            reversed: index.reverse_bits(),
            next: 0,
            end: CAMERA_SLOTS,
            left: false,
        }
    }

    /// Moves to the block of bounce `depth` (none past the sequence's depths).
    #[inline]
    pub(crate) fn start_bounce(&mut self, depth: u32) {
        if self.left || depth >= SEQUENCE_DEPTHS {
            self.end = 0;
            return;
        }
        self.next = CAMERA_SLOTS + depth * BOUNCE_SLOTS;
        self.end = self.next + BOUNCE_SLOTS;
    }

    /// No more slots for this sample.
    #[inline]
    pub(crate) fn leave(&mut self) {
        self.left = true;
        self.end = 0;
    }

    /// The next slot, if the block has one.
    #[inline]
    fn next_slot(&mut self) -> Option<u32> {
        if self.next >= self.end {
            return None;
        }
        self.next += 1;
        Some(self.next - 1)
    }

    /// The next slot's 4D point (the first four Sobol' dimensions), if
    /// the block has one.
    #[inline]
    pub(crate) fn take4(&mut self) -> Option<([u32; 4], Point)> {
        let slot = self.next_slot()?;
        let h = slot_key(self.pixel_key, slot);
        let h2 = slot_key(h, 0);
        let h3 = slot_key(h, 2);
        let seeds = Point4Seeds {
            shuffle: h as u32,
            dims: [(h >> 32) as u32, h2 as u32, (h2 >> 32) as u32, h3 as u32],
        };
        let p = sobol::point4(self.index, seeds);
        let first = Point {
            xy: [p[0], p[1]],
            tail: h3 ^ self.index as u64,
        };
        Some((p, first))
    }

    /// The next slot's point, if the block has one.
    #[inline]
    pub(crate) fn take(&mut self) -> Option<Point> {
        let slot = self.next_slot()?;
        let h = slot_key(self.pixel_key, slot);
        let xy = sobol::point_of_reversed(self.reversed, PointSeeds::from_hash(h));
        Some(Point {
            xy,
            tail: h ^ self.index as u64,
        })
    }
}

/// One slot's 2D point as 32-bit fractions, and bits to extend its first
/// coordinate to 53.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Point {
    pub xy: [u32; 2],
    tail: u64,
}

impl Point {
    #[inline]
    pub(crate) fn f32s(self) -> [f32; 2] {
        self.xy.map(sobol::to_f32)
    }

    #[inline]
    pub(crate) fn f64s(self) -> [f64; 2] {
        self.xy.map(sobol::to_f64)
    }

    /// The first coordinate with 53 bits: 21 hashed ones below its 32.
    #[inline]
    pub(crate) fn x_f64_53(self) -> f64 {
        sobol::to_f64_53(self.xy[0], slot_key(self.tail, 1) >> 43)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Catches a name that does not parse back, and a default other than
    /// the sequence.
    #[test]
    fn names_parse_back() {
        for k in SamplerKind::ALL {
            assert_eq!(SamplerKind::parse(k.name()), Some(k));
            assert!(!k.describe().is_empty());
        }
        assert_eq!(SamplerKind::default(), SamplerKind::Sobol);
        assert_eq!(SamplerKind::parse("halton"), None);
        assert_eq!(SamplerKind::expected(), "\"sobol\" or \"random\"");
    }

    /// A bounce's block starts at the same slot whatever the bounce before
    /// drew; past the depths, and after leaving, no slot.
    #[test]
    fn blocks_do_not_shift() {
        let first_of = |draws_before: u32| {
            let mut c = Cursor::new(7, 3);
            c.start_bounce(0);
            for _ in 0..draws_before {
                c.take();
            }
            c.start_bounce(1);
            c.take().unwrap().xy
        };
        assert_eq!(first_of(0), first_of(5));
        let mut c = Cursor::new(7, 3);
        for _ in 0..CAMERA_SLOTS {
            assert!(c.take().is_some());
        }
        assert!(c.take().is_none());
        c.start_bounce(SEQUENCE_DEPTHS);
        assert!(c.take().is_none());
        c.start_bounce(0);
        for _ in 0..BOUNCE_SLOTS {
            assert!(c.take().is_some());
        }
        assert!(c.take().is_none());
        c.leave();
        c.start_bounce(1);
        assert!(c.take().is_none());
    }
}
