//! One consistent set of TIM1 settings: period, dead time, duty and ADC trigger compare.
//!
//! Waveform (edge-aligned up-counting, PWM mode 1 on CH1): the high-side output CH1 rises at
//! the counter overflow (tick 0, plus the dead time) and falls at CCR1 = `D T`; the low-side
//! output CH1N is the complement, delayed by the dead time. With `D <= 1/2` the low-side phase
//! spans at least the second half of the period, so an ADC trigger at 3/4 of the period (OC4REF
//! in PWM mode 2, routed to TRGO2) is always a quarter period away from both switching edges,
//! at any amplitude: the sample is taken where the switching node is quiet.

use super::amplitude::Amplitude;
use super::clock::TimerClock;
use super::dead_time::DeadTime;
use super::error::DriveError;
use super::frequency::Frequency;
use super::period::{DITHER_STEPS, PwmPeriod};
use crate::fx::{self, Q2_30};

/// Where the ADC trigger sits in the period: 3/4, in Q2.30.
const TRIGGER_FRACTION_Q30: u32 = 3 << 28;

/// Period, dead time and the timer clock they were computed for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriveTiming {
    clock: TimerClock,
    period: PwmPeriod,
    dead_time: DeadTime,
}

impl DriveTiming {
    /// Settings for `frequency` with a dead time of at least `dead_time_ns`.
    ///
    /// Errors: those of [`PwmPeriod::nearest`] and [`DeadTime::at_least_ns`], and
    /// `DeadTimeTooLongForPeriod` when the dead time exceeds 1/8 of the period.
    pub const fn new(
        frequency: Frequency,
        dead_time_ns: u32,
        clock: TimerClock,
    ) -> Result<Self, DriveError> {
        let dead_time = match DeadTime::at_least_ns(dead_time_ns, clock) {
            Ok(dead_time) => dead_time,
            Err(error) => return Err(error),
        };
        Self::with_dead_time(frequency, dead_time, clock)
    }

    /// The same dead time at a new frequency (a resonance tracker's step). Integer only.
    pub const fn retune(&self, frequency: Frequency) -> Result<Self, DriveError> {
        Self::with_dead_time(frequency, self.dead_time, self.clock)
    }

    const fn with_dead_time(
        frequency: Frequency,
        dead_time: DeadTime,
        clock: TimerClock,
    ) -> Result<Self, DriveError> {
        let period = match PwmPeriod::nearest(frequency, clock) {
            Ok(period) => period,
            Err(error) => return Err(error),
        };
        let dead_sixteenths = dead_time.ticks() * DITHER_STEPS;
        let max_sixteenths = period.sixteenths() / 8;
        if dead_sixteenths > max_sixteenths {
            return Err(DriveError::DeadTimeTooLongForPeriod {
                max_ns: PwmPeriod::sixteenths_to_ns(max_sixteenths, clock),
            });
        }
        Ok(Self {
            clock,
            period,
            dead_time,
        })
    }

    /// The timer clock.
    pub const fn clock(&self) -> TimerClock {
        self.clock
    }

    /// The period (TIM1_ARR with dithering: [`PwmPeriod::arr_register`]).
    pub const fn period(&self) -> PwmPeriod {
        self.period
    }

    /// The dead time (TIM1_BDTR.DTG: [`DeadTime::dtg`]).
    pub const fn dead_time(&self) -> DeadTime {
        self.dead_time
    }

    /// The frequency the timer actually produces, to the millihertz.
    pub const fn frequency(&self) -> Frequency {
        self.period.frequency(self.clock)
    }

    /// TIM1_CCR1 (dithered format) for `amplitude`: `D = asin(a) / pi` of the period.
    pub const fn duty_compare(&self, amplitude: Amplitude) -> u32 {
        self.period.compare_at(amplitude.duty().to_bits() as u32)
    }

    /// TIM1_CCR4 (dithered format) for the ADC trigger at 3/4 of the period.
    pub const fn adc_trigger_compare(&self) -> u32 {
        self.period.compare_at(TRIGGER_FRACTION_Q30)
    }

    /// Time from the ADC trigger to the next switching edge (the end of the period), in ns:
    /// a conversion shorter than this is not disturbed by switching.
    pub const fn quiet_window_ns(&self) -> u32 {
        let window = self.period.sixteenths() - self.adc_trigger_compare();
        PwmPeriod::sixteenths_to_ns(window, self.clock)
    }

    /// How long CH1 (high side) is on per period at `amplitude`, in ns: `D T` minus the dead
    /// time, or 0 when the dead time swallows the pulse.
    pub const fn high_side_on_ns(&self, amplitude: Amplitude) -> u32 {
        let on = self.duty_compare(amplitude);
        self.minus_dead_time_ns(on)
    }

    /// How long CH1N (low side) is on per period at `amplitude`, in ns: `(1 - D) T` minus the
    /// dead time.
    pub const fn low_side_on_ns(&self, amplitude: Amplitude) -> u32 {
        let off = self.period.sixteenths() - self.duty_compare(amplitude);
        self.minus_dead_time_ns(off)
    }

    const fn minus_dead_time_ns(&self, sixteenths: u32) -> u32 {
        let dead = self.dead_time.ticks() * DITHER_STEPS;
        let remaining = sixteenths.saturating_sub(dead);
        PwmPeriod::sixteenths_to_ns(remaining, self.clock)
    }

    /// The smallest amplitude whose high-side pulse outlasts the dead time,
    /// `sin(pi t_dead / T)`: below it CH1 never turns on and the stack sees no drive.
    pub const fn min_effective_amplitude(&self) -> Amplitude {
        let dead = (self.dead_time.ticks() * DITHER_STEPS) as u64;
        // dead <= T/8, so the phase (a fraction of a turn, 2^32 = 2 pi) is at most 2^28.
        let phase = ((dead << 31) / self.period.sixteenths() as u64) as u32;
        let sine = fx::sin(phase).to_bits(); // Q1.31, in [0, 0.39]
        match Amplitude::new(Q2_30::from_bits(sine >> 1)) {
            Ok(amplitude) => amplitude,
            Err(_) => Amplitude::FULL,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CLOCK: TimerClock = TimerClock::G474_TIM1;

    fn at_40k() -> DriveTiming {
        DriveTiming::new(Frequency::from_hz(40_000), 200, CLOCK).unwrap()
    }

    #[test]
    fn forty_kilohertz_with_200_ns_dead_time() {
        let timing = at_40k();
        assert_eq!(timing.frequency(), Frequency::from_hz(40_000));
        // 200 ns = 34 ticks (exactly), encoded directly.
        assert_eq!(timing.dead_time().ticks(), 34);
        assert_eq!(timing.dead_time().nanoseconds(CLOCK), 200);
        // Trigger at 3/4 of 68 000 sixteenths; 6.25 us before the period ends.
        assert_eq!(timing.adc_trigger_compare(), 51_000);
        assert_eq!(timing.quiet_window_ns(), 6_250);
        // Full scale: duty 1/2, CH1 on 12.5 us - 0.2 us.
        assert_eq!(timing.duty_compare(Amplitude::FULL), 34_000);
        assert_eq!(timing.high_side_on_ns(Amplitude::FULL), 12_300);
        assert_eq!(timing.low_side_on_ns(Amplitude::FULL), 12_300);
        // A quarter: D = asin(0.25)/pi = 0.080431, 2.011 us, so CH1 is on 1.811 us.
        let quarter = Amplitude::from_ratio(1, 4).unwrap();
        assert_eq!(timing.high_side_on_ns(quarter), 1_811);
        assert_eq!(timing.low_side_on_ns(quarter), 22_789);
        assert_eq!(timing.high_side_on_ns(Amplitude::ZERO), 0);
    }

    #[test]
    fn the_trigger_is_a_quarter_period_from_every_edge_at_every_amplitude() {
        for hz in [20_000, 33_333, 47_000, 60_000] {
            let timing = DriveTiming::new(Frequency::from_hz(hz), 300, CLOCK).unwrap();
            let period = timing.period().sixteenths();
            let trigger = timing.adc_trigger_compare();
            for step in 0..=64 {
                let falling = timing.duty_compare(Amplitude::from_ratio(step, 64).unwrap());
                // Edges: 0 and `falling` (<= T/2); the next rise is at `period`.
                assert!(trigger - falling >= period / 4 - 1, "{hz} Hz, {step}/64");
                assert!(period - trigger >= period / 4 - 1, "{hz} Hz");
            }
        }
    }

    #[test]
    fn the_minimum_effective_amplitude_matches_the_dead_time() {
        let timing = at_40k();
        let minimum = timing.min_effective_amplitude();
        // sin(pi 200 ns / 25 us) = 0.025130.
        assert!((minimum.fraction().to_f64() - 0.025_130).abs() < 1e-5);
        // 0.002 above it the pulse exists, 0.002 below it the dead time swallows it.
        let above =
            Amplitude::new(Q2_30::from_bits(minimum.fraction().to_bits() + (1 << 21))).unwrap();
        assert!(timing.high_side_on_ns(above) > 0);
        let below =
            Amplitude::new(Q2_30::from_bits(minimum.fraction().to_bits() - (1 << 21))).unwrap();
        assert_eq!(timing.high_side_on_ns(below), 0);
    }

    #[test]
    fn dead_time_is_checked_against_the_period() {
        // 1/8 of a 60 kHz period is 2.083 us.
        assert_eq!(
            DriveTiming::new(Frequency::BAND_MAX, 2_100, CLOCK),
            Err(DriveError::DeadTimeTooLongForPeriod { max_ns: 2_083 })
        );
        // Accepted at 20 kHz (1/8 period 6.25 us), refused after retuning to 60 kHz.
        let slow = DriveTiming::new(Frequency::BAND_MIN, 2_100, CLOCK).unwrap();
        assert!(slow.retune(Frequency::BAND_MAX).is_err());
        assert!(slow.retune(Frequency::from_hz(30_000)).is_ok());
        assert_eq!(
            DriveTiming::new(Frequency::BAND_MIN, 0, CLOCK),
            Err(DriveError::DeadTimeZero)
        );
        assert_eq!(
            DriveTiming::new(Frequency::from_hz(19_000), 100, CLOCK),
            Err(DriveError::FrequencyOutOfBand {
                requested_mhz: 19_000_000
            })
        );
    }

    #[test]
    fn retuning_keeps_the_dead_time() {
        let timing = at_40k();
        let moved = timing
            .retune(Frequency::from_millihertz(41_234_567))
            .unwrap();
        assert_eq!(moved.dead_time(), timing.dead_time());
        let error = i64::from(moved.frequency().millihertz()) - 41_234_567;
        assert!(error.abs() <= 700, "{error} mHz");
    }
}
