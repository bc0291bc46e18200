//! Where the firmware's UART is reached: a Unix socket (QEMU's `-chardev socket`), a TCP port,
//! or a serial port (the board's ST-LINK virtual COM port), and opening it as a byte stream.

use std::fmt;
use std::io::{ErrorKind, Read, Write};
use std::net::TcpStream;
use std::os::unix::net::UnixStream;
use std::path::PathBuf;
use std::thread;
use std::time::{Duration, Instant};

/// Baud rate of the firmware's UART when a `serial:` endpoint names none (8N1, no flow control).
pub const DEFAULT_BAUD: u32 = 115_200;

/// How long one read of the receiving thread blocks before it checks whether it should stop.
pub(crate) const READ_POLL: Duration = Duration::from_millis(50);

/// Pause between two connection attempts while the peer is not there yet.
const RETRY_PAUSE: Duration = Duration::from_millis(50);

/// A place where the firmware's command interface is reached, as written after `--connect`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Endpoint {
    /// `unix:PATH`: a Unix stream socket, such as QEMU's `-chardev socket,path=PATH,server=on`.
    Unix(PathBuf),
    /// `tcp:HOST:PORT`: a TCP connection (QEMU's `-serial tcp:...`, a serial-to-network bridge).
    Tcp {
        /// Host name or address (`[::1]` style brackets for IPv6 are removed).
        host: String,
        /// TCP port, 1..=65535.
        port: u16,
    },
    /// `serial:DEVICE[@BAUD]`: a serial port, 8 data bits, no parity, 1 stop bit, no flow
    /// control.
    Serial {
        /// Device path, for example `/dev/ttyACM0`.
        device: String,
        /// Baud rate, [`DEFAULT_BAUD`] unless given.
        baud: u32,
    },
}

impl Endpoint {
    /// Reads `unix:PATH`, `tcp:HOST:PORT` or `serial:DEVICE[@BAUD]`.
    pub fn parse(text: &str) -> Result<Endpoint, String> {
        let (scheme, rest) = text.split_once(':').ok_or_else(|| {
            format!("endpoint '{text}' is not unix:PATH, tcp:HOST:PORT or serial:DEVICE[@BAUD]")
        })?;
        match scheme {
            "unix" if !rest.is_empty() => Ok(Endpoint::Unix(PathBuf::from(rest))),
            "unix" => Err("unix: needs a socket path".to_string()),
            "tcp" => {
                let (host, port) = rest
                    .rsplit_once(':')
                    .ok_or_else(|| format!("tcp endpoint '{text}' needs HOST:PORT"))?;
                let host = host
                    .strip_prefix('[')
                    .and_then(|h| h.strip_suffix(']'))
                    .unwrap_or(host);
                let port = port
                    .parse::<u16>()
                    .ok()
                    .filter(|&p| p != 0)
                    .ok_or_else(|| format!("tcp port '{port}' is not 1..=65535"))?;
                if host.is_empty() {
                    return Err(format!("tcp endpoint '{text}' has no host"));
                }
                Ok(Endpoint::Tcp {
                    host: host.to_string(),
                    port,
                })
            }
            "serial" => {
                let (device, baud) = match rest.rsplit_once('@') {
                    Some((device, baud)) => {
                        let baud =
                            baud.parse::<u32>().ok().filter(|&b| b > 0).ok_or_else(|| {
                                format!("baud rate '{baud}' is not a positive integer")
                            })?;
                        (device, baud)
                    }
                    None => (rest, DEFAULT_BAUD),
                };
                if device.is_empty() {
                    return Err("serial: needs a device path".to_string());
                }
                Ok(Endpoint::Serial {
                    device: device.to_string(),
                    baud,
                })
            }
            other => Err(format!(
                "unknown endpoint kind '{other}:' (use unix:, tcp: or serial:)"
            )),
        }
    }
}

impl fmt::Display for Endpoint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Endpoint::Unix(path) => write!(f, "unix:{}", path.display()),
            Endpoint::Tcp { host, port } if host.contains(':') => write!(f, "tcp:[{host}]:{port}"),
            Endpoint::Tcp { host, port } => write!(f, "tcp:{host}:{port}"),
            Endpoint::Serial { device, baud } => write!(f, "serial:{device}@{baud}"),
        }
    }
}

/// An open byte stream to the firmware, split into its two directions.
///
/// The reading half returns within about [`READ_POLL`] when no byte arrives (`WouldBlock` or
/// `TimedOut`), so the thread that owns it can stop.
pub struct Connection {
    /// Bytes from the firmware.
    pub reader: Box<dyn Read + Send>,
    /// Bytes to the firmware; a write blocks at most the write timeout given to [`connect`].
    pub writer: Box<dyn Write + Send>,
}

impl Connection {
    /// A connection over a connected Unix socket (also how tests attach to a mock firmware).
    pub fn unix(stream: UnixStream, write_timeout: Duration) -> std::io::Result<Connection> {
        stream.set_read_timeout(Some(READ_POLL))?;
        stream.set_write_timeout(Some(write_timeout))?;
        let writer = stream.try_clone()?;
        Ok(Connection {
            reader: Box::new(stream),
            writer: Box::new(writer),
        })
    }

    fn tcp(stream: TcpStream, write_timeout: Duration) -> std::io::Result<Connection> {
        stream.set_nodelay(true)?;
        stream.set_read_timeout(Some(READ_POLL))?;
        stream.set_write_timeout(Some(write_timeout))?;
        let writer = stream.try_clone()?;
        Ok(Connection {
            reader: Box::new(stream),
            writer: Box::new(writer),
        })
    }
}

/// Opens `endpoint`. Sockets are retried for `retry_for` while they refuse or do not exist yet
/// (QEMU creates its socket when it starts); a serial port is opened once. Writes give up after
/// `write_timeout`.
pub fn connect(
    endpoint: &Endpoint,
    retry_for: Duration,
    write_timeout: Duration,
) -> Result<Connection, String> {
    let io = |e: std::io::Error| format!("{endpoint}: {e}");
    match endpoint {
        Endpoint::Unix(path) => {
            let stream = retry(retry_for, || UnixStream::connect(path)).map_err(io)?;
            Connection::unix(stream, write_timeout).map_err(io)
        }
        Endpoint::Tcp { host, port } => {
            let stream =
                retry(retry_for, || TcpStream::connect((host.as_str(), *port))).map_err(io)?;
            Connection::tcp(stream, write_timeout).map_err(io)
        }
        Endpoint::Serial { device, baud } => {
            let serial = |e: serialport::Error| format!("{endpoint}: {e}");
            let port = serialport::new(device, *baud)
                .data_bits(serialport::DataBits::Eight)
                .parity(serialport::Parity::None)
                .stop_bits(serialport::StopBits::One)
                .flow_control(serialport::FlowControl::None)
                .timeout(READ_POLL)
                .open()
                .map_err(serial)?;
            // Bytes the board sent before we opened the port belong to nobody's command.
            port.clear(serialport::ClearBuffer::Input).map_err(serial)?;
            let mut writer = port.try_clone().map_err(serial)?;
            writer.set_timeout(write_timeout).map_err(serial)?;
            Ok(Connection {
                reader: Box::new(port),
                writer: Box::new(writer),
            })
        }
    }
}

/// Calls `attempt` until it succeeds or `retry_for` has passed; returns the last error.
fn retry<T>(
    retry_for: Duration,
    mut attempt: impl FnMut() -> std::io::Result<T>,
) -> std::io::Result<T> {
    let deadline = Instant::now() + retry_for;
    loop {
        match attempt() {
            Ok(value) => return Ok(value),
            Err(e) if Instant::now() >= deadline => return Err(e),
            Err(e)
                if matches!(
                    e.kind(),
                    ErrorKind::NotFound
                        | ErrorKind::ConnectionRefused
                        | ErrorKind::ConnectionReset
                        | ErrorKind::TimedOut
                        | ErrorKind::Interrupted
                        | ErrorKind::AddrNotAvailable
                ) =>
            {
                thread::sleep(RETRY_PAUSE)
            }
            Err(e) => return Err(e),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn endpoints_parse_and_print() {
        let cases = [
            ("unix:/tmp/uart.sock", "unix:/tmp/uart.sock"),
            ("tcp:localhost:4321", "tcp:localhost:4321"),
            ("tcp:[::1]:4321", "tcp:[::1]:4321"),
            ("serial:/dev/ttyACM0", "serial:/dev/ttyACM0@115200"),
            ("serial:/dev/ttyUSB1@921600", "serial:/dev/ttyUSB1@921600"),
        ];
        for (text, shown) in cases {
            let endpoint = Endpoint::parse(text).unwrap();
            assert_eq!(endpoint.to_string(), shown);
            assert_eq!(Endpoint::parse(shown).unwrap(), endpoint);
        }
        assert_eq!(
            Endpoint::parse("tcp:[::1]:7").unwrap(),
            Endpoint::Tcp {
                host: "::1".into(),
                port: 7
            }
        );
    }

    #[test]
    fn bad_endpoints_say_why() {
        for text in [
            "/tmp/uart.sock",
            "unix:",
            "tcp:host",
            "tcp:host:0",
            "tcp:host:99999",
            "tcp::80",
            "serial:",
            "serial:/dev/ttyACM0@fast",
            "serial:/dev/ttyACM0@0",
            "ftp:x",
        ] {
            let error = Endpoint::parse(text).unwrap_err();
            assert!(!error.is_empty(), "{text}");
        }
    }

    #[test]
    fn a_missing_socket_is_retried_then_reported() {
        let path =
            std::env::temp_dir().join(format!("sonolube-absent-{}.sock", std::process::id()));
        let started = Instant::now();
        let error = connect(
            &Endpoint::Unix(path),
            Duration::from_millis(200),
            Duration::from_secs(1),
        )
        .err()
        .unwrap();
        assert!(started.elapsed() >= Duration::from_millis(200));
        assert!(error.starts_with("unix:"), "{error}");
    }
}
