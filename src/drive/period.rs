//! Frequency to TIM1 period with dithering: 1/16-tick resolution of the average period.
//!
//! TIM1 counts up (edge-aligned) at the [`TimerClock`] with prescaler 1, so a period of `n`
//! ticks gives `f = f_clk / n`. Plain integer periods step the frequency by `f^2 / f_clk`:
//! 9.4 Hz at 40 kHz and 21.2 Hz at 60 kHz with 170 MHz. With CR1.DITHEN set (RM0440,
//! advanced-control timers, "Dithering mode"), ARR and CCRx hold 4 extra fractional bits:
//! ARR[19:4] is the integer auto-reload value and ARR[3:0] says in how many of 16 consecutive
//! periods the hardware lengthens the period by one tick. The average period is then
//! `ARR/16 + 1` ticks in steps of 1/16 tick, so the frequency step shrinks 16-fold, to
//! `f^2 / (16 f_clk)`: 1.32 Hz at 60 kHz, the worst case of the band. The price is a period
//! jitter of one tick (5.9 ns, 0.035 % of a 60 kHz period), which a stack resonance with a
//! quality factor in the hundreds averages out.

use super::clock::TimerClock;
use super::error::DriveError;
use super::frequency::Frequency;

/// Dithering spreads 16 periods: register values carry 4 fractional bits (RM0440, "Dithering
/// mode").
pub const DITHER_STEPS: u32 = 16;

/// Largest dithered ARR value: integer part 0xFFFE so that the periods lengthened by one tick
/// still fit the 16-bit counter.
const ARR_DITHERED_MAX: u32 = 0xF_FFEF;

/// A PWM period in sixteenths of a timer tick: the average period TIM1 produces in dithering
/// mode. At 170 MHz the band 20-60 kHz spans 45 333 to 136 000 sixteenths.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PwmPeriod {
    sixteenths: u32,
}

impl PwmPeriod {
    /// The period whose frequency is nearest to `frequency` (ties go to the longer period).
    ///
    /// Errors: `FrequencyOutOfBand` outside 20-60 kHz, `PeriodOutOfRange` if the clock is so
    /// fast that the period overflows the dithered ARR register (not the case up to 200 MHz).
    /// Integer arithmetic only (a few `u64` multiplications and one division): cheap enough for
    /// every control step of a resonance tracker.
    pub const fn nearest(frequency: Frequency, clock: TimerClock) -> Result<Self, DriveError> {
        if !frequency.in_band() {
            return Err(DriveError::FrequencyOutOfBand {
                requested_mhz: frequency.millihertz(),
            });
        }
        let numerator = numerator(clock);
        let f = frequency.millihertz() as u64; // >= 20e6, so no division by zero
        let shorter = numerator / f;
        let longer = shorter + 1;
        // Frequency errors are |numerator - f P| / P for P = shorter, longer; compare them
        // cross-multiplied. Each |numerator - f P| < f <= 6e7 and P < 1.7e5, so the
        // products stay below 1.1e13.
        let error_shorter = numerator - f * shorter;
        let error_longer = f * longer - numerator;
        let sixteenths = if error_shorter * longer < error_longer * shorter {
            shorter
        } else {
            longer
        };
        if sixteenths < DITHER_STEPS as u64
            || sixteenths - DITHER_STEPS as u64 > ARR_DITHERED_MAX as u64
        {
            return Err(DriveError::PeriodOutOfRange);
        }
        Ok(Self {
            sixteenths: sixteenths as u32,
        })
    }

    /// The period in sixteenths of a timer tick.
    pub const fn sixteenths(self) -> u32 {
        self.sixteenths
    }

    /// The value to write to TIM1_ARR with CR1.DITHEN set: the average period is `ARR/16 + 1`
    /// ticks, so `ARR = sixteenths - 16`.
    pub const fn arr_register(self) -> u32 {
        self.sixteenths - DITHER_STEPS
    }

    /// The average frequency this period produces, rounded to the nearest millihertz.
    pub const fn frequency(self, clock: TimerClock) -> Frequency {
        let period = self.sixteenths as u64;
        let millihertz = (numerator(clock) + period / 2) / period;
        // At least 16 sixteenths (checked on construction): at most 200 MHz * 1000 mHz/Hz,
        // which fits u32 (construction from an in-band frequency keeps it near 60 kHz anyway).
        Frequency::from_millihertz(if millihertz > u32::MAX as u64 {
            u32::MAX
        } else {
            millihertz as u32
        })
    }

    /// Spacing between this period's frequency and the next achievable one (one sixteenth of a
    /// tick longer), in millihertz, rounded up: the frequency resolution here. The nearest
    /// period is never more than half of it away from a request.
    pub const fn frequency_step(self, clock: TimerClock) -> u32 {
        let period = self.sixteenths as u64;
        // f(P) - f(P+1) = N / (P (P+1)).
        let step = numerator(clock).div_ceil(period * (period + 1));
        if step > u32::MAX as u64 {
            u32::MAX
        } else {
            step as u32
        }
    }

    /// The compare value (TIM1_CCRx with dithering, sixteenths of a tick) at which a fraction
    /// `fraction_q30` of the period has elapsed, rounded to nearest. `fraction_q30` is a Q2.30
    /// fraction in [0, 1] (`1 << 30` is the whole period); larger values give the whole period.
    pub const fn compare_at(self, fraction_q30: u32) -> u32 {
        let fraction = if fraction_q30 > 1 << 30 {
            1 << 30
        } else {
            fraction_q30
        };
        // sixteenths < 2^20 and fraction <= 2^30: the product stays below 2^50.
        ((self.sixteenths as u64 * fraction as u64 + (1 << 29)) >> 30) as u32
    }

    /// `sixteenths` sixteenths of a tick in nanoseconds at `clock`, rounded to nearest.
    pub const fn sixteenths_to_ns(sixteenths: u32, clock: TimerClock) -> u32 {
        let scaled = sixteenths as u64 * 1_000_000_000;
        let den = clock.hz() as u64 * DITHER_STEPS as u64;
        let ns = (scaled + den / 2) / den;
        if ns > u32::MAX as u64 {
            u32::MAX
        } else {
            ns as u32
        }
    }
}

/// `16 f_clk` in sixteenths of a tick times millihertz: `f_mHz = numerator / sixteenths`.
/// At most 16 * 200e6 * 1000 = 3.2e12.
const fn numerator(clock: TimerClock) -> u64 {
    clock.hz() as u64 * DITHER_STEPS as u64 * 1000
}

#[cfg(test)]
mod tests {
    use super::*;

    const CLOCK: TimerClock = TimerClock::G474_TIM1;

    /// Exact frequency error of `period` for `frequency`, in microhertz (rounded up).
    fn error_uhz(period: PwmPeriod, frequency: Frequency, clock: TimerClock) -> u64 {
        let p = u64::from(period.sixteenths());
        let n = numerator(clock);
        let fp = u64::from(frequency.millihertz()) * p;
        (n.abs_diff(fp) * 1000).div_ceil(p)
    }

    #[test]
    fn every_hertz_of_the_band_is_within_0_67_hz_and_is_the_nearest() {
        let mut worst_uhz = 0;
        let mut worst_at_hz = 0;
        let mut widest_step_mhz = 0;
        for hz in 20_000..=60_000 {
            let frequency = Frequency::from_hz(hz);
            let period = PwmPeriod::nearest(frequency, CLOCK).unwrap();
            let error = error_uhz(period, frequency, CLOCK);
            // Nearest: neither neighbouring period is closer.
            for neighbour in [period.sixteenths() - 1, period.sixteenths() + 1] {
                let other = PwmPeriod {
                    sixteenths: neighbour,
                };
                assert!(error <= error_uhz(other, frequency, CLOCK), "{hz} Hz");
            }
            // Within half a step of the achievable grid here.
            let step = period.frequency_step(CLOCK);
            assert!(error <= u64::from(step) * 1000 / 2 + 1, "{hz} Hz");
            widest_step_mhz = widest_step_mhz.max(step);
            if error > worst_uhz {
                worst_uhz = error;
                worst_at_hz = hz;
            }
        }
        eprintln!(
            "20-60 kHz every 1 Hz at 170 MHz: worst error {worst_uhz} uHz at {worst_at_hz} Hz, \
             widest step {widest_step_mhz} mHz"
        );
        // f^2 / (16 f_clk) at 60 kHz is 1.3235 Hz; half of it 0.662 Hz.
        assert!(worst_uhz <= 662_000, "worst {worst_uhz} uHz");
        assert!(
            worst_uhz > 500_000,
            "the sweep must reach the grid's worst case"
        );
        assert_eq!(widest_step_mhz, 1_324);
    }

    #[test]
    fn millihertz_requests_near_60_khz_stay_within_half_a_step() {
        // The coarsest part of the band, every 7 mHz over 10 Hz.
        let mut millihertz = 59_990_000;
        while millihertz <= 60_000_000 {
            let frequency = Frequency::from_millihertz(millihertz);
            let period = PwmPeriod::nearest(frequency, CLOCK).unwrap();
            assert!(error_uhz(period, frequency, CLOCK) <= 662_000);
            millihertz += 7;
        }
    }

    #[test]
    fn without_dithering_the_step_would_be_16_times_coarser() {
        // The plain 16-bit timer: period n ticks, step f_clk/n - f_clk/(n+1).
        let plain_step_at = |hz: u64| {
            let n = 170_000_000 / hz;
            170_000_000.0 / n as f64 - 170_000_000.0 / (n + 1) as f64
        };
        assert!((plain_step_at(40_000) - 9.41).abs() < 0.01);
        assert!((plain_step_at(60_000) - 21.2).abs() < 0.1);
        let dithered = PwmPeriod::nearest(Frequency::from_hz(60_000), CLOCK).unwrap();
        assert_eq!(dithered.frequency_step(CLOCK), 1_324);
    }

    #[test]
    fn registers_for_40_khz() {
        // 170 MHz / 40 kHz = 4250 ticks exactly: ARR integer 4249, no fraction.
        let period = PwmPeriod::nearest(Frequency::from_hz(40_000), CLOCK).unwrap();
        assert_eq!(period.sixteenths(), 68_000);
        assert_eq!(period.arr_register(), 4249 << 4);
        assert_eq!(period.frequency(CLOCK), Frequency::from_hz(40_000));
        // 40 001 Hz: 4249.894 ticks, nearest 4249 + 14/16.
        let period = PwmPeriod::nearest(Frequency::from_hz(40_001), CLOCK).unwrap();
        assert_eq!(period.arr_register(), (4248 << 4) | 14);
        assert_eq!(period.frequency(CLOCK).millihertz(), 40_001_177);
    }

    #[test]
    fn out_of_band_requests_are_refused() {
        for millihertz in [0, 19_999_999, 60_000_001, u32::MAX] {
            assert_eq!(
                PwmPeriod::nearest(Frequency::from_millihertz(millihertz), CLOCK),
                Err(DriveError::FrequencyOutOfBand {
                    requested_mhz: millihertz
                })
            );
        }
    }

    #[test]
    fn every_allowed_clock_fits_the_register_over_the_band() {
        for hz in [1_000_000, 16_000_000, 170_000_000, 200_000_000] {
            let clock = TimerClock::new(hz).unwrap();
            for frequency in [Frequency::BAND_MIN, Frequency::BAND_MAX] {
                let period = PwmPeriod::nearest(frequency, clock).unwrap();
                assert!(period.arr_register() <= ARR_DITHERED_MAX);
            }
        }
    }

    #[test]
    fn compare_values_scale_with_the_fraction() {
        let period = PwmPeriod::nearest(Frequency::from_hz(40_000), CLOCK).unwrap();
        assert_eq!(period.compare_at(0), 0);
        assert_eq!(period.compare_at(1 << 29), 34_000);
        assert_eq!(period.compare_at(3 << 28), 51_000);
        assert_eq!(period.compare_at(1 << 30), 68_000);
        assert_eq!(period.compare_at(u32::MAX), 68_000);
        assert_eq!(PwmPeriod::sixteenths_to_ns(68_000, CLOCK), 25_000);
        assert_eq!(PwmPeriod::sixteenths_to_ns(u32::MAX, CLOCK), 1_579_032_094);
    }
}
