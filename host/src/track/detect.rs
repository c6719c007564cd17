//! The AprilTag detector: the upstream library 3.4.5 that `apriltag-sys` bundles, compiled into
//! the host (`.cargo/config.toml` sets `APRILTAG_SYS_METHOD`), wrapped so that the rest of the
//! tracker never touches a raw pointer.
//!
//! Not Debian's libapriltag 3.3.0: its worker pool lets a thread woken spuriously read a task
//! while the next is being added, and the tasks' array may move under it (AprilRobotics/apriltag
//! #339, fixed in 3.4), and one run of the host's tests died of SIGSEGV in the tracker's tests,
//! which detect with two threads. Compiling the bundled source also keeps the library and the
//! crate's generated bindings the same version.
//!
//! What the wrapper relies on, from `apriltag.h`/`apriltag_pose.h`:
//! * a detector owns no family: the family must outlive it, so [`Detector`] drops the
//!   detector first;
//! * `apriltag_detector_detect` only reads the image, and returns a `zarray` of
//!   `apriltag_detection_t*` that `apriltag_detections_destroy` frees;
//! * the corners `p[0..4]` wrap counter-clockwise in the image, starting at the tag's
//!   bottom-left as printed;
//! * `apriltag_to_image` returns an image the caller frees with `image_u8_destroy`.
//!
//! The pose is not taken from the library's `estimate_tag_pose`: [`super::pnp`] solves it from
//! the corners, for the pose and its mirror, refined on all four (the library's own estimate
//! keeps one of the two and needs `matd_t` matrices freed across the boundary).
#![allow(unsafe_code)]

use apriltag_sys as sys;

use super::TrackError;

/// A tag family the tracker knows (the square, black-bordered ones).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Family {
    /// 36-bit codes, Hamming distance 11: the recommended family (587 ids).
    #[value(name = "tag36h11")]
    Tag36h11,
    /// 25-bit codes, Hamming distance 9 (35 ids).
    #[value(name = "tag25h9")]
    Tag25h9,
    /// 16-bit codes, Hamming distance 5 (30 ids; false detections are likelier).
    #[value(name = "tag16h5")]
    Tag16h5,
}

impl Family {
    /// The family's name as the library spells it.
    pub fn name(self) -> &'static str {
        match self {
            Family::Tag36h11 => "tag36h11",
            Family::Tag25h9 => "tag25h9",
            Family::Tag16h5 => "tag16h5",
        }
    }
}

/// One family table, created by the library and destroyed with it.
struct FamilyTable {
    kind: Family,
    ptr: *mut sys::apriltag_family_t,
}

impl FamilyTable {
    fn new(kind: Family) -> Result<Self, TrackError> {
        // SAFETY: the constructors take no argument and return an owned table or null.
        let ptr = unsafe {
            match kind {
                Family::Tag36h11 => sys::tag36h11_create(),
                Family::Tag25h9 => sys::tag25h9_create(),
                Family::Tag16h5 => sys::tag16h5_create(),
            }
        };
        if ptr.is_null() {
            return Err(TrackError::Detector(format!(
                "libapriltag could not create family {}",
                kind.name()
            )));
        }
        Ok(Self { kind, ptr })
    }

    fn ncodes(&self) -> u32 {
        // SAFETY: `ptr` is a live table owned by `self`.
        unsafe { (*self.ptr).ncodes }
    }
}

impl Drop for FamilyTable {
    fn drop(&mut self) {
        // SAFETY: created by the matching constructor, destroyed once.
        unsafe {
            match self.kind {
                Family::Tag36h11 => sys::tag36h11_destroy(self.ptr),
                Family::Tag25h9 => sys::tag25h9_destroy(self.ptr),
                Family::Tag16h5 => sys::tag16h5_destroy(self.ptr),
            }
        }
    }
}

/// A tag's printed pattern: `width`×`width` cells, row-major from the top-left as printed,
/// `true` black. It includes the white cells around the black border.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TagPattern {
    /// Cells per side, white margin included (10 for tag36h11).
    pub width: usize,
    /// Cells per side of the black border square, the edge `--tag-size` measures (8 for
    /// tag36h11).
    pub border_width: usize,
    /// `width * width` cells, `true` black.
    pub black: Vec<bool>,
}

impl TagPattern {
    /// Whether the cell at column `x`, row `y` (from the top-left as printed) is black.
    pub fn is_black(&self, x: usize, y: usize) -> bool {
        x < self.width && y < self.width && self.black[y * self.width + x]
    }
}

/// The pattern of tag `id` of `family`, drawn by the library from its own code table.
pub fn tag_pattern(family: Family, id: u32) -> Result<TagPattern, TrackError> {
    let table = FamilyTable::new(family)?;
    if id >= table.ncodes() {
        return Err(TrackError::BadTagId {
            family: family.name(),
            id,
            count: table.ncodes(),
        });
    }
    // SAFETY: `table` is live and `id` is within its code table; the image is owned by us
    // and destroyed below, after its pixels are copied.
    unsafe {
        let border = (*table.ptr).width_at_border as usize;
        let im = sys::apriltag_to_image(table.ptr, id);
        if im.is_null() {
            return Err(TrackError::Detector("apriltag_to_image failed".into()));
        }
        let (w, h, stride) = ((*im).width, (*im).height, (*im).stride);
        let mut black = Vec::with_capacity((w * h).max(0) as usize);
        for y in 0..h {
            for x in 0..w {
                black.push(*(*im).buf.add((y * stride + x) as usize) < 128);
            }
        }
        sys::image_u8_destroy(im);
        if w != h || w <= 0 {
            return Err(TrackError::Detector(format!("tag image is {w}×{h}")));
        }
        Ok(TagPattern {
            width: w as usize,
            border_width: border,
            black,
        })
    }
}

/// A grey frame, 8 bits per pixel, row-major, no padding.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GrayFrame {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// `width * height` grey levels, 0 black.
    pub pixels: Vec<u8>,
}

/// The camera's pinhole intrinsics, pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Intrinsics {
    /// Focal length along x, pixels.
    pub fx: f64,
    /// Focal length along y, pixels.
    pub fy: f64,
    /// Principal point x, pixels from the left edge.
    pub cx: f64,
    /// Principal point y, pixels from the top edge.
    pub cy: f64,
}

/// The tag's pose in the camera frame (x right, y down, z forward).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraPose {
    /// Tag→camera rotation, row-major; tag frame x right, y down as printed, z into the tag.
    pub rotation: [[f64; 3]; 3],
    /// The tag's centre in the camera frame, metres.
    pub translation: [f64; 3],
    /// RMS reprojection error of the tag's corners under this pose, pixels.
    pub error: f64,
}

impl CameraPose {
    /// The rotation as a unit quaternion (tag→camera).
    pub fn quat(&self) -> glam::DQuat {
        glam::DQuat::from_mat3(&self.matrix()).normalize()
    }

    /// The rotation as a matrix (tag→camera).
    pub fn matrix(&self) -> glam::DMat3 {
        let r = self.rotation;
        glam::DMat3::from_cols(
            glam::DVec3::new(r[0][0], r[1][0], r[2][0]),
            glam::DVec3::new(r[0][1], r[1][1], r[2][1]),
            glam::DVec3::new(r[0][2], r[1][2], r[2][2]),
        )
    }

    /// A pose from a rotation matrix, a translation (metres) and its RMS corner error
    /// (pixels).
    pub fn from_parts(rotation: glam::DMat3, translation: glam::DVec3, error: f64) -> Self {
        Self {
            rotation: [
                rotation.row(0).to_array(),
                rotation.row(1).to_array(),
                rotation.row(2).to_array(),
            ],
            translation: translation.to_array(),
            error,
        }
    }
}

/// One detected tag.
#[derive(Debug, Clone, PartialEq)]
pub struct Detection {
    /// Tag id within its family.
    pub id: u32,
    /// Bits corrected to decode it (0 is a clean read).
    pub hamming: u32,
    /// The library's decision margin: how clearly the bits were read (tens are good).
    pub margin: f32,
    /// Corners, pixels, counter-clockwise in the image from the printed bottom-left.
    pub corners: [[f64; 2]; 4],
    /// Centre, pixels.
    pub center: [f64; 2],
}

/// Edge of the tiles libapriltag thresholds a frame by, pixels (`apriltag_quad_thresh.c`:
/// `tilesz = 4`), counted from the frame's top-left corner.
const THRESHOLD_TILE_PX: usize = 4;

/// A rectangle of a frame, pixels: columns `x0..x1`, rows `y0..y1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Region {
    /// First column.
    pub x0: usize,
    /// First row.
    pub y0: usize,
    /// One past the last column.
    pub x1: usize,
    /// One past the last row.
    pub y1: usize,
}

impl Region {
    /// The box around `points` grown by `margin` pixels on every side, clipped to a
    /// `width`×`height` frame; `None` when a point is not finite or the box misses the frame.
    pub fn around(points: &[[f64; 2]], margin: f64, width: usize, height: usize) -> Option<Self> {
        if points.is_empty() || !margin.is_finite() {
            return None;
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in points {
            if !(p[0].is_finite() && p[1].is_finite()) {
                return None;
            }
            for k in 0..2 {
                lo[k] = lo[k].min(p[k] - margin);
                hi[k] = hi[k].max(p[k] + margin);
            }
        }
        let clip = |v: f64, lim: usize| v.clamp(0.0, lim as f64) as usize;
        let r = Self {
            x0: clip(lo[0].floor(), width),
            y0: clip(lo[1].floor(), height),
            x1: clip(hi[0].ceil(), width),
            y1: clip(hi[1].ceil(), height),
        };
        (r.x1 > r.x0 && r.y1 > r.y0).then_some(r)
    }

    /// Pixels inside.
    pub fn area(&self) -> usize {
        (self.x1.saturating_sub(self.x0)) * (self.y1.saturating_sub(self.y0))
    }
}

/// Detector settings that trade speed for range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DetectorSettings {
    /// Worker threads inside the library for a whole frame's search (2: both cores of a
    /// 2-core machine; a search of a region near the tag always uses one, since splitting a
    /// few thousand pixels between threads costs more than it saves — measured on the track
    /// bench, a median 4.7 ms per frame with two against 0.8 ms with one).
    pub threads: u32,
    /// Quad search on a frame decimated by this factor (1 = full resolution: a 4 cm tag at 1 m
    /// is only ~20 px wide at 640×480, too small to find at 2).
    pub decimate: f32,
    /// Gaussian blur σ (pixels) before the quad search; 0 for none.
    pub sigma: f32,
    /// Most bits corrected per detection (more finds damaged tags, and more false ones).
    pub max_hamming: u32,
}

impl Default for DetectorSettings {
    fn default() -> Self {
        Self {
            threads: 2,
            decimate: 1.0,
            sigma: 0.0,
            max_hamming: 1,
        }
    }
}

/// A libapriltag detector for one family.
pub struct Detector {
    det: *mut sys::apriltag_detector_t,
    threads: i32,
    // Declared after `det` only for readability: `Drop` destroys `det` before the table.
    table: FamilyTable,
    scratch: Vec<u8>,
}

impl std::fmt::Debug for Detector {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Detector")
            .field("family", &self.table.kind)
            .finish()
    }
}

impl Detector {
    /// A detector for `family` with `settings`.
    pub fn new(family: Family, settings: DetectorSettings) -> Result<Self, TrackError> {
        let table = FamilyTable::new(family)?;
        // SAFETY: the detector is created, configured field by field as `apriltag.h` documents,
        // and given the family table, which `Self` keeps alive for as long as the detector.
        unsafe {
            let det = sys::apriltag_detector_create();
            if det.is_null() {
                return Err(TrackError::Detector(
                    "libapriltag could not create a detector".into(),
                ));
            }
            let threads = settings.threads.clamp(1, 64) as i32;
            (*det).nthreads = threads;
            (*det).quad_decimate = settings.decimate.max(1.0);
            (*det).quad_sigma = settings.sigma.max(0.0);
            (*det).refine_edges = true;
            (*det).decode_sharpening = 0.25;
            sys::apriltag_detector_add_family_bits(det, table.ptr, settings.max_hamming as i32);
            Ok(Self {
                det,
                threads,
                table,
                scratch: Vec::new(),
            })
        }
    }

    /// The family searched for.
    pub fn family(&self) -> Family {
        self.table.kind
    }

    /// Every tag of the family in `frame`.
    pub fn detect(&mut self, frame: &GrayFrame) -> Vec<Detection> {
        self.detect_in(
            frame,
            Region {
                x0: 0,
                y0: 0,
                x1: frame.width,
                y1: frame.height,
            },
        )
    }

    /// Every tag of the family inside `region` of `frame` (clipped to the frame), in the
    /// frame's pixel coordinates. A region a few tag widths across is searched in a fraction
    /// of a whole frame's time: the library's cost grows with the pixels it thresholds and
    /// segments.
    pub fn detect_in(&mut self, frame: &GrayFrame, region: Region) -> Vec<Detection> {
        if frame.width == 0 || frame.height == 0 || frame.pixels.len() < frame.width * frame.height
        {
            return Vec::new();
        }
        // The region starts on the library's grid of 4×4 threshold tiles, so each of its
        // tiles near the tag is a tile of the whole frame, thresholded alike. The corners
        // then agree with the whole frame's to within a tenth of a pixel (the tests measure
        // it), the size of their noise: the library's fits are not exactly shift-invariant.
        let (x0, x1) = (
            region.x0.min(frame.width) / THRESHOLD_TILE_PX * THRESHOLD_TILE_PX,
            region.x1.min(frame.width),
        );
        let (y0, y1) = (
            region.y0.min(frame.height) / THRESHOLD_TILE_PX * THRESHOLD_TILE_PX,
            region.y1.min(frame.height),
        );
        // Under 8 pixels a side the library has nothing to segment (and its 4×4 tiles break).
        if x1 < x0 + 8 || y1 < y0 + 8 {
            return Vec::new();
        }
        let (w, h) = (x1 - x0, y1 - y0);
        // The library takes a mutable pointer; it only reads, but a private copy keeps the
        // caller's buffer out of C's hands altogether (≈ 0.02 ms at 640×480).
        self.copy_to_scratch(frame, x0, x1, y0, y1);
        let whole = w == frame.width && h == frame.height;
        self.run_scratch(w, h, whole)
            .into_iter()
            .map(|d| d.moved(|[x, y]| [x + x0 as f64, y + y0 as f64]))
            .collect()
    }

    /// Every tag of the family inside `region` of `frame`, searched in the region enlarged
    /// [`ENLARGE`] times (bilinear), in the frame's pixel coordinates. A tag 15 px wide has
    /// cells of under 2 px, which the library's quad fit and bit sampling miss; enlarged,
    /// its edges span enough pixels to be fitted. Four times the pixels: a few milliseconds
    /// for a region around one small tag.
    pub fn detect_in_enlarged(&mut self, frame: &GrayFrame, region: Region) -> Vec<Detection> {
        let Some((x0, x1, y0, y1)) = clipped(frame, region) else {
            return Vec::new();
        };
        let (w, h) = ((x1 - x0) * ENLARGE, (y1 - y0) * ENLARGE);
        let at = |x: usize, y: usize| frame.pixels[y * frame.width + x] as f32;
        self.scratch.clear();
        self.scratch.reserve(w * h);
        let scale = ENLARGE as f64;
        // Pixel centres line up: enlarged pixel i's centre is at (i + ½) / n − ½ in the frame.
        let source = |i: usize, lo: usize, hi: usize| {
            let u = ((i as f64 + 0.5) / scale - 0.5).max(0.0) + lo as f64;
            let a = (u.floor() as usize).min(hi - 1);
            let b = (a + 1).min(hi - 1);
            (a, b, (u - a as f64).clamp(0.0, 1.0) as f32)
        };
        let cols: Vec<(usize, usize, f32)> = (0..w).map(|i| source(i, x0, x1)).collect();
        for j in 0..h {
            let (ya, yb, fy) = source(j, y0, y1);
            for &(xa, xb, fx) in &cols {
                let top = at(xa, ya) + (at(xb, ya) - at(xa, ya)) * fx;
                let bottom = at(xa, yb) + (at(xb, yb) - at(xa, yb)) * fx;
                self.scratch
                    .push((top + (bottom - top) * fy).round().clamp(0.0, 255.0) as u8);
            }
        }
        self.run_scratch(w, h, false)
            .into_iter()
            // The library's corners are on the continuous plane where pixel i spans i..i+1
            // (measured: with the pixel-centre mapping, they land a quarter pixel off the
            // whole frame's), so the enlarged plane is the frame's scaled.
            .map(|d| d.moved(|[x, y]| [x / scale + x0 as f64, y / scale + y0 as f64]))
            .collect()
    }

    /// Every tag of the family inside `region` of `frame` after undoing a motion blur of
    /// `blur` (pixels over the exposure: the tag's image velocity times the exposure) there
    /// ([`super::deblur`]), in the frame's pixel coordinates. For a tag the plain search misses
    /// because it moved fast; a few milliseconds for a region around one tag.
    pub fn detect_in_deblurred(
        &mut self,
        frame: &GrayFrame,
        region: Region,
        blur: [f64; 2],
    ) -> Vec<Detection> {
        let Some((x0, x1, y0, y1)) = clipped(frame, region) else {
            return Vec::new();
        };
        let (w, h) = (x1 - x0, y1 - y0);
        self.copy_to_scratch(frame, x0, x1, y0, y1);
        self.scratch =
            super::deblur::deblur_line(&self.scratch, w, h, blur, super::deblur::ITERATIONS);
        self.run_scratch(w, h, false)
            .into_iter()
            .map(|d| d.moved(|[x, y]| [x + x0 as f64, y + y0 as f64]))
            .collect()
    }

    /// Copies the pixels of `frame` in columns `x0..x1`, rows `y0..y1` (already clipped) into
    /// the scratch buffer, row by row.
    fn copy_to_scratch(&mut self, frame: &GrayFrame, x0: usize, x1: usize, y0: usize, y1: usize) {
        self.scratch.clear();
        for y in y0..y1 {
            self.scratch
                .extend_from_slice(&frame.pixels[y * frame.width + x0..y * frame.width + x1]);
        }
    }

    /// Runs the library on the `w`×`h` image in `scratch` (with every thread when it is a
    /// whole frame, one otherwise); coordinates are the scratch image's.
    fn run_scratch(&mut self, w: usize, h: usize, whole: bool) -> Vec<Detection> {
        let mut im = sys::image_u8_t {
            width: w as i32,
            height: h as i32,
            stride: w as i32,
            buf: self.scratch.as_mut_ptr(),
        };
        // SAFETY: `det` is live; the library re-creates its worker pool when the count
        // changes (`apriltag_detector_detect`), which happens only when the tracker
        // falls back to the whole frame or returns to the region.
        unsafe {
            (*self.det).nthreads = if whole { self.threads } else { 1 };
        }
        let mut out = Vec::new();
        // SAFETY: `im` points at `scratch`, alive and unaliased for the call; the returned
        // array and its detections are read, then freed once with the library's destructor.
        unsafe {
            let found = sys::apriltag_detector_detect(self.det, &mut im);
            if found.is_null() {
                return out;
            }
            let n = (*found).size.max(0) as usize;
            for i in 0..n {
                let slot = (*found)
                    .data
                    .add(i * (*found).el_sz)
                    .cast::<*mut sys::apriltag_detection_t>();
                let d = slot.read_unaligned();
                if d.is_null() {
                    continue;
                }
                out.push(Detection {
                    id: (*d).id.max(0) as u32,
                    hamming: (*d).hamming.max(0) as u32,
                    margin: (*d).decision_margin,
                    corners: (*d).p,
                    center: (*d).c,
                });
            }
            sys::apriltag_detections_destroy(found);
        }
        out
    }
}

/// How many times [`Detector::detect_in_enlarged`] enlarges a region.
pub const ENLARGE: usize = 2;

impl Detection {
    /// The same detection with its corners and centre moved by `f` (pixels to pixels).
    fn moved(self, f: impl Fn([f64; 2]) -> [f64; 2]) -> Self {
        Self {
            corners: self.corners.map(&f),
            center: f(self.center),
            ..self
        }
    }
}

impl Drop for Detector {
    fn drop(&mut self) {
        // SAFETY: created in `new`, destroyed once, before `table` (dropped after this body).
        unsafe { sys::apriltag_detector_destroy(self.det) }
    }
}

/// `region` clipped to `frame` as (x0, x1, y0, y1), pixels; None for a frame whose pixels do
/// not fill it, or a region under 8 pixels a side once clipped (nothing to segment).
fn clipped(frame: &GrayFrame, region: Region) -> Option<(usize, usize, usize, usize)> {
    if frame.width == 0 || frame.height == 0 || frame.pixels.len() < frame.width * frame.height {
        return None;
    }
    let (x0, x1) = (region.x0.min(frame.width), region.x1.min(frame.width));
    let (y0, y1) = (region.y0.min(frame.height), region.y1.min(frame.height));
    (x1 >= x0 + 8 && y1 >= y0 + 8).then_some((x0, x1, y0, y1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tag36h11_id0_comes_from_the_library_table() {
        let p = tag_pattern(Family::Tag36h11, 0).unwrap();
        assert_eq!(p.width, 10);
        assert_eq!(p.border_width, 8);
        // White outer ring, black border ring, and a 6×6 data area that is neither all black
        // nor all white.
        for i in 0..10 {
            assert!(!p.is_black(i, 0) && !p.is_black(0, i) && !p.is_black(i, 9));
        }
        for i in 1..9 {
            assert!(p.is_black(i, 1) && p.is_black(1, i) && p.is_black(8, i));
        }
        let data: usize = (2..8)
            .flat_map(|y| (2..8).map(move |x| (x, y)))
            .filter(|&(x, y)| p.is_black(x, y))
            .count();
        assert!(data > 5 && data < 31, "{data} black data cells");
        assert_ne!(p, tag_pattern(Family::Tag36h11, 1).unwrap());
    }

    #[test]
    fn an_id_beyond_the_family_is_an_error() {
        let err = tag_pattern(Family::Tag16h5, 30).unwrap_err();
        assert!(err.to_string().contains("30"), "{err}");
    }

    #[test]
    fn a_region_is_the_box_around_points_clipped_to_the_frame() {
        let r = Region::around(&[[10.0, 20.0], [30.5, 25.0]], 5.0, 640, 480).unwrap();
        assert_eq!((r.x0, r.y0, r.x1, r.y1), (5, 15, 36, 30));
        assert_eq!(r.area(), 31 * 15);
        let edge = Region::around(&[[2.0, 470.0]], 20.0, 640, 480).unwrap();
        assert_eq!((edge.x0, edge.y1), (0, 480));
        assert!(Region::around(&[[-100.0, -100.0]], 5.0, 640, 480).is_none());
        assert!(Region::around(&[[f64::NAN, 1.0]], 5.0, 640, 480).is_none());
        assert!(Region::around(&[], 5.0, 640, 480).is_none());
    }

    #[test]
    fn a_region_search_finds_the_tag_at_the_frame_s_coordinates() {
        use crate::track::render::{tests::test_scene, Faults};
        let faults = Faults {
            occlusion_every_s: 0.0,
            ..Faults::default()
        };
        let s = test_scene(faults, 1);
        let pose = crate::poselog::PoseSample {
            t: 0.0,
            pos: [0.1, 0.05, -0.6],
            quat: [1.0, 0.0, 0.0, 0.0],
        };
        let frame = s.render(&s.background(), 0, 0.0, |_| Some(pose)).frame;
        let mut d = Detector::new(Family::Tag36h11, DetectorSettings::default()).unwrap();
        let whole = d.detect(&frame);
        assert_eq!(whole.len(), 1);
        let r = Region::around(&whole[0].corners, 30.0, 640, 480).unwrap();
        let part = d.detect_in(&frame, r);
        assert_eq!(part.len(), 1);
        let close = |a: &Detection, b: &Detection| {
            a.corners
                .iter()
                .zip(&b.corners)
                .all(|(a, b)| (a[0] - b[0]).hypot(a[1] - b[1]) < 0.15)
        };
        assert!(close(&whole[0], &part[0]), "{whole:?} vs {part:?}");
        // Also from a region that starts off the library's tile grid.
        let odd = Region {
            x0: r.x0 | 3,
            y0: r.y0 | 1,
            ..r
        };
        let part = d.detect_in(&frame, odd);
        assert_eq!(part.len(), 1);
        assert!(close(&whole[0], &part[0]), "{whole:?} vs {part:?}");
        // A region elsewhere, or too small to hold anything, finds nothing.
        let away = Region {
            x0: 0,
            y0: 0,
            x1: 100,
            y1: 100,
        };
        assert!(d.detect_in(&frame, away).is_empty());
        let tiny = Region {
            x0: 10,
            y0: 10,
            x1: 14,
            y1: 900,
        };
        assert!(d.detect_in(&frame, tiny).is_empty());
    }

    #[test]
    fn an_enlarged_region_finds_a_small_tag_where_it_is() {
        use crate::track::pose::{camera_pose, project};
        use crate::track::render::{tests::test_scene, Faults};
        use crate::track::rig::Rig;
        let faults = Faults {
            occlusion_every_s: 0.0,
            ..Faults::default()
        };
        let s = test_scene(faults, 3);
        let mut d = Detector::new(Family::Tag36h11, DetectorSettings::default()).unwrap();
        let face = Rig::single(0, 0.04).faces[0].clone();
        // Near (40 px) and far, turned half away (~14 px across): where the truth puts the
        // corners, and for the near tag where the plain search puts them too.
        for (pos, yaw_deg, within_px) in [
            ([0.05, 0.0, -0.6], 20.0, 0.3),
            ([0.0, 0.0, -1.0], 45.0, 0.5),
        ] {
            let q = glam::DQuat::from_rotation_y(f64::to_radians(yaw_deg));
            let pose = crate::poselog::PoseSample {
                t: 0.0,
                pos,
                quat: [q.w, q.x, q.y, q.z],
            };
            let frame = s.render(&s.background(), 0, 0.0, |_| Some(pose)).frame;
            let (r, t) = camera_pose(glam::DVec3::from_array(pos), q);
            let truth = face
                .corners_in_body(0.04)
                .map(|c| project(&s.intrinsics, r * c + t).unwrap());
            let region = Region::around(&truth, 20.0, 640, 480).unwrap();
            let big = d.detect_in_enlarged(&frame, region);
            assert_eq!(big.len(), 1, "at {pos:?}, {yaw_deg}°");
            let off = |a: &[[f64; 2]; 4], b: &[[f64; 2]; 4]| {
                a.iter()
                    .zip(b)
                    .map(|(a, b)| (a[0] - b[0]).hypot(a[1] - b[1]))
                    .fold(0.0, f64::max)
            };
            assert!(
                off(&big[0].corners, &truth) < within_px,
                "{big:?} vs {truth:?}"
            );
            if yaw_deg < 30.0 {
                let plain = d.detect_in(&frame, region);
                let (b, p) = (off(&big[0].corners, &truth), off(&plain[0].corners, &truth));
                assert!(b <= p + 0.1, "enlarged {b:.2} px off, plain {p:.2} px");
            }
        }
    }

    #[test]
    fn an_empty_or_blank_frame_has_no_tag() {
        let mut d = Detector::new(Family::Tag36h11, DetectorSettings::default()).unwrap();
        let blank = GrayFrame {
            width: 64,
            height: 48,
            pixels: vec![128; 64 * 48],
        };
        assert!(d.detect(&blank).is_empty());
        let empty = GrayFrame {
            width: 0,
            height: 0,
            pixels: Vec::new(),
        };
        assert!(d.detect(&empty).is_empty());
    }
}
