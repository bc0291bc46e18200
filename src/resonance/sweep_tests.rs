use super::*;
use crate::drive::Amplitude;
use crate::resonance::phasor::Phasor;
use crate::resonance::testkit::{Dynamics, Resonator, window_samples};

const CLOCK: TimerClock = TimerClock::G474_TIM1;

fn plan(start_hz: u32, relative_step: f64, points: u16, settle: u16, measure: u16) -> SweepPlan {
    SweepPlan {
        start_mhz: start_hz * 1000,
        relative_step_q32: (relative_step * 4_294_967_296.0).round() as u32,
        points,
        settle_windows: settle,
        measure_windows: measure,
        stop_past_peak: 0,
        start_up: 0,
        min_peak: Q2_30::ZERO,
    }
}

/// Runs `plan` on `plant` (1 MSPS, 4-period windows) at amplitude 0.1; returns the result,
/// every point and the time taken.
fn run(plan: SweepPlan, plant: &mut Resonator) -> (SweepResult, Vec<SweepPoint>, f64) {
    let amplitude = Amplitude::from_ratio(1, 10).unwrap();
    let mut sweep = Sweep::new(plan, CLOCK).unwrap();
    let mut points = Vec::new();
    loop {
        let drive = sweep.tuning().frequency;
        let window = plant.window(drive, amplitude, window_samples(drive), 1e6);
        let (point, progress) = sweep.update(&window);
        points.extend(point);
        if let SweepProgress::Done(result) = progress {
            return (result, points, plant.t_s);
        }
    }
}

fn hz(f: Frequency) -> f64 {
    f64::from(f.millihertz()) / 1000.0
}

#[test]
fn a_settled_sweep_finds_the_conductance_peak() {
    for f0 in [38_123.0, 40_000.0, 41_777.0] {
        for dynamics in [Dynamics::InstantPhase, Dynamics::Lagged] {
            let mut plant = Resonator::reference(dynamics);
            plant.f0_hz = f0;
            // 4 tau of settling per point (32 windows of 4 periods), one bandwidth apart.
            let (result, points, _) = run(plan(36_000, 0.01, 21, 32, 2), &mut plant);
            assert_eq!(points.len(), 21);
            assert!(result.best_index > 0 && result.best_index < 20);
            // The reciprocal parabola is exact for a settled Lorentzian in x; what is left is
            // x's curvature in f and 2 % of unsettled transient.
            let error = hz(result.peak) - f0;
            assert!(error.abs() < 10.0, "{dynamics:?} {f0}: {error}");
        }
    }
}

#[test]
fn the_conductance_peaks_at_f0_where_the_current_magnitude_does_not() {
    // A stack with a large C0 (1.5 uF): |I| peaks well away from f0, G does not.
    let mut plant = Resonator::reference(Dynamics::Lagged);
    plant.c0 = 1.5e-6;
    let (result, points, _) = run(plan(39_000, 0.00125, 41, 32, 2), &mut plant);
    assert!(
        (hz(result.peak) - 40_000.0).abs() < 5.0,
        "{:?}",
        result.peak
    );
    // The magnitude of the same settled currents, point by point.
    let magnitude_peak = points
        .iter()
        .map(|p| {
            let f = f64::from(p.millihertz) / 1000.0;
            let mut settled = plant.clone();
            settled.settle(f, 0.1);
            let (re, im) = settled.current_fs(f, 0.1);
            (re.hypot(im), f)
        })
        .fold((0.0, 0.0), |best, x| if x.0 > best.0 { x } else { best })
        .1;
    assert!(
        (magnitude_peak - 40_000.0).abs() > 100.0,
        "|I| peaks at {magnitude_peak}"
    );
}

#[test]
fn a_fast_sweep_lags_by_about_tau_times_its_rate() {
    // One bandwidth (about 400 Hz) per 0.2 ms: 2 Hz/us, tau = 0.8 ms. The peak comes late, by
    // less than the overrun of one tau (4 points), and never early.
    for dynamics in [Dynamics::InstantPhase, Dynamics::Lagged] {
        let mut lags = Vec::new();
        for f0 in [36_300.0, 38_000.0, 40_000.0, 42_345.0, 44_000.0] {
            let mut plant = Resonator::reference(dynamics);
            plant.f0_hz = f0;
            let (result, _, t) = run(plan(36_000, 0.01, 25, 1, 1), &mut plant);
            assert!(t < 5.2e-3, "{t}");
            let lag = hz(result.peak) - f0;
            assert!(lag > 0.0 && lag < 1600.0, "{dynamics:?} {f0}: {lag}");
            lags.push(lag.round());
        }
        eprintln!("{dynamics:?}: coarse sweep lag {lags:?} Hz");
    }
}

#[test]
fn dwell_counts_windows_and_weights_them_by_length() {
    let mut sweep = Sweep::new(plan(40_000, 0.0025, 3, 2, 2), CLOCK).unwrap();
    let window = |in_phase: f64, samples| Demodulated {
        phasor: Phasor::new(Q2_30::from_f64(in_phase).unwrap(), Q2_30::ZERO),
        samples,
    };
    // Two windows discarded, two averaged by their lengths.
    assert_eq!(sweep.update(&window(9.0e-1, 100)).0, None);
    assert_eq!(sweep.update(&window(9.0e-1, 100)).0, None);
    assert_eq!(sweep.update(&window(0.1, 60)).0, None);
    let (point, progress) = sweep.update(&window(0.2, 120));
    let point = point.expect("the point is done after 2 measured windows");
    assert!((point.conductance.to_f64() - 0.5 / 3.0).abs() < 1e-9);
    assert_eq!(point.millihertz, 40_000_000);
    assert!(
        matches!(progress, SweepProgress::Drive(t) if t.frequency.millihertz().abs_diff(40_100_000) < 300)
    );
    assert_eq!(sweep.index(), 1);
}

#[test]
fn peaks_at_the_ends_are_reported_as_such() {
    let window = |in_phase: f64| Demodulated {
        phasor: Phasor::new(Q2_30::from_f64(in_phase).unwrap(), Q2_30::ZERO),
        samples: 100,
    };
    for (values, index) in [
        ([0.3, 0.2, 0.1], 0),
        ([0.1, 0.2, 0.3], 2),
        ([0.1, 0.3, 0.2], 1),
    ] {
        let mut sweep = Sweep::new(plan(40_000, 0.0025, 3, 0, 1), CLOCK).unwrap();
        let mut result = None;
        for v in values {
            if let (_, SweepProgress::Done(r)) = sweep.update(&window(v)) {
                result = Some(r);
            }
        }
        let result = result.unwrap();
        assert_eq!(result.best_index, index);
        assert_eq!(result.points, 3);
        if index == 1 {
            // The vertex of the reciprocals 10, 3.33, 5 at 40 000, 40 100, 40 200.25 Hz.
            let (x1, x0, x2) = (-100.0, 0.0, 100.25);
            let (u1, u2) = (10.0 - 1.0 / 0.3, 5.0 - 1.0 / 0.3);
            let vertex = x0 - (x2 * x2 * u1 - x1 * x1 * u2) / (2.0 * (x1 * u2 - x2 * u1));
            let got = hz(result.peak) - hz(Frequency::from_millihertz(result.best.millihertz));
            assert!((got - vertex).abs() < 0.5, "{got} vs {vertex}");
        } else {
            assert_eq!(result.peak.millihertz(), result.best.millihertz);
        }
    }
}

#[test]
fn points_the_timer_cannot_make_end_the_sweep() {
    assert!(Sweep::new(plan(61_000, 0.01, 4, 0, 1), CLOCK).is_err());
    // 59 kHz, 59.59 kHz, then 60.19 kHz is out of band: two points, not ten.
    let mut sweep = Sweep::new(plan(59_000, 0.01, 10, 0, 1), CLOCK).unwrap();
    let window = Demodulated {
        phasor: Phasor::new(Q2_30::from_f64(0.1).unwrap(), Q2_30::ZERO),
        samples: 67,
    };
    assert!(matches!(sweep.update(&window).1, SweepProgress::Drive(_)));
    let (_, progress) = sweep.update(&window);
    let SweepProgress::Done(result) = progress else {
        panic!("{progress:?}");
    };
    assert_eq!(result.points, 2);
}

#[test]
fn a_sweep_ends_two_points_past_a_halved_peak_with_the_same_peak() {
    for f0 in [38_123.0, 40_000.0] {
        for dynamics in [Dynamics::InstantPhase, Dynamics::Lagged] {
            let whole = plan(36_000, 0.01, 21, 32, 2);
            let early = SweepPlan {
                stop_past_peak: 2,
                start_up: 1,
                min_peak: Q2_30::from_ratio(1, 1000).unwrap(),
                ..whole
            };
            let mut plant = Resonator::reference(dynamics);
            plant.f0_hz = f0;
            let (full, all, t_full) = run(whole, &mut plant.clone());
            let (short, some, t_short) = run(early, &mut plant);
            // Two points after the best, the last of them at most half of it.
            assert!(
                some.len() < all.len(),
                "{f0}: {} of {}",
                some.len(),
                all.len()
            );
            assert_eq!(usize::from(short.best_index) + 3, some.len(), "{f0}");
            let last = some.last().unwrap().conductance.to_bits();
            assert!(2 * i64::from(last) <= i64::from(short.best.conductance.to_bits()));
            // The same points up to there, so the same peak.
            assert_eq!(some[..], all[..some.len()], "{dynamics:?} {f0}");
            assert_eq!(short.peak, full.peak, "{dynamics:?} {f0}");
            assert!(t_short < t_full);
        }
    }
}

#[test]
fn no_early_end_on_a_start_up_point_or_a_peak_below_the_threshold() {
    let mut plant = Resonator::reference(Dynamics::Lagged);
    plant.f0_hz = 40_000.0;
    let whole = plan(36_000, 0.01, 21, 32, 2);
    // The peak (point 10 or so) inside the start-up points: the whole sweep.
    let start_up = SweepPlan {
        stop_past_peak: 2,
        start_up: 15,
        ..whole
    };
    let (_, points, _) = run(start_up, &mut plant.clone());
    assert_eq!(points.len(), 21);
    // A threshold above the resonance's conductance: the whole sweep.
    let threshold = SweepPlan {
        stop_past_peak: 2,
        min_peak: Q2_30::ONE,
        ..whole
    };
    let (_, points, _) = run(threshold, &mut plant);
    assert_eq!(points.len(), 21);
}
