//! The motional current: the measured current minus the clamped capacitance's, and the
//! detuning it reveals.
//!
//! Butterworth-Van Dyke model (physics-notes §6; `sonolube_sim::plant`): the stack's admittance is
//! `j w C0` in parallel with the motional branch `1 / (R1 + j X)`, `X = w L1 - 1 / (w C1)`. The
//! series (motional) resonance, where the vibration peaks, is `X = 0`: the motional current is
//! in phase with the voltage and the conductance `Re Y` peaks. The *total* current is not in
//! phase there: C0 adds `j w C0 V`, so the V-I phase zero sits above f0 (by 0.12 % for the
//! reference stack, 48 Hz at 40 kHz) or does not exist at all when `w C0 R1 > 1/2`. Hence the
//! tracker works on the motional current, `I - j w C0 V`, with C0 known from the stack's data.
//!
//! Its phase is `-atan x` with the detuning `x = Q (f/f0 - f0/f) ~ 2 Q (f - f0) / f0`, so
//! `x = -Im / Re` of the motional current is the frequency error in half-bandwidths
//! (`f0 / 2Q`), linear over the whole resonance curve: the loop gain does not collapse far
//! from the resonance as the phase's would. A C0 known to within `dC` leaves a frequency bias
//! of `(f0 / 2Q) w dC R1` (4.7 Hz for 10 % of the reference stack's 300 nF).

use super::error::ResonanceError;
use super::phasor::Phasor;
use crate::drive::{Amplitude, Frequency};
use crate::fx::{Q2_30, Q8_24};

/// Largest detuning reported, in half-bandwidths (Q8.24): beyond it the motional current is
/// too small against the capacitive one for its angle to mean much, and the tracker's rate
/// bound limits the step anyway.
pub const MAX_DETUNING: Q8_24 = Q8_24::from_int_const(16);

/// The current through the clamped capacitance C0 at a drive frequency and amplitude.
///
/// Stored as the capacitive current at full drive amplitude per millihertz of drive frequency,
/// in full-scale units x 2^56 (`u32`): `2 pi C0 V_fs / (1000 A_fs) 2^56`. The range check at
/// construction keeps the current at 60 kHz and full amplitude below 2 full scales (the sensor
/// would saturate long before), so the products below never overflow.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ClampedCapacitance {
    full_scale_per_millihertz_q56: u32,
}

impl ClampedCapacitance {
    /// No compensation: the tracker then works on the total current (V-I phase).
    pub const NONE: Self = Self {
        full_scale_per_millihertz_q56: 0,
    };

    /// C0 of `capacitance_f` farads (>= 0) driven with `full_scale_voltage_v` volts of
    /// fundamental at full amplitude, sensed by a channel reading `amperes_per_full_scale` A
    /// per unit fraction of full scale (the current calibration's span, 6.6 A on the
    /// NUCLEO board). Set-up only (f64).
    ///
    /// Error `Setting` for non-finite or non-positive scales, a negative capacitance, or a
    /// capacitive current of 2 full scales or more at 60 kHz and full amplitude.
    pub fn new(
        capacitance_f: f64,
        full_scale_voltage_v: f64,
        amperes_per_full_scale: f64,
    ) -> Result<Self, ResonanceError> {
        let positive = |x: f64| x.is_finite() && x > 0.0;
        let valid = capacitance_f.is_finite()
            && capacitance_f >= 0.0
            && positive(full_scale_voltage_v)
            && positive(amperes_per_full_scale);
        if !valid {
            return Err(ResonanceError::Setting);
        }
        let per_millihertz = core::f64::consts::TAU * capacitance_f * full_scale_voltage_v
            / (1000.0 * amperes_per_full_scale);
        let at_band_top = per_millihertz * f64::from(Frequency::BAND_MAX.millihertz());
        if at_band_top >= 2.0 {
            return Err(ResonanceError::Setting);
        }
        let scaled = libm::round(per_millihertz * (1u64 << 56) as f64);
        Ok(Self {
            // < 2 / 6e7 x 2^56 = 2.4e9: fits u32.
            full_scale_per_millihertz_q56: scaled as u32,
        })
    }

    /// The capacitive current's amplitude at `frequency` and `amplitude`, Q2.30 full scale
    /// (its phase leads the voltage by a quarter turn). Integer only: two multiplications.
    pub const fn current(&self, frequency: Frequency, amplitude: Amplitude) -> Q2_30 {
        // mHz < 2^32 and the factor < 2^32: the product fits u64; >> 26 gives Q2.30 at full
        // amplitude, below 2^31 for in-band frequencies (checked at construction) and
        // saturated above.
        let full = (frequency.millihertz() as u64 * self.full_scale_per_millihertz_q56 as u64
            + (1 << 25))
            >> 26;
        let full = if full > i32::MAX as u64 {
            i32::MAX as u64
        } else {
            full
        };
        // amplitude <= 2^30 (Q2.30 in [0, 1]).
        let bits = (full * amplitude.fraction().to_bits() as u64 + (1 << 29)) >> 30;
        Q2_30::from_bits(bits as i32)
    }

    /// The motional current: `measured - j current(frequency, amplitude)`, saturated to Q2.30.
    pub const fn motional(
        &self,
        measured: Phasor,
        frequency: Frequency,
        amplitude: Amplitude,
    ) -> Phasor {
        let quadrature = measured.quadrature.to_bits() as i64
            - self.current(frequency, amplitude).to_bits() as i64;
        let quadrature = if quadrature < i32::MIN as i64 {
            i32::MIN
        } else {
            quadrature as i32
        };
        Phasor::new(measured.in_phase, Q2_30::from_bits(quadrature))
    }
}

/// The detuning `x = -Im / Re` of a motional current, in half-bandwidths (Q8.24), clamped to
/// +-[`MAX_DETUNING`]: positive above the resonance (the current lags). One division (a
/// control step's, not a sample's). A non-positive conductance, which only noise or a wrong
/// C0 produce, reads as the clamp in the direction the quadrature points.
pub fn detuning(motional: Phasor) -> Q8_24 {
    let re = i64::from(motional.in_phase.to_bits());
    let lag = -i64::from(motional.quadrature.to_bits()); // -Im, > 0 above resonance
    let limit = i64::from(MAX_DETUNING.to_bits()); // 16 in Q8.24
    // |lag| >= 16 re, tested without dividing (re < 2^31, so 16 re << 24 < 2^59).
    if re <= 0 || lag.abs() << 24 >= limit * re {
        return if lag >= 0 {
            MAX_DETUNING
        } else {
            Q8_24::from_bits(-MAX_DETUNING.to_bits())
        };
    }
    // |lag / re| < 16: the rounded quotient fits Q8.24.
    let bits = ((lag << 24) + if lag >= 0 { re / 2 } else { -re / 2 }) / re;
    Q8_24::from_bits(bits as i32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    /// The detuning -Im/Re is rounded to nearest Q8.24 on both sides of resonance, and is odd
    /// in the quadrature: below resonance (Im > 0) it is exactly the negative of above.
    #[test]
    fn detuning_is_rounded_to_nearest_on_both_sides() {
        let q = |bits: i32| Q2_30::from_bits(bits);
        for (re, im) in [
            (1 << 30, 1 << 29),
            (1 << 30, 3),
            (123_456_789, 98_765_432),
            (1 << 20, 7 << 20),
            (1_000_003, 1),
        ] {
            let want = f64::from(im) / f64::from(re) * 16_777_216.0;
            let below = detuning(Phasor::new(q(re), q(im))).to_bits();
            let above = detuning(Phasor::new(q(re), q(-im))).to_bits();
            assert!(
                (f64::from(above) - want).abs() <= 0.5,
                "{re} {im}: {above} vs {want}"
            );
            assert_eq!(below, -above, "{re} {im}");
        }
    }

    /// The reference stack (scenes/reference.toml): 300 nF, 3.1 ohm, Q 100 at 40 kHz, 5.25 V
    /// full scale, and the NUCLEO current sense's 6.6 A per full scale.
    const C0: f64 = 300e-9;
    const R1: f64 = 3.1;
    const Q: f64 = 100.0;
    const F0: f64 = 40_000.0;
    const V_FS: f64 = 5.25;
    const A_FS: f64 = 6.6;

    /// The measured current of the BVD model (settled), full-scale units, at `f` and `a`.
    fn bvd_current(f: f64, a: f64) -> (f64, f64) {
        let x = Q * (f / F0 - F0 / f);
        let v = a * V_FS;
        let (re, im) = (v / R1 / (1.0 + x * x), -v / R1 * x / (1.0 + x * x));
        (re / A_FS, (im + TAU * f * C0 * v) / A_FS)
    }

    fn phasor(re: f64, im: f64) -> Phasor {
        Phasor::new(Q2_30::from_f64(re).unwrap(), Q2_30::from_f64(im).unwrap())
    }

    fn amplitude(a: f64) -> Amplitude {
        Amplitude::new(Q2_30::from_f64(a).unwrap()).unwrap()
    }

    #[test]
    fn capacitive_current_matches_the_formula() {
        let c0 = ClampedCapacitance::new(C0, V_FS, A_FS).unwrap();
        for (hz, a) in [
            (20_000.0, 1.0),
            (40_000.0, 0.1),
            (60_000.0, 1.0),
            (43_210.5, 0.37),
        ] {
            let f = Frequency::from_millihertz((hz * 1000.0) as u32);
            let got = c0.current(f, amplitude(a)).to_f64();
            let want = TAU * hz * C0 * a * V_FS / A_FS;
            assert!(
                (got - want).abs() < 2e-8 + 1e-7 * want,
                "{hz} {a}: {got} {want}"
            );
        }
        assert_eq!(
            ClampedCapacitance::NONE.current(Frequency::BAND_MAX, Amplitude::FULL),
            Q2_30::ZERO
        );
        assert!(ClampedCapacitance::new(0.0, V_FS, A_FS).is_ok());
        for bad in [
            ClampedCapacitance::new(-1e-9, V_FS, A_FS),
            ClampedCapacitance::new(f64::NAN, V_FS, A_FS),
            ClampedCapacitance::new(C0, 0.0, A_FS),
            ClampedCapacitance::new(C0, V_FS, f64::INFINITY),
            // 2 pi 60 kHz 3 uF 5.25 V = 5.94 A: 2.05 full scales of a 2.9 A sensor.
            ClampedCapacitance::new(3e-6, V_FS, 2.9),
        ] {
            assert_eq!(bad, Err(ResonanceError::Setting));
        }
    }

    #[test]
    fn subtracting_c0_recovers_the_motional_phase_and_detuning() {
        let c0 = ClampedCapacitance::new(C0, V_FS, A_FS).unwrap();
        for hz in [
            36_000.0, 39_500.0, 39_900.0, 40_000.0, 40_150.0, 41_000.0, 44_000.0,
        ] {
            let (re, im) = bvd_current(hz, 0.1);
            let f = Frequency::from_millihertz((hz * 1000.0) as u32);
            let motional = c0.motional(phasor(re, im), f, amplitude(0.1));
            let x = Q * (hz / F0 - F0 / hz);
            let got = detuning(motional).to_f64();
            let want = x.clamp(-16.0, 16.0);
            // Quantisation of a 0.0025 full-scale conductance far off resonance limits the
            // agreement there.
            assert!(
                (got - want).abs() < 1e-4 * (1.0 + x * x),
                "{hz}: {got} vs {want}"
            );
            let phase = motional.polar().phase.to_radians();
            assert!(
                (phase + x.atan()).abs() < 1e-5 * (1.0 + x * x),
                "{hz}: {phase}"
            );
        }
    }

    #[test]
    fn the_v_i_phase_zero_misses_the_resonance_and_the_motional_one_does_not() {
        // Scan 1 Hz steps for the zero of each phase.
        let zero_of = |c0: ClampedCapacitance| {
            (39_900..40_200)
                .map(f64::from)
                .find(|&hz| {
                    let (re, im) = bvd_current(hz, 1.0);
                    let f = Frequency::from_hz(hz as u32);
                    let motional = c0.motional(phasor(re, im), f, Amplitude::FULL);
                    detuning(motional).is_positive()
                })
                .unwrap()
        };
        let compensated = zero_of(ClampedCapacitance::new(C0, V_FS, A_FS).unwrap());
        assert!((compensated - F0).abs() <= 1.0, "{compensated}");
        let total = zero_of(ClampedCapacitance::NONE);
        assert!(total - F0 > 0.001 * F0, "V-I phase zero at {total} Hz");
        // A C0 believed 10 % high over-subtracts: the zero moves down by
        // (f0 / 2Q) w dC R1 = 4.7 Hz.
        let off = zero_of(ClampedCapacitance::new(1.1 * C0, V_FS, A_FS).unwrap());
        let bias = F0 / (2.0 * Q) * TAU * F0 * 0.1 * C0 * R1;
        assert!((F0 - off - bias).abs() <= 1.5, "{off} vs {bias}");
    }

    #[test]
    fn detuning_clamps_and_never_divides_by_zero() {
        let q = |x: f64| Q2_30::from_f64(x).unwrap();
        let max = MAX_DETUNING.to_f64();
        assert_eq!(detuning(Phasor::ZERO).to_f64(), max);
        assert_eq!(detuning(Phasor::new(q(-0.1), q(0.01))).to_f64(), -max);
        assert_eq!(detuning(Phasor::new(q(0.001), q(-0.5))).to_f64(), max);
        assert_eq!(detuning(Phasor::new(q(0.001), q(0.5))).to_f64(), -max);
        assert_eq!(detuning(Phasor::new(Q2_30::MAX, Q2_30::MIN)).to_f64(), 1.0);
        assert!((detuning(Phasor::new(q(0.2), q(-0.1))).to_f64() - 0.5).abs() < 1e-7);
        // Saturation of the subtraction: a huge capacitive current on a minimal reading.
        let c0 = ClampedCapacitance::new(2.0e-6, V_FS, 2.0).unwrap();
        let m = c0.motional(
            Phasor::new(q(0.1), Q2_30::MIN),
            Frequency::BAND_MAX,
            Amplitude::FULL,
        );
        assert_eq!(m.quadrature, Q2_30::MIN);
    }
}
