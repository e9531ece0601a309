//! `freq::pade` against python-control's own test (control/tests/
//! delay_test.py: Miklos Vajta's table, "Some remarks on Padé-
//! approximations", with python-control's two corrections), at its
//! tolerance, 2 units in the last place; and the approximation's
//! properties: all-pass, unit DC gain, the delay's phase at low frequency.

use ctrlab::Error;
use ctrlab::freq::{MAX_PADE_ORDER, pade, pade_with_degrees};
use ctrlab::nalgebra::Complex;
use proptest::prelude::*;

/// (denominator degree, numerator degree, den, num) at T = 1.
const VAJTA: [(usize, usize, &[f64], &[f64]); 10] = [
    (1, 1, &[1.0, 2.0], &[-1.0, 2.0]),
    (1, 0, &[1.0, 1.0], &[1.0]),
    (2, 2, &[1.0, 6.0, 12.0], &[1.0, -6.0, 12.0]),
    (2, 1, &[1.0, 4.0, 6.0], &[-2.0, 6.0]),
    (3, 3, &[1.0, 12.0, 60.0, 120.0], &[-1.0, 12.0, -60.0, 120.0]),
    (3, 2, &[1.0, 9.0, 36.0, 60.0], &[3.0, -24.0, 60.0]),
    (
        4,
        4,
        &[1.0, 20.0, 180.0, 840.0, 1680.0],
        &[1.0, -20.0, 180.0, -840.0, 1680.0],
    ),
    (
        4,
        3,
        &[1.0, 16.0, 120.0, 480.0, 840.0],
        &[-4.0, 60.0, -360.0, 840.0],
    ),
    (
        5,
        5,
        &[1.0, 30.0, 420.0, 3360.0, 15120.0, 30240.0],
        &[-1.0, 30.0, -420.0, 3360.0, -15120.0, 30240.0],
    ),
    (
        5,
        4,
        &[1.0, 25.0, 300.0, 2100.0, 8400.0, 15120.0],
        &[5.0, -120.0, 1260.0, -6720.0, 15120.0],
    ),
];

/// Units in the last place between two doubles (NumPy's
/// `assert_array_almost_equal_nulp` measure).
fn nulp(a: f64, b: f64) -> u64 {
    let key = |x: f64| {
        let bits = x.to_bits() as i64;
        if bits < 0 { i64::MIN - bits } else { bits }
    };
    key(a).abs_diff(key(b))
}

fn assert_nulp(got: &[f64], want: &[f64], what: &str) {
    assert_eq!(got.len(), want.len(), "{what}: {got:?} against {want:?}");
    for (g, w) in got.iter().zip(want) {
        assert!(nulp(*g, *w) <= 2, "{what}: {got:?} against {want:?}");
    }
}

#[test]
fn vajtas_table_at_t_1_to_2_ulp() {
    for (p, q, den, num) in VAJTA {
        let d = pade_with_degrees(1.0, q, p).unwrap();
        assert_nulp(d.den(), den, &format!("den {q}/{p}"));
        assert_nulp(d.num(), num, &format!("num {q}/{p}"));
    }
}

/// python-control's `testTvalues`: the table scaled by powers of T, then
/// normalised by the leading denominator coefficient.
#[test]
fn vajtas_table_scaled_to_other_delays_to_2_ulp() {
    for t in [1.0 / 53.0, 21.95f64] {
        for (p, q, den, num) in VAJTA {
            let scale = |c: &[f64], deg: usize| -> Vec<f64> {
                c.iter()
                    .enumerate()
                    .map(|(i, c)| t.powi((deg - i) as i32) * c)
                    .collect()
            };
            let (mut rden, mut rnum) = (scale(den, p), scale(num, q));
            let lead = rden[0];
            rnum.iter_mut().for_each(|c| *c /= lead);
            rden.iter_mut().for_each(|c| *c /= lead);
            let d = pade_with_degrees(t, q, p).unwrap();
            assert_nulp(d.den(), &rden, &format!("den {q}/{p} at T = {t}"));
            assert_nulp(d.num(), &rnum, &format!("num {q}/{p} at T = {t}"));
        }
    }
}

#[test]
fn a_zero_delay_is_one_and_bad_input_is_refused() {
    for n in 0..=5 {
        let d = pade(0.0, n).unwrap();
        assert_eq!((d.num(), d.den()), (&[1.0][..], &[1.0][..]));
    }
    let name = |r: Result<_, Error>| match r {
        Err(Error::InvalidParameter { name, .. }) => name,
        other => panic!("{other:?}"),
    };
    assert_eq!(name(pade(-1.0, 1)), "delay");
    assert_eq!(name(pade(f64::NAN, 1)), "delay");
    assert_eq!(name(pade(f64::INFINITY, 1)), "delay");
    assert_eq!(name(pade_with_degrees(1.0, 3, 2)), "numerator_degree");
    assert_eq!(name(pade(1.0, MAX_PADE_ORDER + 1)), "order");
    assert_eq!(name(pade(1.0, usize::MAX)), "order");
    assert!(pade(1.0, MAX_PADE_ORDER).is_ok());
    assert!(matches!(pade(1e300, 2), Err(Error::Overflow { .. })));
    assert!(matches!(pade(1e-300, 2), Err(Error::Overflow { .. })));
}

proptest! {
    /// Equal degrees are all-pass with unit DC gain; at ω T ≤ 0.1 the
    /// phase is the delay's, −ω T, within the next term of its series.
    #[test]
    fn equal_degrees_are_all_pass_with_the_delays_phase(
        t in 1e-4..10.0f64,
        n in 1usize..=8,
        w_t in 1e-3..0.1f64,
    ) {
        let d = pade(t, n).unwrap();
        prop_assert!((d.dc_gain().unwrap() - 1.0).abs() < 1e-12);
        let g = d.evaluate(Complex::new(0.0, w_t / t)).unwrap();
        prop_assert!((g.norm() - 1.0).abs() < 1e-10, "|G| = {}", g.norm());
        // The first order's phase error is (ωT)³/12; higher orders less.
        prop_assert!((g.arg() + w_t).abs() <= w_t.powi(3) / 12.0 * 1.01 + 1e-12);
    }

    /// A lower numerator is strictly proper, still with unit DC gain.
    #[test]
    fn a_lower_numerator_is_strictly_proper(t in 1e-3..10.0f64, p in 1usize..=8, drop in 1usize..=8) {
        let q = p.saturating_sub(drop);
        let d = pade_with_degrees(t, q, p).unwrap();
        prop_assert_eq!(d.num().len(), q + 1);
        prop_assert_eq!(d.den().len(), p + 1);
        prop_assert!((d.dc_gain().unwrap() - 1.0).abs() < 1e-12);
    }
}
