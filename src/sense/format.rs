//! ADC words to a common scale: a signed fraction of the converter's full scale.
//!
//! Every channel, whatever its converter, is first brought to a Q1.31 fraction of full scale
//! (`code << shift`), so calibrations do not change when the oversampling does and one
//! [`crate::sense::Calibration`] type serves the internal 12-bit ADC and the external 24-bit
//! one alike. Unipolar converters map to [0, 1), bipolar (two's complement) ones to [-1, 1).

use super::error::SenseError;
use crate::fx::Q1_31;

/// The G4 ADC hardware oversampler: `2^ratio_log2` conversions summed, then shifted right by
/// `shift` bits (RM0440, ADC chapter, "Oversampler": ADC_CFGR2.OVSR and OVSS).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Oversampling {
    ratio_log2: u8,
    shift: u8,
}

impl Oversampling {
    /// `2^ratio_log2` samples (2 to 256: `ratio_log2` in 1..=8) shifted right by `shift` bits
    /// (0..=8). Error `InvalidFormat` outside those ranges.
    pub const fn new(ratio_log2: u8, shift: u8) -> Result<Self, SenseError> {
        if ratio_log2 < 1 || ratio_log2 > 8 || shift > 8 {
            return Err(SenseError::InvalidFormat);
        }
        Ok(Self { ratio_log2, shift })
    }

    /// Number of summed conversions, 2 to 256.
    pub const fn ratio(self) -> u32 {
        1 << self.ratio_log2
    }

    /// The ADC_CFGR2.OVSR field: ratio `2^(OVSR + 1)`.
    pub const fn ovsr_field(self) -> u8 {
        self.ratio_log2 - 1
    }

    /// The ADC_CFGR2.OVSS field: right shift in bits.
    pub const fn ovss_field(self) -> u8 {
        self.shift
    }
}

/// One raw converter code, as the converter delivers it: a G4 ADC word (12 bits, or up to 16
/// from its hardware oversampler, unsigned) or an ADS131M02 word (24-bit two's complement,
/// sign-extended). Its width and full scale are its channel's [`AdcFormat`], which refuses a
/// code the converter cannot produce; [`AdcFormat::normalize`] is the one conversion to a
/// fraction of full scale and [`crate::sense::SensorChannel::process`] the one to newtons.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AdcCode(i32);

impl AdcCode {
    /// The code `raw` (any `i32`: the format says which are possible).
    pub const fn new(raw: i32) -> Self {
        Self(raw)
    }

    /// The code of an unsigned 16-bit converter word (a G4 ADC data register).
    pub const fn from_word(word: u16) -> Self {
        Self(word as i32)
    }

    /// The raw code.
    pub const fn raw(self) -> i32 {
        self.0
    }
}

/// The code range of one converter channel and how to scale it to a fraction of full scale.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AdcFormat {
    min_code: i32,
    max_code: i32,
    shift: u8,
}

impl AdcFormat {
    /// A unipolar converter of `bits` bits (1 to 31): codes 0 to `2^bits - 1`.
    pub const fn unipolar(bits: u8) -> Result<Self, SenseError> {
        if bits < 1 || bits > 31 {
            return Err(SenseError::InvalidFormat);
        }
        Ok(Self {
            min_code: 0,
            max_code: ((1u32 << bits) - 1) as i32,
            shift: 31 - bits,
        })
    }

    /// A bipolar two's-complement converter of `bits` bits (2 to 32): codes `-2^(bits-1)` to
    /// `2^(bits-1) - 1`. The ADS131M02 is `bipolar(24)` (datasheet, "Data format").
    pub const fn bipolar(bits: u8) -> Result<Self, SenseError> {
        if bits < 2 || bits > 32 {
            return Err(SenseError::InvalidFormat);
        }
        let half = 1i64 << (bits - 1);
        Ok(Self {
            min_code: -half as i32,
            max_code: (half - 1) as i32,
            shift: 32 - bits,
        })
    }

    /// A unipolar converter of `native_bits` (the G4 ADC: 12) behind the hardware
    /// oversampler. The result has `native_bits + ratio_log2 - shift` bits, and its largest
    /// code is `(2^native_bits - 1) * ratio >> shift` (65 520 for 12 bits, 16x, no shift).
    /// Error `InvalidFormat` when the result would exceed the 16-bit ADC_DR or drop below one
    /// bit.
    pub const fn oversampled(
        native_bits: u8,
        oversampling: Oversampling,
    ) -> Result<Self, SenseError> {
        let grown = native_bits as u32 + oversampling.ratio_log2 as u32;
        if native_bits < 1 || native_bits > 16 || grown <= oversampling.shift as u32 {
            return Err(SenseError::InvalidFormat);
        }
        let bits = grown - oversampling.shift as u32;
        if bits > 16 {
            return Err(SenseError::InvalidFormat);
        }
        let max_code =
            (((1u32 << native_bits) - 1) << oversampling.ratio_log2) >> oversampling.shift;
        Ok(Self {
            min_code: 0,
            max_code: max_code as i32,
            shift: (31 - bits) as u8,
        })
    }

    /// The smallest code the converter produces.
    pub const fn min_code(self) -> AdcCode {
        AdcCode(self.min_code)
    }

    /// The largest code the converter produces.
    pub const fn max_code(self) -> AdcCode {
        AdcCode(self.max_code)
    }

    /// `code` as a fraction of full scale, Q1.31. Error `CodeOutOfRange` for a code the
    /// converter cannot produce (a corrupted transfer, a wrong format).
    pub const fn normalize(self, code: AdcCode) -> Result<Q1_31, SenseError> {
        let code = code.0;
        if code < self.min_code || code > self.max_code {
            return Err(SenseError::CodeOutOfRange { code });
        }
        // In range, `code << shift` stays within i32 (that is how `shift` was chosen).
        Ok(Q1_31::from_bits(code << self.shift))
    }

    /// The fraction of full scale of the smallest code.
    pub const fn min_normalized(self) -> Q1_31 {
        Q1_31::from_bits(self.min_code << self.shift)
    }

    /// The fraction of full scale of the largest code.
    pub const fn max_normalized(self) -> Q1_31 {
        Q1_31::from_bits(self.max_code << self.shift)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_converter_word_is_its_code_without_a_sign() {
        // The G4's 16-bit word is unsigned: the top word is 65 535, never -1.
        assert_eq!(AdcCode::from_word(0).raw(), 0);
        assert_eq!(AdcCode::from_word(u16::MAX).raw(), 65_535);
        let sixteen = AdcFormat::unipolar(16).unwrap();
        assert_eq!(sixteen.max_code(), AdcCode::from_word(u16::MAX));
        assert!(sixteen.normalize(AdcCode::from_word(u16::MAX)).is_ok());
        // 12 bits summed over 16 top out at 65 520: the words above it are refused.
        let summed = AdcFormat::oversampled(12, Oversampling::new(4, 0).unwrap()).unwrap();
        assert_eq!(
            summed.normalize(AdcCode::from_word(65_521)),
            Err(SenseError::CodeOutOfRange { code: 65_521 })
        );
    }

    #[test]
    fn oversampling_fields_follow_the_register_encoding() {
        let os = Oversampling::new(4, 0).unwrap();
        assert_eq!((os.ratio(), os.ovsr_field(), os.ovss_field()), (16, 3, 0));
        let os = Oversampling::new(8, 8).unwrap();
        assert_eq!((os.ratio(), os.ovsr_field(), os.ovss_field()), (256, 7, 8));
        for (ratio, shift) in [(0, 0), (9, 0), (1, 9)] {
            assert_eq!(
                Oversampling::new(ratio, shift),
                Err(SenseError::InvalidFormat)
            );
        }
    }

    #[test]
    fn the_same_voltage_normalizes_the_same_with_any_oversampling() {
        // Half of full scale on a 12-bit ADC: code 2048 raw, 32 768 summed over 16, 2048 after
        // shifting the sum back by 4, 8192 after 16x with shift 2.
        let plain = AdcFormat::unipolar(12).unwrap();
        let sum16 = AdcFormat::oversampled(12, Oversampling::new(4, 0).unwrap()).unwrap();
        let avg16 = AdcFormat::oversampled(12, Oversampling::new(4, 4).unwrap()).unwrap();
        let mid16 = AdcFormat::oversampled(12, Oversampling::new(4, 2).unwrap()).unwrap();
        let half = Q1_31::from_bits(1 << 30);
        assert_eq!(plain.normalize(AdcCode::new(2048)), Ok(half));
        assert_eq!(sum16.normalize(AdcCode::new(32_768)), Ok(half));
        assert_eq!(avg16.normalize(AdcCode::new(2048)), Ok(half));
        assert_eq!(mid16.normalize(AdcCode::new(8192)), Ok(half));
        assert_eq!(sum16.max_code().raw(), 65_520);
        assert_eq!(avg16.max_code().raw(), 4095);
        assert_eq!(mid16.max_code().raw(), 16_380);
    }

    #[test]
    fn bipolar_24_bit_spans_minus_one_to_one() {
        let ads = AdcFormat::bipolar(24).unwrap();
        assert_eq!(ads.normalize(AdcCode::new(-0x80_0000)), Ok(Q1_31::MIN));
        assert_eq!(
            ads.normalize(AdcCode::new(0x7F_FFFF)),
            Ok(Q1_31::from_bits(0x7FFF_FF00))
        );
        assert_eq!(ads.normalize(AdcCode::new(-1)), Ok(Q1_31::from_bits(-256)));
        assert_eq!(ads.min_normalized(), Q1_31::MIN);
        assert_eq!(
            ads.normalize(AdcCode::new(0x80_0000)),
            Err(SenseError::CodeOutOfRange { code: 0x80_0000 })
        );
        let full = AdcFormat::bipolar(32).unwrap();
        assert_eq!(full.normalize(AdcCode::new(i32::MIN)), Ok(Q1_31::MIN));
        assert_eq!(full.normalize(AdcCode::new(i32::MAX)), Ok(Q1_31::MAX));
    }

    #[test]
    fn impossible_formats_and_codes_are_refused() {
        assert_eq!(AdcFormat::unipolar(0), Err(SenseError::InvalidFormat));
        assert_eq!(AdcFormat::unipolar(32), Err(SenseError::InvalidFormat));
        assert_eq!(AdcFormat::bipolar(1), Err(SenseError::InvalidFormat));
        assert_eq!(AdcFormat::bipolar(33), Err(SenseError::InvalidFormat));
        // 12 bits, 256x, no shift: 20 bits, more than ADC_DR holds.
        let wide = Oversampling::new(8, 0).unwrap();
        assert_eq!(
            AdcFormat::oversampled(12, wide),
            Err(SenseError::InvalidFormat)
        );
        let os = Oversampling::new(1, 8).unwrap();
        assert_eq!(
            AdcFormat::oversampled(4, os),
            Err(SenseError::InvalidFormat)
        );
        let twelve = AdcFormat::unipolar(12).unwrap();
        assert_eq!(
            twelve.normalize(AdcCode::new(4096)),
            Err(SenseError::CodeOutOfRange { code: 4096 })
        );
        assert_eq!(
            twelve.normalize(AdcCode::new(-1)),
            Err(SenseError::CodeOutOfRange { code: -1 })
        );
        assert_eq!(twelve.max_normalized(), Q1_31::from_bits(4095 << 19));
    }
}
