//! The simulated plant: a deterministic model of the transducer, the contact and the load
//! cells, stepped at the control rate.
//!
//! A [`Plant`] is built from a [`Scene`] and a [`FrictionModel`] for its contact (normally
//! [`AnyModel::new`] on the scene's plant spec: higher fidelity and its own parameters, so the
//! controller has real model error to remove). Each [`Plant::step`] takes the drive command
//! and frequency, holds them for one control period (zero-order hold), advances the
//! transducer envelope, the contact and the cells' dynamics in `plant_substeps` substeps, and
//! returns what the firmware would read at the end of the period: the two load cells' ADC
//! codes (with bandwidth, calibration errors, noise, quantisation, saturation and the scene's
//! faults), the sliding velocity, the drive current, and the ground truth for plots and pass
//! criteria.
//!
//! # Determinism
//!
//! The physics is `f32` (the Cortex-M4F's FPU format); transcendental functions come from
//! `libm` (pure Rust, no platform maths library); the noise comes from the plant's own seeded
//! generator ([`noise`]); and Rust never contracts or reorders floating-point operations: the
//! host and the firmware produce bit-identical runs for the same scene and the same inputs.
//! Scene values are converted from `f64` once, at construction. Time is kept as the step
//! count and formed as `step / rate` in `f64` (a few operations per substep), so profile
//! breakpoints and fault onsets land on the control grid exactly, however long the run.

pub mod contact;
pub mod dahl_state;
pub mod motor_contact;
pub mod noise;
pub mod profile;
pub mod sensors;
pub mod transducer;

pub use contact::{Contact, ContactTruth};
pub use dahl_state::DahlState;
pub use motor_contact::{BlockOnHorn, MotorTruth};
pub use noise::{Gaussian, Xoshiro128};
pub use profile::{Scenario, ScenarioInputs};
pub use sensors::LoadCellSim;
pub use transducer::{CurrentPhasor, ResonantTransducer};

use sonolube::model::motor::HornRegion;
use sonolube::model::{AnyModel, FrictionModel, ModelError};
use sonolube::protocol::Target;
use sonolube::scene::{Channel, FaultKind, Scene};
use sonolube::sense::AdcCode;

/// Why a plant could not be built.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PlantError {
    /// A scene value the plant needs is outside the range `scenes/README.md` gives (a scene
    /// built by hand rather than by the loader).
    InvalidScene {
        /// The offending field.
        field: &'static str,
    },
    /// The plant's friction model could not be built from the scene's plant spec.
    Model(ModelError),
}

/// Ground truth of the plant at the end of a step, for plots and pass criteria.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GroundTruth {
    /// Time, s from the scene start.
    pub time_s: f32,
    /// Normal load, N.
    pub normal_load_n: f32,
    /// Sliding velocity, m/s, signed.
    pub sliding_velocity_m_per_s: f32,
    /// The contact: friction, natural friction, ratio, model error.
    pub contact: ContactTruth,
    /// Vibration amplitude, fraction of the scene's full-scale amplitude, [0, 1].
    pub vibration_amplitude: f32,
    /// Vibration amplitude, m.
    pub vibration_amplitude_m: f32,
    /// Transducer resonance f0 now, Hz.
    pub resonance_hz: f32,
    /// Gain of the transducer at the drive frequency now, (0, 1].
    pub drive_gain: f32,
    /// The drive command applied over the step, [0, 1].
    pub drive_command: f32,
    /// The drive frequency applied over the step, Hz.
    pub drive_hz: f32,
    /// The scene's target now.
    pub target: Option<Target>,
    /// The fault acting on the normal cell's sample, if any.
    pub normal_fault: Option<FaultKind>,
    /// The fault acting on the tangential cell's sample, if any.
    pub tangential_fault: Option<FaultKind>,
    /// The block on a horn (issue 27): its position and region, and the horn's net force on
    /// it; `None` for a scene without the motor model.
    pub motor: Option<MotorTruth>,
}

/// What the firmware reads at the end of a step, and the ground truth.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SensorReadings {
    /// Steps taken so far (1 after the first step).
    pub step: u32,
    /// Normal-load cell, ADC code, 0 ..= 2^bits - 1 (zero force at mid-scale).
    pub normal_code: AdcCode,
    /// Tangential (friction) cell, ADC code, 0 ..= 2^bits - 1 (zero force at mid-scale).
    pub tangential_code: AdcCode,
    /// Sliding velocity from the carriage encoder, m/s, signed (exact).
    pub sliding_velocity_m_per_s: f32,
    /// Drive current at the drive frequency (for the resonance tracker).
    pub drive_current: CurrentPhasor,
    /// The current sense's 12-bit codes over the period, one per PWM period (transducers
    /// with `bvd_envelope` only; the first `current_count` are valid).
    pub current_codes: [u16; transducer::MAX_CURRENT_CODES],
    /// Valid entries of `current_codes`.
    pub current_count: u8,
    /// Ground truth.
    pub truth: GroundTruth,
}

/// The simulated plant of one scene.
#[derive(Debug, Clone)]
pub struct Plant<'a, M> {
    scenario: Scenario<'a>,
    transducer: ResonantTransducer,
    contact: Contact<M>,
    normal_cell: LoadCellSim,
    tangential_cell: LoadCellSim,
    noise: Gaussian,
    control_rate_hz: f64,
    substeps: u8,
    full_scale_amplitude_m: f32,
    step: u32,
    last_contact: ContactTruth,
    initial_load_n: f32,
    /// The block on the horn and the motor model at the plant's parameters (horn scenes whose
    /// horn seed 001 Table 1 measured, `sonolube::model::motor::scene_motor`).
    block: Option<BlockOnHorn>,
}

impl<'a> Plant<'a, AnyModel> {
    /// The plant of `scene` with the contact model of its plant spec ([`AnyModel::new`]).
    pub fn from_scene(scene: &Scene<'a>) -> Result<Self, PlantError> {
        let model = AnyModel::new(scene, &scene.plant).map_err(PlantError::Model)?;
        Self::new(scene, model)
    }
}

impl<'a, M: FrictionModel> Plant<'a, M> {
    /// The plant of `scene` with `model` for its contact, at t = 0: drive off, cells settled
    /// on the initial load and natural friction.
    pub fn new(scene: &Scene<'a>, model: M) -> Result<Self, PlantError> {
        let invalid = |field| Err(PlantError::InvalidScene { field });
        if !(scene.control_rate_hz >= 1.0 && scene.control_rate_hz <= 1e6) {
            return invalid("control_rate_hz");
        }
        if scene.plant_substeps == 0 {
            return invalid("plant_substeps");
        }
        let t = &scene.transducer;
        if !(t.resonance_hz > 0.0 && t.quality_factor > 0.0 && t.motional_resistance_ohm > 0.0) {
            return invalid("transducer");
        }
        for cell in [&scene.normal_cell, &scene.tangential_cell] {
            if !(cell.full_scale_n > 0.0 && (8..=16).contains(&cell.adc_bits)) {
                return invalid("sensors");
            }
        }
        let scenario = Scenario::new(scene);
        let start = scenario.at(0.0);
        let contact = Contact::in_time(
            model,
            &scene.plant,
            scene.actuator.full_scale_amplitude_m,
            start.normal_load_n,
            start.sliding_velocity_m_per_s,
        )
        .map_err(PlantError::Model)?;
        let initial = contact.evaluate(start.normal_load_n, start.sliding_velocity_m_per_s, 0.0);
        let block = match sonolube::model::motor::scene_motor(scene, &scene.plant)
            .map_err(PlantError::Model)?
        {
            Some((motor, regions)) => {
                let start_m = scene.horn.map_or(0.0, |horn| horn.contact_position_m);
                Some(BlockOnHorn::new(motor, regions, start_m).map_err(PlantError::Model)?)
            }
            None => None,
        };
        let substep_s = (1.0 / (scene.control_rate_hz * f64::from(scene.plant_substeps))) as f32;
        Ok(Self {
            scenario,
            transducer: ResonantTransducer::with_shift(
                &scene.transducer,
                &scene.actuator,
                scene.noise_seed,
            ),
            initial_load_n: start.normal_load_n,
            normal_cell: LoadCellSim::new(&scene.normal_cell, substep_s, start.normal_load_n),
            tangential_cell: LoadCellSim::new(
                &scene.tangential_cell,
                substep_s,
                initial.friction_n,
            ),
            contact,
            noise: Gaussian::from_seed(scene.noise_seed),
            control_rate_hz: scene.control_rate_hz,
            substeps: scene.plant_substeps,
            full_scale_amplitude_m: scene.actuator.full_scale_amplitude_m as f32,
            step: 0,
            last_contact: initial,
            block,
        })
    }

    /// Time now, s from the scene start: steps / control rate.
    pub fn time_s(&self) -> f32 {
        self.time_f64() as f32
    }

    /// Steps taken so far.
    pub fn steps(&self) -> u32 {
        self.step
    }

    /// The transducer (envelope, electrical side, current waveform for lock-in tests).
    pub fn transducer(&self) -> &ResonantTransducer {
        &self.transducer
    }

    /// The contact and its friction model.
    pub fn contact(&self) -> &Contact<M> {
        &self.contact
    }

    /// The scene's inputs (load, velocity, target) at `t_s`.
    pub fn inputs_at(&self, t_s: f32) -> ScenarioInputs {
        self.scenario.at(t_s)
    }

    /// One control period with `drive_command` (fraction of full-scale voltage, clamped to
    /// [0, 1]) at `drive_hz` held: returns the readings at the end of the period.
    pub fn step(&mut self, drive_command: f32, drive_hz: f32) -> SensorReadings {
        let start_s = self.time_f64();
        let substep_s = 1.0 / (self.control_rate_hz * f64::from(self.substeps));
        let mut inputs = self.scenario.at(start_s as f32);
        for k in 1..=self.substeps {
            self.transducer
                .set_load(inputs.normal_load_n, self.initial_load_n);
            let envelope_before = self.transducer.envelope();
            self.transducer
                .advance(drive_command, drive_hz, substep_s as f32);
            inputs = self
                .scenario
                .at((start_s + f64::from(k) * substep_s) as f32);
            let amplitude = self.transducer.envelope();
            self.last_contact = if self.contact.dahl_state().is_some() {
                // The Dahl state is stepped through the substep with the envelope's mean over
                // it (the envelope moves by at most 1 - e^(-dt/tau), 3 % per 25 us substep at
                // tau = 0.8 ms), at the drive frequency (the free ring-down at the resonance).
                let vibration_hz = if drive_hz.is_finite() && drive_hz > 0.0 {
                    drive_hz
                } else {
                    self.transducer.resonance_hz(self.transducer.time_s())
                };
                self.contact.advance(
                    inputs.normal_load_n,
                    inputs.sliding_velocity_m_per_s,
                    0.5 * (envelope_before + amplitude),
                    vibration_hz,
                    substep_s as f32,
                )
            } else {
                self.contact.evaluate(
                    inputs.normal_load_n,
                    inputs.sliding_velocity_m_per_s,
                    amplitude,
                )
            };
            if let Some(block) = self.block.as_mut() {
                // Off the face the block stays at the end (the rig would have lost it).
                let _ = block.advance(inputs.sliding_velocity_m_per_s, substep_s as f32);
                if block.region() != HornRegion::Transition {
                    // A motor region (seed 001 Table 1): the horn drives the block; the cell
                    // reads the block's drag on the horn, minus the horn's force on it.
                    let motor = block.motor_force(
                        inputs.normal_load_n.max(0.0),
                        inputs.sliding_velocity_m_per_s,
                        amplitude.clamp(0.0, 1.0),
                    );
                    let natural = self.last_contact.natural_friction_n;
                    self.last_contact = match motor {
                        Ok(motor) => ContactTruth {
                            friction_n: -motor.force_n,
                            natural_friction_n: natural,
                            ratio: if natural > 0.0 {
                                libm::fabsf(motor.force_n) / natural
                            } else {
                                1.0
                            },
                            error: None,
                        },
                        Err(error) => ContactTruth {
                            error: Some(error),
                            ..self.last_contact
                        },
                    };
                }
            }
            self.normal_cell.track(inputs.normal_load_n);
            self.tangential_cell.track(self.last_contact.friction_n);
        }
        self.step = self.step.saturating_add(1);
        let now = self.time_f64();
        let normal_fault = self.scenario.fault_at(Channel::Normal, self.step);
        let tangential_fault = self.scenario.fault_at(Channel::Tangential, self.step);
        let normal_code = self.normal_cell.sample(&mut self.noise, normal_fault);
        let tangential_code = self
            .tangential_cell
            .sample(&mut self.noise, tangential_fault);
        let time_s = now as f32;
        let amplitude = self.transducer.envelope();
        let (current_codes, current_count) = self.transducer.take_current_codes();
        SensorReadings {
            step: self.step,
            normal_code,
            tangential_code,
            sliding_velocity_m_per_s: inputs.sliding_velocity_m_per_s,
            drive_current: self.transducer.current(),
            current_codes,
            current_count: current_count as u8,
            truth: GroundTruth {
                time_s,
                normal_load_n: inputs.normal_load_n,
                sliding_velocity_m_per_s: inputs.sliding_velocity_m_per_s,
                contact: self.last_contact,
                vibration_amplitude: amplitude,
                vibration_amplitude_m: amplitude * self.full_scale_amplitude_m,
                resonance_hz: self.transducer.resonance_hz(time_s),
                drive_gain: self.transducer.gain(drive_hz, time_s),
                drive_command: self.transducer.command(),
                drive_hz,
                target: inputs.target,
                normal_fault,
                tangential_fault,
                // The horn's force on the block, friction in the transition region.
                motor: self.block.as_ref().map(|block| MotorTruth {
                    position_m: block.position_m() as f32,
                    region: block.region(),
                    force_n: -self.last_contact.friction_n,
                }),
            },
        }
    }

    fn time_f64(&self) -> f64 {
        f64::from(self.step) / self.control_rate_hz
    }
}

#[cfg(test)]
#[path = "plant_tests.rs"]
mod tests;
