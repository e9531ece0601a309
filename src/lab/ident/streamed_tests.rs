//! The streamed stages (factor, then each row's influence built again a
//! block at a time) against the stored ones on the same recordings.

use super::regressors::{CentralDifferences, Differences, Kind, LabDifferences, Out, Spec};
use super::stages::{Factored, Solver};
use super::{MassSpringEstimate, Options, Scheme, SpringModel, identify_by, prepare};
use crate::data::{Channel, Recording, Schema};
use crate::ident::Covariance;
use crate::signal::Rng;

/// A two-cart rig's response (semi-implicit Euler at 2 ms, the lab's
/// parameters) to a square wave with noise on the positions, with two
/// gaps in the time stamps (three segments) and a jitter of 1 %.
fn recording(n: usize) -> Recording {
    let schema = Schema::new(
        vec![Channel::new("u", "V")],
        vec![Channel::new("x1", "m"), Channel::new("x2", "m")],
    )
    .unwrap();
    let (m1, m2, k, b1, b2, gain) = (1.3, 0.7, 950.0, 12.0, 6.0, 8.5);
    let mut rng = Rng::new(7);
    let mut noise = move || rng.uniform() - 0.5;
    let mut rec = Recording::with_capacity(schema, n);
    let (mut x1, mut v1, mut x2, mut v2, mut t) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for i in 0..n {
        let dt = if i == n / 3 || i == 2 * n / 3 {
            0.02
        } else {
            0.002
        };
        let dt = dt * (1.0 + 0.01 * noise());
        let u = if (i / 700) % 2 == 0 { 2.0 } else { -2.0 };
        let a1 = (-b1 * v1 - k * x1 - k * (x1 - x2)) / m1;
        let a2 = (gain * u - b2 * v2 - k * (x2 - x1)) / m2;
        (v1, v2) = (v1 + dt * a1, v2 + dt * a2);
        (x1, x2) = (x1 + dt * v1, x2 + dt * v2);
        t += dt;
        let (y1, y2) = (x1 + 2e-6 * noise(), x2 + 2e-6 * noise());
        rec.push(t, &[u], &[y1, y2]).unwrap();
    }
    rec
}

fn numbers(e: &MassSpringEstimate) -> Vec<f64> {
    [&e.first, &e.second]
        .iter()
        .flat_map(|f| f.theta.iter().chain(f.std_errors.iter()).copied())
        .collect()
}

fn both<D: Differences>(rec: &Recording, options: &Options) -> (Vec<f64>, Vec<f64>) {
    let run = |from| {
        let solver = Solver::streaming_from(options.covariance, from);
        identify_by::<D>(rec, 1.3, 0.7, options, Some(solver)).map(|e| numbers(&e))
    };
    (run(usize::MAX).unwrap(), run(1).unwrap())
}

#[test]
fn streamed_stages_give_the_stored_estimates_and_errors() {
    let rec = recording(6000);
    let mut largest: f64 = 0.0;
    for springs in [SpringModel::Equal, SpringModel::Separate] {
        for (coulomb, free_m2) in [(false, false), (true, false), (false, true), (true, true)] {
            for covariance in [Covariance::NeweyWest { lags: None }, Covariance::Classical] {
                for scheme in [Scheme::Lab, Scheme::Central] {
                    let options = Options {
                        springs,
                        coulomb,
                        free_m2,
                        covariance,
                        ..Options::with_scheme(scheme)
                    };
                    let (stored, streamed) = match scheme {
                        Scheme::Lab => both::<LabDifferences>(&rec, &options),
                        Scheme::Central => both::<CentralDifferences>(&rec, &options),
                    };
                    // The stored stage factors by unblocked Householder, the
                    // streamed one block by block: their rounding differs, by
                    // at most 3.6e-12 relative as measured (a Coulomb force,
                    // Newey–West errors of a poorly determined parameter).
                    for (k, (a, b)) in stored.iter().zip(&streamed).enumerate() {
                        let rel = (a - b).abs() / a.abs();
                        largest = largest.max(rel);
                        assert!(rel < 1e-11, "{options:?}, number {k}: {a} vs {b}");
                    }
                }
            }
        }
    }
    eprintln!("largest relative difference {largest:e}");
}

/// Stage 1's Newey–West work on a thread beside stage 2 gives every
/// figure (estimates, errors, covariances, lags) and every error of the
/// two one after the other, bit for bit.
#[test]
fn stage_1_beside_stage_2_is_one_after_the_other_bit_for_bit() {
    let rec = recording(6000);
    // Cart 2 still: stage 2's columns are degenerate, its error the same.
    let mut still = Recording::with_capacity(rec.schema().clone(), rec.len());
    for k in 0..rec.len() {
        let (u, x) = (rec.input(0).unwrap(), rec.measurement(0).unwrap());
        let (t, u, x) = (rec.time()[k], u[k], x[k]);
        still.push(t, &[u], &[x, 0.0]).unwrap();
    }
    let newey_west = Covariance::NeweyWest { lags: None };
    let mut compared = 0;
    for rec in [&rec, &still] {
        for springs in [SpringModel::Equal, SpringModel::Separate] {
            for (coulomb, free_m2) in [(false, false), (true, false), (false, true), (true, true)] {
                for scheme in [Scheme::Lab, Scheme::Central] {
                    let options = Options {
                        springs,
                        coulomb,
                        free_m2,
                        covariance: newey_west,
                        ..Options::with_scheme(scheme)
                    };
                    let run = |beside| {
                        let solver = Solver::streaming_from(newey_west, 1).with_beside(beside);
                        let e = match scheme {
                            Scheme::Lab => {
                                identify_by::<LabDifferences>(rec, 1.3, 0.7, &options, Some(solver))
                            }
                            Scheme::Central => identify_by::<CentralDifferences>(
                                rec,
                                1.3,
                                0.7,
                                &options,
                                Some(solver),
                            ),
                        };
                        e.map(|e| {
                            let fits = [&e.first, &e.second];
                            let bits: Vec<u64> = fits
                                .iter()
                                .flat_map(|f| {
                                    f.theta.iter().chain(&f.std_errors).chain(&f.covariance)
                                })
                                .map(|v| v.to_bits())
                                .collect();
                            (bits, fits.map(|f| f.covariance_kind))
                        })
                        .map_err(|e| format!("{e:?}"))
                    };
                    let (beside, after) = (run(true), run(false));
                    assert_eq!(beside, after, "{options:?}");
                    compared += usize::from(beside.is_ok());
                }
            }
        }
    }
    assert!(compared >= 16, "{compared} fits compared");
}

/// Given one factor, the influence built again block by block is the
/// stored stage's, bit for bit, and stage 2's sensitivity `g` its sums in
/// another order.
#[test]
fn the_streamed_influence_is_the_stored_one_bit_for_bit() {
    let rec = recording(9000);
    let options = Options::default();
    let (data, ..) = prepare(&rec, 1.3, 0.7, &options).unwrap();
    for kind in [
        Kind::Second { m2: 0.7, k2: 950.0 },
        Kind::First {
            springs: SpringModel::Separate,
            m1: 1.3,
        },
    ] {
        let want_z = matches!(kind, Kind::Second { .. });
        let p = if want_z { 2 } else { 3 };
        let spec = Spec {
            kind,
            data: &data,
            keep: None,
            p,
        };
        let m = data.rows;
        let mut solver = Solver::new(options.covariance);
        let Factored { tri, exponents, .. } = solver
            .factor_streamed::<CentralDifferences>(&spec, m)
            .unwrap();
        let g = solver
            .influence_streamed::<CentralDifferences>(&spec, m, &tri, &exponents, want_z, false);
        let streamed = solver.buf_for_tests()[..m * p].to_vec();
        // The stored layout: room for the factor, [Φ | λ] as built, z.
        let width = p + 1;
        let mut stored = Solver::new(options.covariance);
        let buf = stored.buf_for_tests();
        buf.resize(m * width, 0.0);
        spec.fill::<CentralDifferences>((0, m), true, want_z, Out::Push(buf));
        let g_stored = stored.influence_stored(
            m,
            p,
            &tri,
            &exponents,
            want_z,
            m * width,
            2 * m * width,
            false,
        );
        let same = stored.buf_for_tests()[..m * p]
            .iter()
            .zip(&streamed)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same, "{kind:?}");
        match (g, g_stored) {
            (Some(a), Some(b)) => {
                for (a, b) in a.iter().zip(&b) {
                    assert!((a - b).abs() <= 1e-13 * b.abs(), "{a} vs {b}");
                }
            }
            (None, None) => assert!(!want_z),
            other => panic!("{other:?}"),
        }
    }
}

fn fills<D: Differences>(spec: &Spec<'_, '_>, range: (usize, usize), with_z: bool) {
    let width = spec.p + 1 + usize::from(with_z);
    let (mut rows, mut cols) = (Vec::new(), Vec::new());
    let a = spec.fill::<D>(range, true, with_z, Out::Push(&mut rows));
    let b = spec.fill_by_columns::<D>(range, true, with_z, Out::Push(&mut cols));
    assert_eq!((a, rows.len()), (b, cols.len()));
    assert_eq!(rows.len(), a * width, "{:?} {range:?}", spec.kind);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&rows), bits(&cols), "{:?} {range:?}", spec.kind);
    // Into strided columns (as the streamed stages' blocks).
    let stride = a + 3;
    let mut slices = vec![f64::NAN; stride * width];
    let c = spec.fill::<D>(range, true, with_z, Out::Slices(&mut slices, stride));
    assert_eq!(c, a);
    for (j, col) in cols
        .chunks_exact(a.max(1))
        .enumerate()
        .take(if a == 0 { 0 } else { width })
    {
        assert_eq!(bits(&slices[j * stride..j * stride + a]), bits(col));
    }
}

/// Every row's columns at once are the column by column fill, bit for
/// bit, for every stage and scheme, over ranges that cross segments.
#[test]
fn a_row_at_a_time_fills_the_columns_bit_for_bit() {
    let rec = recording(3000);
    let (data, ..) = prepare(&rec, 1.3, 0.7, &Options::default()).unwrap();
    assert_eq!(data.segments.len(), 3);
    let n = data.rows;
    let ranges = [(0, n), (0, 1), (n - 1, n), (5, 5), (990, 1010), (7, 2500)];
    for (kind, p, with_z) in [
        (
            Kind::First {
                springs: SpringModel::Equal,
                m1: 1.3,
            },
            2,
            false,
        ),
        (
            Kind::First {
                springs: SpringModel::Separate,
                m1: 1.3,
            },
            3,
            false,
        ),
        (Kind::Second { m2: 0.7, k2: 950.0 }, 2, false),
        (Kind::Second { m2: 0.7, k2: 950.0 }, 2, true),
        (Kind::FreeMass { k2: 950.0 }, 3, false),
    ] {
        let spec = Spec {
            kind,
            data: &data,
            keep: None,
            p,
        };
        for range in ranges {
            fills::<LabDifferences>(&spec, range, with_z);
            fills::<CentralDifferences>(&spec, range, with_z);
        }
    }
}
