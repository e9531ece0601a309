//! The sums against the former whole-series ones
//! ([`reference`](super::reference)).

use super::bandwidth::bandwidth_sums;
use super::*;

/// A seeded series of `n` rows and `p` columns: an over-differenced noise
/// (what the lab's rows have) plus a trend, each column at its own
/// magnitude, some of it changing by powers of ten along the series, so
/// that the scales rise block after block.
fn series(n: usize, p: usize, seed: u64) -> Vec<f64> {
    let mut state = seed | 1;
    let mut noise = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut x = vec![0.0; n * p];
    for j in 0..p {
        let w: Vec<f64> = (0..n + 2).map(|_| noise()).collect();
        let magnitude = 10f64.powi(3 * j as i32 - 4);
        for t in 0..n {
            let grow = if j % 2 == 1 {
                1.0 + (t / 3000) as f64 * 7.0
            } else {
                1.0
            };
            let diff = w[t + 2] - 2.0 * w[t + 1] + w[t];
            x[j * n + t] = magnitude * grow * (diff + 0.05 * (t as f64 * 0.01).sin());
        }
    }
    x
}

fn bounds_of(starts: &[usize], n: usize) -> Vec<usize> {
    let mut b = vec![0];
    b.extend(starts.iter().copied().filter(|&s| s > 0 && s < n));
    b.push(n);
    b
}

/// The Bartlett sum is the former one to rounding (its running sums now
/// start from the carry: measured at most a few 1e-16 of the largest
/// entry), whatever the lags (none, a few, more than a segment, more than
/// a block) and the segments (a short one among them); the same bits
/// whether the columns' stats are known or found on the way.
#[test]
fn the_bartlett_sum_is_the_former_one() {
    let mut scratch = Scratch::default();
    let mut worst = 0.0f64;
    for (n, p, starts) in [
        (7000usize, 2usize, vec![]),
        (9000, 3, vec![2000, 2030, 6500]),
        (5003, 1, vec![17]),
        (12_000, 4, vec![4096]),
    ] {
        let x = series(n, p, n as u64 * 31 + p as u64);
        let bounds = bounds_of(&starts, n);
        let (scales, inverses) = reference::scales(&x, n);
        let stats = Stats {
            max: x
                .chunks_exact(n)
                .map(crate::kernels::reduce::max_abs)
                .collect(),
            ss: vec![1.0; p],
        };
        for lags in [0, 1, 7, 29, 700, 2047, 2048, 2500, 5000] {
            let want = reference::bartlett(&x, n, &inverses, &bounds, lags, &mut Vec::new());
            let bits = |v: &[f64]| v.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            let what = format!("n {n}, p {p}, lags {lags}");
            let plain = Series {
                x: &x,
                n,
                stats: None,
            };
            let (got, got_scales) = bartlett(plain, p, &bounds, lags, &mut scratch);
            assert_eq!(got_scales, scales, "{what}");
            let largest = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (g, w) in got.iter().zip(&want) {
                let rel = (g - w).abs() / largest;
                worst = worst.max(rel);
                assert!(rel < 1e-14, "{what}: {g} vs {w}");
            }
            let known = Series {
                stats: Some(&stats),
                ..plain
            };
            let known = bartlett(known, p, &bounds, lags, &mut scratch);
            assert_eq!(
                (bits(&known.0), &known.1),
                (bits(&got), &got_scales),
                "{what}"
            );
        }
    }
    eprintln!("Bartlett sums: worst difference {worst:e} of the largest entry");
}

/// The automatic bandwidth's two sums are the former ones (lag by lag) to
/// rounding, from two Bartlett sums, with and without the columns' stats;
/// the same bandwidth.
#[test]
fn the_bandwidth_sums_are_the_former_ones() {
    let mut scratch = Scratch::default();
    let mut worst = 0.0f64;
    for (n, p, starts) in [
        (5000usize, 2usize, vec![]),
        (50_000, 2, vec![]),
        (9000, 3, vec![2000, 2030, 6500]),
        (20_000, 4, vec![4096, 4100]),
        (600, 1, vec![300]),
    ] {
        let x = series(n, p, n as u64 + 7 * p as u64);
        let bounds = bounds_of(&starts, n);
        let (_, inverses) = reference::scales(&x, n);
        let pre = crate::ident::newey_west_lags(n);
        let mut want = (0.0, 0.0);
        let lags =
            reference::automatic_lags(&x, n, &inverses, &bounds, n, &mut Vec::new(), &mut want);
        // Relative to σ₀ (s⁽⁰⁾ cancels nearly to zero for over-differenced
        // noise): the size of the terms summed.
        let mut h = vec![0.0; n];
        for j in 0..p {
            let c = &x[j * n..(j + 1) * n];
            let ss = c.iter().map(|v| (v * inverses[j]).powi(2)).sum::<f64>();
            for t in 0..n {
                h[t] += c[t] * inverses[j] / ss.sqrt();
            }
        }
        let sigma0 = h.iter().map(|v| v * v).sum::<f64>();
        let stats = Stats {
            max: x
                .chunks_exact(n)
                .map(crate::kernels::reduce::max_abs)
                .collect(),
            ss: x
                .chunks_exact(n)
                .map(|c| c.iter().map(|v| v * v).sum())
                .collect(),
        };
        for known in [None, Some(&stats)] {
            let series = Series {
                x: &x,
                n,
                stats: known,
            };
            let got = bandwidth_sums(series, &bounds, pre, &mut scratch);
            for (g, w) in [(got.0, want.0), (got.1, want.1)] {
                let rel = (g - w).abs() / sigma0;
                worst = worst.max(rel);
                assert!(rel < 1e-13, "n {n}, p {p}: {g} vs {w} (σ₀ {sigma0})");
            }
            let got = automatic_lags(series, &bounds, pre, n, &mut scratch);
            assert_eq!(got, lags, "n {n}, p {p}");
        }
    }
    eprintln!("bandwidth sums: worst difference {worst:e} of σ₀");
}
