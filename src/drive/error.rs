//! Why a drive request was refused.

use core::fmt;

/// A drive setting that cannot be produced safely or at all. Every fallible function of
/// [`crate::drive`] returns one of these instead of panicking or clamping silently.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DriveError {
    /// The frequency is outside the 20-60 kHz band of the stack (seed 003 Table 1).
    FrequencyOutOfBand {
        /// The requested frequency, in millihertz.
        requested_mhz: u32,
    },
    /// The timer kernel clock is outside 1-200 MHz.
    TimerClockOutOfRange {
        /// The clock given, in hertz.
        clock_hz: u32,
    },
    /// The period does not fit the dithered auto-reload register: its integer part must stay
    /// below 0xFFFF so that the periods the dithering lengthens by one tick still fit the
    /// 16-bit counter (RM0440, advanced-control timers, "Dithering mode").
    PeriodOutOfRange,
    /// A dead time of zero: both switches of the half-bridge could conduct at once.
    DeadTimeZero,
    /// The dead time exceeds what the BDTR.DTG field can encode (1008 dead-time clocks).
    DeadTimeTooLong {
        /// The longest dead time that can be encoded at this clock, in nanoseconds.
        max_ns: u32,
    },
    /// The dead time exceeds 1/8 of the drive period: the two dead times per period would eat
    /// more than a quarter of it and the drive would no longer be a square wave.
    DeadTimeTooLongForPeriod {
        /// The longest dead time allowed at this frequency, in nanoseconds.
        max_ns: u32,
    },
    /// An amplitude outside [0, 1] of full scale.
    AmplitudeOutOfRange,
    /// A rating, gain or capacitance that is not finite and strictly positive.
    InvalidRating,
    /// A ramp that would take zero control steps.
    InvalidRamp,
    /// The overcurrent trip level is not a positive current inside the current sensor's range,
    /// so the comparator could never trip (or would trip at zero current).
    TripOutOfSensorRange,
}

impl fmt::Display for DriveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::FrequencyOutOfBand { requested_mhz } => write!(
                f,
                "frequency {requested_mhz} mHz outside the 20-60 kHz band"
            ),
            Self::TimerClockOutOfRange { clock_hz } => {
                write!(f, "timer clock {clock_hz} Hz outside 1-200 MHz")
            }
            Self::PeriodOutOfRange => f.write_str("period does not fit the timer"),
            Self::DeadTimeZero => f.write_str("dead time of zero would shoot through"),
            Self::DeadTimeTooLong { max_ns } => {
                write!(f, "dead time longer than the encodable {max_ns} ns")
            }
            Self::DeadTimeTooLongForPeriod { max_ns } => {
                write!(f, "dead time longer than 1/8 period ({max_ns} ns)")
            }
            Self::AmplitudeOutOfRange => f.write_str("amplitude outside [0, 1]"),
            Self::InvalidRating => f.write_str("rating not finite and positive"),
            Self::InvalidRamp => f.write_str("ramp of zero steps"),
            Self::TripOutOfSensorRange => {
                f.write_str("overcurrent trip outside the current sensor's range")
            }
        }
    }
}

impl core::error::Error for DriveError {}
