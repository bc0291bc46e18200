//! The numeric arguments of the commands: unit, resolution and accepted range of each.
//!
//! One table entry per quantity so that the parser, the error messages and the documentation
//! cannot disagree: an out-of-range reply prints the very bounds the parser checked.

use heapless::string::StringView;

use super::text::{FormatError, put, put_fixed};

/// A numeric command argument: its name in messages, unit, resolution and range.
///
/// Values are scaled integers: the real value times `10^decimals` (for example milli-newtons
/// for a force with 3 decimals). Bounds are in the same scaled unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Quantity {
    /// Name used in error messages, for example `force`.
    pub name: &'static str,
    /// Unit printed after the range (`N`, `Hz`, `%`), empty for a pure number.
    pub unit: &'static str,
    /// Fraction digits: the resolution is `10^-decimals` of the unit.
    pub decimals: u8,
    /// Lower bound, scaled.
    pub min: i64,
    /// Whether the lower bound itself is excluded (`0 < F`).
    pub min_excluded: bool,
    /// Upper bound, scaled.
    pub max: i64,
    /// Whether the upper bound itself is excluded (`r < 100`).
    pub max_excluded: bool,
}

impl Quantity {
    /// Whether a scaled value is inside the range.
    pub fn contains(&self, value: i64) -> bool {
        let above_min = if self.min_excluded {
            value > self.min
        } else {
            value >= self.min
        };
        let below_max = if self.max_excluded {
            value < self.max
        } else {
            value <= self.max
        };
        above_min && below_max
    }

    /// The smallest valid scaled value (one resolution step above an excluded bound).
    pub fn min_valid(&self) -> i64 {
        self.min.saturating_add(i64::from(self.min_excluded))
    }

    /// The largest valid scaled value (one resolution step below an excluded bound).
    pub fn max_valid(&self) -> i64 {
        self.max.saturating_sub(i64::from(self.max_excluded))
    }

    /// Appends the range as a person reads it: `0.000 < force <= 50000.000 N`.
    pub(crate) fn write_range(&self, out: &mut StringView) -> Result<(), FormatError> {
        put_fixed(out, self.min, self.decimals)?;
        put(out, if self.min_excluded { " < " } else { " <= " })?;
        put(out, self.name)?;
        put(out, if self.max_excluded { " < " } else { " <= " })?;
        put_fixed(out, self.max, self.decimals)?;
        self.write_unit(out)
    }

    /// Appends the resolution with its unit: `0.001 N`.
    pub(crate) fn write_resolution(&self, out: &mut StringView) -> Result<(), FormatError> {
        put_fixed(out, 1, self.decimals)?;
        self.write_unit(out)
    }

    fn write_unit(&self, out: &mut StringView) -> Result<(), FormatError> {
        if self.unit.is_empty() {
            Ok(())
        } else {
            put(out, " ")?;
            put(out, self.unit)
        }
    }
}

/// `target force`: friction force in N, `0 < F <= 50000`, resolution 0.001 N (value in mN).
pub const TARGET_FORCE: Quantity = Quantity {
    name: "force",
    unit: "N",
    decimals: 3,
    min: 0,
    min_excluded: true,
    max: 50_000_000,
    max_excluded: false,
};

/// `target coef`: friction coefficient, `0 < mu <= 2`, resolution 1e-6 (value in ppm).
pub const TARGET_COEF: Quantity = Quantity {
    name: "coef",
    unit: "",
    decimals: 6,
    min: 0,
    min_excluded: true,
    max: 2_000_000,
    max_excluded: false,
};

/// `target reduction`: reduction of the natural friction in %, `0 <= r < 100`, resolution
/// 0.001 % (value in milli-percent, so at most 99999).
pub const TARGET_REDUCTION: Quantity = Quantity {
    name: "reduction",
    unit: "%",
    decimals: 3,
    min: 0,
    min_excluded: false,
    max: 100_000,
    max_excluded: true,
};

/// `target net-force`: net tangential force of the horn on the block in N along +x, signed,
/// `-50000 <= F <= 50000`, resolution 0.001 N (value in mN; issue 27). Zero is a valid target:
/// no net force.
pub const TARGET_NET_FORCE: Quantity = Quantity {
    name: "net-force",
    unit: "N",
    decimals: 3,
    min: -50_000_000,
    min_excluded: false,
    max: 50_000_000,
    max_excluded: false,
};

/// `freq`: drive frequency in Hz, `20000 <= f <= 60000`, resolution 0.01 Hz (value in cHz).
pub const DRIVE_FREQ: Quantity = Quantity {
    name: "freq",
    unit: "Hz",
    decimals: 2,
    min: 2_000_000,
    min_excluded: false,
    max: 6_000_000,
    max_excluded: false,
};

/// `cal`: the known load on the axis in N, `0 < F <= 50000`, resolution 0.001 N (value in mN).
pub const CAL_LOAD: Quantity = Quantity {
    name: "load",
    unit: "N",
    decimals: 3,
    min: 0,
    min_excluded: true,
    max: 50_000_000,
    max_excluded: false,
};

/// `telemetry`: record rate in Hz, `1 <= rate <= 10000`, whole hertz. The upper bound is the
/// control-loop rate: one record per control step.
pub const TELEMETRY_RATE: Quantity = Quantity {
    name: "rate",
    unit: "Hz",
    decimals: 0,
    min: 1,
    min_excluded: false,
    max: 10_000,
    max_excluded: false,
};

/// Every quantity, for tests and for documentation tools.
pub const ALL_QUANTITIES: [&Quantity; 7] = [
    &TARGET_FORCE,
    &TARGET_COEF,
    &TARGET_REDUCTION,
    &TARGET_NET_FORCE,
    &DRIVE_FREQ,
    &CAL_LOAD,
    &TELEMETRY_RATE,
];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::code::ErrorCode;
    use crate::protocol::text::put_fixed;
    use crate::protocol::{Command, parse_command};
    use heapless::String;

    fn code(line: &str) -> ErrorCode {
        match parse_command(line) {
            Ok(command) => panic!("{line:?} parsed as {command:?}"),
            Err(error) => error.code(),
        }
    }

    fn text(value: i64, decimals: u8) -> String<32> {
        let mut out = String::new();
        put_fixed(&mut out, value, decimals).unwrap();
        out
    }

    fn range(quantity: &Quantity) -> String<64> {
        let mut out = String::new();
        quantity.write_range(&mut out).unwrap();
        out
    }

    #[test]
    fn ranges_read_like_the_documentation() {
        assert_eq!(range(&TARGET_FORCE), "0.000 < force <= 50000.000 N");
        assert_eq!(range(&TARGET_COEF), "0.000000 < coef <= 2.000000");
        assert_eq!(range(&TARGET_REDUCTION), "0.000 <= reduction < 100.000 %");
        assert_eq!(
            range(&TARGET_NET_FORCE),
            "-50000.000 <= net-force <= 50000.000 N"
        );
        assert_eq!(range(&DRIVE_FREQ), "20000.00 <= freq <= 60000.00 Hz");
        assert_eq!(range(&CAL_LOAD), "0.000 < load <= 50000.000 N");
        assert_eq!(range(&TELEMETRY_RATE), "1 <= rate <= 10000 Hz");
        let mut out: String<16> = String::new();
        TARGET_COEF.write_resolution(&mut out).unwrap();
        assert_eq!(out, "0.000001");
    }

    #[test]
    fn valid_bounds_are_one_step_inside_excluded_bounds() {
        assert_eq!(TARGET_FORCE.min_valid(), 1);
        assert_eq!(TARGET_REDUCTION.max_valid(), 99_999);
        for quantity in ALL_QUANTITIES {
            assert!(quantity.contains(quantity.min_valid()));
            assert!(quantity.contains(quantity.max_valid()));
            assert!(!quantity.contains(quantity.min_valid() - 1));
            assert!(!quantity.contains(quantity.max_valid() + 1));
            // Every valid value fits the fields of the commands: u32, or i32 for the one
            // signed quantity (the net force).
            if quantity.min_valid() < 0 {
                assert!(i32::try_from(quantity.min_valid()).is_ok());
                assert!(i32::try_from(quantity.max_valid()).is_ok());
            } else {
                assert!(u32::try_from(quantity.max_valid()).is_ok());
            }
        }
    }

    /// Each quantity at both ends of its range, and one resolution step outside.
    #[test]
    fn range_boundaries() {
        let commands: [(&str, &Quantity); 7] = [
            ("target force", &TARGET_FORCE),
            ("target coef", &TARGET_COEF),
            ("target reduction", &TARGET_REDUCTION),
            ("target net-force", &TARGET_NET_FORCE),
            ("freq", &DRIVE_FREQ),
            ("cal normal", &CAL_LOAD),
            ("telemetry", &TELEMETRY_RATE),
        ];
        assert_eq!(commands.len(), ALL_QUANTITIES.len());
        for (prefix, quantity) in commands {
            for value in [quantity.min_valid(), quantity.max_valid()] {
                let line = std::format!("{prefix} {}", text(value, quantity.decimals));
                let command = parse_command(&line).unwrap_or_else(|e| panic!("{line}: {e:?}"));
                let scaled = match command {
                    Command::Target(target) => target.scaled_value(),
                    Command::Freq { freq_chz } => i64::from(freq_chz),
                    Command::Cal { load_mn, .. } => i64::from(load_mn),
                    Command::Telemetry { rate_hz } => i64::from(rate_hz),
                    other => panic!("{line}: {other:?}"),
                };
                assert_eq!(scaled, value, "{line}");
            }
            for value in [quantity.min_valid() - 1, quantity.max_valid() + 1] {
                let line = std::format!("{prefix} {}", text(value, quantity.decimals));
                assert_eq!(code(&line), ErrorCode::OutOfRange, "{line}");
            }
        }
        // The written bounds of the brief, literally.
        assert!(parse_command("target force 50000").is_ok());
        assert!(parse_command("target coef 2").is_ok());
        assert!(parse_command("target reduction 0").is_ok());
        assert!(parse_command("target reduction 99.999").is_ok());
        assert_eq!(code("target reduction 100"), ErrorCode::OutOfRange);
        assert!(parse_command("target net-force -50000").is_ok());
        assert!(parse_command("target net-force 0").is_ok());
        assert_eq!(code("target net-force -50000.001"), ErrorCode::OutOfRange);
        assert_eq!(code("target net-force -99999999999"), ErrorCode::OutOfRange);
        assert!(parse_command("freq 20000").is_ok());
        assert!(parse_command("freq 60000").is_ok());
        assert_eq!(code("freq 19999.99"), ErrorCode::OutOfRange);
        assert!(parse_command("telemetry 1").is_ok());
        assert!(parse_command("telemetry 10000").is_ok());
        assert_eq!(code("telemetry 0"), ErrorCode::OutOfRange);
        assert_eq!(code("telemetry 10001"), ErrorCode::OutOfRange);
        assert_eq!(code("telemetry 999999999999"), ErrorCode::OutOfRange);
    }
}
