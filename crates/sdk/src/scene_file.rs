//! Scenes: a file (or the built-in paper case) with `--set` overrides, validated.

use crate::Result;
use clutchpack_scene::{Override, Scene};
use std::path::{Path, PathBuf};

/// The default scene, the paper's case (`scenes/hu-table2.toml`), built in so that a run
/// without a scene works from anywhere.
pub const DEFAULT_SCENE_TEXT: &str = include_str!("../../../scenes/hu-table2.toml");
/// The name the default scene is reported under.
pub const DEFAULT_SCENE_NAME: &str = "scenes/hu-table2.toml (built in)";

/// Loads and validates the scene file `path` (or, without one, the built-in default scene)
/// with the overrides `sets` (`KEY=VALUE`, applied in order). Every problem of the scene is
/// in the error, at its key ([`crate::Error::Scene`], bad input).
pub fn load_scene(path: Option<&Path>, sets: &[Override]) -> Result<Scene> {
    Ok(match path {
        Some(p) => clutchpack_scene::load(p, sets)?,
        None => clutchpack_scene::parse(
            DEFAULT_SCENE_TEXT,
            DEFAULT_SCENE_NAME,
            &std::env::current_dir().unwrap_or_else(|_| PathBuf::from(".")),
            sets,
        )?,
    })
}
