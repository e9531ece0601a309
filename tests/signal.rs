//! `ctrlab::signal`: the square wave against the lab's expression, the PRBS's
//! maximal length and autocorrelation, the generator against independently
//! computed splitmix64 values, and no panics on any input.

use ctrlab::Error;
// Named, not globbed: proptest's prelude exports rand's `Rng` too.
use ctrlab::signal::{Prbs, Rng, Signal, SquareWave, Step};
use proptest::prelude::*;

/// The lab's square wave as the examples and tests wrote it before
/// `SquareWave` existed.
fn lab_square(a: f64, h: f64, t: f64) -> f64 {
    if ((t / h) as u64).is_multiple_of(2) {
        a
    } else {
        -a
    }
}

/// The simulated card's generator as it stood before `Rng` existed, copied
/// verbatim: `Rng` must reproduce its stream bit for bit.
struct CardRng {
    state: u64,
}

impl CardRng {
    fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn gaussian(&mut self) -> f64 {
        let u1 = ((self.next_u64() >> 11) + 1) as f64 / (1u64 << 53) as f64;
        let u2 = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// One period of a PRBS as bits (1 ↔ `+amplitude`), read through `value` at
/// the middle of each bit.
fn prbs_bits(p: &Prbs) -> Vec<bool> {
    (0..p.len())
        .map(|k| p.value((k as f64 + 0.5) * p.clock()) == p.amplitude())
        .collect()
}

fn invalid_name(err: Error) -> &'static str {
    match err {
        Error::InvalidParameter { name, .. } => name,
        other => panic!("expected InvalidParameter, got {other:?}"),
    }
}

// ---------------------------------------------------------------- Step

#[test]
fn step_switches_at_its_time() {
    let s = Step::new(-3.0, 0.25).unwrap();
    assert_eq!(s.value(0.25_f64.next_down()), 0.0);
    assert_eq!(s.value(0.25), -3.0);
    assert_eq!(s.value(f64::NEG_INFINITY), 0.0);
    assert_eq!(s.value(f64::INFINITY), -3.0);
    // NaN t: the value at t = 0.
    assert_eq!(s.value(f64::NAN), 0.0);
    let on = Step::new(2.0, -1.0).unwrap();
    assert_eq!(on.value(f64::NAN), 2.0);
    assert_eq!((on.amplitude(), on.time()), (2.0, -1.0));
}

#[test]
fn step_rejects_non_finite_parameters() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert_eq!(invalid_name(Step::new(bad, 0.0).unwrap_err()), "amplitude");
        assert_eq!(invalid_name(Step::new(1.0, bad).unwrap_err()), "time");
    }
}

// ---------------------------------------------------------------- SquareWave

#[test]
fn square_wave_equals_the_lab_expression() {
    let a = 2.0;
    for h in [0.2, 0.1, 0.3, 1e-3, 0.05, 7.0, 1e-300] {
        let w = SquareWave::new(a, h).unwrap();
        // A 1 ms grid over 10 s, as the 2 ms loop and finer would sample it.
        for k in 0..10_000 {
            let t = k as f64 * 1e-3;
            assert_eq!(w.value(t), lab_square(a, h, t), "h = {h}, t = {t}");
        }
        // At and either side of every switching instant.
        for j in 0..200 {
            let t = j as f64 * h;
            for t in [t, t.next_up(), t.next_down().max(0.0)] {
                assert_eq!(w.value(t), lab_square(a, h, t), "h = {h}, t = {t}");
            }
        }
        // Huge and infinite times, where `as u64` saturates.
        for t in [
            -0.0,
            1e15,
            2f64.powi(53),
            1e19,
            1e20,
            1e300,
            f64::MAX,
            f64::INFINITY,
        ] {
            assert_eq!(w.value(t), lab_square(a, h, t), "h = {h}, t = {t}");
        }
    }
}

#[test]
fn square_wave_continues_periodically_before_zero() {
    let w = SquareWave::new(1.0, 0.2).unwrap();
    for k in -50i64..50 {
        let t = (k as f64 + 0.5) * 0.2;
        let want = if k.rem_euclid(2) == 0 { 1.0 } else { -1.0 };
        assert_eq!(w.value(t), want, "t = {t}");
    }
    assert_eq!(w.value(-0.2), -1.0);
    assert_eq!(w.value(-0.4), 1.0);
    assert_eq!(w.value(f64::NAN), w.value(0.0));
    assert!(w.value(f64::NEG_INFINITY).is_finite());
    assert_eq!(w.period(), 0.4);
}

#[test]
fn square_wave_rejects_bad_parameters() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert_eq!(
            invalid_name(SquareWave::new(bad, 0.2).unwrap_err()),
            "amplitude"
        );
    }
    for bad in [0.0, -0.0, -0.2, f64::NAN, f64::INFINITY, f64::MAX] {
        assert_eq!(
            invalid_name(SquareWave::new(1.0, bad).unwrap_err()),
            "half_period"
        );
    }
    let err = SquareWave::new(1.0, -0.2).unwrap_err();
    assert_eq!(
        err,
        Error::InvalidParameter {
            name: "half_period",
            value: -0.2,
            reason: "half period must be finite and > 0 s, with a finite period",
        }
    );
}

// ---------------------------------------------------------------- Prbs

/// Every order's taps are maximal: one period of 2ⁿ − 1 bits in which every
/// nonzero n-bit window occurs exactly once (circularly). Distinct windows
/// mean no shorter period, and 2ⁿ − 1 distinct nonzero windows are all of
/// them, so the register visits every nonzero state.
#[test]
fn prbs_of_every_order_is_maximal_length() {
    for n in 2..=20u32 {
        for seed in [1, 0x5eed_u64] {
            if seed & ((1 << n) - 1) == 0 {
                continue;
            }
            let p = Prbs::new(1.0, 1.0, n, seed).unwrap();
            let len = (1usize << n) - 1;
            assert_eq!(p.len(), len);
            assert_eq!(p.order(), n);
            assert_eq!(p.period(), len as f64);
            let bits = prbs_bits(&p);

            let ones = bits.iter().filter(|&&b| b).count();
            assert_eq!(ones, 1 << (n - 1), "order {n}: ones");
            assert_eq!(len - ones, (1 << (n - 1)) - 1, "order {n}: zeros");

            let mut seen = vec![false; 1 << n];
            for k in 0..len {
                let w = (0..n as usize)
                    .fold(0usize, |w, i| (w << 1) | usize::from(bits[(k + i) % len]));
                assert_ne!(w, 0, "order {n}: all-zero window at bit {k}");
                assert!(!seen[w], "order {n}: window {w:#b} repeats at bit {k}");
                seen[w] = true;
            }

            // The sequence repeats after exactly one period, read through time.
            for k in [0, 1, len / 2, len - 1] {
                let t = k as f64 + 0.5;
                assert_eq!(p.value(t + p.period()), p.value(t), "order {n}, bit {k}");
                assert_eq!(
                    p.value(t + 3.0 * p.period()),
                    p.value(t),
                    "order {n}, bit {k}"
                );
            }

            // The first n bits are the seed's, least significant first.
            for (i, &bit) in bits.iter().enumerate().take(n as usize) {
                assert_eq!(bit, (p.seed() >> i) & 1 == 1, "order {n}, seed bit {i}");
            }
        }
    }
}

#[test]
fn prbs_autocorrelation_is_minus_one_off_lag_zero() {
    for n in 2..=10u32 {
        let p = Prbs::new(1.0, 0.01, n, 1).unwrap();
        let len = p.len();
        let s: Vec<i64> = prbs_bits(&p)
            .iter()
            .map(|&b| if b { 1 } else { -1 })
            .collect();
        for lag in 0..len {
            let r: i64 = (0..len).map(|k| s[k] * s[(k + lag) % len]).sum();
            let want = if lag == 0 { len as i64 } else { -1 };
            assert_eq!(r, want, "order {n}, lag {lag}");
        }
    }
}

#[test]
fn prbs_seeds_are_masked_and_shift_the_sequence() {
    let base = Prbs::new(1.0, 0.1, 7, 1).unwrap();
    let masked = Prbs::new(1.0, 0.1, 7, 0xffff_ff81).unwrap();
    assert_eq!(masked.seed(), 1);
    assert_eq!(masked, base);

    // Another seed gives a circular shift of the same sequence.
    let other = Prbs::new(1.0, 0.1, 7, 0x55).unwrap();
    let (a, b) = (prbs_bits(&base), prbs_bits(&other));
    assert_ne!(a, b);
    let len = a.len();
    assert!((0..len).any(|shift| (0..len).all(|k| a[(k + shift) % len] == b[k])));
}

#[test]
fn prbs_holds_each_bit_for_one_clock() {
    // Bit k covers [k·clock, (k + 1)·clock) as far as f64 resolves it: with
    // a power-of-two clock the edges are exact; with 0.02 s, k·0.02 can round
    // into bit k − 1, as with any floor of t / clock, so test inside the bit.
    for (clock, fracs) in [
        (0.015625, &[0.0, 0.01, 0.5, 0.99][..]),
        (0.02, &[0.01, 0.5, 0.99]),
    ] {
        let p = Prbs::new(0.5, clock, 9, 0x1a3).unwrap();
        let bits = prbs_bits(&p);
        for (k, &bit) in bits.iter().enumerate() {
            let want = if bit { 0.5 } else { -0.5 };
            for &frac in fracs {
                let t = (k as f64 + frac) * clock;
                assert_eq!(p.value(t), want, "clock {clock}, bit {k} + {frac}");
            }
        }
    }
    let p = Prbs::new(0.5, 0.02, 9, 0x1a3).unwrap();
    // Before the run, and at NaN: the first bit.
    let first = p.value(0.0);
    for t in [-1e-9, -5.0, f64::NEG_INFINITY, f64::NAN] {
        assert_eq!(p.value(t), first, "t = {t}");
    }
    assert!(p.value(f64::INFINITY).abs() == 0.5);
    assert!(p.value(f64::MAX).abs() == 0.5);
}

#[test]
fn prbs_mean_is_amplitude_over_length() {
    let p = Prbs::new(2.0, 0.004, 8, 0x9c).unwrap();
    let u = p.sample(0.002, 0.004, p.len());
    let mean = u.iter().sum::<f64>() / p.len() as f64;
    assert!((mean - 2.0 / 255.0).abs() < 1e-15, "mean {mean}");
}

#[test]
fn prbs_rejects_bad_parameters() {
    for order in [0, 1, 21, 64, u32::MAX] {
        assert_eq!(
            invalid_name(Prbs::new(1.0, 0.1, order, 1).unwrap_err()),
            "order"
        );
    }
    for seed in [0, 1 << 5, 0xffff_ffe0] {
        assert_eq!(
            invalid_name(Prbs::new(1.0, 0.1, 5, seed).unwrap_err()),
            "seed"
        );
    }
    // A clock whose period (2ⁿ − 1)·clock overflows is refused too.
    for clock in [0.0, -0.1, f64::NAN, f64::INFINITY, f64::MAX] {
        assert_eq!(
            invalid_name(Prbs::new(1.0, clock, 5, 1).unwrap_err()),
            "clock"
        );
    }
    assert_eq!(
        invalid_name(Prbs::new(f64::NAN, 0.1, 5, 1).unwrap_err()),
        "amplitude"
    );
}

#[test]
fn prbs_debug_leaves_out_the_bits() {
    let text = format!("{:?}", Prbs::new(1.0, 0.1, 20, 1).unwrap());
    assert!(
        text.starts_with("Prbs {") && text.contains("len: 1048575"),
        "{text}"
    );
    assert!(text.len() < 200, "{text}");
}

// ---------------------------------------------------------------- Signal

#[test]
fn sample_evaluates_at_t0_plus_k_dt() {
    let w = SquareWave::new(1.0, 0.2).unwrap();
    let u = w.sample(0.1, 0.3, 7);
    let want: Vec<f64> = (0..7).map(|k| w.value(0.1 + k as f64 * 0.3)).collect();
    assert_eq!(u, want);
    assert!(w.sample(0.0, 0.1, 0).is_empty());
}

#[test]
fn references_and_trait_objects_are_signals() {
    fn total(s: impl Signal) -> f64 {
        s.sample(0.0, 0.5, 4).iter().sum()
    }
    let step = Step::new(1.0, 1.0).unwrap();
    let by_ref: &Step = &step;
    let by_ref_ref: &&Step = &by_ref;
    let dynamic: &dyn Signal = &step;
    assert_eq!(total(step), 2.0);
    assert_eq!(total(by_ref), 2.0);
    assert_eq!(total(by_ref_ref), 2.0);
    assert_eq!(total(dynamic), 2.0);
}

// ---------------------------------------------------------------- Rng

/// splitmix64 from seed 0x5eed. Expected values computed independently in
/// Python (arbitrary-precision integers, masked to 64 bits) with:
///
/// ```text
/// python3 -c "
/// M=(1<<64)-1
/// s=0x5eed
/// for _ in range(5):
///     s=(s+0x9e3779b97f4a7c15)&M; z=s; z=((z^(z>>30))*0xbf58476d1ce4e5b9)&M; z=((z^(z>>27))*0x94d049bb133111eb)&M; print(hex(z^(z>>31)))
/// "
/// ```
///
/// The same script from seed 0 prints 0xe220a8397b1dcdaf, 0x6e789e6aa1b965f4,
/// the published first outputs of Vigna's splitmix64.c.
#[test]
fn rng_reproduces_splitmix64() {
    let mut rng = Rng::new(0x5eed);
    let want: [u64; 5] = [
        0x09f1_fd9d_03f0_a9b4,
        0x5532_7416_1bbf_8475,
        0x5d5b_ca46_96b3_43b3,
        0x70d2_9b6c_7d22_528d,
        0x0bf2_b716_f991_5475,
    ];
    for (k, &w) in want.iter().enumerate() {
        assert_eq!(rng.next_u64(), w, "output {k}");
    }
    let mut zero = Rng::new(0);
    assert_eq!(zero.next_u64(), 0xe220_a839_7b1d_cdaf);
    assert_eq!(zero.next_u64(), 0x6e78_9e6a_a1b9_65f4);
}

/// The first Box–Muller samples from seed 0x5eed, computed in Python from the
/// splitmix64 stream above (`u1 = ((x >> 11) + 1) / 2**53`,
/// `u2 = (x >> 11) / 2**53`, `sqrt(-2 log u1) cos(2π u2)`). Python's libm may
/// differ from Rust's in the last bit, hence the tolerance.
#[test]
fn rng_gaussian_matches_box_muller() {
    let mut rng = Rng::new(0x5eed);
    for (k, want) in [
        -1.2669898075097232,
        -1.3229606993117362,
        -1.6946897115349515,
    ]
    .into_iter()
    .enumerate()
    {
        let got = rng.gaussian();
        assert!(
            (got - want).abs() <= 4.0 * f64::EPSILON * want.abs(),
            "sample {k}: {got} vs {want}"
        );
    }
}

#[test]
fn rng_reproduces_the_simulated_cards_stream() {
    for seed in [0, 1, 0x5eed, 42, u64::MAX, 0x9e37_79b9_7f4a_7c15] {
        let mut rng = Rng::new(seed);
        let mut card = CardRng { state: seed };
        for k in 0..10_000 {
            assert_eq!(
                rng.gaussian().to_bits(),
                card.gaussian().to_bits(),
                "seed {seed:#x}, sample {k}"
            );
        }
        assert_eq!(rng.next_u64(), card.next_u64());
    }
}

#[test]
fn rng_uniform_is_the_top_53_bits() {
    let mut a = Rng::new(0x5eed);
    let mut b = Rng::new(0x5eed);
    for _ in 0..1000 {
        let u = a.uniform();
        assert!((0.0..1.0).contains(&u));
        assert_eq!(u, (b.next_u64() >> 11) as f64 * 2f64.powi(-53));
    }
}

// ---------------------------------------------------------------- proptest

/// Any f64, with the awkward ones (NaN, ±∞, extremes, subnormals, signed
/// zeros) well represented.
fn any_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => proptest::num::f64::ANY,
        1 => prop::sample::select(vec![
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            5e-324,
            -5e-324,
            0.0,
            -0.0,
            1e300,
            -1e300,
            2f64.powi(64),
        ]),
        2 => -10.0..10.0f64,
    ]
}

/// Checks that an `Ok` signal has finite values in `allowed` at every
/// `t` (NaN and ±∞ included), and the value at `t = 0` for NaN `t`.
fn check_signal(s: &impl Signal, allowed: &[f64], times: &[f64]) -> Result<(), TestCaseError> {
    for &t in times {
        let v = s.value(t);
        prop_assert!(v.is_finite(), "value({t}) = {v}");
        prop_assert!(
            allowed.contains(&v),
            "value({t}) = {v}, allowed {allowed:?}"
        );
    }
    prop_assert_eq!(s.value(f64::NAN), s.value(0.0));
    Ok(())
}

proptest! {
    #[test]
    fn step_never_panics(a in any_f64(), time in any_f64(), t in any_f64(), t2 in any_f64()) {
        match Step::new(a, time) {
            Ok(s) => check_signal(&s, &[0.0, a], &[t, t2, f64::INFINITY, f64::NEG_INFINITY])?,
            Err(e) => {
                prop_assert!(!a.is_finite() || !time.is_finite());
                let name = invalid_name(e);
                prop_assert!(name == "amplitude" || name == "time");
            }
        }
    }

    #[test]
    fn square_wave_never_panics(a in any_f64(), h in any_f64(), t in any_f64(), t2 in any_f64()) {
        match SquareWave::new(a, h) {
            Ok(w) => {
                check_signal(&w, &[a, -a], &[t, t2, f64::INFINITY, f64::NEG_INFINITY])?;
                if t >= 0.0 {
                    prop_assert_eq!(w.value(t), lab_square(a, h, t));
                }
                prop_assert!(w.period().is_finite());
            }
            Err(e) => {
                prop_assert!(!(a.is_finite() && h > 0.0 && (2.0 * h).is_finite()));
                let name = invalid_name(e);
                prop_assert!(name == "amplitude" || name == "half_period");
            }
        }
    }

    #[test]
    fn prbs_never_panics(
        a in any_f64(),
        clock in any_f64(),
        order in prop_oneof![0u32..=22, any::<u32>()],
        seed in any::<u64>(),
        t in any_f64(),
        t2 in any_f64(),
    ) {
        match Prbs::new(a, clock, order, seed) {
            Ok(p) => {
                check_signal(&p, &[a, -a], &[t, t2, f64::INFINITY, f64::NEG_INFINITY])?;
                prop_assert!(p.period().is_finite() && p.period() > 0.0);
                prop_assert_eq!(p.seed(), seed & ((1 << order) - 1));
            }
            Err(e) => {
                let name = invalid_name(e);
                prop_assert!(["amplitude", "clock", "order", "seed"].contains(&name), "{}", name);
            }
        }
    }

    #[test]
    fn sample_never_panics(t0 in any_f64(), dt in any_f64(), n in 0usize..64) {
        let w = SquareWave::new(1.0, 0.2).unwrap();
        let u = w.sample(t0, dt, n);
        prop_assert_eq!(u.len(), n);
        prop_assert!(u.iter().all(|v| v.abs() == 1.0));
    }

    #[test]
    fn rng_outputs_are_in_range(seed in any::<u64>()) {
        let mut rng = Rng::new(seed);
        for _ in 0..16 {
            let u = rng.uniform();
            prop_assert!((0.0..1.0).contains(&u));
            let g = rng.gaussian();
            prop_assert!(g.is_finite() && g.abs() < 8.6);
        }
    }
}
