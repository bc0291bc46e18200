//! Hardware overcurrent shutdown, three comparators into TIM1's break inputs with no software
//! in the path (the register programming is `sonolube_g474_hw::protect`, host-tested):
//!
//! - COMP1: stack current above +trip. PA1 (stack-return shunt amplifier) against DAC3_CH1 ->
//!   BRK.
//! - COMP3: stack current below -trip. PC1, jumpered to PA1, against DAC1_CH1 (mirror of
//!   COMP1's threshold around the tared zero), output inverted -> BRK2. With COMP1 a window:
//!   both half-waves of the stack current trip.
//! - COMP6: DC-link current above its trip. PB11 (DC-link shunt amplifier) against DAC4_CH2
//!   -> BRK2. Shoot-through and a switch node shorted to ground flow here, never through the
//!   stack-return shunt.
//!
//! Each comparator reacts in tens of ns; the break filter adds 0.28 us (board README).
//! Comparators are locked (CSR read-only until reset) once armed; thresholds stay movable.

use embassy_stm32::Peri;
use embassy_stm32::pac;
use embassy_stm32::peripherals::{COMP1, COMP3, COMP6, DAC1, DAC3, DAC4, PB11, PC1};
use sonolube::drive::OvercurrentTrip;
use sonolube::fx::Q1_31;
use sonolube_g474_hw::protect;

/// DAC channel indices.
const CH1: usize = 0;
const CH2: usize = 1;
/// Stack-current input of COMP1 (PA1) and the window and DC-link inputs.
const PA1: usize = 1;
const PC1_PIN: usize = 1;
const PB11_PIN: usize = 11;

/// The peripherals the guard owns: held, never used through embassy (their registers are
/// written through the PAC), so nothing else can claim them.
#[allow(dead_code)]
pub struct Peripherals {
    pub comp1: Peri<'static, COMP1>,
    pub comp3: Peri<'static, COMP3>,
    pub comp6: Peri<'static, COMP6>,
    pub dac1: Peri<'static, DAC1>,
    pub dac3: Peri<'static, DAC3>,
    pub dac4: Peri<'static, DAC4>,
    /// COMP3's input: jumper it to PA1.
    pub window_input: Peri<'static, PC1>,
    /// COMP6's input: the DC-link shunt amplifier.
    pub dc_link_input: Peri<'static, PB11>,
}

/// The three thresholds as DAC codes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub struct Thresholds {
    pub stack_high: u16,
    pub stack_low: u16,
    pub dc_link: u16,
}

impl Thresholds {
    /// The window around `stack_zero` (the current channel's zero reading) for `stack_trip`,
    /// and the DC-link trip. None when the mirrored lower threshold leaves the range.
    pub fn new(
        stack_trip: OvercurrentTrip,
        stack_zero: Q1_31,
        dc_link: OvercurrentTrip,
    ) -> Option<Self> {
        let stack_high = stack_trip.dac_code();
        let stack_low = protect::window_low_code(stack_zero.to_bits(), stack_high)?;
        Some(Self {
            stack_high,
            stack_low,
            dc_link: dc_link.dac_code(),
        })
    }
}

/// The armed comparators. Keep it alive (it owns their peripherals).
pub struct OvercurrentGuard {
    _peripherals: Peripherals,
    thresholds: Thresholds,
}

impl OvercurrentGuard {
    /// Sets the threshold DACs, then enables and locks the three comparators.
    pub fn arm(peripherals: Peripherals, thresholds: Thresholds) -> Self {
        let hook = &mut |_| {};
        protect::enable_clocks(pac::RCC, hook);
        protect::analog_pin(pac::GPIOA, PA1, hook);
        protect::analog_pin(pac::GPIOC, PC1_PIN, hook);
        protect::analog_pin(pac::GPIOB, PB11_PIN, hook);
        protect::threshold_dac(pac::DAC3, CH1, thresholds.stack_high, hook);
        protect::threshold_dac(pac::DAC1, CH1, thresholds.stack_low, hook);
        protect::threshold_dac(pac::DAC4, CH2, thresholds.dc_link, hook);
        // DAC wake-up and comparator start-up: a few us (datasheet tWAKEUP, tSTART).
        embassy_time::block_for(embassy_time::Duration::from_micros(20));
        protect::arm_comparator(pac::COMP1, protect::STACK_HIGH, hook);
        protect::arm_comparator(pac::COMP3, protect::STACK_LOW, hook);
        protect::arm_comparator(pac::COMP6, protect::DC_LINK, hook);
        Self {
            _peripherals: peripherals,
            thresholds,
        }
    }

    /// Moves the stack window (after the zero-current tare changed the calibration).
    pub fn set_stack_window(&mut self, high: u16, low: u16) {
        let hook = &mut |_| {};
        protect::set_threshold(pac::DAC3, CH1, high, hook);
        protect::set_threshold(pac::DAC1, CH1, low, hook);
        self.thresholds.stack_high = high;
        self.thresholds.stack_low = low;
    }

    /// The thresholds in force.
    pub fn thresholds(&self) -> Thresholds {
        self.thresholds
    }

    /// The comparator outputs now (COMP1, COMP3, COMP6): true while one requests a break.
    pub fn outputs(&self) -> [bool; 3] {
        [
            protect::comparator_output(pac::COMP1),
            protect::comparator_output(pac::COMP3),
            protect::comparator_output(pac::COMP6),
        ]
    }
}
