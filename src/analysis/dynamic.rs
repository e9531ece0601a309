//! Analysis of run-time-sized models ([`DynStateSpace`]).

use nalgebra::Complex;

use crate::analysis::eigenvalues_dyn;
use crate::error::Error;
use crate::model::{Domain, DynStateSpace};

impl<D: Domain> DynStateSpace<D> {
    /// The poles: eigenvalues of `A`, sorted by real part then imaginary part
    /// (ascending), as [`StateSpace::poles`](crate::StateSpace::poles) sorts
    /// them. `s`-plane for continuous models, `z`-plane for discrete ones.
    ///
    /// # Errors
    ///
    /// [`Error::NoConvergence`] if the eigenvalue iteration fails;
    /// [`Error::Overflow`] if an eigenvalue is not finite.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use nalgebra::dmatrix;
    ///
    /// // x'' + 2 x' + 5 x = u: poles −1 ± 2i.
    /// let sys = DynStateSpace::continuous(dmatrix![0.0, 1.0; -5.0, -2.0], dmatrix![0.0; 1.0],
    ///                                     dmatrix![1.0, 0.0], dmatrix![0.0])?;
    /// let p = sys.poles()?;
    /// assert!((p[0].re + 1.0).abs() < 1e-12 && (p[0].im + 2.0).abs() < 1e-12);
    /// assert!((p[1].re + 1.0).abs() < 1e-12 && (p[1].im - 2.0).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn poles(&self) -> Result<Vec<Complex<f64>>, Error> {
        eigenvalues_dyn(self.a())
    }
}
