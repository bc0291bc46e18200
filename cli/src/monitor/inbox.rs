//! What the receiving thread has read from the firmware: replies waiting for their command,
//! telemetry records, and the lines that were neither (counted and kept as examples, never a
//! panic).
//!
//! Lines are told apart by their first word, as the protocol says (`ok` and `err` are replies,
//! `tel` is telemetry), and decoded with `sonolube::protocol`.

use std::collections::VecDeque;
use std::time::Instant;

use sonolube::protocol::{
    DecodeError, ErrorReply, Reply, TELEMETRY_TAG, parse_reply, parse_telemetry,
};

use super::telemetry_log::TelemetryLog;

/// Longest line accepted from the firmware, in bytes. The protocol's longest lines are a status
/// reply (263 bytes) and a telemetry record (227 bytes); a long scene list may exceed them.
pub const MAX_INCOMING_LINE: usize = 4096;

/// How many problem lines are kept as examples (all are counted).
const MAX_EXAMPLES: usize = 20;

/// One reply line, as received (without its terminator).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReplyLine {
    /// The line, without `\n` or `\r\n`.
    pub text: String,
}

impl ReplyLine {
    /// The decoded reply, or why it is malformed (for example `ok a` or `err x`).
    pub fn decode(&self) -> Result<Reply<'_>, DecodeError> {
        parse_reply(&self.text)
    }

    /// Whether this is a well-formed `ok` reply.
    pub fn is_ok(&self) -> bool {
        matches!(self.decode(), Ok(Reply::Ok(_)))
    }

    /// The parts of a well-formed `err` reply.
    pub fn error(&self) -> Option<ErrorReply<'_>> {
        match self.decode() {
            Ok(Reply::Err(error)) => Some(error),
            _ => None,
        }
    }
}

/// Lines from the firmware that broke the protocol.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Anomalies {
    /// Lines that were not valid UTF-8, had an unknown first word, were blank or too long, or
    /// were telemetry records that did not decode.
    pub malformed: u64,
    /// Replies that arrived while no command was waiting for one (one reply per line is the
    /// rule, so these are extra).
    pub unsolicited: u64,
    /// Replies whose first word is `ok` or `err` but which do not decode; they still answer
    /// their command (and are also counted in `malformed`).
    pub malformed_replies: u64,
    /// The first line, when it did not decode: the connection may have started in the middle
    /// of a line, so it is reported but not counted as malformed.
    pub partial_first_line: Option<String>,
    /// The first few problem lines with the reason, for the report.
    pub examples: Vec<String>,
}

impl Anomalies {
    /// Whether every line decoded and every reply answered a command.
    pub fn is_clean(&self) -> bool {
        self.malformed == 0 && self.unsolicited == 0
    }

    fn note(&mut self, what: &str, line: &str) {
        if self.examples.len() < MAX_EXAMPLES {
            self.examples.push(format!("{what}: {line:?}"));
        }
    }
}

/// The receiving side's state, shared between the receiving thread and the link.
#[derive(Debug)]
pub(crate) struct Inbox {
    /// Replies not yet taken by a command, oldest first.
    pub(crate) replies: VecDeque<ReplyLine>,
    /// Every telemetry record received.
    pub(crate) telemetry: TelemetryLog,
    /// When the newest telemetry record arrived.
    pub(crate) last_telemetry_at: Option<Instant>,
    /// Protocol violations seen.
    pub(crate) anomalies: Anomalies,
    /// Lines received (complete, any kind).
    pub(crate) lines: u64,
    /// Command lines written so far (set by the sending side before each write).
    pub(crate) commands_sent: u64,
    /// Replies accepted as answers so far.
    pub(crate) replies_received: u64,
    /// Why receiving ended (connection closed or failed), once it has.
    pub(crate) closed: Option<String>,
}

impl Inbox {
    pub(crate) fn new(record_capacity: usize) -> Self {
        Inbox {
            replies: VecDeque::new(),
            telemetry: TelemetryLog::new(record_capacity),
            last_telemetry_at: None,
            anomalies: Anomalies::default(),
            lines: 0,
            commands_sent: 0,
            replies_received: 0,
            closed: None,
        }
    }

    /// Files one complete line (terminator removed, `\r` included if it was there).
    pub(crate) fn accept(&mut self, bytes: &[u8], now: Instant) {
        self.lines += 1;
        let first = self.lines == 1;
        let bytes = bytes.strip_suffix(b"\r").unwrap_or(bytes);
        let Ok(text) = std::str::from_utf8(bytes) else {
            let shown = String::from_utf8_lossy(bytes).into_owned();
            return self.malformed(first, "not UTF-8", &shown);
        };
        let tag = text
            .split([' ', '\t'])
            .find(|w| !w.is_empty())
            .unwrap_or("");
        match tag {
            TELEMETRY_TAG => match parse_telemetry(text) {
                Ok(record) => {
                    self.telemetry.push(record);
                    self.last_telemetry_at = Some(now);
                }
                Err(error) => self.malformed(first, &format!("telemetry {error:?}"), text),
            },
            "ok" | "err" => {
                if self.replies_received >= self.commands_sent {
                    if first && parse_reply(text).is_err() {
                        self.anomalies.partial_first_line = Some(text.to_string());
                        return;
                    }
                    self.anomalies.unsolicited += 1;
                    self.anomalies.note("reply without a command", text);
                    return;
                }
                if let Err(error) = parse_reply(text) {
                    self.anomalies.malformed += 1;
                    self.anomalies.malformed_replies += 1;
                    self.anomalies.note(&format!("reply {error:?}"), text);
                }
                self.replies_received += 1;
                self.replies.push_back(ReplyLine {
                    text: text.to_string(),
                });
            }
            "" => self.malformed(first, "blank line", text),
            _ => self.malformed(first, "unknown first word", text),
        }
    }

    /// Files a line that exceeded [`MAX_INCOMING_LINE`]; `start` is its beginning.
    pub(crate) fn accept_overlong(&mut self, start: &[u8], len: usize) {
        self.lines += 1;
        let shown = String::from_utf8_lossy(start).into_owned();
        self.malformed(
            self.lines == 1,
            &format!("line of {len} bytes, longer than {MAX_INCOMING_LINE}"),
            &shown,
        );
    }

    fn malformed(&mut self, first: bool, why: &str, line: &str) {
        if first {
            self.anomalies.partial_first_line = Some(line.to_string());
        } else {
            self.anomalies.malformed += 1;
            self.anomalies.note(why, line);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::telemetry_log::DEFAULT_RECORD_CAPACITY;
    use super::*;

    const TEL: &[u8] = b"tel t_us=1000 seq=1 state=idle target=none mu=0.240000 normal_n=40.000 \
        tangential_n=9.600 amp=0.000000 freq_hz=40000.00 overruns=0 lost=0 lock=pinned \
        phase_deg=undefined reach=ok reachable=none resonance=near";

    fn inbox() -> Inbox {
        Inbox::new(DEFAULT_RECORD_CAPACITY)
    }

    #[test]
    fn lines_are_sorted_by_their_first_word() {
        let mut inbox = inbox();
        let now = Instant::now();
        inbox.commands_sent = 2;
        inbox.accept(TEL, now);
        inbox.accept(b"ok state=idle\r", now);
        inbox.accept(b"err 1 unknown-command \"x\" is not a command", now);
        assert_eq!(inbox.telemetry.received(), 1);
        assert_eq!(inbox.replies.len(), 2);
        assert_eq!(inbox.replies[0].text, "ok state=idle");
        assert!(inbox.replies[0].is_ok());
        assert_eq!(inbox.replies[1].error().map(|e| e.code), Some(1));
        assert!(inbox.anomalies.is_clean());
        assert_eq!(inbox.lines, 3);
    }

    #[test]
    fn bad_lines_are_counted_not_trusted() {
        let mut inbox = inbox();
        let now = Instant::now();
        inbox.accept(TEL, now);
        inbox.commands_sent = 1;
        inbox.accept(b"tel t_us=1 seq=x", now);
        inbox.accept(b"\xff\xfe garbage", now);
        inbox.accept(b"hello", now);
        inbox.accept(b"", now);
        inbox.accept(b"ok a", now);
        inbox.accept(b"ok", now);
        inbox.accept_overlong(b"tel ...", 5000);
        let a = &inbox.anomalies;
        assert_eq!((a.malformed, a.malformed_replies, a.unsolicited), (6, 1, 1));
        assert_eq!(a.examples.len(), 7);
        assert!(!a.is_clean());
        // The malformed reply still answered the one command sent; the second reply is extra.
        assert_eq!(inbox.replies.len(), 1);
        assert!(inbox.replies[0].decode().is_err());
        assert_eq!(a.partial_first_line, None);
    }

    #[test]
    fn a_broken_first_line_is_reported_apart() {
        let mut inbox = inbox();
        inbox.accept(b"ate=running mu=0.1", Instant::now());
        inbox.accept(TEL, Instant::now());
        assert!(inbox.anomalies.is_clean());
        assert_eq!(
            inbox.anomalies.partial_first_line.as_deref(),
            Some("ate=running mu=0.1")
        );
    }
}
