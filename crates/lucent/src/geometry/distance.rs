//! Lower bounds on the distance from a point to the nearest triangle of a
//! scene, on a grid: the random walk's free flights that need no ray query
//! (`docs/bssrdf.md` §7, "The walk's cost"). A ball around a point of
//! radius below the bound holds no surface, so a flight from that point
//! shorter than the bound cannot meet the boundary.
//!
//! **The bound.** A regular grid of cubic cells of side h covers a box
//! (the domain). A cell is *marked* when it may overlap a triangle: the
//! triangle's box overlaps it and the triangle's plane passes through it
//! (a superset of the cells the triangle overlaps), so every point of
//! every triangle inside the domain lies in a marked cell. The exact
//! Euclidean distance transform (Felzenszwalb & Huttenlocher 2012,
//! "Distance Transforms of Sampled Functions") gives
//! each cell the distance d_c between its centre and the nearest marked
//! cell's centre; any point of the cell is then at least (d_c − √3)·h from
//! any point of a marked cell (two half-diagonals), so from every triangle
//! inside the domain. Triangles outside the domain are at least as far as
//! the domain's faces, so the cell's bound is the smaller of that and the
//! distance from the cell to the domain's faces. Points outside the domain
//! get 0: no bound.
//!
//! The transform works on squared distances of whole cells (exact in
//! f32); the bound in scene units is rounded down by one part in 10⁵. A
//! lookup is an index computation and one load.

use crate::geometry::{Mesh, Vec3};
use rayon::prelude::*;

/// Cells along the domain's longest side.
pub const CELLS: usize = 128;

/// The grid of lower bounds (module docs).
#[derive(Clone, Debug)]
pub struct DistanceGrid {
    lo: Vec3,
    inv_h: f32,
    dims: [usize; 3],
    /// `dims` as floats, for the lookup's range check.
    cells: Vec3,
    /// Per cell (x fastest), the bound in scene units.
    bound: Vec<f32>,
}

impl DistanceGrid {
    /// The grid over the box `[lo, hi]` (a few cells are added on every
    /// side), bounding the distance to every triangle of `meshes`; None for
    /// an empty or non-finite box.
    pub fn build(meshes: &[Mesh], lo: Vec3, hi: Vec3) -> Option<Self> {
        let extent = (hi - lo).max_element();
        if !(extent.is_finite() && extent > 0.0) {
            return None;
        }
        let h = extent / (CELLS - 4) as f32;
        let lo = lo - Vec3::splat(2.0 * h);
        let dims = ((hi - lo) / h)
            .ceil()
            .as_uvec3()
            .to_array()
            .map(|n| n as usize + 2);
        let mut grid = DistanceGrid {
            lo,
            inv_h: 1.0 / h,
            dims,
            cells: Vec3::new(dims[0] as f32, dims[1] as f32, dims[2] as f32),
            bound: vec![f32::INFINITY; dims[0] * dims[1] * dims[2]],
        };
        grid.mark(meshes);
        grid.transform();
        grid.finish(h);
        Some(grid)
    }

    /// A lower bound on the distance from `p` to every triangle; 0 outside
    /// the grid.
    #[inline]
    pub fn bound(&self, p: Vec3) -> f32 {
        let c = (p - self.lo) * self.inv_h;
        let n = self.cells;
        // NaN fails every comparison.
        let inside = c.x >= 0.0 && c.y >= 0.0 && c.z >= 0.0 && c.x < n.x && c.y < n.y && c.z < n.z;
        if !inside {
            return 0.0;
        }
        // SAFETY: every coordinate is finite and in [0, dims), dims a few
        // hundred at most, so it truncates to an index u32 represents.
        let [x, y, z] = c
            .to_array()
            .map(|v| unsafe { v.to_int_unchecked::<u32>() } as usize);
        self.bound[(z * self.dims[1] + y) * self.dims[0] + x]
    }

    /// The cell range `[a, b]` per axis that the box `[lo, hi]` overlaps,
    /// clipped to the grid; None when it lies outside.
    fn cells(&self, lo: Vec3, hi: Vec3) -> Option<[[usize; 2]; 3]> {
        let (a, b) = ((lo - self.lo) * self.inv_h, (hi - self.lo) * self.inv_h);
        let mut r = [[0; 2]; 3];
        for k in 0..3 {
            let n = self.dims[k] as f32;
            if !(b[k] >= 0.0 && a[k] < n) {
                return None;
            }
            // one cell of slack each way: rounding cannot leave a cell out
            r[k] = [
                (a[k].floor() - 1.0).max(0.0) as usize,
                ((b[k].floor() + 1.0).min(n - 1.0)) as usize,
            ];
        }
        Some(r)
    }

    /// Sets every cell a triangle may overlap to 0 (a source): the cells
    /// its box overlaps (with a cell of slack) that its plane passes
    /// through (module docs).
    fn mark(&mut self, meshes: &[Mesh]) {
        let h = 1.0 / self.inv_h;
        for m in meshes {
            for i in 0..m.triangle_count() as u32 {
                let t = m.triangle(i);
                let (lo, hi) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
                let Some([[x0, x1], [y0, y1], [z0, z1]]) = self.cells(lo, hi) else {
                    continue;
                };
                let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
                // half the box's extent along n, and a little for rounding
                let reach = 0.5 * h * n.abs().element_sum() + 1e-3 * h;
                for z in z0..=z1 {
                    for y in y0..=y1 {
                        for x in x0..=x1 {
                            let c = self.lo + (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * h;
                            // a zero or non-finite normal passes: no plane
                            let off = (c - t[0]).dot(n).abs();
                            if off.is_nan() || off <= reach {
                                let row = (z * self.dims[1] + y) * self.dims[0];
                                self.bound[row + x] = 0.0;
                            }
                        }
                    }
                }
            }
        }
    }

    /// The squared Euclidean distance transform, in cells, axis by axis
    /// (each axis's lines in parallel).
    fn transform(&mut self) {
        let [nx, ny, nz] = self.dims;
        // along x, where every value is 0 or ∞: the squared distance to
        // the nearest 0 in the row, by a sweep each way
        self.bound.par_chunks_mut(nx).for_each(nearest_source);
        // along y: within each z-slice, columns of stride nx
        self.bound.par_chunks_mut(nx * ny).for_each_init(
            || Line::new(ny),
            |l, slice| (0..nx).for_each(|x| l.run(slice, x, nx)),
        );
        // along z: per y, the (x, z) plane gathered, transformed, put back
        let planes: Vec<Vec<f32>> = (0..ny)
            .into_par_iter()
            .map_init(
                || Line::new(nz),
                |l, y| {
                    let mut plane: Vec<f32> = (0..nz)
                        .flat_map(|z| {
                            let row = (z * ny + y) * nx;
                            self.bound[row..row + nx].iter().copied()
                        })
                        .collect();
                    (0..nx).for_each(|x| l.run(&mut plane, x, nx));
                    plane
                },
            )
            .collect();
        for (y, plane) in planes.iter().enumerate() {
            for z in 0..nz {
                let row = (z * ny + y) * nx;
                self.bound[row..row + nx].copy_from_slice(&plane[z * nx..(z + 1) * nx]);
            }
        }
    }

    /// Squared centre distances in cells → bounds in scene units (module
    /// docs).
    fn finish(&mut self, h: f32) {
        let [nx, ny, nz] = self.dims;
        let half_diagonals = 3f32.sqrt();
        self.bound
            .par_chunks_mut(nx * ny)
            .enumerate()
            .for_each(|(z, slice)| {
                for (i, b) in slice.iter_mut().enumerate() {
                    let (x, y) = (i % nx, i / nx);
                    // cells between this one and the domain's faces
                    let faces = x
                        .min(nx - 1 - x)
                        .min(y.min(ny - 1 - y))
                        .min(z.min(nz - 1 - z)) as f32;
                    let marked = b.sqrt() - half_diagonals;
                    // rounding of h·cells: one part in 10⁵ less
                    *b = (marked.min(faces) * h * (1.0 - 1e-5)).max(0.0);
                }
            });
    }
}

/// The first axis of the transform, on a row of sources (0) and the rest
/// (∞): the squared distance to the nearest source, ∞ where none is.
fn nearest_source(row: &mut [f32]) {
    let mut last = f32::NEG_INFINITY;
    for (k, v) in row.iter_mut().enumerate() {
        if *v == 0.0 {
            last = k as f32;
        }
        *v = k as f32 - last;
    }
    let mut next = f32::INFINITY;
    for (k, v) in row.iter_mut().enumerate().rev() {
        if *v == 0.0 {
            next = k as f32;
        }
        let d = v.min(next - k as f32);
        *v = d * d;
    }
}

/// One line of the transform: its values gathered from a strided slice,
/// transformed ([`Envelope`]) and put back, the buffers reused.
struct Line {
    input: Vec<f32>,
    output: Vec<f32>,
    envelope: Envelope,
}

impl Line {
    fn new(n: usize) -> Self {
        Line {
            input: vec![0.0; n],
            output: vec![0.0; n],
            envelope: Envelope::new(n),
        }
    }

    /// Transforms `data[start + k·stride]` for k in 0..n.
    fn run(&mut self, data: &mut [f32], start: usize, stride: usize) {
        for (k, v) in self.input.iter_mut().enumerate() {
            *v = data[start + k * stride];
        }
        self.envelope.transform(&self.input, &mut self.output);
        for (k, &v) in self.output.iter().enumerate() {
            data[start + k * stride] = v;
        }
    }
}

/// The lower envelope of parabolas of the 1-D squared distance transform
/// (Felzenszwalb & Huttenlocher 2012, Algorithm 1), its buffers reused.
struct Envelope {
    v: Vec<usize>,
    z: Vec<f32>,
}

impl Envelope {
    fn new(n: usize) -> Self {
        Envelope {
            v: vec![0; n],
            z: vec![0.0; n + 1],
        }
    }

    /// out[q] = min_p (q − p)² + f[p]; infinite where every f is.
    fn transform(&mut self, f: &[f32], out: &mut [f32]) {
        let Some(first) = f.iter().position(|x| x.is_finite()) else {
            out.fill(f32::INFINITY);
            return;
        };
        let (v, z) = (&mut self.v, &mut self.z);
        let mut k = 0;
        v[0] = first;
        z[0] = f32::NEG_INFINITY;
        z[1] = f32::INFINITY;
        for q in first + 1..f.len() {
            if !f[q].is_finite() {
                continue;
            }
            let qf = q as f32;
            let s = loop {
                let p = v[k] as f32;
                let s = ((f[q] + qf * qf) - (f[v[k]] + p * p)) / (2.0 * (qf - p));
                if s <= z[k] {
                    k -= 1;
                } else {
                    break s;
                }
            };
            k += 1;
            v[k] = q;
            z[k] = s;
            z[k + 1] = f32::INFINITY;
        }
        k = 0;
        for (q, o) in out.iter_mut().enumerate() {
            while z[k + 1] < q as f32 {
                k += 1;
            }
            let d = q as f32 - v[k] as f32;
            *o = d * d + f[v[k]];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniform numbers in [0, 1) from a fixed linear congruential stream.
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f32 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// A closed latitude–longitude sphere of radius `r` about `c`.
    fn sphere(c: Vec3, r: f32, rings: u32, segments: u32) -> Mesh {
        let mut pos = Vec::new();
        for i in 0..=rings {
            let th = std::f32::consts::PI * i as f32 / rings as f32;
            for j in 0..segments {
                let ph = std::f32::consts::TAU * j as f32 / segments as f32;
                pos.push(c + r * Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin()));
            }
        }
        let mut tris = Vec::new();
        for i in 0..rings {
            for j in 0..segments {
                let k = |i: u32, j: u32| i * segments + j % segments;
                tris.push([k(i, j), k(i + 1, j), k(i + 1, j + 1)]);
                tris.push([k(i, j), k(i + 1, j + 1), k(i, j + 1)]);
            }
        }
        Mesh::new(pos, tris, None)
    }

    /// The squared distance from `p` to the segment [a, b].
    fn segment2(p: Vec3, a: Vec3, b: Vec3) -> f32 {
        let ab = b - a;
        let s = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
        (p - a - ab * s).length_squared()
    }

    /// The distance from `p` to the triangle: to its plane inside it, else
    /// to the nearest edge.
    fn triangle_distance(p: Vec3, [a, b, c]: [Vec3; 3]) -> f32 {
        let n = (b - a).cross(c - a);
        let inside = [(a, b), (b, c), (c, a)]
            .iter()
            .all(|&(u, w)| (w - u).cross(p - u).dot(n) >= 0.0);
        if inside && n.length_squared() > 0.0 {
            return ((p - a).dot(n) / n.length()).abs();
        }
        [(a, b), (b, c), (c, a)]
            .iter()
            .map(|&(u, w)| segment2(p, u, w))
            .fold(f32::INFINITY, f32::min)
            .sqrt()
    }

    fn exact(meshes: &[Mesh], p: Vec3) -> f32 {
        meshes
            .iter()
            .flat_map(|m| (0..m.triangle_count() as u32).map(|i| m.triangle(i)))
            .map(|t| triangle_distance(p, t))
            .fold(f32::INFINITY, f32::min)
    }

    /// The grid's bound never exceeds the distance to the nearest triangle,
    /// at random points in and around a sphere (the domain) with a second
    /// mesh partly outside the domain; and it is useful: deep inside the
    /// sphere within 2√3 cells of the distance. A transform that forgot an
    /// axis, a cell bound without the half-diagonals, or a domain without
    /// its faces' clamp (the second mesh) gives bounds above the distance
    /// at some of these points.
    #[test]
    fn the_bound_is_below_the_distance_and_close_to_it_inside() {
        let ball = sphere(Vec3::ZERO, 1.0, 24, 48);
        let near = sphere(Vec3::new(1.25, 1.25, 0.0), 0.3, 6, 12);
        let meshes = vec![ball, near];
        let g = DistanceGrid::build(&meshes, Vec3::splat(-1.0), Vec3::splat(1.0)).unwrap();
        let h = 2.0 / (CELLS - 4) as f32;
        let mut rng = Lcg(9);
        let (mut useful, mut inside) = (0, 0);
        // random points, and points by the domain's corner next to the
        // second mesh, nearer to it than to the first
        let corner = (0..4000).map(|i| {
            let (a, b, c) = ((i % 20) as f32, ((i / 20) % 20) as f32, (i / 400) as f32);
            Vec3::new(0.9 + a * 0.0065, 0.9 + b * 0.0065, c * 0.03 - 0.15)
        });
        let random = (0..20_000)
            .map(|_| Vec3::new(rng.next(), rng.next(), rng.next()) * 3.0 - Vec3::splat(1.5))
            .collect::<Vec<_>>();
        for p in random.into_iter().chain(corner) {
            let (b, d) = (g.bound(p), exact(&meshes, p));
            assert!(b <= d, "{p}: bound {b} > distance {d}");
            if p.length() < 0.8 {
                inside += 1;
                if b >= d - 2.0 * 3f32.sqrt() * h {
                    useful += 1;
                }
            }
        }
        assert!(inside > 1000 && useful == inside, "{useful} of {inside}");
        assert_eq!(g.bound(Vec3::splat(f32::NAN)), 0.0);
        assert_eq!(g.bound(Vec3::splat(5.0)), 0.0);
    }

    /// The 1-D transform against brute force, with unmarked stretches at
    /// both ends and none at all; the first axis's sweep on the rows of
    /// sources among them.
    #[test]
    fn the_line_transform_is_the_brute_force_minimum() {
        let inf = f32::INFINITY;
        let mut e = Envelope::new(9);
        let mut out = [0f32; 9];
        for f in [
            [inf, inf, 0.0, inf, 4.0, inf, inf, 0.0, inf],
            [inf, inf, 0.0, inf, 0.0, inf, inf, 0.0, inf],
            [inf; 9],
            [0.0, 1.0, 9.0, inf, inf, inf, inf, inf, 2.0],
        ] {
            e.transform(&f, &mut out);
            for (q, &o) in out.iter().enumerate() {
                let want = (0..9)
                    .map(|p| (q as f32 - p as f32).powi(2) + f[p])
                    .fold(inf, f32::min);
                assert_eq!(o, want, "{f:?} at {q}");
            }
            if f.iter().all(|&x| x == 0.0 || x == inf) {
                let mut row = f;
                nearest_source(&mut row);
                assert_eq!(row, out, "{f:?}");
            }
        }
    }
}
