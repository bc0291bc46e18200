//! The firmware's control side of one scene, without the plant: the two load-cell channels, the
//! controller and its friction model, the drive frequency, and the loop's share of the command
//! protocol.
//!
//! The controller's model is the scene's model variant chosen by
//! [`crate::variant::select`] (the cheapest fixed-point variant whose measured maximum error over
//! the scene's range meets `accuracy.model_pct`, with the parts the scene does not need left
//! out; a scene outside the committed table keeps its own model). This is the one place where
//! the host (`sonolube scene`, `sonolube_sim::ClosedLoop`) and every board build a scene's
//! controller, so they run the same variant; [`Station::selection`] says which and why, for the
//! line printed at scene start.
//!
//! The board gives the station its two load-cell channels ([`SensorChannel`]: its converter's
//! format, fault checks and calibration): the station reads the board's own codes.
//!
//! A board feeds it the converter codes of each period ([`Station::control`]) and applies the
//! returned drive amplitude; between two periods it hands it the commands that change the loop
//! ([`Station::execute`]): a command is applied whole or refused with the protocol error, never
//! half-applied. The scene closed loop of the simulation (`sonolube_sim`) is this station plus a simulated plant
//! and a judge, so the host runs and the firmware runs share every line of the control path.
//!
//! `tare` and `cal` take a burst of samples from the cells through [`CellBench`]: a real board
//! reads its converters (the operator has unloaded or loaded the cell), the simulated board
//! reads its simulated cells under the load the command names.

use crate::control::{
    Config, ConfigError, Controller, ExternalFault, Inputs, Output, Sensor, SensorFault,
    SensorFaultKind, Settings, gain_schedule, tuned,
};
use crate::drive::{Amplitude, Frequency, TimerClock};
use crate::fx::{Q1_31, Q2_30, Q8_24, Q16_16};
use crate::model::{AnyModel, FrictionModel, ModelError};
use crate::resonance::{ResonanceLoop, ResonanceReport, ResonanceSettings, StackSettings};
use core::fmt::Write;

use crate::protocol::DRIVE_FREQ;
use crate::protocol::{Axis, Command, ProtocolError, SupervisorState, TareAxes, TokenText};
use crate::scene::Scene;
use crate::sense::{AdcCode, SampleError, SensorChannel};
use crate::stage::{Stage, StageMarks};
use crate::variant::{Selection, select};

mod commission;

use commission::CommissionState;
mod motor_hold;
pub use commission::{
    CommissionReport, commissioned_settings, noise_standard_error_n, zero_standard_error_n,
};
mod reach;

/// What a board gives the station each period.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sample {
    /// Normal-force converter code (the cell's converter format, see [`crate::sense`]).
    pub normal_code: AdcCode,
    /// Tangential-force converter code.
    pub tangential_code: AdcCode,
    /// Sliding velocity, m/s, signed (measured, or the rig's set speed where it has no
    /// sensor); saturated to the Q8.24 range +-128 m/s.
    pub sliding_velocity_m_per_s: f32,
}

/// The result of one control period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Control {
    /// The controller's output; its `amplitude` is the drive command for the next period.
    pub output: Output,
    /// The fault the sensing chain found in this sample, if any.
    pub sensor_fault: Option<SensorFault>,
}

/// Samples averaged by `tare` and by `cal`: the mean of 256 samples has 1/16 of the noise
/// (0.03 % of full scale for a 0.5 % cell), and the noise dithers the converter's steps so the
/// mean resolves below one step.
pub const COMMISSIONING_SAMPLES: usize = 256;

/// Why a station cannot be built.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StationError {
    /// The controller's model could not be built from the scene's controller spec.
    Model(ModelError),
    /// The controller settings were refused.
    Config(ConfigError),
}

/// Where `tare` and `cal` get their samples.
pub trait CellBench {
    /// Fills `codes` with consecutive converter codes of `axis`'s cell, which carries
    /// `load_n` newtons (0 for `tare`; the known load for `cal`). A real board ignores
    /// `load_n`: the operator has put that load on the cell. Returns false when the cell
    /// could not be read.
    fn burst(&mut self, axis: Axis, load_n: f32, codes: &mut [AdcCode]) -> bool;
}

/// Lowest and highest drive frequency a `freq` command may set, cHz (the protocol's range).
const FREQ_RANGE_CHZ: core::ops::RangeInclusive<u32> = 2_000_000..=6_000_000;

/// The control side of a scene. Its size is mostly the model's ([`AnyModel`] holds the largest
/// variant by value: the tabulated cube model with its exact model and 17 x 17 nodes).
#[derive(Debug, Clone)]
pub struct Station {
    model: AnyModel,
    /// The choice `model` was built from; `None` when the caller gave the model.
    selection: Option<Selection>,
    controller: Controller,
    /// The settings the controller was built from; the gains are recomputed from them with
    /// the cells' measured noise after a tare ([`Station::tune_to_cells`]), and commissioning
    /// replaces the values it measures.
    settings: Settings,
    normal: SensorChannel,
    tangential: SensorChannel,
    drive_hz: f32,
    /// The same frequency in the protocol's cHz, for reports (set with `drive_hz`).
    drive_freq_chz: u32,
    /// The resonance loop (`freq auto`, `freq HZ`); `None` when the scene's stack is outside
    /// what it can model (the reason is in `resonance_refused`).
    resonance: Option<ResonanceLoop>,
    resonance_refused: &'static str,
    /// `freq auto` given while the drive was off: the next `start` searches first.
    auto_armed: bool,
    /// A `start` waits for the search to lock.
    start_pending: bool,
    /// The board feeds current samples ([`Self::enable_current_sense`]): `freq auto` is
    /// possible.
    current_sense: bool,
    /// Why `freq auto` is refused while `current_sense` is false: the board's reason by
    /// default, the scene's when the board said so ([`Self::no_current_sense_in_scene`]).
    no_current_reason: &'static str,
    /// The drive amplitude the station returned last (what the drive applies over the
    /// period whose current samples come next).
    applied: Amplitude,
    /// The last `commission` ([`crate::commission`]).
    commission: CommissionState,
    /// Feasibility while running (issue 26): the watch over the drive's limit, the last
    /// estimate and learned natural coefficient, the scene's nominal resonance, and the
    /// warning of the last `target`.
    reach: reach::ReachWatch,
    last_estimate: Option<(crate::control::FrictionEstimate, Q2_30)>,
    nominal_resonance_hz: f64,
    quality_factor: f64,
    controller_mu: f64,
    target_warning: Option<crate::protocol::Target>,
    /// The block's place on a horn and the net-force hold (issue 27); `None` for a scene the
    /// motor model does not describe (`motor_hold`).
    motor: Option<motor_hold::MotorHold>,
}

/// `freq auto` refused: the board samples no drive current.
const NO_CURRENT_ON_BOARD: &str = "this board does not sample the drive current";

/// `freq auto` refused: the scene's plant gives no drive current (at most
/// [`crate::protocol::MAX_REASON_LEN`] bytes).
const NO_CURRENT_IN_SCENE: &str = "the scene has no current sensing (bvd_envelope = false)";

/// The current sense the station assumes for the resonance loop: the NUCLEO-G474RE's
/// (25 mOhm shunt, INA240A1 at 20 V/V, 3.3 V converter span: 6.6 A per full scale; the QEMU
/// board's simulated sense is the same).
pub const CURRENT_SENSE_A_PER_FULL_SCALE: f64 = 6.6;

/// What the resonance loop believes about `scene`'s stack: its declared f0, Q, C0 and full
/// scale on this board's current sense.
pub fn scene_stack(scene: &Scene<'_>) -> StackSettings {
    StackSettings {
        resonance_hz: scene.transducer.resonance_hz,
        quality_factor: scene.transducer.quality_factor,
        clamped_capacitance_f: scene.transducer.clamped_capacitance_f,
        full_scale_voltage_v: scene.actuator.full_scale_voltage_v,
        amperes_per_full_scale: CURRENT_SENSE_A_PER_FULL_SCALE,
        min_admittance_s: StackSettings::REFERENCE.min_admittance_s,
    }
}

/// The timer the resonance loop's frequencies are rounded to (TIM1 of the G474 at 170 MHz;
/// the QEMU board's simulated drive uses the same grid).
pub const DRIVE_CLOCK: TimerClock = TimerClock::G474_TIM1;

/// Most current samples one [`Station::push_current`] call takes (one per PWM period of a
/// control period: 6 at 60 kHz and 10 kHz).
pub const MAX_CURRENT_SAMPLES: usize = 16;

impl Station {
    /// The station of `scene`: the controller model [`select`] chooses for it (built with
    /// [`Selection::build`]), the controller with `settings` (normally
    /// [`crate::control::controller_settings`]), the board's load-cell channels `normal` and
    /// `tangential`, the scene's drive frequency, idle, no target. Errors: the model or the
    /// settings refused.
    pub fn new(
        scene: &Scene<'_>,
        settings: &Settings,
        normal: SensorChannel,
        tangential: SensorChannel,
    ) -> Result<Self, StationError> {
        let selection = select(scene);
        let model = selection.build(scene).map_err(StationError::Model)?;
        Self::assemble(scene, settings, model, Some(selection), normal, tangential)
    }

    /// [`Station::new`] with a selection made elsewhere: the host's, for a scene file whose
    /// candidates it measured when it loaded the file (`sonolube scene --file`).
    /// Errors: as [`Station::new`].
    pub fn with_selection(
        scene: &Scene<'_>,
        settings: &Settings,
        selection: Selection,
        normal: SensorChannel,
        tangential: SensorChannel,
    ) -> Result<Self, StationError> {
        let model = selection.build(scene).map_err(StationError::Model)?;
        Self::assemble(scene, settings, model, Some(selection), normal, tangential)
    }

    /// [`Station::new`] with the controller running `model` instead of the selected variant
    /// (a benchmark timing one fidelity level; [`Station::selection`] is then `None`).
    pub fn with_model(
        scene: &Scene<'_>,
        settings: &Settings,
        model: AnyModel,
        normal: SensorChannel,
        tangential: SensorChannel,
    ) -> Result<Self, StationError> {
        Self::assemble(scene, settings, model, None, normal, tangential)
    }

    fn assemble(
        scene: &Scene<'_>,
        settings: &Settings,
        model: AnyModel,
        selection: Option<Selection>,
        normal: SensorChannel,
        tangential: SensorChannel,
    ) -> Result<Self, StationError> {
        let controller = Controller::new(Config::new(settings).map_err(StationError::Config)?);
        let stack = scene_stack(scene);
        let start = Frequency::from_millihertz(libm::round(scene.transducer.drive_hz * 1e3) as u32);
        let resonance =
            ResonanceLoop::new(&ResonanceSettings::around(&stack), start, DRIVE_CLOCK).ok();
        let motor =
            motor_hold::MotorHold::for_scene(scene, settings).map_err(StationError::Model)?;
        Ok(Self {
            model,
            selection,
            controller,
            settings: *settings,
            normal,
            tangential,
            drive_hz: scene.transducer.drive_hz as f32,
            // Scene drive frequencies are validated to 20-60 kHz: the cast cannot wrap.
            drive_freq_chz: libm::round(scene.transducer.drive_hz * 100.0) as u32,
            resonance_refused: if resonance.is_some() {
                ""
            } else {
                "the stack's current is beyond the current sense or its data out of range"
            },
            resonance,
            auto_armed: false,
            start_pending: false,
            current_sense: false,
            no_current_reason: NO_CURRENT_ON_BOARD,
            applied: Amplitude::ZERO,
            commission: CommissionState::never(crate::control::overshoot_criterion(scene)),
            reach: reach::ReachWatch::new(reach::ReachWatch::window_s(settings), settings.period_s),
            last_estimate: None,
            nominal_resonance_hz: scene.transducer.resonance_hz,
            quality_factor: scene.transducer.quality_factor,
            controller_mu: scene.controller.mu,
            target_warning: None,
            motor,
        })
    }

    /// Declares that the board calls [`Self::push_current`] every period. Until then `freq
    /// auto` is refused (`unavailable`): a search without samples would never end.
    pub fn enable_current_sense(&mut self) {
        self.current_sense = true;
    }

    /// Declares that the board would sample the drive current but the scene gives none (a
    /// simulated plant without the complex envelope, `transducer.shift.bvd_envelope =
    /// false`): `freq auto` is then refused naming the scene, not the board (issue 26).
    pub fn no_current_sense_in_scene(&mut self) {
        self.current_sense = false;
        self.no_current_reason = NO_CURRENT_IN_SCENE;
    }

    /// The current samples (12-bit current-sense codes, mid-scale zero) taken synchronously
    /// to the PWM over the last control period, one per PWM period, the trigger phase
    /// advancing a quarter period each time (see [`crate::resonance::ResonanceLoop`]); call
    /// it before [`Self::control`]. At most [`MAX_CURRENT_SAMPLES`] are taken (the rest are
    /// ignored). When the loop loses the resonance (`freq auto`), the controller latches
    /// `resonance-lost`: the next step drives zero.
    pub fn push_current(&mut self, codes: &[u16]) {
        let Some(resonance) = self.resonance.as_mut() else {
            return;
        };
        let mut samples = [Q1_31::ZERO; MAX_CURRENT_SAMPLES];
        let mut count = 0;
        for (slot, &code) in samples.iter_mut().zip(codes) {
            *slot = crate::resonance::current_sample(code);
            count += 1;
        }
        let taken = samples.get(..count).unwrap_or(&[]);
        let push = resonance.push(taken, self.applied);
        self.commission_current(codes.get(..count).unwrap_or(&[]));
        let Some(resonance) = self.resonance.as_mut() else {
            return;
        };
        if push.is_err() {
            self.start_pending = false;
            self.controller.trip(ExternalFault::ResonanceLost);
        }
        // `freq auto` moves the drive; pinned, the frequency is the one `freq` set.
        if resonance.report().state != crate::resonance::LockState::Pinned {
            let millihertz = resonance.tuning().frequency.millihertz();
            let chz = millihertz / 10 + u32::from(millihertz % 10 >= 5);
            if chz != self.drive_freq_chz {
                self.drive_freq_chz = chz;
                self.drive_hz = millihertz as f32 / 1000.0;
            }
        }
    }

    /// The resonance loop's last report (mode, lock, frequency, phase error); `None` when
    /// the scene's stack has no loop.
    pub fn resonance(&self) -> Option<ResonanceReport> {
        self.resonance.as_ref().map(ResonanceLoop::report)
    }

    /// One control period: the codes through the sensing chain (format, fault checks,
    /// calibration) to newtons, a fault found there as the controller's sensor fault, and the
    /// controller step.
    pub fn control(&mut self, sample: &Sample) -> Control {
        self.control_marked(sample, &mut ())
    }

    /// [`Self::control`] with its stages marked in `marks` (the benchmark's breakdown of a
    /// step's cost, [`crate::stage`]); the same computation whatever the marks.
    pub fn control_marked(&mut self, sample: &Sample, marks: &mut impl StageMarks) -> Control {
        marks.enter(Stage::Sensing);
        let (normal_force, normal_fault) =
            sense(&mut self.normal, sample.normal_code, Sensor::NormalForce);
        let (tangential_force, tangential_fault) = sense(
            &mut self.tangential,
            sample.tangential_code,
            Sensor::TangentialForce,
        );
        let sensor_fault = normal_fault.or(tangential_fault);
        let inputs = Inputs {
            normal_force,
            tangential_force,
            sliding_velocity: Q8_24::from_f32_saturating(sample.sliding_velocity_m_per_s).value,
            sensor_fault,
        };
        let mut output = self.controller.step_marked(&inputs, &self.model, marks);
        // Issue 27: in a motor region the net-force hold drives instead of the friction path.
        marks.enter(Stage::Feedback);
        if let Some(motor) = self.motor.as_mut()
            && let motor_hold::HoldOutcome::Motor(amplitude) = motor.step(
                sample.sliding_velocity_m_per_s,
                self.controller.target(),
                &output,
                normal_force,
                tangential_force,
            )
        {
            let amplitude = amplitude.min(self.controller.config().limit().max_amplitude);
            output.amplitude = Amplitude::from_command(amplitude);
            self.controller.drive_replaced(amplitude);
        }
        marks.enter(Stage::Resonance);
        if let Some(resonance) = self.resonance.as_ref() {
            let drive_allowed = output.fault.is_none()
                && (self.start_pending
                    || self.commissioning()
                    || matches!(
                        output.state,
                        crate::protocol::SupervisorState::RampUp
                            | crate::protocol::SupervisorState::Running
                    ));
            if resonance.is_searching() {
                // The search drives its own low amplitude; the friction loop waits (a
                // pending `start`) or keeps its supervision while its command is replaced.
                output.amplitude = if drive_allowed {
                    resonance.search_amplitude()
                } else {
                    Amplitude::ZERO
                };
                // The envelope estimate follows in the controller's Q1.31; a search at full
                // scale is its largest value there (2^-31 low: the flag changes nothing).
                self.controller
                    .drive_replaced(output.amplitude.command().value);
            } else if self.start_pending {
                self.start_pending = false;
                // Locked: the friction loop starts at the found frequency, with the current
                // rating's ceiling there. Both were checked when `start` was accepted.
                let hz = f64::from(resonance.tuning().frequency.millihertz()) / 1000.0;
                if let Ok(config) = self.controller.config().at_drive_frequency(hz) {
                    self.controller.reconfigure(config);
                }
                let _ = self.controller.start();
            }
        }
        marks.enter(Stage::Supervision);
        self.applied = output.amplitude;
        self.commission_period(
            &mut output,
            normal_force,
            tangential_force,
            sample.sliding_velocity_m_per_s,
        );
        self.reach.update(&output);
        self.last_estimate = Some((output.estimate, output.natural_coefficient));
        Control {
            output,
            sensor_fault,
        }
    }

    /// Applies one of the loop's commands (`target`, `start`, `stop`, `clear`, `freq`, `tare`,
    /// `cal`) whole, or refuses it with the protocol error and changes nothing. `tare` and
    /// `cal` need the drive off (state `idle` or `fault`): a vibrating contact loads the cells.
    /// Other commands are not the loop's: they are refused as `wrong-state`.
    ///
    /// One step per command, each named for what it does to the loop; while commissioning
    /// runs, the sequence owns the drive ([`Self::execute_while_commissioning`]).
    pub fn execute(
        &mut self,
        command: &Command,
        bench: &mut impl CellBench,
    ) -> Result<(), ProtocolError> {
        if self.commissioning() {
            return self.execute_while_commissioning(command);
        }
        let refused = |e: crate::control::ControlError| e.to_protocol();
        match *command {
            Command::Commission => self.start_commission(command),
            Command::Target(target) => self.set_target(target),
            Command::Start if self.auto_armed => self.start_after_search(command),
            Command::Start => self.controller.start().map_err(refused),
            Command::Stop if self.start_pending => {
                self.cancel_search_before_start();
                Ok(())
            }
            Command::Stop => self.controller.stop().map_err(refused),
            Command::FreqAuto => self.track_resonance(command),
            Command::Clear => self.controller.clear_fault().map_err(refused),
            Command::Freq { freq_chz } => self.pin_drive_frequency(freq_chz),
            Command::Tare(axes) => self.tare(command, axes, bench),
            Command::Cal { axis, load_mn } => self.calibrate(command, axis, load_mn, bench),
            _ => Err(ProtocolError::WrongState {
                command: command.keyword(),
                state: self.state(),
            }),
        }
    }

    /// While commissioning runs, the sequence owns the drive until it ends: `stop` ends it,
    /// every other command is refused in state `tuning`.
    fn execute_while_commissioning(&mut self, command: &Command) -> Result<(), ProtocolError> {
        match command {
            Command::Stop => {
                self.cancel_commission();
                Ok(())
            }
            _ => Err(ProtocolError::WrongState {
                command: command.keyword(),
                state: SupervisorState::Tuning,
            }),
        }
    }

    /// `target`: the controller's new set point, and whether the full drive reaches it now
    /// (the reply's `warning=beyond-reach`).
    fn set_target(&mut self, target: crate::protocol::Target) -> Result<(), ProtocolError> {
        self.controller
            .set_target(target)
            .map_err(|e| e.to_protocol())?;
        self.target_warning = self.beyond_reach(target);
        Ok(())
    }

    /// `start` after `freq auto` given with the drive off: refused for the controller's
    /// reasons (no target, fault latched) before anything changes; accepted, the search runs
    /// first and the friction loop starts at its lock ([`Self::control`]).
    fn start_after_search(&mut self, command: &Command) -> Result<(), ProtocolError> {
        let mut probe = self.controller;
        probe.start().map_err(|e| e.to_protocol())?;
        let resonance = self.resonance_loop(command)?;
        search_now(resonance, command)?;
        self.auto_armed = false;
        self.start_pending = true;
        Ok(())
    }

    /// `stop` while a `start` waits for the search: the search stops where it is, pinned; the
    /// friction loop never started, and the next `start` searches again.
    fn cancel_search_before_start(&mut self) {
        self.start_pending = false;
        self.auto_armed = true;
        self.pin_here();
    }

    /// The stack's resonance loop, or `command` refused for the reason it has none.
    fn resonance_loop(&mut self, command: &Command) -> Result<&mut ResonanceLoop, ProtocolError> {
        self.resonance.as_mut().ok_or(ProtocolError::Unavailable {
            command: command.keyword(),
            reason: self.resonance_refused,
        })
    }

    /// `freq auto`: the resonance loop searches now with the drive on, or at the next `start`
    /// with it off. Refused where the board or the scene gives no current samples, or the
    /// stack has no loop.
    fn track_resonance(&mut self, command: &Command) -> Result<(), ProtocolError> {
        if !self.current_sense {
            return Err(ProtocolError::Unavailable {
                command: command.keyword(),
                reason: self.no_current_reason,
            });
        }
        let drive_on = matches!(
            self.controller.state(),
            SupervisorState::RampUp | SupervisorState::Running
        );
        let resonance = self.resonance_loop(command)?;
        if drive_on {
            search_now(resonance, command)
        } else {
            // Drive off: the search runs at the next `start`.
            self.auto_armed = true;
            Ok(())
        }
    }

    /// `freq HZ`: the drive pinned at `freq_chz`, with the current rating's ceiling there.
    fn pin_drive_frequency(&mut self, freq_chz: u32) -> Result<(), ProtocolError> {
        if !FREQ_RANGE_CHZ.contains(&freq_chz) {
            // The parser never produces one; a program that builds commands may.
            return Err(ProtocolError::OutOfRange {
                token: freq_token(freq_chz),
                quantity: &DRIVE_FREQ,
            });
        }
        // The current rating's ceiling moves with the frequency (I = 2 pi f C V): the
        // controller takes the new ceiling with the new frequency, or neither changes.
        let config = self
            .controller
            .config()
            .at_drive_frequency(f64::from(freq_chz) / 100.0)
            .map_err(|_| ProtocolError::OutOfRange {
                token: freq_token(freq_chz),
                quantity: &DRIVE_FREQ,
            })?;
        // Pinned on the timer's grid: the frequency reported is the one the timer
        // makes (within 0.6 Hz of the command near 40 kHz).
        let mut pinned = None;
        if let Some(resonance) = self.resonance.as_mut() {
            let mut candidate = resonance.clone();
            if candidate
                .pin(Frequency::from_millihertz(freq_chz * 10))
                .is_ok()
            {
                pinned = Some(candidate);
            }
        }
        self.controller.reconfigure(config);
        self.drive_hz = freq_chz as f32 / 100.0;
        self.drive_freq_chz = freq_chz;
        if let Some(pinned) = pinned {
            self.resonance = Some(pinned);
        }
        self.auto_armed = false;
        if self.start_pending {
            self.start_pending = false;
            let _ = self.controller.start();
        }
        Ok(())
    }

    /// `tare`: the zero of one cell or both from a burst each, with the drive off; the gains
    /// retuned to the noise the bursts measured. Both bursts are taken before either channel
    /// changes: all or nothing.
    fn tare(
        &mut self,
        command: &Command,
        axes: TareAxes,
        bench: &mut impl CellBench,
    ) -> Result<(), ProtocolError> {
        self.require_drive_off(command)?;
        let (normal, tangential) = match axes {
            TareAxes::One(Axis::Normal) => (true, false),
            TareAxes::One(Axis::Tangential) => (false, true),
            TareAxes::All => (true, true),
        };
        let mut normal_codes = [AdcCode::default(); COMMISSIONING_SAMPLES];
        let mut tangential_codes = [AdcCode::default(); COMMISSIONING_SAMPLES];
        if normal && !bench.burst(Axis::Normal, 0.0, &mut normal_codes) {
            return Err(cal_failed("normal cell unreadable"));
        }
        if tangential && !bench.burst(Axis::Tangential, 0.0, &mut tangential_codes) {
            return Err(cal_failed("tangential cell unreadable"));
        }
        let mut new_normal = self.normal;
        let mut new_tangential = self.tangential;
        if normal {
            new_normal
                .tare(&normal_codes)
                .map_err(|_| cal_failed("normal zero unusable"))?;
        }
        if tangential {
            new_tangential
                .tare(&tangential_codes)
                .map_err(|_| cal_failed("tangential zero unusable"))?;
        }
        self.normal = new_normal;
        self.tangential = new_tangential;
        self.tune_to_cells()
            .map_err(|_| cal_failed("measured noise unusable for the tuning"))
    }

    /// `cal`: the gain of `axis`'s cell from a burst under the known load `load_mn` (mN),
    /// with the drive off.
    fn calibrate(
        &mut self,
        command: &Command,
        axis: Axis,
        load_mn: u32,
        bench: &mut impl CellBench,
    ) -> Result<(), ProtocolError> {
        self.require_drive_off(command)?;
        let load_n = load_mn as f64 / 1e3;
        let load =
            Q16_16::from_f64(load_n).map_err(|_| cal_failed("load beyond the Q16.16 span"))?;
        let mut codes = [AdcCode::default(); COMMISSIONING_SAMPLES];
        if !bench.burst(axis, load_n as f32, &mut codes) {
            return Err(cal_failed("cell unreadable"));
        }
        let channel = match axis {
            Axis::Normal => &mut self.normal,
            Axis::Tangential => &mut self.tangential,
        };
        let mut updated = *channel;
        updated
            .calibrate_gain(&codes, load)
            .map_err(|_| cal_failed("reading moved too little"))?;
        *channel = updated;
        Ok(())
    }

    /// Pins the resonance loop at its present frequency (a cancelled search).
    fn pin_here(&mut self) {
        if let Some(resonance) = self.resonance.as_mut() {
            let here = resonance.tuning().frequency;
            let _ = resonance.pin(here);
        }
    }

    fn require_drive_off(&self, command: &Command) -> Result<(), ProtocolError> {
        match self.state() {
            SupervisorState::Idle | SupervisorState::Fault | SupervisorState::Boot => Ok(()),
            state => Err(ProtocolError::WrongState {
                command: command.keyword(),
                state,
            }),
        }
    }

    /// The reach fields of `status` and telemetry: whether the target is out of reach (with
    /// the value the full drive reaches now) and whether the drive is far from the resonance.
    pub fn run_reach(&self) -> crate::protocol::RunReach {
        let state = self.reach.state();
        let reachable = match (state, self.controller.target()) {
            (crate::protocol::ReachState::TargetUnreachable, Some(target)) => {
                self.beyond_reach(target)
            }
            _ => None,
        };
        crate::protocol::RunReach {
            state,
            reachable,
            resonance: Some(reach::distance(self.detuning())),
        }
    }

    /// With the last `target` accepted: the value the full drive reaches now when the target
    /// is beyond it (`ok ... warning=beyond-reach reachable=...`), else `None`.
    pub fn target_warning(&self) -> Option<crate::protocol::Target> {
        self.target_warning
    }

    /// The drive's detuning from the resonance, half-bandwidths: the resonance loop's
    /// measurement where there is one, else from the scene's nominal f0.
    fn detuning(&self) -> f64 {
        match self.resonance().and_then(|report| report.detuning) {
            Some(measured) if self.current_sense => reach::measured_detuning(measured),
            _ => reach::nominal_detuning(
                f64::from(self.drive_hz),
                self.nominal_resonance_hz,
                self.quality_factor,
            ),
        }
    }

    /// The value the model says the drive reaches now when `target` asks for more: see
    /// [`reach::beyond_reach`].
    fn beyond_reach(&self, target: crate::protocol::Target) -> Option<crate::protocol::Target> {
        let (estimate, natural) = self.last_estimate?;
        let ceiling = self.controller.config().limit().max_amplitude.to_f64();
        let load_scale = if self.model.load_enters_as_coulomb_force() && self.controller_mu > 0.0 {
            natural.to_f64() / self.controller_mu
        } else {
            1.0
        };
        reach::beyond_reach(
            &self.model,
            target,
            &estimate,
            natural,
            ceiling * reach::detuning_gain(self.detuning()),
            load_scale,
        )
    }

    /// Whether `scene` (the one this station was built for) can work with this station's
    /// controller model: [`crate::scene::feasibility::check`]. A board calls it at `scene`
    /// and refuses a scene with a refusal (issue 26).
    pub fn feasibility(&self, scene: &Scene<'_>) -> crate::scene::feasibility::Feasibility {
        crate::scene::feasibility::check(scene, &self.model)
    }

    /// The supervisor's present state (`tuning` while commissioning runs).
    pub fn state(&self) -> SupervisorState {
        if self.commissioning() {
            SupervisorState::Tuning
        } else {
            self.controller.state()
        }
    }

    /// The drive frequency, Hz.
    pub fn drive_hz(&self) -> f32 {
        self.drive_hz
    }

    /// The drive frequency in cHz (0.01 Hz), as the protocol reports it.
    pub fn drive_freq_chz(&self) -> u32 {
        self.drive_freq_chz
    }

    /// The model variant the controller runs and why ([`select`]); `None` when the model was
    /// given ([`Station::with_model`]).
    pub fn selection(&self) -> Option<&Selection> {
        self.selection.as_ref()
    }

    /// The block's position on the horn, m from the centre, as the station tracks it from the
    /// sliding velocity (issue 27); `None` for a scene without the motor model.
    pub fn block_position_m(&self) -> Option<f64> {
        self.motor.as_ref().map(motor_hold::MotorHold::position_m)
    }

    /// The controller's friction model.
    pub fn model(&self) -> &AnyModel {
        &self.model
    }

    /// The controller.
    pub fn controller(&self) -> &Controller {
        &self.controller
    }

    /// The controller, for the commands a scene script gives it and for trips.
    pub fn controller_mut(&mut self) -> &mut Controller {
        &mut self.controller
    }

    /// The two cells' calibrations (normal, tangential), for the settings store
    /// ([`crate::settings::capture`]).
    pub fn calibrations(&self) -> (crate::sense::Calibration, crate::sense::Calibration) {
        (self.normal.calibration(), self.tangential.calibration())
    }

    /// Recomputes the controller's gains by the tuning rule ([`crate::control::tuned`]) with
    /// the noise the cells' last tare measured (a cell not tared keeps the settings' noise),
    /// and hands them to the controller bumplessly. The station's `tare` calls it; a
    /// simulation that commissions the channels directly calls it after. Errors: the rule or
    /// the gains refused the measured noise (nothing is changed then).
    pub fn tune_to_cells(&mut self) -> Result<(), ConfigError> {
        let mut settings = self.settings;
        if let Some(noise) = self.normal.noise() {
            settings.normal_noise_n = noise.to_f64();
        }
        if let Some(noise) = self.tangential.noise() {
            settings.tangential_noise_n = noise.to_f64();
        }
        let settings = tuned(&settings)?;
        let gains = gain_schedule(&settings)?;
        if let Some(motor) = self.motor.as_mut() {
            motor
                .retune(&settings)
                .map_err(|_| ConfigError::OutOfRange { setting: "kp" })?;
        }
        // Always accepted (bumpless in every state).
        let _ = self.controller.set_gains(gains);
        self.settings = settings;
        Ok(())
    }

    /// The settings the controller's gains were last computed from.
    pub const fn settings(&self) -> &Settings {
        &self.settings
    }

    /// The two channels (normal, tangential), for commissioning.
    pub fn channels_mut(&mut self) -> (&mut SensorChannel, &mut SensorChannel) {
        (&mut self.normal, &mut self.tangential)
    }
}

/// A drive frequency in cHz as the protocol writes it (`39500.50`), for an error reply.
fn freq_token(freq_chz: u32) -> TokenText {
    let mut token: heapless::String<16> = heapless::String::new();
    // 16 bytes hold every u32 with two decimals.
    let _ = write!(token, "{}.{:02}", freq_chz / 100, freq_chz % 100);
    TokenText::new(token.as_str())
}

fn cal_failed(reason: &'static str) -> ProtocolError {
    ProtocolError::CalFailed { reason }
}

/// One code through a channel: the force (zero on a fault) and the fault, as the controller
/// names it. A code the converter cannot produce counts as out of range.
fn sense(
    channel: &mut SensorChannel,
    code: AdcCode,
    sensor: Sensor,
) -> (Q16_16, Option<SensorFault>) {
    let kind = match channel.process(code) {
        Ok(force) => return (force.value, None),
        Err(SampleError::Fault(fault)) => match fault {
            crate::sense::SensorFault::LowRail { .. }
            | crate::sense::SensorFault::HighRail { .. } => SensorFaultKind::Disconnected,
            crate::sense::SensorFault::Stuck { .. } => SensorFaultKind::Stuck,
            crate::sense::SensorFault::Jump { .. } => SensorFaultKind::Jump,
        },
        Err(SampleError::Code(_)) => SensorFaultKind::OutOfRange,
    };
    (Q16_16::ZERO, Some(SensorFault { sensor, kind }))
}

/// Starts `resonance`'s search now, or refuses `command` when the drive's timer cannot make
/// the search's frequencies.
fn search_now(resonance: &mut ResonanceLoop, command: &Command) -> Result<(), ProtocolError> {
    resonance.search().map_err(|_| ProtocolError::Unavailable {
        command: command.keyword(),
        reason: "the timer cannot make the search's frequencies",
    })
}
