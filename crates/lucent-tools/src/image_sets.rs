//! Two sets of renders to compare, read from the files named on a command
//! line: an estimator's and its reference's, each one or more EXRs of
//! independent seeds (`examples/error_model.rs`,
//! `examples/keylight_regions.rs`).

use std::path::Path;

use lucent::film::Film;

/// The films at `first` and at `second`, named `names` in messages: each
/// set not empty and every film the size of the others. An error names
/// the file or the mistake.
pub fn two_sets(
    first: &[String],
    second: &[String],
    names: [&str; 2],
) -> Result<(Vec<Film>, Vec<Film>), String> {
    let read = |paths: &[String]| -> Result<Vec<Film>, String> {
        paths
            .iter()
            .map(|p| Film::read_exr(Path::new(p)).map_err(|e| format!("{p}: {e}")))
            .collect()
    };
    let (a, b) = (read(first)?, read(second)?);
    if a.is_empty() || b.is_empty() {
        return Err(format!("no {} or no {} image", names[0], names[1]));
    }
    let size = |f: &Film| (f.width, f.height);
    if a.iter().chain(&b).any(|f| size(f) != size(&b[0])) {
        return Err("the images differ in size".into());
    }
    Ok((a, b))
}
