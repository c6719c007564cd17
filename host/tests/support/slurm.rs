//! A single-node Slurm cluster of the Debian packages (`slurm-wlm`, `munge`), started in a
//! temporary folder for one test or benchmark and stopped when dropped.
//!
//! Everything it runs lives in that folder: its own munge key, socket and munged; a slurm.conf
//! with free ports and its own state, spool, pid and log files; slurmctld and slurmd in the
//! foreground as child processes. Nothing system-wide is touched, so it runs beside any other
//! Slurm or munge on the machine. Client commands find it through `SLURM_CONF`
//! ([`Cluster::command`]). slurmd must run as root (it starts jobs as their owner).
//!
//! Two scheduler settings keep Slurm's latency to what it cannot avoid (both apply to a lab's
//! cluster as well; see the README):
//! - `batch_sched_delay=0`: Slurm's default lets the scheduler wait up to 3 s before starting a
//!   batch job, which here would be most of the time of a short tile; with it, a submitted job
//!   starts at the controller's next pass (its background loop runs once a second: an `sbatch`
//!   job is never started by the submission itself).
//! - an `Epilog` (a script that does nothing): without one, slurmd acknowledges a finished job
//!   at once and the controller only queues a scheduling pass for its next one-second tick, so
//!   the merge, and each array task waiting for a free node, started up to a second after the
//!   job it waited for (0.9–1.1 s measured with Slurm 22.05). With an epilog, slurmd reports
//!   the epilog's end (`MESSAGE_EPILOG_COMPLETE`), the one event on which slurmctld schedules
//!   immediately, and the next job starts within about 0.1 s.
//!
//! No setting makes slurmctld start a *batch* job on its submission (Slurm 22.05's
//! `job_allocate` only tests batch jobs; `defer`, `sched_min_interval` and `sched_interval` act
//! on later passes): the first array task waits 0–1 s for the next pass unless a job it
//! depends on ends, which is why `graph plan --submit` run under `srun` (allocated at once)
//! makes the tiles wait for the plan's own job.

#![allow(dead_code)]

use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Programs the cluster needs and the Debian package of each.
const PROGRAMS: [(&str, &str); 7] = [
    ("munged", "munge"),
    ("slurmctld", "slurmctld"),
    ("slurmd", "slurmd"),
    ("sbatch", "slurm-client"),
    ("srun", "slurm-client"),
    ("sinfo", "slurm-client"),
    ("scontrol", "slurm-client"),
];
/// The epilog every job runs after it ends: nothing, but its completion message is what makes
/// slurmctld schedule the next job at once rather than at its next one-second pass.
const EPILOG: &str = "#!/bin/sh\n# figurine test cluster: an epilog so that slurmd reports each job's end and\n# slurmctld schedules the next job on that event (see tests/support/slurm.rs).\nexit 0\n";
/// How long the daemons get to report the node idle.
const START_TIMEOUT: Duration = Duration::from_secs(30);

/// A running single-node cluster.
pub struct Cluster {
    dir: PathBuf,
    conf: PathBuf,
    daemons: Vec<Child>,
}

fn find(program: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .chain(["/usr/sbin", "/usr/bin", "/sbin"].map(PathBuf::from))
        .map(|d| d.join(program))
        .find(|p| p.is_file())
}

fn free_port() -> std::io::Result<u16> {
    Ok(TcpListener::bind("127.0.0.1:0")?.local_addr()?.port())
}

fn output(cmd: &mut Command) -> Option<String> {
    let o = cmd.stderr(Stdio::null()).output().ok()?;
    o.status
        .success()
        .then(|| String::from_utf8_lossy(&o.stdout).into_owned())
}

impl Cluster {
    /// Starts a cluster in `dir` (created) with this machine's CPUs; `Err` says why it cannot
    /// (missing packages, not root, a daemon that did not come up), for the caller to print
    /// and skip.
    pub fn start(dir: &Path) -> Result<Cluster, String> {
        let missing: Vec<&str> = PROGRAMS
            .iter()
            .filter(|(p, _)| find(p).is_none())
            .map(|(_, pkg)| *pkg)
            .collect();
        if !missing.is_empty() {
            return Err(format!(
                "Slurm is not installed (missing packages: {}; `cargo xtask setup` installs slurm-wlm and munge)",
                missing.join(" ")
            ));
        }
        if output(Command::new("id").arg("-u"))
            .as_deref()
            .map(str::trim)
            != Some("0")
        {
            return Err("slurmd must run as root to start jobs, and this is not root".into());
        }
        let err = |what: &str, e: &dyn std::fmt::Display| format!("{what}: {e}");
        std::fs::remove_dir_all(dir).ok();
        for d in ["munge", "state", "spool", "log"] {
            std::fs::create_dir_all(dir.join(d))
                .map_err(|e| err("creating the cluster folder", &e))?;
        }
        let munge = dir.join("munge");
        let mut key = vec![0u8; 1024];
        std::io::Read::read_exact(
            &mut std::fs::File::open("/dev/urandom").map_err(|e| err("/dev/urandom", &e))?,
            &mut key,
        )
        .map_err(|e| err("/dev/urandom", &e))?;
        let keyfile = munge.join("munge.key");
        std::fs::write(&keyfile, key).map_err(|e| err("writing the munge key", &e))?;
        {
            use std::os::unix::fs::PermissionsExt;
            let mode =
                |p: &Path, m| std::fs::set_permissions(p, std::fs::Permissions::from_mode(m));
            mode(&keyfile, 0o600).map_err(|e| err("munge key", &e))?;
            mode(&munge, 0o755).map_err(|e| err("munge folder", &e))?;
            mode(dir, 0o755).map_err(|e| err("cluster folder", &e))?;
        }
        let host = output(Command::new("hostname").arg("-s"))
            .map(|h| h.trim().to_string())
            .filter(|h| !h.is_empty())
            .ok_or("no host name")?;
        let cpus = std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1);
        let (p1, p2) = (
            free_port().map_err(|e| err("port", &e))?,
            free_port().map_err(|e| err("port", &e))?,
        );
        let d = dir.display();
        let conf = dir.join("slurm.conf");
        let epilog = dir.join("epilog.sh");
        let ep = epilog.display();
        let text = format!(
            "ClusterName=figurine\n\
             SlurmctldHost={host}(127.0.0.1)\n\
             SlurmctldPort={p1}\nSlurmdPort={p2}\n\
             SlurmUser=root\nSlurmdUser=root\n\
             AuthType=auth/munge\nCredType=cred/munge\nAuthInfo=socket={d}/munge/sock\n\
             StateSaveLocation={d}/state\nSlurmdSpoolDir={d}/spool\n\
             SlurmctldPidFile={d}/slurmctld.pid\nSlurmdPidFile={d}/slurmd.pid\n\
             SlurmctldLogFile={d}/log/slurmctld.log\nSlurmdLogFile={d}/log/slurmd.log\n\
             ProctrackType=proctrack/pgid\nTaskPlugin=task/none\n\
             SelectType=select/cons_tres\nSelectTypeParameters=CR_Core\n\
             SchedulerType=sched/builtin\nSchedulerParameters=batch_sched_delay=0\n\
             Epilog={ep}\n\
             MpiDefault=none\nSwitchType=switch/none\n\
             JobCompType=jobcomp/none\nAccountingStorageType=accounting_storage/none\n\
             JobAcctGatherType=jobacct_gather/none\nReturnToService=2\n\
             NodeName={host} NodeAddr=127.0.0.1 CPUs={cpus} State=UNKNOWN\n\
             PartitionName=figurine Nodes={host} Default=YES MaxTime=INFINITE State=UP\n"
        );
        std::fs::write(&conf, text).map_err(|e| err("writing slurm.conf", &e))?;
        {
            use std::os::unix::fs::PermissionsExt;
            std::fs::write(&epilog, EPILOG).map_err(|e| err("writing the epilog", &e))?;
            std::fs::set_permissions(&epilog, std::fs::Permissions::from_mode(0o755))
                .map_err(|e| err("epilog", &e))?;
        }
        let mut c = Cluster {
            dir: dir.to_path_buf(),
            conf: conf.clone(),
            daemons: Vec::new(),
        };
        let spawn =
            |c: &mut Cluster, prog: &str, args: Vec<String>, log: &str| -> Result<(), String> {
                let log =
                    std::fs::File::create(dir.join("log").join(log)).map_err(|e| err(log, &e))?;
                let child = Command::new(find(prog).ok_or(prog.to_string())?)
                    .args(args)
                    .env("SLURM_CONF", &conf)
                    .stdin(Stdio::null())
                    .stdout(log.try_clone().map_err(|e| err(prog, &e))?)
                    .stderr(log)
                    .spawn()
                    .map_err(|e| err(prog, &e))?;
                c.daemons.push(child);
                Ok(())
            };
        let m = munge.display();
        spawn(
            &mut c,
            "munged",
            vec![
                "-F".into(),
                "-f".into(),
                format!("--socket={m}/sock"),
                format!("--key-file={m}/munge.key"),
                format!("--log-file={m}/munged.log"),
                format!("--pid-file={m}/munged.pid"),
                format!("--seed-file={m}/munged.seed"),
            ],
            "munged.out",
        )?;
        let sock = munge.join("sock");
        let t0 = Instant::now();
        while !sock.exists() && t0.elapsed() < START_TIMEOUT {
            std::thread::sleep(Duration::from_millis(50));
        }
        let cf = conf.display().to_string();
        spawn(
            &mut c,
            "slurmctld",
            vec!["-D".into(), "-i".into(), "-f".into(), cf.clone()],
            "slurmctld.out",
        )?;
        spawn(
            &mut c,
            "slurmd",
            vec!["-D".into(), "-f".into(), cf, "-N".into(), host],
            "slurmd.out",
        )?;
        while t0.elapsed() < START_TIMEOUT {
            let state = output(c.command("sinfo").args(["-h", "-o", "%T"]));
            if state.is_some_and(|s| s.trim() == "idle") {
                return Ok(c);
            }
            std::thread::sleep(Duration::from_millis(200));
        }
        Err(format!(
            "the Slurm node did not become idle within {START_TIMEOUT:?}; logs in {}:\n{}",
            c.dir.join("log").display(),
            c.log_tail()
        ))
    }

    /// A client command (`sbatch`, `squeue`, `sh submit.sh` …) aimed at this cluster.
    pub fn command(&self, program: &str) -> Command {
        let mut cmd = Command::new(program);
        cmd.env("SLURM_CONF", &self.conf);
        cmd
    }

    /// The last lines of the daemons' logs, for error messages.
    pub fn log_tail(&self) -> String {
        let mut out = String::new();
        for f in [
            "slurmctld.log",
            "slurmd.log",
            "slurmctld.out",
            "slurmd.out",
            "munged.out",
        ] {
            let text = std::fs::read_to_string(self.dir.join("log").join(f)).unwrap_or_default();
            let lines: Vec<&str> = text.lines().collect();
            out += &format!(
                "--- {f}\n{}\n",
                lines[lines.len().saturating_sub(8)..].join("\n")
            );
        }
        out
    }

    /// slurmctld's log (one line per submission, allocation and completion, with
    /// millisecond time stamps).
    pub fn controller_log(&self) -> PathBuf {
        self.dir.join("log").join("slurmctld.log")
    }

    /// The state of job `id` (a single job) once it has ended (COMPLETED, FAILED …, or
    /// DependencyNeverSatisfied for a job that can never start); `None` while it is pending or
    /// running. One `scontrol` call.
    pub fn ended_state(&self, id: &str) -> Option<String> {
        let text =
            output(self.command("scontrol").args(["show", "job", "-o", id])).unwrap_or_default();
        let field = |k: &str| {
            text.split_whitespace()
                .find_map(|w| w.strip_prefix(k))
                .unwrap_or("")
                .to_string()
        };
        let state = field("JobState=");
        match state.as_str() {
            "PENDING" if field("Reason=") == "DependencyNeverSatisfied" => {
                Some("DependencyNeverSatisfied".into())
            }
            "" | "PENDING" | "RUNNING" | "CONFIGURING" | "COMPLETING" => None,
            _ => Some(state),
        }
    }

    /// Waits until job `id` (a single job) has ended and returns its state (COMPLETED,
    /// FAILED …); a job whose dependency can never be met is reported as such.
    pub fn wait_job(&self, id: &str, timeout: Duration) -> Result<String, String> {
        let t0 = Instant::now();
        while t0.elapsed() < timeout {
            if let Some(state) = self.ended_state(id) {
                return Ok(state);
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        Err(format!(
            "job {id} still not done after {timeout:?}\n{}",
            self.log_tail()
        ))
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        // Ask slurmctld and slurmd to stop, then end what is left: only our own children.
        let _ = self
            .command("scontrol")
            .arg("shutdown")
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status();
        let t0 = Instant::now();
        // munged (the first) does not listen to scontrol: it is ended after the others.
        for child in self.daemons.iter_mut().skip(1) {
            while t0.elapsed() < Duration::from_secs(5) && matches!(child.try_wait(), Ok(None)) {
                std::thread::sleep(Duration::from_millis(50));
            }
        }
        for child in self.daemons.iter_mut().rev() {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}
