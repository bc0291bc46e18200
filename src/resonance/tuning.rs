//! A drive frequency as the timer will really produce it.

use crate::drive::{DriveError, Frequency, PwmPeriod, TimerClock};

/// A TIM1 period and the frequency it produces: what the search and the tracker command, so
/// every frequency they reason about is one the hardware can make (steps of `f^2 / (16
/// f_clk)`, 0.59 Hz at 40 kHz and 170 MHz).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Tuning {
    /// The period to write (TIM1_ARR with dithering: [`PwmPeriod::arr_register`]).
    pub period: PwmPeriod,
    /// The frequency that period produces, to the millihertz: retune the lock-in with it.
    pub frequency: Frequency,
}

impl Tuning {
    /// The achievable tuning nearest to `requested`. Errors: those of [`PwmPeriod::nearest`].
    pub const fn nearest(requested: Frequency, clock: TimerClock) -> Result<Self, DriveError> {
        match PwmPeriod::nearest(requested, clock) {
            Ok(period) => Ok(Self {
                period,
                frequency: period.frequency(clock),
            }),
            Err(error) => Err(error),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tunings_land_on_the_timer_grid() {
        let clock = TimerClock::G474_TIM1;
        let tuning = Tuning::nearest(Frequency::from_millihertz(40_000_300), clock).unwrap();
        // 40 000.3 Hz lies between 40 000.000 and 40 000.588 Hz: the nearer is 40 000.588.
        assert_eq!(tuning.frequency.millihertz(), 40_000_588);
        assert_eq!(tuning.period.sixteenths(), 67_999);
        assert!(Tuning::nearest(Frequency::from_hz(61_000), clock).is_err());
    }
}
