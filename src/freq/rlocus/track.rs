//! The root locus' branches: the closed-loop poles at each gain, matched
//! from one gain to the next, on a gain grid chosen and refined so that
//! the branches are smooth and the matching is unambiguous.

use nalgebra::Complex;

use super::super::poly;
use super::MAX_GAINS;
use crate::error::Error;

/// The roots of `D + k N` (`n` of them, `deg D = n ≥ deg N`): for
/// `|k| ≤ 1` of `D + k N`, above of `D / k + N` (the same roots, with
/// coefficients that cannot overflow). `None` where the degree drops (a
/// branch at infinity: `d₀ + k n₀ = 0` for a biproper `L`).
pub(super) fn roots_at(
    num: &[f64],
    den: &[f64],
    k: f64,
) -> Result<Option<Vec<Complex<f64>>>, Error> {
    let p = if k.abs() <= 1.0 {
        poly::sub_scaled(den, -k, num)
    } else {
        poly::sub_scaled(num, -1.0 / k, den)
    };
    let r = poly::roots(&p)?;
    Ok((r.len() == den.len() - 1).then_some(r))
}

/// `next` reordered to follow `prev`: pairs taken in order of increasing
/// distance, each root and each branch used once.
pub(super) fn matched(prev: &[Complex<f64>], next: Vec<Complex<f64>>) -> Vec<Complex<f64>> {
    let n = prev.len();
    let mut pairs: Vec<(f64, usize, usize)> = Vec::with_capacity(n * n);
    for (i, p) in prev.iter().enumerate() {
        for (j, q) in next.iter().enumerate() {
            pairs.push(((p - q).norm(), i, j));
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out = vec![None; n];
    let mut used = vec![false; n];
    for (_, i, j) in pairs {
        if out[i].is_none() && !used[j] {
            out[i] = Some(next[j]);
            used[j] = true;
        }
    }
    out.into_iter()
        .zip(next.iter())
        .map(|(o, q)| o.unwrap_or(*q))
        .collect()
}

/// What the refinement measures a step against: the region shown
/// (`centre`, `radius`) and the points a branch's detail is judged near
/// (open-loop poles and zeros, breakaways, crossings).
pub(super) struct Scale {
    pub centre: Complex<f64>,
    pub radius: f64,
    pub landmarks: Vec<Complex<f64>>,
}

/// A step is smooth when no branch moves more than this fraction of its
/// distance to the nearest landmark…
const LOCAL: f64 = 0.08;
/// …or of the region's radius, whichever is larger, …
const FLOOR: f64 = 0.004;
/// …nor more than this fraction of its distance to another branch (so the
/// matching cannot swap two branches).
const APART: f64 = 0.45;
/// Intervals narrower than this (relative to the gain) are not split.
const NARROWEST: f64 = 1e-10;
/// Refinement passes at most (each at most doubles the grid).
const PASSES: usize = 64;

impl Scale {
    fn shown(&self, p: Complex<f64>) -> bool {
        (p - self.centre).norm() <= 1.5 * self.radius
    }

    /// The largest step allowed at `p`.
    fn step(&self, p: Complex<f64>) -> f64 {
        let near = self
            .landmarks
            .iter()
            .map(|q| (p - q).norm())
            .fold(f64::INFINITY, f64::min);
        (LOCAL * near).max(FLOOR * self.radius)
    }
}

/// The distance from root `i` to the nearest other root.
fn separation(r: &[Complex<f64>], i: usize) -> f64 {
    r.iter()
        .enumerate()
        .filter(|&(j, _)| j != i)
        .map(|(_, q)| (r[i] - q).norm())
        .fold(f64::INFINITY, f64::min)
}

/// Whether the step between two matched root sets is too coarse.
fn coarse(scale: &Scale, a: &[Complex<f64>], b: &[Complex<f64>]) -> bool {
    (0..a.len()).any(|i| {
        let (p, q) = (a[i], b[i]);
        if !(scale.shown(p) || scale.shown(q)) {
            return false;
        }
        let d = (p - q).norm();
        let apart = separation(a, i).max(separation(b, i));
        d > scale.step(p).max(scale.step(q)) || d > APART * apart
    })
}

/// Matches every root set to the one before it, in order.
pub(super) fn track(roots: &mut [Vec<Complex<f64>>]) {
    for j in 1..roots.len() {
        let next = std::mem::take(&mut roots[j]);
        roots[j] = matched(&roots[j - 1], next);
    }
}

/// Gains and the matched roots at each.
type Grid = (Vec<f64>, Vec<Vec<Complex<f64>>>);

/// The gains (ascending, from the sorted, de-duplicated `start`) and the
/// matched roots at each, refined where a step is coarse: the midpoint
/// (geometric where the gains differ by more than ten times) is added,
/// pass after pass, until every step is smooth, an interval is narrower
/// than `NARROWEST` of its gain, or [`MAX_GAINS`] gains are reached.
/// Gains at which the degree drops are left out.
pub(super) fn refined(
    num: &[f64],
    den: &[f64],
    start: &[f64],
    scale: &Scale,
) -> Result<Grid, Error> {
    let mut gains = Vec::with_capacity(start.len());
    let mut roots = Vec::with_capacity(start.len());
    for &k in start {
        if let Some(r) = roots_at(num, den, k)? {
            gains.push(k);
            roots.push(r);
        }
    }
    track(&mut roots);
    for _ in 0..PASSES {
        let mut new_gains = Vec::with_capacity(2 * gains.len());
        let mut new_roots = Vec::with_capacity(2 * gains.len());
        let mut added = 0;
        for j in 0..gains.len() {
            new_gains.push(gains[j]);
            new_roots.push(std::mem::take(&mut roots[j]));
            let Some(&hi) = gains.get(j + 1) else { break };
            let lo = gains[j];
            if hi - lo <= NARROWEST * hi.abs()
                || gains.len() + added >= MAX_GAINS
                || !coarse(scale, &new_roots[new_roots.len() - 1], &roots[j + 1])
            {
                continue;
            }
            let mid = if lo > 0.0 && hi > 10.0 * lo {
                (lo * hi).sqrt()
            } else {
                0.5 * (lo + hi)
            };
            if let Some(r) = roots_at(num, den, mid)? {
                new_gains.push(mid);
                new_roots.push(r);
                added += 1;
            }
        }
        gains = new_gains;
        roots = new_roots;
        track(&mut roots);
        if added == 0 {
            break;
        }
    }
    Ok((gains, roots))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matching_follows_the_nearest_root() {
        let prev = [Complex::new(0.0, 1.0), Complex::new(0.0, -1.0)];
        let next = vec![Complex::new(0.1, -1.0), Complex::new(0.1, 1.0)];
        let m = matched(&prev, next);
        assert_eq!(m[0], Complex::new(0.1, 1.0));
    }

    #[test]
    fn the_degree_drop_of_a_biproper_loop_is_no_root_set() {
        // L = (s + 2) / (−s + 1): D + k N = (k − 1) s + (1 + 2k) drops at k = 1.
        assert!(roots_at(&[1.0, 2.0], &[-1.0, 1.0], 1.0).unwrap().is_none());
        assert_eq!(
            roots_at(&[1.0, 2.0], &[-1.0, 1.0], 0.5)
                .unwrap()
                .unwrap()
                .len(),
            1
        );
    }
}
