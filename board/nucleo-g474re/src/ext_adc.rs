//! The external ADS131M02 on SPI1: its clock from TIM3, the shared-bus `SpiDevice`, and the
//! low-rate reading task.
//!
//! Wiring (board README): SCLK PA5 (D13), MOSI PA7 (D11), MISO PA6 (D12), CS PB6 (D10),
//! CLKIN from TIM3_CH1 on PB4 (D5). SPI mode 1 at 4 MHz (the part allows 25 MHz; 4 MHz
//! tolerates a long ribbon to a load-cell box). DRDY is not used: STATUS comes with every
//! sample.

use core::cell::RefCell;

use embassy_embedded_hal::shared_bus::blocking::spi::SpiDevice;
use embassy_stm32::Peri;
use embassy_stm32::gpio::{Level, Output, OutputType, Speed};
use embassy_stm32::peripherals::{PA5, PA6, PA7, PB4, PB6, SPI1, TIM3};
use embassy_stm32::spi::{self, Spi};
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::low_level::CountingMode;
use embassy_stm32::timer::simple_pwm::{PwmPin, SimplePwm};
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::NoopRawMutex;
use embassy_time::{Delay, Duration, Ticker, Timer};
use sonolube::ext_adc::Ads131m02;
use sonolube::sense::{AdcFormat, SensorChannel};

use crate::config;
use crate::sensing::ChannelLog;

/// The pins and peripherals the external ADC uses.
pub struct ExtAdcHardware {
    /// SPI1.
    pub spi: Peri<'static, SPI1>,
    /// SCLK.
    pub sck: Peri<'static, PA5>,
    /// MOSI (to DIN).
    pub mosi: Peri<'static, PA7>,
    /// MISO (from DOUT).
    pub miso: Peri<'static, PA6>,
    /// Chip select, active low.
    pub cs: Peri<'static, PB6>,
    /// Timer generating CLKIN.
    pub clock_timer: Peri<'static, TIM3>,
    /// CLKIN output.
    pub clock_pin: Peri<'static, PB4>,
}

/// Starts CLKIN, initializes the ADS131M02 and logs both channels every 500 ms. Returns if the
/// part does not answer (none fitted is a valid configuration: the internal ADC remains).
pub async fn run(hw: ExtAdcHardware) {
    let mut clock = SimplePwm::new(
        hw.clock_timer,
        Some(PwmPin::new(hw.clock_pin, OutputType::PushPull)),
        None,
        None,
        None,
        Hertz(config::ADS_CLKIN_HZ),
        CountingMode::EdgeAlignedUp,
    );
    {
        let mut clkin = clock.ch1();
        clkin.set_duty_cycle_fraction(1, 2);
        clkin.enable();
    }
    defmt::info!(
        "ADS131M02 CLKIN {=u32} Hz on PB4 (TIM3 ARR {=u32})",
        clock.get_frequency().0,
        clock.max_duty_cycle().saturating_sub(1)
    );
    // Let the part run on its clock before talking to it.
    Timer::after(Duration::from_millis(10)).await;

    let mut spi_config = spi::Config::default();
    spi_config.mode = spi::MODE_1;
    spi_config.frequency = Hertz(4_000_000);
    let bus = Mutex::<NoopRawMutex, _>::new(RefCell::new(Spi::new_blocking(
        hw.spi, hw.sck, hw.mosi, hw.miso, spi_config,
    )));
    let cs = Output::new(hw.cs, Level::High, Speed::VeryHigh);
    let mut adc = Ads131m02::new(SpiDevice::new(&bus, cs));
    match adc.init(&config::ADS_CONFIG, &mut Delay) {
        Ok(id) => defmt::info!(
            "ADS131M02 found: ID {=u16:#06x}, {} , {=u32} mSPS",
            id,
            config::ADS_CONFIG,
            config::ADS_CONFIG
                .osr
                .data_rate_millihertz(config::ADS_CLKIN_HZ)
        ),
        Err(error) => {
            defmt::warn!("ADS131M02 not found ({}); internal ADC only", error);
            return;
        }
    }

    let Ok(format) = AdcFormat::bipolar(24) else {
        return;
    };
    let Ok(calibration) = config::LOAD_CELL_EXTERNAL.calibration() else {
        defmt::error!("external load-cell calibration out of range");
        return;
    };
    let mut channels = [SensorChannel::new(format, config::LOAD_CELL_LIMITS, calibration); 2];
    let mut logs = [ChannelLog::new(), ChannelLog::new()];
    let mut ticker = Ticker::every(Duration::from_millis(500));
    loop {
        ticker.next().await;
        match adc.read_sample() {
            Ok(sample) => {
                for ((log, channel), code) in logs.iter_mut().zip(&mut channels).zip(sample.codes) {
                    // Faults are counted in the log line below.
                    let _ = log.record(channel, code);
                }
                let [normal, tangential] = [logs[0].take(), logs[1].take()];
                defmt::info!(
                    "ext: normal {=i32} mN (code {=i32}), tangential {=i32} mN (code {=i32}), \
                     faults {=u32}/{=u32} {}/{}, status {=u16:#06x}",
                    normal.0,
                    normal.1,
                    tangential.0,
                    tangential.1,
                    normal.2,
                    tangential.2,
                    normal.3,
                    tangential.3,
                    sample.status.0
                );
            }
            Err(error) => defmt::warn!("ADS131M02 read failed: {}", error),
        }
    }
}
