//! `figurine eval`: the accuracy tables ([`super::eval`]; over several seed pairs,
//! [`super::eval_pairs`]) or one of the benchmarks, each in its own module.

use anyhow::{bail, Result};
use clap::{Args, Subcommand};

use super::eval::EvalArgs;

/// Arguments of `figurine eval`.
#[derive(Args, Debug)]
#[command(args_conflicts_with_subcommands = true)]
pub struct EvalCli {
    /// The accuracy tables' options.
    #[command(flatten)]
    pub args: EvalArgs,
    /// A benchmark instead of the accuracy tables.
    #[command(subcommand)]
    pub command: Option<EvalCommand>,
}

/// The benchmarks of `figurine eval`.
#[derive(Subcommand, Debug, Clone)]
pub enum EvalCommand {
    /// False alarms per hour at rest: hours of a figurine held, set down or mounted, under
    /// every tracker level, with the shipped library and libraries learnt from 3 examples.
    Rest(super::rest_bench::RestBenchArgs),
    /// Robustness: isolated accuracy and sequence F1 as the tracker's noise, its rate or the
    /// doodle's scale is swept.
    Sweep(super::sweep::SweepArgs),
    /// Real doodles: motion-capture takes of people turned into figurine logs and labelled
    /// by hand (`host/assets/real_takes.json`), recognised; recall and precision.
    Real(super::real_bench::RealBenchArgs),
    /// Repetitions: one action played 2–4 times back to back is as many events (one for a
    /// walk, run, sidestep, wave or turn played on).
    Repeat(super::repeat_bench::RepeatArgs),
}

/// `figurine eval`.
pub fn run(cli: &EvalCli) -> Result<()> {
    match &cli.command {
        Some(EvalCommand::Rest(a)) => super::rest_bench::run(a),
        Some(EvalCommand::Sweep(a)) => super::sweep::run(a),
        Some(EvalCommand::Real(a)) => super::real_bench::run(a),
        Some(EvalCommand::Repeat(a)) => super::repeat_bench::run(a),
        None if cli.args.pairs == 0 => bail!("--pairs must be at least 1"),
        None if cli.args.pairs > 1 => super::eval_pairs::run(&cli.args),
        None => super::eval::run(&cli.args),
    }
}
