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
    /// Render an animation headless to a GIF, MP4, PNG still or folder of PNG frames.
    Render(figurine_host::render::cli::RenderArgs),
    /// Show an animation in a window: orbit camera, play/pause/scrub/speed.
    View(figurine_host::render::cli::ViewArgs),
    /// Assemble a character animation (BVH, optional .glb) from actions and the doodle.
    Animate(figurine_host::anim::cli::AnimateArgs),
    /// Inspect motion clips (`clip stages CLIP`).
    Clip(figurine_host::anim::cli::ClipArgs),
    /// Generate synthetic spatial motion doodles (seeded, labelled pose logs).
    Synth(figurine_host::synth::cli::SynthArgs),
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Animate(a) => figurine_host::anim::cli::run_animate(&a)?,
        Command::Clip(a) => figurine_host::anim::cli::run_clip(&a)?,
        Command::ProtocolVersion => {
            println!("figurine-host {}", env!("CARGO_PKG_VERSION"));
        }
        Command::Render(args) => figurine_host::render::cli::run_render(&args)?,
        Command::View(args) => figurine_host::render::cli::run_view(&args)?,
        Command::Synth(args) => figurine_host::synth::cli::run(args)?,
    }
    Ok(())
}
