//! The default animations: every default action in the four Laban effort corners and
//! neutral, each assembled along a doodle generated from its label (as `figurine animate
//! --labels` does). `figurine check --defaults` judges them against real motion capture, and
//! `--sheets` draws them side by side, so a reader sees what sudden/sustained and
//! strong/light do to each action:
//!
//! | row of a sheet | Time | Weight |
//! |---|---|---|
//! | 1 | sudden | strong |
//! | 2 | sudden | light |
//! | 3 | sustained | strong |
//! | 4 | sustained | light |
//! | 5 | neutral | neutral |

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use glam::Vec3;

use super::assemble::{assemble_guided, AssembleOptions, Assembly};
use crate::synth::{gesture, Action, Effort, Knobs, TimeClass, WeightClass};

/// The efforts every default action is assembled in, named as `figurine check` prints them,
/// in the order of a sheet's rows.
pub const EFFORTS: [(&str, Effort); 5] = [
    (
        "sudden-strong",
        Effort::new(TimeClass::Sudden, WeightClass::Strong),
    ),
    (
        "sudden-light",
        Effort::new(TimeClass::Sudden, WeightClass::Light),
    ),
    (
        "sustained-strong",
        Effort::new(TimeClass::Sustained, WeightClass::Strong),
    ),
    (
        "sustained-light",
        Effort::new(TimeClass::Sustained, WeightClass::Light),
    ),
    ("neutral", Effort::NEUTRAL),
];

/// Figures drawn per row of an effort sheet, evenly spaced over the action.
pub const FIGURES_PER_ROW: usize = 8;

/// One default action in one effort, assembled.
#[derive(Debug)]
pub struct DefaultAnimation {
    /// The action's name.
    pub action: &'static str,
    /// The effort's name (see [`EFFORTS`]).
    pub effort: &'static str,
    /// The assembled animation.
    pub assembly: Assembly,
}

/// Assembles every default action in every effort of [`EFFORTS`] along doodles generated at
/// `seed`; returns them (action-major, efforts in [`EFFORTS`] order) and the rig's forward
/// axis.
pub fn default_animations(seed: u64) -> Result<(Vec<DefaultAnimation>, Vec3)> {
    let library = super::library::ClipLibrary::default_library()?;
    let mut out = Vec::new();
    for action in Action::ALL {
        for (name, effort) in EFFORTS {
            let d = gesture(seed, &Knobs::default(), action, effort);
            let events = super::cli::label_events(d.labels.clone());
            let clips = library.load(events.iter().map(|e| e.action.as_str()))?;
            let assembly = assemble_guided(
                &events,
                Some(&d.log),
                &clips,
                library.forward(),
                &AssembleOptions::default(),
                None,
            )?;
            out.push(DefaultAnimation {
                action: action.name(),
                effort: name,
                assembly,
            });
        }
    }
    Ok((out, library.forward()))
}

/// Writes one effort sheet per action into `dir` (`ACTION.png`): a row per effort, in the
/// order of [`EFFORTS`], of [`FIGURES_PER_ROW`] stick figures evenly spaced from the
/// action's first frame to its last. Returns the files written.
pub fn write_effort_sheets(
    anims: &[DefaultAnimation],
    forward: Vec3,
    dir: &Path,
) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).with_context(|| format!("{}", dir.display()))?;
    let mut written = Vec::new();
    for chunk in anims.chunk_by(|a, b| a.action == b.action) {
        let rows: Vec<_> = chunk
            .iter()
            .map(|a| {
                let span = a
                    .assembly
                    .placements
                    .first()
                    .map_or(0..=a.assembly.clip.len().saturating_sub(1), |p| {
                        p.start_frame..=p.end_frame
                    });
                (&a.assembly.clip, span)
            })
            .collect();
        let img = super::plot::effort_sheet(&rows, FIGURES_PER_ROW, forward);
        let Some(first) = chunk.first() else { continue };
        let path = dir.join(format!("{}.png", first.action));
        img.save(&path)
            .with_context(|| format!("writing {}", path.display()))?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sheet_shows_each_effort_in_its_own_row_and_the_efforts_differ() {
        if crate::data::data_file("deepmimic", "humanoid.urdf").is_none() {
            eprintln!("skipping: deepmimic data missing — run `cargo xtask setup`");
            return;
        }
        let (anims, forward) = default_animations(5).unwrap();
        assert_eq!(anims.len(), Action::ALL.len() * EFFORTS.len());
        let kick: Vec<_> = anims.iter().filter(|a| a.action == "kick").collect();
        let rows: Vec<_> = kick
            .iter()
            .map(|a| {
                let p = &a.assembly.placements[0];
                (&a.assembly.clip, p.start_frame..=p.end_frame)
            })
            .collect();
        let img = super::super::plot::effort_sheet(&rows, FIGURES_PER_ROW, forward);
        let cell = super::super::plot::CELL;
        assert_eq!(img.dimensions(), (FIGURES_PER_ROW as u32 * cell, 5 * cell));
        // Every row has figures drawn in it, and no two rows are drawn alike.
        let row = |r: u32| -> Vec<u8> {
            (r * cell..(r + 1) * cell)
                .flat_map(|y| (0..img.width()).map(move |x| (x, y)))
                .flat_map(|(x, y)| img.get_pixel(x, y).0)
                .collect()
        };
        let rows: Vec<Vec<u8>> = (0..5).map(row).collect();
        for (i, r) in rows.iter().enumerate() {
            let inked = r.chunks(3).filter(|p| p[2] > 100 && p[0] < 200).count();
            assert!(inked > 500, "row {i}: {inked} figure pixels");
            for other in &rows[..i] {
                assert_ne!(r, other, "row {i} repeats an earlier row");
            }
        }
    }
}
