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
    Config, ConfigError, Controller, Inputs, Output, Sensor, SensorFault, SensorFaultKind, Settings,
};
use crate::fx::{Q8_24, Q16_16};
use crate::model::{AnyModel, ModelError};
use core::fmt::Write;

use crate::protocol::DRIVE_FREQ;
use crate::protocol::{Axis, Command, ProtocolError, SupervisorState, TareAxes, TokenText};
use crate::scene::Scene;
use crate::sense::{SampleError, SensorChannel};
use crate::variant::{Selection, select};

/// What a board gives the station each period.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sample {
    /// Normal-force converter code (the cell's converter format, see [`crate::sense`]).
    pub normal_code: u16,
    /// Tangential-force converter code.
    pub tangential_code: u16,
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
    fn burst(&mut self, axis: Axis, load_n: f32, codes: &mut [i32]) -> bool;
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
    normal: SensorChannel,
    tangential: SensorChannel,
    drive_hz: f32,
    /// The same frequency in the protocol's cHz, for reports (set with `drive_hz`).
    drive_freq_chz: u32,
}

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
        Ok(Self {
            model,
            selection,
            controller,
            normal,
            tangential,
            drive_hz: scene.transducer.drive_hz as f32,
            // Scene drive frequencies are validated to 20-60 kHz: the cast cannot wrap.
            drive_freq_chz: libm::round(scene.transducer.drive_hz * 100.0) as u32,
        })
    }

    /// One control period: the codes through the sensing chain (format, fault checks,
    /// calibration) to newtons, a fault found there as the controller's sensor fault, and the
    /// controller step.
    pub fn control(&mut self, sample: &Sample) -> Control {
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
        let output = self.controller.step(&inputs, &self.model);
        Control {
            output,
            sensor_fault,
        }
    }

    /// Applies one of the loop's commands (`target`, `start`, `stop`, `clear`, `freq`, `tare`,
    /// `cal`) whole, or refuses it with the protocol error and changes nothing. `tare` and
    /// `cal` need the drive off (state `idle` or `fault`): a vibrating contact loads the cells.
    /// Other commands are not the loop's: they are refused as `wrong-state`.
    pub fn execute(
        &mut self,
        command: &Command,
        bench: &mut impl CellBench,
    ) -> Result<(), ProtocolError> {
        let refused = |e: crate::control::ControlError| e.to_protocol();
        match *command {
            Command::Target(target) => self.controller.set_target(target).map_err(refused),
            Command::Start => self.controller.start().map_err(refused),
            Command::Stop => self.controller.stop().map_err(refused),
            Command::Clear => self.controller.clear_fault().map_err(refused),
            Command::Freq { freq_chz } => {
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
                self.controller.reconfigure(config);
                self.drive_hz = freq_chz as f32 / 100.0;
                self.drive_freq_chz = freq_chz;
                Ok(())
            }
            Command::Tare(axes) => {
                self.require_drive_off(command)?;
                let (normal, tangential) = match axes {
                    TareAxes::One(Axis::Normal) => (true, false),
                    TareAxes::One(Axis::Tangential) => (false, true),
                    TareAxes::All => (true, true),
                };
                // Both bursts are taken before either channel changes: all or nothing.
                let mut normal_codes = [0i32; COMMISSIONING_SAMPLES];
                let mut tangential_codes = [0i32; COMMISSIONING_SAMPLES];
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
                Ok(())
            }
            Command::Cal { axis, load_mn } => {
                self.require_drive_off(command)?;
                let load_n = load_mn as f64 / 1e3;
                let load = Q16_16::from_f64(load_n)
                    .map_err(|_| cal_failed("load beyond the Q16.16 span"))?;
                let mut codes = [0i32; COMMISSIONING_SAMPLES];
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
            _ => Err(ProtocolError::WrongState {
                command: command.keyword(),
                state: self.state(),
            }),
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

    /// The supervisor's present state.
    pub fn state(&self) -> SupervisorState {
        self.controller.state()
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
fn sense(channel: &mut SensorChannel, code: u16, sensor: Sensor) -> (Q16_16, Option<SensorFault>) {
    let kind = match channel.process(i32::from(code)) {
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
