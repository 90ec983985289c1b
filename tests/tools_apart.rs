//! The renderer never uses the measuring tools: no source file under
//! `src/` outside `src/tools/` names the `tools` module, except the
//! declaration `pub mod tools;` in `src/lib.rs` and the binary
//! `src/main.rs`, which runs the tools' commands (see `src/tools/mod.rs`).

use std::path::{Path, PathBuf};

/// The Rust files under `dir`, recursively, sorted.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The 1-based numbers of the lines of `text` whose code (the part before
/// a `//` comment) contains the word `tools` as an identifier, other than
/// the module declaration `pub mod tools;`.
fn offending_lines(text: &str) -> Vec<usize> {
    let is_ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    text.lines()
        .enumerate()
        .filter(|(_, line)| {
            let code = line.split("//").next().unwrap_or("");
            if code.trim() == "pub mod tools;" {
                return false;
            }
            code.match_indices("tools").any(|(i, w)| {
                let before = code[..i].chars().next_back();
                let after = code[i + w.len()..].chars().next();
                !before.is_some_and(is_ident) && !after.is_some_and(is_ident)
            })
        })
        .map(|(i, _)| i + 1)
        .collect()
}

#[test]
fn renderer_modules_never_name_the_tools() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut offences = Vec::new();
    let mut scanned = 0;
    for f in &files {
        let rel = f.strip_prefix(&src).unwrap();
        if rel.starts_with("tools") || rel == Path::new("main.rs") {
            continue;
        }
        scanned += 1;
        let text = std::fs::read_to_string(f).unwrap();
        for line in offending_lines(&text) {
            offences.push(format!("src/{}:{line}", rel.display()));
        }
    }
    // The renderer's modules were found (a wrong directory scans nothing).
    assert!(
        scanned > 20,
        "only {scanned} files scanned under {}",
        src.display()
    );
    assert!(
        offences.is_empty(),
        "renderer code names the measuring tools (only src/tools/ and src/main.rs may): {}",
        offences.join(", ")
    );
}

#[test]
fn the_scan_finds_uses_and_ignores_comments_and_other_words() {
    let text = "use crate::tools::bench;\n\
                use crate::{accel, tools};\n\
                // see crate::tools::study\n\
                let toolset = my_tools::x();\n\
                pub mod tools;\n\
                let n = lucent::tools::plot::FONT; // tools\n";
    assert_eq!(offending_lines(text), vec![1, 2, 6]);
}
