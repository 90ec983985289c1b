//! Per-pixel variance of one sample of an integrator (the path tracer unless
//! `--integrator randomwalk`), and where it sits in the image, for
//! docs/accuracy.md ("Smooth sphere"):
//!
//!     cargo run --release --example pixel_variance -- SCENE.toml \
//!         [--width N] [--spp N] [--seed N] [--axes A] [--specular BOOL] \
//!         [--reference REF.exr] [--map OUT.exr] [--image OUT.exr] [--threads N] \
//!         [--integrator path|randomwalk]
//!
//! Renders every pixel with `--spp` samples exactly as `lucent render`
//! does (the same random numbers, from the scene's sampler), but keeps
//! each pixel's sample variance σ²: with independent samples (`[render]
//! sampler = "random"`) relMSE × spp of a render equals the mean over
//! pixels and channels of σ² / (R² + ε), ε = 0.01, R the pixel's true
//! value (the reference if given, else the pixel's own mean), whatever the
//! sample count — without the reference's noise, which a relMSE against a
//! reference includes. With the default `"sobol"` sampler the samples are
//! stratified and the figure overstates the render's error (it is the
//! independent samples' figure); compare renders of several seeds then.
//! The sum is split by region, from the geometry at the pixel (four
//! corner rays and the centre ray): background (the centre misses every
//! object), silhouette (the corners disagree on which object they hit),
//! highlight (the mirror direction at the centre hit meets an emitter),
//! lit body (the emitter's centroid above the centre hit's horizon) and
//! dark side (the rest). Each region's share is its part of the whole
//! figure. `--map` writes σ²/(R² + ε) per pixel and channel as an EXR,
//! `--image` the pixels' means (the render of these samples).
//! The time is the wall time of the samples (no accel build), ms per spp;
//! every estimator option of `lucent render` (`--probe-pair true`,
//! `--control-variate false`, `--axes normal`, …; the option table,
//! `lucent::materials::OPTIONS`) overrides the materials' choices as on
//! the command line.

use std::path::Path;
use std::time::Instant;

use lucent::accel::{self, Backend};
use lucent::film::Film;
use lucent::geometry::{Ray, Vec3};
use lucent::integrator::aov::NoAov;
use lucent::integrator::path::Scratch;
use lucent::integrator::{Context, Counters, IntegratorKind, NoClock};
use lucent::materials::estimator_options::Assignments;
use lucent::materials::OPTIONS;
use lucent::sampling::{Draw, Rng, SampleRng};
use lucent::scene::{self, Camera};
use rayon::prelude::*;

const EPS: f64 = 0.01;

/// Per pixel: the mean and sample variance per channel, and the rays.
type PixelStats = ([f64; 3], [f64; 3], u64);
const REGIONS: [&str; 5] = [
    "background",
    "silhouette",
    "highlight",
    "lit body",
    "dark side",
];

fn arg<T: std::str::FromStr>(args: &[String], name: &str) -> Option<T> {
    let i = args.iter().position(|a| a == name)?;
    let v = args
        .get(i + 1)
        .unwrap_or_else(|| die(&format!("{name} needs a value")));
    Some(
        v.parse()
            .unwrap_or_else(|_| die(&format!("{name}: bad value {v}"))),
    )
}

fn die(msg: &str) -> ! {
    eprintln!("error: {msg}");
    std::process::exit(2)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(path) = args.first() else {
        die("usage: pixel_variance SCENE.toml [options] (see the source)")
    };
    let mut scene = scene::load(Path::new(path)).unwrap_or_else(|e| die(&e.to_string()));
    if let Some(w) = arg::<u32>(&args, "--width") {
        let c = &scene.camera;
        let h = ((c.height as u64 * w as u64) / c.width as u64).max(1) as u32;
        scene.camera = Camera::new(c.look_from, c.look_at, c.up, c.fov_y, w, h);
    }
    let spp: u32 = arg(&args, "--spp").unwrap_or(256);
    let seed: u64 = arg(&args, "--seed").unwrap_or(1);
    let threads: usize = arg(&args, "--threads").unwrap_or(2);
    let integrator = match arg::<String>(&args, "--integrator").as_deref() {
        None | Some("path") => IntegratorKind::Path,
        Some("randomwalk") => IntegratorKind::RandomWalk,
        Some(other) => die(&format!("--integrator: {other} is not path or randomwalk")),
    };
    // any estimator option, as `lucent render` takes it (`--axes normal`)
    let mut ov = Assignments::default();
    for row in &OPTIONS {
        let flag = format!("--{}", row.flag_name());
        if let Some(v) = arg::<String>(&args, &flag) {
            ov.push(row, &v)
                .unwrap_or_else(|e| die(&format!("{flag}: {e}")));
        }
    }
    ov.apply_all(&mut scene.materials)
        .unwrap_or_else(|e| die(&e.to_string()));
    let reference = arg::<String>(&args, "--reference")
        .map(|p| Film::read_exr(Path::new(&p)).unwrap_or_else(|e| die(&e.to_string())));
    // Embree where the build has it (as `lucent render` defaults to)
    let backend = if cfg!(feature = "embree") {
        Backend::Embree
    } else {
        Backend::Bvh
    };
    let accel = accel::build(&scene.meshes, backend).unwrap_or_else(|e| die(&e.to_string()));
    let ctx = Context::new(&scene, accel.as_ref());
    let (w, h) = (scene.camera.width, scene.camera.height);
    if let Some(r) = &reference {
        if (r.width, r.height) != (w, h) {
            die("reference size differs from the image's");
        }
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let seed_key = Rng::seed_key(seed);
    let sampler = scene.settings.sampler;
    let start = Instant::now();
    // per pixel: mean, variance per channel, ray count
    let rows: Vec<Vec<PixelStats>> = pool.install(|| {
        (0..h)
            .into_par_iter()
            .map(|y| {
                let mut scratch = Scratch::default();
                (0..w)
                    .map(|x| {
                        let pixel = y as u64 * w as u64 + x as u64;
                        let key = Rng::pixel_key(seed_key, pixel);
                        let mut c = Counters::default();
                        let (mut s1, mut s2) = ([0f64; 3], [0f64; 3]);
                        for s in 0..spp {
                            let mut rng = SampleRng::with_sampler(sampler, key, s);
                            let [jx, jy] = rng.uniform2_packed();
                            let ray = scene.camera.ray(x as f32 + jx, y as f32 + jy);
                            let l = integrator.radiance::<_, NoClock>(
                                &ctx,
                                ray,
                                &mut rng,
                                &mut scratch,
                                &mut c,
                                &mut NoAov,
                            );
                            if !l.is_finite() {
                                continue;
                            }
                            for k in 0..3 {
                                let v = l[k] as f64;
                                s1[k] += v;
                                s2[k] += v * v;
                            }
                        }
                        let n = spp as f64;
                        let mean = s1.map(|v| v / n);
                        let var = std::array::from_fn(|k| {
                            ((s2[k] - n * mean[k] * mean[k]) / (n - 1.0)).max(0.0)
                        });
                        (mean, var, c.rays)
                    })
                    .collect()
            })
            .collect()
    });
    let secs = start.elapsed().as_secs_f64();
    let light_centre = light_centroid(&scene);
    let mut share = [0f64; 5];
    let mut count = [0usize; 5];
    let mut rays = 0u64;
    let mut map = Film::new(w, h);
    let mut image = Film::new(w, h);
    let total_px = (w * h) as f64;
    for y in 0..h {
        for x in 0..w {
            let (mean, var, r) = rows[y as usize][x as usize];
            rays += r;
            let truth = match &reference {
                Some(f) => {
                    let p = f.get(x, y);
                    [p.x as f64, p.y as f64, p.z as f64]
                }
                None => mean,
            };
            let e: [f64; 3] = std::array::from_fn(|k| var[k] / (truth[k] * truth[k] + EPS));
            let region = classify(&ctx, &scene.camera, x, y, light_centre);
            share[region] += (e[0] + e[1] + e[2]) / (3.0 * total_px);
            count[region] += 1;
            map.set(x, y, Vec3::new(e[0] as f32, e[1] as f32, e[2] as f32));
            image.set(
                x,
                y,
                Vec3::new(mean[0] as f32, mean[1] as f32, mean[2] as f32),
            );
        }
    }
    let total: f64 = share.iter().sum();
    println!(
        "{path}: {w}x{h}, {spp} spp, seed {seed}: relMSE×spp {total:.4}, {:.3} ms/spp, {:.3} rays/sample",
        1000.0 * secs / spp as f64,
        rays as f64 / (total_px * spp as f64)
    );
    for (i, name) in REGIONS.iter().enumerate() {
        println!(
            "  {name:<11} {:>6} px  {:.4}  ({:.1} %)",
            count[i],
            share[i],
            100.0 * share[i] / total
        );
    }
    if let Some(p) = arg::<String>(&args, "--png") {
        // σ²/(R² + ε) of the mean over channels, 0 … 1 as black … white
        let img = image::GrayImage::from_fn(w, h, |x, y| {
            let v = map.get(x, y);
            let e = ((v.x + v.y + v.z) / 3.0).clamp(0.0, 1.0);
            image::Luma([(255.0 * e.sqrt()) as u8])
        });
        img.save(&p).unwrap_or_else(|e| die(&e.to_string()));
    }
    if let Some(p) = arg::<String>(&args, "--map") {
        map.write_exr(Path::new(&p))
            .unwrap_or_else(|e| die(&e.to_string()));
    }
    if let Some(p) = arg::<String>(&args, "--image") {
        image
            .write_exr(Path::new(&p))
            .unwrap_or_else(|e| die(&e.to_string()));
    }
}

/// The centroid of every emissive triangle's vertices (None without one).
fn light_centroid(scene: &lucent::scene::Scene) -> Option<Vec3> {
    let mut sum = Vec3::ZERO;
    let mut n = 0.0;
    for (mesh, obj) in scene.meshes.iter().zip(&scene.objects) {
        if obj.emission.is_none() {
            continue;
        }
        for &p in mesh.positions() {
            sum += p;
            n += 1.0;
        }
    }
    (n > 0.0).then(|| sum / n)
}

fn classify(ctx: &Context, cam: &Camera, x: u32, y: u32, light: Option<Vec3>) -> usize {
    let hit = |fx: f32, fy: f32| {
        let ray = cam.ray(x as f32 + fx, y as f32 + fy);
        ctx.accel
            .intersect(&ray, 0.0, f32::INFINITY)
            .map(|h| (ray, h))
    };
    let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
        .map(|(a, b)| hit(a, b).map(|(_, h)| h.geom));
    let Some((ray, h)) = hit(0.5, 0.5) else {
        return 0;
    };
    if corners.iter().any(|c| *c != Some(h.geom)) {
        return 1;
    }
    let si = ctx.interaction(&ray, &h);
    let wo = -ray.d;
    let n = if si.ns.dot(wo) >= 0.0 { si.ns } else { -si.ns };
    let wi = 2.0 * wo.dot(n) * n - wo;
    let refl = Ray::new(si.p + si.ng * (1e-4 * si.ng.dot(wo).signum()), wi);
    if let Some(hh) = ctx.accel.intersect(&refl, 0.0, f32::INFINITY) {
        if ctx.scene.objects[hh.geom as usize].emission.is_some() {
            return 2;
        }
    }
    match light {
        Some(l) if (l - si.p).dot(n) > 0.0 => 3,
        _ => 4,
    }
}
