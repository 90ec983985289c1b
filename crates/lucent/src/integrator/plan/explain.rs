//! The render plan written out: for every effect the method the renderer
//! will use and why, derived from the scene and the render options by the
//! same tests the renderer makes ([`super::Plan`], the material's own
//! options, the integrator), so that what it says is what runs.
//!
//! It is a plain value: `lucent render --explain` prints it
//! ([`super::text`]), `--explain=json` and the EXR header (`lucent/plan`)
//! store it as JSON whose keys come in the order of the fields below
//! (serde writes struct fields in declaration order). The schema is
//! documented in `docs/output.md` ("The render plan"); [`SCHEMA`] is its
//! version, raised when a key changes meaning or goes away (new keys and
//! new methods do not raise it).
//!
//! **Per material.** A subsurface material's estimator is a list of
//! [`SubsurfaceMethod`]s, each with its reason, tried in order at every
//! hit: today one entry (diffusion or the random walk). A level-of-detail
//! rule ("below footprint X, a Lambertian of albedo A") is one more
//! variant placed before the full estimator, with its own reason.
//!
//! **Active channels.** A channel with A = 0 does no work in the diffusion
//! estimator: `ProbeSampler::new` (`crate::bssrdf::probe`) builds no radius
//! distribution for it, the channel choice and the balance-heuristic
//! density run over the active channels only, and Rd is exactly 0 there,
//! so no probe is aimed by it and no weight is computed for it. The random
//! walk simulates the medium's σs and σa instead: a channel with σs = 0 has
//! zero throughput after the first scattering event, and flights are chosen
//! by throughput, so none is spent on it after that.

// Without subsurface support the per-material plan has only surface
// materials: the channel helpers and the mutable collections go unused.
#![cfg_attr(not(feature = "subsurface"), allow(unused_mut, dead_code))]

use serde::{Deserialize, Serialize};

use super::{emits, Plan};
use crate::accel::Traversal;
use crate::film::passes::PassSet;
#[cfg(feature = "subsurface")]
use crate::integrator::path::COAT_SPLIT_DEPTH;
use crate::integrator::path::{PAIR_DEPTH, RR_START};
use crate::integrator::IntegratorKind;
use crate::materials::Material;
#[cfg(feature = "subsurface")]
use crate::materials::{Subsurface, WalkBoundary};
use crate::scene::Scene;

/// The version of the JSON schema.
pub const SCHEMA: u32 = 1;

/// What besides the scene decides the plan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanOptions {
    pub integrator: IntegratorKind,
    /// The passes asked for (`--aov`, else the scene's `[output] aovs`).
    pub passes: PassSet,
    /// Subsurface hits below this depth, on materials with `probe_pair`,
    /// sample an antithetic probe pair
    /// (`crate::integrator::Context::pair_depth`).
    pub pair_depth: u32,
    /// Subsurface hits below this depth, on materials with
    /// `control_variate`, add the plane control variate
    /// (`crate::integrator::Context::cv_depth`).
    pub cv_depth: u32,
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            integrator: IntegratorKind::Path,
            passes: PassSet::default(),
            pair_depth: PAIR_DEPTH,
            #[cfg(feature = "subsurface")]
            cv_depth: crate::integrator::control_variate::CV_DEPTH,
            #[cfg(not(feature = "subsurface"))]
            cv_depth: 0,
        }
    }
}

/// An effect's method and the reason for it.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Choice {
    pub method: String,
    pub reason: String,
}

fn choice(method: &str, reason: impl Into<String>) -> Choice {
    Choice {
        method: method.into(),
        reason: reason.into(),
    }
}

/// Indirect light: how paths continue after a vertex, and how far.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Indirect {
    pub method: String,
    pub reason: String,
    /// Bounces after which a path ends.
    pub max_depth: u32,
    /// The bounce from which Russian roulette may end a path.
    pub roulette_from: u32,
}

/// Specular and dielectric chains, and the materials that make them.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Specular {
    pub method: String,
    pub reason: String,
    pub materials: Vec<String>,
}

/// The passes (AOVs) recorded besides the beauty.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Aovs {
    pub method: String,
    pub reason: String,
    pub passes: Vec<String>,
}

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
}

/// The whole plan (module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Explanation {
    /// [`SCHEMA`].
    pub schema: u32,
    /// `path` or `randomwalk`.
    pub integrator: String,
    pub direct_lighting: Choice,
    pub environment: Choice,
    pub indirect: Indirect,
    pub specular_chains: Specular,
    pub probe_queries: Choice,
    /// How Embree treats rays through shared edges
    /// ([`crate::accel::Traversal`]); absent in plans written before it.
    #[serde(default)]
    pub traversal: Choice,
    pub aovs: Aovs,
    pub materials: Vec<MaterialPlan>,
}

const CHANNEL_NAMES: [&str; 3] = ["r", "g", "b"];

impl Explanation {
    /// The plan of `scene` rendered with `opts`.
    pub fn new(scene: &Scene, opts: &PlanOptions) -> Self {
        let flags = Plan::new(scene);
        #[cfg(feature = "subsurface")]
        let walk = opts.integrator == IntegratorKind::RandomWalk;
        let users = |i: usize| -> Vec<String> {
            scene
                .objects
                .iter()
                .filter(|o| o.material == i)
                .map(|o| o.name.clone())
                .collect()
        };
        let name = |i: usize| -> String {
            scene
                .output
                .material_names
                .get(i)
                .cloned()
                .unwrap_or_else(|| format!("material {i}"))
        };

        let lights: Vec<&str> = scene
            .objects
            .iter()
            .filter(|o| emits(o.emission))
            .map(|o| o.name.as_str())
            .collect();
        let direct_lighting = if flags.area_lights {
            choice(
                "next-event estimation",
                format!(
                    "{} emitting object(s) ({}): one light sample and shadow ray per \
                     non-specular vertex, MIS with lobe sampling",
                    lights.len(),
                    lights.join(", ")
                ),
            )
        } else {
            choice("none", "no object emits: no light samples, no shadow rays")
        };
        let environment = match scene.environment {
            Some(e) if flags.environment => choice(
                "escaping rays",
                format!(
                    "constant radiance ({}, {}, {}) added where a path escapes; not \
                     light-sampled",
                    e.x, e.y, e.z
                ),
            ),
            _ => choice("none", "no environment (or black): escaping paths end"),
        };
        let max_depth = scene.settings.max_depth;
        let indirect = Indirect {
            method: if max_depth == 0 {
                "none".into()
            } else {
                "lobe sampling".into()
            },
            reason: if max_depth == 0 {
                "max_depth = 0: only what camera rays hit directly".into()
            } else {
                format!(
                    "paths continue by sampling each vertex's lobe, at most {max_depth} \
                     bounce(s); Russian roulette from bounce {RR_START}"
                )
            },
            max_depth,
            roulette_from: RR_START,
        };

        let mut specular_materials = Vec::new();
        let mut specular_why = Vec::new();
        let mut probes_needed: Vec<String> = Vec::new();
        let mut materials = Vec::new();
        for (i, m) in scene.materials.iter().enumerate() {
            let objects = users(i);
            let used = !objects.is_empty();
            let mname = name(i);
            let mut mp = MaterialPlan {
                name: mname.clone(),
                kind: match m {
                    Material::Diffuse { .. } => "diffuse",
                    Material::Dielectric { .. } => "dielectric",
                    #[cfg(feature = "subsurface")]
                    Material::Subsurface(_) => "subsurface",
                }
                .into(),
                objects,
                subsurface: Vec::new(),
                coat: None,
                exit_lobe: None,
                channels: None,
            };
            match m {
                Material::Dielectric { .. } if used => {
                    specular_materials.push(mname.clone());
                    specular_why.push(format!("{mname}: Fresnel reflection or refraction"));
                }
                #[cfg(feature = "subsurface")]
                Material::Subsurface(_) if !used => {
                    mp.subsurface = vec![SubsurfaceMethod::None {
                        reason: "no object uses it".into(),
                    }];
                }
                #[cfg(feature = "subsurface")]
                Material::Subsurface(ss) if walk => {
                    walk_material(ss, &mut mp);
                    if ss.boundary() == WalkBoundary::Dielectric && ss.params().medium.is_some() {
                        specular_materials.push(mname.clone());
                        specular_why.push(format!("{mname}: the walk's dielectric boundary"));
                    }
                }
                #[cfg(feature = "subsurface")]
                Material::Subsurface(ss) => {
                    let active = diffusion_material(ss, opts, flags.area_lights, &mut mp);
                    if active {
                        probes_needed.push(mname.clone());
                    }
                    if ss.specular() && ss.rough_coat().is_none() {
                        specular_materials.push(mname.clone());
                        specular_why.push(format!("{mname}: the mirror coat"));
                    }
                }
                _ => {}
            }
            materials.push(mp);
        }
        let specular_chains = Specular {
            method: if specular_materials.is_empty() {
                "none".into()
            } else {
                "followed".into()
            },
            reason: if specular_materials.is_empty() {
                "no smooth dielectric or mirror coat on any object".into()
            } else {
                format!(
                    "delta events, continued without light sampling ({})",
                    specular_why.join("; ")
                )
            },
            materials: specular_materials,
        };
        #[cfg(feature = "subsurface")]
        let walk_off = walk;
        #[cfg(not(feature = "subsurface"))]
        let walk_off = false;
        let probe_queries = if walk_off {
            choice("off", "random-walk integrator: no probe rays")
        } else if probes_needed.is_empty() {
            choice(
                "off",
                "no object has a subsurface material that casts probes (none with an \
                 active channel, or every hit under level of detail)",
            )
        } else {
            choice(
                "on",
                format!(
                    "diffusion at hits on material(s) {}",
                    probes_needed.join(", ")
                ),
            )
        };
        let asked = scene.settings.traversal;
        let traversal = match (asked, opts.integrator.traversal(asked)) {
            (Traversal::Fast, Traversal::Watertight) => choice(
                "watertight",
                "random-walk integrator: no walk may slip out of a closed medium through \
                 an edge that triangles share",
            ),
            (_, Traversal::Watertight) => choice(
                "watertight",
                "asked for ([render] traversal): no ray slips through an edge that \
                 triangles share",
            ),
            (_, Traversal::Fast) => choice(
                "fast",
                "Embree's default arithmetic: a ray exactly through an edge that \
                 triangles share can slip through (about 1 in 10⁶ from inside a dense \
                 mesh); [render] traversal = \"watertight\" forbids it; lucent's own BVH \
                 is watertight either way",
            ),
        };
        let passes: Vec<String> = opts.passes.iter().map(|p| p.name().to_string()).collect();
        let aovs = Aovs {
            method: if passes.is_empty() {
                "none".into()
            } else {
                "recorded".into()
            },
            reason: if passes.is_empty() {
                "no pass asked for: the tile loop without a recorder".into()
            } else {
                "asked for (--aov or [output] aovs): summed exactly in the render loop, carried by parts".into()
            },
            passes,
        };
        Explanation {
            schema: SCHEMA,
            integrator: match opts.integrator {
                IntegratorKind::Path => "path",
                #[cfg(feature = "subsurface")]
                IntegratorKind::RandomWalk => "randomwalk",
            }
            .into(),
            direct_lighting,
            environment,
            indirect,
            specular_chains,
            probe_queries,
            traversal,
            aovs,
            materials,
        }
    }

    /// The plan as one line of JSON (the EXR header's `lucent/plan`).
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("a plan is plain data")
    }

    /// The plan as indented JSON (`--explain=json`).
    pub fn to_json_pretty(&self) -> String {
        serde_json::to_string_pretty(self).expect("a plan is plain data")
    }
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
/// `pair_depth`) and the plane control variate below `cv_depth` (0 where
/// the scene has no area light, though `asked` was more).
#[cfg(feature = "subsurface")]
fn diffusion_reason(pair_depth: u32, cv_depth: u32, area_lights: bool, asked: u32) -> String {
    let probes = if pair_depth > 0 {
        format!("an antithetic pair at depth < {pair_depth} (probe_pair), one probe deeper")
    } else {
        "one a hit".into()
    };
    let cv = if cv_depth > 0 {
        format!("; the plane control variate on next-event estimation at depth < {cv_depth}")
    } else if asked > 0 && !area_lights {
        "; no control variate (it models area-light sampling; the scene has no area light)".into()
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
    let pair_depth = if ss.probe_pair() { opts.pair_depth } else { 0 };
    let cv_depth = if ss.control_variate() && area_lights {
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
    let active: [bool; 3] = std::array::from_fn(|c| ss.params().active(c));
    let any = active.iter().any(|&a| a);
    let lod = ss.lod().decision();
    let every_hit_lod = any && lod.can_trigger && lod.min_width == Some(0.0);
    mp.subsurface = Vec::new();
    if let (true, Some(min_width)) = (any && lod.can_trigger, lod.min_width) {
        mp.subsurface.push(SubsurfaceMethod::LevelOfDetail {
            min_width,
            reason: lod.reason,
        });
    }
    if !every_hit_lod {
        mp.subsurface.push(if any {
            SubsurfaceMethod::Diffusion {
                axes: o.axes.name().into(),
                channel: o.channel.name().into(),
                radius: o.radius.name(),
                pair_depth,
                control_variate_depth: cv_depth,
                curvature_correction: ss.curvature_correction().is_some(),
                reason: diffusion_reason(pair_depth, cv_depth, area_lights, cv_asked),
            }
        } else {
            SubsurfaceMethod::None {
                reason: "A = 0 in every channel: the medium reflects nothing".into(),
            }
        });
    }
    let split = if COAT_SPLIT_DEPTH > 0 {
        format!("both followed at depth < {COAT_SPLIT_DEPTH}, one chosen by Fr deeper")
    } else {
        "one chosen by Fr".to_string()
    };
    mp.coat = Some(match (ss.rough_coat(), ss.specular()) {
        (None, true) => choice(
            "smooth",
            format!(
                "roughness {}: a mirror reflecting Fr, {split}",
                ss.roughness()
            ),
        ),
        (Some(c), true) => choice(
            "rough",
            format!(
                "roughness {}: GGX α = {}, light-sampled at xo, chosen with probability E(μo)",
                ss.roughness(),
                c.ggx.alpha
            ),
        ),
        (_, false) => choice(
            "none",
            "specular = false: reflection not rendered, the medium weighted by 1 − Fr",
        ),
    });
    mp.exit_lobe = Some(match (ss.exit_sw(), ss.rough_coat().is_some()) {
        (true, false) => choice("sw", "exit_sw: the normalized Fresnel lobe Sw at xi"),
        (true, true) => choice("sw-rough", "exit_sw: (1 − E(μi)) / ((1 − Ē) π) at xi"),
        (false, _) => choice("cosine", "exit_sw = false: 1/π at xi"),
    });
    let off: Vec<&str> = (0..3)
        .filter(|&c| !active[c])
        .map(|c| CHANNEL_NAMES[c])
        .collect();
    mp.channels = Some(channels(
        active,
        if off.is_empty() {
            "A > 0 in every channel".to_string()
        } else {
            format!(
                "A = 0 in {}: never sampled, exactly 0, no work",
                off.join(", ")
            )
        },
    ));
    any && !every_hit_lod
}

/// A used subsurface material under the random walk.
#[cfg(feature = "subsurface")]
fn walk_material(ss: &Subsurface, mp: &mut MaterialPlan) {
    let Some(medium) = ss.params().medium else {
        mp.subsurface = vec![SubsurfaceMethod::None {
            reason: "no medium recorded: the path ends there (a black surface)".into(),
        }];
        return;
    };
    mp.subsurface = vec![SubsurfaceMethod::RandomWalk {
        boundary: ss.boundary().name().into(),
        reason: "--integrator randomwalk: the medium simulated event by event".into(),
    }];
    mp.coat = Some(match ss.boundary() {
        WalkBoundary::Dielectric => choice(
            "dielectric",
            "the walk's exact Fresnel boundary replaces the coat (roughness, specular unused)",
        ),
        WalkBoundary::Diffuse { .. } => choice(
            "diffuse-fresnel",
            "Fresnel probabilities, transmission forgets the direction",
        ),
    });
    mp.exit_lobe = Some(match ss.boundary() {
        WalkBoundary::Dielectric => choice("refraction", "leaves along Snell's direction"),
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
