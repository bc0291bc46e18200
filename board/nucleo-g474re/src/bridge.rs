//! The half-bridge as the control loop's actuator: the controller's amplitude command written
//! to TIM1 ([`crate::drive`]), and the bridge switched on only while the controller drives.
//!
//! Each step [`Bridge::apply`] either drives (state `ramp-up`, `running` or `ramp-down`, no
//! latched fault: duty for the amplitude, MOE set) or makes the drive safe (MOE cleared, duty
//! zero) in every other state, so a controller fault (a sensor fault, an overrun, a model
//! error) stops the bridge in the step it is latched. The bridge refuses to switch on, and
//! reports it, while the overcurrent break is active or unacknowledged or the current sense is
//! faulty; it reports it too when MOE has dropped under it (the comparator's break, or the
//! sensing task's reaction to a faulty current sense). The control loop then latches the
//! controller's `overcurrent` fault; `clear` acknowledges the break ([`Bridge::acknowledge`]).
//!
//! # Amplitude scale (an assumption)
//!
//! The controller's amplitude is a fraction of the *scene's* full-scale stack voltage
//! (`actuator.full_scale_voltage_v`: 5.25 V in `reference`); the board's [`Amplitude`] is a
//! fraction of the half-bridge's full-scale fundamental ([`config::FULL_SCALE_V`], 15.28 V on a
//! 24 V bus, assuming the output network passes the fundamental unchanged: bring-up step 9
//! measures it). The command is scaled by their ratio, so a command means the same volts on
//! the stack as in the scene, and capped by the stack's ratings at the drive frequency
//! ([`config::STACK`]) as a second line behind the controller's own ceiling. A scene whose full
//! scale exceeds the bridge's cannot run on this board.
//!
//! In the `bringup` build the hold-to-run button owns the bridge: this module never writes
//! TIM1 there (the control loop refuses `start`, `freq` and `scene`, see [`crate::rig`]).

use sonolube::control::Output;
use sonolube::drive::{Amplitude, DriveError, DriveLimits, DriveTiming, Frequency};
use sonolube::protocol::SupervisorState;

pub use crate::drive_fit::DriveRefusal;
use crate::drive_fit::drive_fit;
use crate::{drive, safe};

/// Whether the control loop drives the bridge: not in the bring-up build.
pub const CONTROLS_BRIDGE: bool = cfg!(not(feature = "bringup"));

/// Why the bridge is not switching although the controller drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub enum Stopped {
    /// The overcurrent comparator's break fired (or its flag is not acknowledged).
    Break,
    /// The current sense is saturated or disconnected.
    CurrentSense,
    /// MOE dropped with neither of the above (the sensing task cleared it on a faulty current
    /// sample that has since recovered).
    OutputsDropped,
}

/// The bridge settings of one scene and whether the control loop has switched it on.
pub struct Bridge {
    timing: DriveTiming,
    /// The stack ratings on this bridge (integer ceilings per frequency).
    limits: DriveLimits,
    /// Bridge amplitude per controller amplitude, Q2.30 in (0, 1].
    scale_q30: i64,
    /// The stack ratings' ceiling at the drive frequency.
    ceiling: Amplitude,
    /// The amplitude last written.
    amplitude: Amplitude,
    /// Whether this loop set MOE and has not cleared it since.
    on: bool,
}

impl Bridge {
    /// The bridge for a scene whose drive runs at `drive_hz` with `full_scale_voltage_v` on the
    /// stack at full command. Configuration (`f64`), once per scene; writes nothing.
    pub fn for_scene(drive_hz: f64, full_scale_voltage_v: f64) -> Result<Self, DriveRefusal> {
        let fit = drive_fit(drive_hz, full_scale_voltage_v)?;
        Ok(Self {
            timing: fit.timing,
            limits: fit.limits,
            // ratio in (0, 1]: at most 2^30.
            scale_q30: (fit.ratio * (1u64 << 30) as f64 + 0.5) as i64,
            ceiling: fit.limits.max_amplitude(fit.frequency),
            amplitude: Amplitude::ZERO,
            on: false,
        })
    }

    /// Writes this scene's period and ADC trigger to TIM1, with zero amplitude. Call with the
    /// bridge off (a scene is selected only with the drive off).
    pub fn install(&mut self) {
        if CONTROLS_BRIDGE {
            self.amplitude = Amplitude::ZERO;
            drive::write_timing(&self.timing, Amplitude::ZERO);
        }
    }

    /// The timing in force.
    pub fn timing(&self) -> &DriveTiming {
        &self.timing
    }

    /// The timing for a new drive frequency (`freq` command), checked but not yet written.
    pub fn timing_at(&self, frequency: Frequency) -> Result<DriveTiming, DriveError> {
        self.timing.retune(frequency)
    }

    /// Switches to `timing` (from [`Self::timing_at`]): a running bridge changes period at the
    /// next PWM period boundary, glitch-free (preloaded registers), with the same amplitude.
    pub fn retune(&mut self, timing: DriveTiming) {
        self.timing = timing;
        self.ceiling = self.limits.max_amplitude(timing.frequency());
        self.amplitude = self.amplitude.min(self.ceiling);
        if CONTROLS_BRIDGE {
            drive::write_timing(&self.timing, self.amplitude);
        }
    }

    /// Applies one controller output: drive at its amplitude in the driving states, and while
    /// the resonance search runs and the station commands its amplitude (`searching`: a `start`
    /// after `freq auto` searches before the friction loop starts); safe in every other case. Err when the bridge should switch but does not (see [`Stopped`]); the
    /// bridge is then safe.
    pub fn apply(&mut self, output: &Output, searching: bool) -> Result<(), Stopped> {
        if !CONTROLS_BRIDGE {
            return Ok(());
        }
        // A search the station does not drive (stopped meanwhile) leaves the bridge off.
        let search_drives = searching && output.amplitude > Amplitude::ZERO;
        let drives = (search_drives
            || matches!(
                output.state,
                SupervisorState::RampUp | SupervisorState::Running | SupervisorState::RampDown
            ))
            && output.fault.is_none();
        if !drives {
            self.off();
            return Ok(());
        }
        self.amplitude = self.bridge_amplitude(output.amplitude);
        drive::set_amplitude(&self.timing, self.amplitude);
        // The break flag first: a short overcurrent pulse may have cleared MOE and gone again
        // before this step; its sticky flag still tells.
        let stopped = if drive::break_tripped() {
            Some(Stopped::Break)
        } else if self.on {
            if drive::outputs_enabled() {
                None
            } else if !drive::current_sense_healthy() {
                Some(Stopped::CurrentSense)
            } else {
                Some(Stopped::OutputsDropped)
            }
        } else if !drive::current_sense_healthy() {
            Some(Stopped::CurrentSense)
        } else if drive::try_enable_outputs() {
            None
        } else {
            // MOE did not stick: the break input went active in between.
            Some(Stopped::Break)
        };
        match stopped {
            None => {
                self.on = true;
                Ok(())
            }
            Some(cause) => {
                self.off();
                Err(cause)
            }
        }
    }

    /// Makes the drive safe now: MOE cleared, duty zero.
    pub fn off(&mut self) {
        if !CONTROLS_BRIDGE {
            return;
        }
        safe::drive_safe();
        self.on = false;
        if self.amplitude != Amplitude::ZERO {
            self.amplitude = Amplitude::ZERO;
            drive::set_amplitude(&self.timing, Amplitude::ZERO);
        }
    }

    /// Acknowledges a break after the controller's fault was cleared: the next switch-on is
    /// allowed if the comparator no longer trips (a standing overcurrent sets the flag again).
    pub fn acknowledge(&mut self) {
        if CONTROLS_BRIDGE && !self.on {
            drive::clear_break_flag();
        }
    }

    /// The controller's `amplitude` (of the scene's full scale) as the bridge's, capped.
    fn bridge_amplitude(&self, amplitude: Amplitude) -> Amplitude {
        // Unsigned Q1.31 x Q2.30 >> 30 = unsigned Q1.31; at most 2^31 (both factors at most
        // 1), so `from_bits` cannot refuse it (a refusal would be no drive, never a wrap).
        let bits = (i64::from(amplitude.bits()) * self.scale_q30 + (1 << 29)) >> 30;
        u32::try_from(bits)
            .ok()
            .and_then(|bits| Amplitude::from_bits(bits).ok())
            .unwrap_or(Amplitude::ZERO)
            .min(self.ceiling)
    }
}
