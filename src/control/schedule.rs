//! Gain schedule of the PI: fast right after the operating point is set, quiet afterwards.
//!
//! The PI corrects the model error, which is a property of the operating point: it must be
//! found quickly after a target change (the acceptance asks for settling within 3 ms under a
//! +-20 % model mismatch), but once found it changes only as slowly as the load and the
//! surfaces do. A PI fast enough for the first task passes the load cells' noise through to
//! the friction at several hundred hertz. So the gains start at the `fast` set when the loop
//! closes or the target changes, and relax to the `slow` set exponentially with a time
//! constant `tau_boost`: `g = slow + (fast - slow) w`, `w <- w exp(-T / tau_boost)`, the way a
//! Kalman filter's gain falls after its covariance is reset. The gains change a little every
//! step; [`super::pi::Pi::retune`] keeps each change bumpless.

use super::pi::{GainsError, PiGains};
use crate::fx::Q2_30;

/// The two gain sets and how fast the boost fades (configuration).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GainSchedule {
    fast: PiGains,
    slow: PiGains,
    decay: Q2_30,
}

impl GainSchedule {
    /// `fast` gains fading into `slow` ones with time constant `boost_time_constant_s` at
    /// the control period `period_s`. Error `NotFinite` unless both times are positive.
    pub fn new(
        fast: PiGains,
        slow: PiGains,
        boost_time_constant_s: f64,
        period_s: f64,
    ) -> Result<Self, GainsError> {
        if !(boost_time_constant_s > 0.0 && period_s > 0.0 && period_s.is_finite()) {
            return Err(GainsError::NotFinite);
        }
        let decay = libm::exp(-period_s / boost_time_constant_s);
        Ok(Self {
            fast,
            slow,
            decay: Q2_30::from_f64(decay).map_err(|_| GainsError::OutOfRange)?,
        })
    }

    /// The same gains all the time (no boost).
    pub const fn constant(gains: PiGains) -> Self {
        Self {
            fast: gains,
            slow: gains,
            decay: Q2_30::ZERO,
        }
    }

    /// The gains at boost weight `weight` (Q2.30, 1 = fast, 0 = slow).
    pub fn gains(&self, weight: Q2_30) -> PiGains {
        self.slow.lerp(&self.fast, weight)
    }

    /// The fast gains.
    pub const fn fast(&self) -> PiGains {
        self.fast
    }

    /// The slow (steady-state) gains.
    pub const fn slow(&self) -> PiGains {
        self.slow
    }

    /// Factor of the boost weight per step, `exp(-T / tau_boost)`, Q2.30 in [0, 1).
    pub const fn decay(&self) -> Q2_30 {
        self.decay
    }
}

/// The boost weight, state: 1 after [`Boost::restart`], fading by the schedule's decay.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Boost {
    weight: Q2_30,
}

impl Boost {
    /// No boost.
    pub const fn new() -> Self {
        Self {
            weight: Q2_30::ZERO,
        }
    }

    /// Full boost (the operating point was just set).
    pub fn restart(&mut self) {
        self.weight = Q2_30::ONE;
    }

    /// One step of fading. Rounded down, so that the weight reaches exactly zero (rounding
    /// to nearest would stop it at the few ulps where `w decay` rounds back to `w`).
    pub fn advance(&mut self, schedule: &GainSchedule) {
        // Both in [0, 2^30]: the product fits i64 and the result [0, 2^30].
        let product = self.weight.to_bits() as i64 * schedule.decay.to_bits() as i64;
        self.weight = Q2_30::from_bits((product >> 30) as i32);
    }

    /// The weight, Q2.30 in [0, 1].
    pub const fn weight(&self) -> Q2_30 {
        self.weight
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boost_fades_from_fast_to_slow() {
        let fast = PiGains::new(0.3, 3_000.0, 1e-4, 0.5).unwrap();
        let slow = PiGains::new(0.0, 500.0, 1e-4, 0.5).unwrap();
        let schedule = GainSchedule::new(fast, slow, 3e-3, 1e-4).unwrap();
        let mut boost = Boost::new();
        assert_eq!(schedule.gains(boost.weight()), slow);
        boost.restart();
        assert_eq!(schedule.gains(boost.weight()), fast);
        for _ in 0..30 {
            boost.advance(&schedule);
        }
        // After one time constant: slow + (fast - slow) / e.
        let g = schedule.gains(boost.weight());
        let want = 0.05 + 0.25 * (-1.0f64).exp();
        assert!((g.ki_step().to_f64() - want).abs() < 1e-6, "{g:?}");
        assert!((g.kp().to_f64() - 0.3 * (-1.0f64).exp()).abs() < 1e-6);
        for _ in 0..10_000 {
            boost.advance(&schedule);
        }
        assert_eq!(boost.weight(), Q2_30::ZERO);
        assert_eq!(schedule.gains(boost.weight()), slow);
        let constant = GainSchedule::constant(fast);
        assert_eq!(constant.gains(Q2_30::ONE), constant.gains(Q2_30::ZERO));
        assert!(GainSchedule::new(fast, slow, 0.0, 1e-4).is_err());
    }
}
