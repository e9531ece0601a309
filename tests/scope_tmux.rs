//! The live scope (`experiment --scope`, issue 27, item 2) in a real
//! terminal: tmux runs the experiment in a detached 120×40 pane; the test
//! waits for a frame, checks what it shows and that it moves, presses `q`,
//! and checks that the run stopped on the key: halted by the stop request,
//! the rig halted, the recording kept, exit status 1 (a halt, as
//! examples/experiment documents it). Closing the terminal instead (killing
//! tmux) ends the run the same way, and the process with it.
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

/// The experiment with `--scope` in its own tmux, its stdout, stderr, exit
/// status and recordings in files under `CARGO_TARGET_TMPDIR/scope_tmux/name`.
struct Scoped {
    tmux: Tmux,
    stdout: PathBuf,
    stderr: PathBuf,
    status: PathBuf,
    out: PathBuf,
    /// The program's process id, for a failed test to end it.
    pid: PathBuf,
}

impl Scoped {
    /// Starts the run, `shell` (e.g. a `trap`) before it in the pane's sh.
    fn start(name: &str, shell: &str) -> Self {
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
            .join("scope_tmux")
            .join(name);
        if dir.exists() {
            std::fs::remove_dir_all(&dir).unwrap();
        }
        std::fs::create_dir_all(&dir).unwrap();
        let binary = example::example_binary(
            "experiment",
            "EXPERIMENT",
            "cargo build --release --example experiment",
        );
        let (stdout, stderr, status, out, pid) = (
            dir.join("stdout"),
            dir.join("stderr"),
            dir.join("status"),
            dir.join("out"),
            dir.join("pid"),
        );
        // stdout through tee: the scope draws on stdout, so the pane shows
        // it and the file keeps the report printed after the terminal is
        // restored. The inner sh notes its pid and becomes the program.
        let command = format!(
            "{shell}{{ sh -c 'echo $$ > \"$0\"; exec \"$@\"' {} {} --cart 2 --kf 0,0,10,0.1 \
             --setpoint 30mm --duration {DURATION} --real-time --scope --out {}; \
             echo $? > {}; }} 2> {} | tee {}",
            quoted(&pid),
            quoted(&binary),
            quoted(&out),
            quoted(&status),
            quoted(&stderr),
            quoted(&stdout),
        );
        let socket = format!("ctrlab-scope-{}-{name}", std::process::id());
        Self {
            tmux: Tmux::start(&socket, 120, 40, &command),
            stdout,
            stderr,
            status,
            out,
            pid,
        }
    }

    /// The first frame that shows what the scope must: the title with the
    /// gains, setpoint and the key; the position panel with the setpoint,
    /// cart 2's trace and the travel as its limits; the drive panel with
    /// the drive's limits.
    fn frame(&self) -> String {
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
            // The y axes' titles at their axes, not only in the title.
            "│mm".into(),
            "│V".into(),
        ];
        let shows_all = |screen: &String| expected.iter().all(|e| screen.contains(e.as_str()));
        poll(300, || Some(self.tmux.capture()).filter(shows_all)).unwrap_or_else(|| {
            panic!(
                "no frame with {expected:?}; the pane:\n{}\nstderr: {}",
                self.tmux.capture(),
                std::fs::read_to_string(&self.stderr).unwrap_or_default()
            )
        })
    }

    /// The exit status, once the program has ended (or a panic saying it
    /// has not, `after` what).
    fn exit_status(&self, after: &str) -> i32 {
        poll(300, || {
            std::fs::read_to_string(&self.status)
                .ok()
                .and_then(|s| s.trim().parse::<i32>().ok())
        })
        .unwrap_or_else(|| panic!("still running after {after}"))
    }

    /// Checks the run was halted by a stop request, not by its end or
    /// another fault: exit status 1, the rig halted, the recording kept
    /// up to the stop.
    fn check_stopped(&self, code: i32) -> (String, String) {
        let report = std::fs::read_to_string(&self.stdout).unwrap();
        let errors = std::fs::read_to_string(&self.stderr).unwrap();
        assert_eq!(code, 1, "{report}\n{errors}");
        assert!(
            errors.contains("experiment: the rig halted: interrupted at t = ")
                && errors.contains("stop request); rig halted"),
            "{errors}"
        );
        assert!(report.contains("halted at t = "), "{report}");
        let name = "cart2_kf_0_0_10_0.1_to_30mm_60s.csv";
        assert!(report.contains(&format!("recording: {}", self.out.join(name).display())));
        let rec = Recording::read_csv(self.out.join(name)).unwrap();
        let full_run = (DURATION / PERIOD) as usize;
        assert!(!rec.is_empty() && rec.len() < full_run, "{}", rec.len());
        (report, errors)
    }
}

impl Drop for Scoped {
    /// A program that has not ended (a failed test) is ended, not left
    /// running, or spinning, behind the test.
    fn drop(&mut self) {
        self.tmux.command(&["kill-server"]);
        if !self.status.exists()
            && let Ok(pid) = std::fs::read_to_string(&self.pid)
        {
            let _ = Command::new("kill").args(["-KILL", pid.trim()]).status();
        }
    }
}

#[test]
#[ignore = "needs the experiment binary (cargo build --release --example experiment) and tmux"]
fn the_scope_draws_the_run_and_q_stops_it_and_halts_the_rig() {
    let run = Scoped::start("q", "");
    let frame = run.frame();
    // The frame updates while the run goes on: the traces grow.
    let later = poll(100, || Some(run.tmux.capture()).filter(|s| *s != frame));
    assert!(later.is_some(), "the frame never changed from\n{frame}");

    run.tmux.send_keys("q");
    let code = run.exit_status("q");
    let (report, errors) = run.check_stopped(code);
    assert!(report.contains("outcome"), "{report}");
    assert!(!errors.contains("the scope failed"), "{errors}");
}

/// A terminal closed under the scope (here tmux killed, the pane's shell
/// ignoring the hang-up so that it writes the exit status) stops the run,
/// and the program ends instead of spinning on the dead terminal.
#[test]
#[ignore = "needs the experiment binary (cargo build --release --example experiment) and tmux"]
fn closing_the_terminal_stops_the_run_and_the_program_ends() {
    let run = Scoped::start("hangup", "trap '' HUP; ");
    run.frame();
    run.tmux.command(&["kill-server"]);
    let code = run.exit_status("its terminal closed");
    run.check_stopped(code);
}
