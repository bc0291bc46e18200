//! The QEMU board's drive output: what the simulated plant reads as its drive.
//!
//! On the real board the drive is a PWM power stage; here it is an amplitude command in two
//! atomics that the control task writes, the safe-state hook clears, and the simulated plant
//! reads at the start of every period ([`crate::rig`]). So a drive forced safe by a panic, a
//! watchdog NMI or a fault is exactly what the plant sees next.

use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use sonolube::drive::Amplitude;

/// Drive amplitude command, [`Amplitude`]'s bits (unsigned Q1.31, 2^31 = full scale; 0 = off).
static AMPLITUDE: AtomicU32 = AtomicU32::new(0);
/// Whether the output stage is enabled.
static ENABLED: AtomicBool = AtomicBool::new(false);

/// State of the drive output, for logs.
#[derive(Clone, Copy, PartialEq, Eq, defmt::Format)]
pub struct DriveState {
    /// Output stage enabled.
    pub enabled: bool,
    /// Amplitude command, [`Amplitude`]'s bits (unsigned Q1.31, 2^31 = full scale).
    pub amplitude_bits: u32,
}

/// Puts the drive output in its safe state: stage disabled, amplitude zero. Callable from any
/// context (panic, exception, task) and idempotent.
pub fn force_safe() {
    ENABLED.store(false, Ordering::SeqCst);
    AMPLITUDE.store(0, Ordering::SeqCst);
}

/// Sets the amplitude command; the stage is enabled while it is above zero.
pub fn set(amplitude: Amplitude) {
    let bits = amplitude.bits();
    AMPLITUDE.store(bits, Ordering::SeqCst);
    ENABLED.store(bits != 0, Ordering::SeqCst);
}

/// Current state of the drive output.
pub fn state() -> DriveState {
    DriveState {
        enabled: ENABLED.load(Ordering::SeqCst),
        amplitude_bits: AMPLITUDE.load(Ordering::SeqCst),
    }
}

/// The drive the plant sees: the amplitude as a fraction of full scale, zero while the stage
/// is disabled.
pub fn plant_input() -> f32 {
    if ENABLED.load(Ordering::SeqCst) {
        // Only `set` stores, from an `Amplitude`: the bits are in range.
        Amplitude::from_bits(AMPLITUDE.load(Ordering::SeqCst)).map_or(0.0, Amplitude::to_f32)
    } else {
        0.0
    }
}
