//! The QEMU board's drive output.
//!
//! On the real board the drive is a PWM power stage; here it is the amplitude command that the
//! simulated plant reads. Until the plant is wired in, the output is a pair of atomics that the
//! firmware writes and the safe-state hook clears: the hook and its call on panic, fault and exit
//! are real, and the plant will read the same atomics.

use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

/// Drive amplitude command as a fraction of full scale, in Q0.32 (0 = off).
static AMPLITUDE: AtomicU32 = AtomicU32::new(0);
/// Whether the output stage is enabled.
static ENABLED: AtomicBool = AtomicBool::new(false);

/// State of the drive output, for logs.
#[derive(Clone, Copy, PartialEq, Eq, defmt::Format)]
pub struct DriveState {
    /// Output stage enabled.
    pub enabled: bool,
    /// Amplitude command, Q0.32 of full scale.
    pub amplitude_q32: u32,
}

/// Puts the drive output in its safe state: stage disabled, amplitude zero. Callable from any
/// context (panic, exception, task) and idempotent.
pub fn force_safe() {
    ENABLED.store(false, Ordering::SeqCst);
    AMPLITUDE.store(0, Ordering::SeqCst);
}

/// Enables the output stage with an amplitude command in Q0.32 of full scale.
pub fn set(amplitude_q32: u32) {
    AMPLITUDE.store(amplitude_q32, Ordering::SeqCst);
    ENABLED.store(amplitude_q32 != 0, Ordering::SeqCst);
}

/// Current state of the drive output.
pub fn state() -> DriveState {
    DriveState {
        enabled: ENABLED.load(Ordering::SeqCst),
        amplitude_q32: AMPLITUDE.load(Ordering::SeqCst),
    }
}
