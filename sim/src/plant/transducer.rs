//! The resonant transducer: vibration envelope and the electrical side.
//!
//! # Envelope
//!
//! The vibration amplitude `a` (a fraction of the scene's full-scale amplitude) follows the
//! drive command `u` (fraction of full-scale voltage) through a first-order envelope, the
//! slowly varying amplitude of a resonator of quality factor Q:
//!
//! `tau da/dt = g(f) u - a`, `tau = 2 Q / (2 pi f0)`, `g(f) = 1 / sqrt(1 + (2 Q (f - f0) / f0)^2)`
//!
//! (`g` is the resonator's response to a drive at `f` in the narrow-band form the issue
//! states). The update over a substep with `u` and `f` held is exact:
//! `a <- g u + (a - g u) exp(-dt / tau)`. The resonance drifts linearly,
//! `f0(t) = f0 + drift t`, and is evaluated at the middle of each substep.
//!
//! # Electrical side (for the resonance tracker)
//!
//! Butterworth-Van Dyke model: the clamped capacitance C0 in parallel with a series R1-L1-C1
//! motional branch tuned to f0 with quality factor Q (L1 = Q R1 / w0, C1 = 1 / (w0 Q R1)).
//! With the drive voltage `V = u V_fs` as phase reference, the current is
//! `I = j w C0 V + I_m`. The motional current is the vibration in electrical units: its
//! amplitude is `(V_fs / R1) a` and its phase is that of the series branch at the drive
//! frequency, `-atan(Q (f/f0 - f0/f))`. Settled, this is the Butterworth-Van Dyke current to
//! first order in the detuning (exact at f0, where it is in phase with the voltage); during
//! an envelope transient it follows the vibration, as a real motional current does.
//!
//! # Moving resonance, complex envelope, sampled current (`[transducer.shift]`)
//!
//! With a scene's [`scene::ResonanceShift`] the resonance also moves with self-heating and
//! with the static load,
//! `f0(t) = (f0 + drift t) (1 + k_T dT + k_F (F_n - F_n(0)))`, `tau_th d(dT)/dt = R_th P - dT`,
//! `P = |I_m|^2 R1 / 2` (exact first-order update per substep), and with `bvd_envelope` the
//! motional branch is the complex envelope of the series R1-L1-C1 branch,
//! `tau dA/dt = u - (1 + j x) A`, `x = Q (f/f0 - f0/f)`, updated exactly per substep
//! (`A <- A_s + (A - A_s) exp(-(1 + j x) dt / tau)`, `A_s = u / (1 + j x)`): the vibration
//! amplitude is `|A|` and the motional current `(V_fs / R1) A`, whose phase lags a change of
//! frequency by the envelope's time constant as a real stack's does. Such a transducer also
//! samples its current the way the boards' current sense does: one 12-bit code per PWM
//! period (6.6 A full scale, mid-scale zero, 2 LSB RMS noise), at drive phases `1/8 + k/4`
//! turn of period `k` ([`sonolube::resonance::SYNCHRONOUS_PHASE_STEP`]), read from the
//! present phasor at the substep in which the instant falls.
//!
//! With `ResonanceShift::NONE` none of this runs: the plant is bit for bit the one before.
//!
//! The drive phase is a 32-bit turn accumulator (a numerically controlled oscillator)
//! advanced by `f dt` per substep, so long runs lose no phase precision.

use core::f32::consts::TAU;

use sonolube::fx::Turns;
use sonolube::scene;

use super::noise::Gaussian;

/// Most current samples held between two [`ResonantTransducer::take_current_codes`] calls.
pub const MAX_CURRENT_CODES: usize = sonolube::station::MAX_CURRENT_SAMPLES;

/// Current-sense noise, LSB RMS (12-bit converter).
const CURRENT_NOISE_LSB: f32 = 2.0;

/// Seed offset of the current sense's own noise generator (the load cells' stream is not
/// touched).
const CURRENT_NOISE_SEED: u64 = 0xC0DE_5EED_0000_0014;

/// Current drawn at the drive frequency, relative to the drive voltage.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CurrentPhasor {
    /// Amplitude of the drive voltage, V, >= 0.
    pub voltage_v: f32,
    /// Amplitude of the total current, A, >= 0.
    pub amplitude_a: f32,
    /// Phase of the total current relative to the voltage, rad, in (-pi, pi]; positive when
    /// the current leads (capacitive). 0 when there is no current.
    pub phase_rad: f32,
    /// Amplitude of the motional-branch current alone, A, >= 0.
    pub motional_amplitude_a: f32,
    /// Phase of the motional current relative to the voltage, rad, in [-pi/2, pi/2]: exactly
    /// 0 at f = f0.
    pub motional_phase_rad: f32,
}

/// The simulated resonant transducer (envelope state, drive phase, last drive).
#[derive(Debug, Clone, PartialEq)]
pub struct ResonantTransducer {
    resonance_hz: f32,
    drift_hz_per_s: f32,
    quality_factor: f32,
    full_scale_voltage_v: f32,
    capacitance_f: f32,
    resistance_ohm: f32,
    /// Vibration amplitude, fraction of full scale, [0, 1].
    envelope: f32,
    /// Drive phase at the current time (U0.32 turns).
    phase: Turns,
    command: f32,
    drive_hz: f32,
    time_s: f32,
    /// The scene's shift is not `NONE`: the moving-resonance path runs.
    moving: bool,
    bvd: bool,
    thermal_per_k: f32,
    thermal_resistance_k_per_w: f32,
    thermal_time_constant_s: f32,
    load_per_n: f32,
    /// Self-heating above ambient, K.
    heating_k: f32,
    /// `k_F (F_n - F_n(0))`, set by the plant each substep.
    load_shift: f32,
    /// Complex envelope (in-phase, quadrature), fraction of full scale (`bvd`).
    envelope_iq: (f32, f32),
    /// Unwrapped drive phase, turns x 2^32.
    unwrapped: u64,
    /// Unwrapped drive phase of the next current sample, turns x 2^32.
    next_sample: u64,
    /// Current samples taken since the last take.
    codes: [u16; MAX_CURRENT_CODES],
    code_count: usize,
    current_noise: Gaussian,
}

impl ResonantTransducer {
    /// [`Self::new`] with the scene's resonance shift (a no-op for `ResonanceShift::NONE`),
    /// the current sense's noise seeded from `seed`.
    pub fn with_shift(
        transducer: &scene::Transducer,
        actuator: &scene::Actuator,
        seed: u64,
    ) -> Self {
        let shift = &transducer.shift;
        let mut t = Self::new(transducer, actuator);
        t.moving = *shift != scene::ResonanceShift::NONE;
        t.bvd = shift.bvd_envelope;
        t.thermal_per_k = shift.thermal_per_k as f32;
        t.thermal_resistance_k_per_w = shift.thermal_resistance_k_per_w as f32;
        t.thermal_time_constant_s = shift.thermal_time_constant_s as f32;
        t.load_per_n = shift.load_per_n as f32;
        t.current_noise = Gaussian::from_seed(seed ^ CURRENT_NOISE_SEED);
        t
    }

    /// The static normal load now and at the start, N (moves f0 by `load_per_n`).
    pub fn set_load(&mut self, normal_load_n: f32, initial_n: f32) {
        if self.moving {
            self.load_shift = self.load_per_n * (normal_load_n - initial_n);
        }
    }

    /// Self-heating above ambient, K.
    pub fn heating_k(&self) -> f32 {
        self.heating_k
    }

    /// The current-sense codes taken since the last call (at most [`MAX_CURRENT_CODES`]);
    /// empty unless the scene's transducer has `bvd_envelope`.
    pub fn take_current_codes(&mut self) -> ([u16; MAX_CURRENT_CODES], usize) {
        let taken = (self.codes, self.code_count);
        self.code_count = 0;
        taken
    }

    /// At rest (zero envelope, zero command, phase 0) at t = 0, driven at the scene's
    /// starting frequency.
    pub fn new(transducer: &scene::Transducer, actuator: &scene::Actuator) -> Self {
        Self {
            resonance_hz: transducer.resonance_hz as f32,
            drift_hz_per_s: transducer.drift_hz_per_s as f32,
            quality_factor: transducer.quality_factor as f32,
            full_scale_voltage_v: actuator.full_scale_voltage_v as f32,
            capacitance_f: transducer.clamped_capacitance_f as f32,
            resistance_ohm: transducer.motional_resistance_ohm as f32,
            envelope: 0.0,
            phase: Turns::ZERO,
            command: 0.0,
            drive_hz: transducer.drive_hz as f32,
            time_s: 0.0,
            moving: false,
            bvd: false,
            thermal_per_k: 0.0,
            thermal_resistance_k_per_w: 0.0,
            thermal_time_constant_s: 1.0,
            load_per_n: 0.0,
            heating_k: 0.0,
            load_shift: 0.0,
            envelope_iq: (0.0, 0.0),
            unwrapped: 0,
            next_sample: u64::from(sonolube::resonance::SYNCHRONOUS_FIRST_PHASE),
            codes: [0; MAX_CURRENT_CODES],
            code_count: 0,
            current_noise: Gaussian::from_seed(CURRENT_NOISE_SEED),
        }
    }

    /// Resonance f0 at time `t_s`, Hz: f0 + drift t.
    pub fn resonance_hz(&self, t_s: f32) -> f32 {
        let linear = self.resonance_hz + self.drift_hz_per_s * t_s;
        if self.moving {
            linear * (1.0 + self.thermal_per_k * self.heating_k + self.load_shift)
        } else {
            linear
        }
    }

    /// Envelope time constant 2 Q / (2 pi f0) at time `t_s`, s (0.796 ms at 40 kHz, Q = 100).
    pub fn time_constant_s(&self, t_s: f32) -> f32 {
        2.0 * self.quality_factor / (TAU * self.resonance_hz(t_s))
    }

    /// Settled amplitude per unit command at drive frequency `drive_hz` and time `t_s`,
    /// in (0, 1]: 1 / sqrt(1 + (2 Q (f - f0) / f0)^2); 0 for a non-positive or non-finite
    /// frequency.
    pub fn gain(&self, drive_hz: f32, t_s: f32) -> f32 {
        if !(drive_hz.is_finite() && drive_hz > 0.0) {
            return 0.0;
        }
        let f0 = self.resonance_hz(t_s);
        let detuning = 2.0 * self.quality_factor * (drive_hz - f0) / f0;
        1.0 / libm::sqrtf(1.0 + detuning * detuning)
    }

    /// Advances by `dt_s` (> 0) with the drive `command` (fraction of full-scale voltage,
    /// clamped to [0, 1], NaN as 0) at `drive_hz` held: exact envelope update, drive phase
    /// advanced by `drive_hz dt_s` turns.
    pub fn advance(&mut self, command: f32, drive_hz: f32, dt_s: f32) {
        let command = if command.is_nan() {
            0.0
        } else {
            command.clamp(0.0, 1.0)
        };
        if self.moving {
            self.advance_moving(command, drive_hz, dt_s);
            return;
        }
        let mid_s = self.time_s + 0.5 * dt_s;
        let settled = self.gain(drive_hz, mid_s) * command;
        let decay = libm::expf(-dt_s / self.time_constant_s(mid_s));
        self.envelope = (settled + (self.envelope - settled) * decay).clamp(0.0, 1.0);
        if drive_hz.is_finite() && drive_hz > 0.0 {
            self.phase = self.phase.wrapping_add(turn_fraction(drive_hz * dt_s));
        }
        self.command = command;
        self.drive_hz = drive_hz;
        self.time_s += dt_s;
    }

    /// [`Self::advance`] with the resonance shift, the complex envelope (`bvd`) and the
    /// current samples.
    fn advance_moving(&mut self, command: f32, drive_hz: f32, dt_s: f32) {
        let mid_s = self.time_s + 0.5 * dt_s;
        let valid = drive_hz.is_finite() && drive_hz > 0.0;
        let decay = libm::expf(-dt_s / self.time_constant_s(mid_s));
        if self.bvd && valid {
            let f0 = self.resonance_hz(mid_s);
            let x = self.quality_factor * (drive_hz / f0 - f0 / drive_hz);
            let norm = 1.0 + x * x;
            let settled = (command / norm, -command * x / norm);
            let (sin, cos) = libm::sincosf(-x * dt_s / self.time_constant_s(mid_s));
            let (dr, di) = (
                self.envelope_iq.0 - settled.0,
                self.envelope_iq.1 - settled.1,
            );
            self.envelope_iq = (
                settled.0 + decay * (dr * cos - di * sin),
                settled.1 + decay * (dr * sin + di * cos),
            );
            self.envelope = libm::hypotf(self.envelope_iq.0, self.envelope_iq.1).clamp(0.0, 1.0);
        } else {
            let settled = self.gain(drive_hz, mid_s) * command;
            self.envelope = (settled + (self.envelope - settled) * decay).clamp(0.0, 1.0);
            self.envelope_iq = (self.envelope, 0.0);
        }
        // Self-heating from the motional branch's dissipation, exact first-order update.
        let motional_v = self.full_scale_voltage_v * self.envelope;
        let power_w = 0.5 * motional_v * motional_v / self.resistance_ohm;
        let heating = self.thermal_resistance_k_per_w * power_w;
        let thermal_decay = libm::expf(-dt_s / self.thermal_time_constant_s);
        self.heating_k = heating + (self.heating_k - heating) * thermal_decay;
        self.command = command;
        self.drive_hz = drive_hz;
        self.time_s += dt_s;
        if !valid {
            return;
        }
        let turns = drive_hz * dt_s;
        let advance = turn_fraction(turns);
        self.phase = self.phase.wrapping_add(advance);
        // The whole turns too (a substep may hold one or more PWM periods).
        let whole = libm::floorf(turns) as u64;
        self.unwrapped = self
            .unwrapped
            .wrapping_add((whole << 32) + u64::from(advance.bits()));
        if !self.bvd {
            return;
        }
        // One sample per PWM period, the trigger a quarter turn later each period (after the
        // fourth, back to the first phase of the next period).
        while self.next_sample <= self.unwrapped {
            let phasor = self.current();
            let theta = (self.next_sample as u32) as f32 * (TAU / 4_294_967_296.0);
            let amperes = phasor.amplitude_a * libm::cosf(theta + phasor.phase_rad);
            let lsb = amperes / sonolube::station::CURRENT_SENSE_A_PER_FULL_SCALE as f32 * 2048.0;
            let code = libm::roundf(2048.0 + lsb + CURRENT_NOISE_LSB * self.current_noise.sample())
                .clamp(0.0, 4095.0) as u16;
            if let Some(slot) = self.codes.get_mut(self.code_count) {
                *slot = code;
                self.code_count += 1;
            }
            let quarter = 1u64 << 30;
            let within = (self.next_sample as u32) >> 30;
            self.next_sample += if within == 3 {
                quarter
            } else {
                (1 << 32) + quarter
            };
        }
    }

    /// Vibration amplitude, fraction of the full-scale amplitude, [0, 1].
    pub fn envelope(&self) -> f32 {
        self.envelope
    }

    /// The drive command last applied, [0, 1].
    pub fn command(&self) -> f32 {
        self.command
    }

    /// The drive frequency last applied, Hz.
    pub fn drive_hz(&self) -> f32 {
        self.drive_hz
    }

    /// Time since the start, s (the sum of the substeps).
    pub fn time_s(&self) -> f32 {
        self.time_s
    }

    /// The current at the last drive (command, frequency) and the present envelope.
    pub fn current(&self) -> CurrentPhasor {
        let voltage_v = self.command * self.full_scale_voltage_v;
        let f = self.drive_hz;
        let (motional_amplitude_a, motional_phase_rad) = if self.bvd && f.is_finite() && f > 0.0 {
            let (re, im) = self.envelope_iq;
            let magnitude = libm::hypotf(re, im);
            (
                self.full_scale_voltage_v / self.resistance_ohm * magnitude,
                if magnitude > 0.0 {
                    libm::atan2f(im, re)
                } else {
                    0.0
                },
            )
        } else if f.is_finite() && f > 0.0 {
            let f0 = self.resonance_hz(self.time_s);
            let detuning = self.quality_factor * (f / f0 - f0 / f);
            (
                self.full_scale_voltage_v / self.resistance_ohm * self.envelope,
                -libm::atanf(detuning),
            )
        } else {
            (0.0, 0.0)
        };
        let capacitive_a = if f.is_finite() && f > 0.0 {
            TAU * f * self.capacitance_f * voltage_v
        } else {
            0.0
        };
        let (sin, cos) = libm::sincosf(motional_phase_rad);
        let in_phase = motional_amplitude_a * cos;
        let quadrature = motional_amplitude_a * sin + capacitive_a;
        let amplitude_a = libm::hypotf(in_phase, quadrature);
        CurrentPhasor {
            voltage_v,
            amplitude_a,
            phase_rad: if amplitude_a > 0.0 {
                libm::atan2f(quadrature, in_phase)
            } else {
                0.0
            },
            motional_amplitude_a,
            motional_phase_rad,
        }
    }

    /// Drive phase now, rad in [0, 2 pi).
    pub fn phase_rad(&self) -> f32 {
        self.phase.bits() as f32 * (TAU / 4_294_967_296.0)
    }

    /// Drive voltage waveform `V cos(theta)`, V, at `offset_s` after now (|offset| up to a few
    /// thousand drive periods keeps the phase within 1e-3 rad), with the present phasor held.
    pub fn voltage_at(&self, offset_s: f32) -> f32 {
        self.current().voltage_v * libm::cosf(self.phase_at(offset_s))
    }

    /// Current waveform `|I| cos(theta + phase)`, A, at `offset_s` after now, with the
    /// present phasor held: what a current-sense ADC sampling at those instants would read.
    pub fn current_at(&self, offset_s: f32) -> f32 {
        let phasor = self.current();
        phasor.amplitude_a * libm::cosf(self.phase_at(offset_s) + phasor.phase_rad)
    }

    /// Fills `out` with [`current_at`](Self::current_at) at `first_offset_s + k interval_s`,
    /// for lock-in demodulation.
    pub fn current_samples(&self, first_offset_s: f32, interval_s: f32, out: &mut [f32]) {
        for (k, sample) in out.iter_mut().enumerate() {
            *sample = self.current_at(first_offset_s + k as f32 * interval_s);
        }
    }

    /// Drive phase at `offset_s` after now, rad, reduced to [0, 2 pi) before scaling.
    fn phase_at(&self, offset_s: f32) -> f32 {
        let turns = self
            .phase
            .wrapping_add(turn_fraction(self.drive_hz * offset_s));
        turns.bits() as f32 * (TAU / 4_294_967_296.0)
    }
}

/// The fractional part of `turns` (any sign) as a phase, truncated to 2^-32 turn (`f32`: the
/// plant's own arithmetic, kept as it was; [`Turns::from_turns`] rounds in `f64`).
fn turn_fraction(turns: f32) -> Turns {
    let fraction = turns - libm::floorf(turns);
    // fraction is in [0, 1]; a 1.0 from rounding saturates to u32::MAX, one count short of a
    // whole turn.
    Turns::from_bits((fraction * 4_294_967_296.0) as u32)
}

#[cfg(test)]
#[path = "transducer_tests.rs"]
mod tests;
