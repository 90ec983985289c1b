//! The render plan (`lucent::integrator::plan`): for a set of scenes, the
//! plan equals the one written out here by hand (every key but the
//! free-text reasons); a render follows it (no probe ray where it says
//! none, counted per effect); the per-effect counts sum to the total;
//! `--explain` prints without rendering or writing, its JSON parses back,
//! and `--stats` prints the per-effect summary.

use std::path::Path;
use std::process::Command;

use lucent::accel::{self, Backend};
use lucent::film::passes::PassSet;
use lucent::integrator::plan::{Explanation, PlanOptions};
use lucent::integrator::{Counters, Effect, IntegratorKind};
use lucent::render::{self, RenderOptions};
use lucent::scene::{self, Scene};
use serde_json::{json, Value};

const CAMERA: &str = "[camera]\nlook_from = [0, 0, 4]\nlook_at = [0, 0, 0]\n\
                      resolution = [12, 8]\n[render]\nspp = 2\nseed = 3\nmax_depth = 5\n";

const LAMP: &str = "[materials.lamp]\ntype = \"diffuse\"\nalbedo = [0, 0, 0]\n\
                    [[shapes]]\nname = \"light\"\ntype = \"quad\"\nmaterial = \"lamp\"\n\
                    emission = [4, 4, 4]\nrotate = [[90, 1, 0, 0]]\ntranslate = [0, 3, 0]\n";

fn load(body: &str) -> Scene {
    scene::load::load_str(&format!("{CAMERA}{body}"), Path::new("plan-test.toml")).unwrap()
}

fn plan_of(scene: &Scene, integrator: IntegratorKind, passes: PassSet) -> Explanation {
    Explanation::new(
        scene,
        &PlanOptions {
            integrator,
            passes,
            ..PlanOptions::default()
        },
    )
}

/// The plan as JSON without its free-text reasons.
fn without_reasons(p: &Explanation) -> Value {
    fn strip(v: &mut Value) {
        match v {
            Value::Object(m) => {
                m.remove("reason");
                m.remove("min_width");
                // the option rows have a test of their own
                m.remove("options");
                m.values_mut().for_each(strip);
            }
            Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    let mut v = serde_json::to_value(p).unwrap();
    strip(&mut v);
    v
}

fn check(p: &Explanation, want: Value) {
    let got = without_reasons(p);
    assert_eq!(
        got,
        want,
        "got\n{}",
        serde_json::to_string_pretty(&got).unwrap()
    );
}

/// The scene-wide part shared by most expected plans.
fn top(direct: &str, env: &str, specular: (&str, Vec<&str>), probes: &str) -> Value {
    json!({
        "schema": 1,
        "integrator": "path",
        "direct_lighting": {"method": direct},
        "environment": {"method": env},
        "indirect": {"method": "lobe sampling", "max_depth": 5, "roulette_from": 3},
        "specular_chains": {"method": specular.0, "materials": specular.1},
        "probe_queries": {"method": probes},
        "traversal": {"method": "fast"},
        "film": {"method": "opaque"},
        "sampler": {"method": "sobol"},
        "aovs": {"method": "none", "passes": []},
    })
}

fn with_materials(mut v: Value, materials: Value) -> Value {
    v["materials"] = materials;
    v
}

/// The default subsurface plan: level of detail (auto) where the footprint
/// is wide, else the diffusion (`min_width` is checked in
/// `level_of_detail_at_distance_forced_or_off`).
fn diffusion(coat: &str, exit: &str, active: &[&str], inactive: &[&str]) -> Value {
    json!({
        "subsurface": [{"method": "level-of-detail"}, {
            "method": "diffusion", "axes": "curvature", "channel": "mis",
            "radius": "analytic", "pair_depth": 0, "control_variate_depth": 0,
            "curvature_correction": true
        }],
        "coat": {"method": coat},
        "exit_lobe": {"method": exit},
        "channels": {"active": active, "inactive": inactive},
    })
}

fn subsurface_entry(name: &str, objects: &[&str], rest: Value) -> Value {
    let mut v = json!({"name": name, "kind": "subsurface", "objects": objects});
    for (k, x) in rest.as_object().unwrap() {
        v[k] = x.clone();
    }
    v
}

const SPHERE_ENV: &str = "[environment]\nradiance = [0.5, 0.5, 0.5]\n\
                          [materials.clay]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\
                          [[shapes]]\nname = \"ball\"\ntype = \"sphere\"\nmaterial = \"clay\"\n";

#[test]
fn environment_only_no_lights_no_subsurface() {
    let s = load(SPHERE_ENV);
    check(
        &plan_of(&s, IntegratorKind::Path, PassSet::EMPTY),
        with_materials(
            top("none", "escaping rays", ("none", vec![]), "off"),
            json!([{"name": "clay", "kind": "diffuse", "objects": ["ball"]}]),
        ),
    );
}

#[test]
fn lights_and_glass_without_subsurface() {
    let s = load(&format!(
        "{LAMP}[materials.glass]\ntype = \"dielectric\"\neta = 1.5\n\
         [materials.wax]\ntype = \"subsurface\"\npreset = \"marble\"\n\
         [[shapes]]\nname = \"ball\"\ntype = \"sphere\"\nmaterial = \"glass\"\n"
    ));
    // wax is defined but on no object: no probes, and it says so
    check(
        &plan_of(&s, IntegratorKind::Path, PassSet::EMPTY),
        with_materials(
            top(
                "next-event estimation",
                "none",
                ("followed", vec!["glass"]),
                "off",
            ),
            json!([
                {"name": "glass", "kind": "dielectric", "objects": ["ball"]},
                {"name": "lamp", "kind": "diffuse", "objects": ["light"]},
                {"name": "wax", "kind": "subsurface", "objects": [],
                 "subsurface": [{"method": "none"}]},
            ]),
        ),
    );
}

#[test]
fn sphere_spot_and_distant_lights_are_light_sampled() {
    let lights = "[[lights]]\ntype = \"distant\"\ndirection = [0, -1, 0]\nirradiance = [1, 1, 1]\n\
                  [[lights]]\ntype = \"sphere\"\nposition = [0, 2, 0]\nradius = 0.1\n\
                  power = [5, 5, 5]\nspot_direction = [0, -1, 0]\nspot_angle = 30\n";
    // Without an emitting shape, the [[lights]] alone are sampled.
    let s = load(&format!("{SPHERE_ENV}{lights}"));
    let p = plan_of(&s, IntegratorKind::Path, PassSet::EMPTY);
    assert_eq!(p.direct_lighting.method, "next-event estimation");
    let r = &p.direct_lighting.reason;
    assert!(r.contains("lights[0] distant, lights[1] spot"), "{r}");
    // With one, both are said.
    let s = load(&format!("{LAMP}{SPHERE_ENV}{lights}"));
    let r = plan_of(&s, IntegratorKind::Path, PassSet::EMPTY)
        .direct_lighting
        .reason;
    assert!(
        r.contains("1 emitting object(s) (light)") && r.contains("2 light(s)"),
        "{r}"
    );
}

const KETCHUP: &str = "[materials.sauce]\ntype = \"subsurface\"\npreset = \"ketchup\"\n";
const BALL_SAUCE: &str = "[[shapes]]\nname = \"ball\"\ntype = \"sphere\"\nmaterial = \"sauce\"\n";

#[test]
fn ketchup_blue_is_off_with_the_presets_given_albedo_and_on_with_the_table() {
    // The preset data: Jensen's Rd for ketchup is (0.16, 0.01, 0.00), so
    // with `albedo_source = "given"` blue has A = 0; the albedo table gives
    // what the medium reflects, A_b ≈ 0.005 > 0 (bssrdf::params tests).
    let given = load(&format!(
        "{LAMP}{KETCHUP}albedo_source = \"given\"\n{BALL_SAUCE}"
    ));
    let lamp = json!({"name": "lamp", "kind": "diffuse", "objects": ["light"]});
    check(
        &plan_of(&given, IntegratorKind::Path, PassSet::EMPTY),
        with_materials(
            top(
                "next-event estimation",
                "none",
                ("followed", vec!["sauce"]),
                "on",
            ),
            json!([
                lamp,
                subsurface_entry(
                    "sauce",
                    &["ball"],
                    diffusion("smooth", "sw", &["r", "g"], &["b"])
                )
            ]),
        ),
    );
    let table = load(&format!("{LAMP}{KETCHUP}{BALL_SAUCE}"));
    check(
        &plan_of(&table, IntegratorKind::Path, PassSet::EMPTY),
        with_materials(
            top(
                "next-event estimation",
                "none",
                ("followed", vec!["sauce"]),
                "on",
            ),
            json!([
                lamp,
                subsurface_entry(
                    "sauce",
                    &["ball"],
                    diffusion("smooth", "sw", &["r", "g", "b"], &[])
                )
            ]),
        ),
    );
}

#[test]
fn the_variance_reduction_is_planned_as_the_material_asks_and_the_lights_allow() {
    // The control variate models next-event estimation of area lights:
    // under the environment alone there is nothing for it to model, and
    // the plan says so; with a lamp it is on at the camera vertex where
    // the material turns it on; the pair only where the material asks.
    let diffusion_of = |s: &Scene| -> Value {
        let v = serde_json::to_value(plan_of(s, IntegratorKind::Path, PassSet::EMPTY)).unwrap();
        let m = v["materials"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["name"] == "sauce")
            .unwrap()
            .clone();
        m["subsurface"]
            .as_array()
            .unwrap()
            .iter()
            .find(|x| x["method"] == "diffusion")
            .unwrap()
            .clone()
    };
    let env = load(&format!(
        "[environment]\nradiance = [0.5, 0.5, 0.5]\n{KETCHUP}control_variate = true\n{BALL_SAUCE}"
    ));
    let d = diffusion_of(&env);
    assert_eq!(d["control_variate_depth"], 0, "{d}");
    let why = d["reason"].as_str().unwrap();
    assert!(why.contains("no area light"), "{why}");
    let lit = load(&format!(
        "{LAMP}{KETCHUP}control_variate = true\n{BALL_SAUCE}"
    ));
    let d = diffusion_of(&lit);
    assert_eq!(d["control_variate_depth"], 1, "{d}");
    let why = d["reason"].as_str().unwrap();
    assert!(
        why.contains("control variate") && why.contains("depth < 1"),
        "{why}"
    );
    // The material's choices: the pair instead, and neither.
    let pair = load(&format!(
        "{LAMP}{KETCHUP}control_variate = false\nprobe_pair = true\n{BALL_SAUCE}"
    ));
    let d = diffusion_of(&pair);
    assert_eq!(
        (&d["pair_depth"], &d["control_variate_depth"]),
        (&json!(1), &json!(0))
    );
    let why = d["reason"].as_str().unwrap();
    assert!(
        why.contains("antithetic pair")
            && why.contains("no control variate (control_variate = false)"),
        "{why}"
    );
    let neither = load(&format!("{LAMP}{KETCHUP}{BALL_SAUCE}"));
    let d = diffusion_of(&neither);
    assert_eq!(
        (&d["pair_depth"], &d["control_variate_depth"]),
        (&json!(0), &json!(0))
    );
}

#[test]
fn rough_coat_cosine_exit_and_no_specular() {
    let s = load(&format!(
        "{LAMP}{KETCHUP}roughness = 0.5\nexit_sw = false\n{BALL_SAUCE}\
         [materials.dull]\ntype = \"subsurface\"\npreset = \"skin1\"\nspecular = false\n\
         [[shapes]]\nname = \"ball2\"\ntype = \"sphere\"\nmaterial = \"dull\"\n\
         translate = [2, 0, 0]\n"
    ));
    check(
        &plan_of(&s, IntegratorKind::Path, PassSet::EMPTY),
        with_materials(
            // a rough coat is a lobe, not a specular chain; no coat, none
            top("next-event estimation", "none", ("none", vec![]), "on"),
            json!([
                subsurface_entry("dull", &["ball2"], diffusion("none", "sw", &["r", "g", "b"], &[])),
                {"name": "lamp", "kind": "diffuse", "objects": ["light"]},
                subsurface_entry("sauce", &["ball"], diffusion("rough", "cosine", &["r", "g", "b"], &[])),
            ]),
        ),
    );
}

/// The mistake: `--explain` silent about options set away from their
/// defaults, or naming them other than the option table does.
#[test]
fn options_away_from_their_defaults_are_listed_by_the_table() {
    let s = load(&format!(
        "{LAMP}{KETCHUP}axes = \"mis3\"\nprobe_pair = true\nrenormalize = false\n{BALL_SAUCE}"
    ));
    let p = plan_of(&s, IntegratorKind::Path, PassSet::EMPTY);
    let sauce = p.materials.iter().find(|m| m.name == "sauce").unwrap();
    let named: Vec<_> = sauce
        .options
        .iter()
        .map(|o| (o.name.as_str(), o.value.as_str(), o.default.as_str()))
        .collect();
    // renormalize = false is the default: not listed
    assert_eq!(
        named,
        [
            ("axes", "mis3", "curvature"),
            ("probe_pair", "true", "false")
        ]
    );
    let text = lucent::integrator::plan::text::render(&p);
    let rows: Vec<&str> = text
        .lines()
        .filter(|l| l.trim_start().starts_with("option "))
        .collect();
    assert_eq!(rows.len(), 2, "{text}");
    assert!(
        rows[0].contains("axes=mis3") && rows[0].ends_with("(default curvature)"),
        "{}",
        rows[0]
    );
    // a material with every default lists nothing
    let plain = plan_of(
        &load(&format!("{LAMP}{KETCHUP}{BALL_SAUCE}")),
        IntegratorKind::Path,
        PassSet::EMPTY,
    );
    assert!(plain.materials.iter().all(|m| m.options.is_empty()));
}

#[test]
fn random_walk_replaces_probes_with_the_walk() {
    let s = load(&format!(
        "{LAMP}{KETCHUP}boundary = \"diffuse\"\nroughness = 0.5\n{BALL_SAUCE}"
    ));
    let mut want = with_materials(
        top("next-event estimation", "none", ("none", vec![]), "off"),
        json!([
            {"name": "lamp", "kind": "diffuse", "objects": ["light"]},
            {"name": "sauce", "kind": "subsurface", "objects": ["ball"],
             "subsurface": [{"method": "random-walk", "boundary": "diffuse"}],
             "coat": {"method": "diffuse-fresnel"},
             "exit_lobe": {"method": "diffuse-exit"},
             "channels": {"active": ["r", "g", "b"], "inactive": []}},
        ]),
    );
    want["integrator"] = json!("randomwalk");
    want["traversal"] = json!({"method": "watertight"});
    check(
        &plan_of(&s, IntegratorKind::RandomWalk, PassSet::EMPTY),
        want,
    );
}

#[test]
fn aovs_requested_or_not() {
    let s = load(SPHERE_ENV);
    let none = plan_of(&s, IntegratorKind::Path, PassSet::EMPTY);
    assert_eq!(
        (none.aovs.method.as_str(), none.aovs.passes.len()),
        ("none", 0)
    );
    let asked = PassSet::parse_list("albedo,Z").unwrap();
    let p = plan_of(&s, IntegratorKind::Path, asked);
    assert_eq!(p.aovs.method, "recorded");
    assert_eq!(p.aovs.passes, ["albedo", "Z"]);
    // the scene's own [output] aovs, when --aov is not given, come in
    // through the caller (main.rs): the same set, the same plan
    let from_scene = load(&format!(
        "{SPHERE_ENV}[output]\naovs = [\"albedo\", \"Z\"]\n"
    ));
    assert_eq!(
        plan_of(&from_scene, IntegratorKind::Path, from_scene.output.aovs).aovs,
        p.aovs
    );
}

/// The per-effect counts of a real render (BVH, 1 thread).
fn counters(s: &Scene, integrator: IntegratorKind, stats: bool) -> Counters {
    let accel = accel::build(&s.meshes, Backend::Bvh).unwrap();
    let opts = RenderOptions {
        threads: Some(1),
        integrator,
        stats,
        ..RenderOptions::default()
    };
    let (_, st) = render::render(s, accel.as_ref(), &opts).unwrap();
    let c = st.counters;
    assert_eq!(c.effect_rays.iter().sum::<u64>(), c.rays, "{c:?}");
    c
}

#[test]
fn a_plan_without_subsurface_makes_no_probe_query() {
    // wax is defined but on no object: the plan says off, and none is made
    let s = load(&format!(
        "{LAMP}[materials.wax]\ntype = \"subsurface\"\npreset = \"marble\"\n\
         [materials.clay]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\
         [[shapes]]\nname = \"ball\"\ntype = \"sphere\"\nmaterial = \"clay\"\n"
    ));
    assert_eq!(
        plan_of(&s, IntegratorKind::Path, PassSet::EMPTY)
            .probe_queries
            .method,
        "off"
    );
    let c = counters(&s, IntegratorKind::Path, false);
    assert_eq!(c.effect_rays[Effect::Probe as usize], 0, "{c:?}");
    assert_eq!(c.effect_rays[Effect::Walk as usize], 0, "{c:?}");
    assert_eq!(c.effect_rays[Effect::Camera as usize], 12 * 8 * 2);
    assert!(c.effect_rays[Effect::Direct as usize] > 0, "{c:?}");
    assert!(c.effect_rays[Effect::Indirect as usize] > 0, "{c:?}");
    // the tile loop with passes counts the same queries the same way
    let accel = accel::build(&s.meshes, Backend::Bvh).unwrap();
    let opts = RenderOptions {
        threads: Some(1),
        ..RenderOptions::default()
    };
    let out = render::render_passes(
        &s,
        accel.as_ref(),
        &opts,
        PassSet::parse_list("albedo").unwrap(),
    )
    .unwrap();
    assert_eq!(out.stats.counters.effect_rays, c.effect_rays);
    assert_eq!(out.stats.counters.rays, c.rays);
}

#[test]
fn a_plan_with_subsurface_makes_probe_queries_and_the_walk_none() {
    let s = load(&format!("{LAMP}{KETCHUP}{BALL_SAUCE}"));
    assert_eq!(
        plan_of(&s, IntegratorKind::Path, PassSet::EMPTY)
            .probe_queries
            .method,
        "on"
    );
    let c = counters(&s, IntegratorKind::Path, false);
    assert!(c.effect_rays[Effect::Probe as usize] > 0, "{c:?}");
    assert_eq!(c.effect_rays[Effect::Walk as usize], 0, "{c:?}");
    let w = counters(&s, IntegratorKind::RandomWalk, false);
    assert_eq!(w.effect_rays[Effect::Probe as usize], 0, "{w:?}");
    assert!(w.effect_rays[Effect::Walk as usize] > 0, "{w:?}");
}

/// Catches a plan that names the default sampler whatever the scene or
/// the options say.
#[test]
fn the_plan_names_the_scenes_sampler_unless_the_options_name_one() {
    // CAMERA ends in [render]
    let sampled = load(&format!("sampler = \"random\"\n{LAMP}"));
    let plan = plan_of(&sampled, IntegratorKind::Path, PassSet::EMPTY);
    assert_eq!(plan.sampler.method, "random");
    let asked = PlanOptions {
        sampler: Some(lucent::sampling::SamplerKind::Sobol),
        ..PlanOptions::default()
    };
    assert_eq!(Explanation::new(&sampled, &asked).sampler.method, "sobol");
}

#[test]
fn the_plan_traverses_fast_unless_the_scene_asks_or_the_walk_needs_watertight() {
    let method = |s: &Scene, i| plan_of(s, i, PassSet::EMPTY).traversal.method;
    let s = load(&format!("{LAMP}{KETCHUP}{BALL_SAUCE}"));
    assert_eq!(method(&s, IntegratorKind::Path), "fast");
    assert_eq!(method(&s, IntegratorKind::RandomWalk), "watertight");
    // CAMERA ends in [render]
    let w = load(&format!(
        "traversal = \"watertight\"\n{LAMP}{KETCHUP}{BALL_SAUCE}"
    ));
    assert_eq!(method(&w, IntegratorKind::Path), "watertight");
    assert_eq!(method(&w, IntegratorKind::RandomWalk), "watertight");
}

#[test]
fn time_is_measured_only_with_stats() {
    let s = load(&format!("{LAMP}{KETCHUP}{BALL_SAUCE}"));
    let off = counters(&s, IntegratorKind::Path, false);
    assert_eq!((off.effect_ticks, off.sample_ticks), ([0; 5], 0));
    let on = counters(&s, IntegratorKind::Path, true);
    let sections: u64 = on.effect_ticks.iter().sum();
    assert!(on.sample_ticks > 0 && sections > 0, "{on:?}");
    assert!(sections <= on.sample_ticks, "{on:?}");
    for e in [Effect::Camera, Effect::Direct, Effect::Probe] {
        assert!(on.effect_ticks[e as usize] > 0, "{e:?} {on:?}");
    }
    // timing changes no ray and no count
    assert_eq!(on.effect_rays, off.effect_rays);
}

fn lucent(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_lucent"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn explain_prints_the_plan_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.toml");
    std::fs::write(&scene, format!("{CAMERA}{LAMP}{KETCHUP}{BALL_SAUCE}")).unwrap();
    let before: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    let text = lucent(dir.path(), &["render", "s.toml", "--explain"]);
    assert!(text.status.success(), "{text:?}");
    let out = String::from_utf8(text.stdout).unwrap();
    assert!(out.starts_with("render plan (integrator: path)\n"), "{out}");
    // three aligned columns: effect (18), method (24), reason
    for (effect, method, reason) in [
        (
            "probe queries",
            "on",
            "diffusion at hits on material(s) sauce",
        ),
        (
            "direct lighting",
            "next-event estimation",
            "1 emitting object(s) (light)",
        ),
        ("channels", "r g b", "A > 0 in every channel"),
    ] {
        let row = format!("\n  {effect:<18}{method:<24}{reason}");
        assert!(out.contains(&row), "no `{row}` in\n{out}");
    }
    let json = lucent(
        dir.path(),
        &[
            "render",
            "s.toml",
            "--explain=json",
            "--integrator",
            "randomwalk",
            "--aov",
            "albedo",
            "-o",
            "x.exr",
        ],
    );
    assert!(json.status.success(), "{json:?}");
    let p: Explanation = serde_json::from_slice(&json.stdout).unwrap();
    assert_eq!(p.integrator, "randomwalk");
    assert_eq!(p.probe_queries.method, "off");
    assert_eq!(p.aovs.passes, ["albedo"]);
    let again: Explanation = serde_json::from_str(&p.to_json()).unwrap();
    assert_eq!(again, p);
    // the top-level keys in the documented order (indented by 2)
    let raw = String::from_utf8(json.stdout).unwrap();
    let keys: Vec<&str> = raw
        .lines()
        .filter_map(|l| l.strip_prefix("  \""))
        .filter_map(|l| l.split_once('"').map(|k| k.0))
        .collect();
    assert_eq!(
        keys,
        [
            "schema",
            "integrator",
            "direct_lighting",
            "environment",
            "indirect",
            "specular_chains",
            "probe_queries",
            "traversal",
            "film",
            "sampler",
            "aovs",
            "materials"
        ]
    );
    let after: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(before.len(), after.len(), "--explain wrote a file");
    // a bad scene: the render's input error, exit 2
    std::fs::write(dir.path().join("bad.toml"), "[camera]\nfov_y = \"wide\"\n").unwrap();
    let bad = lucent(dir.path(), &["render", "bad.toml", "--explain"]);
    assert_eq!(bad.status.code(), Some(2), "{bad:?}");
    assert!(String::from_utf8_lossy(&bad.stderr).contains("bad.toml"));
}

#[test]
fn stats_prints_rays_and_time_per_effect() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("s.toml"),
        format!("{CAMERA}{LAMP}{KETCHUP}{BALL_SAUCE}"),
    )
    .unwrap();
    let out = lucent(
        dir.path(),
        &[
            "render", "s.toml", "-q", "--stats", "--accel", "bvh", "-o", "r.exr",
        ],
    );
    assert!(out.status.success(), "{out:?}");
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.starts_with("per effect:\n"), "{err}");
    for e in ["camera rays", "subsurface probes", "shading and other"] {
        let line = err
            .lines()
            .find(|l| l.contains(e))
            .unwrap_or_else(|| panic!("{err}"));
        assert!(line.contains("% of time"), "{line}");
    }
    assert!(!err.contains("random walk"), "{err}");
}

#[test]
fn level_of_detail_at_distance_forced_or_off() {
    use lucent::integrator::plan::explain::SubsurfaceMethod;
    use lucent::materials::estimator_options::Assignments;
    use lucent::materials::{LodMode, Material};
    // auto (the default): LOD from 0.25 × Rmax of the widest active
    // channel, then the diffusion
    let s = load(&format!("{LAMP}{KETCHUP}{BALL_SAUCE}"));
    let Material::Subsurface(ss) = &s.materials[1] else {
        panic!("sauce is the second material")
    };
    let rmax = ss.probe().rmax() as f32;
    let p = plan_of(&s, IntegratorKind::Path, PassSet::EMPTY);
    let methods = &p.materials[1].subsurface;
    match &methods[..] {
        [SubsurfaceMethod::LevelOfDetail { min_width, .. }, SubsurfaceMethod::Diffusion { .. }] => {
            assert!(
                (min_width / (0.25 * rmax) - 1.0).abs() < 1e-6,
                "{min_width} vs {rmax}"
            )
        }
        m => panic!("{m:?}"),
    }
    assert_eq!(p.probe_queries.method, "on");
    // lod = "off" in the scene: the diffusion alone
    let off = load(&format!("{LAMP}{KETCHUP}lod = \"off\"\n{BALL_SAUCE}"));
    let p = plan_of(&off, IntegratorKind::Path, PassSet::EMPTY);
    assert!(
        matches!(
            &p.materials[1].subsurface[..],
            [SubsurfaceMethod::Diffusion { .. }]
        ),
        "{:?}",
        p.materials[1].subsurface
    );
    // forced (--lod force): every hit under LOD, so the plan has no probe
    // query, and a render makes none, though it hits the ball
    let mut forced = load(&format!("{LAMP}{KETCHUP}{BALL_SAUCE}"));
    Assignments::default()
        .with("lod", LodMode::Force.name())
        .apply_all(&mut forced.materials)
        .unwrap();
    let p = plan_of(&forced, IntegratorKind::Path, PassSet::EMPTY);
    match &p.materials[1].subsurface[..] {
        [SubsurfaceMethod::LevelOfDetail { min_width, .. }] => assert_eq!(*min_width, 0.0),
        m => panic!("{m:?}"),
    }
    assert_eq!(p.probe_queries.method, "off");
    let c = counters(&forced, IntegratorKind::Path, false);
    assert_eq!(c.effect_rays[Effect::Probe as usize], 0, "{c:?}");
    assert!(c.effect_rays[Effect::Direct as usize] > 0, "{c:?}");
    let full = counters(&s, IntegratorKind::Path, false);
    assert!(full.effect_rays[Effect::Probe as usize] > 0, "{full:?}");
}
