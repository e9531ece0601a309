//! The root locus' special points, found from the polynomials rather than
//! from the sampled branches: the asymptotes, the breakaway and break-in
//! points (multiple roots of `D + k N`), and the gains at which a branch
//! crosses the stability boundary.

use std::f64::consts::PI;

use nalgebra::Complex;

use super::super::margins::{Crossing, crossings};
use super::super::poly;
use super::super::response::point;
use super::super::tf::TransferFunction;
use super::{Asymptotes, BoundaryCrossing, Breakaway};
use crate::error::Error;
use crate::model::{Domain, period_of};

/// `Σ |cᵢ| |s|^(n−i)`: the size of the terms that make up `p(s)`, the
/// scale its rounding is measured against.
pub(super) fn magnitude(p: &[f64], s: Complex<f64>) -> f64 {
    let r = s.norm();
    p.iter().fold(0.0, |acc, c| acc * r + c.abs())
}

/// Whether `p(s)` is zero to rounding (`|p(s)| ≤ 64 (n + 1) ε Σ|cᵢ||s|ⁱ`).
fn vanishes(p: &[f64], s: Complex<f64>) -> bool {
    poly::eval(p, s).norm() <= 64.0 * p.len() as f64 * f64::EPSILON * magnitude(p, s)
}

/// The derivative of a polynomial (descending powers).
fn derivative(p: &[f64]) -> Vec<f64> {
    let n = p.len().saturating_sub(1);
    if n == 0 {
        return vec![0.0];
    }
    p[..n]
        .iter()
        .enumerate()
        .map(|(i, c)| c * (n - i) as f64)
        .collect()
}

/// The asymptotes of `n − m > 0` branches: centroid `(Σ pᵢ − Σ zⱼ) / (n − m)`
/// from the coefficients (`Σ pᵢ = −d₁/d₀`, `Σ zⱼ = −n₁/n₀`), angles
/// `(2q + 1) π / (n − m)`.
pub(super) fn asymptotes(num: &[f64], den: &[f64]) -> Option<Asymptotes> {
    let (n, m) = (den.len() - 1, num.len() - 1);
    if n <= m {
        return None;
    }
    let sum = |p: &[f64]| if p.len() > 1 { -p[1] / p[0] } else { 0.0 };
    let excess = n - m;
    Some(Asymptotes {
        centroid: (sum(den) - sum(num)) / excess as f64,
        angles: (0..excess)
            .map(|q| (2 * q + 1) as f64 * PI / excess as f64)
            .collect(),
    })
}

/// Breakaway and break-in points: roots `s` of `N' D − N D'` at which
/// `k = −D(s)/N(s)` is real and positive (a multiple root of `D + k N` on
/// the locus for `k > 0`), with that gain. A root whose `k` has an
/// imaginary part above `10⁻⁶` of its size is off the locus (a complex
/// root of the derivative polynomial between branches); an open-loop pole
/// (`k = 0`) or zero (`k = ∞`) is no breakaway. Points whose imaginary part
/// is rounding (below `√ε` of the modulus) are put on the real axis.
pub(super) fn breakaways(num: &[f64], den: &[f64]) -> Result<Vec<Breakaway>, Error> {
    let test = poly::sub_scaled(
        &poly::mul(&derivative(num), den),
        1.0,
        &poly::mul(num, &derivative(den)),
    );
    let mut out: Vec<Breakaway> = Vec::new();
    for mut s in poly::roots(&test)? {
        if s.im.abs() <= f64::EPSILON.sqrt() * s.norm() {
            s.im = 0.0;
        }
        if vanishes(den, s) || vanishes(num, s) {
            continue;
        }
        let k = -poly::div(poly::eval(den, s), poly::eval(num, s));
        if !(k.re.is_finite() && k.re > 0.0 && k.im.abs() <= 1e-6 * k.norm()) {
            continue;
        }
        // A double root of the test polynomial (a triple root of D + k N)
        // comes out as two nearly equal roots: report it once.
        let same = |b: &Breakaway| (b.point - s).norm() <= 1e-6 * s.norm().max(1e-300);
        if !out.iter().any(same) {
            out.push(Breakaway {
                point: s,
                gain: k.re,
            });
        }
    }
    out.sort_by(|a, b| a.gain.total_cmp(&b.gain));
    Ok(out)
}

/// The crossings of the stability boundary at `k > 0`: where
/// `L(jω)` (or `L(e^(jω dt))`) is real and negative, `k = −1 / L` puts a
/// closed-loop pole on the boundary, the gain margin's crossings (found
/// as [`stability_margins`](super::super::stability_margins) finds them,
/// polished on the response). Points where `L` cannot be evaluated (an
/// open-loop pole on the boundary, `k = 0`) are skipped. A conjugate pair
/// is one crossing, at `ω > 0`.
pub(super) fn boundary_crossings<D: Domain>(
    l: &TransferFunction<D>,
) -> Result<Vec<BoundaryCrossing>, Error> {
    let period = period_of(&l.domain());
    let (num, den) = (l.num(), l.den());
    let mut out = Vec::new();
    for w in crossings(l, Crossing::RealAxis)? {
        let s = point(period, w);
        let Ok(g) = l.evaluate(s) else { continue };
        if g.re.is_nan() || g.re >= 0.0 || g.im.abs() > 1e-6 * g.norm() {
            continue;
        }
        let gain = -1.0 / g.re;
        if !gain.is_finite() {
            continue;
        }
        // ds/dk = −N / (D' + k N') at the crossing; the pole leaves the
        // stable region if it moves right (continuous) or out (discrete).
        let slope = poly::sub_scaled(&derivative(den), -gain, &derivative(num));
        let ds = -poly::div(poly::eval(num, s), poly::eval(&slope, s));
        let outward = match period {
            None => ds.re,
            Some(_) => (s.conj() * ds).re,
        };
        out.push(BoundaryCrossing {
            gain,
            frequency: w,
            point: s,
            destabilising: outward > 0.0,
        });
    }
    out.sort_by(|a, b| a.gain.total_cmp(&b.gain));
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derivative_and_asymptotes() {
        assert_eq!(derivative(&[1.0, 2.0, 3.0]), vec![2.0, 2.0]);
        assert_eq!(derivative(&[5.0]), vec![0.0]);
        // 1/(s(s+1)(s+2)): centroid −1, angles 60°, 180°, 300°.
        let a = asymptotes(&[1.0], &[1.0, 3.0, 2.0, 0.0]).unwrap();
        assert_eq!(a.centroid, -1.0);
        assert!((a.angles[1] - PI).abs() < 1e-15);
        assert!(asymptotes(&[1.0, 1.0], &[1.0, 2.0]).is_none());
    }
}
