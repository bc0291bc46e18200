//! TIM1 as the half-bridge drive: CH1 (PA8) high side, CH1N (PB13) low side, dithered period
//! (CR1.DITHEN, 16.4 ARR/CCR), dead time, break from COMP1 (stack current) and break 2 from COMP3
//! (bus shunt), TRGO2 = OC4REF for ADC2's stepped current samples, OC3REF at a fixed 3/4 of the
//! period for ADC1's load-cell scan (its trigger TIM1_CC3), and BDTR locked in its first write.
//!
//! The firmware owns TIM1 entirely (no embassy driver): embassy's `ComplementaryPwm` writes BDTR
//! (MOE, dead time) in its constructor, and RM0440 freezes the LOCK field at the first write of
//! BDTR after reset, so a lock written afterwards would never take. Here [`configure`] writes
//! BDTR exactly once, after a peripheral reset ([`enable_clock`]), with the lock level, the dead
//! time, the break setup and MOE = 0 in the same write.
//!
//! Order of [`configure`] (each step is one register write):
//! counter stopped, outputs disabled (CCER = 0), PSC, CR2 (idle levels low, MMS2), CCMR1/CCMR2,
//! AF1/AF2 (break sources), BDTR (once: DTG, OSSI/OSSR, BKE/BKP/BKF, BK2E/BK2P/BK2F, AOE = 0,
//! MOE = 0, LOCK), CR1 (ARPE, DITHEN, counter still stopped), ARR, CCR1, CCR3, CCR4, EGR.UG (load the
//! preloads), SR (flags cleared), CCER (CC1E, CC1NE, CC3E: driven to the idle level since MOE = 0 and
//! OSSI = 1), CR1.CEN. Only [`try_enable_outputs`] sets MOE, after all of it.

use sonolube::drive::{Amplitude, DeadTime, DriveTiming};

use crate::Step;
use crate::pac::gpio::Gpio;
use crate::pac::gpio::vals::{Moder, Ospeedr, Ot, Pupdr};
use crate::pac::rcc::Rcc;
use crate::pac::timer::TimAdv;
use crate::pac::timer::regs::{
    Af1Adv, Af2Adv, ArrDitherCore, BdtrAdv, CcerAdv, CcmrOutputGp16, Ccr1ch, CcrDither1ch, Cr1Gp16,
    Cr2Adv, SrAdv,
};
use crate::pac::timer::vals::{Bkinp, Bkp, FilterValue, Lock, Mms2, Ocm, Ossi, Ossr};

/// CH1 is channel index 0.
const CH1: usize = 0;
/// CCR4 (the ADC trigger) is `ccr(3)`. In dither mode it holds a 16.4 value like CCR1; the
/// metapac models dither-format CCRs for CH1-2 only (`ccr_dither(n)` asserts `n < 2`), so it is
/// written raw through `ccr(3)`, the same 32-bit register at TIM1 + 0x40.
const CCR4: usize = 3;
/// In CCMR2, CH4 is index 1.
const CCMR2_CH4: usize = 1;
/// CH3 (ADC1's trigger, TIM1_CC3) is channel index 2 (CCER, `ccr(2)`) and index 0 in CCMR2.
/// Like CCR4 it is written raw in the dithered 16.4 format through `ccr(2)`.
const CH3: usize = 2;
const CCMR2_CH3: usize = 0;
/// BRK and BRK2 in the BDTR break field arrays.
const BRK: usize = 0;
const BRK2: usize = 1;
/// COMP1 is index 0 of TIM1_AF1.BKCMPxE; COMP3 and COMP6 are indices 2 and 5 of
/// TIM1_AF2.BK2CMPxE.
pub const BRK_COMP1: usize = 0;
pub const BRK2_COMP3: usize = 2;
pub const BRK2_COMP6: usize = 5;

/// Break and break 2 filter: 6 samples at f_DTS / 8 (282 ns at 170 MHz). Rejects the
/// comparators' response to switching spikes shorter than that.
pub const BREAK_FILTER: FilterValue = FilterValue::FDTS_DIV8_N6;
/// The break filter's delay, ns at 170 MHz: 6 samples x 8 ticks of 5.88 ns.
pub const BREAK_FILTER_NS: u32 = (6 * 8 * 1_000_000_000u64 / 170_000_000) as u32;

/// BDTR lock level. Level 3 freezes DTG, BKE/BKP/BKF, BK2E/BK2P/BK2F, AOE, OIS1/OIS1N (level 1),
/// OSSI/OSSR and CC1P/CC1NP (level 2), OC1M/OC1PE and OC4M/OC4PE (level 3) until reset. MOE is
/// locked by no level (RM0440, TIMx_BDTR LOCK), so the drive can still be switched on and off.
pub const LOCK_LEVEL: Lock = Lock::LEVEL3;

/// TIM1_SR is rc_w0: a 1 leaves a flag alone, a 0 clears it. Clears BIF (bit 7), B2IF (bit 8)
/// and SBIF (bit 13, system break); leaves UIF..TIF (0-6), CCxOF (9-12), CC5IF/CC6IF (16-17),
/// IDXF..TERRF (20-23) alone; reserved bits 0.
pub const SR_CLEAR_BREAKS: u32 = 0x00F3_1E7F;
/// TIM1_SR with every flag cleared.
pub const SR_CLEAR_ALL: u32 = 0;

/// PA8 = TIM1_CH1 and PB13 = TIM1_CH1N, alternate function 6 (DS12288 alternate function table).
pub const HIGH_SIDE_PIN: usize = 8;
pub const LOW_SIDE_PIN: usize = 13;
pub const TIM1_AF: u8 = 6;

/// Why a TIM1 write was refused. Nothing was written when one is returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Refused {
    /// MOE is set: the dead time and the break setup are written only with the outputs off.
    OutputsOn,
    /// BDTR was already written since reset (its LOCK field is frozen): call [`enable_clock`]
    /// (which resets TIM1) first.
    AlreadyLocked,
    /// The timing's dead time differs from the one locked into BDTR at configuration.
    DeadTimeDiffers,
}

/// Enables TIM1's clock and pulses its reset, so the next BDTR write is the first one.
pub fn enable_clock(rcc: Rcc, hook: &mut impl FnMut(Step)) {
    rcc.apb2enr().modify(|w| w.set_tim1en(true));
    hook("RCC_APB2ENR");
    rcc.apb2rstr().modify(|w| w.set_tim1rst(true));
    hook("RCC_APB2RSTR");
    rcc.apb2rstr().modify(|w| w.set_tim1rst(false));
    hook("RCC_APB2RSTR");
}

/// The single BDTR value: dead time, off-state selection (OSSI = OSSR = 1: outputs at the idle
/// level while disabled), break from BRK and BRK2 active high through the filter, AOE = 0 (a
/// break latches until software sets MOE), MOE = 0, and the lock level.
pub fn bdtr_value(dead_time: DeadTime) -> BdtrAdv {
    let mut w = BdtrAdv(0);
    w.set_dtg(dead_time.dtg());
    w.set_ossi(Ossi::IDLE_LEVEL);
    w.set_ossr(Ossr::IDLE_LEVEL);
    w.set_aoe(false);
    w.set_moe(false);
    for brk in [BRK, BRK2] {
        w.set_bke(brk, true);
        w.set_bkp(brk, Bkp::ACTIVE_HIGH);
        w.set_bkf(brk, BREAK_FILTER);
    }
    w.set_lock(LOCK_LEVEL);
    w
}

/// Configures TIM1 for `timing` with zero amplitude and the outputs off (see the module doc for
/// the order), and starts the counter (the ADC needs its triggers). Refused, with nothing
/// written, while MOE is set or after BDTR has been locked.
pub fn configure(
    tim: TimAdv,
    timing: &DriveTiming,
    hook: &mut impl FnMut(Step),
) -> Result<(), Refused> {
    let bdtr = tim.bdtr().read();
    if bdtr.moe() {
        return Err(Refused::OutputsOn);
    }
    if bdtr.lock() != Lock::DISABLED {
        return Err(Refused::AlreadyLocked);
    }
    tim.cr1().write_value(Cr1Gp16(0));
    hook("TIM1_CR1");
    tim.ccer().write_value(CcerAdv(0));
    hook("TIM1_CCER");
    tim.psc().write_value(0);
    hook("TIM1_PSC");
    let mut cr2 = Cr2Adv(0);
    cr2.set_ois(CH1, false);
    cr2.set_oisn(CH1, false);
    cr2.set_mms2(Mms2::COMPARE_OC4);
    tim.cr2().write_value(cr2);
    hook("TIM1_CR2");
    // CH1: PWM mode 1 (high while the counter is below CCR1), preloaded.
    let mut ccmr1 = CcmrOutputGp16(0);
    ccmr1.set_ocm(0, Ocm::PWM_MODE1);
    ccmr1.set_ocpe(0, true);
    tim.ccmr_output(0).write_value(ccmr1);
    hook("TIM1_CCMR1");
    // CH4: PWM mode 2, so OC4REF rises at CCR4 and TRGO2 starts ADC2 there (stepped by the
    // current table's DMA). CH3: PWM mode 2 too, OC3REF rising at CCR3, a fixed 3/4 of the
    // period in the low-side phase: ADC1's load-cell scan (trigger TIM1_CC3) stays in that quiet
    // window whatever phase CCR4 steps to (review finding 4). Both preloaded, so a compare
    // changes only at an update event, together with ARR.
    let mut ccmr2 = CcmrOutputGp16(0);
    ccmr2.set_ocm(CCMR2_CH3, Ocm::PWM_MODE2);
    ccmr2.set_ocpe(CCMR2_CH3, true);
    ccmr2.set_ocm(CCMR2_CH4, Ocm::PWM_MODE2);
    ccmr2.set_ocpe(CCMR2_CH4, true);
    tim.ccmr_output(1).write_value(ccmr2);
    hook("TIM1_CCMR2");
    // Break sources: COMP1 only on BRK, COMP3 and COMP6 only on BRK2; the BKIN pins off (their
    // reset value is on). (BKCMPxP exists for COMP1-4 only; COMP6's polarity is its own.)
    let mut af1 = Af1Adv(0);
    af1.set_bkine(false);
    af1.set_bkcmpe(BRK_COMP1, true);
    af1.set_bkcmpp(BRK_COMP1, Bkinp::NOT_INVERTED);
    tim.af1().write_value(af1);
    hook("TIM1_AF1");
    let mut af2 = Af2Adv(0);
    af2.set_bk2ine(false);
    af2.set_bk2cmpe(BRK2_COMP3, true);
    af2.set_bk2cmpp(BRK2_COMP3, Bkinp::NOT_INVERTED);
    af2.set_bk2cmpe(BRK2_COMP6, true);
    tim.af2().write_value(af2);
    hook("TIM1_AF2");
    tim.bdtr().write_value(bdtr_value(timing.dead_time()));
    hook("TIM1_BDTR");
    // DITHEN may only change while the counter is stopped (RM0440, "Dithering mode").
    let mut cr1 = Cr1Gp16(0);
    cr1.set_arpe(true);
    cr1.set_dithen(true);
    tim.cr1().write_value(cr1);
    hook("TIM1_CR1");
    write_period_registers(tim, timing, Amplitude::ZERO, hook);
    tim.egr().write(|w| w.set_ug(true));
    hook("TIM1_EGR");
    tim.sr().write_value(SrAdv(SR_CLEAR_ALL));
    hook("TIM1_SR");
    let mut ccer = CcerAdv(0);
    ccer.set_cce(CH1, true);
    ccer.set_ccne(CH1, true);
    // CC3E: so that ADC1's TIM1_CC3 trigger does not depend on whether RM0440's CC3 event is
    // taken before or after the output enable. OC3 reaches no pin: PA10 (TIM1_CH3) stays in
    // its reset analog mode (no AF6), and with MOE = 0 the output is at its idle level anyway.
    ccer.set_cce(CH3, true);
    tim.ccer().write_value(ccer);
    hook("TIM1_CCER");
    tim.cr1().modify(|w| w.set_cen(true));
    hook("TIM1_CR1");
    Ok(())
}

/// Connects PA8/PB13 to TIM1 (AF6, push-pull, high speed, no pull: the gate-driver inputs have
/// their own pull-downs). Call after [`configure`]: TIM1 then drives both low (MOE = 0, OSSI =
/// 1), so the pins go from high impedance to driven low. Output data low first, mode last.
pub fn connect_pins(gpioa: Gpio, gpiob: Gpio, hook: &mut impl FnMut(Step)) {
    for (gpio, pin, name) in [
        (
            gpioa,
            HIGH_SIDE_PIN,
            [
                "GPIOA_BSRR",
                "GPIOA_OTYPER",
                "GPIOA_OSPEEDR",
                "GPIOA_PUPDR",
                "GPIOA_AFR",
                "GPIOA_MODER",
            ],
        ),
        (
            gpiob,
            LOW_SIDE_PIN,
            [
                "GPIOB_BSRR",
                "GPIOB_OTYPER",
                "GPIOB_OSPEEDR",
                "GPIOB_PUPDR",
                "GPIOB_AFR",
                "GPIOB_MODER",
            ],
        ),
    ] {
        gpio.bsrr().write(|w| w.set_br(pin, true));
        hook(name[0]);
        gpio.otyper().modify(|w| w.set_ot(pin, Ot::PUSH_PULL));
        hook(name[1]);
        gpio.ospeedr()
            .modify(|w| w.set_ospeedr(pin, Ospeedr::HIGH_SPEED));
        hook(name[2]);
        gpio.pupdr().modify(|w| w.set_pupdr(pin, Pupdr::FLOATING));
        hook(name[3]);
        gpio.afr(pin / 8).modify(|w| w.set_afr(pin % 8, TIM1_AF));
        hook(name[4]);
        gpio.moder().modify(|w| w.set_moder(pin, Moder::ALTERNATE));
        hook(name[5]);
    }
}

/// ARR, CCR1, CCR3 and CCR4 for `timing` at `amplitude`, without guarding the update event (the
/// counter is stopped during [`configure`]; [`write_timing`] guards it).
fn write_period_registers(
    tim: TimAdv,
    timing: &DriveTiming,
    amplitude: Amplitude,
    hook: &mut impl FnMut(Step),
) {
    tim.arr_dither()
        .write_value(ArrDitherCore(timing.period().arr_register()));
    hook("TIM1_ARR");
    tim.ccr_dither(CH1)
        .write_value(CcrDither1ch(timing.duty_compare(amplitude)));
    hook("TIM1_CCR1");
    tim.ccr(CH3)
        .write_value(Ccr1ch(timing.adc_trigger_compare()));
    hook("TIM1_CCR3");
    tim.ccr(CCR4)
        .write_value(Ccr1ch(timing.adc_trigger_compare()));
    hook("TIM1_CCR4");
}

/// Switches period, duty and ADC triggers together: update events are disabled (CR1.UDIS = 1)
/// while ARR, CCR1, CCR3 and CCR4 are written, so the preload registers are never transferred
/// with a new ARR and an old CCR; the next period boundary after UDIS = 0 takes all four. Refused,
/// with nothing written, when `timing`'s dead time is not the one locked in BDTR (the dead time
/// is written only by [`configure`], with MOE = 0).
pub fn write_timing(
    tim: TimAdv,
    timing: &DriveTiming,
    amplitude: Amplitude,
    hook: &mut impl FnMut(Step),
) -> Result<(), Refused> {
    if tim.bdtr().read().dtg() != timing.dead_time().dtg() {
        return Err(Refused::DeadTimeDiffers);
    }
    tim.cr1().modify(|w| w.set_udis(true));
    hook("TIM1_CR1");
    write_period_registers(tim, timing, amplitude, hook);
    tim.cr1().modify(|w| w.set_udis(false));
    hook("TIM1_CR1");
    Ok(())
}

/// TIM1_SR value that clears UIF alone (rc_w0: every other flag bit written 1, reserved bits 0).
pub const SR_CLEAR_UIF: u32 = 0x00F3_3FFE;

/// Whether an update event fell inside [`write_timing_stepped`]'s UDIS window.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum UpdateEvents {
    /// Every period boundary produced its update (and its DMA request).
    AllTaken,
    /// One period boundary passed with UDIS set: no shadow load, no update DMA request.
    OneSuppressed,
}

/// [`write_timing`] for the stepped ADC trigger ([`crate::current`]): ARR, CCR1 and CCR3
/// (ADC1's fixed trigger at 3/4 of the new period, below the new ARR) under CR1.UDIS, CCR4 left to the DMA table except that its preload is pulled below
/// `ccr4_limit` (dithered format; [`crate::current::trigger_limit`] of the old and new ARR)
/// when it is not already: the preload holds an entry for the old period, which the next
/// update makes active under the new ARR, and an entry at or above the new ARR never makes
/// OC4REF rise (no TRGO2, no conversion). The suppressed update is detected too: UIF is
/// cleared first and the counter read before UDIS is set and after it is cleared: the counter
/// went backwards (it wrapped; the window is far shorter than a period) while no update event
/// set UIF exactly when the wrap happened with UDIS set. (A wrap before UDIS took effect or
/// after it was cleared sets UIF.) Refused, with nothing written, as [`write_timing`].
///
/// The caller runs it in a critical section: an interrupt inside the window longer than a
/// period would hide a whole counter wrap from the CNT comparison.
pub fn write_timing_stepped(
    tim: TimAdv,
    timing: &DriveTiming,
    amplitude: Amplitude,
    ccr4_limit: u32,
    hook: &mut impl FnMut(Step),
) -> Result<UpdateEvents, Refused> {
    if tim.bdtr().read().dtg() != timing.dead_time().dtg() {
        return Err(Refused::DeadTimeDiffers);
    }
    tim.sr().write_value(SrAdv(SR_CLEAR_UIF));
    hook("TIM1_SR");
    let before = tim.cnt().read().cnt();
    tim.cr1().modify(|w| w.set_udis(true));
    hook("TIM1_CR1");
    tim.arr_dither()
        .write_value(ArrDitherCore(timing.period().arr_register()));
    hook("TIM1_ARR");
    tim.ccr_dither(CH1)
        .write_value(CcrDither1ch(timing.duty_compare(amplitude)));
    hook("TIM1_CCR1");
    tim.ccr(CH3)
        .write_value(Ccr1ch(timing.adc_trigger_compare()));
    hook("TIM1_CCR3");
    // CCR4 (channel index 3) in the dithered format, as the table's DMA writes it.
    let preloaded = tim.ccr(3).read().0;
    if preloaded >= ccr4_limit {
        tim.ccr(3)
            .write_value(Ccr1ch(ccr4_limit.saturating_sub(16).max(16)));
        hook("TIM1_CCR4");
    }
    tim.cr1().modify(|w| w.set_udis(false));
    hook("TIM1_CR1");
    let after = tim.cnt().read().cnt();
    let updated = tim.sr().read().uif();
    Ok(if after < before && !updated {
        UpdateEvents::OneSuppressed
    } else {
        UpdateEvents::AllTaken
    })
}

/// Sets the duty for `amplitude` (CCR1, dithered), effective at the next period. One register,
/// so no update event can split it.
pub fn set_amplitude(
    tim: TimAdv,
    timing: &DriveTiming,
    amplitude: Amplitude,
    hook: &mut impl FnMut(Step),
) {
    tim.ccr_dither(CH1)
        .write_value(CcrDither1ch(timing.duty_compare(amplitude)));
    hook("TIM1_CCR1");
}

/// Sets MOE: the bridge switches. Refused (false, nothing written) while a break flag is set;
/// false too if MOE did not stick (a break input active at that moment).
pub fn try_enable_outputs(tim: TimAdv, hook: &mut impl FnMut(Step)) -> bool {
    if break_tripped(tim) {
        return false;
    }
    tim.bdtr().modify(|w| w.set_moe(true));
    hook("TIM1_BDTR");
    tim.bdtr().read().moe()
}

/// Whether a break (BRK: stack current, BRK2: bus current, or a system break such as a core
/// lockup) has occurred since the flags were last cleared.
pub fn break_tripped(tim: TimAdv) -> bool {
    let sr = tim.sr().read();
    sr.bif(BRK) || sr.bif(BRK2) || sr.sbif()
}

/// Acknowledges the breaks (BIF, B2IF, SBIF), leaving every other flag alone.
pub fn clear_break_flags(tim: TimAdv, hook: &mut impl FnMut(Step)) {
    tim.sr().write_value(SrAdv(SR_CLEAR_BREAKS));
    hook("TIM1_SR");
}

/// Whether the outputs are enabled (MOE).
pub fn outputs_enabled(tim: TimAdv) -> bool {
    tim.bdtr().read().moe()
}

#[cfg(test)]
mod tests;
