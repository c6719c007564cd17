//! The Cortex-M4F's square-root instruction for figurine's recognizer, `libm` elsewhere.
//!
//! The recognizer computes every float through `libm` so that host and MCU produce the same
//! bits. `libm::sqrtf` on a Cortex-M4F is a software routine (≈ 60 instructions and a 256-byte
//! table of flash) although the FPU has `VSQRT.F32`. Both are IEEE 754 square roots, correctly
//! rounded, so they return the same bits for every input; on x86-64 `libm` itself uses the SSE
//! instruction. This crate gives the recognizer the instruction on the MCU (hard-float ARM) and
//! `libm::sqrtf` everywhere else, and keeps the one `unsafe` block out of the recognizer, which
//! forbids it. The firmware's QEMU tests compare its events bit for bit with the host's.
#![no_std]
#![warn(missing_docs)]

/// Correctly rounded single-precision square root (NaN for negative input).
#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
// One copy for every caller: a call costs less flash than the five instructions inline.
#[inline(never)]
#[allow(unsafe_code)] // The one instruction; see the SAFETY note.
pub fn sqrt(x: f32) -> f32 {
    let bits: u32;
    // SAFETY: the instructions only use `s0` (saved and restored on the stack around them) and
    // the two general registers given; every hard-float ARM target has VFP's VSQRT.F32. The
    // register class for `s0` needs a target feature this single-precision FPU's target does
    // not name, hence the explicit save instead of a clobber.
    unsafe {
        core::arch::asm!(
            "vpush {{s0}}",
            "vmov s0, {x}",
            "vsqrt.f32 s0, s0",
            "vmov {y}, s0",
            "vpop {{s0}}",
            x = in(reg) x.to_bits(),
            y = lateout(reg) bits,
            options(preserves_flags)
        );
    }
    f32::from_bits(bits)
}

/// Correctly rounded single-precision square root (NaN for negative input).
#[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
#[inline]
pub fn sqrt(x: f32) -> f32 {
    libm::sqrtf(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_roots_are_correctly_rounded() {
        assert_eq!(sqrt(4.0), 2.0);
        assert_eq!(sqrt(2.0), core::f32::consts::SQRT_2);
        assert_eq!(sqrt(0.0), 0.0);
        assert!(sqrt(-1.0).is_nan());
        assert_eq!(sqrt(f32::INFINITY), f32::INFINITY);
        // Exact squares of every representable magnitude class come back exactly.
        let mut x = 1.0e-18f32;
        while x < 1.0e18 {
            let r = sqrt(x * x);
            assert_eq!(r, x, "{x:e}");
            x *= 3.7;
        }
    }
}
