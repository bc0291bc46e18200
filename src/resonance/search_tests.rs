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
    while plant.t_s < 0.05 {
        let drive = search.tuning().frequency;
        let window = plant.window(drive, search.amplitude(), window_samples(drive), 1e6);
        match search.update(&window) {
            SearchStep::Drive(tuning) => assert!(tuning.frequency.in_band()),
            outcome => return (outcome, plant.t_s),
        }
    }
    panic!("the search neither locked nor failed in 50 ms");
}

#[test]
fn locks_within_10_ms_to_0_1_percent_on_both_plant_dynamics() {
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
            assert!(t <= 0.010, "{dynamics:?} f0 {f0}: locked after {t} s");
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
    assert_eq!(windows, 2 * config(0.10).plan().points);
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
    assert!(t < 6e-3, "{t}");
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
    assert!(t > 6e-3 && t < 13e-3, "{t}");
}

#[test]
fn the_plan_covers_the_band_and_one_time_constant_beyond() {
    let plan = config(0.10).plan();
    // From 36 kHz / 1.01 (one step below the band) in steps of 1 % (one bandwidth) past
    // 44 kHz: 22 steps; then tau = 0.8 ms of 0.2 ms points: 4 more.
    assert_eq!(plan.start_mhz, 35_643_564);
    assert_eq!(plan.relative_step_q32, 42_949_673);
    assert_eq!(plan.points, 27);
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
