//! Whether a set of parts covers a frame's pixels and sample indices
//! exactly once.
//!
//! Each part is a box in (x, y, sample index): its region times its sample
//! range. The boxes cover the frame box `[0, W) × [0, H) × [0, spp)`
//! exactly once iff (1) every box lies inside it, (2) no two boxes
//! intersect, and (3) their volumes add up to its volume — disjoint boxes
//! inside the frame whose volumes fill it leave no gap. (2) is checked
//! pairwise, O(P²) for P parts (a million comparisons for a thousand
//! parts). When (3) fails, a gap is located for the message: the sample
//! boundaries of all parts cut the sample axis into slabs; in the first
//! slab whose boxes' areas fall short, the x and y boundaries of those
//! boxes cut the frame into cells, and the first cell no box covers is
//! named.

use std::ops::Range;

use crate::film::region::Region;

/// A part as a box: its region and sample range.
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    pub region: Region,
    pub samples: Range<u32>,
}

/// How a set of pieces fails to cover the frame exactly once.
#[derive(Clone, Debug, PartialEq)]
pub enum CoverError {
    /// Piece `i` reaches outside the frame or the sample range.
    Outside(usize),
    /// Pieces `a` and `b` both cover these pixels and samples.
    Overlap {
        a: usize,
        b: usize,
        region: Region,
        samples: Range<u32>,
    },
    /// No piece covers these pixels and samples.
    Gap { region: Region, samples: Range<u32> },
}

fn overlap(a: &Range<u32>, b: &Range<u32>) -> Option<Range<u32>> {
    let r = a.start.max(b.start)..a.end.min(b.end);
    (!r.is_empty()).then_some(r)
}

/// Checks that `pieces` cover `frame` × `0..spp` exactly once.
pub fn check(pieces: &[Piece], frame: Region, spp: u32) -> Result<(), CoverError> {
    for (i, p) in pieces.iter().enumerate() {
        if p.region.is_empty()
            || !p.region.within(&frame)
            || p.samples.is_empty()
            || p.samples.end > spp
        {
            return Err(CoverError::Outside(i));
        }
    }
    for (a, pa) in pieces.iter().enumerate() {
        for (b, pb) in pieces.iter().enumerate().skip(a + 1) {
            if let (Some(region), Some(samples)) = (
                pa.region.intersection(&pb.region),
                overlap(&pa.samples, &pb.samples),
            ) {
                return Err(CoverError::Overlap {
                    a,
                    b,
                    region,
                    samples,
                });
            }
        }
    }
    let volume: u128 = pieces
        .iter()
        .map(|p| p.region.area() as u128 * p.samples.len() as u128)
        .sum();
    if volume == frame.area() as u128 * spp as u128 {
        return Ok(());
    }
    Err(find_gap(pieces, frame, spp))
}

/// A gap in disjoint pieces that do not fill the frame (see the module
/// docs).
fn find_gap(pieces: &[Piece], frame: Region, spp: u32) -> CoverError {
    let mut cuts: Vec<u32> = pieces
        .iter()
        .flat_map(|p| [p.samples.start, p.samples.end])
        .chain([0, spp])
        .collect();
    cuts.sort_unstable();
    cuts.dedup();
    for slab in cuts.windows(2) {
        let samples = slab[0]..slab[1];
        let here: Vec<&Region> = pieces
            .iter()
            .filter(|p| p.samples.start <= samples.start && samples.end <= p.samples.end)
            .map(|p| &p.region)
            .collect();
        if here.iter().map(|r| r.area()).sum::<u64>() == frame.area() {
            continue;
        }
        let axis = |f: &dyn Fn(&Region) -> [u32; 2], whole: [u32; 2]| {
            let mut v: Vec<u32> = here.iter().flat_map(|r| f(r)).chain(whole).collect();
            v.sort_unstable();
            v.dedup();
            v
        };
        let xs = axis(&|r| [r.x0, r.x1], [frame.x0, frame.x1]);
        let ys = axis(&|r| [r.y0, r.y1], [frame.y0, frame.y1]);
        for y in ys.windows(2) {
            for x in xs.windows(2) {
                let cell = Region {
                    x0: x[0],
                    y0: y[0],
                    x1: x[1],
                    y1: y[1],
                };
                if !here.iter().any(|r| cell.within(r)) {
                    return CoverError::Gap {
                        region: cell,
                        samples,
                    };
                }
            }
        }
    }
    unreachable!("disjoint pieces whose volume falls short leave a gap")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(r: &str, s: Range<u32>) -> Piece {
        Piece {
            region: Region::parse(r).unwrap(),
            samples: s,
        }
    }

    #[test]
    fn exact_covers_pass_and_every_flaw_is_named() {
        let frame = Region::full(10, 6);
        let good = vec![
            p("0,0,10,3", 0..8),
            p("0,3,4,6", 0..8),
            p("4,3,10,6", 0..5),
            p("4,3,10,6", 5..8),
        ];
        assert_eq!(check(&good, frame, 8), Ok(()));
        // a missing piece: the gap is its box
        let mut gap = good.clone();
        gap.remove(2);
        assert_eq!(
            check(&gap, frame, 8),
            Err(CoverError::Gap {
                region: Region::parse("4,3,10,6").unwrap(),
                samples: 0..5
            })
        );
        // a piece one sample short
        let mut short = good.clone();
        short[3].samples = 5..7;
        assert_eq!(
            check(&short, frame, 8),
            Err(CoverError::Gap {
                region: Region::parse("4,3,10,6").unwrap(),
                samples: 7..8
            })
        );
        // an overlap in pixels and samples, named by both pieces
        let mut over = good.clone();
        over[2].samples = 0..6;
        assert_eq!(
            check(&over, frame, 8),
            Err(CoverError::Overlap {
                a: 2,
                b: 3,
                region: Region::parse("4,3,10,6").unwrap(),
                samples: 5..6
            })
        );
        // the same region twice with overlapping samples, plus extra volume
        let mut twice = good.clone();
        twice.push(p("0,0,1,1", 7..8));
        assert!(matches!(
            check(&twice, frame, 8),
            Err(CoverError::Overlap { a: 0, b: 4, .. })
        ));
        // outside the frame or the sample range
        let mut out = good.clone();
        out[0].samples = 0..9;
        assert_eq!(check(&out, frame, 8), Err(CoverError::Outside(0)));
        out[0] = p("0,0,11,3", 0..8);
        assert_eq!(check(&out, frame, 8), Err(CoverError::Outside(0)));
        // a gap in the middle of a region's pixels
        let holes = vec![
            p("0,0,10,2", 0..8),
            p("0,2,3,4", 0..8),
            p("5,2,10,4", 0..8),
            p("0,4,10,6", 0..8),
        ];
        assert_eq!(
            check(&holes, frame, 8),
            Err(CoverError::Gap {
                region: Region::parse("3,2,5,4").unwrap(),
                samples: 0..8
            })
        );
        assert!(matches!(check(&[], frame, 8), Err(CoverError::Gap { .. })));
    }
}
