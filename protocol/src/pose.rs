//! The quantised pose sample carried by [`crate::HostToDevice::Pose`].
//!
//! Seven plain `f32`s and a timestamp would not fit the 32-byte frame budget, so the pose is
//! quantised (all resolutions below are exact, not approximate):
//!
//! | field | wire type | unit / resolution | range |
//! |---|---|---|---|
//! | `seq` | u16 varint (≤ 3 B) | sample counter, wraps at 65 536 | — |
//! | `t_us` | u32 varint (≤ 5 B) | 1 µs, wraps every 71.6 min ([`TimeUnwrapper`]) | — |
//! | `pos` | 3 × i32 zigzag varint (≤ 3 B each in range) | 0.1 mm ([`POS_UNIT_M`]) | ±[`POS_LIMIT_M`] = ±100 m |
//! | `rot` | 6 bytes, smallest-three | 15 bits per component: ≤ 3.1e-5 per component, ≈ 1e-4 rad | unit quaternions |
//!
//! Smallest-three: the component of largest magnitude is dropped (its sign made positive, since
//! `q` and `-q` are the same rotation) and the other three, each in ±1/√2, are stored in 15 bits.
//! Decoding recomputes the dropped one as `sqrt(1 − a² − b² − c²)` with `libm::sqrtf`, which is
//! correctly rounded, so the firmware and host simulation get the same `f32` bits.

use serde::{Deserialize, Serialize};

/// Position resolution: one unit of [`Pose::pos`] is 0.1 mm.
pub const POS_UNIT_M: f64 = 1e-4;
/// Largest encodable |coordinate|, metres; farther positions are rejected by [`Pose::quantize`].
pub const POS_LIMIT_M: f64 = 100.0;
/// Quantisation steps on each side of zero for a smallest-three component.
const ROT_STEPS: f64 = 16383.0;
/// Largest magnitude of a non-dropped component of a unit quaternion: 1/√2.
const ROT_RANGE: f64 = core::f64::consts::FRAC_1_SQRT_2;

/// A pose sample as sent on the wire (quantised; see the module docs for units).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Pose {
    /// Sample counter set by the sender, +1 per sample, wrapping; gaps reveal lost frames.
    pub seq: u16,
    /// Sample time on the sender's clock, microseconds, wrapping at 2³².
    pub t_us: u32,
    /// Position in world coordinates (+Y up), units of 0.1 mm.
    pub pos: [i32; 3],
    /// Orientation (object → world), smallest-three packed, little-endian 48 bits.
    pub rot: [u8; 6],
}

/// Why a pose could not be quantised.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PoseQuantizeError {
    /// A time, position or quaternion value is NaN or infinite.
    NotFinite,
    /// A coordinate exceeds ±[`POS_LIMIT_M`].
    OutOfRange,
    /// The quaternion has (nearly) zero length and names no rotation.
    ZeroQuaternion,
}

impl core::fmt::Display for PoseQuantizeError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            PoseQuantizeError::NotFinite => "pose has a NaN or infinite value",
            PoseQuantizeError::OutOfRange => "position beyond ±100 m",
            PoseQuantizeError::ZeroQuaternion => "zero-length quaternion",
        })
    }
}

fn round_to_i64(x: f64) -> i64 {
    // `as` saturates and maps NaN to 0; callers reject non-finite values first.
    if x >= 0.0 {
        (x + 0.5) as i64
    } else {
        (x - 0.5) as i64
    }
}

impl Pose {
    /// Quantises a pose: `t_s` seconds, `pos_m` metres, `quat` (w, x, y, z), any length > 0
    /// and either sign.
    pub fn quantize(
        seq: u16,
        t_s: f64,
        pos_m: [f64; 3],
        quat: [f64; 4],
    ) -> Result<Pose, PoseQuantizeError> {
        if !t_s.is_finite() || pos_m.iter().chain(quat.iter()).any(|v| !v.is_finite()) {
            return Err(PoseQuantizeError::NotFinite);
        }
        if pos_m.iter().any(|v| *v > POS_LIMIT_M || *v < -POS_LIMIT_M) {
            return Err(PoseQuantizeError::OutOfRange);
        }
        let norm2: f64 = quat.iter().map(|c| c * c).sum();
        if norm2 < 1e-12 {
            return Err(PoseQuantizeError::ZeroQuaternion);
        }
        let inv = 1.0 / libm::sqrt(norm2);
        let q = quat.map(|c| c * inv);
        let mut largest = 0usize;
        for i in 1..4 {
            if q[i].abs() > q[largest].abs() {
                largest = i;
            }
        }
        let sign = if q[largest] < 0.0 { -1.0 } else { 1.0 };
        let mut packed: u64 = (largest as u64) << 45;
        let mut slot = 0u32;
        for (i, c) in q.iter().enumerate() {
            if i == largest {
                continue;
            }
            let v = (sign * c / ROT_RANGE).clamp(-1.0, 1.0);
            let u = (round_to_i64(v * ROT_STEPS) + ROT_STEPS as i64) as u64;
            packed |= (u & 0x7FFF) << (15 * slot);
            slot += 1;
        }
        let bytes = packed.to_le_bytes();
        let rot = [bytes[0], bytes[1], bytes[2], bytes[3], bytes[4], bytes[5]];
        let t_us = round_to_i64(t_s * 1e6) as u32;
        let pos = pos_m.map(|v| round_to_i64(v / POS_UNIT_M) as i32);
        Ok(Pose {
            seq,
            t_us,
            pos,
            rot,
        })
    }

    /// Position in metres as `f32`, exactly as the firmware sees it.
    pub fn position_m(&self) -> [f32; 3] {
        self.pos.map(|v| v as f32 * (POS_UNIT_M as f32))
    }

    /// Unit quaternion (w, x, y, z) as `f32`, exactly as the firmware sees it. Malformed
    /// bit patterns (a component index or value out of range) still give a finite unit
    /// quaternion: decoding never fails.
    pub fn orientation(&self) -> [f32; 4] {
        let mut b = [0u8; 8];
        b[..6].copy_from_slice(&self.rot);
        let packed = u64::from_le_bytes(b);
        let largest = ((packed >> 45) & 0x3) as usize;
        let step = (ROT_RANGE / ROT_STEPS) as f32;
        let mut small = [0f32; 3];
        for (slot, s) in small.iter_mut().enumerate() {
            let u = ((packed >> (15 * slot)) & 0x7FFF) as i32 - ROT_STEPS as i32;
            *s = u as f32 * step;
        }
        let sum = small[0] * small[0] + small[1] * small[1] + small[2] * small[2];
        // Correctly rounded everywhere: the FPU's instruction on the MCU, the same bits as
        // the host's.
        let big = figurine_fpu::sqrt((1.0 - sum).max(0.0));
        let mut q = [0f32; 4];
        // The three small components fill the other slots in order (an iterator, not an
        // index: nothing on this decoding path can panic).
        let mut rest = small.iter();
        for (i, c) in q.iter_mut().enumerate() {
            *c = if i == largest {
                big
            } else {
                rest.next().copied().unwrap_or(0.0)
            };
        }
        q
    }
}

/// Extends a wrapping 32-bit microsecond clock to 64 bits, so a session can run for years.
///
/// Each new raw value moves the extended time by the signed 32-bit difference from the previous
/// one: forward steps up to 35 minutes are understood, and time going backwards stays visible
/// (as a smaller extended value) for the recognizer to count and skip.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TimeUnwrapper {
    last: Option<(u32, u64)>,
}

impl TimeUnwrapper {
    /// Extended time of `raw_us`, microseconds.
    pub fn unwrap(&mut self, raw_us: u32) -> u64 {
        let ext = match self.last {
            None => u64::from(raw_us),
            Some((prev_raw, prev_ext)) => {
                let delta = raw_us.wrapping_sub(prev_raw) as i32;
                prev_ext.saturating_add_signed(i64::from(delta))
            }
        };
        self.last = Some((raw_us, ext));
        ext
    }
}

/// Extends the wrapping 16-bit pose sequence number to 32 bits, the same way on both sides.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SeqUnwrapper {
    last: Option<(u16, u32)>,
}

impl SeqUnwrapper {
    /// Extended sequence number of `raw`.
    pub fn unwrap(&mut self, raw: u16) -> u32 {
        let ext = match self.last {
            None => u32::from(raw),
            Some((prev_raw, prev_ext)) => {
                let delta = raw.wrapping_sub(prev_raw) as i16;
                prev_ext.saturating_add_signed(i32::from(delta))
            }
        };
        self.last = Some((raw, ext));
        ext
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Rotation angle between `a` and `b`, radians, robust near zero (atan2, not acos).
    fn angle_between(a: [f32; 4], b: [f64; 4]) -> f64 {
        let nb = libm::sqrt(b.iter().map(|c| c * c).sum::<f64>());
        let b = b.map(|c| c / nb);
        let a = a.map(f64::from);
        // d = conj(a) * b
        let w = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
        let x = a[0] * b[1] - a[1] * b[0] - a[2] * b[3] + a[3] * b[2];
        let y = a[0] * b[2] + a[1] * b[3] - a[2] * b[0] - a[3] * b[1];
        let z = a[0] * b[3] - a[1] * b[2] + a[2] * b[1] - a[3] * b[0];
        2.0 * libm::atan2(libm::sqrt(x * x + y * y + z * z), w.abs())
    }

    #[test]
    fn identity_and_negated_quaternion_decode_alike() {
        let a = Pose::quantize(0, 0.0, [0.0; 3], [1.0, 0.0, 0.0, 0.0]).unwrap();
        let b = Pose::quantize(0, 0.0, [0.0; 3], [-1.0, 0.0, 0.0, 0.0]).unwrap();
        assert_eq!(a, b);
        assert_eq!(a.orientation(), [1.0, 0.0, 0.0, 0.0]);
    }

    #[test]
    fn rejects_bad_values() {
        let q = [1.0, 0.0, 0.0, 0.0];
        assert_eq!(
            Pose::quantize(0, f64::NAN, [0.0; 3], q),
            Err(PoseQuantizeError::NotFinite)
        );
        assert_eq!(
            Pose::quantize(0, 0.0, [0.0, f64::INFINITY, 0.0], q),
            Err(PoseQuantizeError::NotFinite)
        );
        assert_eq!(
            Pose::quantize(0, 0.0, [101.0, 0.0, 0.0], q),
            Err(PoseQuantizeError::OutOfRange)
        );
        assert_eq!(
            Pose::quantize(0, 0.0, [0.0; 3], [0.0; 4]),
            Err(PoseQuantizeError::ZeroQuaternion)
        );
    }

    #[test]
    fn time_and_seq_unwrap_across_wraps_and_show_backwards_steps() {
        let mut t = TimeUnwrapper::default();
        assert_eq!(t.unwrap(u32::MAX - 10), u64::from(u32::MAX - 10));
        assert_eq!(t.unwrap(5), u64::from(u32::MAX) + 6);
        assert_eq!(t.unwrap(3), u64::from(u32::MAX) + 4);
        let mut s = SeqUnwrapper::default();
        assert_eq!(s.unwrap(65535), 65535);
        assert_eq!(s.unwrap(0), 65536);
        assert_eq!(s.unwrap(1), 65537);
    }

    #[test]
    fn arbitrary_rot_bytes_decode_to_a_finite_unit_quaternion() {
        for pattern in [[0xFFu8; 6], [0u8; 6], [0x55; 6], [0xAA; 6]] {
            let p = Pose {
                seq: 0,
                t_us: 0,
                pos: [0; 3],
                rot: pattern,
            };
            let q = p.orientation();
            let n: f32 = q.iter().map(|c| c * c).sum();
            assert!(q.iter().all(|c| c.is_finite()));
            assert!((n - 1.0).abs() < 0.6, "{n}");
        }
    }

    proptest! {
        #[test]
        fn quantisation_error_is_within_the_stated_resolution(
            x in -100.0f64..100.0, y in -100.0f64..100.0, z in -100.0f64..100.0,
            qw in -1.0f64..1.0, qx in -1.0f64..1.0, qy in -1.0f64..1.0, qz in -1.0f64..1.0,
            t in 0.0f64..4000.0,
        ) {
            let quat = [qw, qx, qy, qz];
            prop_assume!(quat.iter().map(|c| c * c).sum::<f64>() > 1e-6);
            let p = Pose::quantize(7, t, [x, y, z], quat).unwrap();
            let pos = p.position_m();
            for (a, b) in pos.iter().zip([x, y, z]) {
                // 0.05 mm rounding plus f32 representation at 100 m (≈ 4 µm).
                prop_assert!((f64::from(*a) - b).abs() < 6e-5);
            }
            prop_assert!(angle_between(p.orientation(), quat) < 2e-4);
            prop_assert_eq!(u64::from(p.t_us), (t * 1e6).round() as u64);
        }
    }
}
