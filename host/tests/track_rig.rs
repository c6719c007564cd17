//! End-to-end tests of `figurine track --rig`: a box of tags around the figurine, rendered,
//! encoded, tracked at every heading of a full turn; its tags printed; bad rigs refused.

mod track_common;

use figurine_host::poselog::{PoseLog, PoseSample};
use figurine_host::track::detect::Family;
use figurine_host::track::eval::{
    compare, render_video, scene, summarize, track_video, Setup, Tracking,
};
use figurine_host::track::render::Faults;
use figurine_host::track::rig::BoxSize;
use glam::{DQuat, DVec3};
use track_common::{fails_saying, figurine, s, scratch, succeeds};

/// A figurine 0.7 m ahead spinning a full turn to its left in 3 s, bobbing a little.
fn spin() -> PoseLog {
    PoseLog {
        samples: (0..=720)
            .map(|i| {
                let t = i as f64 / 240.0;
                let a = std::f64::consts::TAU * t / 3.0;
                let q = DQuat::from_euler(glam::EulerRot::YXZ, a, 0.1 * (2.0 * a).sin(), 0.0);
                PoseSample {
                    t,
                    pos: [0.02 * a.sin(), 0.01 * (3.0 * a).sin(), -0.7],
                    quat: [q.w, q.x, q.y, q.z],
                }
            })
            .collect(),
    }
}

/// Longest run of consecutive frames without a sample.
fn longest_gap(frames: &[figurine_host::track::eval::FrameError]) -> usize {
    let (mut run, mut worst) = (0, 0);
    for f in frames {
        run = if f.error.is_none() { run + 1 } else { 0 };
        worst = worst.max(run);
    }
    worst
}

#[test]
fn a_box_rig_is_tracked_at_every_heading_of_a_full_turn() {
    let dir = scratch("rig-spin");
    let mut lost = Vec::new();
    for rig_box in [Some(BoxSize::sides(0.08, 0.08)), None] {
        let setup = Setup {
            seed: 3,
            rig_box,
            // No finger over the tags: every frame of the rig has a tag in sight.
            faults: Faults {
                occlusion_every_s: 0.0,
                ..Faults::default()
            },
            ..Setup::default()
        };
        let sc = scene(&setup, Family::Tag36h11, 0).unwrap();
        let video = dir.join(format!("spin-{}.mp4", rig_box.is_some()));
        let truths = render_video(&setup, &sc, &spin(), &video).unwrap();
        let run = track_video(&setup, Family::Tag36h11, 0, &video, Tracking::default()).unwrap();
        let frames = compare(&truths, &run.log, setup.camera());
        let all = summarize(&frames);
        lost.push((all.lost, longest_gap(&frames), all.frames));
        if rig_box.is_some() {
            assert!(
                truths.iter().all(|f| !f.hidden),
                "some tag of the rig is always turned toward the camera"
            );
            assert!(
                longest_gap(&frames) <= 3,
                "{} frames in a row lost; lost {} of {}",
                longest_gap(&frames),
                all.lost,
                all.frames
            );
            assert!(
                all.lost * 20 <= all.frames,
                "lost {} of {}",
                all.lost,
                all.frames
            );
            assert!(
                all.pos_median_mm < 5.0,
                "position {:.1} mm",
                all.pos_median_mm
            );
            assert!(
                all.ori_median_deg < 2.5,
                "orientation {:.2}°",
                all.ori_median_deg
            );
            assert!(
                all.pos_p90_mm < 15.0,
                "position p90 {:.1} mm",
                all.pos_p90_mm
            );
            assert!(
                all.ori_p90_deg < 8.0,
                "orientation p90 {:.2}°",
                all.ori_p90_deg
            );
        }
    }
    // The chest tag alone loses the back half of the turn, the rig hardly a frame.
    let (rig, single) = (lost[0], lost[1]);
    assert!(
        single.1 > 20 && single.0 > 3 * rig.0,
        "rig {rig:?}, one tag {single:?}"
    );
}

#[test]
fn a_fast_turn_stays_within_half_the_mirror_angle_at_every_frame() {
    // A turn of 120° at 3.5 rad/s, 0.6 m away: halfway, the left tag is square to the camera
    // and the front one edge-on, so for a few frames one flat square alone gives the pose,
    // and its mirror (tilted the other way, ~22° off) fits its corners nearly as well. At
    // this noise seed no frame takes the mirror (the old tie-break passed too: this bounds
    // the chooser from doing worse; its own tests are in `track::mirror`).
    let turn = PoseLog {
        samples: (0..=240)
            .map(|i| {
                let t = i as f64 / 240.0;
                let q = DQuat::from_rotation_y(2.1 * ((t - 0.2) / 0.6).clamp(0.0, 1.0));
                PoseSample {
                    t,
                    pos: [0.0, 0.0, -0.6],
                    quat: [q.w, q.x, q.y, q.z],
                }
            })
            .collect(),
    };
    let dir = scratch("rig-mirror");
    let setup = Setup {
        seed: 5,
        rig_box: Some(BoxSize::sides(0.08, 0.08)),
        faults: Faults {
            occlusion_every_s: 0.0,
            ..Faults::default()
        },
        ..Setup::default()
    };
    let sc = scene(&setup, Family::Tag36h11, 0).unwrap();
    let video = dir.join("turn.mp4");
    let truths = render_video(&setup, &sc, &turn, &video).unwrap();
    let run = track_video(&setup, Family::Tag36h11, 0, &video, Tracking::default()).unwrap();
    let frames = compare(&truths, &run.log, setup.camera());
    assert!(summarize(&frames).lost <= 2, "{:?}", summarize(&frames));
    // Every frame within half the mirror's 22° of the truth.
    let worst = frames
        .iter()
        .filter_map(|f| f.error.map(|e| (e.1, f.truth.t)))
        .fold((0.0, 0.0), |a: (f64, f64), b| if b.0 > a.0 { b } else { a });
    assert!(worst.0 < 11.0, "{:.1}° off at {:.2} s", worst.0, worst.1);
}

#[test]
fn the_cli_tracks_a_rig_prints_its_tags_and_refuses_bad_rigs() {
    let dir = scratch("rig-cli");
    // A turn of 120° to the left: the front tag hands over to the left one.
    let path = dir.join("path.csv");
    let turn = PoseLog {
        samples: (0..=120)
            .map(|i| {
                let t = i as f64 / 120.0;
                let q = DQuat::from_rotation_y(2.1 * ((t - 0.2) / 0.6).clamp(0.0, 1.0));
                PoseSample {
                    t,
                    pos: [0.0, 0.0, 0.0],
                    quat: [q.w, q.x, q.y, q.z],
                }
            })
            .collect(),
    };
    turn.write_path(&path).unwrap();
    let (video, truth, tracked) = (dir.join("v.mp4"), dir.join("truth.csv"), dir.join("t.csv"));
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
        "0.6",
        "--rig",
        "box",
    ]);
    let out = succeeds(&[
        "track",
        "--video",
        s(&video),
        "--rig",
        "box",
        "--out",
        s(&tracked),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("id 1 on the left"), "{err}");
    let truth = PoseLog::read_path(&truth).unwrap();
    let log = PoseLog::read_path(&tracked).unwrap();
    assert!(log.samples.len() + 3 >= truth.samples.len(), "frames lost");
    let mut errs: Vec<f64> = log
        .samples
        .iter()
        .map(|t| {
            let want = truth
                .samples
                .iter()
                .find(|w| (w.t - t.t).abs() < 1e-5)
                .unwrap();
            (DVec3::from_array(t.pos) - DVec3::from_array(want.pos)).length()
        })
        .collect();
    errs.sort_by(f64::total_cmp);
    assert!(
        errs[errs.len() / 2] < 5e-3,
        "median {:.1} mm",
        errs[errs.len() / 2] * 1e3
    );
    // Mid-turn (3.5 rad/s), with one tag square to the camera and the other edge-on, a frame
    // can still take the face-on tag's mirror pose (22° off, 15 mm at the box's centre) when
    // its corners favour the mirror strongly two frames running.
    let worst = errs[errs.len() - 1];
    assert!(worst < 0.025, "worst {:.1} mm", worst * 1e3);
    // The rig's tags to print, each with its face.
    for name in ["rig.png", "rig.pdf"] {
        let p = dir.join(name);
        let out = succeeds(&["track", "print-tag", "--rig", "box", "--out", s(&p)]);
        assert!(String::from_utf8_lossy(&out.stderr).contains("id 3 on the right"));
        assert!(std::fs::metadata(&p).unwrap().len() > 100);
    }
    let text = std::fs::read_to_string(dir.join("rig.pdf")).unwrap();
    assert!(
        text.contains("ON THE BACK OF THE FIGURINE"),
        "captions name the faces"
    );
    // Bad rigs: too narrow a box, a file that is not one, ids beyond the family.
    fails_saying(
        &figurine(&[
            "track",
            "--video",
            s(&video),
            "--rig",
            "box",
            "--box-width",
            "0.02",
            "--out",
            s(&tracked),
        ]),
        &["bad rig", "box width 0.02 m"],
    );
    let rig = dir.join("rig.json");
    std::fs::write(
        &rig,
        r#"{"faces":[{"id":0,"centre":[0,0,0],"normal":[0,0,1]}]}"#,
    )
    .unwrap();
    fails_saying(
        &figurine(&[
            "track",
            "--video",
            s(&video),
            "--rig",
            s(&rig),
            "--out",
            s(&tracked),
        ]),
        &["bad rig", "rig.json", "missing field `up`"],
    );
    fails_saying(
        &figurine(&[
            "track",
            "--video",
            s(&video),
            "--rig",
            "box",
            "--tag-id",
            "585",
            "--out",
            s(&tracked),
        ]),
        &["has ids 0..587, not 587"],
    );
    fails_saying(
        &figurine(&[
            "track",
            "--video",
            s(&video),
            "--rig",
            s(&dir.join("none.json")),
            "--out",
            s(&tracked),
        ]),
        &["bad rig", "none.json"],
    );
}

#[test]
fn a_figurine_held_still_in_view_is_tracked_and_read_for_false_alarms() {
    use figurine_host::track::still::{run_still, still_report};
    let dir = scratch("still");
    let setup = Setup {
        distance: 0.5,
        seed: 4,
        rig_box: Some(BoxSize::sides(0.08, 0.08)),
        ..Setup::default()
    };
    let how = Tracking {
        smooth: true,
        region_search: true,
        exposure_s: 0.008,
        ..Tracking::default()
    };
    let r = run_still(&setup, 3.0, 7, &dir, how, false).unwrap();
    // 3 s at 30 frames per second, nearly all of them tracked.
    assert!(
        (89..=91).contains(&r.frames.len()),
        "{} frames",
        r.frames.len()
    );
    let tracked = r.frames.iter().filter(|f| f.error.is_some()).count();
    assert!(
        tracked >= 80,
        "{tracked} of {} frames tracked",
        r.frames.len()
    );
    // A hand holding the figurine still plays no action. It wobbles a little from frame to
    // frame; the tracked log turns by about as much, its smoothing taking out part of the
    // hand's wobble as its jitter adds some (which of the two is larger depends on the
    // encoder's bits), and stays far below the 2° orientation goal.
    assert!(r.truth_actions.is_empty(), "{:?}", r.truth_actions);
    assert_eq!(r.tracked_turns_deg.len(), tracked - 1);
    let median = |v: &[f64]| {
        let mut v = v.to_vec();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (truth, turned) = (median(&r.truth_turns_deg), median(&r.tracked_turns_deg));
    assert!(truth > 0.0, "the hand does not wobble: {truth}°");
    assert!(
        turned > 0.0 && turned < 0.5,
        "tracked {turned}° per frame, truth {truth}°"
    );
    let text = still_report(&[r]);
    assert!(text.contains("| 0.50 m | 3 |"), "{text}");
    // A bad length is refused with the option's name.
    let err = run_still(&setup, -1.0, 7, &dir, how, false).unwrap_err();
    assert!(err.to_string().contains("--rest-seconds"), "{err}");
}
