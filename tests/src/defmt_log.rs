//! Reading the firmware's defmt log (written by QEMU's semihosting) with `defmt-print`.

use std::path::Path;
use std::process::{Command, Stdio};

use anyhow::{bail, Context, Result};

/// The firmware's per-sample cost report (its `stats:` log line, written on `GetStats`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CycleReport {
    /// Samples processed since the last reset.
    pub samples: u64,
    /// Core cycles spent in the recognizer on them.
    pub total_cycles: u64,
    /// Worst cycles on one sample.
    pub worst_cycles: u64,
}

/// Decodes `log` against `elf` with `defmt-print` (`cargo install defmt-print`).
pub fn decode(elf: &Path, log: &Path) -> Result<String> {
    let input = std::fs::File::open(log).with_context(|| format!("opening {}", log.display()))?;
    let out = Command::new("defmt-print")
        .arg("-e")
        .arg(elf)
        .stdin(input)
        .stderr(Stdio::null())
        .output()
        .context("running defmt-print (install it with `cargo install defmt-print`)")?;
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// The `stats:` lines of a decoded log, in order.
pub fn cycle_reports(text: &str) -> Result<Vec<CycleReport>> {
    let mut out = Vec::new();
    for line in text.lines() {
        let Some(rest) = line.split_once("stats: ").map(|(_, r)| r) else {
            continue;
        };
        let nums: Vec<u64> = rest
            .split(|c: char| !c.is_ascii_digit())
            .filter(|s| !s.is_empty())
            .map(str::parse)
            .collect::<Result<_, _>>()?;
        let [samples, total_cycles, worst_cycles] = nums[..] else {
            bail!("unexpected stats line: {line}");
        };
        out.push(CycleReport {
            samples,
            total_cycles,
            worst_cycles,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_firmware_stats_line() {
        let r =
            cycle_reports("INFO  x\nINFO  stats: 1776 samples, 123456 cycles total, 400 worst\n")
                .unwrap();
        assert_eq!(
            r,
            [CycleReport {
                samples: 1776,
                total_cycles: 123_456,
                worst_cycles: 400
            }]
        );
    }
}
