//! The render orchestration called as a library (`lucent::session`),
//! without the binary: a render resumed from a part gives the sums of one
//! uninterrupted run, a part of another render is refused at the field
//! that differs, the settings are resolved once (options over the scene),
//! and a part's options are named canonically.

use std::path::{Path, PathBuf};

use lucent::accel::Backend;
use lucent::farm::part;
use lucent::film::exr_layers::Preview;
use lucent::film::ToneMap;
use lucent::render::{RenderOptions, Settings};
use lucent::session::{self, Request, Split};

const FIXTURE: &str = "tests/fixtures/marble-ball.toml";

fn request(output: PathBuf, samples: std::ops::Range<u32>, resume: Option<&Path>) -> Request {
    Request {
        scene: FIXTURE.into(),
        output,
        backend: Backend::Bvh,
        opts: RenderOptions {
            spp: Some(4),
            threads: Some(1),
            ..RenderOptions::default()
        },
        aov: None,
        overrides: Default::default(),
        file: Default::default(),
        split: Split {
            samples: Some(samples),
            resume: resume.map(Path::to_path_buf),
            ..Split::default()
        },
        preview: Preview {
            tonemap: ToneMap::Filmic,
            exposure: 0.0,
        },
        denoise: None,
    }
}

#[test]
fn resuming_a_part_gives_the_sums_of_one_run() {
    let dir = tempfile::tempdir().unwrap();
    let first = dir.path().join("first.exr");
    let resumed = dir.path().join("resumed.exr");
    let whole = dir.path().join("whole.exr");
    session::run(&request(first.clone(), 0..1, None)).unwrap();
    let o = session::run(&request(resumed.clone(), 0..4, Some(&first))).unwrap();
    assert_eq!(o.samples, 0..4);
    session::run(&request(whole.clone(), 0..4, None)).unwrap();
    let (ha, a) = part::read(&resumed).unwrap();
    let (hb, b) = part::read(&whole).unwrap();
    assert_eq!(ha.identity, hb.identity);
    assert_eq!((a.start, a.done), (0, 4));
    let r = a.region;
    for y in r.y0..r.y1 {
        for x in r.x0..r.x1 {
            assert_eq!(a.pixel(x, y), b.pixel(x, y), "pixel ({x}, {y})");
        }
    }
}

#[test]
fn a_part_of_another_render_is_not_resumed() {
    let dir = tempfile::tempdir().unwrap();
    let first = dir.path().join("first.exr");
    session::run(&request(first.clone(), 0..1, None)).unwrap();
    let mut other = request(dir.path().join("other.exr"), 0..4, Some(&first));
    other.opts.seed = Some(99);
    let e = session::run(&other).unwrap_err().to_string();
    assert!(e.contains("lucent.seed"), "{e}");
}

#[test]
fn options_win_over_the_scene_once_resolved() {
    let scene = lucent::scene::load(Path::new(FIXTURE)).unwrap();
    let s = Settings::resolved(
        &scene,
        &RenderOptions {
            seed: Some(7),
            ..RenderOptions::default()
        },
    );
    assert_eq!((s.spp, s.seed), (scene.settings.spp, 7));
    assert_eq!(s.max_depth, scene.settings.max_depth);
}

#[cfg(feature = "subsurface")]
#[test]
fn a_part_names_its_options_as_the_scene_format_does() {
    use lucent::materials::estimator_options::option;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("part.exr");
    let mut r = request(out.clone(), 0..1, None);
    r.overrides.push(option("axes").unwrap(), "MIS3").unwrap();
    r.overrides
        .push(option("probe-pair").unwrap(), "false")
        .unwrap();
    session::run(&r).unwrap();
    let (h, _) = part::read(&out).unwrap();
    assert_eq!(
        h.identity.options,
        "accel=bvh integrator=path sampler=sobol axes=mis3 probe_pair=false"
    );
}
