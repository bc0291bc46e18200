//! ADC1 plan: the two load cells and the stack current converted on every PWM period.
//!
//! Each TIM1_CC3 event (OC3REF rising at CCR3, a fixed 3/4 of the period, in the long low-side
//! phase; [`crate::tim1`]) starts one scan of the regular sequence PA0 (ADC1_IN1, normal force), PB0 (ADC1_IN15,
//! tangential force), PA1 (ADC1_IN2, stack current), with no hardware oversampling, so a
//! complete triplet arrives every PWM period. At 24.5 + 12.5 ADC clock cycles per conversion and
//! 42.5 MHz the scan takes 2.61 us, inside the 4.17 us from the trigger to the end of the period
//! at 60 kHz (the shortest in the band). ADC1 has its own trigger, not TRGO2: TRGO2 follows CCR4,
//! which the current table steps a quarter period each period for ADC2 ([`crate::current`]), and
//! a scan started at the period's start or middle would straddle a switching edge (review
//! finding 4). The DMA moves the triplets into a circular buffer
//! (CFGR.DMACFG = 1 here, the channel's CIRC bit by embassy's ring buffer: [`check_dma_ring`]).
//!
//! The sensing task sums [`SCANS_PER_PAIR`] consecutive scans per channel and scales the sum to
//! the 16-bit format of the old 16x oversampled plan ([`pair_code`]), so a fresh load-cell pair
//! reaches the control loop every 2 PWM periods: 10 kHz at 20 kHz, 20 kHz at 40 kHz, 30 kHz at
//! 60 kHz, at least one per 10 kHz control period over the whole band (the old plan gave one
//! per 48 periods, 833/s at 40 kHz).
//!
//! The ADC itself (voltage regulator, calibration, ADEN) is brought up by embassy's driver;
//! [`program_regular`] then writes every field of the plan with ADSTART = 0, before the ring
//! starts.

use crate::Step;
use crate::pac::adc::Adc;
use crate::pac::adc::regs::{Cfgr, Cfgr2, Smpr, Smpr2, Sqr1};
use crate::pac::adc::vals::{Dmacfg, Dmaen, Exten, Ovrmod, Res, SampleTime};
use crate::pac::bdma::Dma;
use crate::pac::bdma::vals::{Dir, Size};
use crate::pac::dmamux::Dmamux;

/// ADC1/ADC2 regular external trigger 10 is TIM1_TRGO2 (RM0440, ADC1/2 regular trigger table):
/// ADC2's stepped current samples.
pub const EXTSEL_TIM1_TRGO2: u8 = 10;
/// ADC1/ADC2 regular external trigger 2 is TIM1_CC3 (RM0440, the same table): ADC1's scan.
pub const EXTSEL_TIM1_CC3: u8 = 2;
/// The regular sequence: ADC1 channel numbers of PA0, PB0, PA1.
pub const SEQUENCE: [u8; 3] = [1, 15, 2];
/// Sampling time of every channel: 24.5 ADC cycles (576 ns at 42.5 MHz), enough for the
/// low-impedance amplifier outputs (INA826, INA240) on these pins.
pub const SAMPLE_TIME: SampleTime = SampleTime::CYCLES24_5;
/// Sampling plus the 12.5-cycle successive approximation, in half cycles.
pub const CONVERSION_HALF_CYCLES: u32 = 49 + 25;
/// DMAMUX request line of ADC1 (RM0440, DMAMUX request table).
pub const DMAMUX_REQ_ADC1: u8 = 5;
/// Scans summed into one pair.
pub const SCANS_PER_PAIR: u32 = 2;

/// One scan of the sequence at `adc_clock_hz`, ns, rounded up.
pub const fn scan_ns(adc_clock_hz: u32) -> u32 {
    let half_cycles = CONVERSION_HALF_CYCLES as u64 * SEQUENCE.len() as u64;
    (half_cycles * 1_000_000_000).div_ceil(2 * adc_clock_hz as u64) as u32
}

/// [`SCANS_PER_PAIR`] 12-bit results of one channel as one code of the 16-bit format
/// (0 to 65 520, full scale 65 536, the range of 16 summed 12-bit samples): the sum times 8.
/// Bits above the 12 a conversion can produce are refused (None), not masked.
pub const fn pair_code(first: u16, second: u16) -> Option<u16> {
    if first > 4095 || second > 4095 {
        return None;
    }
    Some((first + second) << 3)
}

/// Refused: a regular conversion is running (CFGR, SMPR and SQR are written only with
/// ADSTART = 0, RM0440).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AdcRunning;

/// CFGR of a converter on one of the PWM's triggers (`extsel`: [`EXTSEL_TIM1_CC3`] for ADC1's
/// scan, [`EXTSEL_TIM1_TRGO2`] for ADC2's current conversion): DMA circular, 12 bits
/// right-aligned, rising edge, one sequence per trigger (no continuous or discontinuous mode),
/// overrun overwrites, injected queue disabled (its reset value; injected conversions are unused).
pub fn triggered_cfgr(extsel: u8) -> Cfgr {
    let mut cfgr = Cfgr(0);
    cfgr.set_dmaen(Dmaen::ENABLE);
    cfgr.set_dmacfg(Dmacfg::CIRCULAR);
    cfgr.set_res(Res::BITS12);
    cfgr.set_align(false);
    cfgr.set_extsel(extsel);
    cfgr.set_exten(Exten::RISING_EDGE);
    cfgr.set_ovrmod(Ovrmod::OVERWRITE);
    cfgr.set_cont(false);
    cfgr.set_discen(false);
    cfgr.set_jqdis(true);
    cfgr
}

/// Writes the plan: CFGR ([`triggered_cfgr`] on TIM1_CC3), CFGR2 (no oversampling), SMPR1/SMPR2, SQR1.
pub fn program_regular(adc: Adc, hook: &mut impl FnMut(Step)) -> Result<(), AdcRunning> {
    if adc.cr().read().adstart() {
        return Err(AdcRunning);
    }
    let cfgr = triggered_cfgr(EXTSEL_TIM1_CC3);
    adc.cfgr().write_value(cfgr);
    hook("ADC1_CFGR");
    adc.cfgr2().write_value(Cfgr2(0));
    hook("ADC1_CFGR2");
    let mut smpr = Smpr(0);
    let mut smpr2 = Smpr2(0);
    let mut sqr1 = Sqr1(0);
    sqr1.set_l(SEQUENCE.len() as u8 - 1);
    for (rank, &channel) in SEQUENCE.iter().enumerate() {
        let channel = usize::from(channel);
        if channel < 10 {
            smpr.set_smp(channel, SAMPLE_TIME);
        } else {
            smpr2.set_smp(channel - 10, SAMPLE_TIME);
        }
        sqr1.set_sq(rank, channel as u8);
    }
    adc.smpr().write_value(smpr);
    hook("ADC1_SMPR1");
    adc.smpr2().write_value(smpr2);
    hook("ADC1_SMPR2");
    adc.sqr1().write_value(sqr1);
    hook("ADC1_SQR1");
    Ok(())
}

/// What [`check_dma_ring`] found wrong in the DMA channel the ADC ring runs on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DmaProblem {
    /// Not enabled.
    Disabled,
    /// Not circular: the ring would stop after one pass.
    NotCircular,
    /// Direction, increments or sizes are not "16-bit peripheral register to 16-bit memory
    /// array".
    Layout,
    /// The peripheral address is not ADC1_DR.
    Address,
    /// The DMAMUX channel does not forward ADC1's request.
    Request,
}

/// Checks DMA1 channel `channel` (0 = channel 1) and its DMAMUX channel as embassy's ring
/// buffer set them up: enabled, circular, peripheral-to-memory, memory increment only, 16-bit
/// both sides, from `adc_dr_address`, on ADC1's request.
pub fn check_dma_ring(
    dma: Dma,
    channel: usize,
    dmamux: Dmamux,
    adc_dr_address: u32,
) -> Result<(), DmaProblem> {
    let ch = dma.ch(channel);
    let cr = ch.cr().read();
    if !cr.en() {
        return Err(DmaProblem::Disabled);
    }
    if !cr.circ() {
        return Err(DmaProblem::NotCircular);
    }
    if cr.dir() != Dir::FROM_PERIPHERAL
        || cr.pinc()
        || !cr.minc()
        || cr.psize() != Size::BITS16
        || cr.msize() != Size::BITS16
        || cr.mem2mem()
    {
        return Err(DmaProblem::Layout);
    }
    if ch.par().read() != adc_dr_address {
        return Err(DmaProblem::Address);
    }
    if dmamux.ccr(channel).read().dmareq_id() != DMAMUX_REQ_ADC1 {
        return Err(DmaProblem::Request);
    }
    Ok(())
}

/// Whether the ADC overran since the last call (ISR.OVR, bit 4: a conversion ended before the
/// DMA read the previous one), clearing the flag (rc_w1: only OVR is written 1, so the other
/// flags are left alone). With OVRMOD = 1 the new result overwrites the old one silently: a
/// lost DMA request rotates the DMA's place in the channel sequence, so every later sample
/// may carry another channel's code. The caller treats it as a sensor fault.
pub fn take_overrun(adc: Adc) -> bool {
    let overran = adc.isr().read().ovr();
    if overran {
        adc.isr().write(|w| w.set_ovr(true));
    }
    overran
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::Image;

    #[test]
    fn the_plan_in_rm0440s_fields() {
        let mut image = Image::new();
        image.set_word(0x0C, 0x8000_0000); // CFGR reset value (JQDIS)
        image.set_word(0x10, 0b1 | (3 << 2) | (4 << 5) | (1 << 9)); // a 16x TROVS leftover
        // SAFETY: the image outlives the handle.
        let adc = unsafe { Adc::from_ptr(image.ptr()) };
        let mut steps = std::vec::Vec::new();
        program_regular(adc, &mut |s| steps.push(s)).unwrap();
        // RM0440 ADC_CFGR at 0x0C: DMAEN 0, DMACFG 1, RES 3-4, EXTSEL 5-9, EXTEN 10-11,
        // OVRMOD 12, CONT 13, ALIGN 15, DISCEN 16, JQDIS 31.
        assert!(image.bit(0x0C, 0), "DMAEN");
        assert!(image.bit(0x0C, 1), "DMACFG circular");
        assert_eq!(image.bits(0x0C, 3, 2), 0, "12 bits");
        // RM0440's ADC1/2 regular trigger table: EXT2 = TIM1_CC3 (EXT10 is TIM1_TRGO2, the
        // stepped trigger of ADC2 that this scan must not follow).
        assert_eq!(image.bits(0x0C, 5, 5), 2, "EXTSEL = TIM1_CC3");
        assert_eq!(image.bits(0x0C, 10, 2), 0b01, "EXTEN rising");
        assert!(image.bit(0x0C, 12), "OVRMOD overwrite");
        assert!(!image.bit(0x0C, 13), "CONT = 0: one scan per trigger");
        assert!(!image.bit(0x0C, 15), "right-aligned");
        assert!(
            !image.bit(0x0C, 16),
            "DISCEN = 0: the whole sequence per trigger"
        );
        // ADC_CFGR2 at 0x10: ROVSE 0, OVSR 2-4, OVSS 5-8, TROVS 9: no oversampling at all.
        assert!(!image.bit(0x10, 0), "ROVSE");
        assert_eq!(image.bits(0x10, 2, 3), 0, "OVSR");
        assert_eq!(image.bits(0x10, 5, 4), 0, "OVSS");
        assert!(!image.bit(0x10, 9), "TROVS");
        // SMPR1 at 0x14 (SMPx at 3x): channels 1 and 2; SMPR2 at 0x18: channel 15 at bits 15-17.
        assert_eq!(image.bits(0x14, 3, 3), 0b011, "SMP1 24.5 cycles");
        assert_eq!(image.bits(0x14, 6, 3), 0b011, "SMP2 24.5 cycles");
        assert_eq!(image.bits(0x18, 15, 3), 0b011, "SMP15 24.5 cycles");
        // SQR1 at 0x30: L 0-3, SQ1 6-10, SQ2 12-16, SQ3 18-22.
        assert_eq!(image.bits(0x30, 0, 4), 2, "three conversions");
        assert_eq!(image.bits(0x30, 6, 5), 1, "SQ1 = IN1 (PA0)");
        assert_eq!(image.bits(0x30, 12, 5), 15, "SQ2 = IN15 (PB0)");
        assert_eq!(image.bits(0x30, 18, 5), 2, "SQ3 = IN2 (PA1)");
        assert_eq!(
            steps,
            [
                "ADC1_CFGR",
                "ADC1_CFGR2",
                "ADC1_SMPR1",
                "ADC1_SMPR2",
                "ADC1_SQR1"
            ]
        );
    }

    #[test]
    fn the_plan_is_refused_while_converting() {
        let mut image = Image::new();
        image.set_word(0x08, 1 << 2); // CR.ADSTART
        let before = image.snapshot();
        // SAFETY: the image outlives the handle.
        let adc = unsafe { Adc::from_ptr(image.ptr()) };
        assert_eq!(program_regular(adc, &mut |_| {}), Err(AdcRunning));
        assert_eq!(image.snapshot(), before);
    }

    #[test]
    fn one_scan_fits_the_quiet_window_of_every_period_in_the_band() {
        let adc_clock = 42_500_000;
        assert_eq!(scan_ns(adc_clock), 2612);
        // The trigger sits at 3/4 of the period: the scan must end before the next switching
        // edge, at the period's end. Shortest window at 60 kHz: 4.17 us.
        for hz in [20_000u32, 40_000, 60_000] {
            let window_ns = 1_000_000_000 / hz / 4;
            assert!(scan_ns(adc_clock) < window_ns, "{hz} Hz");
        }
        // (The old plan's 47.5-cycle sampling would not: 3 x 60 cycles = 4.24 us > 4.17 us.)
    }

    /// ADC clock of the board: SYSCLK 170 MHz / 4 (embassy's ADC12 prescaler, the board's
    /// `config::ADC_CLOCK_HZ`; the bring-up checklist reads ADC12_CCR back on the board).
    const ADC_CLOCK_HZ: f64 = 42.5e6;
    const TIM1_CLOCK_HZ: f64 = 170e6;
    /// Trigger to start of sampling, ADC clock cycles: the external trigger is resynchronised
    /// to the ADC clock. Taken as 3 cycles here (an assumption, not a figure from RM0440's
    /// tables; the board's bring-up checklist measures it).
    const TRIGGER_LATENCY_CYCLES: f64 = 3.0;

    /// RM0440, SMPx codes 0-7: 2.5, 6.5, 12.5, 24.5, 47.5, 92.5, 247.5, 640.5 ADC cycles.
    fn sampling_cycles(code: u32) -> f64 {
        [2.5, 6.5, 12.5, 24.5, 47.5, 92.5, 247.5, 640.5][code as usize]
    }

    /// RM0440, dead-time generator: DTG's four ranges, in t_DTS ticks (CKD = 0).
    fn dead_time_ticks(dtg: u32) -> u32 {
        match dtg >> 5 {
            0..=3 => dtg,
            4 | 5 => (64 + (dtg & 0x3F)) * 2,
            6 => (32 + (dtg & 0x1F)) * 8,
            _ => (32 + (dtg & 0x1F)) * 16,
        }
    }

    /// Where ADC1's conversions fall in the PWM period, from the register images alone (RM0440
    /// fields and offsets, nothing of the code's own timing): for every start of a scan the
    /// trigger can give, the time of the last switching edge before it and of the next one,
    /// and the scan's start and end, all in ns from the period's start.
    struct ScanPosition {
        low_side_on_ns: f64,
        period_end_ns: f64,
        starts_ns: std::vec::Vec<f64>,
        scan_ns: f64,
    }

    fn scan_position(tim: &Image, adc: &Image) -> ScanPosition {
        let tick_ns = 1e9 / TIM1_CLOCK_HZ;
        // TIM1, dithered (CR1.DITHEN): ARR and CCRx in sixteenths of a tick, the period is
        // ARR + 16 sixteenths. The dithering pattern spreads the fraction over 16 periods: the
        // worst case is the shortest period (integer part), the earliest trigger and the latest
        // duty edge.
        assert!(tim.bit(0x00, 12), "DITHEN");
        assert_eq!(tim.bits(0x00, 4, 3), 0, "edge-aligned, up-counting");
        let arr = tim.word(0x2C);
        let period_end_ns = f64::from((arr + 16) >> 4) * tick_ns;
        // CH1 PWM mode 1: high side on below CCR1; the low side comes on a dead time later.
        assert_eq!(tim.bits(0x18, 4, 3), 0b110, "OC1M PWM mode 1");
        let ccr1 = tim.word(0x34);
        let dead_ticks = dead_time_ticks(tim.bits(0x44, 0, 8));
        let low_side_on_ns = f64::from(ccr1.div_ceil(16) + dead_ticks) * tick_ns;
        // ADC1's trigger: EXTSEL (CFGR 5-9), rising edge (EXTEN 10-11 = 01). RM0440's ADC1/2
        // regular trigger table: EXT2 = TIM1_CC3, EXT10 = TIM1_TRGO2 (MMS2 = 0111: OC4REF).
        assert_eq!(adc.bits(0x0C, 10, 2), 0b01, "EXTEN rising");
        let pwm_mode_2 = |ocm_low: u32, ocm_high: bool| ocm_low == 0b111 && !ocm_high;
        let compares: std::vec::Vec<u32> = match adc.bits(0x0C, 5, 5) {
            2 => {
                // OC3REF rises at CCR3 only in PWM mode 2 (mode 1 rises at the update).
                assert!(pwm_mode_2(tim.bits(0x1C, 4, 3), tim.bit(0x1C, 16)));
                std::vec![tim.word(0x3C)]
            }
            10 => {
                assert_eq!(tim.bits(0x04, 20, 4), 0b0111, "MMS2 = OC4REF");
                assert!(pwm_mode_2(tim.bits(0x1C, 12, 3), tim.bit(0x1C, 24)));
                // CCR4 is stepped through the current table's phases by DMA.
                crate::current::phase_table(arr, ccr1).unwrap().to_vec()
            }
            other => panic!("EXTSEL {other}: not a TIM1 compare of this plan"),
        };
        let latency_ns = TRIGGER_LATENCY_CYCLES * 1e9 / ADC_CLOCK_HZ;
        let starts_ns = compares
            .iter()
            .map(|ccr| f64::from(ccr >> 4) * tick_ns + latency_ns)
            .collect();
        // The scan: SQR1.L + 1 conversions, each the channel's sampling time (SMPR1 for
        // channels 0-9, SMPR2 for 10-18, 3 bits each) plus 12.5 cycles (12 bits: CFGR.RES = 0).
        assert_eq!(adc.bits(0x0C, 3, 2), 0, "12 bits");
        let length = adc.bits(0x30, 0, 4) + 1;
        let mut cycles = 0.0;
        for rank in 0..length {
            let channel = adc.bits(0x30, 6 + 6 * rank, 5);
            let code = if channel < 10 {
                adc.bits(0x14, 3 * channel, 3)
            } else {
                adc.bits(0x18, 3 * (channel - 10), 3)
            };
            cycles += sampling_cycles(code) + 12.5;
        }
        ScanPosition {
            low_side_on_ns,
            period_end_ns,
            starts_ns,
            scan_ns: cycles * 1e9 / ADC_CLOCK_HZ,
        }
    }

    fn drive_and_adc1(hz: u32) -> (Box<Image>, Box<Image>) {
        use sonolube::drive::{Amplitude, DriveTiming, Frequency, TimerClock};
        let timing = DriveTiming::new(Frequency::from_hz(hz), 200, TimerClock::G474_TIM1).unwrap();
        let mut tim = Image::new();
        tim.set_word(0x60, 1);
        tim.set_word(0x64, 1);
        // SAFETY: the images outlive the handles.
        let handle = unsafe { crate::pac::timer::TimAdv::from_ptr(tim.ptr()) };
        crate::tim1::configure(handle, &timing, &mut |_| {}).unwrap();
        // The widest high-side pulse the drive writes: full amplitude, duty 1/2.
        crate::tim1::set_amplitude(handle, &timing, Amplitude::FULL, &mut |_| {});
        let mut adc = Image::new();
        // SAFETY: as above.
        program_regular(unsafe { Adc::from_ptr(adc.ptr()) }, &mut |_| {}).unwrap();
        (tim, adc)
    }

    /// Finding 4: ADC1's scan (both load cells and the stack current) starts after the low side
    /// has come on and ends before the period's end, the next switching edge, at every
    /// frequency of the band (a 10 Hz grid over 20-60 kHz) and the widest duty. Fails with ADC1
    /// on TRGO2: CCR4's stepped phases put scans on both edges.
    #[test]
    fn the_load_cell_scan_sits_in_the_quiet_window_at_every_frequency_of_the_band() {
        let mut tightest_ns = f64::INFINITY;
        for hz in (20_000..=60_000).step_by(10) {
            let (tim, adc) = drive_and_adc1(hz);
            let p = scan_position(&tim, &adc);
            for start in &p.starts_ns {
                assert!(
                    *start >= p.low_side_on_ns,
                    "{hz} Hz: scan at {start:.0} ns before the low side is on ({:.0} ns)",
                    p.low_side_on_ns
                );
                let end = start + p.scan_ns;
                assert!(
                    end <= p.period_end_ns,
                    "{hz} Hz: scan ends at {end:.0} ns, after the period ({:.0} ns)",
                    p.period_end_ns
                );
                tightest_ns = tightest_ns.min(p.period_end_ns - end);
            }
        }
        // At 60 kHz: 16 667 ns period, trigger at 12 500 ns, 2 612 ns scan plus the latency.
        assert!(tightest_ns > 1_400.0, "margin {tightest_ns:.0} ns");
    }

    #[test]
    fn the_scan_on_trgo2_would_straddle_a_switching_edge() {
        let (tim, mut adc) = drive_and_adc1(40_000);
        let cfgr = adc.word(0x0C);
        adc.set_word(
            0x0C,
            (cfgr & !(0x1F << 5)) | (u32::from(EXTSEL_TIM1_TRGO2) << 5),
        );
        let p = scan_position(&tim, &adc);
        assert!(
            p.starts_ns
                .iter()
                .any(|s| *s < p.low_side_on_ns || s + p.scan_ns > p.period_end_ns)
        );
    }

    #[test]
    fn fresh_pairs_at_least_every_10_khz_control_period() {
        for pwm_hz in [20_000u32, 40_000, 60_000] {
            let pairs_per_s = pwm_hz / SCANS_PER_PAIR;
            assert!(
                pairs_per_s >= 10_000,
                "{pwm_hz} Hz PWM: {pairs_per_s} pairs/s"
            );
        }
    }

    #[test]
    fn pair_codes_span_the_16_bit_format_and_refuse_wider_inputs() {
        assert_eq!(pair_code(0, 0), Some(0));
        assert_eq!(pair_code(4095, 4095), Some(65_520));
        assert_eq!(pair_code(2048, 2047), Some(32_760));
        assert_eq!(pair_code(4096, 0), None);
        assert_eq!(pair_code(0, u16::MAX), None);
    }

    fn dma_ok_image() -> (Box<Image>, Box<Image>) {
        let mut dma = Image::new();
        // Channel 1 CCR at 0x08: EN, TCIE, HTIE, CIRC, MINC, PSIZE 16, MSIZE 16.
        dma.set_word(0x08, 1 | 2 | 4 | (1 << 5) | (1 << 7) | (1 << 8) | (1 << 10));
        dma.set_word(0x10, 0x5000_0040); // CPAR = ADC1_DR
        let mut mux = Image::new();
        mux.set_word(0x00, 5);
        (dma, mux)
    }

    #[test]
    fn the_dma_ring_check_accepts_embassys_setup_and_names_each_fault() {
        let check = |dma: &mut Image, mux: &mut Image| {
            // SAFETY: the images outlive the handles.
            let (d, m) = unsafe { (Dma::from_ptr(dma.ptr()), Dmamux::from_ptr(mux.ptr())) };
            check_dma_ring(d, 0, m, 0x5000_0040)
        };
        let (mut dma, mut mux) = dma_ok_image();
        assert_eq!(check(&mut dma, &mut mux), Ok(()));
        for (clear, problem) in [
            (1u32, DmaProblem::Disabled),
            (1 << 5, DmaProblem::NotCircular),
            (1 << 7, DmaProblem::Layout),
            (1 << 8, DmaProblem::Layout),
        ] {
            let (mut dma, mut mux) = dma_ok_image();
            let ccr = dma.word(0x08);
            dma.set_word(0x08, ccr & !clear);
            assert_eq!(check(&mut dma, &mut mux), Err(problem));
        }
        let (mut dma, mut mux) = dma_ok_image();
        dma.set_word(0x10, 0x5000_0140);
        assert_eq!(check(&mut dma, &mut mux), Err(DmaProblem::Address));
        let (mut dma, mut mux) = dma_ok_image();
        mux.set_word(0x00, 6);
        assert_eq!(check(&mut dma, &mut mux), Err(DmaProblem::Request));
    }

    /// RM0440 ADC_ISR at 0x00: OVR is bit 4, cleared by writing 1; EOC (2), EOS (3) and ADRDY
    /// (0) must not be written 1 with it.
    #[test]
    fn an_overrun_is_taken_once_and_only_ovr_is_cleared() {
        let mut image = Image::new();
        // SAFETY: the image outlives the handle.
        let adc = unsafe { Adc::from_ptr(image.ptr()) };
        image.set_word(0x00, 0b0_1101);
        assert!(!take_overrun(adc));
        assert_eq!(
            image.word(0x00),
            0b0_1101,
            "nothing written without an overrun"
        );
        image.set_word(0x00, 0b1_1101);
        assert!(take_overrun(adc));
        // A RAM image keeps the written value: exactly OVR written 1.
        assert_eq!(image.word(0x00), 1 << 4);
    }
}
