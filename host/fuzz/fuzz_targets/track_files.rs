//! Fuzzes the tracker's two input files: a rig file (`figurine track --rig FILE`: which tag
//! sits where on the figurine) and a camera calibration (`--calibration CAL.json`). An input
//! is the rig's text, a NUL byte, then the calibration's text. Each gives a checked value or
//! an error naming its file, never a panic. What is accepted is used as `figurine track` uses
//! it: the rig's faces are seen, as a perfect detector would see them, through the
//! calibration's camera (or a 60° one) from three figurine poses, and their corners are solved
//! and fused into the figurine's pose.
#![no_main]

use std::path::Path;

use figurine_host::track::detect::{Detection, Family};
use figurine_host::track::fuse::{fuse, solve_tags};
use figurine_host::track::pose::{camera_pose, intrinsics_from_fov, Calibration};
use figurine_host::track::rig::Rig;
use glam::{DQuat, DVec3};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let (rig_bytes, cal_bytes) = match data.iter().position(|&b| b == 0) {
        Some(i) => (&data[..i], &data[i + 1..]),
        None => (data, &[][..]),
    };
    let (Ok(rig_text), Ok(cal_text)) = (
        std::str::from_utf8(rig_bytes),
        std::str::from_utf8(cal_bytes),
    ) else {
        return;
    };
    let rig = match Rig::from_json(rig_text, Path::new("RIG.json"), Family::Tag36h11, 0.04) {
        Ok(r) => r,
        Err(e) => {
            assert!(e.to_string().contains("RIG.json"), "{e}");
            Rig::single(0, 0.04)
        }
    };
    let _ = rig.describe();
    let k = match Calibration::from_json(cal_text, Path::new("CAL.json")) {
        Ok(c) => match c.intrinsics_for(640, 480) {
            Ok(k) => k,
            Err(_) => return,
        },
        Err(e) => {
            assert!(e.to_string().contains("CAL.json"), "{e}");
            intrinsics_from_fov(640, 480, 60.0)
        }
    };
    for (p, q) in [
        (DVec3::new(0.0, 0.0, -0.6), DQuat::IDENTITY),
        (DVec3::new(0.1, -0.05, -0.9), DQuat::from_rotation_y(0.7)),
        (
            DVec3::new(-0.05, 0.1, -0.4),
            DQuat::from_euler(glam::EulerRot::YXZ, -2.0, 0.4, 0.2),
        ),
    ] {
        let (r, t) = camera_pose(p, q);
        let found: Vec<Detection> = rig
            .faces
            .iter()
            .map(|f| Detection {
                id: f.id,
                hamming: 0,
                margin: 50.0,
                corners: f
                    .corners_in_body(rig.tag_size)
                    .map(|o| r * o + t)
                    .map(|v| [k.cx + k.fx * v.x / v.z, k.cy + k.fy * v.y / v.z]),
                center: [0.0; 2],
            })
            .collect();
        let seen = solve_tags(&rig, found, &k);
        let _ = fuse(&rig, &seen, &k);
    }
});
