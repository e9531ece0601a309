//! One experiment at a time (issue 27, item 1): `lab::tables::Experiment`
//! refuses what it cannot run and names what halts it; the
//! `examples/experiment` binary (its tests are `#[ignore]`d: they need it
//! built, `cargo build --release --example experiment`, as .ci/run does)
//! prints the batch's metrics for a row of Table 5, writes the recording
//! under a name that says what ran, and on a faulty simulated rig halts
//! and names the fault. That a row run alone is the batch's row, sample
//! for sample, is tests/lab_tables.rs's.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

#[path = "common/example.rs"]
mod example;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use ctrlab::Recording;
use ctrlab::hw::{Clock, LoopConfig, LoopFault, Pc104, RigError, VirtualClock};
use ctrlab::lab::protocol::PERIOD;
use ctrlab::lab::tables::{Experiment, ExperimentError, Halt, RigOutcome, TABLE5, TABLE6};
use ctrlab::lab::{Calibration, CardSettings, Cart, LabGains, MassSpringRig, SimulatedRig};

fn cart2(kf: [f64; 4], setpoint_mm: f64, duration: f64) -> Experiment {
    Experiment {
        cart: Cart::Two,
        gains: LabGains::new(kf, Cart::Two),
        setpoint_mm,
        duration,
    }
}

#[test]
fn an_experiment_is_checked_against_the_rig_before_it_runs() {
    let cal = Calibration::default();
    assert_eq!(cal.travel_limits, [0.05, 0.05]);
    assert!(
        cart2([0.0, 0.0, 10.0, 0.1], -30.0, 3.0)
            .validate(&cal)
            .is_ok()
    );
    let far = cart2([0.0, 0.0, 10.0, 0.1], 30.5, 3.0).validate(&cal);
    assert!(
        matches!(far, Err(ExperimentError::Setpoint { cart: 2, max_mm, .. }) if max_mm == 30.0),
        "{far:?}"
    );
    let nan = cart2([0.0, 0.0, f64::NAN, 0.1], 30.0, 3.0).validate(&cal);
    assert_eq!(
        nan.unwrap_err().to_string(),
        "Kf3 = NaN is not a finite number"
    );
    for duration in [0.0, -1.0, f64::INFINITY, 61.0] {
        let e = cart2([0.0, 0.0, 10.0, 0.1], 30.0, duration).validate(&cal);
        assert_eq!(e, Err(ExperimentError::Duration(duration)));
    }
    let g = Experiment {
        gains: LabGains {
            kf: [0.0; 4],
            g: [0.0, 0.0, f64::NAN, 0.0],
        },
        ..cart2([0.0; 4], 30.0, 3.0)
    };
    assert!(g.validate(&cal).unwrap_err().to_string().starts_with("G3"));
}

#[test]
fn the_name_says_what_ran_and_a_row_finds_its_seed() {
    let e = cart2([0.0, 0.0, 10.0, 0.1], 30.0, 3.0);
    assert_eq!(e.to_string(), "cart2_kf_0_0_10_0.1_to_30mm");
    assert_eq!((e.table_row(), e.seed()), (Some((TABLE5, 7)), 107));
    // Not a row: another setpoint, duration or G.
    let other = cart2([0.0, 0.0, 10.0, 0.1], 20.0, 5.0);
    assert_eq!(other.to_string(), "cart2_kf_0_0_10_0.1_to_20mm_5s");
    assert_eq!((other.table_row(), other.seed()), (None, 100));
    let scaled = Experiment {
        gains: LabGains {
            g: [0.0, 0.0, 1.05, 0.0],
            ..e.gains
        },
        ..e
    };
    assert_eq!(
        scaled.to_string(),
        "cart2_kf_0_0_10_0.1_g_0_0_1.05_0_to_30mm"
    );
    assert_eq!(scaled.table_row(), None);
    // Table 6's rows are cart 1's.
    let t6 = TABLE6.experiment(9).unwrap();
    assert_eq!(t6.to_string(), "cart1_kf_1_0.01_0_0_to_15mm");
    assert_eq!(t6.seed(), 109);
}

/// Issue 27's check, at the library: Table 5's `[0 0 10 0]` on a simulated
/// card whose calibration reads cart 2 from counter 2, which the card
/// leaves unconnected (a dead encoder, as tests/failsafe.rs injects it).
#[test]
fn a_dead_cart_2_encoder_halts_the_experiment_and_is_named() {
    let sim = SimulatedRig::default();
    let calibration = Calibration {
        encoder_channels: [0, 2],
        ..sim.calibration
    };
    let clock = Clock::Virtual(VirtualClock::new());
    let card = Pc104::with_map(sim.card(&clock).unwrap(), sim.card.map).unwrap();
    let rig = MassSpringRig::with_clock(card, calibration, PERIOD, clock.clone()).unwrap();
    let run = TABLE5
        .experiment(4)
        .unwrap()
        .run(rig, &clock, &LoopConfig::default())
        .unwrap();
    assert!(
        matches!(
            run.fault,
            Some(RigError::Fault(LoopFault::EncoderNotFollowing {
                cart: 2,
                ..
            }))
        ),
        "{:?}",
        run.fault
    );
    let RigOutcome::Diverged {
        why: Halt::Fault(message),
        at,
    } = &run.outcome
    else {
        panic!("{:?}", run.outcome)
    };
    assert!(message.contains("the encoder of cart 2"), "{message}");
    assert!(*at < 0.1 && !run.recording.is_empty(), "{at}");
}

/// The experiment binary: `$EXPERIMENT`, else this test's profile's.
fn experiment_binary() -> PathBuf {
    example::example_binary(
        "experiment",
        "EXPERIMENT",
        "cargo build --release --example experiment",
    )
}

/// Runs the binary with `args`, its recordings into a fresh `out`.
fn experiment(out: &Path, args: &[&str]) -> Output {
    if out.exists() {
        std::fs::remove_dir_all(out).unwrap();
    }
    Command::new(experiment_binary())
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .expect("the experiment binary runs")
}

fn out_dir(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("experiment")
        .join(name)
}

#[test]
#[ignore = "needs the experiment binary: cargo build --release --example experiment"]
fn the_binary_prints_the_batchs_metrics_of_a_table_5_row_and_writes_its_recording() {
    let out = out_dir("row8");
    let run = experiment(
        &out,
        &[
            "--cart",
            "2",
            "--kf",
            "0,0,10,0.1",
            "--setpoint",
            "30mm",
            "--duration",
            "3",
        ],
    );
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    // The batch's row, as lab5 runs it: Table 5's eighth row, seed 107.
    let row = TABLE5.experiment(7).unwrap();
    let sim = SimulatedRig::default();
    let sim = SimulatedRig {
        card: CardSettings {
            seed: TABLE5.row_seed(7),
            ..sim.card
        },
        period: PERIOD,
        ..sim
    };
    let clock = Clock::Virtual(VirtualClock::new());
    let batch = row
        .run(sim.rig(&clock).unwrap(), &clock, &LoopConfig::default())
        .unwrap();
    let step = batch.outcome.step().expect("the row settles");
    // The metrics at lab5's report's precision, as the binary prints them.
    for (name, value) in [
        ("POT", format!("{:.2} %", step.overshoot)),
        (
            "settling time (2 %)",
            format!("{:.3} s", step.settling_time),
        ),
        (
            "steady-state error",
            format!("{:.2} mm", step.steady_state_error.unwrap()),
        ),
        ("peak", format!("{:.2} mm at", step.peak)),
        ("outcome", "settled".into()),
    ] {
        let line = stdout
            .lines()
            .find(|l| l.trim_start().starts_with(name))
            .unwrap_or_else(|| panic!("no {name} in\n{stdout}"));
        assert!(line.contains(&value), "{line:?} against {value:?}");
    }
    assert!(stdout.contains("Table 5, row 8"), "{stdout}");
    // The recording, under its name, with units in its header: the batch's.
    let csv = out.join("cart2_kf_0_0_10_0.1_to_30mm.csv");
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(
        text.starts_with("t_s,u_V,x1_m,v1_m_s,x2_m,v2_m_s\n"),
        "{}",
        &text[..60]
    );
    let written = Recording::read_csv(&csv).unwrap();
    assert_eq!(written, batch.recording);
}

#[test]
#[ignore = "needs the experiment binary: cargo build --release --example experiment"]
fn on_a_rig_whose_drive_cannot_move_cart_2_the_binary_halts_and_names_the_fault() {
    let out = out_dir("stuck");
    let truth = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/stuck_cart2.toml");
    let run = experiment(
        &out,
        &[
            "--cart",
            "2",
            "--kf",
            "0,0,10,0",
            "--setpoint",
            "30mm",
            "--truth",
            truth,
        ],
    );
    let (stdout, stderr) = (
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr),
    );
    assert_eq!(run.status.code(), Some(1), "{stdout}\n{stderr}");
    assert!(
        stderr.contains("the rig halted: motor or encoder not responding"),
        "{stderr}"
    );
    assert!(stdout.contains("halted at t = "), "{stdout}");
    // What was recorded up to the halt is kept.
    let rec = Recording::read_csv(out.join("cart2_kf_0_0_10_0_to_30mm.csv")).unwrap();
    assert!(!rec.is_empty() && rec.len() < 1500, "{}", rec.len());
}

#[test]
#[ignore = "needs the experiment binary: cargo build --release --example experiment"]
fn the_binary_refuses_bad_input_and_says_why() {
    let out = out_dir("refused");
    for (args, code, says) in [
        (&["--cart", "2", "--kf", "0,0,10"][..], 2, "3 gains given"),
        (&["--cart", "2", "--kf", "0,0,NaN,0"][..], 2, "Kf3 = NaN"),
        (&["--cart", "3", "--kf", "0,0,10,0"][..], 2, "1 or 2"),
        (
            &["--cart", "2", "--kf", "0,0,10,0", "--setpoint", "30"][..],
            2,
            "needs its unit",
        ),
        (
            &["--cart", "2", "--kf", "0,0,10,0", "--duration", "-1"][..],
            2,
            "> 0 s",
        ),
        (
            &["--cart", "2", "--kf", "0,0,10,0", "--setpoint", "40mm"][..],
            1,
            "not within ±30 mm, 60 % of cart 2's travel",
        ),
        (
            &["--cart", "2", "--kf", "0,0,10,0", "--duration", "90"][..],
            1,
            "at most 60 s",
        ),
    ] {
        let run = experiment(&out, args);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(code), "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
        // Refused before anything ran: nothing written.
        assert!(!out.exists(), "{args:?} wrote {}", out.display());
    }
}

#[test]
#[ignore = "needs the experiment binary: cargo build --release --example experiment"]
fn a_saved_design_runs_with_its_g_and_is_named_by_it() {
    let dir = out_dir("design");
    std::fs::create_dir_all(&dir).unwrap();
    let design = dir.join("design.toml");
    std::fs::write(&design, "kf = [0, 0, 10, 0.1]\ng = [0, 0, 1.05, 0]\n").unwrap();
    let out = dir.join("out");
    let run = experiment(
        &out,
        &["--cart", "2", "--gains-file", design.to_str().unwrap()],
    );
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(
        stdout.contains("G = [0 0 1.05 0], setpoint 30 mm"),
        "{stdout}"
    );
    // G = 1.05 asks for 31.5 mm, which the loop's error brings back near 30.
    assert!(
        out.join("cart2_kf_0_0_10_0.1_g_0_0_1.05_0_to_30mm.csv")
            .is_file()
    );
    // Three gains: refused, the file and what it should hold named.
    std::fs::write(&design, "kf = [0, 0, 10]\n").unwrap();
    let run = experiment(
        &out,
        &["--cart", "2", "--gains-file", design.to_str().unwrap()],
    );
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("expected kf = [Kf1, Kf2, Kf3, Kf4]"),
        "{stderr}"
    );
}
