//! Everything that can go wrong with a command line, and the messages of `err` replies.
//!
//! An error is a small `Copy` value that owns a copy of the offending word, so it can outlive the
//! line buffer; its message is written only when the reply is formatted.

use heapless::string::StringView;

use super::MAX_LINE_LEN;
use super::code::ErrorCode;
use super::name::{MAX_SCENE_NAME_LEN, SceneName};
use super::number::{MAX_COMMAND_DIGITS, NumberError};
use super::quantity::Quantity;
use super::state::SupervisorState;
use super::text::{FormatError, MAX_WORD_LEN, put, put_byte, put_sanitized, put_uint};

/// Longest part of a [`ProtocolError::CalFailed`] reason shown in the message, in bytes.
pub const MAX_REASON_LEN: usize = 64;

/// Longest part of an offending token quoted in a message, in bytes.
pub const MAX_QUOTED_TOKEN_LEN: usize = 24;

/// A copy of the offending token for the error message, so the error does not borrow the line.
///
/// Bytes that are not printable ASCII are stored as `?`; a token longer than
/// [`MAX_QUOTED_TOKEN_LEN`] keeps its first 21 bytes and is shown with `...`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct TokenText {
    bytes: [u8; MAX_QUOTED_TOKEN_LEN],
    len: u8,
}

impl TokenText {
    /// Copies (and if needed shortens) `token`.
    pub fn new(token: &str) -> Self {
        const ELLIPSIS: &[u8] = b"...";
        let mut bytes = [0u8; MAX_QUOTED_TOKEN_LEN];
        let source = token.as_bytes();
        let shortened = source.len() > MAX_QUOTED_TOKEN_LEN;
        let kept = if shortened {
            MAX_QUOTED_TOKEN_LEN - ELLIPSIS.len()
        } else {
            source.len()
        };
        let shown = source
            .iter()
            .take(kept)
            .map(|&b| if b.is_ascii_graphic() { b } else { b'?' });
        let tail = if shortened { ELLIPSIS } else { &[] };
        let mut len = 0u8;
        for (slot, byte) in bytes.iter_mut().zip(shown.chain(tail.iter().copied())) {
            *slot = byte;
            len = len.saturating_add(1);
        }
        Self { bytes, len }
    }

    /// The token as quoted in messages.
    pub fn as_str(&self) -> &str {
        let used = self.bytes.get(..usize::from(self.len)).unwrap_or(&[]);
        core::str::from_utf8(used).unwrap_or("?")
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for TokenText {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(f, "{=str}", self.as_str())
    }
}

/// Why a command line was not accepted, or why a command was not executed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ProtocolError {
    /// The first word is not a command.
    UnknownCommand {
        /// The word.
        token: TokenText,
    },
    /// An argument that should be a number is not of the form `[+-]digits[.digits]`.
    BadNumber {
        /// The argument.
        token: TokenText,
    },
    /// A number with something glued after it (`12N`, `1e3`).
    TrailingGarbage {
        /// The argument.
        token: TokenText,
    },
    /// A number with more than [`MAX_COMMAND_DIGITS`] digits.
    TooManyDigits {
        /// The argument.
        token: TokenText,
    },
    /// A number with a non-zero digit finer than the quantity's resolution.
    TooManyDecimals {
        /// The argument.
        token: TokenText,
        /// The quantity it was read as.
        quantity: &'static Quantity,
    },
    /// A number outside the quantity's range.
    OutOfRange {
        /// The argument.
        token: TokenText,
        /// The quantity it was read as.
        quantity: &'static Quantity,
    },
    /// The command needs more arguments.
    MissingArgument {
        /// The command's usage, for example `target force <newtons>`.
        usage: &'static str,
    },
    /// The command takes fewer arguments.
    ExtraArgument {
        /// The first argument too many.
        token: TokenText,
        /// The command's usage.
        usage: &'static str,
    },
    /// An argument that is not one of the allowed words.
    BadChoice {
        /// The argument.
        token: TokenText,
        /// The allowed words, for example `force|coef|reduction`.
        choices: &'static str,
    },
    /// An argument that is not a valid scene name.
    BadName {
        /// The argument.
        token: TokenText,
    },
    /// The line was longer than [`MAX_LINE_LEN`] bytes.
    LineTooLong {
        /// Bytes received before the newline (`\r` not counted), saturating at `u32::MAX`.
        len: u32,
    },
    /// The line holds a byte that is neither printable ASCII nor a tab.
    BadEncoding {
        /// 1-based position of the first such byte in the line.
        column: u32,
        /// The byte.
        byte: u8,
    },
    /// The parser was given a line without any word.
    EmptyLine,
    /// `scene <name>` with a valid name that no scene has (returned by the firmware).
    UnknownScene {
        /// The name asked for.
        name: SceneName,
    },
    /// The command is not allowed in the current state (returned by the firmware).
    WrongState {
        /// The command's keyword, see [`Command::keyword`](super::Command::keyword).
        command: &'static str,
        /// The current state.
        state: SupervisorState,
    },
    /// A fault is latched and must be cleared first (returned by the firmware).
    FaultLatched {
        /// The latched fault's name (a word: see [`is_word`](super::is_word)); at most
        /// [`MAX_WORD_LEN`](super::MAX_WORD_LEN) bytes are shown.
        fault: &'static str,
    },
    /// `start` without a target (returned by the firmware).
    NoTarget,
    /// The calibration failed (returned by the firmware).
    CalFailed {
        /// A short reason in plain words, for example `load unstable`; at most
        /// [`MAX_REASON_LEN`] bytes are shown.
        reason: &'static str,
    },
    /// The settings flash could not be read or written (returned by the firmware).
    StorageFailed {
        /// What failed, one word (for example `flash-error`); at most [`MAX_REASON_LEN`]
        /// bytes are shown.
        reason: &'static str,
    },
    /// `load` found nothing stored, or stored settings that fail their checks (returned by
    /// the firmware).
    SettingsInvalid {
        /// Why, one word (for example `crc-mismatch`); at most [`MAX_REASON_LEN`] bytes are
        /// shown.
        reason: &'static str,
    },
    /// The command cannot be carried out by this loop in any state (returned by the
    /// firmware): `unavailable freq: <reason>`.
    Unavailable {
        /// The command's keyword.
        command: &'static str,
        /// Why, in plain words; at most [`MAX_REASON_LEN`] bytes are shown.
        reason: &'static str,
    },
}

impl ProtocolError {
    /// The stable code of this error.
    pub const fn code(&self) -> ErrorCode {
        match self {
            ProtocolError::UnknownCommand { .. } => ErrorCode::UnknownCommand,
            ProtocolError::BadNumber { .. } => ErrorCode::BadNumber,
            ProtocolError::TrailingGarbage { .. } => ErrorCode::TrailingGarbage,
            ProtocolError::TooManyDigits { .. } => ErrorCode::TooManyDigits,
            ProtocolError::TooManyDecimals { .. } => ErrorCode::TooManyDecimals,
            ProtocolError::OutOfRange { .. } => ErrorCode::OutOfRange,
            ProtocolError::MissingArgument { .. } => ErrorCode::MissingArgument,
            ProtocolError::ExtraArgument { .. } => ErrorCode::ExtraArgument,
            ProtocolError::BadChoice { .. } => ErrorCode::BadChoice,
            ProtocolError::BadName { .. } => ErrorCode::BadName,
            ProtocolError::LineTooLong { .. } => ErrorCode::LineTooLong,
            ProtocolError::BadEncoding { .. } => ErrorCode::BadEncoding,
            ProtocolError::EmptyLine => ErrorCode::EmptyLine,
            ProtocolError::UnknownScene { .. } => ErrorCode::UnknownScene,
            ProtocolError::WrongState { .. } => ErrorCode::WrongState,
            ProtocolError::FaultLatched { .. } => ErrorCode::FaultLatched,
            ProtocolError::NoTarget => ErrorCode::NoTarget,
            ProtocolError::CalFailed { .. } => ErrorCode::CalFailed,
            ProtocolError::StorageFailed { .. } => ErrorCode::StorageFailed,
            ProtocolError::SettingsInvalid { .. } => ErrorCode::SettingsInvalid,
            ProtocolError::Unavailable { .. } => ErrorCode::Unavailable,
        }
    }

    /// The error for `token`, read as `quantity`, that the number reader rejected.
    pub(crate) fn from_number(
        error: NumberError,
        token: &str,
        quantity: &'static Quantity,
    ) -> Self {
        let token = TokenText::new(token);
        match error {
            NumberError::NotANumber => ProtocolError::BadNumber { token },
            NumberError::TrailingGarbage => ProtocolError::TrailingGarbage { token },
            NumberError::TooManyDigits => ProtocolError::TooManyDigits { token },
            NumberError::TooManyDecimals => ProtocolError::TooManyDecimals { token, quantity },
            NumberError::OutOfRange => ProtocolError::OutOfRange { token, quantity },
        }
    }

    /// Appends the human-readable message (what was wrong, with the token and the range).
    pub(crate) fn write_message(&self, out: &mut StringView) -> Result<(), FormatError> {
        match self {
            ProtocolError::UnknownCommand { token } => {
                quote(out, token)?;
                put(out, " is not a command; send help for the list")
            }
            ProtocolError::BadNumber { token } => {
                quote(out, token)?;
                put(out, " is not a decimal number ([+-]digits[.digits])")
            }
            ProtocolError::TrailingGarbage { token } => {
                quote(out, token)?;
                put(
                    out,
                    " has characters after the number; no units or exponents",
                )
            }
            ProtocolError::TooManyDigits { token } => {
                quote(out, token)?;
                put(out, " has more than ")?;
                put_uint(out, u64::from(MAX_COMMAND_DIGITS))?;
                put(out, " digits")
            }
            ProtocolError::TooManyDecimals { token, quantity } => {
                quote(out, token)?;
                put(out, " is finer than the ")?;
                put(out, quantity.name)?;
                put(out, " resolution ")?;
                quantity.write_resolution(out)
            }
            ProtocolError::OutOfRange { token, quantity } => {
                quote(out, token)?;
                put(out, " is out of range ")?;
                quantity.write_range(out)
            }
            ProtocolError::MissingArgument { usage } => {
                put(out, "missing argument; usage: ")?;
                put(out, usage)
            }
            ProtocolError::ExtraArgument { token, usage } => {
                put(out, "unexpected ")?;
                quote(out, token)?;
                put(out, "; usage: ")?;
                put(out, usage)
            }
            ProtocolError::BadChoice { token, choices } => {
                quote(out, token)?;
                put(out, " is not one of ")?;
                put(out, choices)
            }
            ProtocolError::BadName { token } => {
                quote(out, token)?;
                put(out, " is not a scene name ([a-z0-9_-], 1 to ")?;
                put_uint(out, MAX_SCENE_NAME_LEN as u64)?;
                put(out, " bytes, not list or none)")
            }
            ProtocolError::LineTooLong { len } => {
                put(out, "line of ")?;
                put_uint(out, u64::from(*len))?;
                put(out, " bytes is longer than ")?;
                put_uint(out, MAX_LINE_LEN as u64)?;
                put(out, "; line discarded")
            }
            ProtocolError::BadEncoding { column, byte } => {
                put(out, "byte 0x")?;
                put_hex_byte(out, *byte)?;
                put(out, " at column ")?;
                put_uint(out, u64::from(*column))?;
                put(out, " is not printable ASCII; line discarded")
            }
            ProtocolError::EmptyLine => put(out, "line has no command"),
            ProtocolError::UnknownScene { name } => {
                put(out, "no scene named ")?;
                put(out, name.as_str())?;
                put(out, "; send scene list")
            }
            ProtocolError::WrongState { command, state } => {
                put_sanitized(out, command, MAX_WORD_LEN)?;
                put(out, " is not allowed in state ")?;
                put(out, state.name())
            }
            ProtocolError::FaultLatched { fault } => {
                put(out, "fault ")?;
                put_sanitized(out, fault, MAX_WORD_LEN)?;
                put(out, " is latched; send clear first")
            }
            ProtocolError::NoTarget => put(out, "no target set; send target first"),
            ProtocolError::CalFailed { reason } => {
                put(out, "calibration failed: ")?;
                put_sanitized(out, reason, MAX_REASON_LEN)
            }
            ProtocolError::StorageFailed { reason } => {
                put(out, "flash: ")?;
                put_sanitized(out, reason, MAX_REASON_LEN)
            }
            ProtocolError::SettingsInvalid { reason } => {
                put(out, "stored settings: ")?;
                put_sanitized(out, reason, MAX_REASON_LEN)
            }
            ProtocolError::Unavailable { command, reason } => {
                put_sanitized(out, command, MAX_WORD_LEN)?;
                put(out, " is unavailable: ")?;
                put_sanitized(out, reason, MAX_REASON_LEN)
            }
        }
    }
}

/// Appends `"token"`.
fn quote(out: &mut StringView, token: &TokenText) -> Result<(), FormatError> {
    put(out, "\"")?;
    put(out, token.as_str())?;
    put(out, "\"")
}

/// Appends a byte as two lowercase hex digits.
fn put_hex_byte(out: &mut StringView, byte: u8) -> Result<(), FormatError> {
    const HEX: &[u8; 16] = b"0123456789abcdef";
    for nibble in [byte >> 4, byte & 0x0f] {
        put_byte(out, HEX.get(usize::from(nibble)).copied().unwrap_or(b'?'))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::{REPLY_CAPACITY, format_error, parse_command};
    use heapless::String;

    fn message(line: &str) -> String<REPLY_CAPACITY> {
        let mut out = String::new();
        format_error(&parse_command(line).unwrap_err(), &mut out).unwrap();
        out
    }

    #[test]
    fn tokens_are_shortened_and_sanitized() {
        assert_eq!(TokenText::new("1.2.3").as_str(), "1.2.3");
        assert_eq!(TokenText::new("").as_str(), "");
        let exact = "x".repeat(MAX_QUOTED_TOKEN_LEN);
        assert_eq!(TokenText::new(&exact).as_str(), exact);
        let long = "y".repeat(MAX_QUOTED_TOKEN_LEN + 1);
        let shown = TokenText::new(&long);
        assert_eq!(shown.as_str().len(), MAX_QUOTED_TOKEN_LEN);
        assert!(shown.as_str().ends_with("yyy..."));
        assert_eq!(TokenText::new("a\"\u{e9}\t").as_str(), "a\"???");
    }

    #[test]
    fn messages_name_the_word_and_the_rule() {
        assert_eq!(
            message("target force 1.2.3"),
            "err 2 bad-number \"1.2.3\" is not a decimal number ([+-]digits[.digits])\n"
        );
        assert_eq!(
            message("freq 60000.01"),
            "err 6 out-of-range \"60000.01\" is out of range 20000.00 <= freq <= 60000.00 Hz\n"
        );
        assert_eq!(
            message("target coef 0.0000001"),
            "err 5 too-many-decimals \"0.0000001\" is finer than the coef resolution 0.000001\n"
        );
        assert_eq!(
            message("cal normal"),
            "err 7 missing-argument missing argument; usage: cal normal|tangential <newtons>\n"
        );
        assert_eq!(
            message("start now"),
            "err 8 extra-argument unexpected \"now\"; usage: start\n"
        );
        assert_eq!(
            message("freq fast"),
            "err 9 bad-choice \"fast\" is not one of auto|<hertz>\n"
        );
        assert_eq!(
            message("telemetry on"),
            "err 9 bad-choice \"on\" is not one of off|<hertz>\n"
        );
        assert_eq!(
            message("jump"),
            "err 1 unknown-command \"jump\" is not a command; send help for the list\n"
        );
    }
}
