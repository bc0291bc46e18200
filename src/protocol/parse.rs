//! The command parser.
//!
//! The grammar is in the table of the [module documentation](super). A line is split into words
//! at runs of spaces and tabs; the first word is the keyword. Errors are found left to right, so
//! the reply names the first wrong word.

use super::command::{Axis, Command, TareAxes};
use super::error::{ProtocolError, TokenText};
use super::name::SceneName;
use super::number::parse_decimal;
use super::quantity::{
    CAL_LOAD, DRIVE_FREQ, Quantity, TARGET_COEF, TARGET_FORCE, TARGET_NET_FORCE, TARGET_REDUCTION,
    TELEMETRY_RATE,
};
use super::target::Target;

// Usages quoted by `missing-argument` and `extra-argument` replies.
const USAGE_TARGET: &str = "target force|coef|reduction|net-force <value>";
const USAGE_TARGET_FORCE: &str = "target force <newtons>";
const USAGE_TARGET_COEF: &str = "target coef <mu>";
const USAGE_TARGET_REDUCTION: &str = "target reduction <percent>";
const USAGE_TARGET_NET_FORCE: &str = "target net-force <newtons along +x>";
const USAGE_SCENE: &str = "scene list|<name>";
const USAGE_FREQ: &str = "freq auto|<hertz>";
const USAGE_TARGET_KINDS: &str = "force|coef|reduction|net-force";
const USAGE_TARE: &str = "tare normal|tangential|all";
const USAGE_CAL: &str = "cal normal|tangential <newtons>";
const USAGE_TELEMETRY: &str = "telemetry off|<hertz>";

/// The words of a line: runs of bytes other than space and tab.
struct Words<'a> {
    rest: &'a str,
}

impl<'a> Iterator for Words<'a> {
    type Item = &'a str;

    fn next(&mut self) -> Option<&'a str> {
        let start = self.rest.trim_start_matches([' ', '\t']);
        if start.is_empty() {
            self.rest = start;
            return None;
        }
        let end = start.find([' ', '\t']).unwrap_or(start.len());
        let (word, rest) = start.split_at_checked(end)?;
        self.rest = rest;
        Some(word)
    }
}

/// Parses one command line, with or without its `\n` or `\r\n` terminator.
///
/// Never panics. Any byte other than printable ASCII or tab is `bad-encoding` (the
/// [`LineAssembler`](super::LineAssembler) already filters them, but a host may call this
/// directly), and a line without any word is `empty-line`.
pub fn parse_command(line: &str) -> Result<Command, ProtocolError> {
    let line = line
        .strip_suffix('\n')
        .map(|l| l.strip_suffix('\r').unwrap_or(l))
        .unwrap_or(line);
    check_encoding(line)?;
    let mut words = Words { rest: line };
    let keyword = words.next().ok_or(ProtocolError::EmptyLine)?;
    let (command, usage) = match keyword {
        "version" => (Command::Version, "version"),
        "status" => (Command::Status, "status"),
        "faults" => (Command::Faults, "faults"),
        "target" => parse_target(&mut words)?,
        "scene" => (parse_scene(&mut words)?, USAGE_SCENE),
        "start" => (Command::Start, "start"),
        "stop" => (Command::Stop, "stop"),
        "freq" => match word_or_number(&mut words, "auto", USAGE_FREQ)? {
            None => (Command::FreqAuto, USAGE_FREQ),
            Some(token) => {
                let freq_chz = quantity(token, &DRIVE_FREQ)?;
                (Command::Freq { freq_chz }, USAGE_FREQ)
            }
        },
        "tare" => {
            let axes = match required(&mut words, USAGE_TARE)? {
                "all" => TareAxes::All,
                other => TareAxes::One(axis(other, "normal|tangential|all")?),
            };
            (Command::Tare(axes), USAGE_TARE)
        }
        "cal" => {
            let axis = axis(required(&mut words, USAGE_CAL)?, "normal|tangential")?;
            let load_mn = quantity(required(&mut words, USAGE_CAL)?, &CAL_LOAD)?;
            (Command::Cal { axis, load_mn }, USAGE_CAL)
        }
        "clear" => (Command::Clear, "clear"),
        "telemetry" => match word_or_number(&mut words, "off", USAGE_TELEMETRY)? {
            None => (Command::TelemetryOff, USAGE_TELEMETRY),
            Some(token) => {
                let rate = quantity(token, &TELEMETRY_RATE)?;
                let rate_hz =
                    u16::try_from(rate).map_err(|_| out_of_range(token, &TELEMETRY_RATE))?;
                (Command::Telemetry { rate_hz }, USAGE_TELEMETRY)
            }
        },
        "save" => (Command::Save, "save"),
        "load" => (Command::Load, "load"),
        "defaults" => (Command::Defaults, "defaults"),
        "log" => (Command::Log, "log"),
        "help" => (Command::Help, "help"),
        "commission" => match words.next() {
            None => (Command::Commission, "commission [status]"),
            Some("status") => (Command::CommissionStatus, "commission [status]"),
            Some(other) => {
                return Err(ProtocolError::BadChoice {
                    token: TokenText::new(other),
                    choices: "status",
                });
            }
        },
        other => {
            return Err(ProtocolError::UnknownCommand {
                token: TokenText::new(other),
            });
        }
    };
    match words.next() {
        Some(extra) => Err(ProtocolError::ExtraArgument {
            token: TokenText::new(extra),
            usage,
        }),
        None => Ok(command),
    }
}

/// The first byte that is neither printable ASCII nor tab is an error.
fn check_encoding(line: &str) -> Result<(), ProtocolError> {
    match line
        .bytes()
        .enumerate()
        .find(|&(_, b)| !(b == b' ' || b == b'\t' || b.is_ascii_graphic()))
    {
        Some((index, byte)) => Err(ProtocolError::BadEncoding {
            column: u32::try_from(index).unwrap_or(u32::MAX).saturating_add(1),
            byte,
        }),
        None => Ok(()),
    }
}

fn required<'a>(words: &mut Words<'a>, usage: &'static str) -> Result<&'a str, ProtocolError> {
    words.next().ok_or(ProtocolError::MissingArgument { usage })
}

fn parse_target(words: &mut Words<'_>) -> Result<(Command, &'static str), ProtocolError> {
    let kind = required(words, USAGE_TARGET)?;
    let bad_kind = || ProtocolError::BadChoice {
        token: TokenText::new(kind),
        choices: USAGE_TARGET_KINDS,
    };
    let (quantity_of, usage) = match kind {
        "force" => (&TARGET_FORCE, USAGE_TARGET_FORCE),
        "coef" => (&TARGET_COEF, USAGE_TARGET_COEF),
        "reduction" => (&TARGET_REDUCTION, USAGE_TARGET_REDUCTION),
        "net-force" => (&TARGET_NET_FORCE, USAGE_TARGET_NET_FORCE),
        _ => return Err(bad_kind()),
    };
    let token = required(words, usage)?;
    let value = signed_quantity(token, quantity_of)?;
    // In range, the value fits the kind's field (checked for every quantity in `quantity`'s
    // tests); a misfit would still be refused, never wrapped.
    let target = Target::from_kind(kind, value).ok_or_else(|| out_of_range(token, quantity_of))?;
    Ok((Command::Target(target), usage))
}

fn parse_scene(words: &mut Words<'_>) -> Result<Command, ProtocolError> {
    match required(words, USAGE_SCENE)? {
        "list" => Ok(Command::SceneList),
        name => SceneName::new(name)
            .map(Command::Scene)
            .ok_or(ProtocolError::BadName {
                token: TokenText::new(name),
            }),
    }
}

fn axis(word: &str, choices: &'static str) -> Result<Axis, ProtocolError> {
    match word {
        "normal" => Ok(Axis::Normal),
        "tangential" => Ok(Axis::Tangential),
        other => Err(ProtocolError::BadChoice {
            token: TokenText::new(other),
            choices,
        }),
    }
}

/// For `freq auto|<hertz>` and `telemetry off|<hertz>`: `None` for the word, the token for
/// anything that starts like a number (so `freq 4x` is a number error, not a bad choice), and
/// `bad-choice` otherwise.
fn word_or_number<'a>(
    words: &mut Words<'a>,
    word: &str,
    usage: &'static str,
) -> Result<Option<&'a str>, ProtocolError> {
    let token = required(words, usage)?;
    if token == word {
        return Ok(None);
    }
    match token.bytes().next() {
        Some(b) if b.is_ascii_digit() || matches!(b, b'+' | b'-' | b'.') => Ok(Some(token)),
        _ => Err(ProtocolError::BadChoice {
            token: TokenText::new(token),
            // The usage minus the keyword: `auto|<hertz>`.
            choices: usage.split_once(' ').map_or(usage, |(_, choices)| choices),
        }),
    }
}

/// Reads `token` as `quantity` and checks the range; the value is scaled.
fn quantity(token: &str, quantity: &'static Quantity) -> Result<u32, ProtocolError> {
    let value = parse_decimal(token, quantity.decimals)
        .map_err(|error| ProtocolError::from_number(error, token, quantity))?;
    if !quantity.contains(value) {
        return Err(out_of_range(token, quantity));
    }
    u32::try_from(value).map_err(|_| out_of_range(token, quantity))
}

/// A value of `quantity` in range, signed (the target kinds; the net force can be negative).
fn signed_quantity(token: &str, quantity: &'static Quantity) -> Result<i64, ProtocolError> {
    let value = parse_decimal(token, quantity.decimals)
        .map_err(|error| ProtocolError::from_number(error, token, quantity))?;
    if !quantity.contains(value) {
        return Err(out_of_range(token, quantity));
    }
    Ok(value)
}

fn out_of_range(token: &str, quantity: &'static Quantity) -> ProtocolError {
    ProtocolError::OutOfRange {
        token: TokenText::new(token),
        quantity,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::code::ErrorCode;
    use crate::protocol::reply::{REPLY_CAPACITY, format_error};
    use heapless::String;

    fn code(line: &str) -> ErrorCode {
        match parse_command(line) {
            Ok(command) => panic!("{line:?} parsed as {command:?}"),
            Err(error) => error.code(),
        }
    }

    fn message(line: &str) -> String<REPLY_CAPACITY> {
        let mut out = String::new();
        format_error(&parse_command(line).unwrap_err(), &mut out).unwrap();
        out
    }

    #[test]
    fn every_command() {
        let scene = SceneName::new("ramp-up_2").unwrap();
        let cases = [
            ("version", Command::Version),
            ("status", Command::Status),
            ("faults", Command::Faults),
            (
                "target force 12.5",
                Command::Target(Target::Force { force_mn: 12_500 }),
            ),
            (
                "target coef 0.35",
                Command::Target(Target::Coef { coef_ppm: 350_000 }),
            ),
            (
                "target reduction 40",
                Command::Target(Target::Reduction {
                    reduction_mpct: 40_000,
                }),
            ),
            (
                "target net-force -5.25",
                Command::Target(Target::NetForce { force_mn: -5_250 }),
            ),
            (
                "target net-force +0",
                Command::Target(Target::NetForce { force_mn: 0 }),
            ),
            ("scene list", Command::SceneList),
            ("scene ramp-up_2", Command::Scene(scene)),
            ("start", Command::Start),
            ("stop", Command::Stop),
            (
                "freq 40000.5",
                Command::Freq {
                    freq_chz: 4_000_050,
                },
            ),
            ("freq auto", Command::FreqAuto),
            ("tare normal", Command::Tare(TareAxes::One(Axis::Normal))),
            (
                "tare tangential",
                Command::Tare(TareAxes::One(Axis::Tangential)),
            ),
            ("tare all", Command::Tare(TareAxes::All)),
            (
                "cal tangential 10",
                Command::Cal {
                    axis: Axis::Tangential,
                    load_mn: 10_000,
                },
            ),
            ("clear", Command::Clear),
            ("telemetry 100", Command::Telemetry { rate_hz: 100 }),
            ("telemetry off", Command::TelemetryOff),
            ("help", Command::Help),
            ("commission", Command::Commission),
            ("commission status", Command::CommissionStatus),
            ("save", Command::Save),
            ("load", Command::Load),
            ("defaults", Command::Defaults),
            ("log", Command::Log),
        ];
        for (line, command) in cases {
            assert_eq!(parse_command(line), Ok(command), "{line:?}");
        }
    }

    #[test]
    fn spacing_and_terminators() {
        let expected = Ok(Command::Target(Target::Force { force_mn: 1 }));
        for line in [
            "target force 0.001",
            "  target \t force   0.001\t",
            "target force 0.001\n",
            "target force 0.001\r\n",
        ] {
            assert_eq!(parse_command(line), expected, "{line:?}");
        }
        assert_eq!(code("target force 0.001\r"), ErrorCode::BadEncoding);
        assert_eq!(code("target force 0.001\n\n"), ErrorCode::BadEncoding);
    }

    #[test]
    fn every_parse_error() {
        let cases = [
            ("Status", ErrorCode::UnknownCommand),
            ("reboot now", ErrorCode::UnknownCommand),
            ("target force 1.2.3", ErrorCode::BadNumber),
            ("target force .5", ErrorCode::BadNumber),
            ("freq 4x", ErrorCode::TrailingGarbage),
            ("target force 12N", ErrorCode::TrailingGarbage),
            ("target coef 1e-3", ErrorCode::TrailingGarbage),
            ("target force 0000000000001", ErrorCode::TooManyDigits),
            ("target force 1.0001", ErrorCode::TooManyDecimals),
            ("telemetry 10.5", ErrorCode::TooManyDecimals),
            ("target force 0", ErrorCode::OutOfRange),
            ("target force -5", ErrorCode::OutOfRange),
            ("target", ErrorCode::MissingArgument),
            ("target force", ErrorCode::MissingArgument),
            ("scene", ErrorCode::MissingArgument),
            ("freq", ErrorCode::MissingArgument),
            ("tare", ErrorCode::MissingArgument),
            ("cal", ErrorCode::MissingArgument),
            ("cal normal", ErrorCode::MissingArgument),
            ("telemetry", ErrorCode::MissingArgument),
            ("start now", ErrorCode::ExtraArgument),
            ("status status", ErrorCode::ExtraArgument),
            ("save now", ErrorCode::ExtraArgument),
            ("log all", ErrorCode::ExtraArgument),
            ("Save", ErrorCode::UnknownCommand),
            ("target force 1 2", ErrorCode::ExtraArgument),
            ("scene list all", ErrorCode::ExtraArgument),
            ("freq auto 40000", ErrorCode::ExtraArgument),
            ("telemetry off 1", ErrorCode::ExtraArgument),
            ("tare all normal", ErrorCode::ExtraArgument),
            ("target speed 1", ErrorCode::BadChoice),
            ("target Force 1", ErrorCode::BadChoice),
            ("freq fast", ErrorCode::BadChoice),
            ("telemetry on", ErrorCode::BadChoice),
            ("tare both", ErrorCode::BadChoice),
            ("commission now", ErrorCode::BadChoice),
            ("commission status now", ErrorCode::ExtraArgument),
            ("cal all 10", ErrorCode::BadChoice),
            ("scene Demo", ErrorCode::BadName),
            ("scene none", ErrorCode::BadName),
            ("scene abcdefghijklmnopqrstuvwxy", ErrorCode::BadName),
            ("", ErrorCode::EmptyLine),
            (" \t ", ErrorCode::EmptyLine),
            ("\n", ErrorCode::EmptyLine),
            ("st\u{e9}", ErrorCode::BadEncoding),
            ("stop\x07", ErrorCode::BadEncoding),
        ];
        for (line, expected) in cases {
            assert_eq!(code(line), expected, "{line:?}");
        }
    }

    /// The signed kind's malformed and out-of-range values are refused with an error reply
    /// that names the token and the range, never wrapped or clamped.
    #[test]
    fn net_force_refusals() {
        for (line, expected) in [
            ("target net-force", ErrorCode::MissingArgument),
            ("target net-force --5", ErrorCode::BadNumber),
            ("target net-force -", ErrorCode::BadNumber),
            ("target net-force 5N", ErrorCode::TrailingGarbage),
            ("target net-force -1.0001", ErrorCode::TooManyDecimals),
            ("target net-force -50000.001", ErrorCode::OutOfRange),
            ("target net-force 50000.001", ErrorCode::OutOfRange),
            ("target net-force -999999999.999", ErrorCode::OutOfRange),
            ("target net-force -9999999999.999", ErrorCode::TooManyDigits),
            ("target net-force 1 2", ErrorCode::ExtraArgument),
            ("target netforce 1", ErrorCode::BadChoice),
        ] {
            assert_eq!(code(line), expected, "{line:?}");
        }
        let reply = message("target net-force -60000");
        assert!(
            reply.contains("-50000.000 <= net-force <= 50000.000 N"),
            "{reply}"
        );
    }

    #[test]
    fn errors_are_found_left_to_right() {
        assert_eq!(code("target force abc extra"), ErrorCode::BadNumber);
        assert_eq!(code("target speed abc"), ErrorCode::BadChoice);
        assert_eq!(code("cal all abc"), ErrorCode::BadChoice);
        assert_eq!(code("cal normal 0 extra"), ErrorCode::OutOfRange);
    }

    #[test]
    fn longest_scene_name_and_quoted_tokens() {
        let name = "a".repeat(24);
        assert!(matches!(
            parse_command(&std::format!("scene {name}")),
            Ok(Command::Scene(n)) if n.as_str() == name
        ));
        let long = "x".repeat(90);
        assert!(message(&long).starts_with("err 1 unknown-command \"xxxxxxxxxxxxxxxxxxxxx...\""));
    }
}
