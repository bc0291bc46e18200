//! CRC-32 (IEEE 802.3: polynomial 0x04C11DB7 reflected, init and final XOR 0xFFFF_FFFF), the
//! check value of every settings and log record. Bitwise, no table: a record is 64 bytes and is
//! checked once per boot or command.

/// The CRC-32 of `bytes`.
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xFFFF_FFFFu32;
    for &byte in bytes {
        crc ^= u32::from(byte);
        for _ in 0..8 {
            let mask = (crc & 1).wrapping_neg();
            crc = (crc >> 1) ^ (0xEDB8_8320 & mask);
        }
    }
    !crc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standard_check_values() {
        // The check value of the CRC-32/ISO-HDLC catalogue entry, and two more vectors.
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
        assert_eq!(crc32(b""), 0);
        assert_eq!(
            crc32(b"The quick brown fox jumps over the lazy dog"),
            0x414F_A339
        );
    }

    #[test]
    fn every_single_bit_flip_changes_the_crc() {
        let data: [u8; 64] = core::array::from_fn(|i| (i as u8).wrapping_mul(37));
        let good = crc32(&data);
        for bit in 0..data.len() * 8 {
            let mut flipped = data;
            flipped[bit / 8] ^= 1 << (bit % 8);
            assert_ne!(crc32(&flipped), good, "bit {bit}");
        }
    }
}
