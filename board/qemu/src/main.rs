//! Sonolube firmware for QEMU's mps2-an386 (Cortex-M4F at 25 MHz): the simulated board.
//!
//! Boots, starts the SysTick time driver, the control executor (a software interrupt above
//! everything else) and a WFI thread executor, and runs the application's tasks (see
//! `sonolube_app`): the boot self-check, then the control loop on the simulated plant of a
//! scene (`rig.rs`), the console on UART0 and the watchdog keeper. The run's verdict is the
//! exit status of QEMU (see `exit.rs`).
//!
//! What runs is chosen by QEMU's `-append` words (`args.rs`): by default the `reference`
//! scene's script, judged, then exit; `scene=NAME` another scene; `serve` the console drives
//! the plant and the run goes on until QEMU is stopped; `flash=FILE` keeps the settings (`save`,
//! `load`, `defaults`, `log`) in that host file (`flash.rs`), loaded and checked at boot.
//!
//! Test builds (cargo features) fail on purpose, so that the test command can check each
//! failure is reported: `fail-selfcheck` stalls the heartbeat once (the self-check must fail),
//! `hang` blocks the executor forever with the watchdog off (the runner's timeout must end the
//! run), `watchdog-test` hangs the control task half-way through the scene with the watchdog
//! on (the keeper must stop feeding, the watchdog reset the machine and the next boot report
//! it), `panic-test` panics in the control task half-way through the scene (the drive, which
//! is the plant's input, must be safe before the report).
#![no_std]
#![no_main]

mod args;
mod bench;
mod drive;
mod executor;
mod exit;
mod failure;
mod flash;
mod irq;
mod report;
mod rig;
mod stage;
mod time_driver;
mod uart;
mod watchdog;

use defmt_semihosting as _;
use embassy_executor::{SendSpawner, raw};
use embassy_time::{Duration, Instant};
use sonolube::settings::{Source, boot};
use sonolube_app::console::Identity;
use sonolube_app::persist::Persisted;
use sonolube_app::{Board, console, heartbeat, supervisor};
use sonolube_sim::Mode;
use static_cell::StaticCell;

use crate::args::Args;
use crate::flash::FileFlash;
use crate::rig::SimulatedRig;

/// The control loop: the simulated rig with its settings store.
type Rig = Persisted<SimulatedRig, FileFlash>;

fn known_scene(name: &str) -> bool {
    sonolube::scene::builtin::find(name).is_some()
}

/// The settings store of the run (`flash=FILE`), with the power cut armed (`cut=N`); `None`
/// without a flash file. A file that cannot be opened ends the run.
fn settings_store(args: &Args) -> Option<sonolube::settings::Store<FileFlash>> {
    let path = args.flash?;
    if let Some(n) = args.cut {
        flash::cut_power_after(n);
    }
    match flash::open_store(path) {
        Ok(store) => Some(store),
        Err(error) => {
            defmt::error!("settings flash {=str} cannot be opened: {}", path, error);
            exit::exit(exit::SELFCHECK_FAILED);
        }
    }
}

defmt::timestamp!("{=u64:us}", Instant::now().as_micros());

/// The QEMU mps2-an386 board.
struct Qemu;

impl Board for Qemu {
    const NAME: &'static str = "qemu-mps2-an386";

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

/// In test builds, fails the boot self-check in the way the build's feature names.
fn inject_boot_failure(wakeups: u32) {
    const AT: u32 = heartbeat::WAKEUPS_PER_REPORT * heartbeat::REPORTS / 2;
    if wakeups != AT {
        return;
    }
    if cfg!(feature = "fail-selfcheck") {
        defmt::warn!("test build: stalling the heartbeat for 3 ms");
        embassy_time::block_for(Duration::from_millis(3));
    }
    if cfg!(feature = "hang") {
        defmt::warn!("test build: blocking the executor forever");
        #[allow(clippy::empty_loop)]
        loop {}
    }
}

#[embassy_executor::task]
async fn heartbeat_task() {
    heartbeat::heartbeat(inject_boot_failure).await
}

/// Watchdog timeout: an NMI after this long without a feed, a reset after twice this long.
/// QEMU's watchdog counts virtual time, which includes the simulated plant's computation
/// (left out of the firmware's clock: a period of the reference scene's Dahl plant costs about
/// five periods of virtual time), so this is far longer than a real board's.
const WATCHDOG_TIMEOUT_MS: u32 = 200;
/// The keeper looks for signs of life this often (firmware time).
const KEEPER_EVERY_MS: u64 = 5;

#[embassy_executor::task]
async fn supervisor_task(args: Args, control_spawner: SendSpawner) {
    if !heartbeat::self_check::<Qemu>().await {
        exit::exit(exit::SELFCHECK_FAILED);
    }
    if cfg!(feature = "bench") {
        Qemu::finish(bench::run());
    }
    let Some(home) = sonolube::scene::builtin::find(args.scene) else {
        defmt::error!("no scene named {=str}", args.scene);
        exit::exit(exit::SELFCHECK_FAILED);
    };
    // The settings first: a stored scene is the one the loop is built for.
    let mut store = settings_store(&args);
    let booted = store
        .as_mut()
        .map(|store| embassy_futures::block_on(boot(store, false, known_scene)));
    let scene = booted
        .as_ref()
        .filter(|booted| booted.source == Source::Stored && args.serve)
        .and_then(|booted| booted.record.scene)
        .and_then(|name| sonolube::scene::builtin::find(name.as_str()))
        .unwrap_or(home);
    // `commission`: the scene as if it had `commission = true`, in a static (the rig keeps
    // `'static` scenes).
    static COMMISSIONED: StaticCell<sonolube::scene::Scene<'static>> = StaticCell::new();
    let scene: &'static sonolube::scene::Scene<'static> = if args.commission {
        COMMISSIONED.init(sonolube::scene::Scene {
            commission: true,
            ..*scene
        })
    } else {
        scene
    };
    let mode = if args.serve {
        Mode::Operated
    } else {
        Mode::Scripted
    };
    // The two loop slots: the rig runs one; under the console the other is the spare a `scene`
    // load is prepared in (`stage.rs`), so a load swaps them instead of copying a loop.
    static ACTIVE_SLOT: StaticCell<sonolube_sim::ClosedLoop<'static>> = StaticCell::new();
    static SPARE_SLOT: StaticCell<sonolube_sim::ClosedLoop<'static>> = StaticCell::new();
    let rig = match time_driver::exclude(|| {
        SimulatedRig::new(scene, mode, |run| ACTIVE_SLOT.init(run))
    }) {
        Ok(rig) => rig.with_home(home),
        Err(error) => {
            // A scene refused for its control period: the selection line says which budget
            // fails and by how much (`sonolube::variant::select`).
            let selection = sonolube::variant::select(scene);
            if selection.refused() {
                defmt::error!("scene {=str}: controller {}", scene.name, selection);
            }
            defmt::error!("scene {=str} cannot run: {}", scene.name, error);
            exit::exit(exit::SELFCHECK_FAILED);
        }
    };
    // The rig (the station, the simulated plant and the judge: about 25 KB) lives in a static,
    // and the control task holds a reference: passed by value, its copies on the way into the
    // task's future overflowed the 99 KB stack.
    let spare = if args.serve {
        match time_driver::exclude(|| sonolube_sim::ClosedLoop::operated(scene)) {
            Ok(run) => Some(SPARE_SLOT.init(run)),
            Err(error) => {
                defmt::error!("scene {=str} cannot run: {}", scene.name, error);
                exit::exit(exit::SELFCHECK_FAILED);
            }
        }
    } else {
        None
    };
    static STAGER: StaticCell<stage::SceneStager> = StaticCell::new();
    let stager = STAGER.init(stage::SceneStager::new(spare));
    static RIG: StaticCell<Rig> = StaticCell::new();
    let rig = RIG.init(Persisted::new(rig, store, booted, false, known_scene));
    match control_task(rig, args) {
        Ok(token) => {
            control_spawner.spawn(token);
        }
        Err(_) => {
            defmt::error!("could not spawn the control task");
            exit::exit(exit::FAULT);
        }
    }
    STAGER_FOR_CONSOLE.signal(stager);
}

#[embassy_executor::task]
async fn control_task(rig: &'static mut Rig, args: Args) {
    let scene = rig.inner().scene();
    if args.serve {
        defmt::info!(
            "serving the console on UART0: scene {=str} at {=f64} Hz, idle",
            scene.name,
            scene.control_rate_hz
        );
    } else {
        defmt::info!(
            "scene {=str}: {=u32} steps at {=f64} Hz",
            scene.name,
            scene.step_count(),
            scene.control_rate_hz
        );
    }
    rig.inner().log_model();
    let steps = scene.step_count();
    let start = (
        time_driver::cycles(),
        executor::idle_cycles(),
        time_driver::excluded_cycles(),
    );
    let stats = failure::run(rig, steps).await;
    let elapsed = time_driver::cycles().saturating_sub(start.0);
    let plant = time_driver::excluded_cycles().saturating_sub(start.2);
    let idle = executor::idle_cycles().saturating_sub(start.1);
    drive::force_safe();
    report::cpu(
        &stats,
        elapsed.saturating_sub(idle),
        elapsed,
        args.icount_shift,
    );
    report::plant(&stats, plant, args.icount_shift);
    let passed = report::verdicts(scene.name, &rig.inner().summary());
    Qemu::finish(passed)
}

/// The console's stager of `scene` loads, handed over by the supervisor once the loops are
/// built.
static STAGER_FOR_CONSOLE: embassy_sync::signal::Signal<
    embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex,
    &'static mut stage::SceneStager,
> = embassy_sync::signal::Signal::new();

#[embassy_executor::task]
async fn console_task(rx: uart::UartRx, tx: uart::UartTx, identity: &'static Identity) {
    let stager = STAGER_FOR_CONSOLE.wait().await;
    console::serve_preparing(rx, tx, identity, stager).await
}

/// Feeds the watchdog while the heartbeat (boot) or the control loop (after) advances.
#[embassy_executor::task]
async fn watchdog_task() {
    supervisor::keeper(Duration::from_millis(KEEPER_EVERY_MS), watchdog::feed).await
}

#[cortex_m_rt::entry]
fn main() -> ! {
    Qemu::drive_safe();
    let Some(core) = cortex_m::Peripherals::take() else {
        exit::exit(exit::FAULT);
    };
    time_driver::init(core.SYST);
    let args = match args::read() {
        Ok(args) => args,
        Err(reason) => {
            defmt::error!("bad arguments: {=str}", reason);
            exit::exit(exit::SELFCHECK_FAILED);
        }
    };
    if watchdog::take_reset_mark() {
        defmt::error!("the previous run ended in a watchdog reset");
        if let Some(mut store) = settings_store(&args) {
            let booted =
                embassy_futures::block_on(sonolube::settings::boot(&mut store, true, known_scene));
            defmt::info!(
                "settings log: boot {=u32}, {=u32} watchdog resets",
                booted.log.boots,
                booted.log.watchdog_resets
            );
        }
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
    // Every compiled scene (issue 26: a list of 16 hid the rest).
    let names: &'static [&'static str] = &sonolube::scene::SCENE_NAMES;
    static IDENTITY: StaticCell<Identity> = StaticCell::new();
    let identity = IDENTITY.init(Identity {
        firmware: env!("CARGO_PKG_VERSION"),
        board: Qemu::NAME,
        scenes: names,
    });
    let (rx, tx) = uart::init();
    let Some(control_spawner) = executor::start_control() else {
        exit::exit(exit::FAULT);
    };

    static EXECUTOR: StaticCell<raw::Executor> = StaticCell::new();
    let executor = EXECUTOR.init(raw::Executor::new(core::ptr::null_mut()));
    executor::run(executor, |spawner| {
        match (
            heartbeat_task(),
            supervisor_task(args, control_spawner),
            console_task(rx, tx, identity),
            watchdog_task(),
        ) {
            (Ok(heartbeat), Ok(supervisor), Ok(console), Ok(watchdog)) => {
                spawner.spawn(heartbeat);
                spawner.spawn(supervisor);
                spawner.spawn(console);
                spawner.spawn(watchdog);
            }
            _ => {
                defmt::error!("could not spawn the tasks");
                exit::exit(exit::FAULT);
            }
        }
    })
}
