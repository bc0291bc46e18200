//! Scene files: every `scenes/*.toml` parses, loads at run time into exactly the scene the
//! build script compiled in (field by field), and satisfies its own invariants; broken files
//! are refused with their file, key and reason.

use sonolube::protocol::TargetRange;
use std::path::PathBuf;

use sonolube::protocol::{Target, is_scene_name};
use sonolube::scene::{self, Criterion, ModelKind, SCENES, System, target_at};
use sonolube_cli::scene_file::{LoadedScene, out_of_reach, scenes_dir, target_ratio};
use sonolube_sim::ClosedLoop;
use sonolube_sim::plant::Plant;

fn loaded() -> Vec<LoadedScene> {
    LoadedScene::load_dir(&scenes_dir()).unwrap_or_else(|error| panic!("{error}"))
}

#[test]
fn every_file_loads_into_exactly_the_compiled_scene() {
    let files = scene_toml::scene_files(&scenes_dir()).expect("scenes/ lists");
    let loaded = loaded();
    assert_eq!(loaded.len(), files.len());
    assert_eq!(
        loaded.len(),
        SCENES.len(),
        "a file is not compiled in, or vice versa"
    );
    for (file, compiled) in loaded.iter().zip(SCENES) {
        let scene = file.scene();
        let name = compiled.name;
        assert_eq!(scene.name, compiled.name);
        assert_eq!(scene.description, compiled.description, "{name}");
        assert_eq!(scene.system, compiled.system, "{name}");
        assert_eq!(scene.materials, compiled.materials, "{name}");
        assert_eq!(scene.control_rate_hz, compiled.control_rate_hz, "{name}");
        assert_eq!(scene.duration_s, compiled.duration_s, "{name}");
        assert_eq!(scene.plant_substeps, compiled.plant_substeps, "{name}");
        assert_eq!(scene.noise_seed, compiled.noise_seed, "{name}");
        assert_eq!(scene.controller, compiled.controller, "{name}");
        assert_eq!(scene.plant, compiled.plant, "{name}");
        assert_eq!(scene.mismatch, compiled.mismatch, "{name}");
        assert_eq!(scene.actuator, compiled.actuator, "{name}");
        assert_eq!(scene.horn, compiled.horn, "{name}");
        assert_eq!(scene.transducer, compiled.transducer, "{name}");
        assert_eq!(scene.normal_cell, compiled.normal_cell, "{name}");
        assert_eq!(scene.tangential_cell, compiled.tangential_cell, "{name}");
        assert_eq!(scene.faults, compiled.faults, "{name}");
        assert_eq!(scene.normal_load_n, compiled.normal_load_n, "{name}");
        assert_eq!(
            scene.sliding_velocity_m_per_s, compiled.sliding_velocity_m_per_s,
            "{name}"
        );
        assert_eq!(scene.target, compiled.target, "{name}");
        assert_eq!(scene.accuracy, compiled.accuracy, "{name}");
        assert_eq!(scene.criteria, compiled.criteria, "{name}");
        assert_eq!(scene.contents, compiled.contents, "{name}");
        assert_eq!(&scene, compiled);
        // Bit for bit (Debug prints the shortest round-trip decimal, and -0.0 as such).
        assert_eq!(format!("{scene:?}"), format!("{compiled:?}"));
        assert_eq!(scene::find(name), Some(compiled));
    }
}

#[test]
fn a_run_on_the_loaded_scene_is_the_run_on_the_compiled_one() {
    let files = loaded();
    let file = files
        .iter()
        .find(|f| f.scene().name == "reference")
        .expect("reference");
    let loaded_scene = file.scene();
    let compiled = scene::find("reference").expect("compiled in");
    let mut a = Plant::from_scene(&loaded_scene).expect("plant");
    let mut b = Plant::from_scene(compiled).expect("plant");
    for k in 0..100u32 {
        let command = if k < 50 { 0.0 } else { 0.6 };
        assert_eq!(
            a.step(command, 40_000.0),
            b.step(command, 40_000.0),
            "step {k}"
        );
    }
}

fn extent(points: &[scene::Breakpoint]) -> (f64, f64) {
    points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.value), hi.max(p.value))
        })
}

#[test]
fn every_scene_satisfies_its_invariants() {
    for scene in SCENES {
        let name = scene.name;
        assert!(is_scene_name(name), "{name}");
        assert!(
            scene.duration_s > 0.0 && scene.control_rate_hz >= 1e3,
            "{name}"
        );
        assert!(
            scene.step_count() >= 10 && scene.step_count() <= 20_000,
            "{name}: long run"
        );
        // Models: the plant is of higher fidelity (a Dahl plant integrates in time what a Dahl
        // controller averages) and has what its kind needs.
        assert!(
            scene.plant.kind.fidelity() > scene.controller.kind.fidelity()
                || (scene.plant.kind == ModelKind::Dahl
                    && scene.controller.kind == ModelKind::Dahl),
            "{name}"
        );
        for spec in [&scene.controller, &scene.plant] {
            match spec.kind {
                ModelKind::Dahl => assert!(spec.k_t_n_per_m.is_some() && spec.dahl_alpha.is_some()),
                ModelKind::ExpCoulomb => assert!(spec.mu_static >= Some(spec.mu)),
                ModelKind::CubeElastic | ModelKind::CubeElasticPlastic => {
                    assert!(spec.surface.is_some() && scene.horn.is_some(), "{name}")
                }
                ModelKind::Coulomb => {}
            }
        }
        // The mismatch is the ratio of the two specs.
        assert_eq!(
            scene.mismatch.mu_ratio,
            scene.plant.mu / scene.controller.mu,
            "{name}"
        );
        let k_t = scene.controller.k_t_n_per_m.zip(scene.plant.k_t_n_per_m);
        assert_eq!(scene.mismatch.k_t_ratio, k_t.map(|(c, p)| p / c), "{name}");
        // Profiles: start at 0, increase, end within the run, covered by the contents.
        for table in [scene.normal_load_n, scene.sliding_velocity_m_per_s] {
            assert_eq!(table.first().map(|p| p.t_s), Some(0.0), "{name}");
            assert!(table.windows(2).all(|w| w[0].t_s < w[1].t_s), "{name}");
            assert!(
                table.last().is_some_and(|p| p.t_s <= scene.duration_s),
                "{name}"
            );
        }
        let (load_lo, load_hi) = extent(scene.normal_load_n);
        let (v_lo, v_hi) = extent(scene.sliding_velocity_m_per_s);
        let c = &scene.contents;
        assert!(c.load_min_n <= load_lo && load_hi <= c.load_max_n, "{name}");
        assert!(
            c.velocity_min_m_per_s <= v_lo && v_hi <= c.velocity_max_m_per_s,
            "{name}"
        );
        assert!(c.tangential_vibration || c.normal_vibration, "{name}");
        assert_eq!(c.normal_vibration, scene.horn.is_some(), "{name}");
        // Forces stay inside the cells' ranges.
        assert!(load_hi < scene.normal_cell.full_scale_n, "{name}");
        let peak_mu = scene.plant.mu_static.unwrap_or(scene.plant.mu);
        assert!(
            peak_mu * load_hi < scene.tangential_cell.full_scale_n,
            "{name}"
        );
        // Targets: valid protocol targets, starting with a step at 0.
        assert!(!scene.target.is_empty() && !scene.target[0].ramp, "{name}");
        assert!(scene.target.iter().all(|p| p.target.is_valid()), "{name}");
        // Criteria: present, windows inside the run, fault reactions exactly with faults.
        assert!(!scene.criteria.is_empty(), "{name}");
        let mut tightest = f64::INFINITY;
        for criterion in scene.criteria {
            match *criterion {
                Criterion::SteadyRmsError {
                    max_pct,
                    from_s,
                    to_s,
                }
                | Criterion::TrackingError {
                    max_pct,
                    from_s,
                    to_s,
                } => {
                    assert!(0.0 <= from_s && from_s < to_s && to_s <= scene.duration_s);
                    tightest = tightest.min(max_pct);
                }
                Criterion::Settle { band_pct, within_s } => {
                    assert!(within_s < scene.duration_s);
                    tightest = tightest.min(band_pct);
                }
                Criterion::Overshoot { max_pct } => assert!(max_pct > 0.0),
                Criterion::FaultReaction { within_periods } => assert!(within_periods >= 1),
            }
        }
        let reacts = scene
            .criteria
            .iter()
            .any(|c| matches!(c, Criterion::FaultReaction { .. }));
        assert_eq!(reacts, !scene.faults.is_empty(), "{name}");
        assert!(
            scene.faults.iter().all(|f| f.at_s < scene.duration_s),
            "{name}"
        );
        if tightest.is_finite() {
            assert_eq!(scene.accuracy.friction_pct, tightest, "{name}");
        }
        assert!(
            scene.accuracy.model_pct <= scene.accuracy.friction_pct,
            "{name}"
        );
        // The drive stays within the actuator's current rating at resonance.
        let t = &scene.transducer;
        let admittance = (1.0 / t.motional_resistance_ohm)
            .hypot(std::f64::consts::TAU * t.resonance_hz * t.clamped_capacitance_f);
        assert!(scene.actuator.full_scale_voltage_v * admittance <= scene.actuator.max_current_a);
    }
}

#[test]
fn the_issue_asks_for_these_scenes() {
    let systems: Vec<System> = SCENES.iter().map(|s| s.system).collect();
    for system in [
        System::StackOnRail,
        System::PoissonHorn,
        System::BeamOnTable,
        System::SeatBelt,
    ] {
        assert!(systems.contains(&system), "no scene for {system:?}");
    }
    let materials: Vec<&str> = SCENES
        .iter()
        .filter(|s| s.system == System::PoissonHorn)
        .map(|s| s.materials)
        .collect();
    assert!(
        materials.contains(&"Al horn on SS block") && materials.contains(&"SS horn on SS block")
    );
    assert!(
        SCENES.iter().any(|s| s.plant.kind == ModelKind::ExpCoulomb),
        "seed 002's law"
    );

    // REFERENCE: 40 kHz, Q = 100 (tau 0.8 ms), 0.5 % FS noise, +-20 % mu and k_t, a step from
    // 100 % to 50 % of natural friction, settle +-2 % in 3 ms, overshoot 5 %, RMS 1 %.
    let reference = scene::find("reference").expect("reference");
    assert_eq!(reference.transducer.resonance_hz, 40_000.0);
    assert_eq!(reference.transducer.quality_factor, 100.0);
    assert!((reference.transducer.envelope_time_constant_s() - 0.8e-3).abs() < 0.01e-3);
    assert_eq!(reference.normal_cell.noise_rms_pct_fs, 0.5);
    assert_eq!(reference.tangential_cell.noise_rms_pct_fs, 0.5);
    assert!((reference.mismatch.mu_ratio - 1.2).abs() < 1e-12);
    assert!((reference.mismatch.k_t_ratio.unwrap_or(0.0) - 0.8).abs() < 1e-12);
    let reduction = |r| Some(Target::Reduction { reduction_mpct: r });
    assert_eq!(target_at(reference.target, 0.0), reduction(0));
    assert_eq!(target_at(reference.target, 0.01), reduction(50_000));
    for wanted in [
        Criterion::Settle {
            band_pct: 2.0,
            within_s: 0.003,
        },
        Criterion::Overshoot { max_pct: 5.0 },
    ] {
        assert!(reference.criteria.contains(&wanted), "{wanted:?}");
    }
    assert!(reference.criteria.iter().any(|c| matches!(
        c,
        Criterion::SteadyRmsError { max_pct, .. } if *max_pct == 1.0
    )));

    // LOAD-RAMP: 40 -> 240 N in 1 s, coefficient held, error within 2 %.
    let ramp = scene::find("load-ramp").expect("load-ramp");
    let ramp_start = ramp
        .normal_load_n
        .iter()
        .rposition(|p| p.value == 40.0)
        .expect("40 N");
    let (from, to) = (
        ramp.normal_load_n[ramp_start],
        ramp.normal_load_n[ramp_start + 1],
    );
    assert_eq!((from.value, to.value), (40.0, 240.0));
    assert!((to.t_s - from.t_s - 1.0).abs() < 1e-12);
    assert!(
        ramp.target
            .iter()
            .all(|p| matches!(p.target, Target::Coef { .. }))
    );
    assert_eq!(ramp.target.len(), 1);
    assert!(ramp.criteria.iter().any(|c| matches!(
        c,
        Criterion::TrackingError { max_pct, .. } if *max_pct == 2.0
    )));

    // SENSOR-FAULT: a fault during the run, supervisor in fault within one control period.
    let fault = scene::find("sensor-fault").expect("sensor-fault");
    assert!(
        fault
            .faults
            .iter()
            .all(|f| f.at_s > 0.0 && f.at_s < fault.duration_s)
    );
    assert!(!fault.faults.is_empty());
    assert!(
        fault
            .criteria
            .contains(&Criterion::FaultReaction { within_periods: 1 })
    );
}

#[test]
fn every_target_is_within_the_plants_reach() {
    // The plant must reach each target with at most 90 % of its settled amplitude at the
    // drive frequency (the resonance may drift away from it), or no controller could pass
    // the criteria. Checked every 5 ms along each scene, with the plant's own model.
    for scene in SCENES {
        let misses =
            out_of_reach(scene, 0.9, 0.005).unwrap_or_else(|e| panic!("{}: {e}", scene.name));
        assert!(misses.is_empty(), "{}: {misses:?}", scene.name);
    }
    // And the check can fail: 20 % of full scale cannot give the reference's 50 %.
    let reference = scene::find("reference").expect("reference");
    let misses = out_of_reach(reference, 0.2, 0.005).expect("model");
    assert!(
        misses
            .iter()
            .all(|m| m.t_s >= 0.005 && m.needed == 0.5 && m.reached > 0.5)
    );
    assert_eq!(misses.len(), 5);
    assert_eq!(target_ratio(reference, 0.0), Some(1.0));
}

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sonolube-scenes-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn reference_text() -> String {
    std::fs::read_to_string(scenes_dir().join("reference.toml")).expect("reference.toml")
}

#[test]
fn a_user_file_loads_and_runs_without_being_compiled_in() {
    let dir = temp_dir("user");
    let text = reference_text()
        .replace("name = \"reference\"", "name = \"my-bench\"")
        .replace(
            "normal_load_n = [[0.0, 4.155]]",
            "normal_load_n = [[0.0, 1.902]]",
        )
        .replace(
            "load_range_n = [4.155, 4.155]",
            "load_range_n = [1.902, 1.902]",
        );
    let path = dir.join("my-bench.toml");
    std::fs::write(&path, text).expect("write");
    let user = LoadedScene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let scene = user.scene();
    assert_eq!(scene.name, "my-bench");
    assert!(scene::find("my-bench").is_none());
    let mut plant = Plant::from_scene(&scene).expect("plant");
    let readings = plant.step(0.0, 40_000.0);
    assert_eq!(readings.truth.normal_load_n, 1.902);
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn a_scene_may_ask_for_commissioning_and_its_run_uses_the_measured_values() {
    let text = reference_text();
    let declared = scene_toml::parse(&text, "reference.toml").expect("loads");
    assert!(!declared.commission);
    let with_key = text.replacen(
        "noise_seed = 1001",
        "noise_seed = 1001\ncommission = true",
        1,
    );
    assert_ne!(with_key, text);
    let description = scene_toml::parse(&with_key, "reference.toml").expect("loads");
    assert!(description.commission);
    let loaded = LoadedScene::from_description(description);
    let scene = loaded.scene();
    assert!(scene.commission);
    let run = ClosedLoop::new(&scene).expect("commissioned run");
    let result = run.commissioned().expect("commissioned before the run");
    // The run drives at the measured f0 (39 999.66 Hz), not the declared 40 kHz.
    let f0_chz = (result.resonance_hz.value * 100.0).round() as u32;
    assert_eq!(run.station().drive_freq_chz(), f0_chz);
    assert_ne!(f0_chz, 4_000_000);
    assert!(
        (result.quality_factor.value - 100.0).abs() < 4.0 * result.quality_factor.standard_error
    );
    let wrong = text.replacen("noise_seed = 1001", "noise_seed = 1001\ncommission = 1", 1);
    assert!(scene_toml::parse(&wrong, "edited.toml").is_err());
}

/// `[controller] model_mismatch_pct` is the user's declaration: absent it is `None` (the
/// tuning's default), given it loads as a fraction into the compiled scene type, the loop's
/// settings take it; out of range or in `[plant]` it is refused with the value and why.
#[test]
fn the_declared_mismatch_is_read_from_the_controller_table() {
    let text = reference_text();
    assert_eq!(
        scene_toml::parse(&text, "reference.toml")
            .expect("loads")
            .model_mismatch,
        None
    );
    let with_key = text.replacen(
        "k_t_n_per_m = 2.5e7",
        "k_t_n_per_m = 2.5e7\nmodel_mismatch_pct = 35.0",
        1,
    );
    let description = scene_toml::parse(&with_key, "edited.toml").expect("loads");
    assert_eq!(description.model_mismatch, Some(0.35));
    let loaded = LoadedScene::from_description(description);
    let scene = loaded.scene();
    assert_eq!(scene.model_mismatch, Some(0.35));
    let settings = sonolube::control::controller_settings(&scene);
    assert_eq!(settings.model_mismatch, 0.35);
    for (pct, reason) in [
        ("100.0", "outside 0 <= m < 100"),
        ("-1.0", "outside 0 <= m < 100"),
        ("nan", "outside 0 <= m < 100"),
    ] {
        let error = error_after(
            "k_t_n_per_m = 2.5e7",
            &format!("k_t_n_per_m = 2.5e7\nmodel_mismatch_pct = {pct}"),
        );
        assert_eq!(error.key, "controller.model_mismatch_pct", "{error}");
        assert!(error.reason.contains(reason), "{error}");
        // The value itself (f64's Display: 100, -1, NaN).
        assert!(
            error
                .reason
                .to_lowercase()
                .starts_with(pct.trim_end_matches(".0")),
            "{error}"
        );
    }
    let error = error_after(
        "dahl_alpha = 1.0",
        "dahl_alpha = 1.0\nmodel_mismatch_pct = 20.0",
    );
    assert_eq!(error.key, "plant.model_mismatch_pct", "{error}");
    assert!(error.reason.contains("[controller]"), "{error}");
}

/// The error for `text` with `from` replaced by `to`, as `key: reason`.
fn error_after(from: &str, to: &str) -> scene_toml::SceneError {
    let text = reference_text();
    assert!(text.contains(from), "the reference scene lacks {from:?}");
    scene_toml::parse(&text.replacen(from, to, 1), "edited.toml").expect_err("should fail")
}

#[test]
fn a_negative_net_force_target_loads_signed() {
    let text = reference_text().replacen("reduction_pct = 50.0", "net_force_n = -2.5", 1);
    let scene = scene_toml::parse(&text, "edited.toml").expect("loads");
    let last = scene.target.last().expect("points");
    assert_eq!(
        last.target,
        scene_toml::Target::NetForce { force_mn: -2_500 }
    );
}

#[test]
fn broken_files_are_refused_with_file_key_and_reason() {
    let cases: [(&str, &str, &str, &str); 16] = [
        ("duration_s = 0.025\n", "", "duration_s", "missing field"),
        (
            "duration_s = 0.025",
            "duration_s = 0.025\nspeed = 3",
            "speed",
            "unknown field",
        ),
        ("mu = 0.24\n", "", "plant.mu", "missing field `mu`"),
        (
            "quality_factor = 100.0",
            "quality_factor = 0.5",
            "transducer.quality_factor",
            "outside",
        ),
        (
            "model = \"dahl\"",
            "model = \"stribeck\"",
            "plant.model",
            "expected one of",
        ),
        (
            "model = \"dahl\"",
            "model = \"coulomb\"",
            "plant.model",
            "higher fidelity",
        ),
        (
            "noise_rms_pct_fs = 0.5",
            "noise_rms_pct_fs = \"high\"",
            "sensors.normal.noise_rms_pct_fs",
            "invalid type",
        ),
        (
            "[[0.0, 4.155]]",
            "[[0.0, 4.155, 1.0]]",
            "profiles.normal_load_n[0]",
            "pair",
        ),
        (
            "reduction_pct = 50.0",
            "reduction_pct = 50.0001",
            "profiles.target[1].reduction_pct",
            "resolution",
        ),
        (
            "reduction_pct = 50.0",
            "coef = 0.1\nramp = true",
            "profiles.target[1].ramp",
            "same kind",
        ),
        // The signed net force (issue 27): its range is the command's, +-50 kN, at 1 mN.
        (
            "reduction_pct = 50.0",
            "net_force_n = -50000.001",
            "profiles.target[1].net_force_n",
            "outside -50000 ..= 50000",
        ),
        (
            "reduction_pct = 50.0",
            "net_force_n = -1.0001",
            "profiles.target[1].net_force_n",
            "resolution",
        ),
        (
            "reduction_pct = 50.0",
            "reduction_pct = 50.0\nnet_force_n = 1.0",
            "profiles.target[1]",
            "exactly one of",
        ),
        (
            "load_range_n = [4.155, 4.155]",
            "load_range_n = [5.0, 6.0]",
            "contents.load_range_n",
            "does not contain",
        ),
        (
            "vibration = [\"tangential\"]",
            "vibration = [\"normal\"]",
            "contents.vibration",
            "hardware",
        ),
        (
            "full_scale_voltage_v = 5.25",
            "full_scale_voltage_v = 6.0",
            "actuator.full_scale_voltage_v",
            "max_current_a",
        ),
    ];
    for (from, to, key, reason) in cases {
        let error = error_after(from, to);
        assert_eq!(error.file, "edited.toml");
        assert_eq!(error.key, key, "{error}");
        assert!(error.reason.contains(reason), "{error}");
        assert!(
            error
                .to_string()
                .starts_with(&format!("edited.toml: {key}: "))
        );
    }
    // A fault without a fault-reaction criterion.
    let error = error_after(
        "[[criteria]]\nkind = \"settle\"",
        "[[faults]]\nat_s = 0.01\nchannel = \"normal\"\nkind = \"stuck\"\n\n[[criteria]]\nkind = \"settle\"",
    );
    assert_eq!(error.key, "criteria", "{error}");
}

#[test]
fn a_directory_needs_unique_names_matching_the_files() {
    let dir = temp_dir("names");
    std::fs::write(dir.join("reference.toml"), reference_text()).expect("write");
    std::fs::write(dir.join("copy.toml"), reference_text()).expect("write");
    let error = scene_toml::load_dir(&dir).expect_err("copy.toml holds scene reference");
    assert!(
        error.file.ends_with("copy.toml") && error.key == "name",
        "{error}"
    );
    std::fs::remove_file(dir.join("copy.toml")).expect("remove");
    assert_eq!(scene_toml::load_dir(&dir).map(|s| s.len()), Ok(1));
    let missing = scene_toml::load(&dir.join("absent.toml")).expect_err("no such file");
    assert_eq!(missing.key, "(file)");
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn the_loader_and_the_firmware_share_their_rules() {
    // Scene names: the loader's rule is the protocol's.
    for name in [
        "reference",
        "a",
        "x-1_y",
        "",
        "list",
        "none",
        "Upper",
        "sp ace",
        "é",
    ] {
        assert_eq!(
            scene_toml::is_scene_name(name),
            is_scene_name(name),
            "{name:?}"
        );
    }
    assert!(!scene_toml::is_scene_name(&"a".repeat(25)) && !is_scene_name(&"a".repeat(25)));
    // The fidelity order.
    let kinds = [
        (scene_toml::ModelKind::Coulomb, ModelKind::Coulomb),
        (scene_toml::ModelKind::ExpCoulomb, ModelKind::ExpCoulomb),
        (scene_toml::ModelKind::Dahl, ModelKind::Dahl),
        (scene_toml::ModelKind::CubeElastic, ModelKind::CubeElastic),
        (
            scene_toml::ModelKind::CubeElasticPlastic,
            ModelKind::CubeElasticPlastic,
        ),
    ];
    for (loader, firmware) in kinds {
        assert_eq!(scene_toml::fidelity(loader), firmware.fidelity());
    }
}
