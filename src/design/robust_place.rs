//! Pole placement for multi-input systems by the robust method of Kautsky,
//! Nichols and Van Dooren (method 0), and its dual for observers.

use nalgebra::{
    Complex, DMatrix, DefaultAllocator, Dim, OMatrix, OVector, U1, allocator::Allocator,
};

use super::Design;
use super::place::{conjugate_pairs, heap};
use super::system::{PoleTargets, targets};
use crate::analysis::{eigenvalues_near, krylov, rank};
use crate::error::Error;
use crate::kernels::linalg::{Lu, SystemAlloc, dotc, householder_q, mul, norm};
use crate::model::Token;
#[cfg(doc)]
use crate::model::{DynStateSpace, StateSpace};

/// Sweeps over all eigenvectors at most (SciPy's `place_poles` default).
const MAX_SWEEPS: usize = 30;
/// Stop when a sweep changes `|det X|` by less than this, relative (SciPy's
/// default `rtol`).
const SWEEP_RTOL: f64 = 1e-3;
/// A projected eigenvector shorter than this is treated as zero and the old
/// one kept (SciPy's `allclose(y, 0)`).
const NEGLIGIBLE: f64 = 1e-8;
/// An achieved pole must lie within `PLACE_TOL · max(1, |target|)` of its
/// target: python-control's own test of `place` checks six decimals.
pub(crate) const PLACE_TOL: f64 = 1e-6;

type CMatrix<R, C> = OMatrix<Complex<f64>, R, C>;
type CVector<R> = OVector<Complex<f64>, R>;

/// The state gain `K` that puts the poles of `A − B K` at `poles`, for any
/// number of inputs, by the robust eigenvector method of Kautsky, Nichols
/// and Van Dooren (1985), method 0: of all gains that place the poles, the
/// one whose closed-loop eigenvectors are as well conditioned as the method
/// finds, so the poles move least when the plant is not quite the model.
/// MATLAB's and python-control's `place` (python-control through SciPy's
/// `place_poles`, which uses the Tits–Yang refinement of the same idea).
///
/// # Algorithm
///
/// With `B = [U₀ U₁] [Z; 0]` (QR, `B` of full column rank `M`), the
/// eigenvector `x_j` of a target `λ_j` can be any vector of
/// `S_j = ker U₁ᵀ (A − λ_j I)`, an `M`-dimensional space. Starting from the
/// normalised sum of an orthonormal basis of each `S_j`, each sweep replaces
/// every `x_j` by the unit vector of `S_j` closest to the normal of the
/// other eigenvectors' span, which raises `|det X|` for normalised columns;
/// sweeps stop when `|det X|` changes by less than 1e-3 relative, or after
/// 30 (SciPy's defaults). Complex targets are handled in complex
/// arithmetic, a conjugate pair's second eigenvector being kept the exact
/// conjugate of the first, so the gain is real. Then
/// `A − B K = X Λ X⁻¹` (in real block form) and
/// `K = Z⁻¹ U₀ᵀ (A − X Λ X⁻¹)`. With one input there is nothing to choose
/// and no sweep; with `M = N`, `K = B⁻¹ (A − Λ)`.
///
/// The achieved poles (eigenvalues of `A − B K`) are then checked: each
/// must be within `1e-6 · max(1, |target|)` of its target (python-control's
/// tests check six decimals). Works for continuous (`s`) and discrete (`z`)
/// models alike, of either size ([`Design`]): a fixed-size model takes an
/// array of exactly `N` targets and returns an `SMatrix<f64, M, N>`, a
/// [`DynStateSpace`] any list of `n` targets (counted when called) and
/// returns a `DMatrix`. Targets are any [`PoleTargets`]: real ones as plain
/// `f64`, complex ones as `Complex<f64>`. For a single input,
/// [`acker`](crate::design::acker) gives the same gain by Ackermann's
/// formula.
///
/// # Errors
///
/// [`Error::LengthMismatch`] named `"poles"` unless there are `n` targets
/// (a run-time-sized model); [`Error::InvalidParameter`] named `"poles"` for a non-finite target,
/// targets not closed under conjugation, or a target repeated more than
/// `M` times (a closed loop with more equal poles than inputs is defective:
/// no eigenvector basis exists); [`Error::InvalidMatrix`] named `"B"`
/// unless `B` has full column rank `M ≤ N`; [`Error::Uncontrollable`] when
/// `(A, B)` is not controllable and a target could not be placed;
/// [`Error::PoleNotPlaced`] when an achieved pole misses its target.
///
/// # Examples
///
/// The lab's two carts with a force on each (two inputs), a complex pair
/// and a pole repeated twice:
///
/// ```
/// use ctrlab::{StateSpace, design::place};
/// use ctrlab::nalgebra::{Complex, matrix};
///
/// let (m1, m2, k1, k2) = (1.3, 0.7, 1000.0, 1000.0);
/// let a = matrix![0.0, 1.0, 0.0, 0.0;
///                 -(k1 + k2) / m1, 0.0, k2 / m1, 0.0;
///                 0.0, 0.0, 0.0, 1.0;
///                 k2 / m2, 0.0, -k2 / m2, 0.0];
/// let b = matrix![0.0, 0.0; 1.0 / m1, 0.0; 0.0, 0.0; 0.0, 1.0 / m2];
/// let sys = StateSpace::continuous(a, b, matrix![0.0, 0.0, 1.0, 0.0], matrix![0.0, 0.0])?;
/// let targets = [Complex::new(-20.0, 20.0), Complex::new(-20.0, -20.0),
///                Complex::new(-40.0, 0.0), Complex::new(-40.0, 0.0)];
/// let k = place(&sys, &targets)?;
/// let achieved = StateSpace::continuous(a - b * k, b, sys.c().clone_owned(), *sys.d())?.poles()?;
/// assert!((achieved[0] - Complex::new(-40.0, 0.0)).norm() < 1e-6 * 40.0);
/// assert!((achieved[3] - Complex::new(-20.0, 20.0)).norm() < 1e-6 * 40.0);
///
/// // Real targets as plain numbers; the model sized at run time gives the
/// // same gain.
/// let k = place(&sys, [-5.0, -6.0, -7.0, -8.0])?;
/// let dynamic = ctrlab::DynStateSpace::from(&sys);
/// assert_eq!(place(&dynamic, [-5.0, -6.0, -7.0, -8.0])?.as_slice(), k.as_slice());
/// assert!(place(&dynamic, &[-5.0, -6.0, -7.0][..]).is_err()); // three targets, four states
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "place_poles")]
pub fn place<S: Design>(sys: &S, poles: impl PoleTargets<S::States>) -> Result<S::Gain, Error> {
    sys.place_gain(Token(()), &targets(&poles))
}

/// The observer gain `L` that puts the poles of `A − L C` at `poles`: a
/// Luenberger observer designed by [`place`] on the dual system
/// `(Aᵀ, Cᵀ)`, `L = place(Aᵀ, Cᵀ, poles)ᵀ`, as MATLAB and python-control
/// do it. For a discrete model this is the gain of the predictor form
/// `x̂[k+1] = A x̂[k] + B u[k] + L (y[k] − C x̂[k] − D u[k])`; an
/// [`Observer`](crate::design::Observer) can run it in either form.
/// Either model size and any [`PoleTargets`], as [`place`].
///
/// # Errors
///
/// As [`place`], with [`Error::InvalidMatrix`] named `"C"` unless `C` has
/// full row rank `P ≤ N`, and [`Error::Unobservable`] in place of
/// [`Error::Uncontrollable`].
///
/// # Examples
///
/// Both carts' positions measured, observer poles at −100 and −150 rad/s:
///
/// ```
/// use ctrlab::{MassSpring, Cart, design::place_observer};
/// use ctrlab::nalgebra::{Complex, matrix};
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?
///     .with_output(ctrlab::lab::position_output_matrix(), matrix![0.0; 0.0])?;
/// let l = place_observer(&plant, [-100.0, -100.0, -150.0, -150.0])?;
/// let error_dynamics = plant.a() - l * plant.c();
/// let trace: f64 = error_dynamics.trace();
/// assert!((trace + 500.0).abs() < 1e-6); // the sum of the poles
///
/// // Complex targets, and the model sized at run time: the same gain.
/// let targets = [-100.0, -100.0, -150.0, -150.0].map(|re| Complex::new(re, 0.0));
/// let dynamic = ctrlab::DynStateSpace::from(&plant);
/// assert_eq!(place_observer(&dynamic, &targets)?.as_slice(), l.as_slice());
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "luenberger")]
pub fn place_observer<S: Design>(
    sys: &S,
    poles: impl PoleTargets<S::States>,
) -> Result<S::ObserverGain, Error> {
    sys.observer_gain(Token(()), &targets(&poles))
}

/// [`place_observer`] on a bare pair `(A, C)`.
pub(super) fn observer_pair<N: Dim, P: Dim>(
    a: &OMatrix<f64, N, N>,
    c: &OMatrix<f64, P, N>,
    poles: &[Complex<f64>],
) -> Result<OMatrix<f64, N, P>, Error>
where
    DefaultAllocator: SystemAlloc<N, P>,
{
    place_pair(&a.transpose(), &c.transpose(), poles)
        .map(|k| k.transpose())
        .map_err(|e| match e {
            Error::Uncontrollable { rank, states } => Error::Unobservable { rank, states },
            Error::InvalidMatrix { matrix: "B", .. } => Error::InvalidMatrix {
                matrix: "C",
                reason: "must have full row rank, with no more outputs than states",
            },
            other => other,
        })
}

/// [`place`] on a bare pair `(A, B)` with one target per state (the
/// callers' check). Written once over nalgebra's dimensions, so a
/// fixed-size model's sweeps run on stack matrices.
pub(super) fn place_pair<N: Dim, M: Dim>(
    a: &OMatrix<f64, N, N>,
    b: &OMatrix<f64, N, M>,
    poles: &[Complex<f64>],
) -> Result<OMatrix<f64, M, N>, Error>
where
    DefaultAllocator: SystemAlloc<N, M>,
{
    let (dim_n, dim_m) = b.shape_generic();
    let (n, m) = (dim_n.value(), dim_m.value());
    let targets = conjugate_pairs(poles)?;
    if let Some(p) = targets
        .iter()
        .find(|p| targets.iter().filter(|q| q == p).count() > m)
    {
        return Err(Error::InvalidParameter {
            name: "poles",
            value: p.re,
            reason: "a target repeated more times than there are inputs cannot be placed",
        });
    }
    let rank_error = Error::InvalidMatrix {
        matrix: "B",
        reason: "must have full column rank, with no more inputs than states",
    };
    if m == 0 || m > n {
        return Err(rank_error);
    }
    // B = U [Z; 0]: U from Householder reflections of B's columns.
    let mut padded = CMatrix::zeros_generic(dim_n, dim_n);
    padded
        .columns_generic_mut(0, dim_m)
        .copy_from(&b.map(|v| Complex::new(v, 0.0)));
    let u = householder_q(&padded, m).map(|c| c.re);
    let ut = u.transpose();
    let z = mul(&ut, b).rows_generic(0, dim_m).into_owned();
    let z_max = z.amax();
    if (0..m).any(|i| z[(i, i)].abs() <= n as f64 * f64::EPSILON * z_max) || z_max == 0.0 {
        return Err(rank_error);
    }
    let z_lu = Lu::new(&z, "pole placement (B)")?;

    let x = if m == n {
        OMatrix::identity_generic(dim_n, dim_n)
    } else {
        real_columns(&eigenvectors(&mul(&ut, a), &u, &targets, dim_m), &targets)
    };
    let lambda = real_block_form(&targets, dim_n);
    // A − B K = X Λ X⁻¹.
    let closed = Lu::solve_right(&x, &mul(&x, &lambda), "pole placement (eigenvector matrix)")
        .map_err(|_| {
            uncontrollable_or(
                a,
                b,
                Error::Singular {
                    operation: "pole placement (eigenvector matrix)",
                },
            )
        })?;
    let rows = mul(&ut, &(a - closed)).rows_generic(0, dim_m).into_owned();
    let k = z_lu.solve(&rows);
    if k.iter().any(|v| !v.is_finite()) {
        return Err(Error::Overflow {
            operation: "pole placement gain",
        });
    }
    check_placed(&heap(&(a - mul(b, &k))), &targets).map_err(|e| uncontrollable_or(a, b, e))?;
    Ok(k)
}

/// The closed-loop eigenvectors, one per target (complex; a conjugate
/// pair's second the conjugate of the first), by KNV method 0 when there is
/// a choice (`m > 1`).
fn eigenvectors<N: Dim, M: Dim>(
    ut_a: &OMatrix<f64, N, N>,
    u: &OMatrix<f64, N, N>,
    targets: &[Complex<f64>],
    dim_m: M,
) -> CMatrix<N, N>
where
    DefaultAllocator: SystemAlloc<N, M>,
{
    let (dim_n, _) = u.shape_generic();
    let (n, m) = (dim_n.value(), dim_m.value());
    // (j, basis of S_j) per real target and per pair, whose second
    // column is kept the conjugate of the first.
    let mut bases = Vec::with_capacity(n);
    let mut x = CMatrix::zeros_generic(dim_n, dim_n);
    let mut j = 0;
    while j < n {
        let lambda = targets[j];
        // S_j = ker W, W = U₁ᵀ (A − λ I): the last m columns of the Q of
        // a QR of Wᴴ span it.
        let mut wh = CMatrix::zeros_generic(dim_n, dim_n);
        for col in 0..n - m {
            for row in 0..n {
                let w = Complex::new(ut_a[(m + col, row)], 0.0) - lambda * u[(row, m + col)];
                wh[(row, col)] = w.conj();
            }
        }
        let basis = householder_q(&wh, n - m)
            .columns_generic(n - m, dim_m)
            .into_owned();
        // SciPy's start: the normalised sum of the basis vectors.
        let start = basis.column_sum();
        let start = &start / Complex::new(norm(&start).max(f64::MIN_POSITIVE), 0.0);
        x.set_column(j, &start);
        if lambda.im != 0.0 {
            x.set_column(j + 1, &start.map(|c| c.conj()));
        }
        bases.push((j, basis));
        j += if lambda.im != 0.0 { 2 } else { 1 };
    }
    if m == 1 {
        return x;
    }
    let floor = f64::EPSILON.sqrt();
    let mut det_before = det_abs(&real_columns(&x, targets));
    for _ in 0..MAX_SWEEPS {
        for (j, basis) in &bases {
            let (j, pair) = (*j, targets[*j].im != 0.0);
            let y = if pair {
                pair_update(&x, basis, targets, j)
            } else {
                knv_update(&x, basis, j)
            };
            if let Some(y) = y {
                if pair {
                    x.set_column(j + 1, &y.map(|c| c.conj()));
                }
                x.set_column(j, &y);
            }
        }
        let det = det_abs(&real_columns(&x, targets)).max(floor);
        let change = ((det - det_before) / det).abs();
        det_before = det;
        if change < SWEEP_RTOL && det > floor {
            break;
        }
    }
    x
}

/// KNV method 0 for a real target's eigenvector `j`: the unit vector of
/// its space `S_j` closest to the normal of the other eigenvectors' span;
/// `None` to keep the old one when the normal is (nearly) orthogonal to
/// `S_j`.
fn knv_update<N: Dim, M: Dim>(
    x: &CMatrix<N, N>,
    basis: &CMatrix<N, M>,
    j: usize,
) -> Option<CVector<N>>
where
    DefaultAllocator: SystemAlloc<N, M>,
{
    let n = x.ncols();
    let mut others = x.clone();
    others.swap_columns(j, n - 1);
    let normal = householder_q(&others, n - 1).column(n - 1).into_owned();
    unit(basis * (basis.adjoint() * normal))
}

/// Tits and Yang's update of a complex pair's eigenvector `x = xr + i xi`
/// (columns `j`, `j + 1` of the real form): with `ur`, `ui` an orthonormal
/// basis of the complement of the other `N − 2` columns and
/// `u = ur + i ui`, the pair's share of `det X` is proportional to
/// `xᴴ (u uᴴ − ū uᵀ) x`; over `x = S μ`, `‖μ‖ = 1`, it is largest at the
/// dominant eigenvector of the Hermitian `Sᴴ (u uᴴ − ū uᵀ) S`. The old `x`
/// is projected on that direction (keeping its phase).
fn pair_update<N: Dim, M: Dim>(
    x: &CMatrix<N, N>,
    basis: &CMatrix<N, M>,
    targets: &[Complex<f64>],
    j: usize,
) -> Option<CVector<N>>
where
    DefaultAllocator: SystemAlloc<N, M>,
{
    let (dim_n, _) = x.shape_generic();
    let n = dim_n.value();
    if n < 3 {
        // No other columns: any x of S works as well as another.
        return None;
    }
    let mut others = real_columns(x, targets).map(|v| Complex::new(v, 0.0));
    others.swap_columns(j + 1, n - 1);
    others.swap_columns(j, n - 2);
    let q = householder_q(&others, n - 2);
    let u = CVector::from_fn_generic(dim_n, U1, |i, _| {
        Complex::new(q[(i, n - 2)].re, q[(i, n - 1)].re)
    });
    let basis_h = basis.adjoint();
    let a = &basis_h * &u;
    let b = basis_h * u.map(|c| c.conj());
    let mu = dominant_rank_two(&a, &b)?;
    let direction = basis * mu;
    let along = dotc(&direction, &x.column(j));
    if along.norm() > NEGLIGIBLE {
        unit(direction * along)
    } else {
        unit(direction)
    }
}

/// The unit eigenvector, for the eigenvalue of largest magnitude, of the
/// rank-two Hermitian `a aᴴ − b bᴴ`: it lies in `span(a, b)`, so a 2 × 2
/// Hermitian eigenproblem on an orthonormal basis of that span gives it.
fn dominant_rank_two<M: Dim>(a: &CVector<M>, b: &CVector<M>) -> Option<CVector<M>>
where
    DefaultAllocator: Allocator<M>,
{
    let e1 = unit(a.clone()).or_else(|| unit(b.clone()))?;
    let rest = b - &e1 * dotc(&e1, b);
    let e2 = if norm(&rest) > NEGLIGIBLE * norm(b) {
        unit(rest)
    } else {
        None
    };
    let Some(e2) = e2 else {
        return Some(e1);
    };
    // h = Eᴴ (a aᴴ − b bᴴ) E with E = [e1 e2].
    let (a1, a2, b1, b2) = (dotc(&e1, a), dotc(&e2, a), dotc(&e1, b), dotc(&e2, b));
    let p = a1.norm_sqr() - b1.norm_sqr();
    let s = a2.norm_sqr() - b2.norm_sqr();
    let q = a1 * a2.conj() - b1 * b2.conj();
    let mid = 0.5 * (p + s);
    let radius = (0.25 * (p - s) * (p - s) + q.norm_sqr()).sqrt();
    let lambda = if (mid + radius).abs() >= (mid - radius).abs() {
        mid + radius
    } else {
        mid - radius
    };
    // (h − λ I) w = 0: w = (q, λ − p) or (λ − s, q̄), the longer.
    let w1 = (q, Complex::new(lambda - p, 0.0));
    let w2 = (Complex::new(lambda - s, 0.0), q.conj());
    let (c1, c2) = if w1.0.norm_sqr() + w1.1.norm_sqr() >= w2.0.norm_sqr() + w2.1.norm_sqr() {
        w1
    } else {
        w2
    };
    if c1.norm() + c2.norm() == 0.0 {
        // h is a multiple of the identity: any direction is dominant.
        return Some(e1);
    }
    unit(e1 * c1 + e2 * c2)
}

/// `v / ‖v‖`, or `None` for a negligible `v`.
fn unit<R: Dim>(v: CVector<R>) -> Option<CVector<R>>
where
    DefaultAllocator: Allocator<R>,
{
    let length = norm(&v);
    (length > NEGLIGIBLE).then(|| v / Complex::new(length, 0.0))
}

/// The real form of the eigenvector matrix: a real target's eigenvector as
/// is, a pair's as its real and imaginary parts.
fn real_columns<N: Dim>(x: &CMatrix<N, N>, targets: &[Complex<f64>]) -> OMatrix<f64, N, N>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N>,
{
    let mut out = x.map(|c| c.re);
    let mut j = 0;
    while j < targets.len() {
        if targets[j].im != 0.0 {
            out.set_column(j + 1, &x.column(j).map(|c| c.im));
            j += 2;
        } else {
            j += 1;
        }
    }
    out
}

/// `Λ` in real block form to match [`real_columns`]: `a` on the diagonal
/// for a real target, `[[a, b], [−b, a]]` for a pair `a ± b i`
/// (`A (xr + i xi) = (a + b i)(xr + i xi)` is `A [xr xi] = [xr xi] [[a, b], [−b, a]]`).
fn real_block_form<N: Dim>(targets: &[Complex<f64>], dim: N) -> OMatrix<f64, N, N>
where
    DefaultAllocator: Allocator<N, N>,
{
    let mut lambda = OMatrix::zeros_generic(dim, dim);
    let mut j = 0;
    while j < targets.len() {
        let p = targets[j];
        lambda[(j, j)] = p.re;
        if p.im != 0.0 {
            lambda[(j + 1, j + 1)] = p.re;
            lambda[(j, j + 1)] = p.im;
            lambda[(j + 1, j)] = -p.im;
            j += 2;
        } else {
            j += 1;
        }
    }
    lambda
}

/// `|det X|`, 0 for a numerically singular `X`.
fn det_abs<N: Dim>(x: &OMatrix<f64, N, N>) -> f64
where
    DefaultAllocator: Allocator<N, N> + Allocator<N>,
{
    Lu::new(x, "determinant").map_or(0.0, |lu| lu.det().abs())
}

/// Every target has its own achieved pole (eigenvalue of `closed`) within
/// `PLACE_TOL · max(1, |target|)`, matched greedily nearest first. The
/// targets are the eigenvalue iteration's first shifts (`eigenvalues_near`).
fn check_placed(closed: &DMatrix<f64>, targets: &[Complex<f64>]) -> Result<(), Error> {
    let achieved = eigenvalues_near(closed.as_slice(), closed.nrows(), targets)?;
    let achieved = achieved.as_slice();
    let mut used = vec![false; achieved.len()];
    for target in targets {
        let nearest = (0..achieved.len()).filter(|&i| !used[i]).min_by(|&x, &y| {
            (achieved[x] - target)
                .norm()
                .total_cmp(&(achieved[y] - target).norm())
        });
        let Some(i) = nearest else { break };
        used[i] = true;
        if (achieved[i] - target).norm() > PLACE_TOL * target.norm().max(1.0) {
            return Err(Error::PoleNotPlaced {
                target_re: target.re,
                target_im: target.im,
                achieved_re: achieved[i].re,
                achieved_im: achieved[i].im,
            });
        }
    }
    Ok(())
}

/// [`Error::Uncontrollable`] when `(A, B)` is not controllable (the reason
/// a placement failed), otherwise `error`. An error path: on heap copies.
fn uncontrollable_or<N: Dim, M: Dim>(
    a: &OMatrix<f64, N, N>,
    b: &OMatrix<f64, N, M>,
    error: Error,
) -> Error
where
    DefaultAllocator: Allocator<N, N> + Allocator<N, M>,
{
    let n = a.nrows();
    match krylov(&heap(a), &heap(b), "controllability matrix").and_then(|c| rank(&c, None)) {
        Ok(rank) if rank < n => Error::Uncontrollable { rank, states: n },
        _ => error,
    }
}
