//! The random-walk reference integrator (`lucent::integrator::randomwalk`):
//! energy conservation on its own closed-form answers, agreement with the
//! diffusion BSSRDF on the flat-slab ground truth, determinism across thread
//! counts, and clean termination on open meshes.

use crate::common;

use std::sync::Arc;

use crate::common::scene::{object, TestScene};
use lucent::accel::{self, Backend};
use lucent::bssrdf::params::{dipole_reflectance, invert_dipole_reflectance, Medium};
use lucent::bssrdf::{Fit, Measured, ProbeOptions, SubsurfaceParams, PRESETS};
use lucent::film::Film;
use lucent::geometry::{Mesh, Vec3};
use lucent::integrator::{Counters, Effect, IntegratorKind};
use lucent::materials::{Material, Subsurface, WalkBoundary};
use lucent::render::{render, RenderOptions};
use lucent::scene::{shapes, Camera, Scene};

fn placed(mut m: Mesh, scale: Vec3, translate: Vec3) -> Mesh {
    m.transform(|p| p * scale + translate, |n| n / scale);
    m
}

fn subsurface(params: SubsurfaceParams) -> Material {
    let opts = ProbeOptions {
        renormalize: true,
        ..ProbeOptions::default()
    };
    // Plain cosine lobe and no coat: with η = 1 the diffusion model then
    // reflects exactly A (docs/bssrdf.md §7, ground truth 1).
    Material::Subsurface(Arc::new(
        Subsurface::new(params, &opts, false, false).unwrap(),
    ))
}

/// A medium given directly in mm⁻¹ (units_per_mm = 1).
fn medium(sigma_s: [f64; 3], sigma_a: [f64; 3], g: f64, eta: f32) -> SubsurfaceParams {
    let m = Measured {
        sigma_s,
        sigma_a,
        g,
        albedo: [1.0; 3],
        eta,
    };
    SubsurfaceParams::from_measured(&m, 1.0, Fit::Searchlight).unwrap()
}

struct Part {
    mesh: Mesh,
    material: Material,
    emission: Option<Vec3>,
}

fn scene(parts: Vec<Part>, env: Option<Vec3>, camera: Camera, spp: u32, max_depth: u32) -> Scene {
    let meshes = parts.iter().map(|p| p.mesh.clone()).collect();
    let objects = parts
        .iter()
        .enumerate()
        .map(|(i, p)| object(format!("o{i}"), i, p.emission))
        .collect();
    let materials = parts.into_iter().map(|p| p.material).collect();
    TestScene {
        camera,
        spp,
        max_depth,
        seed: 11,
        environment: env,
    }
    .build(meshes, materials, objects)
}

fn run(scene: &Scene, integrator: IntegratorKind, threads: Option<usize>) -> (Film, Counters, f64) {
    let a = accel::build(&scene.meshes, Backend::default_available()).unwrap();
    let opts = RenderOptions {
        integrator,
        threads,
        ..Default::default()
    };
    let (film, stats) = render(scene, a.as_ref(), &opts).unwrap();
    (film, stats.counters, stats.seconds)
}

/// Mean over the image and its standard error (pixels are independent).
fn mean_and_error(film: &Film) -> (Vec3, Vec3) {
    let (m, se) = common::mean_se(film);
    let v = |x: [f64; 3]| Vec3::new(x[0] as f32, x[1] as f32, x[2] as f32);
    (v(m), v(se))
}

/// A slab 200 × `thickness` × 200 with its top face at y = 0.
fn slab(thickness: f32, material: Material) -> Part {
    let mesh = placed(
        shapes::cuboid(),
        Vec3::new(100.0, thickness / 2.0, 100.0),
        Vec3::new(0.0, -thickness / 2.0, 0.0),
    );
    Part {
        mesh,
        material,
        emission: None,
    }
}

fn camera_above(res: u32) -> Camera {
    Camera::new(
        Vec3::new(0.0, 10.0, 0.0),
        Vec3::ZERO,
        Vec3::new(0.0, 0.0, -1.0),
        10.0,
        res,
        res,
    )
}

/// With σa = 0 and η = 1 nothing is absorbed and nothing reflects at the
/// boundary, so every walk leaves the slab (top, bottom or side) into a
/// uniform environment of radiance 1: each sample's expectation is exactly
/// one. The chromatic σs exercises the spectral MIS weights (one channel's
/// distance, all channels' throughputs). Then the same slab with a
/// black floor (reflectance R) and with an emitting floor under a black sky
/// (transmittance T): R + T = 1, and forward scattering transmits more.
#[test]
fn albedo_one_slab_conserves_energy_and_r_plus_t_is_one() {
    let sigma_s = [1.0, 2.0, 4.0];
    let mut transmitted = Vec::new();
    for g in [0.0, 0.8] {
        let mat = || subsurface(medium(sigma_s, [0.0; 3], g, 1.0));
        let cam = camera_above(8);
        let s = scene(vec![slab(1.0, mat())], Some(Vec3::ONE), cam.clone(), 64, 8);
        let (film, c, _) = run(&s, IntegratorKind::RandomWalk, None);
        let (m, e) = mean_and_error(&film);
        println!("g = {g}: furnace mean {m}, standard error {e}");
        assert_eq!((c.walks_capped, c.walks_escaped, c.nonfinite), (0, 0, 0));
        for k in 0..3 {
            assert!(
                (m[k] - 1.0).abs() < 4.0 * e[k] + 1e-5,
                "g = {g}, channel {k}: {} ± {}",
                m[k],
                e[k]
            );
        }

        // A large floor 1 unit below the slab catches what leaves downwards.
        let floor = || placed(shapes::quad(), Vec3::splat(2000.0), Vec3::ZERO);
        let floor = || {
            let mut f = floor();
            // quad faces +z; turn it to face +y and move it under the slab
            f.transform(
                |p| Vec3::new(p.x, -2.0, -p.y),
                |n| Vec3::new(n.x, n.z, -n.y),
            );
            f
        };
        let black = Material::Diffuse { albedo: Vec3::ZERO };
        let r_scene = scene(
            vec![
                slab(1.0, mat()),
                Part {
                    mesh: floor(),
                    material: black.clone(),
                    emission: None,
                },
            ],
            Some(Vec3::ONE),
            cam.clone(),
            64,
            8,
        );
        let t_scene = scene(
            vec![
                slab(1.0, mat()),
                Part {
                    mesh: floor(),
                    material: black,
                    emission: Some(Vec3::ONE),
                },
            ],
            None,
            cam,
            64,
            8,
        );
        let (r, er) = mean_and_error(&run(&r_scene, IntegratorKind::RandomWalk, None).0);
        let (t, et) = mean_and_error(&run(&t_scene, IntegratorKind::RandomWalk, None).0);
        println!("g = {g}: R = {r} ± {er}, T = {t} ± {et}, R + T = {}", r + t);
        for k in 0..3 {
            let err = (er[k] * er[k] + et[k] * et[k]).sqrt();
            assert!(
                (r[k] + t[k] - 1.0).abs() < 4.0 * err + 1e-4,
                "g = {g}, channel {k}: R {} T {}",
                r[k],
                t[k]
            );
            assert!(
                r[k] > 0.02 && t[k] > 0.05,
                "g = {g}, channel {k}: R {} T {}",
                r[k],
                t[k]
            );
        }
        // optically thicker channels reflect more
        assert!(r.x < r.y && r.y < r.z, "R {r}");
        transmitted.push(t);
    }
    assert!(
        transmitted[1].min_element() > transmitted[0].max_element() * 0.9,
        "{transmitted:?}"
    );
    for k in 0..3 {
        assert!(
            transmitted[1][k] > transmitted[0][k],
            "forward scattering transmits more: {transmitted:?}"
        );
    }
}

/// The dipole relations behind the artist-form medium: the Jensen table's
/// Rd column follows the dipole at its η (docs/bssrdf.md §3: within 0.01
/// except Chicken1 blue), and the numeric inversion round-trips.
#[test]
fn dipole_inversion_round_trips_and_matches_the_table() {
    for pr in PRESETS.iter().filter(|p| p.name != "Spectralon") {
        for c in 0..3 {
            let a = pr.sigma_s_reduced[c] / (pr.sigma_s_reduced[c] + pr.sigma_a[c]);
            let rd = dipole_reflectance(a, pr.eta as f64);
            let tol = if pr.name == "Chicken1" && c == 2 {
                0.03
            } else {
                0.012
            };
            assert!(
                (rd - pr.albedo[c]).abs() < tol,
                "{} {c}: dipole {rd} table {}",
                pr.name,
                pr.albedo[c]
            );
        }
    }
    for eta in [1.0, 1.3, 1.5] {
        for a in [0.0, 0.01, 0.2, 0.5, 0.8, 0.95, 0.99] {
            let alpha = invert_dipole_reflectance(a, eta);
            assert!(
                (dipole_reflectance(alpha, eta) - a).abs() < 1e-9,
                "eta {eta} A {a}"
            );
        }
    }
    // Artist form: σtr = 1/ℓd per channel; ℓ = 0 is a dense absorber.
    let p = SubsurfaceParams::from_artist([0.2, 0.5, 0.8], [0.2, 0.0, 0.4], 1.0, Fit::Searchlight)
        .unwrap();
    let m: Medium = p.medium.unwrap();
    for c in [0, 2] {
        let st = m.sigma_t()[c];
        let str_ = (3.0 * m.sigma_a[c] * st).sqrt();
        assert!((str_ * [0.2, 0.0, 0.4][c] - 1.0).abs() < 1e-9, "{m:?}");
    }
    assert!(m.sigma_s[1] == 0.0 && m.sigma_a[1] >= 1e6 / 0.2, "{m:?}");
}

/// Ground truth 1 against ground truth 3: a thick flat slab under uniform
/// white light, η = 1, rendered with the diffusion BSSRDF (which returns A
/// exactly, renormalized) and with the random walk in the medium the
/// parameters came from. Measured (seed 11, 8×8 px, 256 spp; standard
/// errors ≈ 0.5–1 %), (diffusion − walk) / walk per channel:
///
/// - marble σ's with A = the dipole's Rd at η = 1: +0.14 %, −0.07 %, −0.20 %
///   (walk R = 0.914, 0.891, 0.868): for this high-albedo medium the
///   diffusion total reflectance is exact within noise; bound 2 %;
/// - marble with the preset's A (for η = 1.5: the albedo table's R, 0.842,
///   0.804, 0.768) but rendered at η = 1: −7.7 %, −10.1 %, −12.3 %: that A
///   belongs to another boundary, not a diffusion error; asserted to stay
///   in [−17 %, −6 %];
/// - the artist material of `scenes/slab-uniform.toml` (A = 0.2, 0.5, 0.8,
///   medium from inverting the albedo table): +28.1 %, +15.8 %, +4.6 %. The
///   medium reflects A for diffuse light (the mean over view directions),
///   but this camera looks straight down, and light entering along the
///   normal goes deeper, so less of it returns: the walk must match the
///   table's normal-entry column R_normal(α') (asserted, 4σ + 0.5 %), and
///   diffusion, which has one A for all directions, is above it by
///   A / R_normal − 1 (bounds [20, 36] %, [10, 22] %, [1, 9] %). (With the
///   dipole inversion instead of the table, the same scene gives −15.0 %,
///   −4.6 %, +0.03 %: the dipole's medium reflects less than A.)
#[test]
fn diffusion_agrees_with_random_walk_on_the_flat_slab() {
    let marble = SubsurfaceParams::from_preset("marble", 1.0, Fit::Searchlight).unwrap();
    let table = &PRESETS.iter().find(|p| p.name == "Marble").unwrap();
    // The table's A was measured at η = 1.5; the dipole's total reflectance
    // of the same medium at η = 1 is the consistent A for this slab.
    let a_eta1: [f64; 3] = std::array::from_fn(|c| {
        let (s, a) = (table.sigma_s_reduced[c], table.sigma_a[c]);
        dipole_reflectance(s / (s + a), 1.0)
    });
    let cases: Vec<(&str, SubsurfaceParams, f32)> = vec![
        (
            "marble, table A (η = 1.5)",
            SubsurfaceParams { eta: 1.0, ..marble },
            100.0,
        ),
        (
            "marble, A = dipole Rd at η = 1",
            SubsurfaceParams {
                eta: 1.0,
                albedo: a_eta1,
                ..marble
            },
            100.0,
        ),
        (
            "artist (0.2, 0.5, 0.8), dmfp 0.2",
            SubsurfaceParams::from_artist([0.2, 0.5, 0.8], [0.2; 3], 1.0, Fit::Searchlight)
                .unwrap(),
            10.0,
        ),
    ];
    for (name, params, thickness) in cases {
        let mut part = slab(thickness, subsurface(params));
        part.mesh = placed(part.mesh, Vec3::new(5.0, 1.0, 5.0), Vec3::ZERO);
        let s = scene(vec![part], Some(Vec3::ONE), camera_above(8), 256, 8);
        let (fd, _, td) = run(&s, IntegratorKind::Path, None);
        let (fw, cw, tw) = run(&s, IntegratorKind::RandomWalk, None);
        let (d, ed) = mean_and_error(&fd);
        let (w, ew) = mean_and_error(&fw);
        let rel = (d - w) / w;
        println!(
            "{name}: diffusion {d} ± {ed} ({td:.2} s), random walk {w} ± {ew} ({tw:.2} s), \
             (diffusion − walk)/walk = {rel}, walks capped {} escaped {}",
            cw.walks_capped, cw.walks_escaped
        );
        assert_eq!(cw.nonfinite, 0);
        assert_eq!((cw.walks_capped, cw.walks_escaped), (0, 0));
        let (lo, hi): ([f32; 3], [f32; 3]) = match name {
            n if n.contains("dipole") => ([-0.02; 3], [0.02; 3]),
            n if n.contains("table") => ([-0.17; 3], [-0.06; 3]),
            _ => ([0.20, 0.10, 0.01], [0.36, 0.22, 0.09]),
        };
        if name.starts_with("artist") {
            let t = lucent::bssrdf::albedo_table::AlbedoTable::get().unwrap();
            let m = params.medium.unwrap();
            for k in 0..3 {
                let alpha = m.sigma_s[k] / m.sigma_t()[k];
                let want = t.normal_reflectance(alpha, 1.0).unwrap() as f32;
                println!("channel {k}: walk {} vs table R_normal {want}", w[k]);
                assert!(
                    (w[k] - want).abs() < 4.0 * ew[k] + 0.005 * want,
                    "channel {k}: walk {} vs table R_normal {want}",
                    w[k]
                );
            }
        }
        for k in 0..3 {
            assert!(
                lo[k] <= rel[k] && rel[k] <= hi[k],
                "{name}, channel {k}: {rel}"
            );
        }
    }
}

/// Same seed → the same image, bit for bit, on 1 and 2 threads (each sample
/// draws from its own counter-based stream, and the walk uses only it).
#[test]
fn random_walk_is_deterministic_across_thread_counts() {
    let ball = placed(shapes::sphere(2), Vec3::splat(1.0), Vec3::ZERO);
    let params =
        SubsurfaceParams::from_artist([0.8, 0.5, 0.3], [0.5, 0.3, 0.1], 1.3, Fit::Searchlight)
            .unwrap();
    let mut lamp = placed(shapes::quad(), Vec3::splat(0.5), Vec3::new(0.0, 0.0, 3.0));
    lamp.flip_winding(); // face −z, towards the ball
    let s = scene(
        vec![
            Part {
                mesh: ball,
                material: subsurface(params),
                emission: None,
            },
            Part {
                mesh: lamp,
                material: Material::Diffuse { albedo: Vec3::ZERO },
                emission: Some(Vec3::splat(4.0)),
            },
        ],
        Some(Vec3::splat(0.2)),
        Camera::new(Vec3::new(0.0, 1.0, 4.0), Vec3::ZERO, Vec3::Y, 40.0, 20, 12),
        4,
        6,
    );
    let (one, c1, _) = run(&s, IntegratorKind::RandomWalk, Some(1));
    let (two, c2, _) = run(&s, IntegratorKind::RandomWalk, Some(2));
    assert_eq!(one.pixels, two.pixels);
    assert_eq!(c1, c2);
    let (path, _, _) = run(&s, IntegratorKind::Path, Some(2));
    assert_ne!(
        one.pixels, path.pixels,
        "the option must select a different estimator"
    );
    assert!(one
        .pixels
        .iter()
        .all(|p| p.is_finite() && p.min_element() >= 0.0));
}

/// Open meshes (the Stanford dragon has holes): a bowl (an open hemisphere,
/// seen from its open side, so the medium behind the single sheet is
/// unbounded) and a sphere with a cap cut off, of a medium with σa = 0 and
/// η = 1.3 (total internal reflection keeps walks inside for long). Walks
/// that leave through the hole must end cleanly: no hang, no NaN, counted.
#[test]
fn open_mesh_walks_end_cleanly() {
    let s3 = shapes::sphere(3);
    let pos = s3.positions().to_vec();
    let keep = |f: &dyn Fn(f32) -> bool| -> Mesh {
        let tris = s3
            .indices
            .iter()
            .copied()
            .filter(|t| t.iter().all(|&i| f(pos[i as usize].y)))
            .collect();
        Mesh::new(pos.clone(), tris, None)
    };
    let bowl = keep(&|y| y >= -1e-4);
    let holed = keep(&|y| y <= 0.7);
    let cases = [
        ("bowl", bowl, Vec3::new(0.0, -3.0, 2.0), 1.3, 0.0),
        (
            "bowl",
            keep(&|y| y >= -1e-4),
            Vec3::new(0.0, -3.0, 2.0),
            1.0,
            0.01,
        ),
        ("cut sphere", holed, Vec3::new(0.0, 0.3, 3.0), 1.3, 0.0),
    ];
    for (name, mesh, eye, eta, sigma_a) in cases {
        let params = medium([2.0, 3.0, 4.0], [sigma_a; 3], 0.5, eta);
        let s = scene(
            vec![Part {
                mesh,
                material: subsurface(params),
                emission: None,
            }],
            Some(Vec3::ONE),
            Camera::new(eye, Vec3::ZERO, Vec3::Y, 50.0, 16, 16),
            16,
            8,
        );
        let (film, c, secs) = run(&s, IntegratorKind::RandomWalk, None);
        println!("{name} η {eta} σa {sigma_a}: {c:?} in {secs:.2} s");
        assert!(film
            .pixels
            .iter()
            .all(|p| p.is_finite() && p.min_element() >= 0.0));
        assert_eq!(c.nonfinite, 0);
        assert!(
            c.walks_escaped > 0,
            "{name}: some walks must leave through the opening"
        );
        let (m, _) = mean_and_error(&film);
        // energy is lost through the opening, never created
        assert!(
            m.min_element() > 0.1 && m.max_element() <= 1.05,
            "{name}: {m}"
        );
    }
}

/// A closed sphere of a σa = 0 medium behind a Fresnel boundary (η = 1.3,
/// g = 0.5) in a uniform environment: Fresnel reflection, refraction (with
/// its 1/η² radiance scaling in and η² out) and total internal reflection
/// lose nothing, so every pixel is 1 in expectation, and no walk escapes.
#[test]
fn closed_sphere_with_fresnel_boundary_is_invisible_in_a_furnace() {
    let params = medium([2.0, 3.0, 4.0], [0.0; 3], 0.5, 1.3);
    let ball = Part {
        mesh: shapes::sphere(3),
        material: subsurface(params),
        emission: None,
    };
    let cam = Camera::new(Vec3::new(0.0, 0.0, 2.2), Vec3::ZERO, Vec3::Y, 40.0, 12, 12);
    let (film, c, _) = run(
        &scene(vec![ball], Some(Vec3::ONE), cam, 32, 16),
        IntegratorKind::RandomWalk,
        None,
    );
    let (m, e) = mean_and_error(&film);
    println!("furnace sphere: {m} ± {e}, {c:?}");
    assert_eq!((c.walks_capped, c.walks_escaped, c.nonfinite), (0, 0, 0));
    for k in 0..3 {
        assert!(
            (m[k] - 1.0).abs() < 4.0 * e[k] + 1e-5,
            "channel {k}: {} ± {}",
            m[k],
            e[k]
        );
    }
}

/// A black medium (σs = 0) ends every walk at its first scattering, and a
/// walk with nothing left to carry makes no further query: one flight query
/// per walk, whether it scattered (throughput 0) or crossed to the far
/// face. Every camera ray meets the slab and enters (η = 1, no coat), so
/// the walks are the camera rays.
#[test]
fn a_black_medium_costs_one_query_per_walk() {
    let mat = subsurface(medium([0.0; 3], [2.0, 3.0, 5.0], 0.0, 1.0));
    let s = scene(
        vec![slab(1.0, mat)],
        Some(Vec3::ONE),
        camera_above(8),
        16,
        8,
    );
    let (film, c, _) = run(&s, IntegratorKind::RandomWalk, Some(1));
    let walks = c.effect_rays[Effect::Camera as usize];
    assert_eq!(walks, 8 * 8 * 16);
    assert_eq!(c.effect_rays[Effect::Walk as usize], walks);
    // What crosses the slab (e^{−σa·t} along the way) sees the sky below.
    let (m, _) = mean_and_error(&film);
    assert!(m.max_element() < 0.2, "{m}");
    assert_eq!((c.walks_capped, c.walks_escaped, c.nonfinite), (0, 0, 0));
}

/// A scene of `mesh` alone (a diffuse material, no light): what tests
/// that call [`walk`](lucent::integrator::randomwalk::walk) directly build
/// their context from.
fn walk_scene(mesh: Mesh) -> Scene {
    let part = Part {
        mesh,
        material: Material::Diffuse { albedo: Vec3::ONE },
        emission: None,
    };
    scene(vec![part], None, camera_above(4), 1, 1)
}

/// A walk that cannot end within [`MAX_WALK_EVENTS`] events is stopped
/// there and counted as capped: started at the centre of a sphere of
/// optical radius 10⁴ of a medium that absorbs nothing, a walk needs ~10⁸
/// events to reach the boundary (its distance grows like √N mean free
/// paths), so every one of them stops at the cap and is neither escaped
/// nor lost uncounted. Within the 10⁻² radii it wanders from the centre,
/// every flight is far shorter than the distance to the surface, so the
/// walk asks the accelerator nothing (`randomwalk::walk`: flights within
/// the distance bound need no query); with the bounds off, it asks once
/// per event.
///
/// [`MAX_WALK_EVENTS`]: lucent::integrator::randomwalk::MAX_WALK_EVENTS
#[test]
fn walks_that_cannot_end_stop_at_the_cap_and_are_counted() {
    use lucent::integrator::randomwalk::{walk, Boundary, MAX_WALK_EVENTS};
    use lucent::integrator::Context;
    use lucent::sampling::{Draw, SampleRng};
    let m = Medium {
        sigma_s: [1e4; 3],
        sigma_a: [0.0; 3],
        g: 0.0,
    };
    let s = walk_scene(shapes::sphere(2));
    let a = accel::build(&s.meshes, Backend::Bvh).unwrap();
    let ctx = Context::new(&s, a.as_ref());
    let mut c = Counters::default();
    let walks = 12u64;
    for i in 0..walks {
        let mut rng = SampleRng::new(3, i, 0);
        let d = lucent::sampling::uniform_sphere(rng.uniform2());
        let ray = lucent::geometry::Ray::new(Vec3::ZERO, d);
        let end = walk(&ctx, &m, Boundary::Dielectric(1.0), ray, &mut rng, &mut c);
        assert!(end.is_none(), "walk {i} ended at the boundary");
    }
    assert_eq!(
        (c.walks_capped, c.walks_escaped, c.nonfinite),
        (walks, 0, 0)
    );
    assert_eq!(c.effect_rays[Effect::Walk as usize], 0);
    let mut unbounded = Context::new(&s, a.as_ref());
    unbounded.without_distance_bounds();
    let mut c = Counters::default();
    let mut rng = SampleRng::new(3, 0, 0);
    let ray = lucent::geometry::Ray::new(Vec3::ZERO, Vec3::Z);
    let end = walk(
        &unbounded,
        &m,
        Boundary::Dielectric(1.0),
        ray,
        &mut rng,
        &mut c,
    );
    assert!(end.is_none() && c.walks_capped == 1);
    assert_eq!(c.effect_rays[Effect::Walk as usize], MAX_WALK_EVENTS as u64);
}

/// Closed icospheres never lose a walk (`walks_escaped == 0`), on every
/// backend, at several tessellations and at scales from 10⁻³ to 10³ scene
/// units. The medium is dense (mean free path 10⁻⁴ of the radius), so walks
/// scatter within a few float spacings of the boundary often. Before
/// scattering points were kept inside (`randomwalk::walk`), a point that
/// rounded to the outside lost its walk whenever the next flight headed
/// outwards: this test counted escapes on every configuration.
#[test]
fn closed_icospheres_lose_no_walk_at_any_scale() {
    use lucent::integrator::interaction::offset_along;
    use lucent::integrator::randomwalk::{walk, Boundary};
    use lucent::integrator::Context;
    use lucent::sampling::{cosine_hemisphere, Draw, SampleRng};
    let cases = [(1u32, 1e-3f32), (2, 1e3), (3, 1.0), (4, 1e-2), (5, 1e2)];
    let walks = 24_000u64;
    let mut failures = Vec::new();
    for backend in common::backends() {
        for (subdivisions, scale) in cases {
            let mesh = placed(shapes::sphere(subdivisions), Vec3::splat(scale), Vec3::ZERO);
            // optical radius 10⁴, single-scattering albedo 0.99, no Fresnel
            // (η = 1: every boundary hit leaves) or TIR (η = 1.3) in turn
            let k = 1e4 / scale as f64;
            let m = Medium {
                sigma_s: [0.99 * k; 3],
                sigma_a: [0.01 * k; 3],
                g: 0.0,
            };
            let s = walk_scene(mesh.clone());
            let a = accel::build(&s.meshes, backend).unwrap();
            let ctx = Context::new(&s, a.as_ref());
            let mut c = Counters::default();
            let pos = mesh.positions();
            for i in 0..walks {
                let mut rng = SampleRng::new(subdivisions as u64, i, 0);
                // a uniform point on a random triangle, entering along a
                // cosine-distributed direction
                let tri = mesh.indices
                    [(rng.uniform_f64() * mesh.indices.len() as f64) as usize % mesh.indices.len()];
                let [p0, p1, p2] = tri.map(|j| pos[j as usize]);
                let [mut u, mut v] = rng.uniform2();
                if u + v > 1.0 {
                    (u, v) = (1.0 - u, 1.0 - v);
                }
                let p = p0 + (p1 - p0) * u + (p2 - p0) * v;
                let n = (p1 - p0).cross(p2 - p0).normalize();
                let frame = lucent::geometry::Frame::from_normal(-n);
                let d = frame
                    .to_world(cosine_hemisphere(rng.uniform2()))
                    .normalize();
                let ray = lucent::geometry::Ray::new(offset_along(p, -n, ctx.ray_epsilon), d);
                let eta = if i % 2 == 0 { 1.0 } else { 1.3 };
                walk(&ctx, &m, Boundary::Dielectric(eta), ray, &mut rng, &mut c);
            }
            println!(
                "{backend:?} sphere({subdivisions}) × {scale}: {walks} walks, {} rays, {} capped, {} escaped",
                c.rays, c.walks_capped, c.walks_escaped
            );
            if c.walks_escaped != 0 {
                failures.push(format!(
                    "{backend:?} sphere({subdivisions}) × {scale}: {} of {walks} walks escaped",
                    c.walks_escaped
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The diffuse Fresnel boundary as a material option.
fn with_boundary(params: SubsurfaceParams, boundary: WalkBoundary) -> Material {
    let Material::Subsurface(ss) = subsurface(params) else {
        unreachable!()
    };
    let options = lucent::materials::EstimatorOptions {
        boundary,
        ..*ss.options()
    };
    Material::Subsurface(Arc::new(ss.with_options(&options).unwrap()))
}

/// The diffuse Fresnel boundary conserves energy exactly
/// (`integrator::diffuse_boundary`): a closed sphere of a σa = 0 chromatic
/// medium (η = 1.5, so most of the boundary reflects internally, and
/// g = 0.5) in a uniform environment of radiance 1 returns 1 in every
/// channel, like the dielectric boundary. The exit lobe's normalization
/// 1 − F̄ enters through the weight T/(1 − F̄) of every exit: an error of
/// 2 % there, or a lobe without its Fresnel factor (+9 %, checked by hand),
/// fails this.
#[test]
fn diffuse_boundary_sphere_is_invisible_in_a_furnace() {
    for (eta, g) in [(1.5, 0.5), (1.0, 0.0), (0.8, 0.0)] {
        let params = medium([2.0, 3.0, 4.0], [0.0; 3], g, eta);
        let ball = Part {
            mesh: shapes::sphere(3),
            material: with_boundary(params, WalkBoundary::Diffuse { exit_nee: true }),
            emission: None,
        };
        let cam = Camera::new(Vec3::new(0.0, 0.0, 2.2), Vec3::ZERO, Vec3::Y, 40.0, 16, 16);
        let (film, c, _) = run(
            &scene(vec![ball], Some(Vec3::ONE), cam, 64, 16),
            IntegratorKind::RandomWalk,
            None,
        );
        let (m, e) = mean_and_error(&film);
        println!("η {eta}, g {g}: diffuse-boundary furnace {m} ± {e}, {c:?}");
        assert_eq!((c.walks_capped, c.walks_escaped, c.nonfinite), (0, 0, 0));
        for k in 0..3 {
            assert!(
                (m[k] - 1.0).abs() < 4.0 * e[k] + 1e-5,
                "η {eta}, channel {k}: {} ± {}",
                m[k],
                e[k]
            );
        }
    }
}

/// Light sampling at the exit point changes the estimator, not the model:
/// a sphere under a square area light and a dim sky, rendered with the
/// diffuse boundary with and without next-event estimation at the exit,
/// gives the same image mean per channel (within 4 standard errors of the
/// per-pixel difference, ≈ 1.5 % of the mean here), and the estimate with
/// light sampling is several times less noisy. An exit lobe whose value in
/// light sampling disagrees with what lobe sampling weighs by more than
/// ~10 % fails the first check (a 5 % disagreement shows as 2.3 standard
/// errors: this is a check of gross errors, the furnace test above checks
/// the lobe's normalization to ~1 %).
#[test]
fn diffuse_boundary_light_sampling_keeps_the_mean() {
    let params =
        SubsurfaceParams::from_artist([0.8, 0.5, 0.3], [0.5, 0.3, 0.1], 1.4, Fit::Searchlight)
            .unwrap();
    let mut lamp = placed(shapes::quad(), Vec3::splat(0.6), Vec3::new(0.0, 0.0, 3.0));
    lamp.flip_winding(); // face −z, towards the ball
    let make = |exit_nee| {
        scene(
            vec![
                Part {
                    mesh: shapes::sphere(3),
                    material: with_boundary(params, WalkBoundary::Diffuse { exit_nee }),
                    emission: None,
                },
                Part {
                    mesh: lamp.clone(),
                    material: Material::Diffuse { albedo: Vec3::ZERO },
                    emission: Some(Vec3::splat(5.0)),
                },
            ],
            Some(Vec3::splat(0.05)),
            Camera::new(Vec3::new(0.0, 2.5, 3.0), Vec3::ZERO, Vec3::Y, 40.0, 24, 24),
            256,
            8,
        )
    };
    let (nee, c1, t1) = run(&make(true), IntegratorKind::RandomWalk, None);
    let (plain, c2, t2) = run(&make(false), IntegratorKind::RandomWalk, None);
    assert_eq!((c1.walks_escaped, c2.walks_escaped), (0, 0));
    assert_eq!((c1.nonfinite, c2.nonfinite), (0, 0));
    let (ma, _) = mean_and_error(&nee);
    let (mb, _) = mean_and_error(&plain);
    println!("with NEE {ma} ({t1:.2} s), without {mb} ({t2:.2} s)");
    assert_same_mean(&nee, &plain);
    let (r_nee, r_plain) = (roughness(&nee), roughness(&plain));
    println!("roughness with NEE {r_nee}, without {r_plain}");
    assert!(r_nee * 3.0 < r_plain, "{r_nee} vs {r_plain}");
}

/// Two estimators of one image agree: per channel, the mean over the
/// pixels of their difference is within 4 of its standard errors and
/// within 5 % of `a`'s mean.
fn assert_same_mean(a: &Film, b: &Film) {
    let n = a.pixels.len() as f64;
    let (mut mean, mut sq) = ([0f64; 3], [0f64; 3]);
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        for k in 0..3 {
            let d = (p[k] - q[k]) as f64;
            mean[k] += d / n;
            sq[k] += d * d / n;
        }
    }
    let (ma, _) = mean_and_error(a);
    for k in 0..3 {
        let se = ((sq[k] - mean[k] * mean[k]) / (n - 1.0)).sqrt();
        println!("channel {k}: difference {} ± {se}", mean[k]);
        assert!(mean[k].abs() < 4.0 * se, "channel {k}: {} ± {se}", mean[k]);
        assert!(mean[k].abs() < 0.05 * ma[k] as f64, "channel {k}");
    }
}

/// An image's pixel-to-pixel roughness (squared adjacent-pixel
/// differences), dominated by sampling noise at a few hundred spp: the
/// variance about a smooth reference is not available in these tests.
fn roughness(f: &Film) -> f64 {
    let w = f.width as usize;
    let mut s = 0.0;
    for (i, p) in f.pixels.iter().enumerate() {
        if i % w + 1 < w {
            let q = f.pixels[i + 1];
            s += ((p.x - q.x).powi(2) + (p.y - q.y).powi(2) + (p.z - q.z).powi(2)) as f64;
        }
    }
    s
}

/// A sphere of a chromatic medium (η = 1.4) under a square light and a dim
/// sky, with the smooth dielectric boundary: `connect` samples the lights
/// through the boundary from the walk's scattering points.
fn lit_dielectric_ball(connect: bool, res: u32, spp: u32) -> Scene {
    let params =
        SubsurfaceParams::from_artist([0.8, 0.5, 0.3], [0.5, 0.3, 0.1], 1.4, Fit::Searchlight)
            .unwrap();
    let mut lamp = placed(shapes::quad(), Vec3::splat(0.6), Vec3::new(0.0, 0.0, 3.0));
    lamp.flip_winding(); // face −z, towards the ball
    scene(
        vec![
            Part {
                mesh: shapes::sphere(3),
                material: with_boundary(params, WalkBoundary::Dielectric { connect }),
                emission: None,
            },
            Part {
                mesh: lamp,
                material: Material::Diffuse { albedo: Vec3::ZERO },
                emission: Some(Vec3::splat(5.0)),
            },
        ],
        Some(Vec3::splat(0.05)),
        Camera::new(
            Vec3::new(0.0, 2.5, 3.0),
            Vec3::ZERO,
            Vec3::Y,
            40.0,
            res,
            res,
        ),
        spp,
        8,
    )
}

/// Sampling the lights through the smooth boundary changes the estimator,
/// not the model: the walk with the connection and without it give the
/// same image mean per channel (within 4 standard errors of the per-pixel
/// difference), and the connection's image is less noisy. A connection
/// without the η² of radiance entering the medium, without Fresnel's
/// transmittance or with a wrong geometry term moves the mean by far more
/// than that; so does an exit whose emission both estimators count (the
/// split `walk_nee::covers` draws), or that neither does.
#[test]
fn light_through_the_smooth_boundary_keeps_the_mean() {
    let (on, c1, t1) = run(
        &lit_dielectric_ball(true, 24, 256),
        IntegratorKind::RandomWalk,
        None,
    );
    let (off, c2, t2) = run(
        &lit_dielectric_ball(false, 24, 256),
        IntegratorKind::RandomWalk,
        None,
    );
    assert_eq!((c1.walks_escaped, c2.walks_escaped), (0, 0));
    assert_eq!((c1.nonfinite, c2.nonfinite), (0, 0));
    assert!(on
        .pixels
        .iter()
        .all(|p| p.is_finite() && p.min_element() >= 0.0));
    let (ma, _) = mean_and_error(&on);
    let (mb, _) = mean_and_error(&off);
    println!("with the connection {ma} ({t1:.2} s), without {mb} ({t2:.2} s)");
    assert_same_mean(&on, &off);
    let (r_on, r_off) = (roughness(&on), roughness(&off));
    println!("roughness with the connection {r_on}, without {r_off}");
    assert!(r_on * 2.0 < r_off, "{r_on} vs {r_off}");
}

/// The connection draws its randoms from the sample's own stream: the
/// same image, bit for bit, for any thread count.
#[test]
fn light_through_the_smooth_boundary_is_deterministic_across_thread_counts() {
    let s = lit_dielectric_ball(true, 20, 4);
    let (one, c1, _) = run(&s, IntegratorKind::RandomWalk, Some(1));
    let (two, c2, _) = run(&s, IntegratorKind::RandomWalk, Some(2));
    assert_eq!(one.pixels, two.pixels);
    assert_eq!(c1, c2);
}

/// On a coarse ball (80 facets; the normal turns by ≈ 0.4 rad across each
/// edge) a light point is often reached from a scattering point through
/// two neighbouring facets. Every path the connection counts
/// (`walk_nee::counted_paths`) is a refracted path: its point lies on its
/// triangle, the segment from x meets that triangle first, and Snell's
/// law there carries x's direction onto l. The walk leaves each of them
/// to the connection (`walk_nee::covers`), so none counts twice; and
/// paths through a neighbour are found (the facet's alone would leave
/// them to the walk's heavy tail). A walk leaving only the first facet's
/// exits to the connection, a neighbour solved on the wrong plane or not
/// checked to hold its point, or no neighbours at all, fail here.
#[test]
fn connection_paths_are_refracted_paths_the_walk_leaves_to_it() {
    use lucent::integrator::walk_nee::{counted_paths, left_to_connection};
    use lucent::integrator::Context;
    use lucent::sampling::Rng;
    let eta = 1.4f32;
    let params =
        SubsurfaceParams::from_artist([0.8, 0.5, 0.3], [0.5, 0.3, 0.1], eta, Fit::Searchlight)
            .unwrap();
    let ball = scene(
        vec![Part {
            mesh: shapes::sphere(1),
            material: with_boundary(params, WalkBoundary::Dielectric { connect: true }),
            emission: None,
        }],
        None,
        Camera::new(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, 40.0, 8, 8),
        1,
        8,
    );
    let accel = accel::build(&ball.meshes, Backend::Bvh).unwrap();
    let ctx = Context::new(&ball, accel.as_ref());
    let mesh = &ball.meshes[0];
    let mut rng = Rng::from_key(39);
    let mut u = || rng.uniform_f64() as f32;
    let (mut pairs, mut found, mut second) = (0, 0, 0);
    while pairs < 4000 {
        // x inside, towards the light; l on a square at z = 3
        let x = Vec3::new(2.0 * u() - 1.0, 2.0 * u() - 1.0, u()) * 0.9;
        if x.length() > 0.85 || x.length() < 0.3 {
            continue;
        }
        let l = Vec3::new(0.6 * u() - 0.3, 0.6 * u() - 0.3, 3.0);
        pairs += 1;
        let paths = counted_paths(&ctx, x, l, eta);
        found += paths.len().min(1);
        second += paths.len().saturating_sub(1);
        for (i, &(geom, prim, y)) in paths.iter().enumerate() {
            assert!(
                paths[..i].iter().all(|p| p.1 != prim),
                "{x} {l}: twice {prim}"
            );
            let ng = mesh.face_normal(prim);
            let n = if ng.dot(l - x) > 0.0 { ng } else { -ng };
            let w1 = (y - x).normalize();
            let hit = accel
                .intersect(&lucent::geometry::Ray::new(x, w1), 0.0, f32::INFINITY)
                .unwrap();
            assert_eq!((hit.geom, hit.prim), (geom, prim), "{x} {l}: not first");
            let tangent = w1 - n * w1.dot(n);
            let out = tangent * eta + n * (1.0 - eta * eta * tangent.length_squared()).sqrt();
            let to_l = (l - y).normalize();
            assert!(out.dot(to_l) > 1.0 - 1e-6, "{x} {l}: {out} vs {to_l}");
            assert!(
                left_to_connection(&ctx, x, geom, prim, l, eta),
                "{x} {l}: the walk counts {prim} too"
            );
        }
    }
    println!("{pairs} pairs: {found} with a path, {second} with a second");
    assert!(found > pairs / 2, "{found} of {pairs}");
    assert!(second * 50 > found, "{second} of {found}");
}

/// The dielectric boundary stays the default; the diffuse one is as
/// deterministic across thread counts (its rejection sampling draws from
/// the sample's own stream).
#[test]
fn diffuse_boundary_is_deterministic_across_thread_counts() {
    let params =
        SubsurfaceParams::from_artist([0.8, 0.5, 0.3], [0.5, 0.3, 0.1], 1.3, Fit::Searchlight)
            .unwrap();
    let Material::Subsurface(ss) = subsurface(params) else {
        unreachable!()
    };
    assert_eq!(ss.boundary(), WalkBoundary::DIELECTRIC);
    let ball = placed(shapes::sphere(2), Vec3::splat(1.0), Vec3::ZERO);
    let make = |b| {
        scene(
            vec![Part {
                mesh: ball.clone(),
                material: with_boundary(params, b),
                emission: None,
            }],
            Some(Vec3::splat(1.0)),
            Camera::new(Vec3::new(0.0, 1.0, 4.0), Vec3::ZERO, Vec3::Y, 40.0, 20, 12),
            4,
            6,
        )
    };
    let diffuse = make(WalkBoundary::Diffuse { exit_nee: true });
    let (one, c1, _) = run(&diffuse, IntegratorKind::RandomWalk, Some(1));
    let (two, c2, _) = run(&diffuse, IntegratorKind::RandomWalk, Some(2));
    assert_eq!(one.pixels, two.pixels);
    assert_eq!(c1, c2);
    assert!(one
        .pixels
        .iter()
        .all(|p| p.is_finite() && p.min_element() >= 0.0));
}

/// The study compares both boundaries: the full matrix has a `boundary`
/// row rendering the random walk with the other boundary than the scene's,
/// and applying its overrides sets it on every subsurface material.
#[test]
fn study_matrix_has_the_other_boundary() {
    use lucent_tools::study::config::{apply, matrix};
    use lucent_tools::study::Axis;
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/slab-uniform.toml");
    let s = lucent::scene::load(&path).unwrap();
    let full = matrix(&s, false, &[Backend::Bvh]).unwrap();
    let rows: Vec<_> = full.iter().filter(|c| c.axis == Axis::Boundary).collect();
    assert_eq!(rows.len(), 1);
    let row = rows[0];
    assert_eq!(row.integrator, IntegratorKind::RandomWalk);
    assert_eq!(
        (row.name.as_str(), row.value.as_str()),
        ("boundary=diffuse", "diffuse")
    );
    let applied = apply(&s, &row.overrides).unwrap();
    for m in &applied.materials {
        if let Material::Subsurface(ss) = m {
            assert_eq!(ss.boundary(), WalkBoundary::Diffuse { exit_nee: true });
        }
    }
    assert!(!matrix(&s, true, &[Backend::Bvh])
        .unwrap()
        .iter()
        .any(|c| c.axis == Axis::Boundary));
}

/// Inside the diffuse boundary a walk reflects in the mirror direction
/// about the surface normal. In a cube of a clear medium (no scattering on
/// the way) a mirror path is a straight line folded at the faces: from a
/// start that meets a face at total internal reflection first (cosine
/// 0.30 < 0.75 at η = 1.5), every walk must leave at one of the face hits
/// of the folded line, through that face. A reflection off the mirror
/// direction (the mutation 2μ → 2 + μ in the walk) leaves
/// elsewhere. The cube is walked twice, wound outwards and inwards: the
/// exit normal faces the way the walk leaves, whichever way the mesh's
/// triangles face.
#[test]
fn the_walk_reflects_inside_the_diffuse_boundary_in_the_mirror_direction() {
    use lucent::integrator::diffuse_boundary::DiffuseBoundary;
    use lucent::integrator::randomwalk::{walk, Boundary, WalkEnd};
    use lucent::integrator::Context;
    use lucent::sampling::SampleRng;
    let m = Medium {
        sigma_s: [0.0; 3],
        sigma_a: [1e-9; 3],
        g: 0.0,
    };
    let outward = shapes::cuboid();
    let inward = Mesh::new(
        outward.positions().to_vec(),
        outward.indices.iter().map(|&[i, j, k]| [i, k, j]).collect(),
        None,
    );
    let b = DiffuseBoundary::new(1.5);
    let p0 = Vec3::new(0.8, 0.0, -0.5);
    let d0 = Vec3::new(0.3, 0.5, 0.8).normalize();
    // the folded line's face hits: (point, outward normal)
    let mut hits = Vec::new();
    let (mut p, mut d) = (p0, d0);
    for _ in 0..400 {
        let t = |k: usize| (d[k].signum() - p[k]) / d[k];
        let k = (0..3).min_by(|&i, &j| t(i).total_cmp(&t(j))).unwrap();
        p += d * t(k);
        let mut n = Vec3::ZERO;
        n[k] = d[k].signum();
        hits.push((p, n));
        d[k] = -d[k];
    }
    assert_eq!(hits[0].1, Vec3::X, "the first face met is x = 1");
    for mesh in [outward, inward] {
        let s = walk_scene(mesh);
        let a = accel::build(&s.meshes, Backend::Bvh).unwrap();
        let ctx = Context::new(&s, a.as_ref());
        let mut c = Counters::default();
        let mut reflected = 0;
        for i in 0..64u64 {
            let mut rng = SampleRng::new(11, i, 0);
            let ray = lucent::geometry::Ray::new(p0, d0);
            let Some((WalkEnd::Exit { p, n_out }, _)) =
                walk(&ctx, &m, Boundary::Diffuse(&b), ray, &mut rng, &mut c)
            else {
                panic!("walk {i} did not leave through the boundary");
            };
            let at = hits.iter().position(|(h, _)| (*h - p).length() < 1e-4);
            let Some(k) = at else {
                panic!("walk {i} left at {p}, off the mirror path");
            };
            assert_eq!(n_out, hits[k].1, "walk {i}: normal at hit {k}");
            reflected += k;
        }
        // every walk reflected at least once (x = 1 first); several more often
        assert!(reflected > 64, "{reflected} reflections in 64 walks");
    }
}

/// Each sample's radiance under the random walk (bits) and the walk's
/// flight queries, `spp` samples of every pixel, with the walk's distance
/// bounds as the context builds them or switched off.
fn walk_samples(scene: &Scene, backend: Backend, bounds: bool, spp: u64) -> (Vec<[u32; 3]>, u64) {
    use lucent::integrator::path::Scratch;
    use lucent::integrator::{Context, NoClock};
    use lucent::sampling::{Draw, SampleRng};
    let accel = accel::build(&scene.meshes, backend).unwrap();
    let mut ctx = Context::new(scene, accel.as_ref());
    if !bounds {
        ctx.without_distance_bounds();
    }
    let (mut scratch, mut counters) = (Scratch::default(), Counters::default());
    let (w, h) = (scene.camera.width, scene.camera.height);
    let mut out = Vec::new();
    for pixel in 0..(w * h) as u64 {
        for s in 0..spp {
            let mut rng = SampleRng::new(7, pixel, s);
            let [jx, jy] = rng.uniform2_packed();
            let (x, y) = ((pixel % w as u64) as f32, (pixel / w as u64) as f32);
            let ray = scene.camera.ray(x + jx, y + jy);
            let l = IntegratorKind::RandomWalk.radiance::<_, NoClock>(
                &ctx,
                ray,
                &mut rng,
                &mut scratch,
                &mut counters,
                &mut lucent::integrator::aov::NoAov,
            );
            out.push(l.to_array().map(f32::to_bits));
        }
    }
    (out, counters.effect_rays[Effect::Walk as usize])
}

/// A flight shorter than the distance bound at its origin scatters without
/// a query (`randomwalk::walk`, `geometry::distance`): that changes no
/// sample, bit for bit, on the marble sphere (convex) and the marble bunny
/// (not convex; its floor meets the grid), with both boundaries and on
/// every backend, while it saves more than half of the walk's queries. A
/// bound larger than the distance (the cells' half-diagonals left out of
/// it) lets flights leave the body unseen: samples differ.
#[test]
fn distance_bounds_change_no_sample_bit_for_bit() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for name in ["smooth-sphere", "marble-bunny"] {
        let mut scene = lucent::scene::load(&root.join(format!("scenes/{name}.toml"))).unwrap();
        let c = &scene.camera;
        scene.camera = Camera::new(c.look_from, c.look_at, c.up, c.fov_y, 16, 12);
        for boundary in [
            WalkBoundary::DIELECTRIC,
            WalkBoundary::Diffuse { exit_nee: true },
        ] {
            let mut s = scene.clone();
            for m in s.materials.iter_mut() {
                if let Material::Subsurface(ss) = m {
                    let options = lucent::materials::EstimatorOptions {
                        boundary,
                        ..*ss.options()
                    };
                    *m = Material::Subsurface(Arc::new(ss.with_options(&options).unwrap()));
                }
            }
            for backend in common::backends() {
                let (on, q_on) = walk_samples(&s, backend, true, 2);
                let (off, q_off) = walk_samples(&s, backend, false, 2);
                let differ = on.iter().zip(&off).filter(|(a, b)| a != b).count();
                println!(
                    "{name} {boundary:?} {backend:?}: {q_on} queries with bounds, \
                     {q_off} without, {differ} samples differ"
                );
                assert_eq!(differ, 0, "{name} {boundary:?} {backend:?}");
                assert!(
                    2 * q_on < q_off,
                    "{name} {boundary:?} {backend:?}: {q_on} vs {q_off}"
                );
            }
        }
    }
}
