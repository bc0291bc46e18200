//! Acceptance of `sonolube::resonance` against `sonolube_sim::plant`'s resonant transducer: the current waveform sampled at
//! 1 MSPS (and 250 kSPS) by a 12-bit ADC (0.5 V/A around mid-scale, 6.6 A full scale, 2 LSB RMS Gaussian
//! noise), demodulated by the lock-in, searched and tracked, with f0 drifting.

use sonolube::drive::{Amplitude, Frequency, TimerClock};
use sonolube::fx::{Q1_31, Q2_30};
use sonolube::resonance::*;
use sonolube::scene::{Actuator, ActuatorKind, Transducer};
use sonolube::sense::AdcFormat;
use sonolube_sim::plant::{Gaussian, ResonantTransducer};

const CLOCK: TimerClock = TimerClock::G474_TIM1;
const LOCK_IN: LockInConfig = LockInConfig {
    sample_rate_hz: 1_000_000,
    periods_per_window: 4,
    sense_delay_ns: 0,
};
/// ADC noise, LSB RMS.
const NOISE_LSB: f32 = 2.0;
/// Plant substep, s: the plant's envelope is advanced every 20 us (its f32 clock would run
/// 5 % slow at 1 s if advanced every microsecond) and the waveform in between is read with
/// the phasor held.
const SUBSTEP_S: f64 = 20e-6;

/// The plant, the converter and the lock-in, sample by sample.
struct Rig {
    plant: ResonantTransducer,
    noise: Gaussian,
    adc: AdcFormat,
    lock_in: LockIn,
    connected: bool,
}

impl Rig {
    fn new(f0_hz: f64, drift_hz_per_s: f64, r1_ohm: f64, seed: u64) -> Self {
        Self::sampled(f0_hz, drift_hz_per_s, r1_ohm, seed, LOCK_IN)
    }

    fn sampled(
        f0_hz: f64,
        drift_hz_per_s: f64,
        r1_ohm: f64,
        seed: u64,
        lock_in: LockInConfig,
    ) -> Self {
        let transducer = Transducer {
            resonance_hz: f0_hz,
            quality_factor: 100.0,
            drift_hz_per_s,
            drive_hz: 40_000.0,
            clamped_capacitance_f: 300e-9,
            motional_resistance_ohm: r1_ohm,
            shift: sonolube::scene::ResonanceShift::NONE,
        };
        let actuator = Actuator {
            kind: ActuatorKind::PmnPtStack,
            full_scale_voltage_v: 5.25,
            full_scale_amplitude_m: 0.4756e-6,
            max_voltage_v: 15.466,
            max_current_a: 1.75,
            stack: None,
        };
        Self {
            plant: ResonantTransducer::new(&transducer, &actuator),
            noise: Gaussian::from_seed(seed),
            adc: AdcFormat::unipolar(12).unwrap(),
            lock_in: LockIn::new(lock_in, Frequency::from_hz(40_000)).unwrap(),
            connected: true,
        }
    }

    fn f0(&self) -> f64 {
        f64::from(self.plant.resonance_hz(self.plant.time_s()))
    }

    fn t(&self) -> f64 {
        f64::from(self.plant.time_s())
    }

    /// The ADC's reading of a current (A): 1.65 V + 0.5 V/A of 3.3 V, noise, 12 bits.
    fn convert(&mut self, current_a: f32) -> Q1_31 {
        let current_a = if self.connected { current_a } else { 0.0 };
        let code = 4096.0 * (0.5 + current_a / 6.6) + NOISE_LSB * self.noise.sample();
        let code = libm::roundf(code).clamp(0.0, 4095.0) as i32;
        self.adc
            .normalize(sonolube::sense::AdcCode::new(code))
            .unwrap()
    }

    /// One lock-in window at `tuning` and `amplitude`. The ADC is triggered from the drive's
    /// timer clock, so the drive phase at the window's first sample is known exactly.
    fn window(&mut self, tuning: Tuning, amplitude: Amplitude) -> Demodulated {
        let hz = tuning.frequency.millihertz() as f32 / 1000.0;
        let command = amplitude.fraction().to_f64() as f32;
        let rate = self.lock_in.config().sample_rate_hz;
        let dt = 1.0 / rate as f32;
        let substep = (SUBSTEP_S * f64::from(rate)).max(1.0) as u32;
        // The plant reports the current of its last drive: apply this one (for 1 ns) first.
        self.plant.advance(command, hz, 1e-9);
        self.lock_in.retune(tuning.frequency).unwrap();
        let turns = f64::from(self.plant.phase_rad()) / core::f64::consts::TAU;
        self.lock_in
            .set_drive_phase((turns * 4_294_967_296.0) as u32);
        let mut remaining = self.lock_in.window_samples();
        loop {
            let count = remaining.min(substep);
            let mut done = None;
            for k in 0..count {
                let sample = self.convert(self.plant.current_at(k as f32 * dt));
                done = self.lock_in.push(sample);
            }
            self.plant.advance(command, hz, count as f32 * dt);
            remaining -= count;
            if remaining == 0 {
                return done.expect("the window ends with its last sample");
            }
        }
    }
}

fn stack(c0_belief_f: f64) -> StackSettings {
    StackSettings {
        clamped_capacitance_f: c0_belief_f,
        ..StackSettings::REFERENCE
    }
}

fn hz(f: Frequency) -> f64 {
    f64::from(f.millihertz()) / 1000.0
}

/// Search, then track with the operation settings for `track_s`; returns (lock time s, error
/// at lock, worst relative error while tracking) or the fault.
fn search_then_track(
    rig: &mut Rig,
    relative_band: f64,
    c0_belief_f: f64,
    track_s: f64,
) -> Result<(f64, f64, f64), ResonanceFault> {
    let stack = stack(c0_belief_f);
    let lock_in = rig.lock_in.config();
    let settings = SearchSettings::around(&stack, relative_band);
    let config = SearchConfig::new(&settings, &stack, &lock_in).unwrap();
    let bound_s = config.lock_bound_s();
    let mut search = Search::new(config, CLOCK).unwrap();
    let lock = loop {
        let window = rig.window(search.tuning(), search.amplitude());
        match search.update(&window) {
            SearchStep::Drive(_) => assert!(rig.t() < 2.0 * bound_s, "no outcome in {bound_s} s"),
            SearchStep::Locked(lock) => break lock,
            SearchStep::Failed(fault) => return Err(fault),
        }
    };
    let lock_time = rig.t();
    let lock_error = (hz(lock.tuning.frequency) - rig.f0()).abs() / rig.f0();
    let operation = TrackerSettings {
        min_hz: settings.min_hz,
        max_hz: settings.max_hz,
        ..TrackerSettings::OPERATION
    };
    let model = StackModel::new(&stack).unwrap();
    let config = TrackerConfig::new(&operation, model, lock_in.sample_rate_hz).unwrap();
    let mut tracker = Tracker::new(config, lock.tuning.frequency, CLOCK).unwrap();
    let amplitude = Amplitude::new(Q2_30::from_f64(0.5).unwrap()).unwrap();
    let mut worst: f64 = 0.0;
    while rig.t() < lock_time + track_s {
        let window = rig.window(tracker.tuning(), amplitude);
        tracker.update(&window, amplitude)?;
        worst = worst.max((hz(tracker.tuning().frequency) - rig.f0()).abs() / rig.f0());
    }
    Ok((lock_time, lock_error, worst))
}

/// The search's time by its rule for the reference stack over f0 +- `band`.
fn rule_s(band: f64, lock_in: LockInConfig) -> f64 {
    let stack = stack(300e-9);
    let settings = SearchSettings::around(&stack, band);
    SearchConfig::new(&settings, &stack, &lock_in)
        .unwrap()
        .lock_bound_s()
}

#[test]
fn search_locks_to_0_1_percent_and_stays_there() {
    // The time budget is the search's rule (`SearchConfig::lock_bound_s`: the sweep at one
    // bandwidth per tau / 2, the pull-in and its hold; +-50 % is the stack's whole 20-60 kHz).
    for band in [0.05, 0.10, 0.20, 0.50] {
        let stack = stack(300e-9);
        let settings = SearchSettings::around(&stack, band);
        let budget_s = SearchConfig::new(&settings, &stack, &LOCK_IN)
            .unwrap()
            .lock_bound_s();
        let mut times = Vec::new();
        let mut worst_error: f64 = 0.0;
        for (k, position) in [-0.98, -0.61, -0.2, 0.0, 0.137, 0.55, 0.97]
            .iter()
            .enumerate()
        {
            let f0 = 40_000.0 * (1.0 + band * position);
            let mut rig = Rig::new(f0, 0.0, 3.1, 100 + k as u64);
            let (t, at_lock, tracking) = search_then_track(&mut rig, band, 300e-9, 0.01)
                .unwrap_or_else(|fault| panic!("+-{band} f0 {f0}: {fault}"));
            assert!(t <= budget_s, "+-{band} f0 {f0}: lock after {t} s");
            assert!(
                at_lock <= 1e-3 && tracking <= 1e-3,
                "+-{band} f0 {f0}: {at_lock} {tracking}"
            );
            times.push(t * 1e3);
            worst_error = worst_error.max(at_lock).max(tracking);
        }
        let worst_time = times.iter().fold(0.0f64, |m, &t| m.max(t));
        eprintln!(
            "plant, band +-{:.0} %: lock {:.2}-{:.2} ms, worst |f - f0| / f0 {:.4} % at and after lock",
            band * 100.0,
            times.iter().fold(f64::MAX, |m, &t| m.min(t)),
            worst_time,
            worst_error * 100.0
        );
    }
}

#[test]
fn a_quarter_of_the_sample_rate_is_enough() {
    // 250 kSPS: 6.25 samples per period at 40 kHz, a window of 25 samples; a quarter of the
    // per-sample work of 1 MSPS.
    let lock_in = LockInConfig {
        sample_rate_hz: 250_000,
        ..LOCK_IN
    };
    let mut worst = (0.0f64, 0.0f64);
    for (k, f0) in [36_400.0, 39_000.0, 41_700.0, 43_800.0]
        .into_iter()
        .enumerate()
    {
        let mut rig = Rig::sampled(f0, 0.0, 3.1, 40 + k as u64, lock_in);
        let (t, at_lock, tracking) = search_then_track(&mut rig, 0.10, 300e-9, 0.01).unwrap();
        assert!(t <= rule_s(0.10, lock_in), "{f0}: {t}");
        assert!(
            at_lock <= 1e-3 && tracking <= 1e-3,
            "{f0}: {at_lock} {tracking}"
        );
        worst = (worst.0.max(t), worst.1.max(at_lock).max(tracking));
    }
    eprintln!(
        "plant at 250 kSPS, band +-10 %: lock within {:.2} ms, worst |f - f0| / f0 {:.4} %",
        worst.0 * 1e3,
        worst.1 * 100.0
    );
}

#[test]
fn a_c0_believed_10_percent_high_still_locks_within_0_1_percent() {
    for f0 in [37_000.0, 42_500.0] {
        let mut rig = Rig::new(f0, 0.0, 3.1, 7);
        let (t, at_lock, tracking) = search_then_track(&mut rig, 0.10, 330e-9, 0.01).unwrap();
        assert!(
            t <= rule_s(0.10, LOCK_IN) && at_lock <= 1e-3 && tracking <= 1e-3,
            "{f0}: {t} {at_lock} {tracking}"
        );
    }
}

#[test]
fn tracking_follows_a_drift_of_one_percent_per_second() {
    for drift in [400.0, -400.0] {
        let mut rig = Rig::new(40_000.0, drift, 3.1, 21);
        let band = 0.10;
        let stack = stack(300e-9);
        let settings = SearchSettings::around(&stack, band);
        let config = SearchConfig::new(&settings, &stack, &LOCK_IN).unwrap();
        let mut search = Search::new(config, CLOCK).unwrap();
        let lock = loop {
            let window = rig.window(search.tuning(), search.amplitude());
            if let SearchStep::Locked(lock) = search.update(&window) {
                break lock;
            }
            assert!(rig.t() < 2.0 * rule_s(band, LOCK_IN));
        };
        let operation = TrackerSettings {
            min_hz: settings.min_hz,
            max_hz: settings.max_hz,
            ..TrackerSettings::OPERATION
        };
        let model = StackModel::new(&stack).unwrap();
        let config = TrackerConfig::new(&operation, model, LOCK_IN.sample_rate_hz).unwrap();
        let mut tracker = Tracker::new(config, lock.tuning.frequency, CLOCK).unwrap();
        let amplitude = Amplitude::new(Q2_30::from_f64(0.5).unwrap()).unwrap();
        let (start_f0, start_t) = (rig.f0(), rig.t());
        let (mut sum_sq, mut sum, mut worst, mut n) = (0.0, 0.0, 0.0f64, 0.0);
        let mut worst_overall: f64 = 0.0;
        while rig.t() < start_t + 1.0 {
            let window = rig.window(tracker.tuning(), amplitude);
            let status = tracker.update(&window, amplitude).unwrap();
            assert!(
                status.locked || rig.t() < start_t + 0.01,
                "lost lock at {}",
                rig.t()
            );
            let error = hz(tracker.tuning().frequency) - rig.f0();
            worst_overall = worst_overall.max(error.abs());
            // Statistics after the hand-over from the search (its lock is good to about
            // 0.1 half-bandwidth, which the operation rate bound takes 10 ms to trim at most).
            if rig.t() > start_t + 0.01 {
                sum += error;
                sum_sq += error * error;
                worst = worst.max(error.abs());
                n += 1.0;
            }
        }
        let rate = (rig.f0() - start_f0) / (rig.t() - start_t);
        let (mean, rms) = (sum / n, (sum_sq / n).sqrt());
        eprintln!(
            "plant, drift {rate:+.1} Hz/s ({:+.3} %/s) over 1 s: tracking error after 10 ms mean \
             {mean:+.3} Hz, RMS {rms:.3} Hz, worst {worst:.3} Hz ({:.4} %); worst from the \
             lock on {worst_overall:.3} Hz",
            rate / 400.0,
            worst / 400.0
        );
        assert!((rate - drift).abs() < 0.02 * drift.abs(), "{rate}");
        assert!(worst < 1.5 && rms < 0.5, "worst {worst} Hz, RMS {rms} Hz");
        // From the lock on: within the lock band, 0.1 half-bandwidth (20 Hz).
        assert!(worst_overall < 0.1 * 200.0, "{worst_overall} Hz");
    }
}

#[test]
fn a_disconnected_stack_is_a_fault_not_a_frequency() {
    let mut rig = Rig::new(40_000.0, 0.0, 3.1, 3);
    rig.connected = false;
    let fault = search_then_track(&mut rig, 0.10, 300e-9, 0.0).unwrap_err();
    assert_eq!(fault, ResonanceFault::NoCurrent);
    // The stack comes loose while tracking: a fault within 3 windows.
    let mut rig = Rig::new(40_000.0, 0.0, 3.1, 4);
    let model = StackModel::new(&stack(300e-9)).unwrap();
    let config =
        TrackerConfig::new(&TrackerSettings::OPERATION, model, LOCK_IN.sample_rate_hz).unwrap();
    let mut tracker = Tracker::new(config, Frequency::from_hz(40_000), CLOCK).unwrap();
    let amplitude = Amplitude::new(Q2_30::from_f64(0.5).unwrap()).unwrap();
    for _ in 0..20 {
        let window = rig.window(tracker.tuning(), amplitude);
        assert!(tracker.update(&window, amplitude).is_ok());
    }
    rig.connected = false;
    let outcomes: Vec<_> = (0..3)
        .map(|_| {
            let window = rig.window(tracker.tuning(), amplitude);
            tracker.update(&window, amplitude)
        })
        .collect();
    assert!(outcomes[0].is_ok() && outcomes[1].is_ok());
    assert_eq!(outcomes[2], Err(ResonanceFault::NoCurrent));
}

#[test]
fn a_capacitor_without_a_resonance_is_a_fault() {
    let mut rig = Rig::new(40_000.0, 0.0, 1e5, 5);
    let fault = search_then_track(&mut rig, 0.10, 300e-9, 0.0).unwrap_err();
    assert_eq!(fault, ResonanceFault::NoResonance);
}
