//! A value that is not finite is reported as the first one, whichever
//! path finds it: the identification checks `u`, `x1` and `x2` through the
//! rows that read them (and the samples no row reads on their own), so
//! these tests put one, or two, at every sample of every channel, in
//! recordings with gaps (a segment too short for a row included), under
//! every option that changes which samples the rows read, and compare
//! with a plain scan of the recording: time first, then the channels in
//! the schema's order.

#![cfg(feature = "lab")]

use ctrlab::Error;
use ctrlab::data::Recording;
use ctrlab::ident::Covariance;
use ctrlab::lab::ident::{Options, Scheme, identify_with};

const N: usize = 48;

/// The lab's schema (`u`, `x1`, `v1`, `x2`, `v2`): carts swinging, time
/// stamps with a gap after sample 19 and a two-sample segment at 30–31.
fn recording() -> Recording {
    let mut rec = Recording::new(ctrlab::lab::schema());
    let mut t = 0.0;
    for k in 0..N {
        t += if k == 20 || k == 30 || k == 32 {
            0.05
        } else {
            0.002
        };
        let s = k as f64 * 0.3;
        let (x1, x2) = (1e-3 * s.sin(), 2e-3 * (0.7 * s).cos());
        rec.push(t, &[(k % 7) as f64 - 3.0], &[x1, 0.0, x2, 0.0])
            .unwrap();
    }
    rec
}

/// The first value that is not finite, scanning as the check is defined.
fn first(rec: &Recording) -> Option<(usize, String)> {
    let names = ["t", "u", "x1", "v1", "x2", "v2"];
    names.iter().find_map(|&name| {
        let col = if name == "t" {
            rec.time()
        } else {
            rec.channel(name).unwrap()
        };
        col.iter()
            .position(|v| !v.is_finite())
            .map(|k| (k, format!("{name} = {} is not finite", col[k])))
    })
}

fn options() -> Vec<Options> {
    let mut all = Vec::new();
    for scheme in [Scheme::Lab, Scheme::Central] {
        for coulomb in [false, true] {
            for covariance in [Covariance::NeweyWest { lags: None }, Covariance::Classical] {
                all.push(Options {
                    scheme,
                    coulomb,
                    covariance,
                    ..Options::default()
                });
            }
        }
    }
    all
}

fn set(rec: &mut Recording, name: &str, k: usize, v: f64) {
    if name == "t" {
        rec.time_mut()[k] = v;
    } else {
        rec.channel_mut(name).unwrap()[k] = v;
    }
}

fn check(rec: &Recording, options: &Options, what: &str) {
    let want = first(rec).expect("a value that is not finite");
    match identify_with(rec, 1.3, 0.7, options) {
        Err(Error::InvalidRecording { index, reason }) => {
            assert_eq!((index, reason), want, "{what}, {options:?}");
        }
        other => panic!("{what}, {options:?}: {other:?}, want {want:?}"),
    }
}

#[test]
fn one_value_that_is_not_finite_is_named_wherever_it_is() {
    let clean = recording();
    for options in options() {
        // Without one, no error about the recording's values.
        let result = identify_with(&clean, 1.3, 0.7, &options);
        assert!(
            !matches!(result, Err(Error::InvalidRecording { .. })),
            "{options:?}: {result:?}"
        );
        for name in ["u", "x1", "v1", "x2", "v2"] {
            for k in 0..N {
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                    let mut rec = clean.clone();
                    set(&mut rec, name, k, bad);
                    check(&rec, &options, &format!("{name}[{k}] = {bad}"));
                }
            }
        }
    }
}

#[test]
fn of_two_the_first_in_the_scan_is_named() {
    let clean = recording();
    let names = ["t", "u", "x1", "v1", "x2", "v2"];
    for options in options() {
        for (i, a) in names.iter().enumerate() {
            for b in &names[i..] {
                for (ka, kb) in [(0, N - 1), (N - 1, 0), (25, 5), (31, 31), (5, 47)] {
                    let mut rec = clean.clone();
                    set(&mut rec, a, ka, f64::NAN);
                    set(&mut rec, b, kb, f64::INFINITY);
                    check(&rec, &options, &format!("{a}[{ka}], {b}[{kb}]"));
                }
            }
        }
    }
}

/// A recording long enough for the streamed stages (blocks of rows).
#[test]
fn in_a_long_recording_too() {
    let n = 70_000;
    let mut clean = Recording::new(ctrlab::lab::schema());
    for k in 0..n {
        let s = k as f64 * 0.01;
        let (x1, x2) = (1e-3 * s.sin(), 2e-3 * (0.7 * s).cos());
        clean
            .push(
                k as f64 * 0.002,
                &[((k / 500) % 2) as f64],
                &[x1, 0.0, x2, 0.0],
            )
            .unwrap();
    }
    for options in options() {
        for (name, k) in [
            ("x2", 69_000),
            ("u", n - 1),
            ("x1", 0),
            ("u", 40_000),
            ("v2", 3),
        ] {
            let mut rec = clean.clone();
            set(&mut rec, name, k, f64::NAN);
            check(&rec, &options, &format!("{name}[{k}]"));
        }
    }
}
