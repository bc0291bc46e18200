//! Gain schedule of the PI: fast right after the operating point is set, quiet afterwards.
//!
//! The PI corrects the model error, which is a property of the operating point: it must be
//! found quickly after a target change (the acceptance asks for settling within 3 ms under a
//! +-20 % model mismatch), but once found it changes only as slowly as the load and the
//! surfaces do. A PI fast enough for the first task passes the load cells' noise through to
//! the friction at several hundred hertz. So the gains start at the `fast` set when the loop
//! closes or the target changes, and relax to the `slow` set as a scalar Kalman filter's gain
//! does after its covariance is reset: `g = slow + (fast - slow) w`. While the drive's
//! transient lasts (`hold`, about three time constants of the lag chain the model error is
//! seen through: `control/tuning.rs`) the model error the cells show is still moving, the
//! filter's process noise is large and its gain stays at the fast value (`w = 1`). Once the
//! error it observes is constant, the Riccati equation without process noise, `P' = -P^2 /
//! r`, makes the gain `K = P / r` fall as `1 / (t + 1 / K_fast)`: the running mean of what
//! has been seen since. In weight terms `w' = -K_fast w^2`, one step `w <- w - (K_fast T) w^2`
//! (one multiply; `K_fast T` is the fast set's `ki T`). The fade is independent of the noise
//! (the running mean is the best estimate of a constant whatever the noise); the noise sets
//! `K_fast` and the `slow` floor. The gains change a little every step;
//! [`super::pi::Pi::retune`] keeps each change bumpless.

use super::SampleBlock;
use super::pi::{GainsError, PiGains};
use crate::fx::Q2_30;

/// The two gain sets and how fast the boost fades (configuration).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GainSchedule {
    fast: PiGains,
    slow: PiGains,
    /// Steps the fast gains are held after a restart.
    hold_steps: u32,
    /// Shrink of the weight per step, `K_fast T` (the fast `ki T`), Q2.30 in [0, 1].
    shrink: Q2_30,
}

impl GainSchedule {
    /// `fast` gains held for `hold_s` after a restart, then fading into `slow` ones by the
    /// running-mean law (module docs) at the control period `period_s`. Error `NotFinite`
    /// unless the hold is finite and non-negative and the period positive.
    pub fn new(
        fast: PiGains,
        slow: PiGains,
        hold_s: f64,
        period_s: f64,
    ) -> Result<Self, GainsError> {
        if !(hold_s >= 0.0 && hold_s.is_finite() && period_s > 0.0 && period_s.is_finite()) {
            return Err(GainsError::NotFinite);
        }
        let hold_steps = libm::round(hold_s / period_s).min(u32::MAX as f64) as u32;
        Ok(Self {
            fast,
            slow,
            hold_steps,
            shrink: fast.ki_step(),
        })
    }

    /// The same gains all the time (no boost).
    pub const fn constant(gains: PiGains) -> Self {
        Self {
            fast: gains,
            slow: gains,
            hold_steps: 0,
            shrink: Q2_30::ONE,
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

    /// Steps the fast gains are held after a restart.
    pub const fn hold_steps(&self) -> u32 {
        self.hold_steps
    }

    /// Shrink of the weight per step after the hold, `K_fast T`, Q2.30 in [0, 1].
    pub const fn shrink(&self) -> Q2_30 {
        self.shrink
    }
}

/// The boost weight, state: 1 after [`Boost::restart`], held, then fading by the schedule's
/// running-mean law.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Boost {
    weight: Q2_30,
    /// Steps held since the restart (up to the schedule's hold).
    held: u32,
}

impl Boost {
    /// No boost.
    pub const fn new() -> Self {
        Self {
            weight: Q2_30::ZERO,
            held: 0,
        }
    }

    /// Full boost (the operating point was just set).
    pub fn restart(&mut self) {
        self.weight = Q2_30::ONE;
        self.held = 0;
    }

    /// The weight, Q2.30 in [0, 1].
    pub const fn weight(&self) -> Q2_30 {
        self.weight
    }
}

/// The schedule: one step (no input) gives this step's gains, at the boost's weight, and
/// advances the boost: held for the schedule's hold, then `w <- w - (K_fast T) w^2`. The
/// decrement is rounded up (at least one lsb while `w > 0`), so that the weight reaches
/// exactly zero (rounding to nearest would stop it where `s w^2` rounds to nothing).
impl SampleBlock<()> for GainSchedule {
    type State = Boost;
    type Output = PiGains;

    fn process(&self, boost: &mut Boost, (): ()) -> PiGains {
        let gains = self.gains(boost.weight);
        if boost.held < self.hold_steps {
            boost.held += 1;
            return gains;
        }
        // w and s in [0, 2^30]: w^2 < 2^61 and (w^2 >> 30) s < 2^61, both fit i64.
        let w = boost.weight.to_bits() as i64;
        let square = (w * w + (1 << 30) - 1) >> 30;
        let decrement = (square * self.shrink.to_bits() as i64 + (1 << 30) - 1) >> 30;
        boost.weight = Q2_30::from_bits((w - decrement.max(i64::from(w > 0))).max(0) as i32);
        gains
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boost_fades_from_fast_to_slow() {
        let fast = PiGains::new(0.3, 3_000.0, 1e-4, 0.5).unwrap();
        let slow = PiGains::new(0.0, 500.0, 1e-4, 0.5).unwrap();
        // Held for 1 ms (10 steps), then the running mean from ki 3000 /s.
        let schedule = GainSchedule::new(fast, slow, 1e-3, 1e-4).unwrap();
        let mut boost = Boost::new();
        assert_eq!(schedule.gains(boost.weight()), slow);
        boost.restart();
        for _ in 0..10 {
            assert_eq!(schedule.gains(boost.weight()), fast);
            schedule.process(&mut boost, ());
        }
        assert_eq!(schedule.gains(boost.weight()), fast);
        for _ in 0..100 {
            schedule.process(&mut boost, ());
        }
        // 10 ms after the hold: w = 1 / (1 + K_fast t) = 1 / 31 by the continuous law; the
        // one-step recurrence of w' = -K w^2 with K T = 0.3 runs a little slower (it sums
        // 1/w in steps of K T / (1 - K T w)): within 5 %.
        let w = boost.weight().to_f64();
        assert!((w * 31.0 - 1.0).abs() < 0.05, "{w}");
        let g = schedule.gains(boost.weight());
        assert!(
            (g.ki_step().to_f64() - (0.05 + 0.25 * w)).abs() < 1e-6,
            "{g:?}"
        );
        // The hyperbola reaches 2^-15 after about 1 / (K T 2^-15) = 110 000 steps, then one lsb
        // a step to zero.
        for _ in 0..200_000 {
            schedule.process(&mut boost, ());
        }
        assert_eq!(boost.weight(), Q2_30::ZERO);
        assert_eq!(schedule.gains(boost.weight()), slow);
        let constant = GainSchedule::constant(fast);
        assert_eq!(constant.gains(Q2_30::ONE), constant.gains(Q2_30::ZERO));
        assert!(GainSchedule::new(fast, slow, -1.0, 1e-4).is_err());
        assert!(GainSchedule::new(fast, slow, f64::NAN, 1e-4).is_err());
    }
}
