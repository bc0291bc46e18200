//! The fixed-step sampled average of the Coulomb sign (physics-notes §1): the protocol whose
//! numbers seed 003 printed in Tables 2-3 ("Coulomb" columns, 63.21 % and 5.57 %), in fixed
//! point. The exact period average is the Littmann law ([`super::littmann`]); this sampled one
//! carries an O(1/N) error by design and exists to reproduce the paper.
//!
//! Samples at t_k = k dt, k = 0..N-1: a 64-bit phase accumulator (fraction of a turn, advanced
//! by round(f dt 2^64) per sample, so the phase wraps exactly like the angle and its drift is
//! below 1e-19 turn per sample) drives `fx::cos`; the sign of zeta + cos(phase) is counted.
//! Not a control-loop function: its cost is N times one `cos`, a rounding and a compare.

use crate::fx::{Q, Q2_30, cos};

use super::ModelError;
use super::fx_error;
use super::littmann::{VelocityRatio, velocity_ratio};
use crate::fx::Scaled;
use crate::fx::wide;

/// Largest number of samples accepted (as the reference: 1e8).
pub const MAX_SAMPLES: u32 = 100_000_000;

/// Sampling protocol: frequency, step and window, fixed per scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SampledSign {
    /// Phase step per sample, fraction of a turn in units of 2^-64.
    increment: u64,
    /// Number of samples N = round(Tw / dt), 1..=1e8.
    samples: u32,
}

impl SampledSign {
    /// Protocol from the vibration frequency `frequency_hz` (> 0), the sampling step
    /// `time_step_s` (> 0) and the window `window_s` (> 0) in SI units (f64, scene load).
    ///
    /// Errors: `NonFinite`; `OutOfDomain` for a value <= 0, N = round(Tw / dt) outside
    /// 1..=1e8, or fewer than two samples per vibration period (f dt > 1/2): such samples alias
    /// onto a slower beat of the phase, and when f dt is a whole number every sample falls at
    /// the same phase (a "200 % reduction" from one phase of the cosine).
    pub fn new(frequency_hz: f64, time_step_s: f64, window_s: f64) -> Result<Self, ModelError> {
        let f = positive("f", frequency_hz)?;
        let dt = positive("dt", time_step_s)?;
        let tw = positive("Tw", window_s)?;
        if f * dt > 0.5 {
            return Err(ModelError::OutOfDomain {
                input: "dt",
                reason: "fewer than 2 samples per vibration period (f dt > 1/2): the samples \
                         alias (at f dt = 1, 2, ... all fall at one phase); take dt <= 1 / (2 f)",
            });
        }
        let samples = libm::round(tw / dt);
        if !(1.0..=MAX_SAMPLES as f64).contains(&samples) {
            return Err(ModelError::OutOfDomain {
                input: "Tw",
                reason: "Tw / dt must round to between 1 and 1e8 samples",
            });
        }
        let cycles = f * dt;
        let fraction = cycles - libm::floor(cycles); // whole turns do not move the phase
        // fraction in [0, 1): its 2^64 multiple rounds into u64 (1.0 wraps to 0, as a turn does).
        let increment = libm::round(fraction * 18_446_744_073_709_551_616.0);
        let increment = if increment >= 18_446_744_073_709_551_616.0 {
            0
        } else {
            increment as u64
        };
        Ok(Self {
            increment,
            samples: samples as u32,
        })
    }

    /// Number of samples N.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// (1/N) sum_k sgn(v + v_a cos(2 pi f k dt)) with sgn(0) = 0: Q2.30 in [-1, 1], rounded to
    /// nearest. Inputs: sliding velocity `v` in m/s (any format, any sign) and vibration velocity
    /// amplitude `v_a` in m/s (`None` = no vibration).
    ///
    /// Each sample compares zeta (Q2.30, exact to 9.3e-10) with -cos (Q1.31 rounded to Q2.30 so
    /// that cos 0 = 1 and cos pi = -1 exactly): a sample within about 1e-9 of a sign change may
    /// count differently from an f64 evaluation. Error `OutOfDomain` for v = 0 without
    /// vibration.
    pub fn mean_sign<const FV: u32>(
        &self,
        v: Q<FV>,
        v_a: Option<Scaled>,
    ) -> Result<Q2_30, ModelError> {
        let ratio = velocity_ratio(v, v_a)?;
        let sign_of_v: i64 = if ratio.is_negative() { -1 } else { 1 };
        // zeta in Q2.30 when |zeta| < 2; beyond, every sample has the sign of v.
        let zeta_bits = match ratio {
            VelocityRatio::Zero => Some(0i64),
            VelocityRatio::Finite { magnitude, .. } => {
                let z = wide::to_q::<30>(magnitude);
                (!z.saturated).then_some(sign_of_v * z.value.to_bits() as i64)
            }
            VelocityRatio::Infinite { .. } => None,
        };
        let sum = match zeta_bits {
            None => sign_of_v * self.samples as i64,
            Some(zeta) => {
                let mut phase: u64 = 0;
                let mut sum: i64 = 0;
                for _ in 0..self.samples {
                    // Nearest 2^-32 turn (the top word rounded; 2^64 - 2^31 and up wraps to 0).
                    let turn = (phase.wrapping_add(1 << 31) >> 32) as u32;
                    let c = cos(turn).to_bits() as i64;
                    let c30 = if c >= 0 {
                        (c + 1) >> 1
                    } else {
                        -((1 - c) >> 1)
                    };
                    let total = zeta + c30;
                    sum += total.signum();
                    phase = phase.wrapping_add(self.increment);
                }
                sum
            }
        };
        // |sum| <= N <= 1e8 fits an i32.
        Q2_30::from_ratio(sum as i32, self.samples as i32).map_err(fx_error("mean_sign"))
    }
}

fn positive(input: &'static str, x: f64) -> Result<f64, ModelError> {
    if !x.is_finite() {
        Err(ModelError::NonFinite { input })
    } else if x <= 0.0 {
        Err(ModelError::OutOfDomain {
            input,
            reason: "must be > 0",
        })
    } else {
        Ok(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fx::Q8_24;

    /// Seed 003's protocol: 0.1 us steps over 1 ms at 40 kHz, v_a = 0.0683 m/s.
    fn seed003() -> (SampledSign, Option<Scaled>) {
        (
            SampledSign::new(40e3, 1e-7, 1e-3).unwrap(),
            crate::model::scaled_from_f64(0.0683, "v_a").ok(),
        )
    }

    #[test]
    fn reproduces_seed_003_printed_coulomb_columns() {
        let (protocol, v_a) = seed003();
        assert_eq!(protocol.samples(), 10_000);
        // 171 of 250 samples positive per period: mean 92/250, reduction 63.20 % (printed
        // 63.21 %); at 0.068 m/s 243 of 250: mean 236/250, 5.60 % (printed 5.57 %).
        for (v, positive_per_period) in [(0.038, 171), (0.068, 243)] {
            let mean = protocol
                .mean_sign(Q8_24::from_f64(v).unwrap(), v_a)
                .unwrap();
            let want = (2 * positive_per_period - 250) as f64 / 250.0;
            assert!((mean.to_f64() - want).abs() < 1e-9, "{v}: {mean:?}");
            let negated = protocol
                .mean_sign(Q8_24::from_f64(-v).unwrap(), v_a)
                .unwrap();
            assert_eq!(negated.to_bits(), -mean.to_bits());
        }
    }

    #[test]
    fn limits_and_errors() {
        let (protocol, v_a) = seed003();
        let fast = protocol.mean_sign(Q8_24::from_f64(0.2).unwrap(), v_a);
        assert_eq!(fast, Ok(Q2_30::ONE));
        let none = protocol.mean_sign(Q8_24::from_f64(-0.2).unwrap(), None);
        assert_eq!(none.unwrap().to_f64(), -1.0);
        // v = 0: the cosine's signs cancel over whole periods.
        assert_eq!(protocol.mean_sign(Q8_24::ZERO, v_a), Ok(Q2_30::ZERO));
        assert!(protocol.mean_sign(Q8_24::ZERO, None).is_err());
        assert!(SampledSign::new(40e3, 1e-7, 1e3).is_err());
        assert!(SampledSign::new(40e3, 0.0, 1e-3).is_err());
        assert!(SampledSign::new(f64::NAN, 1e-7, 1e-3).is_err());
        // One sample per whole turn would put every sample at phase 0 (issue 15: v = -0.2,
        // v_a = 0.77 read as a 200 % reduction): refused, as is anything under two samples per
        // period; exactly two per period (phases 0 and pi) is the limit accepted.
        assert!(SampledSign::new(40e3, 2.5e-5, 1e-3).is_err());
        assert!(SampledSign::new(1.0, 1.0, 10.0).is_err());
        assert!(SampledSign::new(1.0, 0.5000001, 10.0).is_err());
        let nyquist = SampledSign::new(1.0, 0.5, 10.0).unwrap();
        assert_eq!(nyquist.increment, 1 << 63);
        let m = nyquist.mean_sign(
            Q8_24::from_f64(-0.5).unwrap(),
            crate::model::scaled_from_f64(1.0, "v_a").ok(),
        );
        // Phase 0: -0.5 + 1 > 0; phase pi: -0.5 - 1 < 0: the signs cancel.
        assert_eq!(m, Ok(Q2_30::ZERO));
    }
}
