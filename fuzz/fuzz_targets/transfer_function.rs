//! Transfer functions and zero-pole-gain models from any coefficients: a
//! constructor refuses or builds, and everything computed from what it
//! built is refused or finite (issue 28: an `Ok` holds finite numbers).
#![no_main]

use arbitrary::Arbitrary;
use ctrlab::freq::{FrequencyDomain, TransferFunction, Zpk};
use ctrlab::nalgebra::Complex;
use libfuzzer_sys::fuzz_target;

#[derive(Debug, Arbitrary)]
struct Input {
    num: Vec<f64>,
    den: Vec<f64>,
    dt: f64,
    discrete: bool,
    omega: [f64; 3],
}

fn finite(c: &Complex<f64>) -> bool {
    c.re.is_finite() && c.im.is_finite()
}

fn check<D: ctrlab::Domain>(tf: &TransferFunction<D>, omega: &[f64])
where
    TransferFunction<D>: FrequencyDomain,
{
    if let Ok(p) = tf.poles() {
        assert!(p.iter().all(finite), "poles {p:?}");
    }
    if let Ok(z) = tf.zeros() {
        assert!(z.iter().all(finite), "zeros {z:?}");
    }
    if let Ok(g) = tf.dc_gain() {
        assert!(g.is_finite(), "dc gain {g}");
    }
    for &w in omega {
        if let Ok(g) = tf.evaluate(Complex::new(0.0, w)) {
            assert!(finite(&g), "G(j{w}) = {g}");
        }
    }
    if let Ok(r) = tf.frequency_response(omega) {
        let _ = r;
    }
    if let Ok(zpk) = Zpk::from_transfer_function(tf) {
        assert!(zpk.gain().is_finite(), "zpk gain {}", zpk.gain());
        assert!(zpk.poles().iter().chain(zpk.zeros()).all(finite));
        if let Ok(back) = zpk.to_transfer_function() {
            assert!(back.num().iter().chain(back.den()).all(|v| v.is_finite()));
        }
    }
    if let Ok(ss) = tf.to_state_space() {
        if let Ok(back) = TransferFunction::from_state_space(&ss) {
            assert!(back.num().iter().chain(back.den()).all(|v| v.is_finite()));
        }
    }
}

fuzz_target!(|input: Input| {
    // Bounded work: the degrees a control model has, and some.
    if input.num.len() > 24 || input.den.len() > 24 {
        return;
    }
    if input.discrete {
        if let Ok(tf) = TransferFunction::discrete(&input.num, &input.den, input.dt) {
            assert!(tf.dt().is_finite() && tf.dt() > 0.0);
            check(&tf, &input.omega);
        }
    } else if let Ok(tf) = TransferFunction::continuous(&input.num, &input.den) {
        check(&tf, &input.omega);
    }
});
