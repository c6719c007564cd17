//! Stage 1 — Savitzky–Golay denoising (3rd order) with derivative outputs.
//!
//! A cubic is least-squares fitted over a centred window of [`SG_WINDOW`] ticks of the 100 Hz
//! grid (110 ms); its value and first three derivatives at the centre give the smoothed pose,
//! velocity, acceleration and jerk of every channel (3 position + 4 quaternion components).
//! Added latency: [`SG_HALF`] ticks = 50 ms. The coefficients are computed at compile time.
//! RAM: `SG_WINDOW × (7 f32 + 2 u64 + u32)` ≈ 0.5 KiB.

use crate::intake::{Tick, TICK_S};

/// Half window, ticks.
pub const SG_HALF: usize = 5;
/// Window length, ticks (odd).
pub const SG_WINDOW: usize = 2 * SG_HALF + 1;
/// Number of filtered channels: x, y, z, qw, qx, qy, qz.
pub const CHANNELS: usize = 7;

/// Coefficients `[derivative order][window offset]` for unit tick spacing.
const COEFFS: [[f64; SG_WINDOW]; 4] = sg_coefficients();

const fn sg_coefficients() -> [[f64; SG_WINDOW]; 4] {
    // Normal matrix A[j][k] = Σ i^(j+k) over the window, inverted by Gauss–Jordan.
    let h = SG_HALF as i64;
    let mut a = [[0.0f64; 8]; 4];
    let mut j = 0;
    while j < 4 {
        let mut k = 0;
        while k < 4 {
            let mut sum = 0.0;
            let mut i = -h;
            while i <= h {
                let mut p = 1.0;
                let mut e = 0;
                while e < j + k {
                    p *= i as f64;
                    e += 1;
                }
                sum += p;
                i += 1;
            }
            a[j][k] = sum;
            k += 1;
        }
        a[j][4 + j] = 1.0;
        j += 1;
    }
    let mut col = 0;
    while col < 4 {
        let piv = a[col][col];
        let mut c = 0;
        while c < 8 {
            a[col][c] /= piv;
            c += 1;
        }
        let mut r = 0;
        while r < 4 {
            if r != col {
                let f = a[r][col];
                let mut c = 0;
                while c < 8 {
                    a[r][c] -= f * a[col][c];
                    c += 1;
                }
            }
            r += 1;
        }
        col += 1;
    }
    let fact = [1.0, 1.0, 2.0, 6.0];
    let mut out = [[0.0f64; SG_WINDOW]; 4];
    let mut d = 0;
    while d < 4 {
        let mut idx = 0;
        while idx < SG_WINDOW {
            let i = idx as i64 - h;
            let mut sum = 0.0;
            let mut p = 1.0;
            let mut jj = 0;
            while jj < 4 {
                sum += a[d][4 + jj] * p;
                p *= i as f64;
                jj += 1;
            }
            out[d][idx] = sum * fact[d];
            idx += 1;
        }
        d += 1;
    }
    out
}

/// Per-tick coefficients scaled by the tick period, f32 (`[order][offset]`).
const SCALED: [[f32; SG_WINDOW]; 4] = scaled();

const fn scaled() -> [[f32; SG_WINDOW]; 4] {
    let dt = TICK_S as f64;
    let scale = [1.0, 1.0 / dt, 1.0 / (dt * dt), 1.0 / (dt * dt * dt)];
    let mut out = [[0.0f32; SG_WINDOW]; 4];
    let mut d = 0;
    while d < 4 {
        let mut i = 0;
        while i < SG_WINDOW {
            out[d][i] = (COEFFS[d][i] * scale[d]) as f32;
            i += 1;
        }
        d += 1;
    }
    out
}

/// The filter output for the centre tick of the window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Smoothed {
    /// The centre tick (time, sequence number of the input sample that closed it).
    pub tick: Tick,
    /// `[order][channel]`: value, d/dt, d²/dt², d³/dt³ (units of the channel per sᵏ).
    pub d: [[f32; CHANNELS]; 4],
}

/// Streaming Savitzky–Golay filter over a ring of the last [`SG_WINDOW`] ticks.
#[derive(Debug, Clone)]
pub struct SavGol {
    ring: [Option<Tick>; SG_WINDOW],
    head: usize,
    len: usize,
}

impl Default for SavGol {
    fn default() -> Self {
        Self::new()
    }
}

impl SavGol {
    /// An empty filter.
    pub const fn new() -> Self {
        SavGol {
            ring: [None; SG_WINDOW],
            head: 0,
            len: 0,
        }
    }

    /// Forgets all ticks (after a gap).
    pub fn reset(&mut self) {
        *self = Self::new();
    }

    /// Pushes a tick; once the window is full, returns the filtered centre tick.
    pub fn push(&mut self, t: Tick) -> Option<Smoothed> {
        if let Some(slot) = self.ring.get_mut(self.head) {
            *slot = Some(t);
        }
        self.head = (self.head + 1) % SG_WINDOW;
        if self.len < SG_WINDOW {
            self.len += 1;
        }
        if self.len < SG_WINDOW {
            return None;
        }
        let mut d = [[0.0f32; CHANNELS]; 4];
        let mut centre = None;
        #[allow(clippy::needless_range_loop)] // k also picks the ring slot
        for k in 0..SG_WINDOW {
            // Oldest first: the slot at `head` is the oldest after the increment.
            let Some(Some(tk)) = self.ring.get((self.head + k) % SG_WINDOW) else {
                return None;
            };
            if k == SG_HALF {
                centre = Some(*tk);
            }
            let ch = [
                tk.pos[0], tk.pos[1], tk.pos[2], tk.quat[0], tk.quat[1], tk.quat[2], tk.quat[3],
            ];
            for (row, coeffs) in d.iter_mut().zip(&SCALED) {
                let c = coeffs.get(k).copied().unwrap_or(0.0);
                for (acc, v) in row.iter_mut().zip(ch) {
                    *acc += c * v;
                }
            }
        }
        centre.map(|tick| Smoothed { tick, d })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tick(i: u64, x: f32) -> Tick {
        Tick {
            t_us: i * 10_000,
            pos: [x, 0.0, 0.0],
            quat: [1.0, 0.0, 0.0, 0.0],
            seq: i as u32,
            sample_t_us: i * 10_000,
        }
    }

    #[test]
    fn cubic_is_reproduced_exactly_with_derivatives() {
        let f = |t: f32| 0.3 + 2.0 * t - 1.5 * t * t + 4.0 * t * t * t;
        let mut sg = SavGol::new();
        let mut last = None;
        for i in 0..20u64 {
            if let Some(o) = sg.push(tick(i, f(i as f32 * TICK_S))) {
                last = Some(o);
            }
        }
        let o = last.unwrap();
        let t = o.tick.t_us as f32 * 1e-6;
        assert_eq!(o.tick.seq, 14);
        assert!((o.d[0][0] - f(t)).abs() < 1e-4);
        assert!(
            (o.d[1][0] - (2.0 - 3.0 * t + 12.0 * t * t)).abs() < 1e-2,
            "{}",
            o.d[1][0]
        );
        assert!((o.d[2][0] - (-3.0 + 24.0 * t)).abs() < 0.2, "{}", o.d[2][0]);
        assert!((o.d[3][0] - 24.0).abs() < 2.0, "{}", o.d[3][0]);
        // Constant channels have zero derivatives.
        assert!(o.d[1][3].abs() < 1e-3);
    }

    #[test]
    fn needs_a_full_window_and_resets() {
        let mut sg = SavGol::new();
        for i in 0..(SG_WINDOW as u64 - 1) {
            assert!(sg.push(tick(i, 0.0)).is_none());
        }
        assert!(sg.push(tick(99, 0.0)).is_some());
        sg.reset();
        assert!(sg.push(tick(0, 0.0)).is_none());
    }
}
