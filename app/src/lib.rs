//! The Sonolube firmware application, shared by every board.
//!
//! Written against the [`Board`] trait, never against a chip: a board crate provides the trait,
//! the time driver and the executor, and wraps these async functions in its
//! `#[embassy_executor::task]`s (embassy tasks cannot be generic).
#![no_std]
#![deny(missing_docs)]

pub mod heartbeat;

/// What the application needs from a board.
pub trait Board {
    /// Name of the board, for logs.
    const NAME: &'static str;
    /// Puts the drive output in its safe state (stage off, amplitude zero). Must work from any
    /// context, including a panic handler, and be idempotent.
    fn drive_safe();
    /// Ends a run whose outcome is known: `passed` tells whether every self-check passed. A
    /// simulated board exits with a status code; a real board makes the drive safe and parks.
    fn finish(passed: bool) -> !;
}
