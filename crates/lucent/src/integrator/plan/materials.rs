//! The render plan's rows per material: the subsurface estimator(s), the
//! coat, the exit lobe and the channels simulated, and what the global
//! rows (specular chains, probe queries) need from them. Why a channel
//! with A = 0 does no work: [`super::explain`]'s module docs.

// Without subsurface support the per-material plan has only surface
// materials: the channel helpers and the mutable collections go unused.
#![cfg_attr(not(feature = "subsurface"), allow(unused_mut, dead_code))]

use serde::{Deserialize, Serialize};

#[cfg(feature = "subsurface")]
use super::choice::choice;
use super::choice::Choice;
use super::options::PlanOptions;
#[cfg(feature = "subsurface")]
use crate::integrator::path::COAT_SPLIT_DEPTH;
#[cfg(feature = "subsurface")]
use crate::integrator::IntegratorKind;
use crate::materials::Material;
#[cfg(feature = "subsurface")]
use crate::materials::{Subsurface, WalkBoundary};
use crate::scene::Scene;

/// One way a subsurface hit is estimated, with its reason; a material's
/// list is tried in order (module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "kebab-case")]
pub enum SubsurfaceMethod {
    /// Level of detail ([`crate::materials::lod`]): hits whose footprint is
    /// at least `min_width` wide (0: every hit, `--lod force`) are shaded
    /// as the entry lobe at xo weighted by the profile's plane integral,
    /// with no probe; the others go on to the next method.
    LevelOfDetail { min_width: f32, reason: String },
    /// The Christensen–Burley diffusion BSSRDF sampled with probe rays.
    Diffusion {
        /// Probe axes: `normal`, `mis3` or `curvature`.
        axes: String,
        /// Channel choice: `single` or `mis`.
        channel: String,
        /// The radius sampler's name.
        radius: String,
        /// Hits below this depth sample an antithetic pair of probes.
        pair_depth: u32,
        /// Hits below this depth add the plane control variate (where
        /// the scene has area lights).
        control_variate_depth: u32,
        /// Whether the diffusion weight is corrected for curvature.
        curvature_correction: bool,
        reason: String,
    },
    /// The volumetric random walk in the medium.
    RandomWalk {
        /// `dielectric` or `diffuse`.
        boundary: String,
        reason: String,
    },
    /// Nothing: no object uses the material, or it has no medium.
    None { reason: String },
}

/// The colour channels a subsurface material spends work on.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Channels {
    /// Channel names (`r`, `g`, `b`) that are simulated.
    pub active: Vec<String>,
    /// The others: exactly 0, no work (module docs).
    pub inactive: Vec<String>,
    pub reason: String,
}

/// What is done at one material.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MaterialPlan {
    pub name: String,
    /// `diffuse`, `dielectric` or `subsurface`.
    pub kind: String,
    /// The objects using it (none: it costs nothing).
    pub objects: Vec<String>,
    /// Parameters read from textures at each hit, `key=texture`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub textures: Vec<String>,
    /// Subsurface materials: the estimator(s), in the order they are tried.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub subsurface: Vec<SubsurfaceMethod>,
    /// Subsurface materials: the coat at xo.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coat: Option<Choice>,
    /// Subsurface materials: the lobe light leaves the medium by.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exit_lobe: Option<Choice>,
    /// Subsurface materials: the channels simulated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub channels: Option<Channels>,
    /// Subsurface materials: the estimator options given a value other
    /// than their default, in the option table's order and names.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub options: Vec<OptionSetting>,
    /// Subsurface materials with an accuracy budget: each object's
    /// candidates, their predicted error and cost, and the choice
    /// ([`super::budget`]).
    #[cfg(feature = "subsurface")]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub budget: Option<super::budget::BudgetPlan>,
}

/// An estimator option set away from its default
/// ([`crate::materials::OPTIONS`]).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct OptionSetting {
    /// The scene key (the flag with `-` for `_`).
    pub name: String,
    /// The value, as the scene format writes it.
    pub value: String,
    /// The default's value.
    pub default: String,
}

const CHANNEL_NAMES: [&str; 3] = ["r", "g", "b"];

/// The per-material part of the plan and what the global rows need from
/// it: the materials that make specular chains (and why), and those that
/// cast probes.
pub(super) struct MaterialRows {
    pub materials: Vec<MaterialPlan>,
    pub specular_materials: Vec<String>,
    pub specular_why: Vec<String>,
    pub probes_needed: Vec<String>,
}

/// The objects using material `i`.
fn users(scene: &Scene, i: usize) -> Vec<String> {
    scene
        .objects
        .iter()
        .filter(|o| o.material == i)
        .map(|o| o.name.clone())
        .collect()
}

/// Whether the accuracy budget gave every object using material `i` the
/// random walk (some object uses it).
fn all_walk(scene: &Scene, i: usize) -> bool {
    let mut users = scene.objects.iter().filter(|o| o.material == i).peekable();
    users.peek().is_some() && users.all(|o| o.walk)
}

/// Material `i`'s name in the scene file.
fn material_name(scene: &Scene, i: usize) -> String {
    scene
        .output
        .material_names
        .get(i)
        .cloned()
        .unwrap_or_else(|| format!("material {i}"))
}

/// Material `i`'s row before its estimator is decided.
fn base_plan(scene: &Scene, i: usize, m: &Material) -> MaterialPlan {
    MaterialPlan {
        name: material_name(scene, i),
        kind: match m.base() {
            Material::Diffuse { .. } => "diffuse",
            Material::Dielectric { .. } | Material::RoughDielectric(_) => "dielectric",
            Material::Conductor(_) => "conductor",
            Material::Plastic(_) => "plastic",
            #[cfg(feature = "subsurface")]
            Material::Subsurface(_) => "subsurface",
            Material::Textured(_) => "textured",
        }
        .into(),
        objects: users(scene, i),
        textures: match m {
            Material::Textured(t) => t
                .names
                .iter()
                .map(|u| format!("{}={}", u.key, u.texture))
                .collect(),
            _ => Vec::new(),
        },
        subsurface: Vec::new(),
        coat: None,
        exit_lobe: None,
        channels: None,
        options: Vec::new(),
        #[cfg(feature = "subsurface")]
        budget: None,
    }
}

/// The options of `ss` that differ from the table's defaults.
#[cfg(feature = "subsurface")]
fn changed_options(ss: &Subsurface) -> Vec<OptionSetting> {
    crate::materials::OPTIONS
        .iter()
        .filter_map(|row| {
            let value = (row.get)(ss.options());
            let default = row.default_text();
            (value != default).then(|| OptionSetting {
                name: row.name.into(),
                value,
                default,
            })
        })
        .collect()
}

/// Every material's row, in the scene's order.
#[cfg_attr(not(feature = "subsurface"), allow(unused_variables))]
pub(super) fn material_rows(scene: &Scene, opts: &PlanOptions, area_lights: bool) -> MaterialRows {
    #[cfg(feature = "subsurface")]
    let walk = opts.integrator == IntegratorKind::RandomWalk;
    let mut rows = MaterialRows {
        materials: Vec::new(),
        specular_materials: Vec::new(),
        specular_why: Vec::new(),
        probes_needed: Vec::new(),
    };
    for (i, m) in scene.materials.iter().enumerate() {
        let mut mp = base_plan(scene, i, m);
        let used = !mp.objects.is_empty();
        let mname = mp.name.clone();
        match m.base() {
            Material::Dielectric { .. } if used => {
                rows.specular_materials.push(mname.clone());
                rows.specular_why
                    .push(format!("{mname}: Fresnel reflection or refraction"));
            }
            Material::RoughDielectric(_) if used => {
                rows.specular_materials.push(mname.clone());
                rows.specular_why.push(format!(
                    "{mname}: rough reflection and refraction, sampled by the interface alone"
                ));
            }
            Material::Conductor(c) if used && c.is_smooth() => {
                rows.specular_materials.push(mname.clone());
                rows.specular_why
                    .push(format!("{mname}: mirror reflection (roughness 0)"));
            }
            Material::Plastic(p) if used && p.is_smooth() => {
                rows.specular_materials.push(mname.clone());
                rows.specular_why
                    .push(format!("{mname}: the mirror coat (roughness 0)"));
            }
            #[cfg(feature = "subsurface")]
            Material::Subsurface(_) if !used => {
                mp.subsurface = vec![SubsurfaceMethod::None {
                    reason: "no object uses it".into(),
                }];
            }
            #[cfg(feature = "subsurface")]
            Material::Subsurface(ss) if walk || all_walk(scene, i) => {
                let why = match walk {
                    true => "--integrator randomwalk: the medium simulated event by event",
                    false => "the accuracy budget's choice: the medium simulated event by event",
                };
                walk_material(ss, why, &mut mp);
                mp.options = changed_options(ss);
                if matches!(ss.boundary(), WalkBoundary::Dielectric { .. })
                    && ss.params().medium.is_some()
                {
                    rows.specular_materials.push(mname.clone());
                    rows.specular_why
                        .push(format!("{mname}: the walk's dielectric boundary"));
                }
            }
            #[cfg(feature = "subsurface")]
            Material::Subsurface(ss) => {
                let active = diffusion_material(ss, opts, area_lights, &mut mp);
                mp.options = changed_options(ss);
                if active {
                    rows.probes_needed.push(mname.clone());
                }
                if ss.specular() && ss.rough_coat().is_none() {
                    rows.specular_materials.push(mname.clone());
                    rows.specular_why.push(format!("{mname}: the mirror coat"));
                }
            }
            _ => {}
        }
        #[cfg(feature = "subsurface")]
        if !walk {
            mp.budget = super::budget::decide(scene, i);
        }
        rows.materials.push(mp);
    }
    rows
}

/// The channels `active` says are on.
fn channels(active: [bool; 3], reason: impl Into<String>) -> Channels {
    let pick = |on: bool| -> Vec<String> {
        (0..3)
            .filter(|&c| active[c] == on)
            .map(|c| CHANNEL_NAMES[c].to_string())
            .collect()
    };
    Channels {
        active: pick(true),
        inactive: pick(false),
        reason: reason.into(),
    }
}

/// Why the diffusion estimator samples as it does: probes (a pair below
/// `pair_depth`, `pair_paths` paths going on from it at the camera
/// vertex) and the plane control variate below `cv_depth` (0 where the
/// scene has no area light, though `asked` was more).
#[cfg(feature = "subsurface")]
fn diffusion_reason(
    (pair_depth, pair_paths): (u32, u32),
    cv_depth: u32,
    area_lights: bool,
    asked: u32,
) -> String {
    let probes = if pair_depth > 0 {
        format!(
            "an antithetic pair at depth < {pair_depth} (probe_pair), {pair_paths} path(s) \
             going on from it at the camera vertex (pair_paths), one probe deeper"
        )
    } else {
        "one a hit".into()
    };
    let cv = if cv_depth > 0 {
        format!(
            "; the plane control variate chooses between each probe and its mirror at depth \
             < {cv_depth}"
        )
    } else if asked > 0 && !area_lights {
        "; no control variate (it models area-light sampling; the scene has no area light)".into()
    } else if asked > 0 {
        "; no control variate (the pair traces both mirrors it would choose between)".into()
    } else {
        "; no control variate (control_variate = false)".into()
    };
    format!("probe rays sample the profile: {probes}{cv}")
}

/// A used subsurface material under the diffusion estimator; whether it
/// has an active channel (and so casts probes).
#[cfg(feature = "subsurface")]
fn diffusion_material(
    ss: &Subsurface,
    opts: &PlanOptions,
    area_lights: bool,
    mp: &mut MaterialPlan,
) -> bool {
    let active: [bool; 3] = std::array::from_fn(|c| ss.params().active(c));
    let any = active.iter().any(|&a| a);
    let lod = ss.lod().decision();
    let every_hit_lod = any && lod.can_trigger && lod.min_width == Some(0.0);
    mp.subsurface = diffusion_methods(ss, opts, area_lights, any, lod);
    mp.coat = Some(diffusion_coat(ss));
    mp.exit_lobe = Some(diffusion_exit_lobe(ss));
    mp.channels = Some(diffusion_channels(active));
    any && !every_hit_lod
}

/// The estimators a used subsurface material tries under diffusion, in
/// order: level of detail where it can trigger, then the probes.
#[cfg(feature = "subsurface")]
fn diffusion_methods(
    ss: &Subsurface,
    opts: &PlanOptions,
    area_lights: bool,
    any: bool,
    lod: crate::materials::lod::LodDecision,
) -> Vec<SubsurfaceMethod> {
    let pair_depth = if ss.probe_pair() { opts.pair_depth } else { 0 };
    // below the pair's depth the pair traces both mirrors: nothing to choose
    let cv_depth = if ss.control_variate() && area_lights && pair_depth < opts.cv_depth {
        opts.cv_depth
    } else {
        0
    };
    let cv_asked = if ss.control_variate() {
        opts.cv_depth
    } else {
        0
    };
    let o = ss.probe().options();
    let every_hit_lod = any && lod.can_trigger && lod.min_width == Some(0.0);
    let mut methods = Vec::new();
    if let (true, Some(min_width)) = (any && lod.can_trigger, lod.min_width) {
        methods.push(SubsurfaceMethod::LevelOfDetail {
            min_width,
            reason: lod.reason,
        });
    }
    if !every_hit_lod {
        methods.push(if any {
            SubsurfaceMethod::Diffusion {
                axes: o.axes.name().into(),
                channel: o.channel.name().into(),
                radius: o.radius.name(),
                pair_depth,
                control_variate_depth: cv_depth,
                curvature_correction: ss.curvature_correction().is_some(),
                reason: diffusion_reason(
                    (pair_depth, ss.pair_paths()),
                    cv_depth,
                    area_lights,
                    cv_asked,
                ),
            }
        } else {
            SubsurfaceMethod::None {
                reason: "A = 0 in every channel: the medium reflects nothing".into(),
            }
        });
    }
    methods
}

/// The coat at xo of a subsurface material under diffusion.
#[cfg(feature = "subsurface")]
fn diffusion_coat(ss: &Subsurface) -> Choice {
    let split = if COAT_SPLIT_DEPTH > 0 {
        format!("both followed at depth < {COAT_SPLIT_DEPTH}, one chosen by Fr deeper")
    } else {
        "one chosen by Fr".to_string()
    };
    let after = match ss.regularized_coat() {
        Some(c) if ss.specular() => format!(
            "; after a non-specular vertex GGX α = {} (regularize {}), light-sampled at xo",
            c.ggx.alpha,
            ss.options().regularize
        ),
        _ => String::new(),
    };
    match (ss.rough_coat(), ss.specular()) {
        (None, true) => choice(
            "smooth",
            format!(
                "roughness {}: a mirror reflecting Fr, {split}{after}",
                ss.roughness()
            ),
        ),
        (Some(c), true) => choice(
            "rough",
            format!(
                "roughness {}: GGX α = {}, light-sampled at xo, chosen with probability \
                 E(μo){after}",
                ss.roughness(),
                c.ggx.alpha
            ),
        ),
        (_, false) => choice(
            "none",
            "specular = false: reflection not rendered, the medium weighted by 1 − Fr",
        ),
    }
}

/// The lobe light leaves a subsurface material by under diffusion.
#[cfg(feature = "subsurface")]
fn diffusion_exit_lobe(ss: &Subsurface) -> Choice {
    match (ss.exit_sw(), ss.rough_coat().is_some()) {
        (true, false) => choice("sw", "exit_sw: the normalized Fresnel lobe Sw at xi"),
        (true, true) => choice("sw-rough", "exit_sw: (1 − E(μi)) / ((1 − Ē) π) at xi"),
        (false, _) => choice("cosine", "exit_sw = false: 1/π at xi"),
    }
}

/// The channels a subsurface material under diffusion simulates.
#[cfg(feature = "subsurface")]
fn diffusion_channels(active: [bool; 3]) -> Channels {
    let off: Vec<&str> = (0..3)
        .filter(|&c| !active[c])
        .map(|c| CHANNEL_NAMES[c])
        .collect();
    channels(
        active,
        if off.is_empty() {
            "A > 0 in every channel".to_string()
        } else {
            format!(
                "A = 0 in {}: never sampled, exactly 0, no work",
                off.join(", ")
            )
        },
    )
}

/// A used subsurface material under the random walk, and why.
#[cfg(feature = "subsurface")]
fn walk_material(ss: &Subsurface, why: &str, mp: &mut MaterialPlan) {
    let Some(medium) = ss.params().medium else {
        mp.subsurface = vec![SubsurfaceMethod::None {
            reason: "no medium recorded: the path ends there (a black surface)".into(),
        }];
        return;
    };
    mp.subsurface = vec![SubsurfaceMethod::RandomWalk {
        boundary: ss.boundary().name().into(),
        reason: why.into(),
    }];
    mp.coat = Some(match ss.boundary() {
        WalkBoundary::Dielectric { .. } => choice(
            "dielectric",
            "the walk's exact Fresnel boundary replaces the coat (roughness, specular unused)",
        ),
        WalkBoundary::Diffuse { .. } => choice(
            "diffuse-fresnel",
            "Fresnel probabilities, transmission forgets the direction",
        ),
    });
    mp.exit_lobe = Some(match ss.boundary() {
        WalkBoundary::Dielectric { connect: false } => {
            choice("refraction", "leaves along Snell's direction")
        }
        WalkBoundary::Dielectric { connect: true } => choice(
            "refraction",
            "leaves along Snell's direction; lights sampled through the boundary from its \
             scattering points",
        ),
        WalkBoundary::Diffuse { exit_nee: true } => {
            choice("diffuse-exit", "exit lobe at the exit point, light-sampled")
        }
        WalkBoundary::Diffuse { exit_nee: false } => choice(
            "diffuse-exit",
            "exit lobe at the exit point, not light-sampled",
        ),
    });
    let active: [bool; 3] = std::array::from_fn(|c| medium.sigma_s[c] > 0.0);
    mp.channels = Some(channels(
        active,
        if active.iter().all(|&a| a) {
            "σs > 0 in every channel; flights chosen by throughput"
        } else {
            "σs = 0: zero throughput after the first scattering, no flight chosen by it"
        },
    ));
}
