//! The eigenvalue kernel against backward-error and trace invariants, its
//! shifts, and its refusals.

use super::*;

fn eig(a: &[f64], n: usize) -> Vec<Complex<f64>> {
    let mut out = [Complex::new(0.0, 0.0); SMALL];
    assert!(small_eigenvalues(a, n, &mut out));
    let mut v = out[..n].to_vec();
    v.sort_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
    v
}

#[test]
fn triangular_and_companion_matrices() {
    // Upper triangular, column-major: eigenvalues on the diagonal.
    let a = [1.0, 0.0, 0.0, 5.0, -2.0, 0.0, 7.0, 3.0, 4.0];
    let e = eig(&a, 3);
    for (got, want) in e.iter().zip([-2.0, 1.0, 4.0]) {
        assert!((got - Complex::new(want, 0.0)).norm() < 1e-14, "{e:?}");
    }
    // Companion of s² + 2s + 5: −1 ± 2i.
    let a = [0.0, -5.0, 1.0, -2.0];
    let e = eig(&a, 2);
    assert!((e[0] - Complex::new(-1.0, -2.0)).norm() < 1e-14, "{e:?}");
    assert!((e[1] - Complex::new(-1.0, 2.0)).norm() < 1e-14, "{e:?}");
}

#[test]
fn a_rotation_chain_needs_the_iteration() {
    // The 8-cycle permutation: the 8th roots of unity (no real
    // shift deflates it at once, and the first sweeps stall).
    let n = 8;
    let mut a = vec![0.0; n * n];
    for j in 0..n {
        a[j * n + (j + 1) % n] = 1.0;
    }
    let e = eig(&a, n);
    for z in &e {
        assert!((z.norm() - 1.0).abs() < 1e-12, "{e:?}");
        assert!((z.powi(8) - Complex::new(1.0, 0.0)).norm() < 1e-11, "{e:?}");
    }
}

/// `σ_min(A − λI)`: zero for an exact eigenvalue of `A`, and at most
/// `‖E‖` for an exact eigenvalue of a nearby `A + E`.
fn backward_error(a: &[f64], n: usize, lambda: Complex<f64>) -> f64 {
    let m = nalgebra::DMatrix::from_fn(n, n, |i, j| {
        Complex::new(a[j * n + i], 0.0)
            - if i == j {
                lambda
            } else {
                Complex::new(0.0, 0.0)
            }
    });
    m.singular_values()
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min)
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(2000))]
    /// Random matrices of every size the kernel takes, entries spread
    /// over twelve decades, with zeros (so defective and clustered
    /// eigenvalues occur, whose positions only a backward error pins
    /// down): every eigenvalue is an exact one of a matrix within
    /// 1e-12 ‖A‖_F of `A` (a backward-stable method gives about
    /// n ε ‖A‖ ≈ 2e-15 ‖A‖), and the first two power sums are the
    /// traces of `A` and `A²` (well conditioned, unlike the
    /// eigenvalues; they catch a missing or repeated one). A distance
    /// to another solver's eigenvalues would not do: in a defective
    /// cluster two correct answers differ by ε^(1/k) (5e-5 against faer
    /// on one such 5 × 5 case).
    #[test]
    fn every_eigenvalue_is_backward_stable(
        n in 1usize..=SMALL,
        entries in proptest::collection::vec((-1.0f64..1.0, -6i32..6, 0u8..8), SMALL * SMALL),
        guesses in proptest::collection::vec((-1.0f64..1.0, -1.0f64..1.0), SMALL),
    ) {
        let (mut near, mut far) = ([Complex::new(0.0, 0.0); SMALL], [Complex::new(0.0, 0.0); SMALL]);
        let a: Vec<f64> = entries[..n * n]
            .iter()
            .map(|&(v, e, z)| if z == 0 { 0.0 } else { v * 10f64.powi(e) })
            .collect();
        let mut plain = [Complex::new(0.0, 0.0); SMALL];
        proptest::prop_assert!(small_eigenvalues(&a, n, &mut plain), "{a:?}");
        check_spectrum(&a, n, &plain[..n])?;
        // The same matrix with guesses as first shifts: its own
        // eigenvalues moved by 1e-6 relative (a placement that hit its
        // targets), and guesses far off (one that missed them).
        for (i, g) in guesses.iter().enumerate().take(n) {
            let scale = plain[i].norm().max(1.0);
            near[i] = plain[i] + Complex::new(g.0, g.1) * 1e-6 * scale;
            far[i] = Complex::new(g.0, g.1) * scale;
        }
        for guess in [&near[..n], &far[..n]] {
            let mut out = [Complex::new(0.0, 0.0); SMALL];
            proptest::prop_assert!(small_eigenvalues_near(&a, n, guess, &mut out), "{a:?}");
            check_spectrum(&a, n, &out[..n])?;
        }
    }
}

/// Every eigenvalue backward stable, and the power sums right.
fn check_spectrum(
    a: &[f64],
    n: usize,
    out: &[Complex<f64>],
) -> Result<(), proptest::test_runner::TestCaseError> {
    let norm = a
        .iter()
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt()
        .max(f64::MIN_POSITIVE);
    for &z in out {
        let e = backward_error(a, n, z);
        proptest::prop_assert!(
            e <= 1e-12 * norm,
            "n = {n}: {z} has σ_min {e:e}, ‖A‖ {norm:e}"
        );
    }
    let am = nalgebra::DMatrix::from_column_slice(n, n, a);
    let a2 = &am * &am;
    let sum: Complex<f64> = out.iter().sum();
    let squares: Complex<f64> = out.iter().map(|z| z * z).sum();
    proptest::prop_assert!((sum - Complex::new(am.trace(), 0.0)).norm() <= 1e-12 * norm * n as f64);
    proptest::prop_assert!(
        (squares - Complex::new(a2.trace(), 0.0)).norm() <= 1e-12 * norm * norm * n as f64,
        "Σλ² {squares} vs tr A² {}",
        a2.trace()
    );
    Ok(())
}

#[test]
fn repeated_and_defective_eigenvalues() {
    // 2·I (4 × 4): four times 2, at once.
    let mut a = [0.0; 16];
    for i in 0..4 {
        a[i * 4 + i] = 2.0;
    }
    assert!(
        eig(&a, 4)
            .iter()
            .all(|z| (z - Complex::new(2.0, 0.0)).norm() < 1e-15)
    );
    // A 3 × 3 Jordan block at −1: defective, so rounding moves the
    // eigenvalues by about ε^(1/3) ≈ 6e-6.
    let a = [-1.0, 0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 1.0, -1.0];
    assert!(
        eig(&a, 3)
            .iter()
            .all(|z| (z - Complex::new(-1.0, 0.0)).norm() < 1e-4)
    );
    // The lab's scale trouble: diag(−1e-3, −1e12) stays exact.
    let e = eig(&[-1e-3, 0.0, 0.0, -1e12], 2);
    assert_eq!(e, [Complex::new(-1e12, 0.0), Complex::new(-1e-3, 0.0)]);
}

#[test]
fn exact_guesses_save_sweeps() {
    // The lab plant under Ackermann's gain for −30 ± 30i, −40, −50
    // (A − b K, column-major): the targets as first shifts confirm the
    // poles in 2 sweeps, one per pair, against 8 with the standard
    // shifts.
    let a = [
        0.0,
        -1538.4615384615383,
        0.0,
        8453.72781065089,
        1.0,
        -7.692307692307692,
        0.0,
        -16.31597633136095,
        0.0,
        769.2307692307692,
        0.0,
        -6566.863905325444,
        0.0,
        0.0,
        1.0,
        -142.30769230769232,
    ];
    let targets = [
        Complex::new(-30.0, 30.0),
        Complex::new(-30.0, -30.0),
        Complex::new(-40.0, 0.0),
        Complex::new(-50.0, 0.0),
    ];
    let mut out = [Complex::new(0.0, 0.0); SMALL];
    let plain = eigenvalues_and_sweeps(&a, 4, &[], &mut out).unwrap();
    let guided = eigenvalues_and_sweeps(&a, 4, &targets, &mut out).unwrap();
    let mut got = out[..4].to_vec();
    got.sort_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
    for (g, t) in got
        .iter()
        .zip([targets[3], targets[2], targets[1], targets[0]])
    {
        assert!((g - t).norm() < 1e-9, "{got:?}");
    }
    assert!(
        guided <= 2 && plain >= 6,
        "{guided} sweeps guided, {plain} plain"
    );
}

#[test]
fn refuses_what_it_cannot_do() {
    let mut out = [Complex::new(0.0, 0.0); SMALL];
    assert!(!small_eigenvalues(&[f64::NAN], 1, &mut out));
    assert!(!small_eigenvalues(
        &[f64::INFINITY, 0.0, 0.0, 1.0],
        2,
        &mut out
    ));
}

#[test]
fn an_isolated_eigenvalue_is_permuted_out_and_exact() {
    // Row 0 has no off-diagonal entry: −1e-8 is an eigenvalue of this
    // matrix whatever the rest, which is six orders larger. Permuted to
    // the bottom (as LAPACK's `dgebal` does), it is read off exactly;
    // scaled with the rest, it came out with an error relative to 1e6.
    #[rustfmt::skip]
    let a = [
        -1e-8, 1e6, 1e-6,
        0.0, -1.0, 1e-6,
        0.0, 1e6, -2.0,
    ];
    let e = eig(&a, 3);
    assert!(e.contains(&Complex::new(-1e-8, 0.0)), "{e:?}");
    let mut w = Work {
        a: [0.0; (SMALL + 1) * (SMALL + 1)],
    };
    for j in 1..=3 {
        for i in 1..=3 {
            w.set(i, j, a[(j - 1) * 3 + (i - 1)]);
        }
    }
    assert_eq!(isolate(&mut w, 3), (1, 2));
    assert_eq!((w.at(3, 1), w.at(3, 2), w.at(3, 3)), (0.0, 0.0, -1e-8));
}
