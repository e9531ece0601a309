//! `Display` for [`StateSpace`]: the four matrices, as a user would print
//! them (MATLAB's `ss` display is the model).

use std::fmt;

use nalgebra::SMatrix;

use super::{Domain, StateSpace};

impl<const N: usize, const M: usize, const P: usize, D: Domain> fmt::Display
    for StateSpace<N, M, P, D>
{
    /// The equations, then `A`, `B`, `C`, `D` row by row, each entry in the
    /// formatter's precision (`{:.3}`) or as the shortest exact form
    /// (`{}`), right-aligned per matrix.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::StateSpace;
    /// use nalgebra::matrix;
    ///
    /// let sys = StateSpace::discrete(matrix![0.5], matrix![1.0], matrix![2.0], matrix![0.0], 0.1)?;
    /// let text = format!("{sys:.2}");
    /// assert!(text.starts_with("x[k+1] = A x[k] + B u[k], y[k] = C x[k] + D u[k], dt = 0.1 s"));
    /// assert!(text.contains("A =\n  0.50\n"));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use super::state_space::period_of;
        match period_of(&self.domain()) {
            None => writeln!(f, "x' = A x + B u, y = C x + D u")?,
            Some(dt) => writeln!(
                f,
                "x[k+1] = A x[k] + B u[k], y[k] = C x[k] + D u[k], dt = {dt} s"
            )?,
        }
        write_matrix(f, "A", self.a())?;
        write_matrix(f, "B", self.b())?;
        write_matrix(f, "C", self.c())?;
        write_matrix(f, "D", self.d())
    }
}

fn write_matrix<const R: usize, const C: usize>(
    f: &mut fmt::Formatter<'_>,
    name: &str,
    m: &SMatrix<f64, R, C>,
) -> fmt::Result {
    let precision = f.precision();
    let cell = |v: f64| match precision {
        Some(p) => format!("{v:.p$}"),
        None => format!("{v}"),
    };
    let width = m.iter().map(|&v| cell(v).len()).max().unwrap_or(0);
    writeln!(f, "{name} =")?;
    for r in 0..R {
        for c in 0..C {
            write!(f, "  {:>width$}", cell(m[(r, c)]))?;
        }
        writeln!(f)?;
    }
    Ok(())
}
