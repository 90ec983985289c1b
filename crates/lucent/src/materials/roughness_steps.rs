//! Albedo tables at fixed roughness steps, for a roughness read from a
//! texture. A microfacet lobe's energy compensation reads its directional
//! albedo E(μ) for its own α ([`super::albedo_table`]), a table of a
//! quarter of a million samples of the lobe or more: too dear to build at
//! a hit. A textured material holds the tables of the roughnesses
//! r_j = j / [`STEPS`] that its texture's values span, built once (and
//! shared with constant materials of those roughnesses), and a hit blends
//! the two around its roughness linearly in r. At a step the blend is
//! that step's table bit for bit. The blend's error against the exact
//! table: `docs/scene-format.md`, "Textures".

use std::sync::Arc;

use rayon::prelude::*;

use super::albedo_table::AlbedoTable;

/// Roughness steps per unit of roughness.
pub const STEPS: u32 = 32;

/// The roughness of step `j`.
pub fn step_roughness(j: u32) -> f32 {
    j as f32 / STEPS as f32
}

/// The tables of consecutive roughness steps from `first` on.
#[derive(Clone, Debug, PartialEq)]
pub struct RoughnessSteps {
    first: u32,
    tables: Vec<Arc<AlbedoTable>>,
}

impl RoughnessSteps {
    /// The tables of the steps whose span covers roughnesses in
    /// [`lo`, `hi`] ⊂ [0, 1] (at least step 1: step 0, α = 0, has no lobe),
    /// `table(r)` giving the table of roughness r. They are built in
    /// parallel.
    pub fn new(lo: f32, hi: f32, table: impl Fn(f32) -> Arc<AlbedoTable> + Sync) -> Self {
        let scaled = |r: f32| r.clamp(0.0, 1.0) * STEPS as f32;
        let first = (scaled(lo).floor() as u32).clamp(1, STEPS);
        let last = (scaled(hi).ceil() as u32).clamp(first, STEPS);
        let tables = (first..=last)
            .into_par_iter()
            .map(|j| table(step_roughness(j)))
            .collect();
        RoughnessSteps { first, tables }
    }

    /// The table at roughness `r`: the blend of the two steps around it
    /// (`r` clamped to the steps held).
    pub fn at(&self, r: f32) -> AlbedoTable {
        let n = self.tables.len() as u32;
        if n == 1 {
            return *self.tables[0];
        }
        let x = r * STEPS as f32;
        let j = (x.floor().max(0.0) as u32).clamp(self.first, self.first + n - 2);
        let t = (x - j as f32).clamp(0.0, 1.0);
        let i = (j - self.first) as usize;
        AlbedoTable::lerp(&self.tables[i], &self.tables[i + 1], t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A table whose E is the roughness itself at every μ.
    fn flat(r: f32) -> Arc<AlbedoTable> {
        Arc::new(AlbedoTable::new(|_| r as f64))
    }

    /// A quantity linear in roughness is reproduced between steps, a step
    /// is its own table bit for bit, and values outside the steps held
    /// take the nearest end: catches a blend weight measured from the
    /// wrong step or an off-by-one in the steps built.
    #[test]
    fn blends_are_linear_in_roughness_and_exact_at_steps() {
        let s = RoughnessSteps::new(0.2, 0.55, flat);
        assert_eq!(s.first, 6);
        assert_eq!(s.tables.len(), 18 - 6 + 1);
        for r in [0.2f32, 0.3, 0.4321, 0.55] {
            assert!((s.at(r).at(0.5) - r).abs() < 1e-6, "r {r}");
        }
        assert_eq!(s.at(0.5), *flat(0.5));
        assert!((s.at(0.9).at(0.3) - 18.0 / 32.0).abs() < 1e-6);
        assert!((s.at(0.0).at(0.3) - 6.0 / 32.0).abs() < 1e-6);
        let one = RoughnessSteps::new(1.0, 1.0, flat);
        assert_eq!(one.at(0.7), *flat(1.0));
    }
}
