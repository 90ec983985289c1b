//! Scene loading and validation.
use super::{Scene, SceneError};
use std::path::Path;

pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| SceneError::new(path, format!("cannot read scene file: {e}")))?;
    load_str(&text, path)
}

pub fn load_str(_text: &str, path: &Path) -> Result<Scene, SceneError> {
    Err(SceneError::new(path, "not yet implemented"))
}
