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
    /// Style-coherent motion graphs: build, synth, eval (seed 003).
    Graph(figurine_host::graph::cli::GraphArgs),
    /// Learn (or replace) an action's pattern from example pose logs.
    Learn(figurine_host::recognize::learn::LearnArgs),
    /// Train the Laban Time/Weight classifiers from labelled one-gesture logs.
    TrainEffort(figurine_host::recognize::effort_train::TrainEffortArgs),
    /// Run the recognizer on a pose log and print the recognised actions.
    Simulate(figurine_host::recognize::simulate::SimulateArgs),
    /// Print the motion-token runs of a pose log (what patterns are written in).
    Tokens(figurine_host::recognize::tokens::TokensArgs),
    /// Evaluate recognition and effort accuracy on synthetic doodles (seed 000 Fig. 7-9).
    Eval(figurine_host::recognize::eval::EvalArgs),
    /// Generate synthetic spatial motion doodles (seeded, labelled pose logs).
    Synth(figurine_host::synth::cli::SynthArgs),
    /// Render an animation headless to a GIF, MP4, PNG still or folder of PNG frames.
    Render(figurine_host::render::cli::RenderArgs),
    /// Show an animation in a window: orbit camera, play/pause/scrub/speed.
    View(figurine_host::render::cli::ViewArgs),
    /// List serial ports (and, with --probe, the figurines on them).
    Devices(figurine_host::link::cli::DevicesArgs),
    /// Store an action library and effort model on figurines (kept across power cuts).
    Upload(figurine_host::link::cli::UploadArgs),
    /// Run a pose log through a figurine; prints events like `simulate --jsonl`.
    Replay(figurine_host::link::cli::ReplayArgs),
    /// Stream poses to figurines live, print events as they arrive, record the session.
    Live(figurine_host::link::live::LiveArgs),
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Animate(a) => figurine_host::anim::cli::run_animate(&a)?,
        Command::Clip(a) => figurine_host::anim::cli::run_clip(&a)?,
        Command::ProtocolVersion => {
            println!("figurine-host {}", env!("CARGO_PKG_VERSION"));
        }
        Command::Graph(args) => figurine_host::graph::cli::run(args)?,
        Command::Learn(a) => figurine_host::recognize::learn::run(&a)?,
        Command::TrainEffort(a) => figurine_host::recognize::effort_train::run(&a)?,
        Command::Simulate(a) => figurine_host::recognize::simulate::run(&a)?,
        Command::Tokens(a) => figurine_host::recognize::tokens::run(&a)?,
        Command::Eval(a) => figurine_host::recognize::eval::run(&a)?,
        Command::Synth(args) => figurine_host::synth::cli::run(args)?,
        Command::Render(args) => figurine_host::render::cli::run_render(&args)?,
        Command::View(args) => figurine_host::render::cli::run_view(&args)?,
        Command::Devices(a) => figurine_host::link::cli::devices(&a)?,
        Command::Upload(a) => figurine_host::link::cli::upload(&a)?,
        Command::Replay(a) => figurine_host::link::cli::replay(&a)?,
        Command::Live(a) => figurine_host::link::live::live(&a)?,
    }
    Ok(())
}
