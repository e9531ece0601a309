//! Identifies the two-cart plant from a logged run (docs/lab.md, the lab's section 2.2 and
//! the report's question 1).
//!
//! ```text
//! cargo run --release --example identify -- path/to/log.csv --m1 1.3 --m2 0.7
//! cargo run --release --example identify            # the shipped fixture
//! ```
//!
//! Prints the estimates of both schemes (`Lab`: the lab's own formulas;
//! `Central`: without their half-sample bias) with standard errors and the
//! fit of each least-squares stage, then the identified state equations.
//! The CSV format is described at `ctrlab::Recording::from_reader`.

use std::fmt::Write as _;
use std::io::Write as _;
use std::process::ExitCode;

use ctrlab::Recording;
use ctrlab::ident::Covariance;
use ctrlab::lab::ident::{MassSpringEstimate, Scheme, identify};

const USAGE: &str = "usage: identify [LOG.csv] [--m1 KG] [--m2 KG]
  LOG.csv   recording with columns t_s, u, x1_mm|x1_m, x2_mm|x2_m
            (default: tests/data/ident_square_wave.csv)
  --m1 KG   mass of cart 1 in kg (default 1.3)
  --m2 KG   mass of cart 2 in kg (default 0.7)";

struct Args {
    path: String,
    m1: f64,
    m2: f64,
}

fn parse_args(mut args: impl Iterator<Item = String>) -> Result<Args, String> {
    let mut path = None;
    let (mut m1, mut m2) = (1.3, 0.7);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--m1" | "--m2" => {
                let text = args.next().ok_or(format!("{arg} needs a value"))?;
                let v: f64 = text
                    .parse()
                    .map_err(|_| format!("{arg}: `{text}` is not a number"))?;
                if !(v.is_finite() && v > 0.0) {
                    return Err(format!("{arg}: mass must be > 0 kg, got {v}"));
                }
                if arg == "--m1" {
                    m1 = v;
                } else {
                    m2 = v;
                }
            }
            "-h" | "--help" => return Err(String::new()),
            s if s.starts_with('-') => return Err(format!("unknown option {s}")),
            _ if path.is_some() => return Err(format!("unexpected argument {arg}")),
            _ => path = Some(arg),
        }
    }
    let path = path.unwrap_or_else(|| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/data/ident_square_wave.csv"
        )
        .to_string()
    });
    Ok(Args { path, m1, m2 })
}

fn print_estimate(out: &mut String, name: &str, e: &MassSpringEstimate) {
    writeln!(out, "{name} scheme:").unwrap_or_default();
    for (label, unit, p) in [
        // `identify` fits the lab's equal springs: k1 is k12.
        ("k12", "N/m", e.k1()),
        ("b1", "N s/m", e.b1),
        ("K", "N/V", e.gain),
        ("b2", "N s/m", e.b2),
    ] {
        writeln!(
            out,
            "  {label:>3} = {:>12.5} ± {:<10.5} {unit:<6} ({:.3} %)",
            p.value,
            p.std_error,
            100.0 * p.relative_error()
        )
        .unwrap_or_default();
    }
    for (stage, fit) in [
        ("stage 1 [k12, b1]", &e.first),
        ("stage 2 [K, b2]", &e.second),
    ] {
        let errors = match fit.covariance_kind {
            Covariance::NeweyWest { lags: Some(lags) } => format!("Newey–West, {lags} lags"),
            Covariance::NeweyWest { lags: None } => "Newey–West".to_string(),
            Covariance::Classical => "classical".to_string(),
        };
        writeln!(
            out,
            "  {stage:<18} fit {:6.2} %, R² {:.5}, condition {:.3e}, {} rows, errors {errors}",
            fit.fit_percent, fit.r_squared, fit.condition, fit.rows
        )
        .unwrap_or_default();
    }
}

/// Identifies and formats the report (written to a `String`, so a closed
/// pipe cannot interrupt it half way).
fn run(args: &Args) -> Result<String, Box<dyn std::error::Error>> {
    let rec = Recording::read_csv(&args.path)?;
    let mut out = String::new();
    let w = &mut out;
    writeln!(
        w,
        "{}: {} samples, T = {} ms, m1 = {} kg, m2 = {} kg\n",
        args.path,
        rec.len(),
        rec.sample_period()? * 1e3,
        args.m1,
        args.m2
    )
    .unwrap_or_default();
    let lab = identify(&rec, args.m1, args.m2, Scheme::Lab)?;
    let central = identify(&rec, args.m1, args.m2, Scheme::Central)?;
    print_estimate(w, "Lab (equations (6)-(11))", &lab);
    writeln!(w).unwrap_or_default();
    print_estimate(w, "Central (bias-free)", &central);
    writeln!(w).unwrap_or_default();
    writeln!(
        w,
        "Identified state equations (Central), x = [x1 m, x1' m/s, x2 m, x2' m/s], u in V, y = x2:"
    )
    .unwrap_or_default();
    let sys = central.state_space()?;
    write!(w, "{sys:.4}").unwrap_or_default();
    Ok(out)
}

fn main() -> ExitCode {
    let args = match parse_args(std::env::args().skip(1)) {
        Ok(a) => a,
        Err(msg) if msg.is_empty() => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(msg) => {
            eprintln!("error: {msg}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    match run(&args) {
        // A closed pipe (`| head`) is not worth a panic or an error.
        Ok(report) => match std::io::stdout().lock().write_all(report.as_bytes()) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("error: writing the report: {e}");
                ExitCode::FAILURE
            }
        },
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
