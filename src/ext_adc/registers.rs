//! ADS131M02 registers: addresses, the fields this driver sets, and the STATUS word.
//!
//! Layout from the ADS131M02 datasheet register map (ID 00h, STATUS 01h, MODE 02h, CLOCK 03h,
//! GAIN 04h), the same as TI's ADS131M0x family header with two channels.

/// Register addresses.
pub mod address {
    /// ID: channel count in bits 11:8.
    pub const ID: u8 = 0x00;
    /// STATUS: the response to NULL.
    pub const STATUS: u8 = 0x01;
    /// MODE: word length, CRC options, DRDY format, the RESET flag.
    pub const MODE: u8 = 0x02;
    /// CLOCK: channel enables, oversampling ratio, power mode.
    pub const CLOCK: u8 = 0x03;
    /// GAIN: PGA gain of each channel.
    pub const GAIN: u8 = 0x04;
}

/// Value of the ID register's CHANCNT field (bits 11:8) on the two-channel ADS131M02.
pub const CHANNEL_COUNT: u16 = 2;

/// MODE as this driver writes it: the reset default 0x0510 with the RESET flag (bit 10)
/// cleared, so a later spontaneous reset shows up in STATUS. Word length 24 bits
/// (WLENGTH = 01), SPI timeout on, DRDY active low as a level, output CRC in CCITT.
pub const MODE_VALUE: u16 = 0x0110;

/// The modulator oversampling ratio, CLOCK.OSR[2:0] (bits 4:2). The output data rate is
/// `f_CLKIN / (2 OSR)` (modulator at `f_CLKIN / 2`): 4 kSPS at OSR 1024 with 8.192 MHz.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Osr {
    /// 128: 32 kSPS at 8.192 MHz.
    X128 = 0,
    /// 256: 16 kSPS.
    X256 = 1,
    /// 512: 8 kSPS.
    X512 = 2,
    /// 1024: 4 kSPS (reset default).
    X1024 = 3,
    /// 2048: 2 kSPS.
    X2048 = 4,
    /// 4096: 1 kSPS.
    X4096 = 5,
    /// 8192: 500 SPS.
    X8192 = 6,
    /// 16384: 250 SPS.
    X16384 = 7,
}

impl Osr {
    const ALL: [Self; 8] = [
        Self::X128,
        Self::X256,
        Self::X512,
        Self::X1024,
        Self::X2048,
        Self::X4096,
        Self::X8192,
        Self::X16384,
    ];

    /// The ratio, 128 to 16384.
    pub const fn ratio(self) -> u32 {
        128 << self as u32
    }

    /// The output data rate with `clkin_hz` on CLKIN, in millihertz (rounded down; saturates
    /// at `u32::MAX` for clocks far beyond the part's 8.2 MHz).
    pub const fn data_rate_millihertz(self, clkin_hz: u32) -> u32 {
        let rate = clkin_hz as u64 * 1000 / (2 * self.ratio() as u64);
        if rate > u32::MAX as u64 {
            u32::MAX
        } else {
            rate as u32
        }
    }

    /// The largest ratio (the lowest noise) whose data rate with `clkin_hz` is at least
    /// `min_sps` samples per second; `None` if even OSR 128 is too slow.
    pub const fn slowest_at_least(clkin_hz: u32, min_sps: u32) -> Option<Self> {
        let mut i = Self::ALL.len();
        while i > 0 {
            i -= 1;
            let osr = Self::ALL[i];
            if osr.data_rate_millihertz(clkin_hz) as u64 >= min_sps as u64 * 1000 {
                return Some(osr);
            }
        }
        None
    }
}

/// PGA gain of one channel, GAIN.PGAGAINn[2:0]: `2^code`, full scale +-1.2 V / gain.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Gain {
    /// 1 (reset default).
    X1 = 0,
    /// 2.
    X2 = 1,
    /// 4.
    X4 = 2,
    /// 8.
    X8 = 3,
    /// 16.
    X16 = 4,
    /// 32.
    X32 = 5,
    /// 64.
    X64 = 6,
    /// 128.
    X128 = 7,
}

impl Gain {
    /// The gain, 1 to 128.
    pub const fn factor(self) -> u32 {
        1 << self as u32
    }
}

/// The settings the driver writes: oversampling and the gain of each channel. Both channels are
/// enabled, in high-resolution power mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// Oversampling ratio (sets the data rate).
    pub osr: Osr,
    /// PGA gain of channel 0 and channel 1.
    pub gains: [Gain; 2],
}

impl Config {
    /// The CLOCK register: CH1_EN (bit 9), CH0_EN (bit 8), OSR (bits 4:2), PWR = 10b
    /// (high resolution, bits 1:0). The reset default is 0x030E (OSR 1024).
    pub const fn clock_register(&self) -> u16 {
        0x0300 | (self.osr as u16) << 2 | 0b10
    }

    /// The GAIN register: PGAGAIN1 in bits 6:4, PGAGAIN0 in bits 2:0.
    pub const fn gain_register(&self) -> u16 {
        (self.gains[1] as u16) << 4 | self.gains[0] as u16
    }
}

/// The STATUS register, sent as the response to every NULL command (so with every sample).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Status(pub u16);

impl Status {
    /// The interface is locked (LOCK, bit 15).
    pub const fn locked(self) -> bool {
        self.0 & 0x8000 != 0
    }

    /// The device has reset since MODE.RESET was last cleared (RESET, bit 10): it lost its
    /// configuration.
    pub const fn reset(self) -> bool {
        self.0 & 0x0400 != 0
    }

    /// The device saw a CRC error on its input (CRC_ERR, bit 12).
    pub const fn input_crc_error(self) -> bool {
        self.0 & 0x1000 != 0
    }

    /// New data on channel `channel` (DRDY0, DRDY1: bits 0, 1); false for other channels.
    pub const fn data_ready(self, channel: usize) -> bool {
        channel < 2 && self.0 & (1 << channel) != 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn register_values_match_the_datasheet_defaults() {
        // The default configuration reproduces the reset values (CLOCK 0x030E, GAIN 0).
        let default = Config {
            osr: Osr::X1024,
            gains: [Gain::X1, Gain::X1],
        };
        assert_eq!(default.clock_register(), 0x030E);
        assert_eq!(default.gain_register(), 0x0000);
        // OSR 512 (8 kSPS at 8.192 MHz): 0x030A.
        let fast = Config {
            osr: Osr::X512,
            gains: [Gain::X128, Gain::X2],
        };
        assert_eq!(fast.clock_register(), 0x030A);
        assert_eq!(fast.gain_register(), 0x0017);
        assert_eq!(Gain::X128.factor(), 128);
    }

    #[test]
    fn data_rates_follow_the_clock() {
        assert_eq!(Osr::X1024.data_rate_millihertz(8_192_000), 4_000_000);
        assert_eq!(Osr::X128.data_rate_millihertz(8_192_000), 32_000_000);
        assert_eq!(Osr::X16384.ratio(), 16_384);
        // The board's CLKIN, 170 MHz / 21 = 8.095 MHz: OSR 2048 would give 1976 SPS, below
        // 2 kSPS, so the slowest ratio that keeps 2 kSPS is 1024 (3953 SPS).
        let board = 170_000_000 / 21;
        assert_eq!(Osr::slowest_at_least(board, 2000), Some(Osr::X1024));
        assert_eq!(Osr::X1024.data_rate_millihertz(board), 3_952_752);
        assert_eq!(Osr::slowest_at_least(8_192_000, 2000), Some(Osr::X2048));
        assert_eq!(Osr::slowest_at_least(8_192_000, 32_001), None);
        assert_eq!(Osr::slowest_at_least(u32::MAX, 0), Some(Osr::X16384));
        assert_eq!(Osr::X128.data_rate_millihertz(u32::MAX), u32::MAX);
        assert_eq!(Osr::X16384.data_rate_millihertz(u32::MAX), 131_071_999);
    }

    #[test]
    fn status_bits() {
        let status = Status(0x8000 | 0x1000 | 0x0400 | 0x0002);
        assert!(status.locked() && status.input_crc_error() && status.reset());
        assert!(!status.data_ready(0) && status.data_ready(1) && !status.data_ready(2));
        assert!(!Status(0x0500).locked());
    }
}
