//! What the loop reads and drives at one step, in the protocol's integer units: the fields the
//! `status` reply ([`super::StatusReport`]), every telemetry record
//! ([`super::TelemetryRecord`]) and the firmware's loop snapshot share, defined once.

use super::state::SupervisorState;
use super::target::Target;

/// The loop at one step: state, target, the friction estimate and the drive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoopReading {
    /// Supervisor state.
    pub state: SupervisorState,
    /// Friction target, if set.
    pub target: Option<Target>,
    /// Friction coefficient estimate in ppm (1e-6), full `u32` range.
    pub friction_coef_ppm: u32,
    /// Normal force in mN, full `i32` range (±2147483.647 N).
    pub normal_force_mn: i32,
    /// Tangential (friction) force in mN, full `i32` range.
    pub tangential_force_mn: i32,
    /// Drive amplitude in ppm of full scale (1_000_000 = full scale).
    pub drive_amplitude_ppm: u32,
    /// Drive frequency in cHz (0.01 Hz).
    pub drive_freq_chz: u32,
}

impl LoopReading {
    /// Before the loop's first step: booting, no target, everything zero.
    pub const BOOT: Self = Self {
        state: SupervisorState::Boot,
        target: None,
        friction_coef_ppm: 0,
        normal_force_mn: 0,
        tangential_force_mn: 0,
        drive_amplitude_ppm: 0,
        drive_freq_chz: 0,
    };
}
