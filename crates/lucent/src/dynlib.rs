//! Opening a shared library lucent loads at run time (Embree 4, Open Image
//! Denoise): the path an environment variable names, else the loader's
//! search for the library's own names; and looking its functions up. What
//! else the library must have (its version) is checked by the module that
//! binds it.

use libloading::Library;

/// A library lucent loads at run time, as its errors name it.
pub(crate) struct Wanted {
    /// The environment variable that names its path.
    pub env_var: &'static str,
    /// Its file names, for the loader's search.
    pub names: &'static [&'static str],
    /// What it is, in "… was not found".
    pub name: &'static str,
    /// What its functions make it, in "… is not an … library".
    pub kind: &'static str,
    /// How to get it, in the not-found message's parentheses.
    pub install: &'static str,
}

/// Why no library was opened, or a function is missing from it.
#[derive(Debug, thiserror::Error)]
pub enum OpenError {
    /// The environment variable named `path`, which would not load.
    #[error("{env_var}={path}: cannot load it ({problem})")]
    CannotLoad {
        env_var: &'static str,
        path: String,
        problem: String,
    },
    /// None of the names loaded: each one's error, joined.
    #[error("{name} was not found: {tried} ({install})")]
    NotFound {
        name: &'static str,
        tried: String,
        install: &'static str,
    },
    /// The library has no function of that name.
    #[error("{path} is not an {kind} library: it has no {symbol} ({problem})")]
    MissingSymbol {
        path: String,
        kind: &'static str,
        symbol: &'static str,
        problem: String,
    },
}

/// A library opened by [`open`], with the path or name it was opened by.
pub(crate) struct Opened {
    pub lib: Library,
    pub path: String,
    kind: &'static str,
}

impl Opened {
    /// The function `name` (NUL-terminated), copied out of the library.
    ///
    /// # Safety
    /// `T` must be the C signature of the library's function `name`, and
    /// the pointer is valid only while `self.lib` stays loaded.
    pub(crate) unsafe fn function<T: Copy>(&self, name: &'static str) -> Result<T, OpenError> {
        // SAFETY: the caller vouches for `T`; `get` reads the symbol's
        // address without calling it.
        match unsafe { self.lib.get::<T>(name.as_bytes()) } {
            Ok(s) => Ok(*s),
            Err(e) => Err(OpenError::MissingSymbol {
                path: self.path.clone(),
                kind: self.kind,
                symbol: name.trim_end_matches('\0'),
                problem: e.to_string(),
            }),
        }
    }
}

/// The library at the path in `wanted.env_var` (when set and not empty),
/// else the first of `wanted.names` the loader finds.
pub(crate) fn open(wanted: &Wanted) -> Result<Opened, OpenError> {
    let opened = |lib, path| Opened {
        lib,
        path,
        kind: wanted.kind,
    };
    if let Some(p) = std::env::var_os(wanted.env_var).filter(|v| !v.is_empty()) {
        let shown = p.to_string_lossy().into_owned();
        // SAFETY: loading runs the library's initializers, which for the
        // libraries lucent loads (Embree 4, Open Image Denoise 2) are
        // sound. A path to some other library is the user's explicit
        // choice; the caller refuses it before calling into it unless it
        // has the expected functions and version.
        return match unsafe { Library::new(&p) } {
            Ok(lib) => Ok(opened(lib, shown)),
            Err(e) => Err(OpenError::CannotLoad {
                env_var: wanted.env_var,
                path: shown,
                problem: e.to_string(),
            }),
        };
    }
    let mut errs = Vec::new();
    for name in wanted.names {
        // SAFETY: as above; `names` are the library's own file names.
        match unsafe { Library::new(name) } {
            Ok(lib) => return Ok(opened(lib, name.to_string())),
            Err(e) => errs.push(e.to_string()),
        }
    }
    Err(OpenError::NotFound {
        name: wanted.name,
        tried: errs.join("; "),
        install: wanted.install,
    })
}
