//! `Display` for [`StateSpace`] and [`DynStateSpace`]: the four matrices,
//! as a user would print them (MATLAB's `ss` display is the model); and the
//! crate's one way to print a number, which the other results' `Display`
//! (poles, regulators, step figures) share.
//!
//! A number prints to [`SIGNIFICANT`] significant digits by default (`{}`),
//! as `%g` does (`0.0019993`, `1.4142`, `2.5e-07`); a precision prints that
//! many decimals (`{:.3}`: `0.002`); the alternate flag (`{:#}`) prints the
//! shortest form that reads back to the same `f64`
//! (`0.0019992502499583`), for when every bit matters.

use std::fmt;

use nalgebra::{Dim, Matrix, RawStorage};

use super::state_space::period_of;
use super::{Domain, DynStateSpace, StateSpace};

/// Significant digits of a number printed without a precision.
pub(crate) const SIGNIFICANT: usize = 5;

/// `v` as the formatter asks: `{:.N}` decimals, `{:#}` the shortest exact
/// form, otherwise [`SIGNIFICANT`] significant digits.
pub(crate) fn number(v: f64, f: &fmt::Formatter<'_>) -> String {
    match f.precision() {
        Some(p) => format!("{v:.p$}"),
        None if f.alternate() => format!("{v}"),
        None => significant(v, SIGNIFICANT),
    }
}

/// `v` to `digits` significant digits, trailing zeros dropped, in
/// scientific notation below 1e-4 and from `10^digits` up (`%g`'s rule).
pub(crate) fn significant(v: f64, digits: usize) -> String {
    if v == 0.0 {
        return "0".to_string();
    }
    if !v.is_finite() {
        return format!("{v}");
    }
    let digits = digits.max(1);
    // The exponent after rounding to `digits` (9.99999 rounds up to 10).
    let rounded = format!("{:.*e}", digits - 1, v);
    let (mantissa, exponent) = rounded.split_once('e').unwrap_or((&rounded, "0"));
    let exponent: i32 = exponent.parse().unwrap_or(0);
    if exponent < -4 || exponent >= digits as i32 {
        format!("{}e{exponent}", trim_zeros(mantissa))
    } else {
        let decimals = (digits as i32 - 1 - exponent).max(0) as usize;
        trim_zeros(&format!("{v:.decimals$}")).to_string()
    }
}

/// `1.2500` → `1.25`, `2.000` → `2`; integers unchanged.
fn trim_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

/// `name =` and the matrix row by row, each entry as [`number`] prints it,
/// right-aligned to the widest entry of the matrix.
pub(crate) fn write_matrix<R: Dim, C: Dim, S: RawStorage<f64, R, C>>(
    f: &mut fmt::Formatter<'_>,
    name: &str,
    m: &Matrix<f64, R, C, S>,
) -> fmt::Result {
    let width = m.iter().map(|&v| number(v, f).len()).max().unwrap_or(0);
    writeln!(f, "{name} =")?;
    for r in 0..m.nrows() {
        for c in 0..m.ncols() {
            write!(f, "  {:>width$}", number(m[(r, c)], f))?;
        }
        writeln!(f)?;
    }
    Ok(())
}

/// The header of a model in `domain`: its equations, and its period.
fn write_header<D: Domain>(f: &mut fmt::Formatter<'_>, domain: &D) -> fmt::Result {
    match period_of(domain) {
        None => writeln!(f, "x' = A x + B u, y = C x + D u"),
        Some(dt) => writeln!(
            f,
            "x[k+1] = A x[k] + B u[k], y[k] = C x[k] + D u[k], dt = {dt} s"
        ),
    }
}

impl<const N: usize, const M: usize, const P: usize, D: Domain> fmt::Display
    for StateSpace<N, M, P, D>
{
    /// The equations (with the period `dt` of a discrete model, exactly),
    /// then `A`, `B`, `C`, `D` row by row, right-aligned per matrix, each
    /// entry to five significant digits (`{}`), to the formatter's number of
    /// decimals (`{:.3}`), or as the shortest form that reads back exactly
    /// (`{:#}`).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Discretization, StateSpace};
    /// use ctrlab::nalgebra::matrix;
    ///
    /// let sys = StateSpace::discrete(matrix![0.5], matrix![1.0], matrix![2.0], matrix![0.0], 0.1)?;
    /// let text = format!("{sys:.2}");
    /// assert!(text.starts_with("x[k+1] = A x[k] + B u[k], y[k] = C x[k] + D u[k], dt = 0.1 s"));
    /// assert!(text.contains("A =\n  0.50\n"));
    ///
    /// // A ZOH model prints five significant digits, not seventeen…
    /// let lag = StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
    /// let d = lag.discretize(0.002, Discretization::Zoh)?;
    /// assert_eq!(d.to_string(), "x[k+1] = A x[k] + B u[k], y[k] = C x[k] + D u[k], dt = 0.002 s\n\
    ///                            A =\n  0.998\nB =\n  0.001998\nC =\n  1\nD =\n  0\n");
    /// // …and every digit on request.
    /// assert!(format!("{d:#}").contains(&format!("  {}\n", d.a()[(0, 0)])));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // One implementation: a copy on the heap costs nothing that
        // printing does not.
        fmt::Display::fmt(&DynStateSpace::from(self), f)
    }
}

impl<D: Domain> fmt::Display for DynStateSpace<D> {
    /// As a fixed-size model prints: the equations, then `A`, `B`, `C`,
    /// `D`, to five significant digits (`{}`), to a number of decimals
    /// (`{:.3}`), or exactly (`{:#}`).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{DynStateSpace, StateSpace};
    /// use ctrlab::nalgebra::matrix;
    ///
    /// let sys = StateSpace::continuous(matrix![-1.0, 2.0; 0.0, -3.0], matrix![0.0; 1.0],
    ///                                  matrix![1.0, 0.0], matrix![0.0])?;
    /// let text = DynStateSpace::from(&sys).to_string();
    /// assert_eq!(text, sys.to_string());
    /// assert_eq!(text, "x' = A x + B u, y = C x + D u\nA =\n  -1   2\n   0  -3\nB =\n  0\n  1\nC =\n  1  0\nD =\n  0\n");
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_header(f, &self.domain())?;
        write_matrix(f, "A", self.a())?;
        write_matrix(f, "B", self.b())?;
        write_matrix(f, "C", self.c())?;
        write_matrix(f, "D", self.d())
    }
}
