//! `sonolube monitor` against a mock firmware on a Unix socket: the library (link, scripts,
//! acceptance test) and the command-line tool.
//!
//! The mock speaks the protocol with `sonolube::protocol` (line assembler, parser, formatters),
//! runs a first-order "friction" that moves toward the target (time constant 3 ms of its
//! firmware time, which is wall time since it started plus 1 s) and sends telemetry at the
//! requested rate. It can misbehave on purpose, so that each acceptance check is shown to fail
//! when it should.

use std::io::{ErrorKind, Read, Write};
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::PathBuf;
use std::process::Command as Process;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::thread::{self, JoinHandle};
use std::time::{Duration, Instant};

use heapless::String as Line;
use sonolube::protocol::LoopReading;
use sonolube::protocol::{
    Command, FaultReport, LineAssembler, PROTOCOL_VERSION, ProtocolError, REPLY_CAPACITY,
    StatusReport, SupervisorState, TELEMETRY_CAPACITY, Target, TelemetryRecord, VersionReport,
    format_ack, format_error, format_faults, format_scene_list, format_status, format_telemetry,
    format_version, parse_command,
};
use sonolube_cli::monitor::{
    AcceptanceConfig, AcceptanceReport, CSV_HEADER, Connection, Link, LinkOptions, Step, WaitClock,
    parse_script, run_acceptance, run_steps, telemetry_csv, telemetry_svg,
};

const SCENES: [&str; 2] = ["reference", "demo"];
const NATURAL_MU: f64 = 0.24;
const NORMAL_N: f64 = 40.0;
const TAU_S: f64 = 0.003;

/// Ways the mock breaks the protocol, each triggered at its n-th `err` reply.
#[derive(Debug, Clone, Copy, Default)]
struct Misbehaviour {
    /// Does not send this `err` reply.
    drop_error_reply: Option<u64>,
    /// Counts a control-loop overrun.
    overrun: Option<u64>,
    /// Skips a telemetry `seq` without counting it lost.
    skip_seq: Option<u64>,
    /// Sends a garbled telemetry line and a non-UTF-8 line.
    garbage: Option<u64>,
}

struct Firmware {
    out: UnixStream,
    epoch: Instant,
    faults: Misbehaviour,
    state: SupervisorState,
    scene: Option<&'static str>,
    target: Option<Target>,
    mu: f64,
    amplitude: f64,
    freq_chz: u32,
    telemetry_period_us: Option<u64>,
    next_record_us: u64,
    plant_us: u64,
    seq: u32,
    lost: u32,
    overruns: u32,
    errors_sent: u64,
}

impl Firmware {
    fn now_us(&self) -> u64 {
        1_000_000 + self.epoch.elapsed().as_micros() as u64
    }

    fn target_mu(&self) -> f64 {
        match self.target {
            Some(Target::Coef { coef_ppm }) => f64::from(coef_ppm) * 1e-6,
            Some(Target::Force { force_mn }) => f64::from(force_mn) * 1e-3 / NORMAL_N,
            // This stand-in plant has friction only: a net force acts as its magnitude.
            Some(Target::NetForce { force_mn }) => {
                f64::from(force_mn.unsigned_abs()) * 1e-3 / NORMAL_N
            }
            Some(Target::Reduction { reduction_mpct }) => {
                NATURAL_MU * (1.0 - f64::from(reduction_mpct) * 1e-5)
            }
            None => NATURAL_MU,
        }
    }

    /// Moves the plant to `to_us`: first-order friction, linear ramp-down of the drive.
    fn advance(&mut self, to_us: u64) {
        let dt = to_us.saturating_sub(self.plant_us) as f64 * 1e-6;
        self.plant_us = self.plant_us.max(to_us);
        let goal = if self.state == SupervisorState::Running {
            self.target_mu().clamp(0.10, NATURAL_MU)
        } else {
            NATURAL_MU
        };
        self.mu = goal + (self.mu - goal) * (-dt / TAU_S).exp();
        match self.state {
            SupervisorState::Running => {
                self.amplitude = ((NATURAL_MU - self.mu) / NATURAL_MU * 1.5).clamp(0.0, 1.0)
            }
            SupervisorState::RampDown => {
                self.amplitude = (self.amplitude - dt / 0.005).max(0.0);
                if self.amplitude == 0.0 {
                    self.state = SupervisorState::Idle;
                }
            }
            _ => self.amplitude = 0.0,
        }
    }

    fn record(&self) -> TelemetryRecord {
        TelemetryRecord {
            time_us: self.plant_us,
            seq: self.seq,
            reading: LoopReading {
                state: self.state,
                target: self.target,
                friction_coef_ppm: (self.mu * 1e6).round() as u32,
                normal_force_mn: (NORMAL_N * 1e3) as i32,
                tangential_force_mn: (self.mu * NORMAL_N * 1e3).round() as i32,
                drive_amplitude_ppm: (self.amplitude * 1e6).round() as u32,
                drive_freq_chz: self.freq_chz,
            },
            overruns: self.overruns,
            lost_records: self.lost,
            lock: None,
            phase_mdeg: None,
            reach: sonolube::protocol::RunReach::UNKNOWN,
        }
    }

    fn write(&mut self, bytes: &[u8]) -> bool {
        self.out.write_all(bytes).is_ok()
    }

    /// Sends the records due by now; a backlog beyond 100 records is dropped and counted lost,
    /// as the firmware does when its UART is busy.
    fn telemetry(&mut self) -> bool {
        let Some(period) = self.telemetry_period_us else {
            return true;
        };
        let now = self.now_us();
        let mut line = Line::<TELEMETRY_CAPACITY>::new();
        while self.next_record_us <= now {
            self.advance(self.next_record_us);
            self.seq = self.seq.wrapping_add(1);
            if (now - self.next_record_us) / period > 100 {
                self.lost += 1;
            } else if format_telemetry(&self.record(), &mut line).is_ok()
                && !self.write(line.as_bytes())
            {
                return false;
            }
            self.next_record_us += period;
        }
        self.advance(now);
        true
    }

    fn reply(&mut self, line: Result<&str, ProtocolError>) -> bool {
        let mut out = Line::<REPLY_CAPACITY>::new();
        let executed = line
            .and_then(parse_command)
            .and_then(|c| self.execute(&c, &mut out));
        let Err(error) = executed else {
            return self.write(out.as_bytes());
        };
        self.errors_sent += 1;
        let n = Some(self.errors_sent);
        if self.faults.overrun == n {
            self.overruns += 1;
        }
        if self.faults.skip_seq == n {
            self.seq = self.seq.wrapping_add(1);
        }
        if self.faults.garbage == n && !self.write(b"tel t_us=oops\n\xff\xfe\n") {
            return false;
        }
        if self.faults.drop_error_reply == n {
            return true;
        }
        format_error(&error, &mut out).is_ok() && self.write(out.as_bytes())
    }

    fn execute(
        &mut self,
        command: &Command,
        out: &mut Line<REPLY_CAPACITY>,
    ) -> Result<(), ProtocolError> {
        self.advance(self.now_us());
        let formatted = match command {
            Command::Version => format_version(
                &VersionReport {
                    firmware: "0.0.0-mock",
                    board: "mock",
                    protocol: PROTOCOL_VERSION,
                },
                out,
            ),
            Command::Status => format_status(
                &StatusReport {
                    reading: LoopReading {
                        state: self.state,
                        target: self.target,
                        friction_coef_ppm: self.record().reading.friction_coef_ppm,
                        normal_force_mn: self.record().reading.normal_force_mn,
                        tangential_force_mn: self.record().reading.tangential_force_mn,
                        drive_amplitude_ppm: self.record().reading.drive_amplitude_ppm,
                        drive_freq_chz: self.freq_chz,
                    },
                    scene: self.scene,
                    overruns: self.overruns,
                    lost_telemetry: self.lost,
                    latched_fault: None,
                    lock: Some("pinned"),
                    phase_mdeg: None,
                    reach: sonolube::protocol::RunReach::UNKNOWN,
                    commissioned: false,
                },
                out,
            ),
            Command::Faults => format_faults(
                &FaultReport {
                    latched: &[],
                    active: &[],
                },
                out,
            ),
            Command::SceneList => format_scene_list(&SCENES, out),
            Command::Scene(name) => {
                let found = SCENES.iter().find(|s| **s == name.as_str());
                let scene = found.ok_or(ProtocolError::UnknownScene { name: *name })?;
                self.scene = Some(scene);
                format_ack(command, out)
            }
            Command::Start => {
                if self.target.is_none() {
                    return Err(ProtocolError::NoTarget);
                }
                self.state = SupervisorState::Running;
                format_ack(command, out)
            }
            Command::Stop => {
                if self.state == SupervisorState::Running {
                    self.state = SupervisorState::RampDown;
                }
                format_ack(command, out)
            }
            Command::Target(target) => {
                self.target = Some(*target);
                format_ack(command, out)
            }
            Command::Freq { freq_chz } => {
                self.freq_chz = *freq_chz;
                format_ack(command, out)
            }
            Command::Telemetry { rate_hz } => {
                self.telemetry_period_us = Some(1_000_000 / u64::from(*rate_hz));
                self.next_record_us = self.now_us();
                format_ack(command, out)
            }
            Command::TelemetryOff => {
                self.telemetry_period_us = None;
                format_ack(command, out)
            }
            _ => format_ack(command, out),
        };
        // Every reply of the mock fits its buffer; a failure here is a bug of the mock.
        formatted.expect("the mock's reply fits");
        Ok(())
    }
}

/// Serves one connection until the host closes it.
fn serve(stream: UnixStream, faults: Misbehaviour) {
    stream
        .set_read_timeout(Some(Duration::from_millis(1)))
        .expect("read timeout");
    let out = stream.try_clone().expect("socket clone");
    let mut input = stream;
    let mut firmware = Firmware {
        out,
        epoch: Instant::now(),
        faults,
        state: SupervisorState::Idle,
        scene: None,
        target: None,
        mu: NATURAL_MU,
        amplitude: 0.0,
        freq_chz: 4_000_000,
        telemetry_period_us: None,
        next_record_us: 0,
        plant_us: 1_000_000,
        seq: 0,
        lost: 0,
        overruns: 0,
        errors_sent: 0,
    };
    let mut assembler = LineAssembler::new();
    let mut buffer = [0u8; 1024];
    loop {
        match input.read(&mut buffer) {
            Ok(0) => return,
            Ok(count) => {
                let mut lines = Vec::new();
                assembler.push_all(&buffer[..count], |line| {
                    lines.push(line.map(str::to_string))
                });
                for line in lines {
                    if !firmware.reply(line.as_deref().map_err(|e| *e)) {
                        return;
                    }
                }
            }
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
            Err(_) => return,
        }
        if !firmware.telemetry() {
            return;
        }
    }
}

/// A mock firmware listening on a fresh socket path, bound after `delay`.
fn mock(faults: Misbehaviour, delay: Duration) -> (PathBuf, JoinHandle<()>) {
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let path = std::env::temp_dir().join(format!(
        "sonolube-monitor-{}-{}.sock",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = std::fs::remove_file(&path);
    let bound = path.clone();
    let thread = thread::spawn(move || {
        thread::sleep(delay);
        let listener = UnixListener::bind(&bound).expect("bind the mock socket");
        let (stream, _) = listener.accept().expect("the monitor connects");
        let _ = std::fs::remove_file(&bound);
        serve(stream, faults);
    });
    (path, thread)
}

fn options() -> LinkOptions {
    LinkOptions {
        reply_timeout: Duration::from_millis(700),
        ..LinkOptions::default()
    }
}

/// Runs the acceptance test against a mock that misbehaves as told.
fn acceptance(faults: Misbehaviour) -> (AcceptanceReport, String) {
    let (path, server) = mock(faults, Duration::ZERO);
    let link_options = LinkOptions {
        connect_timeout: Duration::from_secs(5),
        ..options()
    };
    let endpoint = sonolube_cli::monitor::Endpoint::Unix(path);
    let mut link = Link::connect(&endpoint, link_options).expect("connect to the mock");
    let mut printed = Vec::new();
    let report = run_acceptance(&mut link, &AcceptanceConfig::default(), &mut printed);
    drop(link);
    server
        .join()
        .expect("the mock ends when the monitor leaves");
    (report, String::from_utf8(printed).expect("UTF-8 report"))
}

fn verdicts(report: &AcceptanceReport) -> Vec<(u8, bool)> {
    report.checks.iter().map(|c| (c.number, c.passed)).collect()
}

#[test]
fn acceptance_passes_against_a_correct_firmware() {
    let (report, printed) = acceptance(Misbehaviour::default());
    assert!(report.all_passed(), "{printed}");
    assert_eq!(report.checks.len(), 6);
    assert_eq!(report.summary(), "monitor acceptance: 6 passed, 0 failed");
    let flood = &report.check(3).unwrap().measured;
    assert!(flood.starts_with("10000 lines"), "{flood}");
    assert!(
        flood.contains("10000 err with the predicted code"),
        "{flood}"
    );
    assert!(
        printed.contains("PASS 2 convergence: target coef 0.150000"),
        "{printed}"
    );
}

#[test]
fn acceptance_fails_when_one_reply_is_missing() {
    let (report, printed) = acceptance(Misbehaviour {
        drop_error_reply: Some(5_000),
        ..Misbehaviour::default()
    });
    assert_eq!(
        verdicts(&report)[..3],
        [(1, true), (2, true), (3, false)],
        "{printed}"
    );
    let flood = &report.check(3).unwrap().measured;
    assert!(flood.contains("9999 replies"), "{flood}");
    assert!(flood.contains("timed out waiting for a reply"), "{flood}");
}

#[test]
fn acceptance_fails_when_the_loop_overruns_during_the_flood() {
    let (report, printed) = acceptance(Misbehaviour {
        overrun: Some(3_000),
        ..Misbehaviour::default()
    });
    assert_eq!(
        verdicts(&report),
        [
            (1, true),
            (2, true),
            (3, true),
            (4, false),
            (5, true),
            (6, true)
        ],
        "{printed}"
    );
    assert!(
        report
            .check(4)
            .unwrap()
            .measured
            .contains("overruns rose by 1")
    );
}

#[test]
fn acceptance_fails_on_a_seq_gap_without_lost_and_on_garbled_lines() {
    let (report, printed) = acceptance(Misbehaviour {
        skip_seq: Some(2_000),
        garbage: Some(4_000),
        ..Misbehaviour::default()
    });
    assert_eq!(
        verdicts(&report),
        [
            (1, true),
            (2, true),
            (3, true),
            (4, false),
            (5, true),
            (6, false)
        ],
        "{printed}"
    );
    assert!(
        report.check(4).unwrap().measured.contains("1 unexplained"),
        "{printed}"
    );
    assert!(
        report.check(6).unwrap().measured.contains("2 malformed"),
        "{printed}"
    );
}

#[test]
fn scripts_wait_on_firmware_time_and_record_telemetry() {
    let (path, server) = mock(Misbehaviour::default(), Duration::from_millis(300));
    // The socket appears 300 ms later: connecting retries until it does.
    let endpoint = sonolube_cli::monitor::Endpoint::Unix(path.clone());
    let mut link = Link::connect(&endpoint, options()).expect("connect after a retry");
    let steps = parse_script(
        "# telemetry is off: wall time\nwait 20\nscene reference\ntarget coef 0.2\n\
         telemetry 500\nstart\nwait 30\nstop\ntarget coef 9\nwait 10\n",
    )
    .unwrap();
    assert_eq!(steps[0], Step::Wait(20));
    let mut printed = Vec::new();
    let outcome = run_steps(&mut link, &steps, &mut printed).expect("the script runs");
    let printed = String::from_utf8(printed).unwrap();
    assert_eq!(
        (outcome.commands, outcome.errors, outcome.malformed),
        (6, 1, 0),
        "{printed}"
    );
    assert!(
        printed.contains("# waited 20 ms of wall time (telemetry off)"),
        "{printed}"
    );
    assert!(printed.contains("< ok target=coef:0.200000"), "{printed}");
    assert!(printed.contains("< err 6 out-of-range \"9\""), "{printed}");
    let waited = printed
        .lines()
        .find(|l| l.starts_with("# waited 30 ms of firmware time"))
        .unwrap_or_else(|| panic!("{printed}"));
    let t_us: Vec<u64> = waited
        .split(|c: char| !c.is_ascii_digit())
        .filter_map(|n| n.parse().ok())
        .collect();
    assert!(t_us[2] - t_us[1] >= 30_000, "{waited}");
    assert_eq!(
        link.wait_ms(1)
            .map(|c| matches!(c, WaitClock::Firmware { .. })),
        Ok(true)
    );
    let session = link.finish();
    server.join().unwrap();
    assert!(session.anomalies.is_clean());
    let records = session.telemetry.records();
    assert!(records.len() >= 20, "{} records", records.len());
    assert!(
        records
            .iter()
            .any(|r| r.reading.state == SupervisorState::Running)
    );
    let csv = telemetry_csv(records);
    assert_eq!(csv.lines().next(), Some(CSV_HEADER));
    assert_eq!(csv.lines().count(), records.len() + 1);
    assert!(telemetry_svg("script", records, None).contains("estimate (mu)"));
}

#[test]
fn a_reply_that_never_comes_is_a_timeout_not_a_hang() {
    let (path, server) = mock(
        Misbehaviour {
            drop_error_reply: Some(1),
            ..Misbehaviour::default()
        },
        Duration::ZERO,
    );
    // Attach through an already connected socket, as a caller with its own transport would.
    let stream = (0..100)
        .find_map(|_| {
            thread::sleep(Duration::from_millis(10));
            UnixStream::connect(&path).ok()
        })
        .expect("the mock listens");
    let mut link = Link::start(
        Connection::unix(stream, Duration::from_secs(5)).unwrap(),
        options(),
    );
    let started = Instant::now();
    let error = link.command("bogus").unwrap_err();
    assert!(
        error
            .to_string()
            .starts_with("timed out waiting for a reply"),
        "{error}"
    );
    assert!(started.elapsed() < Duration::from_secs(3));
    assert!(link.command("version").unwrap().is_ok());
    drop(link);
    server.join().unwrap();
}

fn sonolube(args: &[&str]) -> (i32, String, String) {
    let output = Process::new(env!("CARGO_BIN_EXE_sonolube"))
        .args(args)
        .output()
        .expect("the sonolube binary runs");
    (
        output.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

#[test]
fn the_cli_prints_replies_writes_files_and_sets_its_exit_status() {
    let dir = std::env::temp_dir().join(format!("sonolube-monitor-cli-{}", std::process::id()));
    let csv = dir.join("out/run.csv");
    let svg = dir.join("out/run.svg");
    let (path, server) = mock(Misbehaviour::default(), Duration::ZERO);
    let endpoint = format!("unix:{}", path.display());
    let (code, stdout, stderr) = sonolube(&[
        "monitor",
        "--connect",
        &endpoint,
        "-c",
        "telemetry 1000",
        "-c",
        "status",
        "-c",
        "wait 20",
        "--csv",
        csv.to_str().unwrap(),
        "--svg",
        svg.to_str().unwrap(),
    ]);
    server.join().unwrap();
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    assert!(stdout.contains("> status\n< ok state=idle"), "{stdout}");
    assert!(
        stdout.contains("# waited 20 ms of firmware time"),
        "{stdout}"
    );
    let table = std::fs::read_to_string(&csv).unwrap();
    assert!(
        table.starts_with(CSV_HEADER) && table.lines().count() > 10,
        "{table}"
    );
    assert!(std::fs::read_to_string(&svg).unwrap().contains("</svg>"));

    for (allow, expected) in [(false, 1), (true, 0)] {
        let (path, server) = mock(Misbehaviour::default(), Duration::ZERO);
        let endpoint = format!("unix:{}", path.display());
        let mut args = vec!["monitor", "--connect", &endpoint, "-c", "target coef 9"];
        if allow {
            args.push("--allow-errors");
        }
        let (code, stdout, stderr) = sonolube(&args);
        server.join().unwrap();
        assert_eq!(code, expected, "{stdout}\n{stderr}");
        assert!(stdout.contains("< err 6 out-of-range"), "{stdout}");
    }
    let (code, _, stderr) = sonolube(&["monitor", "-c", "status"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("--connect ENDPOINT is required"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// An output file that cannot be written is found before the monitor connects: nothing is sent
/// (the listening socket never sees a connection) and the exit status is 1, with the reason.
#[test]
fn unwritable_output_paths_stop_the_monitor_before_it_connects() {
    let dir = std::env::temp_dir().join(format!("sonolube-monitor-paths-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let socket = dir.join("uart.sock");
    let listener = UnixListener::bind(&socket).unwrap();
    listener.set_nonblocking(true).unwrap();
    let endpoint = format!("unix:{}", socket.display());
    let blocker = dir.join("a-file");
    std::fs::write(&blocker, "not a folder").unwrap();
    let under_a_file = blocker.join("run.csv");
    for (flag, path) in [
        ("--csv", under_a_file.to_str().unwrap()),
        ("--svg", dir.to_str().unwrap()),
    ] {
        let (code, stdout, stderr) = sonolube(&[
            "monitor",
            "--connect",
            &endpoint,
            "--connect-timeout-ms",
            "200",
            "-c",
            "status",
            flag,
            path,
        ]);
        assert_eq!(code, 1, "{flag} {path}: {stdout}\n{stderr}");
        assert!(
            stderr.contains(path) && stderr.contains("nothing was sent"),
            "{stderr}"
        );
        assert!(!stdout.contains("> status"), "{stdout}");
        assert_eq!(
            listener.accept().map(|_| ()).unwrap_err().kind(),
            std::io::ErrorKind::WouldBlock,
            "{flag}: the monitor connected although its output path was bad"
        );
    }
    let (code, _, stderr) = sonolube(&[
        "monitor",
        "--connect",
        &endpoint,
        "-c",
        "status",
        "--csv",
        "same.out",
        "--svg",
        "same.out",
    ]);
    assert_eq!(code, 2, "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}
