//! Which layers a set of passes makes and where each pixel keeps their
//! sums: the stride of i128 sums a pixel, each summed layer's offset in
//! it, and the names (light groups, matted objects and materials) the
//! passes use. What each pass keeps is tabled in docs/farm.md, "Passes in
//! parts".

use super::accumulate::FixedPoint;
use super::layers::LayerKind;
use super::passes::{Pass, PassSet, LIGHT_PATHS};
use super::variance::{SQUARE_BITS, SQUARE_WORDS};

/// One output layer: what it holds and, for summed layers, where its sums
/// sit in a pixel's stride.
#[derive(Clone, Debug, PartialEq)]
pub struct Slot {
    pub pass: Pass,
    /// For [`Pass::LightGroups`]: the group.
    pub group: usize,
    pub name: String,
    pub channels: &'static [&'static str],
    pub kind: LayerKind,
    /// First i128 of its sums in the pixel's stride (summed layers and
    /// the variance's squares).
    pub offset: usize,
}

/// The layers a set of passes makes, in output order, what each pixel
/// sums for them, and the names they need (light groups, matted objects
/// and materials). A function of the pass set and the scene's names alone,
/// so a merge rebuilds it from a part's header.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    pub passes: PassSet,
    pub groups: Vec<String>,
    pub object_names: Vec<String>,
    pub material_names: Vec<String>,
    slots: Vec<Slot>,
    /// i128 sums per pixel.
    stride: usize,
}

const RGB: &[&str] = &["R", "G", "B"];
/// A light group's channels: its light, and the frame's alpha (the
/// compositing convention for `RGBA_<group>` layers; not summed).
const RGBA: &[&str] = &["R", "G", "B", "A"];
const XYZ: &[&str] = &["X", "Y", "Z"];

/// A layer of summed channels, as a part lists it: name, channels, and
/// the fixed-point fraction bits of their sums.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct SumLayer {
    pub name: String,
    pub channels: Vec<String>,
    pub frac_bits: u32,
}

impl Layout {
    /// The layout of `passes` with these names (light groups, object names,
    /// material names; unused ones are dropped, so the layout says only
    /// what the passes need).
    pub fn new(
        passes: PassSet,
        groups: &[String],
        object_names: &[String],
        material_names: &[String],
    ) -> Layout {
        let mut slots = Vec::new();
        let mut offset = 0;
        let mut add = |pass, group, name: String, channels: &'static [&'static str], kind| {
            let sums = match pass {
                Pass::Variance => channels.len() * SQUARE_WORDS,
                p if LIGHT_PATHS.contains(&p) => channels.len(),
                Pass::LightGroups | Pass::Albedo | Pass::Normal => 3,
                _ => 0,
            };
            slots.push(Slot {
                pass,
                group,
                name,
                channels,
                kind,
                offset,
            });
            offset += sums;
        };
        for pass in passes.iter() {
            use LayerKind::{Data, Id, Light};
            let name = pass.name().to_string();
            match pass {
                Pass::LightGroups => {
                    for (g, group) in groups.iter().enumerate() {
                        add(pass, g, format!("RGBA_{group}"), RGBA, Light);
                    }
                }
                p if LIGHT_PATHS.contains(&p) => add(p, 0, name, RGB, Light),
                Pass::Albedo | Pass::Variance => add(pass, 0, name, RGB, Data),
                Pass::Normal | Pass::Position => add(pass, 0, name, XYZ, Data),
                Pass::Depth => add(pass, 0, name, &["Z"], Data),
                Pass::SampleCount => add(pass, 0, name, &["count"], Data),
                Pass::ObjectId | Pass::MaterialId => add(pass, 0, name, &["id"], Id),
                // Coverage, not layers.
                _ => {}
            }
        }
        let keep = |p: Pass, names: &[String]| {
            if passes.contains(p) {
                names.to_vec()
            } else {
                Vec::new()
            }
        };
        Layout {
            passes,
            groups: keep(Pass::LightGroups, groups),
            object_names: keep(Pass::CryptoObject, object_names),
            material_names: keep(Pass::CryptoMaterial, material_names),
            slots,
            stride: offset,
        }
    }

    /// The layers, in output order.
    pub fn slots(&self) -> &[Slot] {
        &self.slots
    }

    /// i128 sums per pixel.
    pub fn stride(&self) -> usize {
        self.stride
    }

    /// Whether the nearest camera hit is kept (P, Z, IDs).
    pub fn nearest(&self) -> bool {
        [
            Pass::Position,
            Pass::Depth,
            Pass::ObjectId,
            Pass::MaterialId,
        ]
        .iter()
        .any(|p| self.passes.contains(*p))
    }

    /// The summed layers, in stride order (a part's `lucent.layers` after
    /// the beauty).
    pub(crate) fn sum_layers(&self) -> Vec<SumLayer> {
        let mut v = Vec::new();
        for s in &self.slots {
            match s.pass {
                Pass::Variance => v.push(SumLayer {
                    name: "variance.sq".into(),
                    channels: s
                        .channels
                        .iter()
                        .flat_map(|c| (0..SQUARE_WORDS).map(move |k| format!("{c}{k}")))
                        .collect(),
                    frac_bits: SQUARE_BITS,
                }),
                p if p == Pass::LightGroups
                    || p == Pass::Albedo
                    || p == Pass::Normal
                    || LIGHT_PATHS.contains(&p) =>
                {
                    v.push(SumLayer {
                        name: s.name.clone(),
                        // a light group's A is the frame's, not a sum
                        channels: RGB.iter().map(|c| c.to_string()).collect(),
                        frac_bits: FixedPoint::RADIANCE.frac_bits,
                    })
                }
                _ => {}
            }
        }
        v
    }
}
