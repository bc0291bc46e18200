//! The kernel clock of the PWM timer.

use super::error::DriveError;

/// The clock that TIM1 counts, in hertz (1 to 200 MHz).
///
/// On the NUCLEO-G474RE this is 170 MHz: SYSCLK from the PLL with APB2 undivided, so TIM1
/// counts at PCLK2 (RM0440, RCC chapter, clock tree). The prescaler stays at 1: every division
/// would multiply the frequency step (see [`crate::drive::PwmPeriod`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TimerClock {
    hz: u32,
}

impl TimerClock {
    /// The G474's TIM1 clock at the board's 170 MHz system clock.
    pub const G474_TIM1: Self = Self { hz: 170_000_000 };

    /// A timer clock of `hz` Hz. Error `TimerClockOutOfRange` outside 1-200 MHz: below, one
    /// tick would be a sizeable part of a 60 kHz period; above, no STM32G4 timer runs.
    pub const fn new(hz: u32) -> Result<Self, DriveError> {
        if hz < 1_000_000 || hz > 200_000_000 {
            return Err(DriveError::TimerClockOutOfRange { clock_hz: hz });
        }
        Ok(Self { hz })
    }

    /// The clock in hertz.
    pub const fn hz(self) -> u32 {
        self.hz
    }

    /// `ticks` clock periods in nanoseconds, rounded to nearest. Exact in `u64` for any
    /// `ticks` up to `u32::MAX`.
    pub const fn ticks_to_ns(self, ticks: u32) -> u32 {
        let ns = (ticks as u64 * 1_000_000_000 + self.hz as u64 / 2) / self.hz as u64;
        if ns > u32::MAX as u64 {
            u32::MAX
        } else {
            ns as u32
        }
    }

    /// The fewest whole ticks lasting at least `ns` nanoseconds (rounded up).
    pub const fn ns_to_ticks_ceil(self, ns: u32) -> u64 {
        (ns as u64 * self.hz as u64).div_ceil(1_000_000_000)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn range_is_enforced() {
        assert_eq!(TimerClock::new(170_000_000), Ok(TimerClock::G474_TIM1));
        assert_eq!(
            TimerClock::new(999_999),
            Err(DriveError::TimerClockOutOfRange { clock_hz: 999_999 })
        );
        assert!(TimerClock::new(200_000_001).is_err());
        assert!(TimerClock::new(200_000_000).is_ok());
    }

    #[test]
    fn tick_conversions_round_the_right_way() {
        let clock = TimerClock::G474_TIM1;
        // One tick is 5.88 ns.
        assert_eq!(clock.ticks_to_ns(1), 6);
        assert_eq!(clock.ticks_to_ns(17), 100);
        assert_eq!(clock.ns_to_ticks_ceil(100), 17);
        assert_eq!(clock.ns_to_ticks_ceil(101), 18);
        assert_eq!(clock.ns_to_ticks_ceil(0), 0);
        assert_eq!(clock.ns_to_ticks_ceil(u32::MAX), 730_144_441);
        assert_eq!(clock.ticks_to_ns(u32::MAX), u32::MAX);
    }
}
