//! `sonolube monitor --commission`: runs the firmware's `commission` and waits for its result.
//!
//! Sends `commission` (the firmware answers `ok commission=started` and runs the sequence in its
//! control loop, [`sonolube::commission`]), then asks `commission status` every
//! [`POLL_MS`] ms until the reply is no longer `commission=running`, and prints each reply.

use std::io::Write;

use super::{Link, LinkError};

/// Time between two `commission status` requests, ms (the sequence takes about 150 ms of
/// firmware time at 40 kHz and Q = 100).
pub const POLL_MS: u64 = 20;

/// Longest wait for the sequence, polls: its five steps may take one second each in firmware
/// time, and QEMU runs slower than real time; 3000 polls of 20 ms is one minute of wall time.
pub const MAX_POLLS: u32 = 3_000;

/// How a commissioning ended.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CommissionOutcome {
    /// `commission=done` and its values.
    Done(String),
    /// The firmware refused the command, or the sequence refused its result (the reply).
    Refused(String),
    /// Still running after [`MAX_POLLS`] polls.
    TimedOut,
}

/// Runs `commission` on `link` and waits for it, printing each exchange to `out`.
pub fn run_commission(
    link: &mut Link,
    out: &mut dyn Write,
) -> Result<CommissionOutcome, LinkError> {
    let _ = writeln!(out, "> commission");
    let started = link.command("commission")?;
    let _ = writeln!(out, "< {}", started.text);
    if !started.text.starts_with("ok commission=started") {
        return Ok(CommissionOutcome::Refused(started.text));
    }
    for _ in 0..MAX_POLLS {
        link.wait_ms(POLL_MS)?;
        let status = link.command("commission status")?;
        let text = status.text;
        if text.contains("commission=running") {
            continue;
        }
        let _ = writeln!(out, "> commission status\n< {text}");
        return Ok(if text.starts_with("ok commission=done") {
            CommissionOutcome::Done(text)
        } else {
            CommissionOutcome::Refused(text)
        });
    }
    Ok(CommissionOutcome::TimedOut)
}
