//! The control task: one step per period on an `embassy_time::Ticker`, commands applied
//! between steps, overruns counted, snapshot and telemetry published.
//!
//! # Overruns
//!
//! A step overruns when it ends after the next tick is due (the period's deadline). Each one
//! is counted in [`link::OVERRUNS`] (reported by `status` and in every telemetry record) and
//! the ticker is re-aligned to now, so missed ticks are skipped rather than run in a burst.
//! [`OVERRUN_FAULT_RUN`] overruns in a row latch the controller's `overrun` fault: the drive
//! goes to zero until `clear`. The run is counted afresh after each trip ([`OverrunRun`]), so
//! a loop that still overruns after `clear` trips again [`OVERRUN_FAULT_RUN`] steps later.

use embassy_time::{Duration, Instant, Ticker};
use sonolube::protocol::{Command, ProtocolError};

use crate::link::{self, LOST, OVERRUNS, REQUESTS, RESPONSES, SNAPSHOT, STEPS, TELEMETRY};
use crate::snapshot::Snapshot;

/// Overruns in a row that latch the `overrun` fault.
pub const OVERRUN_FAULT_RUN: u32 = 3;

/// Overruns in a row, and when they latch the fault.
///
/// The count restarts at zero after a step on time and after each trip: `clear` acknowledges
/// the fault, and a loop that keeps overrunning after it must latch it again, not run on
/// with the fault cleared (a count that only grows would pass the trip value once and never
/// equal it again).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct OverrunRun {
    in_a_row: u32,
}

impl OverrunRun {
    /// Counts a step that overran; `true` when this one completes a run of
    /// [`OVERRUN_FAULT_RUN`] (the caller latches the fault), which starts the count afresh.
    pub fn overran(&mut self) -> bool {
        self.in_a_row += 1;
        if self.in_a_row >= OVERRUN_FAULT_RUN {
            self.in_a_row = 0;
            true
        } else {
            false
        }
    }

    /// Counts a step that ended before its deadline: the run is broken.
    pub fn on_time(&mut self) {
        self.in_a_row = 0;
    }

    /// Overruns in the current run.
    pub fn in_a_row(&self) -> u32 {
        self.in_a_row
    }
}

/// A board's control loop: its sensing, the station (cells, controller, model) and its drive.
pub trait ControlLoop {
    /// Rate of the cycle clock in which [`Snapshot::control_cycles`] is counted, Hz.
    const CYCLE_HZ: u64;
    /// The control rate, Hz (the scene's); read again after every command.
    fn rate_hz(&self) -> u32;
    /// One period: read the sensors, run the control part, set the drive. `None` when the job
    /// has ended (a scripted scene has taken its last step).
    fn step(&mut self) -> Option<Snapshot>;
    /// Applies a loop command between two steps, whole, or refuses it.
    fn execute(&mut self, command: &Command) -> Result<(), ProtocolError>;
    /// Latches the controller's overrun fault.
    fn trip_overrun(&mut self);
    /// After an accepted `target`: the value the full drive reaches now when the target is
    /// beyond it (the `warning=beyond-reach` of the reply); `None` by default.
    fn target_warning(&self) -> Option<sonolube::protocol::Target> {
        None
    }
}

/// What the loop measured over its run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, defmt::Format)]
pub struct LoopStats {
    /// Steps taken.
    pub steps: u32,
    /// Overrun steps.
    pub overruns: u32,
    /// Sum of the steps' control cycles.
    pub control_cycles_total: u64,
    /// Longest control part of a step, cycles.
    pub control_cycles_max: u32,
}

impl LoopStats {
    /// Mean control cycles per step, 0 before the first step.
    pub fn control_cycles_mean(&self) -> u64 {
        self.control_cycles_total
            .checked_div(u64::from(self.steps))
            .unwrap_or(0)
    }
}

/// Runs `control` until its job ends (its [`ControlLoop::step`] returns `None`); returns what
/// it measured. Test builds that fail on purpose wrap their loop in a [`ControlLoop`] of their
/// own (the QEMU board's `failure.rs`).
pub async fn run<L: ControlLoop>(control: &mut L) -> LoopStats {
    let mut stats = LoopStats::default();
    let mut rate_hz = control.rate_hz().max(1);
    let mut period = Duration::from_hz(u64::from(rate_hz));
    let mut ticker = Ticker::every(period);
    let mut tick_at = Instant::now() + period;
    let mut run_of_overruns = OverrunRun::default();
    let mut seq = 0u32;
    let mut since_record = 0u32;
    loop {
        ticker.next().await;
        let woke = Instant::now();
        // Between two steps: at most one command per period.
        if let Ok(command) = REQUESTS.try_receive() {
            let result = control.execute(&command);
            if result.is_ok() && matches!(command, Command::Target(_)) {
                let warning = control.target_warning();
                link::TARGET_WARNING.lock(|cell| cell.set(warning));
            }
            // The console waits for each answer before it sends the next request, so the
            // depth-1 queue is empty here.
            let _ = RESPONSES.try_send(result);
            if control.rate_hz().max(1) != rate_hz {
                rate_hz = control.rate_hz().max(1);
                period = Duration::from_hz(u64::from(rate_hz));
                ticker = Ticker::every(period);
                tick_at = Instant::now() + period;
                continue;
            }
        }
        let Some(snapshot) = control.step() else {
            return stats;
        };
        STEPS.fetch_add(1, core::sync::atomic::Ordering::Relaxed);
        stats.steps = stats.steps.saturating_add(1);
        stats.control_cycles_total += u64::from(snapshot.control_cycles);
        stats.control_cycles_max = stats.control_cycles_max.max(snapshot.control_cycles);
        SNAPSHOT.lock(|cell| cell.set(snapshot));
        if stats.steps == 1 {
            // The loop runs: the console may answer from now on.
            link::BOOTED.signal(());
        }

        let sample_at = tick_at;
        let deadline = tick_at + period;
        if Instant::now() >= deadline {
            link::bump(&OVERRUNS);
            stats.overruns = stats.overruns.saturating_add(1);
            // Rate-limited: the 1st, 2nd, 4th, 8th ... overrun is logged, with the total, so a
            // loop that overruns steadily cannot flood the log (and stall on it).
            if stats.overruns.is_power_of_two() {
                defmt::warn!(
                    "control overrun {=u32}: woke {=u64} us after its tick, step ended {=u64} us after the deadline, control part {=u32} cycles",
                    stats.overruns,
                    (woke - tick_at.min(woke)).as_micros(),
                    (Instant::now() - deadline).as_micros(),
                    snapshot.control_cycles
                );
            }
            if run_of_overruns.overran() {
                defmt::error!(
                    "{=u32} control overruns in a row: overrun fault",
                    OVERRUN_FAULT_RUN
                );
                control.trip_overrun();
            }
            ticker.reset();
            tick_at = Instant::now() + period;
        } else {
            run_of_overruns.on_time();
            tick_at = deadline;
        }

        // Steps per record: the rate rounded down to whole steps, at most one per step; none
        // while telemetry is off (rate 0).
        if let Some(every) = rate_hz.checked_div(link::count(&link::TELEMETRY_HZ)) {
            since_record += 1;
            if since_record >= every.max(1) {
                since_record = 0;
                let record = snapshot.record(
                    sample_at.as_micros(),
                    seq,
                    link::count(&OVERRUNS),
                    link::count(&LOST),
                );
                seq = seq.wrapping_add(1);
                if TELEMETRY.try_send(record).is_err() {
                    link::bump(&LOST);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Steps of a loop that overruns every period: which of them latch the fault.
    fn trips_of_steady_overruns(steps: u32) -> Vec<u32> {
        let mut run = OverrunRun::default();
        (1..=steps).filter(|_| run.overran()).collect()
    }

    #[test]
    fn a_steady_overrun_trips_every_run_of_three_so_again_after_clear() {
        // Every step overruns: the fault latches at step 3; `clear` between steps 3 and 4
        // (the loop runs on, still overrunning) must see it latch again at step 6, and so on.
        assert_eq!(OVERRUN_FAULT_RUN, 3);
        assert_eq!(trips_of_steady_overruns(10), vec![3, 6, 9]);
    }

    #[test]
    fn a_step_on_time_breaks_the_run() {
        let mut run = OverrunRun::default();
        assert!(!run.overran());
        assert!(!run.overran());
        run.on_time();
        assert_eq!(run.in_a_row(), 0);
        assert!(!run.overran());
        assert!(!run.overran());
        assert!(run.overran());
        assert_eq!(run.in_a_row(), 0);
    }
}
