//! The station's side of `commission` ([`crate::commission`]): starting the sequence, giving it
//! each period's current samples and readings, driving what it asks, and applying its result
//! to the controller. Kept apart from `station.rs` so that the loop's other commands read as
//! before.

use super::Station;
use crate::commission::{
    CellZero, CommissionResult, Commissioning, PeriodInputs, Phase, Refusal, Step, check,
};
use crate::control::{
    Config, GainSchedule, Output, Settings, ShaperConfig, drive_lead_s, gain_schedule, tuned,
};
use crate::drive::{Amplitude, Frequency};
use crate::fx::{Q1_31, Q16_16};
use crate::protocol::{Command, ProtocolError, SupervisorState};
use crate::sense::{Calibration, SensorChannel};

/// The station's commissioning: the last `commission` command, and the values the loop runs on
/// (from that command, or restored from the settings store), which outlive a later refused
/// `commission`.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct CommissionState {
    last: LastCommission,
    applied: Option<CommissionResult>,
    /// The scene's tightest overshoot criterion ([`crate::control::overshoot_criterion`]):
    /// the lead on the measured envelope is bounded by it as the declared tuning's is.
    overshoot: Option<f64>,
}

impl CommissionState {
    /// No `commission` given, the declared values, for a scene whose tightest overshoot
    /// criterion is `overshoot` (fraction of the step).
    pub(super) const fn never(overshoot: Option<f64>) -> Self {
        Self {
            last: LastCommission::Never,
            applied: None,
            overshoot,
        }
    }
}

/// The state of the last `commission`.
#[derive(Debug, Clone, PartialEq)]
#[allow(clippy::large_enum_variant)] // one per station, never moved in the control step
enum LastCommission {
    /// None was given since the station was built.
    Never,
    /// Running.
    Running(Commissioning),
    /// The sequence ended with this result, which is being put into the loop one stage per
    /// control period ([`ApplyStage`]); the drive stays off.
    Applying(CommissionResult, ApplyStage),
    /// Finished: the result, or why there is none.
    Finished(Result<CommissionResult, Refusal>),
}

/// Putting a commissioning result into the loop, one stage per control period: the tuning
/// rule on the measured values ([`commissioned_settings`]: square roots, a logarithm,
/// divisions), then the controller's gain schedule ([`gain_schedule`]), then its drive shaper
/// on the measured envelope ([`ShaperConfig::new`]), then the rest of its configuration from
/// the running one ([`Config::commissioned`]: the contact lag, the ceiling at f0, mu0's
/// prior; the force filters and the rest are unchanged), then the swap. Done in the one
/// period the sequence ended in, the three made that period the only one of a console
/// `commission` to overrun in the QEMU serve mode (a control part of 5,861 SysTick cycles,
/// 145 us past its deadline at 10 kHz; `scripts/qemu-settings-test reset`'s commissioning
/// session logs it).
#[derive(Debug, Clone, Copy, PartialEq)]
enum ApplyStage {
    /// Next: the settings on the measured values.
    Settings,
    /// Next: the gain schedule of these settings.
    Gains(Settings),
    /// Next: the drive shaper of these settings (the measured envelope and the lead).
    Shaper(Settings, GainSchedule),
    /// Next: the rest of the configuration of these settings, from the running one
    /// ([`Config::commissioned`]).
    Config(Settings, GainSchedule, ShaperConfig),
    /// Next: swap these into the controller, pin the drive at f0.
    Install(Settings, Config),
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
    /// Refused (the loop keeps the values it ran on before).
    Refused(Refusal),
    /// No `commission` since the station was built, but the loop runs on values a former one
    /// measured, restored from the settings store ([`Station::apply_commissioned`]).
    Restored(CommissionResult),
}

/// Samples a cell's `tare` averages ([`super::COMMISSIONING_SAMPLES`]), for the standard errors
/// of its zero and noise.
const TARE_SAMPLES: f64 = super::COMMISSIONING_SAMPLES as f64;

/// The standard error of a cell's zero, N: the mean of the tare's samples scatters by the
/// noise over the square root of their count (`None` without a measured noise).
pub fn zero_standard_error_n(cell: &CellZero) -> Option<f64> {
    cell.noise_rms_n
        .map(|noise| noise / libm::sqrt(TARE_SAMPLES))
}

/// The standard error of a cell's measured noise, N: an RMS over `n` Gaussian samples
/// scatters by `sigma / sqrt(2 n)` (the chi distribution's spread for large `n`).
pub fn noise_standard_error_n(cell: &CellZero) -> Option<f64> {
    cell.noise_rms_n
        .map(|noise| noise / libm::sqrt(2.0 * TARE_SAMPLES))
}

/// A cell's zero in newtons relative to mid-scale (the front ends' zero-force reading,
/// [`crate::sense`]): what the unloaded cell reads through the datasheet calibration; with the
/// noise its last `tare` measured, if it was tared.
fn cell_zero(channel: &SensorChannel) -> CellZero {
    let calibration: Calibration = channel.calibration();
    let offset = calibration.offset().to_f64() - 0.5;
    CellZero {
        zero_n: offset * calibration.span().to_f64(),
        noise_rms_n: channel.noise().map(Q16_16::to_f64),
    }
}

impl Station {
    /// `commission`: refused unless the drive is off and the board samples its drive current
    /// on a stack the resonance loop can model; accepted, the search starts.
    pub(super) fn start_commission(&mut self, command: &Command) -> Result<(), ProtocolError> {
        self.require_drive_off(command)?;
        if self.commissioning() {
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
        let resonance = self.resonance_loop(command)?;
        super::search_now(resonance, command)?;
        // Half the ceiling the ratings allow at the present frequency: the burst rings the
        // stack well above the sense's noise and within its current rating.
        let ceiling = self.controller.config().limit().max_amplitude;
        let burst = Q1_31::from_bits(ceiling.to_bits() / 2);
        self.auto_armed = false;
        self.commission.last = LastCommission::Running(Commissioning::new(
            self.settings.period_s,
            burst,
            cell_zero(&self.normal),
            cell_zero(&self.tangential),
        ));
        Ok(())
    }

    /// Whether commissioning is running (the station reports `tuning`).
    pub(super) fn commissioning(&self) -> bool {
        matches!(
            self.commission.last,
            LastCommission::Running(_) | LastCommission::Applying(..)
        )
    }

    /// `stop` during commissioning: it ends, refused, drive off, the resonance loop pinned.
    pub(super) fn cancel_commission(&mut self) {
        let step = match &self.commission.last {
            LastCommission::Running(sequence) => Some(sequence.step()),
            LastCommission::Applying(..) => Some(Step::Natural),
            _ => None,
        };
        if let Some(step) = step {
            self.commission.last =
                LastCommission::Finished(Err(Refusal::new(step, "stopped", f64::NAN)));
            self.pin_here();
        }
    }

    /// The period's current samples to the sequence.
    pub(super) fn commission_current(&mut self, codes: &[u16]) {
        if let LastCommission::Running(sequence) = &mut self.commission.last {
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
        if let LastCommission::Applying(result, stage) = self.commission.last {
            self.commission.last = self.apply_stage(result, stage);
            if output.fault.is_none() {
                output.amplitude = Amplitude::ZERO;
                self.controller.drive_replaced(Q1_31::ZERO);
            }
            self.applied = output.amplitude;
            return;
        }
        let LastCommission::Running(sequence) = &mut self.commission.last else {
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
            Phase::Search => resonance.search_amplitude(),
            Phase::Drive(amplitude) => Amplitude::from_command(amplitude),
            Phase::DriveOffPinned => {
                let here = resonance.tuning().frequency;
                let _ = resonance.pin(here);
                Amplitude::ZERO
            }
            Phase::Off => Amplitude::ZERO,
            Phase::Done(Ok(result)) => {
                // Applied over the next periods ([`ApplyStage`]).
                self.commission.last = LastCommission::Applying(result, ApplyStage::Settings);
                Amplitude::ZERO
            }
            Phase::Done(Err(refusal)) => {
                self.pin_here();
                self.commission.last = LastCommission::Finished(Err(refusal));
                Amplitude::ZERO
            }
        };
        if output.fault.is_none() {
            output.amplitude = amplitude;
            // A search at full scale is the controller's largest Q1.31 (2^-31 low).
            self.controller.drive_replaced(amplitude.command().value);
        }
        self.applied = output.amplitude;
    }

    /// One stage of putting `result` into the loop ([`ApplyStage`]): the state after it. A
    /// refusal pins the drive where it is and ends the command refused.
    fn apply_stage(&mut self, result: CommissionResult, stage: ApplyStage) -> LastCommission {
        let next = match stage {
            ApplyStage::Settings => self
                .commission_settings(&result)
                .map(|settings| Some(ApplyStage::Gains(settings))),
            ApplyStage::Gains(settings) => gain_schedule(&settings)
                .map(|gains| Some(ApplyStage::Shaper(settings, gains)))
                .map_err(|_| refused_by_controller()),
            ApplyStage::Shaper(settings, gains) => ShaperConfig::new(
                settings.envelope_time_constant_s,
                settings.response_time_constant_s,
                settings.slew_full_scale_s,
                settings.period_s,
            )
            .map(|shaper| Some(ApplyStage::Config(settings, gains, shaper)))
            .map_err(|_| refused_by_controller()),
            ApplyStage::Config(settings, gains, shaper) => self
                .controller
                .config()
                .commissioned(&settings, gains, shaper)
                .map(|config| Some(ApplyStage::Install(settings, config)))
                .map_err(|_| refused_by_controller()),
            ApplyStage::Install(settings, config) => self
                .install_commission(&result, settings, config)
                .map(|()| None),
        };
        match next {
            Ok(Some(stage)) => LastCommission::Applying(result, stage),
            Ok(None) => LastCommission::Finished(Ok(result)),
            Err(refusal) => {
                self.pin_here();
                LastCommission::Finished(Err(refusal))
            }
        }
    }

    /// The loop on the measured values, all or nothing ([`commissioned_settings`]): the
    /// controller's envelope time constant, its gains by the tuning rule with the measured
    /// noise and mu0, mu0 as the prior of the learned natural coefficient (the estimate starts
    /// there), the current ceiling at f0, the drive pinned at f0; the scene's nominal f0 and Q
    /// (the detuning without a current sense) become the measured ones. At once: for values
    /// restored from the settings store (a console `commission` spreads the same stages over
    /// control periods, [`ApplyStage`]).
    fn apply_commission(&mut self, result: &CommissionResult) -> Result<(), Refusal> {
        let settings = self.commission_settings(result)?;
        let config = commission_config(&settings)?;
        self.install_commission(result, settings, config)
    }

    /// [`ApplyStage::Settings`]: the result checked against its ranges, the settings on it.
    fn commission_settings(&self, result: &CommissionResult) -> Result<Settings, Refusal> {
        check(result)?;
        commissioned_settings(&self.settings, result, self.commission.overshoot)
            .map_err(|_| refused_by_controller())
    }

    /// [`ApplyStage::Install`]: the drive pinned at f0, the controller on `config`, the
    /// station's f0 and Q the measured ones.
    fn install_commission(
        &mut self,
        result: &CommissionResult,
        settings: Settings,
        config: Config,
    ) -> Result<(), Refusal> {
        let f0 = result.resonance_hz.value;
        let millihertz = libm::round(f0 * 1e3) as u32;
        let mut resonance = self.resonance.clone();
        if let Some(resonance) = resonance.as_mut() {
            resonance
                .pin(Frequency::from_millihertz(millihertz))
                .map_err(|_| Refusal::new(Step::Natural, "the timer cannot make f0", f64::NAN))?;
        }
        self.resonance = resonance;
        self.controller.reconfigure(config);
        self.settings = settings;
        let chz = millihertz / 10 + u32::from(millihertz % 10 >= 5);
        self.drive_freq_chz = chz;
        self.drive_hz = millihertz as f32 / 1000.0;
        self.nominal_resonance_hz = f0;
        self.quality_factor = result.quality_factor.value;
        self.commission.applied = Some(*result);
        Ok(())
    }

    /// Puts commissioned values restored from the settings store into the loop
    /// ([`crate::settings::apply`]): as a `commission` that ends with `result` does, all or
    /// nothing. Refused while the drive runs or commissioning does, and for a result outside
    /// its physical ranges ([`check`]).
    pub fn apply_commissioned(&mut self, result: &CommissionResult) -> Result<(), Refusal> {
        let drive_off = matches!(
            self.controller.state(),
            SupervisorState::Idle | SupervisorState::Fault | SupervisorState::Boot
        );
        if self.commissioning() || !drive_off {
            return Err(Refusal::new(
                Step::Resonance,
                "the drive is on or commissioning runs",
                f64::NAN,
            ));
        }
        self.apply_commission(result)
    }

    /// The commissioned values the loop runs on, `None` while it runs on the scene's declared
    /// ones (what `save` keeps, and `status` reports as `values=`).
    pub fn commissioned(&self) -> Option<CommissionResult> {
        self.commission.applied
    }

    /// The last `commission`: running (its step), done (the values the loop now runs on) or
    /// refused (why).
    pub fn commission_report(&self) -> CommissionReport {
        match (&self.commission.last, self.commission.applied) {
            (LastCommission::Never, None) => CommissionReport::Never,
            (LastCommission::Never, Some(result)) => CommissionReport::Restored(result),
            (LastCommission::Running(sequence), _) => CommissionReport::Running(sequence.step()),
            // The sequence's last step ends when its result is in the loop.
            (LastCommission::Applying(..), _) => CommissionReport::Running(Step::Natural),
            (LastCommission::Finished(Ok(result)), _) => CommissionReport::Done(*result),
            (LastCommission::Finished(Err(refusal)), _) => CommissionReport::Refused(*refusal),
        }
    }
}

/// The refusal of values the controller does not accept.
fn refused_by_controller() -> Refusal {
    Refusal::new(Step::Natural, "controller refused the values", f64::NAN)
}

/// [`ApplyStage::Config`]: the controller's configuration of `settings`.
fn commission_config(settings: &Settings) -> Result<Config, Refusal> {
    Config::new(settings).map_err(|_| refused_by_controller())
}

/// `settings` on the commissioned values: the envelope time constant tau (and the lead on it,
/// [`drive_lead_s`]: bounded for the settings' declared mismatch under the scene's tightest
/// overshoot criterion `overshoot`, never slower than tau; the rule of
/// [`crate::control::controller_settings`]), the drive frequency f0 (the current ceiling),
/// mu0 as the prior of the natural coefficient, the contact's relaxation lag scaled with it
/// (the slip length `mu W / k_t` is proportional to mu: [`crate::control::contact_lag_s`]),
/// each cell's measured noise where the tare measured it, then the tuning rule
/// ([`tuned`]) for the gains on all of them. The declared mismatch (`settings.model_mismatch`,
/// the scene's) is kept: commissioning measures f0, Q, mu0 and the noise, not the model's
/// error. Errors: the rule refused a value.
pub fn commissioned_settings(
    settings: &Settings,
    result: &CommissionResult,
    overshoot: Option<f64>,
) -> Result<Settings, crate::control::ConfigError> {
    let mut s = *settings;
    let tau = result.time_constant_s.value;
    let mu0 = result.natural_coefficient.value;
    s.envelope_time_constant_s = tau;
    s.response_time_constant_s = drive_lead_s(&s, overshoot);
    s.actuator.drive_frequency_hz = result.resonance_hz.value;
    if s.natural_prior > 0.0 {
        s.contact_lag_s *= mu0 / s.natural_prior;
    }
    s.natural_prior = mu0;
    if let Some(noise) = result.normal.noise_rms_n {
        s.normal_noise_n = noise;
    }
    if let Some(noise) = result.tangential.noise_rms_n {
        s.tangential_noise_n = noise;
    }
    tuned(&s)
}
