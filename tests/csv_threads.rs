//! A large file read by `Recording::read_csv`, on a thread per CPU, reads
//! as the same file read on the calling thread (`from_reader_with` on the
//! opened file): the same values bit for bit, the same errors on the same
//! lines, wherever in the file the blocks and parts are cut.

use std::fs::File;
use std::path::PathBuf;

use ctrlab::Recording;
use ctrlab::data::{CsvError, CsvOptions};

/// 160 000 rows of the lab's log (about 5 MB: over the 4 MiB from which a
/// file is read on several threads), with `edit` applied to each row
/// `(index, row)`.
fn log(edit: impl Fn(usize, String) -> String) -> String {
    let mut text = String::from("t_s;u_V;x1 [mm];x2_mm\n");
    for k in 0..160_000 {
        let t = k as f64 * 0.002;
        let x1 = 12.5 * (t * 3.1).sin();
        let x2 = 20.25 * (t * 2.3).cos();
        let row = format!(
            "{t:.3};{};{x1:.6};{x2:.6}",
            if k % 200 < 100 { 2 } else { -2 }
        );
        text += &edit(k, row.replace('.', ","));
        text.push('\n');
    }
    text
}

/// A read's outcome: the bits of every value per channel, or the error's
/// text.
type Outcome = Result<Vec<Vec<u64>>, String>;

/// `text` in a temporary file, read both ways: each outcome as the bits of
/// every value, or the error's text.
fn both_ways(name: &str, text: &str) -> (Outcome, Outcome) {
    let path: PathBuf =
        std::env::temp_dir().join(format!("ctrlab_threads_{}_{name}.csv", std::process::id()));
    std::fs::write(&path, text).unwrap();
    let outcome = |r: Result<Recording, CsvError>| {
        r.map(|rec| {
            ["t", "u", "x1", "x2"]
                .iter()
                .map(|name| match *name {
                    "t" => rec.time(),
                    name => rec.channel(name).unwrap(),
                })
                .map(|c| c.iter().map(|v| v.to_bits()).collect())
                .collect()
        })
        .map_err(|e| e.to_string())
    };
    let threads = outcome(Recording::read_csv(&path));
    let one = outcome(Recording::from_reader_with(
        File::open(&path).unwrap(),
        &CsvOptions::default(),
    ));
    std::fs::remove_file(&path).unwrap();
    (threads, one)
}

#[test]
fn a_large_log_reads_as_on_one_thread() {
    let (threads, one) = both_ways("clean", &log(|_, row| row));
    let cols = one.clone().unwrap();
    assert_eq!(cols[0].len(), 160_000);
    // Row 150 000 (in the threads' blocks): x1 as written, in m.
    let x1: f64 = format!("{:.6}", 12.5 * (300.0f64 * 3.1).sin())
        .parse()
        .unwrap();
    assert_eq!(f64::from_bits(cols[2][150_000]), x1 / 1000.0);
    assert_eq!(threads, one);
}

#[test]
fn errors_deep_in_a_large_log_name_the_same_line() {
    // Rows spread over the file, so that some fall on the first and last
    // rows of the threads' parts.
    for (bad, why) in [
        (41_234usize, "not a number"),
        (99_999, "does not increase"),
        (159_999, "fields"),
    ] {
        let text = log(|k, row| match (k == bad, why) {
            (true, "not a number") => row.replacen("2;", "2x;", 1),
            (true, "does not increase") => format!("0{}", &row[row.find(';').unwrap()..]),
            (true, _) => row + ";1",
            _ => row,
        });
        let (threads, one) = both_ways("bad", &text);
        let err = one.clone().unwrap_err();
        assert!(err.starts_with(&format!("CSV line {}: ", bad + 2)), "{err}");
        assert!(err.contains(why), "{err}");
        assert_eq!(threads, one);
    }
}

#[test]
fn comments_in_a_large_log_read_as_on_one_thread() {
    let text = log(|k, row| {
        if k % 25_000 == 24_999 {
            format!("# {k} rows\n{row}")
        } else {
            row
        }
    });
    let (threads, one) = both_ways("comments", &text);
    assert_eq!(one.clone().unwrap()[0].len(), 160_000);
    assert_eq!(threads, one);
}

#[test]
fn unusual_large_logs_read_as_on_one_thread() {
    let cases: [(&str, String); 5] = [
        // Windows line breaks throughout.
        ("crlf", log(|_, row| row + "\r")),
        // A quoted value, an exponent and padded fields late in the file.
        (
            "quoted",
            log(|k, row| match k {
                120_001 => row
                    .replacen(";2;", ";\"2\";", 1)
                    .replacen(";-2;", ";\"-2\";", 1),
                130_002 => row
                    .replacen(";2;", ";2e0;", 1)
                    .replacen(";-2;", ";-2e0;", 1),
                140_003 => row.replace(';', " ; "),
                _ => row,
            }),
        ),
        // Old Mac line breaks: no `\n` at all (each row once searched the
        // rest of the buffer for one: 6 s for these 5 MB, now 0.07 s).
        ("cr", log(|_, row| row).replace('\n', "\r")),
        // One line of 5 MB after the header: a row with far too many fields.
        ("long", format!("t_s;u;x1_m\n{}\n", "1;".repeat(2_500_000))),
        // Blank lines between every row.
        ("blank", log(|_, row| row + "\n")),
    ];
    for (name, text) in cases {
        let (threads, one) = both_ways(name, &text);
        assert_eq!(threads, one, "{name}");
        match name {
            "long" => assert!(one.unwrap_err().contains("fields"), "{name}"),
            _ => assert_eq!(one.unwrap()[0].len(), 160_000, "{name}"),
        }
    }
}
