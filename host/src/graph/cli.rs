//! `figurine graph build | synth | eval`, and the subcommands of [`super::job_cli`].

use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, Subcommand};

use crate::motion::{write_bvh_path, write_glb_path};

use super::build::build_graph;
use super::eval::{evaluate, read_labels};
use super::graph::{MotionGraph, Variant};
use super::inputs::{load, BuildOpts};
use super::job_cli::{merge_cmd, plan_cmd, tile_cmd, MergeArgs, PlanArgs, TileArgs};
use super::source::load_clip;
use super::synth::{best_start, plan, reference_style, render, Chooser, Rng};
use super::{cpu_seconds, peak_memory_mib, GraphError, FPS};

/// Style-coherent motion graphs (seed 003).
#[derive(Args, Debug)]
pub struct GraphArgs {
    #[command(subcommand)]
    command: GraphCommand,
}

#[derive(Subcommand, Debug)]
enum GraphCommand {
    /// Build a graph from BVH / DeepMimic clips (files or folders), on this machine.
    Build(BuildArgs),
    /// Plan a distributed build: features, manifest and Slurm scripts into a job folder.
    Plan(PlanArgs),
    /// Compute one tile of a planned job (a Slurm array task runs one).
    Tile(TileArgs),
    /// Merge a job's tiles into the graph file (byte-identical to `graph build`).
    Merge(MergeArgs),
    /// Synthesise a motion by walking a graph.
    Synth(SynthArgs),
    /// Evaluate MG vs LMA-MG with per-clip labels (§5.2–5.3).
    Eval(EvalArgs),
}

#[derive(Args, Debug)]
struct BuildArgs {
    /// Clip files (.bvh, DeepMimic .txt next to humanoid.urdf) or folders of them.
    #[arg(required = true)]
    clips: Vec<PathBuf>,
    /// Output graph file.
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    opts: BuildOpts,
}

#[derive(Args, Debug)]
struct SynthArgs {
    /// Graph file from `figurine graph build`.
    graph: PathBuf,
    /// Length of the output, seconds (default: the example's length, else 60).
    #[arg(long)]
    seconds: Option<f32>,
    /// Output BVH file.
    #[arg(long)]
    out: PathBuf,
    /// Also write a binary glTF (.glb), in metres for a 1.7 m body.
    #[arg(long)]
    glb: Option<PathBuf>,
    /// Follow this reference clip's style over time (synthesis by example, §5.4).
    #[arg(long)]
    example: Option<PathBuf>,
    /// Graph variant to walk.
    #[arg(long, value_enum, default_value = "lma")]
    variant: Variant,
    /// Seed of the start frame.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

#[derive(Args, Debug)]
struct EvalArgs {
    /// Graph file.
    graph: PathBuf,
    /// Labels per clip: JSON object clip name → label.
    #[arg(long)]
    labels: PathBuf,
    /// Walks per variant.
    #[arg(long, default_value_t = 3)]
    runs: usize,
    /// Transitions per walk.
    #[arg(long, default_value_t = 1000)]
    transitions: usize,
    /// Seed of the walks.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Also write the report as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
}

/// Runs a `figurine graph …` command.
pub fn run(args: GraphArgs) -> anyhow::Result<()> {
    match args.command {
        GraphCommand::Build(a) => build(a),
        GraphCommand::Plan(a) => plan_cmd(a),
        GraphCommand::Tile(a) => tile_cmd(a),
        GraphCommand::Merge(a) => merge_cmd(a),
        GraphCommand::Synth(a) => synth(a),
        GraphCommand::Eval(a) => eval(a),
    }
}

fn build(a: BuildArgs) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let (clips, roles, p) = load(&a.clips, &a.opts)?;
    let load_seconds = t0.elapsed().as_secs_f64();
    let (mut g, st) = build_graph(&clips, &p)?;
    g.roles = roles;
    g.save(&a.out)?;
    let mg = g.count(Variant::Mg, None, None);
    let lma = g.count(Variant::Lma, None, None);
    let scc = |v| {
        g.largest_scc(&g.transitions(v, None, None))
            .iter()
            .filter(|&&b| b)
            .count()
    };
    println!(
        "{} clips, {} frames at {FPS} fps, {} window pairs, {} local maxima",
        clips.len(),
        st.frames,
        st.pairs,
        st.local_minima
    );
    println!(
        "transitions: MG {mg} (T_MG {}), LMA-MG {lma} (T_LMA {}), pruned {:.1}%",
        p.t_mg,
        p.t_lma,
        if mg > 0 {
            100.0 * (1.0 - lma as f64 / mg as f64)
        } else {
            0.0
        }
    );
    println!(
        "largest strongly connected part: MG {} frames, LMA-MG {} frames",
        scc(Variant::Mg),
        scc(Variant::Lma)
    );
    println!(
        "time: load {:.2} s, LMA {:.2} s, posture {:.2} s (posture cpu {:.2} s), style {:.2} s, total {:.2} s, cpu {:.2} s, peak {:.0} MiB; wrote {}",
        load_seconds,
        st.lma_seconds,
        st.posture_seconds,
        st.posture_cpu_seconds,
        st.style_seconds,
        t0.elapsed().as_secs_f64(),
        cpu_seconds().unwrap_or(f64::NAN),
        peak_memory_mib().unwrap_or(f64::NAN),
        a.out.display()
    );
    Ok(())
}

fn synth(a: SynthArgs) -> anyhow::Result<()> {
    let g = MotionGraph::load(&a.graph)?;
    let mut rng = Rng::new(a.seed);
    let (p, name) = match &a.example {
        Some(ex) => {
            let reference = load_clip(ex, &g.roles)?;
            let style = reference_style(&g, &reference);
            anyhow::ensure!(
                !style.is_empty(),
                "{}: shorter than one window",
                ex.display()
            );
            let frames = a
                .seconds
                .map(|s| (s * FPS) as usize)
                .unwrap_or(reference.len())
                .max(1);
            let start = best_start(&g, &style);
            (
                plan(
                    &g,
                    a.variant,
                    &Chooser::Example(&style),
                    frames,
                    start,
                    &mut rng,
                )?,
                "by_example",
            )
        }
        None => {
            let frames = (a.seconds.unwrap_or(60.0) * FPS) as usize;
            anyhow::ensure!(frames > 0, "--seconds must be positive");
            (
                plan(
                    &g,
                    a.variant,
                    &Chooser::Similarity(a.variant),
                    frames,
                    None,
                    &mut rng,
                )?,
                "highest_similarity",
            )
        }
    };
    let clip = render(&g, &p, name)?;
    write_bvh_path(&clip, &a.out)?;
    let mut used: Vec<&str> = p
        .frames
        .iter()
        .filter_map(|&f| g.clip_of(f))
        .map(|c| g.clips[c].name.as_str())
        .collect();
    used.dedup();
    println!(
        "{} frames ({:.1} s), {} transitions, clips: {}; wrote {}",
        clip.len(),
        clip.len() as f32 / FPS,
        p.cuts.len(),
        used.join(" → "),
        a.out.display()
    );
    let cuts: Vec<String> = p
        .cuts
        .iter()
        .map(|(k, t)| {
            let name = |f: u32| {
                g.clip_of(f)
                    .map(|c| g.clips[c].name.as_str())
                    .unwrap_or("?")
            };
            format!(
                "{:.2}s {}→{} (posture {:.2}, style {:.2})",
                *k as f32 / FPS,
                name(t.from),
                name(t.to),
                t.posture,
                t.style
            )
        })
        .collect();
    println!("transitions at: {}", cuts.join("; "));
    if let Some(glb) = &a.glb {
        let scale = p
            .frames
            .first()
            .and_then(|&f| g.clip_of(f))
            .map(|c| g.clips[c].scale)
            .unwrap_or(1.0);
        write_glb_path(&clip, scale, glb)?;
        println!("wrote {}", glb.display());
    }
    Ok(())
}

fn eval(a: EvalArgs) -> anyhow::Result<()> {
    let g = MotionGraph::load(&a.graph)?;
    let labels = read_labels(&a.labels, &g)?;
    let r = evaluate(&g, &labels, a.runs, a.transitions, a.seed)?;
    print!("{r}");
    if let Some(j) = &a.json {
        let text = serde_json::to_string_pretty(&r)?;
        std::fs::write(j, text).map_err(|source| GraphError::Io {
            path: j.clone(),
            source,
        })?;
    }
    Ok(())
}
