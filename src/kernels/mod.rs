//! Private numeric kernels shared by the public modules: small dense
//! factorisations on fixed-size matrices ([`linalg`]), eigenvalues of
//! small matrices on the stack ([`eigen`]), vectorisable reductions over
//! long columns ([`reduce`]), and MINPACK's Levenberg–Marquardt for
//! nonlinear least squares ([`lm`]). Nothing here is public API;
//! every module above may use these, and these use nothing above them.

pub(crate) mod eigen;
pub(crate) mod linalg;
// The output-error refinement (`lab::ident::refine`) is its only user.
#[cfg(feature = "lab")]
pub(crate) mod lm;
pub(crate) mod reduce;
