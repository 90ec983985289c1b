//! Checks our hand-written Embree structs against the installed C headers:
//! a small C program prints `sizeof`/`offsetof`/constants for every entry of
//! `ffi::layout_table()`, and each must match what Rust computed. A library
//! built with other options (e.g. more instance levels) or a different major
//! version then fails here instead of corrupting memory at run time.
//!
//! Built only with the `embree` feature (`#[cfg]` in tests/accel/main.rs).

#[test]
fn rust_layout_matches_embree_headers() {
    use std::fmt::Write;
    use std::process::Command;

    let include = lucent::accel::embree::ffi::INCLUDE_DIR;
    let table = lucent::accel::embree::ffi::layout_table();
    assert!(table.len() > 30, "layout table suspiciously short");

    let mut c = String::from(
        "#include <stdio.h>\n#include <stddef.h>\n#include <embree3/rtcore.h>\nint main(void) {\n",
    );
    for (expr, _) in &table {
        writeln!(c, "  printf(\"%s=%zu\\n\", \"{expr}\", (size_t)({expr}));").unwrap();
    }
    c.push_str("  return 0;\n}\n");

    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("layout.c");
    let exe = dir.path().join("layout");
    std::fs::write(&src, &c).unwrap();
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let out = Command::new(&cc)
        .arg("-std=c11")
        .arg("-I")
        .arg(include)
        .arg(&src)
        .arg("-o")
        .arg(&exe)
        .output()
        .unwrap_or_else(|e| panic!("cannot run the C compiler `{cc}`: {e}"));
    assert!(
        out.status.success(),
        "compiling the layout probe failed:\n{}\n{c}",
        String::from_utf8_lossy(&out.stderr)
    );
    let run = Command::new(&exe).output().unwrap();
    assert!(run.status.success());
    let text = String::from_utf8(run.stdout).unwrap();

    let mut c_values = std::collections::HashMap::new();
    for line in text.lines() {
        let (k, v) = line.rsplit_once('=').unwrap();
        c_values.insert(k.to_string(), v.parse::<usize>().unwrap());
    }
    let mut mismatches = Vec::new();
    for (expr, rust) in &table {
        let c = c_values[*expr];
        if c != *rust {
            mismatches.push(format!("{expr}: C {c}, Rust {rust}"));
        }
    }
    assert!(
        mismatches.is_empty(),
        "Embree layout drift:\n{}",
        mismatches.join("\n")
    );
    // The numbers the brief established on these machines, as a second,
    // independent check of the table itself.
    assert_eq!(c_values["sizeof(struct RTCRayHit)"], 80);
    assert_eq!(c_values["sizeof(struct RTCIntersectContext)"], 24);
    assert_eq!(c_values["sizeof(struct RTCFilterFunctionNArguments)"], 48);
}

#[test]
fn linked_library_is_embree_3() {
    let v = lucent::accel::embree::version();
    assert!(v.starts_with("3."), "linked Embree is {v}, expected 3.x");
}
