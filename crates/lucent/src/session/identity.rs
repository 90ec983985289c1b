//! What a render's outputs record about it: a part's [`Identity`] (what
//! must agree for parts to merge or a render to resume) and a frame's EXR
//! header (docs/output.md).

use std::path::Path;

use super::provenance;
use crate::accel::Backend;
use crate::error::Error;
use crate::farm::part::{self, Identity};
use crate::film::exr_layers::{FrameHeader, OutputOptions};
use crate::film::pass_layout::Layout;
use crate::film::passes::PassSet;
use crate::integrator::{plan, IntegratorKind};
use crate::render::Settings;
use crate::sampling::SamplerKind;
use crate::scene::Scene;

/// The integrator's name on the command line and in headers.
pub fn integrator_name(i: IntegratorKind) -> &'static str {
    match i {
        IntegratorKind::Path => "path",
        #[cfg(feature = "subsurface")]
        IntegratorKind::RandomWalk => "randomwalk",
    }
}

/// The identity of a render of `scene` (read from `scene_bytes`) with
/// `settings` on `backend`, the subsurface `options` (canonical text),
/// passes `layout` and file options `out`.
pub fn identity(
    scene_bytes: &[u8],
    scene: &Scene,
    settings: &Settings,
    backend: Backend,
    options: &str,
    layout: Option<&Layout>,
    out: &OutputOptions,
) -> Identity {
    Identity {
        passes: part::passes_text(layout),
        names: part::names_text(layout),
        output: part::output_text(out),
        version: env!("CARGO_PKG_VERSION").into(),
        scene_hash: crate::farm::scene_hash(scene_bytes, scene),
        seed: settings.seed,
        spp: settings.spp,
        options: format!(
            "accel={} integrator={} sampler={} {options}",
            backend.name(),
            integrator_name(settings.integrator),
            settings.sampler.name()
        )
        .trim_end()
        .into(),
        frame: (scene.camera.width, scene.camera.height),
    }
}

/// The plan a render of `scene` with `integrator`, `sampler` and `passes`
/// follows.
pub fn render_plan(
    scene: &Scene,
    integrator: IntegratorKind,
    sampler: SamplerKind,
    passes: PassSet,
) -> plan::Explanation {
    plan::Explanation::new(
        scene,
        &plan::PlanOptions {
            integrator,
            passes,
            sampler: Some(sampler),
            ..plan::PlanOptions::default()
        },
    )
}

/// What the EXR header records about this render (docs/output.md): the
/// scene file (`scene_text`) and its SHA-256, samples, seed, sampler, depth,
/// backend that ran (`accel_name`, a resolved `backend`) and its version,
/// integrator, every subsurface material's sampling options (named by the
/// objects that use it), the plan with its `passes`, this host, the build
/// and the camera. The caller adds the date and render time.
pub(crate) fn frame_header(
    scene_path: &Path,
    scene_text: &str,
    scene: &Scene,
    accel_name: &str,
    backend: Backend,
    settings: &Settings,
    passes: PassSet,
) -> Result<FrameHeader, Error> {
    use sha2::{Digest, Sha256};
    let (world_to_camera, world_to_ndc) = provenance::camera_matrices(&scene.camera);
    let sha: String = Sha256::digest(scene_text.as_bytes())
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    Ok(FrameHeader {
        scene_path: Some(scene_path.display().to_string()),
        scene_sha256: Some(sha),
        spp: Some(settings.spp),
        seed: Some(settings.seed),
        max_depth: Some(settings.max_depth),
        backend: Some(accel_name.into()),
        backend_version: Some(backend_version(backend)?),
        integrator: Some(integrator_name(settings.integrator).into()),
        sampler: Some(settings.sampler.name().into()),
        sampling: sampling(scene),
        plan: Some(render_plan(scene, settings.integrator, settings.sampler, passes).to_json()),
        render_seconds: None,
        date: None,
        hosts: vec![provenance::host_name()],
        build: Some(provenance::build_id().into()),
        world_to_camera: Some(world_to_camera),
        world_to_ndc: Some(world_to_ndc),
    })
}

/// Each subsurface material's sampling options, named by the objects
/// that use it (materials no object uses are left out).
fn sampling(scene: &Scene) -> Vec<(String, String)> {
    #[cfg_attr(not(feature = "subsurface"), allow(unused_mut))]
    let mut sampling = Vec::new();
    #[cfg(feature = "subsurface")]
    for (i, m) in scene.materials.iter().enumerate() {
        let crate::materials::Material::Subsurface(ss) = m.base() else {
            continue;
        };
        let users: Vec<String> = scene
            .objects
            .iter()
            .filter(|o| o.material == i)
            .map(|o| match o.walk {
                true => format!("{} (random walk)", o.name),
                false => o.name.clone(),
            })
            .collect();
        if !users.is_empty() {
            sampling.push((users.join(","), ss.sampling_description()));
        }
    }
    #[cfg(not(feature = "subsurface"))]
    let _ = scene;
    sampling
}

/// The backend's version: the Embree in use (the one `backend` resolves
/// to), or lucent's for its own BVH.
pub fn backend_version(backend: Backend) -> Result<String, Error> {
    Ok(match backend.resolve()? {
        #[cfg(feature = "embree")]
        Backend::Embree3 => format!("Embree {}", crate::accel::embree::version()),
        #[cfg(feature = "embree4")]
        Backend::Embree4 => format!("Embree {}", crate::accel::embree4::version()?),
        _ => format!("lucent {}", env!("CARGO_PKG_VERSION")),
    })
}
