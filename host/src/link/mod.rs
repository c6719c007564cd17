//! The host side of the figurine link: transports (serial, `tcp:HOST:PORT` for the emulator),
//! the connected [`Device`] (handshake, requests, acknowledged uploads, event stream), log
//! replay through a device with the same JSON-lines output as `figurine simulate`, live
//! sessions that survive unplugging, and the `devices`/`upload`/`replay`/`live` subcommands.

pub mod blobs;
pub mod cli;
pub mod device;
pub mod lines;
pub mod live;
pub mod replay;
pub mod transport;

pub use device::Device;
pub use replay::{replay_log, Replay, ReplayOptions};
pub use transport::PortSpec;

use figurine_protocol::{DeviceError, ProtocolError};
use thiserror::Error;

/// What can go wrong talking to a figurine.
#[derive(Debug, Error)]
pub enum LinkError {
    /// `--port` is neither a device path nor `tcp:HOST:PORT`.
    #[error("bad port `{0}`: expected a serial device path or tcp:HOST:PORT")]
    BadPort(String),
    /// The port could not be opened.
    #[error("cannot open {port}: {source}")]
    Open {
        /// The port.
        port: String,
        /// Why.
        source: std::io::Error,
    },
    /// The device speaks another protocol version.
    #[error(
        "{port}: the figurine speaks protocol version {theirs}, this host speaks version {ours}; \
         update the {}",
        if theirs < ours { "firmware" } else { "host (figurine CLI)" }
    )]
    Version {
        /// The port.
        port: String,
        /// Our version.
        ours: u16,
        /// The device's version.
        theirs: u16,
    },
    /// The connection dropped (unplugged, emulator stopped).
    #[error("link lost: {0}")]
    Disconnected(String),
    /// The device did not answer in time.
    #[error("{0}: no answer from the figurine")]
    Timeout(String),
    /// The device rebooted while a request was in progress.
    #[error("{0}: the figurine rebooted")]
    Rebooted(String),
    /// The device refused something.
    #[error("the figurine refused: {0:?}")]
    Device(DeviceError),
    /// A blob does not fit the device.
    #[error("blob of {0} bytes does not fit the figurine")]
    TooLarge(usize),
    /// A message could not be framed.
    #[error("cannot frame message: {0}")]
    Encode(ProtocolError),
}
