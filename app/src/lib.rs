//! The Sonolube firmware application, shared by every board.
//!
//! Written against small traits, never against a chip: a board crate provides [`Board`], the
//! time driver, the executor, a [`control::ControlLoop`] (its sensing and drive, or a simulated
//! plant) and a UART with `embedded_io_async` read and write halves, and wraps these async
//! functions in its `#[embassy_executor::task]`s (embassy tasks cannot be generic).
//!
//! The tasks and how they talk (all through [`link`]):
//! - **control** ([`control::run`]): the loop on a `Ticker` at the scene's rate; applies queued
//!   commands between two steps, counts overruns (three in a row latch an `overrun` fault),
//!   publishes a snapshot each step and a telemetry record at the telemetry rate;
//! - **console** ([`console::serve`]): the command protocol of [`sonolube::protocol`] over the
//!   UART, one reply per line, and the telemetry lines in between;
//! - **supervisor** ([`heartbeat`] at boot, then [`supervisor::keeper`]): the boot self-check,
//!   then the watchdog, fed only while the control loop advances.
#![cfg_attr(not(test), no_std)]
#![deny(missing_docs)]

pub mod console;
pub mod control;
pub mod heartbeat;
pub mod link;
pub mod persist;
pub mod snapshot;
pub mod supervisor;

/// What the application needs from a board.
pub trait Board {
    /// Name of the board, for logs and the `version` reply (a protocol word).
    const NAME: &'static str;
    /// Puts the drive output in its safe state (stage off, amplitude zero). Must work from any
    /// context, including a panic handler, and be idempotent.
    fn drive_safe();
    /// Ends a run whose outcome is known: `passed` tells whether every self-check passed. A
    /// simulated board exits with a status code; a real board makes the drive safe and parks.
    fn finish(passed: bool) -> !;
}
