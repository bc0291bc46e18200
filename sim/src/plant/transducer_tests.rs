//! Tests of the resonant transducer (`transducer.rs`).

use super::*;
use sonolube::scene::{Actuator, ActuatorKind, Transducer};

/// The seed 003 stack of the reference scene: 40 kHz, Q = 100, C0 = 300 nF, R1 = 3.1 ohm,
/// 5.25 V at full command.
const STACK: Transducer = Transducer {
    resonance_hz: 40_000.0,
    quality_factor: 100.0,
    drift_hz_per_s: 0.0,
    drive_hz: 40_000.0,
    clamped_capacitance_f: 300e-9,
    motional_resistance_ohm: 3.1,
    shift: sonolube::scene::ResonanceShift::NONE,
};

const ACTUATOR: Actuator = Actuator {
    kind: ActuatorKind::PmnPtStack,
    full_scale_voltage_v: 5.25,
    full_scale_amplitude_m: 0.4756e-6,
    max_voltage_v: 15.466,
    max_current_a: 1.75,
    stack: None,
};

/// Settled at `drive_hz` with full command (40 time constants: e^-40 is below f32's ulp).
fn settled(drive_hz: f32) -> ResonantTransducer {
    let mut transducer = ResonantTransducer::new(&STACK, &ACTUATOR);
    let tau = transducer.time_constant_s(0.0);
    for _ in 0..40 {
        transducer.advance(1.0, drive_hz, tau);
    }
    transducer
}

#[test]
fn the_step_response_has_the_stated_time_constant() {
    let mut transducer = ResonantTransducer::new(&STACK, &ACTUATOR);
    let tau = transducer.time_constant_s(0.0);
    // 2 Q / (2 pi f0) = 200 / (2 pi 40 kHz) = 0.7958 ms.
    assert!((tau - 0.000_795_77).abs() < 1e-8, "tau = {tau}");
    // 25 us substeps (10 kHz, 4 substeps): 1 - e^(-t / tau) at every substep.
    let dt = 25e-6;
    for n in 1..=200 {
        transducer.advance(1.0, 40_000.0, dt);
        let expected = 1.0 - libm::expf(-(n as f32) * dt / tau);
        assert!(
            (transducer.envelope() - expected).abs() < 2e-6,
            "n = {n}: {} vs {expected}",
            transducer.envelope()
        );
    }
    // Releasing the command decays with the same time constant.
    let start = transducer.envelope();
    transducer.advance(0.0, 40_000.0, tau);
    assert!((transducer.envelope() - start * libm::expf(-1.0)).abs() < 1e-6);
}

#[test]
fn the_step_size_does_not_change_the_response() {
    let (mut coarse, mut fine) = (
        ResonantTransducer::new(&STACK, &ACTUATOR),
        ResonantTransducer::new(&STACK, &ACTUATOR),
    );
    coarse.advance(0.7, 40_050.0, 1e-3);
    for _ in 0..40 {
        fine.advance(0.7, 40_050.0, 25e-6);
    }
    assert!((coarse.envelope() - fine.envelope()).abs() < 1e-5);
}

#[test]
fn gain_falls_off_the_resonance() {
    let transducer = ResonantTransducer::new(&STACK, &ACTUATOR);
    assert_eq!(transducer.gain(40_000.0, 0.0), 1.0);
    // Half-power points at f0 (1 +- 1 / 2Q): 200 Hz either side.
    let half = core::f32::consts::FRAC_1_SQRT_2;
    assert!((transducer.gain(40_200.0, 0.0) - half).abs() < 1e-6);
    assert!((transducer.gain(39_800.0, 0.0) - half).abs() < 1e-6);
    // 2Q (f - f0) / f0 = 3 at 600 Hz off: 1 / sqrt(10).
    assert!((transducer.gain(40_600.0, 0.0) - 0.316_227_77).abs() < 1e-6);
    assert_eq!(transducer.gain(0.0, 0.0), 0.0);
    assert_eq!(transducer.gain(f32::NAN, 0.0), 0.0);
    // The settled envelope follows the gain.
    assert!((settled(40_200.0).envelope() - half).abs() < 1e-5);
}

#[test]
fn the_resonance_drifts_away_from_a_fixed_drive() {
    let drifting = Transducer {
        drift_hz_per_s: -100.0,
        ..STACK
    };
    let mut transducer = ResonantTransducer::new(&drifting, &ACTUATOR);
    assert_eq!(transducer.resonance_hz(0.0), 40_000.0);
    assert_eq!(transducer.resonance_hz(2.0), 39_800.0);
    // After 2 s at 40 kHz the resonance is 200 Hz below, near the half-power point: the
    // envelope is the gain there, 1 / sqrt(1 + (2 Q 200 / 39 800)^2) = 0.7053 (lagging the
    // drifting gain by about one time constant, 1e-5).
    let dt = 1e-3;
    for _ in 0..2000 {
        transducer.advance(1.0, 40_000.0, dt);
    }
    assert!((transducer.time_s() - 2.0).abs() < 1e-3);
    let envelope = transducer.envelope();
    assert!((envelope - 0.705_33).abs() < 3e-4, "envelope {envelope}");
    // The time constant follows f0.
    assert!(transducer.time_constant_s(2.0) > transducer.time_constant_s(0.0));
}

#[test]
fn the_current_at_resonance_is_the_bvd_current() {
    let current = settled(40_000.0).current();
    // Motional: V / R1 = 5.25 / 3.1 A in phase; C0: 2 pi f C0 V leading by 90 degrees.
    let motional = 5.25 / 3.1;
    let capacitive = TAU * 40_000.0 * 300e-9 * 5.25;
    assert!((current.voltage_v - 5.25).abs() < 1e-6);
    assert!((current.motional_amplitude_a - motional).abs() < 1e-4);
    assert_eq!(current.motional_phase_rad, 0.0);
    let amplitude = libm::hypotf(motional, capacitive);
    assert!(
        (current.amplitude_a - amplitude).abs() < 1e-4,
        "{current:?}"
    );
    // Within seed 003's 1.75 A rating, as the scene loader checked.
    assert!(current.amplitude_a < 1.75);
    let phase = libm::atan2f(capacitive, motional);
    assert!((current.phase_rad - phase).abs() < 1e-5);
}

#[test]
fn the_motional_phase_crosses_zero_at_f0_and_the_current_peaks_there() {
    let half_band = 40_000.0 / (2.0 * 100.0);
    let mut previous_phase = f32::INFINITY;
    let (mut peak_hz, mut peak_a) = (0.0, 0.0);
    let mut total_zero_hz = None;
    let mut previous_total = f32::NAN;
    let mut f = 39_000.0;
    while f <= 41_000.0 {
        let current = settled(f).current();
        // The motional phase falls monotonically through the resonance and is 0 exactly at f0.
        assert!(current.motional_phase_rad < previous_phase);
        assert_eq!(
            current.motional_phase_rad == 0.0,
            f == 40_000.0,
            "at {f} Hz"
        );
        assert_eq!(current.motional_phase_rad > 0.0, f < 40_000.0, "at {f} Hz");
        previous_phase = current.motional_phase_rad;
        if current.amplitude_a > peak_a {
            (peak_hz, peak_a) = (f, current.amplitude_a);
        }
        if previous_total > 0.0 && current.phase_rad <= 0.0 && total_zero_hz.is_none() {
            total_zero_hz = Some(f);
        }
        previous_total = current.phase_rad;
        f += 5.0;
    }
    // C0's current shifts the total's extremes a little; both stay inside the half-power band.
    assert!(
        (peak_hz - 40_000.0f32).abs() < half_band,
        "peak at {peak_hz} Hz"
    );
    let zero = total_zero_hz.unwrap_or(0.0);
    assert!(
        (zero - 40_000.0f32).abs() < half_band,
        "zero phase at {zero} Hz"
    );
    // Far from resonance only C0 is left: the current leads by nearly 90 degrees.
    assert!(settled(39_000.0).current().phase_rad > 1.2);
}

#[test]
fn no_drive_draws_no_current() {
    let transducer = ResonantTransducer::new(&STACK, &ACTUATOR);
    let current = transducer.current();
    assert_eq!(current.amplitude_a, 0.0);
    assert_eq!(current.phase_rad, 0.0);
    assert_eq!(transducer.current_at(1e-6), 0.0);
}

#[test]
fn the_drive_phase_accumulates_whole_turns() {
    let mut transducer = ResonantTransducer::new(&STACK, &ACTUATOR);
    // 40 kHz for 25 us is one turn; 1 s of it is 40 000 turns.
    for _ in 0..40_000 {
        transducer.advance(0.5, 40_000.0, 25e-6);
    }
    let phase = transducer.phase_rad();
    assert!(phase.min(TAU - phase) < 1e-3, "phase {phase}");
    // A quarter period later the voltage crosses zero.
    assert!(transducer.voltage_at(6.25e-6).abs() < 0.01);
}

#[test]
fn lock_in_demodulation_of_the_sampled_current_recovers_the_phasor() {
    let transducer = settled(40_100.0);
    let phasor = transducer.current();
    // 1 MHz sampling over 401 whole drive periods (10 ms).
    let interval = 1e-6;
    let mut samples = [0.0f32; 10_000];
    transducer.current_samples(0.0, interval, &mut samples);
    // References from the drive voltage, as a lock-in has them: v(t) / V = cos(theta) and,
    // a quarter period later, cos(theta + pi/2) = -sin(theta).
    let quarter = 0.25 / 40_100.0;
    let (mut in_phase, mut quadrature) = (0.0f64, 0.0f64);
    for (k, sample) in samples.iter().enumerate() {
        let t = k as f32 * interval;
        let cos = transducer.voltage_at(t) / phasor.voltage_v;
        let minus_sin = transducer.voltage_at(t + quarter) / phasor.voltage_v;
        in_phase += f64::from(sample * cos);
        quadrature += f64::from(sample * minus_sin);
    }
    let n = samples.len() as f64;
    let (i, q) = (2.0 * in_phase / n, 2.0 * quadrature / n);
    let amplitude = (i * i + q * q).sqrt() as f32;
    let phase = q.atan2(i) as f32;
    assert!((amplitude - phasor.amplitude_a).abs() < 2e-3 * phasor.amplitude_a);
    assert!(
        (phase - phasor.phase_rad).abs() < 2e-3,
        "{phase} vs {}",
        phasor.phase_rad
    );
    // Above resonance the motional current lags.
    assert!(phasor.motional_phase_rad < 0.0);
}

/// The stack with the complex envelope, whose current the boards' sense samples.
fn sampled_stack(resonance_hz: f64, quality_factor: f64) -> ResonantTransducer {
    let stack = Transducer {
        resonance_hz,
        quality_factor,
        drive_hz: resonance_hz,
        shift: sonolube::scene::ResonanceShift {
            bvd_envelope: true,
            ..sonolube::scene::ResonanceShift::NONE
        },
        ..STACK
    };
    ResonantTransducer::with_shift(&stack, &ACTUATOR, 7)
}

#[test]
fn the_sampled_current_rings_down_with_tau_q_over_pi_f0() {
    // Commissioning's measurement (`sonolube::commission`): drive half full scale at f0 for
    // ten time constants, then off; the lock-in amplitude of each group of four current
    // samples decays as exp(-t / tau), tau = Q / (pi f0).
    for (f0, q) in [(40_000.0f64, 100.0f64), (28_000.0, 300.0), (50_000.0, 30.0)] {
        let mut transducer = sampled_stack(f0, q);
        let tau = q / (core::f64::consts::PI * f0);
        let substep_s = 0.25 / f0 as f32;
        let steps = libm::ceil(10.0 * tau / f64::from(substep_s)) as u32;
        for _ in 0..steps {
            transducer.advance(0.5, f0 as f32, substep_s);
            transducer.take_current_codes();
        }
        let mut groups = std::vec::Vec::new();
        let mut codes = std::vec::Vec::new();
        for _ in 0..libm::ceil(4.0 * tau * f0 * 4.0) as u32 {
            transducer.advance(0.0, f0 as f32, substep_s);
            let (taken, count) = transducer.take_current_codes();
            codes.extend_from_slice(&taken[..count]);
        }
        for group in codes.chunks_exact(4) {
            let squared = sonolube::resonance::group_amplitude_squared([
                group[0], group[1], group[2], group[3],
            ]);
            groups.push(sonolube::resonance::group_amplitude_lsb(squared));
        }
        let fit =
            sonolube::resonance::fit_ring_down(groups.iter().copied(), 4.0 / f0).expect("fits");
        let error = (fit.time_constant_s - tau).abs();
        assert!(
            error < 4.0 * fit.time_constant_se_s && fit.time_constant_se_s < 0.03 * tau,
            "f0 {f0} Q {q}: {fit:?} against tau {tau}"
        );
    }
}
