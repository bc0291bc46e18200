//! Property tests across the whole receive path: line assembler, parser and reply formatter.
//!
//! Property (a) of the protocol: for arbitrary bytes, and for valid lines with random damage,
//! nothing panics, every non-empty line gets exactly one reply, that reply is a well-formed
//! `err` line that fits [`REPLY_CAPACITY`] whenever the line was not a command, and the
//! assembler agrees with a straightforward model of its documented rules.

use super::command::tests::any_command;
use super::{
    Command, LineAssembler, MAX_LINE_LEN, ProtocolError, REPLY_CAPACITY, Reply, format_ack,
    format_command, format_error, parse_command, parse_reply,
};
use heapless::String;
use proptest::prelude::*;
use proptest::sample::Index;
use std::vec::Vec;

/// What the assembler should yield for `input`, by its documented rules, written the obvious
/// way (split, filter, classify) rather than byte by byte.
fn model(input: &[u8]) -> Vec<Result<Vec<u8>, ProtocolError>> {
    let mut expected = Vec::new();
    // One line end per LF, per CR, and per CR LF pair (taken left to right): turn each pair
    // into a lone LF, then every CR into LF, and split.
    let mut normalised = Vec::with_capacity(input.len());
    let mut bytes = input.iter().copied().peekable();
    while let Some(byte) = bytes.next() {
        if byte == b'\r' {
            bytes.next_if_eq(&b'\n');
            normalised.push(b'\n');
        } else {
            normalised.push(byte);
        }
    }
    let mut segments: Vec<&[u8]> = normalised.split(|&b| b == b'\n').collect();
    // The bytes after the last line end are an incomplete line.
    segments.pop();
    for segment in segments {
        let line: Vec<u8> = segment.to_vec();
        let first_bad = line
            .iter()
            .position(|&b| !(b == b'\t' || b == b' ' || b.is_ascii_graphic()));
        // The byte after the buffer is full overflows it, unless a bad byte came first.
        match first_bad {
            Some(index) if index <= MAX_LINE_LEN => {
                expected.push(Err(ProtocolError::BadEncoding {
                    column: index as u32 + 1,
                    byte: line[index],
                }))
            }
            _ if line.len() > MAX_LINE_LEN => expected.push(Err(ProtocolError::LineTooLong {
                len: line.len() as u32,
            })),
            _ if line.iter().all(|&b| b == b' ' || b == b'\t') => {}
            _ => expected.push(Ok(line)),
        }
    }
    expected
}

/// Runs `input` through the receive path and checks every reply; returns what the assembler
/// yielded, for comparison with the model.
fn receive(input: &[u8]) -> Result<Vec<Result<Vec<u8>, ProtocolError>>, TestCaseError> {
    let mut assembler = LineAssembler::new();
    let mut yielded = Vec::new();
    let mut reply: String<REPLY_CAPACITY> = String::new();
    let mut rest = input;
    while !rest.is_empty() {
        let (used, line) = assembler.push_bytes(rest);
        prop_assert!(used > 0 && used <= rest.len());
        rest = &rest[used..];
        let Some(line) = line else { continue };
        yielded.push(line.map(|text| text.as_bytes().to_vec()));
        match line.and_then(parse_command) {
            Ok(command) => {
                prop_assert!(format_ack(&command, &mut reply).is_ok());
                prop_assert!(reply.starts_with("ok"));
                check_command_is_valid(&command)?;
            }
            Err(error) => {
                prop_assert!(format_error(&error, &mut reply).is_ok(), "{error:?}");
                prop_assert!(reply.starts_with("err "), "{reply}");
                prop_assert!(reply.len() <= REPLY_CAPACITY);
                prop_assert_eq!(
                    reply.find('\n'),
                    Some(reply.len() - 1),
                    "{}",
                    reply.as_str()
                );
                let decoded = parse_reply(&reply);
                prop_assert!(
                    matches!(decoded, Ok(Reply::Err(e)) if e.error_code() == Some(error.code())),
                    "{reply}"
                );
            }
        }
    }
    Ok(yielded)
}

/// A parsed command is one the canonical text reproduces (so its values are in range).
fn check_command_is_valid(command: &Command) -> Result<(), TestCaseError> {
    let mut text: String<MAX_LINE_LEN> = String::new();
    prop_assert!(format_command(command, &mut text).is_ok());
    prop_assert_eq!(parse_command(&text), Ok(*command));
    Ok(())
}

/// Bytes biased towards what makes lines: printable ASCII, separators and terminators, with
/// arbitrary bytes mixed in.
fn line_byte() -> impl Strategy<Value = u8> {
    prop_oneof![
        6 => 0x20u8..=0x7e,
        2 => Just(b' '),
        1 => Just(b'\n'),
        1 => Just(b'\r'),
        1 => Just(b'\t'),
        1 => any::<u8>(),
    ]
}

/// Bytes a typo or line noise inserts into a valid command.
fn damage_byte() -> impl Strategy<Value = u8> {
    prop_oneof![
        proptest::sample::select(&b"0123456789.+-e eautoffNlist\t"[..]),
        Just(b'\r'),
        Just(b'\n'),
        any::<u8>(),
    ]
}

#[derive(Debug, Clone)]
enum Damage {
    Insert(Index, u8),
    Delete(Index),
    Replace(Index, u8),
    /// Repeats the tail of the line from this point (a doubled word, or a very long line).
    Repeat(Index, usize),
}

fn damage() -> impl Strategy<Value = Damage> {
    prop_oneof![
        (any::<Index>(), damage_byte()).prop_map(|(at, byte)| Damage::Insert(at, byte)),
        any::<Index>().prop_map(Damage::Delete),
        (any::<Index>(), damage_byte()).prop_map(|(at, byte)| Damage::Replace(at, byte)),
        (any::<Index>(), 1usize..8).prop_map(|(at, times)| Damage::Repeat(at, times)),
    ]
}

fn apply(line: &mut Vec<u8>, damage: &Damage) {
    match damage {
        Damage::Insert(at, byte) => {
            let at = at.index(line.len() + 1);
            line.insert(at, *byte);
        }
        Damage::Delete(at) if !line.is_empty() => {
            line.remove(at.index(line.len()));
        }
        Damage::Replace(at, byte) if !line.is_empty() => {
            let at = at.index(line.len());
            line[at] = *byte;
        }
        Damage::Repeat(at, times) if !line.is_empty() => {
            let tail = line[at.index(line.len())..].to_vec();
            for _ in 0..*times {
                line.extend_from_slice(&tail);
            }
        }
        _ => {}
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(10_000))]

    /// Random bytes: no panic, one `err` reply per bad line, and the assembler matches the model.
    #[test]
    fn random_bytes_never_panic(input in proptest::collection::vec(line_byte(), 0..300)) {
        let yielded = receive(&input)?;
        prop_assert_eq!(yielded, model(&input));
    }

    /// Valid lines with up to four random edits: the same guarantees.
    #[test]
    fn damaged_commands_never_panic(
        command in any_command(),
        damages in proptest::collection::vec(damage(), 1..5),
    ) {
        let mut text: String<MAX_LINE_LEN> = String::new();
        prop_assert!(format_command(&command, &mut text).is_ok());
        let mut input = text.as_bytes().to_vec();
        input.pop();
        for damage in &damages {
            apply(&mut input, damage);
        }
        input.push(b'\n');
        let yielded = receive(&input)?;
        prop_assert_eq!(yielded, model(&input));
    }
}
