//! The total diffuse reflectance of a semi-infinite plane-parallel medium
//! behind a smooth dielectric boundary, by the random walk's own physics:
//! the generator of the albedo table (`bssrdf::albedo_table`,
//! `docs/bssrdf.md` §9).
//!
//! The medium fills z < 0 (σt = 1), albedo α, Henyey–Greenstein phase of
//! mean cosine g, boundary z = 0 of relative index η; a walk is
//! `integrator::randomwalk`'s with the mesh replaced by the plane
//! ([`free_flight`], [`sample_hg`], [`dielectric::sample`]). Light enters
//! as [`Entry::Diffuse`] or [`Entry::Normal`]; walks run with α = 1 and
//! their event counts n give R(α) = E[α^n] for every α at once, a capped
//! walk counting 0 ([`Tally::cap_bound`] bounds that). Why this R is the
//! diffusion model's A, and the estimator: `docs/bssrdf.md` §12.8.

use lucent::bssrdf::albedo_table::interpolate_row;
use lucent::bssrdf::params::Medium;
use lucent::geometry::Vec3;
use lucent::integrator::randomwalk::{free_flight, sample_hg};
use lucent::materials::dielectric;
use lucent::sampling::{cosine_hemisphere, Draw};

/// How light enters the half-space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Entry {
    /// Uniform radiance outside: cosine-weighted, refracted with prob. Ft.
    Diffuse,
    /// Along the normal (μ = 1), refracted with probability Ft(1).
    Normal,
    /// From the direction at cos θ = μ to the normal in the xz-plane on
    /// the +x side (the refracted light heads towards −x), refracted with
    /// probability Ft(μ): a key light (`crate::sphere_transfer`).
    Oblique(f32),
}

impl Entry {
    /// The random stream a run of walks entering this way draws from
    /// (diffuse 0 and normal 1, as the albedo table was made).
    fn stream(self) -> u64 {
        match self {
            Entry::Diffuse => 0,
            Entry::Normal => 1,
            Entry::Oblique(mu) => 2 + mu.to_bits() as u64,
        }
    }
}

/// The direction (z < 0) of one walk entering the medium.
pub(crate) fn enter(eta: f32, entry: Entry, rng: &mut impl Draw) -> Vec3 {
    loop {
        // wo: the direction the light comes from, +z = outside.
        let wo = match entry {
            Entry::Diffuse => cosine_hemisphere(rng.uniform2()),
            Entry::Normal => Vec3::new(0.0, 0.0, 1.0),
            Entry::Oblique(mu) => Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu),
        };
        let s = dielectric::sample(eta, wo, rng.uniform());
        if s.transmitted {
            return s.wi;
        }
    }
}

/// One walk with α = 1: the number of scattering events before it refracts
/// out, or None if it is still inside after `cap` events.
pub fn walk(eta: f32, g: f64, entry: Entry, cap: u32, rng: &mut impl Draw) -> Option<u32> {
    let mut d = enter(eta, entry, rng);
    let mut z = 0.0f64;
    let mut n = 0u32;
    loop {
        let t = free_flight(1.0, rng.uniform_f64());
        let z_next = z + t * d.z as f64;
        if z_next >= 0.0 {
            // The boundary, seen from inside: the local frame is the world
            // frame (outward normal +z) and wo points back into the medium.
            let s = dielectric::sample(eta, -d, rng.uniform());
            if s.transmitted {
                return Some(n);
            }
            d = s.wi;
            z = 0.0;
            continue;
        }
        z = z_next;
        n += 1;
        if n > cap {
            return None;
        }
        d = sample_hg(d, g, rng.uniform2());
    }
}

/// Sums over walks of α^n and α^{2n} for a list of albedos.
#[derive(Clone, Debug, PartialEq)]
pub struct Tally {
    pub albedos: Vec<f64>,
    pub sum: Vec<f64>,
    pub sum_sq: Vec<f64>,
    pub walks: u64,
    pub capped: u64,
    pub cap: u32,
    /// Scattering events simulated (the cost).
    pub events: u64,
}

impl Tally {
    pub fn new(albedos: &[f64], cap: u32) -> Self {
        Tally {
            albedos: albedos.to_vec(),
            sum: vec![0.0; albedos.len()],
            sum_sq: vec![0.0; albedos.len()],
            walks: 0,
            capped: 0,
            cap,
            events: 0,
        }
    }

    pub fn add(&mut self, n: Option<u32>) {
        self.walks += 1;
        match n {
            Some(n) => {
                self.events += n as u64;
                for (i, &a) in self.albedos.iter().enumerate() {
                    let w = a.powi(n as i32);
                    self.sum[i] += w;
                    self.sum_sq[i] += w * w;
                }
            }
            None => {
                self.events += self.cap as u64;
                self.capped += 1;
            }
        }
    }

    pub fn merge(&mut self, o: &Tally) {
        for i in 0..self.sum.len() {
            self.sum[i] += o.sum[i];
            self.sum_sq[i] += o.sum_sq[i];
        }
        self.walks += o.walks;
        self.capped += o.capped;
        self.events += o.events;
    }

    /// R(α_i) and its standard error.
    pub fn estimate(&self, i: usize) -> (f64, f64) {
        let n = self.walks as f64;
        let m = self.sum[i] / n;
        let var = (self.sum_sq[i] / n - m * m).max(0.0);
        (m, (var / (n - 1.0)).sqrt())
    }

    /// The most the cap can have taken from R(α_i): P(n > cap)·α^cap.
    pub fn cap_bound(&self, i: usize) -> f64 {
        self.capped as f64 / self.walks as f64 * self.albedos[i].powi(self.cap as i32)
    }
}

/// The single-scattering albedo α of a medium of reduced albedo
/// α' = α(1 − g)/(1 − αg) and mean cosine g (the inverse of that relation).
pub fn albedo_from_reduced(alpha_reduced: f64, g: f64) -> f64 {
    alpha_reduced / (1.0 - g + g * alpha_reduced)
}

/// The reduced albedo α' = σs' / (σs' + σa) of channel `c` of a medium.
pub fn reduced_albedo(m: &Medium, c: usize) -> f64 {
    let ss = m.sigma_s[c] * (1.0 - m.g);
    ss / (ss + m.sigma_a[c])
}

/// What the table generator runs.
#[derive(Clone, Debug, PartialEq)]
pub struct TableSettings {
    /// Tabulated relative indices η (inside / outside).
    pub etas: Vec<f64>,
    /// Nodes in x = √(1 − α') on [0, 1] (x = 0 is α' = 1).
    pub x_nodes: usize,
    pub walks_diffuse: u64,
    pub walks_normal: u64,
    pub cap: u32,
    pub seed: u64,
    /// η between the rows where the η interpolation is checked.
    pub eta_checks: Vec<f64>,
    /// Walks per parallel chunk (each chunk has its own random stream, so
    /// the result does not depend on the thread count).
    pub chunk: u64,
}

impl Default for TableSettings {
    fn default() -> Self {
        TableSettings {
            etas: (0..=10).map(|i| 1.0 + 0.1 * i as f64).collect(),
            x_nodes: 41,
            walks_diffuse: 300_000,
            walks_normal: 60_000,
            cap: 10_000,
            seed: 2026,
            eta_checks: vec![1.25, 1.45, 1.75],
            chunk: 5_000,
        }
    }
}

impl TableSettings {
    /// `walks` walks with these settings' cap and streams.
    pub fn batch(&self, walks: u64) -> Batch {
        Batch {
            walks,
            cap: self.cap,
            seed: self.seed,
            chunk: self.chunk,
        }
    }

    /// The x = √(1 − α') nodes, and the midpoints between them (the
    /// interpolation check), in one list: nodes first.
    pub fn xs(&self) -> (Vec<f64>, Vec<f64>) {
        let n = self.x_nodes - 1;
        let nodes = (0..=n).map(|i| i as f64 / n as f64).collect();
        let mids = (0..n).map(|i| (i as f64 + 0.5) / n as f64).collect();
        (nodes, mids)
    }
}

/// How many walks to run and how: the event cap, and the random streams
/// (chunk k of `chunk` walks draws from the stream (seed, entry, k)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Batch {
    pub walks: u64,
    pub cap: u32,
    pub seed: u64,
    pub chunk: u64,
}

/// The tally of `b.walks` walks at (η, g, entry) for the single-scattering
/// albedos `albedos`. The streams are the same for every η and g: common
/// random numbers, so differences between neighbouring η (the
/// interpolation check) carry little noise.
pub fn run(eta: f64, g: f64, entry: Entry, albedos: &[f64], b: &Batch) -> Tally {
    let Batch {
        walks,
        cap,
        seed,
        chunk,
    } = *b;
    use lucent::sampling::Rng;
    use rayon::prelude::*;
    let chunks = walks.div_ceil(chunk);
    let parts: Vec<Tally> = (0..chunks)
        .into_par_iter()
        .map(|k| {
            let mut rng = Rng::new(seed, entry.stream(), k);
            let mut t = Tally::new(albedos, cap);
            let n = chunk.min(walks - k * chunk);
            for _ in 0..n {
                t.add(walk(eta as f32, g, entry, cap, &mut rng));
            }
            t
        })
        .collect();
    let mut total = Tally::new(albedos, cap);
    for p in &parts {
        total.merge(p);
    }
    total
}

/// One row of the table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Row {
    pub eta: f64,
    pub x: f64,
    pub r_diffuse: f64,
    pub se_diffuse: f64,
    pub r_normal: f64,
    pub se_normal: f64,
}

/// The table and the measured errors that go into its header.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    pub rows: Vec<Row>,
    pub max_se: f64,
    /// Largest |linear interpolation in x − simulated| at the x midpoints
    /// (same walks, so nearly free of noise), over all η; diffuse column.
    pub max_x_interp: f64,
    /// Largest |linear interpolation in η − simulated| at the η midpoints
    /// checked ([`TableSettings::eta_checks`]), all x nodes; diffuse column.
    pub max_eta_interp: f64,
    /// Largest |R(cap) bound| over the tabulated nodes.
    pub max_cap_bound: f64,
    pub walk_events: u64,
}

/// Runs the generator for every η in `s`: the diffuse and the normal
/// column at every x node, and the x-interpolation check.
pub fn generate(s: &TableSettings, mut progress: impl FnMut(&str)) -> Table {
    let (nodes, mids) = s.xs();
    let albedos: Vec<f64> = nodes.iter().chain(&mids).map(|x| 1.0 - x * x).collect();
    let k = nodes.len();
    let mut t = Table {
        rows: Vec::new(),
        max_se: 0.0,
        max_x_interp: 0.0,
        max_eta_interp: 0.0,
        max_cap_bound: 0.0,
        walk_events: 0,
    };
    let mut rows_by_eta: Vec<Vec<f64>> = Vec::new();
    for &eta in &s.etas {
        let d = run(
            eta,
            0.0,
            Entry::Diffuse,
            &albedos,
            &s.batch(s.walks_diffuse),
        );
        let n = run(eta, 0.0, Entry::Normal, &albedos, &s.batch(s.walks_normal));
        t.walk_events += d.events + n.events;
        let mut ys = Vec::new();
        for (i, &x) in nodes.iter().enumerate() {
            // α' = 1: a half-space that absorbs nothing returns all the
            // light that enters (the walk is recurrent); exactly 1.
            let exact = i == 0;
            let (rd, sd) = if exact { (1.0, 0.0) } else { d.estimate(i) };
            let (rn, sn) = if exact { (1.0, 0.0) } else { n.estimate(i) };
            if !exact {
                t.max_cap_bound = t.max_cap_bound.max(d.cap_bound(i)).max(n.cap_bound(i));
            }
            t.max_se = t.max_se.max(sd);
            ys.push(rd);
            t.rows.push(Row {
                eta,
                x,
                r_diffuse: rd,
                se_diffuse: sd,
                r_normal: rn,
                se_normal: sn,
            });
        }
        for (j, &x) in mids.iter().enumerate() {
            // Near α' = 1 the cap takes too much from a midpoint for the
            // check to measure interpolation (the first one, x = 1/80).
            if d.cap_bound(k + j) > 1e-5 {
                continue;
            }
            let (r, _) = d.estimate(k + j);
            let err = (interpolate_row(&ys, x, eta) - r).abs();
            t.max_x_interp = t.max_x_interp.max(err);
        }
        rows_by_eta.push(ys);
        progress(&format!(
            "eta {eta:.2}: {} + {} walks, {} capped, {:.1} events per walk",
            d.walks,
            n.walks,
            d.capped + n.capped,
            (d.events + n.events) as f64 / (d.walks + n.walks) as f64
        ));
    }
    // η midpoints: ρ linear in η between the two rows, times the dipole.
    for &eta in &s.eta_checks {
        let d = run(
            eta,
            0.0,
            Entry::Diffuse,
            &albedos,
            &s.batch(s.walks_diffuse / 3),
        );
        t.walk_events += d.events;
        let i = s
            .etas
            .iter()
            .position(|&e| e > eta)
            .unwrap_or(s.etas.len() - 1)
            .max(1)
            - 1;
        let w = (eta - s.etas[i]) / (s.etas[i + 1] - s.etas[i]);
        for (j, &x) in nodes.iter().enumerate().skip(1) {
            let dip = lucent::bssrdf::params::dipole_reflectance(1.0 - x * x, eta);
            let rho = |k: usize| {
                let e = s.etas[k];
                interpolate_row(&rows_by_eta[k], x, e)
                    / lucent::bssrdf::params::dipole_reflectance(1.0 - x * x, e)
            };
            if dip.is_nan() || dip <= 0.0 {
                continue;
            }
            let r = (rho(i) * (1.0 - w) + rho(i + 1) * w) * dip;
            t.max_eta_interp = t.max_eta_interp.max((r - d.estimate(j).0).abs());
        }
        progress(&format!("eta check {eta:.2}: {} walks", d.walks));
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;
    use lucent::sampling::Rng;

    /// η = 1, isotropic scattering: the classical half-space problem,
    /// whose albedos follow from Chandrasekhar's H function (Radiative
    /// Transfer, 1960, §26–§29): for light entering at μ0 the plane albedo
    /// is 1 − H(μ0)√(1 − α), and for diffuse light 1 − 2√(1 − α) ∫H μ dμ.
    /// H was solved here from 1/H(μ) = √(1 − α) + α/2 ∫ μ' H(μ')/(μ + μ') dμ'
    /// (600-point midpoint rule, iterated; its zeroth moment matches the
    /// closed form 2(1 − √(1 − α))/α to 1e-12): α = 0.5 → diffuse 0.146544,
    /// normal 0.115226; α = 0.8 → 0.341867, 0.285255.
    #[test]
    fn index_matched_isotropic_half_space_matches_chandrasekhar() {
        let alphas = [0.5, 0.8];
        let cases = [
            (Entry::Diffuse, [0.146544, 0.341867]),
            (Entry::Normal, [0.115226, 0.285255]),
        ];
        for (entry, expect) in cases {
            // 0.8^1000 ≈ 1e-97: the cap takes nothing measurable.
            let mut t = Tally::new(&alphas, 1000);
            let mut rng = Rng::new(3, 0, 0);
            for _ in 0..400_000 {
                t.add(walk(1.0, 0.0, entry, 1000, &mut rng));
            }
            for i in 0..2 {
                let (r, se) = t.estimate(i);
                println!(
                    "{entry:?} α {}: R {r} ± {se}, H function {}",
                    alphas[i], expect[i]
                );
                assert!(
                    se < 1e-3 && (r - expect[i]).abs() < 4.0 * se,
                    "{r} vs {}",
                    expect[i]
                );
            }
        }
    }
}
