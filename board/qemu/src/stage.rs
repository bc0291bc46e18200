//! `scene NAME` prepared out of the control step.
//!
//! On this board commands run inside a control step: the control task applies a queued
//! command right after its tick, before the step. A scene load there (the loop's build, its
//! feasibility check, the selection line and a copy of the whole loop into the rig) overran
//! that step by about 60 us at every switch. So the load is split:
//!
//! - the console's task ([`SceneStager::prepare`], thread mode: the control task preempts it)
//!   builds the new scene's loop into the spare of two static loop slots, checks its
//!   feasibility and remembers its selection line;
//! - the control task ([`crate::rig::SimulatedRig`]'s `scene` command) only swaps the rig's
//!   slot with the staged one at the step boundary, when the drive is still off, and hands the
//!   old slot back ([`take_staged`], [`give_back`]);
//! - the console's task then logs the selection line ([`SceneStager::answered`]).
//!
//! The loop's build stays out of the firmware's clock ([`time_driver::exclude`]): it is mostly
//! the simulated plant's tables, which stand for the rig's hardware. The feasibility check and
//! the log are the firmware's own work and count in its time, in the console's task. The log
//! line still masks interrupts while defmt encodes it (defmt-semihosting writes a frame in a
//! critical section), so it can delay one tick by its length; the step's slack takes that
//! (a step is at most 6,400 of the 25,000 instructions of a 10 kHz period at the default
//! `icount` shift 2, docs/speed.md), where the same line inside the step overran it.

use core::cell::RefCell;

use critical_section::Mutex;
use sonolube::protocol::{Command, ProtocolError, SupervisorState};
use sonolube::scene::ModelKind;
use sonolube::scene::Scene;
use sonolube::variant::Selection;
use sonolube_app::console::Prepare;
use sonolube_sim::ClosedLoop;

use crate::time_driver;

/// One of the two loop slots (statics in `main.rs`): the rig runs one, the stager holds the
/// other as its spare.
pub type Slot = &'static mut ClosedLoop<'static>;

/// A scene's loop, built and checked, waiting for the control task.
pub struct Staged {
    /// The scene the loop was built for.
    pub scene: &'static Scene<'static>,
    /// Its loop.
    pub run: Slot,
}

/// Prepared by the console's task, taken by the control task at a step boundary.
static STAGED: Mutex<RefCell<Option<Staged>>> = Mutex::new(RefCell::new(None));
/// The slot the control task gave back: the previous scene's loop, or a staged loop it refused.
static FREED: Mutex<RefCell<Option<Slot>>> = Mutex::new(RefCell::new(None));

/// The staged loop, if any (the control task, at a step boundary).
pub fn take_staged() -> Option<Staged> {
    critical_section::with(|cs| STAGED.borrow_ref_mut(cs).take())
}

/// Hands a slot back to the stager (the control task, after a swap or a refusal).
pub fn give_back(slot: Slot) {
    critical_section::with(|cs| *FREED.borrow_ref_mut(cs) = Some(slot));
}

/// Whether a `scene` command may replace the loop in `state`: only with the drive off.
pub fn drive_off(state: SupervisorState) -> bool {
    matches!(
        state,
        SupervisorState::Idle | SupervisorState::Fault | SupervisorState::Boot
    )
}

/// What the selection line of a scene says ([`log_model`]), kept from the prepared loop.
#[derive(Debug, Clone, Copy)]
pub struct ModelLine {
    scene: &'static str,
    selection: Option<Selection>,
    kind: ModelKind,
}

impl ModelLine {
    /// The line of `run`, the loop of the scene named `scene`.
    pub fn of(scene: &'static str, run: &ClosedLoop<'_>) -> Self {
        let station = run.station();
        Self {
            scene,
            selection: station.selection().copied(),
            kind: station.model().kind(),
        }
    }

    /// Logs the model variant the controller runs and why ([`sonolube::variant::select`]).
    pub fn log(&self) {
        match &self.selection {
            Some(selection) => defmt::info!("scene {=str}: controller {}", self.scene, selection),
            None => defmt::info!(
                "scene {=str}: controller model {} (given, not selected)",
                self.scene,
                self.kind
            ),
        }
    }
}

/// The console's side of `scene NAME` ([`Prepare`]).
pub struct SceneStager {
    /// The spare slot; `None` on a scripted run, where the rig refuses `scene` itself.
    spare: Option<Slot>,
    /// The selection line of the staged scene, logged once the control task took it.
    line: Option<ModelLine>,
}

impl SceneStager {
    /// The stager holding `spare`, the slot the rig does not run (`None`: stage nothing).
    pub fn new(spare: Option<Slot>) -> Self {
        Self { spare, line: None }
    }

    /// Takes back every slot the control task is not running.
    fn reclaim(&mut self) {
        let freed = critical_section::with(|cs| FREED.borrow_ref_mut(cs).take());
        if let Some(slot) = freed {
            self.spare = Some(slot);
        }
        if let Some(staged) = take_staged() {
            self.spare = Some(staged.run);
        }
    }
}

impl Prepare for SceneStager {
    fn prepare(&mut self, command: &Command) -> Result<(), ProtocolError> {
        let Command::Scene(name) = *command else {
            return Ok(());
        };
        let Some(spare) = self.spare.as_mut() else {
            return Ok(());
        };
        // Refused early with the drive on (the control task checks again when it swaps: the
        // state may change in between).
        let state = sonolube_app::link::snapshot().reading.state;
        if !drive_off(state) {
            return Err(ProtocolError::WrongState {
                command: command.keyword(),
                state,
            });
        }
        let unknown = ProtocolError::UnknownScene { name };
        let scene = sonolube::scene::builtin::find(name.as_str()).ok_or(unknown)?;
        // Building a loop takes a large part of the watchdog timeout in QEMU's virtual time
        // (the plant's tables, out of the firmware's clock): the watchdog is fed on either
        // side. Built in place: the 25 KB loop is never copied.
        crate::watchdog::feed();
        let built = time_driver::exclude(|| {
            ClosedLoop::operated(scene).map(|run| {
                **spare = run;
            })
        });
        crate::watchdog::feed();
        if let Err(error) = built {
            defmt::error!("scene {=str} cannot run: {}", name.as_str(), error);
            return Err(unknown);
        }
        // What cannot work is refused before it runs (issue 26); the built-in scenes all pass
        // (`sonolube::scene::feasibility` tests). About 2.5 ms of soft f64 at 25 MHz, in this
        // task: the control task preempts it.
        if let Some(refusal) = spare.station().feasibility(scene).refusal() {
            return Err(ProtocolError::Unavailable {
                command: command.keyword(),
                reason: refusal.summary(),
            });
        }
        self.line = Some(ModelLine::of(scene.name, spare));
        if let Some(run) = self.spare.take() {
            critical_section::with(|cs| *STAGED.borrow_ref_mut(cs) = Some(Staged { scene, run }));
        }
        Ok(())
    }

    fn answered(&mut self, command: &Command, result: &Result<(), ProtocolError>) {
        if !matches!(command, Command::Scene(_)) {
            return;
        }
        self.reclaim();
        let line = self.line.take();
        if let (Ok(()), Some(line)) = (result, line) {
            line.log();
        }
    }
}
