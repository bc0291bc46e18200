//! Sonolube firmware for the NUCLEO-G474RE (STM32G474RE, Cortex-M4F at 170 MHz).
//!
//! Clocks: HSI16 through the PLL to 170 MHz (range-1 boost), so the board needs no crystal;
//! ADC1/2 clocked from SYSCLK. Time driver: embassy-stm32's (`time-driver-any`: TIM15),
//! leaving TIM1 for the drive and TIM3 for the external ADC's clock. Log: defmt over RTT.
//!
//! Boot: the self-check (heartbeat and supervisor tasks, thread executor) runs first, with the
//! drive pins untouched. When it passes, the supervisor signals the drive-and-sense task, which
//! runs in an interrupt executor (priority 6, software interrupt FMAC): it configures TIM1 with
//! the outputs off, arms the overcurrent trip, tares the current sense and starts
//! TIM1-triggered ADC sampling, handing every load-cell pair to the control loop. The
//! supervisor then starts the control task in the same interrupt executor (the application's
//! loop on [`rig::BoardRig`]: the `reference` scene's station on the real cells and bridge,
//! idle until `start`) and the watchdog keeper in thread mode. The console (USART2, the ST-LINK
//! virtual COM port) and the external ADC run in thread mode, below the control loop. When the
//! self-check fails, the drive stays safe and the firmware parks.
//!
//! The `bringup` feature adds a hold-to-run button (B1) that owns the bridge; the control loop
//! then never switches it (see `bridge.rs`).
#![no_std]
#![no_main]

mod bridge;
#[cfg(feature = "bringup")]
mod bringup;
mod cells;
mod config;
mod console;
mod drive;
mod ext_adc;
mod overcurrent;
mod rig;
mod safe;
mod sense_task;
mod sensing;

use defmt_rtt as _;
use embassy_executor::{InterruptExecutor, SendSpawner, Spawner};
use embassy_stm32::interrupt;
use embassy_stm32::interrupt::{InterruptExt, Priority};
use embassy_stm32::peripherals::IWDG;
use embassy_stm32::usart::{BufferedUartRx, BufferedUartTx};
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_stm32::{bind_interrupts, comp, dma, peripherals, rcc, usart};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;
use embassy_time::{Duration, Instant, Timer};
use sonolube_app::console::Identity;
use sonolube_app::control::ControlLoop;
use sonolube_app::{Board, control, heartbeat, link, supervisor};
use static_cell::StaticCell;

use crate::rig::BoardRig;

// Every interrupt handler the firmware binds, in one place.
bind_interrupts!(pub struct Irqs {
    DMA1_CHANNEL1 => dma::InterruptHandler<peripherals::DMA1_CH1>;
    COMP1_2_3 => comp::InterruptHandler<peripherals::COMP1>;
    USART2 => usart::BufferedInterruptHandler<peripherals::USART2>;
});

/// Set once the self-check has passed: the drive and sensing may start.
pub static SELF_CHECK_PASSED: Signal<CriticalSectionRawMutex, ()> = Signal::new();
/// Set once the drive is configured and sampling runs: the external ADC may start.
pub static SENSING_STARTED: Signal<CriticalSectionRawMutex, ()> = Signal::new();

/// The executor of the drive, sensing and control tasks. An interrupt executor, so they
/// preempt any thread-mode work (console, external ADC, watchdog keeper).
static EXECUTOR_SENSE: InterruptExecutor = InterruptExecutor::new();

/// FMAC has no driver in embassy-stm32 0.6 and is unused: its vector is the software
/// interrupt that runs [`EXECUTOR_SENSE`].
#[interrupt]
unsafe fn FMAC() {
    // SAFETY: the interrupt executor's documented use: called from the interrupt it was
    // started on, and from nowhere else.
    unsafe { EXECUTOR_SENSE.on_interrupt() }
}

/// The scene the control loop starts with (`scene NAME` selects another with the drive off).
const DEFAULT_SCENE: &str = "reference";

/// Watchdog (IWDG, on the 32 kHz LSI) timeout: 500 periods of the `reference` loop.
const WATCHDOG_TIMEOUT_US: u32 = 50_000;
/// The keeper looks for signs of life this often.
const KEEPER_EVERY_MS: u64 = 5;
/// The watchdog starts with the control loop's first step, or this long after the self-check
/// if the loop has not stepped by then (a hung start-up then ends in a watchdog reset).
const CONTROL_START_LIMIT: Duration = Duration::from_secs(1);

/// Most scenes the console lists.
const MAX_SCENES: usize = 16;

/// The NUCLEO-G474RE board.
struct NucleoG474re;

impl Board for NucleoG474re {
    const NAME: &'static str = "nucleo-g474re";

    fn drive_safe() {
        safe::drive_safe();
    }

    fn finish(passed: bool) -> ! {
        safe::drive_safe();
        if passed {
            defmt::info!("run ended: drive safe, parked");
        } else {
            defmt::error!("self-check failed: drive safe, parked");
        }
        loop {
            cortex_m::asm::wfi();
        }
    }
}

/// Core clock: HSI16 / 4 * 85 / 2 = 170 MHz; ADC1/2 kernel clock = SYSCLK (embassy divides by
/// 4 to 42.5 MHz, under the ADC's 60 MHz).
fn clock_config() -> embassy_stm32::Config {
    let mut config = embassy_stm32::Config::default();
    config.rcc.pll = Some(rcc::Pll {
        source: rcc::PllSource::HSI,
        prediv: rcc::PllPreDiv::DIV4,
        mul: rcc::PllMul::MUL85,
        divp: None,
        divq: None,
        divr: Some(rcc::PllRDiv::DIV2),
    });
    config.rcc.sys = rcc::Sysclk::PLL1_R;
    config.rcc.boost = true;
    config.rcc.mux.adc12sel = rcc::mux::Adcsel::SYS;
    config
}

#[embassy_executor::task]
async fn heartbeat_task() {
    heartbeat::heartbeat(|_| {}).await
}

/// The self-check; when it passes, sensing, the control loop and the watchdog start.
#[embassy_executor::task]
async fn supervisor_task(
    spawner: Spawner,
    control_spawner: SendSpawner,
    watchdog: IndependentWatchdog<'static, IWDG>,
) {
    if !heartbeat::self_check::<NucleoG474re>().await {
        NucleoG474re::finish(false);
    }
    SELF_CHECK_PASSED.signal(());
    match (control_task(), watchdog_task(watchdog)) {
        (Ok(control), Ok(watchdog)) => {
            control_spawner.spawn(control);
            spawner.spawn(watchdog);
        }
        _ => {
            defmt::error!("could not spawn the control and watchdog tasks");
            NucleoG474re::finish(false);
        }
    }
}

/// The control loop on the default scene, from the first load-cell pair on.
#[embassy_executor::task]
async fn control_task() {
    let first = cells::first().await;
    let rig = match sonolube::scene::builtin::find(DEFAULT_SCENE) {
        Some(scene) => BoardRig::new(scene, first).map_err(|refusal| (scene.name, refusal)),
        None => {
            defmt::error!("no scene named {=str}", DEFAULT_SCENE);
            return;
        }
    };
    let mut rig = match rig {
        Ok(rig) => rig,
        Err((name, refusal)) => {
            // The drive stays safe; the watchdog (started without steps) resets the board.
            defmt::error!("scene {=str} cannot run on this board: {}", name, refusal);
            return;
        }
    };
    let scene = rig.scene();
    defmt::info!(
        "control: scene {=str} at {=f64} Hz, drive {=f64} Hz, idle; cycles in {=u64} Hz",
        scene.name,
        scene.control_rate_hz,
        scene.transducer.drive_hz,
        BoardRig::CYCLE_HZ
    );
    rig.log_model();
    let stats = control::run(&mut rig).await;
    // The board's loop has no end of job; should it end, the drive goes safe.
    safe::drive_safe();
    defmt::error!("control loop ended: {}", stats);
}

#[embassy_executor::task]
async fn console_task(
    rx: BufferedUartRx<'static>,
    tx: BufferedUartTx<'static>,
    identity: &'static Identity,
) {
    sonolube_app::console::serve(rx, tx, identity).await
}

/// Starts the IWDG with the control loop and feeds it while the loop steps.
#[embassy_executor::task]
async fn watchdog_task(mut watchdog: IndependentWatchdog<'static, IWDG>) {
    let after_self_check = Instant::now();
    while link::count(&link::STEPS) == 0 && after_self_check.elapsed() < CONTROL_START_LIMIT {
        Timer::after_millis(1).await;
    }
    watchdog.unleash();
    defmt::info!(
        "watchdog: {=u32} us timeout, fed while the control loop steps",
        WATCHDOG_TIMEOUT_US
    );
    supervisor::keeper(Duration::from_millis(KEEPER_EVERY_MS), || watchdog.pet()).await
}

#[embassy_executor::task]
async fn drive_and_sense_task(hw: sense_task::Hardware) {
    sense_task::run(hw).await
}

#[embassy_executor::task]
async fn ext_adc_task(hw: ext_adc::ExtAdcHardware) {
    SENSING_STARTED.wait().await;
    ext_adc::run(hw).await
}

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    NucleoG474re::drive_safe();
    let p = embassy_stm32::init(clock_config());
    defmt::info!(
        "sonolube {} on {}",
        env!("CARGO_PKG_VERSION"),
        NucleoG474re::NAME
    );
    // The control loop times its steps with the DWT cycle counter.
    let Some(mut core) = cortex_m::Peripherals::take() else {
        defmt::error!("core peripherals already taken");
        NucleoG474re::finish(false);
    };
    core.DCB.enable_trace();
    core.DWT.enable_cycle_counter();
    // Configured now, started by the watchdog task with the control loop.
    let watchdog = IndependentWatchdog::new(p.IWDG, WATCHDOG_TIMEOUT_US);

    static SCENE_NAMES: StaticCell<[&'static str; MAX_SCENES]> = StaticCell::new();
    let slots = SCENE_NAMES.init([""; MAX_SCENES]);
    let mut count = 0;
    for (slot, scene) in slots.iter_mut().zip(sonolube::scene::builtin::SCENES) {
        *slot = scene.name;
        count += 1;
    }
    let slots: &'static [&'static str] = slots;
    let names = slots.get(..count).unwrap_or(&[]);
    static IDENTITY: StaticCell<Identity> = StaticCell::new();
    let identity = IDENTITY.init(Identity {
        firmware: env!("CARGO_PKG_VERSION"),
        board: NucleoG474re::NAME,
        scenes: names,
    });
    let Ok((rx, tx)) = console::init(p.USART2, p.PA2, p.PA3) else {
        defmt::error!("USART2 configuration refused");
        NucleoG474re::finish(false);
    };

    interrupt::FMAC.set_priority(Priority::P6);
    let sense_spawner = EXECUTOR_SENSE.start(interrupt::FMAC);
    let drive_and_sense = drive_and_sense_task(sense_task::Hardware {
        tim1: p.TIM1,
        high_side: p.PA8,
        low_side: p.PB13,
        comparator: p.COMP1,
        threshold_dac: p.DAC3,
        adc: p.ADC1,
        normal_force: p.PA0,
        tangential_force: p.PB0,
        drive_current: p.PA1,
        dma: p.DMA1_CH1,
        #[cfg(feature = "bringup")]
        button: p.PC13,
    });
    let ext_adc = ext_adc_task(ext_adc::ExtAdcHardware {
        spi: p.SPI1,
        sck: p.PA5,
        mosi: p.PA7,
        miso: p.PA6,
        cs: p.PB6,
        clock_timer: p.TIM3,
        clock_pin: p.PB4,
    });
    match (
        heartbeat_task(),
        supervisor_task(spawner, sense_spawner, watchdog),
        console_task(rx, tx, identity),
        drive_and_sense,
        ext_adc,
    ) {
        (Ok(heartbeat), Ok(supervisor), Ok(console), Ok(drive_and_sense), Ok(ext_adc)) => {
            sense_spawner.spawn(drive_and_sense);
            spawner.spawn(ext_adc);
            spawner.spawn(heartbeat);
            spawner.spawn(supervisor);
            spawner.spawn(console);
        }
        _ => defmt::panic!("could not spawn the tasks"),
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    // The drive goes safe before anything else (logging may itself fail): MOE off and both
    // gate-driver pins forced low as GPIOs. Then report like panic-probe does: the message
    // over defmt, and a HardFault that probe-rs reports as a failed run. (panic-probe itself is
    // not linked: its handler would log first.)
    safe::drive_safe_final();
    cortex_m::interrupt::disable();
    defmt::error!("drive output safe; panic: {}", defmt::Display2Format(info));
    cortex_m::asm::udf()
}
