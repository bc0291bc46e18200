use super::*;
use crate::fx::Q2_30;
use crate::resonance::phasor::Phasor;
use crate::resonance::stack::StackSettings;
use crate::resonance::testkit::{Dynamics, Resonator, window_samples};

const CLOCK: TimerClock = TimerClock::G474_TIM1;
const FS: u32 = 1_000_000;

fn config(settings: &TrackerSettings) -> TrackerConfig {
    let stack = StackModel::new(&StackSettings::REFERENCE).unwrap();
    TrackerConfig::new(settings, stack, FS).unwrap()
}

fn amplitude(a: f64) -> Amplitude {
    Amplitude::new(Q2_30::from_f64(a).unwrap()).unwrap()
}

fn hz(f: Frequency) -> f64 {
    f64::from(f.millihertz()) / 1000.0
}

/// Runs the loop on `plant` for `seconds`; returns (time, drive Hz, f0 Hz) per window.
fn run(
    tracker: &mut Tracker,
    plant: &mut Resonator,
    a: Amplitude,
    seconds: f64,
) -> Vec<(f64, f64, f64)> {
    let mut trace = Vec::new();
    while plant.t_s < seconds {
        let drive = tracker.tuning().frequency;
        let window = plant.window(drive, a, window_samples(drive), f64::from(FS));
        tracker.update(&window, a).unwrap();
        trace.push((
            plant.t_s,
            hz(tracker.tuning().frequency),
            plant.resonance_hz(),
        ));
    }
    trace
}

/// First time after which |drive - f0| stays within `band_hz`.
fn settled_at(trace: &[(f64, f64, f64)], band_hz: f64) -> Option<f64> {
    let last_out = trace
        .iter()
        .rposition(|&(_, f, f0)| (f - f0).abs() > band_hz);
    match last_out {
        None => Some(0.0),
        Some(i) if i + 1 < trace.len() => Some(trace[i + 1].0),
        Some(_) => None,
    }
}

#[test]
fn pulls_in_from_either_side_on_both_plant_dynamics() {
    let mut report = Vec::new();
    for dynamics in [Dynamics::InstantPhase, Dynamics::Lagged] {
        for offset_hz in [-800.0, -300.0, 150.0, 500.0, 1500.0] {
            let mut plant = Resonator::reference(dynamics);
            let start = 40_000.0 + offset_hz;
            plant.settle(start, 0.1);
            let mut tracker = Tracker::new(
                config(&TrackerSettings::PULL_IN),
                Frequency::from_millihertz((start * 1000.0) as u32),
                CLOCK,
            )
            .unwrap();
            let trace = run(&mut tracker, &mut plant, amplitude(0.1), 0.010);
            let t = settled_at(&trace, 10.0).expect("settles");
            report.push(format!("{dynamics:?} {offset_hz:+} Hz: {:.2} ms", t * 1e3));
            assert!(t < 4.0e-3, "{dynamics:?} from {offset_hz:+} Hz: {t} s");
            let (_, f, f0) = *trace.last().unwrap();
            assert!(
                (f - f0).abs() < 1.0,
                "{dynamics:?} {offset_hz}: ends {f} vs {f0}"
            );
        }
    }
    eprintln!("pull-in to +-10 Hz: {}", report.join(", "));
}

#[test]
fn follows_a_drift_of_one_percent_per_second() {
    for dynamics in [Dynamics::InstantPhase, Dynamics::Lagged] {
        let mut plant = Resonator::reference(dynamics);
        plant.drift_hz_per_s = 400.0;
        plant.settle(40_000.0, 0.5);
        let mut tracker = Tracker::new(
            config(&TrackerSettings::OPERATION),
            Frequency::from_hz(40_000),
            CLOCK,
        )
        .unwrap();
        let trace = run(&mut tracker, &mut plant, amplitude(0.5), 0.3);
        let steady: Vec<f64> = trace
            .iter()
            .filter(|&&(t, _, _)| t > 0.05)
            .map(|&(_, f, f0)| f - f0)
            .collect();
        let worst = steady.iter().fold(0.0f64, |m, e| m.max(e.abs()));
        let mean = steady.iter().sum::<f64>() / steady.len() as f64;
        // rho / Ki = 0.13 Hz of lag, plus the timer grid (0.59 Hz steps near 40 kHz).
        assert!(
            worst < 1.0 && mean.abs() < 0.5,
            "{dynamics:?}: worst {worst}, mean {mean}"
        );
    }
}

#[test]
fn the_correction_rate_is_bounded() {
    let settings = TrackerSettings {
        max_rate_hz_per_s: 2000.0,
        ..TrackerSettings::OPERATION
    };
    let mut plant = Resonator::reference(Dynamics::InstantPhase);
    plant.settle(41_000.0, 0.3);
    let mut tracker = Tracker::new(config(&settings), Frequency::from_hz(41_000), CLOCK).unwrap();
    let trace = run(&mut tracker, &mut plant, amplitude(0.3), 0.1);
    // Per window: at most R T (0.2 Hz per 100 us) plus the timer's rounding of both ends
    // (half a 0.64 Hz step each).
    let mut previous = (0.0, 41_000.0);
    for &(t, f, _) in &trace {
        let allowed = 2000.0 * (t - previous.0) + 0.65;
        assert!(
            (f - previous.1).abs() <= allowed,
            "{t}: {} -> {f}",
            previous.1
        );
        previous = (t, f);
    }
    // Over 0.1 s the drive came down by R t = 200 Hz, no more and not much less.
    let moved = 41_000.0 - trace.last().unwrap().1;
    assert!((199.0..=200.7).contains(&moved), "{moved}");
    assert!(config(&settings).max_step_mhz(100) == 200);
}

#[test]
fn a_resonance_beyond_the_limits_is_a_fault_not_a_frequency() {
    let mut plant = Resonator::reference(Dynamics::InstantPhase);
    plant.f0_hz = 45_000.0;
    plant.settle(43_900.0, 0.3);
    let mut tracker = Tracker::new(
        config(&TrackerSettings::PULL_IN),
        Frequency::from_hz(43_900),
        CLOCK,
    )
    .unwrap();
    let a = amplitude(0.3);
    let mut fault = None;
    for k in 0..200 {
        let drive = tracker.tuning().frequency;
        let window = plant.window(drive, a, window_samples(drive), f64::from(FS));
        match tracker.update(&window, a) {
            Ok(status) => assert!(hz(status.tuning.frequency) <= 44_000.7),
            Err(e) => {
                fault = Some((k, e));
                break;
            }
        }
    }
    let (windows, fault) = fault.expect("a fault");
    assert_eq!(fault, ResonanceFault::AtFrequencyLimit);
    assert!((48..60).contains(&windows), "{windows}");
}

#[test]
fn no_current_is_a_fault_and_no_drive_holds() {
    let mut tracker = Tracker::new(
        config(&TrackerSettings::OPERATION),
        Frequency::from_hz(40_000),
        CLOCK,
    )
    .unwrap();
    let a = amplitude(0.2);
    // A disconnected stack: only a little noise on the lock-in's output.
    let noise = Demodulated {
        phasor: Phasor::new(Q2_30::from_bits(1 << 12), Q2_30::from_bits(-3 << 11)),
        samples: 100,
    };
    assert!(!tracker.update(&noise, a).unwrap().locked);
    assert!(tracker.update(&noise, a).is_ok());
    assert_eq!(tracker.update(&noise, a), Err(ResonanceFault::NoCurrent));
    assert_eq!(tracker.tuning().frequency, Frequency::from_hz(40_000));
    // Drive off: nothing to measure, the frequency holds and no fault builds up.
    let mut idle = Tracker::new(
        config(&TrackerSettings::OPERATION),
        Frequency::from_hz(40_000),
        CLOCK,
    )
    .unwrap();
    for _ in 0..10 {
        let status = idle.update(&noise, Amplitude::ZERO).unwrap();
        assert_eq!(status.tuning.frequency, Frequency::from_hz(40_000));
    }
}

#[test]
fn locks_only_after_consecutive_windows_on_resonance() {
    let mut plant = Resonator::reference(Dynamics::InstantPhase);
    plant.settle(40_000.0, 0.3);
    let mut tracker = Tracker::new(
        config(&TrackerSettings::OPERATION),
        Frequency::from_hz(40_000),
        CLOCK,
    )
    .unwrap();
    let a = amplitude(0.3);
    let mut locked_at = None;
    for k in 0..10 {
        let window = plant.window(tracker.tuning().frequency, a, 100, f64::from(FS));
        let status = tracker.update(&window, a).unwrap();
        assert!(status.detuning.to_f64().abs() < 0.01);
        if status.locked && locked_at.is_none() {
            locked_at = Some(k);
        }
    }
    assert_eq!(locked_at, Some(4)); // the 5th window
}

#[test]
fn settings_are_checked_and_reconfiguring_clamps() {
    let stack = StackModel::new(&StackSettings::REFERENCE).unwrap();
    let base = TrackerSettings::OPERATION;
    for (bad, error) in [
        (
            TrackerSettings {
                proportional: 2.0,
                ..base
            },
            ResonanceError::Setting,
        ),
        (
            TrackerSettings {
                integral_per_s: f64::NAN,
                ..base
            },
            ResonanceError::Setting,
        ),
        (
            TrackerSettings {
                max_rate_hz_per_s: 0.0,
                ..base
            },
            ResonanceError::Setting,
        ),
        (
            TrackerSettings {
                lock_detuning: 17.0,
                ..base
            },
            ResonanceError::Setting,
        ),
        (
            TrackerSettings {
                lock_windows: 0,
                ..base
            },
            ResonanceError::Setting,
        ),
        (
            TrackerSettings {
                min_hz: 45_000.0,
                ..base
            },
            ResonanceError::Band,
        ),
        (
            TrackerSettings {
                max_hz: 61_000.0,
                ..base
            },
            ResonanceError::Band,
        ),
    ] {
        assert_eq!(TrackerConfig::new(&bad, stack, FS), Err(error), "{bad:?}");
    }
    let mut tracker = Tracker::new(config(&base), Frequency::from_hz(50_000), CLOCK).unwrap();
    // 44 kHz rounded to the timer's grid.
    assert_eq!(tracker.tuning().frequency.millihertz(), 44_000_129);
    let narrow = TrackerSettings {
        min_hz: 39_000.0,
        max_hz: 41_000.0,
        ..base
    };
    tracker.reconfigure(config(&narrow)).unwrap();
    assert!(tracker.tuning().frequency.millihertz().abs_diff(41_000_000) < 300);
    assert_eq!(config(&base).stack(), stack);
}

/// A window at zero amplitude (the drive paused) ends the loop's history: the next window's
/// proportional term must not difference against the error from before the pause, so the
/// loop resumes exactly as a loop started afresh at its frequency would.
#[test]
fn a_zero_amplitude_window_restarts_the_loop_as_new() {
    let mut plant = Resonator::reference(Dynamics::InstantPhase);
    let start = 40_600.0;
    plant.settle(start, 0.3);
    let settings = TrackerSettings::OPERATION;
    let mut tracker = Tracker::new(
        config(&settings),
        Frequency::from_millihertz((start * 1000.0) as u32),
        CLOCK,
    )
    .unwrap();
    let a = amplitude(0.3);
    for _ in 0..3 {
        let drive = tracker.tuning().frequency;
        let window = plant.window(drive, a, window_samples(drive), f64::from(FS));
        tracker.update(&window, a).unwrap();
    }
    // Hundreds of hertz off resonance: the error before the pause is large.
    let before = tracker.tuning().frequency;
    assert!((hz(before) - 40_000.0).abs() > 100.0, "{}", hz(before));
    let drive = tracker.tuning().frequency;
    let paused = plant.window(drive, Amplitude::ZERO, window_samples(drive), f64::from(FS));
    tracker.update(&paused, Amplitude::ZERO).unwrap();
    assert_eq!(tracker.tuning().frequency, before, "the frequency holds");
    let mut fresh = Tracker::new(
        config(&settings),
        Frequency::from_millihertz(tracker.state.command_mhz as u32),
        CLOCK,
    )
    .unwrap();
    assert_eq!(tracker, fresh);
    let window = plant.window(drive, a, window_samples(drive), f64::from(FS));
    tracker.update(&window, a).unwrap();
    fresh.update(&window, a).unwrap();
    assert_eq!(tracker.tuning(), fresh.tuning());
}
