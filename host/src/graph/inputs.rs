//! What `graph build` and `graph plan` share: the clips given (files or folders), the build
//! options, and their checking into [`BuildParams`].

use std::path::{Path, PathBuf};

use clap::Args;

use super::graph::BuildParams;
use super::roles::{read_overrides, RoleOverrides};
use super::source::{load_clips, GraphClip};
use super::style::ComponentWeights;
use super::{GraphError, FPS, WINDOW};

/// Options shared by `graph build` and `graph plan`.
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
