//! The `figurine` command-line tool: a thin dispatcher; each subcommand lives in its module.

use clap::{Parser, Subcommand};
#[cfg(feature = "render")]
use figurine_host::render;
use figurine_host::{anim, graph, link, recognize, synth, track};

/// figurine: play with a toy, get a character animation.
#[derive(Parser, Debug)]
#[command(name = "figurine", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// Subcommands, in data-flow order.
#[derive(Subcommand, Debug)]
enum Command {
    /// Generate synthetic spatial motion doodles (seeded, labelled pose logs).
    Synth(synth::cli::SynthArgs),
    /// Print the motion-token runs of a pose log (what patterns are written in).
    Tokens(recognize::tokens::TokensArgs),
    /// Learn (or replace) an action's pattern from example pose logs.
    Learn(recognize::learn::LearnArgs),
    /// Train the Laban Time/Weight classifiers from labelled one-gesture logs.
    TrainEffort(recognize::report::TrainEffortArgs),
    /// Run the recognizer on a pose log and print the recognised actions.
    Simulate(recognize::simulate::SimulateArgs),
    /// Turn a motion-capture take (BVH or DeepMimic) into a figurine pose log: a real doodle.
    Doodle(recognize::doodle::DoodleArgs),
    /// Evaluate recognition and effort accuracy on synthetic doodles (seed 000 Fig. 7-9);
    /// `eval rest`: false alarms per hour at rest; `eval sweep`: robustness to noise, rate, scale.
    Eval(recognize::eval_cli::EvalCli),
    /// List serial ports (and, with --probe, the figurines on them).
    Devices(link::cli::DevicesArgs),
    /// Store an action library and effort model on figurines (kept across power cuts).
    Upload(link::cli::UploadArgs),
    /// Run a pose log through a figurine; prints events like `simulate --jsonl`.
    Replay(link::cli::ReplayArgs),
    /// Stream poses to figurines live, print events as they arrive, record the session.
    Live(link::live::LiveArgs),
    /// Assemble a character animation (BVH, optional .glb) from actions and the doodle.
    Animate(anim::cli::AnimateArgs),
    /// Judge whether motion looks human: foot penetration, floating, skating, torso tilt,
    /// knees and elbows bent backwards, root pops (any BVH or DeepMimic clip).
    Check(anim::check::CheckArgs),
    /// Inspect motion clips (`clip stages CLIP`).
    Clip(anim::cli::ClipArgs),
    /// Style-coherent motion graphs: build (or plan, tile, merge across machines), synth, eval (seed 003).
    Graph(graph::cli::GraphArgs),
    /// Render an animation headless to a GIF, MP4, PNG still or folder of PNG frames.
    #[cfg(feature = "render")]
    Render(render::cli::RenderArgs),
    /// Show an animation in a window: orbit camera, play/pause/scrub/speed.
    #[cfg(feature = "render")]
    View(render::cli::ViewArgs),
    /// Track a printed AprilTag in a video or a webcam: a pose log anyone can make
    /// (`track print-tag`, `track calibrate`, `track render`, `track bench`).
    Track(track::cli::TrackArgs),
    /// Print the wire-protocol version this host speaks.
    ProtocolVersion,
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    #[cfg(feature = "render")]
    render::gpu::ensure_runtime_dir();
    match cli.command {
        Command::Synth(a) => synth::cli::run(a)?,
        Command::Tokens(a) => recognize::tokens::run(&a)?,
        Command::Learn(a) => recognize::learn::run(&a)?,
        Command::TrainEffort(a) => recognize::report::run(&a)?,
        Command::Simulate(a) => recognize::simulate::run(&a)?,
        Command::Doodle(a) => recognize::doodle::run(&a)?,
        Command::Eval(a) => recognize::eval_cli::run(&a)?,
        Command::Devices(a) => link::cli::devices(&a)?,
        Command::Upload(a) => link::cli::upload(&a)?,
        Command::Replay(a) => link::cli::replay(&a)?,
        Command::Live(a) => link::live::live(&a)?,
        Command::Animate(a) => anim::cli::run_animate(&a)?,
        Command::Check(a) => anim::check::run(&a)?,
        Command::Clip(a) => anim::cli::run_clip(&a)?,
        Command::Graph(a) => graph::cli::run(a)?,
        Command::Track(a) => track::cli::run(&a)?,
        #[cfg(feature = "render")]
        Command::Render(a) => render::cli::run_render(&a)?,
        #[cfg(feature = "render")]
        Command::View(a) => render::cli::run_view(&a)?,
        Command::ProtocolVersion => {
            println!(
                "figurine protocol version {}",
                figurine_protocol::PROTOCOL_VERSION
            );
        }
    }
    Ok(())
}
