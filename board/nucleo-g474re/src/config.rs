//! The board's numbers in one place: drive, power stage, analog front ends, fault limits.
//!
//! Every value here is an assumption about the hardware around the NUCLEO (board README,
//! "Power stage and front ends"); change it here when the hardware differs. The timing values
//! are checked at compile time: an invalid frequency or dead time does not build.

use sonolube::drive::{Amplitude, DriveTiming, Frequency, StackRatings, TimerClock};
use sonolube::ext_adc::{Config as AdsConfig, Gain, Osr, clkin_divider};
use sonolube::fx::{Q1_31, Q16_16};
use sonolube::sense::{AdcFormat, BridgeAmplifier, FaultLimits, Oversampling, ShuntAmplifier};

/// TIM1 counts the 170 MHz system clock (main.rs clock tree: 24 MHz HSE, or HSI16 as the
/// fallback, through the PLL; APB2 undivided).
pub const TIMER_CLOCK: TimerClock = TimerClock::G474_TIM1;

/// Drive frequency at start: 40 kHz, the half-wave mode seed 003 drives the stack in.
pub const FREQUENCY: Frequency = Frequency::from_hz(40_000);

/// Dead time between the half-bridge switches, ns: a gate driver with about 20 ns propagation
/// mismatch and MOSFETs switching in about 30 ns at 24 V need well under 100 ns; 200 ns leaves
/// margin for a first bring-up (measured in step 5 of the procedure, then shortened).
pub const DEAD_TIME_NS: u32 = 200;

/// The start-up timing, validated at compile time.
pub const TIMING: DriveTiming = match DriveTiming::new(FREQUENCY, DEAD_TIME_NS, TIMER_CLOCK) {
    Ok(timing) => timing,
    Err(_) => panic!("board drive timing is invalid"),
};

/// Bus voltage of the half-bridge, V.
pub const BUS_VOLTAGE_V: f64 = 24.0;

/// Fundamental voltage amplitude on the stack at full scale: `2 V_bus / pi` (series inductor and
/// blocking capacitor assumed transparent at the drive frequency; measure at bring-up).
pub const FULL_SCALE_V: f64 = 2.0 * BUS_VOLTAGE_V / core::f64::consts::PI;

/// The stack (seed 003 Table 1).
pub const STACK: StackRatings = StackRatings::SEED_003;

/// Amplitude the bring-up build runs at while B1 is held: a quarter of full scale, 3.8 V on a
/// stack (CH1 on 1.81 us per 25 us period at 40 kHz with the dead time above).
pub const BRINGUP_AMPLITUDE: Amplitude = match Amplitude::from_ratio(1, 4) {
    Ok(amplitude) => amplitude,
    Err(_) => panic!("bring-up amplitude out of range"),
};

#[cfg(feature = "bringup")]
/// Soft start and stop of the bring-up drive, in polls of the hold-to-run (one per 32 ADC
/// triplets, 38 ms at 40 kHz): 0 to full scale in 10 steps (0.4 s), back in 5.
pub const RAMP_RISE_STEPS: u32 = 10;
/// See [`RAMP_RISE_STEPS`].
#[cfg(feature = "bringup")]
pub const RAMP_FALL_STEPS: u32 = 5;

/// Stack current sense (25 mOhm, INA240A1, 0.5 V/A around 1.65 V into PA1), defined with the
/// comparators it feeds in `sonolube_g474_hw::protect` (host-tested thresholds).
pub const CURRENT_SENSE: ShuntAmplifier = sonolube_g474_hw::protect::STACK_SENSE;

/// Stack overcurrent trip (2.5 A, both half-waves), DC-link sense (10 mOhm, 0.2 V/A into PB11)
/// and DC-link trip (6 A): `sonolube_g474_hw::protect`, where their DAC codes are tested.
pub const TRIP_CURRENT: Q16_16 = sonolube_g474_hw::protect::STACK_TRIP_CURRENT;
/// See [`TRIP_CURRENT`].
pub const DC_LINK_SENSE: ShuntAmplifier = sonolube_g474_hw::protect::DC_LINK_SENSE;
/// See [`TRIP_CURRENT`].
pub const DC_LINK_TRIP_CURRENT: Q16_16 = sonolube_g474_hw::protect::DC_LINK_TRIP_CURRENT;

/// Load cells on the internal ADC: 50 lbf (222 N) cells like seed 003's MPL-50-T, 2 mV/V at
/// 5 V excitation, INA826 at gain 150 (RG = 332 Ohm) referenced to 1.65 V.
pub const LOAD_CELL_INTERNAL: BridgeAmplifier = BridgeAmplifier {
    rated_load_n: 222,
    sensitivity_uv_per_v: 2000,
    excitation_millivolt: 5000,
    gain_milli: 150_000,
    full_scale_microvolt: 3_300_000,
    zero: Q1_31::from_bits(1 << 30),
};

/// The same cells wired straight to the ADS131M02 (PGA 64: 0.64 V of its 1.2 V at rated load).
pub const LOAD_CELL_EXTERNAL: BridgeAmplifier = BridgeAmplifier {
    gain_milli: 64_000,
    full_scale_microvolt: 1_200_000,
    zero: Q1_31::ZERO,
    ..LOAD_CELL_INTERNAL
};

/// The 16-bit format of the internal ADC's codes (0 to 65 520): that of 16 summed 12-bit
/// results. The plan converts without hardware oversampling and sums two scans, times 8
/// (`sonolube_g474_hw::adc::pair_code`), so the codes keep the format the sensing chain and
/// [`crate::cells`] expect, with steps of 8.
pub const OVERSAMPLING: Oversampling = match Oversampling::new(4, 0) {
    Ok(oversampling) => oversampling,
    Err(_) => panic!("oversampling setting invalid"),
};

/// The format of the internal ADC's results.
pub const ADC_FORMAT: AdcFormat = match AdcFormat::oversampled(12, OVERSAMPLING) {
    Ok(format) => format,
    Err(_) => panic!("ADC format invalid"),
};

/// ADC clock: SYSCLK / 4 = 42.5 MHz (embassy picks the prescaler to stay under 60 MHz).
pub const ADC_CLOCK_HZ: u32 = 42_500_000;
/// One scan of the three channels (24.5 + 12.5 cycles each), ns: 2612.
pub const ADC_SCAN_NS: u32 = sonolube_g474_hw::adc::scan_ns(ADC_CLOCK_HZ);

// Each trigger starts one scan, which must end before the next switching edge at every
// frequency of the band; the quiet window is shortest at 60 kHz.
const _: () = {
    let fastest = match DriveTiming::new(Frequency::BAND_MAX, DEAD_TIME_NS, TIMER_CLOCK) {
        Ok(timing) => timing,
        Err(_) => panic!("dead time too long for 60 kHz"),
    };
    assert!(ADC_SCAN_NS < fastest.quiet_window_ns());
};

/// Fault limits of the load-cell channels: rail within 0.2 % of full scale; stuck if 48 000
/// triplets (2.4 s at 40 kHz / 2 triggers per triplet) stay within 1 LSB of the 16-bit
/// format; a jump of more than 1/8 of full scale between triplets 50 us apart is no force.
pub const LOAD_CELL_LIMITS: FaultLimits = FaultLimits {
    rail_margin: Q1_31::from_bits(1 << 22),
    noise_band: Q1_31::from_bits(1 << 15),
    stuck_samples: 48_000,
    max_step: Q1_31::from_bits(1 << 28),
};

/// Fault limits of the current channel: rail (saturated or disconnected) only matters; the
/// current legitimately sits still at zero with the drive off and jumps with the amplitude.
pub const CURRENT_LIMITS: FaultLimits = FaultLimits {
    rail_margin: Q1_31::from_bits(1 << 22),
    noise_band: Q1_31::ZERO,
    stuck_samples: 0,
    max_step: Q1_31::MAX,
};

/// CLKIN of the ADS131M02 from TIM3 CH1: 170 MHz / 21 = 8.095 MHz.
pub const ADS_CLKIN_DIVIDER: u32 = clkin_divider(TIMER_CLOCK.hz());
/// The resulting CLKIN, Hz.
pub const ADS_CLKIN_HZ: u32 = TIMER_CLOCK.hz() / ADS_CLKIN_DIVIDER;

/// ADS131M02 settings: the lowest-noise oversampling that still gives at least 2 kSPS
/// (OSR 1024, 3953 SPS at 8.095 MHz), PGA 64 on both channels.
pub const ADS_CONFIG: AdsConfig = AdsConfig {
    osr: match Osr::slowest_at_least(ADS_CLKIN_HZ, 2000) {
        Some(osr) => osr,
        None => panic!("CLKIN too slow for 2 kSPS"),
    },
    gains: [Gain::X64, Gain::X64],
};
