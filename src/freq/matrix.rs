//! MIMO transfer functions: [`TransferMatrix`], one SISO
//! [`TransferFunction`] per output and input.

use nalgebra::{Complex, DMatrix};

use super::response::check_channel;
use super::tf::{TransferFunction, characteristic, entry};
use crate::error::Error;
use crate::model::{Continuous, Domain, DynStateSpace, StateSpace};

/// A MIMO transfer function: one SISO [`TransferFunction`] per output `i`
/// and input `j`, `Y_i = Σ_j G_ij U_j`, all in time domain `D`.
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, freq::TransferMatrix};
/// use ctrlab::nalgebra::dmatrix;
///
/// // Two decoupled lags: 1/(s + 1) and 2/(s + 2).
/// let sys = DynStateSpace::continuous(dmatrix![-1.0, 0.0; 0.0, -2.0], dmatrix![1.0, 0.0; 0.0, 2.0],
///                                     dmatrix![1.0, 0.0; 0.0, 1.0], dmatrix![0.0, 0.0; 0.0, 0.0])?;
/// let g = TransferMatrix::from_state_space(&sys)?;
/// assert_eq!((g.outputs(), g.inputs()), (2, 2));
/// assert!((g.get(1, 1)?.dc_gain()? - 1.0).abs() < 1e-12);
/// assert_eq!(g.get(0, 1)?.num(), &[0.0]);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct TransferMatrix<D: Domain = Continuous> {
    outputs: usize,
    inputs: usize,
    /// Row-major: entry `(i, j)` at `i · inputs + j`.
    entries: Vec<TransferFunction<D>>,
}

impl<D: Domain> TransferMatrix<D> {
    /// A transfer matrix from its entries, row by row (`rows[i][j]` from
    /// input `j` to output `i`), all in the same domain.
    ///
    /// # Errors
    ///
    /// [`Error::LengthMismatch`] if the rows differ in length;
    /// [`Error::InvalidData`] if there is no entry or the entries' periods
    /// differ.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::freq::{TransferFunction, TransferMatrix};
    ///
    /// let g = TransferFunction::continuous(&[1.0], &[1.0, 1.0])?;
    /// let m = TransferMatrix::new(vec![vec![g.clone(), g.clone()]])?;
    /// assert_eq!((m.outputs(), m.inputs()), (1, 2));
    /// assert!(TransferMatrix::new(vec![vec![g.clone()], vec![]]).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn new(rows: Vec<Vec<TransferFunction<D>>>) -> Result<Self, Error> {
        let outputs = rows.len();
        let inputs = rows.first().map_or(0, Vec::len);
        if inputs == 0 {
            return Err(Error::InvalidData {
                what: "rows",
                index: 0,
                reason: "a transfer matrix needs at least one entry",
            });
        }
        if let Some(i) = rows.iter().position(|r| r.len() != inputs) {
            return Err(Error::LengthMismatch {
                what: "transfer matrix row",
                expected: inputs,
                found: rows[i].len(),
            });
        }
        let entries: Vec<_> = rows.into_iter().flatten().collect();
        let domain = entries[0].domain();
        if let Some(index) = entries.iter().position(|e| e.domain() != domain) {
            return Err(Error::InvalidData {
                what: "rows",
                index,
                reason: "every entry must have the same sampling period",
            });
        }
        Ok(Self {
            outputs,
            inputs,
            entries,
        })
    }

    /// The transfer matrix of a state-space model (`ss2tf` entry by entry:
    /// each over the characteristic polynomial of `A`, as
    /// [`TransferFunction::from_state_space`]).
    ///
    /// # Errors
    ///
    /// [`Error::InvalidData`] for a model without inputs or outputs; the
    /// errors of the eigenvalue computations.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, DynStateSpace, MassSpring, freq::TransferMatrix};
    ///
    /// let plant = DynStateSpace::from(MassSpring::nominal().state_space(Cart::Two)?);
    /// let g = TransferMatrix::from_state_space(&plant)?;
    /// // 2 mm per newton at rest.
    /// assert!((g.get(0, 0)?.dc_gain()? - 0.002).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "ss2tf")]
    pub fn from_state_space(sys: &DynStateSpace<D>) -> Result<Self, Error> {
        if sys.inputs() == 0 || sys.outputs() == 0 {
            return Err(Error::InvalidData {
                what: "model",
                index: 0,
                reason: "a transfer matrix needs at least one input and one output",
            });
        }
        let den = characteristic(sys)?;
        let mut entries = Vec::with_capacity(sys.outputs() * sys.inputs());
        for i in 0..sys.outputs() {
            for j in 0..sys.inputs() {
                entries.push(entry(sys, &den, i, j)?);
            }
        }
        Ok(Self {
            outputs: sys.outputs(),
            inputs: sys.inputs(),
            entries,
        })
    }

    /// The number of outputs (rows).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::{TransferFunction, TransferMatrix};
    /// let g = TransferFunction::continuous(&[1.0], &[1.0, 1.0])?;
    /// assert_eq!(TransferMatrix::new(vec![vec![g.clone()], vec![g]])?.outputs(), 2);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn outputs(&self) -> usize {
        self.outputs
    }

    /// The number of inputs (columns).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::{TransferFunction, TransferMatrix};
    /// let g = TransferFunction::continuous(&[1.0], &[1.0, 1.0])?;
    /// assert_eq!(TransferMatrix::new(vec![vec![g.clone(), g]])?.inputs(), 2);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn inputs(&self) -> usize {
        self.inputs
    }

    /// The entry from input `input` to output `output`.
    ///
    /// # Errors
    ///
    /// [`Error::OutOfRange`] for an index past the end.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::{TransferFunction, TransferMatrix};
    /// let g = TransferFunction::continuous(&[1.0], &[1.0, 1.0])?;
    /// let m = TransferMatrix::new(vec![vec![g.clone()]])?;
    /// assert_eq!(m.get(0, 0)?, &g);
    /// assert!(m.get(1, 0).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn get(&self, output: usize, input: usize) -> Result<&TransferFunction<D>, Error> {
        check_channel(output, input, self.outputs, self.inputs)?;
        Ok(&self.entries[output * self.inputs + input])
    }

    /// `G` at a complex point, `outputs × inputs`.
    ///
    /// # Errors
    ///
    /// As [`TransferFunction::evaluate`].
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::{TransferFunction, TransferMatrix};
    /// # use ctrlab::nalgebra::Complex;
    /// let g = TransferFunction::continuous(&[1.0], &[1.0, 1.0])?;
    /// let m = TransferMatrix::new(vec![vec![g.clone(), g]])?;
    /// assert_eq!(m.evaluate(Complex::new(1.0, 0.0))?[(0, 1)], Complex::new(0.5, 0.0));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn evaluate(&self, s: Complex<f64>) -> Result<DMatrix<Complex<f64>>, Error> {
        let mut out = DMatrix::zeros(self.outputs, self.inputs);
        for i in 0..self.outputs {
            for j in 0..self.inputs {
                out[(i, j)] = self.entries[i * self.inputs + j].evaluate(s)?;
            }
        }
        Ok(out)
    }

    /// The DC gain matrix, `outputs × inputs`: each entry's
    /// [`TransferFunction::dc_gain`].
    ///
    /// # Errors
    ///
    /// [`Error::Singular`] if an entry has a pole at `s = 0` (`z = 1`).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::{TransferFunction, TransferMatrix};
    /// let g = TransferFunction::continuous(&[4.0], &[1.0, 2.0])?;
    /// let m = TransferMatrix::new(vec![vec![g.clone(), g]])?;
    /// assert_eq!(m.dc_gain()?[(0, 1)], 2.0);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "dcgain")]
    pub fn dc_gain(&self) -> Result<DMatrix<f64>, Error> {
        let mut out = DMatrix::zeros(self.outputs, self.inputs);
        for i in 0..self.outputs {
            for j in 0..self.inputs {
                out[(i, j)] = self.entries[i * self.inputs + j].dc_gain()?;
            }
        }
        Ok(out)
    }

    /// A minimal state-space realisation: each entry realised by
    /// [`TransferFunction::to_state_space`], the realisations connected in
    /// parallel (block-diagonal `A`), and the states neither controllable
    /// nor observable removed by [`DynStateSpace::minimal_realization`] (default
    /// tolerance). Entries sharing a denominator share their states:
    /// `[1/(s+1), 1/(s+2); 1/(s+1), 1/(s+2)]` has 2 states, not 4, as
    /// python-control's `tf2ss` (Slycot `td04ad`, also minimal) gives.
    ///
    /// # Errors
    ///
    /// As [`TransferFunction::to_state_space`] and
    /// [`DynStateSpace::minimal_realization`].
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::{TransferFunction, TransferMatrix};
    /// let g = TransferFunction::continuous(&[1.0], &[1.0, 1.0])?;
    /// let sys = TransferMatrix::new(vec![vec![g.clone(), g]])?.to_state_space()?;
    /// // One state: both inputs drive the same lag.
    /// assert_eq!((sys.states(), sys.inputs(), sys.outputs()), (1, 2, 1));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "tf2ss")]
    pub fn to_state_space(&self) -> Result<DynStateSpace<D>, Error> {
        let parts = self
            .entries
            .iter()
            .map(TransferFunction::to_state_space)
            .collect::<Result<Vec<_>, _>>()?;
        let n: usize = parts.iter().map(DynStateSpace::states).sum();
        let (p, m) = (self.outputs, self.inputs);
        let mut a = DMatrix::zeros(n, n);
        let mut b = DMatrix::zeros(n, m);
        let mut c = DMatrix::zeros(p, n);
        let mut d = DMatrix::zeros(p, m);
        let mut at = 0;
        for (k, part) in parts.iter().enumerate() {
            let (i, j, s) = (k / m, k % m, part.states());
            a.view_mut((at, at), (s, s)).copy_from(part.a());
            b.view_mut((at, j), (s, 1)).copy_from(part.b());
            c.view_mut((i, at), (1, s)).copy_from(part.c());
            d[(i, j)] = part.d()[(0, 0)];
            at += s;
        }
        DynStateSpace::from_computed(a, b, c, d, self.entries[0].domain(), "tf2ss")?
            .minimal_realization(None)
    }

    pub(crate) fn entries(&self) -> &[TransferFunction<D>] {
        &self.entries
    }
}

impl<D: Domain> TryFrom<&DynStateSpace<D>> for TransferMatrix<D> {
    type Error = Error;

    /// [`TransferMatrix::from_state_space`].
    fn try_from(sys: &DynStateSpace<D>) -> Result<Self, Error> {
        Self::from_state_space(sys)
    }
}

impl<const N: usize, const M: usize, const P: usize, D: Domain> TryFrom<&StateSpace<N, M, P, D>>
    for TransferMatrix<D>
{
    type Error = Error;

    /// [`TransferMatrix::from_state_space`] of the fixed-size model.
    fn try_from(sys: &StateSpace<N, M, P, D>) -> Result<Self, Error> {
        Self::from_state_space(&DynStateSpace::from(sys))
    }
}
