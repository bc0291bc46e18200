//! Axis ticks: 1-2-5 steps on linear axes, decades on log axes, and SI-friendly labels.
//!
//! Tick values are built from their decimal form (`"2e-3".parse()`), so `0.3` is exactly the
//! literal `0.3`, not `3.0 * 0.1`.

/// Values are clamped to +-this, so a span never overflows (far beyond any quantity plotted here).
const VALUE_LIMIT: f64 = 1.0e300;
/// Spans below this, or below [`RELATIVE_SPAN`] of the centre's magnitude, count as one value.
const MIN_SPAN: f64 = 1.0e-290;
/// Relative span below which f64 can no longer give distinct tick labels.
const RELATIVE_SPAN: f64 = 1.0e-12;
/// At most this many ticks per axis, whatever the request.
const MAX_TICKS: i64 = 200;
/// Tolerance, in units of the step, for a range end that is almost a tick.
const STEP_SLACK: f64 = 1.0e-9;

/// A tick label.
#[derive(Debug, Clone, PartialEq)]
pub enum TickLabel {
    /// Plain text, such as `0.25` or `20k`.
    Text(String),
    /// A power of ten, drawn as `10` with the exponent raised.
    Pow10(i32),
}

/// One tick: its position in data units, and its label (`None` for a minor tick).
#[derive(Debug, Clone, PartialEq)]
pub struct Tick {
    /// Position, in the axis's data unit.
    pub value: f64,
    /// Label of a major tick; `None` for a minor one (drawn as a fainter grid line only).
    pub label: Option<TickLabel>,
}

/// `floor(log10(v))`, snapping to the nearest integer when within 1e-9 (so `log10(1000)` that
/// comes out as 2.9999999999999996 still counts as 3). `v` must be positive and finite.
pub(crate) fn floor_log10(v: f64) -> i32 {
    let l = v.log10();
    let r = l.round();
    (if (l - r).abs() < 1e-9 { r } else { l.floor() }) as i32
}

/// `ceil(log10(v))` with the same snapping as [`floor_log10`].
pub(crate) fn ceil_log10(v: f64) -> i32 {
    let l = v.log10();
    let r = l.round();
    (if (l - r).abs() < 1e-9 { r } else { l.ceil() }) as i32
}

/// The f64 nearest to `mantissa` x 10^`exp`, parsed from its decimal form.
pub(crate) fn decimal(mantissa: i64, exp: i32) -> f64 {
    format!("{mantissa}e{exp}").parse().unwrap_or(f64::NAN)
}

/// Step (mantissa 1, 2 or 5, and decimal exponent) giving about `target_count` intervals over
/// `span`.
fn step_parts(span: f64, target_count: usize) -> (i64, i32) {
    let raw = span.abs() / target_count.max(1) as f64;
    if !(raw.is_finite() && raw >= f64::MIN_POSITIVE) {
        return (1, 0);
    }
    let exp = floor_log10(raw);
    // Switch mantissa at the geometric means (sqrt 2, sqrt 10, sqrt 50), so the tick count
    // lands as close to the target as 1-2-5 steps allow.
    match raw / decimal(1, exp) {
        f if f < 2f64.sqrt() => (1, exp),
        f if f < 10f64.sqrt() => (2, exp),
        f if f < 50f64.sqrt() => (5, exp),
        _ => (1, exp + 1),
    }
}

/// The 1-2-5 step (1, 2 or 5 x 10^n) nearest, on a log scale, to `span / target_count`, so
/// `span` holds between about 0.7 and 1.4 times `target_count` steps. Returns 1 for a zero or
/// non-finite span.
pub fn nice_step(span: f64, target_count: usize) -> f64 {
    let (m, e) = step_parts(span, target_count);
    decimal(m, e)
}

/// Makes any pair usable as an axis range: orders it, replaces non-finite ends, clamps to
/// +-1e300, and widens a single value `v` to `v +- 10 %` (or -1..1 for zero).
pub(crate) fn sane_range(min: f64, max: f64) -> (f64, f64) {
    let (lo, hi) = match (min.is_finite(), max.is_finite()) {
        (true, true) => (min.min(max), min.max(max)),
        (true, false) => (min, min),
        (false, true) => (max, max),
        (false, false) => (0.0, 1.0),
    };
    let (lo, hi) = (
        lo.clamp(-VALUE_LIMIT, VALUE_LIMIT),
        hi.clamp(-VALUE_LIMIT, VALUE_LIMIT),
    );
    let centre = lo / 2.0 + hi / 2.0;
    if hi - lo > MIN_SPAN.max(centre.abs() * RELATIVE_SPAN) {
        return (lo, hi);
    }
    let half = if centre == 0.0 {
        1.0
    } else {
        (centre.abs() * 0.1).max(MIN_SPAN)
    };
    (centre - half, centre + half)
}

/// `[min, max]` widened outward to whole 1-2-5 steps (see [`nice_step`]), for a value axis.
/// Handles reversed, degenerate (one value) and non-finite input like [`linear_ticks`].
pub fn nice_linear_range(min: f64, max: f64, target_count: usize) -> (f64, f64) {
    let (lo, hi) = sane_range(min, max);
    let (m, e) = step_parts(hi - lo, target_count);
    let step = decimal(m, e);
    let first = (lo / step + STEP_SLACK).floor() as i64;
    let last = (hi / step - STEP_SLACK).ceil() as i64;
    (decimal(first * m, e), decimal(last * m, e))
}

/// Ticks at every multiple of a 1-2-5 step inside `[lo, hi]` (about `target_count` intervals),
/// labelled by [`format_linear_tick`]. A degenerate or invalid range is first made usable
/// (one value `v` becomes `v +- 10 %`; NaN/inf ends are replaced).
pub fn linear_ticks(lo: f64, hi: f64, target_count: usize) -> Vec<Tick> {
    let (lo, hi) = sane_range(lo, hi);
    let (m, e) = step_parts(hi - lo, target_count);
    let step = decimal(m, e);
    let first = (lo / step - STEP_SLACK).ceil() as i64;
    let last = (hi / step + STEP_SLACK).floor() as i64;
    let count = (last - first + 1).clamp(0, MAX_TICKS);
    let values: Vec<f64> = (0..count).map(|i| decimal((first + i) * m, e)).collect();
    let max_abs = values.iter().fold(0.0_f64, |acc, v| acc.max(v.abs()));
    values
        .into_iter()
        .map(|value| Tick {
            value,
            label: Some(TickLabel::Text(format_linear_tick(value, step, max_abs))),
        })
        .collect()
}

/// Label for a linear tick `value` on an axis with tick spacing `step` whose largest tick
/// magnitude is `max_abs`. Axes reaching 1e4 or more, or staying below 0.01, use an SI prefix
/// (`20k`, `5µ`; `2e18` beyond the prefixes); decimals follow the step (`0.25` -> 2), and zero is `0`.
pub fn format_linear_tick(value: f64, step: f64, max_abs: f64) -> String {
    let step_exp = if step.is_finite() && step > 0.0 {
        floor_log10(step)
    } else {
        0
    };
    let group = if max_abs.is_finite() && (max_abs >= 1e4 || (max_abs > 0.0 && max_abs < 1e-2)) {
        floor_log10(max_abs).div_euclid(3) * 3
    } else {
        0
    };
    let decimals = (group - step_exp).clamp(0, 17) as usize;
    let text = format!("{:.*}", decimals, value / decimal(1, group));
    if text
        .trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        return "0".to_string();
    }
    let prefix = match group {
        -15 => "f",
        -12 => "p",
        -9 => "n",
        -6 => "µ",
        -3 => "m",
        0 => "",
        3 => "k",
        6 => "M",
        9 => "G",
        12 => "T",
        15 => "P",
        g => return format!("{text}e{g}"),
    };
    format!("{text}{prefix}")
}

/// Whole-decade log range covering the positive finite values among `min` and `max`; a single
/// decade value `10^n` becomes `10^(n-1)..10^(n+1)`. Without a usable value, 1..10.
pub fn log_range(min: f64, max: f64) -> (f64, f64) {
    let usable = |v: f64| v.is_finite() && v > 0.0;
    let (lo, hi) = match (usable(min), usable(max)) {
        (true, true) => (min.min(max), min.max(max)),
        (true, false) => (min, min),
        (false, true) => (max, max),
        (false, false) => return (1.0, 10.0),
    };
    let mut lo_exp = floor_log10(lo).clamp(-307, 307);
    let mut hi_exp = ceil_log10(hi).clamp(-307, 307);
    if hi_exp <= lo_exp {
        lo_exp = (lo_exp - 1).max(-307);
        hi_exp = lo_exp + 2;
    }
    (decimal(1, lo_exp), decimal(1, hi_exp))
}

/// Ticks at each decade `10^n` inside `[lo, hi]` (labelled as powers of ten), with minor ticks
/// at 2..9 x 10^n when the range spans six decades or fewer. When there are more than
/// `max_labels` decades only every k-th is labelled (multiples of k) and the rest become minor.
/// An unusable range (not positive, not finite, reversed) is replaced by [`log_range`] of it.
pub fn log_ticks(lo: f64, hi: f64, max_labels: usize) -> Vec<Tick> {
    let usable = |v: f64| v.is_finite() && v > 0.0;
    let (lo, hi) = if usable(lo) && usable(hi) && lo < hi {
        (lo, hi)
    } else {
        log_range(lo, hi)
    };
    let lo_exp = floor_log10(lo);
    let hi_exp = ceil_log10(hi);
    let decades = hi_exp - lo_exp;
    let max_labels = max_labels.clamp(1, 1000) as i32;
    let every = ((decades + max_labels - 1) / max_labels).max(1);
    let minors = decades <= 6;
    let inside = |v: f64| v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9);
    let mut ticks = Vec::new();
    for exp in lo_exp..=hi_exp {
        let value = decimal(1, exp);
        if inside(value) {
            let label = (exp.rem_euclid(every) == 0).then_some(TickLabel::Pow10(exp));
            ticks.push(Tick { value, label });
        }
        for m in 2..=9 {
            let value = decimal(m, exp);
            if minors && inside(value) {
                ticks.push(Tick { value, label: None });
            }
        }
    }
    ticks
}

#[cfg(test)]
mod tests {
    use super::*;

    fn values(ticks: &[Tick]) -> Vec<f64> {
        ticks.iter().map(|t| t.value).collect()
    }

    fn texts(ticks: &[Tick]) -> Vec<String> {
        ticks
            .iter()
            .map(|t| match &t.label {
                Some(TickLabel::Text(s)) => s.clone(),
                Some(TickLabel::Pow10(e)) => format!("10^{e}"),
                None => "-".to_string(),
            })
            .collect()
    }

    #[test]
    fn steps_are_one_two_five() {
        assert_eq!(nice_step(10.0, 5), 2.0);
        assert_eq!(nice_step(10.0, 10), 1.0);
        assert_eq!(nice_step(7.0, 5), 1.0);
        assert_eq!(nice_step(0.3, 5), 0.05);
        assert_eq!(nice_step(2.4e-9, 5), 5e-10);
        assert_eq!(nice_step(9.0e6, 4), 2e6);
        assert_eq!(nice_step(0.0, 5), 1.0);
        assert_eq!(nice_step(f64::NAN, 5), 1.0);
    }

    #[test]
    fn linear_ticks_are_exact_decimals() {
        let t = linear_ticks(0.0, 1.0, 5);
        assert_eq!(values(&t), [0.0, 0.2, 0.4, 0.6, 0.8, 1.0]);
        assert_eq!(texts(&t), ["0", "0.2", "0.4", "0.6", "0.8", "1.0"]);
        let t = linear_ticks(0.05, 0.95, 9);
        assert_eq!(values(&t)[..3], [0.1, 0.2, 0.3]);
    }

    #[test]
    fn negative_and_reversed_ranges() {
        let t = linear_ticks(-3.0, -1.2, 4);
        assert_eq!(values(&t), [-3.0, -2.5, -2.0, -1.5]);
        assert_eq!(texts(&t), ["-3.0", "-2.5", "-2.0", "-1.5"]);
        assert_eq!(linear_ticks(-1.2, -3.0, 4), t);
        let t = linear_ticks(-5.0, 5.0, 4);
        assert_eq!(texts(&t), ["-4", "-2", "0", "2", "4"]);
    }

    #[test]
    fn tiny_and_huge_ranges_use_si_prefixes() {
        let t = linear_ticks(1e-9, 3e-9, 4);
        assert_eq!(texts(&t), ["1.0n", "1.5n", "2.0n", "2.5n", "3.0n"]);
        let t = linear_ticks(0.0, 4e4, 4);
        assert_eq!(texts(&t), ["0", "10k", "20k", "30k", "40k"]);
        let t = linear_ticks(0.0, 3e18, 3);
        assert_eq!(texts(&t), ["0", "1e18", "2e18", "3e18"]);
        let t = linear_ticks(0.0, 0.004, 4);
        assert_eq!(texts(&t), ["0", "1m", "2m", "3m", "4m"]);
        // An offset range narrower than its magnitude keeps enough decimals to differ.
        let t = linear_ticks(1.0, 1.0 + 4e-6, 4);
        assert_eq!(texts(&t)[1], "1.000001");
        for (lo, hi) in [(-1e308, 1e308), (1e-300, 2e-300), (f64::MIN, f64::MAX)] {
            let t = linear_ticks(lo, hi, 5);
            assert!((2..=12).contains(&t.len()), "{lo} {hi}: {}", t.len());
            assert!(t.iter().all(|t| t.value.is_finite()));
        }
    }

    #[test]
    fn single_value_and_invalid_ranges_are_widened() {
        for v in [0.0, 5.0, -2.5, 1e-20, 1e20] {
            let t = linear_ticks(v, v, 5);
            assert!(t.len() >= 2, "{v}");
            let (lo, hi) = nice_linear_range(v, v, 5);
            assert!(lo < v && v < hi, "{v}: {lo} {hi}");
        }
        assert_eq!(nice_linear_range(f64::NAN, f64::NAN, 5), (0.0, 1.0));
        assert_eq!(nice_linear_range(2.0, f64::INFINITY, 5), (1.8, 2.2));
    }

    #[test]
    fn nice_range_snaps_outward_to_steps() {
        assert_eq!(nice_linear_range(0.13, 0.87, 5), (0.0, 1.0));
        assert_eq!(nice_linear_range(-0.3, 1.7, 4), (-0.5, 2.0));
        assert_eq!(nice_linear_range(0.0, 2.0, 4), (0.0, 2.0));
        assert_eq!(nice_linear_range(1.96, 2.04, 4), (1.96, 2.04));
    }

    #[test]
    fn log_ticks_on_decades() {
        let t = log_ticks(10.0, 1e6, 10);
        let majors: Vec<_> = t.iter().filter(|t| t.label.is_some()).collect();
        assert_eq!(majors.len(), 6);
        assert_eq!(majors[0].label, Some(TickLabel::Pow10(1)));
        assert_eq!(majors[5].value, 1e6);
        assert_eq!(t.len(), 6 + 5 * 8);
        assert!(t.windows(2).all(|w| w[0].value < w[1].value));
    }

    #[test]
    fn log_ticks_thin_labels_on_wide_ranges() {
        let t = log_ticks(1e-12, 1.0, 7);
        let labelled: Vec<_> = t.iter().filter_map(|t| t.label.clone()).collect();
        assert_eq!(labelled.first(), Some(&TickLabel::Pow10(-12)));
        assert_eq!(labelled.last(), Some(&TickLabel::Pow10(0)));
        assert_eq!(labelled.len(), 7);
        assert_eq!(t.len(), 13, "no 2..9 minors beyond six decades");
        let huge = log_ticks(1e-300, 1e300, 8);
        assert!(huge.iter().filter(|t| t.label.is_some()).count() <= 9);
    }

    #[test]
    fn log_range_of_single_and_invalid_values() {
        assert_eq!(log_range(1e-5, 1e-5), (1e-6, 1e-4));
        assert_eq!(log_range(3e-5, 3e-5), (1e-5, 1e-4));
        assert_eq!(log_range(1000.0, 1000.0), (100.0, 1e4));
        assert_eq!(log_range(12.0, 9.0e5), (10.0, 1e6));
        assert_eq!(log_range(-1.0, 0.0), (1.0, 10.0));
        assert_eq!(log_range(f64::NAN, 50.0), (10.0, 100.0));
        assert_eq!(log_range(f64::MIN_POSITIVE, f64::MAX), (1e-307, 1e307));
        assert!(!log_ticks(-1.0, f64::NAN, 5).is_empty());
    }
}
