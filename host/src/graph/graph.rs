//! The motion graph: frames as nodes, transition edges, blends, strongly connected trimming, and
//! its file format.
//!
//! Nodes are the library's frames at 30 fps (global index = clip start + frame). A frame leads
//! to the next frame of its clip, and a transition edge `from → to` (both directions of every
//! stored pair) lets playback jump from window centre `from` to continue after `to`, blended
//! over [`BLEND_FRAMES`]. Every stored edge passed T_MG (the plain motion graph, MG); the ones
//! whose smoothed style similarity also passes T_LMA form the LMA-pruned graph (LMA-MG).
//!
//! Synthesis must never dead-end, so it walks only the largest strongly connected component of
//! the chosen variant, restricted to transitions between clips of the same rig (clips of
//! different rigs are compared through their roles, but a pose of one rig cannot be played on
//! another without retargeting).
//!
//! File format (`G.bin`): the bytes `FIGGRAPH`, then the [`MotionGraph`] encoded with postcard
//! (its `version` field is [`GRAPH_VERSION`]). Clip motion is not stored: the clips are re-read
//! from their recorded paths when synthesising, and their frame counts checked.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::lma::MEASUREMENTS;
use super::style::{ComponentWeights, Standardiser};
use super::{GraphError, WINDOW};

/// Parameters of a graph build.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BuildParams {
    /// Posture-correlation threshold T_MG ∈ [0, 1] (paper: 0.9).
    pub t_mg: f32,
    /// Style-correlation threshold T_LMA ∈ [0, 1] (paper: 0.8).
    pub t_lma: f32,
    /// LMA component weights of the style similarity.
    pub weights: ComponentWeights,
    /// Minimum distance in frames between two windows of the same clip for a transition.
    pub min_gap: usize,
    /// Tile side in windows (memory per tile ≈ 3 × (tile + 36)² × 4 bytes).
    pub tile: usize,
    /// Show a progress bar on stderr.
    pub progress: bool,
}

impl Default for BuildParams {
    fn default() -> Self {
        BuildParams {
            t_mg: 0.9,
            t_lma: 0.8,
            weights: ComponentWeights::default(),
            min_gap: WINDOW,
            tile: 256,
            progress: false,
        }
    }
}

/// Magic bytes at the start of a graph file.
pub const MAGIC: &[u8; 8] = b"FIGGRAPH";
/// Version of the graph file layout.
pub const GRAPH_VERSION: u32 = 1;
/// Frames over which a transition blends from the old clip into the new one (1/3 s).
pub const BLEND_FRAMES: usize = 10;

/// One source clip of the graph.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClipEntry {
    /// Clip name (file stem).
    pub name: String,
    /// Source file path as given to `graph build`.
    pub path: String,
    /// First global frame of the clip.
    pub start: u32,
    /// Frames at 30 fps.
    pub frames: u32,
    /// Rig identity (joint names and parents); only equal rigs can be spliced.
    pub rig: String,
    /// Factor from the clip's length unit to analysis metres.
    pub scale: f32,
}

/// A transition between two window centres (global frames), `from < to` as stored.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Edge {
    /// One end (global frame).
    pub from: u32,
    /// The other end (global frame).
    pub to: u32,
    /// Posture correlation 1 − d̂ ∈ [0, 1] (eq. 1, normalised).
    pub posture: f32,
    /// Smoothed style similarity ∈ [0, 1] (eq. 2, weighted).
    pub style: f32,
}

/// Which graph to walk.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Variant {
    /// Plain motion graph: posture threshold only; picks by posture correlation.
    Mg,
    /// LMA-pruned motion graph: posture and style thresholds; picks by style correlation.
    Lma,
}

/// A built motion graph.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MotionGraph {
    /// File layout version.
    pub version: u32,
    /// Source clips, in global frame order.
    pub clips: Vec<ClipEntry>,
    /// The parameters the graph was built with.
    pub params: BuildParams,
    /// Smallest posture distance over all window pairs, m².
    pub dmin: f32,
    /// Largest posture distance over all window pairs, m².
    pub dmax: f32,
    /// All transitions passing T_MG (local maxima of posture correlation), `from < to`.
    pub edges: Vec<Edge>,
    /// Measurement standardiser of the library.
    pub standardiser: Standardiser,
    /// Raw LMA measurements of every window (`windows × 114`, clip order).
    pub measurements: Vec<f32>,
    /// Role overrides the clips were loaded with (role name → joint name).
    pub roles: std::collections::BTreeMap<String, String>,
}

/// A playable transition: jump from window centre `from` to continue after `to`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transition {
    /// Global frame left.
    pub from: u32,
    /// Global frame joined.
    pub to: u32,
    /// Posture correlation ∈ [0, 1].
    pub posture: f32,
    /// Style similarity ∈ [0, 1].
    pub style: f32,
}

impl MotionGraph {
    /// Total frames.
    pub fn frames(&self) -> usize {
        self.clips
            .last()
            .map(|c| (c.start + c.frames) as usize)
            .unwrap_or(0)
    }

    /// Clip index of a global frame.
    pub fn clip_of(&self, frame: u32) -> Option<usize> {
        let k = self.clips.partition_point(|c| c.start <= frame);
        let c = self.clips.get(k.checked_sub(1)?)?;
        (frame < c.start + c.frames).then_some(k - 1)
    }

    /// Window index (row of [`MotionGraph::measurements`]) of a window-centre frame.
    pub fn window_of(&self, frame: u32) -> Option<usize> {
        let ci = self.clip_of(frame)?;
        let mut w = 0usize;
        for c in &self.clips[..ci] {
            w += (c.frames as usize + 1).saturating_sub(WINDOW);
        }
        let c = &self.clips[ci];
        let local = (frame - c.start) as usize;
        let lw = local.checked_sub(WINDOW / 2)?;
        (lw + WINDOW <= c.frames as usize).then_some(w + lw)
    }

    /// Raw measurements of the window centred on `frame`.
    pub fn window_measurements(&self, frame: u32) -> Option<&[f32]> {
        let w = self.window_of(frame)?;
        self.measurements
            .get(w * MEASUREMENTS..(w + 1) * MEASUREMENTS)
    }

    /// Whether an edge is in a variant at thresholds `t_mg`, `t_lma` (None: the build's).
    pub fn keeps(&self, e: &Edge, v: Variant, t_mg: Option<f32>, t_lma: Option<f32>) -> bool {
        let t_mg = t_mg.unwrap_or(self.params.t_mg);
        let t_lma = t_lma.unwrap_or(self.params.t_lma);
        e.posture >= t_mg && (v == Variant::Mg || e.style >= t_lma)
    }

    /// Number of transitions (both directions counted once) in a variant.
    pub fn count(&self, v: Variant, t_mg: Option<f32>, t_lma: Option<f32>) -> usize {
        self.edges
            .iter()
            .filter(|e| self.keeps(e, v, t_mg, t_lma))
            .count()
    }

    /// Whether two frames belong to clips of the same rig.
    pub fn same_rig(&self, a: u32, b: u32) -> bool {
        match (self.clip_of(a), self.clip_of(b)) {
            (Some(x), Some(y)) => self.clips[x].rig == self.clips[y].rig,
            _ => false,
        }
    }

    /// Directed playable transitions of a variant (both directions of every kept same-rig edge),
    /// grouped by source frame: `out[f]` lists the transitions leaving global frame `f`.
    pub fn transitions(
        &self,
        v: Variant,
        t_mg: Option<f32>,
        t_lma: Option<f32>,
    ) -> Vec<Vec<Transition>> {
        let mut out = vec![Vec::new(); self.frames()];
        for e in &self.edges {
            if !self.keeps(e, v, t_mg, t_lma) || !self.same_rig(e.from, e.to) {
                continue;
            }
            for (a, b) in [(e.from, e.to), (e.to, e.from)] {
                if let Some(list) = out.get_mut(a as usize) {
                    list.push(Transition {
                        from: a,
                        to: b,
                        posture: e.posture,
                        style: e.style,
                    });
                }
            }
        }
        out
    }

    /// Membership of every frame in the largest strongly connected component of the graph of
    /// played frames: clip continuations (`f → f + 1`) and jumps (`from → to + 1`).
    pub fn largest_scc(&self, transitions: &[Vec<Transition>]) -> Vec<bool> {
        let n = self.frames();
        let succ = |f: usize| -> Vec<usize> {
            // A jump from `f` plays `to + 1` next (window centres are never a clip's last frame).
            let mut s: Vec<usize> = transitions
                .get(f)
                .map(|t| t.iter().map(|t| t.to as usize + 1).collect())
                .unwrap_or_default();
            if let Some(c) = self.clip_of(f as u32) {
                let c = &self.clips[c];
                if (f as u32) + 1 < c.start + c.frames {
                    s.push(f + 1);
                }
            }
            s
        };
        let comp = tarjan(n, succ);
        let mut sizes = vec![0usize; n];
        for &c in &comp {
            sizes[c] += 1;
        }
        let best = (0..n).max_by_key(|&c| (sizes[c], std::cmp::Reverse(c)));
        match best {
            Some(b) if sizes[b] > 1 => comp.iter().map(|&c| c == b).collect(),
            _ => vec![false; n],
        }
    }

    /// Writes the graph file.
    ///
    /// The encoding streams into the file: encoding into memory first held the file's bytes
    /// (~29 MB at 54k frames) up to three times over (the growing body, then the body copied
    /// behind the header), and that was a `graph merge`'s peak: 114 MiB at 54k frames, 69 MiB
    /// streamed.
    pub fn save(&self, path: &Path) -> Result<(), GraphError> {
        use std::io::Write;
        let io = |source| GraphError::Io {
            path: path.to_path_buf(),
            source,
        };
        let mut w = std::io::BufWriter::new(std::fs::File::create(path).map_err(io)?);
        w.write_all(MAGIC).map_err(io)?;
        let w = postcard::to_io(self, w)
            .map_err(|e| GraphError::format(path, format!("encoding the graph: {e}")))?;
        w.into_inner().map_err(|e| io(e.into_error()))?;
        Ok(())
    }

    /// Reads a graph file.
    pub fn load(path: &Path) -> Result<MotionGraph, GraphError> {
        let bytes = std::fs::read(path).map_err(|source| GraphError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_bytes(&bytes, path)
    }

    /// Decodes the bytes of graph file `path` (named in errors).
    pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<MotionGraph, GraphError> {
        let body = bytes.strip_prefix(MAGIC.as_slice()).ok_or_else(|| {
            GraphError::format(path, "not a figurine graph file (no FIGGRAPH header)")
        })?;
        let g: MotionGraph = postcard::from_bytes(body)
            .map_err(|e| GraphError::format(path, format!("corrupt graph file: {e}")))?;
        if g.version != GRAPH_VERSION {
            return Err(GraphError::format(
                path,
                format!(
                    "graph file version {} (this build reads {GRAPH_VERSION}); rebuild it",
                    g.version
                ),
            ));
        }
        // The clips tile the global frames from 0, in order: every frame lookup relies on it.
        let mut next = 0u32;
        for (k, c) in g.clips.iter().enumerate() {
            if c.start != next {
                return Err(GraphError::format(
                    path,
                    format!(
                        "inconsistent graph file (clip {} starts at frame {}, not {next})",
                        k + 1,
                        c.start
                    ),
                ));
            }
            next = next.checked_add(c.frames).ok_or_else(|| {
                GraphError::format(path, "inconsistent graph file (more than 2³² frames)")
            })?;
        }
        let windows: usize = g
            .clips
            .iter()
            .map(|c| (c.frames as usize + 1).saturating_sub(WINDOW))
            .sum();
        if g.measurements.len() != windows * MEASUREMENTS
            || g.standardiser.mean.len() != MEASUREMENTS
            || g.standardiser.std.len() != MEASUREMENTS
            || g.edges
                .iter()
                .any(|e| e.to as usize >= g.frames() || e.from as usize >= g.frames())
        {
            return Err(GraphError::format(
                path,
                "inconsistent graph file (sizes do not match)",
            ));
        }
        Ok(g)
    }
}

/// Iterative Tarjan: component id of every node (ids are arbitrary but equal within an SCC).
fn tarjan(n: usize, succ: impl Fn(usize) -> Vec<usize>) -> Vec<usize> {
    const UNSEEN: usize = usize::MAX;
    let mut index = vec![UNSEEN; n];
    let mut low = vec![0usize; n];
    let mut on_stack = vec![false; n];
    let mut comp = vec![UNSEEN; n];
    let mut stack = Vec::new();
    let mut next = 0usize;
    for root in 0..n {
        if index[root] != UNSEEN {
            continue;
        }
        let mut call: Vec<(usize, Vec<usize>, usize)> = vec![(root, succ(root), 0)];
        index[root] = next;
        low[root] = next;
        next += 1;
        stack.push(root);
        on_stack[root] = true;
        while let Some((v, ws, k)) = call.last_mut() {
            let v = *v;
            if let Some(&w) = ws.get(*k) {
                *k += 1;
                if w >= n {
                    continue;
                }
                if index[w] == UNSEEN {
                    index[w] = next;
                    low[w] = next;
                    next += 1;
                    stack.push(w);
                    on_stack[w] = true;
                    call.push((w, succ(w), 0));
                } else if on_stack[w] {
                    low[v] = low[v].min(index[w]);
                }
            } else {
                call.pop();
                if let Some((u, _, _)) = call.last() {
                    low[*u] = low[*u].min(low[v]);
                }
                if low[v] == index[v] {
                    while let Some(w) = stack.pop() {
                        on_stack[w] = false;
                        comp[w] = v;
                        if w == v {
                            break;
                        }
                    }
                }
            }
        }
    }
    comp
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn toy_graph(edges: Vec<Edge>, clip_frames: &[u32]) -> MotionGraph {
        let mut start = 0;
        let clips = clip_frames
            .iter()
            .enumerate()
            .map(|(k, &f)| {
                let c = ClipEntry {
                    name: format!("c{k}"),
                    path: format!("c{k}.bvh"),
                    start,
                    frames: f,
                    rig: "r".into(),
                    scale: 1.0,
                };
                start += f;
                c
            })
            .collect::<Vec<_>>();
        let windows: usize = clip_frames
            .iter()
            .map(|&f| (f as usize + 1).saturating_sub(WINDOW))
            .sum();
        MotionGraph {
            version: GRAPH_VERSION,
            clips,
            params: BuildParams::default(),
            dmin: 0.0,
            dmax: 1.0,
            edges,
            standardiser: Standardiser {
                mean: vec![0.0; MEASUREMENTS],
                std: vec![1.0; MEASUREMENTS],
            },
            measurements: vec![0.5; windows * MEASUREMENTS],
            roles: Default::default(),
        }
    }

    fn e(from: u32, to: u32, style: f32) -> Edge {
        Edge {
            from,
            to,
            posture: 0.95,
            style,
        }
    }

    #[test]
    fn scc_keeps_the_cycle_and_drops_dead_ends() {
        // Clip 0: frames 0..50, clip 1: 50..100, clip 2: 100..150.
        // 20 ↔ 70 and 40 ↔ 60 make a cycle 21..40 → 61..70 → 21. Clip 2 is joined by 30 ↔ 110
        // only, which LMA pruning removes (low style).
        let g = toy_graph(
            vec![e(20, 70, 0.9), e(40, 60, 0.9), e(30, 110, 0.1)],
            &[50, 50, 50],
        );
        let lma = g.largest_scc(&g.transitions(Variant::Lma, None, None));
        assert!(lma[21] && lma[40] && lma[61] && lma[70] && lma[30]);
        assert!(
            !lma[0] && !lma[49] && !lma[45] && !lma[111],
            "dead ends must be trimmed"
        );
        let mg = g.largest_scc(&g.transitions(Variant::Mg, None, None));
        // One link each way is no cycle: clip 2 stays out even in MG.
        assert!(mg[30] && !mg[111]);
        assert_eq!(g.count(Variant::Mg, None, None), 3);
        assert_eq!(g.count(Variant::Lma, None, None), 2);
    }

    #[test]
    fn file_round_trip_and_bad_files() {
        let g = toy_graph(vec![e(20, 70, 0.9)], &[50, 50]);
        let dir = std::env::temp_dir().join(format!("figurine-graph-file-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("g.bin");
        g.save(&p).unwrap();
        assert_eq!(MotionGraph::load(&p).unwrap(), g);
        // The streamed file is the format's bytes: the header, then postcard's encoding.
        let mut want = MAGIC.to_vec();
        want.extend(postcard::to_allocvec(&g).unwrap());
        assert_eq!(std::fs::read(&p).unwrap(), want);
        std::fs::write(&p, b"garbage").unwrap();
        assert!(MotionGraph::load(&p)
            .unwrap_err()
            .to_string()
            .contains("g.bin"));
        let mut bytes = MAGIC.to_vec();
        bytes.extend([1, 2, 3]);
        std::fs::write(&p, bytes).unwrap();
        assert!(MotionGraph::load(&p)
            .unwrap_err()
            .to_string()
            .contains("corrupt"));
        std::fs::remove_dir_all(&dir).ok();
    }

    /// A graph file whose sizes disagree is refused with the file's name, before anything
    /// indexes by them: clips that do not tile the frames from 0 (a frame count past 2³² made
    /// `graph synth` overflow, found by the `graph_file` fuzz target), or a standardiser of
    /// another length than the measurements.
    #[test]
    fn a_graph_whose_sizes_disagree_is_refused() {
        let path = Path::new("G.bin");
        let bytes = |g: &MotionGraph| {
            let mut b = MAGIC.to_vec();
            b.extend(postcard::to_allocvec(g).unwrap());
            b
        };
        let good = toy_graph(vec![e(20, 45, 0.9)], &[50, 40]);
        assert!(MotionGraph::from_bytes(&bytes(&good), path).is_ok());
        let mut gap = good.clone();
        gap.clips[1].start = 60;
        let mut past = good.clone();
        past.clips[1].frames = u32::MAX;
        let mut short = good.clone();
        short.standardiser.std.pop();
        for (g, why) in [
            (gap, "clip 2 starts at frame 60, not 50"),
            (past, "2³²"),
            (short, "sizes"),
        ] {
            let e = MotionGraph::from_bytes(&bytes(&g), path)
                .unwrap_err()
                .to_string();
            assert!(e.contains("G.bin") && e.contains(why), "{e}");
        }
    }

    /// The seed of the `graph_file` fuzz target: a two-clip graph with edges within and
    /// between the clips. Written again with FIGURINE_WRITE_FUZZ_SEEDS=1 (after a change of
    /// the format).
    #[test]
    fn the_fuzz_seed_is_a_graph_the_reader_accepts() {
        let seed =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds/graph_file/two-clips.bin");
        let g = toy_graph(
            vec![e(20, 45, 0.9), e(25, 60, 0.8), e(40, 70, 0.2)],
            &[50, 40],
        );
        if std::env::var_os("FIGURINE_WRITE_FUZZ_SEEDS").is_some() {
            let mut bytes = MAGIC.to_vec();
            bytes.extend(postcard::to_allocvec(&g).unwrap());
            std::fs::create_dir_all(seed.parent().unwrap()).unwrap();
            std::fs::write(&seed, bytes).unwrap();
        }
        let read = MotionGraph::from_bytes(&std::fs::read(&seed).unwrap(), &seed).unwrap();
        assert_eq!(read, g);
        assert_eq!(read.count(Variant::Mg, None, None), 3);
    }

    #[test]
    fn frame_lookups() {
        let g = toy_graph(vec![], &[50, 40]);
        assert_eq!(g.clip_of(0), Some(0));
        assert_eq!(g.clip_of(49), Some(0));
        assert_eq!(g.clip_of(50), Some(1));
        assert_eq!(g.clip_of(90), None);
        assert_eq!(g.window_of(17), Some(0));
        assert_eq!(g.window_of(16), None);
        assert_eq!(g.window_of(32), Some(15));
        assert_eq!(g.window_of(33), None);
        assert_eq!(g.window_of(50 + 17), Some(16));
    }
}
