//! What the parser reports beyond the error code (issue 18): the column of a bad byte, and
//! which tokens `freq`/`telemetry` read as numbers rather than as a bad keyword.

use super::code::ErrorCode;
use super::{Command, ProtocolError, parse_command};

fn code(line: &str) -> ErrorCode {
    parse_command(line).map_or_else(|e| e.code(), |c| panic!("{line:?} parsed as {c:?}"))
}

#[test]
fn a_bad_byte_is_reported_at_its_1_based_column() {
    // The parser's own check (lines that did not come through the assembler).
    for (line, column, byte) in [
        ("\x01", 1, 0x01),
        ("stop\x07", 5, 0x07),
        ("st\u{e9}", 3, 0xc3),
        ("target force 1\x7f", 15, 0x7f),
    ] {
        assert_eq!(
            parse_command(line),
            Err(ProtocolError::BadEncoding { column, byte }),
            "{line:?}"
        );
    }
}

#[test]
fn a_sign_or_a_point_starts_a_number_not_a_keyword() {
    // A leading `+` is a number's sign: `freq +40000` is 40 kHz, `telemetry +10` is 10 Hz.
    assert_eq!(
        parse_command("freq +40000"),
        Ok(Command::Freq {
            freq_chz: 4_000_000
        })
    );
    assert_eq!(
        parse_command("telemetry +10"),
        Ok(Command::Telemetry { rate_hz: 10 })
    );
    // `-` and `.` also start numbers: their errors are the number's, not `bad-choice`.
    assert_eq!(code("freq -40000"), ErrorCode::OutOfRange);
    assert_eq!(code("telemetry -1"), ErrorCode::OutOfRange);
    assert_eq!(code("freq .5"), ErrorCode::BadNumber);
    assert_eq!(code("telemetry +x"), ErrorCode::BadNumber);
    // Anything else is a bad keyword.
    assert_eq!(code("freq *40000"), ErrorCode::BadChoice);
    assert_eq!(code("telemetry x10"), ErrorCode::BadChoice);
}
