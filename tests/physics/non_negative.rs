//! No negative light: every light pass (the beauty, each light path, each
//! light group) of every shipped subsurface scene, rendered small with its
//! emitters and environment in light groups, at 1, 4 and 16 spp, is ≥ 0
//! in every pixel and channel — the default estimators, and at 4 and 16
//! spp the plane model at the camera vertex (`control_variate = true`,
//! `probe_pair = false`, `integrator::control_variate`: a choice between
//! mirrored probes, never a subtraction), and at 4 spp the tabulated
//! profile (`profile = "tabulated"`, whose densities come from a table).
//! Caught: an
//! additive control variate without a shadow ray, which goes below zero
//! where the model surface is lit and the real one is in shadow.

use std::path::Path;

use lucent::accel::{self, Backend};
use lucent::film::layers::LayerKind;
use lucent::film::passes::PassSet;
use lucent::render::{self, Job, RenderOptions};

/// The scene file's text with every emitter in the group `key` and the
/// environment in `sky`, at `w`×`h` pixels.
fn with_light_groups(text: &str, w: u32, h: u32) -> String {
    let mut out = String::new();
    for line in text.lines() {
        let t = line.trim_start();
        if t.starts_with("resolution") {
            out.push_str(&format!("resolution = [{w}, {h}]\n"));
            continue;
        }
        out.push_str(line);
        out.push('\n');
        if t.starts_with("emission") && !t.starts_with("emission_") {
            out.push_str("light_group = \"key\"\n");
        }
        if t == "[environment]" {
            out.push_str("light_group = \"sky\"\n");
        }
    }
    out
}

/// The light layers' negative values of `name` at `spp`: (layer, count,
/// minimum).
fn negatives(path: &Path, spp: u32, options: &str) -> Vec<(String, usize, f32)> {
    let text = std::fs::read_to_string(path).unwrap().replace(
        "type = \"subsurface\"\n",
        &format!("type = \"subsurface\"\n{options}"),
    );
    let scene = lucent::scene::load_str(&with_light_groups(&text, 48, 36), path).unwrap();
    let a = accel::build(&scene.meshes, Backend::Bvh).unwrap();
    let opts = RenderOptions {
        spp: Some(spp),
        ..RenderOptions::default()
    };
    let job = Job {
        passes: PassSet::parse_list("lightpaths,lightgroups").unwrap(),
        ..Job::full(&scene, spp)
    };
    let r = render::render_job(&scene, a.as_ref(), &opts, &job, None, &mut |_| Ok(())).unwrap();
    let (layers, _) = r.sums.layers(false).unwrap();
    let film = r.sums.film().unwrap();
    let mut found = Vec::new();
    let beauty: Vec<f32> = film.pixels.iter().flat_map(|p| p.to_array()).collect();
    let mut all = vec![("beauty".to_string(), beauty)];
    assert!(
        layers.iter().any(|l| l.name.starts_with("RGBA_")),
        "{}: no light group layer",
        path.display()
    );
    for l in layers.into_iter().filter(|l| l.kind == LayerKind::Light) {
        all.push((l.name, l.values));
    }
    for (name, values) in all {
        let neg: Vec<f32> = values.into_iter().filter(|v| *v < 0.0).collect();
        if !neg.is_empty() {
            let min = neg.iter().cloned().fold(0.0, f32::min);
            found.push((name, neg.len(), min));
        }
    }
    found
}

/// The first mesh file the scene at `path` names that does not exist: the
/// meshes `scripts/fetch-meshes.sh` fetches and the repository does not
/// hold (the dragon); the committed ones are always there.
fn missing_mesh(path: &Path, text: &str) -> Option<std::path::PathBuf> {
    text.lines()
        .filter_map(|l| l.trim_start().strip_prefix("file"))
        .filter_map(|rest| rest.split('"').nth(1))
        .map(|f| path.parent().unwrap().join(f))
        .find(|f| !f.exists())
}

/// The plane control variate, an option for every subsurface material.
const CV: &str = "control_variate = true\nprobe_pair = false\n";
/// The tabulated radial profile, another option for every subsurface
/// material.
const TABULATED: &str = "profile = \"tabulated\"\n";

#[test]
fn no_light_pass_of_a_shipped_subsurface_scene_goes_below_zero() {
    let mut bad = Vec::new();
    for entry in std::fs::read_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        if !text.contains("subsurface") {
            continue;
        }
        if let Some(mesh) = missing_mesh(&path, &text) {
            // a fetched, uncommitted mesh (scenes/meshes/README.md)
            eprintln!("{}: skipped, no {}", path.display(), mesh.display());
            continue;
        }
        let runs = [
            (1, ""),
            (4, ""),
            (16, ""),
            (4, CV),
            (16, CV),
            (4, TABULATED),
        ];
        for (spp, options) in runs {
            for n in negatives(&path, spp, options) {
                bad.push(format!(
                    "{} {options:?} at {spp} spp: {n:?}",
                    path.display()
                ));
            }
        }
    }
    assert!(bad.is_empty(), "negative light:\n{}", bad.join("\n"));
}
