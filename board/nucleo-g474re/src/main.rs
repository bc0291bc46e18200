//! Sonolube firmware for the NUCLEO-G474RE (STM32G474RE, Cortex-M4F at 170 MHz).
//!
//! Clocks: HSI16 through the PLL to 170 MHz (range-1 boost), so the board needs no crystal.
//! Time driver: embassy-stm32's (`time-driver-any`), leaving TIM1/TIM8 for the drive.
//! Log: defmt over RTT, read by `probe-rs run`.
#![no_std]
#![no_main]

mod safe;

use defmt_rtt as _;
use embassy_executor::Spawner;
use embassy_stm32::rcc;
use sonolube_app::{Board, heartbeat};

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
        }
        loop {
            cortex_m::asm::wfi();
        }
    }
}

/// Core clock: HSI16 / 4 * 85 / 2 = 170 MHz.
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

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    NucleoG474re::drive_safe();
    let _peripherals = embassy_stm32::init(clock_config());
    defmt::info!(
        "sonolube {} on {}",
        env!("CARGO_PKG_VERSION"),
        NucleoG474re::NAME
    );
    match (heartbeat_task(), supervisor_task()) {
        (Ok(heartbeat), Ok(supervisor)) => {
            spawner.spawn(heartbeat);
            spawner.spawn(supervisor);
        }
        _ => defmt::panic!("could not spawn the tasks"),
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    // The drive goes safe before anything else (logging may itself fail). Then report like
    // panic-probe does: the message over defmt, and a HardFault that probe-rs reports as a
    // failed run. (panic-probe itself is not linked: its handler would log first.)
    safe::drive_safe();
    cortex_m::interrupt::disable();
    defmt::error!("drive output safe; panic: {}", defmt::Display2Format(info));
    cortex_m::asm::udf()
}
