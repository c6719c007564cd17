//! Byte transports to a figurine: a serial port (USB CDC-ACM or UART adapter) or, for the
//! emulator, a TCP socket (`tcp:HOST:PORT`, QEMU's `-chardev socket`).

use std::fmt;
use std::io::{self, Read, Write};
use std::net::{Shutdown, TcpStream, ToSocketAddrs};
use std::str::FromStr;
use std::time::Duration;

use super::LinkError;

/// Read timeout of a transport: how often a blocked reader wakes to check for shutdown.
pub const READ_POLL: Duration = Duration::from_millis(20);
/// Serial line rate used when opening a real UART, baud (ignored by USB CDC-ACM).
pub const SERIAL_BAUD: u32 = 1_000_000;
/// How long connecting to a TCP port may take.
const TCP_CONNECT_TIMEOUT: Duration = Duration::from_secs(2);

/// Where a figurine is attached, as given to `--port`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PortSpec {
    /// A serial device path (`/dev/ttyACM0`, `COM3`).
    Serial(String),
    /// `tcp:HOST:PORT`, e.g. an emulated figurine.
    Tcp(String),
}

impl FromStr for PortSpec {
    type Err = LinkError;

    fn from_str(s: &str) -> Result<Self, LinkError> {
        match s.strip_prefix("tcp:") {
            Some(addr)
                if addr
                    .rsplit_once(':')
                    .is_some_and(|(h, p)| !h.is_empty() && p.parse::<u16>().is_ok()) =>
            {
                Ok(PortSpec::Tcp(addr.to_string()))
            }
            Some(_) => Err(LinkError::BadPort(s.to_string())),
            None if s.is_empty() => Err(LinkError::BadPort(s.to_string())),
            None => Ok(PortSpec::Serial(s.to_string())),
        }
    }
}

impl fmt::Display for PortSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PortSpec::Serial(p) => f.write_str(p),
            PortSpec::Tcp(a) => write!(f, "tcp:{a}"),
        }
    }
}

/// The receive half of an open transport (reads time out after [`READ_POLL`]).
pub type Reader = Box<dyn Read + Send>;

/// The transmit half of an open transport.
pub trait Writer: Write + Send {
    /// Closes the connection so that a reader blocked on it returns.
    fn shutdown(&mut self);
}

struct TcpWriter(TcpStream);

impl Write for TcpWriter {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.write(buf)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.0.flush()
    }
}

impl Writer for TcpWriter {
    fn shutdown(&mut self) {
        let _ = self.0.shutdown(Shutdown::Both);
    }
}

struct SerialWriter(Box<dyn serialport::SerialPort>);

impl Write for SerialWriter {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.write(buf)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.0.flush()
    }
}

impl Writer for SerialWriter {
    fn shutdown(&mut self) {}
}

/// Opens `spec`, returning its receive and transmit halves.
pub fn open(spec: &PortSpec) -> Result<(Reader, Box<dyn Writer>), LinkError> {
    let io_err = |source: io::Error| LinkError::Open {
        port: spec.to_string(),
        source,
    };
    match spec {
        PortSpec::Tcp(addr) => {
            let sock = addr
                .to_socket_addrs()
                .map_err(io_err)?
                .next()
                .ok_or_else(|| io_err(io::Error::new(io::ErrorKind::NotFound, "no address")))?;
            let stream = TcpStream::connect_timeout(&sock, TCP_CONNECT_TIMEOUT).map_err(io_err)?;
            stream.set_nodelay(true).map_err(io_err)?;
            stream.set_read_timeout(Some(READ_POLL)).map_err(io_err)?;
            let reader = stream.try_clone().map_err(io_err)?;
            Ok((Box::new(reader), Box::new(TcpWriter(stream))))
        }
        PortSpec::Serial(path) => {
            let port = serialport::new(path, SERIAL_BAUD)
                .timeout(READ_POLL)
                .open()
                .map_err(|e| io_err(io::Error::other(e)))?;
            let reader = port.try_clone().map_err(|e| io_err(io::Error::other(e)))?;
            Ok((Box::new(reader), Box::new(SerialWriter(port))))
        }
    }
}

/// True for the errors a read with a timeout returns when no byte arrived.
pub fn is_timeout(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted
    )
}

/// Serial ports present on this machine: (path, description).
pub fn serial_ports() -> Result<Vec<(String, String)>, LinkError> {
    let ports = serialport::available_ports().map_err(|e| LinkError::Open {
        port: "serial port list".into(),
        source: io::Error::other(e),
    })?;
    Ok(ports
        .into_iter()
        .map(|p| {
            let what = match p.port_type {
                serialport::SerialPortType::UsbPort(u) => format!(
                    "USB {:04x}:{:04x} {} {}",
                    u.vid,
                    u.pid,
                    u.manufacturer.unwrap_or_default(),
                    u.product.unwrap_or_default()
                ),
                serialport::SerialPortType::PciPort => "PCI".into(),
                serialport::SerialPortType::BluetoothPort => "Bluetooth".into(),
                serialport::SerialPortType::Unknown => "serial".into(),
            };
            (p.port_name, what.trim().to_string())
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn port_specs_parse() {
        assert_eq!(
            "tcp:127.0.0.1:4444".parse::<PortSpec>().unwrap(),
            PortSpec::Tcp("127.0.0.1:4444".into())
        );
        assert_eq!(
            "/dev/ttyACM0".parse::<PortSpec>().unwrap(),
            PortSpec::Serial("/dev/ttyACM0".into())
        );
        assert!("tcp:nohost".parse::<PortSpec>().is_err());
        assert!("tcp::12".parse::<PortSpec>().is_err());
        assert!("tcp:h:99999".parse::<PortSpec>().is_err());
        assert!("".parse::<PortSpec>().is_err());
        assert_eq!(PortSpec::Tcp("h:1".into()).to_string(), "tcp:h:1");
    }
}
