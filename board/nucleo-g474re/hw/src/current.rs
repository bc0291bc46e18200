//! The drive current for the resonance loop: ADC2 converts PA1 (ADC2_IN2, the INA240 output)
//! once per PWM period on TIM1 TRGO2, at a trigger phase that steps a quarter period each
//! period (docs/resonance-adc-plan.md).
//!
//! # The stepped trigger
//!
//! TRGO2 is OC4REF (PWM mode 2: rising at CCR4). A DMA channel on TIM1's update request
//! (DMAMUX request [`DMAMUX_REQ_TIM1_UP`]) writes CCR4 from a circular four-entry table at every
//! update event; CCR4 is preloaded (OC4PE, set by [`crate::tim1::configure`]), so a value
//! written at the update that ends period `n` takes effect at the next update and triggers in
//! period `n + 2` ([`TABLE_LEAD`]). The table holds, in the format of the dithered compare
//! registers (sixteenths of a tick), the trigger at `1/8, 3/8, 5/8, 7/8` of the period after
//! the maximum of the drive voltage's fundamental ([`phase_table`]): the high-side pulse of
//! the edge-aligned PWM1 output runs from 0 to CCR1, so that maximum is at `CCR1/2`. The
//! control step rewrites the table whenever it writes CCR1 or ARR ([`dma_order`]).
//!
//! # The converter and its ring
//!
//! ADC2 converts IN2 alone ([`program_adc`]): 12 bits, 2.5-cycle sampling (59 ns at
//! 42.5 MHz, 0.85 degrees at 40 kHz), external trigger 10 = TIM1_TRGO2 on the rising edge,
//! no oversampling, DMA circular. A second DMA channel moves each result into a
//! [`RING_LEN`]-entry ring (DMAMUX request [`DMAMUX_REQ_ADC2`]). Conversion `c` lands at ring
//! index `c mod 16` and was taken at phase index `c mod 4` ([`start`] makes period 0 the first
//! conversion, at phase 0), so the ring index alone names a sample's phase: the control step
//! drains the ring from its last read position ([`pending`]) into `Station::push_current`.
//!
//! # Updates suppressed by a frequency change
//!
//! A frequency change holds update events off while ARR and CCR1 are written (CR1.UDIS,
//! [`crate::tim1::write_timing_stepped`]). A period boundary inside that window (a few bus
//! cycles out of 2,800 to 8,500 ticks) loads no shadow register and requests no DMA transfer:
//! from then on the DMA's table position lags the periods by one. `write_timing_stepped`
//! reports it, and [`dma_order`] rotates the table by the number of such skips, so that the
//! sample in period `p` is again at phase `p mod 4` from the second period after the rewrite
//! (the two or three samples in between are a quarter period off: one lock-in window).
//!
//! # A frequency change loses no conversion
//!
//! CCR4's preload holds the entry the update DMA wrote for the old period, and the table in
//! memory holds three more. An entry at or above the new ARR never makes OC4REF rise: no
//! TRGO2, no conversion, and from then on the ring index no longer names the phase (the
//! conversion count lags the periods). [`change_timing`] therefore keeps every compare that
//! can become active across the change below [`trigger_limit`], the smaller of the old and
//! new ARR: the table is first rewritten for the new period with its entries pulled below
//! that limit, then ARR and CCR1 are written under UDIS with CCR4's preload pulled below it
//! too, and only then is the table written unclamped. Whichever period boundary falls between
//! these writes, every compare made active runs under an ARR above it (the model in the tests
//! checks every frequency pair of the band on a 500 Hz grid at every such position). A pulled
//! entry samples up to a quarter period early: the sample is there, on a slightly wrong phase,
//! in the lock-in window the change disturbs anyway.
//!
//! Register layouts: RM0440 rev 8 (ADC, DMA, DMAMUX, advanced-control timer chapters).

use core::sync::atomic::{AtomicU32, Ordering};

use sonolube::drive::{Amplitude, DriveTiming};

use crate::Step;
use crate::adc::{AdcRunning, EXTSEL_TIM1_TRGO2, triggered_cfgr};
use crate::pac::adc::Adc;
use crate::pac::adc::regs::{Cfgr2, Smpr, Sqr1};
use crate::pac::adc::vals::SampleTime;
use crate::pac::bdma::Dma;
use crate::pac::bdma::regs::Cr;
use crate::pac::bdma::vals::{Dir, Pl, Size};
use crate::pac::dmamux::Dmamux;
use crate::pac::timer::TimAdv;
use crate::pac::timer::regs::{Ccr1ch, SrAdv};
use crate::tim1::{Refused, UpdateEvents, write_timing_stepped};

/// Entries of the ADC2 ring (a multiple of 4, so a ring index names a phase).
pub const RING_LEN: usize = 16;
/// Entries of the CCR4 table: one turn of the quarter-period steps.
pub const TABLE_LEN: usize = 4;
/// Periods from a table entry's DMA transfer (at the update ending period `n`) to the period
/// it triggers in (`n + 2`): the transfer lands in CCR4's preload register, which the next
/// update copies to the active register.
pub const TABLE_LEAD: usize = 2;
/// ADC2_IN2 (PA1): the current-sense amplifier's output.
pub const CURRENT_CHANNEL: u8 = 2;
/// Sampling time: 2.5 ADC cycles (the INA240 drives the pin at low impedance).
pub const SAMPLE_TIME: SampleTime = SampleTime::CYCLES2_5;
/// DMAMUX request line of ADC2 (RM0440 DMAMUX request table; stm32-metapac's G474 data).
pub const DMAMUX_REQ_ADC2: u8 = 36;
/// DMAMUX request line of the TIM1 update event.
pub const DMAMUX_REQ_TIM1_UP: u8 = 46;
/// DMA1 channel (index, 0 = channel 1) of the ADC2 ring. Channel 1 is ADC1's (embassy's ring).
pub const RING_DMA_CHANNEL: usize = 1;
/// DMA1 channel (index) of the CCR4 table.
pub const TABLE_DMA_CHANNEL: usize = 2;
/// Offset of TIM1_CCR4 in TIM1's block.
pub const TIM1_CCR4_OFFSET: u32 = 0x40;
/// One tick in the dithered compare format.
const TICK: u32 = 16;

/// Why [`phase_table`] has no table for these register values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TableError {
    /// ARR (dithered format) outside the drive band's range: the period must be at least
    /// 64 ticks (a quarter period wider than the excluded edges) and ARR at most 0xFFFE.F.
    Period,
    /// CCR1 beyond half the period (rounded up): the drive never runs above duty 1/2.
    Duty,
}

/// The four trigger compares (TIM1_CCR4, dithered format: sixteenths of a tick) of one turn,
/// phase index `j = 0..3` at `CCR1/2 + (1/8 + j/4)` of the period, from TIM1_ARR (dithered:
/// the period is `arr + 16` sixteenths) and TIM1_CCR1 (dithered, at most half the period).
///
/// Each entry lies in `[16, arr & !0xF)`: an integer part of at least one tick, so OC4REF is
/// low at the start of every period and rises once; and at least one tick below ARR's integer
/// part, so the dithered compare is reached in every period of the dithering pattern. Entries
/// follow each other by a quarter period rounded to the sixteenth. When the ideal position of
/// one entry falls in the excluded edges (less than 3 ticks around the period boundary), all
/// four move together by the least amount that clears it (at most 24 sixteenths, 1.5 ticks:
/// 0.19 degrees at 60 kHz), which keeps the quarter-period spacing.
///
/// `u32` arithmetic, no division but by 8 (a shift): cheap enough for every control step.
pub const fn phase_table(arr: u32, ccr1: u32) -> Result<[u32; TABLE_LEN], TableError> {
    // 0xFFFE.F: the dithered ARR's largest value (`sonolube::drive::PwmPeriod`).
    if arr > 0x000F_FFEF || arr < 63 * TICK {
        return Err(TableError::Period);
    }
    let period = arr + TICK;
    // Half the period rounded up: `DriveTiming::duty_compare` rounds duty 1/2 to nearest.
    if ccr1 > period.div_ceil(2) {
        return Err(TableError::Duty);
    }
    let low = TICK;
    let high = arr & !(TICK - 1);
    let mut entries = [0u32; TABLE_LEN];
    // The shift that clears the edges, as an amount added modulo the period (0: none).
    let mut shift = 0u32;
    let mut j = 0;
    while j < TABLE_LEN {
        // 8 x (CCR1/2 + (2j + 1) T/8) <= 4 (T + 1)/2 + 7 T < 2^24 for T < 2^20: no overflow.
        let eighths = 4 * ccr1 + (2 * j as u32 + 1) * period;
        // Rounded to the nearest sixteenth; below 9 T/8 + 1, so one subtraction wraps it.
        let mut x = (eighths + 4) / 8;
        if x >= period {
            x -= period;
        }
        entries[j] = x;
        if x < low || x >= high {
            // Up to `low` (through the wrap) or down below `high` (through the wrap).
            let (up, down) = if x < low {
                (low - x, x + 1 + (period - high))
            } else {
                (period - x + low, x - high + 1)
            };
            shift = if up <= down { up } else { period - down };
        }
        j += 1;
    }
    if shift != 0 {
        let mut j = 0;
        while j < TABLE_LEN {
            let moved = entries[j] + shift;
            entries[j] = if moved >= period {
                moved - period
            } else {
                moved
            };
            j += 1;
        }
    }
    Ok(entries)
}

/// The table as the DMA channel reads it: memory entry `i` is transferred at the update
/// ending period `4k + i + skipped` and triggers two periods later ([`TABLE_LEAD`]), so it
/// holds phase index `(i + 2 + skipped) mod 4`. `skipped` counts the update events that
/// frequency changes suppressed since [`start`] (only its value mod 4 matters).
pub const fn dma_order(phases: &[u32; TABLE_LEN], skipped: u32) -> [u32; TABLE_LEN] {
    let mut memory = [0u32; TABLE_LEN];
    let mut i = 0;
    while i < TABLE_LEN {
        memory[i] = phases[(i + TABLE_LEAD + skipped as usize % TABLE_LEN) % TABLE_LEN];
        i += 1;
    }
    memory
}

/// The bound CCR4 must stay below across a change of TIM1_ARR from `old_arr` to `new_arr`
/// (dithered format): the integer part of the smaller, the bound [`phase_table`] keeps its
/// entries below for their own ARR.
pub const fn trigger_limit(old_arr: u32, new_arr: u32) -> u32 {
    let smaller = if old_arr < new_arr { old_arr } else { new_arr };
    smaller & !(TICK - 1)
}

/// `phases` with every entry at or above `limit` pulled one tick below it (never below one
/// tick), so that each is reached under either ARR of a change.
pub const fn clamp_table(phases: &[u32; TABLE_LEN], limit: u32) -> [u32; TABLE_LEN] {
    let below = if limit > 2 * TICK { limit - TICK } else { TICK };
    let mut out = *phases;
    let mut j = 0;
    while j < TABLE_LEN {
        if out[j] >= limit {
            out[j] = below;
        }
        j += 1;
    }
    out
}

/// What [`change_timing`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Changed {
    /// Whether an update event fell inside the UDIS window.
    pub events: UpdateEvents,
    /// Suppressed updates since the start, mod 4, this change's included (the table is
    /// written rotated by it, [`dma_order`]).
    pub skipped: u32,
}

/// Why [`change_timing`] wrote nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ChangeRefused {
    /// No table for the new registers.
    Table(TableError),
    /// The timer refused the timing (another dead time).
    Timer(Refused),
}

/// Changes TIM1's period and duty to `timing` at `amplitude` while the stepped trigger runs,
/// losing no conversion (see "A frequency change loses no conversion" above): the table
/// (`table`, the DMA's memory) for the new period with its entries pulled below
/// [`trigger_limit`] of the old ARR (read from TIM1) and the new; ARR, CCR1 and CCR4's
/// preload under UDIS ([`write_timing_stepped`]); then the table unclamped, rotated by the
/// suppressed updates (`skipped` before, the returned count after). Run it in a critical
/// section. Refused with nothing written when there is no table or the dead time differs.
pub fn change_timing(
    tim: TimAdv,
    table: &[AtomicU32; TABLE_LEN],
    timing: &DriveTiming,
    amplitude: Amplitude,
    skipped: u32,
    hook: &mut impl FnMut(Step),
) -> Result<Changed, ChangeRefused> {
    let new_arr = timing.period().arr_register();
    let phases =
        phase_table(new_arr, timing.duty_compare(amplitude)).map_err(ChangeRefused::Table)?;
    if tim.bdtr().read().dtg() != timing.dead_time().dtg() {
        return Err(ChangeRefused::Timer(Refused::DeadTimeDiffers));
    }
    let limit = trigger_limit(tim.arr_dither().read().0, new_arr);
    store_table(table, &dma_order(&clamp_table(&phases, limit), skipped));
    hook("TABLE");
    let events =
        write_timing_stepped(tim, timing, amplitude, limit, hook).map_err(ChangeRefused::Timer)?;
    let skipped = (skipped + u32::from(events == UpdateEvents::OneSuppressed)) % TABLE_LEN as u32;
    store_table(table, &dma_order(&phases, skipped));
    hook("TABLE");
    Ok(Changed { events, skipped })
}

/// Lost conversions found from the two DMA counts, for a realignment of the table.
///
/// Period `p` of the stepped trigger starts with the update that makes the table channel's
/// transfer count `T = p - s` (`s`: the updates frequency changes suppressed) and ends after
/// its conversion, which makes the ring's count `C = p + 1 - L` (`L`: conversions lost since the
/// start). So `X = T + s - C` (mod 4) is `L` between a period's update and its conversion and
/// `L - 1` after it: read the ring's count first and the table's second, and an update or a
/// conversion between the two reads still gives one of these two values. One value alone is
/// ambiguous (the firmware cannot read CCR4's active register to know which half of the period
/// it read in); once both adjacent values have been seen, `L` is the larger (mod 4). The board
/// observes once per control step, whose phase to the PWM period drifts at every frequency
/// but exact submultiples of the control rate.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ConversionAudit {
    /// Bit `x` set: `X = x` was observed since the last verdict.
    seen: u8,
}

impl ConversionAudit {
    /// One observation: `ring_remaining` (the ring channel's CNDTR, read first),
    /// `table_remaining` (the table channel's CNDTR, read second) and the suppressed updates
    /// mod 4. `Some(L)`: the conversions lost mod 4 (0: none), once both values of the pair
    /// have been seen; the audit then starts afresh. None: not yet decided, or a count the
    /// channels cannot have.
    pub fn observe(
        &mut self,
        ring_remaining: u16,
        table_remaining: u16,
        skipped: u32,
    ) -> Option<u32> {
        let converted = write_index(ring_remaining)? as u32;
        let table_remaining = u32::from(table_remaining);
        if table_remaining == 0 || table_remaining > TABLE_LEN as u32 {
            return None;
        }
        let transfers = (TABLE_LEN as u32 - table_remaining) % TABLE_LEN as u32;
        let x = (transfers + skipped % 4 + RING_LEN as u32 - converted % 4) % TABLE_LEN as u32;
        self.seen |= 1 << x;
        match self.seen.count_ones() {
            1 => None,
            2 => {
                // The pair {L - 1, L}: L is the value whose predecessor (mod 4) was seen too.
                let lost = (0..TABLE_LEN as u32)
                    .find(|&l| self.seen & (1 << l) != 0 && self.seen & (1 << ((l + 3) % 4)) != 0);
                self.seen = 0;
                // Two values that are not adjacent cannot happen: start afresh.
                lost
            }
            _ => {
                self.seen = 1 << x;
                None
            }
        }
    }
}

/// The table memory rotated so that the ring index names the phase again after `lost`
/// conversions (mod 4) were lost: as [`dma_order`] with the suppressed updates lowered by
/// `lost` (entry `i` takes entry `i - lost`).
pub const fn realigned(memory: &[u32; TABLE_LEN], lost: u32) -> [u32; TABLE_LEN] {
    let mut out = [0u32; TABLE_LEN];
    let mut i = 0;
    while i < TABLE_LEN {
        out[i] = memory[(i + TABLE_LEN - lost as usize % TABLE_LEN) % TABLE_LEN];
        i += 1;
    }
    out
}

/// Writes the DMA's table memory.
pub fn store_table(table: &[AtomicU32; TABLE_LEN], memory: &[u32; TABLE_LEN]) {
    for (slot, &value) in table.iter().zip(memory) {
        slot.store(value, Ordering::Relaxed);
    }
}

/// The ring index the DMA writes next, from its channel's remaining count (CNDTR counts down
/// from [`RING_LEN`] and reloads in circular mode). None for a count the ring cannot have
/// (0 or above [`RING_LEN`]: the channel is disabled or not the ring's).
pub const fn write_index(remaining: u16) -> Option<usize> {
    let remaining = remaining as usize;
    if remaining == 0 || remaining > RING_LEN {
        return None;
    }
    Some((RING_LEN - remaining) % RING_LEN)
}

/// Samples waiting in the ring between the reader's position `read` and the DMA's `write`
/// (both ring indices), oldest first at `read`: 0 to 15. A reader that fell a whole ring or
/// more behind has lost multiples of 16 samples, which keeps every index's phase.
pub const fn pending(read: usize, write: usize) -> usize {
    (write + RING_LEN - read % RING_LEN) % RING_LEN
}

/// Where a reader that starts now begins: the newest ring index of phase 0 at or before
/// `write` (the first sample a new lock-in takes must be at phase index 0).
pub const fn aligned_start(write: usize) -> usize {
    write % RING_LEN / TABLE_LEN * TABLE_LEN
}

/// Writes ADC2's plan: CFGR (ADC1's set-up, [`triggered_cfgr`], on TIM1_TRGO2), CFGR2 (no
/// oversampling), SMPR1 (IN2 at 2.5 cycles), SQR1 (IN2 alone). Refused ([`AdcRunning`]) while a
/// regular conversion of ADC2 runs.
pub fn program_adc(adc: Adc, hook: &mut impl FnMut(Step)) -> Result<(), AdcRunning> {
    if adc.cr().read().adstart() {
        return Err(AdcRunning);
    }
    let cfgr = triggered_cfgr(EXTSEL_TIM1_TRGO2);
    adc.cfgr().write_value(cfgr);
    hook("ADC2_CFGR");
    adc.cfgr2().write_value(Cfgr2(0));
    hook("ADC2_CFGR2");
    let mut smpr = Smpr(0);
    smpr.set_smp(usize::from(CURRENT_CHANNEL), SAMPLE_TIME);
    adc.smpr().write_value(smpr);
    hook("ADC2_SMPR1");
    let mut sqr1 = Sqr1(0);
    sqr1.set_l(0);
    sqr1.set_sq(0, CURRENT_CHANNEL);
    adc.sqr1().write_value(sqr1);
    hook("ADC2_SQR1");
    Ok(())
}

/// The DMA channel layout of the ring: 16-bit ADC2_DR to 16-bit memory, memory increment,
/// circular, no interrupt (the control step polls CNDTR), high priority.
pub fn ring_channel_config() -> Cr {
    let mut cr = Cr(0);
    cr.set_dir(Dir::FROM_PERIPHERAL);
    cr.set_circ(true);
    cr.set_pinc(false);
    cr.set_minc(true);
    cr.set_psize(Size::BITS16);
    cr.set_msize(Size::BITS16);
    cr.set_pl(Pl::HIGH);
    cr
}

/// The DMA channel layout of the table: 32-bit memory to the 32-bit TIM1_CCR4, memory
/// increment, circular, no interrupt, very high priority (the transfer must land within the
/// period it is requested in: a few bus cycles against 2,800 ticks at 60 kHz).
pub fn table_channel_config() -> Cr {
    let mut cr = Cr(0);
    cr.set_dir(Dir::FROM_MEMORY);
    cr.set_circ(true);
    cr.set_pinc(false);
    cr.set_minc(true);
    cr.set_psize(Size::BITS32);
    cr.set_msize(Size::BITS32);
    cr.set_pl(Pl::VERY_HIGH);
    cr
}

/// Programs DMA1 channel `channel` and its DMAMUX channel: disabled first, then the addresses,
/// the count, the request line, and last the layout `config` with EN.
#[allow(clippy::too_many_arguments)]
fn program_channel(
    dma: Dma,
    dmamux: Dmamux,
    channel: usize,
    peripheral_address: u32,
    memory_address: u32,
    count: u16,
    request: u8,
    config: Cr,
    names: &[Step; 6],
    hook: &mut impl FnMut(Step),
) {
    let ch = dma.ch(channel);
    ch.cr().write_value(Cr(0));
    hook(names[0]);
    ch.par().write_value(peripheral_address);
    hook(names[1]);
    ch.mar().write_value(memory_address);
    hook(names[2]);
    ch.ndtr().write(|w| w.set_ndt(count));
    hook(names[3]);
    dmamux.ccr(channel).write(|w| w.set_dmareq_id(request));
    hook(names[4]);
    let mut enabled = config;
    enabled.set_en(true);
    ch.cr().write_value(enabled);
    hook(names[5]);
}

/// Where [`start`] points its two DMA channels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Addresses {
    /// ADC2_DR.
    pub adc_dr: u32,
    /// TIM1_CCR4.
    pub tim1_ccr4: u32,
    /// The ring, [`RING_LEN`] half-words.
    pub ring: u32,
    /// The table, [`TABLE_LEN`] words, already in [`dma_order`] for `skipped = 0`.
    pub table: u32,
}

/// Why [`start`] wrote nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StartRefused {
    /// TIM1's outputs are on (MOE): the counter is stopped for the start, which would hold the
    /// bridge in one state.
    OutputsOn,
    /// ADC2 is not enabled (ADEN): its calibration and enable come first (embassy's driver).
    AdcDisabled,
    /// ADC2 is converting.
    AdcRunning,
}

/// Starts the stepped current sampling, with TIM1's counter stopped so that conversion 0 is
/// taken in period 0 at phase 0: counter stopped (CR1.CEN = 0), ADC2's plan, the ring's DMA
/// channel, the table's DMA channel, CCR4 = phase 0 and an update (EGR.UG, update DMA still
/// off) to make it active, UIF cleared, CCR4 = phase 1 in the preload for period 1, DIER.UDE
/// (the table then feeds period 2 on), ADC2 ADSTART (waiting for triggers), counter started.
///
/// `phases` is [`phase_table`] for the registers in force. Refused, with nothing written,
/// while MOE is set or ADC2 is disabled or converting.
pub fn start(
    tim: TimAdv,
    adc: Adc,
    dma: Dma,
    dmamux: Dmamux,
    addresses: &Addresses,
    phases: &[u32; TABLE_LEN],
    hook: &mut impl FnMut(Step),
) -> Result<(), StartRefused> {
    if tim.bdtr().read().moe() {
        return Err(StartRefused::OutputsOn);
    }
    let cr = adc.cr().read();
    if !cr.aden() {
        return Err(StartRefused::AdcDisabled);
    }
    if cr.adstart() {
        return Err(StartRefused::AdcRunning);
    }
    tim.cr1().modify(|w| w.set_cen(false));
    hook("TIM1_CR1");
    program_adc(adc, hook).map_err(|_| StartRefused::AdcRunning)?;
    program_channel(
        dma,
        dmamux,
        RING_DMA_CHANNEL,
        addresses.adc_dr,
        addresses.ring,
        RING_LEN as u16,
        DMAMUX_REQ_ADC2,
        ring_channel_config(),
        &[
            "DMA1_CCR2",
            "DMA1_CPAR2",
            "DMA1_CMAR2",
            "DMA1_CNDTR2",
            "DMAMUX_C1CR",
            "DMA1_CCR2",
        ],
        hook,
    );
    program_channel(
        dma,
        dmamux,
        TABLE_DMA_CHANNEL,
        addresses.tim1_ccr4,
        addresses.table,
        TABLE_LEN as u16,
        DMAMUX_REQ_TIM1_UP,
        table_channel_config(),
        &[
            "DMA1_CCR3",
            "DMA1_CPAR3",
            "DMA1_CMAR3",
            "DMA1_CNDTR3",
            "DMAMUX_C2CR",
            "DMA1_CCR3",
        ],
        hook,
    );
    tim.dier().modify(|w| w.set_ude(false));
    hook("TIM1_DIER");
    tim.ccr(3).write_value(Ccr1ch(phases[0]));
    hook("TIM1_CCR4");
    tim.egr().write(|w| w.set_ug(true));
    hook("TIM1_EGR");
    // UG set UIF: cleared before UDE, so that no request can be taken for that old update.
    tim.sr().write_value(SrAdv(crate::tim1::SR_CLEAR_UIF));
    hook("TIM1_SR");
    tim.ccr(3).write_value(Ccr1ch(phases[1]));
    hook("TIM1_CCR4");
    tim.dier().modify(|w| w.set_ude(true));
    hook("TIM1_DIER");
    adc.cr().modify(|w| w.set_adstart(true));
    hook("ADC2_CR");
    tim.cr1().modify(|w| w.set_cen(true));
    hook("TIM1_CR1");
    Ok(())
}

/// What [`check_running`] found wrong.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Stalled {
    /// The ring's DMA channel is disabled (a transfer error clears EN).
    RingChannel,
    /// The table's DMA channel is disabled.
    TableChannel,
    /// ADC2 is not converting on triggers (ADSTART cleared).
    Adc,
    /// ADC2 overran (ISR.OVR): a conversion was not moved to the ring, so from then on a
    /// ring index no longer names its sample's phase.
    Overrun,
}

/// Whether both DMA channels and ADC2 still run (a DMA transfer error disables its channel
/// without an interrupt here) and ADC2 has not overrun (the flag stays set: a ring that lost
/// a conversion stays stalled).
pub fn check_running(dma: Dma, adc: Adc) -> Result<(), Stalled> {
    if !dma.ch(RING_DMA_CHANNEL).cr().read().en() {
        return Err(Stalled::RingChannel);
    }
    if !dma.ch(TABLE_DMA_CHANNEL).cr().read().en() {
        return Err(Stalled::TableChannel);
    }
    if !adc.cr().read().adstart() {
        return Err(Stalled::Adc);
    }
    if adc.isr().read().ovr() {
        return Err(Stalled::Overrun);
    }
    Ok(())
}

/// The ring index the DMA writes next (see [`write_index`]).
pub fn ring_write_index(dma: Dma) -> Option<usize> {
    write_index(dma.ch(RING_DMA_CHANNEL).ndtr().read().ndt())
}

#[cfg(test)]
mod tests;
