//! How sudden and how strong each of an action's clip variants is: its own Effort-component
//! LMA measurements ([`crate::graph::effort`]), over 35-frame windows at 30 fps, standardised
//! over the windows of all the action's variants ([`variant_efforts`]), so that "sudden" means
//! sudden for this action. [`super::variants`] chooses among them by the recognised effort.

use std::path::Path;

use crate::graph::effort::Effort;
use crate::graph::lma::{clip_measurements, MEASUREMENTS};
use crate::graph::roles::RoleOverrides;
use crate::graph::source::prepare;
use crate::graph::style::Standardiser;
use crate::graph::{GraphError, Role, WINDOW};
use crate::motion::Clip;

/// LMA measurement rows (`windows × MEASUREMENTS`, flat) of a clip, after the graph's
/// analysis normalisation (30 fps, 1.7 m body, floor at 0). Clips shorter than a window are
/// extended by playing them back and forth.
pub fn clip_rows(clip: &Clip) -> Result<Vec<f32>, GraphError> {
    let g = prepare(clip.clone(), Path::new(&clip.name), &RoleOverrides::new())?;
    let mut points: Vec<[glam::Vec3; Role::COUNT]> = g.points;
    if points.len() < 2 {
        return Err(GraphError::format(
            &clip.name,
            "fewer than 2 frames to measure",
        ));
    }
    let base = points.clone();
    let mut backwards = true;
    while points.len() < WINDOW {
        let seq: Vec<_> = if backwards {
            base.iter().rev().skip(1).copied().collect()
        } else {
            base.iter().skip(1).copied().collect()
        };
        points.extend(seq);
        backwards = !backwards;
    }
    Ok(clip_measurements(&points))
}

/// The effort of each of an action's variant `clips` (named for errors), from their measurement
/// rows standardised over all of them; `None` for a clip without a whole window.
pub fn variant_efforts(clips: &[Clip]) -> Result<Vec<Option<Effort>>, GraphError> {
    let rows: Vec<Vec<f32>> = clips.iter().map(clip_rows).collect::<Result<_, _>>()?;
    let all: Vec<f32> = rows.iter().flatten().copied().collect();
    let st = Standardiser::fit(&all);
    Ok(rows.iter().map(|r| mean_effort(r, &st)).collect())
}

/// Mean effort of measurement rows.
fn mean_effort(rows: &[f32], st: &Standardiser) -> Option<Effort> {
    let (mut t, mut w, mut n) = (0.0f32, 0.0f32, 0usize);
    for row in rows.chunks_exact(MEASUREMENTS) {
        let e = Effort::of_measurements(row, st);
        t += e.time;
        w += e.weight;
        n += 1;
    }
    (n > 0).then(|| Effort {
        time: t / n as f32,
        weight: w / n as f32,
    })
}
