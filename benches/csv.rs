//! Reading a lab log: 1e6 rows of `t, u, x1, x2` (a 2 ms log of 33 min)
//! through `Recording::from_reader` (target < 1 s in release), the same log
//! as a file through `Recording::read_csv` (which sizes the columns from the
//! file's length), the file with `;` and decimal commas, and the log as
//! Excel writes it in a German locale (`;`, decimal commas, `\r\n`) with a
//! comment line every 1000 rows.

use criterion::{Criterion, criterion_group, criterion_main};
use ctrlab::Recording;
use ctrlab::data::CsvOptions;
use std::hint::black_box;

const ROWS: usize = 1_000_000;

/// The lab's log as its logger writes it: time in s to the millisecond, the
/// input in V, positions in mm to six decimals (as `ident_square_wave.csv`).
fn lab_log() -> String {
    let mut text = String::with_capacity(ROWS * 40);
    text.push_str("t_s,u,x1_mm,x2_mm\n");
    for k in 0..ROWS {
        let t = k as f64 * 0.002;
        let u = if (k / 100) % 2 == 0 { 2.0 } else { -2.0 };
        let x1 = 12.5 * (t * 3.1).sin();
        let x2 = 20.25 * (t * 2.3).cos();
        text.push_str(&format!("{t:.3},{u},{x1:.6},{x2:.6}\n"));
    }
    text
}

fn benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("csv");
    group.sample_size(10);
    let log = lab_log();
    group.bench_function("from_reader, 1e6 rows t,u,x1,x2 (comma)", |b| {
        b.iter(|| Recording::from_reader(black_box(log.as_bytes())).unwrap())
    });
    // The same log as a file (31 MB, written once into the temporary
    // directory, removed at the end).
    let path = std::env::temp_dir().join(format!("ctrlab_bench_{}.csv", std::process::id()));
    std::fs::write(&path, &log).unwrap();
    group.bench_function("read_csv, 1e6 rows t,u,x1,x2 (comma), a file", |b| {
        b.iter(|| Recording::read_csv(black_box(&path)).unwrap())
    });
    // As pandas is compared on it (scripts/ahead_csv.py): `;` and decimal
    // commas, `\n`, no comments.
    let semicolon = log.replace(',', ";").replace('.', ",");
    std::fs::write(&path, &semicolon).unwrap();
    group.bench_function(
        "read_csv, 1e6 rows t;u;x1;x2 (decimal commas), a file",
        |b| b.iter(|| Recording::read_csv(black_box(&path)).unwrap()),
    );
    std::fs::remove_file(&path).unwrap();
    let excel: String = log
        .replace(',', ";")
        .replace('.', ",")
        .lines()
        .enumerate()
        .map(|(k, line)| {
            if k % 1000 == 999 {
                format!("# {k} rows\r\n{line}\r\n")
            } else {
                format!("{line}\r\n")
            }
        })
        .collect();
    let options = CsvOptions::default();
    group.bench_function(
        "from_reader_with, 1e6 rows t;u;x1;x2 (decimal commas, CRLF, comments)",
        |b| b.iter(|| Recording::from_reader_with(black_box(excel.as_bytes()), &options).unwrap()),
    );
    group.finish();
}

criterion_group!(csv, benches);
criterion_main!(csv);
