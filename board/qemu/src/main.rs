//! Sonolube firmware for QEMU's mps2-an386 (Cortex-M4F at 25 MHz): the simulated board.
//!
//! Boots, starts the SysTick time driver and a WFI executor, and runs the application's tasks
//! (see `sonolube_app`). The run's verdict is the exit status of QEMU (see `exit.rs`).
//!
//! A watchdog keeper feeds the CMSDK watchdog only while the heartbeat advances; a stalled
//! heartbeat gets an NMI (drive safe) and then a reset, and the next boot reports it.
//!
//! Test builds (cargo features) fail on purpose half-way through the run, so that the test
//! command can check each failure is reported: `fail-selfcheck` stalls the heartbeat once (the
//! self-check must fail), `hang` blocks the executor forever with the watchdog off (the runner's
//! timeout must end the run), `watchdog-test` blocks it with the watchdog on (the watchdog must
//! reset the machine and the next boot must report it), `panic-test` enables the drive and
//! panics (the drive must be safe before the report).
#![no_std]
#![no_main]

mod bench;
mod drive;
mod executor;
mod exit;
mod scene_run;
mod time_driver;
mod watchdog;

use defmt_semihosting as _;
use embassy_executor::raw;
use embassy_time::{Duration, Instant};
use sonolube_app::{Board, heartbeat};
use static_cell::StaticCell;

defmt::timestamp!("{=u64:us}", Instant::now().as_micros());

/// The QEMU mps2-an386 board.
struct Qemu;

impl Board for Qemu {
    const NAME: &'static str = "qemu mps2-an386";

    fn drive_safe() {
        drive::force_safe();
    }

    fn finish(passed: bool) -> ! {
        exit::exit(if passed {
            exit::PASS
        } else {
            exit::SELFCHECK_FAILED
        })
    }
}

/// In test builds, fails in the way the build's feature names, half-way through the run.
fn inject_test_failure(wakeups: u32) {
    const AT: u32 = heartbeat::WAKEUPS_PER_REPORT * heartbeat::REPORTS / 2;
    if wakeups != AT {
        return;
    }
    if cfg!(feature = "fail-selfcheck") {
        defmt::warn!("test build: stalling the heartbeat for 3 ms");
        embassy_time::block_for(Duration::from_millis(3));
    }
    if cfg!(feature = "panic-test") {
        drive::set(u32::MAX / 4);
        defmt::warn!("test build: drive {} and panicking", drive::state());
        panic!("deliberate panic after {} heartbeats", wakeups);
    }
    if cfg!(any(feature = "hang", feature = "watchdog-test")) {
        defmt::warn!("test build: blocking the executor forever");
        #[allow(clippy::empty_loop)]
        loop {}
    }
}

#[embassy_executor::task]
async fn heartbeat_task() {
    heartbeat::heartbeat(inject_test_failure).await
}

/// Watchdog timeout: an NMI after this long without progress of the heartbeat, a reset after
/// twice this long.
const WATCHDOG_TIMEOUT_MS: u32 = 20;

#[embassy_executor::task]
async fn watchdog_task() {
    let mut last = heartbeat::alive_count();
    loop {
        embassy_time::Timer::after_millis(u64::from(WATCHDOG_TIMEOUT_MS / 4)).await;
        let now = heartbeat::alive_count();
        if now != last {
            watchdog::feed();
            last = now;
        }
    }
}

/// The scene the firmware runs after its self-check.
const DEFAULT_SCENE: &str = "reference";

#[embassy_executor::task]
async fn supervisor_task() {
    if !heartbeat::self_check::<Qemu>().await {
        exit::exit(exit::SELFCHECK_FAILED);
    }
    let Some(scene) = sonolube::scene::builtin::find(DEFAULT_SCENE) else {
        defmt::error!("no scene named {=str}", DEFAULT_SCENE);
        exit::exit(exit::SELFCHECK_FAILED);
    };
    let passed = if cfg!(feature = "bench") {
        bench::run()
    } else {
        scene_run::run(scene).await
    };
    Qemu::finish(passed)
}

#[cortex_m_rt::entry]
fn main() -> ! {
    Qemu::drive_safe();
    let Some(core) = cortex_m::Peripherals::take() else {
        exit::exit(exit::FAULT);
    };
    time_driver::init(core.SYST);
    if watchdog::take_reset_mark() {
        defmt::error!("the previous run ended in a watchdog reset");
        exit::exit(exit::WATCHDOG_RESET);
    }
    if !cfg!(feature = "hang") {
        watchdog::start(WATCHDOG_TIMEOUT_MS);
    }
    defmt::info!(
        "sonolube {} on {}, core clock {=u64} Hz",
        env!("CARGO_PKG_VERSION"),
        Qemu::NAME,
        time_driver::CORE_CLOCK_HZ
    );

    static EXECUTOR: StaticCell<raw::Executor> = StaticCell::new();
    let executor = EXECUTOR.init(raw::Executor::new(core::ptr::null_mut()));
    executor::run(executor, |spawner| {
        match (heartbeat_task(), supervisor_task(), watchdog_task()) {
            (Ok(heartbeat), Ok(supervisor), Ok(watchdog)) => {
                spawner.spawn(heartbeat);
                spawner.spawn(supervisor);
                spawner.spawn(watchdog);
            }
            _ => {
                defmt::error!("could not spawn the tasks");
                exit::exit(exit::FAULT);
            }
        }
    })
}
