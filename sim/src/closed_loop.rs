//! The closed loop of one scene: plant, sensing, controller and judge, one control period at
//! a time, in three phases.
//!
//! 1. [`ClosedLoop::plant_phase`]: the plant advances one period with the last drive command
//!    held and gives the converter codes at the end of it (in the firmware under QEMU this
//!    stands for the hardware).
//! 2. [`ClosedLoop::control_phase`]: the scene's target is applied as a `target` command when
//!    it changes, the codes go through [`sonolube::sense`] (format, fault checks, calibration) to
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
use super::rig_commission::commission_rig;
use super::setup::scene_station;
use super::summary::{Observation, RunSummary};
use crate::plant::{Gaussian, LoadCellSim, Plant, SensorReadings};
use sonolube::commission::{CommissionResult, commissioned_scene};
use sonolube::control::{
    Controller, ExternalFault, Output, Reason, SensorFault, Settings, controller_settings,
};
use sonolube::drive::Amplitude;
use sonolube::model::AnyModel;
use sonolube::protocol::{Axis, Command, ProtocolError, SupervisorState, Target, TargetRange};
use sonolube::scene::{Breakpoint, Scene};
use sonolube::sense::AdcCode;
use sonolube::stage::{Stage, StageMarks};
use sonolube::station::{CellBench, Sample, Station};

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
    /// The drive frequency over the step, Hz.
    pub drive_hz: f32,
    /// The transducer's resonance f0 at the sample, Hz.
    pub resonance_hz: f32,
}

/// Where the loop is within a period. The period's readings stay in `ClosedLoop::readings`
/// (they carry the current sense's codes, a few hundred bytes): the control phase reads them
/// in place rather than copying them in and out of the phase (600 instructions a step in
/// QEMU, `bench stage ... / script` in docs/speed.md).
#[derive(Debug, Clone, Copy)]
enum Phase {
    Plant,
    Control,
    Finish(Output, Option<SensorFault>, bool),
}

/// Who gives the loop its targets and its start.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Mode {
    /// The scene's script: its target profile, started at t = 0, judged, for its duration.
    /// The loop's commands are refused (`wrong-state`): the script owns the loop.
    Scripted,
    /// An operator over the command protocol ([`ClosedLoop::execute`]): no target, idle at
    /// t = 0, runs until stopped, not judged.
    Operated,
}

/// A scene run in closed loop. No heap: about 9 KB, of which 4 KB hold the judge's step
/// segments ([`super::MAX_SEGMENTS`]) and 2 KB the two models.
#[derive(Debug, Clone)]
pub struct ClosedLoop<'a> {
    scene: Scene<'a>,
    plant: Plant<'a, AnyModel>,
    station: Station,
    mode: Mode,
    command: f32,
    target_points: usize,
    phase: Phase,
    /// The last plant phase's readings (`None` before the first).
    readings: Option<SensorReadings>,
    judge: Judge,
    /// What commissioning measured before the run (`commission = true` scenes).
    commissioned: Option<CommissionResult>,
}

impl<'a> ClosedLoop<'a> {
    /// The run of `scene` with the model variant the scene selects ([`Station::new`]), the
    /// controller settings made from it ([`controller_settings`]) and commissioned cells
    /// ([`COMMISSIONED`]), at t = 0 with the first target set and started. A scene with
    /// `commission = true` is commissioned first ([`commission_rig`]) and its controller runs
    /// on the measured values ([`commissioned_scene`]).
    pub fn new(scene: &Scene<'a>) -> Result<Self, SimError> {
        Self::with_selection_calibrated(scene, sonolube::variant::select(scene), COMMISSIONED)
    }

    /// [`ClosedLoop::new`] with the controller running `model` instead of the variant the
    /// scene selects ([`Station::with_model`]): the QEMU benchmark times the control step of one
    /// fidelity level this way.
    pub fn with_model(scene: &Scene<'a>, model: AnyModel) -> Result<Self, SimError> {
        let settings = controller_settings(scene);
        let normal = super::sensor_channel(&scene.normal_cell)?;
        let tangential = super::sensor_channel(&scene.tangential_cell)?;
        let station = Station::with_model(scene, &settings, model, normal, tangential)?;
        Self::scripted(scene, station, COMMISSIONED, None)
    }

    /// [`ClosedLoop::new`] with the variant `selection` names ([`Station::with_selection`]):
    /// the host's selection for a scene file it measured when loading it.
    pub fn with_selection(
        scene: &Scene<'a>,
        selection: sonolube::variant::Selection,
    ) -> Result<Self, SimError> {
        Self::with_selection_calibrated(scene, selection, COMMISSIONED)
    }

    /// [`ClosedLoop::with_selection`] with the cells' `calibration` given (the robustness
    /// sweeps: a mismatch point's cells carry exactly their gain error).
    pub fn with_selection_calibrated(
        scene: &Scene<'a>,
        selection: sonolube::variant::Selection,
        calibration: CellCalibration,
    ) -> Result<Self, SimError> {
        let commissioned = if scene.commission {
            Some(commission_rig(scene)?)
        } else {
            None
        };
        Self::with_commissioned(scene, selection, calibration, commissioned)
    }

    /// [`ClosedLoop::with_selection_calibrated`] with the commissioning already done
    /// (`commissioned`, from [`commission_rig`]; `None`: the declared values). The QEMU board
    /// commissions first and builds the run after, so that its stack never holds the rig's run
    /// and the scene's at once.
    pub fn with_commissioned(
        scene: &Scene<'a>,
        selection: sonolube::variant::Selection,
        calibration: CellCalibration,
        commissioned: Option<CommissionResult>,
    ) -> Result<Self, SimError> {
        // The variant is the scene's choice; its parameters, the measured ones.
        let controller_scene = commissioned
            .as_ref()
            .map_or(*scene, |result| commissioned_scene(scene, result));
        let settings = controller_settings(&controller_scene);
        let normal = super::sensor_channel(&scene.normal_cell)?;
        let tangential = super::sensor_channel(&scene.tangential_cell)?;
        let station =
            Station::with_selection(&controller_scene, &settings, selection, normal, tangential)?;
        // Built with the result in place: the run (14 KB) is not copied once more, which the
        // QEMU board's stack would feel.
        Self::scripted(scene, station, calibration, commissioned)
    }

    /// What commissioning measured before this run; `None` unless the scene has
    /// `commission = true`.
    pub fn commissioned(&self) -> Option<&CommissionResult> {
        self.commissioned.as_ref()
    }

    /// The run of `scene` with the controller `settings` and the cells' `calibration` given.
    pub fn with_settings(
        scene: &Scene<'a>,
        settings: &Settings,
        calibration: CellCalibration,
    ) -> Result<Self, SimError> {
        Self::scripted(scene, scene_station(scene, settings)?, calibration, None)
    }

    /// The scripted run of `scene` on `station`: first target set, started.
    fn scripted(
        scene: &Scene<'a>,
        station: Station,
        calibration: CellCalibration,
        commissioned: Option<CommissionResult>,
    ) -> Result<Self, SimError> {
        let mut run = Self::build(scene, station, calibration, Mode::Scripted, commissioned)?;
        if scene.target.iter().any(|point| !point.target.is_valid()) {
            return Err(SimError::InvalidTarget);
        }
        let first = scene.target.first().ok_or(SimError::InvalidTarget)?;
        let controller = run.station.controller_mut();
        controller
            .set_target(first.target)
            .map_err(SimError::Control)?;
        // A commissioned run starts at the measured f0: no search.
        if scene.transducer.shift.freq_auto && !scene.commission {
            // `freq auto` then `start`, as an operator would: the search runs first and the
            // friction loop starts at its lock.
            let mut bench = SimulatedCells { scene, burst: 0 };
            run.station
                .execute(&Command::FreqAuto, &mut bench)
                .and_then(|()| run.station.execute(&Command::Start, &mut bench))
                .map_err(SimError::Resonance)?;
        } else {
            controller.start().map_err(SimError::Control)?;
        }
        Ok(run)
    }

    /// The scene's plant under an operator's commands ([`Mode::Operated`]): commissioned
    /// cells, the scene's controller settings, idle, no target.
    pub fn operated(scene: &Scene<'a>) -> Result<Self, SimError> {
        let station = scene_station(scene, &controller_settings(scene))?;
        Self::build(scene, station, COMMISSIONED, Mode::Operated, None)
    }

    fn build(
        scene: &Scene<'a>,
        mut station: Station,
        calibration: CellCalibration,
        mode: Mode,
        commissioned: Option<CommissionResult>,
    ) -> Result<Self, SimError> {
        let plant = Plant::from_scene(scene).map_err(SimError::Plant)?;
        if scene.transducer.shift.bvd_envelope {
            // This plant samples its drive current every PWM period (`plant::transducer`).
            station.enable_current_sense();
        } else {
            // The simulated board would sample it: the scene's plant has none.
            station.no_current_sense_in_scene();
        }
        let seed = scene.noise_seed;
        let (normal, tangential) = station.channels_mut();
        commission(normal, &scene.normal_cell, calibration, seed, 0)?;
        commission(tangential, &scene.tangential_cell, calibration, seed, 1)?;
        // The tare measured each cell's noise: the gains follow it, as the station's `tare`
        // makes them.
        station.tune_to_cells().map_err(|_| SimError::Calibration)?;
        Ok(Self {
            scene: *scene,
            plant,
            station,
            mode,
            command: 0.0,
            target_points: 1,
            phase: Phase::Plant,
            readings: None,
            judge: Judge::new(scene).ok_or(SimError::TooLarge)?,
            commissioned,
        })
    }

    /// Whether the run has taken all of the scene's steps.
    /// Always false in [`Mode::Operated`].
    pub fn is_finished(&self) -> bool {
        self.mode == Mode::Scripted
            && matches!(self.phase, Phase::Plant)
            && self.plant.steps() >= self.scene.step_count()
    }

    /// Phase 1: the plant advances one period with the last command; returns what the
    /// converters read at its end. `None` when the run is finished or the period's other
    /// phases are still due.
    pub fn plant_phase(&mut self) -> Option<SensorReadings> {
        self.plant_phase_driven(self.command)
    }

    /// Phase 1 with the drive amplitude the board's output holds (fraction of full scale,
    /// [0, 1]) instead of the controller's last command: the firmware's plant reads its
    /// drive output, so a drive forced safe (panic, fault) is what the plant sees.
    pub fn plant_phase_driven(&mut self, drive_amplitude: f32) -> Option<SensorReadings> {
        if self.is_finished() || !matches!(self.phase, Phase::Plant) {
            return None;
        }
        let readings = self.plant.step(drive_amplitude, self.station.drive_hz());
        self.phase = Phase::Control;
        self.readings = Some(readings);
        Some(readings)
    }

    /// Phase 2: target command, sensing and the controller step; returns the controller's
    /// output (its `amplitude` is the command for the next period). `None` unless a plant
    /// phase is due for control.
    pub fn control_phase(&mut self) -> Option<Output> {
        self.control_phase_marked(&mut ())
    }

    /// Phase 2 with its stages marked in `marks` (the benchmark's breakdown of a control
    /// step's cost, `sonolube::stage`); the same computation whatever the marks.
    pub fn control_phase_marked(&mut self, marks: &mut impl StageMarks) -> Option<Output> {
        marks.enter(Stage::Script);
        if !matches!(self.phase, Phase::Control) {
            return None;
        }
        let Some(readings) = &self.readings else {
            return None;
        };
        let t_s = readings.truth.time_s;
        let points = self.scene.target.partition_point(|p| p.at_s as f32 <= t_s);
        let target_step = points > self.target_points
            && self.scene.target.get(points - 1).is_some_and(|p| !p.ramp);
        self.target_points = points;
        if self.mode == Mode::Scripted
            && let Some(target) = readings.truth.target
            && self.station.controller().target() != Some(target)
        {
            // Every point was checked against the command's range at construction, and a ramp
            // interpolates between two of them: the command is accepted.
            let _ = self.station.controller_mut().set_target(target);
        }
        marks.enter(Stage::Resonance);
        let count = usize::from(readings.current_count);
        if count > 0 {
            self.station
                .push_current(readings.current_codes.get(..count).unwrap_or(&[]));
        }
        let control = self.station.control_marked(
            &Sample {
                normal_code: readings.normal_code,
                tangential_code: readings.tangential_code,
                sliding_velocity_m_per_s: readings.sliding_velocity_m_per_s,
            },
            marks,
        );
        marks.enter(Stage::Script);
        let output = control.output;
        self.command = output.amplitude.to_f32();
        self.phase = Phase::Finish(output, control.sensor_fault, target_step);
        Some(output)
    }

    /// Phase 3: judges the step and returns its record. `None` unless a control phase is
    /// due for it.
    pub fn finish_step(&mut self) -> Option<StepRecord> {
        let (Phase::Finish(output, sensor_fault, target_step), Some(readings)) =
            (self.phase, &self.readings)
        else {
            return None;
        };
        self.phase = Phase::Plant;
        let truth = &readings.truth;
        let judged = truth.target.map(|target| Judged::new(&target, truth));
        let ceiling = self.station.controller().config().limit().max_amplitude;
        let at_limit =
            output.amplitude > Amplitude::ZERO && output.amplitude.command().value >= ceiling;
        let observation = Observation {
            step: readings.step,
            time_s: truth.time_s,
            judged,
            friction_n: truth.target.map(|target| {
                (
                    target_friction_n(&target, truth),
                    libm::fabsf(truth.contact.friction_n),
                )
            }),
            target_step,
            at_limit,
            load_ramping: ramping(self.scene.normal_load_n, truth.time_s),
            state: output.state,
            drive_zero: output.amplitude == Amplitude::ZERO,
        };
        if self.mode == Mode::Scripted {
            self.judge.observe(&observation);
        }
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
            drive_hz: truth.drive_hz,
            resonance_hz: truth.resonance_hz,
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

    /// Applies an operator's command to the loop between two periods ([`Station::execute`];
    /// `tare` and `cal` read the scene's simulated cells under the load they name). Refused
    /// as `wrong-state` in [`Mode::Scripted`].
    pub fn execute(&mut self, command: &Command) -> Result<(), ProtocolError> {
        if self.mode == Mode::Scripted {
            return Err(ProtocolError::WrongState {
                command: command.keyword(),
                state: self.station.state(),
            });
        }
        let mut bench = SimulatedCells {
            scene: &self.scene,
            burst: self.plant.steps(),
        };
        self.station.execute(command, &mut bench)
    }

    /// Latches an external fault (a control-loop overrun, an overcurrent trip) in the
    /// controller: the next step drives zero. Accepted in either mode.
    pub fn trip(&mut self, fault: ExternalFault) {
        self.station.controller_mut().trip(fault);
    }

    /// Who gives the targets.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// The control side (cells, controller, model, drive frequency).
    pub fn station(&self) -> &Station {
        &self.station
    }

    /// The control side, to put stored settings into it ([`crate::settings::apply`]).
    pub fn station_mut(&mut self) -> &mut Station {
        &mut self.station
    }

    /// The controller (its configuration and state).
    pub fn controller(&self) -> &Controller {
        self.station.controller()
    }

    /// The plant.
    pub fn plant(&self) -> &Plant<'a, AnyModel> {
        &self.plant
    }
}

/// The scene's cells as a [`CellBench`]: settled on the load a command names, with their
/// offset, gain error, noise and quantisation, and a noise generator of their own per burst
/// (seeded from the scene and the plant's step count, so a run stays deterministic).
struct SimulatedCells<'s, 'a> {
    scene: &'s Scene<'a>,
    burst: u32,
}

impl CellBench for SimulatedCells<'_, '_> {
    fn burst(&mut self, axis: Axis, load_n: f32, codes: &mut [AdcCode]) -> bool {
        let (cell, index) = match axis {
            Axis::Normal => (&self.scene.normal_cell, 2u64),
            Axis::Tangential => (&self.scene.tangential_cell, 3u64),
        };
        let seed = self
            .scene
            .noise_seed
            .wrapping_add(u64::from(self.burst).wrapping_mul(0x9E37_79B9_7F4A_7C15))
            .wrapping_add(index);
        let mut noise = Gaussian::from_seed(seed);
        let mut sim = LoadCellSim::new(cell, 1e-4, load_n);
        for code in codes.iter_mut() {
            *code = sim.sample(&mut noise, None);
        }
        self.burst = self.burst.wrapping_add(1);
        true
    }
}

/// Whether the piecewise-linear `profile` changes at `t_s` (between two breakpoints of
/// different values), with the breakpoints in `f32` as [`sonolube::scene::interpolate`] uses them.
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
