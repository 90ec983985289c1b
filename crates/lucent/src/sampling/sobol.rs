//! Owen-scrambled Sobol' points in two dimensions (docs/accuracy.md,
//! "Low-discrepancy sampling"): the first two Sobol' dimensions, a
//! (0,2)-sequence in base 2, scrambled by hashing (Burley 2020, "Practical
//! hash-based Owen scrambling"; Laine & Karras 2011). Each 2D point the
//! renderer draws has its own seed: its own scramble of both coordinates
//! and its own shuffle of the sample index, so points of different seeds
//! are independent while the first 2^m indices of one seed stay a
//! (0,m,2)-net. A subsurface probe's four numbers take the first four
//! dimensions of one index, so its discrete choices and its radius and
//! angle are stratified together (the first three dimensions are a
//! (1,3)-sequence, the four a (3,4)-sequence; Joe & Kuo 2008's direction
//! numbers).

/// Direction numbers of the second Sobol' dimension (primitive polynomial
/// x + 1): column k of its generator matrix is row k of Pascal's triangle
/// mod 2, v_k = v_{k−1} ⊕ (v_{k−1} >> 1) from v_0 = 2^31.
const SECOND: [u32; 32] = {
    let mut v = [0u32; 32];
    v[0] = 1 << 31;
    let mut k = 1;
    while k < 32 {
        v[k] = v[k - 1] ^ (v[k - 1] >> 1);
        k += 1;
    }
    v
};

/// Direction numbers of a Sobol' dimension of primitive polynomial degree
/// `s` with coefficients `a` (Joe & Kuo's encoding, highest inner
/// coefficient first) and initial numbers `m`.
const fn directions(s: usize, a: u32, m: [u32; 3]) -> [u32; 32] {
    let mut v = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        v[k] = if k < s {
            m[k] << (31 - k)
        } else {
            let mut x = v[k - s] ^ (v[k - s] >> s);
            let mut j = 1;
            while j < s {
                if (a >> (s - 1 - j)) & 1 == 1 {
                    x ^= v[k - j];
                }
                j += 1;
            }
            x
        };
        k += 1;
    }
    v
}

/// The third and fourth Sobol' dimensions: x² + x + 1 with m = 1, 3, and
/// x³ + x + 1 with m = 1, 3, 1.
const THIRD: [u32; 32] = directions(2, 1, [1, 3, 0]);
const FOURTH: [u32; 32] = directions(3, 1, [1, 3, 1]);

/// A dimension's generator matrix by bytes of the index: four lookups.
const fn byte_tables(dirs: &[u32; 32]) -> [[u32; 256]; 4] {
    let mut t = [[0u32; 256]; 4];
    let mut b = 0;
    while b < 4 {
        let mut v = 0;
        while v < 256 {
            let mut x = 0u32;
            let mut j = 0;
            while j < 8 {
                if v >> j & 1 == 1 {
                    x ^= dirs[8 * b + j];
                }
                j += 1;
            }
            t[b][v] = x;
            v += 1;
        }
        b += 1;
    }
    t
}

static THIRD_BYTES: [[u32; 256]; 4] = byte_tables(&THIRD);
static FOURTH_BYTES: [[u32; 256]; 4] = byte_tables(&FOURTH);

#[inline]
fn by_bytes(t: &[[u32; 256]; 4], i: u32) -> u32 {
    let [b0, b1, b2, b3] = i.to_le_bytes();
    t[0][b0 as usize] ^ t[1][b1 as usize] ^ t[2][b2 as usize] ^ t[3][b3 as usize]
}

/// The first Sobol' dimension (van der Corput in base 2) of `index`, as a
/// 32-bit fraction.
#[inline]
pub fn first(index: u32) -> u32 {
    index.reverse_bits()
}

/// The second Sobol' dimension of `index`, as a 32-bit fraction.
#[inline]
pub fn second(mut index: u32) -> u32 {
    let mut x = 0;
    while index != 0 {
        x ^= SECOND[index.trailing_zeros() as usize];
        index &= index - 1;
    }
    x
}

/// Direction numbers that act on the bit-reversed index and give the
/// bit-reversed fraction: column k is `dirs[31 − k].reverse_bits()`.
const fn reversed_directions(dirs: &[u32; 32]) -> [u32; 32] {
    let mut r = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        r[k] = dirs[31 - k].reverse_bits();
        k += 1;
    }
    r
}

/// The second dimension bit-reversed, by bytes of the bit-reversed index.
static REVERSED_SECOND: [[u32; 256]; 4] = byte_tables(&reversed_directions(&SECOND));

/// `second(i).reverse_bits()` from `reversed = i.reverse_bits()`.
#[inline]
fn second_reversed(reversed: u32) -> u32 {
    by_bytes(&REVERSED_SECOND, reversed)
}

/// A bijection of 32-bit words whose output bit k is input bit k flipped
/// by a function of the input bits below k (and the seed): additions,
/// odd multiplications and `x ^= x·even` all have that form. Applied to
/// bit-reversed fractions it flips each binary digit by a hash of the
/// digits before it: Owen's nested uniform scrambling.
#[inline]
fn lower_triangular_hash(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 15) | 1);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x = x.wrapping_add(seed.rotate_left(11));
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// Owen's nested uniform scramble of the 32-bit fraction `x` under `seed`:
/// every digit flipped by a hash of the digits above it, so an
/// elementary interval's points stay in one elementary interval of the
/// same shape, and every value is uniform over the seeds.
#[inline]
pub fn owen_scramble(x: u32, seed: u32) -> u32 {
    lower_triangular_hash(x.reverse_bits(), seed).reverse_bits()
}

/// The shuffled index: a nested uniform scramble of `index` read as a
/// fraction, so each low bit is flipped by a hash of the bits above it and
/// every aligned block of 2^m indices goes to an aligned block of 2^m (the
/// first 2^m samples stay a net). It also decorrelates the points of
/// different seeds: their first coordinates do not share strata.
#[inline]
pub fn shuffle(index: u32, seed: u32) -> u32 {
    owen_scramble(index, seed)
}

/// The seeds of one 2D point: the index shuffle and the two coordinates'
/// scrambles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PointSeeds {
    pub shuffle: u32,
    pub x: u32,
    pub y: u32,
}

impl PointSeeds {
    /// Three seeds from the 64-bit hash `h`: its two halves and the high
    /// half of an odd multiple.
    #[inline]
    pub fn from_hash(h: u64) -> Self {
        PointSeeds {
            shuffle: h as u32,
            x: (h >> 32) as u32,
            y: (h.wrapping_mul(0xd6e8_feb8_6659_fd93) >> 32) as u32,
        }
    }
}

/// Sample `index` of the Owen-scrambled Sobol' (0,2)-sequence with `seeds`,
/// as two 32-bit fractions: `owen_scramble` of both dimensions of
/// `shuffle(index)`, with the bit reversals that cancel left out.
#[inline]
pub fn point(index: u32, seeds: PointSeeds) -> [u32; 2] {
    point_of_reversed(index.reverse_bits(), seeds)
}

/// [`point`] of the index whose bits reversed are `reversed` (a sample
/// reverses its index once for all its points).
#[inline]
pub fn point_of_reversed(reversed: u32, seeds: PointSeeds) -> [u32; 2] {
    // the shuffled index reversed: its first dimension
    let first_dim = lower_triangular_hash(reversed, seeds.shuffle);
    let i = first_dim.reverse_bits();
    [
        lower_triangular_hash(i, seeds.x).reverse_bits(),
        lower_triangular_hash(second_reversed(first_dim), seeds.y).reverse_bits(),
    ]
}

/// The seeds of one 4D point: the index shuffle and each dimension's
/// scramble.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Point4Seeds {
    pub shuffle: u32,
    pub dims: [u32; 4],
}

/// Sample `index` of the first four Owen-scrambled Sobol' dimensions
/// with `seeds`, as 32-bit fractions (its first two are [`point`]'s).
#[inline]
pub fn point4(index: u32, seeds: Point4Seeds) -> [u32; 4] {
    let [x, y] = point(
        index,
        PointSeeds {
            shuffle: seeds.shuffle,
            x: seeds.dims[0],
            y: seeds.dims[1],
        },
    );
    let i = shuffle(index, seeds.shuffle);
    [
        x,
        y,
        owen_scramble(by_bytes(&THIRD_BYTES, i), seeds.dims[2]),
        owen_scramble(by_bytes(&FOURTH_BYTES, i), seeds.dims[3]),
    ]
}

/// A 32-bit fraction as an f32 in [0, 1): its top 24 bits.
#[inline]
pub fn to_f32(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// A 32-bit fraction as an f64 in [0, 1).
#[inline]
pub fn to_f64(x: u32) -> f64 {
    x as f64 * (1.0 / (1u64 << 32) as f64)
}

/// A 32-bit fraction extended by 21 further bits `tail` (uniform and
/// independent of it) to an f64 in [0, 1) with 53 bits.
#[inline]
pub fn to_f64_53(x: u32, tail: u64) -> f64 {
    (((x as u64) << 21) | (tail & 0x1f_ffff)) as f64 * (1.0 / (1u64 << 53) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether the 2^m points are a (0,m,2)-net: every elementary interval
    /// of area 2^−m (2^a columns × 2^(m−a) rows) holds exactly one point.
    fn is_net(points: &[[u32; 2]], m: u32) -> bool {
        (0..=m).all(|a| {
            let mut seen = vec![false; 1 << m];
            points.iter().all(|&[x, y]| {
                let col = if a == 0 { 0 } else { x >> (32 - a) };
                let row = if a == m { 0 } else { y >> (32 - (m - a)) };
                let cell = ((col << (m - a)) | row) as usize;
                !std::mem::replace(&mut seen[cell], true)
            })
        })
    }

    /// Catches wrong direction numbers of the second dimension (any other
    /// pairing of the two columns breaks some elementary interval).
    #[test]
    fn unscrambled_points_are_nets() {
        for m in 0..=12 {
            let p: Vec<[u32; 2]> = (0..1u32 << m).map(|i| [first(i), second(i)]).collect();
            assert!(is_net(&p, m), "m = {m}");
        }
        // the byte tables give the same second dimension
        let mut r = crate::sampling::Rng::from_key(1);
        for _ in 0..1000 {
            let i = r.next_u32();
            assert_eq!(second_reversed(i.reverse_bits()), second(i).reverse_bits());
        }
        // the matrix is Pascal's triangle mod 2: pinned columns
        assert_eq!(
            &SECOND[..5],
            &[
                0x8000_0000,
                0xc000_0000,
                0xa000_0000,
                0xf000_0000,
                0x8800_0000
            ]
        );
    }

    /// Whether the 2^m points are a (t,m,3)-net in their first three
    /// coordinates: every elementary box of volume 2^(t−m) holds 2^t.
    fn is_net3(points: &[[u32; 4]], m: u32, t: u32) -> bool {
        let k = m - t;
        (0..=k).all(|a| {
            (0..=k - a).all(|b| {
                let c = k - a - b;
                let mut count = vec![0u32; 1 << k];
                for p in points {
                    let cut = |v: u32, bits: u32| if bits == 0 { 0 } else { v >> (32 - bits) };
                    let cell = (cut(p[0], a) << (b + c)) | (cut(p[1], b) << c) | cut(p[2], c);
                    count[cell as usize] += 1;
                }
                count.iter().all(|&n| n == 1 << t)
            })
        })
    }

    /// The first three dimensions are a (1,m,3)-net for every m, scrambled
    /// or not, and the fourth is stratified in 1D; catches a wrong
    /// recurrence or initial numbers of the third dimension and a fourth
    /// that repeats another.
    #[test]
    fn four_dimensional_points_are_nets() {
        let seeds = Point4Seeds {
            shuffle: 0x5151_2323,
            dims: [1, 0x8000_0001, 0xdead_beef, 0x0bad_f00d],
        };
        let zero = Point4Seeds {
            shuffle: 0,
            dims: [0; 4],
        };
        for m in 1..=10 {
            for s in [seeds, zero] {
                let p: Vec<[u32; 4]> = (0..1u32 << m).map(|i| point4(i, s)).collect();
                assert!(is_net3(&p, m, 1), "m = {m}");
                let mut w: Vec<u32> = p.iter().map(|q| q[3] >> (32 - m)).collect();
                w.sort_unstable();
                assert_eq!(w, (0..1u32 << m).collect::<Vec<_>>());
                assert!(m < 3 || p.iter().any(|q| q[3] != q[2]));
            }
        }
        assert_eq!(&THIRD[..3], &[0x8000_0000, 0xc000_0000, 0x6000_0000]);
        assert_eq!(&FOURTH[..3], &[0x8000_0000, 0xc000_0000, 0x2000_0000]);
    }

    /// `point` is the scramble of both dimensions of the shuffled index.
    #[test]
    fn point_is_the_scrambled_shuffled_sobol_point() {
        let seeds = PointSeeds {
            shuffle: 0x1234_5678,
            x: 0x9abc_def0,
            y: 0x0fed_cba9,
        };
        for index in [0, 1, 2, 3, 77, 1 << 20, u32::MAX] {
            let i = shuffle(index, seeds.shuffle);
            assert_eq!(
                point(index, seeds),
                [
                    owen_scramble(first(i), seeds.x),
                    owen_scramble(second(i), seeds.y)
                ]
            );
        }
    }

    /// Catches a scramble that is not nested (a hash of all bits, or of
    /// the digits in the wrong order) and an index shuffle that leaves
    /// the first 2^m indices' block: both break the net.
    #[test]
    fn scrambled_and_shuffled_points_stay_nets() {
        for k in 0..200u64 {
            let h = crate::sampling::Rng::from_key(k).next_u64();
            let seeds = PointSeeds::from_hash(h);
            for m in [1, 4, 7, 10] {
                let p: Vec<[u32; 2]> = (0..1u32 << m).map(|i| point(i, seeds)).collect();
                assert!(is_net(&p, m), "seed {k}, m = {m}");
                // the next block of 2^m is a net as well
                let q: Vec<[u32; 2]> = (1u32 << m..2 << m).map(|i| point(i, seeds)).collect();
                assert!(is_net(&q, m), "seed {k}, second block, m = {m}");
            }
        }
    }

    /// Values in [0, 1) at the extremes, and the scramble is uniform:
    /// over many seeds one index's coordinates fill 64 bins evenly (a
    /// scramble that fixes the leading digit fails).
    #[test]
    fn values_are_in_range_and_uniform_over_seeds() {
        for x in [0, 1, u32::MAX - 1, u32::MAX] {
            assert!((0.0..1.0).contains(&to_f32(x)));
            assert!((0.0..1.0).contains(&to_f64(x)));
            assert!((0.0..1.0).contains(&to_f64_53(x, u64::MAX)));
        }
        let n = 64_000u64;
        let mut bins = [[0u32; 64]; 2];
        let mut r = crate::sampling::Rng::from_key(5);
        for _ in 0..n {
            let seeds = PointSeeds::from_hash(r.next_u64());
            let p = point(3, seeds);
            for c in 0..2 {
                bins[c][(p[c] >> 26) as usize] += 1;
            }
        }
        for b in &bins {
            let e = n as f64 / 64.0;
            let chi2: f64 = b.iter().map(|&c| (c as f64 - e).powi(2) / e).sum();
            // 63 dof: p = 1e-4 critical value ≈ 112
            assert!(chi2 < 112.0, "chi2 = {chi2}");
        }
    }

    /// The shuffle sends each aligned block of 2^m indices to an aligned
    /// block of 2^m (a hash of all bits does not).
    #[test]
    fn shuffle_maps_aligned_blocks_to_aligned_blocks() {
        for seed in [0, 1, 0xdead_beef, u32::MAX] {
            for m in [0, 3, 8] {
                for block in [0u32, 5] {
                    let mut s: Vec<u32> = (block << m..(block + 1) << m)
                        .map(|i| shuffle(i, seed))
                        .collect();
                    s.sort_unstable();
                    let start = s[0];
                    assert_eq!(start % (1 << m), 0);
                    assert_eq!(s, (start..start + (1 << m)).collect::<Vec<_>>());
                }
            }
        }
    }

    /// The first coordinates of two points of different seeds share no
    /// strata: over the first 2^m indices, the points with both first
    /// coordinates below ½ are about a quarter, not 0 or a half (a shuffle
    /// nested from the low bits fails).
    #[test]
    fn points_of_different_seeds_are_decorrelated() {
        let m = 10;
        let mut r = crate::sampling::Rng::from_key(9);
        let mut worst = 0.0f64;
        for _ in 0..50 {
            let a = PointSeeds::from_hash(r.next_u64());
            let b = PointSeeds::from_hash(r.next_u64());
            let both = (0..1u32 << m)
                .filter(|&i| point(i, a)[0] < 1 << 31 && point(i, b)[0] < 1 << 31)
                .count();
            worst = worst.max((both as f64 / (1 << m) as f64 - 0.25).abs());
        }
        // binomial sd of the share at n = 1024 is 0.0135
        assert!(worst < 0.08, "worst share off a quarter by {worst}");
    }
}
