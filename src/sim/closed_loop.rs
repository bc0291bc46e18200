//! The closed loop of one scene: plant, sensing, controller and judge, one control period at
//! a time, in three phases.
//!
//! 1. [`ClosedLoop::plant_phase`]: the plant advances one period with the last drive command
//!    held and gives the converter codes at the end of it (in the firmware under QEMU this
//!    stands for the hardware).
//! 2. [`ClosedLoop::control_phase`]: the scene's target is applied as a `target` command when
//!    it changes, the codes go through [`crate::sense`] (format, fault checks, calibration) to
//!    newtons, a fault found there is the controller's `sensor_fault`, and
//!    the controller computes the next drive command. This is the part a firmware times.
//! 3. [`ClosedLoop::finish_step`]: the step is judged and returned as a [`StepRecord`].
//!
//! [`ClosedLoop::step`] runs the three. Time: step `k` (from 1) samples the plant at `k`
//! periods; its drive command acts over the next period. Before t = 0 the cells are
//! calibrated (by default `tare` and `cal`, [`super::commission`]); at t = 0 the scene's first
//! target is set and the run started, as an operator would.

use super::SimError;
use super::commission::{COMMISSIONED, CellCalibration, commission};
use super::judge::Judge;
use super::quantity::{Judged, target_friction_n};
use super::setup::{controller_settings, sensor_channel};
use super::summary::{Observation, RunSummary};
use crate::control::{
    Config, Controller, Inputs, Output, Reason, Sensor, SensorFault, SensorFaultKind, Settings,
};
use crate::fx::{Q1_31, Q8_24, Q16_16};
use crate::plant::{AnyModel, Plant, SensorReadings};
use crate::protocol::{SupervisorState, Target};
use crate::scene::{Breakpoint, Scene};
use crate::sense::{SampleError, SensorChannel};

/// One control step of a run, for plots, CSV files and checks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepRecord {
    /// Control step, from 1.
    pub step: u32,
    /// Time of the step's sample, s from the scene start.
    pub time_s: f32,
    /// The scene's target now.
    pub target: Option<Target>,
    /// The target and the plant's true value in the target's quantity.
    pub judged: Option<Judged>,
    /// The friction the target asks for now, N (NaN without a target).
    pub target_friction_n: f32,
    /// The controller's (filtered) friction measurement, N, magnitude.
    pub estimated_friction_n: f32,
    /// The plant's true friction, N, magnitude.
    pub true_friction_n: f32,
    /// Drive amplitude command for the next period, fraction of full scale, [0, 1].
    pub drive_amplitude: f32,
    /// The plant's vibration amplitude (envelope) at the sample, fraction of full scale.
    pub vibration_amplitude: f32,
    /// The plant's true normal load, N.
    pub normal_load_n: f32,
    /// Supervisor state after the step.
    pub state: SupervisorState,
    /// Reason of the supervisor's last transition.
    pub reason: Reason,
    /// The drive command is at the actuator's ceiling.
    pub at_limit: bool,
    /// The fault the sensing chain found in this sample, if any.
    pub sensor_fault: Option<SensorFault>,
    /// A scene fault acts on this sample (either cell).
    pub injected_fault: bool,
}

/// Where the loop is within a period.
#[derive(Debug, Clone, Copy)]
enum Phase {
    Plant,
    Control(SensorReadings),
    Finish(SensorReadings, Output, Option<SensorFault>, bool),
}

/// A scene run in closed loop. No heap: about 9 KB, of which 4 KB hold the judge's step
/// segments ([`super::MAX_SEGMENTS`]) and 2 KB the two models.
#[derive(Debug, Clone)]
pub struct ClosedLoop<'a> {
    scene: Scene<'a>,
    plant: Plant<'a, AnyModel>,
    model: AnyModel,
    controller: Controller,
    normal: SensorChannel,
    tangential: SensorChannel,
    drive_hz: f32,
    command: f32,
    target_points: usize,
    phase: Phase,
    judge: Judge,
}

impl<'a> ClosedLoop<'a> {
    /// The run of `scene` with the controller settings made from it
    /// ([`controller_settings`]) and commissioned cells ([`COMMISSIONED`]), at t = 0 with the
    /// first target set and started.
    pub fn new(scene: &Scene<'a>) -> Result<Self, SimError> {
        Self::with_settings(scene, &controller_settings(scene), COMMISSIONED)
    }

    /// The run of `scene` with the controller `settings` and the cells' `calibration` given.
    pub fn with_settings(
        scene: &Scene<'a>,
        settings: &Settings,
        calibration: CellCalibration,
    ) -> Result<Self, SimError> {
        let plant = Plant::from_scene(scene).map_err(SimError::Plant)?;
        let model = AnyModel::new(scene, &scene.controller).map_err(SimError::Model)?;
        let mut controller = Controller::new(Config::new(settings).map_err(SimError::Config)?);
        if scene.target.iter().any(|point| !point.target.is_valid()) {
            return Err(SimError::InvalidTarget);
        }
        let first = scene.target.first().ok_or(SimError::InvalidTarget)?;
        controller
            .set_target(first.target)
            .map_err(SimError::Control)?;
        controller.start().map_err(SimError::Control)?;
        let mut normal = sensor_channel(&scene.normal_cell)?;
        let mut tangential = sensor_channel(&scene.tangential_cell)?;
        let seed = scene.noise_seed;
        commission(&mut normal, &scene.normal_cell, calibration, seed, 0)?;
        commission(
            &mut tangential,
            &scene.tangential_cell,
            calibration,
            seed,
            1,
        )?;
        Ok(Self {
            scene: *scene,
            plant,
            model,
            controller,
            normal,
            tangential,
            drive_hz: scene.transducer.drive_hz as f32,
            command: 0.0,
            target_points: 1,
            phase: Phase::Plant,
            judge: Judge::new(scene).ok_or(SimError::TooLarge)?,
        })
    }

    /// Whether the run has taken all of the scene's steps.
    pub fn is_finished(&self) -> bool {
        matches!(self.phase, Phase::Plant) && self.plant.steps() >= self.scene.step_count()
    }

    /// Phase 1: the plant advances one period with the last command; returns what the
    /// converters read at its end. `None` when the run is finished or the period's other
    /// phases are still due.
    pub fn plant_phase(&mut self) -> Option<SensorReadings> {
        if self.is_finished() || !matches!(self.phase, Phase::Plant) {
            return None;
        }
        let readings = self.plant.step(self.command, self.drive_hz);
        self.phase = Phase::Control(readings);
        Some(readings)
    }

    /// Phase 2: target command, sensing and the controller step; returns the controller's
    /// output (its `amplitude` is the command for the next period). `None` unless a plant
    /// phase is due for control.
    pub fn control_phase(&mut self) -> Option<Output> {
        let Phase::Control(readings) = self.phase else {
            return None;
        };
        let t_s = readings.truth.time_s;
        let points = self.scene.target.partition_point(|p| p.at_s as f32 <= t_s);
        let target_step = points > self.target_points
            && self.scene.target.get(points - 1).is_some_and(|p| !p.ramp);
        self.target_points = points;
        if let Some(target) = readings.truth.target
            && self.controller.target() != Some(target)
        {
            // Every point was checked against the command's range at construction, and a ramp
            // interpolates between two of them: the command is accepted.
            let _ = self.controller.set_target(target);
        }
        let (normal_force, normal_fault) =
            sense(&mut self.normal, readings.normal_code, Sensor::NormalForce);
        let (tangential_force, tangential_fault) = sense(
            &mut self.tangential,
            readings.tangential_code,
            Sensor::TangentialForce,
        );
        let sensor_fault = normal_fault.or(tangential_fault);
        let inputs = Inputs {
            normal_force,
            tangential_force,
            sliding_velocity: Q8_24::from_f32_saturating(readings.sliding_velocity_m_per_s).value,
            sensor_fault,
        };
        let output = self.controller.step(&inputs, &self.model);
        self.command = output.amplitude.to_f32();
        self.phase = Phase::Finish(readings, output, sensor_fault, target_step);
        Some(output)
    }

    /// Phase 3: judges the step and returns its record. `None` unless a control phase is
    /// due for it.
    pub fn finish_step(&mut self) -> Option<StepRecord> {
        let Phase::Finish(readings, output, sensor_fault, target_step) = self.phase else {
            return None;
        };
        self.phase = Phase::Plant;
        let truth = &readings.truth;
        let judged = truth.target.map(|target| Judged::new(&target, truth));
        let ceiling = self.controller.config().limit().max_amplitude;
        let at_limit = output.amplitude > Q1_31::ZERO && output.amplitude >= ceiling;
        self.judge.observe(&Observation {
            step: readings.step,
            time_s: truth.time_s,
            judged,
            target_step,
            at_limit,
            load_ramping: ramping(self.scene.normal_load_n, truth.time_s),
            state: output.state,
            drive_zero: output.amplitude == Q1_31::ZERO,
        });
        Some(StepRecord {
            step: readings.step,
            time_s: truth.time_s,
            target: truth.target,
            judged,
            target_friction_n: truth
                .target
                .map_or(f32::NAN, |target| target_friction_n(&target, truth)),
            estimated_friction_n: libm::fabsf(output.estimate.tangential_force.to_f32()),
            true_friction_n: libm::fabsf(truth.contact.friction_n),
            drive_amplitude: self.command,
            vibration_amplitude: truth.vibration_amplitude,
            normal_load_n: truth.normal_load_n,
            state: output.state,
            reason: output.reason,
            at_limit,
            sensor_fault,
            injected_fault: truth.normal_fault.is_some() || truth.tangential_fault.is_some(),
        })
    }

    /// One whole period (the three phases); `None` when the run is finished.
    pub fn step(&mut self) -> Option<StepRecord> {
        self.plant_phase()?;
        self.control_phase()?;
        self.finish_step()
    }

    /// Runs the remaining steps and returns the summary.
    pub fn run(&mut self) -> RunSummary {
        while self.step().is_some() {}
        self.summary()
    }

    /// The summary of the steps so far: segment metrics, fault reactions, verdicts.
    pub fn summary(&self) -> RunSummary {
        self.judge.summary()
    }

    /// The scene.
    pub fn scene(&self) -> &Scene<'a> {
        &self.scene
    }

    /// The controller (its configuration and state).
    pub fn controller(&self) -> &Controller {
        &self.controller
    }

    /// The plant.
    pub fn plant(&self) -> &Plant<'a, AnyModel> {
        &self.plant
    }
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

/// Whether the piecewise-linear `profile` changes at `t_s` (between two breakpoints of
/// different values), with the breakpoints in `f32` as [`crate::scene::interpolate`] uses them.
fn ramping(profile: &[Breakpoint], t_s: f32) -> bool {
    let after = profile.partition_point(|p| p.t_s as f32 <= t_s);
    match (
        after.checked_sub(1).and_then(|i| profile.get(i)),
        profile.get(after),
    ) {
        (Some(a), Some(b)) => a.value != b.value,
        _ => false,
    }
}
