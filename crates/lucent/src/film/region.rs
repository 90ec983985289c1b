//! A rectangle of the frame's pixels: what one render (or one part of a
//! split frame) covers, and the balanced split of a frame into N of them.
//!
//! Pixels are named by their frame coordinates everywhere (the random
//! streams are keyed by the frame's pixel index), so a region renders
//! exactly the pixels the whole frame would have there.

use std::fmt;

use serde::{Deserialize, Serialize};

/// The pixels `x0 ≤ x < x1`, `y0 ≤ y < y1` of a frame (half-open).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Region {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl Region {
    /// The whole `width` × `height` frame.
    pub fn full(width: u32, height: u32) -> Region {
        Region {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }
    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }
    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }
    /// Pixel count.
    pub fn area(&self) -> u64 {
        self.width() as u64 * self.height() as u64
    }
    pub fn is_empty(&self) -> bool {
        self.x0 >= self.x1 || self.y0 >= self.y1
    }
    /// Whether `self` lies inside `outer`.
    pub fn within(&self, outer: &Region) -> bool {
        self.x0 >= outer.x0 && self.y0 >= outer.y0 && self.x1 <= outer.x1 && self.y1 <= outer.y1
    }
    /// The pixels in both, if any.
    pub fn intersection(&self, o: &Region) -> Option<Region> {
        let r = Region {
            x0: self.x0.max(o.x0),
            y0: self.y0.max(o.y0),
            x1: self.x1.min(o.x1),
            y1: self.y1.min(o.y1),
        };
        (!r.is_empty()).then_some(r)
    }
    /// Region `i` (0-based) of `n` balanced horizontal bands of the
    /// `width` × `height` frame: band `i` is rows `⌊i·h/n⌋ .. ⌊(i+1)·h/n⌋`,
    /// so band heights differ by at most one row and the bands cover the
    /// frame exactly once. `None` unless `i < n ≤ height`.
    pub fn band(i: u32, n: u32, width: u32, height: u32) -> Option<Region> {
        if n == 0 || i >= n || n > height {
            return None;
        }
        let row = |k: u32| (k as u64 * height as u64 / n as u64) as u32;
        Some(Region {
            x0: 0,
            y0: row(i),
            x1: width,
            y1: row(i + 1),
        })
    }
    /// Parses `X0,Y0,X1,Y1` (the form [`Display`](fmt::Display) writes).
    pub fn parse(s: &str) -> Option<Region> {
        let v: Vec<u32> = s
            .split(',')
            .map(|p| p.trim().parse().ok())
            .collect::<Option<_>>()?;
        match v[..] {
            [x0, y0, x1, y1] => Some(Region { x0, y0, x1, y1 }),
            _ => None,
        }
    }
}

impl fmt::Display for Region {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{},{},{}", self.x0, self.y0, self.x1, self.y1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_cover_the_frame_once_and_are_balanced() {
        for (w, h) in [(7, 1), (64, 48), (33, 100)] {
            for n in 1..=h.min(17) {
                let bands: Vec<Region> =
                    (0..n).map(|i| Region::band(i, n, w, h).unwrap()).collect();
                assert_eq!(bands[0].y0, 0);
                assert_eq!(bands[n as usize - 1].y1, h);
                for p in bands.windows(2) {
                    assert_eq!(p[0].y1, p[1].y0);
                }
                let (lo, hi) = bands.iter().fold((u32::MAX, 0), |(lo, hi), b| {
                    (lo.min(b.height()), hi.max(b.height()))
                });
                assert!(lo >= 1 && hi - lo <= 1, "{w}x{h}/{n}: {lo}..{hi}");
                assert!(bands.iter().all(|b| b.x0 == 0 && b.x1 == w));
            }
        }
        assert_eq!(Region::band(3, 3, 10, 10), None);
        assert_eq!(Region::band(0, 11, 10, 10), None);
        assert_eq!(Region::band(0, 0, 10, 10), None);
    }

    #[test]
    fn parse_display_and_geometry() {
        let r = Region::parse("1, 2,5,9").unwrap();
        assert_eq!(
            r,
            Region {
                x0: 1,
                y0: 2,
                x1: 5,
                y1: 9
            }
        );
        assert_eq!(r.to_string(), "1,2,5,9");
        assert_eq!((r.width(), r.height(), r.area()), (4, 7, 28));
        for bad in ["", "1,2,3", "1,2,3,4,5", "a,2,3,4", "-1,2,3,4"] {
            assert_eq!(Region::parse(bad), None, "{bad}");
        }
        let f = Region::full(10, 10);
        assert!(r.within(&f) && !f.within(&r));
        assert_eq!(
            r.intersection(&Region::parse("4,0,10,3").unwrap()),
            Region::parse("4,2,5,3")
        );
        assert_eq!(r.intersection(&Region::parse("5,0,10,3").unwrap()), None);
        assert!(Region::parse("3,3,3,4").unwrap().is_empty());
    }
}
