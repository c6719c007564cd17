//! Stage 2 — the figurine's own frame: linear and angular motion in object coordinates.
//!
//! Linear quantities are the filter's world derivatives rotated into the object frame
//! (`Rᵀ ṗ`, `Rᵀ p̈`, `Rᵀ p⃛`). Angular velocity comes from the quaternion derivative, not from
//! Euler differences (which break near gimbal lock): `ω_local = 2·vec(q* ⊗ q̇)`, and likewise
//! `α_local = 2·vec(q* ⊗ q̈)` and the angular jerk `2·vec(q̇* ⊗ q̈ + q* ⊗ q⃛)`. Because q is made
//! sign-continuous at intake, q and −q give the same result. Object frame: +X left, +Y up,
//! +Z front.

use crate::filter::Smoothed;
use crate::fmath;
use crate::intake::Tick;

/// Kinematics of one filtered tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kinematics {
    /// The tick (time and the input sample that closed it).
    pub tick: Tick,
    /// Linear velocity in the object frame, m/s.
    pub v: [f32; 3],
    /// Linear acceleration in the object frame, m/s².
    pub a: [f32; 3],
    /// Linear jerk in the object frame, m/s³.
    pub j: [f32; 3],
    /// Angular velocity in the object frame, rad/s.
    pub w: [f32; 3],
    /// Angular acceleration in the object frame, rad/s².
    pub wa: [f32; 3],
    /// Angular jerk in the object frame, rad/s³.
    pub wj: [f32; 3],
    /// World velocity, m/s.
    pub world_v: [f32; 3],
    /// World acceleration, m/s².
    pub world_a: [f32; 3],
    /// World jerk, m/s³.
    pub world_j: [f32; 3],
}

fn vec_part(q: [f32; 4], s: f32) -> [f32; 3] {
    [2.0 * q[1] * s, 2.0 * q[2] * s, 2.0 * q[3] * s]
}

fn pick(d: &[f32; 7], off: usize) -> [f32; 4] {
    [d[off], d[off + 1], d[off + 2], d[off + 3]]
}

/// Computes the object-frame kinematics of a filtered tick.
pub fn kinematics(s: &Smoothed) -> Kinematics {
    let q = pick(&s.d[0], 3);
    let n2 = fmath::qdot(q, q);
    let inv_n2 = if n2 > 1e-12 { 1.0 / n2 } else { 1.0 };
    let inv_n = fmath::sqrt(inv_n2);
    let qu = [q[0] * inv_n, q[1] * inv_n, q[2] * inv_n, q[3] * inv_n];
    let qd = pick(&s.d[1], 3);
    let qdd = pick(&s.d[2], 3);
    let qddd = pick(&s.d[3], 3);
    let qc = fmath::qconj(q);
    let w = vec_part(fmath::qmul(qc, qd), inv_n2);
    let wa = vec_part(fmath::qmul(qc, qdd), inv_n2);
    let a1 = fmath::qmul(fmath::qconj(qd), qdd);
    let a2 = fmath::qmul(qc, qddd);
    let wj = vec_part([0.0, a1[1] + a2[1], a1[2] + a2[2], a1[3] + a2[3]], inv_n2);
    let world_v = [s.d[1][0], s.d[1][1], s.d[1][2]];
    let world_a = [s.d[2][0], s.d[2][1], s.d[2][2]];
    let world_j = [s.d[3][0], s.d[3][1], s.d[3][2]];
    Kinematics {
        tick: s.tick,
        v: fmath::rotate_inv(qu, world_v),
        a: fmath::rotate_inv(qu, world_a),
        j: fmath::rotate_inv(qu, world_j),
        w,
        wa,
        wj,
        world_v,
        world_a,
        world_j,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::SavGol;
    use crate::intake::TICK_S;

    fn run(f: impl Fn(f32) -> ([f32; 3], [f32; 4])) -> Kinematics {
        let mut sg = SavGol::new();
        let mut out = None;
        for i in 0..30u64 {
            let (pos, quat) = f(i as f32 * TICK_S);
            let t = Tick {
                t_us: i * 10_000,
                pos,
                quat,
                seq: i as u32,
                sample_t_us: i * 10_000,
            };
            if let Some(s) = sg.push(t) {
                out = Some(kinematics(&s));
            }
        }
        out.unwrap()
    }

    fn yaw(a: f32) -> [f32; 4] {
        [libm::cosf(a / 2.0), 0.0, libm::sinf(a / 2.0), 0.0]
    }

    #[test]
    fn forward_motion_is_local_plus_z_whatever_the_heading() {
        for heading in [0.0f32, 1.0, 2.5, -2.0] {
            let q = yaw(heading);
            // Object front (+Z) in world for this heading.
            let fwd = [libm::sinf(heading), 0.0, libm::cosf(heading)];
            let k = run(|t| ([fwd[0] * 0.5 * t, 0.3, fwd[2] * 0.5 * t], q));
            assert!((k.v[2] - 0.5).abs() < 1e-3, "{heading}: {:?}", k.v);
            assert!(k.v[0].abs() < 1e-3 && k.v[1].abs() < 1e-3);
            assert!(fmath::norm3(k.w) < 1e-3);
        }
    }

    #[test]
    fn yaw_rate_is_local_y_and_sign_of_q_does_not_matter() {
        let k = run(|t| ([0.0; 3], yaw(2.0 * t)));
        assert!((k.w[1] - 2.0).abs() < 1e-2, "{:?}", k.w);
        let k2 = run(|t| {
            let q = yaw(2.0 * t);
            ([0.0; 3], [-q[0], -q[1], -q[2], -q[3]])
        });
        assert!((k2.w[1] - 2.0).abs() < 1e-2, "{:?}", k2.w);
    }
}
