//! External 24-bit load-cell ADC: the TI ADS131M02 (two simultaneous channels, up to 32 kSPS).
//!
//! Why this part: two channels sampled simultaneously (normal and tangential force together),
//! a PGA up to 128 so a strain bridge connects directly, and a CRC on every frame, which a
//! long cable to the load cells needs. The driver is generic over `embedded-hal` 1.0
//! [`SpiDevice`](embedded_hal::spi::SpiDevice) and [`DelayNs`](embedded_hal::delay::DelayNs),
//! so it runs on the board and, against a scripted mock, in the host tests. The data-ready pin
//! is not needed: each sample carries STATUS, whose DRDY bits say which channels are new.
//!
//! Use: [`Ads131m02::init`] once (reset, ID check, configuration written and read back), then
//! [`Ads131m02::read_sample`] at the rate wanted; convert the codes with
//! `sense::AdcFormat::bipolar(24)` and a `sense::Calibration`.

mod crc;
mod driver;
mod frame;
mod registers;
#[cfg(test)]
mod tests;

pub use crc::crc16_ccitt;
pub use driver::{Ads131m02, Error, RESET_WAIT_US, Sample};
pub use frame::{CrcMismatch, DeviceFrame, FRAME_BYTES, command, decode, encode};
pub use registers::{CHANNEL_COUNT, Config, Gain, MODE_VALUE, Osr, Status, address};

/// The CLKIN divider for a timer output at `timer_hz`: the smallest division that keeps CLKIN
/// at or below the nominal 8.192 MHz of high-resolution mode (datasheet, "Clock"). 21 at
/// 170 MHz, giving 8.095 MHz. Returns at least 1.
pub const fn clkin_divider(timer_hz: u32) -> u32 {
    let divider = timer_hz.div_ceil(8_192_000);
    if divider == 0 { 1 } else { divider }
}

#[cfg(test)]
mod divider_tests {
    use super::*;

    #[test]
    fn the_board_clock_divides_to_8_095_mhz() {
        assert_eq!(clkin_divider(170_000_000), 21);
        assert_eq!(170_000_000 / clkin_divider(170_000_000), 8_095_238);
        assert_eq!(clkin_divider(8_192_000), 1);
        assert_eq!(clkin_divider(0), 1);
        assert_eq!(clkin_divider(16_384_001), 3);
    }
}
