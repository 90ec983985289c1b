//! Area lights: every triangle of an emissive object emits its object's
//! radiance from its front face. Next-event estimation picks a triangle in
//! proportion to its power (area × luminance) and a uniform point on it
//! (pbrt-v4 §12.5 and §12.6, without light BVHs).

use crate::geometry::{Mesh, Vec3};
use crate::sampling::{uniform_triangle, Distribution1D};
use crate::scene::Scene;

/// The emissive triangles of a scene and the distribution NEE samples from.
#[derive(Clone, Debug, Default)]
pub struct LightSet {
    /// (geom, prim) of each emissive triangle, in distribution order.
    tris: Vec<(u32, u32)>,
    dist: Distribution1D,
    /// For each geom: index of its first triangle in `tris`, or None.
    first: Vec<Option<u32>>,
}

/// A point sampled on a light.
pub struct LightSample {
    pub point: Vec3,
    /// Front-face geometric normal at the point.
    pub normal: Vec3,
    pub radiance: Vec3,
    /// Probability density per unit area.
    pub pdf_area: f32,
}

pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

impl LightSet {
    pub fn new(scene: &Scene) -> Self {
        let mut tris = Vec::new();
        let mut weights = Vec::new();
        let mut first = vec![None; scene.meshes.len()];
        for (g, (mesh, obj)) in scene.meshes.iter().zip(&scene.objects).enumerate() {
            let Some(le) = obj.emission else { continue };
            let power = luminance(le).max(le.max_element() * 1e-3) as f64;
            if power <= 0.0 {
                continue;
            }
            first[g] = Some(tris.len() as u32);
            for p in 0..mesh.triangle_count() as u32 {
                tris.push((g as u32, p));
                weights.push(mesh.area(p) as f64 * power);
            }
        }
        LightSet {
            tris,
            dist: Distribution1D::new(&weights),
            first,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.dist.is_empty()
    }

    /// Samples a light point with one selection number and two for the point.
    pub fn sample(&self, scene: &Scene, u_pick: f32, u: [f32; 2]) -> Option<LightSample> {
        if self.is_empty() {
            return None;
        }
        let (i, pmf) = self.dist.sample(u_pick);
        let (g, p) = self.tris[i];
        let mesh = &scene.meshes[g as usize];
        let [a, b, c] = mesh.triangle(p);
        let [b1, b2] = uniform_triangle(u);
        let point = a * (1.0 - b1 - b2) + b * b1 + c * b2;
        let n = (b - a).cross(c - a);
        let area = 0.5 * n.length();
        if pmf <= 0.0 || area <= 0.0 {
            return None;
        }
        Some(LightSample {
            point,
            normal: n.normalize(),
            radiance: scene.objects[g as usize].emission.unwrap_or(Vec3::ZERO),
            pdf_area: pmf / area,
        })
    }

    /// The area density with which [`sample`](Self::sample) picks a point on
    /// triangle (geom, prim); 0 for non-emitters.
    pub fn pdf_area(&self, meshes: &[Mesh], geom: u32, prim: u32) -> f32 {
        match self.first.get(geom as usize).copied().flatten() {
            Some(f) => {
                let area = meshes[geom as usize].area(prim);
                if area > 0.0 {
                    self.dist.pmf((f + prim) as usize) / area
                } else {
                    0.0
                }
            }
            None => 0.0,
        }
    }
}
