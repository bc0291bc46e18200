//! The `commission status` reply: the last commissioning's step, result or refusal
//! ([`crate::station::CommissionReport`]).
//!
//! - `ok commission=none` (none since the loop was built);
//! - `ok commission=running step=burst`;
//! - `ok commission=done f0_hz=39999.66 f0_se_hz=0.52 q=99.59 q_se=0.62 tau_us=792.6
//!   tau_se_us=5.0 mu0=0.240673 mu0_se=0.000119 points=25 normal_zero_n=0.017
//!   tangential_zero_n=-0.003` (values rounded to the decimals shown; each `_se` is the standard
//!   error);
//! - `ok commission=refused step=ring-down reason=ring-down-too-small` (the reason's words joined
//!   by `-`).

use heapless::String;
use heapless::string::StringView;

use super::reply::OkReply;
use super::text::FormatError;
use crate::station::CommissionReport;

/// `value` x 10^decimals rounded to an integer (0 for a value that is not finite or does not
/// fit).
fn scaled(value: f64, decimals: u8) -> i64 {
    let scaled = libm::round(value * libm::pow(10.0, f64::from(decimals)));
    if scaled.is_finite() && libm::fabs(scaled) < 9.0e15 {
        scaled as i64
    } else {
        0
    }
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
        CommissionReport::Done(r) => reply
            .word("commission", "done")
            .fixed("f0_hz", scaled(r.resonance_hz.value, 2), 2)
            .fixed("f0_se_hz", scaled(r.resonance_hz.standard_error, 2), 2)
            .fixed("q", scaled(r.quality_factor.value, 2), 2)
            .fixed("q_se", scaled(r.quality_factor.standard_error, 2), 2)
            .fixed("tau_us", scaled(r.time_constant_s.value * 1e6, 1), 1)
            .fixed(
                "tau_se_us",
                scaled(r.time_constant_s.standard_error * 1e6, 1),
                1,
            )
            .fixed("mu0", scaled(r.natural_coefficient.value, 6), 6)
            .fixed("mu0_se", scaled(r.natural_coefficient.standard_error, 6), 6)
            .uint("points", u64::from(r.ring_down_points))
            .fixed("normal_zero_n", scaled(r.normal.zero_n, 3), 3)
            .fixed("tangential_zero_n", scaled(r.tangential.zero_n, 3), 3),
        CommissionReport::Refused(refusal) => {
            let mut reason: String<48> = String::new();
            for c in refusal.reason.chars() {
                let c = if c.is_ascii_alphanumeric() { c } else { '-' };
                if reason.push(c).is_err() {
                    break;
                }
            }
            reply
                .word("commission", "refused")
                .word("step", refusal.step.name())
                .word("reason", reason.as_str())
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

    #[test]
    fn each_state_has_its_reply() {
        assert_eq!(reply(&CommissionReport::Never), "ok commission=none\n");
        assert_eq!(
            reply(&CommissionReport::Running(Step::RingDown)),
            "ok commission=running step=ring-down\n"
        );
        let refused = Refusal::new(Step::RingDown, "Q outside [5, 5000]", 4.0);
        assert_eq!(
            reply(&CommissionReport::Refused(refused)),
            "ok commission=refused step=ring-down reason=Q-outside--5--5000-\n"
        );
        let m = |value, standard_error| Measured {
            value,
            standard_error,
        };
        let zero = |zero_n| CellZero {
            zero_n,
            noise_rms_n: None,
        };
        let done = CommissionResult {
            resonance_hz: m(39_999.655, 0.523),
            time_constant_s: m(792.6e-6, 4.95e-6),
            quality_factor: m(99.594, 0.622),
            natural_coefficient: m(0.240_673, 0.000_119),
            ring_down_points: 25,
            normal: zero(0.0167),
            tangential: zero(-0.0034),
        };
        assert_eq!(
            reply(&CommissionReport::Done(done)),
            "ok commission=done f0_hz=39999.66 f0_se_hz=0.52 q=99.59 q_se=0.62 tau_us=792.6 \
             tau_se_us=5.0 mu0=0.240673 mu0_se=0.000119 points=25 normal_zero_n=0.017 \
             tangential_zero_n=-0.003\n"
        );
    }
}
