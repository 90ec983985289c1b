//! The albedo table (`lucent::bssrdf::albedo_table`, `docs/bssrdf.md` §9)
//! against the full renderer:
//!
//! 1. **Same physics.** The table comes from a half-space walker
//!    (`tools::halfspace`) that reuses the random walk's free-flight,
//!    phase-function and boundary code. Here the integrator's random walk
//!    renders a large, thick slab of a medium at two table nodes under a
//!    uniform environment, seen straight down, where each pixel is
//!    Fr(1) + Ft(1)·R_normal(α', η): the table's normal-entry column, at a
//!    node (no interpolation).
//! 2. **Diffusion matches the walk.** Marble and Skin1 on the same slab,
//!    diffusion (A from the table) against the random walk, in the mean
//!    over view directions weighted by cos θ (what a uniformly lit body's
//!    pixels average), by a three-point Gauss–Legendre rule in μ²: within
//!    1.5 % (measured: within 0.8 %), which the given A (the Jensen table's
//!    Rd column, 2–4 % off) misses.

use crate::common;

use std::sync::Arc;

use crate::common::scene::{object, TestScene};
use lucent::accel::{self, Backend};
use lucent::bssrdf::albedo_table::AlbedoTable;
use lucent::bssrdf::{AlbedoSource, Fit, Measured, ProbeOptions, SubsurfaceParams};
use lucent::film::Film;
use lucent::fresnel;
use lucent::geometry::{Mesh, Vec3};
use lucent::integrator::IntegratorKind;
use lucent::materials::{Material, Subsurface};
use lucent::render::{render, RenderOptions};
use lucent::scene::{shapes, Camera, Scene};

/// The material with the renderer's defaults (smooth coat, Sw lobe),
/// renormalized so the diffusion side reflects exactly A.
fn material(params: SubsurfaceParams) -> Material {
    let opts = ProbeOptions {
        renormalize: true,
        ..ProbeOptions::default()
    };
    Material::Subsurface(Arc::new(
        Subsurface::new(params, &opts, true, true).unwrap(),
    ))
}

/// A slab `side` × `thickness` × `side`, top face at y = 0, seen from
/// direction θ off the normal (in the y–z plane) by a narrow camera.
fn slab_scene(material: Material, side: f32, thickness: f32, theta_deg: f32, spp: u32) -> Scene {
    let mut mesh: Mesh = shapes::cuboid();
    let (h, t) = (side / 2.0, thickness / 2.0);
    mesh.transform(|p| p * Vec3::new(h, t, h) - Vec3::new(0.0, t, 0.0), |n| n);
    let th = theta_deg.to_radians();
    let eye = Vec3::new(0.0, th.cos(), th.sin()) * 10.0;
    TestScene {
        camera: Camera::new(eye, Vec3::ZERO, Vec3::X, 4.0, 8, 8),
        spp,
        max_depth: 8,
        seed: 5,
        environment: Some(Vec3::ONE),
    }
    .build(vec![mesh], vec![material], vec![object("slab", 0, None)])
}

fn run(scene: &Scene, integrator: IntegratorKind) -> Film {
    let a = accel::build(&scene.meshes, Backend::default_available()).unwrap();
    let opts = RenderOptions {
        integrator,
        ..Default::default()
    };
    let (film, stats) = render(scene, a.as_ref(), &opts).unwrap();
    assert_eq!(stats.counters.nonfinite, 0);
    assert_eq!(
        (stats.counters.walks_escaped, stats.counters.walks_capped),
        (0, 0)
    );
    film
}

/// A g = 0 medium of reduced albedo α' with σt' = 1 mm⁻¹, all channels
/// equal.
fn medium(alpha: f64, eta: f32) -> SubsurfaceParams {
    let m = Measured {
        sigma_s: [alpha; 3],
        sigma_a: [1.0 - alpha; 3],
        g: 0.0,
        albedo: [1.0; 3],
        eta,
    };
    SubsurfaceParams::from_measured(&m, 1.0, Fit::Searchlight).unwrap()
}

/// Table nodes x = √(1 − α') = 0.1 and 0.3 at η = 1.5 (α' = 0.99, 0.91):
/// the random walk through the integrator reflects what the table says.
#[test]
fn integrator_random_walk_reproduces_table_nodes() {
    let t = AlbedoTable::get().unwrap();
    let eta = 1.5;
    let i = t.etas.iter().position(|&e| (e - eta).abs() < 1e-9).unwrap();
    for x in [0.1, 0.3] {
        let j = t.xs.iter().position(|&v| (v - x).abs() < 1e-9).unwrap();
        let alpha = 1.0 - x * x;
        // ℓd = 1/√(3(1 − α')) = 5.8 and 1.9 mm: 100 mm thick is deep
        let s = slab_scene(
            material(medium(alpha, eta as f32)),
            1000.0,
            100.0,
            0.0,
            1024,
        );
        let (m, se) = common::mean_se(&run(&s, IntegratorKind::RandomWalk));
        let fr = fresnel::dielectric(1.0, eta as f32) as f64;
        let expect = fr + (1.0 - fr) * t.normal[i][j];
        println!(
            "α' {alpha}: walk {m:?} ± {se:?}, table Fr + Ft·R_normal = {expect:.5} \
             (R_normal {:.5} ± {:.5})",
            t.normal[i][j], t.max_se
        );
        for c in 0..3 {
            let tol = 4.0 * (se[c] * se[c] + t.max_se * t.max_se).sqrt();
            assert!(
                (m[c] - expect).abs() < tol,
                "channel {c}: {} vs {expect}",
                m[c]
            );
        }
    }
}

/// Gauss–Legendre in u = μ² on [0, 1] (three points): ∫ f(μ) 2μ dμ =
/// ∫ f(√u) du. Returns (θ in degrees, weight).
fn view_rule() -> [(f32, f64); 3] {
    let u = [0.5 - 0.15f64.sqrt(), 0.5, 0.5 + 0.15f64.sqrt()];
    let w = [5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0];
    std::array::from_fn(|k| (u[k].sqrt().acos().to_degrees() as f32, w[k]))
}

/// Cosine-weighted mean radiance over view directions of the slab.
fn view_mean(
    params: SubsurfaceParams,
    integrator: IntegratorKind,
    spp: u32,
) -> ([f64; 3], [f64; 3]) {
    let mut mean = [0.0; 3];
    let mut var = [0.0; 3];
    for (theta, w) in view_rule() {
        let s = slab_scene(material(params), 1000.0, 150.0, theta, spp);
        let (m, se) = common::mean_se(&run(&s, integrator));
        for c in 0..3 {
            mean[c] += w * m[c];
            var[c] += (w * se[c]).powi(2);
        }
    }
    (mean, var.map(f64::sqrt))
}

/// Marble and Skin1 (the presets, A from the table): diffusion against the
/// random walk per channel in the view-direction mean. Measured (seed 5,
/// 8×8 px, walk 1024 spp, diffusion 512 spp; ± one standard error of the
/// difference), (diffusion − walk) / walk:
///
/// - table A: marble −0.81 ± 0.38, −0.75 ± 0.33, −0.50 ± 0.36 %;
///   skin1 −0.36 ± 0.48, −0.30 ± 0.48, −0.16 ± 0.66 %;
/// - given A (Jensen Rd): marble −2.09, −2.35, −2.54 %; skin1 −3.92, −3.09,
///   +2.57 %.
///
/// Bound 1.5 % per channel: the table's A passes with room for the noise;
/// the given A is off by more than that on average over the channels (by
/// 1.5–2.9 % per channel, within noise of the figures above, under the
/// curvature axis rule: marble −1.47, −1.79, −2.04 %,
/// skin1 −2.91, −2.56, +2.80 %).
#[test]
fn diffusion_matches_random_walk_on_the_slab_for_marble_and_skin1() {
    for name in ["marble", "skin1"] {
        let p = SubsurfaceParams::from_preset(name, 1.0, Fit::Searchlight).unwrap();
        let old = SubsurfaceParams::from_preset_with(
            name,
            1.0,
            Fit::Searchlight,
            AlbedoSource::Given,
            None,
        )
        .unwrap();
        let (w, ew) = view_mean(p, IntegratorKind::RandomWalk, 1024);
        let (d, ed) = view_mean(p, IntegratorKind::Path, 512);
        let (o, _) = view_mean(old, IntegratorKind::Path, 512);
        let mut old_off = 0.0;
        for c in 0..3 {
            let rel = d[c] / w[c] - 1.0;
            let rel_old = o[c] / w[c] - 1.0;
            let err = (ew[c].powi(2) + ed[c].powi(2)).sqrt() / w[c];
            println!(
                "{name} channel {c}: walk {:.4} ± {:.4}, diffusion {:.4} ({:+.2} % ± {:.2} %), \
                 old A {:+.2} %",
                w[c],
                ew[c],
                d[c],
                100.0 * rel,
                100.0 * err,
                100.0 * rel_old
            );
            assert!(rel.abs() < 0.015, "{name} channel {c}: {rel}");
            old_off += rel_old.abs() / 3.0;
        }
        assert!(old_off > 0.015, "{name}: old A off by {old_off} on average");
    }
}

/// The scene key `albedo_source`: "given" restores the Jensen Rd column,
/// the default is the table, and anything else is an error naming the
/// file, line and field.
#[test]
fn scene_key_albedo_source() {
    use lucent::scene::load_str;
    use std::path::Path;
    let scene = |src: &str| {
        format!(
            "[camera]\nlook_from = [0, 1, 5]\nlook_at = [0, 1, 0]\nresolution = [8, 8]\n\
             [materials.m]\ntype = \"subsurface\"\npreset = \"marble\"\n{src}\n\
             [[shapes]]\ntype = \"sphere\"\nmaterial = \"m\"\n"
        )
    };
    let albedo = |src: &str| match &load_str(&scene(src), Path::new("s.toml"))
        .unwrap()
        .materials[0]
    {
        Material::Subsurface(s) => s.params().albedo,
        _ => unreachable!(),
    };
    assert_eq!(albedo("albedo_source = \"given\""), [0.83, 0.79, 0.75]);
    let table = SubsurfaceParams::from_preset("marble", 1.0, Fit::Searchlight).unwrap();
    assert_eq!(albedo(""), table.albedo);
    assert_eq!(albedo("albedo_source = \"Table\""), table.albedo);
    let e = load_str(&scene("albedo_source = \"dipole\""), Path::new("s.toml")).unwrap_err();
    assert_eq!(e.line, Some(8));
    assert_eq!(e.field.as_deref(), Some("materials.m.albedo_source"));
    assert!(
        e.message.contains("dipole") && e.message.contains("table or given"),
        "{e}"
    );
}
