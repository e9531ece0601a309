//! The Excitation section: the lab's square wave against the identification
//! inputs of `ctrlab::signal` (PRBS, multisine, chirp) at the same peak
//! voltage and length, each identified as the separate-springs model with
//! Coulomb friction.

use ctrlab::lab::ident::{MassSpringEstimate, Options, Scheme, SpringModel, identify_with};
use ctrlab::nalgebra::vector;
use ctrlab::signal::{Chirp, Multisine, Phases, Prbs, Signal, SquareWave, Sweep};
use ctrlab::{OpenLoop, Recording};

use crate::report::Report;
use crate::rig::{Backend, IDENT_DURATION, IDENT_HALF_PERIOD, IDENT_VOLTS, M1, M2, RUNS};

/// An input compared: its name, its settings, and the signal (V).
type Input = (&'static str, String, Box<dyn Signal>);

/// The inputs compared, each at `IDENT_VOLTS` peak over `IDENT_DURATION`.
fn inputs() -> Result<Vec<Input>, ctrlab::Error> {
    let square = SquareWave::new(IDENT_VOLTS, IDENT_HALF_PERIOD)?;
    // A new bit every 40 ms: flat to 0.44 / 0.04 = 11 Hz, past both modes;
    // 2⁷ − 1 bits = 5.08 s, one period per run.
    let prbs = Prbs::new(IDENT_VOLTS, 0.04, 7, 0x5b)?;
    // Harmonics 1..=50 of 1 / 5 s: 0.2 to 10 Hz, one period per run, scaled
    // to the drive's peak.
    let unit = Multisine::new(1.0, IDENT_DURATION, 1..=50, Phases::Schroeder)?;
    let multisine = Multisine::new(
        IDENT_VOLTS / unit.peak(),
        IDENT_DURATION,
        1..=50,
        Phases::Schroeder,
    )?;
    let chirp = Chirp::new(IDENT_VOLTS, 0.2, 10.0, IDENT_DURATION, Sweep::Logarithmic)?;
    Ok(vec![
        (
            "square wave (the lab's)",
            format!("±{IDENT_VOLTS} V, {IDENT_HALF_PERIOD} s half period"),
            Box::new(square),
        ),
        (
            "PRBS",
            format!("±{IDENT_VOLTS} V, 7 bits, 40 ms clock"),
            Box::new(prbs),
        ),
        (
            "multisine",
            format!(
                "{:.2} V per line on 0.2–10 Hz (50 lines), Schroeder phases, crest {:.2}",
                multisine.amplitude(),
                multisine.crest_factor()
            ),
            Box::new(multisine),
        ),
        (
            "chirp",
            format!("{IDENT_VOLTS} V, 0.2 → 10 Hz logarithmic"),
            Box::new(chirp),
        ),
    ])
}

/// Every input `RUNS` times; a table of the estimates' errors against the
/// truth (simulated rig) or their spread (real card). Returns the first
/// PRBS run's recording, a run the Validation section's models have not
/// seen.
pub fn section(
    backend: &Backend,
    report: &mut Report,
) -> Result<Option<Recording>, Box<dyn std::error::Error>> {
    report.heading(2, "Excitation: which input identifies best");
    report.add(&format!(
        "The same identification (separate springs, Coulomb friction, Central scheme) from four inputs of the same peak ({IDENT_VOLTS} V) and length ({IDENT_DURATION} s), {RUNS} runs each (recordings in `runs/excite_*.csv`). The square wave puts its power on a few odd harmonics of 2.5 Hz; the PRBS spreads it flat to 11 Hz; the multisine puts it exactly on 50 lines from 0.2 to 10 Hz; the chirp sweeps 0.2–10 Hz once, the same time per octave.\n"
    ));
    let options = Options {
        springs: SpringModel::Separate,
        scheme: Scheme::Central,
        coulomb: true,
        ..Options::default()
    };
    let truth = backend.truth();
    let coulomb_truth = backend.coulomb_truth();
    let mut rows = Vec::new();
    // (input, worst |error| %) on the simulated rig.
    let mut worst: Vec<(&str, f64)> = Vec::new();
    let mut fresh = None;
    for (i, (name, what, signal)) in inputs()?.into_iter().enumerate() {
        let mut estimates: Vec<MassSpringEstimate> = Vec::new();
        let mut failure = None;
        let rms = {
            let u = signal.sample(
                0.0,
                crate::rig::PERIOD,
                (IDENT_DURATION / crate::rig::PERIOD) as usize,
            );
            (u.iter().map(|v| v * v).sum::<f64>() / u.len() as f64).sqrt()
        };
        for seed in 1..=RUNS {
            let outcome = backend.experiment(
                &format!("excite_{i}_{seed}"),
                seed,
                None,
                OpenLoop,
                |t| vector![signal.value(t)],
                IDENT_DURATION,
            )?;
            match outcome {
                Ok(out) => {
                    match identify_with(&out.recording, M1, M2, &options) {
                        Ok(e) => estimates.push(e),
                        Err(e) => failure = Some(format!("not identified: {e}")),
                    }
                    if name == "PRBS" && seed == 1 {
                        fresh = Some(out.recording);
                    }
                }
                Err(e) => failure = Some(format!("run halted: {}", e.error)),
            }
            if failure.is_some() {
                break;
            }
        }
        let mut row = vec![format!("**{name}**<br>{what}"), format!("{rms:.2}")];
        if let Some(f) = failure {
            row.push(f);
            row.extend(std::iter::repeat_n(String::new(), 6));
            rows.push(row);
            continue;
        }
        let n = estimates.len() as f64;
        let mean =
            |f: &dyn Fn(&MassSpringEstimate) -> f64| estimates.iter().map(f).sum::<f64>() / n;
        let coulomb = |e: &MassSpringEstimate, c: usize| e.coulomb.map_or(f64::NAN, |f| f[c].value);
        let cells: [(f64, Option<f64>); 7] = [
            (mean(&|e| e.k1().value), truth.map(|t| t.k1)),
            (mean(&|e| e.k2().value), truth.map(|t| t.k2)),
            (mean(&|e| e.gain.value), truth.map(|t| t.gain)),
            (mean(&|e| e.b1.value), truth.map(|t| t.b1)),
            (mean(&|e| e.b2.value), truth.map(|t| t.b2)),
            (mean(&|e| coulomb(e, 0)), coulomb_truth.map(|c| c[0])),
            (mean(&|e| coulomb(e, 1)), coulomb_truth.map(|c| c[1])),
        ];
        let errors = cells
            .iter()
            .filter_map(|(v, t)| t.map(|t| (v / t - 1.0).abs() * 100.0));
        if truth.is_some() {
            worst.push((name, errors.fold(0.0, f64::max)));
        }
        for (value, truth) in cells {
            row.push(match truth {
                Some(t) => format!("{:.4} ({:+.1} %)", value, (value / t - 1.0) * 100.0),
                None => format!("{value:.4}"),
            });
        }
        rows.push(row);
    }
    report.table(
        &[
            "input",
            "RMS (V)",
            "k1 (N/m)",
            "k2 (N/m)",
            "K (N/V)",
            "b1 (N·s/m)",
            "b2 (N·s/m)",
            "F1 (N)",
            "F2 (N)",
        ],
        &rows,
    );
    if let Some((best, e)) = worst.iter().min_by(|a, b| a.1.total_cmp(&b.1)) {
        report.add(&format!(
            "Means over the runs, with the error against the simulated card's truth in brackets. Smallest worst-case error: the {best} ({e:.1} %). At one peak voltage the input with the most RMS puts the most energy into the fit, and where its power lies in frequency decides which parameters it pins down: the viscous frictions need slow motion, the springs and the gain the band around the two modes.\n"
        ));
    } else {
        report.add("Means over the runs (the real rig's truth is unknown: compare the inputs with each other and with the square wave's Tables 3 and 4).\n");
    }
    Ok(fresh)
}
