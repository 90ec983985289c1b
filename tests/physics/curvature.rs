//! The curvature correction (`lucent::bssrdf::curvature_correction`,
//! `docs/bssrdf.md` §10) against the full renderer:
//!
//! 1. **Diffusion matches the walk on a sphere.** Skin1 on a sphere of one
//!    diffusion length (of its longest channel) under a uniform
//!    environment: without the correction the diffusion estimator is
//!    22–44 % darker than the random walk (the half-space profile on a
//!    small convex body); with it, within 4 % per channel (measured
//!    −1.2/+0.4/+0.3 % in `docs/accuracy.md`); at four diffusion lengths
//!    4–16 % darker without, within 3.5 % with it.
//! 2. **Flat surfaces are untouched, bit for bit.** A slab (flat-shaded
//!    box) renders the same image with the correction on and off.

use std::sync::Arc;

use crate::common::scene::{object, TestScene};
use lucent::accel::{self, Backend};
use lucent::bssrdf::{Fit, ProbeOptions, ProfileShape, SubsurfaceParams};
use lucent::film::Film;
use lucent::geometry::{Mesh, Vec3};
use lucent::integrator::IntegratorKind;
use lucent::materials::{CurvatureMode, Material, Subsurface};
use lucent::render::{render, RenderOptions};
use lucent::scene::{shapes, Camera, Scene};

/// The material with the renderer's defaults (smooth coat, Sw lobe),
/// renormalized so the diffusion side reflects exactly A on a flat surface.
fn material(params: SubsurfaceParams, mode: CurvatureMode, profile: ProfileShape) -> Material {
    let opts = ProbeOptions {
        renormalize: true,
        profile,
        ..ProbeOptions::default()
    };
    Material::Subsurface(Arc::new(
        Subsurface::new(params, &opts, true, true)
            .unwrap()
            .with_curvature_mode(mode),
    ))
}

const RES: u32 = 16;

/// `mesh` under a uniform environment, seen by a camera at `eye` looking
/// at the origin.
fn scene(material: Material, mesh: Mesh, eye: Vec3, up: Vec3, fov: f32, spp: u32) -> Scene {
    TestScene {
        camera: Camera::new(eye, Vec3::ZERO, up, fov, RES, RES),
        spp,
        max_depth: 4,
        seed: 1,
        environment: Some(Vec3::ONE),
    }
    .build(vec![mesh], vec![material], vec![object("body", 0, None)])
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

/// Mean per channel over the pixels whose square lies wholly inside the
/// disk of radius `r` pixels at the image centre (the sphere's pixels: a
/// cosine-weighted mean over its visible hemisphere, what the diffusion A
/// is matched to), with its standard error.
fn disk_mean(film: &Film, r: f64) -> ([f64; 3], [f64; 3]) {
    let c = RES as f64 / 2.0;
    let mut vals = Vec::new();
    for y in 0..RES as usize {
        for x in 0..RES as usize {
            let dx = (x as f64 - c).abs().max((x as f64 + 1.0 - c).abs());
            let dy = (y as f64 - c).abs().max((y as f64 + 1.0 - c).abs());
            if dx * dx + dy * dy <= r * r {
                vals.push(film.pixels[y * RES as usize + x]);
            }
        }
    }
    let n = vals.len() as f64;
    assert!(n > 100.0, "{n} pixels");
    let mut mean = [0.0; 3];
    let mut se = [0.0; 3];
    for k in 0..3 {
        let m = vals.iter().map(|p| p[k] as f64).sum::<f64>() / n;
        let var = vals.iter().map(|p| (p[k] as f64 - m).powi(2)).sum::<f64>() / (n - 1.0);
        mean[k] = m;
        se[k] = (var / n).sqrt();
    }
    (mean, se)
}

/// Skin1 on a sphere of `k` diffusion lengths (its longest channel's):
/// the diffusion estimator with the correction against the random walk
/// within `bound`, and without it below `uncorrected_below` (so the test
/// sees the deficit it corrects).
fn sphere_case(k: f32, bound: f64, uncorrected_below: f64, profile: ProfileShape) {
    let p = SubsurfaceParams::from_preset("skin1", 1.0, Fit::Searchlight).unwrap();
    let m = p.medium.unwrap();
    let ld = (0..3)
        .map(|c| lucent::bssrdf::params::diffuse_mfp(m.sigma_s[c], m.sigma_a[c]))
        .fold(0.0, f64::max);
    let rho = k * ld as f32;
    let mut mesh = shapes::sphere(5);
    mesh.transform(|q| q * rho, |n| n);
    let dist = 4.0 * rho;
    let half = (rho / dist).asin() * 1.08;
    let disk = (rho / dist).asin().tan() / half.tan() * RES as f32 / 2.0;
    let eye = Vec3::new(0.0, 0.0, dist);
    let fov = 2.0 * half.to_degrees();
    let render_with = |mode, integrator, spp| {
        let s = scene(
            material(p, mode, profile),
            mesh.clone(),
            eye,
            Vec3::Y,
            fov,
            spp,
        );
        disk_mean(&run(&s, integrator), disk as f64)
    };
    let (walk, se_w) = render_with(CurvatureMode::Off, IntegratorKind::RandomWalk, 256);
    let (on, se_on) = render_with(CurvatureMode::Auto, IntegratorKind::Path, 64);
    let (off, _) = render_with(CurvatureMode::Off, IntegratorKind::Path, 16);
    for c in 0..3 {
        let e_on = on[c] / walk[c] - 1.0;
        let e_off = off[c] / walk[c] - 1.0;
        println!(
            "{k} ld, ch{c}: walk {:.4} ± {:.4}, corrected {:.4} ± {:.4} ({:+.1} %), uncorrected {:+.1} %",
            walk[c],
            se_w[c],
            on[c],
            se_on[c],
            100.0 * e_on,
            100.0 * e_off
        );
        assert!(
            e_on.abs() < bound,
            "{k} ld, channel {c}: corrected {e_on:+.4}"
        );
        assert!(
            e_off < uncorrected_below,
            "{k} ld, channel {c}: uncorrected {e_off:+.4}"
        );
    }
}

#[test]
fn diffusion_matches_the_random_walk_on_a_sphere_of_one_diffusion_length() {
    sphere_case(1.0, 0.04, -0.15, ProfileShape::Burley);
}

/// The tabulated profile (`bssrdf::tabulated`) keeps the sphere's total
/// under uniform light: the correction applies to it as to the fit (its
/// g(R) from the table's own CDF), so the change of shape moves no light
/// in or out (measured +0.5/+1.2/+1.5 %); without the correction it is
/// −43/−35/−21 %. Integrating the fit's CDF in g instead moves this
/// sphere by only ~2 % (the table's share beyond the diameter), inside
/// the bound: this test guards the correction, not that choice.
#[test]
fn a_tabulated_profile_matches_the_random_walk_on_a_sphere_of_one_diffusion_length() {
    sphere_case(1.0, 0.04, -0.15, ProfileShape::Tabulated);
}

#[test]
fn diffusion_matches_the_random_walk_on_a_sphere_of_four_diffusion_lengths() {
    sphere_case(4.0, 0.035, -0.03, ProfileShape::Burley);
}

#[test]
fn flat_surfaces_render_bit_for_bit_as_without_the_correction() {
    let p = SubsurfaceParams::from_preset("marble", 1.0, Fit::Searchlight).unwrap();
    let mut slab: Mesh = shapes::cuboid();
    slab.transform(
        |q| q * Vec3::new(200.0, 40.0, 200.0) - Vec3::new(0.0, 40.0, 0.0),
        |n| n,
    );
    let eye = Vec3::new(0.0, 100.0, 40.0);
    let img = |mode| {
        let s = scene(
            material(p, mode, ProfileShape::Burley),
            slab.clone(),
            eye,
            Vec3::X,
            10.0,
            4,
        );
        run(&s, IntegratorKind::Path).pixels
    };
    let (on, off) = (img(CurvatureMode::Auto), img(CurvatureMode::Off));
    assert!(on.iter().any(|p| p[0] > 0.0));
    assert_eq!(on, off);
}
