//! The `figurine` command-line tool.

use clap::{Parser, Subcommand};

/// figurine: play with a toy, get a character animation.
#[derive(Parser, Debug)]
#[command(name = "figurine", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// Subcommands; each lives in its own module of the library.
#[derive(Subcommand, Debug)]
enum Command {
    /// Print the wire-protocol version this host speaks.
    ProtocolVersion,
    /// Generate synthetic spatial motion doodles (seeded, labelled pose logs).
    Synth(figurine_host::synth::cli::SynthArgs),
    /// Render an animation headless to a GIF, MP4, PNG still or folder of PNG frames.
    Render(figurine_host::render::cli::RenderArgs),
    /// Show an animation in a window: orbit camera, play/pause/scrub/speed.
    View(figurine_host::render::cli::ViewArgs),
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::ProtocolVersion => {
            println!("figurine-host {}", env!("CARGO_PKG_VERSION"));
        }
        Command::Synth(args) => figurine_host::synth::cli::run(args)?,
        Command::Render(args) => figurine_host::render::cli::run_render(&args)?,
        Command::View(args) => figurine_host::render::cli::run_view(&args)?,
    }
    Ok(())
}
