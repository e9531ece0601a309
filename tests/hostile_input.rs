//! Issue 28's hostile inputs that are not one module's: error messages
//! print numbers readably (an extreme value as `1e300`, not its 301 digits:
//! `Chirp::new(1, 1, 1e300, 1, Linear)`'s message was 398 characters,
//! lab5's `max_gap = 0.000…` 300 digits), and sizes no machine holds are
//! refused or taken as hints, never a panic or an aborting allocation.

use ctrlab::signal::{Chirp, Sweep};

/// Every message here names its number in at most this many characters
/// (the longest, the loop's configuration conflict, is ~110).
const SHORT: usize = 160;

#[test]
fn a_sweep_over_too_many_cycles_names_its_frequency_in_exponent_form() {
    let message = Chirp::new(1.0, 1.0, 1e300, 1.0, Sweep::Linear)
        .unwrap_err()
        .to_string();
    assert!(message.contains("`f1` = 1e300"), "{message}");
    assert!(
        message.len() <= SHORT,
        "{} characters: {message}",
        message.len()
    );
}

#[test]
fn a_tiny_parameter_is_not_printed_as_zeros() {
    let message = Chirp::new(1.0, 1e-300, 1.0, -1.0, Sweep::Linear)
        .unwrap_err()
        .to_string();
    assert!(message.contains("`duration` = -1"), "{message}");
    let message = Chirp::new(1.0, -1e-300, 1.0, 1.0, Sweep::Linear)
        .unwrap_err()
        .to_string();
    assert!(message.contains("-1e-300"), "{message}");
    assert!(message.len() <= SHORT, "{message}");
}

#[cfg(feature = "lab")]
#[test]
fn a_gap_limit_of_1e_300_reads_as_1e_300() {
    use ctrlab::OpenLoop;
    use ctrlab::hw::{Clock, LoopConfig, VirtualClock, run};
    use ctrlab::lab::SimulatedRig;
    use nalgebra::vector;
    let clock = VirtualClock::new();
    let rig = SimulatedRig::default()
        .rig(&Clock::Virtual(clock.clone()))
        .unwrap();
    let cfg = LoopConfig {
        max_gap: Some(1e-300),
        ..LoopConfig::default()
    };
    let err = run(
        rig,
        OpenLoop,
        |_| vector![0.0],
        &Clock::Virtual(clock),
        &cfg,
    )
    .unwrap_err();
    let message = err.error.to_string();
    assert!(message.contains("`max_gap` = 1e-300"), "{message}");
    assert!(
        message.len() <= SHORT,
        "{} characters: {message}",
        message.len()
    );
}

/// Sizes no machine holds are refused, or taken as hints, without a
/// "capacity overflow" panic or an aborting allocation (issue 28).
#[test]
fn impossible_sizes_are_refused_or_hints_never_a_panic() {
    use ctrlab::data::{MAX_CHANNELS, Recording, Schema};
    use ctrlab::freq::logspace;
    assert!(logspace(0.0, 1.0, usize::MAX).is_err());
    assert!(Schema::numbered(1 << 40, 0).is_err());
    assert!(Schema::numbered(usize::MAX, usize::MAX).is_err());
    assert_eq!(
        Schema::numbered(MAX_CHANNELS - 1, 1).unwrap().len(),
        MAX_CHANNELS
    );
    let mut rec = Recording::with_capacity(Schema::numbered(1, 1).unwrap(), usize::MAX);
    rec.push(0.0, &[1.0], &[2.0]).unwrap();
    assert_eq!(rec.len(), 1);
}

/// Issue 28 reported `bode_svg` never returning for a frequency of 1e-309
/// (fine down to 2.2e-308). Not reproduced on this code; kept as a guard:
/// subnormal frequencies, alone or over 312 decades, in both units, marked
/// and not, draw and return.
#[cfg(feature = "plot")]
#[test]
fn bode_figures_of_subnormal_frequencies_return() {
    use ctrlab::freq::{Bode, FrequencyUnit, bode_marked_svg, bode_svg};
    let dir = std::env::temp_dir().join(format!("ctrlab_subnormal_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bode.svg");
    let w: Vec<f64> = (0..200)
        .map(|k| 10f64.powf(-309.0 + 312.0 * k as f64 / 199.0))
        .collect();
    let grids = [
        vec![1e-309],
        vec![1e-309, 2e-309],
        vec![5e-324, 1.0],
        w.clone(),
    ];
    for omega in grids {
        let n = omega.len();
        for magnitude in [
            vec![1.0; n],
            omega.iter().map(|w| 1.0 / w.max(1e-300)).collect(),
        ] {
            let b = Bode {
                omega: omega.clone(),
                magnitude,
                phase: vec![0.0; n],
            };
            for unit in [FrequencyUnit::RadPerSecond, FrequencyUnit::Hertz] {
                // Drawn or refused: what matters is that it returns.
                let _ = bode_svg(&path, "subnormal", unit, &[("a", &b)]);
                let _ = bode_marked_svg(&path, "subnormal", unit, &[("a", &b)], &[("m", 1e-309)]);
            }
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `LeastSquares::new(usize::MAX)` and `with_capacity(2, usize::MAX)`
/// panicked ("capacity overflow"); the sizes are hints now, and a problem
/// that cannot have more rows than parameters says so when solved.
#[test]
fn least_squares_of_impossible_sizes_refuse_instead_of_panicking() {
    use ctrlab::Error;
    use ctrlab::ident::LeastSquares;
    let mut huge = LeastSquares::new(usize::MAX);
    assert_eq!(huge.parameters(), usize::MAX);
    assert!(huge.push_row(&[1.0], 1.0).is_err());
    assert!(matches!(huge.solve(), Err(Error::TooFewSamples { .. })));
    let mut tall = LeastSquares::with_capacity(2, usize::MAX);
    for k in 0..10 {
        tall.push_row(&[1.0, k as f64], 1.0 + 2.0 * k as f64)
            .unwrap();
    }
    let fit = tall.solve().unwrap();
    assert!((fit.theta[0] - 1.0).abs() < 1e-12 && (fit.theta[1] - 2.0).abs() < 1e-12);
}
