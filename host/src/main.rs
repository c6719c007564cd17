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
    /// Style-coherent motion graphs: build, synth, eval (seed 003).
    Graph(figurine_host::graph::cli::GraphArgs),
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::ProtocolVersion => {
            println!("figurine-host {}", env!("CARGO_PKG_VERSION"));
        }
        Command::Graph(args) => figurine_host::graph::cli::run(args)?,
    }
    Ok(())
}
