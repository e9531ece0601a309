//! Helpers built on the two-cart lab (feature `lab`).

use ctrlab::data::Recording;
use ctrlab::hw::{self, Clock, LoopConfig, VirtualClock};
use ctrlab::lab::{CardSettings, Friction, SimulatedRig, Unmodelled, lqi};
use ctrlab::signal::Signal;
use ctrlab::{Cart, Controller, Discrete, MassSpring, StateSpace};
use nalgebra::{SVector, vector};

/// The rig's sampling period, s.
pub const PERIOD: f64 = 0.002;

/// The plausible rig with less damping than the default (the
/// rig of `tests/data/lighter_rig.toml`): cart 2 at 0.9 kg with the
/// motor's rotor, b1 = 5 and b2 = 4 N·s/m, K = 1.2 N/V, Coulomb friction
/// 0.5 / 1 N (breakaway 1.2 × that, as the default's); the rest the
/// default rig's. The lab's fixed ±8 V square wave drives cart 2 past its
/// travel on it; its carts move at 2 V, where the default's friction holds
/// them.
pub fn lighter() -> SimulatedRig {
    SimulatedRig {
        truth: MassSpring {
            m2: 0.9,
            b1: 5.0,
            b2: 4.0,
            gain: 1.2,
            ..SimulatedRig::default_truth()
        },
        friction: Friction {
            coulomb: [0.5, 1.0],
            stiction: [0.6, 1.2],
        },
        ..SimulatedRig::default()
    }
}

/// `controller` toward `setpoint` (m, cart 2) for `duration` seconds
/// through the sampled-data simulator with `sim`'s plant, sensor and drive.
pub fn simulate_on<C: Controller<4, 1, 1>>(
    sim: &SimulatedRig,
    controller: C,
    setpoint: f64,
    duration: f64,
) -> Recording {
    lqi::predict(sim, controller, setpoint, duration).unwrap()
}

/// `controller` toward `setpoint` for `duration` seconds on `sim`'s rig
/// (card, driver, 2 ms loop) over a fresh virtual clock, with no overrun.
pub fn run_on_rig<C: Controller<4, 1, 1>>(
    sim: &SimulatedRig,
    controller: C,
    setpoint: f64,
    duration: f64,
) -> Recording {
    let out = try_run_on_rig(sim, controller, setpoint, duration).unwrap();
    assert_eq!(out.stats.overruns, 0);
    out.recording
}

/// [`run_on_rig`], returning the loop's error (a travel limit, say) with
/// the recording up to it.
pub fn try_run_on_rig<C: Controller<4, 1, 1>>(
    sim: &SimulatedRig,
    controller: C,
    setpoint: f64,
    duration: f64,
) -> Result<hw::RunOutcome, Box<hw::RunError>> {
    run_loop(sim, controller, |_| vector![setpoint], duration)
}

/// `controller` with `reference` for `duration` seconds on `sim`'s rig
/// (card, driver, 2 ms loop) over a fresh virtual clock.
fn run_loop<C: Controller<4, 1, 1>>(
    sim: &SimulatedRig,
    controller: C,
    reference: impl FnMut(f64) -> SVector<f64, 1>,
    duration: f64,
) -> Result<hw::RunOutcome, Box<hw::RunError>> {
    let clock = VirtualClock::new();
    let rig = sim.rig(&Clock::Virtual(clock.clone())).unwrap();
    let config = LoopConfig {
        duration,
        ..LoopConfig::default()
    };
    hw::run(rig, controller, reference, &Clock::Virtual(clock), &config)
}

/// The default simulated rig with plant `truth`, Coulomb friction
/// `friction` (N, cart 1 and 2) and stiction 20 % above it, noise `seed`,
/// and none of the default's unmodelled effects: the tests that use it
/// check the identification's machinery against a truth they set (cart
/// 2's mass included), not its realism (that is `lab_identification`'s).
pub fn friction_rig(truth: MassSpring, friction: [f64; 2], seed: u64) -> SimulatedRig {
    SimulatedRig {
        truth,
        unmodelled: Unmodelled::NONE,
        friction: Friction {
            coulomb: friction,
            stiction: friction.map(|f| 1.2 * f),
        },
        card: CardSettings {
            seed,
            ..CardSettings::default()
        },
        ..SimulatedRig::default()
    }
}

/// `input` (V) open loop for `duration` seconds on `sim`'s rig (card,
/// driver, 2 ms loop) over a fresh virtual clock.
pub fn open_loop(sim: &SimulatedRig, input: &dyn Signal, duration: f64) -> Recording {
    try_open_loop(sim, input, duration).unwrap()
}

/// [`open_loop`], returning the loop's error (a travel limit, say).
pub fn try_open_loop(
    sim: &SimulatedRig,
    input: &dyn Signal,
    duration: f64,
) -> Result<Recording, Box<hw::RunError>> {
    run_loop(sim, ctrlab::OpenLoop, |t| vector![input.value(t)], duration).map(|out| out.recording)
}

/// The nominal plant's ZOH model at the rig's period, outputs `[x1, x2]`.
pub fn position_model() -> StateSpace<4, 1, 2, Discrete> {
    lqi::position_model(&MassSpring::nominal(), PERIOD).unwrap()
}

/// LQI on cart 2 (weights 1e7 on x2, 1e10 on its integral, 1 on u) with a
/// current-form Kalman filter on both positions (force noise 10 V², each
/// position read to a count of `metres_per_count`), back-calculation
/// anti-windup past the drive's 24 mV step; it uses only `[x1, x2]` of the
/// rig's `[x1, v1, x2, v2]`. The construction lab5's Design section uses.
pub fn positions_lqi(metres_per_count: f64) -> lqi::PositionsLqi {
    let q = lqi::weights(Cart::Two, 1e7);
    lqi::positions_lqi(&position_model(), Cart::Two, &q, metres_per_count)
        .unwrap()
        .controller
}

/// Last value of channel `name`.
pub fn last(rec: &Recording, name: &str) -> f64 {
    *rec.channel(name).unwrap().last().unwrap()
}

/// Number of samples where the applied input is at the drive's ±24 V.
pub fn saturated(rec: &Recording) -> usize {
    rec.channel("u")
        .unwrap()
        .iter()
        .filter(|u| u.abs() >= 24.0)
        .count()
}

/// The loop's default settings, for a run of `duration` s.
pub fn loop_config(duration: f64) -> LoopConfig {
    LoopConfig {
        duration,
        ..LoopConfig::default()
    }
}

/// The halted run's recording holds exactly `samples` samples, the last at
/// `last` s (virtual time: exact to the nanosecond the clock counts in), and
/// the error says how many.
pub fn assert_recorded(err: &hw::RunError, samples: usize, last: f64) {
    assert_eq!(err.recording.len(), samples, "{err}");
    assert_eq!(err.stats.ticks, samples);
    let t = *err.recording.time().last().unwrap();
    assert!(
        (t - last).abs() < 1e-12,
        "last sample at {t} s, not {last} s"
    );
    assert!(
        err.to_string()
            .contains(&format!("after {samples} samples"))
    );
}
