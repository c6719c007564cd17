//! End-to-end tests of `figurine track`: rendered videos of a tag on a moving figurine, encoded
//! to MP4, tracked, and compared with the poses that were drawn; the printed tag; and the
//! errors bad input gets.

use std::path::Path;

use figurine_host::poselog::{PoseLog, PoseSample};
use figurine_host::synth::Action;
use figurine_host::track::bench::run_gesture;
use figurine_host::track::eval::{summarize, Setup, Tracking};
use glam::{DQuat, DVec3};

mod track_common;

use track_common::{fails_saying, figurine, render_as_is, s, scratch, succeeds};

#[test]
fn a_gesture_is_tracked_within_goals_and_reads_as_the_same_action() {
    let dir = scratch("gesture");
    let setup = Setup {
        distance: 0.6,
        seed: 5,
        ..Setup::default()
    };
    let run = run_gesture(
        &setup,
        Action::Sidestep,
        4,
        &dir,
        Tracking::default(),
        false,
    )
    .unwrap();
    let all = summarize(&run.frames);
    assert!(all.frames > 30, "{} frames", all.frames);
    assert!(
        all.lost_visible_share() < 0.05,
        "{:.1} % of frames in sight lost",
        100.0 * all.lost_visible_share()
    );
    assert!(
        all.pos_median_mm < 5.0,
        "position {:.1} mm",
        all.pos_median_mm
    );
    assert!(
        all.ori_median_deg < 2.0,
        "orientation {:.2}°",
        all.ori_median_deg
    );
    assert_eq!(run.truth_actions, vec!["sidestep".to_string()]);
    assert_eq!(run.tracked_actions, run.truth_actions);
}

#[test]
fn searching_near_the_tag_first_finds_the_same_poses_in_a_fraction_of_the_pixels() {
    let dir = scratch("region");
    std::fs::write(dir.join("keep"), b"").unwrap();
    let setup = Setup {
        distance: 0.9,
        seed: 2,
        ..Setup::default()
    };
    let whole = Tracking {
        region_search: false,
        ..Tracking::default()
    };
    let a = run_gesture(&setup, Action::Walk, 6, &dir, whole, false).unwrap();
    // The same video, kept and tracked again, searching near the tag's last place first.
    let b = run_gesture(&setup, Action::Walk, 6, &dir, Tracking::default(), true).unwrap();
    assert_eq!(a.frames.len(), b.frames.len());
    let (sa, sb) = (summarize(&a.frames), summarize(&b.frames));
    assert_eq!(sa.lost, sb.lost, "frames lost");
    // The corners agree to within a tenth of a pixel (the library's fits are not exactly
    // shift-invariant): at 0.9 m that is a few millimetres of depth at most, and the errors
    // against the truth are alike.
    for (fa, fb) in a.frames.iter().zip(&b.frames) {
        if let (Some(pa), Some(pb)) = (fa.tracked, fb.tracked) {
            let gap = (DVec3::from_array(pa.pos) - DVec3::from_array(pb.pos)).length();
            assert!(gap < 5e-3, "{:.2} mm apart at {}", gap * 1000.0, pa.t);
        }
    }
    assert!(
        (sa.pos_median_mm - sb.pos_median_mm).abs() < 0.5,
        "{sa:?} vs {sb:?}"
    );
    assert!(
        (sa.ori_median_deg - sb.ori_median_deg).abs() < 0.5,
        "{sa:?} vs {sb:?}"
    );
    // The work saved, counted rather than timed (the time, release-built, is the track
    // bench's "frame → sample" figure, against `--whole-frames`): the median frame is searched
    // in a region a few tag widths across, not a whole frame.
    let median = |v: &[usize]| {
        let mut v = v.to_vec();
        v.sort_unstable();
        v[v.len() / 2]
    };
    let (pa, pb) = (median(&a.searched_px), median(&b.searched_px));
    assert_eq!(pa, 640 * 480, "the whole frame, every frame");
    assert!(
        pb * 20 < pa,
        "median {pb} pixels searched near the tag, {pa} whole"
    );
}

/// A short path: still, then a slide to the figurine's left and a quarter turn.
fn short_path() -> PoseLog {
    PoseLog {
        samples: (0..=120)
            .map(|i| {
                let t = i as f64 / 120.0;
                let s = ((t - 0.3) / 0.5).clamp(0.0, 1.0);
                let q = DQuat::from_rotation_y(0.6 * s);
                PoseSample {
                    t,
                    pos: [0.15 * s, 0.02 * s, 0.0],
                    quat: [q.w, q.x, q.y, q.z],
                }
            })
            .collect(),
    }
}

#[test]
fn the_cli_renders_tracks_and_draws_the_overlay() {
    let dir = scratch("cli");
    let path = dir.join("path.csv");
    short_path().write_path(&path).unwrap();
    let (video, truth, tracked, overlay) = (
        dir.join("v.mp4"),
        dir.join("truth.csv"),
        dir.join("tracked.csv"),
        dir.join("overlay.png"),
    );
    succeeds(&[
        "track",
        "render",
        "--log",
        s(&path),
        "--out",
        s(&video),
        "--truth",
        s(&truth),
        "--distance",
        "0.5",
        "--seed",
        "2",
    ]);
    succeeds(&[
        "track",
        "--video",
        s(&video),
        "--tag-size",
        "0.04",
        "--out",
        s(&tracked),
        "--overlay",
        s(&overlay),
    ]);
    let truth = PoseLog::read_path(&truth).unwrap();
    let tracked = PoseLog::read_path(&tracked).unwrap();
    assert!(
        tracked.samples.len() + 3 >= truth.samples.len(),
        "frames lost"
    );
    for t in &tracked.samples {
        let want = truth
            .samples
            .iter()
            .find(|w| (w.t - t.t).abs() < 1e-5)
            .expect("a sample at a frame time");
        let err = (DVec3::from_array(t.pos) - DVec3::from_array(want.pos)).length();
        assert!(err < 0.01, "{:.1} mm at {}", err * 1000.0, t.t);
    }
    // Moved left (+x of the camera's world: the figurine faces the camera) and turned.
    let (a, b) = (&tracked.samples[0], tracked.samples.last().unwrap());
    assert!(b.pos[0] - a.pos[0] > 0.12);
    assert!(image::open(&overlay).unwrap().width() == 640);
    // `--out -`: the same log on stdout, a line per frame, for `figurine live`'s stdin.
    let out = succeeds(&["track", "--video", s(&video), "--out", "-"]);
    let piped = PoseLog::read(&out.stdout[..], Path::new("stdout")).unwrap();
    assert_eq!(piped.samples.len(), tracked.samples.len());
    for line in String::from_utf8_lossy(&out.stdout).lines().skip(1) {
        assert!(
            figurine_host::link::lines::parse_pose_line(line).is_some(),
            "{line}"
        );
    }
}

#[test]
fn print_tag_writes_png_and_pdf() {
    let dir = scratch("print");
    for name in ["tag.png", "tag.pdf"] {
        let p = dir.join(name);
        succeeds(&[
            "track",
            "print-tag",
            "--id",
            "3",
            "--size",
            "0.05",
            "--out",
            s(&p),
        ]);
        assert!(std::fs::metadata(&p).unwrap().len() > 100);
    }
    fails_saying(
        &figurine(&[
            "track",
            "print-tag",
            "--id",
            "9999",
            "--out",
            s(&dir.join("x.png")),
        ]),
        &["tag36h11 has ids 0..587, not 9999"],
    );
}

#[test]
fn bad_input_gets_clear_errors() {
    let dir = scratch("bad");
    // No tag: the figurine shows the camera its back the whole time.
    let q = DQuat::from_rotation_y(std::f64::consts::PI);
    let back = PoseLog {
        samples: (0..=20)
            .map(|i| PoseSample {
                t: i as f64 / 60.0,
                pos: [0.0, 0.0, -0.5],
                quat: [q.w, q.x, q.y, q.z],
            })
            .collect(),
    };
    let video = render_as_is(&dir, "back", &back, &[]);
    let log = dir.join("log.csv");
    fails_saying(
        &figurine(&["track", "--video", s(&video), "--out", s(&log)]),
        &["no tag36h11 tag 0 in any of", "frames"],
    );
    // A camera tilted past straight down, or not a number.
    for bad in ["95", "NaN"] {
        fails_saying(
            &figurine(&[
                "track",
                "--video",
                s(&video),
                "--camera-tilt",
                bad,
                "--out",
                s(&log),
            ]),
            &["--camera-tilt", "degrees (-90 to 90)"],
        );
    }
    // Not a video, and no file at all.
    let junk = dir.join("junk.mp4");
    std::fs::write(&junk, b"not a video at all").unwrap();
    fails_saying(
        &figurine(&["track", "--video", s(&junk), "--out", s(&log)]),
        &["junk.mp4", "cannot read the video"],
    );
    fails_saying(
        &figurine(&[
            "track",
            "--video",
            s(&dir.join("none.mp4")),
            "--out",
            s(&log),
        ]),
        &["none.mp4", "no such file"],
    );
    // A camera that is not there, and a file that is not a camera.
    fails_saying(
        &figurine(&["track", "--camera", "/dev/video-none-9", "--out", s(&log)]),
        &["/dev/video-none-9", "no such camera"],
    );
    fails_saying(
        &figurine(&["track", "--camera", "/dev/null", "--out", s(&log)]),
        &["not a video device"],
    );
    // Calibration files that hold no camera.
    let cal = dir.join("cal.json");
    for (text, why) in [
        ("{ not json", "bad calibration file"),
        (
            r#"{"width":640,"height":480,"fx":-5,"fy":500,"cx":320,"cy":240}"#,
            "fx must be a positive",
        ),
        (r#"{"width":640}"#, "missing field"),
    ] {
        std::fs::write(&cal, text).unwrap();
        fails_saying(
            &figurine(&[
                "track",
                "--video",
                s(&video),
                "--calibration",
                s(&cal),
                "--out",
                s(&log),
            ]),
            &["cal.json", why],
        );
    }
    fails_saying(
        &figurine(&[
            "track",
            "--video",
            s(&video),
            "--tag-size=-1",
            "--out",
            s(&log),
        ]),
        &["--tag-size"],
    );
}

#[test]
fn calibrate_finds_the_focal_length_and_tracking_uses_it() {
    let dir = scratch("calibrate");
    // The tag waved through tilts 0.35 m ahead of a 72° camera, already in its world frame.
    let waved = PoseLog {
        samples: (0..30)
            .map(|i| {
                let a = i as f64 * 0.45;
                let q = DQuat::from_euler(glam::EulerRot::YXZ, 0.6 * a.cos(), 0.5 * a.sin(), 0.1);
                PoseSample {
                    t: i as f64 / 30.0,
                    pos: [0.03 * a.sin(), 0.0, -0.35],
                    quat: [q.w, q.x, q.y, q.z],
                }
            })
            .collect(),
    };
    let video = render_as_is(&dir, "wave", &waved, &["--fov", "72", "--clean"]);
    let cal = dir.join("cal.json");
    succeeds(&["track", "calibrate", "--video", s(&video), "--out", s(&cal)]);
    let c = figurine_host::track::pose::Calibration::read(&cal).unwrap();
    let f_true = 320.0 / 36f64.to_radians().tan();
    assert!((c.fx / f_true - 1.0).abs() < 0.03, "f {} vs {f_true}", c.fx);
    // Tracking with it gets the depth right; the default 60° guess gets it 24 % long.
    let depth = |extra: &[&str]| {
        let log = dir.join("tracked.csv");
        let mut args = vec!["track", "--video", s(&video), "--out", s(&log)];
        args.extend_from_slice(extra);
        let out = figurine(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let l = PoseLog::read_path(&log).unwrap();
        l.samples.iter().map(|p| -p.pos[2]).sum::<f64>() / l.samples.len() as f64
    };
    let calibrated = depth(&["--calibration", s(&cal)]);
    assert!((calibrated - 0.35).abs() < 0.01, "{calibrated} m");
    let guessed = depth(&[]);
    let expected = 0.35 * 36f64.to_radians().tan() / 30f64.to_radians().tan();
    assert!(
        (guessed - expected).abs() < 0.015,
        "{guessed} m vs {expected} m"
    );
}

#[test]
fn a_camera_looking_down_is_measured_and_its_tilt_undone() {
    let dir = scratch("tilt");
    // A figurine standing upright and still for two seconds, 0.6 m along the line of sight of
    // a camera that looks down 25°, facing it across the desk.
    let camera = figurine_host::track::pose::camera_tilt(25.0);
    let at = camera * DVec3::new(0.0, 0.0, -0.6);
    let log = PoseLog {
        samples: (0..=60)
            .map(|i| PoseSample {
                t: i as f64 / 30.0,
                pos: at.to_array(),
                quat: [1.0, 0.0, 0.0, 0.0],
            })
            .collect(),
    };
    let video = render_as_is(&dir, "down", &log, &["--camera-tilt", "25"]);
    // Measured from the figurine's own up.
    let out = succeeds(&["track", "--video", s(&video), "--level"]);
    let said = String::from_utf8_lossy(&out.stdout).to_string();
    let tilt: f64 = said
        .split("looks down ")
        .nth(1)
        .and_then(|r| r.split('°').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{said}"));
    assert!((tilt - 25.0).abs() < 2.0, "{said}");
    // Told the tilt, the log stands upright where the figurine stood; untold, it leans 25°.
    let up_err = |path: &Path| {
        let log = PoseLog::read_path(path).unwrap();
        assert!(log.samples.len() > 50, "{} samples", log.samples.len());
        let worst = log
            .samples
            .iter()
            .map(|p| {
                let q = DQuat::from_xyzw(p.quat[1], p.quat[2], p.quat[3], p.quat[0]);
                (q * DVec3::Y).angle_between(DVec3::Y).to_degrees()
            })
            .fold(0.0, f64::max);
        let far = log
            .samples
            .iter()
            .map(|p| (DVec3::from_array(p.pos) - at).length())
            .fold(0.0, f64::max);
        (worst, far)
    };
    let told = dir.join("told.csv");
    succeeds(&[
        "track",
        "--video",
        s(&video),
        "--camera-tilt",
        &format!("{tilt}"),
        "--out",
        s(&told),
    ]);
    let (lean, far) = up_err(&told);
    assert!(lean < 3.0 && far < 0.01, "leans {lean}°, {far} m off");
    let untold = dir.join("untold.csv");
    succeeds(&["track", "--video", s(&video), "--out", s(&untold)]);
    let (lean, _) = up_err(&untold);
    assert!(lean > 20.0, "leans {lean}°");
    // Never still: a clear error, not a made-up tilt.
    let moving = PoseLog {
        samples: (0..=60)
            .map(|i| {
                let t = i as f64 / 30.0;
                let q = DQuat::from_rotation_y(0.8 * (2.0 * t).sin());
                PoseSample {
                    t,
                    pos: (at + DVec3::new(0.1 * (3.0 * t).sin(), 0.0, 0.0)).to_array(),
                    quat: [q.w, q.x, q.y, q.z],
                }
            })
            .collect(),
    };
    let video = render_as_is(&dir, "moving", &moving, &["--camera-tilt", "25"]);
    let out = figurine(&["track", "--video", s(&video), "--level"]);
    assert!(!out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("stood still"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
