//! A piecewise-constant density over the unit square, sampled by its
//! marginal over rows and the conditional within the row (pbrt-v4 §A.5.2,
//! `PiecewiseConstant2D`); what the environment map samples directions
//! from (`docs/scene-format.md`, "`[environment]`").

/// A piecewise-constant density on [0, 1) with `n` equal pieces.
#[derive(Clone, Debug)]
pub struct Piecewise1D {
    /// The non-negative value of each piece.
    func: Vec<f32>,
    /// cdf[i] = ∫₀^{i/n}, normalized so that cdf[n] = 1.
    cdf: Vec<f32>,
    /// ∫₀¹ of the function (the mean of `func`).
    integral: f64,
}

/// A point sampled from a [`Piecewise1D`].
#[derive(Clone, Copy, Debug)]
pub struct Sample1D {
    /// In [0, 1).
    pub x: f32,
    /// The density at `x`.
    pub pdf: f32,
    /// The piece `x` is in.
    pub index: usize,
}

impl Piecewise1D {
    /// The density proportional to `func` (negative values count as 0); a
    /// function that is 0 everywhere gives the uniform density.
    pub fn new(func: &[f32]) -> Self {
        let n = func.len().max(1);
        let mut func: Vec<f32> = func.iter().map(|f| f.max(0.0)).collect();
        if func.is_empty() {
            func.push(0.0);
        }
        let mut acc = Vec::with_capacity(n + 1);
        let mut sum = 0.0f64;
        acc.push(0.0f64);
        for f in &func {
            sum += *f as f64;
            acc.push(sum);
        }
        let integral = sum / n as f64;
        let cdf = if sum > 0.0 {
            acc.iter().map(|c| (c / sum) as f32).collect()
        } else {
            func.iter_mut().for_each(|f| *f = 1.0);
            (0..=n).map(|i| i as f32 / n as f32).collect()
        };
        Piecewise1D {
            func,
            cdf,
            integral: if sum > 0.0 { integral } else { 1.0 },
        }
    }

    pub fn len(&self) -> usize {
        self.func.len()
    }

    pub fn is_empty(&self) -> bool {
        self.func.is_empty()
    }

    /// ∫₀¹ of the function the density is proportional to.
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// Inverts the cdf at `u` ∈ [0, 1).
    #[inline]
    pub fn sample(&self, u: f32) -> Sample1D {
        let n = self.func.len();
        // The last i with cdf[i] <= u, among the pieces.
        let i = (self.cdf.partition_point(|&c| c <= u).max(1) - 1).min(n - 1);
        let width = self.cdf[i + 1] - self.cdf[i];
        let du = if width > 0.0 {
            ((u - self.cdf[i]) / width).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let x = ((i as f32 + du) / n as f32).min(1.0 - f32::EPSILON / 2.0);
        Sample1D {
            x,
            pdf: self.pdf_of(i),
            index: i,
        }
    }

    /// The density on piece `i`.
    #[inline]
    pub fn pdf_of(&self, i: usize) -> f32 {
        (self.func[i] as f64 / self.integral) as f32
    }

    /// The piece holding `x` ∈ [0, 1].
    #[inline]
    pub fn piece(&self, x: f32) -> usize {
        ((x * self.func.len() as f32) as usize).min(self.func.len() - 1)
    }
}

/// A piecewise-constant density on [0, 1)² with `nu` × `nv` cells, row v
/// of which holds `func[v·nu .. (v+1)·nu]`.
#[derive(Clone, Debug)]
pub struct Distribution2D {
    rows: Vec<Piecewise1D>,
    marginal: Piecewise1D,
}

/// A point sampled from a [`Distribution2D`].
#[derive(Clone, Copy, Debug)]
pub struct Sample2D {
    pub uv: [f32; 2],
    /// The density at `uv` (per unit area of the square).
    pub pdf: f32,
}

impl Distribution2D {
    pub fn new(func: &[f32], nu: usize, nv: usize) -> Self {
        let rows: Vec<Piecewise1D> = (0..nv)
            .map(|v| Piecewise1D::new(&func[v * nu..(v + 1) * nu]))
            .collect();
        // A row whose function is 0 everywhere is uniform within itself
        // but weighs 0 in the marginal.
        let row_weights: Vec<f32> = (0..nv)
            .map(|v| {
                let s: f64 = func[v * nu..(v + 1) * nu]
                    .iter()
                    .map(|f| f.max(0.0) as f64)
                    .sum();
                (s / nu as f64) as f32
            })
            .collect();
        Distribution2D {
            rows,
            marginal: Piecewise1D::new(&row_weights),
        }
    }

    /// Two uniform numbers to a point and its density.
    #[inline]
    pub fn sample(&self, u: [f32; 2]) -> Sample2D {
        let v = self.marginal.sample(u[1]);
        let s = self.rows[v.index].sample(u[0]);
        Sample2D {
            uv: [s.x, v.x],
            pdf: v.pdf * s.pdf,
        }
    }

    /// The density at `uv`.
    #[inline]
    pub fn pdf(&self, uv: [f32; 2]) -> f32 {
        let v = self.marginal.piece(uv[1]);
        let row = &self.rows[v];
        self.marginal.pdf_of(v) * row.pdf_of(row.piece(uv[0]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The density integrates to one and the samples land in proportion
    /// to the function (catches a cdf off by one piece, or a pdf not
    /// normalized by the integral).
    #[test]
    fn samples_follow_the_function() {
        let func = [0.0, 1.0, 3.0, 0.0, 4.0, 2.0];
        let d = Distribution2D::new(&func, 3, 2);
        let total: f32 = func.iter().sum();
        let mut counts = [0u32; 6];
        let n = 60_000;
        for k in 0..n {
            let u = [
                ((k * 7919) % n) as f32 / n as f32,
                (k as f32 + 0.5) / n as f32,
            ];
            let s = d.sample(u);
            let (i, j) = ((s.uv[0] * 3.0) as usize, (s.uv[1] * 2.0) as usize);
            counts[j * 3 + i] += 1;
            let expect = func[j * 3 + i] / total * 6.0;
            assert!((s.pdf - expect).abs() < 1e-5, "{} vs {expect}", s.pdf);
            assert!((d.pdf(s.uv) - s.pdf).abs() < 1e-6);
        }
        for (c, f) in counts.iter().zip(func) {
            let expect = f / total * n as f32;
            assert!(
                (*c as f32 - expect).abs() < 0.01 * n as f32,
                "{c} vs {expect}"
            );
        }
    }

    #[test]
    fn a_zero_function_is_uniform() {
        let d = Piecewise1D::new(&[0.0, 0.0]);
        let s = d.sample(0.75);
        assert_eq!(s.index, 1);
        assert!((s.x - 0.75).abs() < 1e-6 && (s.pdf - 1.0).abs() < 1e-6);
    }
}
