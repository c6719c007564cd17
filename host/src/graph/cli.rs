//! `figurine graph build | synth | eval`, and the subcommands of [`super::job_cli`].

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, Subcommand};

use crate::motion::{write_bvh_path, write_glb_path};

use super::build::{build_graph, BuildParams};
use super::eval::{evaluate, read_labels};
use super::graph::{MotionGraph, Variant};
use super::job_cli::{merge_cmd, plan_cmd, tile_cmd, MergeArgs, PlanArgs, TileArgs};
use super::roles::{read_overrides, RoleOverrides};
use super::source::{load_clip, load_clips, GraphClip};
use super::style::ComponentWeights;
use super::synth::{best_start, plan, reference_style, render, Chooser, Rng};
use super::{GraphError, FPS, WINDOW};

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

// Options shared by `graph build` and `graph plan`.
#[derive(Args, Debug)]
pub(super) struct BuildOpts {
    /// Role override file: JSON object role → joint name (e.g. {"left_hand": "forearm.L_end"}).
    #[arg(long)]
    roles: Option<PathBuf>,
    /// Posture-correlation threshold T_MG ∈ [0, 1].
    #[arg(long, default_value_t = 0.9)]
    t_mg: f32,
    /// Style-correlation threshold T_LMA ∈ [0, 1].
    #[arg(long, default_value_t = 0.8)]
    t_lma: f32,
    /// LMA component weights body,effort,shape,space.
    #[arg(long, default_value = "0.25,0.25,0.25,0.25")]
    weights: String,
    /// Kernel tile side in windows.
    #[arg(long, default_value_t = 256)]
    tile: usize,
    /// Hide progress bars.
    #[arg(long)]
    quiet: bool,
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

/// Expands folders into their clip files (sorted), keeping files as given.
pub fn expand_inputs(inputs: &[PathBuf]) -> Result<Vec<PathBuf>, GraphError> {
    let mut out = Vec::new();
    for p in inputs {
        if p.is_dir() {
            let rd = std::fs::read_dir(p).map_err(|source| GraphError::Io {
                path: p.clone(),
                source,
            })?;
            let mut files: Vec<PathBuf> = rd
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|f| {
                    let ext = f
                        .extension()
                        .map(|e| e.to_string_lossy().to_ascii_lowercase());
                    matches!(ext.as_deref(), Some("bvh") | Some("txt"))
                })
                .collect();
            files.sort();
            out.extend(files);
        } else {
            out.push(p.clone());
        }
    }
    Ok(out)
}

fn overrides(path: Option<&Path>) -> Result<RoleOverrides, GraphError> {
    path.map(read_overrides)
        .transpose()
        .map(Option::unwrap_or_default)
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

/// Clips, role overrides and parameters from the shared build options.
pub(super) fn load(
    inputs: &[PathBuf],
    o: &BuildOpts,
) -> anyhow::Result<(Vec<GraphClip>, RoleOverrides, BuildParams)> {
    for (name, t) in [("--t-mg", o.t_mg), ("--t-lma", o.t_lma)] {
        anyhow::ensure!(
            (0.0..=1.0).contains(&t),
            "{name} must be within 0..1, got {t}"
        );
    }
    let weights = ComponentWeights::parse(&o.weights).map_err(anyhow::Error::msg)?;
    let roles = overrides(o.roles.as_deref())?;
    let files = expand_inputs(inputs)?;
    let given = || {
        inputs
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    anyhow::ensure!(
        !files.is_empty(),
        "no clip files (.bvh, DeepMimic .txt) in {}",
        given()
    );
    let clips = load_clips(&files, &roles)?;
    anyhow::ensure!(
        !clips.is_empty(),
        "no clip in {} is at least one window ({WINDOW} frames at {FPS} fps) long; nothing to build",
        given()
    );
    let rigs: std::collections::BTreeSet<String> = clips.iter().map(|c| c.rig_key()).collect();
    if rigs.len() > 1 {
        eprintln!(
            "note: {} different rigs; they are compared through their joint roles, and synthesis \
             only splices clips of the same rig",
            rigs.len()
        );
    }
    let p = BuildParams {
        t_mg: o.t_mg,
        t_lma: o.t_lma,
        weights,
        tile: o.tile,
        progress: !o.quiet,
        ..BuildParams::default()
    };
    Ok((clips, roles, p))
}

fn build(a: BuildArgs) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let (clips, roles, p) = load(&a.clips, &a.opts)?;
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
        "time: LMA {:.2} s, posture {:.2} s, style {:.2} s, total {:.2} s; wrote {}",
        st.lma_seconds,
        st.posture_seconds,
        st.style_seconds,
        t0.elapsed().as_secs_f64(),
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
