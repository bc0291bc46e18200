//! The `commission status` reply: the last commissioning's step, result or refusal
//! ([`crate::station::CommissionReport`]).
//!
//! - `ok commission=none` (none since the loop was built, and none restored);
//! - `ok commission=running step=burst`;
//! - `ok commission=done f0_hz=39999.66 f0_se_hz=0.52 q=99.59 q_se=0.62 tau_us=792.6
//!   tau_se_us=5.0 mu0=0.240673 mu0_se=0.000119 points=25 normal_zero_n=0.0167
//!   normal_zero_se_n=0.0003 normal_noise_n=0.0050 normal_noise_se_n=0.0002
//!   tangential_zero_n=-0.0034 tangential_zero_se_n=none tangential_noise_n=none
//!   tangential_noise_se_n=none` (values rounded to the decimals shown; each `_se` is the
//!   standard error; a cell's zero error and noise are `none` until a `tare` measured its
//!   noise);
//! - `ok commission=restored ...` (the same fields): the loop runs on values a former
//!   commissioning measured, restored from the settings store by `load` or at boot;
//! - `ok commission=refused step=ring-down reason=Q-outside--5--5000- value=4.900000` (the
//!   reason's words joined by `-`; `value` the refused value in the step's unit, left out when
//!   there is none).

use heapless::String;
use heapless::string::StringView;

use super::reply::{NONE, OkReply};
use super::text::FormatError;
use crate::commission::{CellZero, CommissionResult};
use crate::station::{CommissionReport, noise_standard_error_n, zero_standard_error_n};

/// Powers of ten for [`scaled`] (a table: `pow` in soft float costs more than a control
/// period's budget on the QEMU board, where a command's reply is made inside a step).
const POWERS_OF_TEN: [f64; 7] = [1.0, 10.0, 100.0, 1e3, 1e4, 1e5, 1e6];

/// `value` x 10^decimals (at most 6) rounded to an integer, `None` for a value that is not
/// finite or does not fit (|scaled| < 9e15, exact in `f64`).
fn scaled(value: f64, decimals: u8) -> Option<i64> {
    let power = POWERS_OF_TEN.get(usize::from(decimals))?;
    let scaled = libm::round(value * power);
    (scaled.is_finite() && libm::fabs(scaled) < 9.0e15).then_some(scaled as i64)
}

/// Decimals of the cells' newtons: 0.1 mN (a 0.2 % FS cell of 2 N has 4 mN of noise, its
/// zero's error a sixteenth of that).
const CELL_DECIMALS: u8 = 4;

/// `key=value` with `decimals`, or `key=none` when the value is absent or cannot be written.
fn optional<'a>(reply: OkReply<'a>, key: &str, value: Option<f64>, decimals: u8) -> OkReply<'a> {
    match value.and_then(|v| scaled(v, decimals)) {
        Some(bits) => reply.fixed(key, bits, decimals),
        None => reply.word(key, NONE),
    }
}

/// The four fields of one cell: zero, its standard error, noise and its standard error.
fn cell<'a>(reply: OkReply<'a>, keys: [&str; 4], cell: &CellZero) -> OkReply<'a> {
    let reply = optional(reply, keys[0], Some(cell.zero_n), CELL_DECIMALS);
    let reply = optional(reply, keys[1], zero_standard_error_n(cell), CELL_DECIMALS);
    let reply = optional(reply, keys[2], cell.noise_rms_n, CELL_DECIMALS);
    optional(reply, keys[3], noise_standard_error_n(cell), CELL_DECIMALS)
}

/// The values of a result and their standard errors.
fn values<'a>(reply: OkReply<'a>, r: &CommissionResult) -> OkReply<'a> {
    let reply = optional(reply, "f0_hz", Some(r.resonance_hz.value), 2);
    let reply = optional(reply, "f0_se_hz", Some(r.resonance_hz.standard_error), 2);
    let reply = optional(reply, "q", Some(r.quality_factor.value), 2);
    let reply = optional(reply, "q_se", Some(r.quality_factor.standard_error), 2);
    let reply = optional(reply, "tau_us", Some(r.time_constant_s.value * 1e6), 1);
    let reply = optional(
        reply,
        "tau_se_us",
        Some(r.time_constant_s.standard_error * 1e6),
        1,
    );
    let reply = optional(reply, "mu0", Some(r.natural_coefficient.value), 6);
    let reply = optional(
        reply,
        "mu0_se",
        Some(r.natural_coefficient.standard_error),
        6,
    );
    let reply = reply.uint("points", u64::from(r.ring_down_points));
    let reply = cell(
        reply,
        [
            "normal_zero_n",
            "normal_zero_se_n",
            "normal_noise_n",
            "normal_noise_se_n",
        ],
        &r.normal,
    );
    cell(
        reply,
        [
            "tangential_zero_n",
            "tangential_zero_se_n",
            "tangential_noise_n",
            "tangential_noise_se_n",
        ],
        &r.tangential,
    )
}

/// Writes the `commission status` reply for `report`.
pub fn format_commission(
    report: &CommissionReport,
    out: &mut StringView,
) -> Result<(), FormatError> {
    let reply = OkReply::new(out);
    match report {
        CommissionReport::Never => reply.word("commission", "none"),
        CommissionReport::Running(step) => reply
            .word("commission", "running")
            .word("step", step.name()),
        CommissionReport::Done(r) => values(reply.word("commission", "done"), r),
        CommissionReport::Restored(r) => values(reply.word("commission", "restored"), r),
        CommissionReport::Refused(refusal) => {
            let mut reason: String<48> = String::new();
            for c in refusal.reason.chars() {
                let c = if c.is_ascii_alphanumeric() { c } else { '-' };
                if reason.push(c).is_err() {
                    break;
                }
            }
            let reply = reply
                .word("commission", "refused")
                .word("step", refusal.step.name())
                .word("reason", reason.as_str());
            match scaled(refusal.value, 6) {
                Some(bits) => reply.fixed("value", bits, 6),
                None => reply,
            }
        }
    }
    .finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::commission::{CellZero, CommissionResult, Measured, Refusal, Step};

    fn reply(report: &CommissionReport) -> std::string::String {
        let mut out: String<{ super::super::REPLY_CAPACITY }> = String::new();
        format_commission(report, out.as_mut_view()).expect("fits");
        out.as_str().into()
    }

    fn m(value: f64, standard_error: f64) -> Measured {
        Measured {
            value,
            standard_error,
        }
    }

    fn done() -> CommissionResult {
        CommissionResult {
            resonance_hz: m(39_999.655, 0.523),
            time_constant_s: m(792.6e-6, 4.95e-6),
            quality_factor: m(99.594, 0.622),
            natural_coefficient: m(0.240_673, 0.000_119),
            ring_down_points: 25,
            normal: CellZero {
                zero_n: 0.0167,
                noise_rms_n: Some(0.005),
            },
            tangential: CellZero {
                zero_n: -0.0034,
                noise_rms_n: None,
            },
        }
    }

    #[test]
    fn each_state_has_its_reply() {
        assert_eq!(reply(&CommissionReport::Never), "ok commission=none\n");
        assert_eq!(
            reply(&CommissionReport::Running(Step::RingDown)),
            "ok commission=running step=ring-down\n"
        );
        let refused = Refusal::new(Step::RingDown, "Q outside [5, 5000]", 4.9);
        assert_eq!(
            reply(&CommissionReport::Refused(refused)),
            "ok commission=refused step=ring-down reason=Q-outside--5--5000- value=4.900000\n"
        );
        let no_value = Refusal::new(Step::Burst, "stopped", f64::NAN);
        assert_eq!(
            reply(&CommissionReport::Refused(no_value)),
            "ok commission=refused step=burst reason=stopped\n"
        );
        // The zero's error is the noise over sqrt(256), the noise's over sqrt(512).
        let fields = "f0_hz=39999.66 f0_se_hz=0.52 q=99.59 q_se=0.62 tau_us=792.6 \
             tau_se_us=5.0 mu0=0.240673 mu0_se=0.000119 points=25 normal_zero_n=0.0167 \
             normal_zero_se_n=0.0003 normal_noise_n=0.0050 normal_noise_se_n=0.0002 \
             tangential_zero_n=-0.0034 tangential_zero_se_n=none tangential_noise_n=none \
             tangential_noise_se_n=none\n";
        assert_eq!(
            reply(&CommissionReport::Done(done())),
            std::format!("ok commission=done {fields}")
        );
        assert_eq!(
            reply(&CommissionReport::Restored(done())),
            std::format!("ok commission=restored {fields}")
        );
    }

    /// The longest reply (every value at the widest [`crate::commission::check`] lets
    /// through, both cells measured) fits the reply buffer, and a value that cannot be
    /// written reads `none` instead of a wrong number.
    #[test]
    fn the_widest_result_fits_and_an_unwritable_value_reads_none() {
        let mut wide = done();
        wide.resonance_hz = m(59_999.999, 40_000.0);
        wide.time_constant_s = m(0.079_577_4, 0.079_577_4);
        wide.quality_factor = m(4_999.999, 4_999.999);
        wide.natural_coefficient = m(1.999_999, 1.999_999);
        wide.ring_down_points = u32::MAX;
        let cell = CellZero {
            zero_n: -32_767.999_9,
            noise_rms_n: Some(32_767.999_9),
        };
        wide.normal = cell;
        wide.tangential = cell;
        let mut out: String<{ super::super::REPLY_CAPACITY }> = String::new();
        format_commission(&CommissionReport::Restored(wide), out.as_mut_view())
            .expect("the widest reply fits");
        assert_eq!(out.len(), 389, "{}", out.as_str());
        let mut unwritable = done();
        unwritable.quality_factor.standard_error = f64::INFINITY;
        assert!(reply(&CommissionReport::Done(unwritable)).contains(" q_se=none "));
    }
}
