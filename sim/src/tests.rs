//! The closed loop on the built-in scenes: phases, commands, calibration, faults, capacity.

use super::*;
use sonolube::control::{Reason, Sensor, SensorFault, SensorFaultKind, controller_settings};
use sonolube::protocol::{SupervisorState, Target};
use sonolube::scene::{Criterion, Scene, TargetPoint, find};

fn scene(name: &str) -> Scene<'static> {
    *find(name).expect("built in")
}

fn records(sim: &mut ClosedLoop<'_>) -> std::vec::Vec<StepRecord> {
    core::iter::from_fn(|| sim.step()).collect()
}

#[test]
fn the_phases_run_in_their_order_only() {
    let reference = scene("reference");
    let mut sim = ClosedLoop::new(&reference).expect("runs");
    assert!(sim.control_phase().is_none());
    assert!(sim.finish_step().is_none());
    let readings = sim.plant_phase().expect("first period");
    assert_eq!(readings.step, 1);
    assert!(sim.plant_phase().is_none(), "the control phase is due");
    assert!(sim.finish_step().is_none());
    let output = sim.control_phase().expect("control");
    assert!(sim.control_phase().is_none());
    let record = sim.finish_step().expect("record");
    assert_eq!((record.step, record.time_s), (1, 1e-4));
    assert_eq!(record.state, output.state);
    assert!(sim.plant_phase().is_some());
}

#[test]
fn a_run_takes_the_scenes_steps_and_applies_its_target_at_its_time() {
    let reference = scene("reference");
    let mut sim = ClosedLoop::new(&reference).expect("runs");
    let run = records(&mut sim);
    assert_eq!(run.len(), 250);
    assert!(sim.is_finished() && sim.step().is_none() && sim.plant_phase().is_none());
    let natural = Some(Target::Reduction { reduction_mpct: 0 });
    let half = Some(Target::Reduction {
        reduction_mpct: 50_000,
    });
    // The step at 5 ms is the 50th sample's target, and the controller holds it from there.
    assert_eq!((run[48].target, run[49].target), (natural, half));
    assert_eq!(sim.controller().target(), half);
    // Started at t = 0: running once the sliding is confirmed (1 ms) and mu0 has been learned
    // for 3 ms (`natural_learn_s`), drive off until the step.
    let first_running = run.iter().position(|r| r.state == SupervisorState::Running);
    assert!(matches!(first_running, Some(37..=40)), "{first_running:?}");
    assert!(run[..37].iter().all(|r| r.state == SupervisorState::Idle));
    assert!(
        run[40..49]
            .iter()
            .all(|r| r.state == SupervisorState::Running)
    );
    assert!(run[..49].iter().all(|r| r.drive_amplitude == 0.0));
    assert!(run[52].drive_amplitude > 0.5);
    // The drive command of one step is what the plant holds over the next.
    let plant = sim.plant().steps();
    assert_eq!(plant, 250);
}

#[test]
fn the_reference_step_meets_its_criteria() {
    let summary = ClosedLoop::new(&scene("reference")).expect("runs").run();
    assert!(summary.passed(), "{summary:?}");
    assert_eq!(summary.segments.len(), 2);
    let step = summary.segments[1];
    assert_eq!(step.origin, Origin::Step);
    assert!((step.metrics.start_s - 0.005).abs() < 1e-6);
    assert!(step.metrics.settling_s.is_some_and(|s| s <= 0.003));
}

#[test]
fn commissioning_takes_the_cells_errors_out_of_the_estimate() {
    // Drive off until 5 ms: the estimate is the natural friction 0.24 x 4.155 N = 0.9972 N,
    // read by a cell with -1 % gain and -4 mN offset (0.9832 N).
    let reference = scene("reference");
    let mean_estimate = |calibration| {
        let settings = controller_settings(&reference);
        let mut sim = ClosedLoop::with_settings(&reference, &settings, calibration).expect("runs");
        let run = records(&mut sim);
        let natural = &run[10..49];
        let sum: f64 = natural
            .iter()
            .map(|r| f64::from(r.estimated_friction_n))
            .sum();
        sum / natural.len() as f64
    };
    let nominal = mean_estimate(CellCalibration::Nominal);
    let commissioned = mean_estimate(COMMISSIONED);
    assert!((nominal - 0.9832).abs() < 0.003, "{nominal}");
    assert!((commissioned - 0.9972).abs() < 0.003, "{commissioned}");
}

#[test]
fn a_disconnected_cell_faults_the_loop_in_the_step_that_reads_it() {
    let mut sim = ClosedLoop::new(&scene("sensor-fault")).expect("runs");
    let run = records(&mut sim);
    // The fault starts at 15 ms: the 150th sample.
    let before = &run[148];
    assert!(!before.injected_fault && before.sensor_fault.is_none());
    assert_eq!(before.state, SupervisorState::Running);
    let onset = &run[149];
    let fault = SensorFault {
        sensor: Sensor::TangentialForce,
        kind: SensorFaultKind::Disconnected,
    };
    assert!(onset.injected_fault);
    assert_eq!(onset.sensor_fault, Some(fault));
    assert_eq!(onset.state, SupervisorState::Fault);
    assert_eq!(onset.reason, Reason::SensorFault(fault));
    assert_eq!(onset.drive_amplitude, 0.0);
    assert!(run[149..].iter().all(|r| r.drive_amplitude == 0.0));
    let summary = sim.summary();
    assert_eq!(summary.faults[0].onset_step, 150);
    assert_eq!(summary.faults[0].periods, Some(1));
    assert!(summary.passed());
}

#[test]
fn a_run_is_the_same_every_time() {
    let spike = scene("sensor-spike");
    let first = records(&mut ClosedLoop::new(&spike).expect("runs"));
    let second = records(&mut ClosedLoop::new(&spike).expect("runs"));
    assert_eq!(format!("{first:?}"), format!("{second:?}"));
}

#[test]
fn scenes_the_runner_cannot_hold_are_refused() {
    let reference = scene("reference");
    let many = [Criterion::Overshoot { max_pct: 5.0 }; MAX_CRITERIA + 1];
    let crowded = Scene {
        criteria: &many,
        ..reference
    };
    assert_eq!(ClosedLoop::new(&crowded).err(), Some(SimError::TooLarge));
    let zero_coef = [TargetPoint {
        at_s: 0.0,
        target: Target::Coef { coef_ppm: 0 },
        ramp: false,
    }];
    let bad_target = Scene {
        target: &zero_coef,
        ..reference
    };
    assert_eq!(
        ClosedLoop::new(&bad_target).err(),
        Some(SimError::InvalidTarget)
    );
    let no_target = Scene {
        target: &[],
        ..reference
    };
    assert_eq!(
        ClosedLoop::new(&no_target).err(),
        Some(SimError::InvalidTarget)
    );
}

/// The model each built-in scene's controller runs is the variant `select` names for it, built
/// by the variant's own builder, whichever way the run is made (scripted, operated, or the
/// station alone as the G474 board builds it); and the choice differs from the scene file's
/// own model somewhere, so this cannot pass by building the own model everywhere.
#[test]
fn every_scene_runs_the_variant_select_names() {
    use sonolube::model::AnyModel;
    use sonolube::variant::{fixed::fixed_model, select};

    let mut differs = 0;
    for built in sonolube::scene::SCENES {
        let selection = select(built);
        let variant = selection.variant.expect(built.name);
        let chosen = fixed_model(built, variant).expect(built.name);
        let scripted = ClosedLoop::new(built).expect(built.name);
        let operated = ClosedLoop::operated(built).expect(built.name);
        let station = scene_station(built, &controller_settings(built)).expect(built.name);
        for station in [scripted.station(), operated.station(), &station] {
            assert_eq!(station.selection(), Some(&selection), "{}", built.name);
            assert_eq!(station.model(), &chosen, "{}: {}", built.name, variant.name);
        }
        let own = AnyModel::new(built, &built.controller).expect(built.name);
        differs += usize::from(own != chosen);
    }
    assert!(differs > 0, "no scene's choice differs from its own model");
}

/// A built-in scene whose selected variant is not the model its file names, so that a run of
/// it tells the two apart.
fn scene_choosing_another_model() -> Scene<'static> {
    use sonolube::model::AnyModel;
    let differs = |s: &&Scene<'static>| {
        let chosen = sonolube::variant::select(s).build(s);
        chosen.is_ok() && chosen != AnyModel::new(s, &s.controller)
    };
    *sonolube::scene::SCENES
        .iter()
        .find(differs)
        .expect("a scene whose choice is not its own model")
}

/// A scene the committed table did not measure (a built-in name with other contents) runs its
/// own controller model, and says so; a renamed copy of a built-in scene is that scene's
/// measured twin (`variant::select::measured_twin`: the same measurement inputs) and runs its
/// choice; a budget change alone is still measured.
#[test]
fn a_scene_outside_the_table_keeps_its_own_model() {
    use sonolube::model::AnyModel;
    use sonolube::scene::Contents;
    use sonolube::variant::{Reason, select};

    let horn = scene_choosing_another_model();
    let renamed = Scene {
        name: "my-horn",
        ..horn
    };
    let moved = Scene {
        contents: Contents {
            load_max_n: horn.contents.load_max_n + 40.0,
            ..horn.contents
        },
        ..horn
    };
    let twin = ClosedLoop::new(&renamed).expect("runs");
    assert_eq!(
        twin.station().selection().map(|s| s.variant),
        Some(select(&horn).variant)
    );
    // Unmeasured, the scene's own model is the choice; its control step must still fit the
    // period (issue 24), and the horn's exact cube model does not: the run is refused, saying so.
    let selection = select(&moved);
    assert_eq!(selection.variant, None);
    let own = AnyModel::new(&moved, &moved.controller).expect("own model");
    match ClosedLoop::new(&moved) {
        Ok(run) => {
            assert_eq!(
                selection.reason,
                Reason::NotMeasured {
                    kind: horn.controller.kind
                }
            );
            assert_eq!(run.station().model(), &own);
        }
        Err(_) => assert!(
            selection.refused(),
            "refused without the selection saying so"
        ),
    }
    // The built-in scene itself runs another model than its own.
    let measured = ClosedLoop::new(&horn).expect("runs");
    let own = AnyModel::new(&horn, &horn.controller).expect("own model");
    assert_ne!(measured.station().model(), &own);
    let budget = Scene {
        accuracy: sonolube::scene::Accuracy {
            model_pct: 2.0 * horn.accuracy.model_pct,
            ..horn.accuracy
        },
        ..horn
    };
    assert!(select(&budget).variant.is_some());
}

/// A run given its model runs that model, and has no selection to print.
#[test]
fn a_run_given_its_model_runs_it() {
    use sonolube::model::AnyModel;

    let horn = scene_choosing_another_model();
    let own = AnyModel::new(&horn, &horn.controller).expect("own model");
    let run = ClosedLoop::with_model(&horn, own.clone()).expect("runs");
    assert_eq!(run.station().selection(), None);
    assert_eq!(run.station().model(), &own);
    assert_ne!(
        ClosedLoop::new(&horn).expect("runs").station().model(),
        &own
    );
}
