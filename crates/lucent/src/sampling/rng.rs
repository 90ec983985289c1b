//! A counter-based random number generator keyed by (seed, pixel, sample).
//!
//! Every sample owns its own stream, derived only from its key, so the image
//! does not depend on thread count, tile order or how samples are split
//! across jobs. The stream is `hash(key, counter)` with a strong 64-bit
//! mixer (the SplitMix64 / Stafford "variant 13" finalizer, applied twice
//! with the counter folded in between), in the spirit of counter-based
//! generators (Salmon et al. 2011, "Parallel random numbers: as easy as 1, 2, 3").
//! The renderer's samples use [`SampleRng`], the same key with one mix per
//! draw, because the hashing showed in the render's profile, or with the
//! `sobol` sampler points of a low-discrepancy sequence indexed by the same
//! (seed, pixel, sample) where it has them ([`super::sampler`]).

use super::mix::mix64;
use super::sampler::{Cursor, Point, SamplerKind};
use super::sobol;

#[derive(Clone, Debug)]
pub struct Rng {
    key: u64,
    counter: u64,
}

impl Rng {
    /// The stream for one (seed, pixel, sample) triple.
    pub fn new(seed: u64, pixel: u64, sample: u64) -> Self {
        Rng::for_sample(Rng::pixel_key(Rng::seed_key(seed), pixel), sample)
    }

    /// The key is hashed level by level (seed, then pixel, then sample), so
    /// a renderer can hash the seed once per render and the pixel once per
    /// pixel: `for_sample(pixel_key(seed_key(s), p), i)` is `new(s, p, i)`.
    #[inline]
    pub fn seed_key(seed: u64) -> u64 {
        mix64(seed ^ 0x6a09_e667_f3bc_c909)
    }

    /// See [`seed_key`](Self::seed_key).
    #[inline]
    pub fn pixel_key(seed_key: u64, pixel: u64) -> u64 {
        mix64(seed_key ^ pixel.wrapping_mul(0x9e37_79b9_7f4a_7c15))
    }

    /// See [`seed_key`](Self::seed_key).
    #[inline]
    pub fn for_sample(pixel_key: u64, sample: u64) -> Self {
        Rng {
            key: mix64(pixel_key ^ sample.wrapping_mul(0xd1b5_4a32_d192_ed03)),
            counter: 0,
        }
    }

    /// A stream keyed by an arbitrary value (tests, studies, benches).
    pub fn from_key(key: u64) -> Self {
        Rng {
            key: mix64(key ^ 0x243f_6a88_85a3_08d3),
            counter: 0,
        }
    }

    #[inline]
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.counter += 1;
        mix64(mix64(self.key ^ self.counter.wrapping_mul(0x9e37_79b9_7f4a_7c15)) ^ self.key)
    }

    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        Draw::next_u32(self)
    }

    /// Uniform in [0, 1), 24 random bits, never 1.0.
    #[inline]
    pub fn uniform(&mut self) -> f32 {
        Draw::uniform(self)
    }

    /// Uniform in [0, 1), 53 random bits.
    #[inline]
    pub fn uniform_f64(&mut self) -> f64 {
        Draw::uniform_f64(self)
    }

    #[inline]
    pub fn uniform2(&mut self) -> [f32; 2] {
        Draw::uniform2(self)
    }

    /// See [`Draw::uniform2_packed`].
    #[inline]
    pub fn uniform2_packed(&mut self) -> [f32; 2] {
        Draw::uniform2_packed(self)
    }

    /// See [`Draw::uniform3`].
    #[inline]
    pub fn uniform3(&mut self) -> [f32; 3] {
        Draw::uniform3(self)
    }

    /// See [`Draw::uniform2_f64_32`].
    #[inline]
    pub fn uniform2_f64_32(&mut self) -> [f64; 2] {
        Draw::uniform2_f64_32(self)
    }
}

impl Draw for Rng {
    #[inline]
    fn next_u64(&mut self) -> u64 {
        Rng::next_u64(self)
    }
}

/// The render's per-sample stream: the key of [`Rng::new`] for the same
/// (seed, pixel, sample), but one mix per draw instead of two — SplitMix64
/// (Steele et al. 2014) started at the key: state += γ, output mix64(state).
/// The draws are a visible share of the render's instructions outside ray
/// queries (docs/performance.md, "Where the renderer's time goes"); this
/// halves their hashing. Streams of different samples are the same
/// Weyl sequence entered at hashed, effectively random, points, so they
/// overlap only if two keys fall within a path's few dozen steps of each
/// other (probability ~1e-17 per pair). [`Rng`] keeps the doubly mixed
/// stream for the mesh and ray generators, tests and studies, whose
/// outputs must not change.
#[derive(Clone, Debug)]
pub struct SampleRng {
    state: u64,
    /// The sample's slots of the low-discrepancy sequence (None: the
    /// `random` sampler, every draw from the stream).
    sequence: Option<Cursor>,
}

impl SampleRng {
    /// The stream for one (seed, pixel, sample) triple.
    pub fn new(seed: u64, pixel: u64, sample: u64) -> Self {
        SampleRng::for_sample(Rng::pixel_key(Rng::seed_key(seed), pixel), sample)
    }

    /// See [`Rng::seed_key`].
    #[inline]
    pub fn for_sample(pixel_key: u64, sample: u64) -> Self {
        SampleRng {
            state: Rng::for_sample(pixel_key, sample).key,
            sequence: None,
        }
    }

    /// Sample `sample` of the pixel keyed `pixel_key` with `sampler`: with
    /// `Random` exactly [`for_sample`](Self::for_sample); with `Sobol`
    /// its draws take the sequence's slots ([`super::sampler`]) where it
    /// has them and the same stream otherwise.
    #[inline]
    pub fn with_sampler(sampler: SamplerKind, pixel_key: u64, sample: u32) -> Self {
        let mut r = SampleRng::for_sample(pixel_key, sample as u64);
        if sampler == SamplerKind::Sobol {
            r.sequence = Some(Cursor::new(pixel_key, sample));
        }
        r
    }

    /// Whether draws come from the low-discrepancy sequence (where it has
    /// slots), so callers may lay out a 2D point's coordinates together.
    #[inline]
    pub fn stratifies(&self) -> bool {
        self.sequence.is_some()
    }

    /// The path reached bounce `depth`: the next draws take that bounce's
    /// block of slots.
    #[inline]
    pub fn start_bounce(&mut self, depth: u32) {
        if let Some(c) = &mut self.sequence {
            c.start_bounce(depth);
        }
    }

    /// The sample follows a path split off another: its draws from here
    /// on are from the stream (the slots of its depths are taken).
    #[inline]
    pub fn leave_sequence(&mut self) {
        if let Some(c) = &mut self.sequence {
            c.leave();
        }
    }

    /// Four numbers in [0, 1), the first with 53 bits: one slot's 4D
    /// point of the sequence (stratified together), or four 53-bit draws
    /// of the stream.
    #[inline]
    pub fn point4_f64(&mut self) -> [f64; 4] {
        match self.sequence.as_mut().and_then(|c| c.take4()) {
            Some((p, first)) => [
                first.x_f64_53(),
                sobol::to_f64(p[1]),
                sobol::to_f64(p[2]),
                sobol::to_f64(p[3]),
            ],
            None => std::array::from_fn(|_| self.stream().uniform_f64()),
        }
    }

    #[inline]
    fn slot(&mut self) -> Option<Point> {
        self.sequence.as_mut()?.take()
    }

    #[inline]
    fn stream(&mut self) -> Stream<'_> {
        Stream(&mut self.state)
    }
}

/// The pseudo-random stream of a [`SampleRng`] (its draws as they are
/// without the sequence).
struct Stream<'a>(&'a mut u64);

impl Draw for Stream<'_> {
    #[inline]
    fn next_u64(&mut self) -> u64 {
        *self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        mix64(*self.0)
    }
}

/// Each draw of one or two numbers takes one slot; three numbers take
/// two (a 2D point and one more, in the order the method names).
impl Draw for SampleRng {
    #[inline]
    fn next_u64(&mut self) -> u64 {
        self.stream().next_u64()
    }

    #[inline]
    fn uniform(&mut self) -> f32 {
        match self.slot() {
            Some(p) => p.f32s()[0],
            None => self.stream().uniform(),
        }
    }

    #[inline]
    fn uniform_f64(&mut self) -> f64 {
        match self.slot() {
            Some(p) => p.x_f64_53(),
            None => self.stream().uniform_f64(),
        }
    }

    #[inline]
    fn uniform2(&mut self) -> [f32; 2] {
        match self.slot() {
            Some(p) => p.f32s(),
            None => self.stream().uniform2(),
        }
    }

    #[inline]
    fn uniform2_packed(&mut self) -> [f32; 2] {
        match self.slot() {
            Some(p) => p.f32s(),
            None => self.stream().uniform2_packed(),
        }
    }

    #[inline]
    fn uniform3(&mut self) -> [f32; 3] {
        match self.slot() {
            Some(p) => {
                let [a, b] = p.f32s();
                [a, b, self.uniform()]
            }
            None => self.stream().uniform3(),
        }
    }

    #[inline]
    fn choice_and_point(&mut self) -> (f32, [f32; 2]) {
        match self.slot() {
            Some(p) => (p.f32s()[0], self.uniform2()),
            None => self.stream().choice_and_point(),
        }
    }

    #[inline]
    fn uniform2_f64_32(&mut self) -> [f64; 2] {
        match self.slot() {
            Some(p) => p.f64s(),
            None => self.stream().uniform2_f64_32(),
        }
    }
}

/// Uniform numbers from a stream of 64-bit draws, shared by [`Rng`] and
/// [`SampleRng`] (code that takes either is generic over this).
pub trait Draw {
    fn next_u64(&mut self) -> u64;

    #[inline]
    fn next_u32(&mut self) -> u32 {
        (self.next_u64() >> 32) as u32
    }

    /// Uniform in [0, 1), 24 random bits, never 1.0.
    #[inline]
    fn uniform(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }

    /// Uniform in [0, 1), 53 random bits.
    #[inline]
    fn uniform_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    #[inline]
    fn uniform2(&mut self) -> [f32; 2] {
        [self.uniform(), self.uniform()]
    }

    /// Two uniforms in [0, 1) with 24 random bits each from one draw (bits
    /// 40–63 and 16–39, as the first two of [`uniform3`](Self::uniform3)),
    /// for the integrator's per-vertex pairs; [`uniform2`](Self::uniform2)
    /// keeps its two draws so the streams of the mesh and ray generators do
    /// not change.
    #[inline]
    fn uniform2_packed(&mut self) -> [f32; 2] {
        let x = self.next_u64();
        let k = 1.0 / (1u64 << 24) as f32;
        [(x >> 40) as f32 * k, ((x >> 16) & 0xff_ffff) as f32 * k]
    }

    /// Three uniforms in [0, 1) with 24 random bits each from two draws
    /// (the first draw's 64 bits hold two of them), for hot paths where
    /// the hashing is a noticeable part of the cost.
    #[inline]
    fn uniform3(&mut self) -> [f32; 3] {
        let x = self.next_u64();
        let k = 1.0 / (1u64 << 24) as f32;
        [
            (x >> 40) as f32 * k,
            ((x >> 16) & 0xff_ffff) as f32 * k,
            self.uniform(),
        ]
    }

    /// A number for a discrete choice and a 2D point: the three numbers of
    /// [`uniform3`](Self::uniform3) in that order (a sequence's sampler
    /// gives the choice and the point a slot each).
    #[inline]
    fn choice_and_point(&mut self) -> (f32, [f32; 2]) {
        let [c, a, b] = self.uniform3();
        (c, [a, b])
    }

    /// Two uniforms in [0, 1) as f64 with 32 random bits each from one draw.
    #[inline]
    fn uniform2_f64_32(&mut self) -> [f64; 2] {
        let x = self.next_u64();
        let k = 1.0 / (1u64 << 32) as f64;
        [(x >> 32) as f64 * k, (x & 0xffff_ffff) as f64 * k]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a: Vec<u64> = {
            let mut r = Rng::new(1, 2, 3);
            (0..8).map(|_| r.next_u64()).collect()
        };
        let b: Vec<u64> = {
            let mut r = Rng::new(1, 2, 3);
            (0..8).map(|_| r.next_u64()).collect()
        };
        assert_eq!(a, b);
        for other in [Rng::new(1, 2, 4), Rng::new(1, 3, 3), Rng::new(2, 2, 3)] {
            let mut r = other;
            let c: Vec<u64> = (0..8).map(|_| r.next_u64()).collect();
            assert_ne!(a, c);
        }
    }

    #[test]
    fn stream_keys_were_not_changed() {
        // the first draws of a stream keyed in one call and keyed level by
        // level agree: changing them would change every rendered image
        let mut r = Rng::new(1, 2, 3);
        let first = [r.next_u64(), r.next_u64()];
        let mut r = Rng::for_sample(Rng::pixel_key(Rng::seed_key(1), 2), 3);
        assert_eq!(first, [r.next_u64(), r.next_u64()]);
        // a pinned value of the key derivation
        let mut r = Rng::new(0, 0, 0);
        assert_eq!(r.next_u64(), 0xa65b_97c9_51aa_8759);
    }

    #[test]
    fn packed_uniforms_are_in_range_flat_and_independent() {
        // chi-square on 8×8 joint bins of each pair drawn together
        let bins = 8;
        let n = 256_000;
        let mut joint = [
            vec![0u64; bins * bins],
            vec![0u64; bins * bins],
            vec![0u64; bins * bins],
        ];
        let mut r = Rng::new(3, 1, 4);
        for _ in 0..n {
            let [a, b, c] = r.uniform3();
            let [d, e] = r.uniform2_f64_32();
            let [f, g] = r.uniform2_packed();
            assert!((0.0..1.0).contains(&f) && (0.0..1.0).contains(&g));
            joint[2][(f * bins as f32) as usize * bins + (g * bins as f32) as usize] += 1;
            for u in [a, b, c] {
                assert!((0.0..1.0).contains(&u));
            }
            assert!((0.0..1.0).contains(&d) && (0.0..1.0).contains(&e));
            joint[0][(a * bins as f32) as usize * bins + (b * bins as f32) as usize] += 1;
            joint[1][(d * bins as f64) as usize * bins + (e * bins as f64) as usize] += 1;
        }
        for counts in &joint {
            let e = n as f64 / (bins * bins) as f64;
            let chi2: f64 = counts.iter().map(|&c| (c as f64 - e).powi(2) / e).sum();
            // 63 dof: p = 1e-4 critical value ≈ 112
            assert!(chi2 < 112.0, "chi2 = {chi2}");
        }
    }

    #[test]
    fn sample_streams_are_flat_independent_and_distinct() {
        // like the tests below for Rng: 64-bin flatness over many keys, then
        // 8×8 joint bins of consecutive draws within a stream and of the
        // same draw in neighbouring samples and pixels (the keys that
        // differ least)
        let bins = 64;
        let mut counts = vec![0u64; bins];
        let mut within = vec![0u64; 64];
        let mut across = vec![0u64; 64];
        let n_streams = 10_000u64;
        for s in 0..n_streams {
            let mut r = SampleRng::new(7, s / 4, s % 4);
            let mut next = SampleRng::new(7, s / 4, s % 4 + 1);
            let mut prev = r.uniform();
            for _ in 0..64 {
                let u = r.uniform();
                let v = next.uniform();
                assert!((0.0..1.0).contains(&u));
                counts[(u * bins as f32) as usize] += 1;
                within[(prev * 8.0) as usize * 8 + (u * 8.0) as usize] += 1;
                across[(u * 8.0) as usize * 8 + (v * 8.0) as usize] += 1;
                prev = u;
            }
        }
        let chi2 = |c: &[u64]| {
            let e = c.iter().sum::<u64>() as f64 / c.len() as f64;
            c.iter().map(|&c| (c as f64 - e).powi(2) / e).sum::<f64>()
        };
        // 63 dof: p = 1e-4 critical value ≈ 112
        for (what, c) in [("flat", &counts), ("within", &within), ("across", &across)] {
            let x = chi2(c);
            assert!(x < 112.0, "{what}: chi2 = {x}");
        }
        // the same key as Rng::new, another stream
        let (mut a, mut b) = (SampleRng::new(1, 2, 3), Rng::new(1, 2, 3));
        assert_ne!(a.next_u64(), b.next_u64());
        let mut a2 = SampleRng::for_sample(Rng::pixel_key(Rng::seed_key(1), 2), 3);
        let mut a = SampleRng::new(1, 2, 3);
        assert_eq!(a.next_u64(), a2.next_u64());
    }

    #[test]
    fn uniform_is_in_range_and_flat() {
        // chi-square on 64 bins, 640k draws across many keys
        let bins = 64;
        let mut counts = vec![0u64; bins];
        let n = 640_000;
        for s in 0..10_000u64 {
            let mut r = Rng::new(7, s, 0);
            for _ in 0..64 {
                let u = r.uniform();
                assert!((0.0..1.0).contains(&u));
                counts[(u * bins as f32) as usize] += 1;
            }
        }
        let e = n as f64 / bins as f64;
        let chi2: f64 = counts.iter().map(|&c| (c as f64 - e).powi(2) / e).sum();
        // 63 dof: p = 1e-4 critical value ≈ 112
        assert!(chi2 < 112.0, "chi2 = {chi2}");
    }
}
