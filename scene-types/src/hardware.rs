//! The hardware of a scene: vibration source, horn, resonant transducer, load cells.

/// Kind of vibration source.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ActuatorKind {
    /// Piezoelectric stack transducer (seed 003 Table 1: EDO PMN-PT, 62 discs).
    PmnPtStack,
    /// Ultrasonic welding converter driving a horn (seeds 000/001: Dukane 220, 20 kHz,
    /// 2.2 kW).
    WeldingConverter,
}

/// Stack data of seed 003 Table 1.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Stack {
    /// Number of discs n, 1 ..= 65535 (seed 003: 62).
    pub discs: u16,
    /// Piezoelectric coefficient d33, m/V, (0, 1e-8] (seed 003: 730e-12).
    pub d33_m_per_v: f64,
    /// Stack stiffness, N/m, (0, 1e12] (seed 003: 3.14e8).
    pub stiffness_n_per_m: f64,
    /// Preload bolt stiffness, N/m, [0, 1e12] (seed 003: 3.7e7).
    pub bolt_stiffness_n_per_m: f64,
}

/// The vibration source. A drive command of 1.0 (full scale) applies `full_scale_voltage_v`
/// and, on resonance and settled, gives a vibration of `full_scale_amplitude_m`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Actuator {
    /// Kind of source.
    pub kind: ActuatorKind,
    /// Drive voltage amplitude at full command, V, (0, max_voltage_v]; the current it draws at
    /// resonance, |1/R1 + j 2 pi f0 C0| V, is at most `max_current_a`.
    pub full_scale_voltage_v: f64,
    /// Vibration displacement amplitude at full command on resonance, m, (0, 1e-4]: along the
    /// sliding direction for a stack (x_a, seed 003 eq 2), the longitudinal amplitude A of a
    /// horn (seed 000 eq 16).
    pub full_scale_amplitude_m: f64,
    /// Voltage rating, V, (0, 1e4] (seed 003: 15.466 V).
    pub max_voltage_v: f64,
    /// Current rating, A, (0, 1e3] (seed 003: 1.75 A).
    pub max_current_a: f64,
    /// Stack data; present for [`ActuatorKind::PmnPtStack`].
    pub stack: Option<Stack>,
}

/// Horn (waveguide) geometry and contact position (seed 000 §3, eqs 16-17; seed 001 §3.1:
/// 127 x 61 x 25.4 mm).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Horn {
    /// Length L, m, (0, 1].
    pub length_m: f64,
    /// Width, m, (0, 1].
    pub width_m: f64,
    /// Thickness D, m, (0, 1].
    pub thickness_m: f64,
    /// Vertical (Poisson) amplitude B at full command, m, (0, 1e-4] (seed 000 Table 1).
    pub vertical_amplitude_m: f64,
    /// Contact position x measured from the vibration node, m, |x| <= L/2. At x = 0 the
    /// longitudinal component u = A sin(pi x / L) vanishes.
    pub contact_position_m: f64,
    /// The block travels along the horn through seed 001 Table 1's regions (issue 27): its
    /// position is tracked from the sliding velocity, the plant's horn drives it by the motor
    /// model outside the measured transition region, and a net-force target is held there.
    /// False (the default): the contact stays where it is, friction reduction only.
    pub motor_regions: bool,
}

/// The resonant transducer: envelope dynamics and the Butterworth-Van Dyke electrical model
/// (C0 in parallel with a series R1-L1-C1 branch tuned to f0 with quality factor Q).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Transducer {
    /// Mechanical resonance f0 at t = 0, Hz, 20e3 ..= 60e3.
    pub resonance_hz: f64,
    /// Quality factor Q, 1 ..= 1e4. Envelope time constant tau = 2 Q / (2 pi f0).
    pub quality_factor: f64,
    /// Drift of f0, Hz/s, |drift| <= 1e4; f0 stays in 20e3 ..= 60e3 during the run.
    pub drift_hz_per_s: f64,
    /// Drive frequency the scene starts with, Hz, 20e3 ..= 60e3 (default f0).
    pub drive_hz: f64,
    /// Clamped (parallel) capacitance C0, F, (0, 1e-3] (seed 003 stack: 300 nF).
    pub clamped_capacitance_f: f64,
    /// Motional resistance R1, ohm, (0, 1e5].
    pub motional_resistance_ohm: f64,
    /// Self-heating, load shift, envelope form and `freq auto` (`[transducer.shift]`).
    pub shift: ResonanceShift,
}

/// How the transducer's resonance moves beyond the linear drift (the plant), and whether the
/// scene runs the resonance loop (`freq auto`). [`ResonanceShift::NONE`] (every field zero or
/// false) is the plant of the scenes that predate it, bit for bit.
///
/// `f0(t) = (resonance_hz + drift t) (1 + thermal_per_k dT + load_per_n (F_n - F_n(0)))`,
/// `tau_th d(dT)/dt = R_th P - dT` with `P = |I_m|^2 R1 / 2` dissipated in the motional branch.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ResonanceShift {
    /// Relative f0 change per kelvin of self-heating, 1/K, |.| <= 1e-2 (PMN-PT stacks soften:
    /// negative).
    pub thermal_per_k: f64,
    /// Thermal resistance from the stack to ambient, K/W, [0, 1e3].
    pub thermal_resistance_k_per_w: f64,
    /// Thermal time constant, s, (0, 1e4].
    pub thermal_time_constant_s: f64,
    /// Relative f0 change per newton of static normal load above the initial load, 1/N,
    /// |.| <= 1e-2 (clamping stiffens the stack: positive).
    pub load_per_n: f64,
    /// The motional branch as a complex envelope (`tau dA/dt = u - (1 + j x) A`, the series
    /// R1-L1-C1 branch's own dynamics: its phase lags a frequency change like a real stack's)
    /// instead of the real envelope with the settled phase; the plant then also samples the
    /// drive current synchronously to the PWM for the resonance loop.
    pub bvd_envelope: bool,
    /// The scene runs `freq auto` before its start: the loop searches, then tracks.
    pub freq_auto: bool,
}

impl ResonanceShift {
    /// No shift, real envelope, frequency pinned.
    pub const NONE: Self = Self {
        thermal_per_k: 0.0,
        thermal_resistance_k_per_w: 0.0,
        thermal_time_constant_s: 1.0,
        load_per_n: 0.0,
        bvd_envelope: false,
        freq_auto: false,
    };
}

impl Transducer {
    /// Envelope time constant tau = 2 Q / (2 pi f0) at t = 0, s (0.8 ms at 40 kHz, Q = 100).
    pub fn envelope_time_constant_s(&self) -> f64 {
        2.0 * self.quality_factor / (core::f64::consts::TAU * self.resonance_hz)
    }
}

/// A load cell and its converter channel. Zero force reads mid-scale (the front ends bias
/// the bridge amplifier to mid-supply, see `crate::sense`), so the channel spans
/// `-full_scale_n ..< +full_scale_n` over codes `0 ..= 2^adc_bits - 1`.
///
/// `full_scale_n` and `adc_bits` are the datasheet calibration a controller may use;
/// `offset_n` and `gain_error` are the cell's actual deviations from it, which only the plant
/// knows (a controller has to tare and calibrate them out).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoadCell {
    /// Force at either end of the converter span, N, (0, 5e4].
    pub full_scale_n: f64,
    /// First-order bandwidth of cell and amplifier, Hz, (0, 1e6].
    pub bandwidth_hz: f64,
    /// Offset from the nominal calibration, N, |offset| <= 0.1 full scale.
    pub offset_n: f64,
    /// Relative gain error from the nominal calibration, [-0.2, 0.2] (0.01 = reads 1 % high).
    pub gain_error: f64,
    /// Gaussian noise, RMS, % of full scale, [0, 10].
    pub noise_rms_pct_fs: f64,
    /// Converter resolution, bits, 8 ..= 16 (default 12).
    pub adc_bits: u8,
}

impl LoadCell {
    /// Largest code, 2^bits - 1 (4095 for 12 bits).
    pub const fn max_code(&self) -> u16 {
        ((1u32 << self.adc_bits) - 1) as u16
    }

    /// Code of zero force, 2^(bits - 1) (2048 for 12 bits).
    pub const fn zero_code(&self) -> u16 {
        (1u32 << (self.adc_bits - 1)) as u16
    }

    /// Nominal force of a code, N: (code - zero) / zero * full scale (the datasheet
    /// calibration, without the cell's actual offset and gain error).
    pub fn nominal_force_n(&self, code: u16) -> f64 {
        let zero = f64::from(self.zero_code());
        (f64::from(code) - zero) / zero * self.full_scale_n
    }
}
