//! The MPC section: the design, each case's prediction against the rig in
//! a table and a figure, against the limits the controller knows.

use ctrlab::design::mpc::Row;
use ctrlab::lab::lqi::DURATION;
use ctrlab::lab::mpc::{CART1_SETPOINT, SETPOINT_MARGIN, TICK_TIME_LIMIT, Tuning};
use ctrlab::lab::position_channel;

use super::{ComparePanel, Report, curve};
use crate::mpc::{Case, MpcSection, Run};

impl Report {
    /// The whole MPC section.
    pub fn mpc(&mut self, s: &MpcSection) -> Result<(), Box<dyn std::error::Error>> {
        self.heading(2, "Constrained MPC: predict, then run");
        let t = Tuning::LAB;
        let cal = s.rig.calibration;
        let count = s.rig.metres_per_count();
        let (linear, quadratic) = match t.travel_penalty {
            Row::Soft { linear, quadratic } => (linear, quadratic),
            Row::Hard => (f64::INFINITY, f64::INFINITY),
        };
        self.add(&format!(
            "**Controller** (`lab::mpc::design`, `design::mpc::Mpc`), on the model identified above at {} ms: every period it estimates the state from both positions (a steady-state Kalman filter), finds the steady state that puts the tracked cart on its setpoint, and plans the drive over the next {} periods ({:.0} ms) by a quadratic program: weights {:.0e} /m² on the tracked position, {:.0e} /m² on the other cart, {} /V² on the drive and {} /V² on its change per period; **hard** limits on the drive (±{} V) and on its change ({} V per period); **soft** limits on both carts {} mm inside their travel limits (±{:.1} and ±{:.1} mm), at {:.0e} per metre and {:.0e} per square metre of violation at each predicted step; integral action {} /s within {} mm of the setpoint (a cart held by friction is walked off it). The QP is solved by `DenseQp`: the plan of the last period, shifted and clipped to the hard limits, is polished by an active-set method, with ADMM behind it; each tick is bounded (at most {} ADMM iterations and {} active-set solves; on the wall clock, the card or `--real-time`, also {} µs of solving), and if that runs out or the hard limits cannot hold, the tick falls back to the last plan shifted, else the LQR law clipped — counted below.\n",
            PERIOD_MS,
            t.horizon,
            t.horizon as f64 * PERIOD_MS,
            t.tracked_weight,
            t.other_weight,
            t.input_weight,
            t.rate_weight,
            cal.volts_full_scale,
            t.rate_limit,
            t.travel_margin * 1e3,
            (cal.travel_limits[0] - t.travel_margin) * 1e3,
            (cal.travel_limits[1] - t.travel_margin) * 1e3,
            linear,
            quadratic,
            t.integral_gain,
            t.integral_zone * 1e3,
            ctrlab::design::mpc::MPC_SOLVER.max_iterations,
            ctrlab::design::mpc::MPC_SOLVER.active_set_steps,
            TICK_TIME_LIMIT.as_micros(),
        ));
        self.add(&format!(
            "**Cases**: cart 2 to {:.0} mm, {} mm inside its travel limit — holding it there takes most of the drive, so a fixed gain either creeps up to it or overshoots into the stop; cart 1 to Table 6's {:.0} mm. **Prediction**: `run_sampled` on the identified plant with its Coulomb friction, the drive's steps and delay, the encoders' counts (as the Design section). **Rig**: the same controller through `hw::run`. Recordings: `runs/mpc_cart{{1,2}}_{{predicted,rig}}.csv`.\n",
            (cal.travel_limits[1] - SETPOINT_MARGIN) * 1e3,
            SETPOINT_MARGIN * 1e3,
            CART1_SETPOINT * 1e3,
        ));
        self.mpc_table(&s.cases, count, cal.travel_limits, cal.max_saturation_time);
        let panels = s
            .cases
            .iter()
            .map(|c| {
                let channel = position_channel(c.cart);
                Ok(ComparePanel {
                    title: format!(
                        "cart {} to {:.0} mm (MPC)",
                        c.cart.number(),
                        c.setpoint * 1e3
                    ),
                    setpoint_mm: c.setpoint * 1e3,
                    runs: vec![
                        curve("predicted".into(), &c.predicted.recording, channel)?,
                        curve("rig".into(), &c.rig.recording, channel)?,
                    ],
                })
            })
            .collect::<Result<Vec<_>, ctrlab::Error>>()?;
        self.compare(
            "mpc.svg",
            "Constrained MPC: predicted and measured position, at rest in encoder counts, and voltage",
            (cal.volts_full_scale, count * 1e3),
            &panels,
        )?;
        self.mpc_agreement(&s.cases);
        Ok(())
    }

    /// One row per figure, predicted and rig per case.
    fn mpc_table(&mut self, cases: &[Case], count: f64, travel: [f64; 2], saturation: f64) {
        self.heading(3, "The MPC predicted and run, against its limits");
        let mut header = vec![String::new()];
        let mut runs: Vec<&Run> = Vec::new();
        for c in cases {
            let (n, mm) = (c.cart.number(), c.setpoint * 1e3);
            header.push(format!("cart {n} to {mm:.0} mm, predicted"));
            header.push(format!("cart {n} to {mm:.0} mm, rig"));
            runs.push(&c.predicted);
            runs.push(&c.rig);
        }
        type Figure = fn(&Run, f64, [f64; 2]) -> String;
        let rows: [(&str, Figure); 13] = [
            ("rise time 10–90 % (s)", |r, _, _| {
                r.metrics
                    .step
                    .as_ref()
                    .map_or("–".into(), |s| format!("{:.3}", s.rise))
            }),
            ("overshoot (%)", |r, _, _| {
                r.metrics
                    .step
                    .as_ref()
                    .map_or("–".into(), |s| format!("{:.2}", s.overshoot))
            }),
            ("settling time 2 % (s)", |r, _, _| {
                r.metrics
                    .step
                    .as_ref()
                    .map_or("–".into(), |s| format!("{:.3}", s.settling))
            }),
            ("steady-state error (counts)", |r, _, _| {
                r.metrics
                    .step
                    .as_ref()
                    .map_or("–".into(), |s| format!("{:+.2}", s.error_counts))
            }),
            ("closest approach to a travel limit (mm)", |r, _, t| {
                let i = if r.figures.clearance[0] / t[0] < r.figures.clearance[1] / t[1] {
                    0
                } else {
                    1
                };
                format!("{:.2} (cart {})", r.figures.clearance[i] * 1e3, i + 1)
            }),
            ("peak drive (V)", |r, _, _| {
                format!("{:.2}", r.figures.peak_u)
            }),
            ("samples at the drive's full scale", |r, _, _| {
                r.figures.at_limit.to_string()
            }),
            ("longest at full scale (s)", |r, _, _| {
                format!("{:.3}", r.longest_at_limit)
            }),
            ("largest change of drive per period (V)", |r, _, _| {
                format!("{:.3}", r.figures.max_step_u)
            }),
            ("ticks solved / fallbacks", |r, _, _| {
                format!("{} / {}", r.stats.solved, r.stats.fallbacks())
            }),
            ("active-set solves, most in a tick", |r, _, _| {
                r.stats.active_set_steps_max.to_string()
            }),
            ("ADMM iterations, most in a tick", |r, _, _| {
                r.stats.iterations_max.to_string()
            }),
            ("longest tick, wall clock (µs)", |r, _, _| {
                format!("{:.0}", r.stats.solve_time_max * 1e6)
            }),
        ];
        let mut body = Vec::new();
        for (name, figure) in rows {
            let mut row = vec![name.to_string()];
            for r in &runs {
                row.push(figure(r, count, travel));
            }
            body.push(row);
        }
        self.table(&header, &body);
        self.add(&format!(
            "The drive at full scale is planned, not clipped: the controller's hard limit is the drive's range, and the rig halts a drive held at full scale for {saturation} s (`max_saturation_time`). The rate limit holds on the applied drive to half of its 24 mV steps. The longest tick is measured on this machine's wall clock while the simulation runs (virtual time), so it includes whatever else the machine was doing; the performance guide has the solve time measured alone.\n"
        ));
        let mut counts = String::from("The controller's own counts (`MpcStats`):\n\n");
        for c in cases {
            for (label, r) in [("predicted", &c.predicted), ("rig", &c.rig)] {
                counts += &format!(
                    "- cart {} to {:.0} mm, {label}: {}\n",
                    c.cart.number(),
                    c.setpoint * 1e3,
                    r.stats
                );
            }
        }
        self.add(&counts);
        for c in cases {
            if let Some(why) = &c.halted {
                self.add(&format!(
                    "Cart {}'s rig run ended early: {why}.\n",
                    c.cart.number()
                ));
            }
        }
    }

    /// Where the prediction and the rig agree.
    fn mpc_agreement(&mut self, cases: &[Case]) {
        self.heading(3, "Prediction and rig");
        let mut lines = Vec::new();
        for c in cases {
            let n = c.cart.number();
            let transient = c
                .comparison
                .transient
                .map_or("no step figures to compare".to_string(), |t| {
                    if t.agrees() {
                        "the transients agree (rise within a period and 10 %, overshoot within 1 point, settling within 10 ms and 10 %)".into()
                    } else {
                        "the transients differ (rise, overshoot or settling beyond the agreement band)".into()
                    }
                });
            let rest = if c.comparison.rest_agrees {
                "they rest alike (steady-state errors within half a count)"
            } else {
                "they rest differently (steady-state errors more than half a count apart, or the rig's readings spread wider)"
            };
            // The reading that halts a run is not in its recording: a halt
            // says more than the recorded clearance.
            let limits = if let Some(why) = &c.halted {
                format!("**the rig halted the run**: {why}")
            } else if c.rig.figures.clearance.iter().all(|&x| x > 0.0) {
                "neither cart reached its travel limit on the rig".into()
            } else {
                "**a cart reached its travel limit on the rig**".into()
            };
            lines.push(format!(
                "- **Cart {n} to {:.0} mm** (for {DURATION} s): {transient}; {rest}; {limits}; the rig's run had {} fallbacks in {} ticks.",
                c.setpoint * 1e3,
                c.rig.stats.fallbacks(),
                c.rig.stats.ticks,
            ));
        }
        self.add(&(lines.join("\n") + "\n"));
    }
}

/// The loop's period, ms.
const PERIOD_MS: f64 = ctrlab::lab::protocol::PERIOD * 1e3;
