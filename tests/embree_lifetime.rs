//! Building and dropping Embree scenes must not leak: the backend's live
//! device/scene counters return to zero and the process's resident memory
//! stays bounded over many build/drop cycles. Also checks that the shared
//! mesh buffers outlive the scene however the `Arc`s are dropped.
//!
//! The same tests run on Embree 3 (`embree3::*`) and Embree 4
//! (`embree4::*`, where this process has it; required under
//! scripts/test.sh, which sets `LUCENT_REQUIRE_EMBREE4`), one backend's
//! tests at a time (the RSS bound would not hold with another backend
//! building beside it). Built only with the `embree` feature
//! (`required-features` in Cargo.toml).

use std::sync::Mutex;

/// The counters and RSS are process-wide, so these tests run one at a time.
static SERIAL: Mutex<()> = Mutex::new(());

/// Whether the Embree 4 tests may run: Embree 4 loads, or else skip (saying
/// so) unless `LUCENT_REQUIRE_EMBREE4` is set, where that fails the test.
#[cfg(feature = "embree4")]
fn have_embree4() -> bool {
    match lucent::accel::Backend::Embree4.resolve() {
        Ok(_) => true,
        Err(e) if std::env::var_os("LUCENT_REQUIRE_EMBREE4").is_none() => {
            eprintln!("Embree 4 not tested: {e}");
            false
        }
        Err(e) => panic!("LUCENT_REQUIRE_EMBREE4 is set but {e}"),
    }
}

/// The lifetime tests for one backend module: `$accel` is its accel type,
/// `$available` whether to run, `$version` its version string, `$major`
/// the major version that must start it.
macro_rules! lifetime_tests {
    ($name:ident, $module:path, $accel:ident, $available:expr, $version:expr, $major:expr) => {
        mod $name {
            use std::sync::Arc;

            use super::SERIAL;
            use lucent::accel::{Accel, ProbeHits};
            use lucent::geometry::{Mesh, Ray, Vec3};
            use lucent::scene::shapes;
            use $module::{live_objects, $accel as EmbreeAccel};

            fn available() -> bool {
                $available
            }

            fn rss_bytes() -> usize {
                let statm = std::fs::read_to_string("/proc/self/statm").unwrap();
                let pages: usize = statm.split_whitespace().nth(1).unwrap().parse().unwrap();
                pages * 4096
            }

            /// One build/query/drop cycle; returns a hit so the work is not elided.
            fn cycle(meshes: &Arc<Vec<Mesh>>) -> f32 {
                let a = EmbreeAccel::build(meshes).unwrap();
                assert_eq!(live_objects(), (1, 1));
                let ray = Ray::new(Vec3::new(0.01, 0.02, -3.0), Vec3::Z);
                let h = a.intersect(&ray, 0.0, f32::INFINITY).expect("sphere hit");
                let mut out = ProbeHits::new();
                a.hits_on_segment(&ray, 10.0, 0, 7, &mut out);
                assert_eq!(out.total(), 2);
                h.t
            }

            #[test]
            fn build_drop_loop_does_not_leak() {
                let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
                if !available() {
                    return;
                }
                let meshes = Arc::new(vec![shapes::displaced_sphere(4, 0.05)]); // 5,120 triangles
                let meshes2 = Arc::new(vec![shapes::sphere(5)]); // 20,480 triangles
                assert!(meshes2[0].triangle_count() >= 10_000);
                assert_eq!(live_objects(), (0, 0));
                // Warm up: Embree's thread pool and allocator caches reach their
                // steady state in the first builds.
                for _ in 0..20 {
                    cycle(&meshes2);
                }
                let before = rss_bytes();
                let n = 200;
                let mut acc = 0.0;
                for i in 0..n {
                    acc += cycle(if i % 2 == 0 { &meshes2 } else { &meshes });
                    assert_eq!(live_objects(), (0, 0), "cycle {i}");
                }
                let after = rss_bytes();
                assert!(acc > 0.0);
                // A scene over 20k triangles takes ~2 MB; leaking it every other
                // cycle would grow RSS by ~200 MB. Allow 32 MB of allocator noise.
                let growth = after.saturating_sub(before);
                println!(
                    "RSS before {before} after {after} (growth {growth} bytes over {n} cycles)"
                );
                assert!(
                    growth < 32 << 20,
                    "RSS grew by {growth} bytes over {n} cycles"
                );
                // The meshes are only referenced by us again.
                assert_eq!(Arc::strong_count(&meshes), 1);
                assert_eq!(Arc::strong_count(&meshes2), 1);
            }

            /// The accel keeps the mesh buffers alive: dropping every other handle
            /// first must not leave Embree reading freed memory (valgrind or ASan
            /// would flag it; here the hits must still be right).
            #[test]
            fn accel_outlives_callers_meshes() {
                let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
                if !available() {
                    return;
                }
                let a = {
                    let meshes = Arc::new(vec![shapes::sphere(4)]);
                    let a = EmbreeAccel::build(&meshes).unwrap();
                    assert_eq!(Arc::strong_count(&meshes), 2);
                    a
                };
                assert_eq!(Arc::strong_count(a.meshes()), 1);
                // Allocate and scribble over freed memory a little, then query.
                let junk: Vec<Vec<u8>> = (0..64).map(|i| vec![i as u8; 64 << 10]).collect();
                let h = a
                    .intersect(&Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z), 0.0, 100.0)
                    .unwrap();
                assert!((h.t - 4.0).abs() < 2e-3, "{h:?}");
                drop(junk);
                // Queries from several threads at once on the shared accel give the
                // same answers as one thread.
                let ray = |k: usize, i: u32| {
                    let x = (i as f32 / 2000.0 - 0.5) * 1.2 + 1.234e-3;
                    Ray::new(Vec3::new(x, 0.1 * k as f32 + 2.71e-3, -3.0), Vec3::Z)
                };
                let run = |a: &EmbreeAccel, k: usize| -> Vec<(usize, Option<u32>)> {
                    let mut out = ProbeHits::new();
                    (0..2000)
                        .map(|i| {
                            let r = ray(k, i);
                            a.hits_on_segment(&r, 10.0, 0, i, &mut out);
                            (out.total(), a.intersect(&r, 0.0, 10.0).map(|h| h.prim))
                        })
                        .collect()
                };
                let serial: Vec<_> = (0..4).map(|k| run(&a, k)).collect();
                assert!(serial.iter().flatten().all(|&(n, h)| n >= 2 && h.is_some()));
                let a = Arc::new(a);
                let parallel: Vec<_> = std::thread::scope(|s| {
                    let hs: Vec<_> = (0..4)
                        .map(|k| {
                            let a = Arc::clone(&a);
                            s.spawn(move || run(&a, k))
                        })
                        .collect();
                    hs.into_iter().map(|h| h.join().unwrap()).collect()
                });
                assert_eq!(serial, parallel);
                drop(a);
                assert_eq!(live_objects(), (0, 0));
            }

            /// A failed build releases what it created.
            #[test]
            fn failed_build_releases_everything() {
                let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
                if !available() {
                    return;
                }
                let mut bad = shapes::quad();
                bad.indices.push([0, 1, 99]);
                let meshes = Arc::new(vec![shapes::sphere(2), bad]);
                assert!(EmbreeAccel::build(&meshes).is_err());
                assert_eq!(live_objects(), (0, 0));
                assert_eq!(Arc::strong_count(&meshes), 1);
            }

            #[test]
            fn version_is_reported_and_releases_its_device() {
                let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
                if !available() {
                    return;
                }
                let v: String = $version;
                // "3.13.5", or "4.4.0 (path)".
                let v = v.split(' ').next().unwrap();
                let parts: Vec<u32> = v.split('.').map(|p| p.parse().unwrap()).collect();
                assert_eq!(parts.len(), 3, "{v}");
                assert_eq!(parts[0], $major, "{v}");
                assert_eq!(live_objects(), (0, 0));
            }
        }
    };
}

lifetime_tests!(
    embree3,
    lucent::accel::embree,
    EmbreeAccel,
    true,
    lucent::accel::embree::version(),
    3
);

#[cfg(feature = "embree4")]
lifetime_tests!(
    embree4,
    lucent::accel::embree4,
    Embree4Accel,
    super::have_embree4(),
    lucent::accel::embree4::version().unwrap(),
    4
);
