use super::*;
use crate::resonance::phasor::Phasor;
use crate::resonance::testkit::{Dynamics, Resonator, window_samples};

const CLOCK: TimerClock = TimerClock::G474_TIM1;
const LOCK_IN: LockInConfig = LockInConfig {
    sample_rate_hz: 1_000_000,
    periods_per_window: 4,
    sense_delay_ns: 0,
};

fn config(relative_band: f64) -> SearchConfig {
    let settings = SearchSettings::around(&StackSettings::REFERENCE, relative_band);
    SearchConfig::new(&settings, &StackSettings::REFERENCE, &LOCK_IN).unwrap()
}

fn hz(f: Frequency) -> f64 {
    f64::from(f.millihertz()) / 1000.0
}

/// Runs a search on the fixture until it ends (or 50 ms); returns the outcome and the time.
fn run(search: &mut Search, plant: &mut Resonator) -> (SearchStep, f64) {
    run_for(search, plant, 0.05)
}

/// Runs a search on the fixture until it ends (or `limit_s`).
fn run_for(search: &mut Search, plant: &mut Resonator, limit_s: f64) -> (SearchStep, f64) {
    while plant.t_s < limit_s {
        let drive = search.tuning().frequency;
        let window = plant.window(drive, search.amplitude(), window_samples(drive), 1e6);
        match search.update(&window) {
            SearchStep::Drive(tuning) => assert!(tuning.frequency.in_band()),
            outcome => return (outcome, plant.t_s),
        }
    }
    panic!("the search neither locked nor failed in {limit_s} s");
}

#[test]
fn locks_within_the_rule_s_time_to_0_1_percent_on_both_plant_dynamics() {
    let mut worst = (0.0f64, 0.0f64);
    for dynamics in [Dynamics::InstantPhase, Dynamics::Lagged] {
        // f0 across the +-10 % band, edges included.
        for f0 in [
            36_000.0, 36_789.0, 38_500.0, 40_000.0, 41_234.0, 43_100.0, 44_000.0,
        ] {
            let mut plant = Resonator::reference(dynamics);
            plant.f0_hz = f0;
            let mut search = Search::new(config(0.10), CLOCK).unwrap();
            let (outcome, t) = run(&mut search, &mut plant);
            let SearchStep::Locked(lock) = outcome else {
                panic!("{dynamics:?} f0 {f0}: {outcome:?}");
            };
            let error = (hz(lock.tuning.frequency) - f0).abs() / f0;
            assert!(
                t <= config(0.10).lock_bound_s(),
                "{dynamics:?} f0 {f0}: locked after {t} s"
            );
            assert!(error <= 0.001, "{dynamics:?} f0 {f0}: {error}");
            // The estimate carries what is left of the envelope transient: 20 Hz is 0.05 %.
            assert!(
                (hz(lock.resonance) - f0).abs() < 20.0,
                "{dynamics:?} {f0} {lock:?}"
            );
            assert_eq!(lock.elapsed_samples, (t * 1e6).round() as u64);
            worst = (worst.0.max(t), worst.1.max(error));
        }
    }
    eprintln!(
        "fixture, +-10 %: worst lock time {:.2} ms, worst error {:.4} %",
        worst.0 * 1e3,
        worst.1 * 100.0
    );
}

#[test]
fn a_disconnected_stack_is_a_fault_after_the_sweep() {
    let mut search = Search::new(config(0.10), CLOCK).unwrap();
    // A little noise out of the lock-in: no current.
    let noise = Demodulated {
        phasor: Phasor::new(Q2_30::from_bits(3 << 12), Q2_30::from_bits(-(1 << 13))),
        samples: 100,
    };
    let mut outcome = SearchStep::Drive(search.tuning());
    let mut windows = 0;
    while let SearchStep::Drive(_) = outcome {
        outcome = search.update(&noise);
        windows += 1;
    }
    assert_eq!(outcome, SearchStep::Failed(ResonanceFault::NoCurrent));
    let plan = config(0.10).plan();
    assert_eq!(
        windows,
        (plan.settle_windows + plan.measure_windows) * plan.points
    );
    // The outcome sticks.
    assert_eq!(search.update(&noise), outcome);
}

#[test]
fn a_capacitor_without_resonance_is_a_fault() {
    // C0 draws current but there is no motional branch to speak of.
    let mut plant = Resonator::reference(Dynamics::Lagged);
    plant.r1 = 1e5;
    let mut search = Search::new(config(0.10), CLOCK).unwrap();
    let (outcome, t) = run(&mut search, &mut plant);
    assert_eq!(outcome, SearchStep::Failed(ResonanceFault::NoResonance));
    // The sweep's points at their dwell (the lowest frequency's windows are the longest).
    let plan = config(0.10).plan();
    let sweep_s = f64::from((plan.settle_windows + plan.measure_windows) * plan.points) * 4e3
        / f64::from(plan.start_mhz);
    assert!(t <= sweep_s, "{t} {sweep_s}");
    // A resonance outside the band: the conductance rises toward the band's end.
    let mut plant = Resonator::reference(Dynamics::InstantPhase);
    plant.f0_hz = 48_000.0;
    let mut search = Search::new(config(0.05), CLOCK).unwrap();
    let (outcome, _) = run(&mut search, &mut plant);
    assert_eq!(outcome, SearchStep::Failed(ResonanceFault::NoResonance));
}

#[test]
fn a_loop_that_cannot_settle_times_out() {
    let stack = StackSettings::REFERENCE;
    let mut settings = SearchSettings::around(&stack, 0.10);
    settings.pull_in.proportional = 0.0;
    settings.pull_in.integral_per_s = 0.0;
    let config = SearchConfig::new(&settings, &stack, &LOCK_IN).unwrap();
    // The lagged plant's sweep peak is 500 Hz late: far outside the lock band.
    let mut plant = Resonator::reference(Dynamics::Lagged);
    plant.f0_hz = 41_000.0;
    let mut search = Search::new(config, CLOCK).unwrap();
    let (outcome, t) = run(&mut search, &mut plant);
    assert_eq!(outcome, SearchStep::Failed(ResonanceFault::PullInTimeout));
    // The time-out counts from the pull-in's start, after the sweep.
    let timeout_s = settings.pull_in_timeout_s;
    assert!(
        t > timeout_s && t < config.lock_bound_s() + timeout_s,
        "{t}"
    );
}

#[test]
fn the_plan_covers_the_band_and_one_time_constant_beyond() {
    let plan = config(0.10).plan();
    // From 36 kHz / 1.01 (one step below the band) in steps of 1 % (one bandwidth) past
    // 44 kHz: 22 steps; each point dwells tau / 2 = 0.4 ms (4 windows of 0.1 ms: the sweep
    // lags 2 bandwidths), so tau = 0.8 ms is 2 more points.
    assert_eq!(plan.start_mhz, 35_643_564);
    assert_eq!(plan.relative_step_q32, 42_949_673);
    assert_eq!(plan.settle_windows + plan.measure_windows, 4);
    assert_eq!(plan.points, 25);
    assert_eq!(
        config(0.10).amplitude(),
        Amplitude::from_ratio(1, 10).unwrap()
    );
    // The whole 20-60 kHz band: the overrun stops at 60 kHz.
    let plan = config(0.5).plan();
    let last = f64::from(plan.start_mhz) * 1.01f64.powi(i32::from(plan.points) - 1);
    assert!(last <= 60_000_000.0 && last * 1.01 > 60_000_000.0, "{last}");
}

#[test]
fn settings_out_of_range_are_refused() {
    let stack = StackSettings::REFERENCE;
    let base = SearchSettings::around(&stack, 0.10);
    for (bad, error) in [
        (
            SearchSettings {
                min_hz: 45_000.0,
                ..base
            },
            ResonanceError::Band,
        ),
        (
            SearchSettings {
                max_hz: 60_001.0,
                ..base
            },
            ResonanceError::Band,
        ),
        (
            SearchSettings {
                relative_step: 0.0,
                ..base
            },
            ResonanceError::Band,
        ),
        (
            SearchSettings {
                relative_step: 0.2,
                ..base
            },
            ResonanceError::Band,
        ),
        (
            SearchSettings {
                relative_step: 1e-4,
                min_hz: 20_000.0,
                max_hz: 60_000.0,
                ..base
            },
            ResonanceError::Band,
        ),
        (
            SearchSettings {
                amplitude: 0.0,
                ..base
            },
            ResonanceError::Setting,
        ),
        (
            SearchSettings {
                amplitude: 1.5,
                ..base
            },
            ResonanceError::Setting,
        ),
        (
            SearchSettings {
                measure_windows: 0,
                ..base
            },
            ResonanceError::Setting,
        ),
        (
            SearchSettings {
                pull_in_timeout_s: f64::NAN,
                ..base
            },
            ResonanceError::Setting,
        ),
    ] {
        assert_eq!(
            SearchConfig::new(&bad, &stack, &LOCK_IN),
            Err(error),
            "{bad:?}"
        );
    }
}

/// The reference stack on another resonator, as `sonolube scene NAME --resonators` builds it:
/// the same motional inductance L1 = Q R1 / w0 (modal mass over the squared force factor), so
/// R1 = w0 L1 / Q, and a full-scale voltage that keeps the motional current at full scale
/// where the reference's is (1.7 A).
fn resonator_stack(f0_hz: f64, q: f64) -> (StackSettings, Resonator) {
    let reference = StackSettings::REFERENCE;
    let inductance_h = 100.0 * 3.1 / (std::f64::consts::TAU * 40_000.0);
    let r1 = std::f64::consts::TAU * f0_hz * inductance_h / q;
    let v_fs = (5.25 * r1 / 3.1).min(15.0);
    let stack = StackSettings {
        resonance_hz: f0_hz,
        quality_factor: q,
        full_scale_voltage_v: v_fs,
        ..reference
    };
    let mut plant = Resonator::reference(Dynamics::Lagged);
    plant.f0_hz = f0_hz;
    plant.q = q;
    plant.r1 = r1;
    plant.v_fs = v_fs;
    (stack, plant)
}

/// The search's time is set by the resonator: on the lagging (real) resonator at Q 300 and
/// at Q 30, from 20 to 60 kHz, with f0 anywhere in the +-10 % band, it locks within the
/// time its rule predicts ([`SearchConfig::lock_bound_s`]: the sweep at one bandwidth per
/// `tau / 2`, then the pull-in's decay at `(1 + Kp) / 2 tau` from the sweep's lag and the
/// hold), on resonance to within the lock band. With the gains of before (Ki 3000 /s, a
/// dwell of one window a bandwidth) no Q 300 search locked (docs/resonance.md).
#[test]
fn locks_at_q_300_and_q_30_within_the_time_the_rule_predicts() {
    for (f0, q) in [
        (20_000.0, 300.0),
        (40_000.0, 300.0),
        (60_000.0, 300.0),
        (20_000.0, 30.0),
        (40_000.0, 30.0),
        (60_000.0, 30.0),
    ] {
        let (stack, _) = resonator_stack(f0, q);
        let settings = SearchSettings::around(&stack, 0.10);
        let config = SearchConfig::new(&settings, &stack, &LOCK_IN).unwrap();
        let bound_s = config.lock_bound_s();
        let half_bandwidth = f0 / (2.0 * q);
        for offset in [-0.09, -0.03, 0.0, 0.05, 0.09] {
            let (_, mut plant) = resonator_stack(f0, q);
            // Within the timer's band: at its very edge the loop's command rounds past it.
            plant.f0_hz =
                (f0 * (1.0 + offset)).clamp(20_000.0 + half_bandwidth, 60_000.0 - half_bandwidth);
            let mut search = Search::new(config, CLOCK).unwrap();
            let (outcome, t) = run_for(&mut search, &mut plant, 2.0 * bound_s);
            let SearchStep::Locked(lock) = outcome else {
                panic!("f0 {f0} Q {q} offset {offset}: {outcome:?} after {t} s");
            };
            let detuning = (hz(lock.tuning.frequency) - plant.f0_hz) / half_bandwidth;
            eprintln!(
                "f0 {f0} Q {q} offset {offset:+}: locked after {:.2} ms (rule {:.2} ms), {detuning:+.3} half-bandwidths",
                t * 1e3,
                bound_s * 1e3
            );
            assert!(
                t <= bound_s,
                "f0 {f0} Q {q} offset {offset}: {t} s > {bound_s} s"
            );
            assert!(
                detuning.abs() <= 0.2,
                "f0 {f0} Q {q} offset {offset}: {detuning}"
            );
        }
    }
}
