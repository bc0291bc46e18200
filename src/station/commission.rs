//! The station's side of `commission` ([`crate::commission`]): starting the sequence, giving it
//! each period's current samples and readings, driving what it asks, and applying its result
//! to the controller. Kept apart from `station.rs` so that the loop's other commands read as
//! before.

use super::Station;
use crate::commission::{
    CellZero, CommissionResult, Commissioning, PeriodInputs, Phase, Refusal, Step,
};
use crate::control::{Config, Output};
use crate::drive::{Amplitude, Frequency};
use crate::fx::{Q1_31, Q16_16};
use crate::protocol::{Command, ProtocolError, SupervisorState};
use crate::sense::Calibration;

/// The state of the last `commission`.
#[derive(Debug, Clone, PartialEq)]
#[allow(clippy::large_enum_variant)] // one per station, never moved in the control step
pub(super) enum CommissionState {
    /// None was given since the station was built.
    Never,
    /// Running.
    Running(Commissioning),
    /// Finished: the result, or why there is none.
    Finished(Result<CommissionResult, Refusal>),
}

/// What the station reports of commissioning (`status`, the `commission` reply).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CommissionReport {
    /// No `commission` since the station was built.
    Never,
    /// Running, in this step.
    Running(Step),
    /// Accepted and applied.
    Done(CommissionResult),
    /// Refused.
    Refused(Refusal),
}

/// A cell's zero in newtons relative to mid-scale (the front ends' zero-force reading,
/// [`crate::sense`]): what the unloaded cell reads through the datasheet calibration.
fn cell_zero(calibration: Calibration) -> CellZero {
    let offset = calibration.offset().to_f64() - 0.5;
    CellZero {
        zero_n: offset * calibration.span().to_f64(),
        noise_rms_n: None,
    }
}

impl Station {
    /// `commission`: refused unless the drive is off and the board samples its drive current
    /// on a stack the resonance loop can model; accepted, the search starts.
    pub(super) fn start_commission(&mut self, command: &Command) -> Result<(), ProtocolError> {
        self.require_drive_off(command)?;
        if matches!(self.commission, CommissionState::Running(_)) {
            return Err(ProtocolError::WrongState {
                command: command.keyword(),
                state: SupervisorState::Tuning,
            });
        }
        if !self.current_sense {
            return Err(ProtocolError::Unavailable {
                command: command.keyword(),
                reason: "this board does not sample the drive current",
            });
        }
        let resonance = self.resonance.as_mut().ok_or(ProtocolError::Unavailable {
            command: command.keyword(),
            reason: self.resonance_refused,
        })?;
        resonance.search().map_err(|_| ProtocolError::Unavailable {
            command: command.keyword(),
            reason: "the timer cannot make the search's frequencies",
        })?;
        // Half the ceiling the ratings allow at the present frequency: the burst rings the
        // stack well above the sense's noise and within its current rating.
        let ceiling = self.controller.config().limit().max_amplitude;
        let burst = Q1_31::from_bits(ceiling.to_bits() / 2);
        let (normal, tangential) = self.calibrations();
        self.auto_armed = false;
        self.commission = CommissionState::Running(Commissioning::new(
            self.settings.period_s,
            burst,
            cell_zero(normal),
            cell_zero(tangential),
        ));
        Ok(())
    }

    /// Whether commissioning is running (the station reports `tuning`).
    pub(super) fn commissioning(&self) -> bool {
        matches!(self.commission, CommissionState::Running(_))
    }

    /// `stop` during commissioning: it ends, refused, drive off, the resonance loop pinned.
    pub(super) fn cancel_commission(&mut self) {
        if let CommissionState::Running(sequence) = &self.commission {
            let step = sequence.step();
            self.commission =
                CommissionState::Finished(Err(Refusal::new(step, "stopped", f64::NAN)));
            self.pin_here();
        }
    }

    /// The period's current samples to the sequence.
    pub(super) fn commission_current(&mut self, codes: &[u16]) {
        if let CommissionState::Running(sequence) = &mut self.commission {
            sequence.push_current(codes);
        }
    }

    /// One period of the sequence: replaces the controller's output amplitude with the drive
    /// the sequence asks for (the controller is told, as for the search), and applies the
    /// result when it ends.
    pub(super) fn commission_period(
        &mut self,
        output: &mut Output,
        normal_force: Q16_16,
        tangential_force: Q16_16,
        sliding_velocity_m_per_s: f32,
    ) {
        let CommissionState::Running(sequence) = &mut self.commission else {
            return;
        };
        let Some(resonance) = self.resonance.as_mut() else {
            return;
        };
        let inputs = PeriodInputs {
            resonance: resonance.report(),
            normal_force,
            tangential_force,
            sliding_velocity_m_per_s,
            sliding_on_m_s: self.settings.sliding_on_m_s,
            min_normal_force_n: self.settings.min_normal_force_n,
            fault: output.fault.is_some(),
        };
        let amplitude = match sequence.control(&inputs) {
            Phase::Search => resonance.search_amplitude().command(),
            Phase::Drive(amplitude) => amplitude,
            Phase::DriveOffPinned => {
                let here = resonance.tuning().frequency;
                let _ = resonance.pin(here);
                Q1_31::ZERO
            }
            Phase::Off => Q1_31::ZERO,
            Phase::Done(result) => {
                let result = result.and_then(|r| self.apply_commission(&r).map(|()| r));
                if result.is_err() {
                    self.pin_here();
                }
                self.commission = CommissionState::Finished(result);
                Q1_31::ZERO
            }
        };
        if output.fault.is_none() {
            output.amplitude = amplitude;
            self.controller.drive_replaced(amplitude);
        }
        self.applied = Amplitude::from_command(output.amplitude);
    }

    /// The loop on the measured values: the controller's envelope time constant (and the lead,
    /// which cannot make it slower) and its current ceiling at the measured f0, the drive pinned
    /// at f0. All or nothing.
    fn apply_commission(&mut self, result: &CommissionResult) -> Result<(), Refusal> {
        let refused = |reason| Refusal::new(Step::Natural, reason, f64::NAN);
        let mut settings = self.settings;
        let tau = result.time_constant_s.value;
        let f0 = result.resonance_hz.value;
        settings.envelope_time_constant_s = tau;
        settings.response_time_constant_s = libm::fmin(settings.response_time_constant_s, tau);
        settings.actuator.drive_frequency_hz = f0;
        let config =
            Config::new(&settings).map_err(|_| refused("controller refused the values"))?;
        let millihertz = libm::round(f0 * 1e3) as u32;
        let mut resonance = self.resonance.clone();
        if let Some(resonance) = resonance.as_mut() {
            resonance
                .pin(Frequency::from_millihertz(millihertz))
                .map_err(|_| refused("the timer cannot make f0"))?;
        }
        self.resonance = resonance;
        self.controller.reconfigure(config);
        self.settings = settings;
        let chz = millihertz / 10 + u32::from(millihertz % 10 >= 5);
        self.drive_freq_chz = chz;
        self.drive_hz = millihertz as f32 / 1000.0;
        Ok(())
    }

    /// The last `commission`: running (its step), done (the values the loop now runs on) or
    /// refused (why).
    pub fn commission_report(&self) -> CommissionReport {
        match &self.commission {
            CommissionState::Never => CommissionReport::Never,
            CommissionState::Running(sequence) => CommissionReport::Running(sequence.step()),
            CommissionState::Finished(Ok(result)) => CommissionReport::Done(*result),
            CommissionState::Finished(Err(refusal)) => CommissionReport::Refused(*refusal),
        }
    }
}
