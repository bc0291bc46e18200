//! Reading what the firmware sends, for the host tool: replies and the classification of
//! incoming lines. Telemetry records are decoded in [`parse_telemetry`](super::parse_telemetry).
//!
//! Decoding borrows from the line: a [`Payload`] is a view of the text after `ok`, and its
//! values are read on demand with [`decode_u32`](super::decode_u32) and friends.

use super::code::ErrorCode;
use super::number::{NumberError, decode_u64};
use super::target::TargetDecodeError;
use super::telemetry::{TELEMETRY_TAG, TelemetryRecord, parse_telemetry};

/// Why a received line could not be decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DecodeError {
    /// The line has no words.
    Empty,
    /// The first word is not `ok`, `err` or `tel`.
    UnknownTag,
    /// A word of an `ok` payload or telemetry record is not `key=value` with both non-empty.
    BadPair {
        /// 0-based index of the word after the tag.
        index: u8,
    },
    /// `err` is not followed by a decimal code in `0..=65535`.
    BadErrorCode,
    /// `err <code>` is not followed by the error's name.
    MissingErrorName,
    /// A telemetry field is missing (the record ends early).
    MissingField {
        /// The key expected.
        key: &'static str,
    },
    /// A telemetry field has another key than the one expected at its position.
    UnexpectedField {
        /// The key expected.
        key: &'static str,
    },
    /// The record has words after its last field.
    ExtraField,
    /// A numeric field is not a number of its resolution that fits its type.
    BadNumber {
        /// The field's key.
        key: &'static str,
        /// What was wrong with it.
        error: NumberError,
    },
    /// The `state` field is not a known state name.
    BadState,
    /// The `target` field is neither `none` nor `kind:value`.
    BadTarget(TargetDecodeError),
}

/// A decoded reply.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Reply<'a> {
    /// `ok` with its (possibly empty) payload.
    Ok(Payload<'a>),
    /// `err <code> <name> <message>`.
    Err(ErrorReply<'a>),
}

/// The parts of an `err` reply.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ErrorReply<'a> {
    /// The numeric code (see [`ErrorCode`]; unknown codes are kept as numbers).
    pub code: u16,
    /// The code's kebab-case name as sent.
    pub name: &'a str,
    /// The message, without the line terminator.
    pub message: &'a str,
}

impl ErrorReply<'_> {
    /// The code as a known [`ErrorCode`], if this protocol version knows it.
    pub fn error_code(&self) -> Option<ErrorCode> {
        ErrorCode::from_code(self.code)
    }
}

/// The `key=value` pairs of an `ok` reply, checked when the reply was parsed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Payload<'a> {
    text: &'a str,
}

impl<'a> Payload<'a> {
    /// The payload text, pairs separated by single spaces or tabs (empty for a bare `ok`).
    pub fn as_str(&self) -> &'a str {
        self.text
    }

    /// The pairs in order.
    pub fn pairs(&self) -> impl Iterator<Item = (&'a str, &'a str)> + 'a {
        words(self.text).filter_map(|word| word.split_once('='))
    }

    /// The value of the first pair with this key.
    pub fn get(&self, key: &str) -> Option<&'a str> {
        self.pairs()
            .find(|&(k, _)| k == key)
            .map(|(_, value)| value)
    }
}

/// One line from the firmware: a reply or a telemetry record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Incoming<'a> {
    /// A reply to a command.
    Reply(Reply<'a>),
    /// A telemetry record.
    Telemetry(TelemetryRecord),
}

/// The words of a decoded line (split at spaces and tabs).
pub(crate) fn words(text: &str) -> impl Iterator<Item = &str> {
    text.split([' ', '\t']).filter(|word| !word.is_empty())
}

/// Strips one `\n` or `\r\n` terminator.
pub(crate) fn strip_terminator(line: &str) -> &str {
    let line = line.strip_suffix('\n').unwrap_or(line);
    line.strip_suffix('\r').unwrap_or(line)
}

/// Splits off the first word: `(word, rest)`, both trimmed of leading spaces and tabs.
fn split_word(text: &str) -> (&str, &str) {
    let text = text.trim_start_matches([' ', '\t']);
    let end = text.find([' ', '\t']).unwrap_or(text.len());
    let (word, rest) = text.split_at_checked(end).unwrap_or((text, ""));
    (word, rest.trim_start_matches([' ', '\t']))
}

/// Checks that every word is `key=value` with a non-empty key and value.
pub(crate) fn check_pairs(text: &str) -> Result<(), DecodeError> {
    for (index, word) in words(text).enumerate() {
        let pair = word.split_once('=');
        if !matches!(pair, Some((key, value)) if !key.is_empty() && !value.is_empty()) {
            return Err(DecodeError::BadPair {
                index: u8::try_from(index).unwrap_or(u8::MAX),
            });
        }
    }
    Ok(())
}

/// Decodes a reply line (with or without its terminator).
pub fn parse_reply(line: &str) -> Result<Reply<'_>, DecodeError> {
    let (tag, rest) = split_word(strip_terminator(line));
    match tag {
        "" => Err(DecodeError::Empty),
        "ok" => {
            check_pairs(rest)?;
            Ok(Reply::Ok(Payload {
                text: rest.trim_end_matches([' ', '\t']),
            }))
        }
        "err" => {
            let (code, rest) = split_word(rest);
            let code = decode_u64(code, 0)
                .ok()
                .and_then(|code| u16::try_from(code).ok())
                .ok_or(DecodeError::BadErrorCode)?;
            let (name, message) = split_word(rest);
            if name.is_empty() {
                return Err(DecodeError::MissingErrorName);
            }
            Ok(Reply::Err(ErrorReply {
                code,
                name,
                message: message.trim_end_matches([' ', '\t']),
            }))
        }
        _ => Err(DecodeError::UnknownTag),
    }
}

/// Decodes any line from the firmware: a reply or a telemetry record, told apart by the tag.
pub fn parse_incoming(line: &str) -> Result<Incoming<'_>, DecodeError> {
    let (tag, _) = split_word(strip_terminator(line));
    if tag == TELEMETRY_TAG {
        parse_telemetry(line).map(Incoming::Telemetry)
    } else {
        parse_reply(line).map(Incoming::Reply)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::vec::Vec;

    #[test]
    fn ok_replies() {
        let Ok(Reply::Ok(payload)) = parse_reply("ok scene=demo freq_hz=40000.00\r\n") else {
            panic!()
        };
        assert_eq!(payload.as_str(), "scene=demo freq_hz=40000.00");
        assert_eq!(
            payload.pairs().collect::<Vec<_>>(),
            [("scene", "demo"), ("freq_hz", "40000.00")]
        );
        assert_eq!(payload.get("freq_hz"), Some("40000.00"));
        assert_eq!(payload.get("state"), None);
        let Ok(Reply::Ok(empty)) = parse_reply("ok\n") else {
            panic!()
        };
        assert_eq!(empty.pairs().count(), 0);
        assert_eq!(
            parse_reply("ok a=1 b"),
            Err(DecodeError::BadPair { index: 1 })
        );
        assert_eq!(parse_reply("ok =1"), Err(DecodeError::BadPair { index: 0 }));
        assert_eq!(parse_reply("ok a="), Err(DecodeError::BadPair { index: 0 }));
    }

    #[test]
    fn err_replies() {
        let reply = parse_reply("err 6 out-of-range \"0\" is out of range 0.000 < force\n");
        let Ok(Reply::Err(error)) = reply else {
            panic!("{reply:?}")
        };
        assert_eq!(error.code, 6);
        assert_eq!(error.error_code(), Some(ErrorCode::OutOfRange));
        assert_eq!(error.name, "out-of-range");
        assert_eq!(error.message, "\"0\" is out of range 0.000 < force");
        let future = parse_reply("err 99 new-thing").unwrap();
        assert!(
            matches!(future, Reply::Err(e) if e.error_code().is_none() && e.message.is_empty())
        );
        assert_eq!(parse_reply("err x bad"), Err(DecodeError::BadErrorCode));
        assert_eq!(parse_reply("err 65536 big"), Err(DecodeError::BadErrorCode));
        assert_eq!(parse_reply("err 5"), Err(DecodeError::MissingErrorName));
    }

    #[test]
    fn other_lines() {
        assert_eq!(parse_reply(""), Err(DecodeError::Empty));
        assert_eq!(parse_reply(" \r\n"), Err(DecodeError::Empty));
        assert_eq!(parse_reply("okay"), Err(DecodeError::UnknownTag));
        assert_eq!(parse_reply("tel t_us=1"), Err(DecodeError::UnknownTag));
        assert!(matches!(
            parse_incoming("ok\n"),
            Ok(Incoming::Reply(Reply::Ok(_)))
        ));
        assert_eq!(
            parse_incoming("tel t_us=1"),
            Err(DecodeError::MissingField { key: "seq" })
        );
    }
}
