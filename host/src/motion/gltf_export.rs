//! Binary glTF 2.0 (.glb) export: joint nodes, a skinned "bone" mesh, and one animation.
//!
//! Every joint becomes a node whose rest translation is its offset; an `Armature` node holds
//! the roots. A mesh of one bipyramid per bone (parent joint → joint), rigidly skinned to the
//! parent, makes the character visible in any viewer. The animation has one LINEAR rotation
//! channel per animated joint and translation channels for the roots and joints with animated
//! translation, sampled at the clip's frames. glTF is metres and +Y up: pass the factor that
//! turns the clip's unit into metres (0.01 for centimetre BVH, 1.0 for DeepMimic).

use std::path::Path;

use glam::{Mat4, Quat, Vec3};
use serde_json::{json, Value};

use super::clip::Clip;
use super::MotionError;

const GLB_MAGIC: u32 = 0x4654_6C67;
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;
const FLOAT: u32 = 5126;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// Builds the .glb bytes of a clip; `to_metres` scales lengths (0.01 for cm data).
pub fn write_glb_bytes(clip: &Clip, to_metres: f32) -> Result<Vec<u8>, MotionError> {
    let sk = &clip.skeleton;
    sk.validate().map_err(MotionError::Invalid)?;
    if sk.is_empty() || clip.frames.is_empty() {
        return Err(MotionError::Invalid(format!("clip {} is empty", clip.name)));
    }
    if !(to_metres.is_finite() && to_metres > 0.0) {
        return Err(MotionError::Invalid(format!(
            "bad length scale {to_metres}"
        )));
    }
    let n = sk.len();
    if n > usize::from(u16::MAX) {
        return Err(MotionError::Invalid(format!(
            "{n} joints: glTF skins here index joints with 16 bits"
        )));
    }
    let mut b = Builder::default();

    // Rest pose, world positions (scaled).
    let rest: Vec<Vec3> = sk
        .rest_positions()
        .into_iter()
        .map(|p| p * to_metres)
        .collect();

    // Mesh: a bipyramid per bone.
    let size = rest
        .iter()
        .fold(0.0f32, |m, p| m.max((*p - rest[0]).length()))
        .max(0.1);
    let mut positions: Vec<Vec3> = Vec::new();
    let mut joints_attr: Vec<[u16; 4]> = Vec::new();
    let mut indices: Vec<u32> = Vec::new();
    for (j, joint) in sk.joints.iter().enumerate() {
        let Some(p) = joint.parent else { continue };
        let (a, c) = (rest[p], rest[j]);
        let d = c - a;
        let len = d.length();
        if len < 1e-6 {
            continue;
        }
        let dir = d / len;
        let side = dir.any_orthonormal_vector();
        let up = dir.cross(side);
        let w = (0.1 * len).min(0.04 * size).max(1e-4);
        let mid = a + d * 0.2;
        let base = positions.len() as u32;
        positions.push(a);
        positions.push(c);
        for k in 0..4 {
            let ang = k as f32 * std::f32::consts::FRAC_PI_2;
            positions.push(mid + (side * ang.cos() + up * ang.sin()) * w);
        }
        let ring = |k: u32| base + 2 + (k % 4);
        for k in 0..4 {
            indices.extend([base, ring(k + 1), ring(k)]);
            indices.extend([base + 1, ring(k), ring(k + 1)]);
        }
        // Unused slots hold joint 0 with weight 0, as validators expect.
        let ja = [p as u16, 0, 0, 0];
        joints_attr.extend(std::iter::repeat_n(ja, 6));
    }
    if positions.is_empty() {
        // A single-joint skeleton: a small tetrahedron at the root.
        let r = rest[0];
        positions.extend([
            r,
            r + Vec3::X * 0.05,
            r + Vec3::Y * 0.05,
            r + Vec3::Z * 0.05,
        ]);
        indices.extend([0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]);
        joints_attr.extend(std::iter::repeat_n([0u16, 0, 0, 0], 4));
    }
    let (pmin, pmax) = positions.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let pos_acc = b.accessor(
        &f32s(positions.iter().flat_map(|p| p.to_array())),
        FLOAT,
        positions.len(),
        "VEC3",
        Some(ARRAY_BUFFER),
        Some((pmin.to_array().to_vec(), pmax.to_array().to_vec())),
    );
    let joint_bytes: Vec<u8> = joints_attr
        .iter()
        .flat_map(|j| j.iter().flat_map(|x| x.to_le_bytes()))
        .collect();
    let joints_acc = b.accessor(
        &joint_bytes,
        UNSIGNED_SHORT,
        joints_attr.len(),
        "VEC4",
        Some(ARRAY_BUFFER),
        None,
    );
    let weights: Vec<f32> = joints_attr
        .iter()
        .flat_map(|_| [1.0, 0.0, 0.0, 0.0])
        .collect();
    let weights_acc = b.accessor(
        &f32s(weights),
        FLOAT,
        joints_attr.len(),
        "VEC4",
        Some(ARRAY_BUFFER),
        None,
    );
    let idx_bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
    let idx_acc = b.accessor(
        &idx_bytes,
        UNSIGNED_INT,
        indices.len(),
        "SCALAR",
        Some(ELEMENT_ARRAY_BUFFER),
        None,
    );

    // Skin: inverse bind matrices undo each joint's rest translation.
    let ibm: Vec<f32> = rest
        .iter()
        .flat_map(|p| Mat4::from_translation(-*p).to_cols_array())
        .collect();
    let ibm_acc = b.accessor(&f32s(ibm), FLOAT, n, "MAT4", None, None);

    // Nodes: 0 = Armature, 1..=n joints, n+1 = mesh.
    let mut nodes: Vec<Value> = vec![json!({
        "name": "Armature",
        "children": sk.joints.iter().enumerate().filter(|(_, j)| j.parent.is_none()).map(|(i, _)| i + 1).collect::<Vec<_>>(),
    })];
    for (j, joint) in sk.joints.iter().enumerate() {
        let mut node = json!({
            "name": joint.name,
            "translation": (joint.offset * to_metres).to_array(),
        });
        let kids: Vec<usize> = sk.children(j).into_iter().map(|k| k + 1).collect();
        if !kids.is_empty() {
            node["children"] = json!(kids);
        }
        nodes.push(node);
    }
    nodes.push(json!({"name": "Body", "mesh": 0, "skin": 0}));

    // Animation.
    let frames = clip.frames.len();
    let times: Vec<f32> = (0..frames).map(|f| f as f32 * clip.frame_time).collect();
    let t_last = times.last().copied().unwrap_or(0.0);
    let time_acc = b.accessor(
        &f32s(times),
        FLOAT,
        frames,
        "SCALAR",
        None,
        Some((vec![0.0], vec![t_last])),
    );
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
    for (j, joint) in sk.joints.iter().enumerate() {
        if joint.end_site {
            continue;
        }
        let rots: Vec<f32> = clip
            .frames
            .iter()
            .flat_map(|p| {
                let q = p.rotations.get(j).copied().unwrap_or(Quat::IDENTITY);
                let q = if q.is_finite() && q.length() > 1e-6 {
                    q.normalize()
                } else {
                    Quat::IDENTITY
                };
                q.to_array()
            })
            .collect();
        let acc = b.accessor(&f32s(rots), FLOAT, frames, "VEC4", None, None);
        channels.push(
            json!({"sampler": samplers.len(), "target": {"node": j + 1, "path": "rotation"}}),
        );
        samplers.push(json!({"input": time_acc, "output": acc, "interpolation": "LINEAR"}));
        if joint.parent.is_none() || joint.has_position() {
            let ts: Vec<f32> = clip
                .frames
                .iter()
                .flat_map(|p| {
                    (p.translations.get(j).copied().unwrap_or(joint.offset) * to_metres).to_array()
                })
                .collect();
            let acc = b.accessor(&f32s(ts), FLOAT, frames, "VEC3", None, None);
            channels.push(json!({"sampler": samplers.len(), "target": {"node": j + 1, "path": "translation"}}));
            samplers.push(json!({"input": time_acc, "output": acc, "interpolation": "LINEAR"}));
        }
    }

    let bin = b.bin;
    let doc = json!({
        "asset": {"version": "2.0", "generator": "figurine"},
        "scene": 0,
        "scenes": [{"name": clip.name, "nodes": [0, n + 1]}],
        "nodes": nodes,
        "meshes": [{"name": "bones", "primitives": [{
            "attributes": {"POSITION": pos_acc, "JOINTS_0": joints_acc, "WEIGHTS_0": weights_acc},
            "indices": idx_acc, "mode": 4
        }]}],
        "skins": [{"name": "skeleton", "inverseBindMatrices": ibm_acc, "skeleton": 0,
                   "joints": (1..=n).collect::<Vec<_>>()}],
        "animations": [{"name": clip.name, "samplers": samplers, "channels": channels}],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": b.views,
        "accessors": b.accessors,
    });
    let mut json_bytes =
        serde_json::to_vec(&doc).map_err(|e| MotionError::Invalid(e.to_string()))?;
    while !json_bytes.len().is_multiple_of(4) {
        json_bytes.push(b' ');
    }
    let total = 12 + 8 + json_bytes.len() + 8 + bin.len();
    let total = u32::try_from(total)
        .map_err(|_| MotionError::Invalid("animation too large for one .glb (4 GiB)".into()))?;
    let mut out = Vec::with_capacity(total as usize);
    out.extend(GLB_MAGIC.to_le_bytes());
    out.extend(2u32.to_le_bytes());
    out.extend(total.to_le_bytes());
    out.extend((json_bytes.len() as u32).to_le_bytes());
    out.extend(CHUNK_JSON.to_le_bytes());
    out.extend(&json_bytes);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(CHUNK_BIN.to_le_bytes());
    out.extend(&bin);
    Ok(out)
}

/// Writes a clip as a .glb file; `to_metres` scales lengths (0.01 for cm data).
pub fn write_glb_path(clip: &Clip, to_metres: f32, path: &Path) -> Result<(), MotionError> {
    let bytes = write_glb_bytes(clip, to_metres)?;
    std::fs::write(path, bytes).map_err(|source| MotionError::Io {
        path: path.to_path_buf(),
        source,
    })
}

fn f32s(v: impl IntoIterator<Item = f32>) -> Vec<u8> {
    v.into_iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// Accumulates the binary chunk, its buffer views and accessors.
#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    /// Appends `bytes` as a new 4-byte-aligned buffer view with one accessor; returns its index.
    fn accessor(
        &mut self,
        bytes: &[u8],
        component: u32,
        count: usize,
        kind: &str,
        target: Option<u32>,
        min_max: Option<(Vec<f32>, Vec<f32>)>,
    ) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut view =
            json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()});
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.bin.extend_from_slice(bytes);
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views.push(view);
        let mut acc = json!({
            "bufferView": self.views.len() - 1,
            "componentType": component,
            "count": count,
            "type": kind,
        });
        if let Some((lo, hi)) = min_max {
            acc["min"] = json!(lo);
            acc["max"] = json!(hi);
        }
        self.accessors.push(acc);
        self.accessors.len() - 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::clip::Pose;
    use crate::motion::skeleton::{Joint, Skeleton};

    #[test]
    fn glb_has_valid_header_and_chunks() {
        let j = Joint::bare;
        let sk = Skeleton {
            joints: vec![j("root", None, Vec3::ZERO), j("a", Some(0), Vec3::Y)],
        };
        let clip = Clip {
            name: "t".into(),
            frame_time: 0.1,
            frames: vec![Pose::rest(&sk), Pose::rest(&sk)],
            skeleton: sk,
        };
        let g = write_glb_bytes(&clip, 1.0).unwrap();
        assert_eq!(&g[0..4], b"glTF");
        assert_eq!(
            u32::from_le_bytes([g[8], g[9], g[10], g[11]]) as usize,
            g.len()
        );
        let jlen = u32::from_le_bytes([g[12], g[13], g[14], g[15]]) as usize;
        let doc: Value = serde_json::from_slice(&g[20..20 + jlen]).unwrap();
        assert_eq!(doc["nodes"].as_array().unwrap().len(), 4);
        assert_eq!(
            doc["animations"][0]["channels"].as_array().unwrap().len(),
            3
        );
        assert!(write_glb_bytes(&clip, f32::NAN).is_err());
    }
}
