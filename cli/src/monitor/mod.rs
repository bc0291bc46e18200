//! A live connection to the firmware's command interface (the line protocol of
//! [`sonolube::protocol`]), for `sonolube monitor` and its tests.
//!
//! - [`Endpoint`] and [`connect`]: where the UART is (QEMU's Unix socket, TCP, a serial port).
//! - [`Link`]: a receiving thread that files every incoming line (replies in order, telemetry
//!   records, malformed lines counted), and the sending side: [`Link::command`],
//!   [`Link::pipeline`] for many lines in flight, [`Link::wait_ms`] for firmware-time pauses.
//! - [`Step`], [`parse_script`], [`run_steps`]: `-c` commands and `--script` files.
//! - [`telemetry_csv`] and [`telemetry_svg`]: what was recorded.
//! - [`run_acceptance`]: the acceptance test of the command interface (its checks and
//!   tolerances are listed in [`acceptance`]).
//!
//! Every line from the firmware is decoded with `sonolube::protocol` (`parse_reply`,
//! `parse_telemetry`); nothing here parses the protocol a second way.

pub mod acceptance;
mod checks;
mod commission;
mod csv;
mod endpoint;
mod figure;
pub mod flood;
mod inbox;
mod link;
mod reports;
mod script;
mod telemetry_log;
mod verdicts;

pub use acceptance::{AcceptanceConfig, AcceptanceReport, Check, run_acceptance};
pub use commission::{CommissionOutcome, MAX_POLLS, POLL_MS, run_commission};
pub use csv::{CSV_HEADER, telemetry_csv};
pub use endpoint::{Connection, DEFAULT_BAUD, Endpoint, connect};
pub use figure::telemetry_svg;
pub use flood::{FloodKind, FloodLine, expected_error};
pub use inbox::{Anomalies, MAX_INCOMING_LINE, ReplyLine};
pub use link::{Link, LinkError, LinkOptions, Session, WaitClock};
pub use reports::{
    STATUS_KEYS, Status, Version, decode_status, decode_version, fixed, target_text,
};
pub use script::{MAX_WAIT_MS, Step, StepsOutcome, parse_script, parse_step, run_steps};
pub use telemetry_log::{DEFAULT_RECORD_CAPACITY, SeqGaps, TelemetryLog};
pub use verdicts::{Convergence, FloodTally, convergence, drive_is_off};
