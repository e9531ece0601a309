//! Minimal realisations: the controllable and observable part of a
//! state-space model by an orthogonal staircase (Kalman) decomposition.

use nalgebra::DMatrix;

use crate::error::Error;
use crate::model::{Domain, DynStateSpace};

/// An orthonormal basis (`n × k`) of the controllable subspace of
/// `(A, B)`, by the orthogonal staircase reduction of SLICOT's `TB01UD`:
/// each step splits the current "input" block by its singular values
/// (those above `tol` count) and moves on to the part of `A` it does not
/// yet reach.
fn controllable_basis(a: &DMatrix<f64>, b: &DMatrix<f64>, tol: f64) -> Result<DMatrix<f64>, Error> {
    let n = a.nrows();
    let mut q = DMatrix::<f64>::identity(n, n);
    let mut at = a.clone();
    let mut input = b.clone();
    let mut start = 0;
    while start < n {
        let rem = n - start;
        // faer's full SVD (U square, singular values descending); nalgebra's
        // 2 × 2 SVD left U 1e-3 off on a rank-one block (the null direction
        // rotated into the kept one), which kept a state it should drop.
        let k = input.ncols();
        if k == 0 {
            break;
        }
        let fm = faer::MatRef::from_column_major_slice(input.as_slice(), rem, k);
        let svd = fm.svd().map_err(|_| Error::NoConvergence {
            operation: "minimal realization (SVD of a staircase step)",
            iterations: 0,
        })?;
        let (u, sv) = (svd.U(), svd.S().column_vector());
        let r = (0..rem.min(k)).take_while(|&i| sv[i] > tol).count();
        if r == 0 {
            break;
        }
        let mut t = DMatrix::<f64>::identity(n, n);
        for j in 0..rem {
            for i in 0..rem {
                t[(start + i, start + j)] = u[(i, j)];
            }
        }
        at = t.transpose() * &at * &t;
        q = &q * &t;
        if start + r == n {
            start = n;
            break;
        }
        input = at.view((start + r, start), (rem - r, r)).into_owned();
        start += r;
    }
    Ok(q.columns(0, start).into_owned())
}

/// `minreal`'s `tol`, when given, is finite and non-negative: `reason`
/// says what it measures (shared by the state-space and transfer-function
/// forms).
pub(crate) fn check_tolerance(tol: Option<f64>, reason: &'static str) -> Result<(), Error> {
    match tol {
        Some(t) if !(t.is_finite() && t >= 0.0) => Err(Error::InvalidParameter {
            name: "tol",
            value: t,
            reason,
        }),
        _ => Ok(()),
    }
}

/// SLICOT `TB01PD`'s default tolerance (python-control's `minreal` with
/// Slycot, `tol = 0`), `n² ε`, relative to the model's size
/// `max(‖A‖_F, ‖B‖_F, ‖C‖_F)`; `n` the original state count, used in
/// both steps.
fn default_tolerance(a: &DMatrix<f64>, b: &DMatrix<f64>, c: &DMatrix<f64>) -> f64 {
    let n = a.nrows() as f64;
    n * n * f64::EPSILON * a.norm().max(b.norm()).max(c.norm())
}

impl<D: Domain> DynStateSpace<D> {
    /// A minimal realisation (MATLAB's and python-control's `minreal`):
    /// the states neither controllable nor observable removed, leaving the
    /// transfer matrix unchanged. The controllable part is found first,
    /// then the observable part of that, each by an orthogonal staircase
    /// reduction (SLICOT `TB01PD`'s method, which python-control calls with
    /// Slycot): a singular value in a staircase step counts as non-zero
    /// above `tol`, by default `n² ε max(‖A‖_F, ‖B‖_F, ‖C‖_F)` for the
    /// original `n` in both steps, `TB01PD`'s default. That default is
    /// tight: in a model formed by floating-point products (a rotated
    /// realisation) a coupling that is rounding, amplified by a small
    /// singular value of an earlier staircase step, can reach 50 ε ‖A‖ and
    /// keep a state; pass a larger `tol` (say `1e-10` times the model's
    /// size) for such models. The result's states are
    /// orthogonal combinations of the original ones; `D` and the domain are
    /// kept.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] (`"tol"`) for a negative or non-finite
    /// tolerance; [`Error::NoConvergence`] if an SVD fails;
    /// [`Error::Overflow`] if the transformed matrices are not finite.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// // 1/(s + 1) with an extra state at −2 that the input cannot reach.
    /// let sys = DynStateSpace::continuous(dmatrix![-1.0, 0.0; 0.0, -2.0], dmatrix![1.0; 0.0],
    ///                                     dmatrix![1.0, 1.0], dmatrix![0.0])?;
    /// let min = sys.minimal_realization(None)?;
    /// assert_eq!(min.states(), 1);
    /// assert!((min.a()[(0, 0)] + 1.0).abs() < 1e-15);
    /// assert!((min.dc_gain()?[(0, 0)] - 1.0).abs() < 1e-15);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "minreal")]
    pub fn minimal_realization(&self, tol: Option<f64>) -> Result<Self, Error> {
        check_tolerance(tol, "the rank tolerance must be finite and non-negative")?;
        if self.states() == 0 {
            return Ok(self.clone());
        }
        let op = "minreal";
        let (a, b, c) = (self.a(), self.b(), self.c());
        // Controllable part.
        let tol = tol.unwrap_or_else(|| default_tolerance(a, b, c));
        let qc = controllable_basis(a, b, tol)?;
        let (a1, b1, c1) = (qc.transpose() * a * &qc, qc.transpose() * b, c * &qc);
        // Observable part of that: the controllable part of the dual.
        let a1t = a1.transpose();
        let c1t = c1.transpose();
        let qo = if a1.nrows() == 0 {
            DMatrix::zeros(0, 0)
        } else {
            controllable_basis(&a1t, &c1t, tol)?
        };
        let a2 = qo.transpose() * &a1 * &qo;
        let b2 = qo.transpose() * &b1;
        let c2 = &c1 * &qo;
        Self::from_computed(a2, b2, c2, self.d().clone(), self.domain(), op)
    }
}
