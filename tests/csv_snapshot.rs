//! What the CSV reader makes of every log it has ever been shown, pinned bit
//! for bit: every CSV under `tests/data/` (with and without a calibration),
//! the fuzz target's seeds, variants of the logs (line breaks, byte-order
//! mark, quotes, padding, comments, the faults the other tests build), the
//! bench's logs in small, and some thousand seeded random log-like texts and
//! mutations of a valid log.
//!
//! `tests/data/csv_snapshot.txt` holds one line per case: for a recording,
//! its channels and a hash of the bits of every value (time first, then each
//! channel; the sign of zero and every last bit count); for an error, its
//! line and its message. It was written by the reader built on the `csv`
//! crate, before the port to `csv-core`; the test fails on any case whose
//! outcome differs.
//!
//! Rewrite it only for a change meant to alter what a file reads as:
//! `CTRLAB_UPDATE_CSV_SNAPSHOT=1 cargo test --release --test csv_snapshot`.

use ctrlab::data::{CsvError, CsvOptions};
use ctrlab::{Error, Recording};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

const SNAPSHOT: &str = "tests/data/csv_snapshot.txt";

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn calibrated() -> CsvOptions {
    CsvOptions {
        metres_per_count: Some(1.0 / 102_400.0),
    }
}

/// FNV-1a, 64 bits: a hash that does not change with the Rust version.
struct Fnv(u64);

impl Fnv {
    fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
    fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
    }
}

/// One line of the snapshot: the recording's shape and the hash of every
/// value's bits, or the error's line and message.
fn outcome(result: Result<Recording, CsvError>) -> String {
    match result {
        Ok(rec) => {
            let mut h = Fnv::new();
            let mut channels = String::new();
            for c in rec.schema().channels() {
                write!(channels, " {}({})", c.name, c.unit).unwrap();
            }
            h.bytes(channels.as_bytes());
            for v in rec.time() {
                h.bytes(&v.to_bits().to_le_bytes());
            }
            for c in rec.schema().channels() {
                for v in rec.channel(&c.name).unwrap() {
                    h.bytes(&v.to_bits().to_le_bytes());
                }
            }
            format!(
                "ok rows={} inputs={} channels:{channels} bits={:016x}",
                rec.len(),
                rec.schema().inputs().len(),
                h.0
            )
        }
        Err(CsvError::Line { line, reason }) => format!("line {line}: {reason:?}"),
        Err(CsvError::Options {
            source: Error::InvalidParameter { name, .. },
        }) => format!("options: {name}"),
        Err(e) => format!("other: {e:?}"),
    }
}

/// Whether an old and a new outcome agree. Invalid UTF-8 in a row was the
/// `csv` crate's message (its record and line counts, which ignore comment
/// lines); there the line must agree, not the wording.
fn agree(want: &str, got: &str) -> bool {
    if want == got {
        return true;
    }
    let line = |s: &str| s.split(':').next().map(str::to_string);
    want.contains("invalid utf-8") && want.starts_with("line ") && line(want) == line(got)
}

/// A case: its name, its bytes, and whether it is read with the
/// calibration.
struct Case {
    name: String,
    bytes: Vec<u8>,
    counts: bool,
}

fn case(name: impl Into<String>, bytes: impl Into<Vec<u8>>, counts: bool) -> Case {
    Case {
        name: name.into(),
        bytes: bytes.into(),
        counts,
    }
}

/// Every file under `dir` ending in `.csv` or `.tsv`, sorted.
fn logs_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "csv" || e == "tsv") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// xorshift64*: seeded, the same on every platform.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

const TIME_HEADERS: [&str; 8] = [
    "t_s", "T_s", "t [s]", "Time (s)", "time_s", "t_ms", "T [ms]", " t_s ",
];
const CHANNEL_HEADERS: [&str; 12] = [
    "u",
    "U_V",
    "x1_mm",
    "X2 [m]",
    "v1 [mm/s]",
    "x3_counts",
    "x4 [cnt]",
    "y [deg]",
    "w (rad/s)",
    "u2",
    "\"x5_mm\"",
    "x1_m",
];
const JUNK: [&str; 22] = [
    "1.234,5",
    "1,2,3",
    "nan",
    "inf",
    "-0",
    "1e308",
    "-1e309",
    "",
    " ",
    "\"1,5\"",
    "#",
    "%",
    "\"",
    "x",
    "\"2.5\"",
    "\" 3 \"",
    "\"4\"\"\"",
    "\"0.5\n\"",
    "\"#\n1\"",
    "\"1\r\n\"",
    "\u{a0}7\u{a0}",
    "\u{3000}8",
];

/// A data cell: mostly numbers, now and then something that is not one.
fn cell(rng: &mut Rng) -> String {
    match rng.below(20) {
        0..14 => format!("{}", -1e4 + 2e4 * rng.unit()),
        14..17 => format!("{:e}", f64::from_bits(rng.next())),
        17..19 => format!("{}", f64::from_bits(rng.next())),
        _ => rng.pick(&JUNK).to_string(),
    }
}

/// A log as a logger or a spreadsheet might write it, faults included.
fn log_like(rng: &mut Rng) -> (String, bool) {
    let time = *rng.pick(&TIME_HEADERS);
    let mut header: Vec<&str> = CHANNEL_HEADERS
        .iter()
        .copied()
        .filter(|_| rng.below(3) == 0)
        .take(5)
        .collect();
    if header.is_empty() {
        header.push("u");
    }
    let time_at = rng.below(header.len() + 1);
    header.insert(time_at, time);
    let width = header.len();
    let separator = *rng.pick(&[",", ";", "\t", ", "]);
    let breaks = *rng.pick(&["\n", "\r\n", "\r"]);
    let random_dt = 1e-9 + 10.0 * rng.unit();
    let dt = *rng.pick(&[0.002, random_dt, 1e300, 5e-324, 0.5]);
    let rows = rng.below(12);
    let mut lines = vec![header.join(separator)];
    for k in 0..rows {
        let mut row: Vec<String> = (1..width).map(|_| cell(rng)).collect();
        let t = if rng.below(30) == 0 {
            "q".to_string()
        } else {
            format!("{}", k as f64 * dt)
        };
        row.insert(time_at, t);
        if rng.below(25) == 0 {
            row.pop();
        }
        let row = row.join(separator);
        lines.push(if separator.starts_with(',') {
            row
        } else {
            row.replace('.', ",")
        });
    }
    for _ in 0..rng.below(4) {
        let at = rng.below(lines.len() + 1);
        let extra = *rng.pick(&["# c", "% c, \"x", "", "  \t", "#", " # t_s,u", "\u{feff}"]);
        lines.insert(at, extra.to_string());
    }
    let mut text = lines.join(breaks);
    if rng.below(2) == 0 {
        text.push_str(breaks);
    }
    if rng.below(15) == 0 {
        text.insert(0, '\u{feff}');
    }
    (text, rng.below(4) != 0)
}

/// A valid log of `rows` rows, to be mutated.
fn valid_log(rng: &mut Rng) -> Vec<u8> {
    let semicolons = rng.below(2) == 0;
    let (sep, point) = if semicolons { (";", ",") } else { (",", ".") };
    let mut text = ["t_s", "u_V", "x1_mm", "x2_m"].join(sep) + "\n";
    for k in 0..2 + rng.below(10) {
        let row = [
            format!("{}", k as f64 * 0.002),
            format!("{}", -1e3 + 2e3 * rng.unit()),
            format!("{}", -1e3 + 2e3 * rng.unit()),
            format!("{:e}", rng.unit()),
        ];
        text += &row.map(|v| v.replace('.', point)).join(sep);
        text.push('\n');
        if rng.below(5) == 0 {
            text += "# note\n";
        }
    }
    text.into_bytes()
}

const INTERESTING: [u8; 16] = [
    b'\n', b'\r', b'"', b',', b';', b'\t', b'#', b'%', b' ', 0xff, 0xc3, 0xa0, b'e', b'-', b'.',
    b'0',
];

/// `bytes` with a few bytes replaced, inserted or removed.
fn mutate(rng: &mut Rng, mut bytes: Vec<u8>) -> Vec<u8> {
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(bytes.len() + 1);
        let b = if rng.below(4) == 0 {
            rng.next() as u8
        } else {
            *rng.pick(&INTERESTING)
        };
        match rng.below(3) {
            0 if at < bytes.len() => bytes[at] = b,
            1 => bytes.insert(at, b),
            _ if at < bytes.len() => {
                bytes.remove(at);
            }
            _ => bytes.push(b),
        }
    }
    bytes
}

/// The bench's lab log (`benches/csv.rs`), `rows` rows.
fn lab_log(rows: usize) -> String {
    let mut text = String::from("t_s,u,x1_mm,x2_mm\n");
    for k in 0..rows {
        let t = k as f64 * 0.002;
        let u = if (k / 100) % 2 == 0 { 2.0 } else { -2.0 };
        let x1 = 12.5 * (t * 3.1).sin();
        let x2 = 20.25 * (t * 2.3).cos();
        writeln!(text, "{t:.3},{u},{x1:.6},{x2:.6}").unwrap();
    }
    text
}

/// The bench's log as Excel writes it in a German locale.
fn excel_log(rows: usize) -> String {
    lab_log(rows)
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
        .collect()
}

/// The lab's log of `tests/data_csv.rs`.
const GOOD: &str = "t_s,u,x1_mm,x2_mm
0.000,2,0,0
0.002,2,0,0.048828125
0.004,2,0,0.1953125
0.006,2,0.009765625,0.4296875
0.008,2,0.029296875,0.751953125
0.010,2,0.068359375,1.1572265625
";

/// Variants of a log's text: other line breaks, a byte-order mark, no last
/// line break, quoted fields, padded fields, comments between rows.
fn variants(name: &str, text: &str, counts: bool, cases: &mut Vec<Case>) {
    let lf = text.replace("\r\n", "\n");
    let sep = if lf.lines().next().unwrap_or("").contains(',') {
        ','
    } else if lf.lines().next().unwrap_or("").contains('\t') {
        '\t'
    } else {
        ';'
    };
    let quoted: String = lf
        .lines()
        .map(|l| {
            if l.starts_with(['#', '%']) || l.trim().is_empty() {
                format!("{l}\n")
            } else {
                let fields: Vec<String> = l.split(sep).map(|f| format!("\"{f}\"")).collect();
                format!("{}\n", fields.join(&sep.to_string()))
            }
        })
        .collect();
    let padded: String = lf
        .lines()
        .map(|l| {
            let fields: Vec<String> = l.split(sep).map(|f| format!(" {f}\t")).collect();
            format!("{}\n", fields.join(&sep.to_string()))
        })
        .collect();
    let commented: String = lf
        .lines()
        .enumerate()
        .map(|(k, l)| match k % 4 {
            0 => format!("{l}\n# row {k}\n"),
            1 => format!("{l}\n\n"),
            2 => format!("  % {k}\n{l}\n \t\n"),
            _ => format!("{l}\n"),
        })
        .collect();
    let all = [
        ("lf", lf.clone()),
        ("crlf", lf.replace('\n', "\r\n")),
        ("cr", lf.replace('\n', "\r")),
        ("bom", format!("\u{feff}{lf}")),
        ("bom_crlf", format!("\u{feff}{}", lf.replace('\n', "\r\n"))),
        ("no_last_break", lf.trim_end_matches('\n').to_string()),
        ("quoted", quoted),
        ("padded", padded),
        ("commented", commented),
        ("lf_cr_mixed", lf.replacen('\n', "\r", 2)),
    ];
    for (what, t) in all {
        cases.push(case(format!("{name} [{what}]"), t, counts));
    }
}

fn cases() -> Vec<Case> {
    let mut cases = Vec::new();
    let data = root().join("tests/data");
    for path in logs_under(&data) {
        let name = path.strip_prefix(root()).unwrap().display().to_string();
        let bytes = std::fs::read(&path).unwrap();
        for counts in [false, true] {
            cases.push(case(
                format!("{name} counts={counts}"),
                bytes.clone(),
                counts,
            ));
        }
        if bytes.len() < 4096 {
            let text = String::from_utf8(bytes).unwrap();
            variants(&name, &text, true, &mut cases);
        }
    }
    let mut seeds: Vec<PathBuf> = std::fs::read_dir(root().join("fuzz/seeds/csv_identify"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    seeds.sort();
    for path in seeds {
        let name = path.strip_prefix(root()).unwrap().display().to_string();
        cases.push(case(name, std::fs::read(&path).unwrap(), false));
    }

    // The faults and spellings other tests build.
    let comments = std::fs::read_to_string(data.join("logs/comments.csv")).unwrap();
    for (row, what) in [
        ("0.000,", "5"),
        ("0.002,", "6"),
        ("0.004,", "9"),
        ("0.010,", "13"),
    ] {
        let bad = comments.replace(&format!("{row}2.5"), &format!("{row}2.5x"));
        let bad = bad.replace(&format!("{row}-2.5"), &format!("{row}-2.5x"));
        cases.push(case(format!("comments.csv bad on line {what}"), bad, false));
    }
    cases.push(case(
        "comments.csv time back",
        comments.replace("0.008,", "0.003,"),
        false,
    ));
    cases.push(case(
        "comments.csv t without unit",
        comments.replace("t_s,", "t,"),
        false,
    ));
    let excel = std::fs::read_to_string(data.join("logs/semicolon_decimal_comma.csv")).unwrap();
    cases.push(case(
        "semicolon_decimal_comma.csv bad",
        excel.replace("0,006;-2,5", "0,006;-2,5V"),
        false,
    ));
    let good_variants = [
        ("x1 in m and mm", GOOD.replace("t_s,u,", "t_s,u,x1_m,")),
        (
            "zero",
            GOOD.replace("0.004,2,0,0.1953125", "0.004,2,zero,0.1953125"),
        ),
        ("NaN", GOOD.replace("0.006,2,", "0.006,NaN,")),
        ("inf", GOOD.replace("0.006,2,", "0.006,inf,")),
        (
            "short row",
            GOOD.replace("0.002,2,0,0.048828125", "0.002,2,0"),
        ),
        ("time back", GOOD.replace("0.006,", "0.003,")),
        ("time repeated", GOOD.replace("0.006,", "0.004,")),
        ("late", GOOD.replace("0.008,", "0.0085,")),
        ("time_stamp", GOOD.replace("t_s,", "time_stamp,")),
        ("t", GOOD.replace("t_s,", "t,")),
        ("x3", GOOD.replace("x2_mm", "x3_mm")),
        ("x1 no unit", GOOD.replace("x1_mm", "x1")),
        ("one row", GOOD.lines().take(2).map(|l| format!("{l}\n")).collect()),
        ("header only", "t_s,u,x1_m,x2_m\n".to_string()),
        ("empty", String::new()),
        ("t_s,u,t_ms", "t_s,u,t_ms\n0,1,0\n0.002,1,2\n".to_string()),
        (
            "bracketed",
            "t [ms], u [V] ,x1 [mm],v1 [mm/s],angle [deg],w (rad/s)\n0,1.5,1,10,90,0.5\n\
             2,1.5,2,20,45,0.25\n4,-1.5,4,-30,0,0\n"
                .to_string(),
        ),
        ("only comments", "# a\n\n% b\n".to_string()),
        ("blank then x,u", "\n\nx,u\n0,1\n1,1\n".to_string()),
        ("blank then t_s,u", "\n\nt_s,u\n0,1\n0,1\n".to_string()),
        ("time_ms_x", "time_ms_x,u,x1_m\n0,1,2\n1,1,2\n".to_string()),
        ("quoted comma", "t_s,u\n0,1\n0.002,\"0,5\"\n".to_string()),
        ("two commas", "t_s;u\n0;1\n0,002;1,234,5\n".to_string()),
        ("comma point", "t_s;u\n0;1\n0,002;1,234.5\n".to_string()),
        ("point in ;", "t_s;u\n0;1.5\n0,002;2,5\n".to_string()),
        ("tab short", "t_s\tu\tx1_mm\n0\t1\t2\n0,002\t1\n".to_string()),
        ("upper", "T_s,U,X1\n0,1,2\n1,1,2\n".to_string()),
        ("case twice", "t_s,x1_mm,X1_m\n0,1,2\n1,1,2\n".to_string()),
        ("bom only", "\u{feff}".to_string()),
        ("two boms", "\u{feff}\u{feff}t_s,u\n0,1\n1,2\n".to_string()),
        ("bom line", "\u{feff}\u{feff}\n0,1\nt_s,u\n1,2\n".to_string()),
        ("bom line cr", "\u{feff}\u{feff}\rt_s,u\r0,1\r1,2\r".to_string()),
        (
            "quoted newline",
            "t_s,u\n0,\"1\n\"\n1,2\n".to_string(),
        ),
        (
            "quoted comment",
            "t_s,u\n0,\"1\n# c\n\"\n1,2\n".to_string(),
        ),
        (
            "quoted cr",
            "t_s,u\r0,\"1\r\r\"\r1,2\r".to_string(),
        ),
        ("quoted header", "\"t_s\",\"u\nv\"\n0,1\n1,2\n".to_string()),
        ("unterminated quote", "t_s,u\n0,1\n1,\"2\n".to_string()),
        ("nbsp", "t_s,u\n0,\u{a0}1\u{a0}\n1,\u{2003}2\n".to_string()),
        ("vt ff", "t_s,u\n0,\u{b}1\u{c}\n1,2\n".to_string()),
        (
            "huge",
            "t_s,u,x1_m,x2_m\n-1e308,0,0,0\n1e308,0,0,0\n-1e308,0,0,0\n".to_string(),
        ),
        (
            "overflowing interval",
            "t_s,u,x1_m,x2_m\n-1e308,0,0,0\n1e308,0,0,0\n1.1e308,0,0,0\n".to_string(),
        ),
        ("empty header", " , \n0,1\n1,2\n".to_string()),
        ("no time", "u,x\n0,1\n1,2\n".to_string()),
        ("Zeit", "Zeit [s];u [V]\n0;1\n1;2\n".to_string()),
        ("counts", "t_s,u_V,x1_counts\n0,2,0\n0.002,2,512\n".to_string()),
        (
            "all units",
            "t_s,a_mm_s,b_m_s,c_rad_s,d_mm,e_ms,f_m,g_s,h_V,i_N,j_rad,k [MM],l [v],m [RAD/s],n (S)\n\
             0,1,1,1,1,1,1,1,1,1,1,1,1,1,1\n1,2,2,2,2,2,2,2,2,2,2,2,2,2,2\n"
                .to_string(),
        ),
    ];
    for (name, text) in good_variants {
        cases.push(case(format!("built: {name}"), text.clone(), false));
        cases.push(case(format!("built: {name} [counts]"), text, true));
    }
    let mut utf8 = GOOD.as_bytes().to_vec();
    utf8[GOOD.find("0.002").unwrap()] = 0xff;
    cases.push(case("built: invalid utf-8 row", utf8, false));
    let mut utf8 = GOOD.as_bytes().to_vec();
    utf8[1] = 0xff;
    cases.push(case("built: invalid utf-8 header", utf8, false));

    // The bench's logs, in small.
    cases.push(case("bench lab log 5000", lab_log(5000), false));
    cases.push(case("bench excel log 5000", excel_log(5000), false));

    // Seeded random logs, mutations of valid logs, and random bytes.
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for k in 0..1000 {
        let (text, counts) = log_like(&mut rng);
        cases.push(case(format!("random log {k}"), text, counts));
    }
    for k in 0..600 {
        let log = valid_log(&mut rng);
        cases.push(case(
            format!("mutated log {k}"),
            mutate(&mut rng, log),
            false,
        ));
    }
    for k in 0..200 {
        let n = rng.below(120);
        let bytes: Vec<u8> = (0..n)
            .map(|_| {
                if rng.below(3) == 0 {
                    rng.next() as u8
                } else {
                    *rng.pick(b"t_s,u;x1\t\n\r\"#% 0123456789.e-")
                }
            })
            .collect();
        cases.push(case(format!("random bytes {k}"), bytes, k % 2 == 0));
    }
    cases
}

fn read(case: &Case) -> String {
    let options = if case.counts {
        calibrated()
    } else {
        CsvOptions::default()
    };
    outcome(Recording::from_reader_with(&case.bytes[..], &options))
}

#[test]
fn every_log_reads_as_it_did_bit_for_bit() {
    let cases = cases();
    let lines: Vec<String> = cases
        .iter()
        .map(|c| format!("{:?}\t{}", c.name, read(c)))
        .collect();
    let path = root().join(SNAPSHOT);
    if std::env::var_os("CTRLAB_UPDATE_CSV_SNAPSHOT").is_some() {
        std::fs::write(&path, lines.join("\n") + "\n").unwrap();
        return;
    }
    let want = std::fs::read_to_string(&path).unwrap();
    let want: Vec<&str> = want.lines().collect();
    assert_eq!(want.len(), lines.len(), "number of cases");
    let mut diffs = Vec::new();
    for (w, g) in want.iter().zip(&lines) {
        let (wn, wo) = w.split_once('\t').unwrap();
        let (gn, go) = g.split_once('\t').unwrap();
        assert_eq!(wn, gn, "the cases are generated in the same order");
        if !agree(wo, go) {
            diffs.push(format!("{wn}\n  was {wo}\n  now {go}"));
        }
    }
    assert!(
        diffs.is_empty(),
        "{} of {} cases differ:\n{}",
        diffs.len(),
        lines.len(),
        diffs.join("\n")
    );
    // The snapshot is not trivial: recordings and errors both.
    let ok = want.iter().filter(|l| l.contains("\tok ")).count();
    assert!(ok > 300 && want.len() - ok > 300, "{ok} of {}", want.len());
}

#[test]
fn files_read_by_path_as_from_bytes() {
    // `read_csv_with` reads as `from_reader_with` on the file's bytes.
    for path in logs_under(&root().join("tests/data")) {
        let bytes = std::fs::read(&path).unwrap();
        for options in [CsvOptions::default(), calibrated()] {
            let by_path = outcome(Recording::read_csv_with(&path, &options));
            let by_bytes = outcome(Recording::from_reader_with(&bytes[..], &options));
            assert_eq!(by_path, by_bytes, "{}", path.display());
        }
    }
}
