//! Named metals: complex indices of refraction η + ik at the red, green
//! and blue primaries, for the conductor material (`docs/scene-format.md`,
//! "conductor").
//!
//! Gold, silver, copper and aluminium are the spectral data pbrt-v3 ships
//! (Palik, *Handbook of Optical Constants of Solids*, 1985), integrated
//! against the linear-sRGB primaries as tabulated by the Tungsten renderer
//! (`src/core/bsdfs/ComplexIorData.hpp`, entries Au, Ag, Cu, Al). Iron is
//! Johnson & Christy (Phys. Rev. B 9, 1974) sampled at 650, 550 and 450 nm
//! (refractiveindex.info, "Fe"): point samples, not integrals.

use crate::geometry::Vec3;

/// A metal's complex index of refraction per RGB channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metal {
    pub name: &'static str,
    pub eta: [f32; 3],
    pub k: [f32; 3],
}

impl Metal {
    pub fn eta(&self) -> Vec3 {
        Vec3::from_array(self.eta)
    }
    pub fn k(&self) -> Vec3 {
        Vec3::from_array(self.k)
    }
}

/// The metals a scene can name.
pub const METALS: [Metal; 5] = [
    Metal {
        name: "gold",
        eta: [0.143_119, 0.374_957, 1.442_479],
        k: [3.983_16, 2.385_721, 1.603_215],
    },
    Metal {
        name: "silver",
        eta: [0.155_265, 0.116_723, 0.138_381],
        k: [4.828_343, 3.122_246, 2.146_95],
    },
    Metal {
        name: "copper",
        eta: [0.200_438, 0.924_033, 1.102_212],
        k: [3.912_949, 2.452_848, 2.142_188],
    },
    Metal {
        name: "aluminium",
        eta: [1.657_46, 0.880_369, 0.521_229],
        k: [9.223_869, 6.269_523, 4.837_001],
    },
    Metal {
        name: "iron",
        eta: [2.9114, 2.9497, 2.5845],
        k: [3.0893, 2.9318, 2.7670],
    },
];

/// The metal called `name`.
pub fn metal(name: &str) -> Option<&'static Metal> {
    METALS.iter().find(|m| m.name == name)
}

/// The names, for messages.
pub fn names() -> String {
    METALS.map(|m| format!("\"{}\"", m.name)).join(", ")
}
