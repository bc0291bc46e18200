//! Writing protocol text into a bounded buffer: the output half of the number format, the
//! "word" rule for names in payloads, and the one error every formatter can return.
//!
//! Everything here appends to a [`StringView`] (any `heapless::String<N>` coerces to it), so the
//! formatters are compiled once, not once per buffer size. Integers are printed by hand rather
//! than through `core::fmt`: the firmware then carries no formatting machinery at all, and in
//! particular nothing that could pull in float printing.

use heapless::string::StringView;

/// Why a line could not be formatted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FormatError {
    /// The line does not fit in the buffer. The buffer is left empty, so a half line is never
    /// sent. With [`REPLY_CAPACITY`](super::REPLY_CAPACITY) and
    /// [`TELEMETRY_CAPACITY`](super::TELEMETRY_CAPACITY) this only happens for a scene list
    /// longer than the buffer.
    Overflow,
    /// A name or key given to a formatter is not a word (see [`is_word`]); printing it would
    /// make the line unparseable.
    BadWord,
}

/// Longest word accepted by [`is_word`], in bytes.
pub const MAX_WORD_LEN: usize = 32;

/// Whether `text` may appear as a key or a value in a payload: 1 to [`MAX_WORD_LEN`] bytes of
/// printable ASCII other than space, `=`, `,`, `:` and `"`.
///
/// Those five are the separators of the payload syntax (pairs, key and value, list items,
/// target kind and value, quoted tokens in messages), so a word can never be split wrongly.
pub fn is_word(text: &str) -> bool {
    !text.is_empty()
        && text.len() <= MAX_WORD_LEN
        && text
            .bytes()
            .all(|b| b.is_ascii_graphic() && !matches!(b, b'=' | b',' | b':' | b'"'))
}

/// Largest number of fraction digits the writer and the parser handle. Every quantity of the
/// protocol uses at most 6; the bound keeps the digit buffer below a fixed size.
pub const MAX_DECIMALS: u8 = 9;

/// Appends `text` as it is.
pub(crate) fn put(out: &mut StringView, text: &str) -> Result<(), FormatError> {
    out.push_str(text).map_err(|_| FormatError::Overflow)
}

/// Appends one ASCII byte.
pub(crate) fn put_byte(out: &mut StringView, byte: u8) -> Result<(), FormatError> {
    out.push(char::from(byte))
        .map_err(|_| FormatError::Overflow)
}

/// Appends at most `max_len` bytes of `text` (then `...` if it was longer), with every byte
/// that is not printable ASCII replaced by `?`: free text from the firmware in an error message
/// can neither break the one-line rule nor overflow the reply.
pub(crate) fn put_sanitized(
    out: &mut StringView,
    text: &str,
    max_len: usize,
) -> Result<(), FormatError> {
    for byte in text.bytes().take(max_len) {
        let shown = if byte == b' ' || byte.is_ascii_graphic() {
            byte
        } else {
            b'?'
        };
        put_byte(out, shown)?;
    }
    if text.len() > max_len {
        put(out, "...")?;
    }
    Ok(())
}

/// Appends a word after checking it with [`is_word`].
pub(crate) fn put_word(out: &mut StringView, word: &str) -> Result<(), FormatError> {
    if is_word(word) {
        put(out, word)
    } else {
        Err(FormatError::BadWord)
    }
}

/// Appends an unsigned integer in decimal.
pub(crate) fn put_uint(out: &mut StringView, value: u64) -> Result<(), FormatError> {
    put_scaled(out, false, value, 0)
}

/// Appends a signed scaled integer as a decimal number with exactly `decimals` fraction digits:
/// `put_fixed(out, -12480, 3)` appends `-12.480`.
pub(crate) fn put_fixed(out: &mut StringView, value: i64, decimals: u8) -> Result<(), FormatError> {
    put_scaled(out, value < 0, value.unsigned_abs(), decimals)
}

/// Appends `magnitude / 10^decimals` with a leading `-` when `negative` (and the magnitude is
/// not zero: there is no negative zero in the protocol), at least one integer digit, and
/// exactly `decimals` fraction digits (clamped to [`MAX_DECIMALS`]).
pub(crate) fn put_scaled(
    out: &mut StringView,
    negative: bool,
    magnitude: u64,
    decimals: u8,
) -> Result<(), FormatError> {
    let decimals = usize::from(decimals.min(MAX_DECIMALS));
    // u64::MAX has 20 digits; with up to 9 decimals padded by zeros the number has at most 21
    // digits. Digits are produced least significant first.
    let mut digits = [0u8; 24];
    let mut count = 0;
    let mut rest = magnitude;
    for slot in digits.iter_mut() {
        // The remainder is below 10, so the cast cannot truncate.
        *slot = b'0' + (rest % 10) as u8;
        rest /= 10;
        count += 1;
        if rest == 0 && count > decimals {
            break;
        }
    }
    if negative && magnitude != 0 {
        put_byte(out, b'-')?;
    }
    for (index, digit) in digits.iter().take(count).enumerate().rev() {
        put_byte(out, *digit)?;
        if index == decimals && decimals > 0 {
            put_byte(out, b'.')?;
        }
    }
    Ok(())
}

/// Runs a formatter on a cleared buffer and leaves the buffer empty if it fails, so callers
/// never see a truncated line.
pub(crate) fn write_line(
    out: &mut StringView,
    body: impl FnOnce(&mut StringView) -> Result<(), FormatError>,
) -> Result<(), FormatError> {
    out.clear();
    let result = body(out);
    if result.is_err() {
        out.clear();
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use heapless::String;

    fn fixed(value: i64, decimals: u8) -> String<40> {
        let mut out = String::new();
        put_fixed(&mut out, value, decimals).unwrap();
        out
    }

    #[test]
    fn fixed_point_prints_exactly() {
        assert_eq!(fixed(0, 0), "0");
        assert_eq!(fixed(0, 3), "0.000");
        assert_eq!(fixed(1, 6), "0.000001");
        assert_eq!(fixed(-12480, 3), "-12.480");
        assert_eq!(fixed(4_000_000, 2), "40000.00");
        assert_eq!(fixed(i64::MIN, 0), "-9223372036854775808");
        assert_eq!(fixed(i64::MAX, 9), "9223372036.854775807");
        let mut out: String<40> = String::new();
        put_uint(&mut out, u64::MAX).unwrap();
        assert_eq!(out, "18446744073709551615");
    }

    #[test]
    fn words_exclude_the_separators() {
        assert!(is_word("overcurrent"));
        assert!(is_word("0.1.0+dirty"));
        assert!(is_word(&"x".repeat(MAX_WORD_LEN)));
        for bad in ["", "a b", "a=b", "a,b", "a:b", "\"a", "caf\u{e9}", "a\tb"] {
            assert!(!is_word(bad), "{bad:?}");
        }
        assert!(!is_word(&"x".repeat(MAX_WORD_LEN + 1)));
    }

    #[test]
    fn a_failed_line_leaves_the_buffer_empty() {
        let mut out: String<8> = String::new();
        let result = write_line(&mut out, |out| put(out, "0123456789"));
        assert_eq!(result, Err(FormatError::Overflow));
        assert!(out.is_empty());
        let mut out: String<8> = String::new();
        put_sanitized(&mut out, "a\u{7f}\u{e9}", 8).unwrap();
        assert_eq!(out, "a???");
        out.clear();
        put_sanitized(&mut out, "abcdef", 3).unwrap();
        assert_eq!(out, "abc...");
    }
}
