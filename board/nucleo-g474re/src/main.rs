//! Sonolube firmware for the NUCLEO-G474RE (STM32G474RE, Cortex-M4F at 170 MHz).
//!
//! Clocks: HSI16 through the PLL to 170 MHz (range-1 boost), so the board needs no crystal;
//! ADC1/2 clocked from SYSCLK. Time driver: embassy-stm32's (`time-driver-any`: TIM15),
//! leaving TIM1 for the drive and TIM3 for the external ADC's clock. Log: defmt over RTT.
//!
//! Boot: the self-check (heartbeat and supervisor tasks, thread executor) runs first. When it
//! passes, the supervisor's `finish` parks the thread executor and signals the drive-and-sense
//! task, which runs in an interrupt executor (priority 6, software interrupt FMAC): it
//! configures TIM1 with the outputs off, arms the overcurrent trip, starts TIM1-triggered ADC
//! sampling and logs the sensors twice a second; the external ADC task follows. Nothing in this
//! build switches the bridge on; the `bringup` feature adds a hold-to-run button (B1).
#![no_std]
#![no_main]

#[cfg(feature = "bringup")]
mod bringup;
mod config;
mod drive;
mod ext_adc;
mod overcurrent;
mod safe;
mod sense_task;
mod sensing;

use defmt_rtt as _;
use embassy_executor::{InterruptExecutor, Spawner};
use embassy_stm32::interrupt;
use embassy_stm32::interrupt::{InterruptExt, Priority};
use embassy_stm32::{bind_interrupts, comp, dma, peripherals, rcc};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;
use sonolube_app::{Board, heartbeat};

// Every interrupt handler the firmware binds, in one place.
bind_interrupts!(pub struct Irqs {
    DMA1_CHANNEL1 => dma::InterruptHandler<peripherals::DMA1_CH1>;
    COMP1_2_3 => comp::InterruptHandler<peripherals::COMP1>;
});

/// Set by `finish(true)`: the self-check passed, the drive and sensing may start.
pub static SELF_CHECK_PASSED: Signal<CriticalSectionRawMutex, ()> = Signal::new();
/// Set once the drive is configured and sampling runs: the external ADC may start.
pub static SENSING_STARTED: Signal<CriticalSectionRawMutex, ()> = Signal::new();

/// The executor of the drive and sensing tasks. An interrupt executor, so they keep running
/// while `finish` parks the thread executor, and so they preempt any thread-mode work.
static EXECUTOR_SENSE: InterruptExecutor = InterruptExecutor::new();

/// FMAC has no driver in embassy-stm32 0.6 and is unused: its vector is the software
/// interrupt that runs [`EXECUTOR_SENSE`].
#[interrupt]
unsafe fn FMAC() {
    // SAFETY: the interrupt executor's documented use: called from the interrupt it was
    // started on, and from nowhere else.
    unsafe { EXECUTOR_SENSE.on_interrupt() }
}

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
            defmt::info!("self-check done; drive stays off (no control loop in this build)");
            SELF_CHECK_PASSED.signal(());
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

#[embassy_executor::task]
async fn supervisor_task() {
    heartbeat::supervisor::<NucleoG474re>().await
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
        supervisor_task(),
        drive_and_sense,
        ext_adc,
    ) {
        (Ok(heartbeat), Ok(supervisor), Ok(drive_and_sense), Ok(ext_adc)) => {
            sense_spawner.spawn(drive_and_sense);
            sense_spawner.spawn(ext_adc);
            spawner.spawn(heartbeat);
            spawner.spawn(supervisor);
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
