//! Bit for bit: runs hashed and compared across clocks and builds.

use super::*;

/// FNV-1a over the bits of every time, input and measurement of `rec`.
fn bits(rec: &ctrlab::Recording) -> u64 {
    let mut hash = 0xcbf2_9ce4_8422_2325_u64;
    let mut eat = |v: f64| {
        for byte in v.to_bits().to_le_bytes() {
            hash = (hash ^ u64::from(byte)).wrapping_mul(0x0100_0000_01b3);
        }
    };
    rec.time().iter().for_each(|&t| eat(t));
    for i in 0.. {
        let Some(u) = rec.input(i) else { break };
        u.iter().for_each(|&v| eat(v));
    }
    for i in 0.. {
        let Some(y) = rec.measurement(i) else { break };
        y.iter().for_each(|&v| eat(v));
    }
    hash
}

/// A rig with every field of the truth file away from its default.
fn every_field_changed() -> SimulatedRig {
    SimulatedRig {
        truth: MassSpring {
            m1: 1.25,
            m2: 0.75,
            k1: 900.0,
            k2: 1100.0,
            b1: 9.0,
            b2: 6.5,
            gain: 1.3,
        },
        initial_state: [0.004, 0.0, -0.006, 0.01],
        period: 0.001,
        friction: Friction {
            coulomb: [0.5, 1.5],
            stiction: [0.7, 1.8],
        },
        // Off: the hashes below pin the plant without them (the
        // `[unmodelled]` table's own round trip is in tests/rig_config.rs).
        unmodelled: Unmodelled::NONE,
        card: CardSettings {
            pwm_delay: 0.2e-3,
            map: ctrlab::hw::RegisterMap::default(),
            encoder_noise: 0.6,
            seed: 42,
            max_substep: 0.1e-3,
        },
        calibration: Calibration {
            card_id: 0x3c,
            volts_full_scale: 12.0,
            // 2048 counts per 30 mm.
            metres_per_count: 0.03 / 2048.0,
            pwm_channel: 2,
            encoder_channels: [3, 1],
            watchdog_timeout: Some(0.05),
            travel_limits: [0.06, 0.07],
            ..Calibration::default()
        },
        // lab5's identification input: no part of the plant or the card.
        ident: ctrlab::lab::ident_input::IdentInput {
            signal: ctrlab::lab::ident_input::IdentSignal::Prbs,
            volts: 6.0,
            half_period: 0.3,
            scale_to_travel: false,
        },
    }
}

/// The recordings of seeded runs on the simulated rig, and of the
/// sampled-data simulation that predicts them, hashed bit by bit: a
/// refactoring of the rig's configuration must leave every bit of them
/// alone. (The hashes were taken before `SimulatedRig` was composed of its
/// parts, at 91112b5.)
#[test]
fn seeded_runs_are_unchanged_bit_for_bit() {
    use ctrlab::hw::{LoopConfig, run};
    use ctrlab::{OpenLoop, StateFeedback};
    let law = StateFeedback::new(
        nalgebra::matrix![0.0, 0.0, 10_000.0, 100.0],
        nalgebra::matrix![10_000.0],
    )
    .unwrap();
    let mut hashes = Vec::new();
    // The default rig as it was before its unmodelled effects: with them
    // off the plant must be the same bit for bit (`lab_unmodelled` tests
    // what they do when on).
    let before = SimulatedRig {
        unmodelled: Unmodelled::NONE,
        ..SimulatedRig::default()
    };
    for sim in [before, every_field_changed(), ideal()] {
        let config = LoopConfig {
            duration: 1.5,
            ..LoopConfig::default()
        };
        let closed = {
            let clock = VirtualClock::new();
            let rig = sim.rig(&Clock::Virtual(clock.clone())).unwrap();
            run(rig, law, |_| vector![0.02], &Clock::Virtual(clock), &config)
                .unwrap()
                .recording
        };
        let open = {
            let clock = VirtualClock::new();
            let rig = sim.rig(&Clock::Virtual(clock.clone())).unwrap();
            let square = |t: f64| vector![if (t * 3.0) as i64 % 2 == 0 { 5.0 } else { -4.0 }];
            run(rig, OpenLoop, square, &Clock::Virtual(clock), &config)
                .unwrap()
                .recording
        };
        let predicted = ctrlab::sim::run_sampled(
            sim.plant(),
            sim.sensor(),
            law,
            |_| vector![0.02],
            SVector::from(sim.initial_state),
            &sim.sampled_config(1.5),
        )
        .unwrap();
        // The runs move the carts: the hashes pin behaviour, not a rest.
        let x2 = closed.channel("x2").unwrap();
        assert!(x2[x2.len() - 1] > 0.005, "{}", x2[x2.len() - 1]);
        let x2 = open.channel("x2").unwrap();
        let range = x2.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(range > 0.002, "{range}");
        let model = sim.simulation_model();
        let scalars = [
            sim.metres_per_count(),
            model.max_substep,
            model.input_delay,
            model.stiction_ratio[0],
            model.stiction_ratio[1],
        ];
        hashes.push([
            bits(&closed),
            bits(&open),
            bits(&predicted),
            scalars
                .iter()
                .fold(0, |h: u64, v| h.rotate_left(7) ^ v.to_bits()),
        ]);
    }
    assert_eq!(hashes, EXPECTED_BITS, "{hashes:#x?}");
}

/// Per rig (default, every field changed, ideal): the closed loop, the
/// open loop, the sampled-data prediction, and the scalars.
const EXPECTED_BITS: [[u64; 4]; 3] = [
    [
        0x37a2_671a_7b5b_e822,
        0x9162_0aef_3754_fa0b,
        0x1c67_e2ae_06d2_60a0,
        0x71e0_99cd_6a5b_44c6,
    ],
    [
        0x2608_bb43_ce9a_7a0f,
        0x1491_a858_7c36_973e,
        0x7dc0_b7b8_1c31_99b5,
        0x8b9d_88a4_f682_4725,
    ],
    [
        0xb8a1_5d25_28ec_5fd3,
        0x2987_65ee_ee30_3d06,
        0x3dfb_653e_298b_ee3b,
        0x9a30_bf72_8c69_a1bd,
    ],
];
