//! The Frequency response section: the rig's measured response (ETFE of a
//! periodic multisine, and its Blackman–Tukey smoothing) under the
//! identified model's Bode plot, with the two modes located on each.

use ctrlab::freq::{bode, logspace};
use ctrlab::ident::{FrequencyEstimate, etfe, spa};
use ctrlab::lab::{CardSettings, Cart, Friction, MassSpring, SimulatedRig};
use ctrlab::nalgebra::{SVector, vector};
use ctrlab::signal::{Multisine, Phases, Signal};
use ctrlab::sim::run_sampled;
use ctrlab::{OpenLoop, Recording};

use crate::identification::Identification;
use crate::report::Report;
use crate::rig::{Backend, IDENT_VOLTS, PERIOD};

/// One period of the multisine, s: lines every 0.2 Hz.
const MS_PERIOD: f64 = 5.0;
/// Harmonics of 1 / MS_PERIOD: 0.2 to 15 Hz, past both modes.
const LINES: std::ops::RangeInclusive<u32> = 1..=75;
/// Periods run; the first lets the transient die out (the slowest mode
/// decays in about a second) and is left out of the estimate.
const PERIODS: usize = 3;
/// The smoothed estimate's lag window, s (samples = this / PERIOD).
const SPA_WINDOW: f64 = 2.5;

/// The modes of a model: natural frequencies of its two complex pole
/// pairs, Hz, ascending.
fn modes_hz(model: &MassSpring) -> Result<Vec<f64>, Box<dyn std::error::Error>> {
    let mut hz: Vec<f64> = model
        .state_space(Cart::Two)?
        .damping()?
        .iter()
        .filter(|d| d.pole.im > 0.0)
        .map(|d| d.natural_frequency / std::f64::consts::TAU)
        .collect();
    hz.sort_by(f64::total_cmp);
    Ok(hz)
}

/// The frequencies (Hz) of the `count` largest local maxima of `|G|`,
/// ascending.
fn peaks_hz(g: &FrequencyEstimate, count: usize) -> Vec<f64> {
    let m = g.magnitude();
    let hz = g.frequency_hz();
    let mut peaks: Vec<(f64, f64)> = (1..m.len().saturating_sub(1))
        .filter(|&i| m[i] > m[i - 1] && m[i] >= m[i + 1])
        .map(|i| (m[i], hz[i]))
        .collect();
    peaks.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut out: Vec<f64> = peaks.iter().take(count).map(|p| p.1).collect();
    out.sort_by(f64::total_cmp);
    out
}

/// The ETFE on the multisine's lines (bins above them hold only the
/// drive's quantisation) and the smoothed estimate on `w`, from u (V) to
/// x2 (m) over the periods after the first.
fn estimates(
    rec: &Recording,
    w: &[f64],
) -> Result<(FrequencyEstimate, FrequencyEstimate), Box<dyn std::error::Error>> {
    let skip = (MS_PERIOD / PERIOD).round() as usize;
    let u = rec.channel("u")?;
    let x2 = rec.channel("x2")?;
    let (u, y) = (&u[skip..], &x2[skip..]);
    let mut raw = etfe(u, y, PERIOD)?;
    let top = f64::from(*LINES.end()) / MS_PERIOD * std::f64::consts::TAU * (1.0 + 1e-9);
    let keep = raw.omega.iter().take_while(|w| **w <= top).count();
    raw.omega.truncate(keep);
    raw.response.truncate(keep);
    let smooth = spa(u, y, PERIOD, Some((SPA_WINDOW / PERIOD) as usize), w)?;
    Ok((raw, smooth))
}

/// Runs the multisine, estimates the response from u (V) to x2 (m), and
/// reports it against the identified model (and the truth, simulated).
pub fn section(
    backend: &Backend,
    ident: &Identification,
    report: &mut Report,
) -> Result<(), Box<dyn std::error::Error>> {
    report.heading(
        2,
        "Frequency response: the identified model against the rig",
    );
    let unit = Multisine::new(1.0, MS_PERIOD, LINES, Phases::Schroeder)?;
    let ms = Multisine::new(
        IDENT_VOLTS / unit.peak(),
        MS_PERIOD,
        LINES,
        Phases::Schroeder,
    )?;
    let duration = MS_PERIOD * PERIODS as f64;
    let rec: Recording = match backend.experiment(
        "frequency_multisine",
        1,
        None,
        OpenLoop,
        |t| vector![ms.value(t)],
        duration,
    )? {
        Ok(out) => out.recording,
        Err(e) => {
            report.add(&format!("The multisine run halted: {}\n", e.error));
            return Ok(());
        }
    };
    // Whole periods after the first: the estimate is then exact for a
    // linear rig, so what differs from the model is the rig's own doing.
    let w = logspace(
        (0.2f64 * std::f64::consts::TAU).log10(),
        (15.0f64 * std::f64::consts::TAU).log10(),
        400,
    )?;
    let (measured, smoothed) = estimates(&rec, &w)?;
    // The identified model with its Coulomb friction, driven by the same
    // multisine through the same drive (delay, quantisation), noise-free.
    let coulomb = ident.coulomb();
    let rig = backend.sim().cloned().unwrap_or_default();
    let model_rig = SimulatedRig {
        truth: ident.model,
        period: PERIOD,
        friction: Friction::coulomb(coulomb),
        card: CardSettings {
            encoder_noise: 0.0,
            ..rig.card
        },
        ..rig
    };
    let simulated = run_sampled(
        model_rig.plant(),
        model_rig.sensor(),
        OpenLoop,
        |t| vector![ms.value(t)],
        SVector::zeros(),
        &model_rig.sampled_config(duration),
    )?;
    let (_, simulated_smooth) = estimates(&simulated, &w)?;
    let model = ident.model;
    let model_bode = bode(&model.state_space(Cart::Two)?, &w)?;
    let truth = backend.truth();

    let model_modes = modes_hz(&model)?;
    let measured_peaks = peaks_hz(&smoothed, 2);
    let simulated_peaks = peaks_hz(&simulated_smooth, 2);
    let truth_modes = truth.map(|t| modes_hz(&t)).transpose()?;
    let mut rows = Vec::new();
    for (i, name) in ["first (carts in phase)", "second (carts in opposition)"]
        .iter()
        .enumerate()
    {
        let cell = |v: Option<&f64>| v.map_or("–".to_string(), |v| format!("{v:.2}"));
        let mut row = vec![
            name.to_string(),
            cell(model_modes.get(i)),
            cell(simulated_peaks.get(i)),
            cell(measured_peaks.get(i)),
        ];
        if let Some(t) = &truth_modes {
            row.push(cell(t.get(i)));
        }
        rows.push(row);
    }
    let mut header = vec![
        "mode",
        "identified linear model ωn (Hz)",
        "gain peak, identified model with friction, simulated (Hz)",
        "gain peak, measured (Hz)",
    ];
    if truth_modes.is_some() {
        header.push("truth ωn (Hz)");
    }
    report.add(&format!(
        "A multisine of {} lines from 0.2 to 15 Hz (Schroeder phases, {IDENT_VOLTS} V peak), {PERIODS} periods of {MS_PERIOD} s (recording `runs/frequency_multisine.csv`). The response from the drive voltage to cart 2's position is estimated over the last {} periods, where the input is periodic and the transient has died out: the empirical transfer-function estimate (`ident::etfe`, one point per line) and its Blackman–Tukey smoothing (`ident::spa`, {SPA_WINDOW} s Hann lag window), whose peaks locate the modes. The identified model is the separate-springs average of the identification runs: its linear part's Bode plot (`freq::bode`), and the model with its Coulomb friction simulated on the same input through the same drive (`sim::run_sampled`) and estimated the same way.\n",
        ms.harmonics().len(),
        PERIODS - 1
    ));
    report.table(&header, &rows);
    // Median relative distance between two magnitude curves on `w`.
    let median_gap = |a: &[f64], b: &[f64]| {
        let mut rel: Vec<f64> = a.iter().zip(b).map(|(a, b)| (a / b - 1.0).abs()).collect();
        rel.sort_by(f64::total_cmp);
        rel.get(rel.len() / 2).copied().unwrap_or(f64::NAN)
    };
    let measured_mag = smoothed.magnitude();
    report.add(&format!(
        "Median distance of the measured (smoothed) magnitude from the linear model's: {:.1} %; from the identified model with friction, simulated: {:.1} %. At this drive level Coulomb friction is a large part of the force: it damps the first mode and lowers its peak frequency (the carts stick for part of each cycle), which the linear model cannot show and the model with friction does. The first mode's peak is where a design with the linear model is least to be trusted.\n",
        median_gap(&measured_mag, &model_bode.magnitude) * 100.0,
        median_gap(&measured_mag, &simulated_smooth.magnitude()) * 100.0,
    ));
    #[cfg(feature = "plot")]
    {
        use ctrlab::freq::Bode;
        let measured_bode = Bode::from_response(&measured.omega, &measured.response)?;
        let smoothed_bode = Bode::from_response(&smoothed.omega, &smoothed.response)?;
        let simulated_bode =
            Bode::from_response(&simulated_smooth.omega, &simulated_smooth.response)?;
        let mut curves: Vec<(&str, &Bode)> = vec![
            ("identified model, linear part", &model_bode),
            (
                "identified model with friction, simulated (spa)",
                &simulated_bode,
            ),
            ("measured (ETFE)", &measured_bode),
            ("measured, smoothed (spa)", &smoothed_bode),
        ];
        let truth_bode = truth
            .map(|t| bode(&t.state_space(Cart::Two)?, &w))
            .transpose()?;
        if let Some(t) = &truth_bode {
            curves.push(("truth's linear part (simulated rig)", t));
        }
        report.bode(
            "bode.svg",
            "u (V) to cart 2 position (m): identified model and measured response",
            &curves,
        )?;
    }
    #[cfg(not(feature = "plot"))]
    {
        let _ = &measured;
        report.add("(figure `bode.svg` needs the `plot` feature, on by default)\n");
    }
    Ok(())
}
