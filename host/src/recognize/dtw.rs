//! DTW averaging of example doodles (seed 000 §4.3, after Ciccone et al. 2017).
//!
//! Each example's motion span is resampled at 100 Hz and brought to a common origin and
//! heading (start at the origin, initially facing +Z: the object's yaw is removed, so examples
//! performed anywhere in the room, facing anywhere, average correctly). The example of median
//! duration is the reference; every other example is aligned to it by dynamic time warping
//! with an l2 cost over position (divided by the reference's spatial extent, so the cost is
//! scale-free) and the object's forward and up axes. The average doodle is the mean of the
//! corresponding points per reference instant (quaternions sign-aligned, summed, normalised).

use crate::poselog::{PoseLog, PoseSample};

/// Resampling period for averaging, seconds.
pub const AVG_DT: f64 = 0.01;
/// Still time padded before and after the average doodle, seconds (lets the filter settle).
pub const PAD_S: f64 = 0.4;

type Pt = ([f64; 3], [f64; 4]);

fn qmul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

fn normalise(q: [f64; 4]) -> [f64; 4] {
    let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    if n > 1e-12 {
        q.map(|c| c / n)
    } else {
        [1.0, 0.0, 0.0, 0.0]
    }
}

/// Rotates vector `v` by unit quaternion `q`.
pub fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let p = qmul(
        qmul(q, [0.0, v[0], v[1], v[2]]),
        [q[0], -q[1], -q[2], -q[3]],
    );
    [p[1], p[2], p[3]]
}

/// The samples of `log` between `t0` and `t1` (seconds), resampled every [`AVG_DT`], moved to
/// the origin and rotated so the initial heading is +Z.
pub fn normalised_span(log: &PoseLog, t0: f64, t1: f64) -> Vec<Pt> {
    let s = &log.samples;
    let mut out = Vec::new();
    if s.len() < 2 || t1 <= t0 {
        return out;
    }
    let mut j = 0;
    let mut t = t0;
    let mut prev_q: Option<[f64; 4]> = None;
    while t <= t1 {
        while j + 2 < s.len() && s[j + 1].t < t {
            j += 1;
        }
        let (a, b) = (&s[j], &s[j + 1]);
        let w = if b.t > a.t {
            ((t - a.t) / (b.t - a.t)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let pos = [0, 1, 2].map(|k| a.pos[k] + w * (b.pos[k] - a.pos[k]));
        let qa = normalise(a.quat);
        let mut qb = normalise(b.quat);
        if qa.iter().zip(&qb).map(|(x, y)| x * y).sum::<f64>() < 0.0 {
            qb = qb.map(|c| -c);
        }
        let mut q = normalise([0, 1, 2, 3].map(|k| qa[k] + w * (qb[k] - qa[k])));
        if let Some(p) = prev_q {
            if q.iter().zip(&p).map(|(x, y)| x * y).sum::<f64>() < 0.0 {
                q = q.map(|c| -c);
            }
        }
        prev_q = Some(q);
        out.push((pos, q));
        t += AVG_DT;
    }
    // Remove the start position and the initial yaw.
    let (p0, q0) = out[0];
    let f = rotate(q0, [0.0, 0.0, 1.0]);
    let yaw = f[0].atan2(f[2]);
    let inv = [(yaw / 2.0).cos(), 0.0, -(yaw / 2.0).sin(), 0.0];
    for (p, q) in &mut out {
        let d = [p[0] - p0[0], p[1] - p0[1], p[2] - p0[2]];
        *p = rotate(inv, d);
        *q = normalise(qmul(inv, *q));
    }
    out
}

/// Reflects a normalised span left ↔ right (x → −x; rotations about y and z reverse).
pub fn mirror_span(span: &mut [Pt]) {
    for (p, q) in span.iter_mut() {
        p[0] = -p[0];
        *q = [q[0], q[1], -q[2], -q[3]];
    }
}

fn extent(pts: &[Pt]) -> f64 {
    let n = pts.len().max(1) as f64;
    let c = [0, 1, 2].map(|k| pts.iter().map(|p| p.0[k]).sum::<f64>() / n);
    let var = pts
        .iter()
        .map(|p| (0..3).map(|k| (p.0[k] - c[k]).powi(2)).sum::<f64>())
        .sum::<f64>()
        / n;
    var.sqrt().max(1e-3)
}

fn cost(a: &Pt, b: &Pt, inv_scale: f64) -> f64 {
    let dp: f64 = (0..3)
        .map(|k| ((a.0[k] - b.0[k]) * inv_scale).powi(2))
        .sum();
    let mut dq = 0.0;
    for axis in [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]] {
        let (x, y) = (rotate(a.1, axis), rotate(b.1, axis));
        dq += (0..3).map(|k| (x[k] - y[k]).powi(2)).sum::<f64>();
    }
    dp + 0.5 * dq
}

/// DTW path between `a` (reference) and `b`: for each index of `a`, the indices of `b` mapped
/// to it.
pub fn align(a: &[Pt], b: &[Pt]) -> Vec<Vec<usize>> {
    let (n, m) = (a.len(), b.len());
    let mut map = vec![Vec::new(); n];
    if n == 0 || m == 0 {
        return map;
    }
    let inv_scale = 1.0 / extent(a);
    let mut d = vec![f64::INFINITY; n * m];
    for i in 0..n {
        for j in 0..m {
            let c = cost(&a[i], &b[j], inv_scale);
            let best = if i == 0 && j == 0 {
                0.0
            } else {
                let mut best = f64::INFINITY;
                if i > 0 {
                    best = best.min(d[(i - 1) * m + j]);
                }
                if j > 0 {
                    best = best.min(d[i * m + j - 1]);
                }
                if i > 0 && j > 0 {
                    best = best.min(d[(i - 1) * m + j - 1]);
                }
                best
            };
            d[i * m + j] = c + best;
        }
    }
    let (mut i, mut j) = (n - 1, m - 1);
    loop {
        map[i].push(j);
        if i == 0 && j == 0 {
            break;
        }
        let diag = if i > 0 && j > 0 {
            d[(i - 1) * m + j - 1]
        } else {
            f64::INFINITY
        };
        let up = if i > 0 {
            d[(i - 1) * m + j]
        } else {
            f64::INFINITY
        };
        let left = if j > 0 {
            d[i * m + j - 1]
        } else {
            f64::INFINITY
        };
        if diag <= up && diag <= left {
            i -= 1;
            j -= 1;
        } else if up <= left {
            i -= 1;
        } else {
            j -= 1;
        }
    }
    map
}

/// The DTW average of normalised spans (reference = median length), as a pose log padded with
/// still time at both ends.
pub fn average(spans: &[Vec<Pt>]) -> PoseLog {
    let mut order: Vec<usize> = (0..spans.len()).filter(|&i| !spans[i].is_empty()).collect();
    order.sort_by_key(|&i| spans[i].len());
    let Some(&r) = order.get(order.len() / 2) else {
        return PoseLog::default();
    };
    let reference = &spans[r];
    let mut sum: Vec<([f64; 3], [f64; 4], f64)> =
        reference.iter().map(|p| (p.0, p.1, 1.0)).collect();
    for (k, s) in spans.iter().enumerate() {
        if k == r || s.is_empty() {
            continue;
        }
        let map = align(reference, s);
        for (i, js) in map.iter().enumerate() {
            let w = 1.0 / js.len().max(1) as f64;
            for &j in js {
                let (p, mut q) = s[j];
                if q.iter()
                    .zip(&reference[i].1)
                    .map(|(x, y)| x * y)
                    .sum::<f64>()
                    < 0.0
                {
                    q = q.map(|c| -c);
                }
                for (acc, v) in sum[i].0.iter_mut().zip(p) {
                    *acc += w * v;
                }
                for (acc, v) in sum[i].1.iter_mut().zip(q) {
                    *acc += w * v;
                }
            }
            sum[i].2 += 1.0;
        }
    }
    let mut samples = Vec::new();
    let pts: Vec<Pt> = sum
        .iter()
        .map(|(p, q, n)| (p.map(|c| c / n), normalise(*q)))
        .collect();
    let pad = (PAD_S / AVG_DT) as usize;
    let mut t = 0.0;
    let first = pts[0];
    let last = pts[pts.len() - 1];
    for p in std::iter::repeat_n(first, pad)
        .chain(pts.iter().copied())
        .chain(std::iter::repeat_n(last, pad))
    {
        samples.push(PoseSample {
            t,
            pos: p.0,
            quat: p.1,
        });
        t += AVG_DT;
    }
    PoseLog { samples }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arc(n: usize, height: f64, heading: f64, offset: [f64; 3]) -> PoseLog {
        let q = [(heading / 2.0).cos(), 0.0, (heading / 2.0).sin(), 0.0];
        let samples = (0..n)
            .map(|i| {
                let s = i as f64 / (n - 1) as f64;
                let local = [0.0, height * (std::f64::consts::PI * s).sin(), 0.3 * s];
                let w = rotate(q, local);
                PoseSample {
                    t: i as f64 * 0.01,
                    pos: [w[0] + offset[0], w[1] + offset[1], w[2] + offset[2]],
                    quat: q,
                }
            })
            .collect();
        PoseLog { samples }
    }

    #[test]
    fn spans_are_heading_and_offset_free() {
        let a = normalised_span(&arc(50, 0.2, 0.0, [0.0; 3]), 0.0, 0.49);
        let b = normalised_span(&arc(50, 0.2, 2.0, [3.0, 1.0, -2.0]), 0.0, 0.49);
        for (x, y) in a.iter().zip(&b) {
            for k in 0..3 {
                assert!((x.0[k] - y.0[k]).abs() < 1e-9, "{x:?} {y:?}");
            }
        }
    }

    #[test]
    fn average_of_time_warped_copies_keeps_the_shape() {
        let spans: Vec<_> = [40usize, 50, 70]
            .iter()
            .map(|&n| normalised_span(&arc(n, 0.2, 0.5, [0.0; 3]), 0.0, (n - 1) as f64 * 0.01))
            .collect();
        let avg = average(&spans);
        let peak = avg.samples.iter().map(|s| s.pos[1]).fold(0.0, f64::max);
        assert!((peak - 0.2).abs() < 0.01, "{peak}");
        let end = avg.samples.last().unwrap().pos;
        assert!((end[2] - 0.3).abs() < 0.01, "{end:?}");
    }
}
