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

use crate::{drive, time_driver};

/// The simulated rig running one scene.
pub struct SimulatedRig {
    /// The scene the run was started with: the one the settings' defaults use.
    home: &'static Scene<'static>,
    scene: &'static Scene<'static>,
    run: ClosedLoop<'static>,
    /// No command has changed the loop since it was built: settings for its scene go straight
    /// into it, without building another.
    pristine: bool,
}

impl SimulatedRig {
    /// The rig of `scene`: playing its script ([`Mode::Scripted`]) or under the console
    /// ([`Mode::Operated`]).
    pub fn new(scene: &'static Scene<'static>, mode: Mode) -> Result<Self, SimError> {
        let run = match mode {
            Mode::Scripted => ClosedLoop::new(scene)?,
            Mode::Operated => ClosedLoop::operated(scene)?,
        };
        Ok(Self {
            home: scene,
            scene,
            run,
            pristine: true,
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
        let station = self.run.station();
        match station.selection() {
            Some(selection) => {
                defmt::info!("scene {=str}: controller {}", self.scene.name, selection)
            }
            None => defmt::info!(
                "scene {=str}: controller model {} (given, not selected)",
                self.scene.name,
                station.model().kind()
            ),
        }
    }

    /// The judge's summary of the steps so far.
    pub fn summary(&self) -> RunSummary {
        time_driver::exclude(|| self.run.summary())
    }

    /// `scene NAME` under the console: a new rig with that scene's plant and station, when
    /// the drive is off.
    fn select_scene(&mut self, command: &Command, name: SceneName) -> Result<(), ProtocolError> {
        use sonolube::protocol::SupervisorState::{Boot, Fault, Idle};
        let state = self.run.controller().state();
        if !matches!(state, Idle | Fault | Boot) {
            return Err(ProtocolError::WrongState {
                command: command.keyword(),
                state,
            });
        }
        let unknown = ProtocolError::UnknownScene { name };
        let Some(scene) = sonolube::scene::builtin::find(name.as_str()) else {
            return Err(unknown);
        };
        let run = time_driver::exclude(|| ClosedLoop::operated(scene));
        match run {
            Ok(run) => {
                // What cannot work is refused before it runs (issue 26); the built-in scenes
                // all pass (`sonolube::scene::feasibility` tests).
                let feasibility = run.station().feasibility(scene);
                for finding in feasibility.findings() {
                    defmt::warn!("scene {=str}: {}", name.as_str(), finding);
                }
                if let Some(refusal) = feasibility.refusal() {
                    return Err(ProtocolError::Unavailable {
                        command: command.keyword(),
                        reason: refusal.summary(),
                    });
                }
                self.scene = scene;
                self.run = run;
                self.pristine = true;
                self.log_model();
                Ok(())
            }
            Err(error) => {
                defmt::error!("scene {=str} cannot run: {}", name.as_str(), error);
                Err(unknown)
            }
        }
    }
}

/// The settings store's view of the rig (`sonolube_app::persist`).
impl Persistent for SimulatedRig {
    fn capture(&self) -> Record {
        sonolube::settings::capture(self.run.station(), self.scene.name, 0)
    }

    /// A new loop for the record's scene (the run's own scene when it has none) with the
    /// record's calibrations, drive frequency and target; swapped in only when all applied.
    fn apply(&mut self, record: &Record) -> Result<(), ProtocolError> {
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
            time_driver::exclude(|| sonolube::settings::apply(self.run.station_mut(), record))?;
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
        time_driver::exclude(|| sonolube::settings::apply(run.station_mut(), record))?;
        let changed = !core::ptr::eq(scene, self.scene);
        self.scene = scene;
        self.run = run;
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
            .with_reach(self.run.station().run_reach()),
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
