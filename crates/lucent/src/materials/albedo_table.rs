//! A directional albedo E(μ) tabulated on μ = (k / N)² (dense at grazing
//! angles, where it changes fastest), with its cosine-weighted mean
//! Ē = 2 ∫₀¹ E(μ) μ dμ: what the multiple-scattering compensation of a
//! microfacet lobe reads (Kelemen & Szirmay-Kalos 2001; Kulla & Conty
//! 2017). The same node layout as the coat's table (`docs/bssrdf.md`
//! §12.7).

/// Intervals of the table.
const NODES: usize = 64;

/// The table's k-th cosine, (k / NODES)².
fn node(k: usize) -> f32 {
    let s = k as f32 / NODES as f32;
    s * s
}

/// E(μ) at the nodes and Ē of the interpolated table. The default is the
/// empty table, which [`AlbedoTable::at`] must not be asked.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AlbedoTable {
    values: Vec<f32>,
    mean: f32,
}

impl AlbedoTable {
    /// The table of `e` at every node (μ = 0 itself is a limit: the first
    /// node sits just above it).
    pub fn new(e: impl Fn(f32) -> f64) -> Self {
        let values: Vec<f32> = (0..=NODES).map(|k| e(node(k).max(1e-4)) as f32).collect();
        // 2 ∫ E μ dμ of the piecewise-linear table, exactly: on [a, b] of
        // width h with E linear from ea to eb, ∫ E μ = h (ea (2a + b) + eb (a + 2b)) / 6.
        let mut mean = 0.0f64;
        for k in 0..NODES {
            let (a, b) = (node(k) as f64, node(k + 1) as f64);
            let (ea, eb) = (values[k] as f64, values[k + 1] as f64);
            mean += (b - a) * (ea * (2.0 * a + b) + eb * (a + 2.0 * b)) / 6.0;
        }
        AlbedoTable {
            values,
            mean: (2.0 * mean) as f32,
        }
    }

    /// E(μ), linear between nodes (μ clamped to [0, 1]).
    pub fn at(&self, mu: f32) -> f32 {
        let mu = mu.clamp(0.0, 1.0);
        let k = ((mu.sqrt() * NODES as f32) as usize).min(NODES - 1);
        let (a, b) = (node(k), node(k + 1));
        let t = ((mu - a) / (b - a)).clamp(0.0, 1.0);
        self.values[k] * (1.0 - t) + self.values[k + 1] * t
    }

    /// Ē = 2 ∫₀¹ E(μ) μ dμ.
    pub fn mean(&self) -> f32 {
        self.mean
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear E is reproduced exactly, between nodes too, and its mean
    /// is 2 ∫ (a + bμ) μ dμ = a + 2b/3: catches a wrong interpolation or
    /// a wrong mean.
    #[test]
    fn linear_albedo_is_exact() {
        let t = AlbedoTable::new(|mu| 0.2 + 0.5 * mu as f64);
        for mu in [0.0f32, 0.013, 0.25, 0.6, 1.0] {
            let want = 0.2 + 0.5 * mu.max(1e-4);
            assert!((t.at(mu) - want).abs() < 1e-5, "μ {mu}: {}", t.at(mu));
        }
        assert!((t.mean() - (0.2 + 2.0 * 0.5 / 3.0)).abs() < 1e-5);
    }
}
