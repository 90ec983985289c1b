//! The passes (AOVs) the integrator measures (`crates/lucent/src/integrator/aov/`),
//! through the scene loader and `render_passes`:
//!
//! - the light paths and the light groups each sum to the beauty, pixel by
//!   pixel (relative 1e-5), on a scene with every kind of event (diffuse,
//!   glass, smooth- and rough-coated subsurface, visible emitter and sky),
//!   with both integrators;
//! - ground truths of the split: a diffuse plane under a uniform sky is all
//!   `diffuse_direct` (pixel = ρ L); a scene of uncoated subsurface objects
//!   puts everything in `sss_*`; one without subsurface has `sss_*` zero;
//! - data: Z, P, N, albedo and IDs of a plane at a known distance and of a
//!   sphere; coverage sums to 1 where every sample hits;
//! - noise: the variance pass agrees with the spread of the pixel mean
//!   across seeds;
//! - every pass is bitwise the same for 1 and 2 threads;
//! - bad pass names and light groups are bad input (exit 2, located).

use std::path::Path;
use std::process::Command;

use lucent::accel::{self, Backend};
use lucent::film::layers::Layer;
use lucent::film::passes::{PassSet, LIGHT_PATHS};
use lucent::integrator::IntegratorKind;
use lucent::render::{render_passes, RenderOptions, RenderOutput};
use lucent::scene::{load_str, Scene};

/// Every kind of event: a diffuse floor, a glass sphere, a marble sphere
/// (smooth coat), a wax box (rough coat; diffuse boundary in the random
/// walk), a visible emitting bulb (no group: `default`), an area light in
/// group `key` and a sky in group `sky`.
const MIXED: &str = r#"
units_per_mm = 0.1
[camera]
look_from = [0, 3, 8]
look_at = [0, 1, 0]
fov_y = 40
resolution = [48, 32]
[render]
spp = 8
max_depth = 6
seed = 3
[environment]
radiance = [0.2, 0.25, 0.3]
light_group = "sky"
[materials.floor]
type = "diffuse"
albedo = [0.6, 0.6, 0.6]
[materials.glass]
type = "dielectric"
eta = 1.5
[materials.marble]
type = "subsurface"
preset = "marble"
[materials.wax]
type = "subsurface"
albedo = [0.9, 0.7, 0.5]
dmfp = [4.0, 2.0, 1.0]
roughness = 0.3
boundary = "diffuse"
[materials.lamp]
type = "diffuse"
albedo = [0, 0, 0]
[[shapes]]
name = "floor"
type = "quad"
material = "floor"
scale = 6
rotate = [[-90, 1, 0, 0]]
[[shapes]]
type = "sphere"
subdivisions = 2
material = "glass"
translate = [-2, 1, 0]
[[shapes]]
name = "marble ball"
type = "sphere"
subdivisions = 3
material = "marble"
translate = [0, 1, 0]
[[shapes]]
type = "box"
material = "wax"
scale = 0.7
translate = [2, 0.7, 0]
[[shapes]]
name = "bulb"
type = "sphere"
subdivisions = 1
material = "lamp"
emission = [3, 3, 2]
scale = 0.3
translate = [1.2, 2.6, -1]
[[shapes]]
name = "key"
type = "quad"
material = "lamp"
emission = [6, 6, 6]
light_group = "key"
rotate = [[90, 1, 0, 0]]
translate = [0, 5, 3]
"#;

fn scene(text: &str) -> Scene {
    load_str(text, Path::new("aov-test.toml")).unwrap()
}

fn render_with(
    scene: &Scene,
    passes: PassSet,
    integrator: IntegratorKind,
    threads: usize,
    seed: Option<u64>,
) -> RenderOutput {
    let accel = accel::build(&scene.meshes, Backend::Bvh).unwrap();
    let opts = RenderOptions {
        threads: Some(threads),
        integrator,
        seed,
        ..RenderOptions::default()
    };
    render_passes(scene, accel.as_ref(), &opts, passes).unwrap()
}

fn render(scene: &Scene, passes: &str) -> RenderOutput {
    let set = PassSet::parse_list(passes).unwrap();
    render_with(scene, set, IntegratorKind::Path, 2, None)
}

fn layer<'a>(out: &'a RenderOutput, name: &str) -> &'a Layer {
    out.layers
        .iter()
        .find(|l| l.name == name)
        .unwrap_or_else(|| panic!("no layer {name}"))
}

/// Per pixel and channel, the layers `names` sum to the beauty within
/// relative 1e-5 (and to within 1e-9 where it is 0).
fn assert_sum_is_beauty(out: &RenderOutput, names: &[&str], what: &str) {
    for (p, b) in out.film.pixels.iter().enumerate() {
        for c in 0..3 {
            let b = b[c] as f64;
            let s: f64 = names.iter().map(|n| layer(out, n).get(p, c) as f64).sum();
            assert!(
                (s - b).abs() <= 1e-5 * b.abs() + 1e-9,
                "{what}: pixel {p} channel {c}: passes sum to {s}, beauty {b}"
            );
        }
    }
}

/// The largest value of a layer.
fn max(l: &Layer) -> f32 {
    l.values.iter().fold(0.0f32, |m, v| m.max(*v))
}

fn light_path_names() -> Vec<&'static str> {
    LIGHT_PATHS.iter().map(|p| p.name()).collect()
}

/// The light paths and the light groups `groups` each sum to the beauty
/// of `out`, and, so that neither sum is vacuous, each of them gets light.
fn assert_lit_passes_sum_to_the_beauty(out: &RenderOutput, groups: &[&str], what: &str) {
    assert_sum_is_beauty(out, &light_path_names(), &format!("{what}: light paths"));
    assert_sum_is_beauty(out, groups, &format!("{what}: light groups"));
    for &name in light_path_names().iter().chain(groups) {
        assert!(max(layer(out, name)) > 0.0, "{what}: {name} is black");
    }
}

#[test]
fn light_paths_and_light_groups_sum_to_the_beauty_with_both_integrators() {
    let s = scene(MIXED);
    let groups = ["RGBA_default", "RGBA_key", "RGBA_sky"];
    for integrator in [IntegratorKind::Path, IntegratorKind::RandomWalk] {
        let out = render_with(&s, PassSet::all(), integrator, 2, None);
        let what = format!("{integrator:?}");
        assert_lit_passes_sum_to_the_beauty(&out, &groups, &what);
        // The top row sees the sky only: all of it background, group sky.
        for x in 0..48 {
            for c in 0..3 {
                let b = out.film.pixels[x][c];
                assert_eq!(layer(&out, "background").get(x, c), b);
                assert_eq!(layer(&out, "RGBA_sky").get(x, c), b);
                assert_eq!(layer(&out, "RGBA_key").get(x, c), 0.0);
            }
        }
    }
}

/// [`MIXED`] under the lookdev scene's studio map (group `sky`) instead of
/// its constant sky, which only escaping rays find: the image's light
/// sampled at every vertex (diffuse, coat, the probe's entry points) is
/// filed in the passes too, so light paths and groups still sum to the
/// beauty. Caught: the environment's light sample not recorded
/// (`record_environment` without its `rec.light`).
#[test]
fn light_paths_and_light_groups_sum_to_the_beauty_under_an_environment_image() {
    let text = MIXED.replace(
        "radiance = [0.2, 0.25, 0.3]",
        "file = \"lookdev/studio.exr\"\nintensity = 0.3",
    );
    let at = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/aov-test.toml");
    let s = load_str(&text, &at).unwrap();
    let groups = ["RGBA_default", "RGBA_key", "RGBA_sky"];
    for integrator in [IntegratorKind::Path, IntegratorKind::RandomWalk] {
        let out = render_with(&s, PassSet::all(), integrator, 2, None);
        let what = format!("{integrator:?} under the image");
        assert_lit_passes_sum_to_the_beauty(&out, &groups, &what);
    }
}

/// [`MIXED`] with a sun (group `sun`), a sphere light (group `key`) and a
/// spot light (no group: `default`) besides its emitters.
fn mixed_with_lights() -> String {
    format!(
        "{MIXED}
[[lights]]
type = \"distant\"
direction = [-1, -2, -0.5]
angle = 5
irradiance = [2, 1.8, 1.5]
light_group = \"sun\"
[[lights]]
type = \"sphere\"
position = [-1, 3, 1]
radius = 0.2
radiance = [20, 20, 20]
light_group = \"key\"
[[lights]]
type = \"sphere\"
position = [2, 3, 1]
radius = 0.05
power = [1, 1, 1]
spot_direction = [0, -1, -0.3]
spot_angle = 30
spot_falloff = 10
"
    )
}

#[test]
fn light_paths_and_light_groups_sum_to_the_beauty_with_sphere_spot_and_distant_lights() {
    let s = scene(&mixed_with_lights());
    let groups = ["RGBA_default", "RGBA_key", "RGBA_sky", "RGBA_sun"];
    for integrator in [IntegratorKind::Path, IntegratorKind::RandomWalk] {
        let out = render_with(&s, PassSet::all(), integrator, 2, None);
        let what = format!("{integrator:?}");
        assert_lit_passes_sum_to_the_beauty(&out, &groups, &what);
    }
}

#[test]
fn each_light_group_holds_the_light_of_its_own_lights() {
    // One colour per group: key red, the ungrouped bulb green, the sky
    // blue. Transport never moves light between channels, so each group's
    // layer is its channel of the beauty, and exactly black elsewhere.
    let text = MIXED
        .replace("emission = [6, 6, 6]", "emission = [6, 0, 0]")
        .replace("emission = [3, 3, 2]", "emission = [0, 3, 0]")
        .replace("radiance = [0.2, 0.25, 0.3]", "radiance = [0, 0, 0.3]");
    let s = scene(&text);
    for integrator in [IntegratorKind::Path, IntegratorKind::RandomWalk] {
        let out = render_with(
            &s,
            PassSet::named("lightgroups").unwrap(),
            integrator,
            2,
            None,
        );
        for (g, name) in ["RGBA_key", "RGBA_default", "RGBA_sky"].iter().enumerate() {
            let l = layer(&out, name);
            assert!(max(l) > 0.0, "{integrator:?}: {name} is black");
            for (p, b) in out.film.pixels.iter().enumerate() {
                for c in 0..3 {
                    let (v, want) = (l.get(p, c), if c == g { b[c] } else { 0.0 });
                    // (the beauty sums a coat split's branches apart: ulps;
                    // a pixel of few samples can be slightly negative where
                    // the control variate's model is lit and the surface
                    // is not, `integrator::control_variate`)
                    let ok = (v - want).abs() <= 1e-5 * want.abs();
                    assert!(
                        ok,
                        "{integrator:?}: {name} pixel {p} channel {c}: {v}, not {want}"
                    );
                }
            }
        }
    }
}

#[test]
fn every_pass_is_the_same_for_one_and_two_threads() {
    let s = scene(MIXED);
    for integrator in [IntegratorKind::Path, IntegratorKind::RandomWalk] {
        let one = render_with(&s, PassSet::all(), integrator, 1, None);
        let two = render_with(&s, PassSet::all(), integrator, 2, None);
        assert_eq!(one.film, two.film);
        assert_eq!(one.layers.len(), two.layers.len());
        for (a, b) in one.layers.iter().zip(&two.layers) {
            // bitwise: Z holds +inf where nothing is hit, compare bits
            let bits = |l: &Layer| l.values.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert!(
                bits(a) == bits(b),
                "{integrator:?}: layer {} differs",
                a.name
            );
        }
        assert_eq!(one.coverage, two.coverage);
    }
}

#[test]
fn passes_leave_the_beauty_unchanged() {
    let s = scene(MIXED);
    let with = render_with(&s, PassSet::all(), IntegratorKind::Path, 2, None);
    let without = render_with(&s, PassSet::EMPTY, IntegratorKind::Path, 2, None);
    assert_eq!(with.film, without.film);
    assert!(without.layers.is_empty() && without.coverage.is_empty());
}

/// A diffuse plane (albedo ρ = 0.5) filling the view at distance 5, under
/// a uniform sky L = 2: each pixel converges to ρL = 1, all of it
/// diffuse_direct (the sky is a light, reached by the ray the first event
/// sent; nothing else to bounce off).
const PLANE: &str = r#"
[camera]
look_from = [0, 0, 5]
look_at = [0, 0, 0]
fov_y = 30
resolution = [16, 16]
[render]
spp = 16
[environment]
radiance = [2, 2, 2]
[materials.paper]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]
[[shapes]]
name = "backdrop"
type = "quad"
material = "paper"
scale = 10
"#;

#[test]
fn a_diffuse_plane_under_the_sky_is_all_diffuse_direct() {
    let out = render(&scene(PLANE), "lightpaths");
    let direct = layer(&out, "diffuse_direct");
    let mut sum = 0.0;
    for (p, b) in out.film.pixels.iter().enumerate() {
        for c in 0..3 {
            assert_eq!(direct.get(p, c), b[c], "pixel {p}");
            sum += direct.get(p, c) as f64;
        }
    }
    let mean = sum / (3.0 * out.film.pixels.len() as f64);
    assert!((mean - 1.0).abs() < 0.02, "mean {mean}, expected ρL = 1");
    for name in light_path_names() {
        if name != "diffuse_direct" {
            assert_eq!(max(layer(&out, name)), 0.0, "{name}");
        }
    }
}

#[test]
fn data_passes_of_a_plane_at_a_known_distance() {
    let out = render(&scene(PLANE), "data,ids,cryptomatte,noise");
    let n = out.film.pixels.len();
    for p in 0..n {
        // The plane z = 0 is 5 units along the view axis from every pixel.
        assert!((layer(&out, "Z").get(p, 0) - 5.0).abs() < 1e-5);
        assert!(layer(&out, "P").get(p, 2).abs() < 1e-5);
        for c in 0..3 {
            assert_eq!(layer(&out, "albedo").get(p, c), 0.5);
            assert_eq!(layer(&out, "N").get(p, c), [0.0, 0.0, 1.0][c]);
        }
        assert_eq!(layer(&out, "object_id").get(p, 0), 1.0);
        assert_eq!(layer(&out, "material_id").get(p, 0), 1.0);
        assert_eq!(layer(&out, "sample_count").get(p, 0), 16.0);
        for cov in &out.coverage {
            assert_eq!(cov.pixels[p], [(0, 1.0)], "{}", cov.kind);
        }
    }
    assert_eq!(out.coverage[0].names, ["backdrop"]);
    assert_eq!(out.coverage[1].names, ["paper"]);
    // P spans the visible part of the plane: ±5 tan 15° at the edges.
    let px = layer(&out, "P");
    let half = 5.0 * 15f32.to_radians().tan();
    assert!((px.get(0, 0) + half).abs() < 0.2 && (px.get(0, 1) - half).abs() < 0.2);
}

/// A unit sphere (object `shapes[1]`, unnamed) in front of the plane.
fn sphere_scene() -> Scene {
    scene(&format!(
        "{PLANE}[materials.clay]\ntype = \"diffuse\"\nalbedo = [0.2, 0.4, 0.8]\n\
         [[shapes]]\ntype = \"sphere\"\nmaterial = \"clay\"\n"
    ))
}

#[test]
fn data_passes_of_a_sphere_and_coverage_that_sums_to_one() {
    let out = render(&sphere_scene(), "data,ids,cryptomatte");
    let (z, pos, nrm, albedo) = (
        layer(&out, "Z"),
        layer(&out, "P"),
        layer(&out, "N"),
        layer(&out, "albedo"),
    );
    let [objects, materials] = [&out.coverage[0], &out.coverage[1]];
    assert_eq!(objects.names, ["backdrop", "shapes[1]"]);
    assert_eq!(materials.names, ["clay", "paper"]);
    let (mut inside, mut edge) = (0, 0);
    for p in 0..out.film.pixels.len() {
        // The plane is behind everything: every sample hits something.
        for cov in [objects, materials] {
            let total: f32 = cov.pixels[p].iter().map(|(_, f)| f).sum();
            assert!((total - 1.0).abs() < 1e-6, "pixel {p}: coverage {total}");
        }
        let on_sphere = objects.pixels[p] == [(1, 1.0)];
        if objects.pixels[p].len() == 2 {
            edge += 1;
        }
        // Z is the view-axis distance of P, the nearest hit.
        let pz = pos.get(p, 2);
        assert!((z.get(p, 0) - (5.0 - pz)).abs() < 1e-5);
        if !on_sphere {
            continue;
        }
        inside += 1;
        assert_eq!(layer(&out, "object_id").get(p, 0), 2.0);
        assert_eq!(layer(&out, "material_id").get(p, 0), 1.0);
        for c in 0..3 {
            assert!((albedo.get(p, c) - [0.2, 0.4, 0.8][c]).abs() < 1e-6);
        }
        // The shading normal of a sphere points from its centre.
        let pv = [pos.get(p, 0), pos.get(p, 1), pz];
        let r = pv.iter().map(|v| v * v).sum::<f32>().sqrt();
        assert!((r - 1.0).abs() < 0.01, "pixel {p}: |P| = {r}");
        let nv = [nrm.get(p, 0), nrm.get(p, 1), nrm.get(p, 2)];
        let nl = nv.iter().map(|v| v * v).sum::<f32>().sqrt();
        let cos: f32 = (0..3).map(|c| nv[c] * pv[c]).sum::<f32>() / (nl * r);
        if pv[2] > 0.8 {
            assert!(cos > 0.99, "pixel {p}: N·P/|N||P| = {cos}");
        }
    }
    assert!(
        inside > 20 && edge > 10,
        "{inside} inside, {edge} on the edge"
    );
    // The nearest hit of the centre pixels is the sphere's front, z = 1.
    let centre = 8 * 16 + 8;
    assert!((z.get(centre, 0) - 4.0).abs() < 0.01);
}

#[test]
fn a_pixel_no_sample_hits_has_the_far_depth_and_no_ids() {
    let s = scene(
        "[camera]\nlook_from = [0, 0, 5]\nlook_at = [0, 0, 0]\nresolution = [4, 4]\n\
         [environment]\nradiance = [1, 1, 1]\n",
    );
    let out = render(&s, "Z,P,object_id,crypto_object,noise");
    for p in 0..16 {
        assert_eq!(
            layer(&out, "Z").get(p, 0),
            lucent::film::pass_sums::DEPTH_MISS
        );
        assert_eq!(layer(&out, "object_id").get(p, 0), 0.0);
        assert_eq!(layer(&out, "P").get(p, 1), 0.0);
        assert!(out.coverage[0].pixels[p].is_empty());
        // the sky is constant: no noise
        assert_eq!(layer(&out, "variance").get(p, 0), 0.0);
    }
}

#[test]
fn the_variance_pass_estimates_the_spread_of_the_pixel_mean() {
    // (On the plane alone every sample is exactly ρL: the sphere's shadow
    // and silhouette make the noise.)
    // The pass is s²/n, the variance of a mean of independent samples: the
    // pseudo-random sampler's. (The Sobol' sampler's samples are
    // stratified, the spread of its means smaller: there the pass bounds
    // it from above, docs/output.md.)
    let mut s = sphere_scene();
    s.settings.sampler = lucent::sampling::SamplerKind::Random;
    let runs: Vec<RenderOutput> = (0..8)
        .map(|seed| {
            let set = PassSet::parse_list("variance").unwrap();
            render_with(&s, set, IntegratorKind::Path, 2, Some(seed))
        })
        .collect();
    let n = runs[0].film.pixels.len();
    let k = runs.len() as f64;
    let (mut across, mut estimated) = (0.0, 0.0);
    for p in 0..n {
        for c in 0..3 {
            let x: Vec<f64> = runs.iter().map(|r| r.film.pixels[p][c] as f64).collect();
            let m = x.iter().sum::<f64>() / k;
            across += x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (k - 1.0);
            estimated += runs
                .iter()
                .map(|r| layer(r, "variance").get(p, c) as f64)
                .sum::<f64>()
                / k;
        }
    }
    let ratio = estimated / across;
    assert!(
        (ratio - 1.0).abs() < 0.1,
        "variance pass / spread across seeds = {ratio}"
    );
}

/// Uncoated (specular = false) subsurface objects only, lit by an area light
/// the camera does not see: every sample's light went through a medium.
const ONLY_SUBSURFACE: &str = r#"
units_per_mm = 0.1
[camera]
look_from = [0, 4, 4]
look_at = [0, 0.5, 0]
fov_y = 35
resolution = [24, 24]
[render]
spp = 8
[materials.marble]
type = "subsurface"
preset = "marble"
specular = false
[materials.wax]
type = "subsurface"
albedo = [0.9, 0.7, 0.5]
dmfp = [4.0, 2.0, 1.0]
specular = false
[materials.lamp]
type = "diffuse"
albedo = [0, 0, 0]
[[shapes]]
type = "box"
material = "wax"
scale = [8, 0.5, 8]
translate = [0, -0.5, 0]
[[shapes]]
type = "sphere"
subdivisions = 3
material = "marble"
translate = [0, 1, 0]
[[shapes]]
type = "quad"
material = "lamp"
emission = [10, 10, 10]
rotate = [[90, 1, 0, 0]]
translate = [0, 5, -2]
"#;

#[test]
fn only_subsurface_puts_all_light_in_sss_and_none_leaves_sss_black() {
    let out = render(&scene(ONLY_SUBSURFACE), "lightpaths");
    assert_sum_is_beauty(&out, &["sss_direct", "sss_indirect"], "sss only");
    assert!(max(layer(&out, "sss_direct")) > 0.0);
    assert!(max(layer(&out, "sss_indirect")) > 0.0);
    for name in light_path_names() {
        if !name.starts_with("sss_") {
            assert_eq!(max(layer(&out, name)), 0.0, "{name}");
        }
    }
    // The random walk reflects at the boundary (specular) and sends the
    // rest through the medium (sss): nothing else.
    let set = PassSet::parse_list("lightpaths").unwrap();
    let walk = render_with(
        &scene(ONLY_SUBSURFACE),
        set,
        IntegratorKind::RandomWalk,
        2,
        None,
    );
    let parts = [
        "sss_direct",
        "sss_indirect",
        "specular_direct",
        "specular_indirect",
    ];
    assert_sum_is_beauty(&walk, &parts, "random walk");
    for name in parts {
        assert!(
            max(layer(&walk, name)) > 0.0,
            "random walk: {name} is black"
        );
    }
    // The mixed scene without its subsurface objects (marble, wax → floor).
    let none = MIXED
        .replace("material = \"marble\"", "material = \"floor\"")
        .replace("material = \"wax\"", "material = \"floor\"");
    let out = render(&scene(&none), "lightpaths");
    assert_sum_is_beauty(&out, &light_path_names(), "no subsurface");
    assert_eq!(max(layer(&out, "sss_direct")), 0.0);
    assert_eq!(max(layer(&out, "sss_indirect")), 0.0);
}

#[test]
fn scene_light_groups_and_aovs_are_checked_and_located() {
    let err = |extra: &str, find: &str, replace: &str| {
        let text = format!("{}{extra}", MIXED.replace(find, replace));
        load_str(&text, Path::new("s.toml")).unwrap_err()
    };
    let e = err("[output]\naovs = [\"Z\", \"depth\"]\n", "", "");
    assert_eq!(e.field.as_deref(), Some("output.aovs[1]"));
    assert_eq!(e.line, Some(MIXED.lines().count() + 2));
    assert!(
        e.message.contains("unknown pass \"depth\""),
        "{}",
        e.message
    );
    let e = err(
        "",
        "name = \"floor\"\n",
        "name = \"floor\"\nlight_group = \"x\"\n",
    );
    assert_eq!(e.field.as_deref(), Some("shapes[0].light_group"));
    assert!(e.message.contains("emits nothing"), "{}", e.message);
    let e = err("", "light_group = \"sky\"", "light_group = \"my sky\"");
    assert_eq!(e.field.as_deref(), Some("environment.light_group"));
    // and a good list is kept
    let s = scene(&format!(
        "{MIXED}[output]\naovs = [\"lightgroups\", \"Z\"]\n"
    ));
    assert_eq!(s.output.aovs, PassSet::parse_list("Z,lightgroups").unwrap());
    assert_eq!(s.output.light_groups, ["default", "key", "sky"]);
}

#[test]
fn an_unknown_pass_on_the_command_line_exits_2_naming_the_option() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.toml");
    std::fs::write(&scene, PLANE).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(["render", "--quiet", "--spp", "1", "--aov", "Z,bogus", "-o"])
        .arg(dir.path().join("o.exr"))
        .arg(&scene)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let msg = String::from_utf8_lossy(&out.stderr);
    assert!(msg.contains("--aov") && msg.contains("\"bogus\""), "{msg}");
    assert!(!dir.path().join("o.exr").exists());
}
