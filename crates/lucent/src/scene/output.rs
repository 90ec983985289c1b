//! What a scene says about its passes: the passes `[output] aovs` asks for,
//! the light group of each emitter and of the environment (`light_group`),
//! and the names of its objects' materials (for material mattes).
//!
//! Every light belongs to exactly one group, so the groups' layers sum to
//! the beauty: lights without a `light_group` are in [`DEFAULT_GROUP`]
//! (Arnold's name for lights outside any group, whose layer is
//! `RGBA_default`).

use std::collections::BTreeSet;

use super::checked::{Cx, Res};
use super::format::{SceneFile, Spanned};
use super::key_path::quoted;
use super::output_file::{output_file, OutputSettings};
use super::Object;
use crate::film::passes::PassSet;

/// The group of lights that name none.
pub const DEFAULT_GROUP: &str = "default";

/// The passes and names a scene gives. `Output::default()` (a scene built
/// in code) asks for no pass, puts every light in [`DEFAULT_GROUP`] and
/// names material `i` `materials[i]`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Output {
    /// The passes `[output] aovs` asks for (the CLI's `--aov` replaces it).
    pub aovs: PassSet,
    /// The light groups, sorted by name; empty means one, [`DEFAULT_GROUP`].
    pub light_groups: Vec<String>,
    /// Per object (by index), its group's index in `light_groups`
    /// (meaningful for emitters; missing entries are group 0).
    pub object_group: Vec<u32>,
    /// The environment's group.
    pub environment_group: u32,
    /// Per light of `[[lights]]` (by index), its group's index in
    /// `light_groups` (missing entries are group 0).
    pub analytic_group: Vec<u32>,
    /// Material names by material index, as the scene file gives them.
    pub material_names: Vec<String>,
    /// How the frame is stored (`[output]`'s storage keys; the CLI's
    /// options override them).
    pub file: OutputSettings,
}

impl Output {
    /// The light groups' names, at least one.
    pub(crate) fn group_names(&self) -> Vec<String> {
        if self.light_groups.is_empty() {
            vec![DEFAULT_GROUP.to_string()]
        } else {
            self.light_groups.clone()
        }
    }

    /// The name of material `i`: the scene's, else `materials[i]`.
    pub(crate) fn material_name(&self, i: usize) -> String {
        self.material_names
            .get(i)
            .cloned()
            .unwrap_or_else(|| format!("materials[{i}]"))
    }
}

/// The longest light group name, in bytes: its channels
/// (`RGBA_<group>.<C>` in the frame, `RGBA_<group>.<C>.w0` in a part) stay
/// within OpenEXR's 255 bytes with room for any channel suffix.
pub const MAX_GROUP_NAME: usize = 200;

/// A light group name: ASCII letters, digits and `_`, as compositors accept
/// in a layer name (`RGBA_<group>`).
fn group_name(cx: &Cx, name: &Spanned<String>, field: &str) -> Res<String> {
    let n = name.get_ref();
    if n.len() > MAX_GROUP_NAME {
        return Err(cx.err(
            name.span(),
            field,
            format!(
                "a light group name of {} bytes: at most {MAX_GROUP_NAME} (it becomes EXR \
                 channel names such as RGBA_<group>.R.w0, which OpenEXR limits to 255 bytes)",
                n.len()
            ),
        ));
    }
    if n.is_empty() || !n.bytes().all(|c| c.is_ascii_alphanumeric() || c == b'_') {
        return Err(cx.err(
            name.span(),
            field,
            format!(
                "expected a light group name of ASCII letters, digits and `_` (it becomes \
                 the layer name RGBA_<group>), found {}",
                quoted(n)
            ),
        ));
    }
    Ok(n.clone())
}

/// `[output]`, the `light_group` keys and the material names of `def`,
/// whose shapes became `objects` (object k from shape `shape_of[k]`), with
/// the names of the materials its MTL files added after its own.
pub(super) fn output(
    cx: &Cx,
    def: &SceneFile,
    objects: &[Object],
    shape_of: &[usize],
    added_materials: Vec<String>,
) -> Res<Output> {
    let aovs = match def.output.aovs.as_ref() {
        Some(names) => {
            PassSet::from_names(names.iter().map(|n| n.get_ref().as_str())).map_err(|e| {
                cx.err(
                    names[e.index].span(),
                    &format!("output.aovs[{}]", e.index),
                    e.problem(),
                )
            })?
        }
        None => PassSet::EMPTY,
    };

    // Each light's group name, checked; then indices into the sorted set.
    let mut shape_groups = Vec::with_capacity(objects.len());
    for (&i, o) in shape_of.iter().zip(objects) {
        let s = &def.shapes[i];
        let field = format!("shapes[{i}].light_group");
        let g = match &s.get_ref().light_group {
            Some(g) if o.emission.is_none() => {
                return Err(cx.err(
                    g.span(),
                    &field,
                    "a light group is for emitters, and this shape emits nothing (no \
                     `emission`, or [0, 0, 0])",
                ))
            }
            Some(g) => Some(group_name(cx, g, &field)?),
            None => o.emission.map(|_| DEFAULT_GROUP.to_string()),
        };
        shape_groups.push(g);
    }
    let env_group = match &def.environment {
        Some(env) => match &env.get_ref().light_group {
            Some(g) => Some(group_name(cx, g, "environment.light_group")?),
            None => Some(DEFAULT_GROUP.to_string()),
        },
        None => None,
    };
    let mut light_def_groups = Vec::with_capacity(def.lights.len());
    for (i, l) in def.lights.iter().enumerate() {
        let g = match &l.get_ref().light_group {
            Some(g) => group_name(cx, g, &format!("lights[{i}].light_group"))?,
            None => DEFAULT_GROUP.to_string(),
        };
        light_def_groups.push(Some(g));
    }
    let names: BTreeSet<&String> = (shape_groups.iter().chain([&env_group]))
        .chain(&light_def_groups)
        .flatten()
        .collect();
    let light_groups: Vec<String> = names.into_iter().cloned().collect();
    let index = |g: &Option<String>| {
        g.as_ref()
            .and_then(|g| light_groups.iter().position(|n| n == g))
            .unwrap_or(0) as u32
    };
    Ok(Output {
        aovs,
        object_group: shape_groups.iter().map(index).collect(),
        environment_group: index(&env_group),
        analytic_group: light_def_groups.iter().map(index).collect(),
        light_groups: light_groups.clone(),
        material_names: def
            .materials
            .keys()
            .cloned()
            .chain(added_materials)
            .collect(),
        file: output_file(cx, &def.output)?,
    })
}
