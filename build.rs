//! Build script of the `sonolube` crate: compiles the scenes of `scenes/*.toml` into the
//! firmware.
//!
//! Every scene file is read and validated by the `scene-toml` crate (the same code the host
//! loader uses) and written as Rust `static` data of the `no_std` `sonolube::scene::Scene`
//! type to `$OUT_DIR/scenes.rs`, which `src/scene/builtin.rs` includes. A scene that does not
//! validate fails the build with its file, key and reason.
//!
//! A build without a model family (the cargo features `dahl`, `cube`, `exp-coulomb`) compiles
//! in only the scenes whose controller model is in the build and whose hardware needs no
//! left-out family (a horn vibrates the contact normally: the cube family). The plant model is
//! the simulation's (`sonolube-sim`, which takes every family); a board drives a real contact.

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
    let mut scenes = scene_toml::load_dir(&scenes_dir).unwrap_or_else(|error| fail(&error));
    scenes.retain(|scene| {
        in_build(scene.controller.kind) && (scene.horn.is_none() || feature("CUBE"))
    });
    let out_dir = PathBuf::from(std::env::var_os("OUT_DIR").unwrap_or_default());
    let out = out_dir.join("scenes.rs");
    if let Err(error) = std::fs::write(&out, scene_toml::generate_rust(&scenes)) {
        fail(&format!("cannot write {}: {error}", out.display()));
    }
}

/// Whether the crate is built with the cargo feature `name` (upper case, `-` as `_`).
fn feature(name: &str) -> bool {
    std::env::var_os(format!("CARGO_FEATURE_{name}")).is_some()
}

/// Whether the model family of `kind` is in this build (`ModelKind::in_build` of the crate).
fn in_build(kind: scene_toml::ModelKind) -> bool {
    use scene_toml::ModelKind;
    match kind {
        ModelKind::Coulomb => true,
        ModelKind::ExpCoulomb => feature("EXP_COULOMB"),
        ModelKind::Dahl => feature("DAHL"),
        ModelKind::CubeElastic | ModelKind::CubeElasticPlastic => feature("CUBE"),
    }
}

fn fail(error: &dyn std::fmt::Display) -> ! {
    eprintln!("error: scene files: {error}");
    std::process::exit(1);
}
