//! Command scripts: one command per line, `#` comment lines, and the `wait MS` pseudo-command,
//! run over a [`Link`] with each reply written out as it comes.
//!
//! ```text
//! # hold mu = 0.15 for 50 ms of firmware time, then stop
//! scene reference
//! target coef 0.15
//! telemetry 1000
//! start
//! wait 50
//! stop
//! ```
//!
//! `wait MS` waits `MS` milliseconds of firmware time (telemetry `t_us`) while telemetry is on,
//! and of wall time while it is off (see [`Link::wait_ms`]); it is never sent to the firmware.
//! Every other non-blank line is sent as it is, so a script can also send malformed lines on
//! purpose. Blank lines and lines whose first non-blank character is `#` are skipped (a `#`
//! later in a line is part of the command).

use std::io::Write;

use sonolube::protocol::{LineAssembler, Reply};

use super::link::{Link, LinkError, WaitClock};

/// Longest `wait`, ms (one hour).
pub const MAX_WAIT_MS: u64 = 3_600_000;

/// One step of a script.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Step {
    /// A line to send; it gets exactly one reply.
    Command(String),
    /// `wait MS`: a pause in firmware time (telemetry on) or wall time (telemetry off), ms.
    Wait(u64),
}

/// Reads one script line or `-c` argument: `None` for a blank or comment line.
pub fn parse_step(text: &str) -> Result<Option<Step>, String> {
    let text = text.strip_suffix('\r').unwrap_or(text);
    if text.contains('\n') {
        return Err(format!("{text:?}: a command cannot hold a newline"));
    }
    let trimmed = text.trim_matches([' ', '\t']);
    if trimmed.is_empty() || trimmed.starts_with('#') {
        return Ok(None);
    }
    let mut words = trimmed.split([' ', '\t']).filter(|w| !w.is_empty());
    if words.next() == Some("wait") {
        let ms = words
            .next()
            .ok_or_else(|| "wait needs a time in ms (wait MS)".to_string())?;
        if let Some(extra) = words.next() {
            return Err(format!("wait takes one number, not {extra:?}"));
        }
        let ms = ms
            .parse::<u64>()
            .ok()
            .filter(|&ms| ms <= MAX_WAIT_MS)
            .ok_or_else(|| format!("wait {ms}: not a whole number of ms, 0..={MAX_WAIT_MS}"))?;
        return Ok(Some(Step::Wait(ms)));
    }
    // Whatever the firmware's line assembler would not answer (only `\r`s and blanks) has been
    // skipped above; check with the real assembler so that every command sent gets a reply.
    let mut assembler = LineAssembler::new();
    assembler.push_all(text.as_bytes(), |_| {});
    if assembler.push(b'\n').is_none() {
        return Err(format!("{text:?} would get no reply (a blank line)"));
    }
    Ok(Some(Step::Command(text.to_string())))
}

/// Reads a script file's text; errors name the line.
pub fn parse_script(text: &str) -> Result<Vec<Step>, String> {
    let mut steps = Vec::new();
    for (number, line) in text.split('\n').enumerate() {
        match parse_step(line) {
            Ok(Some(step)) => steps.push(step),
            Ok(None) => {}
            Err(why) => return Err(format!("line {}: {why}", number + 1)),
        }
    }
    Ok(steps)
}

/// What running the steps gave.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StepsOutcome {
    /// Commands sent and answered.
    pub commands: usize,
    /// Replies that were `err`.
    pub errors: usize,
    /// Replies that did not decode.
    pub malformed: usize,
}

/// Runs `steps` in order, writing `> command`, `< reply` and `# waited ...` lines to `out`.
/// Stops at the first link failure (a timeout or a closed connection).
pub fn run_steps(
    link: &mut Link,
    steps: &[Step],
    out: &mut dyn Write,
) -> Result<StepsOutcome, LinkError> {
    let mut outcome = StepsOutcome::default();
    for step in steps {
        match step {
            Step::Command(line) => {
                let _ = writeln!(out, "> {line}");
                let reply = link.command(line)?;
                outcome.commands += 1;
                match reply.decode() {
                    Ok(Reply::Ok(_)) => {
                        let _ = writeln!(out, "< {}", reply.text);
                    }
                    Ok(Reply::Err(_)) => {
                        outcome.errors += 1;
                        let _ = writeln!(out, "< {}", reply.text);
                    }
                    Err(error) => {
                        outcome.malformed += 1;
                        let _ = writeln!(out, "< {}   (malformed reply: {error:?})", reply.text);
                    }
                }
            }
            Step::Wait(ms) => match link.wait_ms(*ms)? {
                WaitClock::Firmware { from_us, to_us } => {
                    let _ = writeln!(
                        out,
                        "# waited {ms} ms of firmware time (t_us {from_us} to {to_us})"
                    );
                }
                WaitClock::Wall => {
                    let _ = writeln!(out, "# waited {ms} ms of wall time (telemetry off)");
                }
            },
        }
    }
    Ok(outcome)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scripts_parse() {
        let text = "# a comment\n\nscene reference\r\n  target coef 0.15\nwait 20\n\
                    \t# indented comment\nstart # not a comment\nwait\t0\n";
        assert_eq!(
            parse_script(text).unwrap(),
            [
                Step::Command("scene reference".into()),
                Step::Command("  target coef 0.15".into()),
                Step::Wait(20),
                Step::Command("start # not a comment".into()),
                Step::Wait(0),
            ]
        );
    }

    #[test]
    fn bad_waits_name_their_line() {
        for (text, line) in [
            ("status\nwait\n", "line 2"),
            ("wait x\n", "line 1"),
            ("wait -1\n", "line 1"),
            ("wait 1 2\n", "line 1"),
            ("a\nb\nwait 3600001\n", "line 3"),
        ] {
            let error = parse_script(text).unwrap_err();
            assert!(error.starts_with(line), "{text:?}: {error}");
        }
    }

    #[test]
    fn commands_that_get_no_reply_are_refused() {
        assert_eq!(parse_step("   ").unwrap(), None);
        assert!(parse_step("\r\r").is_err());
        assert!(parse_step("a\nb").is_err());
        // Malformed commands are sent as they are: the firmware answers them with err.
        assert_eq!(
            parse_step("target coef 9").unwrap(),
            Some(Step::Command("target coef 9".into()))
        );
        assert_eq!(
            parse_step("st\u{e9}p").unwrap(),
            Some(Step::Command("st\u{e9}p".into()))
        );
    }
}
