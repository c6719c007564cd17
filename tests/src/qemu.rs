//! Running the real firmware binary in `qemu-system-arm -M mps2-an386`.
//!
//! The emulated UART0 is a TCP server socket (`nodelay`, or a small frame takes ~44 ms);
//! QEMU waits for the host to connect before starting the guest. Semihosting carries the
//! firmware's defmt log to a file (decode with `defmt-print -e ELF < FILE`) and the fault
//! injection arguments in. [`Qemu`] kills and reaps the process when dropped.

use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use figurine_host::link::{Device, PortSpec};

/// Environment variable naming the firmware ELF to run (overrides the default path).
pub const FIRMWARE_ENV: &str = "FIGURINE_FIRMWARE_ELF";
/// Environment variable naming the QEMU binary (default `qemu-system-arm`).
pub const QEMU_ENV: &str = "FIGURINE_QEMU";
/// How long QEMU may take to open its socket.
const START_TIMEOUT: Duration = Duration::from_secs(10);

/// The firmware ELF: `$FIGURINE_FIRMWARE_ELF`, else the release build of `firmware/app`.
pub fn firmware_elf() -> Result<PathBuf> {
    let path = match std::env::var_os(FIRMWARE_ENV) {
        Some(p) => PathBuf::from(p),
        None => Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../firmware/app/target/thumbv7em-none-eabihf/release/figurine-firmware"),
    };
    if !path.is_file() {
        bail!(
            "firmware ELF not found at {}: build it first with `cargo xtask firmware --board qemu` \
             (or `cd firmware/app && cargo build --release`), or set {FIRMWARE_ENV}",
            path.display()
        );
    }
    let bytes = std::fs::read(&path).with_context(|| format!("reading {}", path.display()))?;
    if !bytes.windows(BOARD_TAG.len()).any(|w| w == BOARD_TAG) {
        bail!(
            "{} is not a QEMU build of the firmware (another board?): rebuild it with \
             `cargo xtask firmware --board qemu`",
            path.display()
        );
    }
    Ok(path)
}

/// Marker the QEMU board puts into its ELF.
const BOARD_TAG: &[u8] = b"figurine-board:qemu-mps2-an386";

/// Makes QEMU receive SIGKILL when the thread that started it dies, so even a test process
/// killed by a signal (when `Drop` cannot run) leaves no emulator behind.
#[allow(unsafe_code)]
fn die_with_parent(cmd: &mut Command) {
    use std::os::unix::process::CommandExt;
    // SAFETY: the closure runs in the child between fork and exec and only calls prctl,
    // which is async-signal-safe.
    unsafe {
        cmd.pre_exec(|| {
            if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL) == -1 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
}

/// How to start the emulator.
#[derive(Debug, Clone, Default)]
pub struct QemuOptions {
    /// Power cut to inject: during upload `U` (1-based, counted since QEMU started) after
    /// `K` bytes were written (`cut=U:K` on the semihosting command line).
    pub cut: Option<(u32, u32)>,
    /// Deterministic instruction counting (`-icount shift=0`: 1 instruction = 1 ns, so
    /// SysTick cycles × 40 = instructions).
    pub icount: bool,
}

/// A running emulated figurine. Dropping it kills and reaps QEMU.
pub struct Qemu {
    child: Child,
    port: u16,
    log: PathBuf,
}

fn free_port() -> Result<u16> {
    let l = TcpListener::bind("127.0.0.1:0").context("finding a free TCP port")?;
    Ok(l.local_addr()?.port())
}

impl Qemu {
    /// Starts QEMU on the firmware ELF. The guest starts when [`Qemu::connect`] connects.
    pub fn start(opts: &QemuOptions) -> Result<Qemu> {
        let elf = firmware_elf()?;
        let qemu = std::env::var(QEMU_ENV).unwrap_or_else(|_| "qemu-system-arm".into());
        let port = free_port()?;
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/e2e");
        std::fs::create_dir_all(&dir)?;
        let log = dir.join(format!("qemu-{port}.defmt"));
        let mut semi = "enable=on,target=native,arg=figurine-firmware".to_string();
        if let Some((u, k)) = opts.cut {
            semi.push_str(&format!(",arg=cut={u}:{k}"));
        }
        let mut cmd = Command::new(&qemu);
        cmd.args(["-M", "mps2-an386", "-nographic", "-monitor", "none"])
            .args(["-semihosting-config", &semi])
            .arg("-kernel")
            .arg(&elf)
            .args([
                "-chardev",
                &format!("socket,id=s0,host=127.0.0.1,port={port},server=on,wait=on,nodelay=on"),
                "-serial",
                "chardev:s0",
            ]);
        if opts.icount {
            cmd.args(["-icount", "shift=0"]);
        }
        die_with_parent(&mut cmd);
        let child = cmd
            .stdin(Stdio::null())
            .stdout(std::fs::File::create(&log)?)
            .stderr(Stdio::null())
            .spawn()
            .with_context(|| {
                format!("starting {qemu} (install it with `apt-get install qemu-system-arm`)")
            })?;
        Ok(Qemu { child, port, log })
    }

    /// The emulated UART's address as a `--port` value.
    pub fn port_spec(&self) -> PortSpec {
        PortSpec::Tcp(format!("127.0.0.1:{}", self.port))
    }

    /// The file receiving the firmware's defmt log (binary; `defmt-print -e ELF`).
    pub fn log_path(&self) -> &Path {
        &self.log
    }

    /// Connects (retrying until QEMU listens) and performs the handshake.
    pub fn connect(&mut self) -> Result<Device> {
        let deadline = Instant::now() + START_TIMEOUT;
        loop {
            if let Some(status) = self.child.try_wait()? {
                bail!("QEMU exited early with {status}");
            }
            match Device::connect(&self.port_spec()) {
                Ok(d) => return Ok(d),
                Err(e) if Instant::now() > deadline => {
                    return Err(e).context("connecting to the emulated figurine")
                }
                Err(_) => std::thread::sleep(Duration::from_millis(20)),
            }
        }
    }

    /// QEMU's exit status if it has exited (a firmware panic exits with 101).
    pub fn exited(&mut self) -> Result<Option<std::process::ExitStatus>> {
        Ok(self.child.try_wait()?)
    }
}

impl Drop for Qemu {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
