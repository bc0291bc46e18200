//! The QEMU board's control loop: the firmware's station on the simulated plant.
//!
//! Each period the plant advances with what the drive output holds ([`crate::drive`]) and
//! gives its converter codes; the station (cells, controller, model) computes the next drive
//! command, which goes to the drive output. The plant's computation, and the scene judge's,
//! run inside [`time_driver::exclude`]: they stand for hardware and for the test bench, so
//! they take none of the firmware's time. Only the control part is timed for the snapshot.
//!
//! This is [`sonolube_sim::ClosedLoop`], the same code as `sonolube scene` on the host, with
//! the plant reading the board's drive output instead of the controller's command directly.

use sonolube::control::{ExternalFault, Reason};
use sonolube::protocol::{Command, ProtocolError, SceneName, SupervisorState};
use sonolube::scene::Scene;
use sonolube::settings::Record;
use sonolube_app::control::ControlLoop;
use sonolube_app::persist::Persistent;
use sonolube_app::snapshot::Snapshot;
use sonolube_sim::{ClosedLoop, Mode, RunSummary, SimError};

use crate::stage::{self, ModelLine, Slot};
use crate::{drive, time_driver};

/// The simulated rig running one scene.
pub struct SimulatedRig {
    /// The scene the run was started with: the one the settings' defaults use.
    home: &'static Scene<'static>,
    scene: &'static Scene<'static>,
    /// The loop, in one of the two static slots: a `scene` load swaps it with the loop the
    /// console prepared in the other ([`crate::stage`]), never copies it.
    run: Slot,
    /// No command has changed the loop since it was built: settings for its scene go straight
    /// into it, without building another.
    pristine: bool,
    /// `run` is the scene's simulated rig, commissioning; the scene's run follows.
    commissioning: bool,
}

impl SimulatedRig {
    /// The rig of `scene`: playing its script ([`Mode::Scripted`]) or under the console
    /// ([`Mode::Operated`]).
    ///
    /// A scripted scene with `commission = true` starts on its simulated rig with `commission`
    /// given ([`sonolube_sim::start_rig_commission`]): the firmware's control loop runs the
    /// sequence period by period, then the scene's run is built on the measured values
    /// ([`ClosedLoop::with_commissioned`]), the same as the host's `commission_rig` and
    /// `ClosedLoop::new`.
    ///
    /// `place` puts the built loop in one of the two static slots.
    pub fn new(
        scene: &'static Scene<'static>,
        mode: Mode,
        place: impl FnOnce(ClosedLoop<'static>) -> Slot,
    ) -> Result<Self, SimError> {
        let commissioning = mode == Mode::Scripted && scene.commission;
        let rig_scene = sonolube_sim::rig_scene(scene);
        let mut run = match mode {
            Mode::Scripted if commissioning => ClosedLoop::operated(&rig_scene)?,
            Mode::Scripted => ClosedLoop::new(scene)?,
            Mode::Operated => ClosedLoop::operated(scene)?,
        };
        if commissioning {
            sonolube_sim::start_rig_commission(&mut run)?;
        }
        let run = place(run);
        Ok(Self {
            home: scene,
            scene,
            run,
            pristine: true,
            commissioning,
        })
    }

    /// The same rig, with `home` as the scene the settings' defaults use.
    pub fn with_home(mut self, home: &'static Scene<'static>) -> Self {
        self.home = home;
        self
    }

    /// The scene.
    pub fn scene(&self) -> &'static Scene<'static> {
        self.scene
    }

    /// Logs the model variant the controller runs and why ([`sonolube::variant::select`]), at
    /// scene start.
    pub fn log_model(&self) {
        ModelLine::of(self.scene.name, self.run).log();
    }

    /// After a commissioning period: when the sequence has ended, the scene's run on the
    /// measured values replaces the rig (the watchdog fed on either side of the build, as for
    /// `load`); a refusal ends the run as a failure.
    fn after_commissioning_period(&mut self) {
        let Some(outcome) = sonolube_sim::rig_commission_outcome(self.run) else {
            return;
        };
        self.commissioning = false;
        let scene = self.scene;
        let built = outcome.and_then(|result| {
            crate::watchdog::feed();
            let built = time_driver::exclude(|| {
                ClosedLoop::with_commissioned(
                    scene,
                    sonolube::variant::select(scene),
                    sonolube_sim::COMMISSIONED,
                    Some(result),
                )
            });
            crate::watchdog::feed();
            built
        });
        match built {
            Ok(run) => {
                *self.run = run;
                drive::set(sonolube::drive::Amplitude::ZERO);
                self.log_commissioned();
            }
            Err(error) => {
                defmt::error!("scene {=str}: commissioning: {}", scene.name, error);
                crate::exit::exit(crate::exit::FAULT);
            }
        }
    }

    /// Logs what commissioning measured before the run (scenes with `commission = true`), as
    /// values and as `f64` bits (which `scripts/test` compares with the host's).
    pub fn log_commissioned(&self) {
        let Some(r) = self.run.commissioned() else {
            return;
        };
        defmt::info!(
            "scene {=str}: commissioned f0 {=f64} +- {=f64} Hz, Q {=f64} +- {=f64}, tau {=f64} +- {=f64} s, mu0 {=f64} +- {=f64}, {=u32} ring-down points",
            self.scene.name,
            r.resonance_hz.value,
            r.resonance_hz.standard_error,
            r.quality_factor.value,
            r.quality_factor.standard_error,
            r.time_constant_s.value,
            r.time_constant_s.standard_error,
            r.natural_coefficient.value,
            r.natural_coefficient.standard_error,
            r.ring_down_points
        );
        let bits =
            |m: sonolube::commission::Measured| (m.value.to_bits(), m.standard_error.to_bits());
        let (f0, q, tau, mu0) = (
            bits(r.resonance_hz),
            bits(r.quality_factor),
            bits(r.time_constant_s),
            bits(r.natural_coefficient),
        );
        defmt::info!(
            "scene {=str}: commissioned bits f0 {=u64:x} {=u64:x} q {=u64:x} {=u64:x} tau {=u64:x} {=u64:x} mu0 {=u64:x} {=u64:x}",
            self.scene.name,
            f0.0,
            f0.1,
            q.0,
            q.1,
            tau.0,
            tau.1,
            mu0.0,
            mu0.1
        );
    }

    /// The judge's summary of the steps so far.
    pub fn summary(&self) -> RunSummary {
        time_driver::exclude(|| self.run.summary())
    }

    /// `scene NAME` under the console, at a step boundary: the loop the console prepared
    /// ([`crate::stage::SceneStager`]) replaces the rig's when the drive is off. A swap of
    /// two references: the build, the feasibility check and the selection line were done in
    /// the console's task, out of the control step.
    fn select_scene(&mut self, command: &Command, name: SceneName) -> Result<(), ProtocolError> {
        let Some(staged) = stage::take_staged() else {
            return Err(ProtocolError::Unavailable {
                command: command.keyword(),
                reason: "the scene was not prepared",
            });
        };
        let state = self.run.controller().state();
        if !stage::drive_off(state) {
            stage::give_back(staged.run);
            return Err(ProtocolError::WrongState {
                command: command.keyword(),
                state,
            });
        }
        if staged.scene.name != name.as_str() {
            stage::give_back(staged.run);
            return Err(ProtocolError::Unavailable {
                command: command.keyword(),
                reason: "another scene was prepared",
            });
        }
        let previous = core::mem::replace(&mut self.run, staged.run);
        stage::give_back(previous);
        self.scene = staged.scene;
        self.pristine = true;
        Ok(())
    }
}

/// The settings store's view of the rig (`sonolube_app::persist`).
impl Persistent for SimulatedRig {
    fn capture(&self) -> Record {
        sonolube::settings::capture(self.run.station(), self.scene.name, 0)
    }

    fn commissioned(&self) -> Option<sonolube::commission::CommissionResult> {
        self.run.station().commissioned()
    }

    /// A new loop for the record's scene (the run's own scene when it has none) with the
    /// record's calibrations, drive frequency and target, and the commissioned values saved
    /// with it; swapped in only when all applied.
    fn apply(
        &mut self,
        record: &Record,
        commissioned: Option<&sonolube::commission::CommissionResult>,
    ) -> Result<(), ProtocolError> {
        if self.run.mode() != Mode::Operated {
            return Err(ProtocolError::WrongState {
                command: "load",
                state: self.run.controller().state(),
            });
        }
        let scene = match record.scene {
            Some(name) => sonolube::scene::builtin::find(name.as_str())
                .ok_or(ProtocolError::UnknownScene { name })?,
            None => self.home,
        };
        if self.pristine && core::ptr::eq(scene, self.scene) {
            // The boot's case: the loop was just built for this scene. Building another would
            // need a second loop on the stack next to this one.
            time_driver::exclude(|| {
                sonolube::settings::apply(self.run.station_mut(), record, commissioned)
            })?;
            self.pristine = false;
            return Ok(());
        }
        // Building a loop takes a large part of the watchdog timeout in QEMU's virtual time
        // (the plant's tables): the watchdog is fed on either side (the loop is alive: this is
        // a command, or the boot).
        crate::watchdog::feed();
        let built = time_driver::exclude(|| ClosedLoop::operated(scene));
        crate::watchdog::feed();
        let mut run = built.map_err(|error| {
            defmt::error!("scene {=str} cannot run: {}", scene.name, error);
            ProtocolError::SettingsInvalid {
                reason: "scene-cannot-run",
            }
        })?;
        time_driver::exclude(|| {
            sonolube::settings::apply(run.station_mut(), record, commissioned)
        })?;
        let changed = !core::ptr::eq(scene, self.scene);
        self.scene = scene;
        *self.run = run;
        self.pristine = false;
        if changed {
            self.log_model();
        }
        Ok(())
    }

    fn state(&self) -> SupervisorState {
        self.run.controller().state()
    }

    fn latched_fault(&self) -> Option<Reason> {
        self.run.controller().fault()
    }

    fn commission(&self) -> sonolube::station::CommissionReport {
        self.run.station().commission_report()
    }
}

impl ControlLoop for SimulatedRig {
    const CYCLE_HZ: u64 = time_driver::CORE_CLOCK_HZ;

    fn rate_hz(&self) -> u32 {
        self.scene.control_rate_hz as u32
    }

    fn step(&mut self) -> Option<Snapshot> {
        let drive_now = drive::plant_input();
        time_driver::exclude(|| self.run.plant_phase_driven(drive_now))?;
        let start = time_driver::cycles();
        let output = self.run.control_phase()?;
        drive::set(output.amplitude);
        let cycles = time_driver::cycles().saturating_sub(start);
        let record = time_driver::exclude(|| self.run.finish_step())?;
        if self.commissioning {
            self.after_commissioning_period();
        }
        Some(
            Snapshot::new(
                &output,
                self.run.controller().target(),
                self.scene.name,
                self.run.station().drive_freq_chz(),
                record
                    .sensor_fault
                    .map(|fault| sonolube::control::Reason::SensorFault(fault).name()),
                u32::try_from(cycles).unwrap_or(u32::MAX),
            )
            .with_resonance(self.run.station().resonance())
            .with_reach(self.run.station().run_reach())
            .with_commissioned(self.run.station().commissioned().is_some()),
        )
    }

    fn target_warning(&self) -> Option<sonolube::protocol::Target> {
        self.run.station().target_warning()
    }

    fn execute(&mut self, command: &Command) -> Result<(), ProtocolError> {
        self.pristine = false;
        match command {
            Command::Scene(name) if self.run.mode() == Mode::Operated => {
                self.select_scene(command, *name)
            }
            _ => time_driver::exclude(|| self.run.execute(command)),
        }
    }

    fn trip_overrun(&mut self) {
        self.run.trip(ExternalFault::Overrun);
    }
}
