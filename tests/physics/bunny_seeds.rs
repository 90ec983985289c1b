//! Two estimators compared on a non-convex real mesh by independent
//! renders: scenes/smooth-bunny.toml (the Stanford bunny, smooth-shaded,
//! one small light) at `SIZE`², `SEEDS` seeds of `SPP` samples each under
//! the default sampler, as `lucent render` makes them. What the tests of
//! the probe pair (`pair_on_meshes`) and of its paths (`pair_paths`) read:
//! the shift of one estimator's mean from the other's over the frame, in
//! standard errors, and each one's relMSE between the seeds (variance only,
//! no reference needed).

use std::path::{Path, PathBuf};

use lucent::accel::{self, Backend};
use lucent::film::passes::PassSet;
use lucent::render::{self, Job, RenderOptions};
use lucent::sampling::SamplerKind;

/// Image width and height.
pub const SIZE: u32 = 24;
/// Samples per pixel of each seed's render.
pub const SPP: u32 = 32;
/// Independent renders per estimator.
pub const SEEDS: u64 = 8;
/// relMSE's ε (as the study's metrics).
const EPS: f64 = 0.01;

/// scenes/smooth-bunny.toml at SIZE², with `options` added to the marble.
pub fn bunny(options: &str) -> lucent::scene::Scene {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/smooth-bunny.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let text = text
        .replace(
            "resolution = [256, 256]",
            &format!("resolution = [{SIZE}, {SIZE}]"),
        )
        .replace(
            "[materials.marble]\n",
            &format!("[materials.marble]\n{options}\n"),
        );
    assert!(text.contains(&format!("[{SIZE}, {SIZE}]")), "resolution");
    lucent::scene::load_str(&text, Path::new(&path)).unwrap()
}

/// One seed's render: the beauty's values, and those of the light-path
/// layer asked for (empty when none was).
pub struct Seed {
    pub beauty: Vec<f64>,
    pub layer: Vec<f64>,
}

/// The scene's render with each seed; with `layer`, that light-path
/// layer's values too (`--aov lightpaths`).
pub fn renders(scene: &lucent::scene::Scene, layer: Option<&str>) -> Vec<Seed> {
    let a = accel::build(&scene.meshes, Backend::Bvh).unwrap();
    (1..=SEEDS)
        .map(|seed| {
            let opts = RenderOptions {
                spp: Some(SPP),
                seed: Some(seed),
                sampler: Some(SamplerKind::Sobol),
                threads: Some(2),
                ..Default::default()
            };
            let Some(name) = layer else {
                let film = render::render(scene, a.as_ref(), &opts).unwrap().0;
                return Seed {
                    beauty: values(&film),
                    layer: Vec::new(),
                };
            };
            let job = Job {
                passes: PassSet::parse_list("lightpaths").unwrap(),
                ..Job::full(scene, SPP)
            };
            let r =
                render::render_job(scene, a.as_ref(), &opts, &job, None, &mut |_| Ok(())).unwrap();
            let (layers, _) = r.sums.layers(false).unwrap();
            let names: Vec<String> = layers.iter().map(|l| l.name.clone()).collect();
            let found = layers
                .into_iter()
                .find(|l| l.name == name)
                .unwrap_or_else(|| panic!("no {name} layer in {names:?}"));
            Seed {
                beauty: values(&r.sums.film().unwrap()),
                layer: found.values.into_iter().map(f64::from).collect(),
            }
        })
        .collect()
}

/// A film's values, pixel by pixel, channel by channel.
fn values(film: &lucent::film::Film) -> Vec<f64> {
    film.pixels
        .iter()
        .flat_map(|p| p.to_array())
        .map(f64::from)
        .collect()
}

/// Per value: the mean over the seeds and the variance of one seed's value.
pub fn moments(seeds: &[Seed], values: fn(&Seed) -> &[f64]) -> Vec<(f64, f64)> {
    let n = seeds.len() as f64;
    (0..values(&seeds[0]).len())
        .map(|i| {
            let v: Vec<f64> = seeds.iter().map(|s| values(s)[i]).collect();
            let m = v.iter().sum::<f64>() / n;
            let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0);
            (m, var)
        })
        .collect()
}

pub fn beauty(s: &Seed) -> &[f64] {
    &s.beauty
}

pub fn layer(s: &Seed) -> &[f64] {
    &s.layer
}

/// Σ(a − b) / Σb over the frame, and its standard error from the
/// per-value variances of the seeds' means.
pub fn mean_shift(a: &[(f64, f64)], b: &[(f64, f64)]) -> (f64, f64) {
    let n = SEEDS as f64;
    let (mut diff, mut total, mut var_diff) = (0.0, 0.0, 0.0);
    for (&(ma, va), &(mb, vb)) in a.iter().zip(b) {
        diff += ma - mb;
        total += mb;
        var_diff += (va + vb) / n;
    }
    (diff / total, var_diff.sqrt() / total)
}

/// relMSE×spp of one seed's render of `a` and of `b`, each against the
/// two means' midpoint.
pub fn rel_mse_spp(a: &[(f64, f64)], b: &[(f64, f64)]) -> (f64, f64) {
    let (mut rel_a, mut rel_b) = (0.0, 0.0);
    for (&(ma, va), &(mb, vb)) in a.iter().zip(b) {
        let r = 0.5 * (ma + mb);
        rel_a += va / (r * r + EPS);
        rel_b += vb / (r * r + EPS);
    }
    let per_spp = SPP as f64 / a.len() as f64;
    (rel_a * per_spp, rel_b * per_spp)
}
