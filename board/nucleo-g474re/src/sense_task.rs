//! The drive-and-sense task: after the self-check, configure the drive (outputs off), arm the
//! overcurrent trips, tare the current sense, then sample the sensors, hand every load-cell
//! pair to the control loop ([`crate::cells`]) and log them at 2 Hz.

use embassy_stm32::peripherals::{ADC1, DMA1_CH1, PA0, PA1, PA8, PB0, PB13, TIM1};
use embassy_stm32::{Peri, pac};
use embassy_time::{Duration, Instant};
use sonolube::drive::{Amplitude, DriveLimits, DriveTiming, OvercurrentTrip};
use sonolube::sense::{AdcCode, Calibration, SampleError, SensorChannel};

use crate::cells::{self, RawPair};
use crate::overcurrent::{self, OvercurrentGuard, Thresholds};
use crate::sensing::{self, Block, CHANNELS, ChannelLog, SCANS_PER_READ};
use crate::{SELF_CHECK_PASSED, SENSING_STARTED, config, current, drive, safe};

/// Everything the task owns.
pub struct Hardware {
    /// The drive timer.
    pub tim1: Peri<'static, TIM1>,
    /// TIM1_CH1: high-side gate-driver input.
    pub high_side: Peri<'static, PA8>,
    /// TIM1_CH1N: low-side gate-driver input.
    pub low_side: Peri<'static, PB13>,
    /// Overcurrent comparators, their threshold DACs and inputs.
    pub protection: overcurrent::Peripherals,
    /// The sensing ADC.
    pub adc: Peri<'static, ADC1>,
    /// Normal-force amplifier output.
    pub normal_force: Peri<'static, PA0>,
    /// Tangential-force (friction) amplifier output.
    pub tangential_force: Peri<'static, PB0>,
    /// Current-sense amplifier output (also COMP1's input; jumpered to COMP3's PC1).
    pub drive_current: Peri<'static, PA1>,
    /// The ADC's DMA channel.
    pub dma: Peri<'static, DMA1_CH1>,
    /// ADC2 and its two DMA channels: the drive current at stepped phases (resonance loop).
    pub current: current::Hardware,
    /// USER button B1, hold-to-run in the bring-up build.
    #[cfg(feature = "bringup")]
    pub button: Peri<'static, embassy_stm32::peripherals::PC13>,
}

/// Interval between sensor log lines.
const LOG_PERIOD: Duration = Duration::from_millis(500);

/// Triplets whose current samples, taken with the drive off, are the current sense's zero
/// (19 ms at 40 kHz).
const TARE_TRIPLETS: usize = 384;

/// The bring-up hold-to-run is polled every this many triplets (38 ms at 40 kHz), the cadence
/// its ramp was set for ([`config::RAMP_RISE_STEPS`]).
#[cfg(feature = "bringup")]
pub const HOLD_POLL_TRIPLETS: u32 = 768;

/// The task body. Never returns; on a configuration error it logs and parks with the outputs
/// off.
pub async fn run(hw: Hardware) {
    SELF_CHECK_PASSED.wait().await;
    let timing = config::TIMING;
    let _drive = match drive::Drive::new(hw.tim1, hw.high_side, hw.low_side, &timing) {
        Ok(drive) => drive,
        Err(refused) => {
            defmt::error!("TIM1 configuration refused ({}); drive stays off", refused);
            return;
        }
    };
    log_timing(&timing);
    // Both ADCs are brought up before either converts: each `Adc::new` writes the ADC12
    // common prescaler, which must not change while a conversion runs (review finding 8).
    let adc1 = sensing::bring_up(hw.adc);
    // The stepped current sampling first: it stops TIM1's counter for a few microseconds to
    // align period 0 with phase 0, before ADC1 takes triggers.
    let _current = match current::start(hw.current, &timing) {
        Ok(sense) => {
            defmt::info!(
                "ADC2: PA1 current, one conversion per TIM1 TRGO2, CCR4 stepped by DMA \
                 (TIM1_UP) to 1/8, 3/8, 5/8, 7/8 of the period after CCR1/2; resonance loop fed"
            );
            Some(sense)
        }
        Err(error) => {
            defmt::error!(
                "ADC2 stepped sampling did not start ({}); `freq auto` unavailable",
                error
            );
            None
        }
    };

    let Ok(nominal_current) = config::CURRENT_SENSE.calibration() else {
        defmt::error!("current-sense calibration out of range; drive stays off");
        return;
    };
    let Ok(trip) = OvercurrentTrip::new(config::TRIP_CURRENT, &nominal_current) else {
        defmt::error!("overcurrent trip out of the sensor range; drive stays off");
        return;
    };
    let dc_link_trip = config::DC_LINK_SENSE
        .calibration()
        .ok()
        .and_then(|calibration| {
            OvercurrentTrip::new(config::DC_LINK_TRIP_CURRENT, &calibration).ok()
        });
    let Some(dc_link_trip) = dc_link_trip else {
        defmt::error!("DC-link trip out of the sensor range; drive stays off");
        return;
    };
    let Some(thresholds) = Thresholds::new(trip, nominal_current.offset(), dc_link_trip) else {
        defmt::error!("stack-current window out of range; drive stays off");
        return;
    };
    let mut guard = OvercurrentGuard::arm(hw.protection, thresholds);
    log_trip(guard.thresholds(), &nominal_current);

    let Ok(cell) = config::LOAD_CELL_INTERNAL.calibration() else {
        defmt::error!("load-cell calibration out of range");
        return;
    };
    let mut channels = [
        SensorChannel::new(config::ADC_FORMAT, config::LOAD_CELL_LIMITS, cell),
        SensorChannel::new(config::ADC_FORMAT, config::LOAD_CELL_LIMITS, cell),
        SensorChannel::new(config::ADC_FORMAT, config::CURRENT_LIMITS, nominal_current),
    ];
    let mut ring = match sensing::start(
        adc1,
        hw.normal_force,
        hw.tangential_force,
        hw.drive_current,
        hw.dma,
    ) {
        Ok(ring) => ring,
        Err(error) => {
            defmt::error!("ADC1 sampling did not start ({}); drive stays off", error);
            return;
        }
    };
    // ADC1 has its own trigger, TIM1_CC3 at a fixed 3/4 of the period (review finding 4):
    // the scan stays in the quiet window whatever phase ADC2's stepped CCR4 is at.
    defmt::info!(
        "ADC1: PA0 normal, PB0 tangential, PA1 current; one scan per TIM1_CC3 (3/4 of the \
         period), {=u32} ns per scan in a {=u32} ns quiet window; a triplet every {=u32} PWM \
         periods",
        config::ADC_SCAN_NS,
        timing.quiet_window_ns(),
        sensing::TRIGGERS_PER_TRIPLET
    );

    // The first triplets, with the drive off, are the current sense's zero (an overrun only
    // loses samples).
    let mut block: Block = [0; CHANNELS * SCANS_PER_READ];
    let mut zero_codes = [AdcCode::default(); TARE_TRIPLETS];
    let mut taken = 0;
    while taken < TARE_TRIPLETS {
        if ring.read(&mut block).await.is_ok()
            && let (Some(slot), Some([_, _, current])) =
                (zero_codes.get_mut(taken), sensing::combine(&block))
        {
            *slot = AdcCode::from_word(current);
            taken += 1;
        }
    }
    tare_current(&mut channels[2], &zero_codes, &nominal_current, &mut guard);
    // Ignore whatever faults the tare block would have shown: start the history afresh.
    for channel in &mut channels {
        channel.reset_faults();
    }
    drive::clear_break_flag();
    SENSING_STARTED.signal(());

    #[cfg(feature = "bringup")]
    let mut hold = crate::bringup::HoldToRun::new(hw.button, timing);
    #[cfg(feature = "bringup")]
    let mut since_poll: u32 = 0;
    let mut logs = [ChannelLog::new(), ChannelLog::new(), ChannelLog::new()];
    let mut overruns: u32 = 0;
    let mut malformed: u32 = 0;
    // An ADC1 overrun (its DMA missed a result; OVRMOD overwrites silently) may have rotated
    // the DMA's place in the channel sequence: every later triplet may mix the channels. A
    // sensor fault until reset: the current sense stays unhealthy, so the bridge stays off.
    // (embassy clears OVR when it starts the conversions; one during the tare counts too.)
    let mut adc1_overran = false;
    let mut next_log = Instant::now() + LOG_PERIOD;
    loop {
        let read = ring.read(&mut block).await;
        if !adc1_overran && sonolube_g474_hw::adc::take_overrun(pac::ADC1) {
            adc1_overran = true;
            defmt::error!(
                "ADC1 overran: the scan's channel order is no longer known; current sense faulty until reset, drive off"
            );
        }
        if adc1_overran {
            drive::set_current_sense_healthy(false);
            safe::drive_safe();
        } else {
            match read {
                Ok(_) => match sensing::combine(&block) {
                    Some(triplet) => {
                        for (i, &code) in triplet.iter().enumerate() {
                            let fault = logs[i].record(&mut channels[i], AdcCode::from_word(code));
                            // A saturated or disconnected current sense stops the drive at once and
                            // keeps the control loop from switching it on; load-cell faults are the
                            // control loop's business (its station checks the codes itself).
                            if i == 2 {
                                drive::set_current_sense_healthy(fault.is_none());
                                if fault.is_some() {
                                    safe::drive_safe();
                                }
                            }
                        }
                        let [normal, tangential, _] = triplet;
                        cells::publish(RawPair { normal, tangential });
                    }
                    None => {
                        // A result wider than 12 bits: the ADC is not in the plan. The current is
                        // then unknown: the drive goes safe, as for a faulty current sample.
                        malformed = malformed.saturating_add(1);
                        drive::set_current_sense_healthy(false);
                        safe::drive_safe();
                    }
                },
                Err(_) => overruns = overruns.saturating_add(1),
            }
        }
        #[cfg(feature = "bringup")]
        {
            since_poll += sensing::TRIPLETS_PER_READ as u32;
            if since_poll >= HOLD_POLL_TRIPLETS {
                since_poll = 0;
                hold.poll();
            }
        }
        if Instant::now() >= next_log {
            next_log += LOG_PERIOD;
            log_sensors(&mut logs, &guard, overruns, malformed);
        }
    }
}

/// Tares the current channel from `codes` (current samples with the drive off) if their mean is
/// near the nominal zero, and moves the trip threshold with it.
fn tare_current(
    current: &mut SensorChannel,
    codes: &[AdcCode],
    nominal: &Calibration,
    guard: &mut OvercurrentGuard,
) {
    let before = current.calibration();
    if current.tare(codes).is_err()
        || !sensing::plausible_zero(current.calibration().offset(), nominal.offset())
    {
        defmt::warn!("current sense not at mid-scale with the drive off; nominal zero kept");
        *current = SensorChannel::new(config::ADC_FORMAT, config::CURRENT_LIMITS, before);
        return;
    }
    let tared = current.calibration();
    let window = OvercurrentTrip::new(config::TRIP_CURRENT, &tared)
        .ok()
        .and_then(|trip| {
            sonolube_g474_hw::protect::window_low_code(tared.offset().to_bits(), trip.dac_code())
                .map(|low| (trip.dac_code(), low))
        });
    match window {
        Some((high, low)) => {
            guard.set_stack_window(high, low);
            log_trip(guard.thresholds(), &tared);
        }
        None => defmt::warn!("tared zero leaves no room for the trip window; nominal window kept"),
    }
}

fn log_timing(timing: &DriveTiming) {
    let clock = timing.clock();
    let period = timing.period();
    let dead_time = timing.dead_time();
    defmt::info!(
        "drive: {=u32} mHz achieved (ARR {=u32:#x}, step {=u32} mHz), dead time {=u32} ns \
         ({=u32} ticks, DTG {=u8:#04x}), ADC trigger CCR4 {=u32:#x}; outputs OFF",
        timing.frequency().millihertz(),
        period.arr_register(),
        period.frequency_step(clock),
        dead_time.nanoseconds(clock),
        dead_time.ticks(),
        dead_time.dtg(),
        timing.adc_trigger_compare()
    );
    let amplitude = config::BRINGUP_AMPLITUDE;
    defmt::info!(
        "drive: at amplitude {=u32}/1024, CH1 high {=u32} ns, CH1N high {=u32} ns per period; \
         pulses vanish below amplitude {=u32}/1024",
        amplitude.bits() >> 21,
        timing.high_side_on_ns(amplitude),
        timing.low_side_on_ns(amplitude),
        timing.min_effective_amplitude().bits() >> 21
    );
    // The ratings' ceiling at this frequency (f64 once, at configuration).
    match DriveLimits::new(&config::STACK, config::FULL_SCALE_V) {
        Ok(limits) => defmt::info!(
            "drive: amplitude ceiling {=u32}/1024 at this frequency (stack 15.466 V, 1.75 A; \
             full scale {=u32} mV); at full scale CH1 high {=u32} ns",
            limits.max_amplitude(timing.frequency()).bits() >> 21,
            (config::FULL_SCALE_V * 1000.0) as u32,
            timing.high_side_on_ns(Amplitude::FULL)
        ),
        Err(error) => defmt::error!("drive limits: {}", error),
    }
}

/// The current a DAC code stands for on the channel calibrated by `calibration`, mA.
fn code_milliamps(code: u16, calibration: &Calibration) -> i32 {
    let reading = sonolube::fx::Q1_31::from_bits(i32::from(code) << 19);
    sensing::milli(calibration.apply(reading).value)
}

fn log_trip(thresholds: Thresholds, calibration: &Calibration) {
    defmt::info!(
        "overcurrent: stack window COMP1 (PA1) > DAC3 code {=u16} ({=i32} mA) -> BRK, \
         COMP3 (PC1) < DAC1 code {=u16} ({=i32} mA) -> BRK2; DC link COMP6 (PB11) > DAC4 code \
         {=u16} -> BRK2",
        thresholds.stack_high,
        code_milliamps(thresholds.stack_high, calibration),
        thresholds.stack_low,
        code_milliamps(thresholds.stack_low, calibration),
        thresholds.dc_link
    );
}

fn log_sensors(
    logs: &mut [ChannelLog; 3],
    guard: &OvercurrentGuard,
    overruns: u32,
    malformed: u32,
) {
    let [normal, tangential, current] = [logs[0].take(), logs[1].take(), logs[2].take()];
    defmt::info!(
        "sense: normal {=i32} mN (code {=i32}), tangential {=i32} mN (code {=i32}), \
         current {=i32} mA (code {=i32}); comparators {}, break {=bool}, \
         outputs {=bool}, overruns {=u32}, malformed reads {=u32}, pairs dropped {=u32}, \
         trigger updates suppressed {=u32}",
        normal.0,
        normal.1,
        tangential.0,
        tangential.1,
        current.0,
        current.1,
        guard.outputs(),
        drive::break_tripped(),
        drive::outputs_enabled(),
        overruns,
        malformed,
        cells::dropped(),
        current::suppressed_updates()
    );
    for (name, (_, _, faults, last)) in [
        ("normal", normal),
        ("tangential", tangential),
        ("current", current),
    ] {
        if let Some(fault) = last {
            log_fault(name, faults, fault);
        }
    }
}

fn log_fault(name: &str, faults: u32, fault: SampleError) {
    defmt::warn!(
        "sense: {=str} channel: {=u32} faulty samples, last {}",
        name,
        faults,
        fault
    );
}
