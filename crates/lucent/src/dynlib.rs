//! Opening a shared library lucent loads at run time (Embree 4, Open Image
//! Denoise): the path an environment variable names, else the loader's
//! search for the library's own names. What the library must then have
//! (functions, version) is checked by the module that binds it.

use libloading::Library;

/// Why no library was opened.
pub(crate) enum OpenError {
    /// The environment variable named `path`, which would not load.
    CannotLoad { path: String, problem: String },
    /// None of the names loaded: each one's error, joined.
    NotFound { tried: String },
}

/// The library at the path in `env_var` (when set and not empty), else the
/// first of `names` the loader finds; with the path or name it was opened
/// by.
pub(crate) fn open(env_var: &str, names: &[&str]) -> Result<(Library, String), OpenError> {
    if let Some(p) = std::env::var_os(env_var).filter(|v| !v.is_empty()) {
        let shown = p.to_string_lossy().into_owned();
        // SAFETY: loading runs the library's initializers, which for the
        // libraries lucent loads (Embree 4, Open Image Denoise 2) are
        // sound. A path to some other library is the user's explicit
        // choice; the caller refuses it before calling into it unless it
        // has the expected functions and version.
        return match unsafe { Library::new(&p) } {
            Ok(lib) => Ok((lib, shown)),
            Err(e) => Err(OpenError::CannotLoad {
                path: shown,
                problem: e.to_string(),
            }),
        };
    }
    let mut errs = Vec::new();
    for name in names {
        // SAFETY: as above; `names` are the library's own file names.
        match unsafe { Library::new(name) } {
            Ok(lib) => return Ok((lib, name.to_string())),
            Err(e) => errs.push(e.to_string()),
        }
    }
    Err(OpenError::NotFound {
        tried: errs.join("; "),
    })
}
