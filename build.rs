//! Build script of the `sonolube` crate: compiles the scenes of `scenes/*.toml` into the
//! firmware, with the cube tables they select.
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
//!
//! `SONOLUBE_EXTRA_SCENES=DIR` compiles the scene files of `DIR` in as well (test scenes run in
//! QEMU, `cli/tests/scenes/`); a name that is also in `scenes/` fails the build.
//!
//! **Cube tables in flash** (issue 24, item 5). A scene whose variant selection
//! (`sonolube::variant::select`) picks a tabulated cube model (`cube ep T=17x17`, ...) used to
//! build its table at scene start: 316,120 Cortex-M4 instructions for 17 x 17 nodes, 18 to 46
//! PWM periods on the G474. This script builds it instead, with the crate's own code: the
//! fixed-point modules (`src/fx`, `src/model`, `src/variant`, the `Scene` type of
//! `src/scene/types.rs`) are compiled into the script by `#[path]`, so the nodes come from the
//! very functions the controller would run (`CubeTable::new`), and are written to
//! `$OUT_DIR/cube_tables.rs` (`sonolube::scene::builtin::cube_table_nodes`). Integer
//! arithmetic and `libm`'s `f64` are the same on the build host as on the Cortex-M4, so the
//! nodes are bit-identical to the runtime build (a test checks it for every compiled scene).

use std::path::PathBuf;

// The crate's fixed-point modules, compiled into the script (see the module docs): `crate::fx`,
// `crate::model`, `crate::variant` and `crate::scene` resolve to these, as in the crate.
#[allow(dead_code, unused_imports, unused_macros, clippy::all)]
#[path = "src/fx/mod.rs"]
mod fx;
#[allow(dead_code, unused_imports, unused_macros, clippy::all)]
#[path = "src/model/mod.rs"]
mod model;
#[allow(dead_code, unused_imports, unused_macros, clippy::all)]
#[path = "src/variant/mod.rs"]
mod variant;

#[allow(dead_code)]
#[path = "src/scene/types.rs"]
mod scene_types;

/// `crate::scene` as the fixed-point modules see it: the scene types, and the scenes being
/// compiled in as the built-in ones (so the selection's "measured as built in" test reads the
/// files this build compiles, as the firmware's own `SCENES`).
#[allow(dead_code, unused_imports)]
mod scene {
    pub use sonolube_scene_types::*;

    pub use super::scene_types::{Scene, in_build};

    /// The scenes this build compiles in, set once by `main`.
    pub static BUILT: std::sync::OnceLock<Vec<Scene<'static>>> = std::sync::OnceLock::new();

    /// The compiled-in scenes.
    pub fn compiled() -> &'static [Scene<'static>] {
        BUILT.get().map_or(&[], Vec::as_slice)
    }

    /// The compiled-in scene named `name`.
    pub fn find(name: &str) -> Option<&'static Scene<'static>> {
        BUILT.get()?.iter().find(|scene| scene.name == name)
    }

    /// No table is in flash yet while the script computes them: every table is built.
    pub fn cube_table_nodes(_scene: &Scene<'_>, _variant: &str) -> Option<&'static [i32]> {
        None
    }
}

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
    // Test scenes compiled in on request (`SONOLUBE_EXTRA_SCENES=DIR`): a firmware that runs a
    // scene file of a test directory (`cli/tests/scenes/`) in QEMU, never a shipped build.
    println!("cargo::rerun-if-env-changed=SONOLUBE_EXTRA_SCENES");
    if let Some(extra) = std::env::var_os("SONOLUBE_EXTRA_SCENES").filter(|d| !d.is_empty()) {
        let extra = PathBuf::from(extra);
        println!("cargo::rerun-if-changed={}", extra.display());
        for file in scene_toml::scene_files(&extra).unwrap_or_else(|error| fail(&error)) {
            println!("cargo::rerun-if-changed={}", file.display());
        }
        for scene in scene_toml::load_dir(&extra).unwrap_or_else(|error| fail(&error)) {
            if scenes.iter().any(|s| s.name == scene.name) {
                fail(&format!(
                    "{}: scene {:?} is also in scenes/",
                    extra.display(),
                    scene.name
                ));
            }
            scenes.push(scene);
        }
    }
    scenes.retain(|scene| {
        in_build(scene.controller.kind) && (scene.horn.is_none() || feature("CUBE"))
    });
    let out_dir = PathBuf::from(std::env::var_os("OUT_DIR").unwrap_or_default());
    let out = out_dir.join("scenes.rs");
    if let Err(error) = std::fs::write(&out, scene_toml::generate_rust(&scenes)) {
        fail(&format!("cannot write {}: {error}", out.display()));
    }
    let built: Vec<scene::Scene<'static>> = scenes.into_iter().map(leak_scene).collect();
    let built = scene::BUILT.get_or_init(|| built);
    let tables = out_dir.join("cube_tables.rs");
    let text = cube_tables(built).unwrap_or_else(|error| fail(&error));
    if let Err(error) = std::fs::write(&tables, text) {
        fail(&format!("cannot write {}: {error}", tables.display()));
    }
    let selections = out_dir.join("selections.rs");
    let text = selections_source(built).unwrap_or_else(|error| fail(&error));
    if let Err(error) = std::fs::write(&selections, text) {
        fail(&format!("cannot write {}: {error}", selections.display()));
    }
}

/// The model variant selection of every compiled scene (`variant::select`, made here with the
/// crate's own code and measured table, as the cube tables are), as Rust source: a firmware
/// that runs only its built-in scenes takes it from flash instead of linking the selection
/// and the measured table (`sonolube::scene::builtin::selection`). Floats are written as
/// their bits, so the constants are the selection's values bit for bit.
fn selections_source(scenes: &[scene::Scene<'static>]) -> Result<String, String> {
    use std::fmt::Write as _;
    let mut out = String::from(
        "// Generated by the sonolube build script from scenes/*.toml: do not edit.\n\
         /// The model variant selection of each compiled scene (`variant::select` run by the\n\
         /// build script), in the order of `SCENES`.\n\
         pub static SELECTIONS: &[(&str, crate::variant::Selection)] = &[\n",
    );
    for scene in scenes {
        let selection = variant::select(scene);
        let text = selection_source(&selection)
            .map_err(|error| format!("scene {}: {error}", scene.name))?;
        let _ = writeln!(out, "    ({:?}, {text}),", scene.name);
    }
    out.push_str("];\n");
    Ok(out)
}

/// One selection as a Rust expression of the crate's types.
fn selection_source(selection: &variant::Selection) -> Result<String, String> {
    use variant::select::{Parts, Reason, Reduction};
    let f32_bits = |value: f32| format!("f32::from_bits({:#010x})", value.to_bits());
    let option_f32 = |value: Option<f32>| match value {
        Some(value) => format!("Some({})", f32_bits(value)),
        None => "None".into(),
    };
    let variant = match selection.variant {
        Some(chosen) => {
            let index = variant::CATALOGUE
                .iter()
                .position(|v| v.name == chosen.name)
                .ok_or_else(|| format!("variant {:?} is not in the catalogue", chosen.name))?;
            format!("Some(&crate::variant::CATALOGUE[{index}])")
        }
        None => "None".into(),
    };
    let required = match selection.required {
        Some(fidelity) => format!("Some(crate::variant::Fidelity::{fidelity:?})"),
        None => "None".into(),
    };
    let reduction = |r: &Reduction| {
        format!(
            "crate::variant::select::Reduction {{ skipped: {}, error_pct: {} }}",
            r.skipped,
            option_f32(r.error_pct)
        )
    };
    let parts = match &selection.parts {
        None => "None".into(),
        Some(Parts::InPlane { compliance }) => format!(
            "Some(crate::variant::Parts::InPlane {{ compliance: {} }})",
            compliance
                .as_ref()
                .map_or_else(|| "None".into(), |r| format!("Some({})", reduction(r)))
        ),
        Some(Parts::Cube {
            plastic,
            load_range_n,
        }) => format!(
            "Some(crate::variant::Parts::Cube {{ plastic: {}, load_range_n: ({}, {}) }})",
            reduction(plastic),
            f32_bits(load_range_n.0),
            f32_bits(load_range_n.1)
        ),
    };
    let reason = match selection.reason {
        Reason::Meets {
            error_pct,
            budget_pct,
            instructions,
            points,
            candidates,
        } => format!(
            "crate::variant::Reason::Meets {{ error_pct: {}, budget_pct: {}, instructions: {}, \
             points: {points}, candidates: {candidates} }}",
            f32_bits(error_pct),
            f32_bits(budget_pct),
            f32_bits(instructions)
        ),
        Reason::NoneMeets {
            error_pct,
            budget_pct,
            instructions,
            points,
        } => format!(
            "crate::variant::Reason::NoneMeets {{ error_pct: {}, budget_pct: {}, \
             instructions: {}, points: {points} }}",
            f32_bits(error_pct),
            f32_bits(budget_pct),
            f32_bits(instructions)
        ),
        Reason::NotMeasured { kind } => {
            format!("crate::variant::Reason::NotMeasured {{ kind: ModelKind::{kind:?} }}")
        }
        Reason::Overruns {
            error_pct,
            budget_pct,
            accurate,
            kind,
        } => format!(
            "crate::variant::Reason::Overruns {{ error_pct: {}, budget_pct: {}, \
             accurate: {accurate}, kind: ModelKind::{kind:?} }}",
            option_f32(error_pct),
            f32_bits(budget_pct)
        ),
    };
    let period = &selection.period;
    Ok(format!(
        "crate::variant::Selection {{ variant: {variant}, required: {required}, \
         reason: {reason}, parts: {parts}, period: crate::variant::select::Period {{ \
         board: {:?}, rate_hz: {}, budget: {}, step_longest: {:?} }} }}",
        period.board, period.rate_hz, period.budget, period.step_longest
    ))
}

/// The cube tables the compiled scenes select, as Rust source: one `(scene, variant, nodes)`
/// per scene whose selection is a tabulated cube model, nodes row-major (Q2.30 bits, `side`^2).
fn cube_tables(scenes: &[scene::Scene<'static>]) -> Result<String, String> {
    use std::fmt::Write as _;
    let mut out = String::from(
        "// Generated by the sonolube build script from scenes/*.toml: do not edit.\n\
         /// The cube tables of the compiled scenes: (scene, variant, F'/F at the nodes, Q2.30\n\
         /// bits, row-major), built by `CubeTable::new` in the build script.\n\
         pub static CUBE_TABLE_NODES: &[(&str, &str, &[i32])] = &[\n",
    );
    for scene in scenes {
        let selection = variant::select(scene);
        let Some(chosen) = selection.variant else {
            continue;
        };
        if chosen.table == 0 || chosen.fidelity.family() != variant::Family::Cube {
            continue;
        }
        let nodes = table_nodes(scene, &selection)
            .map_err(|error| format!("scene {}: {}: {error}", scene.name, chosen.name))?;
        let _ = write!(out, "    ({:?}, {:?}, &[", scene.name, chosen.name);
        for (i, node) in nodes.iter().enumerate() {
            if i % 8 == 0 {
                out.push_str("\n        ");
            }
            let _ = write!(out, "{node}, ");
        }
        out.push_str("\n    ]),\n");
    }
    out.push_str("];\n");
    Ok(out)
}

/// The nodes of the cube table `selection` names for `scene`, as `CubeTable::new` builds them.
#[cfg(feature = "cube")]
fn table_nodes(
    scene: &scene::Scene<'_>,
    selection: &variant::Selection,
) -> Result<Vec<i32>, String> {
    match selection.build(scene) {
        Ok(model::AnyModel::CubeTable(table)) => Ok(table.nodes().to_vec()),
        Ok(_) => Err("not a cube table".into()),
        Err(error) => Err(error.to_string()),
    }
}

/// Without the cube family no compiled scene has a horn, so none selects a cube table.
#[cfg(not(feature = "cube"))]
fn table_nodes(
    _scene: &scene::Scene<'_>,
    _selection: &variant::Selection,
) -> Result<Vec<i32>, String> {
    Err("the cube family is not in this build".into())
}

/// A scene description as the firmware's `Scene` type (leaked: the script runs once).
fn leak_scene(d: scene_toml::SceneDescription) -> scene::Scene<'static> {
    let d: &'static scene_toml::SceneDescription = Box::leak(Box::new(d));
    scene::Scene {
        name: &d.name,
        description: &d.description,
        system: d.system,
        materials: &d.materials,
        control_rate_hz: d.control_rate_hz,
        duration_s: d.duration_s,
        plant_substeps: d.plant_substeps,
        noise_seed: d.noise_seed,
        controller: d.controller,
        plant: d.plant,
        mismatch: d.mismatch,
        actuator: d.actuator,
        horn: d.horn,
        transducer: d.transducer,
        normal_cell: d.normal_cell,
        tangential_cell: d.tangential_cell,
        faults: &d.faults,
        normal_load_n: &d.normal_load_n,
        sliding_velocity_m_per_s: &d.sliding_velocity_m_per_s,
        target: &d.target,
        accuracy: d.accuracy,
        criteria: &d.criteria,
        contents: d.contents,
        commission: d.commission,
        model_mismatch: d.model_mismatch,
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
