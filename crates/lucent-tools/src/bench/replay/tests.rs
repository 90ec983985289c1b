//! Recording and replaying a render of the marble-ball fixture: the
//! recorder logs one record per ray the renderer counts, the replay
//! reproduces every answer, and a changed query or order changes the
//! digest.

use std::path::Path;
use std::sync::Arc;

use super::digest::sum_digests;
use super::{replay_digest, replay_hits, Digests, Kind, Record, Recorder};
use lucent::accel::bvh::Bvh;
use lucent::accel::{self, Accel, ProbeHits};
use lucent::render::{self, RenderOptions};
use lucent::scene::Scene;

/// A marble sphere on a floor under an area light: every query kind.
const SCENE: &str = include_str!("../../../../../tests/fixtures/marble-ball.toml");

fn scene() -> Scene {
    lucent::scene::load::load_str(SCENE, Path::new("test.toml")).unwrap()
}

fn record(scene: &Scene, accel: &dyn Accel, threads: usize) -> (Vec<Vec<Record>>, Digests, u64) {
    let rec = Recorder::new(accel, scene.camera.look_from, threads, 1 << 24);
    let opts = RenderOptions {
        threads: Some(threads),
        ..RenderOptions::default()
    };
    let (_, stats) = render::render(scene, &rec, &opts).unwrap();
    let (logs, d, dropped) = rec.finish();
    assert_eq!(dropped, 0);
    // Rays answered by bounds (integrator::culling) never reach the
    // accelerator, so they are not recorded.
    (logs, d, stats.counters.rays - stats.counters.culled)
}

#[test]
fn recording_counts_every_ray_and_replay_reproduces_the_answers() {
    let scene = scene();
    for backend in crate::bench::available_backends() {
        let accel = accel::build(&scene.meshes, backend).unwrap();
        let accel = accel.as_ref();
        for threads in [1, 2] {
            let (logs, recorded, rays) = record(&scene, accel, threads);
            assert_eq!(logs.len(), threads);
            let n: u64 = logs.iter().map(|l| l.len() as u64).sum();
            assert_eq!(n, rays, "one record per query the renderer makes");
            // Every kind occurs, and the camera rays are one per sample.
            for k in Kind::ALL {
                assert!(recorded[k.index()].queries > 0, "{}", k.name());
            }
            // At most one per sample: camera rays beside the scene's
            // objects are answered by bounds.
            let camera = recorded[Kind::Camera.index()].queries;
            assert!(camera > 0 && camera <= 24 * 16 * 2, "{camera}");
            let mut replayed = Digests::default();
            for l in &logs {
                sum_digests(&mut replayed, &replay_digest(accel, l));
            }
            assert_eq!(replayed, recorded, "{}", backend.name());
            let mut out = ProbeHits::new();
            let hits: u64 = logs.iter().map(|l| replay_hits(accel, l, &mut out)).sum();
            assert_eq!(hits, recorded.iter().map(|d| d.hits).sum::<u64>());
        }
    }
}

#[test]
fn a_changed_query_or_order_changes_the_digest() {
    let scene = scene();
    let bvh = Bvh::build(&scene.meshes);
    let (logs, recorded, _) = record(&scene, &bvh, 1);
    let log = &logs[0];
    // Shorten one probe segment and reverse one nearest ray: the first
    // of its kind whose own answer that changes (a bounce ray that
    // missed may miss reversed too, a probe's hits may all lie in the
    // first half), so the test does not depend on the random stream.
    for kind in [Kind::Probe, Kind::Nearest] {
        let nudge = |r: &Record| {
            let mut r = *r;
            match kind {
                Kind::Probe => r.tmax *= 0.5,
                _ => r.ray.d = -r.ray.d,
            }
            r
        };
        let i = log
            .iter()
            .position(|r| {
                r.kind == kind && replay_digest(&bvh, &[*r]) != replay_digest(&bvh, &[nudge(r)])
            })
            .unwrap();
        let mut bad = log.clone();
        bad[i] = nudge(&log[i]);
        assert_ne!(replay_digest(&bvh, &bad), recorded, "{}", kind.name());
    }
    // The same queries in another order: the same hit counts, another
    // digest (an answer is bound to its position in the thread's log).
    let mut swapped = log.clone();
    let i = swapped
        .iter()
        .position(|r| r.kind == Kind::Nearest)
        .unwrap();
    let j = swapped.iter().position(|r| r.kind == Kind::Camera).unwrap();
    swapped.swap(i, j);
    let d = replay_digest(&bvh, &swapped);
    assert_ne!(d, recorded);
    // Without the floor (and with the ball's geom id shifted) the
    // answers differ too.
    let floorless = Bvh::build(&Arc::new(scene.meshes[1..].to_vec()));
    let without: Vec<Record> = log
        .iter()
        .filter(|r| r.kind != Kind::Probe)
        .copied()
        .collect();
    assert_ne!(
        replay_digest(&floorless, &without),
        replay_digest(&bvh, &without)
    );
}

#[test]
fn the_recorder_stops_logging_at_its_cap() {
    let scene = scene();
    let bvh = Bvh::build(&scene.meshes);
    let rec = Recorder::new(&bvh, scene.camera.look_from, 1, 100);
    let opts = RenderOptions {
        threads: Some(1),
        ..RenderOptions::default()
    };
    let (_, stats) = render::render(&scene, &rec, &opts).unwrap();
    let (logs, _, dropped) = rec.finish();
    assert_eq!(logs[0].len(), 100);
    assert_eq!(dropped + 100, stats.counters.rays - stats.counters.culled);
}
