//! The meshes `lucent bench` measures: displaced spheres of 20·4^level
//! triangles for the requested sizes, the Stanford bunny and a random
//! triangle soup, generated one at a time when their turn comes (so the
//! 5M-triangle sphere is not kept while the others run).

use std::sync::Arc;

use super::settings::Settings;
use lucent::geometry::Mesh;
use lucent::scene::shapes;
use lucent::Error;

/// The subdivision level of the displaced sphere nearest (in ratio) to `n`
/// triangles: 20·4^level.
pub fn sphere_level(n: usize) -> u32 {
    ((n as f64 / 20.0).log(4.0).round().max(0.0) as u32).min(10)
}

/// A benchmarked mesh.
pub struct BenchMesh {
    /// "sphere", "bunny" or "soup".
    pub kind: &'static str,
    pub mesh: Arc<Vec<Mesh>>,
}

impl BenchMesh {
    pub fn triangles(&self) -> usize {
        self.mesh[0].triangle_count()
    }
}

/// Which meshes to measure, in order: (kind, sphere level), the spheres
/// for the requested sizes, then the bunny (or a note that it is
/// missing), then the soup unless its size is 0.
pub(super) fn plan(s: &Settings, notes: &mut Vec<String>) -> Vec<(String, u32)> {
    let mut plan = sphere_plan(s, notes);
    match &s.bunny {
        Some(_) => plan.push(("bunny".into(), 0)),
        None => notes.push("bunny skipped: scenes/meshes/bunny.obj not found".into()),
    }
    if s.soup > 0 {
        plan.push(("soup".into(), 0));
    }
    plan
}

/// The distinct sphere levels of the requested sizes, smallest first
/// (noted when several sizes map to one sphere).
fn sphere_plan(s: &Settings, notes: &mut Vec<String>) -> Vec<(String, u32)> {
    let mut levels: Vec<u32> = s.sizes.iter().map(|&n| sphere_level(n)).collect();
    levels.sort_unstable();
    levels.dedup();
    if levels.len() < s.sizes.len() {
        notes.push(format!(
            "sizes map to displaced spheres of 20·4^level triangles; {} requested sizes gave {} distinct meshes",
            s.sizes.len(),
            levels.len()
        ));
    }
    levels
        .into_iter()
        .map(|l| ("sphere".to_string(), l))
        .collect()
}

/// Builds one mesh of the plan.
pub(super) fn generate(kind: &str, level: u32, s: &Settings) -> Result<BenchMesh, Error> {
    let (kind, mesh) = match kind {
        "sphere" => ("sphere", shapes::displaced_sphere(level, 0.1)),
        "soup" => {
            // Edge lengths up to 4/∛n: a soup about as dense as the sphere
            // of the same count is fine.
            let n = s.soup;
            ("soup", shapes::random_soup(n, 4.0 / (n as f32).cbrt(), 11))
        }
        "bunny" => {
            let path = s.bunny.as_ref().expect("bunny path");
            let text = std::fs::read_to_string(path)
                .map_err(|e| Error::Input(format!("{}: {e}", path.display())))?;
            let m = lucent::scene::load::load_obj(&text, path)
                .map_err(|e| Error::Input(e.to_string()))?;
            ("bunny", m)
        }
        _ => unreachable!(),
    };
    Ok(BenchMesh {
        kind,
        mesh: Arc::new(vec![mesh]),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_levels_are_nearest_in_ratio() {
        assert_eq!(sphere_level(1000), 3); // 1280
        assert_eq!(sphere_level(16_000), 5); // 20480
        assert_eq!(sphere_level(4_000_000), 9); // 5.2M
        assert_eq!(shapes::sphere(3).triangle_count(), 20 * 4usize.pow(3));
    }
}
