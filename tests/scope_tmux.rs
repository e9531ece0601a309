//! The live scope (`experiment --scope`, issue 27, item 2) in a real
//! terminal: tmux runs the experiment in a detached 120×40 pane; the test
//! waits for a frame, checks what it shows and that it moves, presses `q`,
//! and checks that the run stopped on the key: halted by the stop request,
//! the rig halted, the recording kept, exit status 1 (a halt, as
//! examples/experiment documents it).
//!
//! `#[ignore]`d: it needs the built binary (`cargo build --release --example
//! experiment`, as .ci/run does) and tmux, which it refuses to pass
//! without. Nothing here measures time: waits are bounded numbers of polls.

// Built on the two-cart lab (its simulated rig).
#![cfg(feature = "lab")]

#[path = "common/example.rs"]
mod example;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::thread::sleep;
use std::time::Duration;

use ctrlab::Recording;
use ctrlab::lab::SimulatedRig;
use ctrlab::lab::protocol::PERIOD;

/// The run: long enough (60 s, the most) that only the key ends it here.
const DURATION: f64 = 60.0;

/// Between two looks at the pane.
const POLL: Duration = Duration::from_millis(100);

/// A tmux server of its own (`-L`), so tests neither see nor disturb any
/// other session; killed on drop, a failing test's included.
struct Tmux {
    socket: String,
}

impl Tmux {
    /// A detached `width`×`height` session running `command` in `sh`.
    fn start(socket: &str, width: u16, height: u16, command: &str) -> Self {
        let version = Command::new("tmux").arg("-V").output();
        assert!(
            version.is_ok_and(|v| v.status.success()),
            "tmux is not installed: this test runs the scope in a real terminal, it \
             needs tmux (apt-get install tmux)"
        );
        let tmux = Self {
            socket: socket.into(),
        };
        // A stale server of an earlier, killed run of this test.
        tmux.command(&["kill-server"]);
        let started = tmux.command(&[
            "new-session",
            "-d",
            "-s",
            "scope",
            "-x",
            &width.to_string(),
            "-y",
            &height.to_string(),
            command,
        ]);
        assert!(
            started.status.success(),
            "tmux new-session: {}",
            String::from_utf8_lossy(&started.stderr)
        );
        tmux
    }

    /// `tmux -L socket args…`, without the user's configuration, in UTF-8
    /// (the scope's curves are braille), outside any tmux the tests run in.
    fn command(&self, args: &[&str]) -> Output {
        Command::new("tmux")
            .args(["-u", "-f", "/dev/null", "-L", &self.socket])
            .args(args)
            .env_remove("TMUX")
            .output()
            .expect("tmux runs")
    }

    /// What the pane shows now, as text.
    fn capture(&self) -> String {
        String::from_utf8_lossy(&self.command(&["capture-pane", "-p", "-t", "scope"]).stdout)
            .into_owned()
    }

    fn send_keys(&self, keys: &str) {
        let sent = self.command(&["send-keys", "-t", "scope", keys]);
        assert!(
            sent.status.success(),
            "tmux send-keys: {}",
            String::from_utf8_lossy(&sent.stderr)
        );
    }
}

impl Drop for Tmux {
    fn drop(&mut self) {
        // Also ends the experiment if it is still running (SIGHUP: halted).
        self.command(&["kill-server"]);
    }
}

/// `s` quoted for `sh`.
fn quoted(s: &Path) -> String {
    format!("'{}'", s.display().to_string().replace('\'', r"'\''"))
}

/// Polls `what` up to `polls` times, `POLL` apart, until it gives a value.
fn poll<T>(polls: usize, mut what: impl FnMut() -> Option<T>) -> Option<T> {
    (0..polls).find_map(|_| {
        let found = what();
        if found.is_none() {
            sleep(POLL);
        }
        found
    })
}

#[test]
#[ignore = "needs the experiment binary (cargo build --release --example experiment) and tmux"]
fn the_scope_draws_the_run_and_q_stops_it_and_halts_the_rig() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("scope_tmux");
    if dir.exists() {
        std::fs::remove_dir_all(&dir).unwrap();
    }
    std::fs::create_dir_all(&dir).unwrap();
    let (stdout, stderr, status, out) = (
        dir.join("stdout"),
        dir.join("stderr"),
        dir.join("status"),
        dir.join("out"),
    );
    let binary = example::example_binary(
        "experiment",
        "EXPERIMENT",
        "cargo build --release --example experiment",
    );
    // stdout through tee: the scope draws on stdout, so the pane shows it
    // and the file keeps the report printed after the terminal is restored.
    let command = format!(
        "{{ {} --cart 2 --kf 0,0,10,0.1 --setpoint 30mm --duration {DURATION} --real-time \
         --scope --out {}; echo $? > {}; }} 2> {} | tee {}",
        quoted(&binary),
        quoted(&out),
        quoted(&status),
        quoted(&stderr),
        quoted(&stdout),
    );
    let tmux = Tmux::start(
        &format!("ctrlab-scope-{}", std::process::id()),
        120,
        40,
        &command,
    );

    // A frame: the title with the gains, setpoint and the key; the position
    // panel with the setpoint, cart 2's trace and the travel as its limits;
    // the drive panel with the drive's limits.
    let cal = SimulatedRig::default().calibration;
    let (travel, full) = (cal.travel_limits[1] * 1e3, cal.volts_full_scale);
    let expected = [
        "cart 2, Kf = [0 0 10 0.1], to 30 mm".to_string(),
        "q, Esc or Ctrl-C stops the run".into(),
        "setpoint".into(),
        "x2 (mm)".into(),
        "t (s)".into(),
        format!("{DURATION}"),
        format!("{}", -travel),
        format!("{travel}"),
        " drive ".into(),
        "u (V)".into(),
        format!("{}", -full),
        format!("{full}"),
    ];
    let shows_all = |screen: &str| expected.iter().all(|e| screen.contains(e.as_str()));
    let frame = poll(300, || Some(tmux.capture()).filter(|s| shows_all(s))).unwrap_or_else(|| {
        panic!(
            "no frame with {expected:?}; the pane:\n{}\nstderr: {}",
            tmux.capture(),
            std::fs::read_to_string(&stderr).unwrap_or_default()
        )
    });
    // The y axes' titles at their axes (`│mm`), not only in the title.
    for label in ["mm", "V"] {
        assert!(
            frame.contains(&format!("│{label}")),
            "no axis {label:?} in\n{frame}"
        );
    }
    // The frame updates while the run goes on: the traces grow.
    let later = poll(100, || {
        Some(tmux.capture()).filter(|s| *s != frame && shows_all(s))
    });
    assert!(later.is_some(), "the frame never changed from\n{frame}");

    tmux.send_keys("q");
    let code = poll(300, || {
        std::fs::read_to_string(&status)
            .ok()
            .and_then(|s| s.trim().parse::<i32>().ok())
    })
    .unwrap_or_else(|| panic!("still running after q; the pane:\n{}", tmux.capture()));
    let report = std::fs::read_to_string(&stdout).unwrap();
    let errors = std::fs::read_to_string(&stderr).unwrap();
    // Halted by the stop request (the loop's Interrupted), not the end of
    // the run or another fault; the rig halted.
    assert_eq!(code, 1, "{report}\n{errors}");
    assert!(
        errors.contains("experiment: the rig halted: interrupted at t = ")
            && errors.contains("stop request); rig halted"),
        "{errors}"
    );
    assert!(report.contains("outcome"), "{report}");
    assert!(report.contains("halted at t = "), "{report}");
    assert!(!errors.contains("the scope failed"), "{errors}");
    // The recording is kept, up to the stop: short of the 60 s run.
    let rec = Recording::read_csv(out.join("cart2_kf_0_0_10_0.1_to_30mm_60s.csv")).unwrap();
    let full_run = (DURATION / PERIOD) as usize;
    assert!(!rec.is_empty() && rec.len() < full_run, "{}", rec.len());
    assert!(
        report.contains("recording: ") && report.contains("cart2_kf_0_0_10_0.1_to_30mm_60s.csv"),
        "{report}"
    );
}
