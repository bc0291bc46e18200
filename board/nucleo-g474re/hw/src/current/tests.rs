//! The stepped current sampling on RAM images: the phase table against an f64 computation of
//! the same positions, RM0440's fields at RM0440's offsets, the order of the start, and a model
//! of CCR4's preload and the update DMA that checks which phase each period samples.

use core::sync::atomic::{AtomicU32, Ordering};
use std::boxed::Box;
use std::format;
use std::vec::Vec;

use sonolube::drive::{Amplitude, DriveTiming, Frequency, TimerClock};

use super::*;
use crate::image::Image;

// RM0440 offsets. TIM1:
const TIM_CR1: usize = 0x00;
const TIM_DIER: usize = 0x0C;
const TIM_SR: usize = 0x10;
const TIM_EGR: usize = 0x14;
const TIM_CCR4: usize = 0x40;
const TIM_BDTR: usize = 0x44;
// ADC (ADC2's block):
const ADC_CR: usize = 0x08;
const ADC_CFGR: usize = 0x0C;
const ADC_CFGR2: usize = 0x10;
const ADC_SMPR1: usize = 0x14;
const ADC_SQR1: usize = 0x30;
// DMA1 channel x (1-based): CCR at 0x08 + 0x14 (x - 1), then CNDTR, CPAR, CMAR.
const fn dma_ccr(x: usize) -> usize {
    0x08 + 0x14 * (x - 1)
}
const fn dma_cndtr(x: usize) -> usize {
    0x0C + 0x14 * (x - 1)
}
const fn dma_cpar(x: usize) -> usize {
    0x10 + 0x14 * (x - 1)
}
const fn dma_cmar(x: usize) -> usize {
    0x14 + 0x14 * (x - 1)
}
// DMAMUX channel c (0-based, serving DMA1 channel c + 1): CxCR at 4 c, DMAREQ_ID bits 0-6.
const fn mux_ccr(c: usize) -> usize {
    4 * c
}

fn timing(hz: u32) -> DriveTiming {
    DriveTiming::new(Frequency::from_hz(hz), 200, TimerClock::G474_TIM1).unwrap()
}

/// Circular distance between two positions in a period of `period` sixteenths.
fn circular(a: f64, b: f64, period: f64) -> f64 {
    let d = (a - b).rem_euclid(period);
    d.min(period - d)
}

/// Checks one table against the f64 positions `CCR1/2 + (2j + 1) T / 8`: inside
/// `[16, ARR & !0xF)`, a quarter period apart within one sixteenth, and within `tolerance`
/// sixteenths of the ideal position. Returns the largest offset from the ideal.
fn check_table(arr: u32, ccr1: u32, tolerance: f64, label: &str) -> f64 {
    let period = arr + 16;
    let table = phase_table(arr, ccr1).unwrap_or_else(|e| panic!("{label}: {e:?}"));
    let mut worst: f64 = 0.0;
    for (j, &entry) in table.iter().enumerate() {
        assert!(
            entry >= 16 && entry < (arr & !0xF),
            "{label}: entry {j} = {entry} outside [16, {})",
            arr & !0xF
        );
        let ideal = f64::from(ccr1) / 2.0 + (2 * j + 1) as f64 * f64::from(period) / 8.0;
        let offset = circular(f64::from(entry), ideal, f64::from(period));
        assert!(
            offset <= tolerance,
            "{label}: entry {j} is {offset} sixteenths from CCR1/2 + {}/8 T",
            2 * j + 1
        );
        worst = worst.max(offset);
        let next = table[(j + 1) % 4];
        let step = (i64::from(next) - i64::from(entry)).rem_euclid(i64::from(period));
        let quarter = f64::from(period) / 4.0;
        assert!(
            (step as f64 - quarter).abs() <= 1.0,
            "{label}: entries {j} and {} are {step} apart, a quarter period is {quarter}",
            (j + 1) % 4
        );
    }
    worst
}

#[test]
fn the_phase_table_for_every_hertz_from_20_to_60_khz_and_the_extreme_duties() {
    let amplitudes = [
        Amplitude::ZERO,
        Amplitude::from_ratio(1, 1000).unwrap(),
        Amplitude::from_ratio(1, 4).unwrap(),
        Amplitude::from_ratio(707, 1000).unwrap(),
        Amplitude::from_ratio(99, 100).unwrap(),
        Amplitude::FULL,
    ];
    let mut shifted = 0u32;
    let mut worst: f64 = 0.0;
    for hz in 20_000..=60_000 {
        let timing = timing(hz);
        let arr = timing.period().arr_register();
        for amplitude in amplitudes {
            let ccr1 = timing.duty_compare(amplitude);
            // Within 1.5 ticks of the ideal position (the shift away from the period's
            // edges), else within the rounding to a sixteenth.
            let offset = check_table(arr, ccr1, 24.5, &format!("{hz} Hz, CCR1 {ccr1}"));
            if offset > 0.5 {
                shifted += 1;
            }
            worst = worst.max(offset);
        }
        // The duties that put the 7/8 entry on the period's edges: CCR1/2 near T/8.
        let period = arr + 16;
        for edge_ccr1 in [period / 4 - 40, period / 4 - 1, period / 4, period / 4 + 33] {
            check_table(arr, edge_ccr1, 24.5, &format!("{hz} Hz, CCR1 {edge_ccr1}"));
        }
        // Duty 0 and 1/2 exactly.
        check_table(arr, 0, 24.5, &format!("{hz} Hz, duty 0"));
        check_table(arr, period / 2, 24.5, &format!("{hz} Hz, duty 1/2"));
    }
    assert!(worst > 8.0, "the sweep reaches the edge shift ({worst})");
    // Amplitude 0.707 (duty 1/4, CCR1/2 at T/8) puts the 7/8 entry on the period boundary at
    // every frequency.
    assert!(shifted >= 40_001, "{shifted} of 240 006 tables shifted");
}

#[test]
fn an_entry_on_the_period_edge_moves_all_four_together() {
    let timing = timing(40_000);
    let arr = timing.period().arr_register();
    let period = arr + 16;
    assert_eq!(period, 68_000);
    // CCR1 = T/4 puts the 7/8 entry exactly on the period boundary (T/8 + 7T/8 = T).
    let table = phase_table(arr, period / 4).unwrap();
    // ARR = 67 984 = 4249 ticks: excluded from 67 984 up and below 16. Up to 16 costs 16
    // sixteenths, down to 67 983 costs 17: the table moves up by 16.
    assert_eq!(table, [17_016, 34_016, 51_016, 16]);
    // One sixteenth earlier the entry is at 67 999.5, rounded to 68 000 = 0: up by 16 again.
    assert_eq!(phase_table(arr, period / 4 - 1).unwrap()[3], 16);
    // Far from the edge nothing moves: CCR1 = 0 gives T/8, 3T/8, 5T/8, 7T/8.
    assert_eq!(
        phase_table(arr, 0).unwrap(),
        [8_500, 25_500, 42_500, 59_500]
    );
}

#[test]
fn impossible_registers_are_refused() {
    assert_eq!(phase_table(0x000F_FFF0, 0), Err(TableError::Period));
    assert_eq!(phase_table(62 * 16, 0), Err(TableError::Period));
    assert!(phase_table(63 * 16, 0).is_ok());
    assert!(phase_table(0x000F_FFEF, 0).is_ok());
    let arr = timing(40_000).period().arr_register();
    assert_eq!(phase_table(arr, 34_001), Err(TableError::Duty));
    assert!(phase_table(arr, 34_000).is_ok());
    assert_eq!(phase_table(arr, u32::MAX), Err(TableError::Duty));
}

/// CCR4's preload and active registers and the table's DMA position over `periods` periods
/// (RM0440: at each update event the active register takes the preload, and the update's DMA
/// request then writes the next table entry into the preload). `suppressed` lists the period
/// boundaries whose update UDIS held off; at `rewrite.0` (during that period, before its
/// update) the control step rewrites the table for `rewrite.1` skips. Returns the phase index
/// each period's trigger sampled.
fn simulate(
    phases: &[u32; 4],
    periods: usize,
    suppressed: &[usize],
    rewrite: Option<(usize, u32)>,
) -> Vec<usize> {
    let mut memory = dma_order(phases, 0);
    // Where `start` leaves CCR4, read from its register writes, not assumed.
    let (mut active, mut preload) = started_ccr4(phases);
    let mut transfers = 0usize;
    let mut sampled = Vec::new();
    for period in 0..periods {
        let index = phases.iter().position(|&p| p == active).unwrap();
        sampled.push(index);
        if let Some((at, skipped)) = rewrite
            && at == period
        {
            memory = dma_order(phases, skipped);
        }
        if !suppressed.contains(&period) {
            active = preload;
            preload = memory[transfers % 4];
            transfers += 1;
        }
    }
    sampled
}

/// CCR4's active and preload values as [`start`] leaves them, from its writes on the register
/// images (RM0440, advanced-control timers): the software update (EGR.UG) transfers CCR4's
/// preload to the active register, with UDE clear so that no DMA request follows it; the CCR4
/// written after UG stays in the preload until the first update event of the running counter.
/// So the two-period lead of the table ([`TABLE_LEAD`]) is not put into the model: it follows
/// from these two values and RM0440's order at each update (transfer, then the update's DMA
/// request writes the preload).
fn started_ccr4(phases: &[u32; 4]) -> (u32, u32) {
    let mut images = Images::new();
    let addresses = Addresses {
        adc_dr: 0x5000_0140,
        tim1_ccr4: 0x4001_2C40,
        ring: 0x2000_1000,
        table: 0x2000_2000,
    };
    let tim_image = &*images.tim as *const Image;
    // SAFETY: the images outlive the handles.
    let (tim, adc, dma, mux) = unsafe {
        (
            TimAdv::from_ptr(images.tim.ptr()),
            Adc::from_ptr(images.adc.ptr()),
            Dma::from_ptr(images.dma.ptr()),
            Dmamux::from_ptr(images.mux.ptr()),
        )
    };
    let mut at_ug = None;
    start(tim, adc, dma, mux, &addresses, phases, &mut |step| {
        if step == "TIM1_EGR" {
            // SAFETY: the image is alive; read only between the accessors' writes.
            let (ccr4, dier) =
                unsafe { ((*tim_image).word(TIM_CCR4), (*tim_image).word(TIM_DIER)) };
            at_ug = Some((ccr4, dier));
        }
    })
    .unwrap();
    let (active, dier_at_ug) = at_ug.expect("start generates an update (EGR.UG)");
    assert_eq!(dier_at_ug & (1 << 8), 0, "UDE clear at UG");
    assert_eq!(
        images.tim.word(TIM_CR1) & 1,
        1,
        "the counter runs after start"
    );
    (active, images.tim.word(TIM_CCR4))
}

#[test]
fn every_period_samples_the_phase_its_index_names() {
    let phases = phase_table(timing(40_000).period().arr_register(), 10_000).unwrap();
    let sampled = simulate(&phases, 64, &[], None);
    for (period, &index) in sampled.iter().enumerate() {
        assert_eq!(index, period % 4, "period {period}");
    }
}

#[test]
fn a_suppressed_update_is_undone_by_the_rotated_table() {
    let phases = phase_table(timing(40_000).period().arr_register(), 10_000).unwrap();
    for boundary in 5..9 {
        // Without the rotation every later period is a quarter period off.
        let sampled = simulate(&phases, 40, &[boundary], None);
        for (period, &index) in sampled.iter().enumerate().skip(boundary + 3) {
            assert_eq!(index, (period + 3) % 4, "period {period}");
        }
        // The control step that wrote the timing rewrites the table for one skip: from the
        // second period after the rewrite every period is back on its phase.
        let rewrite = boundary + 1;
        let sampled = simulate(&phases, 40, &[boundary], Some((rewrite, 1)));
        let wrong: Vec<usize> = (0..40).filter(|&p| sampled[p] != p % 4).collect();
        assert!(
            wrong.iter().all(|&p| p > boundary && p <= rewrite + 1),
            "boundary {boundary}: periods {wrong:?} off their phase"
        );
        assert!(wrong.len() <= 3, "boundary {boundary}: {wrong:?}");
    }
    // Two skips, rotated by two.
    let sampled = simulate(&phases, 60, &[5, 20], Some((25, 2)));
    for (period, &index) in sampled.iter().enumerate().skip(27) {
        assert_eq!(index, period % 4, "period {period}");
    }
    // The rotation only depends on the skips mod 4.
    assert_eq!(dma_order(&phases, 5), dma_order(&phases, 1));
}

#[test]
fn ring_positions_from_the_dma_count() {
    assert_eq!(write_index(16), Some(0));
    assert_eq!(write_index(15), Some(1));
    assert_eq!(write_index(1), Some(15));
    assert_eq!(write_index(0), None);
    assert_eq!(write_index(17), None);
    assert_eq!(write_index(u16::MAX), None);
    assert_eq!(pending(0, 0), 0);
    assert_eq!(pending(3, 9), 6);
    assert_eq!(pending(14, 2), 4);
    assert_eq!(pending(15, 14), 15);
    for write in 0..RING_LEN {
        let start = aligned_start(write);
        assert_eq!(start % 4, 0);
        assert!(pending(start, write) < 4, "write {write}");
    }
    assert_eq!(aligned_start(7), 4);
    assert_eq!(aligned_start(16), 0);
}

/// TIM1, ADC2, DMA1 and DMAMUX1 images, as embassy leaves them: TIM1 configured (counter on,
/// MOE = 0), ADC2 enabled and idle, channel 1 of DMA1 and DMAMUX channel 0 in use by ADC1.
struct Images {
    tim: Box<Image>,
    adc: Box<Image>,
    dma: Box<Image>,
    mux: Box<Image>,
}

impl Images {
    fn new() -> Self {
        let mut tim = Image::new();
        tim.set_word(TIM_CR1, 0b1 | (1 << 7) | (1 << 12)); // CEN, ARPE, DITHEN
        tim.set_word(TIM_CCR4, 51_000); // configure's 3/4 trigger
        let mut adc = Image::new();
        adc.set_word(ADC_CR, 1 << 28 | 1); // ADVREGEN, ADEN
        adc.set_word(ADC_CFGR, 0x8000_0000);
        let mut dma = Image::new();
        let adc1_ring = 1 | 2 | 4 | (1 << 5) | (1 << 7) | (1 << 8) | (1 << 10);
        dma.set_word(dma_ccr(1), adc1_ring);
        let mut mux = Image::new();
        mux.set_word(mux_ccr(0), 5);
        Self { tim, adc, dma, mux }
    }

    fn run(&mut self, phases: &[u32; 4]) -> (Result<(), StartRefused>, Vec<(Step, Snapshot)>) {
        let addresses = Addresses {
            adc_dr: 0x5000_0140,
            tim1_ccr4: 0x4001_2C40,
            ring: 0x2000_1000,
            table: 0x2000_2000,
        };
        // SAFETY: the images outlive the handles.
        let (tim, adc, dma, mux) = unsafe {
            (
                TimAdv::from_ptr(self.tim.ptr()),
                Adc::from_ptr(self.adc.ptr()),
                Dma::from_ptr(self.dma.ptr()),
                Dmamux::from_ptr(self.mux.ptr()),
            )
        };
        let pointers = [
            &*self.tim as *const Image,
            &*self.adc as *const Image,
            &*self.dma as *const Image,
            &*self.mux as *const Image,
        ];
        let mut steps = Vec::new();
        let result = start(tim, adc, dma, mux, &addresses, phases, &mut |step| {
            // SAFETY: the images are alive; read only between the accessors' writes.
            let snapshot = pointers.map(|p| unsafe { (*p).snapshot() });
            steps.push((step, snapshot));
        });
        (result, steps)
    }
}

/// The four images after one write: TIM1, ADC2, DMA1, DMAMUX1.
type Snapshot = [Vec<u32>; 4];

fn word(snapshot: &[u32], offset: usize) -> u32 {
    snapshot[offset / 4]
}

#[test]
fn the_start_in_rm0440s_fields() {
    let phases = phase_table(timing(40_000).period().arr_register(), 10_000).unwrap();
    let mut images = Images::new();
    let (result, _) = images.run(&phases);
    result.unwrap();
    let (tim, adc, dma, mux) = (&images.tim, &images.adc, &images.dma, &images.mux);
    // ADC_CFGR: DMAEN 0, DMACFG 1 (circular), RES 3-4 = 0 (12 bits), EXTSEL 5-9 = 10
    // (TIM1_TRGO2), EXTEN 10-11 = 01 (rising), OVRMOD 12, CONT 13 = 0, ALIGN 15 = 0,
    // DISCEN 16 = 0.
    assert!(adc.bit(ADC_CFGR, 0), "DMAEN");
    assert!(adc.bit(ADC_CFGR, 1), "DMACFG circular");
    assert_eq!(adc.bits(ADC_CFGR, 3, 2), 0, "12 bits");
    assert_eq!(adc.bits(ADC_CFGR, 5, 5), 10, "EXTSEL = TIM1_TRGO2");
    assert_eq!(adc.bits(ADC_CFGR, 10, 2), 0b01, "EXTEN rising");
    assert!(adc.bit(ADC_CFGR, 12), "OVRMOD");
    assert!(!adc.bit(ADC_CFGR, 13), "CONT = 0");
    assert!(!adc.bit(ADC_CFGR, 15), "right-aligned");
    assert!(!adc.bit(ADC_CFGR, 16), "DISCEN = 0");
    // ADC_CFGR2: ROVSE 0, TROVS 9: no oversampling (it would average the fundamental away).
    assert_eq!(adc.word(ADC_CFGR2), 0);
    // SMPR1: SMP2 at bits 6-8 = 000 (2.5 cycles). SQR1: L = 0 (one conversion), SQ1 = 2.
    assert_eq!(adc.bits(ADC_SMPR1, 6, 3), 0b000, "SMP2 2.5 cycles");
    assert_eq!(adc.bits(ADC_SQR1, 0, 4), 0, "one conversion");
    assert_eq!(adc.bits(ADC_SQR1, 6, 5), 2, "SQ1 = IN2 (PA1)");
    assert!(adc.bit(ADC_CR, 2), "ADSTART");
    assert!(adc.bit(ADC_CR, 0), "ADEN kept");
    // DMA1 channel 2 (the ring): EN 0, TCIE/HTIE/TEIE 1-3 off, DIR 4 = 0 (from peripheral),
    // CIRC 5, PINC 6 = 0, MINC 7, PSIZE 8-9 = 01, MSIZE 10-11 = 01 (16 bits), PL 12-13 = 10,
    // MEM2MEM 14 = 0.
    let ring = dma.word(dma_ccr(2));
    assert_eq!(
        ring,
        1 | (1 << 5) | (1 << 7) | (0b01 << 8) | (0b01 << 10) | (0b10 << 12),
        "DMA1_CCR2 {ring:#x}"
    );
    assert_eq!(dma.word(dma_cndtr(2)), 16);
    assert_eq!(dma.word(dma_cpar(2)), 0x5000_0140, "CPAR2 = ADC2_DR");
    assert_eq!(dma.word(dma_cmar(2)), 0x2000_1000);
    assert_eq!(mux.bits(mux_ccr(1), 0, 7), 36, "DMAMUX C1CR = ADC2");
    // DMA1 channel 3 (the table): EN, DIR 1 (from memory), CIRC, MINC, PSIZE = MSIZE = 10
    // (32 bits), PL 11.
    let table = dma.word(dma_ccr(3));
    assert_eq!(
        table,
        1 | (1 << 4) | (1 << 5) | (1 << 7) | (0b10 << 8) | (0b10 << 10) | (0b11 << 12),
        "DMA1_CCR3 {table:#x}"
    );
    assert_eq!(dma.word(dma_cndtr(3)), 4);
    assert_eq!(dma.word(dma_cpar(3)), 0x4001_2C40, "CPAR3 = TIM1_CCR4");
    assert_eq!(dma.word(dma_cmar(3)), 0x2000_2000);
    assert_eq!(mux.bits(mux_ccr(2), 0, 7), 46, "DMAMUX C2CR = TIM1_UP");
    // ADC1's channel untouched.
    assert_eq!(dma.word(dma_ccr(1)), 0x5A7);
    assert_eq!(mux.word(mux_ccr(0)), 5);
    // TIM1: UDE (DIER bit 8), counter running, CCR4 = phase 1 in the preload.
    assert!(tim.bit(TIM_DIER, 8), "UDE");
    assert!(tim.bit(TIM_CR1, 0), "CEN");
    assert_eq!(tim.bits(TIM_CR1, 1, 1), 0, "UDIS = 0");
    assert_eq!(tim.word(TIM_CCR4), phases[1]);
}

#[test]
fn the_start_aligns_period_0_with_phase_0() {
    let phases = phase_table(timing(23_456).period().arr_register(), 1_234).unwrap();
    let mut images = Images::new();
    let (result, steps) = images.run(&phases);
    result.unwrap();
    let names: Vec<Step> = steps.iter().map(|(s, _)| *s).collect();
    assert_eq!(
        names,
        [
            "TIM1_CR1",
            "ADC2_CFGR",
            "ADC2_CFGR2",
            "ADC2_SMPR1",
            "ADC2_SQR1",
            "DMA1_CCR2",
            "DMA1_CPAR2",
            "DMA1_CMAR2",
            "DMA1_CNDTR2",
            "DMAMUX_C1CR",
            "DMA1_CCR2",
            "DMA1_CCR3",
            "DMA1_CPAR3",
            "DMA1_CMAR3",
            "DMA1_CNDTR3",
            "DMAMUX_C2CR",
            "DMA1_CCR3",
            "TIM1_DIER",
            "TIM1_CCR4",
            "TIM1_EGR",
            "TIM1_SR",
            "TIM1_CCR4",
            "TIM1_DIER",
            "ADC2_CR",
            "TIM1_CR1",
        ]
    );
    let last = steps.len() - 1;
    for (i, (name, [tim, adc, dma, _])) in steps.iter().enumerate() {
        // The counter is stopped from the first write to the last: no trigger and no update
        // event before everything is in place.
        assert_eq!(
            word(tim, TIM_CR1) & 1,
            u32::from(i == last),
            "CEN at {i} ({name})"
        );
        // ADC2's plan is written with ADSTART = 0; ADSTART comes after the DMA channels.
        if name.starts_with("ADC2_C") && *name != "ADC2_CR" || name.starts_with("DMA") {
            assert_eq!(word(adc, ADC_CR) & 4, 0, "ADSTART at {i} ({name})");
        }
        // A channel's addresses and count are written while it is disabled.
        if matches!(*name, "DMA1_CPAR2" | "DMA1_CMAR2" | "DMA1_CNDTR2") {
            assert_eq!(word(dma, dma_ccr(2)) & 1, 0, "{name}");
        }
        if matches!(*name, "DMA1_CPAR3" | "DMA1_CMAR3" | "DMA1_CNDTR3") {
            assert_eq!(word(dma, dma_ccr(3)) & 1, 0, "{name}");
        }
        // The update generated by software loads phase 0 without a DMA request.
        if *name == "TIM1_EGR" {
            assert_eq!(word(tim, TIM_EGR) & 1, 1, "UG");
            assert_eq!(word(tim, TIM_CCR4), phases[0], "CCR4 at UG");
            assert_eq!(word(tim, TIM_DIER) & (1 << 8), 0, "UDE at UG");
        }
    }
    // UG's UIF is cleared (bit 0 written 0, the break flags written 1) before UDE is set.
    let sr = names.iter().position(|n| *n == "TIM1_SR").unwrap();
    assert_eq!(word(&steps[sr].1[0], TIM_SR) & 1, 0, "UIF cleared");
    assert_eq!(
        word(&steps[sr].1[0], TIM_SR) & 0x2180,
        0x2180,
        "BIF, B2IF, SBIF kept"
    );
    assert_eq!(
        word(&steps[sr].1[0], TIM_DIER) & (1 << 8),
        0,
        "UDE after the clear"
    );
    // UDE is set after the preload holds phase 1, and before the counter starts.
    let ude = names.iter().rposition(|n| *n == "TIM1_DIER").unwrap();
    let ccr4 = names.iter().rposition(|n| *n == "TIM1_CCR4").unwrap();
    assert!(ccr4 < ude && ude < last);
    assert_eq!(word(&steps[ccr4].1[0], TIM_CCR4), phases[1]);
}

#[test]
fn the_start_is_refused_with_nothing_written() {
    let phases = phase_table(timing(40_000).period().arr_register(), 0).unwrap();
    for (prepare, refusal) in [
        (
            (|i: &mut Images| i.tim.set_word(TIM_BDTR, 1 << 15)) as fn(&mut Images),
            StartRefused::OutputsOn,
        ),
        (
            |i: &mut Images| i.adc.set_word(ADC_CR, 1 << 28),
            StartRefused::AdcDisabled,
        ),
        (
            |i: &mut Images| i.adc.set_word(ADC_CR, 1 << 28 | 1 << 2 | 1),
            StartRefused::AdcRunning,
        ),
    ] {
        let mut images = Images::new();
        prepare(&mut images);
        let before = [
            images.tim.snapshot(),
            images.adc.snapshot(),
            images.dma.snapshot(),
            images.mux.snapshot(),
        ];
        let (result, steps) = images.run(&phases);
        assert_eq!(result, Err(refusal));
        assert!(steps.is_empty());
        assert_eq!(images.tim.snapshot(), before[0]);
        assert_eq!(images.adc.snapshot(), before[1]);
        assert_eq!(images.dma.snapshot(), before[2]);
        assert_eq!(images.mux.snapshot(), before[3]);
    }
}

#[test]
fn a_stalled_channel_or_converter_is_named() {
    let phases = phase_table(timing(40_000).period().arr_register(), 0).unwrap();
    let mut images = Images::new();
    images.run(&phases).0.unwrap();
    let check = |images: &mut Images| {
        // SAFETY: the images outlive the handles.
        let (dma, adc) = unsafe {
            (
                Dma::from_ptr(images.dma.ptr()),
                Adc::from_ptr(images.adc.ptr()),
            )
        };
        (check_running(dma, adc), ring_write_index(dma))
    };
    assert_eq!(check(&mut images), (Ok(()), Some(0)));
    images.dma.set_word(dma_cndtr(2), 11);
    assert_eq!(check(&mut images).1, Some(5));
    let table = images.dma.word(dma_ccr(3));
    images.dma.set_word(dma_ccr(3), table & !1);
    assert_eq!(check(&mut images).0, Err(Stalled::TableChannel));
    let ring = images.dma.word(dma_ccr(2));
    images.dma.set_word(dma_ccr(2), ring & !1);
    images.dma.set_word(dma_cndtr(2), 0);
    assert_eq!(check(&mut images), (Err(Stalled::RingChannel), None));
    images.dma.set_word(dma_ccr(2), ring);
    images.dma.set_word(dma_ccr(3), table);
    let running_cr = images.adc.word(ADC_CR);
    images.adc.set_word(ADC_CR, 1 << 28 | 1);
    assert_eq!(check(&mut images).0, Err(Stalled::Adc));
    // ADC2_ISR (0x00) OVR, bit 4 (RM0440): an overrun stalls the ring.
    images.adc.set_word(ADC_CR, running_cr);
    assert_eq!(check(&mut images).0, Ok(()));
    images.adc.set_word(0x00, 1 << 4);
    assert_eq!(check(&mut images).0, Err(Stalled::Overrun));
}

/// The current's fundamental measured from the four samples the table takes, by the core's
/// lock-in as the station runs it (`LockIn::synchronous`, first phase 1/8 turn), for a
/// current leading the voltage's fundamental by `lead_deg`. `first` is the phase index of the
/// first sample given to the lock-in (0 when aligned).
fn measured_lead_deg(hz: u32, amplitude: Amplitude, lead_deg: f64, first: usize) -> f64 {
    use sonolube::resonance::{
        LockIn, LockInConfig, SYNCHRONOUS_FIRST_PHASE, SYNCHRONOUS_PHASE_STEP, current_sample,
    };
    let timing = timing(hz);
    let arr = timing.period().arr_register();
    let ccr1 = timing.duty_compare(amplitude);
    let period = f64::from(arr + 16);
    let phases = phase_table(arr, ccr1).unwrap();
    let config = LockInConfig {
        sample_rate_hz: hz,
        periods_per_window: 1,
        sense_delay_ns: 0,
    };
    let mut lock_in =
        LockIn::synchronous(config, timing.frequency(), SYNCHRONOUS_PHASE_STEP).unwrap();
    lock_in.set_drive_phase(SYNCHRONOUS_FIRST_PHASE);
    // The voltage's fundamental peaks at CCR1/2 (the high-side pulse runs from 0 to CCR1).
    let maximum = f64::from(ccr1) / 2.0;
    for k in 0..4 {
        let entry = f64::from(phases[(first + k) % 4]);
        let angle = std::f64::consts::TAU * (entry - maximum) / period + lead_deg.to_radians();
        let code = (2048.0 + 1500.0 * angle.cos()).round() as u16;
        if let Some(window) = lock_in.push(current_sample(code)) {
            return window.phasor.polar().phase.to_radians().to_degrees();
        }
    }
    panic!("no window after four samples");
}

#[test]
fn the_table_samples_at_the_phases_the_lock_in_assumes() {
    for hz in [20_000, 33_333, 40_000, 47_123, 60_000] {
        for amplitude in [
            Amplitude::ZERO,
            Amplitude::from_ratio(1, 10).unwrap(),
            Amplitude::from_ratio(1, 2).unwrap(),
            // Duty 1/4: the table moved off the period edge.
            Amplitude::from_ratio(707, 1000).unwrap(),
            Amplitude::FULL,
        ] {
            for lead in [-80.0, -30.0, 0.0, 45.0, 90.0] {
                let measured = measured_lead_deg(hz, amplitude, lead, 0);
                assert!(
                    (measured - lead).abs() < 0.3,
                    "{hz} Hz, amplitude {}: current leading {lead} deg measured at {measured}",
                    amplitude.fraction().to_f64()
                );
            }
        }
    }
    // A reader starting one sample late (phase index 1) reads the phase a quarter turn off:
    // why the rig starts each station at phase index 0.
    let late = measured_lead_deg(40_000, Amplitude::from_ratio(1, 2).unwrap(), 0.0, 1);
    assert!((late.abs() - 90.0).abs() < 0.3, "{late}");
}

const TIM_CNT: usize = 0x24;
const TIM_ARR: usize = 0x2C;
const TIM_AF1: usize = 0x60;
const TIM_AF2: usize = 0x64;

/// TIM1 with the stepped trigger running, across a frequency change: the RAM image holds the
/// preload registers (what the firmware writes); the model keeps the active ARR and CCR4, the
/// table's DMA position and what ADC2 converted. RM0440 (advanced-control timers): at an
/// update event the active registers take the preloads, and the update's DMA request then
/// writes the next table entry into CCR4's preload; with CR1.UDIS set the counter wraps
/// without either. In PWM mode 2 OC4REF rises once a period when the counter reaches CCR4;
/// with dithering the compare is reached in every period of the pattern when CCR4's integer
/// part is at least one tick and below ARR's (`[16, ARR & !0xF)` in sixteenths), and each
/// rise is a TRGO2, i.e. one ADC2 conversion.
struct Trigger {
    image: Box<Image>,
    arr_active: u32,
    ccr4_active: u32,
    transfers: usize,
    periods: usize,
    /// The active CCR4 of each conversion, in conversion order (= ring order).
    conversions: Vec<u32>,
    /// Periods without a conversion.
    lost: Vec<usize>,
    /// Period boundaries UDIS held off.
    suppressed: usize,
}

impl Trigger {
    /// As [`start`] leaves it for `timing` at `amplitude`: CCR4 = phase 0 active, phase 1
    /// preloaded, the table in DMA order, no transfer yet.
    fn started(timing: &DriveTiming, amplitude: Amplitude, table: &[AtomicU32; 4]) -> Self {
        let mut image = Image::new();
        image.set_word(TIM_AF1, 1);
        image.set_word(TIM_AF2, 1);
        // SAFETY: the image outlives the handle's use here.
        let tim = unsafe { TimAdv::from_ptr(image.ptr()) };
        crate::tim1::configure(tim, timing, &mut |_| {}).unwrap();
        let arr = timing.period().arr_register();
        let phases = phase_table(arr, timing.duty_compare(amplitude)).unwrap();
        let (active, preload) = started_ccr4(&phases);
        image.set_word(TIM_CCR4, preload);
        store_table(table, &dma_order(&phases, 0));
        Self {
            image,
            arr_active: arr,
            ccr4_active: active,
            transfers: 0,
            periods: 0,
            conversions: Vec::new(),
            lost: Vec::new(),
            suppressed: 0,
        }
    }

    fn tim(&mut self) -> TimAdv {
        // SAFETY: the image lives as long as `self`; accesses are volatile, one at a time.
        unsafe { TimAdv::from_ptr(self.image.ptr()) }
    }

    /// The period running now ends at its boundary: its conversion, if OC4REF rose, then the
    /// update event (unless UDIS holds it off).
    fn boundary(&mut self, table: &[AtomicU32; 4]) {
        if (16..self.arr_active & !0xF).contains(&self.ccr4_active) {
            self.conversions.push(self.ccr4_active);
        } else {
            self.lost.push(self.periods);
        }
        self.periods += 1;
        self.image.set_word(TIM_CNT, 0);
        if self.image.bit(TIM_CR1, 1) {
            self.suppressed += 1;
            return;
        }
        self.arr_active = self.image.word(TIM_ARR);
        self.ccr4_active = self.image.word(TIM_CCR4);
        let next = table[self.transfers % 4].load(Ordering::Relaxed);
        self.image.set_word(TIM_CCR4, next);
        self.transfers += 1;
        self.image.set_word(TIM_SR, self.image.word(TIM_SR) | 1);
    }
}

/// What a frequency change did in the model: the conversions, the periods without one, the
/// period the change was made in, and the tables before and after.
struct ChangeRun {
    trigger: Trigger,
    change_period: usize,
    old: [u32; 4],
    new: [u32; 4],
}

/// Runs `before` periods at `from_hz`, changes to `to_hz` (both at `amplitude`) with
/// [`change_timing`] in the next period, the period boundary falling after the change's
/// write number `boundary_at` (None: after the change), then 12 more periods.
fn run_change(
    from_hz: u32,
    to_hz: u32,
    amplitude: Amplitude,
    before: usize,
    boundary_at: Option<usize>,
) -> ChangeRun {
    let table: [AtomicU32; 4] = [const { AtomicU32::new(0) }; 4];
    let (from, to) = (timing(from_hz), timing(to_hz));
    let mut trigger = Trigger::started(&from, amplitude, &table);
    for _ in 0..before {
        trigger.boundary(&table);
    }
    let change_period = trigger.periods;
    trigger.image.set_word(TIM_CNT, 1_000);
    let tim = trigger.tim();
    let mut writes = 0;
    let changed = change_timing(tim, &table, &to, amplitude, 0, &mut |step| {
        if step == "TIM1_SR" {
            // rc_w0: the written zeros clear UIF.
            let written = trigger.image.word(TIM_SR);
            trigger.image.set_word(TIM_SR, written & 1);
        }
        if boundary_at == Some(writes) {
            trigger.boundary(&table);
        }
        writes += 1;
    })
    .unwrap();
    // The change finds the suppressed update (from CNT and UIF) exactly when there was one.
    assert_eq!(
        changed.events == crate::tim1::UpdateEvents::OneSuppressed,
        trigger.suppressed == 1,
        "{from_hz} -> {to_hz} Hz, boundary after write {boundary_at:?} of {writes}"
    );
    for _ in 0..12 {
        trigger.boundary(&table);
    }
    let old = phase_table(from.period().arr_register(), from.duty_compare(amplitude)).unwrap();
    let new = phase_table(to.period().arr_register(), to.duty_compare(amplitude)).unwrap();
    ChangeRun {
        trigger,
        change_period,
        old,
        new,
    }
}

/// No conversion is lost across any change of frequency in the band (every pair of a 500 Hz
/// grid over 20-60 kHz, and 38 -> 40 kHz, the case) at three amplitudes, four table
/// positions and every position of the period boundary among the change's writes; the ring
/// index names the phase before the change and again from the fourth period after it.
#[test]
fn a_frequency_change_loses_no_conversion_and_keeps_the_phases() {
    let amplitudes = [
        Amplitude::ZERO,
        Amplitude::from_ratio(1, 2).unwrap(),
        Amplitude::from_ratio(1, 1).unwrap(),
    ];
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    for from in (20_000..=60_000).step_by(500) {
        for to in (20_000..=60_000).step_by(500) {
            pairs.push((from, to));
        }
    }
    pairs.extend([
        (38_000, 40_000),
        (40_000, 38_000),
        (20_000, 60_000),
        (60_000, 20_000),
    ]);
    let mut runs = 0u32;
    let mut suppressed = 0u32;
    for &(from_hz, to_hz) in &pairs {
        for amplitude in amplitudes {
            for before in 8..12 {
                for boundary_at in [
                    None,
                    Some(0),
                    Some(1),
                    Some(2),
                    Some(3),
                    Some(4),
                    Some(5),
                    Some(6),
                ] {
                    let run = run_change(from_hz, to_hz, amplitude, before, boundary_at);
                    let t = &run.trigger;
                    let label = format!(
                        "{from_hz} -> {to_hz} Hz, amplitude {amplitude:?}, table position \
                         {before}, boundary after write {boundary_at:?}"
                    );
                    assert!(t.lost.is_empty(), "{label}: periods {:?} lost", t.lost);
                    assert_eq!(t.conversions.len(), t.periods, "{label}");
                    for c in 0..run.change_period {
                        assert_eq!(t.conversions[c], run.old[c % 4], "{label}: conversion {c}");
                    }
                    for c in run.change_period + 4..t.conversions.len() {
                        assert_eq!(t.conversions[c], run.new[c % 4], "{label}: conversion {c}");
                    }
                    runs += 1;
                    suppressed += t.suppressed as u32;
                }
            }
        }
    }
    std::eprintln!("{runs} changes, {suppressed} with a suppressed update, none lost a conversion");
    assert!(suppressed > 0);
}

/// The two DMA counts of the model as the channels' CNDTR show them: the ring's, read with
/// the present period's conversion done or not yet, and the table's.
fn counts(t: &Trigger, converted_now: bool) -> (u16, u16) {
    let conversions = t.conversions.len() + usize::from(converted_now);
    let ring = (RING_LEN - conversions % RING_LEN) as u16;
    let table = (TABLE_LEN - t.transfers % TABLE_LEN) as u16;
    (ring, table)
}

#[test]
fn the_audit_needs_both_halves_of_a_period_and_finds_no_loss_without_one() {
    let table: [AtomicU32; 4] = [const { AtomicU32::new(0) }; 4];
    let mut t = Trigger::started(&timing(40_000), Amplitude::ZERO, &table);
    let mut audit = ConversionAudit::default();
    for _ in 0..6 {
        t.boundary(&table);
        let (ring, tab) = counts(&t, false);
        assert_eq!(
            audit.observe(ring, tab, 0),
            None,
            "one value alone decides nothing"
        );
    }
    let (ring, tab) = counts(&t, true);
    assert_eq!(audit.observe(ring, tab, 0), Some(0));
    // Counts the channels cannot have.
    assert_eq!(audit.observe(0, 4, 0), None);
    assert_eq!(audit.observe(16, 0, 0), None);
    assert_eq!(audit.observe(16, 5, 0), None);
}

/// A conversion lost on purpose (CCR4's preload at the period's end, the bug of a frequency
/// change without the clamp): the audit finds one lost conversion from the DMA counts, and
/// the realigned table makes every later conversion `c` sample phase `c mod 4` again.
#[test]
fn a_lost_conversion_is_found_from_the_dma_counts_and_the_table_realigned() {
    for lose_at in 5..9 {
        let table: [AtomicU32; 4] = [const { AtomicU32::new(0) }; 4];
        let drive = timing(40_000);
        let half = Amplitude::from_ratio(1, 2).unwrap();
        let phases = phase_table(drive.period().arr_register(), drive.duty_compare(half)).unwrap();
        let mut t = Trigger::started(&drive, half, &table);
        for _ in 0..lose_at {
            t.boundary(&table);
        }
        // The preload no compare of this period reaches: the next period converts nothing.
        t.image.set_word(TIM_CCR4, drive.period().arr_register());
        for _ in 0..3 {
            t.boundary(&table);
        }
        assert_eq!(t.lost.len(), 1, "lose at {lose_at}");
        // Without a realignment the ring index is a quarter period off from then on.
        let c = t.conversions.len() - 1;
        assert_ne!(t.conversions[c], phases[c % 4]);
        let mut audit = ConversionAudit::default();
        let (ring, tab) = counts(&t, false);
        assert_eq!(audit.observe(ring, tab, 0), None);
        let (ring, tab) = counts(&t, true);
        let lost = audit.observe(ring, tab, 0).expect("both halves seen");
        assert_eq!(lost, 1, "lose at {lose_at}");
        let memory: [u32; 4] = core::array::from_fn(|i| table[i].load(Ordering::Relaxed));
        assert_eq!(realigned(&memory, lost), dma_order(&phases, 4 - lost));
        store_table(&table, &realigned(&memory, lost));
        let realigned_at = t.conversions.len();
        for _ in 0..12 {
            t.boundary(&table);
        }
        assert_eq!(t.lost.len(), 1);
        for c in realigned_at + 3..t.conversions.len() {
            assert_eq!(
                t.conversions[c],
                phases[c % 4],
                "lose at {lose_at}, conversion {c}"
            );
        }
        // The audit agrees: no loss once realigned (the suppressed updates lowered by one).
        let (ring, tab) = counts(&t, false);
        assert_eq!(audit.observe(ring, tab, 3), None);
        let (ring, tab) = counts(&t, true);
        assert_eq!(audit.observe(ring, tab, 3), Some(0));
    }
}
