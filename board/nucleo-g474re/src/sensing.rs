//! Load cells and stack current on ADC1: one scan of the three channels on every TIM1_CC3 event
//! (every PWM period, CCR3 at a fixed 3/4 of the period; ADC2 has TRGO2, stepped), DMA into a ring buffer, two scans summed per channel into one triplet of
//! 16-bit codes, and the pure sensing chain of `sonolube::sense` on every triplet.
//!
//! Plan (register fields in `sonolube_g474_hw::adc`, host-tested): PA0 (ADC1_IN1, normal
//! force), PB0 (ADC1_IN15, tangential force), PA1 (ADC1_IN2, stack current), 24.5-cycle
//! sampling, 2.61 us per scan at 42.5 MHz, inside the 4.17 us quiet window left at 60 kHz; no
//! hardware oversampling. The triplets reach the sensing task two scans at a time (one DMA
//! half-buffer), so a fresh pair is published every 2 PWM periods: 20 000 pairs/s at 40 kHz,
//! 10 000 at 20 kHz, never fewer than one per 10 kHz control period.

use embassy_stm32::Peri;
use embassy_stm32::adc::{
    Adc, AdcChannel, AdcConfig, Exten, Resolution, RingBufferedAdc, SampleTime,
};
use embassy_stm32::pac;
use embassy_stm32::peripherals::{ADC1, DMA1_CH1, PA0, PA1, PB0};
use embassy_stm32::triggers::TIM1_CC3;
use sonolube::fx::{Q1_31, Q16_16};
use sonolube::sense::{AdcCode, SampleError, SensorChannel};
use sonolube_g474_hw::adc as plan;
use static_cell::StaticCell;

use crate::Irqs;

/// Channels in the regular sequence, in order.
pub const CHANNELS: usize = 3;
/// Scans per half of the DMA ring buffer (one `read`): the scans summed into one triplet.
pub const SCANS_PER_READ: usize = plan::SCANS_PER_PAIR as usize;
/// TIM1 triggers (PWM periods) per published triplet (and load-cell pair): 2.
pub const TRIGGERS_PER_TRIPLET: u32 = plan::SCANS_PER_PAIR;
/// Triplets per read: one.
#[cfg(feature = "bringup")]
pub const TRIPLETS_PER_READ: usize = 1;
/// DMA ring buffer: two halves.
const RING_LEN: usize = 2 * CHANNELS * SCANS_PER_READ;

static RING: StaticCell<[u16; RING_LEN]> = StaticCell::new();

/// One read: [`SCANS_PER_READ`] scans, samples in sequence order.
pub type Block = [u16; CHANNELS * SCANS_PER_READ];

/// Why sampling did not start.
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub enum StartError {
    /// The ADC was converting when the plan was written (nothing written).
    AdcRunning,
    /// The DMA ring is not what the plan relies on.
    Dma(plan::DmaProblem),
}

/// ADC1 set up for one TIM1-triggered scan per PWM period, DMA-buffered, and started.
pub fn start(
    adc: Adc<'static, ADC1>,
    normal: Peri<'static, PA0>,
    tangential: Peri<'static, PB0>,
    current: Peri<'static, PA1>,
    dma: Peri<'static, DMA1_CH1>,
) -> Result<RingBufferedAdc<'static, ADC1>, StartError> {
    // The plan writes every field it relies on, with ADSTART = 0, before the ring starts.
    let sample_time = SampleTime::CYCLES24_5;
    let sequence = [
        (normal.degrade_adc(), sample_time),
        (tangential.degrade_adc(), sample_time),
        (current.degrade_adc(), sample_time),
    ];
    let ring = RING.init([0; RING_LEN]);
    let mut ring = adc.into_ring_buffered(
        dma,
        ring,
        Irqs,
        sequence.into_iter(),
        TIM1_CC3,
        Exten::RISING_EDGE,
    );
    plan::program_regular(pac::ADC1, &mut |_| {}).map_err(|_| StartError::AdcRunning)?;
    ring.start();
    plan::check_dma_ring(pac::DMA1, 0, pac::DMAMUX1, pac::ADC1.dr().as_ptr() as u32)
        .map_err(StartError::Dma)?;
    Ok(ring)
}

/// ADC1 brought up by embassy (regulator, calibration, ADEN), not converting. Call it before
/// ADC2's sampling starts: each `Adc::new` writes the ADC12 common prescaler
/// (ADC12_CCR.PRESC), so both are created before either converts. RM0440 asks for every ADC of
/// the pair disabled at such a write; embassy enables ADC1 in its `new`, so ADC2's `new` still
/// writes PRESC (the same value) with ADC1 enabled but idle: not shown harmless here (board
/// README, review finding 8).
pub fn bring_up(adc: Peri<'static, ADC1>) -> Adc<'static, ADC1> {
    Adc::new(
        adc,
        AdcConfig {
            resolution: Some(Resolution::BITS12),
            ..AdcConfig::default()
        },
    )
}

/// The triplet of one read: per channel, the two scans' 12-bit results summed into the 16-bit
/// format ([`plan::pair_code`]). None if a result has bits a 12-bit conversion cannot produce.
pub fn combine(block: &Block) -> Option<[u16; CHANNELS]> {
    let mut triplet = [0u16; CHANNELS];
    for (channel, slot) in triplet.iter_mut().enumerate() {
        let first = *block.get(channel)?;
        let second = *block.get(CHANNELS + channel)?;
        *slot = plan::pair_code(first, second)?;
    }
    Some(triplet)
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
    pub fn record(&mut self, channel: &mut SensorChannel, code: AdcCode) -> Option<SampleError> {
        self.code_sum += i64::from(code.raw());
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
