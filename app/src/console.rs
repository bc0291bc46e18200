//! The console task: the command protocol ([`sonolube::protocol`]) over a UART, and the
//! telemetry lines.
//!
//! Every non-empty received line gets exactly one reply line, in order. Lines that do not
//! parse, or that are too long or not printable ASCII, get an `err` reply and change nothing.
//! Commands that only read (`version`, `help`, `scene list`, `status`, `faults`) and the
//! telemetry rate are answered here; the loop's commands go to the control task, which applies
//! or refuses them between two steps ([`crate::link`]). The console never blocks the control
//! loop: it runs at a lower priority, and a slow UART only fills the telemetry queue, whose
//! overflow is counted in [`link::LOST`].
//!
//! A loop command whose work does not fit in a control step (a `scene NAME` load: building
//! the loop, its feasibility check, the selection line) is prepared here first, by the board's
//! [`Prepare`], at the console's priority where the control task preempts it; the control task
//! then only takes the prepared result at a step boundary.

use embassy_futures::select::{Either, select};
use embassy_futures::yield_now;
use embedded_io_async::{Read, Write};
use heapless::String;
use sonolube::protocol::{
    Command, FaultReport, LineAssembler, PROTOCOL_VERSION, ProtocolError, REPLY_CAPACITY,
    TELEMETRY_CAPACITY, VersionReport, format_ack, format_error, format_faults, format_help,
    format_scene_list, format_status, format_telemetry, format_version, parse_command,
};

use crate::link::{self, LOST, OVERRUNS, REQUESTS, RESPONSES, TELEMETRY, TELEMETRY_HZ};

/// Holds every reply and every telemetry line.
const LINE_CAPACITY: usize = if REPLY_CAPACITY > TELEMETRY_CAPACITY {
    REPLY_CAPACITY
} else {
    TELEMETRY_CAPACITY
};

/// What the `version` and `scene list` replies tell.
#[derive(Debug, Clone, Copy)]
pub struct Identity {
    /// Firmware version (a protocol word).
    pub firmware: &'static str,
    /// Board name (a protocol word).
    pub board: &'static str,
    /// Names of the scenes `scene NAME` accepts.
    pub scenes: &'static [&'static str],
}

/// The board's share of a loop command that is prepared out of the control step.
///
/// For every loop command the console calls [`Prepare::prepare`] before it queues the command
/// for the control task, and [`Prepare::answered`] with the control task's answer. What
/// `prepare` does runs in the console's task: the control task preempts it, so it costs no
/// control step. The control task's [`crate::control::ControlLoop::execute`] then takes what
/// was prepared, which must be cheap (a swap of references, not a copy of the loop).
pub trait Prepare {
    /// Prepares `command`; an error is the command's reply, and the command does not go to
    /// the control task. By default nothing is prepared.
    fn prepare(&mut self, command: &Command) -> Result<(), ProtocolError> {
        let _ = command;
        Ok(())
    }

    /// The control task's answer to `command`, which [`Prepare::prepare`] accepted: what was
    /// prepared and not taken is reclaimed here, and what is reported after a change (the
    /// selection line of a new scene) is logged here, out of the control step.
    fn answered(&mut self, command: &Command, result: &Result<(), ProtocolError>) {
        let _ = (command, result);
    }
}

/// A board that prepares nothing: every loop command is the control task's alone.
#[derive(Debug, Clone, Copy, Default)]
pub struct NothingToPrepare;

impl Prepare for NothingToPrepare {}

/// Serves the console on `rx` / `tx` forever, from the moment [`link::BOOTED`] is signalled.
/// A read error (framing, overrun) discards the
/// partial line, whose remainder then gets its own `err` reply if it is not a command.
pub async fn serve<R: Read, W: Write>(rx: R, tx: W, identity: &Identity) -> ! {
    serve_preparing(rx, tx, identity, &mut NothingToPrepare).await
}

/// [`serve`], with the board's `prepare` doing the work of loop commands that does not fit in a
/// control step ([`Prepare`]).
pub async fn serve_preparing<R: Read, W: Write>(
    mut rx: R,
    mut tx: W,
    identity: &Identity,
    prepare: &mut impl Prepare,
) -> ! {
    link::BOOTED.wait().await;
    let mut assembler = LineAssembler::new();
    let mut received = [0u8; 64];
    let mut out: String<LINE_CAPACITY> = String::new();
    loop {
        // Let the other thread-mode tasks (the watchdog keeper among them) run first: while
        // input keeps arriving and the UART keeps taking bytes, no await below is ever pending,
        // and the executor would poll this task alone.
        yield_now().await;
        let count = match select(rx.read(&mut received), TELEMETRY.receive()).await {
            Either::First(Ok(count)) => count,
            Either::First(Err(_)) => {
                assembler.reset();
                continue;
            }
            Either::Second(record) => {
                // A buffer of TELEMETRY_CAPACITY bytes holds every record.
                if format_telemetry(&record, out.as_mut_view()).is_ok() {
                    write_line(&mut tx, &out).await;
                }
                continue;
            }
        };
        let mut rest = &received[..count];
        while !rest.is_empty() {
            let (used, line) = assembler.push_bytes(rest);
            rest = rest.get(used..).unwrap_or(&[]);
            let Some(line) = line else { continue };
            let replied = match line.and_then(parse_command) {
                Ok(command) => execute(&command, identity, prepare, &mut out).await,
                Err(ProtocolError::EmptyLine) => false,
                Err(error) => format_error(&error, out.as_mut_view()).is_ok(),
            };
            if replied {
                write_line(&mut tx, &out).await;
            }
        }
    }
}

/// Writes one line; a UART write error loses it (nothing else can be done with it).
async fn write_line<W: Write>(tx: &mut W, line: &str) {
    if tx.write_all(line.as_bytes()).await.is_err() {
        defmt::warn!("console: a line could not be written");
    }
}

/// Executes `command` and writes its reply into `out`; false when no reply could be made (a
/// reply that does not fit, which the protocol's sizes rule out).
async fn execute(
    command: &Command,
    identity: &Identity,
    prepare: &mut impl Prepare,
    out: &mut String<LINE_CAPACITY>,
) -> bool {
    let view = out.as_mut_view();
    let written = match *command {
        Command::Version => format_version(
            &VersionReport {
                firmware: identity.firmware,
                board: identity.board,
                protocol: PROTOCOL_VERSION,
            },
            view,
        ),
        Command::Help => format_help(view),
        Command::SceneList => format_scene_list(identity.scenes, view),
        Command::Status => {
            let report = link::snapshot().status(link::count(&OVERRUNS), link::count(&LOST));
            format_status(&report, view)
        }
        Command::Faults => {
            let snapshot = link::snapshot();
            let latched = snapshot.latched_fault.as_slice();
            let mut active: heapless::Vec<&'static str, 2> = heapless::Vec::new();
            for name in [snapshot.latched_fault, snapshot.active_fault]
                .into_iter()
                .flatten()
            {
                if !active.contains(&name) {
                    let _ = active.push(name);
                }
            }
            format_faults(
                &FaultReport {
                    latched,
                    active: &active,
                },
                view,
            )
        }
        Command::Telemetry { rate_hz } => {
            TELEMETRY_HZ.store(u32::from(rate_hz), core::sync::atomic::Ordering::Relaxed);
            format_ack(command, view)
        }
        Command::TelemetryOff => {
            TELEMETRY_HZ.store(0, core::sync::atomic::Ordering::Relaxed);
            format_ack(command, view)
        }
        _ => {
            if let Err(error) = prepare.prepare(command) {
                return format_error(&error, view).is_ok();
            }
            REQUESTS.send(*command).await;
            let result = RESPONSES.receive().await;
            prepare.answered(command, &result);
            match result {
                Ok(()) if crate::persist::has_reply(command) => {
                    crate::persist::take_reply(out);
                    return !out.is_empty();
                }
                Ok(()) => match command {
                    Command::Target(target) => {
                        let warning = link::TARGET_WARNING.lock(core::cell::Cell::get);
                        sonolube::protocol::format_target_ack(target, warning.as_ref(), view)
                    }
                    _ => format_ack(command, view),
                },
                Err(error) => format_error(&error, view),
            }
        }
    };
    written.is_ok()
}
