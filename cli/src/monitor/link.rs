//! A live link to the firmware's command interface: a receiving thread that reads every line
//! as it arrives, and a sending side that writes command lines and takes their replies in order.
//!
//! The receiving thread never waits for the sending side, so neither end can block the other:
//! the firmware's telemetry keeps flowing while a long command batch is written, and replies
//! queue up on the host until their command asks for them.

use std::io::{ErrorKind, Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::thread::{self, JoinHandle};
use std::time::{Duration, Instant};

use sonolube::protocol::{
    Command, LineAssembler, MAX_LINE_LEN, Reply, TelemetryRecord, format_command,
};

use super::endpoint::{Connection, Endpoint, connect};
use super::inbox::{Anomalies, Inbox, MAX_INCOMING_LINE, ReplyLine};
use super::telemetry_log::{DEFAULT_RECORD_CAPACITY, TelemetryLog};

/// Why talking to the firmware failed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum LinkError {
    /// The endpoint could not be opened.
    Connect(String),
    /// Writing failed (the firmware went away, or stopped reading for longer than the timeout).
    Write(String),
    /// The firmware closed the connection, or reading failed.
    Closed(String),
    /// Nothing arrived in time; the text says what was awaited.
    Timeout(String),
    /// A line to send contains a newline (it would be two lines and get two replies).
    BadLine(String),
}

impl std::fmt::Display for LinkError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LinkError::Connect(why) => write!(f, "cannot connect: {why}"),
            LinkError::Write(why) => write!(f, "cannot send: {why}"),
            LinkError::Closed(why) => write!(f, "connection lost: {why}"),
            LinkError::Timeout(what) => write!(f, "timed out waiting for {what}"),
            LinkError::BadLine(why) => write!(f, "cannot send {why}"),
        }
    }
}

impl std::error::Error for LinkError {}

/// Time limits and memory of a link.
#[derive(Debug, Clone, Copy)]
pub struct LinkOptions {
    /// Longest wait for a reply, and longest silence of telemetry while waiting on it (wall time).
    pub reply_timeout: Duration,
    /// How long a socket endpoint is retried while it does not accept yet.
    pub connect_timeout: Duration,
    /// Telemetry records kept for the CSV and the plot (later ones are only counted).
    pub record_capacity: usize,
}

impl Default for LinkOptions {
    fn default() -> Self {
        LinkOptions {
            reply_timeout: Duration::from_secs(5),
            connect_timeout: Duration::from_secs(10),
            record_capacity: DEFAULT_RECORD_CAPACITY,
        }
    }
}

/// Which clock a `wait MS` used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WaitClock {
    /// Firmware time, from the `t_us` of telemetry records: from `from_us` to at least `to_us`.
    Firmware {
        /// `t_us` of the record the wait started from.
        from_us: u64,
        /// `t_us` of the first record at or past the end of the wait.
        to_us: u64,
    },
    /// Wall time on the host (telemetry off).
    Wall,
}

/// Everything a finished session received.
#[derive(Debug, Clone)]
pub struct Session {
    /// The telemetry records.
    pub telemetry: TelemetryLog,
    /// Protocol violations seen.
    pub anomalies: Anomalies,
    /// Lines received in all.
    pub lines: u64,
}

struct Shared {
    inbox: Mutex<Inbox>,
    changed: Condvar,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, Inbox> {
        // A poisoned lock means the other side panicked; its data are still consistent
        // (every update is a single push or counter step), so keep going.
        self.inbox
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

/// An open link to the firmware (see the module docs).
pub struct Link {
    shared: Arc<Shared>,
    writer: Box<dyn Write + Send>,
    stop: Arc<AtomicBool>,
    receiver: Option<JoinHandle<()>>,
    options: LinkOptions,
    /// The last telemetry setting the firmware acknowledged: `Some(true)` after
    /// `ok telemetry_hz=N`, `Some(false)` after `ok telemetry_hz=off`, and the number of records
    /// received at that moment.
    telemetry_setting: Option<(bool, usize)>,
}

impl Link {
    /// Connects to `endpoint` (retrying a socket for `options.connect_timeout`) and starts
    /// receiving.
    pub fn connect(endpoint: &Endpoint, options: LinkOptions) -> Result<Link, LinkError> {
        let connection = connect(endpoint, options.connect_timeout, options.reply_timeout)
            .map_err(LinkError::Connect)?;
        Ok(Link::start(connection, options))
    }

    /// Starts receiving on an open connection.
    pub fn start(connection: Connection, options: LinkOptions) -> Link {
        let shared = Arc::new(Shared {
            inbox: Mutex::new(Inbox::new(options.record_capacity)),
            changed: Condvar::new(),
        });
        let stop = Arc::new(AtomicBool::new(false));
        let receiver = {
            let shared = Arc::clone(&shared);
            let stop = Arc::clone(&stop);
            let reader = connection.reader;
            thread::Builder::new()
                .name("monitor-receive".into())
                .spawn(move || receive(reader, &shared, &stop))
                .ok()
        };
        let link = Link {
            shared,
            writer: connection.writer,
            stop,
            receiver,
            options,
            telemetry_setting: None,
        };
        if link.receiver.is_none() {
            link.shared.lock().closed = Some("cannot start the receiving thread".into());
        }
        link
    }

    /// The link's time limits.
    pub fn options(&self) -> &LinkOptions {
        &self.options
    }

    /// Writes `line` and its `\n` without waiting; its reply is taken later with
    /// [`receive`](Self::receive). A blank line (which gets no reply) may be sent too: it is
    /// not counted as a command.
    pub fn send(&mut self, line: &[u8]) -> Result<(), LinkError> {
        if line.contains(&b'\n') {
            return Err(LinkError::BadLine(format!(
                "{:?}: it holds a newline",
                String::from_utf8_lossy(line)
            )));
        }
        let mut bytes = Vec::with_capacity(line.len() + 1);
        bytes.extend_from_slice(line);
        bytes.push(b'\n');
        let replies = replies(line);
        if replies > 0 {
            self.shared.lock().commands_sent += replies;
        }
        self.writer
            .write_all(&bytes)
            .and_then(|()| self.writer.flush())
            .map_err(|e| LinkError::Write(e.to_string()))
    }

    /// The next reply, waiting at most `timeout`.
    pub fn receive(&mut self, timeout: Duration) -> Result<ReplyLine, LinkError> {
        let deadline = Instant::now() + timeout;
        let mut inbox = self.shared.lock();
        loop {
            if let Some(reply) = inbox.replies.pop_front() {
                return Ok(reply);
            }
            if let Some(why) = &inbox.closed {
                return Err(LinkError::Closed(why.clone()));
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(LinkError::Timeout(format!(
                    "a reply ({} ms)",
                    timeout.as_millis()
                )));
            }
            inbox = self.wait(inbox, deadline - now);
        }
    }

    /// Sends one command line and returns its reply (waiting at most the reply timeout).
    /// The line must not be blank: blank lines get no reply.
    pub fn command(&mut self, line: &str) -> Result<ReplyLine, LinkError> {
        if replies(line.as_bytes()) != 1 {
            return Err(LinkError::BadLine(format!(
                "{line:?}: not one line with one reply (blank, or a CR inside it)"
            )));
        }
        self.send(line.as_bytes())?;
        let reply = self.receive(self.options.reply_timeout)?;
        if let Ok(Reply::Ok(payload)) = reply.decode()
            && let Some(rate) = payload.get("telemetry_hz")
        {
            let received = self.telemetry_received();
            self.telemetry_setting = Some((rate != "off", received));
        }
        Ok(reply)
    }

    /// Sends `command` in its canonical form and returns its reply.
    pub fn send_command(&mut self, command: &Command) -> Result<ReplyLine, LinkError> {
        let mut line = heapless::String::<MAX_LINE_LEN>::new();
        format_command(command, &mut line)
            .map_err(|e| LinkError::BadLine(format!("{command:?}: {e:?}")))?;
        self.command(line.trim_end_matches('\n'))
    }

    /// Sends every line of `lines` (none blank, each must get one reply), keeping at most
    /// `window` lines unanswered, and hands each reply to `on_reply` with its line's index.
    /// Stops at the first line whose reply does not come within the reply timeout.
    pub fn pipeline(
        &mut self,
        lines: &[Vec<u8>],
        window: usize,
        mut on_reply: impl FnMut(usize, ReplyLine),
    ) -> Result<(), LinkError> {
        if let Some(blank) = lines.iter().find(|line| replies(line) != 1) {
            return Err(LinkError::BadLine(format!(
                "{:?}: not one line with one reply (blank, or a CR inside it)",
                String::from_utf8_lossy(blank)
            )));
        }
        let window = window.max(1);
        let mut sent = 0;
        for received in 0..lines.len() {
            while sent < lines.len() && sent - received < window {
                self.send(&lines[sent])?;
                sent += 1;
            }
            let reply = self
                .receive(self.options.reply_timeout)
                .map_err(|e| match e {
                    LinkError::Timeout(what) => LinkError::Timeout(format!(
                        "{what}: reply {} of {} (line {:?})",
                        received + 1,
                        lines.len(),
                        String::from_utf8_lossy(&lines[received])
                    )),
                    other => other,
                })?;
            on_reply(received, reply);
        }
        Ok(())
    }

    /// Telemetry records received so far.
    pub fn telemetry_received(&self) -> usize {
        self.shared.lock().telemetry.records().len()
    }

    /// Runs `read` on the telemetry received so far.
    pub fn with_telemetry<R>(&self, read: impl FnOnce(&TelemetryLog) -> R) -> R {
        read(&self.shared.lock().telemetry)
    }

    /// Waits for the first kept record at index `from` or later that satisfies `wanted`;
    /// returns its index and the record. Fails when no new record arrives for the reply
    /// timeout (telemetry off or stopped), or the log is full.
    pub fn wait_for_record(
        &self,
        from: usize,
        mut wanted: impl FnMut(&TelemetryRecord) -> bool,
    ) -> Result<(usize, TelemetryRecord), LinkError> {
        let silence = self.options.reply_timeout;
        let mut inbox = self.shared.lock();
        let mut next = from;
        let mut last_progress = Instant::now();
        loop {
            let records = inbox.telemetry.records();
            while let Some(record) = records.get(next) {
                if wanted(record) {
                    return Ok((next, *record));
                }
                next += 1;
                last_progress = Instant::now();
            }
            if inbox.telemetry.not_kept() > 0 {
                return Err(LinkError::Timeout(
                    "a telemetry record: the record log is full".into(),
                ));
            }
            if let Some(why) = &inbox.closed {
                return Err(LinkError::Closed(why.clone()));
            }
            let quiet = last_progress.elapsed();
            if quiet >= silence {
                return Err(LinkError::Timeout(format!(
                    "telemetry (none for {} ms)",
                    silence.as_millis()
                )));
            }
            inbox = self.wait(inbox, silence - quiet);
        }
    }

    /// The `wait MS` of scripts: `ms` milliseconds of firmware time when telemetry is on, of
    /// wall time when it is off.
    ///
    /// Telemetry counts as on when the firmware's last `telemetry` acknowledgement in this
    /// session was a rate, or, before any, when a record arrived in the last second. The wait
    /// starts at the newest record received since telemetry was turned on (or the first one to
    /// arrive) and ends at the first record whose `t_us` is `ms` ms later.
    pub fn wait_ms(&mut self, ms: u64) -> Result<WaitClock, LinkError> {
        let firmware_from = match self.telemetry_setting {
            Some((true, since)) => Some(since),
            Some((false, _)) => None,
            None => {
                let inbox = self.shared.lock();
                let recent = inbox
                    .last_telemetry_at
                    .is_some_and(|at| at.elapsed() < Duration::from_secs(1));
                recent.then(|| inbox.telemetry.records().len().saturating_sub(1))
            }
        };
        let Some(since) = firmware_from else {
            thread::sleep(Duration::from_millis(ms));
            return Ok(WaitClock::Wall);
        };
        let newest = self.telemetry_received().saturating_sub(1).max(since);
        let (index, start) = self.wait_for_record(newest, |_| true)?;
        let end_us = start.time_us.saturating_add(ms.saturating_mul(1000));
        let (_, end) = self.wait_for_record(index, |r| r.time_us >= end_us)?;
        Ok(WaitClock::Firmware {
            from_us: start.time_us,
            to_us: end.time_us,
        })
    }

    /// Protocol violations seen so far.
    pub fn anomalies(&self) -> Anomalies {
        self.shared.lock().anomalies.clone()
    }

    /// Lines received so far.
    pub fn lines_received(&self) -> u64 {
        self.shared.lock().lines
    }

    /// Stops receiving and returns what the session received.
    pub fn finish(mut self) -> Session {
        self.stop_receiving();
        let inbox = self.shared.lock();
        Session {
            telemetry: inbox.telemetry.clone(),
            anomalies: inbox.anomalies.clone(),
            lines: inbox.lines,
        }
    }

    fn stop_receiving(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(receiver) = self.receiver.take() {
            // The thread only ends by itself; a panic in it has already been reported.
            let _ = receiver.join();
        }
    }

    fn wait<'a>(
        &'a self,
        inbox: MutexGuard<'a, Inbox>,
        at_most: Duration,
    ) -> MutexGuard<'a, Inbox> {
        match self.shared.changed.wait_timeout(inbox, at_most) {
            Ok((inbox, _)) => inbox,
            Err(poisoned) => poisoned.into_inner().0,
        }
    }
}

impl Drop for Link {
    fn drop(&mut self) {
        self.stop_receiving();
    }
}

/// How many replies the firmware gives `line` sent with a `\n`: how many lines or line errors
/// its assembler yields (a blank line none; a `\r` also ends a line, and a trailing one with
/// the `\n` is the single line end `\r\n`).
fn replies(line: &[u8]) -> u64 {
    let mut assembler = LineAssembler::new();
    let mut count = 0;
    assembler.push_all(line, |_| count += 1);
    assembler.push_all(b"\n", |_| count += 1);
    count
}

/// The receiving thread: splits the byte stream into lines and files each in the inbox.
fn receive(mut reader: Box<dyn Read + Send>, shared: &Shared, stop: &AtomicBool) {
    let mut buffer = [0u8; 4096];
    let mut line: Vec<u8> = Vec::with_capacity(512);
    let mut overlong = 0usize;
    let closed = loop {
        if stop.load(Ordering::Relaxed) {
            break "the monitor stopped".to_string();
        }
        let count = match reader.read(&mut buffer) {
            Ok(0) => break "the firmware closed the connection".to_string(),
            Ok(count) => count,
            Err(e)
                if matches!(
                    e.kind(),
                    ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted
                ) =>
            {
                continue;
            }
            Err(e) => break format!("read failed: {e}"),
        };
        let now = Instant::now();
        let mut inbox = shared.lock();
        for &byte in &buffer[..count] {
            if byte == b'\n' {
                if overlong > 0 {
                    inbox.accept_overlong(&line, overlong);
                } else {
                    inbox.accept(&line, now);
                }
                line.clear();
                overlong = 0;
            } else if overlong > 0 {
                overlong += 1;
            } else if line.len() < MAX_INCOMING_LINE {
                line.push(byte);
            } else {
                // Keep the start for the report, drop the rest up to the newline.
                line.truncate(80);
                overlong = MAX_INCOMING_LINE + 1;
            }
        }
        drop(inbox);
        shared.changed.notify_all();
    };
    shared.lock().closed = Some(closed);
    shared.changed.notify_all();
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::BufRead;
    use std::os::unix::net::UnixStream;

    /// A link whose far end is returned for the test to play the firmware.
    fn pair() -> (Link, UnixStream) {
        let (near, far) = UnixStream::pair().unwrap();
        let options = LinkOptions {
            reply_timeout: Duration::from_millis(300),
            ..LinkOptions::default()
        };
        let connection = Connection::unix(near, Duration::from_secs(2)).unwrap();
        (Link::start(connection, options), far)
    }

    #[test]
    fn blank_lines_are_not_commands() {
        let (mut link, far) = pair();
        assert!(matches!(link.command(" \t"), Err(LinkError::BadLine(_))));
        assert!(matches!(link.send(b"a\nb"), Err(LinkError::BadLine(_))));
        assert!(matches!(
            link.pipeline(&[b"status".to_vec(), b"\r".to_vec()], 2, |_, _| {}),
            Err(LinkError::BadLine(_))
        ));
        link.send(b"   ").unwrap();
        // No command is waiting, so a reply now is an extra one.
        (&far).write_all(b"ok\n").unwrap();
        thread::sleep(Duration::from_millis(100));
        assert_eq!(link.anomalies().unsolicited, 1);
        assert!(matches!(
            link.receive(Duration::from_millis(50)),
            Err(LinkError::Timeout(_))
        ));
    }

    #[test]
    fn pipelined_replies_come_back_in_order() {
        let (mut link, far) = pair();
        let echo = thread::spawn(move || {
            let mut reader = std::io::BufReader::new(&far);
            let mut line = String::new();
            let mut answered = 0;
            while reader.read_line(&mut line).unwrap_or(0) > 0 {
                let reply = format!("err 1 unknown-command \"{}\"\n", line.trim_end());
                (&far).write_all(reply.as_bytes()).unwrap();
                (&far).write_all(b"tel broken\n").unwrap();
                answered += 1;
                line.clear();
            }
            answered
        });
        let lines: Vec<Vec<u8>> = (0..200).map(|i| format!("x{i}").into_bytes()).collect();
        let mut seen = Vec::new();
        link.pipeline(&lines, 8, |index, reply| {
            seen.push((index, reply.error().map(|e| e.message.to_string())))
        })
        .unwrap();
        assert_eq!(seen.len(), 200);
        for (i, (index, message)) in seen.iter().enumerate() {
            assert_eq!(*index, i);
            assert_eq!(message.as_deref(), Some(format!("\"x{i}\"").as_str()));
        }
        let session = link.finish();
        assert_eq!(echo.join().unwrap(), 200);
        assert_eq!(session.anomalies.malformed, 200);
        assert_eq!(session.lines, 400);
    }

    #[test]
    fn an_endless_line_is_cut_and_counted() {
        let (link, far) = pair();
        (&far)
            .write_all(&vec![b'x'; MAX_INCOMING_LINE * 3])
            .unwrap();
        (&far).write_all(b"\nok\n").unwrap();
        drop(far);
        let deadline = Instant::now() + Duration::from_secs(2);
        while link.lines_received() < 2 && Instant::now() < deadline {
            thread::sleep(Duration::from_millis(10));
        }
        let session = link.finish();
        // The first line is taken as a partial one; the reply answers no command.
        assert!(session.anomalies.partial_first_line.is_some());
        assert_eq!(session.anomalies.unsolicited, 1);
    }
}
