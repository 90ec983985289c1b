//! What this build of lucent can do (`lucent info`): its ray-query
//! backends, the default one, the denoiser found (if any) and whether it
//! has subsurface scattering.

use crate::accel::{self, Backend};

/// A few lines: the version, the backends available (and why an Embree is
/// missing), the default backend, the denoiser and the subsurface feature.
pub fn build_info() -> String {
    let names: Vec<&str> = Backend::all_available().iter().map(|b| b.name()).collect();
    let mut s = format!(
        "lucent {}\nbuild: {}\nbackends: {}",
        env!("CARGO_PKG_VERSION"),
        super::provenance::build_id(),
        names.join(", ")
    );
    for line in accel::embree_report() {
        s.push('\n');
        s.push_str(&line);
    }
    let default = Backend::default_available();
    s.push_str(&format!("\ndefault backend: {}", default.name()));
    if let Ok(b) = default.resolve() {
        if b != default {
            s.push_str(&format!(" ({})", b.name()));
        }
    }
    s.push('\n');
    s.push_str(&crate::denoise::load::report());
    s.push_str(if cfg!(feature = "subsurface") {
        "\nsubsurface: yes"
    } else {
        "\nsubsurface: no (built without the `subsurface` feature)"
    });
    s
}
