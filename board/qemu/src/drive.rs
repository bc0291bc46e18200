//! The QEMU board's drive output: what the simulated plant reads as its drive.
//!
//! On the real board the drive is a PWM power stage; here it is an amplitude command in two
//! atomics that the control task writes, the safe-state hook clears, and the simulated plant
//! reads at the start of every period ([`crate::rig`]). So a drive forced safe by a panic, a
//! watchdog NMI or a fault is exactly what the plant sees next.

use core::sync::atomic::{AtomicBool, AtomicI32, Ordering};

use sonolube::fx::Q1_31;

/// Drive amplitude command, Q1.31 fraction of full scale in [0, 1) (0 = off).
static AMPLITUDE: AtomicI32 = AtomicI32::new(0);
/// Whether the output stage is enabled.
static ENABLED: AtomicBool = AtomicBool::new(false);

/// State of the drive output, for logs.
#[derive(Clone, Copy, PartialEq, Eq, defmt::Format)]
pub struct DriveState {
    /// Output stage enabled.
    pub enabled: bool,
    /// Amplitude command, Q1.31 of full scale.
    pub amplitude_q31: i32,
}

/// Puts the drive output in its safe state: stage disabled, amplitude zero. Callable from any
/// context (panic, exception, task) and idempotent.
pub fn force_safe() {
    ENABLED.store(false, Ordering::SeqCst);
    AMPLITUDE.store(0, Ordering::SeqCst);
}

/// Sets the amplitude command (Q1.31, negative values count as zero); the stage is enabled
/// while it is above zero.
pub fn set(amplitude: Q1_31) {
    let bits = amplitude.to_bits().max(0);
    AMPLITUDE.store(bits, Ordering::SeqCst);
    ENABLED.store(bits != 0, Ordering::SeqCst);
}

/// Current state of the drive output.
pub fn state() -> DriveState {
    DriveState {
        enabled: ENABLED.load(Ordering::SeqCst),
        amplitude_q31: AMPLITUDE.load(Ordering::SeqCst),
    }
}

/// The drive the plant sees: the amplitude as a fraction of full scale, zero while the stage
/// is disabled.
pub fn plant_input() -> f32 {
    if ENABLED.load(Ordering::SeqCst) {
        Q1_31::from_bits(AMPLITUDE.load(Ordering::SeqCst)).to_f32()
    } else {
        0.0
    }
}
