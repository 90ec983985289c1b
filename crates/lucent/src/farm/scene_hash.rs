//! The scene's content hash that parts carry: which scene they are of,
//! whatever its file is called or where it lies.
//!
//! It hashes the scene file's bytes, every mesh as loaded (vertex
//! positions, shading normals, triangles and, where a material reads a
//! texture, texture coordinates, as the bits of their f32 and u32 values)
//! and the texels of its textures, so an edited scene file, a changed OBJ
//! or texture gives another hash, and the same files copied to another machine give the same one.
//! It is 64 bits of a non-cryptographic mix (the SplitMix64 finalizer,
//! Steele et al. 2014, applied to each 64-bit word of the input): it
//! catches mistakes — a part of last week's scene — not forgeries. A
//! comment edited in the scene file changes it too: the check errs on the
//! side of refusing.

use crate::scene::Scene;

/// The SplitMix64 finalizer: a bijection of 64-bit words with full
/// avalanche.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58476d1ce4e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d049bb133111eb);
    z ^ (z >> 31)
}

/// A streaming hash over 64-bit words (bytes are packed little-endian,
/// each stream's length is folded in).
struct Hasher(u64);

impl Hasher {
    fn word(&mut self, w: u64) {
        self.0 = mix(self.0 ^ mix(w)).wrapping_add(0x9e3779b97f4a7c15);
    }
    fn bytes(&mut self, b: &[u8]) {
        self.word(b.len() as u64);
        for c in b.chunks(8) {
            let mut w = [0u8; 8];
            w[..c.len()].copy_from_slice(c);
            self.word(u64::from_le_bytes(w));
        }
    }
    fn u32s(&mut self, v: impl ExactSizeIterator<Item = u32>) {
        self.word(v.len() as u64);
        for x in v {
            self.word(x as u64);
        }
    }
}

/// The content hash of a scene loaded from `file_bytes`, as 16 hex digits.
pub fn scene_hash(file_bytes: &[u8], scene: &Scene) -> String {
    let mut h = Hasher(0x6c7563656e74); // "lucent"
    h.bytes(file_bytes);
    h.word(scene.meshes.len() as u64);
    for m in scene.meshes.iter() {
        let p = m.positions();
        h.u32s(
            p.iter()
                .flat_map(|v| [v.x, v.y, v.z])
                .map(f32::to_bits)
                .collect::<Vec<_>>()
                .into_iter(),
        );
        h.u32s(
            m.indices
                .iter()
                .flatten()
                .copied()
                .collect::<Vec<_>>()
                .into_iter(),
        );
        match &m.normals {
            Some(n) => h.u32s(
                n.iter()
                    .flat_map(|v| [v.x, v.y, v.z])
                    .map(f32::to_bits)
                    .collect::<Vec<_>>()
                    .into_iter(),
            ),
            None => h.word(u64::MAX),
        }
        // texture coordinates and textures only where a material reads
        // them: other scenes keep their hash
        if let Some(uv) = &m.uvs {
            let bits = uv
                .iter()
                .flatten()
                .flat_map(|t| [t.x, t.y])
                .map(f32::to_bits);
            h.u32s(bits.collect::<Vec<_>>().into_iter());
        }
    }
    for t in scene.textures() {
        h.u32s(t.texel_bits());
    }
    format!("{:016x}", h.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    const SCENE: &str = "[camera]\nlook_from = [0, 0, 3]\nlook_at = [0, 0, 0]\n\
        resolution = [8, 8]\n[materials.w]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\
        [[shapes]]\ntype = \"sphere\"\nmaterial = \"w\"\n";

    #[test]
    fn the_hash_follows_the_content_not_the_path() {
        let load = |text: &str, path: &str| {
            let s = crate::scene::load::load_str(text, Path::new(path)).unwrap();
            scene_hash(text.as_bytes(), &s)
        };
        let a = load(SCENE, "a.toml");
        assert_eq!(a.len(), 16);
        assert_eq!(a, load(SCENE, "elsewhere/b.toml"));
        // another sphere radius: another mesh and another text
        let moved = SCENE.replace("\"sphere\"\n", "\"sphere\"\nscale = 0.5\n");
        assert_ne!(a, load(&moved, "a.toml"));
        // the same meshes under another text (a comment) still differ
        assert_ne!(a, load(&format!("# note\n{SCENE}"), "a.toml"));
        // the meshes count, not only the text: same text, edited mesh
        let s = crate::scene::load::load_str(SCENE, Path::new("a.toml")).unwrap();
        let mut t = s.clone();
        let mut meshes = (*t.meshes).clone();
        meshes[0].indices[0].swap(0, 1);
        t.meshes = std::sync::Arc::new(meshes);
        assert_ne!(
            scene_hash(SCENE.as_bytes(), &s),
            scene_hash(SCENE.as_bytes(), &t)
        );
    }

    #[test]
    fn a_changed_texture_changes_the_hash() {
        let dir = tempfile::tempdir().unwrap();
        let text = SCENE.replace(
            "albedo = [0.5, 0.5, 0.5]",
            "albedo_texture = \"t\"\n[textures.t]\nfile = \"t.png\"",
        );
        let hash = |v: u8| {
            image::RgbImage::from_pixel(2, 2, image::Rgb([v, v, v]))
                .save(dir.path().join("t.png"))
                .unwrap();
            let s = crate::scene::load::load_str(&text, &dir.path().join("s.toml")).unwrap();
            scene_hash(text.as_bytes(), &s)
        };
        assert_eq!(hash(10), hash(10));
        assert_ne!(hash(10), hash(20));
    }
}
