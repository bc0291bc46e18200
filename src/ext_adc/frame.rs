//! ADS131M02 SPI frames: command words, and the 4-word frame in both directions.
//!
//! Every exchange is one full-duplex frame of four 24-bit words (the reset word length):
//! - host to device: command word (16-bit command, 8 zero bits), the register data for WREG,
//!   then zeros (the input CRC word is ignored: MODE.RX_CRC_EN stays 0);
//! - device to host: response word, channel 0, channel 1 (24-bit two's complement), CRC word
//!   (16-bit CRC, 8 zero bits) over the three words before it.
//!
//! The response in a frame answers the command of the *previous* frame (ADS131M02 datasheet,
//! "Commands": "the expected response that appears in the following frame").

use super::crc::crc16_ccitt;
use crate::sense::AdcCode;

/// Bytes per 24-bit word.
pub const WORD_BYTES: usize = 3;
/// Bytes per frame: response/command, two channels, CRC.
pub const FRAME_BYTES: usize = 4 * WORD_BYTES;

/// Command words (ADS131M02 datasheet, "Commands" table).
pub mod command {
    /// No operation; the response is the STATUS register. Used to read samples.
    pub const NULL: u16 = 0x0000;
    /// Reset to register defaults; acknowledged with [`RESET_ACK`].
    pub const RESET: u16 = 0x0011;
    /// The response to RESET on the ADS131M02: `FF2x` with x the channel count.
    pub const RESET_ACK: u16 = 0xFF22;

    /// Read one register at `address` (`101a aaaa annn nnnn` with n = 0); the response is the
    /// register's value. Addresses are 6 bits; higher bits are dropped.
    pub const fn read_register(address: u8) -> u16 {
        0xA000 | ((address as u16 & 0x3F) << 7)
    }

    /// Write one register at `address` (`011a aaaa annn nnnn` with n = 0); the value follows
    /// in the next word.
    pub const fn write_register(address: u8) -> u16 {
        0x6000 | ((address as u16 & 0x3F) << 7)
    }

    /// The response acknowledging a one-register write at `address`
    /// (`010a aaaa ammm mmmm`, m = registers written minus one = 0).
    pub const fn write_acknowledge(address: u8) -> u16 {
        0x4000 | ((address as u16 & 0x3F) << 7)
    }
}

/// The host's frame for `command`, with `data` in the second word (for WREG).
pub const fn encode(command: u16, data: u16) -> [u8; FRAME_BYTES] {
    let mut frame = [0u8; FRAME_BYTES];
    let command = command.to_be_bytes();
    let data = data.to_be_bytes();
    frame[0] = command[0];
    frame[1] = command[1];
    frame[WORD_BYTES] = data[0];
    frame[WORD_BYTES + 1] = data[1];
    frame
}

/// What the device sent in one frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DeviceFrame {
    /// The response word (to the previous frame's command), its 16 significant bits.
    pub response: u16,
    /// Conversion results of channel 0 and 1, signed 24-bit codes (-8 388 608 to 8 388 607;
    /// full scale is +-1.2 V / gain).
    pub codes: [AdcCode; 2],
}

/// The CRC word of a frame did not match its contents.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CrcMismatch {
    /// CRC computed over the received words.
    pub computed: u16,
    /// CRC the device sent.
    pub received: u16,
}

/// Decodes a device frame, checking its CRC.
pub const fn decode(frame: &[u8; FRAME_BYTES]) -> Result<DeviceFrame, CrcMismatch> {
    let (covered, _) = frame.split_at(3 * WORD_BYTES);
    let computed = crc16_ccitt(covered);
    let received = u16::from_be_bytes([frame[3 * WORD_BYTES], frame[3 * WORD_BYTES + 1]]);
    if computed != received {
        return Err(CrcMismatch { computed, received });
    }
    Ok(DeviceFrame {
        response: u16::from_be_bytes([frame[0], frame[1]]),
        codes: [
            AdcCode::new(word24(frame, 1)),
            AdcCode::new(word24(frame, 2)),
        ],
    })
}

/// The `index`-th word of `frame` as a sign-extended 24-bit value.
const fn word24(frame: &[u8; FRAME_BYTES], index: usize) -> i32 {
    let at = index * WORD_BYTES;
    // Place the 24 bits at the top of an i32, then shift back arithmetically to sign-extend.
    i32::from_be_bytes([frame[at], frame[at + 1], frame[at + 2], 0]) >> 8
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A device frame with a correct CRC (the device side, for the tests).
    fn device(response: u16, codes: [i32; 2]) -> [u8; FRAME_BYTES] {
        let mut frame = [0u8; FRAME_BYTES];
        frame[..2].copy_from_slice(&response.to_be_bytes());
        for (i, code) in codes.iter().enumerate() {
            let bytes = code.to_be_bytes();
            frame[3 + 3 * i..6 + 3 * i].copy_from_slice(&bytes[1..]);
        }
        let crc = crc16_ccitt(&frame[..9]);
        frame[9..11].copy_from_slice(&crc.to_be_bytes());
        frame
    }

    #[test]
    fn command_words_match_the_datasheet_encoding() {
        // WREG to CLOCK (address 3): 0110 0001 1000 0000.
        assert_eq!(command::write_register(3), 0x6180);
        // RREG of ID (address 0): 1010 0000 0000 0000.
        assert_eq!(command::read_register(0), 0xA000);
        assert_eq!(command::read_register(0x3F), 0xBF80);
        assert_eq!(command::write_acknowledge(2), 0x4100);
        assert_eq!(
            encode(command::write_register(3), 0x030E),
            [0x61, 0x80, 0, 0x03, 0x0E, 0, 0, 0, 0, 0, 0, 0]
        );
        assert_eq!(encode(command::NULL, 0), [0; FRAME_BYTES]);
    }

    #[test]
    fn codes_are_sign_extended_from_24_bits() {
        for code in [0, 1, -1, 0x7F_FFFF, -0x80_0000, 123_456, -654_321] {
            let decoded = decode(&device(0x0503, [code, -code.max(-0x7F_FFFF)])).unwrap();
            assert_eq!(
                decoded.codes,
                [code, -code.max(-0x7F_FFFF)].map(AdcCode::new)
            );
            assert_eq!(decoded.response, 0x0503);
        }
    }

    #[test]
    fn a_flipped_bit_anywhere_fails_the_crc() {
        let good = device(0x0503, [0x12_3456, -0x65_4321]);
        assert!(decode(&good).is_ok());
        for byte in 0..11 {
            let mut bad = good;
            bad[byte] ^= 0x10;
            assert!(decode(&bad).is_err(), "byte {byte}");
        }
        // The padding byte after the CRC is not covered.
        let mut padded = good;
        padded[11] = 0xFF;
        assert!(decode(&padded).is_ok());
        // An all-zero frame (no device, MISO low) has the wrong CRC too.
        assert_eq!(
            decode(&[0; FRAME_BYTES]),
            Err(CrcMismatch {
                computed: crc16_ccitt(&[0; 9]),
                received: 0
            })
        );
    }
}
