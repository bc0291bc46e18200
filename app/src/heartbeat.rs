//! Boot self-check: a periodic heartbeat task timed by a supervisor task.
//!
//! `heartbeat` wakes on an `embassy_time::Ticker`, timestamps each wake-up into a
//! [`PeriodMonitor`], and every [`WAKEUPS_PER_REPORT`] wake-ups sends its statistics over a
//! channel. `supervisor` logs each report and, after [`REPORTS`] of them, judges the run: it
//! proves that the time driver, the executor and the channel work together before anything is
//! allowed to drive the transducer.

use core::sync::atomic::{AtomicU32, Ordering};

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_time::{Duration, Instant, Ticker};
use sonolube::selfcheck::{PeriodMonitor, PeriodVerdict};

use crate::Board;

/// Heartbeat rate, in Hz.
pub const HEARTBEAT_HZ: u64 = 1_000;
/// The heartbeat reports every this many wake-ups.
pub const WAKEUPS_PER_REPORT: u32 = 100;
/// Reports the supervisor waits for before judging the run.
pub const REPORTS: u32 = 5;
/// Largest lateness of one wake-up that still passes, in microseconds.
pub const MAX_LATE_US: u64 = 20;

/// What the heartbeat tells the supervisor.
#[derive(Clone, Copy)]
pub struct Report {
    /// Wake-ups so far.
    pub wakeups: u32,
    /// Timing statistics so far.
    pub monitor: PeriodMonitor,
}

static REPORTS_CHANNEL: Channel<CriticalSectionRawMutex, Report, 2> = Channel::new();

/// Wake-ups of the heartbeat so far: a watchdog keeper feeds the watchdog only while this
/// advances, so a stalled heartbeat (or executor) ends in a watchdog reset.
static ALIVE: AtomicU32 = AtomicU32::new(0);

/// Number of heartbeat wake-ups so far (wraps).
pub fn alive_count() -> u32 {
    ALIVE.load(Ordering::Relaxed)
}

/// The heartbeat task body: runs for the self-check's [`REPORTS`] reports, then returns (the
/// control loop is the sign of life after that). `on_wakeup` is called with the wake-up count
/// after each wake-up (boards use it to inject failures in test builds); it may block.
pub async fn heartbeat(mut on_wakeup: impl FnMut(u32)) {
    let period = Duration::from_hz(HEARTBEAT_HZ);
    let mut ticker = Ticker::every(period);
    let mut monitor = PeriodMonitor::new(
        period.as_ticks(),
        Duration::from_micros(MAX_LATE_US).as_ticks(),
    );
    let mut wakeups: u32 = 0;
    while wakeups < WAKEUPS_PER_REPORT * REPORTS {
        ticker.next().await;
        monitor.record(Instant::now().as_ticks());
        wakeups = wakeups.saturating_add(1);
        ALIVE.fetch_add(1, Ordering::Relaxed);
        on_wakeup(wakeups);
        if wakeups.is_multiple_of(WAKEUPS_PER_REPORT) {
            REPORTS_CHANNEL.send(Report { wakeups, monitor }).await;
        }
    }
}

/// Waits for the heartbeat's reports, logs them and judges the run: true when the self-check
/// passed (the verdict is logged either way).
pub async fn self_check<B: Board>() -> bool {
    let mut last: Option<Report> = None;
    for _ in 0..REPORTS {
        let report = REPORTS_CHANNEL.receive().await;
        let m = &report.monitor;
        defmt::info!(
            "heartbeat: {=u32} wake-ups, interval min {=u64} max {=u64} ticks, {=u32} overruns",
            report.wakeups,
            m.min_interval().unwrap_or(0),
            m.max_interval().unwrap_or(0),
            m.overruns()
        );
        last = Some(report);
    }
    let verdict = match last {
        Some(report) => report.monitor.verdict(report.wakeups.saturating_sub(1)),
        None => PeriodVerdict::TooFewIntervals {
            seen: 0,
            required: 1,
        },
    };
    if verdict == PeriodVerdict::Pass {
        defmt::info!("self-check passed on {}: {}", B::NAME, verdict);
        true
    } else {
        defmt::error!("self-check FAILED on {}: {}", B::NAME, verdict);
        false
    }
}

/// The supervisor task body: the self-check, then the end of the run with its verdict.
pub async fn supervisor<B: Board>() -> ! {
    B::finish(self_check::<B>().await)
}
