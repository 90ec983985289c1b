//! The render plan for people: one line per effect, in three aligned
//! columns (effect, method, reason), the scene-wide effects first, then
//! each material with what is done there (`lucent render --explain`).

use super::explain::{Explanation, SubsurfaceMethod};

/// Width of the effect column.
const EFFECT: usize = 18;
/// Width of the method column.
const METHOD: usize = 24;

fn row(out: &mut String, effect: &str, method: &str, reason: &str) {
    out.push_str(&format!("  {effect:<EFFECT$}{method:<METHOD$}{reason}\n"));
}

/// The plan as aligned text, ending in a newline.
pub fn render(p: &Explanation) -> String {
    let mut out = format!("render plan (integrator: {})\n", p.integrator);
    let r = &mut out;
    row(
        r,
        "direct lighting",
        &p.direct_lighting.method,
        &p.direct_lighting.reason,
    );
    row(
        r,
        "environment",
        &p.environment.method,
        &p.environment.reason,
    );
    row(r, "indirect", &p.indirect.method, &p.indirect.reason);
    row(
        r,
        "specular chains",
        &p.specular_chains.method,
        &p.specular_chains.reason,
    );
    row(
        r,
        "probe queries",
        &p.probe_queries.method,
        &p.probe_queries.reason,
    );
    row(r, "traversal", &p.traversal.method, &p.traversal.reason);
    row(r, "film", &p.film.method, &p.film.reason);
    if !p.sampler.method.is_empty() {
        row(r, "sampler", &p.sampler.method, &p.sampler.reason);
    }
    let aov_reason = if p.aovs.passes.is_empty() {
        p.aovs.reason.clone()
    } else {
        format!("{}: {}", p.aovs.reason, p.aovs.passes.join(", "))
    };
    row(r, "aovs", &p.aovs.method, &aov_reason);
    for m in &p.materials {
        let users = if m.objects.is_empty() {
            "unused".to_string()
        } else {
            format!("objects: {}", m.objects.join(", "))
        };
        r.push_str(&format!("material {} ({}; {users})\n", m.name, m.kind));
        if !m.textures.is_empty() {
            let which = format!(
                "{} (docs/scene-format.md, \"Textured parameters\")",
                m.textures.join(" ")
            );
            row(r, "textures", "read per hit", &which);
        }
        for s in &m.subsurface {
            match s {
                SubsurfaceMethod::Diffusion {
                    axes,
                    channel,
                    radius,
                    pair_depth,
                    control_variate_depth,
                    curvature_correction,
                    reason,
                } => row(
                    r,
                    "subsurface",
                    "diffusion",
                    &format!(
                        "axes={axes} channel={channel} radius={radius} pair_depth={pair_depth} \
                         control_variate_depth={control_variate_depth} \
                         curvature_correction={}; {reason}",
                        if *curvature_correction { "on" } else { "off" }
                    ),
                ),
                SubsurfaceMethod::RandomWalk { boundary, reason } => row(
                    r,
                    "subsurface",
                    "random walk",
                    &format!("boundary={boundary}; {reason}"),
                ),
                SubsurfaceMethod::None { reason } => row(r, "subsurface", "none", reason),
                SubsurfaceMethod::LevelOfDetail { min_width, reason } => row(
                    r,
                    "subsurface",
                    "level of detail",
                    &format!("footprint ≥ {min_width:e}; {reason}"),
                ),
            }
        }
        #[cfg(feature = "subsurface")]
        if let Some(b) = &m.budget {
            budget_rows(r, b);
        }
        if let Some(c) = &m.coat {
            row(r, "coat", &c.method, &c.reason);
        }
        if let Some(c) = &m.exit_lobe {
            row(r, "exit lobe", &c.method, &c.reason);
        }
        if let Some(c) = &m.channels {
            let on = if c.active.is_empty() {
                "none".to_string()
            } else {
                c.active.join(" ")
            };
            row(r, "channels", &on, &c.reason);
        }
        #[cfg(feature = "subsurface")]
        for o in &m.options {
            let what = crate::materials::estimator_options::option(&o.name)
                .map_or("", |row| row.description);
            row(
                r,
                "option",
                &format!("{}={}", o.name, o.value),
                &format!("{what} (default {})", o.default),
            );
        }
    }
    out
}

/// A material's accuracy budget: the choice and why, then per object its
/// size and each candidate's predicted error and cost.
#[cfg(feature = "subsurface")]
fn budget_rows(r: &mut String, b: &super::budget::BudgetPlan) {
    row(
        r,
        "accuracy budget",
        &b.chosen,
        &format!(
            "budget {:.1} %, {} light; {}",
            100.0 * b.budget,
            b.lighting,
            b.reason
        ),
    );
    for o in &b.objects {
        let c: Vec<String> = o
            .candidates
            .iter()
            .map(|c| format!("{} {:.1} % ×{:.2}", c.estimator, 100.0 * c.error, c.cost))
            .collect();
        let range = match o.candidates.iter().all(|c| c.in_range) {
            true => String::new(),
            false => {
                "; beyond the measured sizes: the largest error measured is predicted".to_string()
            }
        };
        row(
            r,
            "  object",
            &o.object,
            &format!(
                "{}: size {:.3} = {:.2} ℓd; predicted {}{range}{}",
                o.chosen,
                o.size,
                o.size_ld,
                c.join(", "),
                match o.chosen == b.chosen {
                    true => String::new(),
                    false => format!("; {}", o.reason),
                }
            ),
        );
    }
}
