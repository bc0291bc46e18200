//! Error and saturation reporting shared by every fixed-point operation.
//!
//! The hot path never panics and never wraps: an operation either returns `Err(FxError)`
//! (the `checked_*` family and the elementary functions) or clamps and says so in a
//! [`Sat`] (the `saturating_*` family). A saturation that nobody looks at is a bug, so
//! [`Sat`] is `#[must_use]`.

use core::fmt;

/// Why a fixed-point operation could not produce its result.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FxError {
    /// The floating-point input was NaN or infinite.
    NotFinite,
    /// The exact result lies outside the range of the output format (either sign).
    Overflow,
    /// The divisor was zero.
    DivisionByZero,
    /// The argument is outside the function's domain: `sqrt` of a negative value, `ln` of a
    /// value <= 0, `asin` of |z| > 1, `exp_neg` of a negative value.
    Domain,
}

impl fmt::Display for FxError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let text = match self {
            Self::NotFinite => "input is NaN or infinite",
            Self::Overflow => "result out of range of the fixed-point format",
            Self::DivisionByZero => "division by zero",
            Self::Domain => "argument outside the function's domain",
        };
        f.write_str(text)
    }
}

impl core::error::Error for FxError {}

/// A result that was clamped to its format's range, with a flag saying whether it was.
///
/// `value` is the exact (rounded) result when `saturated` is false, and the nearest end of
/// the format's range (`MIN` or `MAX`) when it is true.
#[must_use = "a saturation flag that nobody reads hides an overflow"]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sat<T> {
    /// The result, clamped to the output range.
    pub value: T,
    /// True when the exact result was outside the range and `value` was clamped.
    pub saturated: bool,
}

impl<T> Sat<T> {
    /// A result that fitted: `saturated` is false.
    pub const fn exact(value: T) -> Self {
        Self {
            value,
            saturated: false,
        }
    }

    /// A result that was clamped: `saturated` is true.
    pub const fn clamped(value: T) -> Self {
        Self {
            value,
            saturated: true,
        }
    }

    /// The value if it was not clamped, `Err(FxError::Overflow)` otherwise.
    pub fn exact_or_overflow(self) -> Result<T, FxError> {
        if self.saturated {
            Err(FxError::Overflow)
        } else {
            Ok(self.value)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_display_and_saturation_converts() {
        assert_eq!(
            FxError::Overflow.to_string(),
            "result out of range of the fixed-point format"
        );
        assert_eq!(
            FxError::Domain.to_string(),
            "argument outside the function's domain"
        );
        assert_eq!(Sat::exact(3).exact_or_overflow(), Ok(3));
        assert_eq!(Sat::clamped(3).exact_or_overflow(), Err(FxError::Overflow));
    }
}
