//! The control loop on the simulated rig, and in the failure test builds (features
//! `panic-test`, `watchdog-test`) the rig failing half-way through the scene on purpose, so
//! that `scripts/test` can check that each failure is reported. The production loop
//! (`sonolube_app::control::run`) has no test hook: a test build wraps the rig instead.

use sonolube::protocol::{Command, ProtocolError};
use sonolube_app::control::{self, ControlLoop, LoopStats};
use sonolube_app::snapshot::Snapshot;

use crate::drive;

/// The rig, failing at step `fail_at`: `panic-test` panics in the control task with the drive
/// on; `watchdog-test` ends the loop there, and the task then hangs.
struct Failing<'a, R> {
    rig: &'a mut R,
    fail_at: u32,
    taken: u32,
    hung: bool,
}

impl<R: ControlLoop> ControlLoop for Failing<'_, R> {
    const CYCLE_HZ: u64 = R::CYCLE_HZ;

    fn rate_hz(&self) -> u32 {
        self.rig.rate_hz()
    }

    fn step(&mut self) -> Option<Snapshot> {
        let snapshot = self.rig.step()?;
        self.taken = self.taken.saturating_add(1);
        if self.taken == self.fail_at {
            if cfg!(feature = "panic-test") {
                defmt::warn!(
                    "test build: panicking in the control task, drive {}",
                    drive::state()
                );
                panic!("deliberate panic at control step {}", self.taken);
            }
            if cfg!(feature = "watchdog-test") {
                self.hung = true;
                return None;
            }
        }
        Some(snapshot)
    }

    fn execute(&mut self, command: &Command) -> Result<(), ProtocolError> {
        self.rig.execute(command)
    }

    fn trip_overrun(&mut self) {
        self.rig.trip_overrun()
    }

    fn target_warning(&self) -> Option<sonolube::protocol::Target> {
        self.rig.target_warning()
    }
}

/// Runs the control loop on `rig` until the scene's `steps` are taken; a failure test build
/// fails half-way instead.
pub async fn run<R: ControlLoop>(rig: &mut R, steps: u32) -> LoopStats {
    if !cfg!(any(feature = "panic-test", feature = "watchdog-test")) {
        return control::run(rig).await;
    }
    let mut failing = Failing {
        rig,
        fail_at: steps / 2,
        taken: 0,
        hung: false,
    };
    let stats = control::run(&mut failing).await;
    if failing.hung {
        defmt::warn!("test build: the control task hangs");
        core::future::pending::<()>().await;
    }
    stats
}
