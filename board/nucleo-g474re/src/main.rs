//! Sonolube firmware for the NUCLEO-G474RE (STM32G474RE, Cortex-M4F at 170 MHz).
//!
//! Clocks: the board's 24 MHz HSE crystal through the PLL to 170 MHz (range-1 boost), with the
//! clock security system on; HSI16 (+-1 %) with a logged warning when the crystal does not
//! start within 20 ms. FLASH: 4 wait states, prefetch and caches on. ADC1/2 clocked from
//! SYSCLK. Time driver: embassy-stm32's (`time-driver-any`: TIM15), leaving TIM1 for the drive
//! and TIM3 for the external ADC's clock. Log: defmt over RTT, never blocking.
//!
//! Faults: HardFault, every unexpected exception or interrupt (cortex-m-rt's
//! `DefaultHandler`, which includes the NMI of a crystal failure) and a panic make the drive
//! safe before anything else: MOE cleared, PA8/PB13 driven low as GPIO outputs. A core lockup
//! breaks TIM1 in hardware (SYSCFG_CFGR2), and a debug halt stops TIM1 with its outputs off.
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
mod current;
mod drive;
mod drive_fit;
mod ext_adc;
mod overcurrent;
mod rig;
mod safe;
mod scene_record;
mod scene_start;
mod sense_task;
mod sensing;
mod settings_flash;

use defmt_rtt as _;
use embassy_executor::{InterruptExecutor, SendSpawner, Spawner};
use embassy_stm32::interrupt;
use embassy_stm32::interrupt::{InterruptExt, Priority};
use embassy_stm32::peripherals::IWDG;
use embassy_stm32::time::Hertz;
use embassy_stm32::usart::{BufferedUartRx, BufferedUartTx};
use embassy_stm32::{Peri, bind_interrupts, dma, pac, peripherals, rcc, usart};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;
use embassy_time::{Duration, Instant, Timer};
use sonolube_app::console::Identity;
use sonolube_app::control::ControlLoop;
use sonolube_app::{Board, control, heartbeat, link, supervisor};
use sonolube_g474_hw::{clock, iwdg};
use static_cell::StaticCell;

use crate::rig::BoardRig;

// Every interrupt handler the firmware binds, in one place.
bind_interrupts!(pub struct Irqs {
    DMA1_CHANNEL1 => dma::InterruptHandler<peripherals::DMA1_CH1>;
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
/// Its prescaler and reload (/4, 400 ticks), checked at compile time.
const WATCHDOG: iwdg::Setting = match iwdg::Setting::for_timeout_us(WATCHDOG_TIMEOUT_US) {
    Some(setting) => setting,
    None => panic!("watchdog timeout out of range"),
};
/// Polls of the IWDG's update flags (a few LSI cycles: well under 1000 polls).
const WATCHDOG_SETTLE_POLLS: u32 = 10_000;
/// The crystal gets this many 1 us polls to start (datasheet: 2 ms typical).
const HSE_START_POLLS: u32 = 20_000;
/// The keeper looks for signs of life this often.
const KEEPER_EVERY_MS: u64 = 5;
/// The watchdog starts with the control loop's first step, or this long after the self-check
/// if the loop has not stepped by then (a hung start-up then ends in a watchdog reset).
const CONTROL_START_LIMIT: Duration = Duration::from_secs(1);

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

// The PLL settings below are the ones `sonolube_g474_hw::clock` checks (170 MHz, VCO limits).
const _: () = assert!(clock::HSE_PLL.frequencies(clock::HSE_HZ).2 == clock::SYSCLK_HZ);
const _: () = assert!(clock::HSI_PLL.frequencies(clock::HSI_HZ).2 == clock::SYSCLK_HZ);
const _: () =
    assert!(clock::HSE_PLL.prediv == 6 && clock::HSE_PLL.mul == 85 && clock::HSE_PLL.divr == 2);
const _: () =
    assert!(clock::HSI_PLL.prediv == 4 && clock::HSI_PLL.mul == 85 && clock::HSI_PLL.divr == 2);

/// Core clock: HSE 24 MHz / 6 * 85 / 2 = 170 MHz when the crystal runs (`hse`), else
/// HSI16 / 4 * 85 / 2; ADC1/2 kernel clock = SYSCLK (embassy divides by 4 to 42.5 MHz, under
/// the ADC's 60 MHz).
fn clock_config(hse: bool) -> embassy_stm32::Config {
    let mut config = embassy_stm32::Config::default();
    let (source, prediv) = if hse {
        config.rcc.hse = Some(rcc::Hse {
            freq: Hertz(clock::HSE_HZ),
            mode: rcc::HseMode::Oscillator,
        });
        (rcc::PllSource::HSE, rcc::PllPreDiv::DIV6)
    } else {
        (rcc::PllSource::HSI, rcc::PllPreDiv::DIV4)
    };
    config.rcc.pll = Some(rcc::Pll {
        source,
        prediv,
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
    watchdog: Peri<'static, IWDG>,
    settings: Settings,
) {
    if !heartbeat::self_check::<NucleoG474re>().await {
        NucleoG474re::finish(false);
    }
    SELF_CHECK_PASSED.signal(());
    match (control_task(settings), watchdog_task(watchdog)) {
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

/// The settings store and the reset cause, read at boot.
struct Settings {
    store: Option<sonolube::settings::Store<settings_flash::SettingsFlash>>,
    after_watchdog_reset: bool,
}

/// The control loop on the default scene (then the stored settings, `settings_flash.rs`),
/// from the first load-cell pair on.
#[embassy_executor::task]
async fn control_task(settings: Settings) {
    let first = cells::first().await;
    let rig = match scene_start::find(DEFAULT_SCENE) {
        Some(scene) => BoardRig::new(scene, first).map_err(|refusal| (scene, refusal)),
        None => {
            defmt::error!("no scene named {=str}", DEFAULT_SCENE);
            return;
        }
    };
    let rig = match rig {
        Ok(rig) => rig,
        Err((scene, refusal)) => {
            let name = scene.name;
            // The drive stays safe; the watchdog (started without steps) resets the board.
            // A scene refused for its control period: the selection line says by how much.
            if let Some(selection) = scene.selection()
                && selection.refused()
            {
                defmt::error!("scene {=str}: controller {}", name, selection);
            }
            defmt::error!("scene {=str} cannot run on this board: {}", name, refusal);
            return;
        }
    };
    let Settings {
        mut store,
        after_watchdog_reset,
    } = settings;
    let booted = match store.as_mut() {
        Some(store) => Some(
            sonolube::settings::boot(store, after_watchdog_reset, settings_flash::known_scene)
                .await,
        ),
        None => None,
    };
    let mut rig = sonolube_app::persist::Persisted::new(
        rig,
        store,
        booted,
        after_watchdog_reset,
        settings_flash::known_scene,
    );
    let scene = rig.inner().scene();
    defmt::info!(
        "control: scene {=str} at {=f64} Hz, drive {=f64} Hz, idle; cycles in {=u64} Hz",
        scene.name,
        rig.inner().start().record.control_rate_hz,
        scene.drive_hz,
        BoardRig::CYCLE_HZ
    );
    rig.inner().log_model();
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
async fn watchdog_task(_watchdog: Peri<'static, IWDG>) {
    let after_self_check = Instant::now();
    while link::count(&link::STEPS) == 0 && after_self_check.elapsed() < CONTROL_START_LIMIT {
        Timer::after_millis(1).await;
    }
    let settled = iwdg::start(pac::IWDG, WATCHDOG, WATCHDOG_SETTLE_POLLS, &mut |_| {});
    defmt::info!(
        "watchdog: {=u32} us timeout (PR /{=u32}, RLR {=u16}), fed while the control loop steps",
        WATCHDOG.timeout_us(iwdg::LSI_HZ),
        4u32 << WATCHDOG.prescaler_code,
        WATCHDOG.reload
    );
    if !settled {
        defmt::warn!("watchdog: prescaler/reload update did not complete in time");
    }
    supervisor::keeper(Duration::from_millis(KEEPER_EVERY_MS), || {
        iwdg::pet(pac::IWDG)
    })
    .await
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
    // The crystal is started here, with a timeout: embassy's clock setup waits for it forever.
    // At reset the core runs on HSI16: 16 cycles are 1 us.
    let hse = clock::start_hse(
        pac::RCC,
        HSE_START_POLLS,
        || cortex_m::asm::delay(16),
        &mut |_| {},
    );
    let on_hse = matches!(hse, clock::HseStart::Ready { .. });
    let p = embassy_stm32::init(clock_config(on_hse));
    clock::configure_flash(pac::FLASH, &mut |_| {});
    defmt::info!(
        "sonolube {} on {}",
        env!("CARGO_PKG_VERSION"),
        NucleoG474re::NAME
    );
    match hse {
        clock::HseStart::Ready { polls } => {
            clock::enable_css(pac::RCC, &mut |_| {});
            defmt::info!(
                "clock: 24 MHz HSE crystal (ready after {=u32} us) -> PLL -> 170 MHz, CSS on",
                polls
            );
        }
        clock::HseStart::TimedOut => defmt::warn!(
            "clock: HSE crystal did not start within {=u32} us; running on HSI16 (+-1 %: the \
             drive frequency may be off by up to 400 Hz at 40 kHz)",
            HSE_START_POLLS
        ),
    }
    // The control loop times its steps with the DWT cycle counter.
    let Some(mut core) = cortex_m::Peripherals::take() else {
        defmt::error!("core peripherals already taken");
        NucleoG474re::finish(false);
    };
    core.DCB.enable_trace();
    core.DWT.enable_cycle_counter();
    // Started by the watchdog task with the control loop.
    let watchdog = p.IWDG;
    let settings = Settings {
        after_watchdog_reset: settings_flash::after_watchdog_reset(),
        store: settings_flash::open(p.FLASH),
    };

    // Every compiled scene (issue 26: a list of 16 hid the rest).
    let names: &'static [&'static str] = &sonolube::scene::SCENE_NAMES;
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
        protection: overcurrent::Peripherals {
            comp1: p.COMP1,
            comp3: p.COMP3,
            comp6: p.COMP6,
            dac1: p.DAC1,
            dac3: p.DAC3,
            dac4: p.DAC4,
            window_input: p.PC1,
            dc_link_input: p.PB11,
        },
        adc: p.ADC1,
        normal_force: p.PA0,
        tangential_force: p.PB0,
        drive_current: p.PA1,
        dma: p.DMA1_CH1,
        current: current::Hardware {
            adc: p.ADC2,
            ring_dma: p.DMA1_CH2,
            table_dma: p.DMA1_CH3,
        },
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
        supervisor_task(spawner, sense_spawner, watchdog, settings),
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

/// A HardFault makes the drive safe before anything else, then reports and waits for the
/// watchdog (or a debugger). cortex-m-rt's default would loop with TIM1 still switching.
#[cortex_m_rt::exception]
unsafe fn HardFault(frame: &cortex_m_rt::ExceptionFrame) -> ! {
    safe::drive_safe_final();
    cortex_m::interrupt::disable();
    defmt::error!(
        "HardFault at pc {=u32:#010x}: drive output safe",
        frame.pc()
    );
    loop {
        cortex_m::asm::nop();
    }
}

/// Every exception and interrupt without a handler of its own (NMI, MemManage, BusFault,
/// UsageFault, an unbound interrupt): the drive goes safe first, as for a HardFault.
#[cortex_m_rt::exception]
unsafe fn DefaultHandler(irqn: i16) -> ! {
    safe::drive_safe_final();
    cortex_m::interrupt::disable();
    defmt::error!(
        "unexpected exception or interrupt {=i16}: drive output safe",
        irqn
    );
    loop {
        cortex_m::asm::nop();
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
