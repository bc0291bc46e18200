//! Assembling received UART bytes into command lines.
//!
//! The assembler never blocks and never grows: it holds at most [`MAX_LINE_LEN`] bytes, and a
//! longer line is dropped byte by byte until its line end, where it is reported once. Reporting
//! at the line end (not at the first extra byte) keeps the one-reply-per-line rhythm a host
//! relies on to match replies to commands.
//!
//! A line ends with LF, CR, or the pair CR LF (one line end, not two): programs send LF,
//! while `screen`, `minicom` and `picocom` send a lone CR when a person presses Enter, and
//! some terminals send CR LF.

use super::error::ProtocolError;

/// Longest command line in bytes, without its terminator. The longest valid command is 31
/// bytes; the slack lets a person type extra spaces.
pub const MAX_LINE_LEN: usize = 96;

/// What went wrong in the line being received; only the first problem is kept.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum LineFault {
    TooLong,
    BadByte { column: u32, byte: u8 },
}

/// What a line end completed; borrows nothing, so the byte loop can return it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Completed {
    Line,
    Error(ProtocolError),
}

/// Splits a byte stream into lines.
///
/// * `\n`, `\r` and the pair `\r\n` each end a line: a `\n` right after a `\r` completes
///   nothing (it is the second half of one line end), also when the pair is split between two
///   calls.
/// * A line of more than [`MAX_LINE_LEN`] bytes yields [`ProtocolError::LineTooLong`] once, at
///   its line end.
/// * A byte other than printable ASCII (`0x20..=0x7e`) or tab yields
///   [`ProtocolError::BadEncoding`] once, at the line end.
/// * Empty lines and lines of only spaces and tabs yield nothing (no reply).
#[derive(Debug, Clone)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LineAssembler {
    buf: [u8; MAX_LINE_LEN],
    /// Bytes stored in `buf`.
    len: usize,
    /// Bytes received in the current line (its line end excluded), saturating.
    received: u32,
    fault: Option<LineFault>,
    /// The last byte completed a line, whose text is still in `buf` for the caller to read;
    /// the next byte starts a new line.
    completed: bool,
    /// The last byte was a `\r`: a `\n` now is the second half of a `\r\n` line end.
    after_cr: bool,
}

impl Default for LineAssembler {
    fn default() -> Self {
        Self::new()
    }
}

impl LineAssembler {
    /// An empty assembler.
    pub const fn new() -> Self {
        Self {
            buf: [0; MAX_LINE_LEN],
            len: 0,
            received: 0,
            fault: None,
            completed: false,
            after_cr: false,
        }
    }

    /// Discards the partial line, for example after a UART error lost bytes of it.
    pub fn reset(&mut self) {
        *self = Self::new();
    }

    /// Feeds one byte. Returns the line (without terminator, printable ASCII and tabs only) or
    /// its error when `byte` is the `\n` or `\r` that completes it, `None` otherwise.
    pub fn push(&mut self, byte: u8) -> Option<Result<&str, ProtocolError>> {
        let completed = self.accept(byte)?;
        Some(self.result(completed))
    }

    /// Feeds bytes until one completes a line. Returns how many bytes were consumed and, if a
    /// line was completed, its result; feed the rest of the slice in the next call.
    pub fn push_bytes(&mut self, bytes: &[u8]) -> (usize, Option<Result<&str, ProtocolError>>) {
        for (index, &byte) in bytes.iter().enumerate() {
            if let Some(completed) = self.accept(byte) {
                return (index.saturating_add(1), Some(self.result(completed)));
            }
        }
        (bytes.len(), None)
    }

    /// Feeds all of `bytes`, calling `on_line` for each completed line or line error.
    pub fn push_all(&mut self, bytes: &[u8], mut on_line: impl FnMut(Result<&str, ProtocolError>)) {
        for &byte in bytes {
            if let Some(completed) = self.accept(byte) {
                on_line(self.result(completed));
            }
        }
    }

    /// The state machine; `Some` when a line (or its error) is complete.
    fn accept(&mut self, byte: u8) -> Option<Completed> {
        let follows_cr = core::mem::replace(&mut self.after_cr, byte == b'\r');
        if self.completed {
            let after_cr = self.after_cr;
            self.reset();
            self.after_cr = after_cr;
        }
        match byte {
            // The `\n` of a `\r\n` pair: the `\r` already ended the line.
            b'\n' if follows_cr => return None,
            b'\n' | b'\r' => return self.complete(),
            _ => {}
        }
        self.received = self.received.saturating_add(1);
        if self.fault.is_some() {
            return None;
        }
        if !(byte == b'\t' || byte == b' ' || byte.is_ascii_graphic()) {
            self.fault = Some(LineFault::BadByte {
                column: self.received,
                byte,
            });
            return None;
        }
        match self.buf.get_mut(self.len) {
            Some(slot) => {
                *slot = byte;
                self.len = self.len.saturating_add(1);
            }
            None => self.fault = Some(LineFault::TooLong),
        }
        None
    }

    fn complete(&mut self) -> Option<Completed> {
        self.completed = true;
        match self.fault {
            Some(LineFault::TooLong) => Some(Completed::Error(ProtocolError::LineTooLong {
                len: self.received,
            })),
            Some(LineFault::BadByte { column, byte }) => {
                Some(Completed::Error(ProtocolError::BadEncoding {
                    column,
                    byte,
                }))
            }
            None if self.line().iter().all(|&b| b == b' ' || b == b'\t') => None,
            None => Some(Completed::Line),
        }
    }

    fn line(&self) -> &[u8] {
        self.buf.get(..self.len).unwrap_or(&[])
    }

    fn result(&self, completed: Completed) -> Result<&str, ProtocolError> {
        match completed {
            Completed::Error(error) => Err(error),
            // Only printable ASCII and tabs are stored, so the conversion cannot fail; should it
            // ever, the line is refused rather than trusted.
            Completed::Line => {
                core::str::from_utf8(self.line()).map_err(|_| ProtocolError::BadEncoding {
                    column: 1,
                    byte: self.line().first().copied().unwrap_or(0),
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::string::{String, ToString};
    use std::vec::Vec;

    /// Everything the assembler yields for `input`, as text (`Err` as the error code name).
    fn lines(input: &[u8]) -> Vec<Result<String, ProtocolError>> {
        let mut assembler = LineAssembler::new();
        let mut out = Vec::new();
        assembler.push_all(input, |line| out.push(line.map(ToString::to_string)));
        out
    }

    #[test]
    fn lf_cr_and_cr_lf_each_end_one_line() {
        assert_eq!(
            lines(b"status\nstart\r\nst\rop\n"),
            [
                Ok("status".into()),
                Ok("start".into()),
                Ok("st".into()),
                Ok("op".into())
            ]
        );
        assert_eq!(lines(b"status"), []);
        assert_eq!(lines(b"\r"), []);
        // What screen, minicom and picocom send on Enter: a lone CR.
        assert_eq!(
            lines(b"version\rstatus\r"),
            [Ok("version".into()), Ok("status".into())]
        );
    }

    /// CR LF is one line end: the LF completes nothing, so a blank line after it still counts
    /// as blank and the next line is intact; CR CR LF is two line ends (a blank line between).
    #[test]
    fn cr_lf_is_one_line_end_even_split_across_calls() {
        let mut assembler = LineAssembler::new();
        assert_eq!(assembler.push_bytes(b"stop\r"), (5, Some(Ok("stop"))));
        assert_eq!(assembler.push_bytes(b"\n"), (1, None));
        assert_eq!(assembler.push_bytes(b"x\n"), (2, Some(Ok("x"))));
        let mut count = 0;
        assembler.push_all(b"a\r\nb\r\r\nc\n\rd\n", |_| count += 1);
        assert_eq!(count, 4);
        // The LF of a pair is swallowed only right after the CR.
        assert_eq!(assembler.push(b'\r'), None); // blank line: no reply
        assert_eq!(assembler.push(b'a'), None);
        assert_eq!(assembler.push(b'\n'), Some(Ok("a")));
    }

    #[test]
    fn blank_lines_yield_nothing() {
        assert_eq!(lines(b"\n\r\n \t \nhelp\n\n"), [Ok("help".into())]);
    }

    #[test]
    fn keeps_spacing_for_the_parser() {
        assert_eq!(lines(b"  freq\t auto \n"), [Ok("  freq\t auto ".into())]);
    }

    #[test]
    fn longest_line_fits_and_one_more_byte_is_an_error_reported_once() {
        let mut input = [b'x'; MAX_LINE_LEN].to_vec();
        input.extend_from_slice(b"\r\n");
        assert_eq!(lines(&input), [Ok("x".repeat(MAX_LINE_LEN))]);

        let mut input = [b'x'; MAX_LINE_LEN + 1].to_vec();
        input.extend_from_slice(b"\r\r\nstatus\r");
        assert_eq!(
            lines(&input),
            [
                Err(ProtocolError::LineTooLong {
                    len: MAX_LINE_LEN as u32 + 1
                }),
                Ok("status".into())
            ]
        );
    }

    #[test]
    fn a_very_long_line_is_discarded_without_growing() {
        let mut assembler = LineAssembler::new();
        for _ in 0..100_000 {
            assert!(assembler.push(b'a').is_none());
        }
        assert_eq!(
            assembler.push(b'\n'),
            Some(Err(ProtocolError::LineTooLong { len: 100_000 }))
        );
        assert_eq!(assembler.push(b'\n'), None);
    }

    #[test]
    fn bad_bytes_make_the_line_an_error_reported_once() {
        assert_eq!(
            lines(b"sta\xc3\xa9tus\x00\nstop\n"),
            [
                Err(ProtocolError::BadEncoding {
                    column: 4,
                    byte: 0xc3
                }),
                Ok("stop".into())
            ]
        );
        for byte in [0x00, 0x07, 0x1b, 0x7f, 0x80, 0xff] {
            assert_eq!(
                lines(&[b'a', byte, b'\n']),
                [Err(ProtocolError::BadEncoding { column: 2, byte })]
            );
        }
        // The first problem wins: a bad byte after the line is already too long.
        let mut input = [b'x'; MAX_LINE_LEN + 3].to_vec();
        input.extend_from_slice(b"\x01\n");
        assert_eq!(
            lines(&input),
            [Err(ProtocolError::LineTooLong {
                len: MAX_LINE_LEN as u32 + 4
            })]
        );
    }

    #[test]
    fn push_bytes_stops_at_each_line() {
        let mut assembler = LineAssembler::new();
        let input = b"start\nstop\nsta";
        let (used, line) = assembler.push_bytes(input);
        assert_eq!((used, line), (6, Some(Ok("start"))));
        let (used, line) = assembler.push_bytes(&input[6..]);
        assert_eq!((used, line), (5, Some(Ok("stop"))));
        let (used, line) = assembler.push_bytes(&input[11..]);
        assert_eq!((used, line), (3, None));
        assert_eq!(assembler.push_bytes(b"tus\n"), (4, Some(Ok("status"))));
        assembler.push_bytes(b"garbage");
        assembler.reset();
        assert_eq!(assembler.push_bytes(b"help\n"), (5, Some(Ok("help"))));
    }
}
