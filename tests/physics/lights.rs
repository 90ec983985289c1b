//! The `[[lights]]` and `power` against closed forms: each light over a
//! diffuse plane of albedo ρ gives the pixel ρE/π for its irradiance E
//! (a sphere of radiance L at distance d and angle α off the normal:
//! E = π L (r/d)² cos α, exact for a sphere above the horizon; a spot
//! scales that by its falloff; a distant light E cos θ, its cone of radiance
//! L giving E = π sin² θmax L); `power` converts to the radiance
//! `docs/scene-format.md` states; a sun's penumbra is as wide as its angle
//! says. Both halves of MIS count: the plane's lobe rays reach the sphere
//! lights and the sun's cone (max_depth 1).

use std::f64::consts::PI;
use std::path::Path;

use crate::common;
use lucent::accel::{self, Backend};
use lucent::analytic_lights::Light;
use lucent::film::Film;
use lucent::geometry::Vec3;
use lucent::render::{render, RenderOptions};
use lucent::scene::{load_str, Scene};

const RHO: f64 = 0.5;

/// A diffuse plane y = 0 of albedo [`RHO`] seen straight down from y = 1
/// through a 2° field of view (a patch 3.5 cm wide about the origin), with
/// `lights` (TOML) and 1 scene unit = 1 m.
fn plane_under(lights: &str, spp: u32) -> Scene {
    let text = format!(
        r#"
units_per_mm = 0.001
[camera]
look_from = [0, 1, 0]
look_at = [0, 0, 0]
up = [0, 0, -1]
fov_y = 2
resolution = [16, 16]
[render]
spp = {spp}
max_depth = 1
seed = 7
[materials.plane]
type = "diffuse"
albedo = [{RHO}, {RHO}, {RHO}]
[[shapes]]
type = "quad"
material = "plane"
scale = 100
rotate = [[-90, 1, 0, 0]]
{lights}
"#
    );
    load_str(&text, Path::new("lights-test.toml")).unwrap()
}

fn run(scene: &Scene) -> Film {
    let a = accel::build(&scene.meshes, Backend::default_available()).unwrap();
    render(scene, a.as_ref(), &RenderOptions::default())
        .unwrap()
        .0
}

/// The pixel mean is ρE/π for irradiance `e` (per channel), within four
/// standard errors and 0.3 % (the patch's own spread of E).
fn assert_irradiance(scene: &Scene, e: [f64; 3], what: &str) {
    let film = run(scene);
    let (m, se) = common::mean_se(&film);
    for c in 0..3 {
        let want = RHO * e[c] / PI;
        let tol = 4.0 * se[c] + 3e-3 * want;
        assert!(
            (m[c] - want).abs() <= tol,
            "{what}: channel {c}: pixel mean {} ± {}, expected {want}",
            m[c],
            se[c]
        );
    }
}

/// A sphere light at (1, 2, 0): d = √5 from the patch, cos α = 2/√5.
const D2: f64 = 5.0;
const COS_A: f64 = 0.894_427_190_999_915_9;

fn sphere(radius: f64, strength: &str) -> String {
    format!("[[lights]]\ntype = \"sphere\"\nposition = [1, 2, 0]\nradius = {radius}\n{strength}\n")
}

#[test]
fn a_sphere_light_lights_a_plane_with_its_irradiance() {
    let l = [8.0, 4.0, 2.0];
    for r in [0.3, 1e-3] {
        // radiance scaled so that E stays the same
        let k = 0.09 / (r * r);
        let text = sphere(
            r,
            &format!("radiance = [{}, {}, {}]", l[0] * k, l[1] * k, l[2] * k),
        );
        let e = l.map(|l| PI * l * k * r * r / D2 * COS_A);
        assert_irradiance(&plane_under(&text, 64), e, &format!("radius {r}"));
    }
}

#[test]
fn a_sphere_lights_power_is_its_radiance_and_its_irradiance() {
    // 1 scene unit = 1 m: Φ = 4π² r² L, E = Φ cos α / (4π d²).
    let p = [60.0, 30.0, 15.0];
    let r = 0.05;
    let s = plane_under(
        &sphere(r, &format!("power = [{}, {}, {}]", p[0], p[1], p[2])),
        64,
    );
    let Light::Sphere(l) = s.lights[0] else {
        panic!("not a sphere light")
    };
    for (c, p) in p.iter().enumerate() {
        let want = p / (4.0 * PI * PI * r * r);
        let rel = (l.radiance[c] as f64 / want - 1.0).abs();
        assert!(
            rel < 1e-6,
            "channel {c}: L = {}, expected {want}",
            l.radiance[c]
        );
    }
    let e = p.map(|p| p * COS_A / (4.0 * PI * D2));
    assert_irradiance(&s, e, "power");
}

#[test]
fn power_converts_with_the_scenes_metres() {
    // The same sphere light and emitting quad in a millimetre scene: r and
    // the area are 1000× and 10⁶× smaller in metres.
    let text = |units_per_mm: f64| {
        format!(
            "units_per_mm = {units_per_mm}\n[camera]\nlook_from = [0, 0, 5]\nlook_at = [0, 0, 0]\n\
             resolution = [4, 4]\n[materials.m]\ntype = \"diffuse\"\nalbedo = [0, 0, 0]\n\
             [[shapes]]\ntype = \"quad\"\nmaterial = \"m\"\nscale = 3\npower = [10, 20, 30]\n\
             [[lights]]\ntype = \"sphere\"\nposition = [0, 0, 1]\nradius = 0.5\n\
             power = [10, 20, 30]\nspot_direction = [0, 0, -1]\nspot_angle = 30\nspot_falloff = 10\n"
        )
    };
    for (units_per_mm, m_per_unit) in [(0.001, 1.0), (1.0, 1e-3)] {
        let s = load_str(&text(units_per_mm), Path::new("p.toml")).unwrap();
        // The quad is 2 × 2 scaled by 3: 36 unit², one-sided: Φ = π A L.
        let a = 36.0 * m_per_unit * m_per_unit;
        let le = s.objects[0].emission.unwrap();
        // The spot: Φ = π r² L · 2π ((1 − cos 20°) + (cos 20° − cos 30°)/2).
        let Light::Sphere(l) = s.lights[0] else {
            panic!("not a sphere light")
        };
        let r = 0.5 * m_per_unit;
        let (ci, co) = (20f64.to_radians().cos(), 30f64.to_radians().cos());
        let omega = 2.0 * PI * ((1.0 - ci) + (ci - co) / 2.0);
        for (c, p) in [10.0, 20.0, 30.0].into_iter().enumerate() {
            let (want_mesh, want_spot) = (p / (PI * a), p / (PI * r * r * omega));
            assert!(
                (le[c] as f64 / want_mesh - 1.0).abs() < 1e-5,
                "mesh: {le:?}"
            );
            let got = l.radiance[c] as f64;
            assert!(
                (got / want_spot - 1.0).abs() < 1e-5,
                "spot: {got} vs {want_spot}"
            );
        }
    }
}

/// The spot aimed `off` degrees (about z) away from the patch.
fn spot(off: f64) -> String {
    let (x, y) = (-1.0 / D2.sqrt(), -2.0 / D2.sqrt());
    let (s, c) = off.to_radians().sin_cos();
    let axis = [x * c - y * s, x * s + y * c];
    sphere(
        0.01,
        &format!(
            "radiance = [900, 900, 900]\nspot_direction = [{}, {}, 0]\nspot_angle = 40\n\
             spot_falloff = 20",
            axis[0], axis[1]
        ),
    )
}

#[test]
fn a_spot_light_scales_the_spheres_irradiance_by_its_falloff() {
    let full = PI * 900.0 * 1e-4 / D2 * COS_A;
    assert_irradiance(
        &plane_under(&spot(0.0), 16),
        [full; 3],
        "aimed at the patch",
    );
    // Halfway through the smoothstep in cos θ: cos θ = (cos 20° + cos 40°)/2.
    let (ci, co) = (20f64.to_radians().cos(), 40f64.to_radians().cos());
    let half = ((ci + co) / 2.0).acos().to_degrees();
    assert_irradiance(&plane_under(&spot(half), 16), [full / 2.0; 3], "half");
    let film = run(&plane_under(&spot(60.0), 4));
    assert!(film.pixels.iter().all(|p| *p == Vec3::ZERO), "aimed away");
}

/// A distant light travelling along (−1, −2, 0): cos θ = 2/√5 on the plane.
fn distant(angle: f64, strength: &str) -> String {
    format!(
        "[[lights]]\ntype = \"distant\"\ndirection = [-1, -2, 0]\nangle = {angle}\n{strength}\n"
    )
}

#[test]
fn a_distant_light_lights_a_plane_with_its_irradiance() {
    let e = [3.0, 2.0, 1.0];
    let irr = "irradiance = [3, 2, 1]";
    for angle in [0.0, 0.53, 20.0] {
        assert_irradiance(
            &plane_under(&distant(angle, irr), 32),
            e.map(|e| e * COS_A),
            &format!("angle {angle}"),
        );
    }
    // The radiance form: E = π sin²(15°) L.
    let sin2 = 15f64.to_radians().sin().powi(2);
    assert_irradiance(
        &plane_under(&distant(30.0, "radiance = [3, 2, 1]"), 64),
        e.map(|l| PI * sin2 * l * COS_A),
        "radiance",
    );
}

#[test]
fn a_suns_penumbra_is_as_wide_as_its_angle() {
    // A sun straight overhead of angular diameter 10°, a black occluder
    // y = 1 over x < 0, the camera at y = 0.5 looking down at x ∈
    // [−0.5, 0.5] (a 128 × 8 image: fov_y = 2 atan(1/16)). On the plane the sun's disc has radius R = tan 5°; the
    // lit fraction across the edge is the fraction of a disc beyond a line,
    // F(u) = ½ + (u √(1 − u²) + asin u)/π for u = x/R, so the 10–90 %
    // width is R (u₉₀ − u₁₀).
    let text = r#"
units_per_mm = 0.001
[camera]
look_from = [0, 0.5, 0]
look_at = [0, 0, 0]
up = [0, 0, -1]
fov_y = 7.1525
resolution = [128, 8]
[render]
spp = 256
max_depth = 1
[materials.plane]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]
[materials.black]
type = "diffuse"
albedo = [0, 0, 0]
[[shapes]]
type = "quad"
material = "plane"
scale = 100
rotate = [[-90, 1, 0, 0]]
[[shapes]]
type = "quad"
material = "black"
scale = [5, 5, 1]
rotate = [[90, 1, 0, 0]]
translate = [-5, 1, 0]
[[lights]]
type = "distant"
direction = [0, -1, 0]
angle = 10
irradiance = [1, 1, 1]
"#;
    let s = load_str(text, Path::new("penumbra.toml")).unwrap();
    let film = run(&s);
    let (w, h) = (128usize, 8usize);
    // Column means of the green channel; x of a column centre on the plane
    // (the camera is 0.5 above it; the half-width is 0.5 · tan(fov_y/2) · 16).
    let col: Vec<f64> = (0..w)
        .map(|x| {
            (0..h)
                .map(|y| film.pixels[y * w + x][1] as f64)
                .sum::<f64>()
                / h as f64
        })
        .collect();
    let full = 0.5 / PI;
    let half_width = 0.5 * (7.1525f64 / 2.0).to_radians().tan() * (w as f64 / h as f64);
    let x_of = |i: f64| (2.0 * (i + 0.5) / w as f64 - 1.0) * half_width;
    // First column (from the left, shadowed side) at or above a fraction.
    let crossing = |f: f64| {
        let i = col.iter().position(|&v| v >= f * full).expect("never lit");
        // linear interpolation between columns i − 1 and i
        let (a, b) = (col[i - 1] / full, col[i] / full);
        x_of(i as f64 - 1.0 + (f - a) / (b - a))
    };
    let measured = crossing(0.9) - crossing(0.1);
    let lit = |u: f64| 0.5 + (u * (1.0 - u * u).sqrt() + u.asin()) / PI;
    let solve = |f: f64| {
        let (mut lo, mut hi) = (-1.0, 1.0);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if lit(mid) < f {
                lo = mid
            } else {
                hi = mid
            }
        }
        lo
    };
    let r = 5f64.to_radians().tan();
    let expect = r * (solve(0.9) - solve(0.1));
    assert!(
        (measured / expect - 1.0).abs() < 0.15,
        "10–90 % penumbra {measured}, expected {expect}"
    );
    // And centred on the occluder's edge, x = 0.
    let mid = crossing(0.5);
    assert!(mid.abs() < 0.1 * expect, "half-lit at x = {mid}");
}

/// A marble ball on a grey floor under a light of radius 0.3 at (0.5, 2,
/// 0.5): a `[[lights]]` sphere, or an emitting icosphere of the same
/// radiance (`mesh`), with no environment, so that the sphere light's not
/// casting shadows changes nothing the camera sees.
#[cfg(feature = "subsurface")]
fn marble_under(light: &str) -> Scene {
    let text = format!(
        r#"
units_per_mm = 0.01
[camera]
look_from = [0, 1.2, 3]
look_at = [0, 0.4, 0]
fov_y = 30
resolution = [32, 24]
[render]
spp = 256
max_depth = 3
seed = 11
[materials.floor]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]
[materials.marble]
type = "subsurface"
preset = "marble"
[materials.lamp]
type = "diffuse"
albedo = [0, 0, 0]
[[shapes]]
type = "quad"
material = "floor"
scale = 3
rotate = [[-90, 1, 0, 0]]
[[shapes]]
type = "sphere"
subdivisions = 3
material = "marble"
scale = 0.4
translate = [0, 0.4, 0]
{light}
"#
    );
    load_str(&text, Path::new("marble-lights.toml")).unwrap()
}

/// The probes' entry points sample a sphere light as they sample an
/// emitting mesh: the same image (its mean within noise and the
/// icosphere's 0.3 % less area) from the `[[lights]]` sphere and from an
/// emitting icosphere of its radius and radiance.
#[cfg(feature = "subsurface")]
#[test]
fn a_sphere_light_on_a_subsurface_object_matches_an_emitting_mesh_sphere() {
    let analytic = marble_under(
        "[[lights]]\ntype = \"sphere\"\nposition = [0.5, 2, 0.5]\nradius = 0.3\n\
         radiance = [20, 16, 12]",
    );
    let mesh = marble_under(
        "[[shapes]]\ntype = \"sphere\"\nsubdivisions = 5\nmaterial = \"lamp\"\n\
         emission = [20, 16, 12]\nscale = 0.3\ntranslate = [0.5, 2, 0.5]",
    );
    let (a, m) = (run(&analytic), run(&mesh));
    let n = a.pixels.len() as f64;
    for c in 0..3 {
        // Pixel by pixel differences: the image's structure cancels, the
        // noise of both renders stays.
        let d: Vec<f64> = (a.pixels.iter().zip(&m.pixels))
            .map(|(x, y)| x[c] as f64 - y[c] as f64)
            .collect();
        let mean = d.iter().sum::<f64>() / n;
        let se = (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
        let level = m.pixels.iter().map(|p| p[c] as f64).sum::<f64>() / n;
        assert!(
            mean.abs() <= 4.0 * se + 0.005 * level,
            "channel {c}: sphere light − mesh = {mean} ± {se} (mean {level})"
        );
    }
}
