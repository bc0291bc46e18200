//! Simulated load cells: dynamics, calibration errors, noise, the 12-bit converter, faults.
//!
//! The chain of one cell, per substep and per sample:
//! 1. the cell and its amplifier low-pass the true force, first order at `bandwidth_hz`
//!    (exact update for a force held over the substep: `y += (1 - exp(-2 pi f_c dt)) (F - y)`);
//! 2. at each sample the reading is `(1 + gain_error) y + offset_n + noise`, the noise
//!    Gaussian with `noise_rms_pct_fs` % of full scale RMS, drawn from the plant's seeded
//!    generator on every sample (faulted or not, so runs with and without faults see the
//!    same noise);
//! 3. the converter maps +-full scale onto its codes with zero force at mid-scale (the front
//!    ends bias the bridge amplifier to mid-supply, `sonolube::sense`): `code = round(zero +
//!    reading / FS * zero)`, saturating at 0 and 2^bits - 1.
//!
//! Faults act on step 3: a disconnected cell reads its rail, a stuck one repeats the code it
//! gave just before the onset, a spike adds its force to the reading before conversion.

use core::f32::consts::TAU;

use super::noise::Gaussian;
use sonolube::scene::{FaultKind, LoadCell, Rail};
use sonolube::sense::AdcCode;

/// One simulated load cell and its converter channel.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadCellSim {
    full_scale_n: f32,
    gain: f32,
    offset_n: f32,
    noise_rms_n: f32,
    /// Filter coefficient per substep, 1 - exp(-2 pi f_c dt).
    smoothing: f32,
    zero_code: u16,
    max_code: u16,
    /// Force seen through the cell's dynamics, N.
    filtered_n: f32,
    last_code: u16,
    stuck_code: Option<u16>,
}

impl LoadCellSim {
    /// A cell whose dynamics advance in substeps of `substep_s` (> 0), settled at
    /// `initial_force_n` (the scene starts in steady sliding).
    pub fn new(cell: &LoadCell, substep_s: f32, initial_force_n: f32) -> Self {
        let bits = cell.adc_bits.clamp(2, 16);
        let max_code = ((1u32 << bits) - 1) as u16;
        let zero_code = (1u32 << (bits - 1)) as u16;
        let full_scale_n = cell.full_scale_n as f32;
        let mut sim = Self {
            full_scale_n,
            gain: 1.0 + cell.gain_error as f32,
            offset_n: cell.offset_n as f32,
            noise_rms_n: (cell.noise_rms_pct_fs / 100.0 * cell.full_scale_n) as f32,
            smoothing: 1.0 - libm::expf(-TAU * cell.bandwidth_hz as f32 * substep_s),
            zero_code,
            max_code,
            filtered_n: initial_force_n,
            last_code: zero_code,
            stuck_code: None,
        };
        sim.last_code = sim.convert(sim.gain * initial_force_n + sim.offset_n);
        sim
    }

    /// One substep of the cell's dynamics with the true force `force_n` (N) held.
    pub fn track(&mut self, force_n: f32) {
        self.filtered_n += self.smoothing * (force_n - self.filtered_n);
    }

    /// Force seen through the cell's dynamics, N (no calibration error, noise or fault).
    pub fn filtered_n(&self) -> f32 {
        self.filtered_n
    }

    /// Samples the converter: one noise draw from `noise`, then `fault` if one is active. The
    /// code is the cell's converter word (unipolar, `adc_bits` wide).
    pub fn sample(&mut self, noise: &mut Gaussian, fault: Option<FaultKind>) -> AdcCode {
        let draw = noise.sample();
        let reading = self.gain * self.filtered_n + self.offset_n + self.noise_rms_n * draw;
        let code = match fault {
            None => self.convert(reading),
            Some(FaultKind::Disconnected { rail: Rail::Low }) => 0,
            Some(FaultKind::Disconnected { rail: Rail::High }) => self.max_code,
            Some(FaultKind::Stuck) => *self.stuck_code.get_or_insert(self.last_code),
            Some(FaultKind::Spike { force_n }) => self.convert(reading + force_n as f32),
        };
        if !matches!(fault, Some(FaultKind::Stuck)) {
            self.stuck_code = None;
        }
        self.last_code = code;
        AdcCode::from_word(code)
    }

    /// Converter code of a reading (N): mid-scale for zero, saturating at both ends.
    pub fn convert(&self, reading_n: f32) -> u16 {
        let zero = f32::from(self.zero_code);
        let code = libm::roundf(zero + reading_n / self.full_scale_n * zero);
        // NaN compares false both ways and lands on 0, the low rail.
        code.clamp(0.0, f32::from(self.max_code)) as u16
    }

    /// Nominal force of a code, N (the datasheet calibration): (code - zero) / zero x FS.
    pub fn nominal_force_n(&self, code: AdcCode) -> f32 {
        let zero = f32::from(self.zero_code);
        // A cell's code has at most 16 bits: exact in f32.
        (code.raw() as f32 - zero) / zero * self.full_scale_n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference scene's tangential cell: 2 N full scale, 2 kHz, 12 bits.
    const CELL: LoadCell = LoadCell {
        full_scale_n: 2.0,
        bandwidth_hz: 2000.0,
        offset_n: 0.0,
        gain_error: 0.0,
        noise_rms_pct_fs: 0.0,
        adc_bits: 12,
    };
    const SUBSTEP: f32 = 25e-6;

    #[test]
    fn codes_are_quantised_around_mid_scale_and_saturate() {
        let cell = LoadCellSim::new(&CELL, SUBSTEP, 0.0);
        // One code is 2 N / 2048 = 0.977 mN.
        assert_eq!(cell.convert(0.0), 2048);
        assert_eq!(cell.convert(1.0), 3072);
        assert_eq!(cell.convert(-1.0), 1024);
        assert_eq!(cell.convert(0.000_48), 2048);
        assert_eq!(cell.convert(0.000_50), 2049);
        assert_eq!(cell.convert(-0.000_50), 2047);
        // Saturation at the rails, beyond +-full scale and for garbage.
        assert_eq!(cell.convert(1.998), 4094);
        assert_eq!(cell.convert(2.0), 4095);
        assert_eq!(cell.convert(50.0), 4095);
        assert_eq!(cell.convert(-2.0), 0);
        assert_eq!(cell.convert(-50.0), 0);
        assert_eq!(cell.convert(f32::NAN), 0);
        assert_eq!(cell.nominal_force_n(AdcCode::new(3072)), 1.0);
        assert_eq!(cell.nominal_force_n(AdcCode::new(2048)), 0.0);
    }

    #[test]
    fn other_resolutions_scale_the_codes() {
        let cell = LoadCellSim::new(
            &LoadCell {
                adc_bits: 16,
                ..CELL
            },
            SUBSTEP,
            0.0,
        );
        assert_eq!(cell.convert(0.0), 32_768);
        assert_eq!(cell.convert(5.0), 65_535);
        assert_eq!(cell.convert(1.0), 49_152);
    }

    #[test]
    fn the_cell_is_a_first_order_low_pass() {
        let mut cell = LoadCellSim::new(&CELL, SUBSTEP, 0.0);
        // Time constant 1 / (2 pi 2 kHz) = 79.6 us, about three substeps.
        let tau = 1.0 / (TAU * 2000.0);
        for n in 1..=12 {
            cell.track(1.0);
            let expected = 1.0 - libm::expf(-(n as f32) * SUBSTEP / tau);
            assert!((cell.filtered_n() - expected).abs() < 1e-6, "substep {n}");
        }
        // And back down with the same time constant.
        let start = cell.filtered_n();
        for _ in 0..4 {
            cell.track(0.0);
        }
        let expected = start * libm::expf(-4.0 * SUBSTEP / tau);
        assert!((cell.filtered_n() - expected).abs() < 1e-6);
    }

    #[test]
    fn offset_and_gain_error_shift_the_reading() {
        let cell = LoadCell {
            offset_n: 0.1,
            gain_error: 0.05,
            ..CELL
        };
        let mut sim = LoadCellSim::new(&cell, SUBSTEP, 1.0);
        let mut noise = Gaussian::from_seed(1);
        // 1.05 x 1 N + 0.1 N = 1.15 N: 2048 + 1.15 / 2 x 2048 = 3225.6.
        assert_eq!(sim.sample(&mut noise, None), AdcCode::new(3226));
    }

    #[test]
    fn noise_has_the_stated_rms() {
        let cell = LoadCell {
            noise_rms_pct_fs: 0.5,
            adc_bits: 16,
            ..CELL
        };
        let mut sim = LoadCellSim::new(&cell, SUBSTEP, 0.5);
        let mut noise = Gaussian::from_seed(9);
        let n = 50_000;
        let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let code = sim.sample(&mut noise, None);
            let force = f64::from(sim.nominal_force_n(code));
            sum += force;
            sum_sq += force * force;
        }
        let mean = sum / f64::from(n);
        let rms = (sum_sq / f64::from(n) - mean * mean).sqrt();
        // 0.5 % of 2 N = 10 mN; standard error of the mean 0.045 mN.
        assert!((mean - 0.5).abs() < 2e-4, "mean {mean}");
        assert!((rms - 0.01).abs() < 2e-4, "rms {rms}");
    }

    #[test]
    fn a_disconnected_cell_reads_its_rail() {
        let mut sim = LoadCellSim::new(&CELL, SUBSTEP, 0.5);
        let mut noise = Gaussian::from_seed(1);
        let high = FaultKind::Disconnected { rail: Rail::High };
        let low = FaultKind::Disconnected { rail: Rail::Low };
        assert_eq!(sim.sample(&mut noise, Some(high)), AdcCode::new(4095));
        assert_eq!(sim.sample(&mut noise, Some(low)), AdcCode::new(0));
        assert_eq!(sim.sample(&mut noise, None), AdcCode::new(2560));
    }

    #[test]
    fn a_stuck_cell_repeats_the_code_before_the_onset() {
        let cell = LoadCell {
            noise_rms_pct_fs: 1.0,
            ..CELL
        };
        let mut sim = LoadCellSim::new(&cell, SUBSTEP, 0.5);
        let mut noise = Gaussian::from_seed(3);
        let before = sim.sample(&mut noise, None);
        let stuck: [AdcCode; 20] = core::array::from_fn(|_| {
            sim.track(1.5);
            sim.sample(&mut noise, Some(FaultKind::Stuck))
        });
        assert!(stuck.iter().all(|&code| code == before));
        // Released, it follows the force again (1.5 N through the filter, with noise).
        for _ in 0..200 {
            sim.track(1.5);
        }
        let live = sim.sample(&mut noise, None);
        assert!((live.raw() as f32 - 3584.0).abs() < 60.0, "{live:?}");
        // A new stuck episode freezes the new value.
        let again = sim.sample(&mut noise, Some(FaultKind::Stuck));
        assert_eq!(again, live);
    }

    #[test]
    fn a_spike_adds_its_force_for_the_sample() {
        let mut sim = LoadCellSim::new(&CELL, SUBSTEP, 0.5);
        let mut noise = Gaussian::from_seed(1);
        let spike = FaultKind::Spike { force_n: 1.0 };
        assert_eq!(sim.sample(&mut noise, Some(spike)), AdcCode::new(3584));
        assert_eq!(sim.sample(&mut noise, None), AdcCode::new(2560));
        // A spike past the range saturates.
        let big = FaultKind::Spike { force_n: -4.0 };
        assert_eq!(sim.sample(&mut noise, Some(big)), AdcCode::new(0));
    }
}
