//! Ray sets for benchmarking the backends, shared by `lucent bench` and the
//! criterion bench (`benches/accel.rs`).
//!
//! Every set is a list of [`Query`]s (a ray and the end of its interval),
//! generated deterministically from a seed, so two backends in one run see
//! exactly the same rays:
//!
//! - [`camera_rays`]: a pinhole camera's primary rays at the mesh, in
//!   32×32-pixel tiles (coherent: neighbours in the list are neighbours in
//!   the image, as a tiled renderer issues them);
//! - [`incoherent_rays`]: origins on a sphere around the mesh, each aimed at
//!   a random point of its bounding ball;
//! - [`shadow_segments`]: segments between two random surface points;
//! - [`probe_segments`]: the BSSRDF's probe segments, of length 2h ≤ 2 Rmax
//!   along the local normal near a random surface point.

use lucent::geometry::{Frame, Mesh, Ray, Vec3};
use lucent::sampling::{uniform_sphere, uniform_triangle, Rng};

/// One query: the ray and the end of its interval `[tmin, tmax]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Query {
    pub ray: Ray,
    pub tmin: f32,
    pub tmax: f32,
}

/// Camera tiles are this many pixels on a side; a tile is
/// `TILE * TILE` = 1024 consecutive queries.
pub(crate) const TILE: usize = 32;

/// The centre and radius of a sphere enclosing `mesh` (the centre of its
/// bounding box and half the box's diagonal).
pub(crate) fn bounding_sphere(mesh: &Mesh) -> (Vec3, f32) {
    let (lo, hi) = mesh.positions().iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    if lo.x > hi.x {
        return (Vec3::ZERO, 1.0);
    }
    ((lo + hi) * 0.5, ((hi - lo) * 0.5).length().max(1e-6))
}

/// `n` incoherent rays: origins uniform on the sphere of radius `3 radius`
/// about `center`, each aimed at a uniform random point of the ball of
/// `radius` about `center`. With centre 0 and radius 1 these are the rays of
/// the criterion bench (same sequence for the same seed).
pub fn incoherent_rays(n: usize, seed: u64, center: Vec3, radius: f32) -> Vec<Ray> {
    let mut rng = Rng::from_key(seed);
    (0..n)
        .map(|_| {
            let o = center + uniform_sphere(rng.uniform2()) * (3.0 * radius);
            let target = loop {
                let p = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE;
                if p.length_squared() <= 1.0 {
                    break center + p * radius;
                }
            };
            Ray::new(o, (target - o).normalize())
        })
        .collect()
}

/// [`incoherent_rays`] through `mesh`'s bounding sphere, as unbounded
/// queries.
pub fn incoherent(mesh: &Mesh, n: usize, seed: u64) -> Vec<Query> {
    let (c, r) = bounding_sphere(mesh);
    incoherent_rays(n, seed, c, r)
        .into_iter()
        .map(unbounded)
        .collect()
}

fn unbounded(ray: Ray) -> Query {
    Query {
        ray,
        tmin: 0.0,
        tmax: f32::INFINITY,
    }
}

/// About `n` primary rays (a square image of ⌈√n⌉² pixels, rounded up to
/// whole tiles and then truncated to `n`) of a pinhole camera at distance
/// `3 radius` from the centre of `mesh`'s bounding sphere, looking at it with
/// a field of view that just frames the sphere. Pixel centres, no jitter;
/// tile by tile, row by row within a tile.
pub fn camera_rays(mesh: &Mesh, n: usize) -> Vec<Query> {
    let (c, r) = bounding_sphere(mesh);
    let eye = c + Vec3::new(0.3, 0.4, 1.0).normalize() * (3.0 * r);
    let fwd = (c - eye).normalize();
    let frame = Frame::from_normal(fwd);
    // tan of the half-angle under which the bounding sphere is seen.
    let tan_half = (1.0f32 / 3.0).asin().tan();
    let side = ((n as f64).sqrt().ceil() as usize).max(1);
    let tiles = side.div_ceil(TILE);
    let mut out = Vec::with_capacity(n);
    'done: for ty in 0..tiles {
        for tx in 0..tiles {
            for y in ty * TILE..((ty + 1) * TILE).min(side) {
                for x in tx * TILE..((tx + 1) * TILE).min(side) {
                    if out.len() == n {
                        break 'done;
                    }
                    let sx = ((x as f32 + 0.5) / side as f32 * 2.0 - 1.0) * tan_half;
                    let sy = (1.0 - (y as f32 + 0.5) / side as f32 * 2.0) * tan_half;
                    let d = (fwd + frame.t * sx + frame.b * sy).normalize();
                    out.push(unbounded(Ray::new(eye, d)));
                }
            }
        }
    }
    out
}

/// Samples points uniformly by area on a mesh (a CDF over triangle areas).
pub(crate) struct SurfaceSampler<'a> {
    mesh: &'a Mesh,
    cdf: Vec<f64>,
}

impl<'a> SurfaceSampler<'a> {
    /// `None` if the mesh has no area.
    pub fn new(mesh: &'a Mesh) -> Option<Self> {
        let mut acc = 0.0f64;
        let cdf: Vec<f64> = (0..mesh.triangle_count() as u32)
            .map(|i| {
                acc += mesh.area(i) as f64;
                acc
            })
            .collect();
        (acc > 0.0).then_some(SurfaceSampler { mesh, cdf })
    }

    /// A point and the unit geometric normal of its triangle.
    pub fn sample(&self, rng: &mut Rng) -> (Vec3, Vec3) {
        let total = *self.cdf.last().unwrap();
        let u = rng.uniform_f64() * total;
        let i = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.cdf.len() - 1);
        let [a, b, c] = self.mesh.triangle(i as u32);
        let [s, t] = uniform_triangle(rng.uniform2());
        let p = a * (1.0 - s - t) + b * s + c * t;
        let n = (b - a).cross(c - a).normalize_or_zero();
        (p, n)
    }
}

/// `n` shadow segments: from one random surface point towards another, with
/// the interval shortened by 0.1 % of the length at both ends (as a renderer
/// offsets shadow rays so they do not hit their own endpoints).
pub fn shadow_segments(mesh: &Mesh, n: usize, seed: u64) -> Vec<Query> {
    let Some(s) = SurfaceSampler::new(mesh) else {
        return Vec::new();
    };
    let mut rng = Rng::from_key(seed);
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let (p, _) = s.sample(&mut rng);
        let (q, _) = s.sample(&mut rng);
        let len = (q - p).length();
        if len <= 0.0 {
            continue;
        }
        out.push(Query {
            ray: Ray::new(p, (q - p) / len),
            tmin: 1e-3 * len,
            tmax: (1.0 - 1e-3) * len,
        });
    }
    out
}

/// `n` probe segments as the BSSRDF issues them (`bssrdf::probe`): around a
/// random surface point xo with normal N, a disk offset of radius r (r
/// uniform in [0, Rmax), which like the diffusion profiles favours the
/// centre over a uniform disk) and a segment from `xo + offset + h N` to
/// `xo + offset − h N` with h = √(Rmax² − r²). The query is every hit on
/// mesh 0 with t in [0, 2h].
pub fn probe_segments(mesh: &Mesh, n: usize, seed: u64, rmax: f32) -> Vec<Query> {
    let Some(s) = SurfaceSampler::new(mesh) else {
        return Vec::new();
    };
    let mut rng = Rng::from_key(seed);
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let (xo, nrm) = s.sample(&mut rng);
        if nrm == Vec3::ZERO {
            continue;
        }
        let f = Frame::from_normal(nrm);
        let r = rmax * rng.uniform();
        let phi = std::f32::consts::TAU * rng.uniform();
        let h = (rmax * rmax - r * r).max(0.0).sqrt();
        let p0 = xo + (f.t * phi.cos() + f.b * phi.sin()) * r + nrm * h;
        out.push(Query {
            ray: Ray::new(p0, -nrm),
            tmin: 0.0,
            tmax: 2.0 * h,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use lucent::scene::shapes;

    #[test]
    fn incoherent_rays_aim_into_the_ball() {
        let c = Vec3::new(1.0, -2.0, 0.5);
        for r in incoherent_rays(1000, 7, c, 2.0) {
            assert!(((r.o - c).length() - 6.0).abs() < 1e-3);
            assert!((r.d.length() - 1.0).abs() < 1e-4);
            // Closest approach to the centre is within the ball.
            let along = (c - r.o).dot(r.d);
            assert!((r.o + r.d * along - c).length() <= 2.0 + 1e-3);
        }
    }

    #[test]
    fn unit_ball_rays_are_the_criterion_bench_sequence() {
        // The sequence the criterion bench (benches/accel.rs) was written
        // against, drawn inline: the shared generator must reproduce it.
        let mut rng = Rng::from_key(1);
        let old: Vec<Ray> = (0..200)
            .map(|_| {
                let o = uniform_sphere(rng.uniform2()) * 3.0;
                let target = loop {
                    let p =
                        Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE;
                    if p.length_squared() <= 1.0 {
                        break p;
                    }
                };
                Ray::new(o, (target - o).normalize())
            })
            .collect();
        assert_eq!(incoherent_rays(200, 1, Vec3::ZERO, 1.0), old);
    }

    #[test]
    fn camera_rays_are_tiled_and_frame_the_sphere() {
        let m = shapes::sphere(3);
        let q = camera_rays(&m, 4096);
        assert_eq!(q.len(), 4096);
        // First tile: 32 pixels of row 0, then row 1 starts at x = 0 again.
        assert_eq!(q[0].ray.o, q[4095].ray.o);
        let d0 = q[0].ray.d;
        let d32 = q[32].ray.d;
        let d1 = q[1].ray.d;
        assert!((d0 - d1).length() < (d0 - q[1023].ray.d).length());
        assert!((d0 - d32).length() < 0.05);
        // Every ray passes within the bounding sphere's cone; the centre
        // pixel hits the sphere.
        let (c, r) = bounding_sphere(&m);
        let hits = q
            .iter()
            .filter(|x| (x.ray.o + x.ray.d * (c - x.ray.o).dot(x.ray.d) - c).length() < r * 0.999)
            .count();
        assert!(hits > 4096 * 6 / 10 && hits < 4096 * 85 / 100, "{hits}");
    }

    #[test]
    fn shadow_segments_join_surface_points() {
        let m = shapes::sphere(3);
        for q in shadow_segments(&m, 500, 3) {
            let p = q.ray.o;
            let e = q.ray.at(q.tmax / (1.0 - 1e-3));
            assert!((p.length() - 1.0).abs() < 0.02 && (e.length() - 1.0).abs() < 0.02);
            assert!(q.tmin > 0.0 && q.tmin < q.tmax);
        }
    }

    #[test]
    fn probe_segments_cross_the_surface_within_rmax() {
        let m = shapes::sphere(4);
        let rmax = 0.05;
        for q in probe_segments(&m, 500, 5, rmax) {
            assert!(q.tmax <= 2.0 * rmax + 1e-6);
            // Endpoints on either side of the unit sphere (it is flat
            // enough at this scale) unless the segment is very short.
            let a = q.ray.o.length() - 1.0;
            let b = q.ray.at(q.tmax).length() - 1.0;
            if q.tmax > 0.02 {
                assert!(a > 0.0 && b < 0.0, "{a} {b}");
            }
        }
    }
}
