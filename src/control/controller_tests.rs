//! Tests of the controller's commands, supervisor transitions, faults and bumpless changes.

use super::config::{Config, Settings};
use super::controller::Controller;
use super::error::ControlError;
use super::io::{Inputs, Output};
use super::pi::PiGains;
use super::reason::{ExternalFault, Reason, Sensor, SensorFault, SensorFaultKind};
use super::schedule::GainSchedule;
use super::testkit::{LittmannModel, Plant};
use crate::drive::Amplitude;
use crate::fx::{Q1_31, Q2_30, Q16_16};
use crate::model::{FrictionModel, ModelError, OperatingPoint, Reach};
use crate::protocol::{SupervisorState as S, Target};

const T: f64 = 1e-4;
const HALF: Target = Target::Reduction {
    reduction_mpct: 50_000,
};

fn setup() -> (Controller, LittmannModel, Plant) {
    let ctl = Controller::new(Config::new(&Settings::REFERENCE).unwrap());
    (
        ctl,
        LittmannModel::new(0.0754),
        Plant::new(0.3, 0.0754 * 0.9, 0.8e-3, T, 3),
    )
}

fn run<M: FrictionModel>(
    ctl: &mut Controller,
    model: &M,
    plant: &mut Plant,
    steps: usize,
) -> Output {
    let mut out = ctl.step(&plant.measure(), model);
    plant.advance(out.amplitude);
    for _ in 1..steps {
        out = ctl.step(&plant.measure(), model);
        plant.advance(out.amplitude);
    }
    out
}

/// Sliding and running at half friction, settled.
fn running() -> (Controller, LittmannModel, Plant) {
    let (mut ctl, model, mut plant) = setup();
    ctl.set_target(HALF).unwrap();
    run(&mut ctl, &model, &mut plant, 100);
    ctl.start().unwrap();
    let out = run(&mut ctl, &model, &mut plant, 300);
    assert_eq!((out.state, out.reason), (S::Running, Reason::RampDone));
    assert!(out.amplitude.to_f64() > 0.5);
    (ctl, model, plant)
}

#[test]
fn commands_are_refused_with_the_protocol_codes() {
    let (mut ctl, model, mut plant) = setup();
    run(&mut ctl, &model, &mut plant, 50);
    assert_eq!(ctl.start(), Err(ControlError::NoTarget));
    assert!(matches!(
        ctl.clear_fault(),
        Err(ControlError::WrongState {
            command: "clear",
            ..
        })
    ));
    let bad = Target::Reduction {
        reduction_mpct: 100_000,
    };
    assert_eq!(
        ctl.set_target(bad),
        Err(ControlError::InvalidTarget { target: bad })
    );
    assert_eq!(ctl.target(), None);
    ctl.set_target(HALF).unwrap();
    ctl.start().unwrap();
    assert_eq!(
        (ctl.state(), ctl.reason()),
        (S::RampUp, Reason::StartCommand)
    );
    assert_eq!(ctl.start().map_err(|e| e.code().code()), Err(21));
    ctl.trip(ExternalFault::Overcurrent);
    assert_eq!(ctl.start().map_err(|e| e.code().code()), Err(22));
    assert_eq!(ctl.report_ratio(Q2_30::from_f64(0.5).unwrap()), Some(HALF));
}

#[test]
fn soft_start_rises_at_the_ramp_rate_then_runs() {
    let (mut ctl, model, mut plant) = setup();
    ctl.set_target(HALF).unwrap();
    run(&mut ctl, &model, &mut plant, 100);
    ctl.start().unwrap();
    let mut previous = 0.0;
    for k in 0..200 {
        let out = run(&mut ctl, &model, &mut plant, 1);
        if out.state == S::RampUp {
            assert!(out.amplitude.to_f64() - previous <= 0.02 + 1e-9, "step {k}");
            assert!(out.saturation.soft_start || k == 0);
        }
        previous = out.amplitude.to_f64();
    }
    assert_eq!((ctl.state(), ctl.reason()), (S::Running, Reason::RampDone));
}

#[test]
fn sensor_fault_zeroes_the_drive_in_the_same_step_and_latches() {
    let (mut ctl, model, mut plant) = running();
    let fault = SensorFault {
        sensor: Sensor::TangentialForce,
        kind: SensorFaultKind::Stuck,
    };
    let out = ctl.step(
        &Inputs {
            sensor_fault: Some(fault),
            ..plant.measure()
        },
        &model,
    );
    assert_eq!(out.amplitude, Amplitude::ZERO);
    assert_eq!(
        (out.state, out.reason, out.fault),
        (
            S::Fault,
            Reason::SensorFault(fault),
            Some(Reason::SensorFault(fault))
        )
    );
    assert_eq!(out.reason.code(), 45);
    // Latched: healthy samples do not clear it, nor does a start.
    let out = run(&mut ctl, &model, &mut plant, 100);
    assert_eq!((out.state, out.amplitude), (S::Fault, Amplitude::ZERO));
    assert!(ctl.start().is_err());
    ctl.clear_fault().unwrap();
    assert_eq!((ctl.state(), ctl.reason()), (S::Idle, Reason::ClearCommand));
    ctl.start().unwrap();
    assert_eq!(run(&mut ctl, &model, &mut plant, 300).state, S::Running);
}

#[test]
fn implausible_readings_and_model_errors_are_faults_too() {
    let (mut ctl, model, mut plant) = running();
    let garbage = Inputs {
        normal_force: Q16_16::from_int(30_000).unwrap(),
        ..plant.measure()
    };
    let out = ctl.step(&garbage, &model);
    assert_eq!((out.amplitude, out.state), (Amplitude::ZERO, S::Fault));
    assert_eq!(out.reason.name(), "normal-out-of-range");

    struct Broken;
    impl FrictionModel for Broken {
        fn ratio(&self, _: &OperatingPoint, _: Q1_31) -> Result<Q2_30, ModelError> {
            Err(ModelError::OutOfDomain {
                input: "normal_force",
                reason: "test",
            })
        }
    }
    let (mut ctl, _, mut plant) = running();
    let out = run(&mut ctl, &Broken, &mut plant, 1);
    assert_eq!(
        (out.amplitude, out.state, out.reason),
        (Amplitude::ZERO, S::Fault, Reason::ModelError)
    );
}

#[test]
fn external_trip_zeroes_the_drive_at_the_next_step() {
    let (mut ctl, model, mut plant) = running();
    ctl.trip(ExternalFault::Overrun);
    let out = run(&mut ctl, &model, &mut plant, 1);
    assert_eq!(
        (out.amplitude, out.reason),
        (Amplitude::ZERO, Reason::Overrun)
    );
}

#[test]
fn stop_ramps_down_at_the_configured_rate() {
    let (mut ctl, model, mut plant) = running();
    let before = run(&mut ctl, &model, &mut plant, 1);
    ctl.stop().unwrap();
    assert_eq!(
        (ctl.state(), ctl.reason()),
        (S::RampDown, Reason::StopCommand)
    );
    let mut previous = before.amplitude.to_f64();
    let mut steps = 0;
    loop {
        let out = run(&mut ctl, &model, &mut plant, 1);
        assert!(
            previous - out.amplitude.to_f64() <= 0.02 + 1e-9,
            "faster than 5 ms full scale"
        );
        previous = out.amplitude.to_f64();
        steps += 1;
        if out.state == S::Idle {
            assert_eq!(
                (out.reason, out.armed, out.amplitude),
                (Reason::RampDone, false, Amplitude::ZERO)
            );
            break;
        }
        assert_eq!(out.state, S::RampDown);
    }
    assert!((25..=60).contains(&steps), "{steps} steps");
}

#[test]
fn losing_sliding_ramps_down_and_resumes_when_it_returns() {
    let (mut ctl, model, mut plant) = running();
    plant.sliding_velocity = 0.0;
    let trace: Vec<Output> = (0..100)
        .map(|_| run(&mut ctl, &model, &mut plant, 1))
        .collect();
    let down = trace.iter().position(|o| o.state == S::RampDown).unwrap();
    assert_eq!(trace[down].reason, Reason::NotSliding);
    assert!(down >= 19, "debounced: {down}");
    let last = trace.last().unwrap();
    assert_eq!(
        (last.state, last.reason, last.armed, last.sliding),
        (S::Idle, Reason::RampDone, true, false)
    );
    assert_eq!(last.amplitude, Amplitude::ZERO);
    plant.sliding_velocity = -0.038; // the other way
    let out = run(&mut ctl, &model, &mut plant, 20);
    assert_eq!((out.state, out.reason), (S::RampUp, Reason::SlidingResumed));
    assert_eq!(run(&mut ctl, &model, &mut plant, 300).state, S::Running);
    // Lifting the load: no friction coefficient to control.
    plant.normal_force = 0.1;
    let trace: Vec<Output> = (0..100)
        .map(|_| run(&mut ctl, &model, &mut plant, 1))
        .collect();
    assert!(
        trace
            .iter()
            .any(|o| (o.state, o.reason) == (S::RampDown, Reason::NoLoad))
    );
    assert_eq!(trace.last().unwrap().state, S::Idle);
}

#[test]
fn target_at_natural_friction_holds_zero_drive() {
    let (mut ctl, model, mut plant) = running();
    ctl.set_target(Target::Coef { coef_ppm: 400_000 }).unwrap(); // above mu = 0.3
    let out = run(&mut ctl, &model, &mut plant, 100);
    assert_eq!(
        (out.reach, out.amplitude, out.state),
        (Some(Reach::AboveNatural), Amplitude::ZERO, S::Running)
    );
    assert!(out.saturation.integral_frozen);
}

#[test]
fn target_changes_are_bumpless_in_the_feedback_path() {
    let (mut ctl, model, mut plant) = running();
    let before = run(&mut ctl, &model, &mut plant, 1);
    // The same ratio as a coefficient target: nothing moves.
    let coef = (0.5 * ctl.natural_coefficient().to_f64() * 1e6).round() as u32;
    ctl.set_target(Target::Coef { coef_ppm: coef }).unwrap();
    let same = run(&mut ctl, &model, &mut plant, 1);
    assert!((same.amplitude.to_f64() - before.amplitude.to_f64()).abs() < 2e-3);
    assert!((same.correction.to_f64() - before.correction.to_f64()).abs() < 1e-3);
    // A real change: the correction stays continuous, the drive moves at the slew limit.
    ctl.set_target(Target::Reduction {
        reduction_mpct: 30_000,
    })
    .unwrap();
    let after = run(&mut ctl, &model, &mut plant, 1);
    assert!((after.correction.to_f64() - same.correction.to_f64()).abs() < 2e-3);
    let slew = Config::new(&Settings::REFERENCE)
        .unwrap()
        .shaper()
        .slew_step()
        .to_f64();
    assert!((after.amplitude.to_f64() - same.amplitude.to_f64()).abs() <= slew + 1e-9);
    assert!(
        after.amplitude < same.amplitude,
        "less reduction, less drive"
    );
}

#[test]
fn gain_changes_and_reconfiguration_are_bumpless() {
    let (mut ctl, model, mut plant) = running();
    // The plant gets 25 % weaker: mid-transient the PI error is large, and a switch that is
    // not bumpless would jump by the kp change times the error.
    plant.velocity_max = 0.0754 * 0.75;
    ctl.set_target(Target::Reduction {
        reduction_mpct: 40_000,
    })
    .unwrap();
    let mut mid = run(&mut ctl, &model, &mut plant, 1);
    for _ in 0..30 {
        if mid.error.to_f64().abs() > 0.01 {
            break;
        }
        mid = run(&mut ctl, &model, &mut plant, 1);
    }
    assert!(mid.error.to_f64().abs() > 0.01, "{mid:?}");
    let gains = PiGains::new(2.0, 4_000.0, T, 0.5).unwrap();
    let mut switched = ctl;
    switched.set_gains(GainSchedule::constant(gains)).unwrap();
    let inputs = plant.measure();
    let kept = ctl.step(&inputs, &model);
    let new = switched.step(&inputs, &model);
    let kp_now = Config::new(&Settings::REFERENCE)
        .unwrap()
        .gains()
        .fast()
        .kp()
        .to_f64()
        * 0.8;
    let naive_jump = (2.0 - kp_now) * mid.error.to_f64().abs();
    let moved = (new.correction.to_f64() - kept.correction.to_f64()).abs();
    assert!(
        moved < 0.3 * naive_jump,
        "moved {moved}, a non-bumpless switch {naive_jump}"
    );
    // A new configuration (other filters, ramps and gains) between two steps, settled: the
    // filter states, the envelope estimate, mu0 and the supervisor carry over (a fresh
    // controller would restart from idle at zero drive).
    run(&mut ctl, &model, &mut plant, 300);
    let mut other = ctl;
    let settings = Settings {
        tangential_bandwidth_hz: 300.0,
        normal_bandwidth_hz: 50.0,
        kp: 1.0,
        ..Settings::REFERENCE
    };
    other.reconfigure(Config::new(&settings).unwrap());
    let inputs = plant.measure();
    let a = ctl.step(&inputs, &model);
    let b = other.step(&inputs, &model);
    assert_eq!((b.state, b.reason), (S::Running, Reason::RampDone));
    assert!(a.amplitude.to_f64() > 0.5);
    assert!(
        (a.amplitude.to_f64() - b.amplitude.to_f64()).abs() < 2e-3,
        "{a:?}\n{b:?}"
    );
    assert!((a.correction.to_f64() - b.correction.to_f64()).abs() < 2e-3);
    assert_eq!(
        b.natural_coefficient, a.natural_coefficient,
        "same prior: mu0 kept"
    );
}

#[test]
fn force_target_uses_the_measured_load() {
    let (mut ctl, model, mut plant) = setup();
    ctl.set_target(Target::Force { force_mn: 7_200 }).unwrap(); // 0.6 of 0.3 * 40 N
    run(&mut ctl, &model, &mut plant, 100);
    ctl.start().unwrap();
    let out = run(&mut ctl, &model, &mut plant, 400);
    assert!(
        (out.target_ratio.unwrap().to_f64() - 0.6).abs() < 1e-3,
        "{out:?}"
    );
    assert!((plant.ratio() - 0.6).abs() < 0.006, "{}", plant.ratio());
    assert_eq!(out.reach, Some(Reach::Reached));
}

/// Records the hint of every inversion and the amplitude it returned.
struct HintRecorder {
    inner: LittmannModel,
    calls: core::cell::RefCell<Vec<(Q1_31, Q1_31)>>,
}

impl FrictionModel for HintRecorder {
    fn ratio(&self, point: &OperatingPoint, amplitude: Q1_31) -> Result<Q2_30, ModelError> {
        self.inner.ratio(point, amplitude)
    }

    fn invert_from(
        &self,
        point: &OperatingPoint,
        target: Q2_30,
        start: Q1_31,
    ) -> Result<crate::model::Inversion, ModelError> {
        let inversion = self.inner.invert(point, target)?;
        self.calls.borrow_mut().push((start, inversion.amplitude));
        Ok(inversion)
    }
}

#[test]
fn each_inversion_starts_from_the_previous_one_and_a_restart_from_zero() {
    let (mut ctl, inner, mut plant) = setup();
    let model = HintRecorder {
        inner,
        calls: core::cell::RefCell::new(Vec::new()),
    };
    ctl.set_target(HALF).unwrap();
    run(&mut ctl, &model, &mut plant, 100);
    assert!(model.calls.borrow().is_empty(), "no inversion while idle");
    ctl.start().unwrap();
    run(&mut ctl, &model, &mut plant, 200);
    let check = |calls: &[(Q1_31, Q1_31)]| {
        assert!(calls.len() > 100, "{} inversions", calls.len());
        assert_eq!(calls[0].0, Q1_31::ZERO, "the first starts from zero");
        for pair in calls.windows(2) {
            assert_eq!(
                pair[1].0, pair[0].1,
                "a hint that is not the previous answer"
            );
        }
        assert!(calls.last().unwrap().1.to_f64() > 0.5);
    };
    check(&model.calls.borrow());
    ctl.stop().unwrap();
    run(&mut ctl, &model, &mut plant, 400);
    model.calls.borrow_mut().clear();
    ctl.start().unwrap();
    run(&mut ctl, &model, &mut plant, 200);
    check(&model.calls.borrow());
}

/// Records the load of every evaluation; declares (or not) that its load enters as `mu W`.
struct LoadRecorder {
    inner: LittmannModel,
    coulomb_force: bool,
    loads: core::cell::RefCell<Vec<f64>>,
}

impl FrictionModel for LoadRecorder {
    fn ratio(&self, point: &OperatingPoint, amplitude: Q1_31) -> Result<Q2_30, ModelError> {
        self.loads.borrow_mut().push(point.normal_force.to_f64());
        self.inner.ratio(point, amplitude)
    }

    fn load_enters_as_coulomb_force(&self) -> bool {
        self.coulomb_force
    }
}

#[test]
fn a_model_of_the_coulomb_force_sees_the_load_at_the_learned_natural_friction() {
    // Prior mu 0.25, plant mu 0.3: the learned mu0 is 20 % above the model's mu.
    let settings = Settings {
        natural_prior: 0.25,
        ..Settings::REFERENCE
    };
    let record = |coulomb_force| {
        let mut ctl = Controller::new(Config::new(&settings).unwrap());
        let mut plant = Plant::new(0.3, 0.0754 * 0.9, 0.8e-3, T, 3);
        let model = LoadRecorder {
            inner: LittmannModel::new(0.0754),
            coulomb_force,
            loads: core::cell::RefCell::new(Vec::new()),
        };
        ctl.set_target(HALF).unwrap();
        run(&mut ctl, &model, &mut plant, 100);
        ctl.start().unwrap();
        run(&mut ctl, &model, &mut plant, 200);
        let mu0 = ctl.natural_coefficient().to_f64();
        (model.loads.into_inner(), mu0)
    };
    let (plain, mu0) = record(false);
    let (scaled, mu0_again) = record(true);
    // The Littmann law ignores the load, so both runs are the same run.
    assert_eq!(mu0, mu0_again);
    assert!((mu0 / 0.25 - 1.2).abs() < 0.02, "mu0 {mu0}");
    assert_eq!(plain.len(), scaled.len());
    assert!(plain.len() > 100, "{} evaluations", plain.len());
    // mu0 is still learned in the first steps of the ramp (drive below natural_max_drive);
    // compare once it has stopped moving.
    for (w, w_model) in plain.iter().zip(&scaled).skip(plain.len() / 2) {
        let expected = w * mu0 / 0.25;
        // Q16.16 rounding of the scaled load, and mu0's rounding in Q2.30.
        assert!(
            (w_model - expected).abs() < 2.0 / 65536.0,
            "{w_model} vs {expected}"
        );
    }
}

#[test]
fn the_coulomb_load_is_exact_at_its_extremes_and_refuses_what_does_not_fit() {
    use super::controller::{coulomb_factor, coulomb_load};
    let coulomb_load = |w, mu0, mu| coulomb_load(w, coulomb_factor(mu0, mu));
    use super::estimate::MIN_NATURAL_COEF;
    let q16 = |x: f64| Q16_16::from_f64(x).unwrap();
    let q30 = |x: f64| Q2_30::from_f64(x).unwrap();
    for (w, mu0, mu) in [
        (4.155, 0.24, 0.2),
        (1.0 / 65536.0, 0.24, 0.2),
        (0.01, 1.999, 1e-3),
        (32767.0, 1e-3, 1.999),
        (16000.0, 0.2, 0.1),
        (1.0, 0.3, 0.3),
    ] {
        let got = coulomb_load(q16(w), q30(mu0), q30(mu)).unwrap().to_f64();
        let exact = q16(w).to_f64() * q30(mu0).to_f64() / q30(mu).to_f64();
        // Half a step of rounding, plus the factor's half-ULP (2^-31) times W < 2^15 N: one step.
        assert!(
            (got - exact).abs() <= 1.5 / 65536.0,
            "{w} {mu0} {mu}: {got} vs {exact}"
        );
    }
    // Equal coefficients: the load unchanged, bit for bit.
    assert_eq!(
        coulomb_load(q16(4.155), q30(0.2), q30(0.2)).unwrap(),
        q16(4.155)
    );
    // Coefficients below the learner's floor count as the floor (never a division by zero).
    assert_eq!(
        coulomb_load(q16(2.0), Q2_30::ZERO, Q2_30::ZERO).unwrap(),
        coulomb_load(q16(2.0), MIN_NATURAL_COEF, MIN_NATURAL_COEF).unwrap()
    );
    // W mu0 / mu >= 32768 N does not fit Q16.16: an error, not a saturated load.
    assert!(matches!(
        coulomb_load(q16(20000.0), q30(0.4), q30(0.2)),
        Err(ModelError::OutOfDomain { .. })
    ));
}

#[test]
fn the_drive_waits_until_the_natural_friction_is_learned_for_natural_learn_s() {
    // Debounce 2 ms (20 steps), then 3 ms (30 samples) of learning before the drive may start.
    let settings = Settings {
        natural_learn_s: 3e-3,
        ..Settings::REFERENCE
    };
    let mut ctl = Controller::new(Config::new(&settings).unwrap());
    let model = LittmannModel::new(0.0754);
    let mut plant = Plant::new(0.3, 0.0754 * 0.9, 0.8e-3, T, 3);
    ctl.set_target(HALF).unwrap();
    // Started before sliding is confirmed: armed, idle.
    ctl.start().unwrap();
    let mut first_drive = None;
    for k in 1..=200 {
        let out = run(&mut ctl, &model, &mut plant, 1);
        if first_drive.is_none() && out.amplitude > Amplitude::ZERO {
            first_drive = Some((k, out.reason));
        }
    }
    let (k, reason) = first_drive.expect("the run starts once mu0 is learned");
    // Sliding is confirmed at step 20 or 21; 30 samples later the ramp-up begins.
    assert!((49..=52).contains(&k), "first drive at step {k}");
    assert_eq!(reason, Reason::SlidingResumed);
    // Without the wait the drive starts as soon as sliding is confirmed.
    let (mut ctl, model, mut plant) = setup();
    ctl.set_target(HALF).unwrap();
    ctl.start().unwrap();
    let first =
        (1..=200).find(|_| run(&mut ctl, &model, &mut plant, 1).amplitude > Amplitude::ZERO);
    assert!(matches!(first, Some(20..=22)), "{first:?}");
}

#[test]
fn a_run_going_on_is_not_stopped_by_a_natural_friction_learned_afresh() {
    let (mut ctl, model, mut plant) = running();
    // A new prior restarts the learning; the drive is on, so nothing is learned, and the run
    // must go on rather than wait.
    let settings = Settings {
        natural_prior: 0.25,
        natural_learn_s: 3e-3,
        ..Settings::REFERENCE
    };
    ctl.reconfigure(Config::new(&settings).unwrap());
    let out = run(&mut ctl, &model, &mut plant, 100);
    assert_eq!(out.state, S::Running);
    assert!(out.amplitude.to_f64() > 0.3);
}

#[test]
fn bad_sensor_lag_and_learning_times_are_named() {
    let r = Settings::REFERENCE;
    for lag in [-1e-4, f64::NAN] {
        assert!(matches!(
            Config::new(&Settings {
                sensor_lag_s: lag,
                ..r
            }),
            Err(super::config::ConfigError::Filter {
                setting: "sensor_lag_s",
                ..
            })
        ));
    }
    for learn in [-1e-3, f64::INFINITY, f64::NAN] {
        assert_eq!(
            Config::new(&Settings {
                natural_learn_s: learn,
                ..r
            }),
            Err(super::config::ConfigError::OutOfRange {
                setting: "natural_learn_s"
            })
        );
    }
    assert!(
        Config::new(&Settings {
            sensor_lag_s: 79.6e-6,
            ..r
        })
        .is_ok()
    );
}

/// Steps with the drive replaced by `applied` (as the station does while the resonance
/// search drives): the plant gets `applied`, the controller is told so. Returns mu0.
fn run_replaced(
    ctl: &mut Controller,
    model: &LittmannModel,
    plant: &mut Plant,
    applied: f64,
    steps: usize,
) -> f64 {
    let applied = Q1_31::from_f64(applied).unwrap();
    for _ in 0..steps {
        let out = ctl.step(&plant.measure(), model);
        assert_eq!(
            out.amplitude,
            Amplitude::ZERO,
            "idle: the controller commands nothing"
        );
        ctl.drive_replaced(applied);
        plant.advance(Amplitude::from_command(applied));
    }
    ctl.natural_coefficient().to_f64()
}

#[test]
fn a_drive_the_controller_did_not_command_stops_mu0_learning_where_it_changes_friction() {
    let (mut ctl, model, mut plant) = setup();
    ctl.set_target(HALF).unwrap();
    run(&mut ctl, &model, &mut plant, 60);
    let learned = ctl.natural_coefficient().to_f64();
    assert!((learned - 0.3).abs() < 1e-3, "mu0 {learned}");
    // The search's drive in the Littmann dead zone (0.3 x 0.0754 m/s < 0.038 m/s): friction
    // stays natural by the model, so mu0 is learned on; the plant's mu moves and mu0 follows.
    plant.mu = 0.33;
    let followed = run_replaced(&mut ctl, &model, &mut plant, 0.3, 100);
    assert!(plant.ratio() == 1.0 && followed > 0.31, "mu0 {followed}");
    // A drive above the dead zone lowers the friction: mu0 must not learn it. (It learns on
    // while the envelope estimate rises through the model's dead zone, which the model
    // leaves earlier than this plant: 0.0754 against 0.068 m/s at full drive.)
    let mut held = followed;
    while plant.ratio() == 1.0 {
        held = run_replaced(&mut ctl, &model, &mut plant, 0.9, 1);
    }
    let after = run_replaced(&mut ctl, &model, &mut plant, 0.9, 100);
    assert!(plant.ratio() < 0.8, "the plant's friction is reduced");
    assert_eq!(
        after, held,
        "mu0 held while the replaced drive reduces friction"
    );
    // Without being told, the controller would have taken the reduced friction for mu0.
    let (mut blind, _, mut blind_plant) = setup();
    blind.set_target(HALF).unwrap();
    run(&mut blind, &model, &mut blind_plant, 60);
    for _ in 0..100 {
        blind.step(&blind_plant.measure(), &model);
        blind_plant.advance(Amplitude::from_command(Q1_31::from_f64(0.9).unwrap()));
    }
    assert!(blind.natural_coefficient().to_f64() < 0.28);
    // The drive off again: the filtered readings lag the envelope, so mu0 waits until the
    // envelope estimate has died out (to 1e-3: about 7 tau, 54 steps), then learns again.
    let decaying = run_replaced(&mut ctl, &model, &mut plant, 0.0, 50);
    assert_eq!(decaying, held, "still vibrating, or the readings still lag");
    run(&mut ctl, &model, &mut plant, 200);
    let relearned = ctl.natural_coefficient().to_f64();
    assert!(relearned > held + 0.002, "mu0 {relearned}, held {held}");
}
