//! The commands and their canonical text.
//!
//! A [`Command`] is what the parser ([`parse_command`](super::parse_command)) produces and what
//! the firmware executes; [`format_command`] writes the one canonical line for it, which the
//! host tool sends.

use heapless::string::StringView;

use super::name::SceneName;
use super::quantity::{CAL_LOAD, DRIVE_FREQ};
use super::target::Target;
use super::text::{FormatError, put, put_fixed, put_uint, write_line};

/// A force-sensing axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Axis {
    /// The normal (contact) force sensor.
    Normal,
    /// The tangential (friction) force sensor.
    Tangential,
}

impl Axis {
    /// The axis as written in commands: `normal` or `tangential`.
    pub const fn name(self) -> &'static str {
        match self {
            Axis::Normal => "normal",
            Axis::Tangential => "tangential",
        }
    }
}

/// Which sensors a `tare` zeroes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TareAxes {
    /// Only one axis.
    One(Axis),
    /// Both axes.
    All,
}

/// A parsed command. Values are scaled integers with the unit in the field name; the parser only
/// produces values inside the documented ranges.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Command {
    /// `version`: firmware and protocol version.
    Version,
    /// `status`: state, target, measurements, drive, counters, latched fault.
    Status,
    /// `faults`: latched and active faults.
    Faults,
    /// `target force|coef|reduction <value>`: set the friction target.
    Target(Target),
    /// `scene list`: names of the available scenes.
    SceneList,
    /// `scene <name>`: select a scene.
    Scene(SceneName),
    /// `start`: drive on, close the friction loop.
    Start,
    /// `stop`: open the loop, drive off.
    Stop,
    /// `freq <hertz>`: fixed drive frequency.
    Freq {
        /// Drive frequency in cHz, `2_000_000..=6_000_000` (20 kHz to 60 kHz).
        freq_chz: u32,
    },
    /// `freq auto`: search the resonance and drive there.
    FreqAuto,
    /// `tare normal|tangential|all`: zero the force sensors under no load.
    Tare(TareAxes),
    /// `cal normal|tangential <newtons>`: set the sensor gain from a known load.
    Cal {
        /// The calibrated axis.
        axis: Axis,
        /// The known load in mN, `1..=50_000_000` (0.001 N to 50 kN).
        load_mn: u32,
    },
    /// `clear`: clear the latched fault.
    Clear,
    /// `telemetry <hertz>`: send telemetry records at this rate.
    Telemetry {
        /// Records per second, `1..=10_000` (at most one per control step).
        rate_hz: u16,
    },
    /// `telemetry off`: stop telemetry.
    TelemetryOff,
    /// `save`: store the loop's settings (calibrations, scene, target, drive frequency) in
    /// flash, where the next boot finds them.
    Save,
    /// `load`: apply the stored settings (checked: version, CRC, ranges).
    Load,
    /// `defaults`: apply the defaults (the scene's datasheet calibration and drive frequency,
    /// no target); the flash is unchanged until `save`.
    Defaults,
    /// `log`: the boot and fault log.
    Log,
    /// `help`: the list of commands.
    Help,
    /// `commission`: measure the resonance, the envelope time constant (ring-down), mu0
    /// (sliding, drive off) and report the cells' zeros; the loop then runs on them.
    Commission,
    /// `commission status`: the last commissioning's step, result or refusal.
    CommissionStatus,
}

/// The keywords, in the order `help` lists them.
pub const KEYWORDS: [&str; 18] = [
    "version",
    "status",
    "faults",
    "target",
    "scene",
    "start",
    "stop",
    "freq",
    "tare",
    "cal",
    "clear",
    "telemetry",
    "save",
    "load",
    "defaults",
    "log",
    "help",
    "commission",
];

impl Command {
    /// The command's keyword (its first word).
    pub const fn keyword(&self) -> &'static str {
        match self {
            Command::Version => "version",
            Command::Status => "status",
            Command::Faults => "faults",
            Command::Target(_) => "target",
            Command::SceneList | Command::Scene(_) => "scene",
            Command::Start => "start",
            Command::Stop => "stop",
            Command::Freq { .. } | Command::FreqAuto => "freq",
            Command::Tare(_) => "tare",
            Command::Cal { .. } => "cal",
            Command::Clear => "clear",
            Command::Telemetry { .. } | Command::TelemetryOff => "telemetry",
            Command::Save => "save",
            Command::Load => "load",
            Command::Defaults => "defaults",
            Command::Log => "log",
            Command::Help => "help",
            Command::Commission | Command::CommissionStatus => "commission",
        }
    }
}

/// Writes the canonical text of `command` followed by `\n`, replacing the buffer's contents:
/// single spaces, numbers with all the decimals of their resolution (`freq 40000.00`).
///
/// [`parse_command`](super::parse_command) reads it back to the same command for every command
/// it can produce. The longest canonical line is 31 bytes (`scene` and a 24-byte name, with the
/// newline), so a buffer of [`MAX_LINE_LEN`](super::MAX_LINE_LEN) always suffices; on failure it
/// is left empty.
pub fn format_command(command: &Command, out: &mut StringView) -> Result<(), FormatError> {
    write_line(out, |out| {
        put(out, command.keyword())?;
        match command {
            Command::Target(target) => {
                put(out, " ")?;
                put(out, target.kind())?;
                put(out, " ")?;
                super::target::write_value(target, out)?;
            }
            Command::SceneList => put(out, " list")?,
            Command::Scene(name) => {
                put(out, " ")?;
                put(out, name.as_str())?;
            }
            Command::Freq { freq_chz } => {
                put(out, " ")?;
                put_fixed(out, i64::from(*freq_chz), DRIVE_FREQ.decimals)?;
            }
            Command::FreqAuto => put(out, " auto")?,
            Command::Tare(TareAxes::All) => put(out, " all")?,
            Command::Tare(TareAxes::One(axis)) => {
                put(out, " ")?;
                put(out, axis.name())?;
            }
            Command::Cal { axis, load_mn } => {
                put(out, " ")?;
                put(out, axis.name())?;
                put(out, " ")?;
                put_fixed(out, i64::from(*load_mn), CAL_LOAD.decimals)?;
            }
            Command::Telemetry { rate_hz } => {
                put(out, " ")?;
                put_uint(out, u64::from(*rate_hz))?;
            }
            Command::TelemetryOff => put(out, " off")?,
            Command::Version
            | Command::Status
            | Command::Faults
            | Command::Start
            | Command::Stop
            | Command::Clear
            | Command::Save
            | Command::Load
            | Command::Defaults
            | Command::Log
            | Command::Help
            | Command::Commission => {}
            Command::CommissionStatus => put(out, " status")?,
        }
        put(out, "\n")
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::protocol::line::MAX_LINE_LEN;
    use crate::protocol::parse::parse_command;
    use crate::protocol::quantity::{
        Quantity, TARGET_COEF, TARGET_FORCE, TARGET_REDUCTION, TELEMETRY_RATE,
    };
    use heapless::String;
    use proptest::prelude::*;

    /// A valid scaled value of `quantity`, as `u32`.
    fn value_of(quantity: &'static Quantity) -> impl Strategy<Value = u32> {
        // Bounds are checked to fit u32 in the quantity tests.
        let min = u32::try_from(quantity.min_valid()).unwrap_or(0);
        let max = u32::try_from(quantity.max_valid()).unwrap_or(0);
        prop_oneof![Just(min), Just(max), min..=max]
    }

    fn axis() -> impl Strategy<Value = Axis> {
        prop_oneof![Just(Axis::Normal), Just(Axis::Tangential)]
    }

    /// Every command the parser can produce.
    pub(crate) fn any_command() -> impl Strategy<Value = Command> {
        prop_oneof![
            Just(Command::Version),
            Just(Command::Status),
            Just(Command::Faults),
            value_of(&TARGET_FORCE)
                .prop_map(|force_mn| Command::Target(Target::Force { force_mn })),
            value_of(&TARGET_COEF).prop_map(|coef_ppm| Command::Target(Target::Coef { coef_ppm })),
            value_of(&TARGET_REDUCTION)
                .prop_map(|reduction_mpct| Command::Target(Target::Reduction { reduction_mpct })),
            Just(Command::SceneList),
            "[a-z0-9_-]{1,24}"
                .prop_filter_map("reserved", |name| SceneName::new(&name).map(Command::Scene)),
            Just(Command::Start),
            Just(Command::Stop),
            value_of(&DRIVE_FREQ).prop_map(|freq_chz| Command::Freq { freq_chz }),
            Just(Command::FreqAuto),
            prop_oneof![axis().prop_map(TareAxes::One), Just(TareAxes::All)]
                .prop_map(Command::Tare),
            (axis(), value_of(&CAL_LOAD))
                .prop_map(|(axis, load_mn)| Command::Cal { axis, load_mn }),
            Just(Command::Clear),
            value_of(&TELEMETRY_RATE).prop_map(|rate| Command::Telemetry {
                rate_hz: u16::try_from(rate).unwrap_or(1)
            }),
            Just(Command::TelemetryOff),
            Just(Command::Save),
            Just(Command::Load),
            Just(Command::Defaults),
            Just(Command::Log),
            Just(Command::Help),
            Just(Command::Commission),
            Just(Command::CommissionStatus),
        ]
    }

    fn canonical(command: &Command) -> String<MAX_LINE_LEN> {
        let mut out = String::new();
        format_command(command, &mut out).unwrap();
        out
    }

    #[test]
    fn canonical_text_examples() {
        let cases = [
            (
                Command::Target(Target::Force { force_mn: 12_500 }),
                "target force 12.500\n",
            ),
            (
                Command::Target(Target::Coef { coef_ppm: 1 }),
                "target coef 0.000001\n",
            ),
            (
                Command::Target(Target::Reduction { reduction_mpct: 0 }),
                "target reduction 0.000\n",
            ),
            (
                Command::Freq {
                    freq_chz: 4_000_000,
                },
                "freq 40000.00\n",
            ),
            (Command::FreqAuto, "freq auto\n"),
            (Command::Tare(TareAxes::All), "tare all\n"),
            (Command::Tare(TareAxes::One(Axis::Normal)), "tare normal\n"),
            (
                Command::Cal {
                    axis: Axis::Tangential,
                    load_mn: 50_000_000,
                },
                "cal tangential 50000.000\n",
            ),
            (Command::Telemetry { rate_hz: 10_000 }, "telemetry 10000\n"),
            (Command::TelemetryOff, "telemetry off\n"),
            (Command::SceneList, "scene list\n"),
            (Command::Help, "help\n"),
            (Command::Commission, "commission\n"),
            (Command::CommissionStatus, "commission status\n"),
            (Command::Save, "save\n"),
            (Command::Load, "load\n"),
            (Command::Defaults, "defaults\n"),
            (Command::Log, "log\n"),
        ];
        for (command, text) in cases {
            assert_eq!(canonical(&command), text);
            assert_eq!(parse_command(&canonical(&command)), Ok(command));
        }
    }

    #[test]
    fn a_too_small_buffer_is_left_empty() {
        let mut out: String<8> = String::new();
        let command = Command::Target(Target::Force { force_mn: 1 });
        assert_eq!(
            format_command(&command, &mut out),
            Err(FormatError::Overflow)
        );
        assert!(out.is_empty());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2_000))]

        /// Property (b): the canonical text of any valid command parses back to it.
        #[test]
        fn canonical_text_round_trips(command in any_command()) {
            let text = canonical(&command);
            prop_assert!(text.len() <= 31, "{text:?}");
            prop_assert_eq!(parse_command(&text), Ok(command));
        }
    }
}
