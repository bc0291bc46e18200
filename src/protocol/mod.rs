//! The command and telemetry line protocol spoken over the UART.
//!
//! Everything is text, one line per message, `\n`-terminated, printable ASCII only, so a person
//! can use a serial terminal and a program can parse every line. The host sends commands; the
//! firmware answers every non-empty command line with exactly one reply line, in order, and
//! sends telemetry lines in between when telemetry is on. The first word tells them apart:
//! `ok` and `err` are replies, `tel` is telemetry.
//!
//! Numbers are exact decimal fixed-point: no floats are parsed or printed anywhere (see
//! [`parse_decimal`]). Values are carried as scaled integers with the unit in the field name
//! (`force_mn`, `coef_ppm`, `freq_chz`).
//!
//! # Flow in the firmware
//!
//! 1. Feed received bytes into a [`LineAssembler`]; it yields each complete line, or the error
//!    of a line that was too long or held a non-ASCII or control byte (once, at its newline).
//! 2. [`parse_command`] turns a line into a [`Command`] or a [`ProtocolError`].
//! 3. Execute the command; reply with [`format_ack`], [`format_status`], [`format_faults`],
//!    [`format_version`], [`format_scene_list`] or [`OkReply`], or with [`format_error`] (a
//!    parse error, or an execution error such as [`ProtocolError::WrongState`]).
//! 4. At the telemetry rate, [`format_telemetry`] a [`TelemetryRecord`].
//!
//! The host tool does the reverse: [`format_command`] to send, [`parse_incoming`] (or
//! [`parse_reply`] and [`parse_telemetry`]) to read.
//!
//! # Lines
//!
//! A line is at most [`MAX_LINE_LEN`] (96) bytes before its terminator. `\n`, `\r` and the
//! pair `\r\n` each end a line (a terminal sends a lone `\r` on Enter; `\r\n` is one line end,
//! not a line and an empty one), tabs count as spaces, and any other byte outside
//! `0x20..=0x7e` makes the line a `bad-encoding` error. Empty and blank lines get no reply.
//! Words are separated by one or more spaces or tabs; keywords are lowercase and
//! case-sensitive.
//!
//! # Commands
//!
//! | command | argument range and resolution | effect | `ok` reply (example) |
//! |---|---|---|---|
//! | `version` | | firmware and protocol version | `ok firmware=0.1.0 board=qemu protocol=3` |
//! | `status` | | state, target and measurements | `ok state=running scene=demo target=force:12.500 mu=0.312000 normal_n=40.000 tangential_n=12.480 amp=0.523000 freq_hz=40000.00 overruns=0 lost=0 fault=none lock=none phase_deg=undefined reach=ok reachable=none resonance=near values=declared` (`values=commissioned` when the loop runs on commissioned values, protocol 3) |
//! | `faults` | | latched and active faults | `ok latched=overcurrent active=none` |
//! | `target force <N>` | `0 < N <= 50000` newtons, 0.001 N | hold this friction force | `ok target=force:12.500` |
//! | `target coef <mu>` | `0 < mu <= 2`, 0.000001 | hold this friction coefficient | `ok target=coef:0.350000` |
//! | `target reduction <r>` | `0 <= r < 100` percent, 0.001 % | hold this reduction of the natural friction | `ok target=reduction:40.000`; beyond what the model reaches now at full drive: `ok target=reduction:99.999 warning=beyond-reach reachable=reduction:79.400` |
//! | `scene list` | | names of every compiled scene (the reply is sized for them all) | `ok count=2 scenes=demo,ramp` |
//! | `scene <name>` | `[a-z0-9_-]`, 1 to 24 bytes, not `list` or `none` | select a scene; one that cannot work (a target beyond the drive's reach, no sliding, cell noise above the band: [`crate::scene::feasibility`]) is refused as `unavailable` | `ok scene=demo` |
//! | `start` | | drive on, close the friction loop | `ok` |
//! | `stop` | | open the loop, drive off | `ok` |
//! | `freq <Hz>` | `20000 <= f <= 60000` hertz, 0.01 Hz | fixed drive frequency; the actuator ceiling is recomputed for it (current rating) | `ok freq_hz=40000.00` |
//! | `freq auto` | | search the resonance and drive there | `ok freq_hz=auto` |
//! | `tare normal\|tangential\|all` | | zero force sensors (no load) | `ok tare=all` |
//! | `cal normal\|tangential <N>` | `0 < N <= 50000` newtons, 0.001 N | set a sensor's gain from a known load | `ok cal=normal load_n=10.000` |
//! | `clear` | | clear the latched fault | `ok` |
//! | `telemetry <Hz>` | `1 <= rate <= 10000` hertz, 1 Hz | send telemetry at this rate | `ok telemetry_hz=100` |
//! | `telemetry off` | | stop telemetry | `ok telemetry_hz=off` |
//! | `save` | | drive off: store the calibrations, scene, target and drive frequency in flash (see [`crate::settings`]) | `ok settings=saved scene=reference cal_count=2 normal_offset_q31=-1234 normal_span_q16=6553600 tangential_offset_q31=0 tangential_span_q16=3276800 target=coef:0.150000 freq_hz=40000.00` |
//! | `load` | | drive off: apply the stored settings, checked (version, CRC, ranges) | `ok settings=loaded ...` (the same fields) |
//! | `defaults` | | drive off: the scene's datasheet calibration and drive frequency, no target; flash unchanged until `save` | `ok settings=defaults scene=reference cal_count=0 normal_offset_q31=none ...` |
//! | `log` | | boots, watchdog resets, where this boot's settings came from, the last 8 faults and resets | `ok boots=3 watchdog_resets=1 boot_settings=defaults boot_reason=crc-mismatch events=watchdog-reset,overcurrent` |
//! | `help` | | list the commands | `ok commands=version,status,faults,target,scene,start,stop,freq,tare,cal,clear,telemetry,save,load,defaults,log,help,commission` |
//! | `commission status` | | the last commissioning: `none`, `running` and its step, `done` and the values with their standard errors, or `refused`, its step and reason | `ok commission=done f0_hz=39999.66 f0_se_hz=0.52 q=99.59 q_se=0.62 tau_us=792.6 tau_se_us=5.0 mu0=0.240673 mu0_se=0.000119 points=25 normal_zero_n=0.017 tangential_zero_n=-0.003` |
//! | `commission` | | drive off, contact loaded and sliding: search the resonance, ring the stack down, measure mu0 with the drive off (see [`crate::commission`]); the loop then runs on the measured f0 and time constant; `status` reports the step, the result or the refusal | `ok commission=started` |
//!
//! Numbers are `[+-]digits[.digits]`: at least one digit before a `.` and one after it, no
//! exponent, no unit, at most 12 digits in all. A value is never rounded: a non-zero digit
//! finer than the resolution is `too-many-decimals`, but zeros past it are accepted (`12.5000`
//! is 12.500 N). A sign is accepted on every number, so `-5` is `out-of-range` rather than
//! `bad-number`. For `freq` and `telemetry` an argument that starts with a digit, sign or `.`
//! is read as a number, anything else must be the word (`auto`, `off`).
//!
//! # Replies
//!
//! `ok` is followed by zero or more `key=value` pairs separated by single spaces. Keys are
//! lowercase, with the unit as a suffix where there is one (`normal_n` in newtons, `freq_hz`
//! in hertz); values contain no space, `=`, `,`, `:` or `"`, except that lists are
//! comma-separated (`none` when empty) and targets are `kind:value` (`none` when unset).
//! Status fields: `state` (see [`SupervisorState`]), `scene`, `target`, `mu` (friction
//! coefficient estimate), `normal_n` and `tangential_n` (forces, N, 3 decimals), `amp` (drive
//! amplitude as a fraction of full scale, 6 decimals), `freq_hz` (2 decimals), `overruns`,
//! `lost` (telemetry records lost), `fault` (latched fault or `none`), `lock` and `phase_deg`
//! (as in telemetry), and the reach fields of telemetry: `reach`, `reachable`, `resonance`.
//!
//! A `target` whose value is beyond what the controller's model reaches at the drive's ceiling
//! at the present load and speed is still accepted (the load or speed may change), with
//! `warning=beyond-reach reachable=<kind:value>` after the target: the nearest value the full
//! drive gives now, in the target's kind.
//!
//! An error is `err <code> <name> <message>`: a stable number, its kebab-case name, and a
//! message for a person that quotes the offending word and states the rule, for example
//! `err 6 out-of-range "60001" is out of range 20000.00 <= freq <= 60000.00 Hz`.
//!
//! | code | name | meaning |
//! |---|---|---|
//! | 1 | `unknown-command` | the first word is not a command |
//! | 2 | `bad-number` | not of the form `[+-]digits[.digits]` (`abc`, `.5`, `1.2.3`) |
//! | 3 | `trailing-garbage` | a number followed by other characters (`12N`, `1e3`) |
//! | 4 | `too-many-digits` | more than 12 digits |
//! | 5 | `too-many-decimals` | a non-zero digit finer than the resolution |
//! | 6 | `out-of-range` | outside the range of the table above |
//! | 7 | `missing-argument` | the command needs more arguments |
//! | 8 | `extra-argument` | more arguments than the command takes |
//! | 9 | `bad-choice` | an argument that is not one of the allowed words |
//! | 10 | `bad-name` | not a valid scene name |
//! | 11 | `line-too-long` | more than 96 bytes before the newline; the line is discarded |
//! | 12 | `bad-encoding` | a byte that is not printable ASCII or tab; the line is discarded |
//! | 13 | `empty-line` | no command on the line (only from a direct parser call) |
//! | 20 | `unknown-scene` | no scene has this name |
//! | 21 | `wrong-state` | the command is not allowed in the current state |
//! | 22 | `fault-latched` | a fault is latched; send `clear` first |
//! | 23 | `no-target` | `start` without a target |
//! | 24 | `cal-failed` | the calibration could not be completed |
//! | 25 | `storage-failed` | the settings flash could not be read or written (`save`, `load`) |
//! | 26 | `settings-invalid` | `load`: nothing stored, or the stored settings fail a check (the reason word says which) |
//! | 27 | `unavailable` | the command exists but this loop cannot do it (`freq auto` on a board, or a simulated scene, that does not sample the drive current); the message says why |
//!
//! In the `save`, `load` and `defaults` replies a field at `none` is the scene's own (its
//! datasheet calibration, its drive frequency, no target); offsets and spans are the exact
//! fixed-point values: `*_offset_q31` the zero reading as a Q1.31 fraction of the converter's
//! full scale, `*_span_q16` the newtons of one full scale in Q16.16. `cal_count` counts the
//! successful `tare` and `cal` commands since the defaults.
//!
//! Codes 1 to 13 come from this module; codes 20 to 27 are for the firmware to return when a
//! well-formed command cannot be executed. A code never changes meaning; new codes get new
//! numbers.
//!
//! # Telemetry
//!
//! One line per record, fields always present and always in this order:
//!
//! ```text
//! tel t_us=1250000 seq=12500 state=running target=force:12.500 mu=0.312000 normal_n=40.000 tangential_n=12.480 amp=0.523000 freq_hz=40000.00 overruns=0 lost=0 lock=locked phase_deg=-0.250 reach=ok reachable=none resonance=near
//! ```
//!
//! | key | field | unit and format | range on the wire |
//! |---|---|---|---|
//! | `t_us` | time of the sample since boot | µs, integer | `0..=18446744073709551615` |
//! | `seq` | record number, +1 per record produced (sent or lost), wrapping | integer | `0..=4294967295` |
//! | `state` | supervisor state | `boot`, `idle`, `tuning`, `calibrating`, `running`, `fault` | |
//! | `target` | friction target | `force:<N, 3 decimals>`, `coef:<6 decimals>`, `reduction:<%, 3 decimals>` or `none` | value `0..=u32::MAX` scaled units |
//! | `mu` | friction coefficient estimate | 6 decimals (ppm) | `0.000000..=4294.967295` |
//! | `normal_n` | normal force | N, 3 decimals (mN), signed | `-2147483.648..=2147483.647` |
//! | `tangential_n` | tangential (friction) force | N, 3 decimals (mN), signed | `-2147483.648..=2147483.647` |
//! | `amp` | drive amplitude, fraction of full scale (1.000000 = full) | 6 decimals (ppm) | `0.000000..=4294.967295` |
//! | `freq_hz` | drive frequency | Hz, 2 decimals (cHz) | `0.00..=42949672.95` |
//! | `overruns` | control-loop overruns since boot | integer | `0..=4294967295` |
//! | `lost` | telemetry records lost since boot (UART busy) | integer | `0..=4294967295` |
//! | `lock` | the resonance loop's state ([`Lock`]) | `pinned`, `searching`, `tracking`, `locked`, `lost`, or `none` (no loop) | |
//! | `phase_deg` | the motional current's phase to the drive voltage (the tracker's error; 0 on resonance) | degrees, 3 decimals (mdeg), signed, or `undefined` (nothing measured) | `-2147483.648..=2147483.647` |
//!
//! | `reach` | whether the target is held ([`ReachState`]) | `ok`, or `target-unreachable`: the drive at its limit for as long as it takes to act (3 x the envelope, cell and force-filter time constants) with the error not falling | |
//! | `reachable` | with `target-unreachable`, the nearest value the model gives at the drive's limit now | a target as `target`, or `none` | |
//! | `resonance` | the drive frequency against the resonance ([`ResonanceDistance`]) | `near` (motional conductance at least half the resonance's, `|2Q (f - f0) / f0| <= 1`), `far`, or `unknown` | |
//!
//! The longest record is 337 bytes with its newline ([`TELEMETRY_CAPACITY`] is 352).
//! Protocol 2 added `reach`, `reachable` and `resonance` (issue 26). A gap in
//! `seq` with a matching increase of `lost` means records were dropped, not corrupted.

mod code;
mod command;
mod commission;
mod decode;
mod error;
mod line;
mod lock;
mod name;
mod number;
mod parse;
mod quantity;
mod reach;
mod reading;
mod reply;
mod report;
mod state;
mod target;
mod telemetry;
mod text;

#[cfg(test)]
mod parse_tests;
#[cfg(test)]
mod props;

pub use code::ErrorCode;
pub use command::{Axis, Command, KEYWORDS, TareAxes, format_command};
pub use commission::format_commission;
pub use decode::{DecodeError, ErrorReply, Incoming, Payload, Reply, parse_incoming, parse_reply};
pub use error::{MAX_QUOTED_TOKEN_LEN, MAX_REASON_LEN, ProtocolError, TokenText};
pub use line::{LineAssembler, MAX_LINE_LEN};
pub use lock::Lock;
pub use name::{MAX_SCENE_NAME_LEN, RESERVED_SCENE_NAMES, SceneName, is_scene_name};
pub use number::{
    MAX_COMMAND_DIGITS, MAX_DECODE_DIGITS, NumberError, decode_i32, decode_u32, decode_u64,
    parse_decimal,
};
pub use parse::parse_command;
pub use quantity::{
    ALL_QUANTITIES, CAL_LOAD, DRIVE_FREQ, Quantity, TARGET_COEF, TARGET_FORCE, TARGET_NET_FORCE,
    TARGET_REDUCTION, TELEMETRY_RATE,
};
pub use reach::{BEYOND_REACH, ReachState, ResonanceDistance, RunReach, format_target_ack};
pub use reading::LoopReading;
pub use reply::{NONE, OkReply, REPLY_CAPACITY, format_ack, format_error};
pub use report::{
    FaultReport, StatusReport, VersionReport, format_faults, format_help, format_scene_list,
    format_status, format_version,
};
pub use state::SupervisorState;
pub(crate) use target::write_value as write_target_value;
pub use target::{NO_TARGET, Target, TargetDecodeError, TargetRange, decode_target};
pub use telemetry::{
    TELEMETRY_CAPACITY, TELEMETRY_TAG, TelemetryRecord, format_telemetry, parse_telemetry,
};
pub use text::{FormatError, MAX_DECIMALS, MAX_WORD_LEN, is_word};

/// Version of this protocol, reported by `version`. Bumped when a line that one side sends
/// could be read differently by the other (a new field, state or keyword); new error codes and
/// commands that old hosts never send do not bump it.
pub const PROTOCOL_VERSION: u16 = 3;
