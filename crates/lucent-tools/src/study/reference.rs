//! The reference image every configuration is judged against: a long
//! render with seeds no configuration uses ([`REFERENCE_SEED_OFFSET`]), so
//! its noise is independent of the images it judges.
//!
//! It is cached as `DIR/reference-<hash>.exr` (with a `.txt` of how it was
//! made, and a `.png` preview), where the hash is 64-bit FNV-1a ([`Fnv1a`],
//! written here so it is stable across Rust versions, unlike
//! `DefaultHasher`) over the scene file's bytes, every mesh's transformed
//! vertex positions (so edits of an OBJ invalidate it too), and the
//! reference settings (integrator, spp, seed, resolution, path depth,
//! probe options).

use std::io::Write as _;
use std::path::PathBuf;

use super::config::{self, Overrides};
use super::input_file::{read_film, read_text};
use super::settings::Settings;
use super::{render_opts, runtime};
use lucent::accel::Accel;
use lucent::film::{self, Film, ToneMap};
use lucent::integrator::IntegratorKind;
use lucent::render;
use lucent::scene::Scene;
use lucent::Error;

/// The reference's seed is the study's seed plus this: another seed than
/// the ladder's, so its noise is independent of the images it judges.
pub const REFERENCE_SEED_OFFSET: u64 = 1_000_003;

/// How the reference image was made.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceInfo {
    pub path: PathBuf,
    pub hash: u64,
    pub integrator: IntegratorKind,
    pub spp: u32,
    pub seed: u64,
    /// Wall time of the render that made it (when it was made, possibly by
    /// an earlier run).
    pub seconds: f64,
    pub cached: bool,
    pub overrides: Overrides,
}

/// 64-bit FNV-1a (Fowler–Noll–Vo): a fixed, documented hash for cache keys.
#[derive(Clone, Copy, Debug)]
pub struct Fnv1a(pub u64);

impl Default for Fnv1a {
    fn default() -> Self {
        Fnv1a(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv1a {
    pub fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    /// A length-prefixed field, so ("ab", "c") and ("a", "bc") differ.
    pub fn field(&mut self, bytes: &[u8]) {
        self.write(&(bytes.len() as u64).to_le_bytes());
        self.write(bytes);
    }
}

/// The cache key of the reference render of `scene` under the settings.
pub(super) fn hash_for(s: &Settings, scene: &Scene, scene_text: &[u8], seed: u64) -> u64 {
    let ref_seed = seed.wrapping_add(REFERENCE_SEED_OFFSET);
    reference_hash(scene_text, scene, s.reference, s.reference_spp, ref_seed)
}

/// The cache key of the reference render.
fn reference_hash(
    scene_text: &[u8],
    scene: &Scene,
    integrator: IntegratorKind,
    spp: u32,
    seed: u64,
) -> u64 {
    let mut h = Fnv1a::default();
    h.field(b"lucent study reference v1");
    h.field(scene_text);
    for m in scene.meshes.iter() {
        h.field(&(m.positions().len() as u64).to_le_bytes());
        for p in m.positions() {
            for v in p.to_array() {
                h.write(&v.to_le_bytes());
            }
        }
    }
    let settings = format!(
        "integrator={} spp={spp} seed={seed} res={}x{} depth={} probe={}",
        config::integrator_name(integrator),
        scene.camera.width,
        scene.camera.height,
        scene.settings.max_depth,
        config::describe(&config::reference_overrides()),
    );
    h.field(settings.as_bytes());
    h.0
}

/// Loads or renders the reference.
pub(super) fn reference(
    s: &Settings,
    scene: &Scene,
    scene_text: &[u8],
    accel: &dyn Accel,
    seed: u64,
) -> Result<(Film, ReferenceInfo), Error> {
    let ref_seed = seed.wrapping_add(REFERENCE_SEED_OFFSET);
    let hash = reference_hash(scene_text, scene, s.reference, s.reference_spp, ref_seed);
    let path = s.out_dir.join(format!("reference-{hash:016x}.exr"));
    let meta = path.with_extension("txt");
    let overrides = config::reference_overrides();
    let mut info = ReferenceInfo {
        path: path.clone(),
        hash,
        integrator: s.reference,
        spp: s.reference_spp,
        seed: ref_seed,
        seconds: f64::NAN,
        cached: false,
        overrides: overrides.clone(),
    };
    let (w, h) = (scene.camera.width, scene.camera.height);
    if let Some(film) = read_film(&path, w, h).map_err(|e| Error::Input(e.to_string()))? {
        {
            info.cached = true;
            info.seconds = read_text(&meta)
                .ok()
                .flatten()
                .and_then(|t| {
                    t.lines().find_map(|l| {
                        l.strip_prefix("seconds=")
                            .and_then(|v| v.trim().parse().ok())
                    })
                })
                .unwrap_or(f64::NAN);
            return Ok((film, info));
        }
    }
    let ref_scene = config::apply(scene, &overrides).map_err(|e| Error::Input(e.to_string()))?;
    if s.progress {
        let _ = writeln!(
            std::io::stderr(),
            "reference: {} at {} spp, {}x{} → {}",
            config::integrator_name(s.reference),
            s.reference_spp,
            scene.camera.width,
            scene.camera.height,
            path.display()
        );
    }
    let (film, stats) = render::render(
        &ref_scene,
        accel,
        &render_opts(s, s.reference_spp, ref_seed, s.reference, None, s.progress),
    )
    .map_err(runtime)?;
    film.write_exr_and_preview(&path, ToneMap::Filmic, 0.0)
        .map_err(runtime)?;
    info.seconds = stats.seconds;
    let text = format!(
        "integrator={}\nspp={}\nseed={}\nseconds={}\nresolution={}x{}\nprobe={}\nthreads={}\n",
        config::integrator_name(s.reference),
        s.reference_spp,
        ref_seed,
        stats.seconds,
        film.width,
        film.height,
        config::describe(&overrides),
        stats.threads
    );
    film::atomic_write(&meta, |tmp| {
        std::io::Write::write_all(tmp, text.as_bytes()).map_err(|e| e.to_string())
    })
    .map_err(runtime)?;
    Ok((film, info))
}
