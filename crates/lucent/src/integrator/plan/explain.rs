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

use serde::{Deserialize, Serialize};

use super::choice::choice;
use super::materials::material_rows;
use super::{emits, Plan};
use crate::accel::Traversal;
use crate::integrator::path::RR_START;
use crate::integrator::IntegratorKind;
use crate::scene::Scene;

pub use super::choice::Choice;
pub use super::materials::{Channels, MaterialPlan, OptionSetting, SubsurfaceMethod};
pub use super::options::PlanOptions;

/// The version of the JSON schema.
pub const SCHEMA: u32 = 1;
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
    /// What alpha holds and whether camera rays see the environment;
    /// absent in plans written before it.
    #[serde(default)]
    pub film: Choice,
    /// Where the samples' numbers come from
    /// ([`crate::sampling::SamplerKind`]); absent in plans written before it.
    #[serde(default)]
    pub sampler: Choice,
    pub aovs: Aovs,
    pub materials: Vec<MaterialPlan>,
}

impl Explanation {
    /// The plan of `scene` rendered with `opts`.
    pub fn new(scene: &Scene, opts: &PlanOptions) -> Self {
        let flags = Plan::new(scene);
        let rows = material_rows(scene, opts, flags.area_lights);
        Explanation {
            schema: SCHEMA,
            integrator: integrator_name(opts.integrator).into(),
            direct_lighting: direct_lighting(scene, &flags),
            environment: environment(scene, &flags),
            indirect: indirect(scene.settings.max_depth),
            specular_chains: specular_chains(rows.specular_materials, &rows.specular_why),
            probe_queries: probe_queries(opts, &rows.probes_needed),
            traversal: traversal(scene, opts),
            film: film(&flags),
            sampler: sampler(scene, opts),
            aovs: aovs(opts),
            materials: rows.materials,
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

/// The integrator's name in the plan.
fn integrator_name(kind: IntegratorKind) -> &'static str {
    match kind {
        IntegratorKind::Path => "path",
        #[cfg(feature = "subsurface")]
        IntegratorKind::RandomWalk => "randomwalk",
    }
}

/// Direct light: next-event estimation when some object emits.
fn direct_lighting(scene: &Scene, flags: &Plan) -> Choice {
    let lights: Vec<&str> = scene
        .objects
        .iter()
        .filter(|o| emits(o.emission))
        .map(|o| o.name.as_str())
        .collect();
    let mut c = if flags.area_lights {
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
    if flags.analytic_lights {
        let reason = analytic_lights(scene);
        c = if flags.area_lights {
            choice(&c.method, format!("{}; {reason}", c.reason))
        } else {
            choice("next-event estimation", reason)
        };
    }
    c
}

/// What is done for the `[[lights]]`.
fn analytic_lights(scene: &Scene) -> String {
    let kinds: Vec<String> = scene
        .lights
        .iter()
        .enumerate()
        .map(|(i, l)| format!("lights[{i}] {}", l.kind()))
        .collect();
    format!(
        "{} light(s) of [[lights]] ({}): one picked uniformly, a direction sampled in the \
         cone it subtends and a shadow ray per non-specular vertex (subsurface entry points \
         and coats included), MIS with lobe sampling; rays crossing a sphere or spot light \
         and rays escaping inside a distant light's cone find its light (a distant light of \
         angle 0 is a delta, only sampled)",
        kinds.len(),
        kinds.join(", ")
    )
}

/// The environment: escaping rays where it is not black.
fn environment(scene: &Scene, flags: &Plan) -> Choice {
    use crate::environment::Environment;
    match &scene.environment {
        Some(Environment::Constant(e)) if flags.environment => choice(
            "escaping rays",
            format!(
                "constant radiance ({}, {}, {}) added where a path escapes; not \
                 light-sampled",
                e.x, e.y, e.z
            ),
        ),
        Some(Environment::Map(m)) if flags.environment => choice(
            "next-event estimation",
            format!(
                "{}×{} image: one direction sampled by luminance × sin θ and a shadow ray \
                 per non-specular vertex, MIS with lobe sampling and with escaping rays",
                m.width(),
                m.height()
            ),
        ),
        _ => choice("none", "no environment (or black): escaping paths end"),
    }
}

/// The film: opaque, or transparent with alpha the coverage of camera
/// rays (docs/output.md, "Transparent film").
fn film(flags: &Plan) -> Choice {
    match flags.transparent {
        true => choice(
            "transparent",
            "alpha = the fraction of each pixel's camera rays that hit something; the \
             environment and distant lights seen directly are left out, so the beauty \
             composites with \"over\"",
        ),
        false => choice(
            "opaque",
            "alpha 1: the environment seen directly is part of the beauty",
        ),
    }
}

/// Indirect light: lobe sampling up to `max_depth` bounces.
fn indirect(max_depth: u32) -> Indirect {
    Indirect {
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
    }
}

/// Specular chains: followed where some used material makes them.
fn specular_chains(specular_materials: Vec<String>, specular_why: &[String]) -> Specular {
    Specular {
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
    }
}

/// Probe queries: on where some material casts probes under diffusion.
#[cfg_attr(not(feature = "subsurface"), allow(unused_variables))]
fn probe_queries(opts: &PlanOptions, probes_needed: &[String]) -> Choice {
    #[cfg(feature = "subsurface")]
    let walk_off = opts.integrator == IntegratorKind::RandomWalk;
    #[cfg(not(feature = "subsurface"))]
    let walk_off = false;
    if walk_off {
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
    }
}

/// Where the samples' numbers come from.
fn sampler(scene: &Scene, opts: &PlanOptions) -> Choice {
    let k = opts.sampler.unwrap_or(scene.settings.sampler);
    choice(k.name(), k.describe())
}

/// How Embree treats rays through shared edges.
fn traversal(scene: &Scene, opts: &PlanOptions) -> Choice {
    let asked = scene.settings.traversal;
    match (asked, opts.integrator.traversal(asked)) {
        (Traversal::Fast, Traversal::Watertight) => choice(
            "watertight",
            "random-walk integrator: no walk may slip out of a closed medium through \
             an edge that triangles share",
        ),
        (_, Traversal::Watertight) if budget_walks(scene) => choice(
            "watertight",
            "an accuracy budget chose the random walk for some object: no walk may slip \
             out of a closed medium through an edge that triangles share",
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
    }
}

/// Whether an accuracy budget gave some object the random walk (which
/// then made the traversal watertight, [`super::budget::resolve`]).
fn budget_walks(scene: &Scene) -> bool {
    Plan::new(scene).walks
}

/// The passes recorded besides the beauty.
fn aovs(opts: &PlanOptions) -> Aovs {
    let passes: Vec<String> = opts.passes.iter().map(|p| p.name().to_string()).collect();
    Aovs {
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
    }
}
