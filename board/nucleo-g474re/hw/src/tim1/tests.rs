//! TIM1 on a RAM image: RM0440's fields at RM0440's offsets, and the order of writes.

use std::vec::Vec;

use sonolube::drive::{Amplitude, DeadTime, DriveTiming, Frequency, TimerClock};

use super::*;
use crate::image::Image;

// RM0440 TIM1 register offsets.
const CR1: usize = 0x00;
const CR2: usize = 0x04;
const SR: usize = 0x10;
const EGR: usize = 0x14;
const CCMR1: usize = 0x18;
const CCMR2: usize = 0x1C;
const CCER: usize = 0x20;
const PSC: usize = 0x28;
const ARR: usize = 0x2C;
const CCR1_OFFSET: usize = 0x34;
const CCR3_OFFSET: usize = 0x3C;
const CCR4_OFFSET: usize = 0x40;
const BDTR: usize = 0x44;
const AF1: usize = 0x60;
const AF2: usize = 0x64;

const CLOCK_HZ: u64 = 170_000_000;

fn timing(hz: u32) -> DriveTiming {
    DriveTiming::new(Frequency::from_hz(hz), 200, TimerClock::G474_TIM1).unwrap()
}

fn tim(image: &mut Image) -> TimAdv {
    // SAFETY: the image outlives every use of the handle in each test.
    unsafe { TimAdv::from_ptr(image.ptr()) }
}

/// TIM1 right after reset (RM0440 reset values that are not zero: AF1 = AF2 = 1, BKINE/BK2INE).
fn reset_image() -> Box<Image> {
    let mut image = Image::new();
    image.set_word(AF1, 1);
    image.set_word(AF2, 1);
    image
}

fn configured(hz: u32) -> Box<Image> {
    let mut image = reset_image();
    configure(tim(&mut image), &timing(hz), &mut |_| {}).unwrap();
    image
}

/// Whether a dithered CCR lies at 3/4 of the period a dithered ARR gives, to one sixteenth of
/// a tick: RM0440's dithering makes the period `ARR + 16` sixteenths.
fn three_quarters_of_the_period(arr: u32, ccr: u32) -> bool {
    (4 * i64::from(ccr) - 3 * i64::from(arr + 16)).abs() <= 4
}

/// Average PWM frequency of a dithered ARR, mHz: the period is `ARR + 16` sixteenths of a tick
/// (RM0440, dithering: `ARR[19:4] + 1` ticks plus `ARR[3:0]` sixteenths).
fn effective_millihertz(arr: u32) -> f64 {
    (CLOCK_HZ * 16 * 1000) as f64 / f64::from(arr + 16)
}

#[test]
fn configure_writes_the_reference_manuals_fields() {
    let image = configured(40_000);
    // CR1: counter on, ARR preloaded, dithering, edge-aligned up-counting, CKD = 1, UDIS = 0.
    assert!(image.bit(CR1, 0), "CEN");
    assert!(!image.bit(CR1, 1), "UDIS");
    assert!(image.bit(CR1, 7), "ARPE");
    assert!(image.bit(CR1, 12), "DITHEN");
    assert_eq!(image.bits(CR1, 4, 3), 0, "DIR/CMS");
    assert_eq!(image.bits(CR1, 8, 2), 0, "CKD: t_DTS = t_CK_INT");
    // CR2: idle levels low, MMS2 = 0111 (OC4REF as TRGO2).
    assert!(!image.bit(CR2, 8), "OIS1");
    assert!(!image.bit(CR2, 9), "OIS1N");
    assert_eq!(image.bits(CR2, 20, 4), 0b0111, "MMS2");
    // CCMR1: CH1 output, PWM mode 1 (OC1M = 0110, bit 16 = 0), preload.
    assert_eq!(image.bits(CCMR1, 0, 2), 0, "CC1S");
    assert_eq!(image.bits(CCMR1, 4, 3), 0b110, "OC1M");
    assert!(!image.bit(CCMR1, 16), "OC1M[3]");
    assert!(image.bit(CCMR1, 3), "OC1PE");
    // CCMR2: CH3 and CH4 PWM mode 2 (OCxM = 0111: inactive below CCRx, so OCxREF rises at
    // CCRx when up-counting), preloaded; CH3 at bits 0-7 and 16, CH4 at 8-15 and 24.
    assert_eq!(image.bits(CCMR2, 0, 2), 0, "CC3S output");
    assert_eq!(image.bits(CCMR2, 4, 3), 0b111, "OC3M");
    assert!(!image.bit(CCMR2, 16), "OC3M[3]");
    assert!(image.bit(CCMR2, 3), "OC3PE");
    assert_eq!(image.bits(CCMR2, 12, 3), 0b111, "OC4M");
    assert!(!image.bit(CCMR2, 24), "OC4M[3]");
    assert!(image.bit(CCMR2, 11), "OC4PE");
    // CCER: CH1 and CH1N enabled, active high.
    assert_eq!(image.bits(CCER, 0, 4), 0b0101, "CC1E, CC1P, CC1NE, CC1NP");
    // CH3 enabled, active high, no complementary output (CCER bits 8-11), CH2 and CH4 off.
    assert_eq!(image.bits(CCER, 8, 4), 0b0001, "CC3E, CC3P, CC3NE, CC3NP");
    assert_eq!(image.bits(CCER, 4, 4), 0, "CH2");
    assert_eq!(image.bits(CCER, 12, 4), 0, "CH4");
    assert_eq!(image.word(PSC), 0);
    // BDTR.
    let t = timing(40_000);
    assert_eq!(
        image.bits(BDTR, 0, 8),
        u32::from(t.dead_time().dtg()),
        "DTG"
    );
    assert_eq!(image.bits(BDTR, 8, 2), 3, "LOCK level 3");
    assert!(image.bit(BDTR, 10), "OSSI");
    assert!(image.bit(BDTR, 11), "OSSR");
    assert!(image.bit(BDTR, 12), "BKE");
    assert!(image.bit(BDTR, 13), "BKP active high");
    assert!(!image.bit(BDTR, 14), "AOE = 0: a break latches");
    assert!(!image.bit(BDTR, 15), "MOE = 0 after configuration");
    assert_eq!(image.bits(BDTR, 16, 4), 0b1000, "BKF: f_DTS/8, N = 6");
    assert_eq!(image.bits(BDTR, 20, 4), 0b1000, "BK2F");
    assert!(image.bit(BDTR, 24), "BK2E");
    assert!(image.bit(BDTR, 25), "BK2P active high");
    assert_eq!(image.bits(BDTR, 26, 4), 0, "BKDSRM, BK2DSRM, BKBID, BK2BID");
    // AF1: COMP1 only, not inverted; BKIN pin off. AF2: COMP3 only.
    assert!(!image.bit(AF1, 0), "BKINE");
    assert_eq!(image.bits(AF1, 1, 7), 0b000_0001, "BKCMP1E only");
    assert!(!image.bit(AF1, 10), "BKCMP1P");
    assert!(!image.bit(AF2, 0), "BK2INE");
    assert_eq!(
        image.bits(AF2, 1, 7),
        0b010_0100,
        "BK2CMP3E and BK2CMP6E only"
    );
    assert!(!image.bit(AF2, 12), "BK2CMP3P");
    // Period registers and the update event that loaded them.
    assert_eq!(image.word(ARR), t.period().arr_register());
    assert_eq!(image.word(CCR1_OFFSET), t.duty_compare(Amplitude::ZERO));
    assert_eq!(image.word(CCR4_OFFSET), t.adc_trigger_compare());
    // CCR3 at 3/4 of the period in RM0440's dithered format (the period is ARR + 16
    // sixteenths of a tick), to the sixteenth.
    assert!(three_quarters_of_the_period(
        image.word(ARR),
        image.word(CCR3_OFFSET)
    ));
    assert!(image.bit(EGR, 0), "UG");
    assert_eq!(image.word(SR), 0);
}

#[test]
fn dead_time_encoding_in_bdtr() {
    // 200 ns at 170 MHz: 34 ticks, DTG = 0x22 (first range, 1-tick steps); 1 us: 170 ticks,
    // second range (2-tick steps): (64 + 21) * 2 = 170, DTG = 0x80 | 21.
    for (ns, dtg, ticks) in [(200, 0x22, 34), (1000, 0x95, 170), (2000, 0xC0 | 11, 344)] {
        let dead_time = DeadTime::at_least_ns(ns, TimerClock::G474_TIM1).unwrap();
        let word = bdtr_value(dead_time).0;
        assert_eq!(word & 0xFF, dtg, "{ns} ns");
        // Decode RM0440's four DTG ranges from the image word, independently of the encoder.
        let d = word & 0xFF;
        let decoded = match d >> 5 {
            0..=3 => d,
            4 | 5 => (64 + (d & 0x3F)) * 2,
            6 => (32 + (d & 0x1F)) * 8,
            _ => (32 + (d & 0x1F)) * 16,
        };
        assert_eq!(decoded, ticks);
        let decoded_ns = u64::from(decoded) * 1_000_000_000 / CLOCK_HZ;
        assert!(
            decoded_ns + 1 >= u64::from(ns),
            "never shorter than requested"
        );
    }
    assert_eq!(BREAK_FILTER_NS, 282);
}

/// Every register write of `f`, with the image after it.
fn trace(image: &mut Image, f: impl FnOnce(&mut dyn FnMut(Step), TimAdv)) -> Vec<(Step, Vec<u32>)> {
    let handle = tim(image);
    let ptr = image as *const Image;
    let mut steps = Vec::new();
    let mut hook = |step: Step| {
        // SAFETY: the image is alive; this only reads it between the accessor's writes.
        steps.push((step, unsafe { (*ptr).snapshot() }));
    };
    f(&mut hook, handle);
    steps
}

fn word(snapshot: &[u32], offset: usize) -> u32 {
    snapshot[offset / 4]
}

#[test]
fn configure_order_moe_stays_off_and_bdtr_is_written_once() {
    let mut image = reset_image();
    let t = timing(40_000);
    let steps = trace(&mut image, |hook, tim| {
        configure(tim, &t, &mut |s| hook(s)).unwrap();
    });
    let names: Vec<Step> = steps.iter().map(|(s, _)| *s).collect();
    assert_eq!(
        names,
        [
            "TIM1_CR1",
            "TIM1_CCER",
            "TIM1_PSC",
            "TIM1_CR2",
            "TIM1_CCMR1",
            "TIM1_CCMR2",
            "TIM1_AF1",
            "TIM1_AF2",
            "TIM1_BDTR",
            "TIM1_CR1",
            "TIM1_ARR",
            "TIM1_CCR1",
            "TIM1_CCR3",
            "TIM1_CCR4",
            "TIM1_EGR",
            "TIM1_SR",
            "TIM1_CCER",
            "TIM1_CR1"
        ]
    );
    let bdtr_at = names.iter().position(|s| *s == "TIM1_BDTR").unwrap();
    assert_eq!(
        names.iter().filter(|s| **s == "TIM1_BDTR").count(),
        1,
        "LOCK freezes at the first BDTR write"
    );
    for (i, (name, snap)) in steps.iter().enumerate() {
        assert_eq!(
            word(snap, BDTR) & (1 << 15),
            0,
            "MOE set at step {i} ({name})"
        );
        let outputs_enabled = word(snap, CCER) & 0b101 != 0;
        if outputs_enabled {
            assert!(i > bdtr_at, "CC1E/CC1NE before BDTR (OSSI) at step {i}");
            assert!(
                names[..i].contains(&"TIM1_EGR"),
                "outputs enabled before the preloads were loaded"
            );
        }
        if word(snap, CR1) & 1 != 0 {
            assert_eq!(i, steps.len() - 1, "counter started before the end");
        }
        // The fields LOCK freezes are in place before the lock.
        if i == bdtr_at {
            assert_eq!(word(snap, CR2) & (0b11 << 8), 0, "OIS1/OIS1N");
            assert_ne!(word(snap, AF1) & 0b10, 0, "BKCMP1E");
            assert_eq!(word(snap, AF2) & 0xFE, 0b0100_1000, "BK2CMP3E, BK2CMP6E");
        }
    }
    // DITHEN changed only while the counter was stopped.
    for pair in steps.windows(2) {
        let (before, after) = (word(&pair[0].1, CR1), word(&pair[1].1, CR1));
        if (before ^ after) & (1 << 12) != 0 {
            assert_eq!(after & 1, 0, "DITHEN changed with CEN = 1");
        }
    }
}

#[test]
fn configure_is_refused_with_the_outputs_on_or_bdtr_locked() {
    for (bdtr, expected) in [
        (1 << 15, Refused::OutputsOn),
        (1 << 8, Refused::AlreadyLocked),
    ] {
        let mut image = reset_image();
        image.set_word(BDTR, bdtr);
        let before = image.snapshot();
        assert_eq!(
            configure(tim(&mut image), &timing(40_000), &mut |_| {}),
            Err(expected)
        );
        assert_eq!(image.snapshot(), before, "nothing written when refused");
    }
}

#[test]
fn every_hertz_from_20_to_60_khz_through_the_registers() {
    let mut image = configured(40_000);
    let quarter = Amplitude::from_ratio(1, 4).unwrap();
    let mut worst_mhz: f64 = 0.0;
    for hz in 20_000..=60_000u32 {
        let t = timing(40_000).retune(Frequency::from_hz(hz)).unwrap();
        write_timing(tim(&mut image), &t, quarter, &mut |_| {}).unwrap();
        let arr = image.word(ARR);
        let ccr1 = image.word(CCR1_OFFSET);
        let ccr4 = image.word(CCR4_OFFSET);
        let period = arr + 16;
        assert!(arr <= 0xF_FFFF, "{hz} Hz: ARR exceeds 20 bits");
        // The effective frequency is the nearest the dithered grid allows: within half a step
        // (at most 1.324 Hz / 2 at 60 kHz).
        let error_at = |a: u32| (effective_millihertz(a) - f64::from(hz) * 1000.0).abs();
        let error = error_at(arr);
        // The nearest of the grid: neither neighbouring ARR comes closer.
        assert!(
            error <= error_at(arr - 1) && error <= error_at(arr + 1),
            "{hz} Hz: not the nearest ARR"
        );
        assert!(error <= 662.0, "{hz} Hz: error {error} mHz");
        worst_mhz = worst_mhz.max(error);
        // CCR1: D = asin(1/4)/pi of the period; CCR4: 3/4 of the period (rounding: 1/16 tick).
        let duty = f64::from(ccr1) / f64::from(period);
        let expected = (0.25f64).asin() / std::f64::consts::PI;
        assert!(
            (duty - expected).abs() * f64::from(period) <= 1.0,
            "{hz} Hz: CCR1 {ccr1}"
        );
        assert!(
            (f64::from(ccr4) - 0.75 * f64::from(period)).abs() <= 0.5,
            "{hz} Hz: CCR4 {ccr4}"
        );
        assert!(
            ccr4 > ccr1 && ccr4 < period,
            "{hz} Hz: trigger in the low-side phase"
        );
        assert_eq!(ccr1, t.duty_compare(quarter));
        assert_eq!(ccr4, t.adc_trigger_compare());
        // UDIS is back to 0: the next period boundary loads them.
        assert!(!image.bit(CR1, 1));
    }
    eprintln!("every hertz 20-60 kHz through TIM1_ARR: worst error {worst_mhz:.1} mHz");
    assert!(worst_mhz > 500.0, "the sweep reaches the grid's worst case");
}

/// The preloaded (ARR, CCR1, CCR4) as one tuple.
fn preloads(snapshot: &[u32]) -> (u32, u32, u32) {
    (
        word(snapshot, ARR),
        word(snapshot, CCR1_OFFSET),
        word(snapshot, CCR4_OFFSET),
    )
}

#[test]
fn a_frequency_change_never_exposes_a_new_arr_with_an_old_ccr() {
    let mut image = configured(40_000);
    let old = timing(40_000);
    let a = Amplitude::from_ratio(1, 4).unwrap();
    set_amplitude(tim(&mut image), &old, a, &mut |_| {});
    let mut current = (old, a);
    for (hz, num) in [(55_555u32, 3u32), (20_000, 1), (60_000, 4), (41_234, 2)] {
        let new = old.retune(Frequency::from_hz(hz)).unwrap();
        let b = Amplitude::from_ratio(num, 4).unwrap();
        let consistent = |t: &DriveTiming, x: Amplitude| {
            (
                t.period().arr_register(),
                t.duty_compare(x),
                t.adc_trigger_compare(),
            )
        };
        let allowed = [consistent(&current.0, current.1), consistent(&new, b)];
        let steps = trace(&mut image, |hook, tim| {
            write_timing(tim, &new, b, &mut |s| hook(s)).unwrap();
        });
        for (i, (name, snap)) in steps.iter().enumerate() {
            // An update event can transfer the preloads whenever UDIS = 0.
            if word(snap, CR1) & 0b10 == 0 {
                assert!(
                    allowed.contains(&preloads(snap)),
                    "{hz} Hz: step {i} ({name}) exposes {:?}",
                    preloads(snap)
                );
            }
            assert_eq!(word(snap, BDTR), word(&steps[0].1, BDTR), "BDTR touched");
        }
        assert_eq!(preloads(&image.snapshot()), allowed[1]);
        current = (new, b);
    }
}

#[test]
fn a_timing_with_another_dead_time_is_refused() {
    let mut image = configured(40_000);
    let before = image.snapshot();
    let other = DriveTiming::new(Frequency::from_hz(40_000), 300, TimerClock::G474_TIM1).unwrap();
    assert_eq!(
        write_timing(tim(&mut image), &other, Amplitude::ZERO, &mut |_| {}),
        Err(Refused::DeadTimeDiffers)
    );
    assert_eq!(image.snapshot(), before);
}

#[test]
fn outputs_are_enabled_only_without_a_break_flag() {
    for (flag, name) in [(1u32 << 7, "BIF"), (1 << 8, "B2IF"), (1 << 13, "SBIF")] {
        let mut image = configured(40_000);
        image.set_word(SR, flag);
        assert!(break_tripped(tim(&mut image)), "{name}");
        assert!(!try_enable_outputs(tim(&mut image), &mut |_| {}), "{name}");
        assert!(!image.bit(BDTR, 15), "{name}: MOE set");
    }
    let mut image = configured(40_000);
    assert!(try_enable_outputs(tim(&mut image), &mut |_| {}));
    assert!(image.bit(BDTR, 15));
    assert!(outputs_enabled(tim(&mut image)));
    // Only MOE changed in BDTR.
    assert_eq!(image.word(BDTR) & !(1 << 15), configured(40_000).word(BDTR));
}

#[test]
fn clearing_the_break_flags_leaves_the_other_flags_alone() {
    let mut image = configured(40_000);
    clear_break_flags(tim(&mut image), &mut |_| {});
    let written = image.word(SR);
    for bit in [7, 8, 13] {
        assert_eq!(written & (1 << bit), 0, "bit {bit} cleared");
    }
    // rc_w0: every other implemented flag written 1 (left alone); reserved bits 0.
    let others: u32 = (0..=6)
        .chain(9..=12)
        .chain(16..=17)
        .chain(20..=23)
        .map(|b| 1 << b)
        .sum();
    assert_eq!(written, others);
}

#[test]
fn the_clock_is_enabled_and_the_timer_reset_before_configuration() {
    // RM0440 RCC: APB2RSTR at 0x40, APB2ENR at 0x60, TIM1 is bit 11 of both.
    let mut image = Image::new();
    // SAFETY: the image outlives the handle.
    let rcc = unsafe { Rcc::from_ptr(image.ptr()) };
    let ptr = &*image as *const Image;
    let mut resets = Vec::new();
    enable_clock(rcc, &mut |step| {
        if step == "RCC_APB2RSTR" {
            // SAFETY: reading our image between writes.
            resets.push(unsafe { (*ptr).bit(0x40, 11) });
        }
    });
    assert_eq!(resets, [true, false], "reset pulsed");
    assert!(image.bit(0x60, 11), "TIM1EN");
}

#[test]
fn pins_are_connected_low_first_then_to_af6() {
    let mut a = Image::new();
    let mut b = Image::new();
    // SAFETY: the images outlive the handles.
    let (gpioa, gpiob) = unsafe { (Gpio::from_ptr(a.ptr()), Gpio::from_ptr(b.ptr())) };
    let mut names = Vec::new();
    connect_pins(gpioa, gpiob, &mut |s| names.push(s));
    for (image, pin, port) in [(&a, 8u32, "GPIOA"), (&b, 13, "GPIOB")] {
        assert_eq!(
            image.bits(0x00, 2 * pin, 2),
            0b10,
            "{port} MODER: alternate"
        );
        assert_eq!(image.bits(0x24, 4 * (pin - 8), 4), 6, "{port} AFRH: AF6");
        assert!(!image.bit(0x04, pin), "{port} push-pull");
        assert_eq!(image.bits(0x0C, 2 * pin, 2), 0, "{port} no pull");
        assert_eq!(
            image.word(0x18),
            1 << (16 + pin),
            "{port} BSRR: reset bit only"
        );
        let bsrr = names
            .iter()
            .position(|n| *n == format!("{port}_BSRR"))
            .unwrap();
        let moder = names
            .iter()
            .position(|n| *n == format!("{port}_MODER"))
            .unwrap();
        assert!(bsrr < moder, "{port}: output low before the mode switch");
    }
}

/// TIM1_CNT (counter, bits 0-15).
const CNT: usize = 0x24;

/// `write_timing_stepped` on a configured image whose counter reads `count` before the
/// write; `wrap` moves the counter back to 3 at the named step (the counter wrapping right
/// after that write), setting UIF when `uif`.
fn stepped(count: u32, wrap: Option<(usize, bool)>) -> (UpdateEvents, Vec<(Step, Vec<u32>)>) {
    let mut image = configured(40_000);
    image.set_word(CNT, count);
    image.set_word(SR, 1); // a stale UIF from long ago
    let ptr = &mut *image as *mut Image;
    let handle = tim(&mut image);
    let new = timing(47_000);
    let mut steps = Vec::new();
    let mut index = 0;
    let limit = crate::current::trigger_limit(
        timing(40_000).period().arr_register(),
        new.period().arr_register(),
    );
    let events = write_timing_stepped(
        handle,
        &new,
        Amplitude::from_ratio(1, 2).unwrap(),
        limit,
        &mut |step| {
            // SAFETY: the image is alive; the handle's accesses are volatile and not concurrent.
            let image = unsafe { &mut *ptr };
            if step == "TIM1_SR" {
                // rc_w0: the written zeros clear, the ones leave a flag as it was.
                let written = image.word(SR);
                image.set_word(SR, written & 1);
            }
            if let Some((at, uif)) = wrap
                && at == index
            {
                image.set_word(CNT, 3);
                if uif {
                    image.set_word(SR, image.word(SR) | 1);
                }
            }
            steps.push((step, image.snapshot()));
            index += 1;
        },
    )
    .unwrap();
    (events, steps)
}

#[test]
fn the_stepped_timing_write_leaves_ccr4_to_the_dma_and_finds_a_suppressed_update() {
    let (events, steps) = stepped(1_000, None);
    assert_eq!(events, UpdateEvents::AllTaken);
    let names: Vec<Step> = steps.iter().map(|(s, _)| *s).collect();
    assert_eq!(
        names,
        [
            "TIM1_SR",
            "TIM1_CR1",
            "TIM1_ARR",
            "TIM1_CCR1",
            "TIM1_CCR3",
            "TIM1_CR1"
        ]
    );
    let new = timing(47_000);
    let half = Amplitude::from_ratio(1, 2).unwrap();
    let last = &steps[5].1;
    assert_eq!(word(last, ARR), new.period().arr_register());
    assert_eq!(word(last, CCR1_OFFSET), new.duty_compare(half));
    // ADC1's trigger moves with the period, inside the same UDIS window: 3/4 of the new one.
    assert!(three_quarters_of_the_period(
        word(last, ARR),
        word(last, CCR3_OFFSET)
    ));
    // CCR4 is the table's: configure's 3/4 trigger at 40 kHz is still there (below the new
    // ARR, so not pulled down).
    assert_eq!(
        word(last, CCR4_OFFSET),
        timing(40_000).adc_trigger_compare()
    );
    // UDIS (CR1 bit 1) set before ARR and cleared after CCR1 and CCR3.
    assert_eq!(word(&steps[2].1, CR1) & 0b10, 0b10);
    assert_eq!(word(&steps[3].1, CR1) & 0b10, 0b10);
    assert_eq!(word(&steps[4].1, CR1) & 0b10, 0b10);
    assert_eq!(word(last, CR1) & 0b10, 0);
    // The SR write clears UIF (bit 0) alone: BIF, B2IF, SBIF and the others are written 1.
    let sr_written = SR_CLEAR_UIF;
    assert_eq!(sr_written & 1, 0);
    for flag in [
        1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 16, 17, 20, 21, 22, 23,
    ] {
        assert_eq!(sr_written >> flag & 1, 1, "SR bit {flag}");
    }
    for reserved in [14, 15, 18, 19, 24, 25, 26, 27, 28, 29, 30, 31] {
        assert_eq!(sr_written >> reserved & 1, 0, "reserved SR bit {reserved}");
    }
    // The counter wraps with UDIS set (after the first CR1 write, before the second) and no
    // update event sets UIF: one update was suppressed.
    for at in 1..=3 {
        assert_eq!(
            stepped(2_000, Some((at, false))).0,
            UpdateEvents::OneSuppressed,
            "wrap after step {at}"
        );
    }
    // A wrap that set UIF (before UDIS took effect, or after it was cleared) was an update.
    for at in 0..=4 {
        assert_eq!(
            stepped(2_000, Some((at, true))).0,
            UpdateEvents::AllTaken,
            "wrap with UIF after step {at}"
        );
    }
    // The stale UIF of long ago does not count: it is cleared first.
    assert_eq!(
        stepped(2_000, Some((2, false))).0,
        UpdateEvents::OneSuppressed
    );
}

#[test]
fn the_stepped_timing_write_refuses_another_dead_time() {
    let mut image = configured(40_000);
    let before = image.snapshot();
    let other = DriveTiming::new(Frequency::from_hz(40_000), 400, TimerClock::G474_TIM1).unwrap();
    assert_eq!(
        write_timing_stepped(
            tim(&mut image),
            &other,
            Amplitude::ZERO,
            u32::MAX,
            &mut |_| {}
        ),
        Err(Refused::DeadTimeDiffers)
    );
    assert_eq!(image.snapshot(), before);
}
