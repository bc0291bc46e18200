//! Dead time between the complementary outputs: nanoseconds to the TIM1_BDTR.DTG byte.
//!
//! The dead-time generator delays the rising edge of each of CH1 and CH1N by `DT` so the two
//! switches of the half-bridge are never on together. DTG[7:0] encodes `DT` in four ranges of
//! `t_DTS` (RM0440, advanced-control timers, TIMx_BDTR register, DTG field), with CR1.CKD = 00
//! so `t_DTS` is one timer tick (5.88 ns at 170 MHz):
//!
//! | DTG[7:5] | dead time (ticks)        | range      | step |
//! |----------|--------------------------|------------|------|
//! | `0xx`    | `DTG[6:0]`               | 0-127      | 1    |
//! | `10x`    | `(64 + DTG[5:0]) * 2`    | 128-254    | 2    |
//! | `110`    | `(32 + DTG[4:0]) * 8`    | 256-504    | 8    |
//! | `111`    | `(32 + DTG[4:0]) * 16`   | 512-1008   | 16   |
//!
//! A request is rounded *up* to the next encodable value: a longer dead time only costs a
//! little duty, a shorter one risks shoot-through.

use super::clock::TimerClock;
use super::error::DriveError;

/// A dead time the TIM1 dead-time generator can produce: 1 to 1008 timer ticks (5.9 ns to
/// 5.93 us at 170 MHz), with its DTG encoding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DeadTime {
    dtg: u8,
}

impl DeadTime {
    /// The longest encodable dead time, in timer ticks (DTG = 0xFF).
    pub const MAX_TICKS: u32 = 1008;

    /// The shortest encodable dead time of at least `ns` nanoseconds at `clock`.
    ///
    /// Errors: `DeadTimeZero` for 0 ns (a half-bridge with no dead time shoots through; a
    /// negative dead time cannot be expressed in the `u32`), `DeadTimeTooLong` beyond
    /// [`Self::MAX_TICKS`] ticks (5.929 us at 170 MHz).
    pub const fn at_least_ns(ns: u32, clock: TimerClock) -> Result<Self, DriveError> {
        if ns == 0 {
            return Err(DriveError::DeadTimeZero);
        }
        let ticks = clock.ns_to_ticks_ceil(ns);
        if ticks > Self::MAX_TICKS as u64 {
            return Err(DriveError::DeadTimeTooLong {
                max_ns: clock.ticks_to_ns(Self::MAX_TICKS),
            });
        }
        Ok(Self::at_least_ticks(ticks as u32))
    }

    /// The shortest encodable dead time of at least `ticks` ticks; `ticks` is clamped to
    /// 1..=[`Self::MAX_TICKS`].
    pub const fn at_least_ticks(ticks: u32) -> Self {
        let t = if ticks == 0 {
            1
        } else if ticks > Self::MAX_TICKS {
            Self::MAX_TICKS
        } else {
            ticks
        };
        let dtg = if t <= 127 {
            t
        } else if t <= 254 {
            0x80 | (t.div_ceil(2) - 64)
        } else if t <= 504 {
            0xC0 | (t.div_ceil(8) - 32)
        } else {
            0xE0 | (t.div_ceil(16) - 32)
        };
        Self { dtg: dtg as u8 }
    }

    /// The dead time a DTG byte produces (decoding per the table above). DTG = 0 decodes to a
    /// zero dead time, which no constructor returns.
    pub const fn from_dtg(dtg: u8) -> Self {
        Self { dtg }
    }

    /// The byte for TIM1_BDTR.DTG.
    pub const fn dtg(self) -> u8 {
        self.dtg
    }

    /// The dead time in timer ticks (0 to 1008).
    pub const fn ticks(self) -> u32 {
        let d = self.dtg as u32;
        if d & 0x80 == 0 {
            d
        } else if d & 0xC0 == 0x80 {
            (64 + (d & 0x3F)) * 2
        } else if d & 0xE0 == 0xC0 {
            (32 + (d & 0x1F)) * 8
        } else {
            (32 + (d & 0x1F)) * 16
        }
    }

    /// The dead time in nanoseconds at `clock`, rounded to nearest.
    pub const fn nanoseconds(self, clock: TimerClock) -> u32 {
        clock.ticks_to_ns(self.ticks())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CLOCK: TimerClock = TimerClock::G474_TIM1;

    #[test]
    fn the_four_ranges_decode_as_the_reference_manual_says() {
        assert_eq!(DeadTime::from_dtg(0x00).ticks(), 0);
        assert_eq!(DeadTime::from_dtg(0x7F).ticks(), 127);
        assert_eq!(DeadTime::from_dtg(0x80).ticks(), 128);
        assert_eq!(DeadTime::from_dtg(0xBF).ticks(), 254);
        assert_eq!(DeadTime::from_dtg(0xC0).ticks(), 256);
        assert_eq!(DeadTime::from_dtg(0xDF).ticks(), 504);
        assert_eq!(DeadTime::from_dtg(0xE0).ticks(), 512);
        assert_eq!(DeadTime::from_dtg(0xFF).ticks(), 1008);
    }

    #[test]
    fn every_request_gets_the_shortest_encodable_value_not_below_it() {
        // All 256 codes, sorted: the answer for t must be the smallest of them >= t.
        let mut achievable: Vec<u32> = (0..=255u8).map(|d| DeadTime::from_dtg(d).ticks()).collect();
        achievable.sort_unstable();
        for t in 1..=DeadTime::MAX_TICKS {
            let got = DeadTime::at_least_ticks(t);
            let best = *achievable.iter().find(|&&a| a >= t).unwrap();
            assert_eq!(got.ticks(), best, "request {t} ticks");
            // The byte round-trips.
            assert_eq!(DeadTime::from_dtg(got.dtg()), got);
        }
    }

    #[test]
    fn nanoseconds_round_up_to_ticks() {
        // 100 ns is exactly 17 ticks at 170 MHz; 101 ns needs 18.
        let dt = DeadTime::at_least_ns(100, CLOCK).unwrap();
        assert_eq!((dt.ticks(), dt.dtg(), dt.nanoseconds(CLOCK)), (17, 17, 100));
        let dt = DeadTime::at_least_ns(101, CLOCK).unwrap();
        assert_eq!(dt.ticks(), 18);
        // 1 us = 170 ticks: second range, even, DTG = 0x80 | (85 - 64).
        let dt = DeadTime::at_least_ns(1_000, CLOCK).unwrap();
        assert_eq!((dt.ticks(), dt.dtg()), (170, 0x80 | 21));
        // 2 us = 340 ticks: third range rounds up to 344 ticks (2.024 us).
        let dt = DeadTime::at_least_ns(2_000, CLOCK).unwrap();
        assert_eq!((dt.ticks(), dt.nanoseconds(CLOCK)), (344, 2_024));
        for ns in 1..=5_929 {
            let dt = DeadTime::at_least_ns(ns, CLOCK).unwrap();
            assert!(dt.ticks() * 1000 >= ns * 170, "{ns} ns");
        }
    }

    #[test]
    fn zero_and_too_long_are_refused() {
        assert_eq!(
            DeadTime::at_least_ns(0, CLOCK),
            Err(DriveError::DeadTimeZero)
        );
        // 1008 ticks = 5929.4 ns: 5930 ns needs 1009 ticks.
        assert!(DeadTime::at_least_ns(5_929, CLOCK).is_ok());
        assert_eq!(
            DeadTime::at_least_ns(5_930, CLOCK),
            Err(DriveError::DeadTimeTooLong { max_ns: 5_929 })
        );
        assert_eq!(
            DeadTime::at_least_ns(u32::MAX, CLOCK),
            Err(DriveError::DeadTimeTooLong { max_ns: 5_929 })
        );
        assert_eq!(DeadTime::at_least_ticks(0).ticks(), 1);
        assert_eq!(DeadTime::at_least_ticks(u32::MAX).ticks(), 1008);
    }
}
