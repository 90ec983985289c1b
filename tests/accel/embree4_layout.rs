//! Checks our hand-written Embree 4 structs three ways:
//! - against the values transcribed from the Embree 4.3/4.4 headers
//!   (`ffi::TRANSCRIBED`, cited there by file), on every machine;
//! - against the installed headers, where there are any (Debian 13's
//!   `libembree-dev` puts them in `/usr/include/embree4`; or
//!   `EMBREE4_INCLUDE=/prefix/include`): a C program prints every
//!   `sizeof`/`offsetof`/constant of `ffi::layout_table()`;
//! - against the loaded library itself (the wheel's 4.4.0 under
//!   scripts/test.sh): a ray/hit record filled with a sentinel is traced,
//!   and the bytes the library wrote show it uses the 96-byte 4.3+
//!   `RTCRayHit` (it writes `instPrimID` at byte 80) and nothing beyond it.
//!
//! Built only with the `embree4` feature (`#[cfg]` in tests/accel/main.rs).

use std::collections::HashMap;
use std::path::PathBuf;

use lucent::accel::embree4::ffi;

#[test]
fn rust_layout_matches_the_transcribed_headers() {
    let rust: HashMap<&str, usize> = ffi::layout_table().into_iter().collect();
    let c: HashMap<&str, usize> = ffi::TRANSCRIBED.iter().copied().collect();
    assert_eq!(rust.len(), ffi::layout_table().len(), "duplicate entries");
    assert!(rust.len() > 50, "layout table suspiciously short");
    let mut diff = Vec::new();
    for (k, v) in &rust {
        match c.get(k) {
            Some(cv) if cv == v => {}
            other => diff.push(format!("{k}: headers {other:?}, Rust {v}")),
        }
    }
    for k in c.keys().filter(|k| !rust.contains_key(*k)) {
        diff.push(format!("{k}: transcribed but not checked"));
    }
    assert!(
        diff.is_empty(),
        "Embree 4 layout drift:\n{}",
        diff.join("\n")
    );
    // The difference that broke bindings made from 4.2 headers.
    assert_eq!(c["sizeof(struct RTCRayHit)"], 96);
}

/// Where Embree 4 headers are, if anywhere.
fn headers() -> Option<PathBuf> {
    std::env::var_os("EMBREE4_INCLUDE")
        .map(PathBuf::from)
        .into_iter()
        .chain(["/usr/include", "/usr/local/include"].map(PathBuf::from))
        .find(|p| p.join("embree4/rtcore.h").is_file())
}

#[test]
fn rust_layout_matches_installed_headers() {
    use std::fmt::Write;
    use std::process::Command;

    let Some(include) = headers() else {
        eprintln!(
            "no embree4/rtcore.h installed (Debian 12 has none): checked against the \
             transcribed values only"
        );
        return;
    };
    let table = ffi::layout_table();
    let mut c = String::from(
        "#include <stdio.h>\n#include <stddef.h>\n#include <embree4/rtcore.h>\nint main(void) {\n",
    );
    for (expr, _) in &table {
        writeln!(c, "  printf(\"%s=%zu\\n\", \"{expr}\", (size_t)({expr}));").unwrap();
    }
    c.push_str("  return 0;\n}\n");
    let dir = tempfile::tempdir().unwrap();
    let (src, exe) = (dir.path().join("layout.c"), dir.path().join("layout"));
    std::fs::write(&src, &c).unwrap();
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let out = Command::new(&cc)
        .arg("-std=c11")
        .arg("-I")
        .arg(&include)
        .arg(&src)
        .arg("-o")
        .arg(&exe)
        .output()
        .unwrap_or_else(|e| panic!("cannot run the C compiler `{cc}`: {e}"));
    assert!(
        out.status.success(),
        "compiling the layout probe failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(Command::new(&exe).output().unwrap().stdout).unwrap();
    let c_values: HashMap<String, usize> = text
        .lines()
        .map(|l| {
            let (k, v) = l.rsplit_once('=').unwrap();
            (k.to_string(), v.parse().unwrap())
        })
        .collect();
    let bad: Vec<String> = table
        .iter()
        .filter(|(e, r)| c_values[*e] != *r)
        .map(|(e, r)| format!("{e}: C {}, Rust {r}", c_values[*e]))
        .collect();
    assert!(bad.is_empty(), "Embree 4 layout drift:\n{}", bad.join("\n"));
}

/// The loaded library writes a 96-byte `RTCRayHit`: `instID` and
/// `instPrimID` (bytes 76 and 80) set to `RTC_INVALID_GEOMETRY_ID` on a hit
/// outside any instance, and not a byte past 96.
#[test]
fn loaded_library_writes_the_4_3_ray_hit_layout() {
    use std::sync::Arc;

    use lucent::accel::embree4::Embree4Accel;
    use lucent::accel::Backend;
    use lucent::scene::shapes;

    if let Err(e) = Backend::Embree4.resolve() {
        assert!(
            std::env::var_os("LUCENT_REQUIRE_EMBREE4").is_none(),
            "LUCENT_REQUIRE_EMBREE4 is set but {e}"
        );
        eprintln!("Embree 4 not tested: {e}");
        return;
    }
    let (major, minor, _) = lucent::accel::embree4::load::api().unwrap().version;
    assert_eq!(major, 4);
    assert!((3..=4).contains(&minor));

    #[repr(C)]
    struct Guarded {
        rh: ffi::RTCRayHit,
        tail: [u32; 8],
    }
    const SENTINEL: u32 = 0x5a5a_5a5a;
    let accel = Embree4Accel::build(&Arc::new(vec![shapes::quad()])).unwrap();
    let mut g = Guarded {
        rh: ffi::RTCRayHit {
            ray: ffi::RTCRay {
                org_x: 0.7,
                org_y: 0.1,
                org_z: 5.0,
                tnear: 0.0,
                dir_x: 0.0,
                dir_y: 0.0,
                dir_z: -1.0,
                time: 0.0,
                tfar: f32::INFINITY,
                mask: u32::MAX,
                id: 0,
                flags: 0,
            },
            hit: ffi::RTCHit {
                ng_x: 0.0,
                ng_y: 0.0,
                ng_z: 0.0,
                u: 0.0,
                v: 0.0,
                prim_id: SENTINEL,
                geom_id: SENTINEL,
                inst_id: [SENTINEL],
                inst_prim_id: [SENTINEL],
            },
        },
        tail: [SENTINEL; 8],
    };
    accel.intersect_raw(&mut g.rh);
    assert_eq!(g.rh.hit.geom_id, 0, "the quad was not hit");
    assert!((g.rh.ray.tfar - 5.0).abs() < 1e-5, "{}", g.rh.ray.tfar);
    assert_eq!(g.rh.hit.inst_id, [ffi::RTC_INVALID_GEOMETRY_ID], "instID");
    assert_eq!(
        g.rh.hit.inst_prim_id,
        [ffi::RTC_INVALID_GEOMETRY_ID],
        "instPrimID (byte 80): not written, so the library has the pre-4.3 80-byte RTCRayHit"
    );
    assert_eq!(g.tail, [SENTINEL; 8], "the library wrote past 96 bytes");
}
