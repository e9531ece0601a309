//! The controller's model-side pieces built at design time: the
//! steady-state target map and the disturbance estimator, and the rate
//! weight's check.

use nalgebra::{DMatrix, SMatrix};

use super::super::Estimation;
use crate::design::kalman;
use crate::error::Error;
use crate::model::{Discrete, StateSpace};

/// `[x_s; u_s] = T · [B d; r]`: the least-squares (minimum-norm) steady
/// state of `(I − A) x − B u = B d`, `T x = r`.
pub(super) fn target_map<const R: usize, const N: usize>(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    tracked: &SMatrix<f64, R, N>,
) -> Result<DMatrix<f64>, Error> {
    let (n, m) = (a.nrows(), b.ncols());
    let mut k = DMatrix::zeros(n + R, n + m);
    k.view_mut((0, 0), (n, n))
        .copy_from(&(DMatrix::identity(n, n) - a));
    k.view_mut((0, n), (n, m)).copy_from(&(-b));
    for i in 0..R {
        for j in 0..n {
            k[(n + i, j)] = tracked[(i, j)];
        }
    }
    let svd = k.clone().svd(true, true);
    let largest = svd.singular_values.max();
    let rank_needed = (n + R).min(n + m);
    let tol = largest * (n + m) as f64 * f64::EPSILON * 1e3;
    let rank = svd.singular_values.iter().filter(|&&s| s > tol).count();
    if rank < rank_needed || !largest.is_finite() {
        return Err(Error::Singular {
            operation: "MPC steady-state target (a plant zero at z = 1 blocks the tracked outputs)",
        });
    }
    svd.pseudo_inverse(tol).map_err(|_| Error::Singular {
        operation: "MPC steady-state target",
    })
}

/// The augmented model `[x; d_u; d_y]` and its current-form Kalman gain.
pub(super) type Augmented = (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>, DMatrix<f64>);

/// The estimator of the state and `Q` disturbances: one on each input
/// (`x⁺ = A x + B (u + d_u)`) and one on each direction of the
/// measurements the tracked outputs do not see (`y = C x + N d_y`, `H N =
/// 0`), so there are as many disturbances as measurements when `R = M`:
/// the condition (Pannocchia and Rawlings, 2003) under which the tracked
/// outputs settle on the reference without offset whatever constant
/// mismatch the model has.
pub(super) fn estimator<const N: usize, const M: usize, const Q: usize, const R: usize>(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    model: &StateSpace<N, M, Q, Discrete>,
    tracked: &SMatrix<f64, R, Q>,
    estimation: &Estimation<M, Q>,
) -> Result<Augmented, Error> {
    // N: an orthonormal basis of the measurements' directions H ignores.
    let h = DMatrix::from_column_slice(R, Q, tracked.as_slice());
    let svd = h.clone().svd(false, true);
    let v_t = svd.v_t.unwrap_or_else(|| DMatrix::zeros(0, Q));
    let tol = svd.singular_values.max() * Q as f64 * f64::EPSILON * 1e3;
    let rank = svd.singular_values.iter().filter(|&&s| s > tol).count();
    let full = DMatrix::<f64>::identity(Q, Q);
    // Q − rank directions orthogonal to the row space of H.
    let mut basis = full.clone();
    for r in 0..rank {
        let row = v_t.row(r).transpose();
        let projection = &row * (row.transpose() * &basis);
        basis -= projection;
    }
    let walk = estimation.output_disturbance_noise;
    if !(walk.is_finite() && walk >= 0.0) {
        return Err(Error::InvalidParameter {
            name: "output_disturbance_noise",
            value: walk,
            reason: "a variance must be finite and ≥ 0",
        });
    }
    // Disturbances are modelled only where they have noise: none at all
    // leaves a plain Kalman filter (offset-free then only by integral
    // action).
    let nu = if estimation.disturbance_noise.iter().any(|&v| v != 0.0) {
        M
    } else {
        0
    };
    let out = if walk > 0.0 {
        basis.qr().q().columns(0, Q - rank).into_owned()
    } else {
        DMatrix::zeros(Q, 0)
    };
    let ny = out.ncols();
    let nd = nu + ny;
    let na = N + nd;
    let mut a_aug = DMatrix::zeros(na, na);
    a_aug.view_mut((0, 0), (N, N)).copy_from(a);
    a_aug.view_mut((0, N), (N, nu)).copy_from(&b.columns(0, nu));
    a_aug.view_mut((N, N), (nd, nd)).fill_with_identity();
    let mut b_aug = DMatrix::zeros(na, M);
    b_aug.view_mut((0, 0), (N, M)).copy_from(b);
    let mut c_aug = DMatrix::zeros(Q, na);
    c_aug
        .view_mut((0, 0), (Q, N))
        .copy_from(&DMatrix::from_column_slice(Q, N, model.c().as_slice()));
    c_aug.view_mut((0, N + nu), (Q, ny)).copy_from(&out);
    // Noise: on the input (through B), on the input disturbances' walk,
    // and on the output disturbances' walk.
    let mut g = DMatrix::zeros(na, M + nd);
    g.view_mut((0, 0), (N, M)).copy_from(b);
    g.view_mut((N, M), (nd, nd)).fill_with_identity();
    let mut qn = DMatrix::zeros(M + nd, M + nd);
    qn.view_mut((0, 0), (M, M))
        .copy_from(&DMatrix::from_column_slice(
            M,
            M,
            estimation.input_noise.as_slice(),
        ));
    if nu > 0 {
        qn.view_mut((M, M), (M, M))
            .copy_from(&DMatrix::from_column_slice(
                M,
                M,
                estimation.disturbance_noise.as_slice(),
            ));
    }
    for i in 0..ny {
        qn[(M + nu + i, M + nu + i)] = walk;
    }
    let rn = DMatrix::from_column_slice(Q, Q, estimation.measurement_noise.as_slice());
    let kf = kalman::estimator(&a_aug, &c_aug, &g, &qn, &rn, Some(model.dt()))?;
    let gain = kf.current_gain.ok_or(Error::Singular {
        operation: "MPC disturbance estimator (current form)",
    })?;
    Ok((a_aug, b_aug, c_aug, gain))
}

/// `S` symmetric positive semidefinite (the rate weight; `Q` and `R` are
/// checked by the Riccati design).
pub(super) fn check_weight(name: &'static str, s: &DMatrix<f64>) -> Result<(), Error> {
    crate::error::check_finite_dyn(name, s)?;
    let n = s.nrows();
    let tol = 1e-12 * s.amax().max(f64::MIN_POSITIVE);
    let symmetric = (0..n).all(|i| (0..i).all(|j| (s[(i, j)] - s[(j, i)]).abs() <= tol));
    let psd = symmetric
        && s.clone()
            .symmetric_eigenvalues()
            .iter()
            .all(|&l| l >= -tol * n as f64);
    if psd {
        Ok(())
    } else {
        Err(Error::InvalidMatrix {
            matrix: name,
            reason: "must be symmetric positive semidefinite",
        })
    }
}
