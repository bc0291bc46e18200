//! Sonolube scene files: TOML in, validated plain data out.
//!
//! A scene file (`scenes/*.toml`, schema in `scenes/README.md`) describes one operating
//! scenario: materials, actuator, horn, transducer, sensors, profiles, target, faults, the
//! controller's and the plant's models, the accuracy it needs and its pass criteria. This crate
//! reads one with serde and `toml`, rejects unknown keys, checks every unit and range and the
//! rules across sections, and returns a [`SceneDescription`]: owned strings and vectors, every
//! number in SI `f64`.
//!
//! It is used twice: by the `sonolube` crate's build script, which writes every scene as a
//! `static` of the firmware's `no_std` `Scene` type with [`generate_rust`]; and by the host
//! tools, which load any file (compiled in or not) into the same data. Errors name the file,
//! the key and the reason ([`SceneError`]).

mod checks;
mod codegen;
mod error;
mod hardware;
mod raw;
mod tables;
mod types;
mod validate;

use std::path::{Path, PathBuf};

pub use checks::plant_peak_coefficient;
pub use codegen::generate_rust;
pub use error::SceneError;
pub use tables::MAX_TABLE_POINTS;
pub use types::*;
pub use validate::{
    DEFAULT_ADC_BITS, DEFAULT_CONTROL_RATE_HZ, DEFAULT_NOISE_SEED, DEFAULT_PLANT_SUBSTEPS,
    DRIVE_RANGE_HZ, fidelity, is_scene_name,
};

use error::{Errors, key_of_parse_error};

/// Parses and validates the text of one scene file; `file` names it in errors.
pub fn parse(text: &str, file: &str) -> Result<SceneDescription, SceneError> {
    let errors = Errors { file };
    let raw: raw::RawScene = toml::from_str(text).map_err(|error| SceneError {
        file: file.to_string(),
        key: key_of_parse_error(text, &error),
        reason: error.message().to_string(),
    })?;
    validate::scene(raw, errors)
}

/// Reads, parses and validates one scene file.
pub fn load(path: &Path) -> Result<SceneDescription, SceneError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|error| SceneError {
        file: file.clone(),
        key: "(file)".to_string(),
        reason: format!("cannot be read: {error}"),
    })?;
    parse(&text, &file)
}

/// The `*.toml` files of `dir`, sorted by file name.
pub fn scene_files(dir: &Path) -> Result<Vec<PathBuf>, SceneError> {
    let unreadable = |error: std::io::Error| SceneError {
        file: dir.display().to_string(),
        key: "(directory)".to_string(),
        reason: format!("cannot be listed: {error}"),
    };
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(unreadable)? {
        let path = entry.map_err(unreadable)?.path();
        if path.extension().is_some_and(|ext| ext == "toml") {
            files.push(path);
        }
    }
    files.sort();
    Ok(files)
}

/// Loads every scene file of `dir` (see [`scene_files`]); names must be unique, and each file
/// must be named after its scene (`<name>.toml`).
pub fn load_dir(dir: &Path) -> Result<Vec<SceneDescription>, SceneError> {
    let mut scenes: Vec<SceneDescription> = Vec::new();
    for path in scene_files(dir)? {
        let scene = load(&path)?;
        let error = |reason: String| SceneError {
            file: path.display().to_string(),
            key: "name".to_string(),
            reason,
        };
        if path.file_stem().and_then(|s| s.to_str()) != Some(scene.name.as_str()) {
            return Err(error(format!(
                "the file of scene {:?} must be named {0}.toml",
                scene.name
            )));
        }
        if scenes.iter().any(|s| s.name == scene.name) {
            return Err(error(format!(
                "{:?} is the name of another scene",
                scene.name
            )));
        }
        scenes.push(scene);
    }
    Ok(scenes)
}
