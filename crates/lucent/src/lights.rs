//! Area lights: every triangle of an emissive object emits its object's
//! radiance from its front face. Next-event estimation picks a triangle in
//! proportion to its power (area × luminance) and a uniform point on it
//! (pbrt-v4 §12.5 and §12.6, without light BVHs).

use crate::geometry::Vec3;
pub use crate::sampling::luminance;
use crate::sampling::{uniform_triangle, Distribution1D};
use crate::scene::Scene;

/// The emissive triangles of a scene and the distribution NEE samples from.
#[derive(Clone, Debug, Default)]
pub struct LightSet {
    /// Each emissive triangle, in distribution order.
    tris: Vec<LightTri>,
    dist: Distribution1D,
    /// For each geom: index of its first triangle in `tris`, or None.
    first: Vec<Option<u32>>,
    /// For each triangle of `tris`, its geom (the object it belongs to).
    geoms: Vec<u32>,
}

/// What sampling a point on one emissive triangle needs, computed once so
/// next-event estimation and the MIS weight of emission found by lobe
/// sampling do not redo the cross product, area and pmf at every vertex.
#[derive(Clone, Copy, Debug)]
struct LightTri {
    a: Vec3,
    /// b − a and c − a.
    e1: Vec3,
    e2: Vec3,
    /// Unit front-face normal.
    normal: Vec3,
    radiance: Vec3,
    /// pmf / area: the area density of a point on it; 0 if degenerate.
    pdf_area: f32,
}
/// A point sampled on a light.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    pub point: Vec3,
    /// Front-face geometric normal at the point.
    pub normal: Vec3,
    pub radiance: Vec3,
    /// Probability density per unit area.
    pub pdf_area: f32,
    /// The emissive triangle it is on (see [`LightSet::geom_of`]).
    pub index: u32,
}

impl LightSet {
    pub fn new(scene: &Scene) -> Self {
        let mut tris = Vec::new();
        let mut weights = Vec::new();
        let mut first = vec![None; scene.meshes.len()];
        let mut geoms = Vec::new();
        for (g, (mesh, obj)) in scene.meshes.iter().zip(&scene.objects).enumerate() {
            let Some(le) = obj.emission else { continue };
            let power = luminance(le).max(le.max_element() * 1e-3) as f64;
            if power <= 0.0 {
                continue;
            }
            first[g] = Some(tris.len() as u32);
            for p in 0..mesh.triangle_count() as u32 {
                let [a, b, c] = mesh.triangle(p);
                let n = (b - a).cross(c - a);
                tris.push(LightTri {
                    a,
                    e1: b - a,
                    e2: c - a,
                    normal: n.normalize_or_zero(),
                    radiance: le,
                    pdf_area: 0.0,
                });
                weights.push(mesh.area(p) as f64 * power);
                geoms.push(g as u32);
            }
        }
        let dist = Distribution1D::new(&weights);
        for (i, t) in tris.iter_mut().enumerate() {
            let area = 0.5 * t.e1.cross(t.e2).length();
            let pmf = dist.pmf(i);
            t.pdf_area = if pmf > 0.0 && area > 0.0 {
                pmf / area
            } else {
                0.0
            };
        }
        LightSet {
            tris,
            dist,
            first,
            geoms,
        }
    }

    /// The number of emissive triangles.
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    pub fn is_empty(&self) -> bool {
        self.dist.is_empty()
    }

    /// Samples a light point with one selection number and two for the point.
    #[inline]
    pub fn sample(&self, u_pick: f32, u: [f32; 2]) -> Option<LightSample> {
        if self.is_empty() {
            return None;
        }
        let index = self.dist.sample_index(u_pick);
        let t = &self.tris[index];
        if t.pdf_area <= 0.0 {
            return None;
        }
        let [b1, b2] = uniform_triangle(u);
        Some(LightSample {
            point: t.a + t.e1 * b1 + t.e2 * b2,
            normal: t.normal,
            radiance: t.radiance,
            pdf_area: t.pdf_area,
            index: index as u32,
        })
    }

    /// The geom (object index) of emissive triangle `index` of a
    /// [`LightSample`].
    pub fn geom_of(&self, index: u32) -> u32 {
        self.geoms[index as usize]
    }

    /// The area density with which [`sample`](Self::sample) picks a point on
    /// triangle (geom, prim); 0 for non-emitters.
    pub(crate) fn pdf_area(&self, geom: u32, prim: u32) -> f32 {
        match self.first.get(geom as usize).copied().flatten() {
            Some(f) => self.tris[(f + prim) as usize].pdf_area,
            None => 0.0,
        }
    }
}
