//! Build script of the `sonolube` crate: compiles the scenes of `scenes/*.toml` into the
//! firmware.
//!
//! Every scene file is read and validated by the `scene-toml` crate (the same code the host
//! loader uses) and written as Rust `static` data of the `no_std` `sonolube::scene::Scene`
//! type to `$OUT_DIR/scenes.rs`, which `src/scene/builtin.rs` includes. A scene that does not
//! validate fails the build with its file, key and reason.

use std::path::PathBuf;

fn main() {
    let manifest_dir = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default());
    let scenes_dir = manifest_dir.join("scenes");
    // The directory itself covers added and removed files; each file covers edits.
    println!("cargo::rerun-if-changed={}", scenes_dir.display());
    let files = scene_toml::scene_files(&scenes_dir).unwrap_or_else(|error| fail(&error));
    for file in &files {
        println!("cargo::rerun-if-changed={}", file.display());
    }
    let scenes = scene_toml::load_dir(&scenes_dir).unwrap_or_else(|error| fail(&error));
    let out_dir = PathBuf::from(std::env::var_os("OUT_DIR").unwrap_or_default());
    let out = out_dir.join("scenes.rs");
    if let Err(error) = std::fs::write(&out, scene_toml::generate_rust(&scenes)) {
        fail(&format!("cannot write {}: {error}", out.display()));
    }
}

fn fail(error: &dyn std::fmt::Display) -> ! {
    eprintln!("error: scene files: {error}");
    std::process::exit(1);
}
