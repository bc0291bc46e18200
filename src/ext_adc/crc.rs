//! CRC-16-CCITT as the ADS131M02 computes it over its SPI frames.
//!
//! Polynomial x^16 + x^12 + x^5 + 1 (0x1021), seed 0xFFFF, bits MSB first, no reflection, no
//! final XOR (ADS131M02 datasheet, "Cyclic redundancy check (CRC)": CCITT CRC, the default
//! CRC_TYPE, seed FFFFh; it covers every word of the frame before the CRC word, padding bits
//! included). Bitwise rather than table-driven: a frame has 9 covered bytes, and the table
//! would cost 512 bytes of flash.

/// The CRC of `bytes`.
pub const fn crc16_ccitt(bytes: &[u8]) -> u16 {
    let mut crc: u16 = 0xFFFF;
    let mut i = 0;
    while i < bytes.len() {
        crc ^= (bytes[i] as u16) << 8;
        let mut bit = 0;
        while bit < 8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ 0x1021
            } else {
                crc << 1
            };
            bit += 1;
        }
        i += 1;
    }
    crc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_standard_check_value() {
        // The catalogued check value of CRC-16/CCITT-FALSE (0x1021, init 0xFFFF) for "123456789".
        assert_eq!(crc16_ccitt(b"123456789"), 0x29B1);
        assert_eq!(crc16_ccitt(&[]), 0xFFFF);
    }

    #[test]
    fn appending_the_crc_leaves_a_zero_remainder() {
        let data = [0x05, 0x00, 0x00, 0x12, 0x34, 0x56, 0xFE, 0xDC, 0xBA];
        let crc = crc16_ccitt(&data);
        let mut with_crc = data.to_vec();
        with_crc.extend_from_slice(&crc.to_be_bytes());
        assert_eq!(crc16_ccitt(&with_crc), 0);
    }

    #[test]
    fn every_single_bit_error_is_detected() {
        let data = [0x05, 0x00, 0x00, 0x12, 0x34, 0x56, 0xFE, 0xDC, 0xBA];
        let crc = crc16_ccitt(&data);
        for byte in 0..data.len() {
            for bit in 0..8 {
                let mut corrupted = data;
                corrupted[byte] ^= 1 << bit;
                assert_ne!(crc16_ccitt(&corrupted), crc, "byte {byte} bit {bit}");
            }
        }
    }
}
