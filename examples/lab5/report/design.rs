//! The Design section: the spec, the design and prediction, each case's
//! weights, prediction against rig in a table and a figure, and where they
//! differ, with the likely reasons, all from the section's results.

use ctrlab::lab::lqi::{
    CART1_ALTERNATIVE, CASES, Choice, DRIVE_DELAY, DURATION, Design, Hold, INPUT_NOISE,
    INTEGRAL_RATIO, Item, KnownDifferences, Metrics, REST_TAIL, Rest, RestKind, Spec, Step,
    rho_grid,
};
use ctrlab::lab::protocol::PERIOD;
use ctrlab::lab::{Cart, position_channel};

use super::{ComparePanel, Report, curve, pct};
use crate::backend::Backend;
use crate::design::{Case, DesignSection};

impl Report {
    /// The whole Design section.
    pub fn design(
        &mut self,
        backend: &Backend,
        d: &DesignSection,
    ) -> Result<(), Box<dyn std::error::Error>> {
        self.heading(2, "Design: predict, then run");
        let count = d.rig.metres_per_count();
        let supply = d.rig.calibration.volts_full_scale;
        let spec = d
            .cases
            .first()
            .map_or(Spec::new(Cart::Two, 0.0, supply), |c| c.design.spec);
        self.add(&format!(
            "**Spec**: from rest to the setpoint, overshoot ≤ {} %, 2 % settling time ≤ {} s, |steady-state error| ≤ {} encoder count ({:.2} µm; y∞ is the mean of the last 5 % of the {DURATION} s run), and |u| ≤ {} V with the drive never at its limit (a design that asks for more than the drive has is clipped, not in spec).\n",
            spec.overshoot,
            spec.settling,
            spec.error_counts,
            count * 1e6,
            spec.volts
        ));
        self.add(&format!(
            "**Design**, on the model identified above (the separate-springs averages, sampled at {} ms, ZOH): discrete LQI (`dlqi`) integrating the tracked cart's measured position, Q = ρ on that position (1/m²) and {INTEGRAL_RATIO:.0} ρ on its integrated error (1/(m·s)²), nothing on the other states, R = 1 /V²; a steady-state Kalman filter (`dlqe`, current form) on both positions, input noise {} V², each position read to a count (RN = count²/12); back-calculation anti-windup. Of the rig's four measurements it uses the two positions. ρ is searched over {} weights from {:.0e} to {:.0e}, evenly on a log scale; each candidate's step is predicted, and the choice is the largest margin (the smallest of the items' relative margins, 1 − figure / limit) among the weights whose prediction meets the spec and whose neighbours' predictions do too (friction makes the response jump with the weight, so a lone pass may be luck). **Prediction**: `run_sampled` with the identified plant and Coulomb friction ({:.2} N and {:.2} N, breakaway taken equal: stiction is not identified), the drive's ±{} V in {:.0} mV steps and its data-sheet {} ms delay, encoder counts without noise. **Rig**: the same controller through `hw::run`, as Tables 5 and 6. Recordings: `runs/design_cart{{1,2}}_{{predicted,rig}}.csv`.\n",
            PERIOD * 1e3,
            INPUT_NOISE,
            rho_grid().count(),
            rho_grid().next().unwrap_or(f64::NAN),
            rho_grid().last().unwrap_or(f64::NAN),
            d.coulomb[0],
            d.coulomb[1],
            supply,
            d.rig.sampled_config(DURATION).input_quantisation[0] * 1e3,
            DRIVE_DELAY * 1e3
        ));
        self.add(&setpoint_reason(d));
        for c in &d.cases {
            self.add(&weights_text(&c.design));
        }
        self.design_table(&d.cases, count);
        let panels = d
            .cases
            .iter()
            .map(|c| {
                let cart = c.design.spec.cart;
                let channel = position_channel(cart);
                Ok(ComparePanel {
                    title: format!(
                        "cart {} to {:.0} mm (ρ = {:.2e})",
                        cart.number(),
                        c.design.spec.setpoint * 1e3,
                        c.design.rho
                    ),
                    setpoint_mm: c.design.spec.setpoint * 1e3,
                    runs: vec![
                        curve("predicted".into(), &c.design.predicted, channel)?,
                        curve("rig".into(), &c.rig, channel)?,
                    ],
                })
            })
            .collect::<Result<Vec<_>, ctrlab::Error>>()?;
        self.compare(
            "design.svg",
            "Design: predicted and measured position, at rest in encoder counts, and voltage",
            (supply, count * 1e3),
            &panels,
        )?;
        self.differences(backend, d);
        Ok(())
    }

    /// The metrics table: one row per figure, predicted and rig per cart.
    fn design_table(&mut self, cases: &[Case], count: f64) {
        self.heading(3, "Predicted against measured");
        let Some(spec) = cases.first().map(|c| c.design.spec) else {
            return;
        };
        let mut header = vec!["".to_string(), "spec".to_string()];
        let mut runs: Vec<(&Metrics, &Spec)> = Vec::new();
        for c in cases {
            let n = c.design.spec.cart.number();
            let mm = c.design.spec.setpoint * 1e3;
            header.push(format!("cart {n} to {mm:.0} mm, predicted"));
            header.push(format!("cart {n} to {mm:.0} mm, rig"));
            runs.push((&c.design.metrics, &c.design.spec));
            runs.push((&c.measured, &c.design.spec));
        }
        type Figure = fn(&Step) -> String;
        let rows: [(&str, String, Figure, Option<Item>); 5] = [
            (
                "rise time 10–90 % (s)",
                "–".into(),
                |s| format!("{:.3}", s.rise),
                None,
            ),
            (
                "overshoot (%)",
                format!("≤ {}", spec.overshoot),
                |s| format!("{:.2}", s.overshoot),
                Some(Item::Overshoot),
            ),
            (
                "settling time 2 % (s)",
                format!("≤ {}", spec.settling),
                |s| format!("{:.3}", s.settling),
                Some(Item::Settling),
            ),
            (
                "steady-state error (counts)",
                format!("≤ {}", spec.error_counts),
                |s| format!("{:+.2}", s.error_counts),
                Some(Item::Error),
            ),
            (
                "steady-state error (mm)",
                format!("≤ {:.4}", spec.error_counts * count * 1e3),
                |s| format!("{:+.4}", s.error_mm),
                Some(Item::Error),
            ),
        ];
        let mut body = Vec::new();
        for (name, limit, figure, item) in rows {
            let mut row = vec![name.to_string(), limit];
            for (m, spec) in &runs {
                row.push(match (&m.step, item) {
                    (Ok(s), Some(i)) => judged(figure(s), m.verdict(spec).met(i)),
                    (Ok(s), None) => figure(s),
                    (Err(e), _) => format!("– ({})", no_figures(e)),
                });
            }
            body.push(row);
        }
        let mut volts = vec![
            "peak voltage (V)".to_string(),
            format!("≤ {}, never at the limit", spec.volts),
        ];
        for (m, spec) in &runs {
            let clipped = if m.clipped > 0 {
                format!(", {} samples at the limit", m.clipped)
            } else {
                String::new()
            };
            volts.push(judged(
                format!("{:.2}{clipped}", m.peak_u),
                m.verdict(spec).volts,
            ));
        }
        body.push(volts);
        self.table(&header, &body);
        for c in cases {
            if let Some(why) = &c.halted {
                self.add(&format!(
                    "Cart {}'s rig run ended early: {why}.\n",
                    c.design.spec.cart.number(),
                ));
            }
        }
    }

    /// Sentences on where prediction and rig differ, and the likely
    /// reasons.
    fn differences(&mut self, backend: &Backend, d: &DesignSection) {
        self.heading(3, "Where prediction and rig differ");
        let mut lines = Vec::new();
        for c in &d.cases {
            let spec = &c.design.spec;
            let (p, m) = (&c.design.metrics, &c.measured);
            let mut s = format!(
                "- **Cart {} to {:.0} mm.** The prediction {}; the rig {}.",
                spec.cart.number(),
                spec.setpoint * 1e3,
                failing(&p.verdict(spec).failing()),
                failing(&m.verdict(spec).failing()),
            );
            match (&p.step, &m.step, c.comparison.transient) {
                (Ok(ps), Ok(ms), Some(same)) => {
                    let figures = format!(
                        "rise {:.3} against {:.3} s, overshoot {:.2} against {:.2} %, settling {:.3} against {:.3} s",
                        ps.rise, ms.rise, ps.overshoot, ms.overshoot, ps.settling, ms.settling
                    );
                    if same.agrees() {
                        s += &format!(" The transient agrees (predicted against rig): {figures}.");
                    } else {
                        s += &format!(" The transient differs (predicted against rig): {figures}.");
                        if !same.settling && same.rise {
                            s += " With the rise alike, the settling time differs where the cart comes to rest: it is the time of a late slip (the 2 % band is around where the cart finally rests).";
                        }
                        s += &format!(" Likely reasons: {}.", transient_reasons(d.known.as_ref()));
                    }
                }
                (Ok(_), Err(e), _) => {
                    s += &format!(" The rig's step has no figures ({}).", no_figures(e));
                }
                (Err(e), _, _) => {
                    s += &format!(" The prediction has no figures ({}).", no_figures(e));
                }
                (Ok(_), Ok(_), None) => {}
            }
            if let Some((pr, mr)) = c.comparison.rest {
                // A step without figures (not settled: a cart hunting on
                // a jittered clock) has no steady-state error to print.
                let errors = match (&p.step, &m.step) {
                    (Ok(ps), Ok(ms)) => {
                        format!(
                            "{:+.2} against {:+.2} counts",
                            ps.error_counts, ms.error_counts
                        )
                    }
                    (Ok(ps), Err(_)) => format!("{:+.2} counts against none", ps.error_counts),
                    (Err(_), Ok(ms)) => format!("none against {:+.2} counts", ms.error_counts),
                    (Err(_), Err(_)) => "none on either".to_owned(),
                };
                let at_rest = format!(
                    "over the last {REST_TAIL} s the predicted cart {}, the rig's {} (steady-state error {errors})",
                    rests(&pr),
                    rests(&mr)
                );
                if c.comparison.rest_agrees {
                    s += &format!(" At rest they agree: {at_rest}.");
                } else {
                    let w = &c.walk;
                    // The band the integrator must cross: cart 2's own
                    // breakaway, or both carts' for cart 1.
                    let band = match spec.cart {
                        Cart::Two => "2 F_s2 / K",
                        Cart::One => "2 (F_s1 + F_s2) / K",
                    };
                    let reason = friction_reason(backend, d.coulomb, spec.cart);
                    if !w.error_counts.is_finite() {
                        // No steady-state error (the rig's step has no
                        // figures): no rate for the integrator to walk at.
                        s += &format!(" At rest they differ: {at_rest}. Likely reason: {reason}.");
                    } else {
                        s += &format!(
                            " At rest they differ: {at_rest}. Likely reason: {}. A stuck cart is held anywhere within ± its breakaway force, and the integrator (|K_z| = {:.3e} V/(m·s)) moves the drive by {:.2} V/s under a {:.1}-count error, where crossing that band can take {band} = {:.1} V: up to {:.1} s, {} the {:.1} s the run has after settling.",
                            reason,
                            w.kz,
                            w.rate,
                            w.error_counts,
                            w.band,
                            w.time,
                            if w.exceeds_run() {
                                "longer than"
                            } else {
                                "within"
                            },
                            w.left,
                        );
                    }
                }
            }
            if !c.comparison.voltage_agrees {
                s += &format!(
                    " The peak voltage differs: {:.2} V predicted, {:.2} V on the rig ({} and {} samples at the limit); likely reasons: {}.",
                    p.peak_u,
                    m.peak_u,
                    p.clipped,
                    m.clipped,
                    transient_reasons(d.known.as_ref())
                );
            }
            lines.push(s);
        }
        self.add(&format!("{}\n", lines.join("\n")));
    }
}

/// Why cart 1 goes to 15 mm: what holding it takes of the drive and of
/// cart 2's travel, against the larger alternative, on the identified
/// model.
fn setpoint_reason(d: &DesignSection) -> String {
    let (supply, travel) = (
        d.rig.calibration.volts_full_scale,
        d.rig.calibration.travel_limits[1],
    );
    let model = &d.model;
    let friction = (d.coulomb[0] + d.coulomb[1]) / model.gain;
    let (chosen, alternative) = (CASES[1].1, CART1_ALTERNATIVE);
    let (h, ha) = (Hold::of(model, chosen), Hold::of(model, alternative));
    format!(
        "**Cart 1's setpoint**, {:.0} mm: Table 6's, so the two compare. On the identified model, holding cart 1 there takes k1 r / K = {:.1} V of the drive's {supply:.0} V, plus up to (F1 + F2) / K = {friction:.1} V against friction, leaving {:.1} V for the transient, with cart 2 at {:.1} mm of its ±{:.0} mm travel. {:.0} mm would take {:.1} V, leaving {:.1} V, with cart 2 at {:.1} mm, {:.1} mm from its travel limit: cart 1 is moved only through the spring k2, and its step needs the headroom.\n",
        chosen * 1e3,
        h.volts,
        supply - h.volts - friction,
        h.x2 * 1e3,
        travel * 1e3,
        alternative * 1e3,
        ha.volts,
        supply - ha.volts - friction,
        ha.x2 * 1e3,
        (travel - ha.x2) * 1e3,
    )
}

/// The chosen weight, the gains and poles, and what the search found.
fn weights_text(d: &Design) -> String {
    let passing: Vec<String> = d.passing().iter().map(|rho| format!("{rho:.2e}")).collect();
    let k = &d.lqi.gain;
    let slowest = d.lqi.poles.iter().map(|z| z.norm()).fold(0.0, f64::max);
    let choice = match d.choice {
        Choice::Robust => "its prediction and both neighbours' meet the spec",
        Choice::Isolated => {
            "its prediction meets the spec, but no weight's does together with both neighbours'"
        }
        Choice::NoneMeets => "no weight's prediction meets the spec; this one has the best margin",
    };
    let i = d.spec.cart.state_index();
    format!(
        "**Cart {} to {:.0} mm**: ρ = {:.3e}, so Q = {:.3e} on x{} and {:.3e} on z (zero elsewhere), R = 1; {choice} (margin {:.0} %). Gain [K_x K_z] = [{:.1} V/m, {:.2} V·s/m, {:.1} V/m, {:.2} V·s/m, {:.4e} V/(m·s)] on [x1, v1, x2, v2, z]; closed-loop poles on the model within |z| ≤ {slowest:.4} (slowest time constant {:.0} ms). Of the {} weights searched, the prediction meets the spec at ρ = {}.\n",
        d.spec.cart.number(),
        d.spec.setpoint * 1e3,
        d.rho,
        d.q[(i, i)],
        d.spec.cart.number(),
        d.q[(4, 4)],
        d.metrics.margin(&d.spec).max(-9.99) * 100.0,
        k[0],
        k[1],
        k[2],
        k[3],
        k[4],
        -PERIOD / slowest.ln() * 1e3,
        d.candidates.len(),
        if passing.is_empty() {
            "none".to_string()
        } else {
            passing.join(", ")
        },
    )
}

/// A value with its verdict: `12.3 ✓` or `**12.3 ✗**`.
fn judged(value: String, pass: bool) -> String {
    if pass {
        format!("{value} ✓")
    } else {
        format!("**{value} ✗**")
    }
}

/// Why a step has no figures, in words.
fn no_figures(e: &ctrlab::Error) -> String {
    match e {
        ctrlab::Error::NotSettled { .. } => "not settled".into(),
        other => other.to_string(),
    }
}

/// The items of a verdict that fail, in words.
fn failing(items: &[Item]) -> String {
    let names: Vec<&str> = items
        .iter()
        .map(|i| match i {
            Item::Overshoot => "overshoot",
            Item::Settling => "settling time",
            Item::Error => "steady-state error",
            Item::Voltage => "voltage",
        })
        .collect();
    match names.split_last() {
        None => "meets every item".into(),
        Some((last, [])) => format!("fails on {last}"),
        Some((last, rest)) => format!("fails on {} and {last}", rest.join(", ")),
    }
}

/// A reading `c` counts from the setpoint, in words.
fn counts_off(c: f64) -> String {
    match c {
        0.0 => "on the setpoint's count".into(),
        c if c < 0.0 => format!("{:.0} short", -c),
        c => format!("{c:.0} past"),
    }
}

/// How a cart rests, in words.
fn rests(r: &Rest) -> String {
    match r.kind() {
        RestKind::Still => format!("rests, reading {}", counts_off(r.lo)),
        RestKind::Jitter => format!("rests, reading {} … {}", counts_off(r.lo), counts_off(r.hi)),
        RestKind::Hunting => format!(
            "hunts, sticking and slipping between {} and {}",
            counts_off(r.lo),
            counts_off(r.hi)
        ),
    }
}

/// What the prediction leaves out of the rig, from the numbers where the
/// rig is simulated.
fn friction_reason(backend: &Backend, coulomb: [f64; 2], cart: Cart) -> String {
    let i = cart.number() - 1;
    match backend.sim() {
        Some(sim) => {
            let breakaway = sim.friction.stiction[i].max(sim.friction.coulomb[i]);
            format!(
                "the prediction's cart {} breaks away at the identified Coulomb force, {:.2} N; the card's at {:.2} N ({} over its {:.2} N Coulomb force), a stiction the identification cannot see (it uses only rows where the carts move), and the card adds σ = {} count of encoder noise the prediction has none of",
                cart.number(),
                coulomb[i],
                breakaway,
                pct(breakaway, sim.friction.coulomb[i]),
                sim.friction.coulomb[i],
                sim.card.encoder_noise
            )
        }
        None => format!(
            "the prediction's cart {} breaks away at the identified Coulomb force, {:.2} N, and a real cart's breakaway force is higher (stiction), which identification from moving rows cannot see",
            cart.number(),
            coulomb[i]
        ),
    }
}

/// The likely causes of a transient that differs: identification error
/// (where it is more than `IDENT_TOLERANCE`), unmodelled delay and
/// stiction, quantified where the rig is simulated.
fn transient_reasons(known: Option<&KnownDifferences>) -> String {
    let Some(k) = known else {
        return "identification error (the springs, K, b2), a PWM delay other than the data sheet's, and breakaway friction (stiction) the prediction does not have".into();
    };
    let off: Vec<String> = k
        .off()
        .iter()
        .map(|(name, got, want)| format!("{name} {}", pct(*got, *want)))
        .collect();
    let mut reasons = Vec::new();
    if !off.is_empty() {
        reasons.push(format!(
            "identification error ({} against the card's truth)",
            off.join(", ")
        ));
    }
    if let Some(delay) = k.delay {
        reasons.push(format!(
            "the card's {:.2} ms PWM delay where the prediction assumed the data sheet's {:.2} ms",
            delay * 1e3,
            DRIVE_DELAY * 1e3
        ));
    }
    if k.stiction {
        reasons.push("breakaway (stiction) the prediction does not have".into());
    }
    if let Some(sigma) = k.encoder_noise {
        reasons.push(format!(
            "σ = {sigma} count of encoder noise the prediction does not have"
        ));
    }
    let mut s = reasons.join(", ");
    if off.is_empty() {
        s += &format!(
            " (not identification error: K, k1, k2, b1 and b2 are within {:.1} % of the card's)",
            k.worst() * 100.0
        );
    }
    s
}
