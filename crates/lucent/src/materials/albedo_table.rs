//! A directional albedo E(μ) tabulated on μ = (k / N)² (dense at grazing
//! angles, where it changes fastest), with its cosine-weighted mean
//! Ē = 2 ∫₀¹ E(μ) μ dμ: what the multiple-scattering compensation of a
//! microfacet lobe reads (Kelemen & Szirmay-Kalos 2001; Kulla & Conty
//! 2017). The same node layout as the coat's table (`docs/bssrdf.md`
//! §12.7). Tables are built once per process for each lobe (`shared`)
//! and blended between fixed roughness steps where a texture gives the
//! roughness ([`AlbedoTable::lerp`], [`super::roughness_steps`]).

use std::sync::{Arc, Mutex};

/// Intervals of the table.
const NODES: usize = 64;

/// The table's k-th cosine, (k / NODES)².
fn node(k: usize) -> f32 {
    let s = k as f32 / NODES as f32;
    s * s
}

/// E(μ) at the nodes and Ē of the interpolated table, held inline so that
/// a blend of two tables at a hit allocates nothing. The default is the
/// zero table, which [`AlbedoTable::at`] must not be asked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlbedoTable {
    values: [f32; NODES + 1],
    mean: f32,
}

impl Default for AlbedoTable {
    fn default() -> Self {
        AlbedoTable {
            values: [0.0; NODES + 1],
            mean: 0.0,
        }
    }
}

impl AlbedoTable {
    /// The table of `e` at every node (μ = 0 itself is a limit: the first
    /// node sits just above it).
    pub fn new(e: impl Fn(f32) -> f64) -> Self {
        let values: [f32; NODES + 1] = std::array::from_fn(|k| e(node(k).max(1e-4)) as f32);
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

    /// (1 − t) `a` + t `b`, node by node, and the mean likewise (Ē is
    /// linear in the nodes, so it is the blended table's own); `a` itself,
    /// bit for bit, at t = 0.
    pub fn lerp(a: &Self, b: &Self, t: f32) -> Self {
        if t == 0.0 {
            return *a;
        }
        let mix = |x: f32, y: f32| x * (1.0 - t) + y * t;
        AlbedoTable {
            values: std::array::from_fn(|k| mix(a.values[k], b.values[k])),
            mean: mix(a.mean, b.mean),
        }
    }
}

/// Which lobe a table belongs to, and the bits of the parameters it is a
/// function of: a dielectric coat's (α, η), or a conductor's α (its table
/// is that of F = 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableKey {
    Coat { alpha: u32, eta: u32 },
    Conductor { alpha: u32 },
}

/// The table of `key`, built by `build` the first time a process asks for
/// it: a table costs a quarter of a million samples of the lobe or more,
/// and materials of one lobe, a material's regularized coat, a material
/// rebuilt with other estimator options and the roughness steps of a
/// textured material all ask for the same.
pub(crate) fn shared(key: TableKey, build: impl FnOnce() -> AlbedoTable) -> Arc<AlbedoTable> {
    static TABLES: Mutex<Vec<(TableKey, Arc<AlbedoTable>)>> = Mutex::new(Vec::new());
    // A panic elsewhere while the lock was held leaves only whole entries.
    let find = || {
        let tables = TABLES.lock().unwrap_or_else(|e| e.into_inner());
        tables
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, t)| Arc::clone(t))
    };
    if let Some(t) = find() {
        return t;
    }
    // Built outside the lock, so that tables of other keys are built at
    // the same time; a table built twice by a race is the same table, and
    // the first one kept is returned to both.
    let table = Arc::new(build());
    let mut tables = TABLES.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, t)) = tables.iter().find(|(k, _)| *k == key) {
        return Arc::clone(t);
    }
    tables.push((key, Arc::clone(&table)));
    table
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

    /// A blend of two linear tables is the linear table of the blended
    /// coefficients, mean included, and t = 0 is the first table bit for
    /// bit: catches a blend weighted the wrong way round or a mean left
    /// unblended.
    #[test]
    fn a_blend_of_tables_is_the_table_of_the_blend() {
        let a = AlbedoTable::new(|mu| 0.2 + 0.5 * mu as f64);
        let b = AlbedoTable::new(|mu| 0.9 - 0.3 * mu as f64);
        let t = 0.25f32;
        let m = AlbedoTable::lerp(&a, &b, t);
        let want =
            AlbedoTable::new(|mu| 0.75 * (0.2 + 0.5 * mu as f64) + 0.25 * (0.9 - 0.3 * mu as f64));
        for mu in [0.0f32, 0.07, 0.5, 1.0] {
            assert!((m.at(mu) - want.at(mu)).abs() < 1e-6, "μ {mu}");
        }
        assert!((m.mean() - want.mean()).abs() < 1e-6);
        assert_eq!(AlbedoTable::lerp(&a, &b, 0.0), a);
    }

    /// The cache builds a key's table once and tells keys apart.
    #[test]
    fn shared_tables_are_built_once_per_key() {
        let key = TableKey::Coat { alpha: 7, eta: 7 };
        let one = shared(key, || AlbedoTable::new(|_| 0.25));
        let again = shared(key, || panic!("built twice"));
        assert!(Arc::ptr_eq(&one, &again));
        let other = shared(TableKey::Conductor { alpha: 7 }, || {
            AlbedoTable::new(|_| 0.5)
        });
        assert_eq!((one.at(0.5), other.at(0.5)), (0.25, 0.5));
    }
}
