//! The accuracy budget's choice (`docs/bssrdf.md` §14): for each object
//! of a subsurface material with `accuracy` set, the cheapest candidate
//! estimator (diffusion with the Burley profile, with the tabulated
//! profile, or the random walk) whose predicted error there is within the
//! budget, from what the scene tells before rendering: the object's size
//! in diffusion lengths of the material's widest channel and how
//! directional the scene's light is, read through the measured model
//! ([`crate::bssrdf::error_model`]). The objects that diffuse share the
//! material's profile: the cheapest one within the budget on all of them.
//! [`decide`] is the choice written out (`--explain`); [`resolve`] makes
//! it, once, on the scene a render or a plan uses.

use serde::{Deserialize, Serialize};

use crate::accel::Traversal;
use crate::bssrdf::error_model::{Candidate, ErrorModel, Lighting, Prediction};
use crate::bssrdf::params::diffuse_mfp;
use crate::bssrdf::ProfileShape;
use crate::error::ParamError;
use crate::geometry::Mesh;
use crate::materials::{Material, Subsurface};
use crate::scene::Scene;

/// One candidate's prediction on one object and what the choice made of it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CandidateRow {
    pub estimator: String,
    /// Predicted relative error of the object's image.
    pub error: f64,
    /// Cost per sample relative to diffusion with the Burley profile.
    pub cost: f64,
    /// Whether the object's size lies within the measured sizes (else
    /// the largest error measured is predicted).
    pub in_range: bool,
}

/// One object's facts and the candidates' predictions there.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ObjectBudget {
    pub object: String,
    /// Its size: 3 × volume / area (a sphere's radius), scene units.
    pub size: f64,
    /// That size over the widest channel's diffusion length ℓd.
    pub size_ld: f64,
    pub candidates: Vec<CandidateRow>,
    /// `burley`, `tabulated` or `walk`: the estimator at its hits.
    pub chosen: String,
    pub reason: String,
}

/// A material's choice under its budget.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BudgetPlan {
    /// The largest predicted error allowed (a fraction).
    pub budget: f32,
    /// `uniform` or `key`.
    pub lighting: String,
    /// `burley` or `tabulated`: the profile of the objects that diffuse;
    /// `walk` where every object walks.
    pub chosen: String,
    pub reason: String,
    /// In the order of the scene's objects.
    pub objects: Vec<ObjectBudget>,
}

/// The choice for material `i`, None where it has no budget, no object
/// uses it, or it records no medium.
pub fn decide(scene: &Scene, i: usize) -> Option<BudgetPlan> {
    let Material::Subsurface(ss) = scene.materials[i].base() else {
        return None;
    };
    let budget = ss.options().accuracy?;
    let ld = widest_diffusion_length(ss)?;
    let model = ErrorModel::get().ok()?;
    let lighting = lighting(scene);
    let mut objects: Vec<ObjectBudget> = (0..scene.objects.len())
        .filter(|&o| scene.objects[o].material == i)
        .map(|o| object_budget(scene, o, ld, lighting, model))
        .collect();
    if objects.is_empty() {
        return None;
    }
    for o in &mut objects {
        let (pick, why) = cheapest(&[&*o], &ANY, budget);
        (o.chosen, o.reason) = (Candidate::ALL[pick].name().into(), why);
    }
    let (chosen, reason) = material_choice(&mut objects, budget);
    Some(BudgetPlan {
        budget,
        lighting: lighting.name().into(),
        chosen,
        reason,
        objects,
    })
}

/// Every candidate, and the diffusion ones, as indices into
/// [`Candidate::ALL`].
const ANY: [usize; 3] = [
    Candidate::Burley as usize,
    Candidate::Tabulated as usize,
    Candidate::Walk as usize,
];
const DIFFUSION: [usize; 2] = [Candidate::Burley as usize, Candidate::Tabulated as usize];

/// Among `candidates` (indices into [`Candidate::ALL`]), the cheapest whose
/// predicted error on every one of `objects` is within `budget`, by the
/// worst error and cost over them; the last one where none is. Why, in
/// words.
fn cheapest(objects: &[&ObjectBudget], candidates: &[usize], budget: f32) -> (usize, String) {
    let worst = |c: usize| -> (f64, f64) {
        let rows = objects.iter().map(|o| &o.candidates[c]);
        let e = rows.clone().map(|r| r.error).fold(0.0, f64::max);
        (e, rows.map(|r| r.cost).fold(0.0, f64::max))
    };
    let mut order = candidates.to_vec();
    order.sort_by(|&a, &b| worst(a).1.total_cmp(&worst(b).1));
    let pick = order
        .iter()
        .copied()
        .find(|&c| worst(c).0 <= budget as f64)
        .unwrap_or(*candidates.last().unwrap());
    (pick, reason(&order, pick, &worst, budget))
}

/// The material's profile for its objects that diffuse, and why: the
/// cheapest diffusion profile within the budget on all of them. An object
/// that profile does not meet walks. Where all objects choose alike, the
/// choice and reason are theirs.
fn material_choice(objects: &mut [ObjectBudget], budget: f32) -> (String, String) {
    let diffusing: Vec<&ObjectBudget> = objects
        .iter()
        .filter(|o| o.chosen != Candidate::Walk.name())
        .collect();
    if diffusing.is_empty() {
        let all: Vec<&ObjectBudget> = objects.iter().collect();
        let (_, why) = cheapest(&all, &ANY, budget);
        return (Candidate::Walk.name().into(), why);
    }
    let (profile, why) = cheapest(&diffusing, &DIFFUSION, budget);
    let name = Candidate::ALL[profile].name();
    if objects.iter().all(|o| o.chosen == name) {
        return (name.into(), why);
    }
    let mut walkers = Vec::new();
    for o in objects.iter_mut() {
        let row = &o.candidates[profile];
        let (walk, within) = (Candidate::Walk.name(), row.error <= budget as f64);
        if o.chosen != walk && o.chosen != name {
            o.reason = format!(
                "the material's {name} profile (its other objects need it) predicted \
                 {:.1} % {} {:.1} % here; alone: {}",
                100.0 * row.error,
                if within { "≤" } else { ">" },
                100.0 * budget,
                o.reason
            );
            o.chosen = if within { name } else { walk }.into();
        }
        if o.chosen == walk {
            walkers.push(o.object.clone());
        }
    }
    let shared = format!("the objects that diffuse share the {name} profile: {why}");
    match walkers.is_empty() {
        true => (name.into(), shared),
        false => (
            name.into(),
            format!("{shared}; the random walk at {}", walkers.join(", ")),
        ),
    }
}

/// Why `pick` was chosen: the cheaper candidates refused, by their worst
/// predicted error.
fn reason(
    order: &[usize],
    pick: usize,
    worst: &dyn Fn(usize) -> (f64, f64),
    budget: f32,
) -> String {
    let refused: Vec<String> = order
        .iter()
        .take_while(|&&c| c != pick)
        .map(|&c| {
            format!(
                "{} predicted {:.1} % > {:.1} %",
                Candidate::ALL[c].name(),
                100.0 * worst(c).0,
                100.0 * budget
            )
        })
        .collect();
    let (e, cost) = worst(pick);
    let chosen = format!(
        "{} predicted {:.1} % ≤ {:.1} % at {cost:.2}× the cost of Burley diffusion",
        Candidate::ALL[pick].name(),
        100.0 * e,
        100.0 * budget
    );
    match refused.is_empty() {
        true => format!("the cheapest within the budget: {chosen}"),
        false => format!("{}; {chosen}", refused.join("; ")),
    }
}

/// Object `o`'s facts and the model's predictions for it.
fn object_budget(
    scene: &Scene,
    o: usize,
    ld: f64,
    lighting: Lighting,
    model: &ErrorModel,
) -> ObjectBudget {
    let size = scene.meshes.get(o).map_or(0.0, volume_radius);
    let size_ld = size / ld;
    let candidates = Candidate::ALL
        .iter()
        .map(|&c| {
            let Prediction {
                error,
                cost,
                in_range,
            } = model.predict(lighting, size_ld, c);
            CandidateRow {
                estimator: c.name().into(),
                error,
                cost,
                in_range,
            }
        })
        .collect();
    ObjectBudget {
        object: scene.objects[o].name.clone(),
        size,
        size_ld,
        candidates,
        chosen: String::new(),
        reason: String::new(),
    }
}

/// How directional the scene's light is: uniform only where a constant
/// environment is all the light; any emitter, `[[lights]]` entry or
/// environment image makes it a key light (the model's worse case).
pub fn lighting(scene: &Scene) -> Lighting {
    let flags = super::Plan::new(scene);
    if flags.area_lights || flags.analytic_lights || flags.environment_map {
        Lighting::Key
    } else {
        Lighting::Uniform
    }
}

/// The diffusion length ℓd = 1/σtr of the material's widest active
/// channel, in scene units; None without a medium.
fn widest_diffusion_length(ss: &Subsurface) -> Option<f64> {
    let m = ss.params().medium?;
    let ld = (0..3)
        .filter(|&c| ss.params().active(c))
        .map(|c| diffuse_mfp(m.sigma_s[c] * (1.0 - m.g), m.sigma_a[c]))
        .fold(0.0, f64::max);
    (ld > 0.0 && ld.is_finite()).then_some(ld)
}

/// 3V/A of a mesh (a sphere's radius), with V by the divergence theorem
/// over its triangles from the centre of its bounds: exact for a closed
/// mesh, about right for a nearly closed one (a scanned body with holes),
/// 0 for a flat one such as a quad.
pub fn volume_radius(mesh: &Mesh) -> f64 {
    let Some((lo, hi)) = mesh.bounds() else {
        return 0.0;
    };
    let c = (0.5 * (lo + hi)).as_dvec3();
    let (mut v, mut a) = (0.0f64, 0.0f64);
    for t in &mesh.indices {
        let [p0, p1, p2] = mesh.vertices(*t).map(|p| p.as_dvec3() - c);
        v += p0.dot(p1.cross(p2)) / 6.0;
        a += 0.5 * (p1 - p0).cross(p2 - p0).length();
    }
    if a > 0.0 {
        3.0 * v.abs() / a
    } else {
        0.0
    }
}

/// Makes every budget's choice in `scene`: the profile its objects that
/// diffuse share, and the random walk at the hits of those that walk (and
/// then a watertight traversal, which the walk needs).
pub fn resolve(scene: &mut Scene) -> Result<(), ParamError> {
    for i in 0..scene.materials.len() {
        let Some(plan) = decide(scene, i) else {
            continue;
        };
        let Material::Subsurface(ss) = scene.materials[i].base() else {
            continue;
        };
        let mut o = *ss.options();
        if plan.chosen == Candidate::Tabulated.name() {
            o.probe.profile = ProfileShape::Tabulated;
        } else if plan.chosen == Candidate::Burley.name() {
            o.probe.profile = ProfileShape::Burley;
        }
        let chosen = std::sync::Arc::new(ss.with_options(&o)?);
        match &mut scene.materials[i] {
            Material::Textured(t) => {
                std::sync::Arc::make_mut(t).base = Material::Subsurface(chosen)
            }
            m => *m = Material::Subsurface(chosen),
        }
        let users = scene.objects.iter_mut().filter(|u| u.material == i);
        for (u, b) in users.zip(&plan.objects) {
            u.walk = b.chosen == Candidate::Walk.name();
        }
    }
    if scene.objects.iter().any(|u| u.walk) {
        scene.settings.traversal = Traversal::Watertight;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// A marble sphere of radius `radius_mm` under a side lamp (`key`) or
    /// a constant environment alone, with `extra` on the material.
    fn sphere(radius_mm: f64, key: bool, extra: &str) -> Scene {
        let light = match key {
            true => {
                "[materials.lamp]\ntype = \"diffuse\"\nalbedo = [0, 0, 0]\n\
                     [[shapes]]\nname = \"light\"\ntype = \"quad\"\nmaterial = \"lamp\"\n\
                     emission = [10, 10, 10]\nrotate = [[90, 0, 1, 0]]\ntranslate = [-2.5, 0, 0]\n"
            }
            false => "[environment]\nradiance = [1, 1, 1]\n",
        };
        let text = format!(
            "units_per_mm = {}\n[camera]\nlook_from = [0, 0, 4.4]\nlook_at = [0, 0, 0]\n\
             resolution = [8, 8]\n[materials.marble]\ntype = \"subsurface\"\n\
             preset = \"marble\"\n{extra}\n{light}[[shapes]]\nname = \"ball\"\n\
             type = \"sphere\"\nmaterial = \"marble\"\nsubdivisions = 3\n",
            1.0 / radius_mm
        );
        crate::scene::load::load_str(&text, Path::new("budget.toml")).unwrap()
    }

    /// The index of the sphere's material.
    fn m(s: &Scene) -> usize {
        s.output
            .material_names
            .iter()
            .position(|n| n == "marble")
            .unwrap()
    }

    fn marble(s: &Scene) -> &Subsurface {
        match s.materials[m(s)].base() {
            Material::Subsurface(ss) => ss,
            _ => panic!("the sphere's material"),
        }
    }

    /// The mistake: the model ignored (one estimator for every scene), or
    /// the lighting or the size read wrong. A thin marble sphere (1.2 ℓd)
    /// under a key light puts the light far from where diffusion does:
    /// only the walk meets 1 %; a large one (24 ℓd) under uniform light is
    /// diffusion's best case: Burley's profile meets it.
    #[test]
    fn thin_marble_under_a_key_light_walks_and_a_large_one_in_uniform_light_diffuses() {
        let thin = sphere(10.0, true, "accuracy = 0.01");
        let plan = decide(&thin, m(&thin)).unwrap();
        assert_eq!(
            (plan.chosen.as_str(), plan.lighting.as_str()),
            ("walk", "key")
        );
        let o = &plan.objects[0];
        assert!((o.size_ld - 1.17).abs() < 0.03, "{}", o.size_ld);
        let large = sphere(200.0, false, "accuracy = 0.01");
        let plan = decide(&large, m(&large)).unwrap();
        assert_eq!(
            (plan.chosen.as_str(), plan.lighting.as_str()),
            ("burley", "uniform")
        );
        // and the choice is made on the scene: the walk at the thin one's hits
        let mut s = thin;
        resolve(&mut s).unwrap();
        assert!(s.objects.iter().any(|o| o.name == "ball" && o.walk));
        assert_eq!(s.settings.traversal, Traversal::Watertight);
    }

    /// The mistake: the choice made per material for its most demanding
    /// object. Three marble spheres of one material under a key light, of
    /// 0.35, 3.5 and 35 ℓd, at a budget of 5 %: only the walk meets it on
    /// the small one, the tabulated profile on the middle one, Burley's on
    /// the large one. The small one walks alone; the other two share the
    /// tabulated profile, which both meet.
    #[test]
    fn each_object_walks_or_diffuses_by_its_own_size() {
        let lamp = "[materials.lamp]\ntype = \"diffuse\"\nalbedo = [0, 0, 0]\n\
                    [[shapes]]\nname = \"light\"\ntype = \"quad\"\nmaterial = \"lamp\"\n\
                    emission = [10, 10, 10]\nrotate = [[90, 0, 1, 0]]\ntranslate = [-9, 0, 0]\n";
        let ball = |name: &str, mm: f64, x: f64| {
            format!(
                "[[shapes]]\nname = \"{name}\"\ntype = \"sphere\"\nmaterial = \"marble\"\n\
                 subdivisions = 3\nscale = {}\ntranslate = [{x}, 0, 0]\n",
                mm / 100.0
            )
        };
        let text = format!(
            "units_per_mm = 0.01\n[camera]\nlook_from = [0, 0, 20]\nlook_at = [0, 0, 0]\n\
             resolution = [8, 8]\n[materials.marble]\ntype = \"subsurface\"\n\
             preset = \"marble\"\naccuracy = 0.05\n{lamp}{}{}{}",
            ball("small", 3.0, -4.0),
            ball("middle", 30.0, -2.0),
            ball("large", 300.0, 4.0)
        );
        let mut s = crate::scene::load::load_str(&text, Path::new("objects.toml")).unwrap();
        let plan = decide(&s, m(&s)).unwrap();
        let chosen: Vec<(&str, &str)> = plan
            .objects
            .iter()
            .map(|o| (o.object.as_str(), o.chosen.as_str()))
            .collect();
        assert_eq!(
            chosen,
            [
                ("small", "walk"),
                ("middle", "tabulated"),
                ("large", "tabulated")
            ],
            "{:#?}",
            plan.objects
        );
        assert_eq!(plan.chosen, "tabulated", "{}", plan.reason);
        resolve(&mut s).unwrap();
        let walks: Vec<bool> = s.objects.iter().map(|o| o.walk).collect();
        assert_eq!(walks, [false, true, false, false]);
        assert_eq!(marble(&s).options().probe.profile, ProfileShape::Tabulated);
        assert_eq!(s.settings.traversal, Traversal::Watertight);
    }

    /// The mistake: a material without a budget touched by the choice.
    #[test]
    fn without_a_budget_nothing_is_decided_or_changed() {
        let s = sphere(10.0, true, "");
        assert_eq!(decide(&s, m(&s)), None);
        let mut r = s.clone();
        resolve(&mut r).unwrap();
        assert_eq!(r.materials, s.materials);
        assert_eq!(r.settings.traversal, s.settings.traversal);
    }

    /// The mistake: the size measure wrong for the model's spheres (3V/A
    /// is the radius) or blind to thinness (an open quad has none).
    #[test]
    fn volume_radius_is_a_spheres_radius_and_zero_for_an_open_quad() {
        let s = sphere(10.0, true, "");
        let r = volume_radius(&s.meshes[1]);
        // an icosphere of 1280 faces inscribed in the unit sphere
        assert!((r - 1.0).abs() < 0.02, "{r}");
        assert_eq!(volume_radius(&s.meshes[0]), 0.0);
    }
}
