//! `figurine tokens LOG.csv`: the token runs the device front end sees in a log — what
//! patterns are written in. One line per run: start and end (log seconds), token, mean speed.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use figurine_recognizer::features::SPEED;
use figurine_recognizer::token::TokenName;

use super::feed::{log_runs, log_samples, Clock};
use crate::poselog::PoseLog;

/// Arguments of `figurine tokens`.
#[derive(Args, Debug)]
pub struct TokensArgs {
    /// Print only the token string (space-separated, STILL as `_`).
    #[arg(long)]
    pub compact: bool,
    /// The pose log (CSV).
    pub log: PathBuf,
}

/// `figurine tokens`.
pub fn run(args: &TokensArgs) -> Result<()> {
    let log = PoseLog::read_path(&args.log)?;
    let (samples, _) = log_samples(&log);
    let clock = Clock::new(&log, &samples);
    let runs = log_runs(&samples);
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    if args.compact {
        let s: Vec<String> = runs
            .iter()
            .map(|r| TokenName(r.token).to_string())
            .collect();
        writeln!(out, "{}", s.join(" "))?;
    } else {
        for r in &runs {
            let n = r.acc.n.max(1) as f32;
            writeln!(
                out,
                "{:>9.3} {:>9.3}  {:<10} speed {:.3} m/s  turn {:.2} rad/s",
                clock.time_of(r.start.0),
                clock.time_of(r.end.0),
                TokenName(r.token).to_string(),
                r.acc.sum[SPEED] / n,
                r.acc.turn_sum() / n,
            )?;
        }
    }
    out.flush()?;
    Ok(())
}
