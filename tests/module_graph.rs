//! The layering of the library (`crates/lucent/src/`) and the measuring
//! tools (`crates/lucent-tools/src/`), checked from the source text: the
//! modules form a directed acyclic graph, the subsurface math (`bssrdf`)
//! knows nothing of ray queries, integrators or materials, and the library
//! depends on no command-line, plotting or progress-bar crate.
//!
//! An edge A → B is any path `crate::B…` written in a file of module A
//! (imports and fully qualified paths alike, comments excluded), so a
//! dependency cannot hide behind a qualified call. Within one folder the
//! sibling files must form a DAG too, and a folder's `mod.rs` takes part:
//! it may declare (`mod`) and re-export (`pub use`) its children, but when
//! its own code also uses them, they must not use its items back.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`, sorted.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// The source without comments (line comments, doc comments and block
/// comments) and without the contents of string literals, so that prose
/// and messages mentioning `crate::x` are not read as dependencies.
fn code_only(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < b.len() {
        if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            let mut depth = 0;
            while i < b.len() {
                if b[i..].starts_with(b"/*") {
                    depth += 1;
                    i += 2;
                } else if b[i..].starts_with(b"*/") {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if b[i] == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            i += 1;
            out.push_str("\"\"");
        } else if b[i] == b'\'' && i + 2 < b.len() && (b[i + 2] == b'\'' || b[i + 1] == b'\\') {
            // A char literal such as '"' or '\n' (lifetimes have no closing quote).
            let end = b[i + 1..].iter().position(|&c| c == b'\'').unwrap_or(0);
            i += end + 2;
            out.push_str("' '");
        } else {
            let ch = text[i..].chars().next().unwrap();
            out.push(ch);
            i += ch.len_utf8();
        }
    }
    out
}

fn ident_at(s: &str) -> &str {
    let end = s
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .unwrap_or(s.len());
    &s[..end]
}

/// The first path segments after each `crate::` (and inside a
/// `crate::{a, b::c}` group, each group member's first segment).
fn crate_refs(code: &str) -> BTreeSet<String> {
    let mut refs = BTreeSet::new();
    for (pos, _) in code.match_indices("crate::") {
        // `$crate::` and identifiers ending in "crate" are not our paths.
        if pos > 0 {
            let prev = code.as_bytes()[pos - 1];
            if prev.is_ascii_alphanumeric() || prev == b'_' || prev == b'$' {
                continue;
            }
        }
        let rest = &code[pos + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let mut depth = 0;
            let mut start = true;
            for (k, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => start = true,
                    c if start && (c.is_ascii_alphabetic() || c == '_') => {
                        refs.insert(ident_at(&group[k..]).to_string());
                        start = false;
                    }
                    _ => {}
                }
            }
        } else {
            let id = ident_at(rest);
            if !id.is_empty() {
                refs.insert(id.to_string());
            }
        }
    }
    refs
}

/// The first segments after each `super::` (the siblings a file uses).
fn super_refs(code: &str) -> BTreeSet<String> {
    let mut refs = BTreeSet::new();
    for (pos, _) in code.match_indices("super::") {
        let rest = &code[pos + "super::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            for part in group.split('}').next().unwrap_or("").split(',') {
                let id = ident_at(part.trim());
                if !id.is_empty() {
                    refs.insert(id.to_string());
                }
            }
        } else {
            let id = ident_at(rest);
            if !id.is_empty() && id != "super" {
                refs.insert(id.to_string());
            }
        }
    }
    refs
}

/// Whether `code` names `name` as a whole word (an identifier).
fn names_word(code: &str, name: &str) -> bool {
    let word = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    code.match_indices(name).any(|(pos, _)| {
        let before = pos.checked_sub(1).map(|k| code.as_bytes()[k]);
        let after = code.as_bytes().get(pos + name.len()).copied();
        !before.is_some_and(word) && !after.is_some_and(word)
    })
}

/// What a `mod.rs` is made of: its children (declared with `mod`), the
/// names it re-exports from each (`pub use child::{A, b::C}` → A, C), and
/// its own code — everything but the `mod` declarations and `pub use`
/// re-exports.
struct Hub {
    children: BTreeSet<String>,
    reexports: BTreeMap<String, String>,
    own: String,
}

impl Hub {
    fn parse(code: &str) -> Hub {
        let mut hub = Hub {
            children: BTreeSet::new(),
            reexports: BTreeMap::new(),
            own: String::new(),
        };
        // items end at `;` (an inline `mod x { … }` is not a child file)
        for item in code.split_inclusive(';') {
            if let Some(k) = item.rfind("mod ") {
                let rest = item[k + "mod ".len()..].trim_start();
                let name = ident_at(rest);
                let prev = k.checked_sub(1).map(|j| item.as_bytes()[j]);
                let word = prev.is_some_and(|b| b.is_ascii_alphanumeric() || b == b'_');
                if !word && !name.is_empty() && rest[name.len()..].trim() == ";" {
                    hub.children.insert(name.to_string());
                    hub.own.push_str(&item[..k]);
                    continue;
                }
            }
            if let Some(k) = item.find("pub use ") {
                let path = &item[k + "pub use ".len()..];
                let path = path.strip_prefix("self::").unwrap_or(path);
                let child = ident_at(path).to_string();
                if hub.children.contains(&child) {
                    // the names it brings in: each path's last segment
                    for part in path.trim_end_matches(';').split([',', '{', '}']) {
                        let last = part.trim().rsplit("::").next().unwrap_or("");
                        let name = ident_at(last.trim());
                        if !name.is_empty() && name != child && name != "self" {
                            hub.reexports.insert(name.to_string(), child.clone());
                        }
                    }
                    hub.own.push_str(&item[..k]);
                    continue;
                }
            }
            hub.own.push_str(item);
        }
        hub
    }

    /// The children its own code uses: by path (`child::…`, not after
    /// another path's `::`) or by a name it re-exports from them.
    fn uses(&self) -> BTreeSet<String> {
        let mut out = BTreeSet::new();
        for c in &self.children {
            let pat = format!("{c}::");
            let by_path = self.own.match_indices(&pat).any(|(pos, _)| {
                let head = &self.own[..pos];
                let prev = head.as_bytes().last().copied();
                let word = prev.is_some_and(|b| b.is_ascii_alphanumeric() || b == b'_');
                !word && (!head.ends_with("::") || head.ends_with("self::"))
            });
            if by_path {
                out.insert(c.clone());
            }
        }
        for (name, c) in &self.reexports {
            if names_word(&self.own, name) {
                out.insert(c.clone());
            }
        }
        out
    }
}

/// The code of a file up to its `#[cfg(test)]` module: unit tests may use
/// whatever they need to check the code, and are not part of the layering.
fn non_test_code(text: &str) -> String {
    let code = code_only(text);
    for (k, _) in code.match_indices("#[cfg(test)]") {
        // Skip whitespace and further attributes up to the item.
        let mut rest = code[k + "#[cfg(test)]".len()..].trim_start();
        while rest.starts_with("#[") {
            rest = rest[rest.find(']').map_or(rest.len(), |e| e + 1)..].trim_start();
        }
        let rest = rest.strip_prefix("pub(crate) ").unwrap_or(rest);
        if rest.starts_with("mod ") {
            return code[..k].to_string();
        }
    }
    code
}

/// Top-level module of a file under a crate's src/: `src/bssrdf/probe.rs`
/// → bssrdf, `src/render.rs` → render; None for the crate roots.
fn top_module(src: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(src).unwrap();
    let first = rel.components().next()?.as_os_str().to_str()?.to_string();
    let name = first.strip_suffix(".rs").unwrap_or(&first).to_string();
    (name != "lib" && name != "main").then_some(name)
}

/// A cycle in `graph`, if any, as the list of its nodes.
fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    #[derive(Clone, Copy, PartialEq)]
    enum Mark {
        New,
        Open,
        Done,
    }
    fn visit(
        n: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        mark: &mut BTreeMap<String, Mark>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        mark.insert(n.to_string(), Mark::Open);
        path.push(n.to_string());
        for m in graph.get(n).into_iter().flatten() {
            match mark.get(m.as_str()).copied().unwrap_or(Mark::New) {
                Mark::Open => {
                    let k = path.iter().position(|p| p == m).unwrap();
                    let mut cycle = path[k..].to_vec();
                    cycle.push(m.clone());
                    return Some(cycle);
                }
                Mark::New => {
                    if let Some(c) = visit(m, graph, mark, path) {
                        return Some(c);
                    }
                }
                Mark::Done => {}
            }
        }
        path.pop();
        mark.insert(n.to_string(), Mark::Done);
        None
    }
    let mut mark = BTreeMap::new();
    for n in graph.keys() {
        if mark.get(n.as_str()).copied().unwrap_or(Mark::New) == Mark::New {
            if let Some(c) = visit(n, graph, &mut mark, &mut Vec::new()) {
                return Some(c);
            }
        }
    }
    None
}

struct Source {
    src: PathBuf,
    /// Prefixed to paths relative to `src` in [`KNOTS`]: "" for the
    /// library, "tools/" for the measuring tools.
    label: &'static str,
    files: Vec<(PathBuf, String)>,
}

impl Source {
    /// The library's modules.
    fn load() -> Self {
        Source::load_crate("lucent", "")
    }

    /// The library's modules and the tools' (each crate on its own).
    fn both() -> [Self; 2] {
        [Source::load(), Source::load_crate("lucent-tools", "tools/")]
    }

    fn load_crate(name: &str, label: &'static str) -> Self {
        let src = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("crates")
            .join(name)
            .join("src");
        let files = rust_files(&src)
            .into_iter()
            // a unit-test module kept in its own file (`probe/tests.rs`)
            .filter(|f| f.file_stem().is_some_and(|s| s != "tests"))
            .map(|f| {
                let text = std::fs::read_to_string(&f).unwrap();
                (f, non_test_code(&text))
            })
            .collect();
        Source { src, label, files }
    }

    /// Top-level module → the top-level modules its files name.
    fn top_graph(&self) -> BTreeMap<String, BTreeSet<String>> {
        let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (f, code) in &self.files {
            let Some(m) = top_module(&self.src, f) else {
                continue;
            };
            let e = g.entry(m.clone()).or_default();
            for r in crate_refs(code) {
                if r != m {
                    e.insert(r);
                }
            }
        }
        g
    }

    /// Files of `top` that name module `target` (file: first line doing so).
    fn files_naming(&self, top: &str, target: &str) -> Vec<String> {
        let mut out = Vec::new();
        for (f, code) in &self.files {
            if top_module(&self.src, f).as_deref() != Some(top) {
                continue;
            }
            if crate_refs(code).contains(target) {
                let line = code
                    .lines()
                    .position(|l| crate_refs(l).contains(target))
                    .map_or(0, |k| k + 1);
                out.push(format!(
                    "{}:{line}",
                    f.strip_prefix(&self.src).unwrap().display()
                ));
            }
        }
        out
    }
}

#[test]
fn the_scanner_reads_paths_groups_and_skips_comments_and_strings() {
    let code = code_only(
        "use crate::{accel::Hit, geometry::{Ray, Vec3}};\n\
         // crate::film in a comment\n\
         /* crate::study */ let x = crate::sampling::draw();\n\
         let s = \"crate::plot\"; let c = '\"'; let t = crate::render::x;\n\
         fn f<'a>(x: &'a str) -> $crate::nope {}\n",
    );
    let refs: Vec<_> = crate_refs(&code).into_iter().collect();
    assert_eq!(refs, ["accel", "geometry", "render", "sampling"]);
    let sup: Vec<_> = super_refs("use super::{fast::X, profile};\nsuper::radius::f()")
        .into_iter()
        .collect();
    assert_eq!(sup, ["fast", "profile", "radius"]);
    let mut g = BTreeMap::new();
    g.insert("a".to_string(), BTreeSet::from(["b".to_string()]));
    g.insert("b".to_string(), BTreeSet::from(["a".to_string()]));
    assert_eq!(
        find_cycle(&g),
        Some(vec!["a".into(), "b".into(), "a".into()])
    );
    g.remove("b");
    assert_eq!(find_cycle(&g), None);
}

#[test]
fn top_level_modules_form_a_dag() {
    for s in Source::both() {
        top_level_modules_of_a_crate_form_a_dag(&s);
    }
}

fn top_level_modules_of_a_crate_form_a_dag(s: &Source) {
    let g = s.top_graph();
    assert!(g.len() > 5, "scanned too few modules: {g:?}");
    if let Some(cycle) = find_cycle(&g) {
        let edges: Vec<String> = cycle
            .windows(2)
            .map(|w| {
                format!(
                    "{} → {} ({})",
                    w[0],
                    w[1],
                    s.files_naming(&w[0], &w[1]).join(", ")
                )
            })
            .collect();
        panic!(
            "import cycle among modules of {}:\n  {}",
            s.src.display(),
            edges.join("\n  ")
        );
    }
}

#[test]
fn sibling_files_form_a_dag_in_every_folder() {
    for s in Source::both() {
        sibling_files_of_a_crate_form_a_dag(&s);
    }
}

fn sibling_files_of_a_crate_form_a_dag(s: &Source) {
    let mut by_dir: BTreeMap<PathBuf, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    for (f, code) in &s.files {
        let stem = f.file_stem().unwrap().to_str().unwrap().to_string();
        if stem == "mod" || f.parent() == Some(s.src.as_path()) {
            continue;
        }
        let dir = f.parent().unwrap().to_path_buf();
        let siblings = by_dir.entry(dir).or_default();
        let refs = super_refs(code);
        siblings
            .entry(stem.clone())
            .or_default()
            .extend(refs.into_iter().filter(|r| *r != stem));
    }
    for (dir, mut g) in by_dir {
        // Only edges to files of the same folder count (not mod.rs items).
        let names: BTreeSet<String> = g.keys().cloned().collect();
        for e in g.values_mut() {
            e.retain(|r| names.contains(r));
        }
        assert!(
            find_cycle(&g).is_none(),
            "import cycle among the files of {}: {:?}",
            dir.display(),
            find_cycle(&g)
        );
    }
}

#[test]
fn the_subsurface_math_knows_no_ray_queries_integrators_or_materials() {
    let s = Source::load();
    for forbidden in ["accel", "integrator", "materials", "render", "scene"] {
        let hits = s.files_naming("bssrdf", forbidden);
        assert!(
            hits.is_empty(),
            "bssrdf must not depend on `{forbidden}`: {}",
            hits.join(", ")
        );
    }
}

/// The mistake: the library depending on the command line's argument
/// parser, the tools' plotting or a progress bar (a render reports its
/// progress through `lucent::progress::Progress` instead).
#[test]
fn the_library_depends_on_no_cli_plotting_or_progress_bar_crate() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("crates/lucent/Cargo.toml");
    let manifest = std::fs::read_to_string(&path).unwrap();
    for (n, line) in manifest.lines().enumerate() {
        let name = line.split(['=', '.']).next().unwrap_or("").trim();
        for forbidden in ["clap", "plotters", "indicatif", "lucent-tools"] {
            assert!(
                name != forbidden,
                "{}:{}: the library must not depend on `{forbidden}`",
                path.display(),
                n + 1
            );
        }
    }
}

/// Hubs (relative to the library's src/, or the tools' src/ as `tools/…`)
/// whose own code and children still use each
/// other: [`a_mod_rs_and_its_children_form_a_dag`] holds every other hub to
/// the rule, and these to staying on this list only while knotted.
const KNOTS: [&str; 5] = [
    "accel/embree4/mod.rs",
    "accel/mod.rs",
    "scene/mod.rs",
    "tools/bench/replay/mod.rs",
    "tools/study/mod.rs",
];

/// The mistake: a `mod.rs` whose own code uses its children (a `Context`
/// built from `culling::Culling` and `path::PAIR_DEPTH`) while they use
/// that code back (`super::Context`), so the hub and its children are one
/// knot no file of which can be read or moved alone. A hub may declare and
/// re-export its children freely; its own code may use a child only if
/// that child (and what it uses in the folder) never reaches the hub's own
/// items. Names re-exported from a child resolve to that child, so
/// `super::Context` from a sibling is an edge to `context.rs`.
///
/// [`KNOTS`] lists the hubs that do not follow the rule yet; each must
/// still be knotted (untie one, and the test asks to strike it off).
#[test]
fn a_mod_rs_and_its_children_form_a_dag() {
    let parse = |text: &str| Hub::parse(&code_only(text));
    // The scanner on a hub's shape: declarations and re-exports are not
    // uses; code naming a child or a re-exported name is.
    let hub = parse(
        "pub mod a;\n#[cfg(feature = \"x\")]\npub mod b;\npub use a::{A, deep::B};\n\
         pub use self::b::C;\nfn f() -> A { b::g() }\n",
    );
    assert_eq!(hub.children, BTreeSet::from(["a".into(), "b".into()]));
    assert_eq!(hub.reexports.get("B").map(String::as_str), Some("a"));
    assert_eq!(hub.reexports.get("C").map(String::as_str), Some("b"));
    assert_eq!(hub.uses(), BTreeSet::from(["a".into(), "b".into()]));
    assert!(parse("pub mod a;\npub use a::A;\n").uses().is_empty());
    let mut bad = Vec::new();
    let mut knotted = BTreeSet::new();
    for s in Source::both() {
        hubs_of_a_crate(&s, &mut bad, &mut knotted);
    }
    let untied: Vec<_> = KNOTS.iter().filter(|k| !knotted.contains(**k)).collect();
    assert!(
        untied.is_empty(),
        "no longer knotted, strike off KNOTS: {untied:?}"
    );
    assert!(
        bad.is_empty(),
        "a mod.rs and its children form a cycle:\n  {}",
        bad.join("\n  ")
    );
}

/// Adds to `bad` each `mod.rs` of `s` knotted with its children (outside
/// [`KNOTS`]), and to `knotted` each hub of [`KNOTS`] still knotted.
fn hubs_of_a_crate(s: &Source, bad: &mut Vec<String>, knotted: &mut BTreeSet<String>) {
    let parse = |text: &str| Hub::parse(&code_only(text));
    for (f, code) in &s.files {
        if f.file_name().is_none_or(|n| n != "mod.rs") {
            continue;
        }
        let dir = f.parent().unwrap();
        let hub = parse(code);
        let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        g.insert("mod.rs".into(), hub.uses());
        for (cf, ccode) in &s.files {
            let stem = cf.file_stem().unwrap().to_str().unwrap();
            let child = if cf.parent() == Some(dir) && stem != "mod" {
                stem.to_string()
            } else if cf.parent().and_then(Path::parent) == Some(dir) && stem == "mod" {
                let d = cf.parent().unwrap().file_name().unwrap();
                d.to_str().unwrap().to_string()
            } else {
                continue;
            };
            if !hub.children.contains(&child) {
                continue;
            }
            let e = g.entry(child.clone()).or_default();
            for r in super_refs(ccode) {
                let to = if hub.children.contains(&r) {
                    r
                } else if let Some(c) = hub.reexports.get(&r) {
                    c.clone()
                } else {
                    "mod.rs".into()
                };
                if to != child {
                    e.insert(to);
                }
            }
        }
        let rel = format!("{}{}", s.label, f.strip_prefix(&s.src).unwrap().display());
        match find_cycle(&g) {
            Some(_) if KNOTS.contains(&rel.as_str()) => {
                knotted.insert(rel);
            }
            Some(cycle) => bad.push(format!("{rel}: {}", cycle.join(" → "))),
            None => {}
        }
    }
}

#[test]
fn the_farm_stores_film_sums_without_the_integrator_or_the_renderer() {
    let s = Source::load();
    for forbidden in ["integrator", "render"] {
        let hits = s.files_naming("farm", forbidden);
        assert!(
            hits.is_empty(),
            "farm must not depend on `{forbidden}`: {}",
            hits.join(", ")
        );
    }
}

#[test]
fn the_film_knows_nothing_of_the_integrator() {
    let s = Source::load();
    let hits = s.files_naming("film", "integrator");
    assert!(
        hits.is_empty(),
        "film must not depend on `integrator`: {}",
        hits.join(", ")
    );
}
