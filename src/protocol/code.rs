//! The stable numeric codes of `err` replies.
//!
//! Codes never change meaning: a host may act on the number, a person reads the name and the
//! message. Codes 1 to 19 are found by the line assembler and the parser; codes 20 and up are
//! returned by the firmware when a well-formed command cannot be executed. A new error gets a new
//! number; a number is never reused.

/// The stable error codes of `err` replies: number (`code`) and kebab-case name (`name`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u16)]
pub enum ErrorCode {
    /// 1 `unknown-command`: the first word is not a command.
    UnknownCommand = 1,
    /// 2 `bad-number`: not of the form `[+-]digits[.digits]`.
    BadNumber = 2,
    /// 3 `trailing-garbage`: a number followed by a unit, exponent or other characters.
    TrailingGarbage = 3,
    /// 4 `too-many-digits`: more than 12 digits.
    TooManyDigits = 4,
    /// 5 `too-many-decimals`: a non-zero digit finer than the resolution.
    TooManyDecimals = 5,
    /// 6 `out-of-range`: a number outside the quantity's range.
    OutOfRange = 6,
    /// 7 `missing-argument`: the command needs more arguments.
    MissingArgument = 7,
    /// 8 `extra-argument`: more arguments than the command takes.
    ExtraArgument = 8,
    /// 9 `bad-choice`: an argument that is not one of the allowed words.
    BadChoice = 9,
    /// 10 `bad-name`: not a valid scene name.
    BadName = 10,
    /// 11 `line-too-long`: the line exceeded the line buffer.
    LineTooLong = 11,
    /// 12 `bad-encoding`: a byte that is not printable ASCII or tab.
    BadEncoding = 12,
    /// 13 `empty-line`: the parser was given a line without a command.
    EmptyLine = 13,
    /// 20 `unknown-scene`: no scene has this name.
    UnknownScene = 20,
    /// 21 `wrong-state`: the command is not allowed in the current supervisor state.
    WrongState = 21,
    /// 22 `fault-latched`: a fault is latched; `clear` it first.
    FaultLatched = 22,
    /// 23 `no-target`: `start` without a target.
    NoTarget = 23,
    /// 24 `cal-failed`: the calibration could not be completed.
    CalFailed = 24,
    /// 25 `storage-failed`: the settings flash could not be read or written.
    StorageFailed = 25,
    /// 26 `settings-invalid`: nothing is stored, or the stored settings fail their checks.
    SettingsInvalid = 26,
    /// 27 `unavailable`: the command exists but this loop cannot do it (for example `freq
    /// auto` on a scene whose stack the resonance loop cannot model); the message says why.
    Unavailable = 27,
}

impl ErrorCode {
    /// Every code, in numeric order.
    pub const ALL: [ErrorCode; 21] = [
        ErrorCode::UnknownCommand,
        ErrorCode::BadNumber,
        ErrorCode::TrailingGarbage,
        ErrorCode::TooManyDigits,
        ErrorCode::TooManyDecimals,
        ErrorCode::OutOfRange,
        ErrorCode::MissingArgument,
        ErrorCode::ExtraArgument,
        ErrorCode::BadChoice,
        ErrorCode::BadName,
        ErrorCode::LineTooLong,
        ErrorCode::BadEncoding,
        ErrorCode::EmptyLine,
        ErrorCode::UnknownScene,
        ErrorCode::WrongState,
        ErrorCode::FaultLatched,
        ErrorCode::NoTarget,
        ErrorCode::CalFailed,
        ErrorCode::StorageFailed,
        ErrorCode::SettingsInvalid,
        ErrorCode::Unavailable,
    ];

    /// The number on the wire, `1..=27`.
    pub const fn code(self) -> u16 {
        self as u16
    }

    /// The kebab-case name on the wire.
    pub const fn name(self) -> &'static str {
        match self {
            ErrorCode::UnknownCommand => "unknown-command",
            ErrorCode::BadNumber => "bad-number",
            ErrorCode::TrailingGarbage => "trailing-garbage",
            ErrorCode::TooManyDigits => "too-many-digits",
            ErrorCode::TooManyDecimals => "too-many-decimals",
            ErrorCode::OutOfRange => "out-of-range",
            ErrorCode::MissingArgument => "missing-argument",
            ErrorCode::ExtraArgument => "extra-argument",
            ErrorCode::BadChoice => "bad-choice",
            ErrorCode::BadName => "bad-name",
            ErrorCode::LineTooLong => "line-too-long",
            ErrorCode::BadEncoding => "bad-encoding",
            ErrorCode::EmptyLine => "empty-line",
            ErrorCode::UnknownScene => "unknown-scene",
            ErrorCode::WrongState => "wrong-state",
            ErrorCode::FaultLatched => "fault-latched",
            ErrorCode::NoTarget => "no-target",
            ErrorCode::CalFailed => "cal-failed",
            ErrorCode::StorageFailed => "storage-failed",
            ErrorCode::SettingsInvalid => "settings-invalid",
            ErrorCode::Unavailable => "unavailable",
        }
    }

    /// The code with this number, if any (for the host decoding an `err` reply).
    pub fn from_code(code: u16) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.code() == code)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_are_stable_unique_and_round_trip() {
        let expected = [
            (1, "unknown-command"),
            (2, "bad-number"),
            (3, "trailing-garbage"),
            (4, "too-many-digits"),
            (5, "too-many-decimals"),
            (6, "out-of-range"),
            (7, "missing-argument"),
            (8, "extra-argument"),
            (9, "bad-choice"),
            (10, "bad-name"),
            (11, "line-too-long"),
            (12, "bad-encoding"),
            (13, "empty-line"),
            (20, "unknown-scene"),
            (21, "wrong-state"),
            (22, "fault-latched"),
            (23, "no-target"),
            (24, "cal-failed"),
            (25, "storage-failed"),
            (26, "settings-invalid"),
            (27, "unavailable"),
        ];
        assert_eq!(ErrorCode::ALL.len(), expected.len());
        for (code, (number, name)) in ErrorCode::ALL.into_iter().zip(expected) {
            assert_eq!((code.code(), code.name()), (number, name));
            assert_eq!(ErrorCode::from_code(number), Some(code));
        }
        assert_eq!(ErrorCode::from_code(0), None);
        assert_eq!(ErrorCode::from_code(14), None);
    }
}
