//! The ADS131M02 driver over an `embedded-hal` 1.0 `SpiDevice`.
//!
//! SPI mode 1 (CPOL 0, CPHA 1), up to 25 MHz, chip select per frame: the `SpiDevice` the board
//! passes in owns the bus and the CS pin. Every call is a whole number of frames, and the
//! response pipeline (a frame answers the previous frame's command) is hidden: each method
//! ends with a NULL frame, so the next frame's response is always STATUS.

use embedded_hal::delay::DelayNs;
use embedded_hal::spi::SpiDevice;

use super::frame::{CrcMismatch, DeviceFrame, FRAME_BYTES, command, decode, encode};
use super::registers::{CHANNEL_COUNT, Config, MODE_VALUE, Status, address};
use crate::sense::AdcCode;

/// Wait after the RESET command before the next frame, in microseconds: generous against the
/// time the device takes to reload its register defaults (datasheet, "RESET" command), and
/// spent once, at start-up.
pub const RESET_WAIT_US: u32 = 1_000;

/// Why a transaction with the ADS131M02 failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Error<E> {
    /// The SPI bus reported an error.
    Spi(E),
    /// A frame's CRC did not match: a wiring or timing problem (or no device, MISO floating).
    Crc(CrcMismatch),
    /// After RESET the device did not answer `FF22h`: absent, not clocked, or another part.
    NoResetAcknowledge {
        /// What came back instead.
        response: u16,
    },
    /// The ID register does not name a two-channel device.
    WrongId {
        /// The ID register.
        id: u16,
    },
    /// A register write was not acknowledged as expected.
    UnexpectedResponse {
        /// The acknowledgement expected.
        expected: u16,
        /// What came back.
        received: u16,
    },
    /// A register read back differs from what was written.
    ConfigMismatch {
        /// Register address.
        address: u8,
        /// Value written.
        written: u16,
        /// Value read back.
        read: u16,
    },
    /// STATUS shows the device has reset since it was configured (its settings are lost).
    DeviceReset {
        /// The STATUS word.
        status: u16,
    },
}

/// One conversion of both channels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sample {
    /// STATUS at the time of reading (DRDY bits say which channels are new).
    pub status: Status,
    /// Channel 0 and 1, signed 24-bit codes (full scale +-1.2 V / gain) of the format
    /// `sense::AdcFormat::bipolar(24)`.
    pub codes: [AdcCode; 2],
}

/// An ADS131M02 on an SPI device.
pub struct Ads131m02<SPI> {
    spi: SPI,
}

impl<SPI: SpiDevice<u8>> Ads131m02<SPI> {
    /// The driver; nothing is sent until [`Self::init`].
    pub const fn new(spi: SPI) -> Self {
        Self { spi }
    }

    /// Gives the SPI device back.
    pub fn release(self) -> SPI {
        self.spi
    }

    /// Resets the device, checks its ID, writes MODE, CLOCK and GAIN for `config` and reads
    /// them back. Returns the ID register.
    pub fn init(
        &mut self,
        config: &Config,
        delay: &mut impl DelayNs,
    ) -> Result<u16, Error<SPI::Error>> {
        self.reset(delay)?;
        let id = self.read_register(address::ID)?;
        if (id >> 8) & 0x0F != CHANNEL_COUNT {
            return Err(Error::WrongId { id });
        }
        let settings = [
            (address::MODE, MODE_VALUE),
            (address::CLOCK, config.clock_register()),
            (address::GAIN, config.gain_register()),
        ];
        for (register, value) in settings {
            self.write_register(register, value)?;
        }
        for (register, written) in settings {
            let read = self.read_register(register)?;
            if read != written {
                return Err(Error::ConfigMismatch {
                    address: register,
                    written,
                    read,
                });
            }
        }
        Ok(id)
    }

    /// Sends RESET, waits [`RESET_WAIT_US`], and checks the reset acknowledgement.
    ///
    /// The frame carrying RESET is not CRC-checked: before the reset the device's word length
    /// and state are unknown (only the leading 16-bit command matters to it).
    pub fn reset(&mut self, delay: &mut impl DelayNs) -> Result<(), Error<SPI::Error>> {
        let mut ignored = [0u8; FRAME_BYTES];
        self.spi
            .transfer(&mut ignored, &encode(command::RESET, 0))
            .map_err(Error::Spi)?;
        delay.delay_us(RESET_WAIT_US);
        let answer = self.frame(command::NULL, 0)?;
        if answer.response != command::RESET_ACK {
            return Err(Error::NoResetAcknowledge {
                response: answer.response,
            });
        }
        Ok(())
    }

    /// Reads one register (two frames: RREG, then NULL carrying the value).
    pub fn read_register(&mut self, register: u8) -> Result<u16, Error<SPI::Error>> {
        self.frame(command::read_register(register), 0)?;
        Ok(self.frame(command::NULL, 0)?.response)
    }

    /// Writes one register (two frames: WREG with the value, then NULL carrying the
    /// acknowledgement, which is checked).
    pub fn write_register(&mut self, register: u8, value: u16) -> Result<(), Error<SPI::Error>> {
        self.frame(command::write_register(register), value)?;
        let expected = command::write_acknowledge(register);
        let received = self.frame(command::NULL, 0)?.response;
        if received != expected {
            return Err(Error::UnexpectedResponse { expected, received });
        }
        Ok(())
    }

    /// Reads the latest conversion of both channels (one NULL frame). Error `DeviceReset` if
    /// STATUS shows a reset since [`Self::init`]: the configuration is gone and the codes may
    /// be at another gain or rate.
    pub fn read_sample(&mut self) -> Result<Sample, Error<SPI::Error>> {
        let frame = self.frame(command::NULL, 0)?;
        let status = Status(frame.response);
        if status.reset() {
            return Err(Error::DeviceReset {
                status: frame.response,
            });
        }
        Ok(Sample {
            status,
            codes: frame.codes,
        })
    }

    /// One frame: sends `command` (and `data` in the second word), returns the CRC-checked
    /// device frame.
    fn frame(&mut self, command: u16, data: u16) -> Result<DeviceFrame, Error<SPI::Error>> {
        let mut received = [0u8; FRAME_BYTES];
        self.spi
            .transfer(&mut received, &encode(command, data))
            .map_err(Error::Spi)?;
        decode(&received).map_err(Error::Crc)
    }
}
