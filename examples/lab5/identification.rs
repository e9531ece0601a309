//! The identification runs, on the rig or from a student's own logs
//! (`--logs DIR`), identified into Tables 3 and 4 and the model
//! (`lab::ident::summarize`); and the equal-springs run on a simulated rig.

use std::path::{Path, PathBuf};

use ctrlab::data::CsvOptions;
use ctrlab::hw::LoopStats;
use ctrlab::lab::MassSpring;
use ctrlab::lab::ident::{EqualSprings, Summary, SummaryError, summarize};
use ctrlab::lab::ident_input::{
    AmplitudeChoice, AmplitudeSearch, IdentInput, IdentRuns, PROBE_DURATION, ProbeOutcome,
    TooFewRuns, peaks,
};
use ctrlab::lab::protocol::{IDENT_DURATION, IDENT_RUNS, M1, M2};
use ctrlab::nalgebra::vector;
use ctrlab::signal::{Signal, SquareWave};
use ctrlab::{OpenLoop, Recording};

use crate::backend::{Backend, LoopTiming, RunId};

/// One identification run: its name (the CSV file's stem) and recording.
pub struct Run {
    pub name: String,
    pub recording: Recording,
}

/// An identification run the rig halted (a travel limit, say): left out
/// of the averages.
pub struct FailedRun {
    pub name: String,
    /// The run's error, as the loop gives it (it names the limit).
    pub error: String,
    /// How long it ran, s.
    pub ran: f64,
    /// Both carts' largest |x| before it halted, m.
    pub peaks: [f64; 2],
}

/// The identification input on the rig: what was asked, the amplitude
/// chosen and why, and the runs the rig halted.
pub struct RigInput {
    pub input: IdentInput,
    pub choice: AmplitudeChoice,
    pub failed: Vec<FailedRun>,
}

/// Where the runs come from.
pub enum Source {
    /// [`IDENT_RUNS`] runs of the identification input on the rig (those
    /// that completed), and the loop's timing when it ran in real time.
    Rig {
        timing: Option<LoopTiming>,
        input: Box<RigInput>,
    },
    /// Every `*.csv` of a directory, read with a calibration.
    Logs {
        dir: PathBuf,
        metres_per_count: Option<f64>,
    },
}

/// The identification runs and what they give.
pub struct Identification {
    pub runs: Vec<Run>,
    pub source: Source,
    /// Tables 3 and 4, the averages, the model.
    pub summary: Summary,
    /// On a simulated rig: one run where the lab's model is exact.
    pub equal_springs: Option<EqualSprings>,
}

impl Identification {
    /// The identified model: the separate-springs averages.
    pub fn model(&self) -> MassSpring {
        self.summary.model()
    }

    /// The identified Coulomb forces, N (cart 1, cart 2).
    pub fn coulomb(&self) -> [f64; 2] {
        self.summary.coulomb()
    }

    /// The identification input's peak voltage on the rig, V (the lab's
    /// default for logs).
    pub fn volts(&self) -> f64 {
        match &self.source {
            Source::Rig { input, .. } => input.choice.volts,
            Source::Logs { .. } => ctrlab::lab::protocol::IDENT_VOLTS,
        }
    }

    /// The runs' recordings, in order.
    pub fn recordings(&self) -> Vec<&Recording> {
        self.runs.iter().map(|r| &r.recording).collect()
    }
}

/// The lab's identification runs on the rig: the amplitude chosen from
/// two probe runs (`runs/ident_probe1_square_2.00V.csv`; none with
/// `--ident-fixed`), then [`IDENT_RUNS`] runs of the input at it, each
/// saved under what ran (`runs/ident_square_4.78V_seed1.csv`). A probe
/// the rig halts at a travel limit lowers the amplitude; any other fault
/// in a probe stops here, named. A run the rig halts because the input was too big (a travel limit, the
/// drive saturated) is kept in [`RigInput::failed`] and the others go on;
/// any other fault, set-up failures and Ctrl-C stop here.
pub fn rig_runs(backend: &Backend) -> Result<(Vec<Run>, Source), Box<dyn std::error::Error>> {
    let ident = backend.ident;
    let limits = backend.calibration().travel_limits;
    let mut stats: Vec<LoopStats> = Vec::new();
    let choice = if ident.scale_to_travel {
        let mut n = 0;
        AmplitudeSearch::new(ident.volts, limits)?.run(
            |volts| -> Result<ProbeOutcome, Box<dyn std::error::Error>> {
                n += 1;
                // The runs' own signal (a multisine's lines are the run's
                // harmonics), for the probe's length.
                let input = ident.input(volts, IDENT_DURATION)?;
                let id = RunId::keyed(
                    format!("ident_probe{n}_{}_{volts:.2}V", ident.signal.name()),
                    format!("ident_probe_{n}"),
                );
                let outcome = backend.experiment(
                    &id,
                    100 + n,
                    OpenLoop,
                    |t| vector![input.value(t)],
                    PROBE_DURATION,
                )?;
                // A probe halted at a travel limit says "lower"; any other
                // fault stops the lab here, named (ProbeFault).
                Ok(ProbeOutcome::of(outcome.map(|out| out.recording))?)
            },
        )?
    } else {
        AmplitudeChoice::fixed(ident.volts, limits)
    };
    let input = ident.input(choice.volts, IDENT_DURATION)?;
    // The runs' names say what ran: the signal, its peak and the seed.
    let name = |seed: u64| {
        format!(
            "ident_{}_{:.2}V_seed{seed}",
            ident.signal.name(),
            choice.volts
        )
    };
    let collected = IdentRuns::collect(1..=IDENT_RUNS, |seed| {
        let outcome = backend.experiment(
            &RunId::keyed(name(seed), format!("ident_{seed}")),
            seed,
            OpenLoop,
            |t| vector![input.value(t)],
            IDENT_DURATION,
        )?;
        Ok::<_, Box<dyn std::error::Error>>(match outcome {
            Ok(out) => {
                stats.push(out.stats);
                Ok(out.recording)
            }
            Err(e) => {
                stats.push(e.stats.clone());
                Err(e)
            }
        })
    })?;
    let runs = collected
        .completed
        .into_iter()
        .map(|r| Run {
            name: name(r.seed),
            recording: r.recording,
        })
        .collect();
    let failed = collected
        .halted
        .into_iter()
        .map(|h| FailedRun {
            name: name(h.seed),
            error: h.error.to_string(),
            ran: h.recording.time().last().copied().unwrap_or(0.0),
            peaks: peaks(&h.recording).unwrap_or([f64::NAN; 2]),
        })
        .collect();
    let timing = backend.timing(&stats);
    let input = Box::new(RigInput {
        input: ident,
        choice,
        failed,
    });
    Ok((runs, Source::Rig { timing, input }))
}

/// Every `*.csv` file in `dir`, in file-name order, read with `options`.
pub fn log_runs(
    dir: &Path,
    options: &CsvOptions,
) -> Result<(Vec<Run>, Source), Box<dyn std::error::Error>> {
    let mut paths = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| format!("--logs {}: {e}", dir.display()))? {
        let path = entry?.path();
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("csv"))
        {
            paths.push(path);
        }
    }
    paths.sort();
    if paths.len() < 2 {
        return Err(format!(
            "--logs {}: found {} CSV file(s); the averages and the validation on a fresh run need at least two",
            dir.display(),
            paths.len()
        )
        .into());
    }
    let mut runs = Vec::new();
    for path in &paths {
        let recording = Recording::read_csv_with(path, options)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        let name = path
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
        runs.push(Run { name, recording });
    }
    let source = Source::Logs {
        dir: dir.to_path_buf(),
        metres_per_count: options.metres_per_count,
    };
    Ok((runs, source))
}

/// Tables 3 and 4 from `runs`: every run identified three ways, averaged.
/// Fewer than two runs (the rig halted the others) is an error that says
/// so.
pub fn identify(
    runs: Vec<Run>,
    source: Source,
) -> Result<Identification, Box<dyn std::error::Error>> {
    if let Source::Rig { input, .. } = &source
        && runs.len() < 2
    {
        // The rig halted the others: say which and why, not a bare error.
        return Err(Box::new(TooFewRuns {
            completed: runs.len(),
            total: runs.len() + input.failed.len(),
            halted: input
                .failed
                .iter()
                .map(|f| format!("{}: {}", f.name, f.error))
                .collect(),
        }));
    }
    let summary = summarize(runs.iter().map(|r| &r.recording), M1, M2).map_err(|e| match e {
        SummaryError::Run { run, source } => format!("run {}: {source}", runs[run].name),
        other => other.to_string(),
    })?;
    Ok(Identification {
        runs,
        source,
        summary,
        equal_springs: None,
    })
}

/// One more run on a card whose springs are equal and without Coulomb
/// friction (simulated rig only), where the lab's model is exact: the
/// schemes' own bias.
/// The square wave at `volts` (the identification's amplitude) with the
/// identification input's half period.
pub fn equal_springs(
    backend: &Backend,
    volts: f64,
) -> Result<Option<EqualSprings>, Box<dyn std::error::Error>> {
    let Some(sim) = backend.sim() else {
        return Ok(None);
    };
    // The lab's formulas assume k1 = k2 and no Coulomb friction. On a truth
    // where that holds, the only difference between the schemes is the
    // finite differences themselves.
    let card = EqualSprings::card(sim);
    let truth = card.truth;
    let wave = SquareWave::new(volts, backend.ident.half_period)?;
    let out = backend
        .with_sim(card)
        .experiment(
            &RunId::keyed(
                format!("ident_equal_springs_square_{volts:.2}V"),
                "ident_equal_springs",
            ),
            99,
            OpenLoop,
            |t| vector![wave.value(t)],
            IDENT_DURATION,
        )?
        .map_err(|e| format!("equal-springs run: {e}"))?;
    Ok(Some(EqualSprings::identify(&out.recording, truth, M1, M2)?))
}
