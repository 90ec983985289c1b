//! Owen-scrambled Sobol' points in two dimensions (docs/accuracy.md,
//! "Low-discrepancy sampling"): the first two Sobol' dimensions, a
//! (0,2)-sequence in base 2, scrambled by hashing (Burley 2020, "Practical
//! hash-based Owen scrambling"; Laine & Karras 2011). Each 2D point the
//! renderer draws has its own seed: its own scramble of both coordinates
//! and its own shuffle of the sample index, so points of different seeds
//! are independent while the first 2^m indices of one seed stay a
//! (0,m,2)-net.

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
/// first 2^m samples stay a net). Flipping low bits by the high ones, not
/// the other way, is what decorrelates the points of different seeds: a
/// shuffle nested the other way is a scramble of the first coordinate, and
/// two points' first coordinates would share their strata.
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
    /// Three seeds from the 64-bit hash `h` and a second hash `h2`.
    #[inline]
    pub fn from_hashes(h: u64, h2: u64) -> Self {
        PointSeeds {
            shuffle: h as u32,
            x: (h >> 32) as u32,
            y: h2 as u32,
        }
    }
}

/// Sample `index` of the Owen-scrambled Sobol' (0,2)-sequence with `seeds`,
/// as two 32-bit fractions.
#[inline]
pub fn point(index: u32, seeds: PointSeeds) -> [u32; 2] {
    let i = shuffle(index, seeds.shuffle);
    // owen_scramble(first(i)) without reversing i twice
    let x = lower_triangular_hash(i, seeds.x).reverse_bits();
    [x, owen_scramble(second(i), seeds.y)]
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

    /// Catches a scramble that is not nested (a hash of all bits, or of
    /// the digits in the wrong order) and an index shuffle that leaves
    /// the first 2^m indices' block: both break the net.
    #[test]
    fn scrambled_and_shuffled_points_stay_nets() {
        for k in 0..200u64 {
            let h = crate::sampling::Rng::from_key(k).next_u64();
            let seeds = PointSeeds::from_hashes(h, h.rotate_left(17) ^ k);
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
            let seeds = PointSeeds::from_hashes(r.next_u64(), r.next_u64());
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
    /// nested from the low bits gives 0 or a half).
    #[test]
    fn points_of_different_seeds_are_decorrelated() {
        let m = 10;
        let mut r = crate::sampling::Rng::from_key(9);
        let mut worst = 0.0f64;
        for _ in 0..50 {
            let a = PointSeeds::from_hashes(r.next_u64(), r.next_u64());
            let b = PointSeeds::from_hashes(r.next_u64(), r.next_u64());
            let both = (0..1u32 << m)
                .filter(|&i| point(i, a)[0] < 1 << 31 && point(i, b)[0] < 1 << 31)
                .count();
            worst = worst.max((both as f64 / (1 << m) as f64 - 0.25).abs());
        }
        // binomial sd of the share at n = 1024 is 0.0135
        assert!(worst < 0.08, "worst share off a quarter by {worst}");
    }
}
