//! Formatting replies: `ok key=value ...` and `err <code> <name> <message>`, one line each.
//!
//! Every formatter replaces the buffer's contents with one complete line ending in `\n`, or
//! leaves it empty and returns an error; a buffer of [`REPLY_CAPACITY`] bytes holds every reply
//! except a long scene list. The replies that carry data (`status`, `faults`, `version`,
//! `scene list`, `help`) are built on [`OkReply`] by [`format_status`](super::format_status)
//! and its siblings.

use heapless::string::StringView;

use super::command::{Command, KEYWORDS, TareAxes};
use super::error::ProtocolError;
use super::quantity::{CAL_LOAD, DRIVE_FREQ};
use super::target::{Target, write_target};
use super::text::{FormatError, put, put_fixed, put_uint, put_word, write_line};

/// Buffer size (bytes) that holds every reply: the longest of 400 bytes and the `scene list`
/// reply of every compiled scene ([`crate::scene::SCENE_NAMES`]: the list is never cut, and
/// its `count` is the number of names it gives). The longest other replies: `commission
/// status` with every value at the widest its checks let through, 389 bytes
/// (`protocol::commission` tests); a status with every field at its extreme and 32-byte scene
/// and fault names, the reach fields and `values=commissioned`, 393 bytes.
pub const REPLY_CAPACITY: usize = {
    let list = scene_list_len(&crate::scene::SCENE_NAMES);
    if list > 400 { list } else { 400 }
};

/// Bytes of the `scene list` reply for `names`: `ok count=N scenes=a,b,c\n` (`none` for no
/// name).
pub const fn scene_list_len(names: &[&str]) -> usize {
    // "ok count=" + at most 10 digits + " scenes=" + "\n".
    let mut len = 9 + 10 + 8 + 1;
    if names.is_empty() {
        return len + NONE.len();
    }
    let mut index = 0;
    while index < names.len() {
        len += names[index].len() + 1;
        index += 1;
    }
    len
}

/// The list text of an empty list, and of an absent name or fault.
pub const NONE: &str = "none";

/// Builder of an `ok` reply: `ok` followed by ` key=value` pairs and `\n`.
///
/// Keys and word values are checked with [`is_word`](super::is_word); the first failure is kept
/// and returned by [`finish`](Self::finish), which leaves the buffer empty in that case.
pub struct OkReply<'a> {
    out: &'a mut StringView,
    result: Result<(), FormatError>,
}

impl<'a> OkReply<'a> {
    /// Starts `ok` in a cleared buffer.
    pub fn new(out: &'a mut StringView) -> Self {
        out.clear();
        let result = put(out, "ok");
        Self { out, result }
    }

    fn pair(
        mut self,
        key: &str,
        value: impl FnOnce(&mut StringView) -> Result<(), FormatError>,
    ) -> Self {
        if self.result.is_ok() {
            let out = &mut *self.out;
            self.result = put(out, " ")
                .and_then(|()| put_word(out, key))
                .and_then(|()| put(out, "="))
                .and_then(|()| value(out));
        }
        self
    }

    /// Adds `key=value` with a word value.
    pub fn word(self, key: &str, value: &str) -> Self {
        self.pair(key, |out| put_word(out, value))
    }

    /// Adds `key=value` with an unsigned integer.
    pub fn uint(self, key: &str, value: u64) -> Self {
        self.pair(key, |out| put_uint(out, value))
    }

    /// Adds `key=value` with a scaled integer printed with `decimals` fraction digits.
    pub fn fixed(self, key: &str, value: i64, decimals: u8) -> Self {
        self.pair(key, |out| put_fixed(out, value, decimals))
    }

    /// Adds `key=a,b,c` (or `key=none` for an empty list); items are words other than `none`.
    pub fn list(self, key: &str, items: &[&str]) -> Self {
        self.pair(key, |out| {
            if items.is_empty() {
                return put(out, NONE);
            }
            for (index, item) in items.iter().enumerate() {
                if index > 0 {
                    put(out, ",")?;
                }
                if *item == NONE {
                    return Err(FormatError::BadWord);
                }
                put_word(out, item)?;
            }
            Ok(())
        })
    }

    /// Adds `key=kind:value` or `key=none` for a target.
    pub fn target(self, key: &str, target: Option<&Target>) -> Self {
        self.pair(key, |out| write_target(out, target))
    }

    /// Ends the line; on any failure the buffer is left empty.
    pub fn finish(self) -> Result<(), FormatError> {
        let result = self.result.and_then(|()| put(self.out, "\n"));
        if result.is_err() {
            self.out.clear();
        }
        result
    }
}

/// Writes `err <code> <name> <message>\n` for `error`.
///
/// Cannot fail with a buffer of [`REPLY_CAPACITY`] bytes: the longest error line is 109 bytes
/// (free text from the firmware is shortened, see [`MAX_REASON_LEN`](super::MAX_REASON_LEN)).
pub fn format_error(error: &ProtocolError, out: &mut StringView) -> Result<(), FormatError> {
    write_line(out, |out| {
        let code = error.code();
        put(out, "err ")?;
        put_uint(out, u64::from(code.code()))?;
        put(out, " ")?;
        put(out, code.name())?;
        put(out, " ")?;
        error.write_message(out)?;
        put(out, "\n")
    })
}

/// Writes the acknowledgement of an executed command: the setting it made, as the firmware now
/// holds it.
///
/// `target=force:12.500`, `scene=demo`, `freq_hz=40000.00` or `freq_hz=auto`, `tare=all`,
/// `cal=normal load_n=10.000`, `telemetry_hz=100` or `telemetry_hz=off`; `help` gets its list;
/// the others get a bare `ok` (`version`, `status`, `faults` and `scene list` have their own
/// formatters with data).
pub fn format_ack(command: &Command, out: &mut StringView) -> Result<(), FormatError> {
    let reply = OkReply::new(out);
    match command {
        Command::Target(target) => reply.target("target", Some(target)),
        Command::Scene(name) => reply.word("scene", name.as_str()),
        Command::Freq { freq_chz } => {
            reply.fixed("freq_hz", i64::from(*freq_chz), DRIVE_FREQ.decimals)
        }
        Command::FreqAuto => reply.word("freq_hz", "auto"),
        Command::Tare(TareAxes::All) => reply.word("tare", "all"),
        Command::Tare(TareAxes::One(axis)) => reply.word("tare", axis.name()),
        Command::Cal { axis, load_mn } => {
            reply
                .word("cal", axis.name())
                .fixed("load_n", i64::from(*load_mn), CAL_LOAD.decimals)
        }
        Command::Telemetry { rate_hz } => reply.uint("telemetry_hz", u64::from(*rate_hz)),
        Command::TelemetryOff => reply.word("telemetry_hz", "off"),
        Command::Help => reply.list("commands", &KEYWORDS),
        Command::Commission => reply.word("commission", "started"),
        Command::CommissionStatus => reply,
        Command::Version
        | Command::Status
        | Command::Faults
        | Command::SceneList
        | Command::Start
        | Command::Stop
        | Command::Clear
        | Command::Save
        | Command::Load
        | Command::Defaults
        | Command::Log => reply,
    }
    .finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::code::ErrorCode;
    use crate::protocol::command::Axis;
    use crate::protocol::decode::{Reply, parse_reply};
    use crate::protocol::error::TokenText;
    use crate::protocol::name::SceneName;
    use crate::protocol::quantity::{ALL_QUANTITIES, TARGET_REDUCTION};
    use crate::protocol::state::SupervisorState;
    use heapless::String;

    type Line = String<REPLY_CAPACITY>;

    #[test]
    fn acknowledgements() {
        let cases = [
            (
                Command::Target(Target::Coef { coef_ppm: 350_000 }),
                "ok target=coef:0.350000\n",
            ),
            (
                Command::Scene(SceneName::new("demo").unwrap()),
                "ok scene=demo\n",
            ),
            (
                Command::Freq {
                    freq_chz: 4_000_050,
                },
                "ok freq_hz=40000.50\n",
            ),
            (Command::FreqAuto, "ok freq_hz=auto\n"),
            (Command::Tare(TareAxes::All), "ok tare=all\n"),
            (
                Command::Tare(TareAxes::One(Axis::Tangential)),
                "ok tare=tangential\n",
            ),
            (
                Command::Cal {
                    axis: Axis::Normal,
                    load_mn: 10_000,
                },
                "ok cal=normal load_n=10.000\n",
            ),
            (Command::Telemetry { rate_hz: 100 }, "ok telemetry_hz=100\n"),
            (Command::TelemetryOff, "ok telemetry_hz=off\n"),
            (Command::Start, "ok\n"),
            (Command::Stop, "ok\n"),
            (Command::Clear, "ok\n"),
        ];
        let mut out = Line::new();
        for (command, text) in cases {
            format_ack(&command, &mut out).unwrap();
            assert_eq!(out, text);
            assert!(matches!(parse_reply(&out), Ok(Reply::Ok(_))));
        }
        format_ack(&Command::Help, &mut out).unwrap();
        assert!(out.starts_with("ok commands=version,"));
    }

    /// One error of every kind, formatted, fits the buffer and decodes back to its code.
    #[test]
    fn every_error_formats_and_decodes() {
        let token = TokenText::new(&"t".repeat(90));
        let long_reason: &'static str = "r".repeat(500).leak();
        let longest_quantity = ALL_QUANTITIES[0];
        let errors = [
            ProtocolError::UnknownCommand { token },
            ProtocolError::BadNumber { token },
            ProtocolError::TrailingGarbage { token },
            ProtocolError::TooManyDigits { token },
            ProtocolError::TooManyDecimals {
                token,
                quantity: longest_quantity,
            },
            ProtocolError::OutOfRange {
                token,
                quantity: &TARGET_REDUCTION,
            },
            ProtocolError::MissingArgument {
                usage: "target force|coef|reduction <value>",
            },
            ProtocolError::ExtraArgument {
                token,
                usage: "target force|coef|reduction <value>",
            },
            ProtocolError::BadChoice {
                token,
                choices: "normal|tangential|all",
            },
            ProtocolError::BadName { token },
            ProtocolError::LineTooLong { len: u32::MAX },
            ProtocolError::BadEncoding {
                column: u32::MAX,
                byte: 0xff,
            },
            ProtocolError::EmptyLine,
            ProtocolError::UnknownScene {
                name: SceneName::new(&"s".repeat(24)).unwrap(),
            },
            ProtocolError::WrongState {
                command: "telemetry",
                state: SupervisorState::Calibrating,
            },
            ProtocolError::FaultLatched {
                fault: "overcurrent\n",
            },
            ProtocolError::NoTarget,
            ProtocolError::CalFailed {
                reason: long_reason,
            },
            ProtocolError::StorageFailed {
                reason: long_reason,
            },
            ProtocolError::SettingsInvalid {
                reason: long_reason,
            },
            ProtocolError::Unavailable {
                command: "freq",
                reason: long_reason,
            },
        ];
        assert_eq!(errors.len(), ErrorCode::ALL.len());
        let mut out = Line::new();
        for (error, code) in errors.iter().zip(ErrorCode::ALL) {
            assert_eq!(error.code(), code);
            format_error(error, &mut out).unwrap();
            assert!(out.len() <= 109, "{out}");
            assert_eq!(out.matches('\n').count(), 1, "{out:?}");
            let Ok(Reply::Err(reply)) = parse_reply(&out) else {
                panic!("{out}")
            };
            assert_eq!(reply.error_code(), Some(code));
            assert_eq!(reply.name, code.name());
            assert!(!reply.message.is_empty());
        }
        format_error(&errors[14], &mut out).unwrap();
        assert_eq!(
            out,
            "err 21 wrong-state telemetry is not allowed in state calibrating\n"
        );
        format_error(&errors[15], &mut out).unwrap();
        assert_eq!(
            out,
            "err 22 fault-latched fault overcurrent? is latched; send clear first\n"
        );
        format_error(&errors[11], &mut out).unwrap();
        assert_eq!(
            out,
            "err 12 bad-encoding byte 0xff at column 4294967295 is not printable ASCII; line \
             discarded\n"
        );
    }
}
