use super::*;

fn image(w: u32, h: u32, f: impl Fn(u32, u32) -> Vec3) -> Vec<Vec3> {
    (0..h)
        .flat_map(|j| (0..w).map(move |i| (i, j)))
        .map(|(i, j)| f(i, j))
        .collect()
}

#[test]
fn a_constant_image_reads_back_its_value_bit_for_bit_everywhere() {
    let c = Vec3::new(0.215_860_5, 0.7, 1.0 / 3.0);
    let t = Texture::new(37, 20, vec![c; 37 * 20], Wrap::Repeat);
    assert_eq!(t.level_count(), 6); // 37×20, 18×10, 9×5, 4×2, 2×1, 1×1
    for (u, v, w) in [
        (0.3, 0.9, 0.0),
        (-2.7, 5.1, 0.013),
        (0.999, 0.001, 0.4),
        (0.5, 0.5, 9.0),
    ] {
        assert_eq!(t.lookup(Vec2::new(u, v), w), c, "at ({u}, {v}), width {w}");
    }
}

#[test]
fn the_level_is_log2_of_the_footprint_in_texels() {
    let t = Texture::new(256, 128, vec![Vec3::ONE; 256 * 128], Wrap::Clamp);
    assert_eq!(t.level_count(), 9);
    // one texel or less: the full-resolution level
    assert_eq!(t.level_for(0.0), 0.0);
    assert_eq!(t.level_for(0.5 / 256.0), 0.0);
    assert_eq!(t.level_for(1.0 / 256.0), 0.0);
    // 4 texels wide: level 2, where one texel is 4 wide
    assert_eq!(t.level_for(4.0 / 256.0), 2.0);
    assert!((t.level_for(6.0 / 256.0) - 6f32.log2()).abs() < 1e-6);
    // the whole texture and beyond: the last level
    assert_eq!(t.level_for(1.0), 8.0);
    assert_eq!(t.level_for(1e9), 8.0);
}

#[test]
fn a_marker_texel_is_read_at_its_centre_and_blurred_by_wide_footprints() {
    // 8×8 black, texel (column 5, row 2) white: its centre is at
    // u = 5.5/8, v = 1 − 2.5/8
    let t = Texture::new(
        8,
        8,
        image(8, 8, |i, j| {
            if (i, j) == (5, 2) {
                Vec3::ONE
            } else {
                Vec3::ZERO
            }
        }),
        Wrap::Repeat,
    );
    let centre = Vec2::new(5.5 / 8.0, 1.0 - 2.5 / 8.0);
    assert_eq!(t.lookup(centre, 0.0), Vec3::ONE);
    assert_eq!(t.lookup(Vec2::new(1.5 / 8.0, 0.5), 0.0), Vec3::ZERO);
    // halfway to the next texel: half
    let half = t.lookup(centre + Vec2::new(0.5 / 8.0, 0.0), 0.0);
    assert_eq!(half, Vec3::splat(0.5));
    // the 2×2 level holds the 4×4 blocks' means: 1/16 in the marker's,
    // read at that texel's centre
    assert_eq!(
        t.bilinear(2, Vec2::new(0.75, 0.75)),
        Vec3::splat(1.0 / 16.0)
    );
    assert_eq!(t.bilinear(2, Vec2::new(0.25, 0.25)), Vec3::ZERO);
    // the 1×1 level the image's mean
    assert_eq!(t.lookup(centre, 1.0), Vec3::splat(1.0 / 64.0));
}

#[test]
fn wrap_modes_tile_or_extend_the_edges() {
    let row = image(4, 1, |i, _| Vec3::splat(i as f32));
    let rep = Texture::new(4, 1, row.clone(), Wrap::Repeat);
    let clamp = Texture::new(4, 1, row, Wrap::Clamp);
    // beyond the right edge: repeat reads column 0 again, clamp column 3
    let u = Vec2::new(1.0 + 0.5 / 4.0, 0.5);
    assert_eq!(rep.bilinear(0, u), Vec3::ZERO);
    assert_eq!(clamp.bilinear(0, u), Vec3::splat(3.0));
    // on the seam repeat blends the last and first columns
    assert_eq!(rep.bilinear(0, Vec2::new(0.0, 0.5)), Vec3::splat(1.5));
    assert_eq!(clamp.bilinear(0, Vec2::new(0.0, 0.5)), Vec3::ZERO);
}
