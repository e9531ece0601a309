//! Pole placement for single-input systems, Ackermann's formula, and the
//! validation of target poles that [`place`](super::place) shares.

use nalgebra::{Complex, DMatrix, DefaultAllocator, Dim, OMatrix, U1, allocator::Allocator};

use super::Design;
use super::system::{PoleTargets, targets};
use crate::analysis::{eigenvalues_near, scaled_krylov_rank};
use crate::error::Error;
use crate::kernels::eigen::SMALL;
use crate::kernels::linalg::Lu;
use crate::kernels::reduce::pow2_floor;
#[cfg(doc)]
use crate::model::{DynStateSpace, StateSpace};
use crate::model::{SingleInput, Token};

/// Relative distance within which two targets count as a conjugate pair.
const CONJUGATE_RTOL: f64 = 1e-10;

/// The state gain `K` that puts the poles of `A − B K` at `poles`, by
/// Ackermann's formula `K = [0 … 0 1] 𝒞⁻¹ φ(A)` with `𝒞` the
/// controllability matrix and `φ` the target characteristic polynomial.
///
/// Works for continuous (`s`, rad/s) and discrete (`z`) models alike, of
/// either size ([`SingleInput`]: a fixed-size model with one input and an
/// array of `N` targets, or a [`DynStateSpace`] with one input, checked
/// when called); targets are any [`PoleTargets`], so real ones are plain
/// `f64`. Complex targets must come in conjugate pairs (matched to 1e-10 relative;
/// the pair is then used as exactly conjugate), so the gain is real. Like
/// python-control's `acker`, the formula is numerically fragile for large
/// `N` or a poorly conditioned `𝒞`; it is exact enough for the lab's four
/// states.
///
/// # Errors
///
/// For a run-time-sized model, [`Error::DimensionMismatch`] named `"B"`
/// unless it has one input and [`Error::LengthMismatch`] named `"poles"`
/// unless there are `n` targets; [`Error::Uncontrollable`] with the numerical rank when `(A, B)` is not
/// controllable (the test of [`is_controllable`](StateSpace::is_controllable),
/// independent of units); [`Error::InvalidPole`] naming a non-finite target
/// or one without its conjugate; [`Error::IllConditioned`] when the poles of
/// `A − B K`, computed back, miss the targets by more than 0.1 % of the
/// largest (the problem is too ill-conditioned for the formula in double
/// precision: eight states with spread-out poles, say).
///
/// # Examples
///
/// ```
/// use ctrlab::{MassSpring, Cart, design::{StateFeedback, acker}};
/// use ctrlab::nalgebra::Complex;
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?;
/// let targets = [
///     Complex::new(-30.0, 30.0), Complex::new(-30.0, -30.0),
///     Complex::new(-40.0, 0.0), Complex::new(-50.0, 0.0),
/// ];
/// let k = acker(&plant, &targets)?;
/// let cl = StateFeedback::with_prefilter(&plant, k)?.closed_loop(&plant)?;
/// let p = cl.poles()?;
/// assert!((p[0] - Complex::new(-50.0, 0.0)).norm() < 1e-8);
/// assert!((p[3] - Complex::new(-30.0, 30.0)).norm() < 1e-8);
///
/// // Real targets as plain numbers, and the model sized at run time.
/// let k = acker(&plant, [-40.0, -45.0, -50.0, -55.0])?;
/// let dynamic = ctrlab::DynStateSpace::from(&plant);
/// assert_eq!(acker(&dynamic, [-40.0, -45.0, -50.0, -55.0])?.as_slice(), k.as_slice());
/// assert!(acker(&dynamic, [-40.0, -45.0]).is_err()); // two targets for four states
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn acker<S: Design + SingleInput>(
    sys: &S,
    poles: impl PoleTargets<S::States>,
) -> Result<S::Gain, Error> {
    sys.acker_gain(Token(()), &targets(&poles))
}

/// One target per state, or [`Error::LengthMismatch`] named `"poles"`.
pub(super) fn check_targets(poles: &[Complex<f64>], states: usize) -> Result<(), Error> {
    if poles.len() == states {
        Ok(())
    } else {
        Err(Error::LengthMismatch {
            what: "poles",
            expected: states,
            found: poles.len(),
        })
    }
}

/// [`acker`] on a bare pair `(A, b)`, `b` one column, one target per state
/// (the callers' checks): the gain as the `1 × n` row of the model's gain
/// type. Written once over nalgebra's dimensions, so a fixed-size model's
/// runs on the stack.
pub(super) fn acker_pair<N: Dim, M: Dim>(
    a: &OMatrix<f64, N, N>,
    b: &OMatrix<f64, N, M>,
    poles: &[Complex<f64>],
) -> Result<OMatrix<f64, M, N>, Error>
where
    DefaultAllocator:
        Allocator<N, N> + Allocator<N, M> + Allocator<M, N> + Allocator<N> + Allocator<U1, N>,
{
    let (dim, dim_m) = b.shape_generic();
    if dim_m.value() != 1 {
        return Err(Error::DimensionMismatch {
            matrix: "B",
            expected_rows: dim.value(),
            expected_cols: 1,
            found_rows: dim.value(),
            found_cols: dim_m.value(),
        });
    }
    let n = dim.value();
    let coeffs = real_polynomial(poles)?;
    // Controllability matrix [B, A B, …, A^(N−1) B], each new column
    // divided by a power of two s_j as it is formed (so that it cannot
    // overflow, and the LU's pivot test sees no units): 𝒞 = 𝒞̃ S with
    // S = diag(s₀, s₀s₁, …), so the last row of 𝒞⁻¹ = S⁻¹ 𝒞̃⁻¹ is that of
    // 𝒞̃⁻¹ divided by s₀ s₁ … s_(N−1).
    let mut ctrb = OMatrix::<f64, N, N>::zeros_generic(dim, dim);
    let mut col = b.column(0).into_owned();
    let mut last_scale = 1.0;
    for j in 0..n {
        let s = pow2_floor(col.amax());
        col /= s;
        ctrb.set_column(j, &col);
        last_scale = if j == 0 { s } else { last_scale * s };
        col = a * col;
    }
    if ctrb.iter().any(|v| !v.is_finite()) {
        return Err(Error::Overflow {
            operation: "controllability matrix",
        });
    }
    // φ(A) by Horner: coeffs are monic, highest power first.
    let mut phi = OMatrix::<f64, N, N>::identity_generic(dim, dim);
    let mut product = phi.clone();
    for &c in &coeffs[1..] {
        product.gemm(1.0, a, &phi, 0.0);
        std::mem::swap(&mut phi, &mut product);
        for i in 0..n {
            phi[(i, i)] += c;
        }
    }
    let mut last = OMatrix::<f64, U1, N>::zeros_generic(U1, dim);
    if n > 0 {
        last[n - 1] = 1.0;
    }
    // The scale-free rank test costs an SVD, so it runs only when the LU's
    // pivot test (the stricter of the two) refuses: a rank below N is an
    // uncontrollable pair; a full rank, a nearly uncontrollable one the LU
    // cannot invert accurately (its own error, not "rank N of N").
    let row = match Lu::solve_right(&ctrb, &last, "Ackermann (controllability matrix)") {
        Ok(row) => row,
        Err(lu) => {
            let rank = scaled_krylov_rank(&heap(a), &heap(b))?;
            return Err(if rank < n {
                Error::Uncontrollable { rank, states: n }
            } else {
                lu
            });
        }
    };
    let k = (row * phi) / last_scale;
    if !k.iter().all(|v| v.is_finite()) {
        return Err(Error::Overflow {
            operation: "Ackermann gain",
        });
    }
    // A − b K, with b's one column (on the stack for a fixed size).
    let a_cl = OMatrix::<f64, N, N>::from_fn_generic(dim, dim, |i, j| a[(i, j)] - b[(i, 0)] * k[j]);
    check_placement(a_cl.as_slice(), n, poles)?;
    Ok(OMatrix::from_row_slice_generic(dim_m, dim, k.as_slice()))
}

/// A copy on the heap, for the code written for run-time-sized matrices.
pub(crate) fn heap<R: Dim, C: Dim>(m: &OMatrix<f64, R, C>) -> DMatrix<f64>
where
    DefaultAllocator: Allocator<R, C>,
{
    DMatrix::from_iterator(m.nrows(), m.ncols(), m.iter().copied())
}

/// Largest distance, relative to the largest target, between the poles of
/// `A − B K` as computed and the targets they were placed at, above which
/// [`acker`] refuses its gain.
const PLACEMENT_RTOL: f64 = 1e-3;

/// Checks that the closed loop's poles, as [`StateSpace::poles`] computes
/// them, are the targets: Ackermann's formula is exact in exact arithmetic,
/// but for many states or targets far from the open-loop poles the closed
/// loop is so sensitive that the gain's rounding moves its poles by tens
/// of percent. Such a gain is refused, not returned.
fn check_placement(a_cl: &[f64], n: usize, targets: &[Complex<f64>]) -> Result<(), Error> {
    let got = eigenvalues_near(a_cl, n, targets)?;
    let got = got.as_slice();
    let scale = targets.iter().map(|t| t.norm()).fold(0.0, f64::max);
    // Each target against its nearest computed pole not used yet.
    let (mut used_small, mut used_heap) = ([false; SMALL], Vec::new());
    let used: &mut [bool] = if n <= SMALL {
        &mut used_small[..n]
    } else {
        used_heap.resize(n, false);
        &mut used_heap
    };
    let mut worst = 0.0f64;
    for t in targets {
        // Squared distances to choose (an overflow only ties), `norm`
        // (overflow-safe) for the distance reported.
        let nearest = (0..got.len())
            .filter(|&j| !used[j])
            .min_by(|&x, &y| (got[x] - t).norm_sqr().total_cmp(&(got[y] - t).norm_sqr()));
        if let Some(j) = nearest {
            used[j] = true;
            worst = worst.max((got[j] - t).norm());
        }
    }
    let error = if scale > 0.0 { worst / scale } else { worst };
    if error <= PLACEMENT_RTOL {
        Ok(())
    } else {
        Err(Error::IllConditioned {
            operation: "Ackermann pole placement (the closed-loop poles miss their \
                        targets; try fewer states, targets nearer the open-loop \
                        poles, or lqr)",
            error,
            limit: PLACEMENT_RTOL,
        })
    }
}

/// Monic real polynomial with the given roots, highest power first
/// (`N + 1` coefficients, returned in a `Vec`: design time, not a hot loop).
fn real_polynomial(poles: &[Complex<f64>]) -> Result<Vec<f64>, Error> {
    let paired = conjugate_pairs(poles)?;
    let mut coeffs = vec![1.0];
    let mul = |coeffs: &mut Vec<f64>, factor: &[f64]| {
        let mut out = vec![0.0; coeffs.len() + factor.len() - 1];
        for (i, &c) in coeffs.iter().enumerate() {
            for (j, &f) in factor.iter().enumerate() {
                out[i + j] += c * f;
            }
        }
        *coeffs = out;
    };
    let mut i = 0;
    while i < paired.len() {
        let p = paired[i];
        if p.im == 0.0 {
            mul(&mut coeffs, &[1.0, -p.re]);
            i += 1;
        } else {
            // (s − p)(s − p̄) = s² − 2 Re p s + |p|².
            mul(&mut coeffs, &[1.0, -2.0 * p.re, p.norm_sqr()]);
            i += 2;
        }
    }
    Ok(coeffs)
}

/// The targets validated and arranged for a real gain: all finite, closed
/// under conjugation (a partner matched to 1e-10 relative). Real targets
/// come out with an imaginary part of exactly 0; each complex pair comes out
/// adjacent, the one with positive imaginary part first and its exact
/// conjugate second.
pub(crate) fn conjugate_pairs(poles: &[Complex<f64>]) -> Result<Vec<Complex<f64>>, Error> {
    let n = poles.len();
    let bad = |index: usize, reason| Error::InvalidPole {
        index,
        re: poles[index].re,
        im: poles[index].im,
        reason,
    };
    if let Some(i) = poles
        .iter()
        .position(|p| !(p.re.is_finite() && p.im.is_finite()))
    {
        return Err(bad(i, "target poles must be finite"));
    }
    let mut used = vec![false; n];
    let mut out = vec![Complex::new(0.0, 0.0); n];
    let mut next = 0;
    for i in 0..n {
        if used[i] {
            continue;
        }
        used[i] = true;
        let p = poles[i];
        let scale = p.norm().max(f64::MIN_POSITIVE);
        if p.im.abs() <= CONJUGATE_RTOL * scale {
            out[next] = Complex::new(p.re, 0.0);
            next += 1;
            continue;
        }
        // Closest unused partner to the conjugate.
        let partner = (i + 1..n)
            .filter(|&j| !used[j])
            .min_by(|&x, &y| {
                (poles[x] - p.conj())
                    .norm()
                    .total_cmp(&(poles[y] - p.conj()).norm())
            })
            .filter(|&j| (poles[j] - p.conj()).norm() <= CONJUGATE_RTOL * scale);
        let Some(j) = partner else {
            return Err(bad(
                i,
                "complex target poles must come in conjugate pairs, and this one has no partner",
            ));
        };
        used[j] = true;
        let upper = Complex::new(p.re, p.im.abs());
        out[next] = upper;
        out[next + 1] = upper.conj();
        next += 2;
    }
    Ok(out)
}
