//! PI on the friction-ratio error, with clamping anti-windup and bumpless gain changes.
//!
//! The output is a *correction* `c` of the friction ratio (Q2.30) that the controller adds to
//! the target before inverting the model: the feedforward is the model inversion itself, and
//! the PI only corrects the model error (see the controller's module docs for the reference
//! it compares against and the tuning).
//!
//! - `c = kp e + I`, `I += ki T e` each step. `I` stores the integral already multiplied by
//!   `ki`, so changing `ki` never moves the output; changing `kp` moves `I` by
//!   `(kp_old - kp_new) e` so that `c` does not jump either ([`Pi::retune`]).
//! - Clamping anti-windup: the integral is frozen in a step where the drive is clamped in the
//!   direction the error pushes (conditional integration). A correction that rises lowers the
//!   drive, so a drive at its floor (the model says no vibration: natural friction) clamps the
//!   correction from above, a drive at its ceiling (full drive, the actuator limits or the
//!   soft start) from below. The integral is also bounded to `+-integral_limit` whatever
//!   happens, so it is bounded even if a saturation is not reported.
//! - Evaluation is two-phase because the clamp is only known after the inversion:
//!   [`Pi::candidate`] proposes, the controller inverts with the proposal, then [`Pi::commit`]
//!   keeps or drops the integration.

use crate::fx::{Q2_30, Q8_24};

/// Why gains could not be made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GainsError {
    /// A gain, the period or the limit was negative, NaN or infinite (or the period zero).
    NotFinite,
    /// `kp >= 128`, `ki T > 1` (the correction loop would oscillate) or `integral_limit >= 2`.
    OutOfRange,
}

/// Gains of the PI (configuration: `Copy`, swapped atomically).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PiGains {
    kp: Q8_24,
    ki_step: Q2_30,
    integral_limit: Q2_30,
}

impl PiGains {
    /// Gains from a proportional gain `kp` (ratio per ratio, [0, 128)), an integral gain
    /// `ki_per_s` (1/s, `ki T` in [0, 1]) at the control period `period_s`, and the bound of
    /// the integral (ratio units, [0, 2)). Configuration only (`f64`).
    pub fn new(
        kp: f64,
        ki_per_s: f64,
        period_s: f64,
        integral_limit: f64,
    ) -> Result<Self, GainsError> {
        let ok = |x: f64| x.is_finite() && x >= 0.0;
        if !(ok(kp) && ok(ki_per_s) && ok(integral_limit) && period_s.is_finite() && period_s > 0.0)
        {
            return Err(GainsError::NotFinite);
        }
        let ki_step = ki_per_s * period_s;
        if kp >= 128.0 || ki_step > 1.0 || integral_limit >= 2.0 {
            return Err(GainsError::OutOfRange);
        }
        let convert = |x: f64| Q2_30::from_f64(x).map_err(|_| GainsError::OutOfRange);
        Ok(Self {
            kp: Q8_24::from_f64(kp).map_err(|_| GainsError::OutOfRange)?,
            ki_step: convert(ki_step)?,
            integral_limit: convert(integral_limit)?,
        })
    }

    /// Proportional gain, Q8.24, dimensionless.
    pub const fn kp(&self) -> Q8_24 {
        self.kp
    }

    /// Integral gain times the period (`ki T`), Q2.30 in [0, 1].
    pub const fn ki_step(&self) -> Q2_30 {
        self.ki_step
    }

    /// Bound of the integral, Q2.30 ratio units in [0, 2).
    pub const fn integral_limit(&self) -> Q2_30 {
        self.integral_limit
    }

    /// The gains `weight` of the way from `self` to `toward` (`weight` Q2.30 in [0, 1]),
    /// each rounded to nearest.
    pub fn lerp(&self, toward: &PiGains, weight: Q2_30) -> PiGains {
        // Between two values of the same format with a weight in [0, 1]: cannot fail.
        PiGains {
            kp: self.kp.lerp(toward.kp, weight).unwrap_or(self.kp),
            ki_step: self
                .ki_step
                .lerp(toward.ki_step, weight)
                .unwrap_or(self.ki_step),
            integral_limit: self
                .integral_limit
                .lerp(toward.integral_limit, weight)
                .unwrap_or(self.integral_limit),
        }
    }
}

/// In which direction the correction is clamped by the drive this step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Clamp {
    /// The drive is free: integrate.
    Free,
    /// A larger correction would change nothing (the drive is at its floor).
    Upper,
    /// A smaller correction would change nothing (the drive is at its ceiling).
    Lower,
}

/// A proposed step of the PI, before the clamp is known.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PiCandidate {
    error: Q2_30,
    integral: Q2_30,
    correction: Q2_30,
}

impl PiCandidate {
    /// The correction if the integration is kept, Q2.30 ratio units.
    pub const fn correction(&self) -> Q2_30 {
        self.correction
    }
}

/// State of the PI.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Pi {
    integral: Q2_30,
    correction: Q2_30,
    error: Q2_30,
    frozen: bool,
}

impl Pi {
    /// At rest: no correction.
    pub const fn new() -> Self {
        Self {
            integral: Q2_30::ZERO,
            correction: Q2_30::ZERO,
            error: Q2_30::ZERO,
            frozen: false,
        }
    }

    /// Back to rest (used when the loop closes).
    pub fn reset(&mut self) {
        *self = Self::new();
    }

    /// The step for `error` (Q2.30, reference minus measured ratio) if it integrates.
    pub fn candidate(&self, gains: &PiGains, error: Q2_30) -> PiCandidate {
        let step = gains.ki_step.saturating_mul(error).value;
        let integral = clamp_abs(
            self.integral.saturating_add(step).value,
            gains.integral_limit,
        );
        PiCandidate {
            error,
            integral,
            correction: output(gains, error, integral),
        }
    }

    /// Keeps the candidate's integration unless `clamp` holds it in the direction of the
    /// error (then the integral stays); returns the correction, Q2.30.
    pub fn commit(&mut self, gains: &PiGains, candidate: PiCandidate, clamp: Clamp) -> Q2_30 {
        let error = candidate.error;
        self.frozen = match clamp {
            Clamp::Free => false,
            Clamp::Upper => error.is_positive(),
            Clamp::Lower => error.is_negative(),
        };
        if self.frozen {
            // The old integral may exceed a limit lowered since: keep it bounded.
            self.integral = clamp_abs(self.integral, gains.integral_limit);
            self.correction = output(gains, error, self.integral);
        } else {
            self.integral = candidate.integral;
            self.correction = candidate.correction;
        }
        self.error = error;
        self.correction
    }

    /// Switches from gains `old` to `new` without a jump of the output: the integral absorbs
    /// the change of `kp e` at the last error (bumpless). Only a lower `integral_limit` that
    /// cuts the present integral moves the output.
    pub fn retune(&mut self, old: &PiGains, new: &PiGains) {
        let kp_change = old.kp.saturating_sub(new.kp).value;
        let shift = kp_change.saturating_mul_to::<30, 30>(self.error).value;
        self.integral = clamp_abs(
            self.integral.saturating_add(shift).value,
            new.integral_limit,
        );
        self.correction = output(new, self.error, self.integral);
    }

    /// The correction of the last step, Q2.30 ratio units.
    pub const fn correction(&self) -> Q2_30 {
        self.correction
    }

    /// The integral (already times `ki`), Q2.30 ratio units, within `+-integral_limit`.
    pub const fn integral(&self) -> Q2_30 {
        self.integral
    }

    /// Whether the last step froze the integral.
    pub const fn frozen(&self) -> bool {
        self.frozen
    }
}

/// `kp e + integral`, saturated to Q2.30.
fn output(gains: &PiGains, error: Q2_30, integral: Q2_30) -> Q2_30 {
    let proportional = gains.kp.saturating_mul_to::<30, 30>(error).value;
    proportional.saturating_add(integral).value
}

/// `value` clamped to `[-limit, limit]` (`limit >= 0`). Written with `max`/`min`, which have
/// no panic path (`clamp` asserts its bounds are ordered).
fn clamp_abs(value: Q2_30, limit: Q2_30) -> Q2_30 {
    let low = Q2_30::from_bits(-limit.to_bits());
    value.min(limit).max(low)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn q(x: f64) -> Q2_30 {
        Q2_30::from_f64(x).unwrap()
    }

    fn gains(kp: f64, ki: f64) -> PiGains {
        PiGains::new(kp, ki, 1e-4, 0.5).unwrap()
    }

    #[test]
    fn proportional_and_integral_action() {
        let g = gains(0.5, 1_000.0); // ki T = 0.1
        let mut pi = Pi::new();
        let c = pi.candidate(&g, q(0.2));
        assert!((c.correction().to_f64() - (0.1 + 0.02)).abs() < 1e-9);
        assert!((pi.commit(&g, c, Clamp::Free).to_f64() - 0.12).abs() < 1e-9);
        let c = pi.candidate(&g, q(0.2));
        assert!((pi.commit(&g, c, Clamp::Free).to_f64() - 0.14).abs() < 1e-9);
        assert!((pi.integral().to_f64() - 0.04).abs() < 1e-9);
    }

    #[test]
    fn clamping_freezes_only_in_the_direction_of_the_error() {
        let g = gains(0.0, 1_000.0);
        let mut pi = Pi::new();
        for _ in 0..100 {
            let c = pi.candidate(&g, q(0.3));
            pi.commit(&g, c, Clamp::Upper);
            assert!(pi.frozen());
        }
        assert_eq!(pi.integral(), Q2_30::ZERO);
        // The opposite clamp does not hold a positive error back.
        let c = pi.candidate(&g, q(0.3));
        pi.commit(&g, c, Clamp::Lower);
        assert!(!pi.frozen());
        assert!((pi.integral().to_f64() - 0.03).abs() < 1e-9);
        // And a negative error may leave an upper clamp at once.
        let c = pi.candidate(&g, q(-0.1));
        pi.commit(&g, c, Clamp::Upper);
        assert!(!pi.frozen());
        assert!((pi.integral().to_f64() - 0.02).abs() < 1e-9);
    }

    #[test]
    fn integral_is_bounded_without_any_clamp_report() {
        let g = gains(1.0, 10_000.0); // ki T = 1, limit 0.5
        let mut pi = Pi::new();
        for _ in 0..1_000 {
            let c = pi.candidate(&g, Q2_30::MAX);
            pi.commit(&g, c, Clamp::Free);
        }
        assert_eq!(pi.integral(), q(0.5));
        for _ in 0..1_000 {
            let c = pi.candidate(&g, Q2_30::MIN);
            pi.commit(&g, c, Clamp::Free);
        }
        assert_eq!(pi.integral(), q(-0.5));
    }

    #[test]
    fn gain_changes_are_bumpless() {
        let old = gains(0.3, 2_000.0);
        let mut pi = Pi::new();
        for _ in 0..7 {
            let c = pi.candidate(&old, q(0.05));
            pi.commit(&old, c, Clamp::Free);
        }
        let before = pi.correction();
        for new in [gains(0.0, 2_000.0), gains(2.0, 500.0), gains(0.3, 0.0)] {
            let mut p = pi;
            p.retune(&old, &new);
            assert!(
                (p.correction().to_f64() - before.to_f64()).abs() < 2e-9,
                "{new:?}: {:?} -> {:?}",
                before,
                p.correction()
            );
        }
    }

    #[test]
    fn gains_are_validated() {
        assert_eq!(
            PiGains::new(-1.0, 0.0, 1e-4, 0.5),
            Err(GainsError::NotFinite)
        );
        assert_eq!(
            PiGains::new(0.0, f64::NAN, 1e-4, 0.5),
            Err(GainsError::NotFinite)
        );
        assert_eq!(PiGains::new(0.0, 1.0, 0.0, 0.5), Err(GainsError::NotFinite));
        assert_eq!(
            PiGains::new(200.0, 1.0, 1e-4, 0.5),
            Err(GainsError::OutOfRange)
        );
        assert_eq!(
            PiGains::new(0.1, 20_000.0, 1e-4, 0.5),
            Err(GainsError::OutOfRange)
        );
        assert_eq!(
            PiGains::new(0.1, 1.0, 1e-4, 2.0),
            Err(GainsError::OutOfRange)
        );
    }

    proptest! {
        #[test]
        fn any_errors_and_clamps_keep_the_integral_bounded(
            steps in proptest::collection::vec((any::<i32>(), 0u8..3), 1..200),
            kp in 0.0f64..100.0, ki in 0.0f64..10_000.0, limit in 0.0f64..1.99,
        ) {
            let g = PiGains::new(kp, ki, 1e-4, limit).unwrap();
            let mut pi = Pi::new();
            for (bits, clamp) in steps {
                let clamp = [Clamp::Free, Clamp::Upper, Clamp::Lower][clamp as usize];
                let c = pi.candidate(&g, Q2_30::from_bits(bits));
                pi.commit(&g, c, clamp);
                prop_assert!(pi.integral().to_bits().unsigned_abs() <= g.integral_limit().to_bits() as u32);
            }
        }
    }
}
