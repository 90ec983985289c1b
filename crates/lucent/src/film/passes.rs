//! Which passes (AOVs, arbitrary output variables) a render computes besides
//! the beauty image, by name: the set `--aov LIST` and `[output] aovs` ask
//! for.
//!
//! Names follow the built-in AOVs of Arnold (Autodesk's production
//! renderer), which compositing templates and the examples use:
//! the light paths `emission`, `background`, `diffuse_direct`,
//! `diffuse_indirect`, `specular_direct`, `specular_indirect`,
//! `transmission`, `sss_direct`, `sss_indirect`; light groups as
//! `RGBA_<group>`; the data passes `albedo`, `N`, `P`, `Z`; the ID mattes
//! `crypto_object`, `crypto_material`. Passes Arnold has no built-in name
//! for keep its lowercase style: `object_id`, `material_id`,
//! `sample_count`, `variance`. What each pass holds: `docs/output.md`,
//! "Passes".
//!
//! Besides single names a list may hold groups: `lightpaths` (the nine
//! light paths, which sum to the beauty), `lightgroups` (one layer per
//! light group, which also sum to the beauty), `data`, `ids`, `noise`,
//! `cryptomatte`, and `all`. Names are case-sensitive (`N`, `P`, `Z` as
//! Arnold writes them); an unknown name is bad input.

/// One pass (or, for [`Pass::LightGroups`], one family of layers).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Pass {
    // Light paths, in the order [`LIGHT_PATHS`] lists them.
    Emission,
    Background,
    DiffuseDirect,
    DiffuseIndirect,
    SpecularDirect,
    SpecularIndirect,
    Transmission,
    SssDirect,
    SssIndirect,
    /// One RGB layer per light group.
    LightGroups,
    // Data.
    Albedo,
    Normal,
    Position,
    Depth,
    ObjectId,
    MaterialId,
    // ID coverage for mattes.
    CryptoObject,
    CryptoMaterial,
    // Noise.
    SampleCount,
    Variance,
}

/// The light paths, which partition the beauty: every sample's radiance is
/// the sum of its parts in these passes.
pub const LIGHT_PATHS: [Pass; 9] = [
    Pass::Emission,
    Pass::Background,
    Pass::DiffuseDirect,
    Pass::DiffuseIndirect,
    Pass::SpecularDirect,
    Pass::SpecularIndirect,
    Pass::Transmission,
    Pass::SssDirect,
    Pass::SssIndirect,
];

/// Every pass, in the order a render outputs them.
pub const ALL: [Pass; 20] = [
    Pass::Emission,
    Pass::Background,
    Pass::DiffuseDirect,
    Pass::DiffuseIndirect,
    Pass::SpecularDirect,
    Pass::SpecularIndirect,
    Pass::Transmission,
    Pass::SssDirect,
    Pass::SssIndirect,
    Pass::LightGroups,
    Pass::Albedo,
    Pass::Normal,
    Pass::Position,
    Pass::Depth,
    Pass::ObjectId,
    Pass::MaterialId,
    Pass::CryptoObject,
    Pass::CryptoMaterial,
    Pass::SampleCount,
    Pass::Variance,
];

/// The names of groups of passes, with their members.
const GROUPS: [(&str, &[Pass]); 7] = [
    ("all", &ALL),
    ("lightpaths", &LIGHT_PATHS),
    ("lightgroups", &[Pass::LightGroups]),
    (
        "data",
        &[Pass::Albedo, Pass::Normal, Pass::Position, Pass::Depth],
    ),
    ("ids", &[Pass::ObjectId, Pass::MaterialId]),
    ("cryptomatte", &[Pass::CryptoObject, Pass::CryptoMaterial]),
    ("noise", &[Pass::SampleCount, Pass::Variance]),
];

impl Pass {
    /// The pass's name (for light groups: the name that selects them; each
    /// layer is `RGBA_<group>`).
    pub fn name(self) -> &'static str {
        match self {
            Pass::Emission => "emission",
            Pass::Background => "background",
            Pass::DiffuseDirect => "diffuse_direct",
            Pass::DiffuseIndirect => "diffuse_indirect",
            Pass::SpecularDirect => "specular_direct",
            Pass::SpecularIndirect => "specular_indirect",
            Pass::Transmission => "transmission",
            Pass::SssDirect => "sss_direct",
            Pass::SssIndirect => "sss_indirect",
            Pass::LightGroups => "lightgroups",
            Pass::Albedo => "albedo",
            Pass::Normal => "N",
            Pass::Position => "P",
            Pass::Depth => "Z",
            Pass::ObjectId => "object_id",
            Pass::MaterialId => "material_id",
            Pass::CryptoObject => "crypto_object",
            Pass::CryptoMaterial => "crypto_material",
            Pass::SampleCount => "sample_count",
            Pass::Variance => "variance",
        }
    }

    /// The pass named `name`, if one is.
    pub(crate) fn from_name(name: &str) -> Option<Pass> {
        ALL.into_iter().find(|p| p.name() == name)
    }

    fn bit(self) -> u32 {
        1 << self as u32
    }
}

/// A set of passes (empty: the beauty alone, and the render pays nothing
/// for passes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct PassSet(u32);

impl PassSet {
    pub const EMPTY: PassSet = PassSet(0);

    /// Every pass.
    pub fn all() -> PassSet {
        ALL.into_iter().collect()
    }

    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    pub fn contains(self, p: Pass) -> bool {
        self.0 & p.bit() != 0
    }

    pub fn insert(&mut self, p: Pass) {
        self.0 |= p.bit();
    }

    /// The union of both sets.
    pub(crate) fn union(self, o: PassSet) -> PassSet {
        PassSet(self.0 | o.0)
    }

    /// The members, in output order.
    pub fn iter(self) -> impl Iterator<Item = Pass> {
        ALL.into_iter().filter(move |p| self.contains(*p))
    }

    /// Whether any light path is in the set.
    pub fn any_light_path(self) -> bool {
        LIGHT_PATHS.iter().any(|p| self.contains(*p))
    }

    /// The passes one name selects: a pass, or a group of them; None for a
    /// name that is neither.
    pub fn named(name: &str) -> Option<PassSet> {
        if let Some(p) = Pass::from_name(name) {
            return Some([p].into_iter().collect());
        }
        GROUPS
            .iter()
            .find(|(g, _)| *g == name)
            .map(|(_, ps)| ps.iter().copied().collect())
    }

    /// The union of the passes `names` select; the first name that selects
    /// none is the error, with its index.
    pub(crate) fn from_names<'a>(
        names: impl IntoIterator<Item = &'a str>,
    ) -> Result<PassSet, UnknownPass> {
        let mut set = PassSet::EMPTY;
        for (index, name) in names.into_iter().enumerate() {
            match PassSet::named(name) {
                Some(s) => set = set.union(s),
                None => {
                    return Err(UnknownPass {
                        index,
                        name: name.to_string(),
                    })
                }
            }
        }
        Ok(set)
    }

    /// A comma-separated list (`--aov diffuse_direct,Z`; spaces around the
    /// names are ignored, an empty entry is an unknown name).
    pub fn parse_list(list: &str) -> Result<PassSet, UnknownPass> {
        PassSet::from_names(list.split(',').map(str::trim))
    }
}

impl FromIterator<Pass> for PassSet {
    fn from_iter<I: IntoIterator<Item = Pass>>(it: I) -> Self {
        let mut s = PassSet::EMPTY;
        for p in it {
            s.insert(p);
        }
        s
    }
}

/// A name that selects no pass: its position in the list and the name.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownPass {
    pub index: usize,
    pub name: String,
}

impl UnknownPass {
    /// "unknown pass "x" (passes: …; groups: …)", for messages.
    pub fn problem(&self) -> String {
        let passes: Vec<&str> = ALL
            .iter()
            .filter(|p| **p != Pass::LightGroups)
            .map(|p| p.name())
            .collect();
        let groups: Vec<&str> = GROUPS.iter().map(|(g, _)| *g).collect();
        format!(
            "unknown pass {:?} (passes: {}; groups: {})",
            self.name,
            passes.join(", "),
            groups.join(", ")
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_pass_is_found_by_its_name_and_names_are_unique() {
        for p in ALL {
            assert_eq!(Pass::from_name(p.name()), Some(p));
        }
        let mut names: Vec<&str> = ALL.iter().map(|p| p.name()).collect();
        names.extend(
            GROUPS
                .iter()
                .map(|(g, _)| *g)
                .filter(|g| *g != "lightgroups"),
        );
        let n = names.len();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), n, "a name is used twice");
        // ALL is in enum order (the output order), with each pass once.
        for (i, p) in ALL.iter().enumerate() {
            assert_eq!(*p as usize, i);
        }
    }

    #[test]
    fn lists_parse_into_sets_and_unknown_names_are_reported_with_their_index() {
        let s = PassSet::parse_list("diffuse_direct, Z,lightgroups").unwrap();
        assert_eq!(
            s.iter().collect::<Vec<_>>(),
            [Pass::DiffuseDirect, Pass::LightGroups, Pass::Depth]
        );
        assert_eq!(PassSet::parse_list("all").unwrap(), PassSet::all());
        assert_eq!(PassSet::all().iter().count(), ALL.len());
        let lp = PassSet::parse_list("lightpaths").unwrap();
        assert_eq!(lp.iter().collect::<Vec<_>>(), LIGHT_PATHS);
        assert!(lp.any_light_path() && !PassSet::named("Z").unwrap().any_light_path());
        let e = PassSet::parse_list("Z,z").unwrap_err();
        assert_eq!((e.index, e.name.as_str()), (1, "z"));
        assert!(
            e.problem().contains("unknown pass \"z\""),
            "{}",
            e.problem()
        );
        assert_eq!(PassSet::parse_list("Z,,N").unwrap_err().index, 1);
        assert!(PassSet::EMPTY.is_empty() && !s.is_empty());
    }
}
