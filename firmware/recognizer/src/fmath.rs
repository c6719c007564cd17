//! The one place where the recognizer does non-trivial float math.
//!
//! Every routine calls `libm` explicitly (correctly rounded or close to it, deterministic,
//! the same code on the host and on the Cortex-M4F), so host simulation and the MCU compute
//! the same bits — except the square root, which is correctly rounded by IEEE 754 wherever it
//! is computed and so comes from the FPU's instruction on the MCU ([`figurine_fpu`]). std's float methods are never used in this crate. micromath was measured
//! and rejected for this pipeline: its `sqrt(2.0)` returned 1.5 on this machine, which would
//! move speed-relative token thresholds by up to 6 % and shift every feature using norms;
//! the pipeline's float budget is small enough that libm's cost is acceptable.

/// Square root, correctly rounded: `VSQRT.F32` on the Cortex-M4F, `libm::sqrtf` on the host
/// (the same bits); negative or NaN input gives NaN as usual.
#[inline]
pub fn sqrt(x: f32) -> f32 {
    figurine_fpu::sqrt(x)
}

/// Absolute value (bit operation, exact).
#[inline]
pub fn abs(x: f32) -> f32 {
    libm::fabsf(x)
}

/// Natural logarithm.
#[inline]
pub fn ln(x: f32) -> f32 {
    libm::logf(x)
}

/// e^x.
#[inline]
pub fn exp(x: f32) -> f32 {
    libm::expf(x)
}

/// Hyperbolic tangent.
#[inline]
pub fn tanh(x: f32) -> f32 {
    libm::tanhf(x)
}

/// Cube root, in single precision only (within 1 ulp of `libm::cbrtf`, measured in the
/// tests below).
///
/// `libm::cbrtf` computes in `f64`, which on the Cortex-M4F (single-precision FPU) pulls in
/// ≈ 3 KiB of software double arithmetic for this one call; this routine uses only `f32`
/// operations, which are IEEE-exact on both host and MCU, so the bits still agree.
pub fn cbrt(x: f32) -> f32 {
    if x == 0.0 || !is_finite(x) {
        return x;
    }
    let a = abs(x);
    // Subnormal and tiny inputs are scaled into the normal range first (2¹²⁰ = (2⁴⁰)³).
    let (a, unscale) = if a < 1e-30 {
        (
            a * f32::from_bits((127 + 120) << 23),
            f32::from_bits((127 - 40) << 23),
        )
    } else {
        (a, 1.0)
    };
    // First guess from the exponent bits (divide the biased exponent by three), ≈ 3 % off;
    // three Newton steps y ← y + (a / y² − y) / 3 bring it to the last bit or two (written
    // without y³, which would overflow near the top of the range).
    let mut y = f32::from_bits(a.to_bits() / 3 + 709_921_077);
    for _ in 0..3 {
        y += (a / (y * y) - y) / 3.0;
    }
    let y = y * unscale;
    if x < 0.0 {
        -y
    } else {
        y
    }
}

/// Rounds half away from zero.
#[inline]
pub fn round(x: f32) -> f32 {
    libm::roundf(x)
}

/// True when `x` is neither NaN nor infinite (bit test, no std).
#[inline]
pub fn is_finite(x: f32) -> bool {
    (x.to_bits() & 0x7f80_0000) != 0x7f80_0000
}

/// The larger of two values (NaN-ignoring like `fmaxf`).
#[inline]
pub fn max(a: f32, b: f32) -> f32 {
    libm::fmaxf(a, b)
}

/// The smaller of two values (NaN-ignoring like `fminf`).
#[inline]
pub fn min(a: f32, b: f32) -> f32 {
    libm::fminf(a, b)
}

/// Clamps `x` to `[lo, hi]`; NaN maps to `lo`.
#[inline]
pub fn clamp(x: f32, lo: f32, hi: f32) -> f32 {
    if x.is_nan() {
        lo
    } else {
        min(max(x, lo), hi)
    }
}

/// Angle of the point (x, y) from the +x axis, radians in [−π, π], within 0.003 rad
/// (micromath's rational approximation, measured in the tests below). Approximate on
/// purpose: it only says how far one sample turned from the last, where a few thousandths
/// of a radian do not matter, and libm's `atan2f` cost 1 KiB of flash and 140 instructions
/// a sample. Pure `f32` operations, so the host and the MCU still agree bit for bit.
#[inline]
pub fn atan2(y: f32, x: f32) -> f32 {
    <f32 as micromath::F32Ext>::atan2(y, x)
}

/// Euclidean norm of a 3-vector.
#[inline]
pub fn norm3(v: [f32; 3]) -> f32 {
    sqrt(dot3(v, v))
}

/// Dot product of two 3-vectors.
#[inline]
pub fn dot3(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product of two 3-vectors.
#[inline]
pub fn cross3(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Hamilton product of quaternions (w, x, y, z).
#[inline]
pub fn qmul(a: [f32; 4], b: [f32; 4]) -> [f32; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// Quaternion conjugate.
#[inline]
pub fn qconj(q: [f32; 4]) -> [f32; 4] {
    [q[0], -q[1], -q[2], -q[3]]
}

/// Dot product of two quaternions.
#[inline]
pub fn qdot(a: [f32; 4], b: [f32; 4]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}

/// Rotates world vector `v` into the frame of unit quaternion `q` (object→world), i.e. `q⁻¹ v q`.
#[inline]
pub fn rotate_inv(q: [f32; 4], v: [f32; 3]) -> [f32; 3] {
    // R^T v with R from q; written out to avoid two quaternion products.
    let [w, x, y, z] = q;
    let (xx, yy, zz) = (x * x, y * y, z * z);
    let (xy, xz, yz) = (x * y, x * z, y * z);
    let (wx, wy, wz) = (w * x, w * y, w * z);
    [
        (1.0 - 2.0 * (yy + zz)) * v[0] + 2.0 * (xy + wz) * v[1] + 2.0 * (xz - wy) * v[2],
        2.0 * (xy - wz) * v[0] + (1.0 - 2.0 * (xx + zz)) * v[1] + 2.0 * (yz + wx) * v[2],
        2.0 * (xz + wy) * v[0] + 2.0 * (yz - wx) * v[1] + (1.0 - 2.0 * (xx + yy)) * v[2],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atan2_is_within_three_thousandths_of_a_radian() {
        let mut worst = 0.0f32;
        // Every half degree strictly inside (−π, π), where both sides agree on the branch.
        for i in 1..720 {
            let a = (i as f32 - 360.0).to_radians() * 0.5;
            for r in [1e-3f32, 0.5, 1.0, 7.0] {
                let (y, x) = (r * libm::sinf(a), r * libm::cosf(a));
                worst = worst.max(libm::fabsf(atan2(y, x) - libm::atan2f(y, x)));
            }
        }
        assert!(worst < 0.003, "worst error {worst} rad");
        assert_eq!(atan2(0.0, 1.0), 0.0);
    }

    #[test]
    fn sqrt_is_accurate_where_micromath_is_not() {
        assert_eq!(sqrt(2.0), core::f32::consts::SQRT_2);
        assert_eq!(sqrt(4.0), 2.0);
    }

    #[test]
    fn cbrt_agrees_with_libm_to_one_ulp() {
        let ulps = |a: f32, b: f32| (a.to_bits() as i64 - b.to_bits() as i64).abs();
        // Every 4099th positive float, subnormals included, and its negative.
        let mut worst = 0;
        for bits in (1..0x7f80_0000u32).step_by(4099) {
            let x = f32::from_bits(bits);
            for v in [x, -x] {
                let d = ulps(cbrt(v), libm::cbrtf(v));
                assert!(
                    d <= 1,
                    "cbrt({v:e}) = {:e}, libm {:e}",
                    cbrt(v),
                    libm::cbrtf(v)
                );
                worst = worst.max(d);
            }
        }
        assert_eq!(cbrt(27.0), 3.0);
        assert_eq!(cbrt(-8.0), -2.0);
        assert_eq!(cbrt(0.0), 0.0);
        assert!(cbrt(f32::NAN).is_nan());
        assert_eq!(cbrt(f32::INFINITY), f32::INFINITY);
        assert!(worst <= 1);
    }

    #[test]
    fn finiteness_by_bits() {
        assert!(is_finite(1.0));
        assert!(is_finite(-0.0));
        assert!(!is_finite(f32::NAN));
        assert!(!is_finite(f32::INFINITY));
        assert!(!is_finite(f32::NEG_INFINITY));
    }

    #[test]
    fn rotate_inv_undoes_a_yaw() {
        // 90° about +Y maps object +Z (front) to world +X.
        let h = core::f32::consts::FRAC_1_SQRT_2;
        let q = [h, 0.0, h, 0.0];
        let local = rotate_inv(q, [1.0, 0.0, 0.0]);
        assert!((local[2] - 1.0).abs() < 1e-6, "{local:?}");
        assert!(local[0].abs() < 1e-6 && local[1].abs() < 1e-6);
    }

    #[test]
    fn clamp_maps_nan_low() {
        assert_eq!(clamp(f32::NAN, -1.0, 1.0), -1.0);
        assert_eq!(clamp(3.0, -1.0, 1.0), 1.0);
    }
}
