//! `figurine track print-tag`: a tag to print at its true size — a PNG whose pixel density is
//! written in the file (so a print dialogue at 100 % keeps the size) or a one-page PDF drawn
//! in millimetres. The pattern comes from libapriltag's own family table
//! ([`super::detect::tag_pattern`]).

use std::io::Write;
use std::path::Path;

use image::{Rgb, RgbImage};

use super::detect::{tag_pattern, Family, TagPattern};
use super::rig::{Face, Rig};
use super::TrackError;
use crate::raster::{draw_text, text_width};

/// Millimetres per inch.
const MM_PER_INCH: f64 = 25.4;

fn write_err(path: &Path, e: impl std::fmt::Display) -> TrackError {
    TrackError::Write {
        path: path.to_path_buf(),
        source: std::io::Error::other(e.to_string()),
    }
}

/// The caption printed under the tag: what it is, its size, and how to stick it on.
pub fn caption(family: Family, id: u32, size_m: f64) -> [String; 2] {
    [
        format!(
            "{} ID {id}  BLACK SQUARE {:.1} MM: PRINT AT 100%",
            family.name(),
            size_m * 1000.0
        ),
        "ON THE CHEST OF THE FIGURINE, THIS WAY UP".to_string(),
    ]
}

/// The caption of a rig's tag: as [`caption`], the face it goes on, and which way its
/// printed top points on the figurine (up on the sides; toward the back on a box's top).
pub fn rig_caption(family: Family, id: u32, size_m: f64, face: &Face) -> [String; 2] {
    let [first, _] = caption(family, id, size_m);
    let up = face.rotation * glam::DVec3::Y;
    let way = [
        (glam::DVec3::Y, "THIS WAY UP"),
        (glam::DVec3::NEG_Y, "THIS EDGE DOWN"),
        (glam::DVec3::Z, "THIS EDGE TO ITS FRONT"),
        (glam::DVec3::NEG_Z, "THIS EDGE TO ITS BACK"),
        (glam::DVec3::X, "THIS EDGE TO ITS LEFT"),
        (glam::DVec3::NEG_X, "THIS EDGE TO ITS RIGHT"),
    ]
    .into_iter()
    .max_by(|a, b| up.dot(a.0).total_cmp(&up.dot(b.0)))
    .map_or("THIS WAY UP", |(_, w)| w);
    [
        first,
        format!("ON THE {} OF THE FIGURINE, {way}", face.name.to_uppercase()),
    ]
}

/// One tag to print: its pattern and the two caption lines under it.
pub type Printed = (TagPattern, [String; 2]);

/// Draws the tags as one PNG, two to a row: `px_per_cell` pixels per cell, with the pixel
/// density that makes each black square `size_m` metres when printed at 100 %.
pub fn tag_png(
    tags: &[Printed],
    size_m: f64,
    px_per_cell: u32,
    path: &Path,
) -> Result<(), TrackError> {
    let Some((first, _)) = tags.first() else {
        return Err(TrackError::BadArgument("no tag to print".into()));
    };
    let cell = px_per_cell.max(1);
    let tag_px = cell * first.width as u32;
    let text_scale = (cell / 12).max(1);
    let text_w = tags
        .iter()
        .flat_map(|(_, lines)| lines.iter().map(|l| text_width(l, text_scale)))
        .max()
        .unwrap_or(0);
    let tile_w = tag_px.max(text_w + 2 * cell);
    let tile_h = tag_px + 2 * 10 * text_scale + 2 * cell;
    let cols = tags.len().min(2) as u32;
    let rows = tags.len().div_ceil(2) as u32;
    let (width, height) = (tile_w * cols, tile_h * rows);
    let mut img = RgbImage::from_pixel(width, height, Rgb([255, 255, 255]));
    let grey = Rgb([90, 90, 90]);
    for (i, (pattern, lines)) in tags.iter().enumerate() {
        let (tx, ty) = ((i as u32 % 2) * tile_w, (i as u32 / 2) * tile_h);
        let x0 = tx + (tile_w - tag_px) / 2;
        for y in 0..pattern.width.min(first.width) {
            for x in 0..pattern.width.min(first.width) {
                if pattern.is_black(x, y) {
                    for py in 0..cell {
                        for px in 0..cell {
                            img.put_pixel(
                                x0 + x as u32 * cell + px,
                                ty + y as u32 * cell + py,
                                Rgb([0, 0, 0]),
                            );
                        }
                    }
                }
            }
        }
        for (j, l) in lines.iter().enumerate() {
            let w = text_width(l, text_scale);
            let y = ty + tag_px + cell / 2 + j as u32 * 10 * text_scale;
            draw_text(
                &mut img,
                i64::from(tx + (tile_w - w.min(tile_w)) / 2),
                i64::from(y),
                l,
                text_scale,
                grey,
            );
        }
    }
    // Pixels per metre such that the border square (border_width cells) is size_m.
    let ppm = (f64::from(cell) * first.border_width as f64 / size_m).round() as u32;
    let file = std::fs::File::create(path).map_err(|source| TrackError::Write {
        path: path.to_path_buf(),
        source,
    })?;
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), width, height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_pixel_dims(Some(png::PixelDimensions {
        xppu: ppm,
        yppu: ppm,
        unit: png::Unit::Meter,
    }));
    let mut w = enc.write_header().map_err(|e| write_err(path, e))?;
    w.write_image_data(img.as_raw())
        .map_err(|e| write_err(path, e))?;
    w.finish().map_err(|e| write_err(path, e))
}

/// Writes the tags on one A4 page as a PDF in exact millimetres, two to a row when they fit:
/// one filled square per black cell, each caption in Helvetica below its tag. Tags too big
/// for one page are an error (print them one at a time).
pub fn tag_pdf(tags: &[Printed], size_m: f64, path: &Path) -> Result<(), TrackError> {
    let Some((first, _)) = tags.first() else {
        return Err(TrackError::BadArgument("no tag to print".into()));
    };
    let pt_per_m = 72.0 / MM_PER_INCH * 1000.0;
    let cell = size_m / first.border_width as f64 * pt_per_m;
    let (page_w, page_h) = (595.28, 841.89);
    let side = cell * first.width as f64;
    // Room for the caption's two lines and a gap under each tag, points.
    let (gap, caption_h) = (30.0, 50.0);
    let cols = if tags.len() > 1 && 2.0 * side + gap <= page_w - 60.0 {
        2
    } else {
        1
    };
    let rows = tags.len().div_ceil(cols);
    if rows as f64 * (side + caption_h) > page_h - 150.0 || side > page_w - 60.0 {
        return Err(TrackError::BadArgument(format!(
            "{} tags of {:.0} mm do not fit on one A4 page: print them one at a time",
            tags.len(),
            size_m * 1000.0
        )));
    }
    let mut content = String::from("0 g\n");
    for (i, (pattern, lines)) in tags.iter().enumerate() {
        let (col, row) = ((i % cols) as f64, (i / cols) as f64);
        let row_w = cols as f64 * side + (cols - 1) as f64 * gap;
        let x0 = (page_w - row_w) / 2.0 + col * (side + gap);
        let top = page_h - 120.0 - row * (side + caption_h);
        for y in 0..pattern.width {
            for x in 0..pattern.width {
                if pattern.is_black(x, y) {
                    // Cells overlap by a hair so no viewer draws seams between them.
                    content.push_str(&format!(
                        "{:.3} {:.3} {:.3} {:.3} re f\n",
                        x0 + x as f64 * cell,
                        top - (y + 1) as f64 * cell,
                        cell + 0.02,
                        cell + 0.02
                    ));
                }
            }
        }
        // Two tags to a row leave half the page each: the caption in a smaller type.
        let font = if cols > 1 { 6 } else { 10 };
        for (j, l) in lines.iter().enumerate() {
            let text = l
                .replace('\\', "\\\\")
                .replace('(', "\\(")
                .replace(')', "\\)");
            content.push_str(&format!(
                "BT /F1 {font} Tf {:.2} {:.2} Td ({text}) Tj ET\n",
                x0,
                top - side - 20.0 - 14.0 * j as f64
            ));
        }
    }
    let objects = [
        "<< /Type /Catalog /Pages 2 0 R >>".to_string(),
        "<< /Type /Pages /Kids [3 0 R] /Count 1 >>".to_string(),
        format!(
            "<< /Type /Page /Parent 2 0 R /MediaBox [0 0 {page_w} {page_h}] \
             /Resources << /Font << /F1 5 0 R >> >> /Contents 4 0 R >>"
        ),
        format!(
            "<< /Length {} >>\nstream\n{content}endstream",
            content.len()
        ),
        "<< /Type /Font /Subtype /Type1 /BaseFont /Helvetica >>".to_string(),
    ];
    let mut out = Vec::new();
    out.extend_from_slice(b"%PDF-1.4\n");
    let mut offsets = Vec::new();
    for (i, o) in objects.iter().enumerate() {
        offsets.push(out.len());
        out.extend_from_slice(format!("{} 0 obj\n{o}\nendobj\n", i + 1).as_bytes());
    }
    let xref = out.len();
    out.extend_from_slice(
        format!("xref\n0 {}\n0000000000 65535 f \n", objects.len() + 1).as_bytes(),
    );
    for off in offsets {
        out.extend_from_slice(format!("{off:010} 00000 n \n").as_bytes());
    }
    out.extend_from_slice(
        format!(
            "trailer\n<< /Size {} /Root 1 0 R >>\nstartxref\n{xref}\n%%EOF\n",
            objects.len() + 1
        )
        .as_bytes(),
    );
    std::fs::File::create(path)
        .and_then(|mut f| f.write_all(&out))
        .map_err(|source| TrackError::Write {
            path: path.to_path_buf(),
            source,
        })
}

/// `figurine track print-tag`: tag `id` (or every tag of `rig`, each captioned with its face)
/// as a PNG or a PDF (by `out`'s extension) at `size` metres, `px` PNG pixels per cell.
pub fn print_tags(
    family: Family,
    id: u32,
    size: f64,
    out: &Path,
    px: u32,
    rig: Option<&Rig>,
) -> Result<(), TrackError> {
    if !(size.is_finite() && size > 0.0 && size < 1.0) {
        return Err(TrackError::BadArgument(format!(
            "--size {size}: the black square's edge in metres, e.g. 0.04"
        )));
    }
    let tags: Vec<Printed> = match rig {
        None => vec![(tag_pattern(family, id)?, caption(family, id, size))],
        Some(rig) => rig
            .faces
            .iter()
            .map(|f| {
                Ok((
                    tag_pattern(family, f.id)?,
                    rig_caption(family, f.id, rig.tag_size, f),
                ))
            })
            .collect::<Result<_, TrackError>>()?,
    };
    let size = rig.map_or(size, |r| r.tag_size);
    match out.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("pdf") => tag_pdf(&tags, size, out)?,
        _ => tag_png(&tags, size, px, out)?,
    }
    let what = match rig {
        None => format!("id {id}"),
        Some(r) => format!(
            "{} tags for the rig:\n  {}",
            r.faces.len(),
            r.describe().join("\n  ")
        ),
    };
    eprintln!(
        "{}: {} {what}\nblack squares {:.1} mm; print at 100 % and measure them",
        out.display(),
        family.name(),
        size * 1000.0
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::detect::{tag_pattern, Detector, DetectorSettings, GrayFrame};

    #[test]
    fn a_rig_caption_says_which_way_each_tag_goes() {
        let size = crate::track::rig::BoxSize {
            top: Some(0.09),
            ..crate::track::rig::BoxSize::sides(0.08, 0.08)
        };
        let rig = Rig::checked_box(Family::Tag36h11, 0, 0.04, size).unwrap();
        let lines: Vec<String> = rig
            .faces
            .iter()
            .map(|f| rig_caption(Family::Tag36h11, f.id, 0.04, f)[1].clone())
            .collect();
        assert_eq!(lines[0], "ON THE FRONT OF THE FIGURINE, THIS WAY UP");
        assert_eq!(lines[3], "ON THE RIGHT OF THE FIGURINE, THIS WAY UP");
        assert_eq!(
            lines[4],
            "ON THE TOP OF THE FIGURINE, THIS EDGE TO ITS BACK"
        );
    }

    #[test]
    fn the_printed_png_is_detected_and_says_its_size() {
        let dir = std::env::temp_dir().join(format!("figurine-print-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("tag.png");
        let pattern = tag_pattern(Family::Tag36h11, 7).unwrap();
        let one = [(pattern.clone(), caption(Family::Tag36h11, 7, 0.04))];
        tag_png(&one, 0.04, 20, &path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let dec = png::Decoder::new(std::io::Cursor::new(bytes));
        let reader = dec.read_info().unwrap();
        let dims = reader.info().pixel_dims.unwrap();
        // 8 cells × 20 px over 40 mm: 4000 px/m.
        assert_eq!(dims.xppu, 4000);
        let img = image::open(&path).unwrap().to_luma8();
        // A white margin so the detector sees the tag's outer white ring.
        let mut frame = GrayFrame {
            width: img.width() as usize + 40,
            height: img.height() as usize + 40,
            pixels: vec![255; (img.width() as usize + 40) * (img.height() as usize + 40)],
        };
        for (x, y, p) in img.enumerate_pixels() {
            frame.pixels[(y as usize + 20) * frame.width + x as usize + 20] = p.0[0];
        }
        let mut d = Detector::new(Family::Tag36h11, DetectorSettings::default()).unwrap();
        let found = d.detect(&frame);
        assert_eq!(found.iter().map(|d| d.id).collect::<Vec<_>>(), vec![7]);
        let pdf = dir.join("tag.pdf");
        tag_pdf(&one, 0.04, &pdf).unwrap();
        let text = std::fs::read_to_string(&pdf).unwrap();
        assert!(text.starts_with("%PDF-1.4") && text.ends_with("%%EOF\n"));
        // 5 mm cells are 14.173 pt.
        assert!(text.contains(" 14.193 14.193 re f"), "cell size in points");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
