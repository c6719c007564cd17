//! `figurine animate` and `figurine clip stages`: argument structs and their runners.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};

use super::assemble::{assemble_guided, AssembleOptions, Assembly};
use super::graph_cuts::GraphGuide;
use super::library::{size_warnings, ClipLibrary};
use super::phrasing::detect_stages;
use super::plot::save_contact_sheet;
use super::trajectory::DEFAULT_WORLD_SCALE;
use crate::events::{read_events_path, ActionRecord};
use crate::motion::{read_take, write_bvh_path, write_glb_path, Clip};
use crate::poselog::PoseLog;

/// `figurine animate`: assemble a character animation from recognised actions and the doodle.
#[derive(clap::Args, Debug)]
pub struct AnimateArgs {
    /// Recognizer action library (used when recognising LOG; default: built-in).
    #[arg(long)]
    pub library: Option<PathBuf>,
    /// Recognizer effort model (used when recognising LOG; default: built-in).
    #[arg(long)]
    pub effort: Option<PathBuf>,
    /// Clip library (action → clip); the built-in DeepMimic library when absent.
    #[arg(long)]
    pub clips: Option<PathBuf>,
    /// Recognised actions as JSON lines (the output of `figurine simulate`).
    #[arg(long)]
    pub events: Option<PathBuf>,
    /// Ground-truth labels of `figurine synth` (JSON array) used as the events, with each
    /// Laban class mapped to ±[`LABEL_EFFORT`] (demo and tests without recognition).
    #[arg(long, conflicts_with = "events")]
    pub labels: Option<PathBuf>,
    /// The doodle's pose log, whose path the character follows (defaults to LOG).
    #[arg(long)]
    pub doodle: Option<PathBuf>,
    /// Pose log to recognise (and follow).
    pub log: Option<PathBuf>,
    /// Output BVH file.
    #[arg(long)]
    pub out: PathBuf,
    /// Also write a binary glTF (.glb).
    #[arg(long)]
    pub glb: Option<PathBuf>,
    /// Toy metres → character metres: the size of the doodled path, wherever a person can
    /// cover it in the doodle's time (a walk or run too fast for that, at this scale, covers a
    /// shrunk copy of its path).
    #[arg(long, default_value_t = DEFAULT_WORLD_SCALE)]
    pub world_scale: f32,
    /// Output frames per second.
    #[arg(long, default_value_t = 30.0)]
    pub fps: f32,
    /// Also draw a contact sheet (root path over the doodle path, stick figures) to this PNG.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Motion graph (`figurine graph build … --out G.bin`) over the library's source clips:
    /// transitions between actions follow its LMA-MG transitions, preferring destinations
    /// whose Effort features match the incoming action's recognised effort.
    #[arg(long)]
    pub graph: Option<PathBuf>,
}

/// Effort value given to a labelled Laban class (sudden/strong +, sustained/light −).
pub const LABEL_EFFORT: f64 = 0.8;

/// Reads `figurine synth` labels as action events (classes → ±[`LABEL_EFFORT`], neutral 0).
pub fn read_label_events(path: &Path) -> anyhow::Result<Vec<ActionRecord>> {
    let text = std::fs::read_to_string(path).with_context(|| path.display().to_string())?;
    let labels: Vec<crate::synth::sequence::Label> = serde_json::from_str(&text)
        .map_err(|e| anyhow::anyhow!("{}:{}: {e}", path.display(), e.line()))?;
    Ok(label_events(labels))
}

/// `figurine synth` labels as action events (classes → ±[`LABEL_EFFORT`], neutral 0).
pub fn label_events(labels: Vec<crate::synth::sequence::Label>) -> Vec<ActionRecord> {
    use crate::synth::effort::{TimeClass, WeightClass};
    labels
        .into_iter()
        .map(|l| ActionRecord {
            action: l.action,
            start: l.start,
            end: l.end,
            time: match l.time_class {
                TimeClass::Sudden => LABEL_EFFORT,
                TimeClass::Sustained => -LABEL_EFFORT,
                TimeClass::Neutral => 0.0,
            },
            weight: match l.weight_class {
                WeightClass::Strong => LABEL_EFFORT,
                WeightClass::Light => -LABEL_EFFORT,
                WeightClass::Neutral => 0.0,
            },
            distance: 0,
        })
        .collect()
}

/// `figurine clip …`: inspect motion clips.
#[derive(clap::Args, Debug)]
pub struct ClipArgs {
    /// What to do.
    #[command(subcommand)]
    pub command: ClipCommand,
}

/// Subcommands of `figurine clip`.
#[derive(clap::Subcommand, Debug)]
pub enum ClipCommand {
    /// Print the motion stages (§6.1) of a clip: an action of the clip library, a .bvh file or
    /// a DeepMimic motion file.
    Stages {
        /// Action name (`ACTION:VARIANT` for a variant), .bvh file or DeepMimic .txt/.json file.
        clip: String,
        /// Clip library to look action names up in (default: built-in).
        #[arg(long)]
        clips: Option<PathBuf>,
        /// URDF for DeepMimic files (default: the data folder's humanoid.urdf).
        #[arg(long)]
        urdf: Option<PathBuf>,
    },
    /// List every action's clip variants with their Laban effort estimates (from their
    /// Effort-component LMA features, or from a motion graph), and which one each of the four
    /// effort corners would play.
    Variants {
        /// Clip library (default: built-in).
        #[arg(long)]
        clips: Option<PathBuf>,
        /// Motion graph whose effort estimates to use where it holds the variants' clips.
        #[arg(long)]
        graph: Option<PathBuf>,
    },
    /// Draw a clip's contact sheet (root path from above, twelve stick figures from the side)
    /// to a PNG.
    Plot {
        /// Action name (`ACTION:VARIANT` for a variant), .bvh file or DeepMimic .txt/.json file.
        clip: String,
        /// Output PNG.
        #[arg(long)]
        out: PathBuf,
        /// Clip library to look action names up in (default: built-in).
        #[arg(long)]
        clips: Option<PathBuf>,
        /// URDF for DeepMimic files (default: the data folder's humanoid.urdf).
        #[arg(long)]
        urdf: Option<PathBuf>,
        /// Length unit → metres (e.g. 0.01 for centimetre BVH).
        #[arg(long, default_value_t = 1.0)]
        scale: f32,
        /// The rig's facing direction in its clips, x,y,z (DeepMimic: 1,0,0).
        #[arg(long, default_value = "1,0,0")]
        forward: String,
    },
    /// Search motion-capture takes for sideways stepping (see [`super::sideways`]).
    Sideways {
        /// .bvh files or DeepMimic .txt/.json files.
        #[arg(required = true)]
        takes: Vec<PathBuf>,
        /// URDF for DeepMimic files (default: the data folder's humanoid.urdf).
        #[arg(long)]
        urdf: Option<PathBuf>,
    },
}

/// Runs `figurine animate`.
pub fn run_animate(args: &AnimateArgs) -> anyhow::Result<()> {
    let events = match (&args.events, &args.labels, &args.log) {
        (Some(e), _, _) => read_events_path(e)?,
        (None, Some(l), _) => read_label_events(l)?,
        (None, None, Some(log)) => recognise(log, args)?,
        (None, None, None) => bail!(
            "give --events EVENTS.jsonl (or --labels LABELS.json) and --doodle LOG.csv, or a LOG \
             to recognise"
        ),
    };
    // Where the events came from, for error messages.
    let source = args
        .events
        .as_ref()
        .or(args.labels.as_ref())
        .or(args.log.as_ref())
        .map(|p| p.display().to_string())
        .unwrap_or_default();
    if events.is_empty() {
        bail!("{source}: no actions to animate (no events in it)");
    }
    let doodle_path = args.doodle.as_ref().or(args.log.as_ref());
    let doodle = doodle_path.map(|p| PoseLog::read_path(p)).transpose()?;
    let library = match &args.clips {
        Some(p) => ClipLibrary::read_path(p)?,
        None => ClipLibrary::default_library()?,
    };
    let actions: Vec<&str> = events.iter().map(|e| e.action.as_str()).collect();
    let clips = library.load(actions.iter().copied())?;
    for w in size_warnings(&clips) {
        eprintln!("warning: {}: {w}", library.origin);
    }
    let opts = AssembleOptions {
        world_scale: args.world_scale,
        fps: args.fps,
        ..AssembleOptions::default()
    };
    let guide = args.graph.as_deref().map(GraphGuide::load).transpose()?;
    let asm = assemble_guided(
        &events,
        doodle.as_ref(),
        &clips,
        library.forward(),
        &opts,
        guide.as_ref(),
    )
    .with_context(|| format!("animating the actions of {source}"))?;
    write_bvh_path(&asm.clip, &args.out)?;
    if let Some(glb) = &args.glb {
        write_glb_path(&asm.clip, 1.0, glb)?;
    }
    if let Some(png) = &args.plot {
        plot_assembly(&asm, library.forward(), png)?;
    }
    print_summary(&asm, &args.out, args.glb.as_deref());
    Ok(())
}

/// Runs the recognizer (the same code as `figurine simulate`) over a pose log.
fn recognise(log: &Path, args: &AnimateArgs) -> anyhow::Result<Vec<ActionRecord>> {
    use crate::recognize::simulate::{load_effort, load_library, simulate_log};
    let (lib, blob) = load_library(args.library.as_deref())?;
    let effort = load_effort(args.effort.as_deref())?;
    let pose_log = PoseLog::read_path(log)?;
    let sim = simulate_log(&pose_log, &lib.names(), &blob, Some(effort))
        .with_context(|| format!("recognising {}", log.display()))?;
    if sim.records.is_empty() {
        bail!(
            "the recognizer found no actions in {} (try `figurine tokens` / `figurine simulate` \
             on it, or pass --events)",
            log.display()
        );
    }
    Ok(sim.records)
}

/// Draws the assembly's contact sheet: every action's path and a figure per action.
pub fn plot_assembly(asm: &Assembly, forward: glam::Vec3, png: &Path) -> anyhow::Result<()> {
    let target: Vec<glam::Vec3> = asm
        .placements
        .iter()
        .filter(|p| p.moving)
        .flat_map(|p| {
            p.path
                .pts
                .iter()
                .map(|q| glam::Vec3::new(q.x, 0.0, q.y))
                .chain([glam::Vec3::NAN])
        })
        .collect();
    // Two to four figures per action, twelve at most.
    let per = (super::plot::MAX_FIGURES / asm.placements.len().max(1)).clamp(2, 4);
    let frames: Vec<usize> = asm
        .placements
        .iter()
        .flat_map(|p| {
            let n = p.end_frame - p.start_frame;
            (0..per).map(move |k| p.start_frame + n * (2 * k + 1) / (2 * per))
        })
        .collect();
    save_contact_sheet(&asm.clip, &frames, &target, forward, png)
}

fn print_summary(asm: &Assembly, out: &Path, glb: Option<&Path>) {
    let c = &asm.clip;
    println!(
        "{}: {} frames @ {:.0} fps ({:.2} s from log time {:.2} s), {} actions, {} transitions",
        out.display(),
        c.len(),
        c.fps(),
        c.duration(),
        asm.t_origin,
        asm.placements.len(),
        asm.transitions.len()
    );
    if let Some(g) = glb {
        println!("{}: binary glTF", g.display());
    }
    for ((i, j), cut) in asm.transitions.iter().zip(&asm.graph_cuts) {
        match cut {
            Some(c) => println!(
                "  transition frames {i}-{j}: motion graph (source {:.2} s → {:.2} s, style {:.2}, effort match {:.2})",
                c.from_time, c.to_time, c.style, c.effort_match
            ),
            None => println!("  transition frames {i}-{j}: posture distance"),
        }
    }
    for p in &asm.placements {
        let stages: Vec<String> = p
            .stages
            .iter()
            .map(|(s, a, b)| format!("{s} {a:.2}-{b:.2}"))
            .collect();
        let variant = p
            .variant
            .as_ref()
            .map(|v| {
                format!(
                    "  variant {} ({}/{}, its effort Lt {:+.2} Lw {:+.2} by {}, match {:.2}; transferred Lt {:+.2} Lw {:+.2})",
                    v.name,
                    v.index + 1,
                    v.of,
                    v.variant_effort.time,
                    v.variant_effort.weight,
                    if v.by_graph { "graph" } else { "clip" },
                    v.effort_match,
                    p.applied_effort.time,
                    p.applied_effort.weight
                )
            })
            .unwrap_or_default();
        println!(
            "  {:9} {:6.2}-{:6.2} s  {}{}  path {:.2} m  [{}]{variant}",
            p.action,
            asm.t_origin as f32 + p.start_frame as f32 * c.frame_time,
            asm.t_origin as f32 + p.end_frame as f32 * c.frame_time,
            if p.moving { "moving" } else { "in place" },
            if p.cycles > 1 {
                format!(" ×{}", p.cycles)
            } else {
                String::new()
            },
            p.path.length(),
            stages.join(", ")
        );
    }
    let contact_frames: Vec<usize> = asm
        .contacts
        .iter()
        .map(|l| l.iter().filter(|c| **c).count())
        .collect();
    println!(
        "  ground: deepest penetration {:.3} m fixed (IK on {} frames, root raised on {}); foot contact frames per leg {:?}",
        asm.ground.max_depth, asm.ground.ik_frames, asm.ground.raised_frames, contact_frames
    );
}

/// Loads a clip named on the command line: a library action, a .bvh or a DeepMimic file.
pub fn load_named_clip(
    name: &str,
    clips: Option<&Path>,
    urdf: Option<&Path>,
) -> anyhow::Result<(Clip, bool)> {
    let p = Path::new(name);
    let ext = p
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("bvh") => Ok((read_take(p, urdf)?, false)),
        Some("txt") | Some("json") if p.is_file() => Ok((read_take(p, urdf)?, false)),
        _ => {
            let lib = match clips {
                Some(c) => ClipLibrary::read_path(c)?,
                None => ClipLibrary::default_library()?,
            };
            // `ACTION` is the action's primary clip, `ACTION:VARIANT` one of its variants.
            let (action, variant) = match name.split_once(':') {
                Some((a, v)) => (a, Some(v)),
                None => (name, None),
            };
            let mut loaded = lib.load([action]).with_context(|| {
                format!(
                    "{name} is neither a clip file nor an action of {}",
                    lib.origin
                )
            })?;
            let ac = loaded.remove(action).context("action vanished")?;
            let ac = match variant {
                None => ac,
                Some(v) => {
                    let names: Vec<String> = ac.variants().map(|c| c.variant.clone()).collect();
                    ac.variants()
                        .find(|c| c.variant == v)
                        .cloned()
                        .with_context(|| {
                            format!(
                                "action {action} of {} has no variant {v:?} (it has: {})",
                                lib.origin,
                                names.join(", ")
                            )
                        })?
                }
            };
            Ok((ac.clip, ac.cyclic))
        }
    }
}

/// Runs `figurine clip …`.
pub fn run_clip(args: &ClipArgs) -> anyhow::Result<()> {
    match &args.command {
        ClipCommand::Stages { clip, clips, urdf } => {
            let (c, cyclic) = load_named_clip(clip, clips.as_deref(), urdf.as_deref())?;
            let ph = detect_stages(&c);
            println!(
                "{}: {} frames @ {:.1} fps ({:.2} s), {} stages{}",
                c.name,
                c.len(),
                c.fps(),
                c.duration(),
                ph.spans.len(),
                if cyclic {
                    " (cyclic: animate plays it as one execution stage)"
                } else {
                    ""
                }
            );
            println!("{:15} {:>11} {:>15}", "stage", "frames", "seconds");
            for s in &ph.spans {
                println!(
                    "{:15} {:>5}-{:<5} {:>7.3}-{:<7.3}",
                    s.stage.to_string(),
                    s.start,
                    s.end,
                    s.start as f32 * c.frame_time,
                    s.end as f32 * c.frame_time
                );
            }
            Ok(())
        }
        ClipCommand::Variants { clips, graph } => {
            print_variants(clips.as_deref(), graph.as_deref())
        }
        ClipCommand::Sideways { takes, urdf } => {
            super::sideways::run_sideways(takes, urdf.as_deref())
        }
        ClipCommand::Plot {
            clip,
            out,
            clips,
            urdf,
            scale,
            forward,
        } => {
            let (mut c, _) = load_named_clip(clip, clips.as_deref(), urdf.as_deref())?;
            c.scale_lengths(*scale);
            let f: Vec<f32> = forward
                .split(',')
                .map(|x| x.trim().parse::<f32>())
                .collect::<Result<_, _>>()
                .with_context(|| format!("--forward {forward:?}: expected x,y,z"))?;
            let fwd = match f.as_slice() {
                [x, y, z] => glam::Vec3::new(*x, *y, *z),
                _ => bail!("--forward {forward:?}: expected three numbers"),
            };
            let n = super::plot::MAX_FIGURES;
            let frames: Vec<usize> = (0..n)
                .map(|k| (k * c.len().saturating_sub(1)) / (n - 1))
                .collect();
            save_contact_sheet(&c, &frames, &[], fwd, out)?;
            println!("{}: {} figures of {}", out.display(), n, c.name);
            Ok(())
        }
    }
}

/// Prints `figurine clip variants`.
fn print_variants(clips: Option<&Path>, graph: Option<&Path>) -> anyhow::Result<()> {
    use crate::graph::effort::Effort;
    let lib = match clips {
        Some(c) => ClipLibrary::read_path(c)?,
        None => ClipLibrary::default_library()?,
    };
    let guide = graph.map(GraphGuide::load).transpose()?;
    let names: Vec<String> = lib.actions.keys().cloned().collect();
    let loaded = lib.load(names.iter().map(String::as_str))?;
    let corners = [
        ("sudden-strong", 0.8, 0.8),
        ("sudden-light", 0.8, -0.8),
        ("sustained-strong", -0.8, 0.8),
        ("sustained-light", -0.8, -0.8),
    ];
    println!("{}: {} actions", lib.origin, loaded.len());
    for (action, ac) in &loaded {
        if ac.alternatives.is_empty() {
            println!("  {action:10} {} (single clip)", ac.variant);
            continue;
        }
        println!("  {action:10} {} variants", 1 + ac.alternatives.len());
        for v in ac.variants() {
            let e = v.effort.unwrap_or_default();
            println!(
                "    {:12} {:6.2} s  effort from its own LMA features: Lt {:+.2} Lw {:+.2}",
                v.variant,
                v.clip.duration(),
                e.time,
                e.weight
            );
        }
        let picks: Vec<String> = corners
            .iter()
            .map(|(name, t, w)| {
                let want = Effort {
                    time: *t,
                    weight: *w,
                };
                let (v, c) = super::variants::choose_variant(ac, want, guide.as_ref());
                let by = match c {
                    Some(c) if c.by_graph => " (graph)",
                    _ => "",
                };
                format!("{name} → {}{by}", v.variant)
            })
            .collect();
        println!("    plays: {}", picks.join(", "));
    }
    Ok(())
}
