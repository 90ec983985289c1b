//! The accuracy budget end to end (`docs/bssrdf.md` §14,
//! `docs/scene-format.md` "Subsurface sampling options"): `--accuracy`
//! is read as a fraction or a percentage and refused out of (0, 1)
//! naming the flag; on the thin marble sphere under its key light
//! (scenes/keylight-sphere.toml, 1.2 ℓd) a budget of 1 % chooses the
//! random walk, `--explain` says so with each candidate's prediction,
//! and the render is the random-walk integrator's bit for bit.

use std::path::Path;
use std::process::{Command, Output};

use super::region::Exr;

fn lucent(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap()
}

/// scenes/keylight-sphere.toml over a small region, with `extra`.
fn render(dir: &Path, name: &str, extra: &[&str]) -> Exr {
    let out = dir.join(name);
    let mut a = vec![
        "render",
        "scenes/keylight-sphere.toml",
        "--region",
        "8,16,24,32",
        "--spp",
        "2",
        "--seed",
        "3",
        "--threads",
        "2",
        "-q",
        "-o",
    ];
    a.push(out.to_str().unwrap());
    a.extend_from_slice(extra);
    let o = lucent(&a);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    Exr::read(&out)
}

/// The mistake: the walk chosen but not run (the path integrator's
/// diffusion at its hits), or run with other random numbers or another
/// traversal than the random-walk integrator's.
#[test]
fn a_budget_that_chooses_the_walk_renders_the_walks_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let budget = render(d, "budget.exr", &["--accuracy", "1%"]);
    let walk = render(d, "walk.exr", &["--integrator", "randomwalk"]);
    let diffusion = render(d, "diffusion.exr", &[]);
    assert_eq!(budget.channels, walk.channels);
    assert_ne!(budget.channels, diffusion.channels);
}

/// The mistake: the choice made but not shown, or shown without the
/// candidates it rejected and their predictions.
#[test]
fn explain_shows_the_choice_and_each_candidates_prediction() {
    let o = lucent(&[
        "render",
        "scenes/keylight-sphere.toml",
        "--accuracy",
        "0.01",
        "--explain",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    let line = |what: &str| {
        text.lines()
            .find(|l| l.contains(what))
            .unwrap_or_else(|| panic!("no {what} in\n{text}"))
            .to_string()
    };
    let choice = line("  accuracy budget  ");
    assert!(
        choice.contains("walk") && choice.contains("key light"),
        "{choice}"
    );
    assert!(choice.contains("burley predicted") && choice.contains("tabulated predicted"));
    let ball = line("  object");
    for c in ["burley", "tabulated", "walk"] {
        assert!(ball.contains(c), "{ball}");
    }
    assert!(line("  subsurface  ").contains("random walk"), "{text}");
    let json = lucent(&[
        "render",
        "scenes/keylight-sphere.toml",
        "--accuracy",
        "1%",
        "--explain=json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let mut materials = v["materials"].as_array().unwrap().iter();
    let marble = materials.find(|m| m["name"] == "marble").unwrap();
    let budget = &marble["budget"];
    assert_eq!(budget["chosen"], "walk", "{budget}");
    assert_eq!(
        budget["objects"][0]["candidates"].as_array().unwrap().len(),
        3
    );
}

/// The mistake: a budget that cannot be met or means nothing accepted,
/// or refused without naming the flag.
#[test]
fn out_of_range_budgets_are_refused_naming_the_flag() {
    for bad in ["0", "1", "150%", "-1%", "nan", "1%%", "x"] {
        let flag = format!("--accuracy={bad}");
        let o = lucent(&["render", "scenes/keylight-sphere.toml", &flag, "--explain"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{bad}: {err}");
        assert!(err.contains("--accuracy"), "{bad}: {err}");
    }
}
