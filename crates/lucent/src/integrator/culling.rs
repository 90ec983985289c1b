//! Ray queries answered without the accelerator: rays that provably meet
//! nothing, so the environment (or an unshadowed light) is the answer and
//! Embree or the BVH is not asked.
//!
//! **The proof.** A ray segment o + t·d, t ∈ [0, t_max], meets no object
//! when for every object one of these holds:
//!
//! 1. the segment misses the object's bounding box, padded (below);
//! 2. the ray starts on the object, on a convex-outside side of it
//!    ([`crate::geometry::convex`]) and leaves towards that side: its origin is
//!    offset from the triangle's plane by at least the scene's ray epsilon
//!    ε_ray ([`offset_along`](super::interaction::offset_along)), more than
//!    the convexity tolerance τ = ε_ray/4, and it moves away from the
//!    plane, which the whole object lies behind (within τ);
//! 3. the segment ends on the object, on a convex-outside side, arriving
//!    from that side (a shadow ray to a light sample on the light's front
//!    face, which next-event estimation has checked faces the ray): every
//!    point before the end is strictly in front of that triangle's plane.
//!
//! Each is a sufficient condition, so a ray reported as missing
//! everything meets nothing the accelerator could have returned — up to
//! the accelerator's own rounding, which the padding covers (an
//! accelerator "hit" within τ of a triangle's plane, behind a convex
//! object's surface, would be a self-intersection, not an occluder). The
//! estimator, its randoms and its pixels are unchanged.
//!
//! **When it pays.** On a translucent object seen alone against an
//! environment — a look-development sphere, a product shot — most rays
//! that leave the object (the coat's mirror, the continuation from the
//! entry point, the shadow rays to a light) meet nothing else, and so do
//! camera rays beside it. Measured in docs/performance.md ("Rays answered
//! by bounds"). A scene with more than [`MAX_OBJECTS`] objects is not
//! culled (the test is a loop over the objects' boxes); where boxes
//! overlap the rays, the test costs a few box tests and the query is made.
//!
//! **Padding.** Boxes grow by 1e-4 of the scene's extent on every side
//! (ε_ray is 1e-6 of it): the box test is f32 slab arithmetic with
//! relative errors ~1e-7, so no rounding can turn a box the segment
//! touches into a miss. An axis the ray does not move along (a direction
//! component of exactly 0) is decided exactly: the origin's coordinate is
//! inside the box's slab or not.

use crate::geometry::{Mesh, Ray, Vec3};

/// Scenes with more objects than this are not culled.
pub const MAX_OBJECTS: usize = 16;

/// The objects' padded bounding boxes and convex-outside sides, per
/// object (the accelerator's `geom`).
#[derive(Clone, Debug)]
pub struct Culling {
    boxes: Vec<[Vec3; 2]>,
    /// `[front, back]`: whether that side of the object is convex-outside.
    outside: Vec<[bool; 2]>,
}

impl Culling {
    /// For `meshes` of a scene of size `extent` with ray epsilon
    /// `ray_epsilon` ([`super::Context::ray_epsilon`]); None for scenes of
    /// more than [`MAX_OBJECTS`] objects.
    pub fn new(meshes: &[Mesh], extent: f32, ray_epsilon: f32) -> Option<Self> {
        if meshes.len() > MAX_OBJECTS {
            return None;
        }
        let pad = Vec3::splat(extent * 1e-4);
        let tol = 0.25 * ray_epsilon as f64;
        Some(Culling {
            boxes: meshes
                .iter()
                .map(|m| match m.bounds() {
                    Some((lo, hi)) => [lo - pad, hi + pad],
                    // no vertices: an empty box, which every ray misses
                    None => [Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)],
                })
                .collect(),
            outside: meshes
                .iter()
                .map(|m| crate::geometry::convex::outside_sides(m, tol))
                .collect(),
        })
    }

    /// `geom` if the side of it a ray starts from or ends on (`front`: the
    /// side its front-face normal points to) is convex-outside; the ray
    /// must leave towards that side or arrive from it (module docs, 2 and
    /// 3).
    #[inline]
    pub fn outside(&self, geom: u32, front: bool) -> Option<u32> {
        self.outside[geom as usize][usize::from(!front)].then_some(geom)
    }

    /// How many objects have a convex-outside side.
    pub fn convex_count(&self) -> usize {
        self.outside.iter().filter(|s| s[0] || s[1]).count()
    }

    /// Whether the segment `ray.o + t·ray.d`, t ∈ [0, `t_max`], provably
    /// meets no object, the objects in `skip` ([`Culling::outside`] of its
    /// start and end) aside.
    #[inline]
    pub fn misses(&self, ray: &Ray, t_max: f32, skip: [Option<u32>; 2]) -> bool {
        let inv = ray.d.recip();
        // Axes the ray moves along; on the others its coordinate is fixed.
        let live = ray.d.cmpne(Vec3::ZERO);
        let (inf, neg_inf) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for (g, b) in self.boxes.iter().enumerate() {
            let g = Some(g as u32);
            if g == skip[0] || g == skip[1] {
                continue;
            }
            let t0 = (b[0] - ray.o) * inv;
            let t1 = (b[1] - ray.o) * inv;
            let inside = ray.o.cmpge(b[0]) & ray.o.cmple(b[1]);
            let near = Vec3::select(live, t0.min(t1), Vec3::select(inside, neg_inf, inf));
            let far = Vec3::select(live, t0.max(t1), Vec3::select(inside, inf, neg_inf));
            // A NaN lane (0·∞ where a box face passes through the origin
            // of a ray with a subnormal direction component) is either
            // dropped by the reductions, which only widens the interval,
            // or reaches the comparison, which is then false: it never
            // proves a miss.
            let enter = near.max_element().max(0.0);
            let exit = far.min_element().min(t_max);
            let proven = enter > exit;
            if !proven {
                return false;
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::shapes;

    fn moved(mut m: Mesh, by: Vec3) -> Mesh {
        m.transform(|p| p + by, |n| n);
        m
    }

    fn scene() -> Culling {
        // A unit sphere at the origin and a quad (z = 0 plane, facing +z)
        // at x = 3.
        let meshes = [
            shapes::sphere(3),
            moved(shapes::quad(), Vec3::new(3.0, 0.0, 0.0)),
        ];
        Culling::new(&meshes, 5.0, 5e-6).unwrap()
    }

    #[test]
    fn rays_that_miss_every_box_are_proven_and_others_are_not() {
        let c = scene();
        let up = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::Z);
        assert!(c.misses(&up, f32::INFINITY, [None, None]));
        let at_sphere = Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
        assert!(!c.misses(&at_sphere, f32::INFINITY, [None, None]));
        // Short of the sphere's box: a miss; reaching it: not.
        assert!(c.misses(&at_sphere, 3.9, [None, None]));
        assert!(!c.misses(&at_sphere, 4.1, [None, None]));
        // Parallel to an axis, inside the box's slab on the others.
        let along = Ray::new(Vec3::new(-5.0, 0.0, 0.0), Vec3::X);
        assert!(!c.misses(&along, f32::INFINITY, [None, None]));
        let beside = Ray::new(Vec3::new(-5.0, 2.0, 0.0), Vec3::X);
        assert!(c.misses(&beside, f32::INFINITY, [None, None]));
        // Parallel, just inside the padded slab: not a miss.
        let grazing = Ray::new(Vec3::new(-5.0, 1.0 + 4e-4, 0.0), Vec3::X);
        assert!(!c.misses(&grazing, f32::INFINITY, [None, None]));
    }

    #[test]
    fn a_ray_leaving_a_convex_object_skips_it_and_no_other() {
        let c = scene();
        assert_eq!(c.convex_count(), 2);
        // The sphere's front (outward) side only; the quad's both.
        assert_eq!(c.outside(0, true), Some(0));
        assert_eq!(c.outside(0, false), None);
        assert_eq!(c.outside(1, false), Some(1));
        // From the sphere's top, up: proven; sideways towards the quad: no.
        let o = Vec3::new(0.0, 0.0, 1.0 + 1e-5);
        let up = Ray::new(o, Vec3::new(0.0, 0.3, 1.0));
        assert!(!c.misses(&up, f32::INFINITY, [None, None]));
        assert!(c.misses(&up, f32::INFINITY, [c.outside(0, true), None]));
        let to_quad = Ray::new(o, Vec3::new(3.0, 0.0, -1.0));
        assert!(!c.misses(&to_quad, f32::INFINITY, [c.outside(0, true), None]));
        // A shadow ray ending on the quad, from the sphere: both skipped.
        assert!(c.misses(
            &to_quad,
            1.0 - 1e-4,
            [c.outside(0, true), c.outside(1, true)]
        ));
    }

    #[test]
    fn a_zero_direction_never_proves_a_miss_inside_a_box() {
        let c = scene();
        let still = Ray::new(Vec3::new(0.0, 0.0, 0.5), Vec3::ZERO);
        assert!(!c.misses(&still, f32::INFINITY, [None, None]));
    }

    #[test]
    fn a_non_convex_object_is_never_skipped_and_large_scenes_are_not_culled() {
        let dented = shapes::displaced_sphere(3, 0.2);
        let c = Culling::new(&[dented], 2.0, 2e-6).unwrap();
        assert_eq!(c.outside(0, true), None);
        assert_eq!(c.outside(0, false), None);
        let many: Vec<Mesh> = (0..MAX_OBJECTS + 1).map(|_| shapes::quad()).collect();
        assert!(Culling::new(&many, 2.0, 2e-6).is_none());
    }
}
