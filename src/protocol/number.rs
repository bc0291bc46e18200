//! Reading exact decimal numbers: `[+-]digits[.digits]`, scaled to an integer.
//!
//! There are no floats anywhere: `12.5` read at 3 decimals is the integer `12500`. A number is
//! never rounded. Fraction digits past the resolution are accepted only when they are zeros
//! (`12.5000` at 3 decimals is exactly `12500`); anything else is
//! [`NumberError::TooManyDecimals`], because silently rounding a set point is worse than asking
//! again. The syntax is deliberately narrow: no exponent, no leading or trailing `.`, no digit
//! separators, no unit suffix.

use super::text::MAX_DECIMALS;

/// Most digits (integer and fraction digits together, leading zeros included) a number in a
/// command may have. 12 is far more than any range of the protocol needs, and with at most 6
/// decimals it keeps every scaled value below 10^18, inside `i64`.
pub const MAX_COMMAND_DIGITS: u8 = 12;

/// Most digits a number in a reply or telemetry line may have: enough for `u64::MAX`.
pub const MAX_DECODE_DIGITS: u8 = 20;

/// Why a token is not an acceptable decimal number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum NumberError {
    /// Not of the form `[+-]digits[.digits]`, for example `abc`, `.5`, `5.`, `1.2.3`, `--1`.
    NotANumber,
    /// A valid number followed by characters that cannot belong to a number, for example a
    /// unit (`12N`, `40kHz`) or an exponent (`1e3`).
    TrailingGarbage,
    /// More digits than allowed ([`MAX_COMMAND_DIGITS`] in commands).
    TooManyDigits,
    /// A non-zero digit past the resolution of the quantity.
    TooManyDecimals,
    /// The value does not fit the integer type of the field (decoding replies and telemetry).
    OutOfRange,
}

/// Parses a number of a command at `decimals` fraction digits: the value times `10^decimals`.
///
/// At most [`MAX_COMMAND_DIGITS`] digits, so the result is within `±10^18`. Range checks are
/// the caller's (see [`Quantity`](super::Quantity)).
pub fn parse_decimal(token: &str, decimals: u8) -> Result<i64, NumberError> {
    let (negative, magnitude) = parse_scaled(token, decimals, MAX_COMMAND_DIGITS)?;
    signed(negative, magnitude)
}

/// Decodes an unsigned field of a reply or telemetry line at `decimals` fraction digits.
/// A `-` sign is accepted only on zero.
pub fn decode_u64(token: &str, decimals: u8) -> Result<u64, NumberError> {
    match parse_scaled(token, decimals, MAX_DECODE_DIGITS)? {
        (true, magnitude) if magnitude != 0 => Err(NumberError::OutOfRange),
        (_, magnitude) => Ok(magnitude),
    }
}

/// Like [`decode_u64`] for a `u32` field (counts, ppm, cHz): `0..=4294967295` scaled units.
pub fn decode_u32(token: &str, decimals: u8) -> Result<u32, NumberError> {
    u32::try_from(decode_u64(token, decimals)?).map_err(|_| NumberError::OutOfRange)
}

/// Decodes a signed `i32` field (forces in mN) at `decimals` fraction digits.
pub fn decode_i32(token: &str, decimals: u8) -> Result<i32, NumberError> {
    let (negative, magnitude) = parse_scaled(token, decimals, MAX_DECODE_DIGITS)?;
    i32::try_from(signed(negative, magnitude)?).map_err(|_| NumberError::OutOfRange)
}

/// Applies the sign to a magnitude without overflowing.
fn signed(negative: bool, magnitude: u64) -> Result<i64, NumberError> {
    let value = i64::try_from(magnitude).map_err(|_| NumberError::OutOfRange)?;
    Ok(if negative { -value } else { value })
}

/// Whether `byte` could continue a number; used to tell `1.2.3` (a malformed number) from
/// `12N` (a number with something else glued to it).
fn is_number_byte(byte: u8) -> bool {
    byte.is_ascii_digit() || matches!(byte, b'.' | b'+' | b'-')
}

/// Splits off the leading run of ASCII digits.
fn split_digits(bytes: &[u8]) -> (&[u8], &[u8]) {
    let end = bytes
        .iter()
        .position(|b| !b.is_ascii_digit())
        .unwrap_or(bytes.len());
    bytes.split_at(end)
}

/// The common reader: sign and magnitude scaled by `10^decimals`, at most `max_digits` digits.
pub(crate) fn parse_scaled(
    token: &str,
    decimals: u8,
    max_digits: u8,
) -> Result<(bool, u64), NumberError> {
    let decimals = usize::from(decimals.min(MAX_DECIMALS));
    let bytes = token.as_bytes();
    let (negative, unsigned) = match bytes.split_first() {
        Some((b'-', rest)) => (true, rest),
        Some((b'+', rest)) => (false, rest),
        _ => (false, bytes),
    };
    let (integer, rest) = split_digits(unsigned);
    if integer.is_empty() {
        return Err(NumberError::NotANumber);
    }
    let (fraction, rest) = match rest.split_first() {
        Some((b'.', after_point)) => {
            let (fraction, rest) = split_digits(after_point);
            if fraction.is_empty() {
                return Err(NumberError::NotANumber);
            }
            (fraction, rest)
        }
        _ => (&[][..], rest),
    };
    if let Some(&next) = rest.first() {
        return Err(if is_number_byte(next) {
            NumberError::NotANumber
        } else {
            NumberError::TrailingGarbage
        });
    }
    if integer.len().saturating_add(fraction.len()) > usize::from(max_digits) {
        return Err(NumberError::TooManyDigits);
    }
    let (kept, dropped) = fraction.split_at(fraction.len().min(decimals));
    if dropped.iter().any(|&b| b != b'0') {
        return Err(NumberError::TooManyDecimals);
    }
    let mut magnitude: u64 = 0;
    for &digit in integer.iter().chain(kept) {
        magnitude = magnitude
            .checked_mul(10)
            .and_then(|m| m.checked_add(u64::from(digit - b'0')))
            .ok_or(NumberError::OutOfRange)?;
    }
    for _ in kept.len()..decimals {
        magnitude = magnitude.checked_mul(10).ok_or(NumberError::OutOfRange)?;
    }
    Ok((negative, magnitude))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_the_documented_forms() {
        assert_eq!(parse_decimal("12", 3), Ok(12_000));
        assert_eq!(parse_decimal("12.5", 3), Ok(12_500));
        assert_eq!(parse_decimal("+12.5", 3), Ok(12_500));
        assert_eq!(parse_decimal("-0.001", 3), Ok(-1));
        assert_eq!(parse_decimal("-0", 3), Ok(0));
        assert_eq!(parse_decimal("007", 0), Ok(7));
        assert_eq!(parse_decimal("12.5000", 3), Ok(12_500));
        assert_eq!(parse_decimal("0.000001", 6), Ok(1));
        assert_eq!(
            parse_decimal("999999999999", 6),
            Ok(999_999_999_999_000_000)
        );
    }

    #[test]
    fn rejects_malformed_numbers() {
        for bad in [
            "", "-", "+", ".5", "5.", "1.2.3", "--1", "+-1", "1-", "1..2", "- 1", "1+1",
        ] {
            assert_eq!(
                parse_decimal(bad, 3),
                Err(NumberError::NotANumber),
                "{bad:?}"
            );
        }
        for glued in [
            "12N", "1e3", "1E3", "40kHz", "5%", "0x10", "1.5_0", "1,5", "12.5 ",
        ] {
            assert_eq!(
                parse_decimal(glued, 3),
                Err(NumberError::TrailingGarbage),
                "{glued:?}"
            );
        }
    }

    #[test]
    fn digit_and_decimal_limits() {
        assert_eq!(
            parse_decimal("1234567890123", 0),
            Err(NumberError::TooManyDigits)
        );
        assert_eq!(parse_decimal("0.00000000000", 3), Ok(0));
        assert_eq!(
            parse_decimal("0.000000000000", 3),
            Err(NumberError::TooManyDigits)
        );
        assert_eq!(
            parse_decimal("1.0001", 3),
            Err(NumberError::TooManyDecimals)
        );
        assert_eq!(parse_decimal("1.5", 0), Err(NumberError::TooManyDecimals));
        assert_eq!(parse_decimal("1.0", 0), Ok(1));
    }

    #[test]
    fn decoders_check_the_field_type() {
        assert_eq!(decode_u64("18446744073709551615", 0), Ok(u64::MAX));
        assert_eq!(
            decode_u64("18446744073709551616", 0),
            Err(NumberError::OutOfRange)
        );
        assert_eq!(decode_u32("4294.967295", 6), Ok(u32::MAX));
        assert_eq!(decode_u32("4294.967296", 6), Err(NumberError::OutOfRange));
        assert_eq!(decode_u32("-1", 0), Err(NumberError::OutOfRange));
        assert_eq!(decode_u32("-0", 0), Ok(0));
        assert_eq!(decode_i32("-2147483.648", 3), Ok(i32::MIN));
        assert_eq!(decode_i32("2147483.648", 3), Err(NumberError::OutOfRange));
        assert_eq!(
            decode_u64("123456789012345678901", 0),
            Err(NumberError::TooManyDigits)
        );
    }
}
