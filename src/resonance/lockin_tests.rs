use super::*;
use crate::resonance::phasor::Angle;
use std::f64::consts::{PI, TAU};

const MSPS: LockInConfig = LockInConfig {
    sample_rate_hz: 1_000_000,
    periods_per_window: 4,
    sense_delay_ns: 0,
};

/// A test signal: `dc + amplitude cos(theta + phase) + sum h_amp cos(h theta + h_phase)`, with
/// `theta` the drive phase at the sample instant minus the sense delay.
struct Signal {
    drive_hz: f64,
    amplitude: f64,
    phase_rad: f64,
    dc: f64,
    harmonics: Vec<(u32, f64, f64)>,
    delay_s: f64,
}

impl Signal {
    fn pure(drive_hz: f64, amplitude: f64, phase_rad: f64) -> Self {
        Self {
            drive_hz,
            amplitude,
            phase_rad,
            dc: 0.0,
            harmonics: Vec::new(),
            delay_s: 0.0,
        }
    }

    fn at(&self, t_s: f64) -> f64 {
        let theta = TAU * self.drive_hz * (t_s - self.delay_s);
        let mut x = self.dc + self.amplitude * (theta + self.phase_rad).cos();
        for &(h, amplitude, phase) in &self.harmonics {
            x += amplitude * (f64::from(h) * theta + phase).cos();
        }
        x
    }
}

fn q31(x: f64) -> Q1_31 {
    Q1_31::from_f64_saturating(x).value
}

/// Runs `windows` windows of `signal` sampled at `config.sample_rate_hz` and returns every
/// window's phasor.
fn demodulate(config: LockInConfig, signal: &Signal, windows: usize) -> Vec<Demodulated> {
    let drive = Frequency::from_millihertz((signal.drive_hz * 1000.0).round() as u32);
    let mut lock_in = LockIn::new(config, drive).unwrap();
    let dt = 1.0 / f64::from(config.sample_rate_hz);
    let mut out = Vec::new();
    let mut k = 0u64;
    while out.len() < windows {
        if let Some(window) = lock_in.push(q31(signal.at(k as f64 * dt))) {
            out.push(window);
        }
        k += 1;
    }
    out
}

/// Largest amplitude error (relative) and phase error (rad) over the windows.
fn errors(signal: &Signal, windows: &[Demodulated]) -> (f64, f64) {
    let want = Angle::from_radians(signal.phase_rad);
    windows.iter().fold((0.0f64, 0.0f64), |(amp, ph), w| {
        let polar = w.phasor.polar();
        let amp_err = (polar.amplitude.to_f64() / signal.amplitude - 1.0).abs();
        let ph_err = polar.phase.wrapping_sub(want).to_radians().abs();
        (amp.max(amp_err), ph.max(ph_err))
    })
}

#[test]
fn exact_sinusoid_across_the_band_and_the_circle() {
    let mut worst = (0.0f64, 0.0f64);
    // Band edges, the nominal resonance, and frequencies whose windows miss whole turns by a
    // sizeable fraction of a sample.
    // 40 200 Hz: 99.5 samples per 4 periods, the worst partial window.
    for drive_hz in [
        20_000.0, 20_013.7, 39_871.3, 40_000.0, 40_200.0, 44_123.4, 59_987.1, 60_000.0,
    ] {
        for k in 0..24 {
            let phase = -PI + k as f64 * TAU / 24.0;
            let signal = Signal::pure(drive_hz, 0.3, phase);
            let windows = demodulate(MSPS, &signal, 3);
            let n = f64::from(windows[0].samples);
            let (amp, ph) = errors(&signal, &windows);
            // Without the 2f correction this reaches 0.35 / N.
            assert!(
                amp <= 0.01 / n && ph <= 0.01 / n,
                "{drive_hz} Hz {phase}: {amp} {ph}"
            );
            worst = (worst.0.max(amp * n), worst.1.max(ph * n));
        }
    }
    eprintln!(
        "lock-in, pure sinusoid, 4 periods at 1 MSPS: amplitude error <= {:.3}/N, phase <= {:.3}/N rad",
        worst.0, worst.1
    );
}

#[test]
fn whole_turn_windows_are_exact_to_the_arithmetic() {
    // 40 kHz at 1 MSPS: 25 samples per period exactly, no leakage left.
    let signal = Signal::pure(40_000.0, 0.5, 1.0);
    let windows = demodulate(MSPS, &signal, 4);
    assert_eq!(windows[0].samples, 100);
    let (amp, ph) = errors(&signal, &windows);
    // What is left is the step's rounding (0.16 of 2^-32 turn per sample, 64 units = 9e-8 rad
    // after the 4th window): boards resynchronise the phase at retunes.
    assert!(amp < 2e-8 && ph < 1e-7, "{amp} {ph}");
}

#[test]
fn a_mid_scale_offset_is_rejected() {
    // A unipolar converter: zero current at half of full scale.
    for drive_hz in [20_000.0, 41_234.5, 60_000.0] {
        let mut signal = Signal::pure(drive_hz, 0.02, -0.4);
        signal.dc = 0.5;
        let windows = demodulate(MSPS, &signal, 3);
        let n = f64::from(windows[0].samples);
        let (amp, ph) = errors(&signal, &windows);
        // The offset is 25 times the signal; left in, it would leak up to 0.5 / N = 25 / N of
        // the amplitude. Measured: 0.005 / N at most.
        assert!(
            amp <= 0.01 / n && ph <= 0.01 / n,
            "{drive_hz} Hz: {amp} {ph}"
        );
    }
}

#[test]
fn harmonics_below_nyquist_are_rejected() {
    // A square-wave-like current: odd harmonics 1/3, 1/5, 1/7 of the fundamental, and an even
    // one. 60 kHz at 1 MSPS keeps the 7th (420 kHz) below Nyquist.
    for drive_hz in [33_333.3, 47_777.7, 60_000.0] {
        let mut signal = Signal::pure(drive_hz, 0.4, 0.7);
        signal.harmonics = vec![
            (2, 0.1, 0.3),
            (3, 0.4 / 3.0, 0.0),
            (5, 0.08, 1.0),
            (7, 0.057, 2.0),
        ];
        let windows = demodulate(MSPS, &signal, 3);
        let n = f64::from(windows[0].samples);
        let (amp, ph) = errors(&signal, &windows);
        // Harmonics are not corrected: they leak about 1/N of their own amplitude (here 0.8 of
        // the fundamental's in total; measured 0.48 / N at most).
        assert!(amp <= 0.6 / n && ph <= 0.6 / n, "{drive_hz} Hz: {amp} {ph}");
    }
}

#[test]
fn longer_windows_leak_less() {
    let config = LockInConfig {
        periods_per_window: 40,
        ..MSPS
    };
    let mut signal = Signal::pure(41_234.5, 0.1, 2.5);
    signal.dc = 0.5;
    signal.harmonics = vec![(3, 0.05, 0.0)];
    let windows = demodulate(config, &signal, 2);
    assert!(windows[0].samples > 900);
    let (amp, ph) = errors(&signal, &windows);
    assert!(amp < 1e-4 && ph < 1e-4, "{amp} {ph}");
}

#[test]
fn full_scale_square_waves_of_the_longest_window_do_not_overflow() {
    // 2^20 samples of a +-full-scale square wave: every sum at its largest.
    let config = LockInConfig {
        sample_rate_hz: 1_000_000,
        periods_per_window: 20_000,
        sense_delay_ns: 0,
    };
    let drive = Frequency::from_hz(20_000);
    let mut lock_in = LockIn::new(config, drive).unwrap();
    assert_eq!(lock_in.window_samples(), 1_000_000);
    let mut result = None;
    for k in 0..1_000_000u32 {
        // 50 samples per period: high for the first 25 (voltage phase in (-pi/2, pi/2) at the
        // window's start is 0 .. 1/4 and 3/4 .. 1 of the turn).
        let sample = if (k + 12) % 50 < 25 {
            Q1_31::MAX
        } else {
            Q1_31::MIN
        };
        result = lock_in.push(sample).or(result);
    }
    let polar = result.expect("one window").phasor.polar();
    // Fundamental of a +-1 square wave: 4/pi (sampling shifts it by half a sample).
    assert!(
        (polar.amplitude.to_f64() - 4.0 / PI).abs() < 2e-3,
        "{polar:?}"
    );
    assert!(polar.phase.to_radians().abs() < TAU / 50.0, "{polar:?}");
    // A constant full-scale negative input: only DC, which the window rejects.
    let mut lock_in = LockIn::new(config, drive).unwrap();
    let mut dc = None;
    for _ in 0..1_000_000u32 {
        dc = lock_in.push(Q1_31::MIN).or(dc);
    }
    assert!(dc.unwrap().phasor.polar().amplitude.to_f64() < 1e-6);
}

#[test]
fn quantised_noisy_samples_average_out() {
    // 12-bit unipolar ADC, mid-scale zero, 1.5 LSB RMS noise (uniform deviates, LCG).
    let signal = Signal {
        dc: 0.5,
        ..Signal::pure(38_765.4, 0.01, -1.2)
    };
    let drive = Frequency::from_millihertz(38_765_400);
    let config = LockInConfig {
        periods_per_window: 40,
        ..MSPS
    };
    let mut lock_in = LockIn::new(config, drive).unwrap();
    let mut seed = 12_345u32;
    let mut windows = Vec::new();
    let mut k = 0u64;
    while windows.len() < 10 {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        let noise = (f64::from(seed) / 4_294_967_296.0 - 0.5) * 1.5 * 12f64.sqrt();
        let code = (signal.at(k as f64 * 1e-6) * 4096.0 + noise)
            .round()
            .clamp(0.0, 4095.0);
        let sample = Q1_31::from_bits((code as i32) << 19);
        if let Some(w) = lock_in.push(sample) {
            windows.push(w);
        }
        k += 1;
    }
    // Signal amplitude 41 LSB; noise per component sqrt(2 / N) x 1.5 LSB = 0.07 LSB.
    let (amp, ph) = errors(&signal, &windows);
    assert!(amp < 0.01 && ph < 0.01, "{amp} {ph}");
}

#[test]
fn sense_delay_is_compensated() {
    let config = LockInConfig {
        sense_delay_ns: 400,
        ..MSPS
    };
    let mut signal = Signal::pure(52_000.0, 0.2, 0.25);
    signal.delay_s = 400e-9;
    let windows = demodulate(config, &signal, 2);
    let (_, ph) = errors(&signal, &windows);
    assert!(ph < 2e-2 / f64::from(windows[0].samples), "{ph}");
    // Uncompensated, the delay reads as a lag of 2 pi f t_d = 0.131 rad.
    let windows = demodulate(MSPS, &signal, 2);
    let lag = Angle::from_radians(signal.phase_rad)
        .wrapping_sub(windows[1].phasor.polar().phase)
        .to_radians();
    assert!((lag - TAU * 52_000.0 * 400e-9).abs() < 1e-3, "{lag}");
}

#[test]
fn equivalent_time_sampling_below_the_drive_frequency() {
    // 34 kHz sampled at 32 kHz: the drive advances 1 + 1/16 turn per sample, so the reference
    // sees 1/16 turn per sample and a window of 4 turns is 64 samples (2 ms).
    let config = LockInConfig {
        sample_rate_hz: 32_000,
        periods_per_window: 4,
        sense_delay_ns: 0,
    };
    let mut signal = Signal::pure(34_000.0, 0.25, -2.0);
    signal.dc = 0.5;
    let windows = demodulate(config, &signal, 2);
    assert_eq!(windows[0].samples, 64);
    let (amp, ph) = errors(&signal, &windows);
    assert!(amp < 1e-7 && ph < 1e-7, "{amp} {ph}");
}

#[test]
fn unusable_sampling_is_refused() {
    let at = |sample_rate_hz, periods_per_window, hz| {
        LockIn::new(
            LockInConfig {
                sample_rate_hz,
                periods_per_window,
                sense_delay_ns: 0,
            },
            Frequency::from_hz(hz),
        )
    };
    // Two samples per period: quadrature invisible.
    assert_eq!(
        at(80_000, 4, 40_000).err(),
        Some(ResonanceError::SamplingTooSlow)
    );
    // The drive an exact multiple of the sample rate: the reference stands still.
    assert_eq!(
        at(20_000, 4, 40_000).err(),
        Some(ResonanceError::SamplingTooSlow)
    );
    assert_eq!(
        at(0, 4, 40_000).err(),
        Some(ResonanceError::SamplingTooSlow)
    );
    assert_eq!(
        at(1_000_000, 0, 40_000).err(),
        Some(ResonanceError::WindowLength)
    );
    assert_eq!(
        at(4_000_000, 60_000, 20_000).err(),
        Some(ResonanceError::WindowLength)
    );
    assert!(at(120_000, 4, 40_000).is_ok()); // exactly 3 samples per period
}

#[test]
fn retune_discards_the_partial_window_and_keeps_the_phase() {
    let mut lock_in = LockIn::new(MSPS, Frequency::from_hz(40_000)).unwrap();
    for _ in 0..60 {
        assert!(lock_in.push(q31(0.1)).is_none());
    }
    lock_in.retune(Frequency::from_hz(50_000)).unwrap();
    assert_eq!(lock_in.window_samples(), 80);
    // The phase went on from 60 samples at 40 kHz: 2.4 turns, i.e. 0.4 turn.
    let signal = Signal::pure(50_000.0, 0.2, 0.0);
    let mut result = None;
    for k in 0..80 {
        let t = k as f64 * 1e-6;
        let x = 0.2 * (TAU * (0.4 + 50_000.0 * t)).cos();
        result = lock_in.push(q31(x)).or(result);
    }
    let polar = result
        .expect("a window after exactly 80 samples")
        .phasor
        .polar();
    assert!((polar.amplitude.to_f64() - signal.amplitude).abs() < 1e-6);
    assert!(polar.phase.to_radians().abs() < 1e-6, "{polar:?}");
    // A refused retune changes nothing.
    assert!(lock_in.retune(Frequency::from_hz(500_000)).is_err());
    assert_eq!(lock_in.window_samples(), 80);
    lock_in.set_drive_phase(1 << 30);
    assert_eq!(lock_in.config(), MSPS);
}

/// Configuration apart from state: one [`Demodulator`] running two [`LockInSums`] with the
/// samples of two currents interleaved gives each current the phasors its own lock-in gives,
/// bit for bit (a sample changes only the sums it is pushed into, never the demodulator).
#[test]
fn one_demodulator_runs_two_states_independently() {
    let first = Signal::pure(40_000.0, 0.6, 0.3);
    let second = Signal::pure(40_000.0, 0.2, -1.1);
    let drive = Frequency::from_hz(40_000);
    let shared = LockIn::new(MSPS, drive).unwrap().demodulator;
    let (mut first_sums, mut second_sums) = (LockInSums::default(), LockInSums::default());
    let dt = 1.0 / f64::from(MSPS.sample_rate_hz);
    let (mut first_out, mut second_out) = (Vec::new(), Vec::new());
    for k in 0..1000u32 {
        let t = f64::from(k) * dt;
        first_out.extend(shared.process(&mut first_sums, q31(first.at(t))));
        second_out.extend(shared.process(&mut second_sums, q31(second.at(t))));
    }
    assert_eq!(first_out, demodulate(MSPS, &first, first_out.len()));
    assert_eq!(second_out, demodulate(MSPS, &second, second_out.len()));
    assert!(first_out.len() >= 9 && first_out != second_out);
}
