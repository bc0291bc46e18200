//! Load cells and drive current on ADC1: conversions triggered by TIM1, DMA into a ring buffer,
//! 16x hardware oversampling, and the pure sensing chain of `sonolube::sense` on every sample.
//!
//! Sequence: PA0 (ADC1_IN1, normal force), PB0 (ADC1_IN15, tangential force), PA1 (ADC1_IN2,
//! drive current). Each TIM1 TRGO2 pulse (3/4 of every PWM period, in the quiet low-side phase)
//! starts one conversion; with triggered oversampling (ADC_CFGR2.TROVS = 1, RM0440 ADC chapter
//! "Triggered regular oversampling") 16 triggers make one 16-bit result, so every sample the
//! oversampler sums was taken at the same quiet point of the period. One triplet therefore
//! takes 48 PWM periods: 833 triplets/s at 40 kHz.

use embassy_stm32::Peri;
use embassy_stm32::adc::{
    Adc, AdcChannel, AdcConfig, Exten, Resolution, RingBufferedAdc, Rovsm, SampleTime, Trovs,
};
use embassy_stm32::peripherals::{ADC1, DMA1_CH1, PA0, PA1, PB0};
use embassy_stm32::triggers::TIM1_TRGO2;
use sonolube::fx::{Q1_31, Q16_16};
use sonolube::sense::{SampleError, SensorChannel};
use static_cell::StaticCell;

use crate::Irqs;
use crate::config;

/// Channels in the regular sequence, in order.
pub const CHANNELS: usize = 3;
/// Triplets per half of the DMA ring buffer (one `read`): one, so each triplet reaches the
/// control loop as soon as it is converted (1.2 ms at 40 kHz) rather than in bursts. The DMA
/// interrupts once per triplet (833 Hz at 40 kHz); the reader has one triplet's time to take a
/// half before the DMA laps it (an overrun loses samples, the ring re-aligns to the sequence).
pub const TRIPLETS_PER_READ: usize = 1;
/// TIM1 triggers (PWM periods) per triplet: the oversampling ratio times the channels, 48.
pub const TRIGGERS_PER_TRIPLET: u32 = config::OVERSAMPLING.ratio() * CHANNELS as u32;
/// DMA ring buffer: two halves.
const RING_LEN: usize = 2 * CHANNELS * TRIPLETS_PER_READ;

static RING: StaticCell<[u16; RING_LEN]> = StaticCell::new();

/// The three channels of one read: samples in sequence order.
pub type Block = [u16; CHANNELS * TRIPLETS_PER_READ];

/// ADC1 set up for TIM1-triggered, oversampled, DMA-buffered conversions of the three inputs.
pub fn start(
    adc: Peri<'static, ADC1>,
    normal: Peri<'static, PA0>,
    tangential: Peri<'static, PB0>,
    current: Peri<'static, PA1>,
    dma: Peri<'static, DMA1_CH1>,
) -> RingBufferedAdc<'static, ADC1> {
    let oversampling = config::OVERSAMPLING;
    let adc = Adc::new(
        adc,
        AdcConfig {
            resolution: Some(Resolution::BITS12),
            oversampling_ratio: Some(oversampling.ovsr_field()),
            oversampling_shift: Some(oversampling.ovss_field()),
            oversampling_mode: Some((Rovsm::CONTINUED, Trovs::TRIGGERED, true)),
            ..AdcConfig::default()
        },
    );
    let sample_time = SampleTime::CYCLES47_5;
    let sequence = [
        (normal.degrade_adc(), sample_time),
        (tangential.degrade_adc(), sample_time),
        (current.degrade_adc(), sample_time),
    ];
    let ring = RING.init([0; RING_LEN]);
    adc.into_ring_buffered(
        dma,
        ring,
        Irqs,
        sequence.into_iter(),
        TIM1_TRGO2,
        Exten::RISING_EDGE,
    )
}

/// Statistics of one channel over a logging period.
pub struct ChannelLog {
    value_sum: i64,
    code_sum: i64,
    samples: u32,
    faults: u32,
    last_fault: Option<SampleError>,
}

impl ChannelLog {
    /// Empty statistics.
    pub const fn new() -> Self {
        Self {
            value_sum: 0,
            code_sum: 0,
            samples: 0,
            faults: 0,
            last_fault: None,
        }
    }

    /// Runs `code` through `channel` and records the outcome. Returns the fault, if any.
    pub fn record(&mut self, channel: &mut SensorChannel, code: i32) -> Option<SampleError> {
        self.code_sum += i64::from(code);
        self.samples = self.samples.saturating_add(1);
        match channel.process(code) {
            Ok(value) => {
                self.value_sum += i64::from(value.value.to_bits());
                None
            }
            Err(error) => {
                self.faults = self.faults.saturating_add(1);
                self.last_fault = Some(error);
                Some(error)
            }
        }
    }

    /// Mean value in thousandths of the unit (mN or mA) over the good samples, mean raw code,
    /// fault count and last fault; then starts a new period.
    pub fn take(&mut self) -> (i32, i32, u32, Option<SampleError>) {
        let good = i64::from(self.samples - self.faults.min(self.samples));
        let milli = if good == 0 {
            0
        } else {
            // Q16.16 mean to thousandths: * 1000 / 65536.
            (self.value_sum / good * 1000 / 65_536) as i32
        };
        let code = if self.samples == 0 {
            0
        } else {
            (self.code_sum / i64::from(self.samples)) as i32
        };
        let report = (milli, code, self.faults, self.last_fault);
        *self = Self::new();
        report
    }
}

/// Whether a tared zero lies within 5 % of full scale of the nominal one: a current-sense
/// amplifier referenced to mid-supply reads 1.65 V +- its offset with no current; anything
/// else means it is missing or the drive was not off.
pub fn plausible_zero(tared: Q1_31, nominal: Q1_31) -> bool {
    const TOLERANCE: u32 = (1 << 31) / 20;
    tared.to_bits().abs_diff(nominal.to_bits()) <= TOLERANCE
}

/// Q16.16 to thousandths, for logs.
pub fn milli(value: Q16_16) -> i32 {
    (i64::from(value.to_bits()) * 1000 / 65_536) as i32
}
