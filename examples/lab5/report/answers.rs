//! The answers on the gains: what each entry of Kf does over every row of
//! Tables 5 and 6, the rows the identified model got wrong, and the
//! steady-state error on its own.

use ctrlab::lab::MassSpring;
use ctrlab::lab::protocol::{PERIOD, STEP_DURATION};
use ctrlab::lab::tables::{
    ERROR_NOISE, Gain, GroupEffect, Halt, Noise, OVERSHOOT_NOISE, Prediction, RigOutcome, RigRun,
    SETTLING_NOISE, Table2, Trend, kf_display, linear_step,
};
use ctrlab::{Recording, StepInfo};

use super::Report;
use super::tables::{outcome, verdict};
use crate::identification::Identification;
use crate::rig_tables::RigTable;

impl Report {
    /// Question 2: the effect of each entry of Kf, from Table 2 and every
    /// row of the rig tables' groups; then the rows the model got wrong.
    pub fn effects(&mut self, ident: &Identification, table2: &Table2, rig: &[RigTable]) {
        self.heading(3, "2. The effect of each entry of Kf");
        let mut lines = Vec::new();
        let step = |kf: [f64; 4]| table2.row(kf).and_then(|r| r.step.as_ref());
        if let (Some(a), Some(b), Some(c)) = (
            step([0.0, 0.0, 0.1, 0.0]),
            step([0.0, 0.0, 10.0, 0.0]),
            step([0.0, 0.0, 10.0, 0.1]),
        ) {
            lines.push(format!(
                "- In simulation (Table 2, linear, no drive limit) Kf3 = 0.1 → 10 cuts the steady-state error from {:.2} to {:.2} mm while overshoot goes from {:.1} to {:.1} %; adding Kf4 = 0.1 brings the overshoot to {:.1} %.",
                a.info.steady_state_error.unwrap_or(f64::NAN),
                b.info.steady_state_error.unwrap_or(f64::NAN),
                a.info.overshoot,
                b.info.overshoot,
                c.info.overshoot,
            ));
        }
        let n = |noise: Noise, unit: &str| {
            format!(
                "{:.0} % of the larger value, at least {} {unit}",
                noise.relative * 100.0,
                noise.floor
            )
        };
        lines.push(format!(
            "- On the rig each trend below reads every settled row; a change counts only when it exceeds what two runs of one row differ by (measured over ten runs of each row on the simulated rig): overshoot {}, settling time {}, steady-state error {}. \"At ±V\" is how long the drive sat at its limit.",
            n(OVERSHOOT_NOISE, "points"),
            n(SETTLING_NOISE, "s"),
            n(ERROR_NOISE, "mm"),
        ));
        let model = ident.model();
        for t in rig {
            let outcomes = t.outcomes();
            for (group, range) in t.table.group_ranges() {
                let held: String = group
                    .held()
                    .iter()
                    .map(|(g, v)| format!(" with {g} = {v}"))
                    .collect();
                let context = format!("{}{held}, Table {}", group.varied.acts_on(), t.table.number);
                let from = range.start.min(t.runs.len());
                let to = range.end.min(t.runs.len());
                let (runs, outcomes) = (&t.runs[from..to], &outcomes[from..to]);
                let effect = GroupEffect::of(group, outcomes);
                lines.push(effect_lines(&context, &effect, (runs, outcomes), t, &model));
            }
        }
        let all: Vec<_> = rig
            .iter()
            .flat_map(|t| t.runs.iter().map(|(r, _)| r))
            .collect();
        let agree = all.iter().filter(|r| r.prediction_agrees()).count();
        let gain = ident.model().gain;
        let full = rig.first().map_or(f64::NAN, |t| t.volts_full_scale);
        lines.push(format!(
            "- The gains are volts per millimetre, so on a rig with K = {gain:.2} N/V they act {gain:.1} times harder than on the nominal force-input model of Table 2, and they saturate the {full} V drive; the loop that matters is the sampled one (a velocity gain makes the 2 ms loop unstable once K·Kf4·1000·T/m2 passes about 2). The identified model sampled at 2 ms predicts stable/unstable correctly for {agree} of the {} rig runs (stable ↔ metrics measured); the others are below.",
            all.len()
        ));
        self.add(&format!("{}\n", lines.join("\n")));
        self.mispredicted(ident, rig);
        self.steady_state_errors(ident, rig);
    }

    /// The rows where the identified model's verdict and the rig disagree,
    /// each with what the linear model leaves out.
    fn mispredicted(&mut self, ident: &Identification, rig: &[RigTable]) {
        let [f1, f2] = ident.coulomb();
        let mut lines = Vec::new();
        for t in rig {
            for (run, rec) in &t.runs {
                if run.prediction_agrees() {
                    continue;
                }
                let p = &run.prediction;
                let row = format!("Table {}, Kf = {}", t.table.number, kf_display(&run.kf));
                if !p.is_stable() {
                    let growth = match p.per_cycle() {
                        Some(g) => format!(
                            "Its growing mode, at {:.1} Hz, gains {:.1} % of its amplitude per cycle",
                            p.dominant_frequency(PERIOD) / std::f64::consts::TAU,
                            (g - 1.0) * 100.0
                        ),
                        None => "Its growing mode is real (no oscillation)".into(),
                    };
                    lines.push(format!(
                        "- **{row}**: the model predicts it {} yet it settled on the rig. {growth}. The linear model has no friction: Coulomb friction ({f1:.2} N on cart 1, {f2:.2} N on cart 2) takes a fixed amount of energy from every cycle, more than a mode this close to ρ = 1 gains while its amplitude is small, so the oscillation dies out instead of growing.",
                        verdict(p)
                    ));
                } else {
                    let u0 = rec
                        .channel("u")
                        .ok()
                        .and_then(|u| u.first().copied())
                        .unwrap_or(f64::NAN);
                    let why = match &run.outcome {
                        RigOutcome::TooSlow { y_end_mm } if y_end_mm.abs() < 0.1 => format!(
                            "it never left the start (at {y_end_mm:.2} mm after {STEP_DURATION} s): its first command, {u0:.2} V, pushes with {:.2} N against Coulomb friction of {:.2} N on the two carts (more to break away), which the linear model does not have",
                            u0.abs() * ident.model().gain,
                            f1 + f2
                        ),
                        RigOutcome::TooSlow { y_end_mm } => format!(
                            "it was still creeping toward the setpoint at {y_end_mm:.2} mm when the {STEP_DURATION} s run ended: near rest the drive's push, proportional to the error, meets Coulomb friction ({:.2} N on the two carts) that the linear model does not have",
                            f1 + f2
                        ),
                        other => format!("it ended {}", outcome(other, t.volts_full_scale)),
                    };
                    lines.push(format!(
                        "- **{row}**: the model predicts it {} but it did not settle: {why}.",
                        verdict(p)
                    ));
                }
            }
        }
        if !lines.is_empty() {
            self.add(&format!(
                "Where the identified model's verdict and the rig disagree:\n\n{}\n",
                lines.join("\n")
            ));
        }
    }

    /// Question 3: the steady-state error on its own, row by row against
    /// the linear model and the friction band around it.
    fn steady_state_errors(&mut self, ident: &Identification, rig: &[RigTable]) {
        self.heading(3, "3. The steady-state error");
        let coulomb = ident.coulomb();
        let mut rows = Vec::new();
        let (mut inside, mut settled) = (0, 0);
        for t in rig {
            for (run, _) in &t.runs {
                let Some(info) = run.outcome.step() else {
                    continue;
                };
                let p = &run.prediction;
                let predicted = p.steady_state_error_mm(t.table.setpoint_mm);
                let band = p.friction_band_mm(coulomb);
                let measured = info.steady_state_error.unwrap_or(f64::NAN);
                let within = (measured - predicted).abs() <= band;
                settled += 1;
                inside += usize::from(within);
                rows.push(vec![
                    t.table.number.to_string(),
                    kf_display(&run.kf).to_string(),
                    format!("{predicted:.2}"),
                    format!("{band:.2}"),
                    format!("{measured:.2}"),
                    if within { "yes" } else { "no" }.into(),
                ]);
            }
        }
        self.add(&format!(
            "The law u = Kf (G r − x) is proportional with no integral action: at rest the springs' force must be held by the drive, and the drive only pushes while there is an error, so the linear model rests at e_ss = r (1 − closed-loop DC gain). Only the position gains (Kf1, Kf3) enter the DC gain: raising them shrinks the error, the velocity gains (Kf2, Kf4) leave the linear prediction unchanged. On the rig Coulomb friction (identified: {:.2} N on cart 1, {:.2} N on cart 2) can hold the cart anywhere within a band around that rest position, whose half-width is the closed loop's static compliance to each cart's friction times that friction; where in the band a cart stops depends on how it arrives (an overdamped approach stops at the near edge). {inside} of the {settled} settled rows rest within the band:\n",
            coulomb[0], coulomb[1]
        ));
        self.table(
            &[
                "Table",
                "Kf (per mm)",
                "linear model e_ss (mm)",
                "friction band ± (mm)",
                "measured e_ss (mm)",
                "within the band",
            ],
            &rows,
        );
        if inside < settled {
            self.add("Rows outside the band stop farther from the linear rest position than the Coulomb (sliding) friction the band is computed with can hold them: breaking away from rest takes more (stiction), and a small command meets that first.\n");
        }
        self.add("A prefilter (`StateFeedback::with_prefilter`) or an integrator (the Design section's LQI) removes the linear part; only integral action removes the friction's. Cart 1 is moved only through the spring k2 (non-collocated control), which is also why its position loop destabilises far sooner than cart 2's.\n");
    }
}

/// The values of one figure along a group's rows, as the table prints
/// them, `–` where a row did not settle.
fn series(steps: &[Option<StepInfo>], figure: fn(&StepInfo) -> String) -> String {
    steps
        .iter()
        .map(|s| s.as_ref().map_or("–".into(), figure))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A trend in words, its turn named by the gain's value there.
fn trend_text(t: &Trend, unit: &str, name: Gain, settled: &[f64], decimals: usize) -> String {
    let at = |i: &usize| {
        settled
            .get(*i)
            .map_or(String::new(), |v| format!(" at {name} = {v}"))
    };
    let d = decimals;
    match t {
        Trend::Flat { lo, hi } => format!("stays within {lo:.d$}–{hi:.d$} {unit}"),
        Trend::Rises { from, to } => format!("rises from {from:.d$} to {to:.d$} {unit}"),
        Trend::Falls { from, to } => format!("falls from {from:.d$} to {to:.d$} {unit}"),
        Trend::Peaks {
            peak, at: i, to, ..
        } => {
            format!(
                "rises to {peak:.d$} {unit}{}, then falls to {to:.d$} {unit}",
                at(i)
            )
        }
        Trend::Dips { low, at: i, to, .. } => {
            format!(
                "falls to {low:.d$} {unit}{}, then rises to {to:.d$} {unit}",
                at(i)
            )
        }
        Trend::Mixed { lo, hi } => {
            format!("turns more than once, between {lo:.d$} and {hi:.d$} {unit}")
        }
    }
}

/// The drive's time at its limit in a run, s.
fn time_at_limit(rec: &Recording, full_scale: f64) -> f64 {
    let (_, fraction) = ctrlab::lab::tables::drive(rec, full_scale);
    let t = rec.time();
    fraction * (t.last().copied().unwrap_or(0.0) - t.first().copied().unwrap_or(0.0))
}

/// The slowest real closed-loop pole, 1/s, if any.
fn slowest_real(p: &Prediction) -> Option<f64> {
    p.poles
        .iter()
        .filter(|z| z.im.abs() < 1e-9)
        .map(|z| z.re)
        .reduce(f64::max)
}

/// A metric in a group's lines: its label, trend, unit, decimals, how to
/// read it off a step, and its noise.
type Metric = (
    &'static str,
    Option<Trend>,
    &'static str,
    usize,
    fn(&StepInfo) -> f64,
    Noise,
);

/// A group's lines: the series as the table has them, each metric's trend
/// over every row with what explains a turn, and a conclusion.
fn effect_lines(
    context: &str,
    e: &GroupEffect,
    (runs, outcomes): (&[(RigRun, Recording)], &[RigOutcome]),
    t: &RigTable,
    model: &MassSpring,
) -> String {
    let name = e.varied;
    let full = t.volts_full_scale;
    let list = |values: &[f64]| {
        values
            .iter()
            .map(|v| format!("{v}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let limit_ms: Vec<f64> = runs
        .iter()
        .map(|(_, rec)| 1e3 * time_at_limit(rec, full))
        .collect();
    let mut s = format!(
        "- **{name}** ({context}) = {}: POT {} %; settling {} s; steady-state error {} mm; at ±{full} V {} ms.",
        list(&e.values),
        series(&e.steps, |i| format!("{:.2}", i.overshoot)),
        series(&e.steps, |i| format!("{:.3}", i.settling_time)),
        series(&e.steps, |i| format!(
            "{:.2}",
            i.steady_state_error.unwrap_or(f64::NAN)
        )),
        limit_ms
            .iter()
            .map(|v| format!("{v:.0}"))
            .collect::<Vec<_>>()
            .join(", "),
    );
    let settled = e.settled();
    // The settled rows' runs, in the order a trend's index counts.
    let settled_runs: Vec<&(RigRun, Recording)> = runs
        .iter()
        .zip(&e.steps)
        .filter(|(_, st)| st.is_some())
        .map(|(r, _)| r)
        .collect();
    let settled_limit: Vec<f64> = limit_ms
        .iter()
        .zip(&e.steps)
        .filter(|(_, st)| st.is_some())
        .map(|(v, _)| *v)
        .collect();
    // What the identified linear model (no drive limit, no friction) says
    // of a metric over the settled rows from `from` on, where its sampled
    // loop is stable.
    let linear = |from: usize, figure: fn(&StepInfo) -> f64, noise: Noise| {
        let mut points = Vec::new();
        for ((run, _), gain) in settled_runs[from..].iter().zip(&settled[from..]) {
            if run.prediction.is_stable()
                && let Ok(step) = linear_step(model, run.kf, t.table.cart, t.table.setpoint_mm)
            {
                points.push((*gain, figure(&step.info)));
            }
        }
        let values: Vec<f64> = points.iter().map(|(_, v)| *v).collect();
        let rises = matches!(Trend::of(&values, noise), Some(Trend::Rises { .. }));
        (points.len() >= 2).then_some((points, rises))
    };
    let turn_cause = |trend: &Trend,
                      figure: fn(&StepInfo) -> f64,
                      noise: Noise,
                      d: usize,
                      unit: &str|
     -> String {
        let Some(i) = trend.turn() else {
            return String::new();
        };
        let before = settled_limit[..i].iter().copied().fold(0.0, f64::max);
        let after = settled_limit[i..]
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let slow: Vec<Option<f64>> = settled_runs
            .iter()
            .map(|(r, _)| slowest_real(&r.prediction))
            .collect();
        if after > before + 2.0 {
            let mut s = format!(
                " The turn is the drive's limit: from {name} = {} on, the step asks more than ±{full} V and the drive sits there ({:.0}–{:.0} ms against at most {before:.0} ms before), so a higher gain no longer pushes harder.",
                settled[i],
                after,
                settled_limit[i..].iter().copied().fold(0.0, f64::max)
            );
            let from = i.saturating_sub(1);
            if let Some((points, rises)) = linear(from, figure, noise) {
                let join = |f: &dyn Fn(&(f64, f64)) -> String| {
                    points.iter().map(f).collect::<Vec<_>>().join(", ")
                };
                s += &format!(
                    " The identified linear model, with no limit and no friction, gives {} {unit} at {name} = {}{} (where its sampled loop is stable).",
                    join(&|(_, v)| format!("{v:.d$}")),
                    join(&|(g, _)| g.to_string()),
                    if rises { ": still rising" } else { "" }
                );
            }
            s
        } else if let (Some(Some(a)), Some(Some(b))) = (slow.get(i), slow.last())
            && b > a
        {
            format!(
                " Past {name} = {} the response is overdamped: the closed loop's slowest pole is real and moves toward 0 ({a:.2} → {b:.2} 1/s), so the cart creeps in, and friction stops a creeping cart early.",
                settled[i]
            )
        } else {
            String::new()
        }
    };
    let metrics: [Metric; 3] = [
        ("POT", e.overshoot, "%", 2, |i| i.overshoot, OVERSHOOT_NOISE),
        (
            "settling time",
            e.settling_time,
            "s",
            3,
            |i| i.settling_time,
            SETTLING_NOISE,
        ),
        (
            "steady-state error",
            e.steady_state_error,
            "mm",
            2,
            |i| i.steady_state_error.unwrap_or(f64::NAN),
            ERROR_NOISE,
        ),
    ];
    for (label, trend, unit, d, figure, noise) in metrics {
        if let Some(trend) = trend {
            s += &format!(
                "\n  - {label}: {}.{}",
                trend_text(&trend, unit, name, &settled, d),
                turn_cause(&trend, figure, noise, d, unit)
            );
        }
    }
    if !e.not_settled.is_empty() {
        s += &format!(
            "\n  - Not settled at {name} = {} (see the outcome column).",
            list(&e.not_settled)
        );
    }
    s += &format!("\n  - **In short**: {}", conclusion(e, outcomes));
    s
}

/// What a group says about its gain, in one sentence.
fn conclusion(e: &GroupEffect, outcomes: &[RigOutcome]) -> String {
    let name = e.varied;
    let mut parts = Vec::new();
    match e.steady_state_error {
        Some(Trend::Falls { .. }) => {
            parts.push("raising it shrinks the steady-state error".to_string())
        }
        Some(Trend::Rises { .. }) => {
            parts.push("raising it leaves a larger steady-state error".into())
        }
        Some(Trend::Flat { .. }) => {
            parts.push("it leaves the steady-state error where it is".into())
        }
        Some(_) => parts.push("the steady-state error follows no single direction".into()),
        None => {}
    }
    match e.overshoot {
        Some(Trend::Falls { .. }) => parts.push("it damps the response (less overshoot)".into()),
        Some(Trend::Rises { .. }) => parts.push("it costs damping (more overshoot)".into()),
        Some(Trend::Peaks { .. }) => {
            parts.push("it costs damping until the drive's limit caps the overshoot".into())
        }
        Some(Trend::Dips { .. }) => {
            parts.push("it damps the response up to a point, past which overshoot returns".into())
        }
        Some(Trend::Flat { .. }) => {
            parts.push("it does not change the overshoot beyond what two runs differ by".into())
        }
        Some(Trend::Mixed { .. }) => parts.push("the overshoot follows no single direction".into()),
        None => {}
    }
    match e.settling_time {
        Some(Trend::Rises { .. }) => parts.push("it slows the settling".into()),
        Some(Trend::Falls { .. }) => parts.push("it speeds the settling".into()),
        Some(Trend::Dips { .. }) => {
            parts.push("it speeds the settling up to a point and slows it past there".into())
        }
        Some(Trend::Peaks { .. }) => {
            parts.push("it slows the settling up to a point and speeds it past there".into())
        }
        _ => {}
    }
    let settled = e.settled();
    // The rows that did not settle, by where they lie against the settled
    // ones, each with how it ended.
    let unsettled: Vec<(f64, &RigOutcome)> = e
        .values
        .iter()
        .zip(outcomes)
        .filter(|(_, o)| !o.is_settled())
        .map(|(v, o)| (*v, o))
        .collect();
    let how = |o: &RigOutcome| match o {
        RigOutcome::TooSlow { .. } => "too slow",
        RigOutcome::Oscillating { .. } => "oscillating",
        RigOutcome::Diverged {
            why: Halt::TravelLimit { .. },
            ..
        } => "diverged",
        RigOutcome::Diverged {
            why: Halt::Fault(_),
            ..
        } => "halted by a fault",
        RigOutcome::Diverged { .. } | RigOutcome::Settled(_) => "without metrics",
    };
    let describe = |rows: &[&(f64, &RigOutcome)]| {
        rows.iter()
            .map(|(v, o)| format!("{name} = {v}: {}", how(o)))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if settled.is_empty() && !unsettled.is_empty() {
        parts.push(format!(
            "no row settles with the gains it is held at ({})",
            describe(&unsettled.iter().collect::<Vec<_>>())
        ));
    } else {
        let lo = settled.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = settled.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let below: Vec<_> = unsettled.iter().filter(|(v, _)| *v < lo).collect();
        let above: Vec<_> = unsettled.iter().filter(|(v, _)| *v > hi).collect();
        let inside: Vec<_> = unsettled
            .iter()
            .filter(|(v, _)| (lo..=hi).contains(v))
            .collect();
        if !below.is_empty() {
            let cart_stays = below
                .iter()
                .all(|(_, o)| matches!(o, RigOutcome::TooSlow { .. }));
            parts.push(format!(
                "too little of it {} ({})",
                if cart_stays {
                    "does not move the cart against friction"
                } else {
                    "does not settle the loop"
                },
                describe(&below)
            ));
        }
        if !above.is_empty() {
            parts.push(format!(
                "too much of it loses the loop ({})",
                describe(&above)
            ));
        }
        if !inside.is_empty() {
            parts.push(format!(
                "between settled rows some do not settle ({})",
                describe(&inside)
            ));
        }
    }
    if parts.is_empty() {
        return format!("{name}: too few settled rows to say.");
    }
    let mut s = format!("{name}: {}", parts.join("; "));
    if matches!(e.overshoot, Some(Trend::Flat { .. }))
        && matches!(e.steady_state_error, Some(Trend::Flat { .. }) | None)
        && matches!(e.settling_time, Some(Trend::Flat { .. }) | None)
    {
        s = format!(
            "{name} at {}–{} changes nothing measurable: every metric stays within what two runs of one row differ by; at these values it is too small to act",
            e.values.first().copied().unwrap_or(f64::NAN),
            e.values.last().copied().unwrap_or(f64::NAN)
        );
    }
    s + "."
}
