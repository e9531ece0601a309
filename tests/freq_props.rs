//! Invariants of `ctrlab::freq` over random models: tf → ss → tf round
//! trips, conjugate symmetry of responses, agreement of the model forms,
//! and on adversarial input no panic and `Ok` only with finite numbers.

use ctrlab::freq::{FrequencyDomain, TransferFunction, Zpk, bandwidth, stability_margins};
use ctrlab::{DynStateSpace, Error};
use nalgebra::{Complex, DMatrix};
use proptest::prelude::*;

/// Roots closed under conjugation: `real` real ones and `pairs` complex
/// pairs, in a box of modest size.
fn conjugate_roots(max_real: usize, max_pairs: usize) -> impl Strategy<Value = Vec<Complex<f64>>> {
    (
        prop::collection::vec(-20.0..-0.1f64, 0..=max_real),
        prop::collection::vec((-10.0..-0.1f64, 0.1..30.0f64), 0..=max_pairs),
    )
        .prop_map(|(real, pairs)| {
            let mut out: Vec<Complex<f64>> =
                real.into_iter().map(|r| Complex::new(r, 0.0)).collect();
            for (re, im) in pairs {
                out.push(Complex::new(re, im));
                out.push(Complex::new(re, -im));
            }
            out
        })
}

fn all_finite(g: &[Complex<f64>]) -> bool {
    g.iter().all(|g| g.re.is_finite() && g.im.is_finite())
}

/// A value weighted towards the ones that break numeric code.
fn wild() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -10.0..10.0f64,
        1 => proptest::num::f64::NORMAL,
        1 => prop_oneof![
            Just(0.0), Just(f64::MAX), Just(-f64::MAX), Just(1e-308), Just(f64::NAN),
            Just(f64::INFINITY), Just(f64::NEG_INFINITY),
        ],
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// tf → ss (SciPy's form) → tf keeps the transfer function: the same
    /// response at test frequencies, to 1e-9 of its size (the eigenvalues
    /// and zeros of a model of degree ≤ 6 with roots apart by 0.1 or more).
    #[test]
    fn tf_ss_tf_round_trip(
        poles in conjugate_roots(2, 2),
        zeros in conjugate_roots(1, 1),
        gain in 0.1..10.0f64,
    ) {
        prop_assume!(!poles.is_empty() && zeros.len() <= poles.len());
        let g = Zpk::continuous(&zeros, &poles, gain).unwrap().to_transfer_function().unwrap();
        let sys = g.to_state_space().unwrap();
        let back = TransferFunction::from_state_space(&sys).unwrap();
        let w = [0.0, 0.3, 1.0, 3.3, 10.0, 100.0];
        let (a, b) = (g.frequency_response(&w).unwrap(), back.frequency_response(&w).unwrap());
        let (a, b) = (a.response(0, 0).unwrap(), b.response(0, 0).unwrap());
        for (x, y) in a.iter().zip(b) {
            prop_assert!((x - y).norm() <= 1e-9 * x.norm().max(1e-12), "{x} vs {y}");
        }
        prop_assert_eq!(back.poles().unwrap().len(), poles.len());
    }

    /// A real model's response is conjugate-symmetric: G(−jω) = conj G(jω),
    /// so |G| is even in ω; through the state-space kernel, continuous and
    /// discrete.
    #[test]
    fn responses_are_conjugate_symmetric(
        entries in prop::collection::vec(-3.0..3.0f64, 3 * 3 + 3 * 2 + 2 * 3 + 2 * 2),
        w in 0.01..50.0f64,
        dt in 0.001..0.5f64,
    ) {
        let a = DMatrix::from_column_slice(3, 3, &entries[..9]) - DMatrix::identity(3, 3) * 4.0;
        let b = DMatrix::from_column_slice(3, 2, &entries[9..15]);
        let c = DMatrix::from_column_slice(2, 3, &entries[15..21]);
        let d = DMatrix::from_column_slice(2, 2, &entries[21..25]);
        let cont = DynStateSpace::continuous(a.clone(), b.clone(), c.clone(), d.clone()).unwrap();
        let disc = DynStateSpace::discrete(a * 0.1, b, c, d, dt).unwrap();
        for r in [cont.frequency_response(&[w, -w]), disc.frequency_response(&[w, -w])] {
            let Ok(r) = r else { continue }; // a pole exactly on the grid
            for i in 0..2 {
                for j in 0..2 {
                    let g = r.response(i, j).unwrap();
                    prop_assert!((g[0] - g[1].conj()).norm() <= 1e-12 * g[0].norm().max(1e-300));
                }
            }
        }
    }

    /// The state-space, transfer-function and zero-pole-gain forms of one
    /// SISO model give one response.
    #[test]
    fn model_forms_agree(
        entries in prop::collection::vec(-3.0..3.0f64, 4 * 4 + 4 + 4 + 1),
        w in 0.01..50.0f64,
    ) {
        let a = DMatrix::from_column_slice(4, 4, &entries[..16]) - DMatrix::identity(4, 4) * 5.0;
        let b = DMatrix::from_column_slice(4, 1, &entries[16..20]);
        let c = DMatrix::from_column_slice(1, 4, &entries[20..24]);
        let d = DMatrix::from_element(1, 1, entries[24]);
        let sys = DynStateSpace::continuous(a, b, c, d).unwrap();
        let g = TransferFunction::from_state_space(&sys).unwrap();
        let z = Zpk::from_state_space(&sys).unwrap();
        let r = sys.frequency_response(&[w]).unwrap().response(0, 0).unwrap()[0];
        let scale = r.norm().max(1e-6);
        prop_assert!((g.frequency_response(&[w]).unwrap().response(0, 0).unwrap()[0] - r).norm() <= 1e-8 * scale);
        prop_assert!((z.evaluate(Complex::new(0.0, w)).unwrap() - r).norm() <= 1e-8 * scale);
    }

    /// Adversarial coefficients and frequencies: no panic; Ok only with
    /// finite numbers, errors typed.
    #[test]
    fn ok_implies_finite(
        num in prop::collection::vec(wild(), 0..5),
        den in prop::collection::vec(wild(), 0..5),
        omega in prop::collection::vec(wild(), 0..4),
        dbdrop in wild(),
    ) {
        let Ok(g) = TransferFunction::continuous(&num, &den) else { return Ok(()) };
        if let Ok(r) = g.frequency_response(&omega) {
            prop_assert!(all_finite(r.response(0, 0).unwrap()));
            let b = r.bode(0, 0).unwrap();
            prop_assert!(b.magnitude_db().iter().chain(&b.phase).all(|v| v.is_finite()));
        }
        if let Ok(p) = g.poles() { prop_assert!(all_finite(&p)); }
        if let Ok(z) = g.zeros() { prop_assert!(all_finite(&z)); }
        if let Ok(m) = stability_margins(&g) {
            for v in [m.gain.map(|g| g.margin), m.gain.map(|g| g.frequency),
                      m.phase.map(|p| p.margin), m.phase.map(|p| p.frequency),
                      m.delay.map(|d| d.margin)].into_iter().flatten() {
                prop_assert!(v.is_finite());
            }
        }
        if let Ok(Some(wb)) = bandwidth(&g, dbdrop) { prop_assert!(wb.is_finite() && wb > 0.0); }
        match g.to_state_space() {
            Ok(sys) => {
                if let Ok(r) = sys.frequency_response(&omega) {
                    prop_assert!(all_finite(r.response(0, 0).unwrap()));
                }
            }
            Err(e) => prop_assert!(matches!(e, Error::InvalidData { .. } | Error::Overflow { .. }), "{e}"),
        }
        if let Ok(d) = TransferFunction::discrete(&num, &den, 0.01)
            && let Ok(m) = stability_margins(&d)
        {
            prop_assert!(m.phase.is_none_or(|p| p.margin.is_finite() && p.frequency.is_finite()));
        }
    }
}
