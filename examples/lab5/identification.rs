//! The identification runs, on the rig or from a student's own logs
//! (`--logs DIR`), identified into Tables 3 and 4 and the model
//! (`lab::ident::summarize`); and the equal-springs run on a simulated rig.

use std::path::{Path, PathBuf};

use ctrlab::data::CsvOptions;
use ctrlab::hw::LoopStats;
use ctrlab::lab::MassSpring;
use ctrlab::lab::ident::{EqualSprings, Summary, SummaryError, summarize};
use ctrlab::lab::protocol::{IDENT_DURATION, IDENT_RUNS, M1, M2, ident_square_wave};
use ctrlab::nalgebra::vector;
use ctrlab::signal::Signal;
use ctrlab::{OpenLoop, Recording};

use crate::backend::{Backend, LoopTiming};

/// One identification run: its name (the CSV file's stem) and recording.
pub struct Run {
    pub name: String,
    pub recording: Recording,
}

/// Where the runs come from.
pub enum Source {
    /// [`IDENT_RUNS`] runs of the square wave on the rig, and the loop's
    /// timing when it ran in real time.
    Rig { timing: Option<LoopTiming> },
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

    /// The runs' recordings, in order.
    pub fn recordings(&self) -> Vec<&Recording> {
        self.runs.iter().map(|r| &r.recording).collect()
    }
}

/// The lab's identification runs on the rig: [`IDENT_RUNS`] runs of the
/// square wave, each saved as `runs/ident_{seed}.csv`.
pub fn rig_runs(backend: &Backend) -> Result<(Vec<Run>, Source), Box<dyn std::error::Error>> {
    let wave = ident_square_wave()?;
    let mut runs = Vec::new();
    let mut stats: Vec<LoopStats> = Vec::new();
    for seed in 1..=IDENT_RUNS {
        let name = format!("ident_{seed}");
        let out = backend
            .experiment(
                &name,
                seed,
                OpenLoop,
                |t| vector![wave.value(t)],
                IDENT_DURATION,
            )?
            .map_err(|e| format!("identification run {seed}: {e}"))?;
        stats.push(out.stats);
        runs.push(Run {
            name,
            recording: out.recording,
        });
    }
    let timing = backend.timing(&stats);
    Ok((runs, Source::Rig { timing }))
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
pub fn identify(
    runs: Vec<Run>,
    source: Source,
) -> Result<Identification, Box<dyn std::error::Error>> {
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
pub fn equal_springs(
    backend: &Backend,
) -> Result<Option<EqualSprings>, Box<dyn std::error::Error>> {
    let Some(sim) = backend.sim() else {
        return Ok(None);
    };
    // The lab's formulas assume k1 = k2 and no Coulomb friction. On a truth
    // where that holds, the only difference between the schemes is the
    // finite differences themselves.
    let card = EqualSprings::card(sim);
    let truth = card.truth;
    let wave = ident_square_wave()?;
    let out = backend
        .with_sim(card)
        .experiment(
            "ident_equal_springs",
            99,
            OpenLoop,
            |t| vector![wave.value(t)],
            IDENT_DURATION,
        )?
        .map_err(|e| format!("equal-springs run: {e}"))?;
    Ok(Some(EqualSprings::identify(&out.recording, truth, M1, M2)?))
}
