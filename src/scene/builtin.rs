//! The scenes compiled into the firmware.
//!
//! The build script (`build.rs`) reads every `scenes/*.toml` with the `scene-toml` crate, which
//! validates it exactly as the host loader does, and writes them as one `static` slice to
//! `$OUT_DIR/scenes.rs`, included here. Editing a scene file rebuilds the crate.

#[allow(unused_imports)]
use super::{
    Accuracy, Actuator, ActuatorKind, Breakpoint, Channel, Contents, Criterion, FaultEvent,
    FaultKind, Horn, LoadCell, Mismatch, ModelKind, ModelSpec, Rail, ResonanceShift, RoughSurface,
    Scene, Stack, System, TargetPoint, Transducer,
};
#[allow(unused_imports)]
use crate::protocol::Target;

include!(concat!(env!("OUT_DIR"), "/scenes.rs"));
include!(concat!(env!("OUT_DIR"), "/cube_tables.rs"));
include!(concat!(env!("OUT_DIR"), "/selections.rs"));

/// Every built-in scene ([`SCENES`]).
pub fn compiled() -> &'static [Scene<'static>] {
    SCENES
}

/// The built-in scene named `name` (the `scene <name>` command), if any.
pub fn find(name: &str) -> Option<&'static Scene<'static>> {
    SCENES.iter().find(|scene| scene.name == name)
}

/// The nodes of the cube table `variant` (a variant name, `cube ep T=17x17`) that the build
/// script computed for `scene` into flash (`build.rs`: the selection's table for every
/// compiled scene that selects one), if `scene` is that compiled scene in every value (a scene
/// file loaded at run time under a built-in name but differing from it gets none: its table is
/// built at scene start, [`crate::model::cube_table::CubeTable::new`]).
pub fn cube_table_nodes(scene: &Scene<'_>, variant: &str) -> Option<&'static [i32]> {
    let (_, _, nodes) = CUBE_TABLE_NODES
        .iter()
        .find(|(name, table, _)| *name == scene.name && *table == variant)?;
    // A bare-metal build without the exact cube model loads no scene file: its scenes are the
    // compiled ones, which the NUCLEO-G474RE holds as its own records (its build script checks
    // that the station built from a record is the compiled scene's), so the name is the
    // scene and the comparison would only link the whole scene table (12.2 KB).
    #[cfg(all(target_os = "none", not(feature = "cube-exact")))]
    let compiled = true;
    #[cfg(not(all(target_os = "none", not(feature = "cube-exact"))))]
    let compiled = find(scene.name)? == scene;
    compiled.then_some(*nodes)
}

/// The model variant selection of `scene` ([`crate::variant::select`]) that the build script
/// made for it (`build.rs`: every compiled scene's, from the same measured table), if `scene`
/// is that compiled scene in every value. A firmware that runs only its built-in scenes (the
/// G474) takes its selections from here and links neither the selection nor the measured
/// table; a test checks that each is the one `select` makes.
pub fn selection(scene: &Scene<'_>) -> Option<crate::variant::Selection> {
    let (_, selection) = SELECTIONS.iter().find(|(name, _)| *name == scene.name)?;
    (find(scene.name)? == scene).then_some(*selection)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::is_scene_name;
    use crate::scene::in_build;

    #[test]
    fn the_name_list_is_every_scene_in_order() {
        let names: std::vec::Vec<&str> = SCENES.iter().map(|s| s.name).collect();
        assert_eq!(names, SCENE_NAMES);
    }

    #[test]
    fn every_scene_is_found_by_its_valid_unique_name() {
        assert!(!SCENES.is_empty());
        for scene in SCENES {
            assert!(is_scene_name(scene.name), "{}", scene.name);
            let found = find(scene.name).map(|s| s as *const Scene<'static>);
            assert_eq!(
                found,
                Some(scene as *const Scene<'static>),
                "{}",
                scene.name
            );
        }
        assert!(find("no-such-scene").is_none());
    }

    /// The selections the build script put in flash are `select`'s, field for field (floats
    /// bit for bit: `PartialEq` on the `f32`s, none of which is NaN), for every compiled scene,
    /// and a copy of a scene that differs from it (loaded at run time) gets none.
    #[test]
    fn the_selections_in_flash_are_the_runtime_ones() {
        use crate::variant::select;
        assert_eq!(SELECTIONS.len(), SCENES.len());
        for scene in SCENES {
            let made = select(scene);
            assert_eq!(selection(scene), Some(made), "{}", scene.name);
            let copy = Scene {
                description: "a copy loaded at run time",
                ..*scene
            };
            assert_eq!(selection(&copy), None, "{}", scene.name);
        }
    }

    #[test]
    fn the_compiled_in_data_stays_small() {
        // Flash budget of the scene table (structs, not counting strings and tables), for
        // the 32-bit target and the 64-bit host alike: under 1 KB per scene (936 B with the
        // resonance shift of issue 14), so that the table grows with the scenes only.
        let bytes = core::mem::size_of_val(SCENES);
        assert!(
            bytes < 1_000 * SCENES.len(),
            "{bytes} bytes for {}",
            SCENES.len()
        );
    }

    #[test]
    fn the_acceptance_scenes_are_built_in() {
        for name in ["reference", "sensor-fault"] {
            assert!(find(name).is_some(), "{name} is missing");
        }
        // The horn scene needs the cube family (cargo feature `cube`).
        assert_eq!(find("load-ramp").is_some(), cfg!(feature = "cube"));
        let reference = find("reference").map(|s| s.transducer.envelope_time_constant_s());
        let tau = reference.unwrap_or(0.0);
        assert!((tau - 0.000_795_8).abs() < 1e-7, "tau = {tau}");
    }

    /// The cube tables the build script put in flash are, bit for bit, the tables the
    /// controller built at scene start before (`CubeTable::new` on the selected variant): for
    /// every compiled scene that selects a table, the model from flash equals the one built
    /// at run time for a copy of the scene (a copy that differs in its description only, so it
    /// is not the compiled scene and gets no flash table). A scene that selects no table has
    /// none in flash.
    #[test]
    fn the_cube_tables_in_flash_are_the_runtime_builds() {
        use crate::fx::{Q1_31, Q2_30, Q8_24, Q16_16};
        use crate::model::cube_table::CubeTable;
        use crate::model::{FrictionModel, OperatingPoint};
        use crate::variant::fixed::fixed_model;
        use crate::variant::{Family, select};
        let mut tables = 0;
        for scene in SCENES {
            let Some(variant) = select(scene).variant else {
                continue;
            };
            let nodes = cube_table_nodes(scene, variant.name);
            if variant.table == 0 || variant.fidelity.family() != Family::Cube {
                assert!(nodes.is_none(), "{}", scene.name);
                continue;
            }
            let nodes = nodes.unwrap_or_else(|| panic!("{}: no table in flash", scene.name));
            let side = usize::from(variant.table);
            assert_eq!(nodes.len(), side * side, "{}", scene.name);
            let copy = Scene {
                description: "a copy loaded at run time",
                ..*scene
            };
            assert!(cube_table_nodes(&copy, variant.name).is_none());
            let from_flash = fixed_model(scene, variant).expect(scene.name);
            let at_run_time = fixed_model(&copy, variant).expect(scene.name);
            assert_eq!(from_flash, at_run_time, "{}", scene.name);
            // A bare-metal build without `cube-exact` (the G474's set) builds the table from
            // the nodes and the variant's contact alone: the same answers over the scene's
            // stated load range, every amplitude node and between them.
            let board = CubeTable::from_flash(
                crate::variant::fixed::contact_kind(variant.fidelity),
                (scene.contents.load_min_n, scene.contents.load_max_n),
                side,
                nodes,
            )
            .expect(scene.name);
            for l in 0..=8 {
                let (lo, hi) = (scene.contents.load_min_n, scene.contents.load_max_n);
                let load = lo * libm::pow(hi / lo, f64::from(l) / 8.0);
                let point = OperatingPoint {
                    normal_force: Q16_16::from_f64(load).expect("load"),
                    sliding_velocity: Q8_24::ZERO,
                };
                for k in 0..=32 {
                    let a = Q1_31::from_bits(((k as i64) << 26).min(i32::MAX as i64) as i32);
                    assert_eq!(
                        board.ratio(&point, a),
                        from_flash.ratio(&point, a),
                        "{} {load} N {k}/32",
                        scene.name
                    );
                }
                let target = Q2_30::from_f64(0.6).expect("target");
                assert_eq!(
                    board.invert(&point, target),
                    from_flash.invert(&point, target),
                    "{} {load} N",
                    scene.name
                );
            }
            tables += 1;
        }
        // The horn scenes select the 17 x 17 elastic-plastic table (docs/speed.md).
        let horns = SCENES.iter().filter(|scene| scene.horn.is_some()).count();
        assert_eq!(tables, horns);
        assert_eq!(tables >= 3, cfg!(feature = "cube"));
    }

    /// A build without a model family (cargo features `dahl`, `cube`, `exp-coulomb`) holds
    /// exactly the scene files whose controller model is in the build and that have no horn
    /// unless the cube family is in (the plant is the simulation's, which has every family):
    /// counted from the files themselves (the host loader), not from the build script's own
    /// filter.
    #[test]
    fn a_scene_is_compiled_in_exactly_when_its_models_are_in_the_build() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
        let files = scene_toml::load_dir(&dir).expect("the scene files load");
        assert!(files.len() >= 10, "{}", files.len());
        let mut expected: Vec<&str> = files
            .iter()
            .filter(|file| {
                in_build(file.controller.kind)
                    && (file.horn.is_none() || in_build(ModelKind::CubeElasticPlastic))
            })
            .map(|file| file.name.as_str())
            .collect();
        expected.sort_unstable();
        let mut built: Vec<&str> = SCENES.iter().map(|scene| scene.name).collect();
        built.sort_unstable();
        assert_eq!(built, expected);
        for scene in SCENES {
            assert!(in_build(scene.controller.kind), "{}", scene.name);
        }
    }
}
