//! Where a frame came from, beyond its settings: the lucent build, the
//! machine, the date and the camera's matrices (docs/output.md, "Header
//! attributes"), and the warning when `--accel embree` cannot use the
//! Embree 4 that `LUCENT_EMBREE4` names.

use crate::accel::Backend;
use crate::scene::Camera;

/// This build of lucent: version, git commit (with a hash of uncommitted
/// changes, so two development builds of one commit differ) and profile,
/// as the build script found them.
pub fn build_id() -> &'static str {
    env!("LUCENT_BUILD_ID")
}

/// This machine's name (the kernel's host name), or `unknown`.
pub fn host_name() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .map(|h| h.trim().to_string())
        .filter(|h| !h.is_empty())
        .unwrap_or_else(|| "unknown".into())
}

/// Now, UTC, as OpenEXR's `capDate` says a date: `YYYY:MM:DD hh:mm:ss`.
pub fn date_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    cap_date(secs)
}

/// The `capDate` of `secs` seconds after 1970-01-01 00:00:00 UTC (the
/// proleptic Gregorian calendar; Hinnant's days-to-civil).
fn cap_date(secs: u64) -> String {
    let (days, rem) = ((secs / 86_400) as i64, secs % 86_400);
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    let (hh, mm, ss) = (rem / 3600, rem / 60 % 60, rem % 60);
    format!("{y:04}:{m:02}:{d:02} {hh:02}:{mm:02}:{ss:02}")
}

/// The camera's OpenEXR `worldToCamera` and `worldToNDC` matrices (row
/// vector × matrix, row-major). Camera space: origin at the eye, +x right,
/// +y up, +z the view direction (left-handed, as the standard says). NDC:
/// (x/w, y/w) is (0, 0) at the display window's top-left corner and
/// (1, 1) at its bottom-right; w and z are the camera-space depth.
pub fn camera_matrices(c: &Camera) -> ([f32; 16], [f32; 16]) {
    let f = (c.look_at - c.look_from).normalize();
    let r = f.cross(c.up).normalize();
    let u = r.cross(f);
    let o = c.look_from;
    // columns: the camera axes; last row: the eye's offset
    let cam = [
        [r.x, u.x, f.x, 0.0],
        [r.y, u.y, f.y, 0.0],
        [r.z, u.z, f.z, 0.0],
        [-o.dot(r), -o.dot(u), -o.dot(f), 1.0],
    ];
    let t = (c.fov_y.to_radians() * 0.5).tan();
    let a = c.width as f32 / c.height as f32;
    // camera (x, y, z, 1) → (x/(2at) + z/2, −y/(2t) + z/2, z, z)
    let proj = [
        [0.5 / (a * t), 0.0, 0.0, 0.0],
        [0.0, -0.5 / t, 0.0, 0.0],
        [0.5, 0.5, 1.0, 1.0],
        [0.0, 0.0, 0.0, 0.0],
    ];
    let mut ndc = [[0.0f32; 4]; 4];
    for (i, row) in ndc.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..4).map(|k| cam[i][k] * proj[k][j]).sum();
        }
    }
    (flat(cam), flat(ndc))
}

fn flat(m: [[f32; 4]; 4]) -> [f32; 16] {
    std::array::from_fn(|i| m[i / 4][i % 4])
}

/// The warning for `--accel embree` (or the default) on a machine where
/// `LUCENT_EMBREE4` names an Embree 4 that cannot be used: the render falls
/// back to Embree 3 (or the BVH), which the user may not expect.
pub fn embree4_warning(backend: Backend) -> Option<String> {
    if backend != Backend::Embree {
        return None;
    }
    let named = std::env::var_os("LUCENT_EMBREE4")?;
    let why = Backend::Embree4.resolve().err()?;
    let used = Backend::Embree.resolve().map_or("no Embree", |b| b.name());
    Some(format!(
        "warning: LUCENT_EMBREE4={} cannot be used ({why}); rendering with {used}",
        named.to_string_lossy()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec3;

    #[test]
    fn dates_are_capdates_of_the_gregorian_calendar() {
        assert_eq!(cap_date(0), "1970:01:01 00:00:00");
        // a leap day and a leap century
        assert_eq!(cap_date(951_782_400 + 3661), "2000:02:29 01:01:01");
        assert_eq!(cap_date(1_796_601_599), "2026:12:06 23:59:59");
    }

    /// Row vector × matrix.
    fn apply(m: &[f32; 16], p: Vec3) -> [f32; 4] {
        let v = [p.x, p.y, p.z, 1.0];
        std::array::from_fn(|j| (0..4).map(|k| v[k] * m[k * 4 + j]).sum())
    }

    #[test]
    fn the_matrices_map_what_the_camera_sees_to_its_pixels() {
        // A point a camera ray through pixel (x, y) passes must land at
        // (x/w, y/h) in NDC, at its depth along the view direction in
        // camera space; a transposed matrix or a flipped axis fails.
        let c = Camera::new(
            Vec3::new(1.0, 2.0, 5.0),
            Vec3::new(0.2, 0.1, -0.3),
            Vec3::Y,
            35.0,
            320,
            200,
        );
        let (cam, ndc) = camera_matrices(&c);
        for (x, y) in [(160.0, 100.0), (0.0, 0.0), (320.0, 200.0), (40.0, 170.0)] {
            let ray = c.ray(x, y);
            let p = ray.o + ray.d * 3.0;
            let depth = ray.d.dot((c.look_at - c.look_from).normalize()) * 3.0;
            let q = apply(&cam, p);
            assert!((q[2] - depth).abs() < 1e-4, "{q:?} against depth {depth}");
            let n = apply(&ndc, p);
            let (u, v) = (n[0] / n[3], n[1] / n[3]);
            assert!(
                (u - x / 320.0).abs() < 1e-4 && (v - y / 200.0).abs() < 1e-4,
                "{u}, {v}"
            );
        }
        // the eye is camera space's origin, up is +y
        let e = apply(&cam, c.look_from);
        assert!(e[..3].iter().all(|v| v.abs() < 1e-5), "{e:?}");
        let above = apply(&cam, c.look_from + Vec3::Y);
        assert!(above[1] > 0.9, "{above:?}");
    }
}
