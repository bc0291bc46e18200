//! Drive of the piezo stack: frequency, dead time, amplitude, limits and ramps as timer settings.
//!
//! # Topology: half-bridge
//!
//! One complementary pair (TIM1 CH1 / CH1N) drives a half-bridge whose switching node feeds the
//! stack through a DC-blocking capacitor and a series inductor (board README). A half-bridge
//! rather than a full bridge because:
//! - the amplitude is set by the duty cycle alone, `D = asin(a) / pi` ([`Amplitude::duty`]),
//!   which keeps the fundamental linear in `a`; a full bridge would need a phase shift between
//!   two legs, i.e. TIM1's asymmetric or combined PWM modes on two channel pairs, whose
//!   interplay with dithering the reference manual documents less well;
//! - a 24 V bus gives a fundamental of `2 * 24 V / pi = 15.3 V`, just under the stack's
//!   15.466 V (seed 003 Table 1), so the full-bridge's doubled swing buys nothing here;
//! - one gate driver, one shunt, one comparator and one break input cover the whole stage.
//!
//! # Timer: TIM1 with dithering, not the HRTIM
//!
//! Both reach the 2 Hz requirement over 20-60 kHz at 170 MHz; TIM1 is the simpler and the more
//! robust of the two:
//! - TIM1 with CR1.DITHEN: period in 1/16 tick, so the frequency step is `f^2 / (16 f_clk)`,
//!   at most 1.32 Hz (at 60 kHz) over the band; the nearest achievable frequency is always
//!   within 0.662 Hz of a request ([`PwmPeriod`], proved for every hertz of the band in its
//!   tests). One prescaler setting for the whole band, so a resonance tracker can sweep it
//!   without ever stopping the timer.
//! - HRTIM: 184 ps ticks (170 MHz x 32), but the 16-bit period (at most 0xFFDF at x32) cannot
//!   span the band with one clock prescaler: x32 reaches down to 83 kHz only, x16 to 41.5 kHz,
//!   x8 to 20.8 kHz. One prescaler for the band (x4, 680 MHz) gives 5.3 Hz steps at 60 kHz,
//!   failing the requirement; switching prescalers by sub-band gives 1.32 Hz at 60 kHz (no
//!   better than dithered TIM1) with prescaler boundaries at 20.8 and 41.5 kHz, right next to
//!   the 40 kHz half-wave mode of seed 003, where the timer would have to be stopped and
//!   restarted.
//! - TIM1 also has what the rest needs on the same peripheral: a dead-time generator
//!   ([`DeadTime`]), a break input fed directly by COMP1 (TIM1_AF1.BKCMP1E) for the hardware
//!   overcurrent trip ([`OvercurrentTrip`]), TRGO2 to start ADC conversions at a quiet point of
//!   the period ([`DriveTiming::adc_trigger_compare`]), and embassy-stm32 0.6 drives it
//!   (`timer::complementary_pwm`).
//!
//! # Arithmetic
//!
//! Everything that can run per control step (retuning the period, amplitude to compare value,
//! the amplitude ceiling at a frequency, the ramp) is integer or fixed point, never panics and
//! never overflows; invalid requests return a [`DriveError`]. Only [`DriveLimits::new`] uses
//! `f64`, once, at configuration.

mod amplitude;
mod clock;
mod dead_time;
mod error;
mod frequency;
mod limits;
mod overcurrent;
mod period;
#[cfg(test)]
mod period_tests;
mod ramp;
mod timing;

pub use amplitude::Amplitude;
pub use clock::TimerClock;
pub use dead_time::DeadTime;
pub use error::DriveError;
pub use frequency::Frequency;
pub use limits::{DriveLimits, StackRatings};
pub use overcurrent::OvercurrentTrip;
pub use period::{DITHER_STEPS, PwmPeriod};
pub use ramp::AmplitudeRamp;
pub use timing::DriveTiming;
