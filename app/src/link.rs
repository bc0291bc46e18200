//! What the tasks share: the command queue into the control loop and its answers, the
//! telemetry queue, the latest snapshot and the counters.
//!
//! The console sends one loop command at a time ([`REQUESTS`], depth 1) and waits for its
//! answer ([`RESPONSES`]); the control loop takes it between two steps, so a command is applied
//! whole at a step boundary or refused, never half-applied. Telemetry records are offered to
//! [`TELEMETRY`] without waiting: a full queue counts the record in [`LOST`].

use core::cell::Cell;
use core::sync::atomic::{AtomicU32, Ordering};

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_sync::signal::Signal;
use sonolube::protocol::{Command, ProtocolError, TelemetryRecord};

use crate::snapshot::Snapshot;

/// Telemetry records queued between the control loop and the console.
pub const TELEMETRY_QUEUE: usize = 16;

/// Loop commands from the console to the control loop.
pub static REQUESTS: Channel<CriticalSectionRawMutex, Command, 1> = Channel::new();
/// The control loop's answer to each request, in order.
pub static RESPONSES: Channel<CriticalSectionRawMutex, Result<(), ProtocolError>, 1> =
    Channel::new();
/// Telemetry records for the console.
pub static TELEMETRY: Channel<CriticalSectionRawMutex, TelemetryRecord, TELEMETRY_QUEUE> =
    Channel::new();
/// The loop after its latest step.
pub static SNAPSHOT: Mutex<CriticalSectionRawMutex, Cell<Snapshot>> =
    Mutex::new(Cell::new(Snapshot::BOOT));

/// Signalled by the control loop after its first step (so after the boot self-check): the
/// console answers nothing before (its bytes wait in the UART), so it cannot disturb the
/// self-check's timing, and `status` always reports a step.
pub static BOOTED: Signal<CriticalSectionRawMutex, ()> = Signal::new();

/// Control steps whose control part ended after the period's deadline, since boot
/// (saturating).
pub static OVERRUNS: AtomicU32 = AtomicU32::new(0);
/// Telemetry records lost to a full queue, since boot (saturating).
pub static LOST: AtomicU32 = AtomicU32::new(0);
/// Control steps taken since boot (wrapping): the watchdog keeper's sign of life.
pub static STEPS: AtomicU32 = AtomicU32::new(0);
/// Telemetry rate in Hz, 0 when off.
pub static TELEMETRY_HZ: AtomicU32 = AtomicU32::new(0);

/// The warning of the last accepted `target` (the value the full drive reaches now, when the
/// target is beyond it), set by the control task before it answers the command.
pub static TARGET_WARNING: Mutex<
    CriticalSectionRawMutex,
    Cell<Option<sonolube::protocol::Target>>,
> = Mutex::new(Cell::new(None));

/// The latest snapshot.
pub fn snapshot() -> Snapshot {
    SNAPSHOT.lock(Cell::get)
}

/// Adds one to a saturating counter.
pub(crate) fn bump(counter: &AtomicU32) {
    let _ = counter.fetch_update(Ordering::Relaxed, Ordering::Relaxed, |n| n.checked_add(1));
}

/// Reads a counter.
pub fn count(counter: &AtomicU32) -> u32 {
    counter.load(Ordering::Relaxed)
}
