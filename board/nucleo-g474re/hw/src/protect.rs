//! Hardware protection that needs no software once armed: three comparators into TIM1's
//! break inputs, the system break sources (SYSCFG_CFGR2), and TIM1 frozen on a debug halt.
//!
//! | comparator | + input | − input (threshold) | trips when | TIM1 input |
//! |---|---|---|---|---|
//! | COMP1 | PA1 (stack-return shunt amplifier) | DAC3_CH1 | stack current > +trip | BRK (AF1.BKCMP1E) |
//! | COMP3 | PC1 (the same signal, jumpered from PA1) | DAC1_CH1 | stack current < −trip (output inverted) | BRK2 (AF2.BK2CMP3E) |
//! | COMP6 | PB11 (DC-link shunt amplifier) | DAC4_CH2 | DC-link current > its trip | BRK2 (AF2.BK2CMP6E) |
//!
//! COMP1 and COMP3 form a window on the stack current (both half-waves); COMP6 sees the
//! bridge's DC-link current, i.e. shoot-through and a switch node shorted to ground, which the
//! stack-return shunt never carries. Inputs and DAC connections: RM0440 COMP chapter, "COMPx
//! non-inverting / inverting input assignment" (COMP1 INP IO1 = PA1; COMP3 INP IO2 = PC1;
//! COMP6 INP IO1 = PB11; INMSEL 100 = DAC3_CH1 for COMP1, 101 = DAC1_CH1 for COMP3,
//! 100 = DAC4_CH2 for COMP6). The DACs run in internal mode (no pin), buffer off.

use sonolube::fx::Q16_16;
use sonolube::sense::ShuntAmplifier;

use crate::Step;
use crate::pac::comp::Comp;
use crate::pac::comp::regs::Csr;
use crate::pac::comp::vals::{Blanking, Hysteresis, Inm, Polarity};
use crate::pac::dac::Dac;
use crate::pac::dac::vals::Mode;
use crate::pac::dbgmcu::Dbgmcu;
use crate::pac::gpio::Gpio;
use crate::pac::gpio::vals::{Moder, Pupdr};
use crate::pac::rcc::Rcc;
use crate::pac::syscfg::Syscfg;
use crate::pac::syscfg::regs::Cfgr2;

/// Stack current sense: 25 mOhm shunt in the stack's return, INA240A1 (20 V/V) referenced to
/// mid-supply, into PA1 (ADC1_IN2, COMP1_INP) and, by a jumper, PC1 (COMP3_INP). 0.5 V/A,
/// +-3.3 A range.
pub const STACK_SENSE: ShuntAmplifier = ShuntAmplifier {
    shunt_micro_ohm: 25_000,
    gain_milli: 20_000,
    zero_millivolt: 1650,
    full_scale_millivolt: 3300,
};

/// Stack overcurrent trip: 2.5 A, 1.43 times the stack's 1.75 A rating (seed 003 Table 1),
/// leaving room for the motional current at resonance. Both half-waves: COMP1 above +2.5 A,
/// COMP3 below -2.5 A.
pub const STACK_TRIP_CURRENT: Q16_16 = Q16_16::from_ratio_const(5, 2);

/// DC-link current sense: 10 mOhm shunt between the half-bridge's ground (the low-side
/// MOSFET's source and the stack-return shunt's ground end) and the bus capacitor's negative
/// terminal, INA240A1 (20 V/V) referenced to mid-supply, into PB11 (COMP6_INP). 0.2 V/A,
/// +-8.25 A range. It carries the stack current during the high-side phase, and every
/// shoot-through or switch-node short.
pub const DC_LINK_SENSE: ShuntAmplifier = ShuntAmplifier {
    shunt_micro_ohm: 10_000,
    gain_milli: 20_000,
    zero_millivolt: 1650,
    full_scale_millivolt: 3300,
};

/// DC-link trip: 6 A, above the 2.5 A stack trip (the DC link carries the stack current in the
/// high-side phase) and far below a shoot-through's current.
pub const DC_LINK_TRIP_CURRENT: Q16_16 = Q16_16::from_ratio_const(6, 1);

/// One comparator's input selection and output polarity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ComparatorSetup {
    /// INPSEL: false = the comparator's IO1 pin, true = IO2.
    pub inp_io2: bool,
    /// INMSEL: the threshold DAC channel.
    pub inm: Inm,
    /// Inverted: the output is high while the + input is *below* the threshold.
    pub inverted: bool,
}

/// COMP1: PA1 against DAC3_CH1, high above the threshold.
pub const STACK_HIGH: ComparatorSetup = ComparatorSetup {
    inp_io2: false,
    inm: Inm::DACA,
    inverted: false,
};
/// COMP3: PC1 against DAC1_CH1, high below the threshold.
pub const STACK_LOW: ComparatorSetup = ComparatorSetup {
    inp_io2: true,
    inm: Inm::DACB,
    inverted: true,
};
/// COMP6: PB11 against DAC4_CH2, high above the threshold.
pub const DC_LINK: ComparatorSetup = ComparatorSetup {
    inp_io2: false,
    inm: Inm::DACA,
    inverted: false,
};

/// Hysteresis of every comparator: 20 mV (40 mA on the stack shunt at 0.5 V/A).
pub const HYSTERESIS: Hysteresis = Hysteresis::HYST20M;

/// DAC_MCR.HFSEL for an AHB clock above 160 MHz (RM0440, DAC "high frequency interface mode").
pub const DAC_HFSEL_ABOVE_160_MHZ: u8 = 0b10;

/// Clocks of the comparators (SYSCFG), the DACs and the GPIO ports they use.
pub fn enable_clocks(rcc: Rcc, hook: &mut impl FnMut(Step)) {
    rcc.apb2enr().modify(|w| w.set_syscfgen(true));
    hook("RCC_APB2ENR");
    rcc.ahb2enr().modify(|w| {
        w.set_gpioaen(true);
        w.set_gpioben(true);
        w.set_gpiocen(true);
        w.set_dac1en(true);
        w.set_dac3en(true);
        w.set_dac4en(true);
    });
    hook("RCC_AHB2ENR");
}

/// `pin` of `gpio` as an analog input, no pull.
pub fn analog_pin(gpio: Gpio, pin: usize, hook: &mut impl FnMut(Step)) {
    gpio.pupdr().modify(|w| w.set_pupdr(pin, Pupdr::FLOATING));
    hook("GPIO_PUPDR");
    gpio.moder().modify(|w| w.set_moder(pin, Moder::ANALOG));
    hook("GPIO_MODER");
}

/// DAC channel `channel` (0 = CH1, 1 = CH2) in internal mode (connected to on-chip peripherals,
/// buffer off), holding `code` (12 bits, right-aligned). The channel is disabled while its mode
/// changes (RM0440: MODE is written only with ENx = 0).
pub fn threshold_dac(dac: Dac, channel: usize, code: u16, hook: &mut impl FnMut(Step)) {
    dac.cr().modify(|w| w.set_en(channel, false));
    hook("DAC_CR");
    dac.mcr().modify(|w| {
        w.set_mode(channel, Mode::NORMAL_INT_BUFDIS);
        w.set_hfsel(DAC_HFSEL_ABOVE_160_MHZ);
    });
    hook("DAC_MCR");
    set_threshold(dac, channel, code, hook);
    dac.cr().modify(|w| w.set_en(channel, true));
    hook("DAC_CR");
}

/// Moves a threshold (after the zero-current tare). Codes above 4095 are refused (false,
/// nothing written): the register would silently drop the top bits.
pub fn set_threshold(dac: Dac, channel: usize, code: u16, hook: &mut impl FnMut(Step)) -> bool {
    if code > 4095 {
        return false;
    }
    dac.dhr12r(channel).write(|w| w.set_dhr(code));
    hook("DAC_DHR12R");
    true
}

/// Enables a comparator (high-speed, 20 mV hysteresis, no blanking), then sets its LOCK bit:
/// its CSR is read-only until reset, so no software error can disarm it.
pub fn arm_comparator(comp: Comp, setup: ComparatorSetup, hook: &mut impl FnMut(Step)) {
    let mut csr = Csr(0);
    csr.set_inpsel(setup.inp_io2);
    csr.set_inmsel(setup.inm);
    csr.set_polarity(if setup.inverted {
        Polarity::INVERTED
    } else {
        Polarity::NOT_INVERTED
    });
    csr.set_hyst(HYSTERESIS);
    csr.set_blanksel(Blanking::NO_BLANKING);
    csr.set_en(true);
    comp.csr().write_value(csr);
    hook("COMP_CSR");
    comp.csr().modify(|w| w.set_lock(true));
    hook("COMP_CSR");
}

/// A comparator's output now (after its polarity): true while it requests a break.
pub fn comparator_output(comp: Comp) -> bool {
    comp.csr().read().value()
}

/// The DAC code of the window's lower threshold: the mirror of `high_code` around the zero
/// current reading `zero` (Q1.31 fraction of the ADC range, as in the current channel's
/// calibration), rounded *up*, so the lower comparator never trips later than the upper one's
/// mirror. None when the mirror falls outside 1..zero (no room below the zero).
pub fn window_low_code(zero_q31: i32, high_code: u16) -> Option<u16> {
    if zero_q31 <= 0 {
        return None;
    }
    // 2 * zero in 12-bit DAC steps, rounded up: zero / 2^31 * 4096 * 2 = zero / 2^18.
    let twice_zero = (i64::from(zero_q31) + (1 << 18) - 1) >> 18;
    let low = twice_zero - i64::from(high_code);
    let zero_code = i64::from(zero_q31) >> 19;
    if low < 1 || low >= zero_code {
        return None;
    }
    u16::try_from(low).ok()
}

/// SYSCFG_CFGR2: core lockup (CLL), SRAM parity error (SPL) and flash ECC double error (ECCL)
/// routed to TIM1's break, so a locked-up core or a corrupted memory stops the bridge in
/// hardware. PVDL is left off: the PVD is not enabled on this board. The bits are set-only
/// until reset; SPF (bit 8, rc_w1) is written 0, so a pending parity flag is left alone.
pub fn lock_system_breaks(syscfg: Syscfg, hook: &mut impl FnMut(Step)) {
    let mut w = Cfgr2(0);
    w.set_cll(true);
    w.set_spl(true);
    w.set_eccl(true);
    syscfg.cfgr2().write_value(w);
    hook("SYSCFG_CFGR2");
}

/// DBGMCU_APB2FZR.DBG_TIM1_STOP: TIM1 stops and its outputs are disabled while a debugger
/// halts the core (RM0440, DBGMCU), so a breakpoint never leaves the bridge on at a fixed duty.
pub fn freeze_tim1_on_halt(dbgmcu: Dbgmcu, hook: &mut impl FnMut(Step)) {
    dbgmcu.apb2fzr().modify(|w| w.set_tim1(true));
    hook("DBGMCU_APB2FZR");
}

/// DBGMCU_APB1FZR1.DBG_IWDG_STOP: the watchdog stops while the core is halted by a debugger.
/// For bring-up builds only: in a field build a halt longer than the timeout ends in a
/// watchdog reset, which leaves the drive safe (TIM1's outputs stop with the core, but MOE
/// stays set, so the bridge would resume switching at the old duty when the core resumes).
pub fn freeze_watchdog_on_halt(dbgmcu: Dbgmcu, hook: &mut impl FnMut(Step)) {
    dbgmcu.apb1lfzr().modify(|w| w.set_iwdg(true));
    hook("DBGMCU_APB1FZR1");
}

#[cfg(test)]
mod tests {
    use std::vec::Vec;

    use super::*;
    use crate::image::Image;

    fn comp_image(setup: ComparatorSetup) -> (Box<Image>, Vec<Step>) {
        let mut image = Image::new();
        let mut steps = Vec::new();
        // SAFETY: the image outlives the handle.
        arm_comparator(unsafe { Comp::from_ptr(image.ptr()) }, setup, &mut |s| {
            steps.push(s)
        });
        (image, steps)
    }

    #[test]
    fn the_three_comparators_select_the_documented_inputs() {
        // RM0440 COMP_CxCSR: EN 0, INMSEL 4-6, INPSEL 8, POLARITY 15, HYST 16-18,
        // BLANKSEL 19-21, BRGEN 22, SCALEN 23, VALUE 30, LOCK 31.
        for (setup, inmsel, inpsel, polarity) in [
            (STACK_HIGH, 0b100, false, false),
            (STACK_LOW, 0b101, true, true),
            (DC_LINK, 0b100, false, false),
        ] {
            let (image, steps) = comp_image(setup);
            assert!(image.bit(0, 0), "EN");
            assert_eq!(image.bits(0, 4, 3), inmsel, "INMSEL");
            assert_eq!(image.bit(0, 8), inpsel, "INPSEL");
            assert_eq!(image.bit(0, 15), polarity, "POLARITY");
            assert_eq!(image.bits(0, 16, 3), 0b010, "HYST 20 mV");
            assert_eq!(image.bits(0, 19, 3), 0, "no blanking");
            assert_eq!(image.bits(0, 22, 2), 0, "BRGEN/SCALEN (DAC inputs)");
            assert!(image.bit(0, 31), "LOCK");
            assert_eq!(steps, ["COMP_CSR", "COMP_CSR"], "locked in a second write");
        }
    }

    /// Which DAC channel each comparator's INMSEL code selects on the STM32G474 (RM0440,
    /// COMPx inverting input assignment; the same in ST's HAL `COMP_INPUT_MINUS_DACx_CHy`
    /// comments): code 0b100 ("DACA") and 0b101 ("DACB") per comparator. The board writes the
    /// thresholds to DAC3_CH1 (COMP1), DAC1_CH1 (COMP3) and DAC4_CH2 (COMP6): each setup's code
    /// must select exactly that channel.
    #[test]
    fn each_comparator_selects_the_dac_channel_its_threshold_is_written_to() {
        const ASSIGNMENT: [(u8, &str, &str); 7] = [
            (1, "DAC3_CH1", "DAC1_CH1"),
            (2, "DAC3_CH2", "DAC1_CH2"),
            (3, "DAC3_CH1", "DAC1_CH1"),
            (4, "DAC3_CH2", "DAC1_CH1"),
            (5, "DAC4_CH1", "DAC1_CH2"),
            (6, "DAC4_CH2", "DAC2_CH1"),
            (7, "DAC4_CH1", "DAC2_CH1"),
        ];
        for (comp, setup, written_to) in [
            (1u8, STACK_HIGH, "DAC3_CH1"),
            (3, STACK_LOW, "DAC1_CH1"),
            (6, DC_LINK, "DAC4_CH2"),
        ] {
            let (image, _) = comp_image(setup);
            let (_, daca, dacb) = ASSIGNMENT[usize::from(comp - 1)];
            let selected = match image.bits(0, 4, 3) {
                0b100 => daca,
                0b101 => dacb,
                other => panic!("COMP{comp}: INMSEL {other:#b} is no DAC"),
            };
            assert_eq!(selected, written_to, "COMP{comp}");
        }
    }

    #[test]
    fn threshold_dacs_are_internal_unbuffered_with_hfsel() {
        for channel in [0usize, 1] {
            let mut image = Image::new();
            let ptr = &*image as *const Image;
            let mut enabled_during_mode_write = Vec::new();
            // SAFETY: the image outlives the handle.
            let dac = unsafe { Dac::from_ptr(image.ptr()) };
            threshold_dac(dac, channel, 3599, &mut |s| {
                if s == "DAC_MCR" {
                    // SAFETY: reading our image between writes.
                    enabled_during_mode_write
                        .push(unsafe { (*ptr).bit(0x00, 16 * channel as u32) });
                }
            });
            // RM0440 DAC: CR EN1 bit 0 / EN2 bit 16; MCR MODE1 0-2 / MODE2 16-18, HFSEL 14-15;
            // DHR12R1 at 0x08, DHR12R2 at 0x14.
            let shift = 16 * channel as u32;
            assert!(image.bit(0x00, shift), "EN");
            assert_eq!(
                image.bits(0x3C, shift, 3),
                0b011,
                "MODE: internal, buffer off"
            );
            assert_eq!(image.bits(0x3C, 14, 2), 0b10, "HFSEL above 160 MHz");
            assert_eq!(image.word([0x08, 0x14][channel]), 3599);
            assert_eq!(
                enabled_during_mode_write,
                [false],
                "MODE written with EN = 0"
            );
            assert!(!set_threshold(dac, channel, 4096, &mut |_| {}));
            assert_eq!(
                image.word([0x08, 0x14][channel]),
                3599,
                "refused code not written"
            );
        }
    }

    #[test]
    fn the_window_mirrors_the_upper_threshold_around_the_zero() {
        // Zero at mid-scale (1.65 V of 3.3 V), upper at code 3599 (+2.499 A at 0.5 V/A): the
        // lower is 4096 - 3599 = 497 (0.400 V, -2.499 A).
        assert_eq!(window_low_code(1 << 30, 3599), Some(497));
        // Tared zero slightly high: the window moves with it.
        let zero = (1 << 30) + (10 << 19);
        assert_eq!(window_low_code(zero, 3619), Some(497));
        // The lower threshold would leave the range or cross the zero: refused.
        assert_eq!(window_low_code(1 << 30, 4095), Some(1));
        assert_eq!(window_low_code(1 << 28, 1100), None);
        assert_eq!(window_low_code(0, 100), None);
        assert_eq!(window_low_code(-5, 100), None);
        assert_eq!(window_low_code(1 << 30, 2048), None);
    }

    /// For a tared zero between two DAC steps the lower code is the exact mirror rounded
    /// *up* (the lower comparator trips at most as late as the upper one's mirror), from an
    /// f64 mirror: `2 * zero / 2^31 * 4096 - high`.
    #[test]
    fn the_window_low_code_rounds_up_for_a_zero_between_dac_steps() {
        let high = 3599u16;
        for zero in [
            (1 << 30) + 1,
            (1 << 30) + (1 << 17),
            (1 << 30) + (1 << 18) - 1,
            (1 << 30) + (1 << 18) + 3,
            (1 << 30) - (1 << 16),
            (1 << 30) - 1,
        ] {
            let mirror = 2.0 * f64::from(zero) / f64::from(1u32 << 31) * 4096.0 - f64::from(high);
            assert_ne!(mirror.fract(), 0.0, "zero {zero} lies between steps");
            let expected = mirror.ceil() as u16;
            assert_eq!(window_low_code(zero, high), Some(expected), "zero {zero}");
        }
    }

    /// A DAC code as the current it stands for on `sense`, mA.
    fn code_ma(code: u16, sense: &ShuntAmplifier) -> i64 {
        let reading = sonolube::fx::Q1_31::from_bits(i32::from(code) << 19);
        let amps = sense.calibration().unwrap().apply(reading).value;
        i64::from(amps.to_bits()) * 1000 / 65_536
    }

    #[test]
    fn the_boards_thresholds() {
        use sonolube::drive::OvercurrentTrip;
        let stack = STACK_SENSE.calibration().unwrap();
        let high = OvercurrentTrip::new(STACK_TRIP_CURRENT, &stack)
            .unwrap()
            .dac_code();
        let low = window_low_code(stack.offset().to_bits(), high).unwrap();
        let dc = OvercurrentTrip::new(DC_LINK_TRIP_CURRENT, &DC_LINK_SENSE.calibration().unwrap())
            .unwrap()
            .dac_code();
        let mv = |code: u16| u32::from(code) * 3300 / 4096;
        std::eprintln!(
            "thresholds: COMP1 DAC3 {high} ({} mV, {} mA), COMP3 DAC1 {low} ({} mV, {} mA), \
             COMP6 DAC4 {dc} ({} mV, {} mA)",
            mv(high),
            code_ma(high, &STACK_SENSE),
            mv(low),
            code_ma(low, &STACK_SENSE),
            mv(dc),
            code_ma(dc, &DC_LINK_SENSE)
        );
        assert_eq!((high, low, dc), (3599, 497, 3537));
        // The same codes from the schematic's numbers in f64, not from the code: the trip
        // voltage `zero + shunt x gain x I` on the 12-bit DAC's 3.3 V scale, rounded towards
        // the zero current, so that each comparator trips at most at the requested current
        // (down for the upper thresholds, up for the window's lower one at -2.5 A).
        let exact = |sense: &ShuntAmplifier, amps: f64| {
            let volts = f64::from(sense.zero_millivolt) / 1e3
                + f64::from(sense.shunt_micro_ohm) / 1e6 * f64::from(sense.gain_milli) / 1e3 * amps;
            volts / (f64::from(sense.full_scale_millivolt) / 1e3) * 4096.0
        };
        assert_eq!(f64::from(high), exact(&STACK_SENSE, 2.5).floor());
        assert_eq!(f64::from(low), exact(&STACK_SENSE, -2.5).ceil());
        assert_eq!(f64::from(dc), exact(&DC_LINK_SENSE, 6.0).floor());
        // Never later than asked: |trip| at most the requested current.
        assert!((2490..=2500).contains(&code_ma(high, &STACK_SENSE)));
        assert!((-2500..=-2490).contains(&code_ma(low, &STACK_SENSE)));
        assert!((5980..=6000).contains(&code_ma(dc, &DC_LINK_SENSE)));
    }

    #[test]
    fn system_breaks_are_locked_and_tim1_freezes_on_halt() {
        let mut syscfg = Image::new();
        syscfg.set_word(0x1C, 0);
        // SAFETY: the image outlives the handle.
        lock_system_breaks(unsafe { Syscfg::from_ptr(syscfg.ptr()) }, &mut |_| {});
        // RM0440 SYSCFG_CFGR2 at 0x1C: CLL 0, SPL 1, PVDL 2, ECCL 3, SPF 8.
        assert_eq!(syscfg.word(0x1C), 0b1011);
        let mut dbg = Image::new();
        // SAFETY: as above.
        freeze_tim1_on_halt(unsafe { Dbgmcu::from_ptr(dbg.ptr()) }, &mut |_| {});
        // RM0440 DBGMCU_APB2FZR at 0x10, DBG_TIM1_STOP bit 11.
        assert_eq!(dbg.word(0x10), 1 << 11);
        // SAFETY: as above.
        freeze_watchdog_on_halt(unsafe { Dbgmcu::from_ptr(dbg.ptr()) }, &mut |_| {});
        // RM0440 DBGMCU_APB1FZR1 at 0x08, DBG_IWDG_STOP bit 12.
        assert_eq!(dbg.word(0x08), 1 << 12);
        assert_eq!(dbg.word(0x10), 1 << 11);
    }

    #[test]
    fn clocks_and_analog_pins() {
        let mut rcc = Image::new();
        // SAFETY: the image outlives the handle.
        enable_clocks(unsafe { Rcc::from_ptr(rcc.ptr()) }, &mut |_| {});
        // RM0440 RCC_AHB2ENR at 0x4C: GPIOA..C 0-2, DAC1 16, DAC3 18, DAC4 19; APB2ENR 0x60
        // SYSCFGEN bit 0.
        assert_eq!(rcc.word(0x4C), 0b111 | (1 << 16) | (1 << 18) | (1 << 19));
        assert!(rcc.bit(0x60, 0));
        let mut gpio = Image::new();
        gpio.set_word(0x0C, 0b01 << 2);
        // SAFETY: as above.
        analog_pin(unsafe { Gpio::from_ptr(gpio.ptr()) }, 1, &mut |_| {});
        assert_eq!(gpio.bits(0x00, 2, 2), 0b11);
        assert_eq!(gpio.bits(0x0C, 2, 2), 0);
    }
}
