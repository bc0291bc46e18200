//! Why a sensing configuration or conversion was refused.

use core::fmt;

/// A sensing request that cannot be honoured. Sensor *faults* (a broken cell, a stuck
/// reading) are [`crate::sense::SensorFault`]s; these are configuration and range errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SenseError {
    /// An ADC word width or oversampling setting the hardware does not have.
    InvalidFormat,
    /// A raw code outside what the ADC format can produce.
    CodeOutOfRange {
        /// The code received.
        code: i32,
    },
    /// The known load moved the reading by less than 1/4096 of full scale: the gain would be
    /// dominated by noise (or the load was not applied).
    SpanTooSmall,
    /// A calibration or converted value does not fit its fixed-point format.
    Overflow,
    /// An analog front-end description with a zero or out-of-range value.
    InvalidFrontEnd,
}

impl fmt::Display for SenseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidFormat => f.write_str("ADC format or oversampling not supported"),
            Self::CodeOutOfRange { code } => write!(f, "ADC code {code} outside the format"),
            Self::SpanTooSmall => f.write_str("calibration load changed the reading too little"),
            Self::Overflow => f.write_str("value does not fit its fixed-point format"),
            Self::InvalidFrontEnd => f.write_str("analog front-end values out of range"),
        }
    }
}

impl core::error::Error for SenseError {}
