//! Fuzzes the DeepMimic motion importer (against pybullet's humanoid, read once from the data
//! folder that `cargo xtask setup` fills) and the URDF reader itself.
#![no_main]

use std::path::Path;
use std::sync::OnceLock;

use figurine_host::motion::deepmimic::{humanoid_skeleton, read_deepmimic};
use figurine_host::motion::skeleton::Skeleton;
use figurine_host::motion::urdf::{read_urdf, UrdfJoint};
use libfuzzer_sys::fuzz_target;

fn humanoid() -> Option<&'static (Vec<UrdfJoint>, Skeleton)> {
    static H: OnceLock<Option<(Vec<UrdfJoint>, Skeleton)>> = OnceLock::new();
    H.get_or_init(|| {
        let path = figurine_host::data::data_file("deepmimic", "humanoid.urdf")?;
        let urdf = figurine_host::motion::urdf::read_urdf_path(&path).ok()?;
        let sk = humanoid_skeleton(&urdf, &path).ok()?;
        Some((urdf, sk))
    })
    .as_ref()
}

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let _ = read_urdf(text, Path::new("fuzz.urdf"));
    if let Some((urdf, sk)) = humanoid() {
        let _ = read_deepmimic(text, Path::new("fuzz.txt"), sk, urdf);
    }
});
