//! The link subcommands: `figurine devices`, `upload`, `replay` (and `live`, in [`super::live`]).

use std::io::{IsTerminal, Write};
use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use figurine_protocol::BlobKind;

use super::blobs::{self, Blobs};
use super::replay::{replay_log, ReplayOptions};
use super::transport::{serial_ports, PortSpec};
use super::Device;
use crate::events::event_line;
use crate::poselog::PoseLog;

/// Arguments of `figurine devices`.
#[derive(Args, Debug)]
pub struct DevicesArgs {
    /// Also connect to each port (and these `tcp:HOST:PORT`s) and print the figurine's Hello.
    #[arg(long)]
    pub probe: bool,
    /// Extra ports to probe (e.g. an emulator's tcp:127.0.0.1:PORT).
    #[arg(long = "port")]
    pub ports: Vec<String>,
}

/// Arguments of `figurine upload`.
#[derive(Args, Debug)]
pub struct UploadArgs {
    /// Serial device or tcp:HOST:PORT; repeat for several figurines.
    #[arg(long = "port", required = true)]
    pub ports: Vec<String>,
    /// Action library (LIB.json from `figurine learn`); default: the shipped library.
    #[arg(long)]
    pub library: Option<PathBuf>,
    /// Effort model (EFFORT.json); default: the shipped model (as `simulate` uses).
    #[arg(long)]
    pub effort: Option<PathBuf>,
}

/// Arguments of `figurine replay`.
#[derive(Args, Debug)]
pub struct ReplayArgs {
    /// Serial device or tcp:HOST:PORT.
    #[arg(long)]
    pub port: String,
    /// The library the device runs, for action names (default: the shipped library). The
    /// device's library CRC is checked against it.
    #[arg(long)]
    pub library: Option<PathBuf>,
    /// Real-time factor (1 = as recorded); default: as fast as the device keeps up without
    /// dropping samples.
    #[arg(long)]
    pub speed: Option<f64>,
    /// Print device statistics to stderr at the end.
    #[arg(long)]
    pub stats: bool,
    /// The pose log (CSV).
    pub log: PathBuf,
}

fn connect(port: &str) -> Result<Device> {
    let spec: PortSpec = port.parse()?;
    Ok(Device::connect(&spec)?)
}

/// `figurine devices`.
pub fn devices(args: &DevicesArgs) -> Result<()> {
    let mut ports: Vec<(String, String)> = serial_ports().unwrap_or_else(|e| {
        eprintln!("warning: {e}");
        Vec::new()
    });
    ports.extend(args.ports.iter().map(|p| (p.clone(), "given".to_string())));
    if ports.is_empty() {
        println!("no serial ports found");
    }
    for (name, what) in ports {
        print!("{name}\t{what}");
        if args.probe {
            match connect(&name) {
                Ok(dev) => {
                    let h = dev.hello();
                    print!(
                        "\tfigurine protocol {} build {:08x} library {:08x} effort {:08x} \
                         (≤{} actions)",
                        h.protocol_version,
                        h.build_id,
                        h.library_crc,
                        h.effort_crc,
                        h.capacities.max_actions
                    );
                }
                Err(e) => print!("\tnot a figurine: {e}"),
            }
        }
        println!();
    }
    Ok(())
}

/// Uploads both blobs to a connected device, skipping any it already runs.
pub fn upload_to(dev: &mut Device, blobs: &Blobs, quiet: bool) -> Result<()> {
    for (kind, blob) in [
        (BlobKind::Library, &blobs.library),
        (BlobKind::Effort, &blobs.effort),
    ] {
        let have = match kind {
            BlobKind::Library => dev.hello().library_crc,
            BlobKind::Effort => dev.hello().effort_crc,
        };
        let crc = blobs::crc32(blob);
        if have == crc {
            if !quiet {
                eprintln!("{}: {kind:?} {crc:08x} already active", dev.port());
            }
            continue;
        }
        let port = dev.port().to_string();
        let show = !quiet && std::io::stderr().is_terminal();
        dev.upload(kind, blob, |done, total| {
            if show {
                eprint!("\r{port}: {kind:?} {done}/{total} bytes");
            }
        })
        .with_context(|| format!("uploading the {kind:?} to {port}"))?;
        if !quiet {
            eprintln!("\r{port}: {kind:?} {crc:08x} stored ({} bytes)", blob.len());
        }
    }
    Ok(())
}

/// `figurine upload`.
pub fn upload(args: &UploadArgs) -> Result<()> {
    let blobs = blobs::load(args.library.as_deref(), args.effort.as_deref())?;
    for port in &args.ports {
        let mut dev = connect(port)?;
        upload_to(&mut dev, &blobs, false)?;
    }
    Ok(())
}

/// `figurine replay`.
pub fn replay(args: &ReplayArgs) -> Result<()> {
    let blobs = blobs::load(args.library.as_deref(), None)?;
    let log = PoseLog::read_path(&args.log)?;
    let mut dev = connect(&args.port)?;
    if dev.hello().library_crc != blobs::crc32(&blobs.library) {
        eprintln!(
            "warning: the figurine runs library {:08x}, not the one named here ({:08x}); \
             run `figurine upload` first",
            dev.hello().library_crc,
            blobs::crc32(&blobs.library)
        );
    }
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    let mut write_err = None;
    let r = replay_log(
        &mut dev,
        &log,
        &blobs.names,
        ReplayOptions {
            speed: args.speed,
            ..ReplayOptions::default()
        },
        |rec, revises| {
            if let Err(e) = writeln!(out, "{}", event_line(rec, revises)).and_then(|()| out.flush())
            {
                write_err.get_or_insert(e);
            }
        },
    )
    .with_context(|| format!("replaying {}", args.log.display()))?;
    if let Some(e) = write_err {
        return Err(e.into());
    }
    if args.stats {
        eprintln!("{:#?}", r.stats);
    }
    if r.unsendable > 0 {
        eprintln!(
            "{} log samples could not be sent (NaN, out of range)",
            r.unsendable
        );
    }
    Ok(())
}
