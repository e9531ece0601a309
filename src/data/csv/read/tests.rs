//! The reader's internals: splitting, trimming, row estimates.

use super::columns::estimate_rows;
use super::records::split;
use super::*;
use csv_core::ReadRecordResult;

#[test]
fn fields_are_trimmed_as_str_trim_trims() {
    for text in [
        "",
        " ",
        "1.5",
        " 1.5\t",
        "\u{b}1\u{c}",
        "\u{a0}2\u{a0}",
        "\u{3000}3",
        "4\u{2003}",
        "\u{a0}",
        "é",
        " é5 ",
        "\u{1c}6",
        "7\u{85}",
        "\r\n8\n",
        "x",
        "\u{7f}",
        "-2e3 ",
    ] {
        assert_eq!(field_text(text.as_bytes()), Some(text.trim()), "{text:?}");
    }
    for text in ["1.5", "", " ", "-2e3 ", "\t", "\u{a0}1", "x", "\u{7f}", "é"] {
        assert_eq!(trim(text), text.trim(), "{text:?}");
    }
    assert_eq!(field_text(b"\xff"), None);
    assert_eq!(field_text(b" 1\xff5 "), None);
    assert_eq!(field_text(b"\xc2\xa0\xff"), None);
}

#[test]
fn a_file_sizes_its_columns_once() {
    let rows = 20_000;
    let mut text = String::from("t_s,u,x1_mm\n");
    for k in 0..rows {
        text += &format!("{},{},{}\n", k as f64 * 0.002, k % 7, (k as f64).sqrt());
    }
    let path = std::env::temp_dir().join(format!("ctrlab_sized_{}.csv", std::process::id()));
    std::fs::write(&path, &text).unwrap();
    let rec = Recording::read_csv(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(rec.len(), rows);
    // Sized from the first rows (shorter than the later ones here) and
    // the file's length, once: doubling would end at 32 768.
    let capacity = rec.capacity();
    assert!(capacity >= rows && capacity < rows + rows / 4, "{capacity}");
    assert_eq!(rec, Recording::from_reader(text.as_bytes()).unwrap());
}

proptest::proptest! {
    #[test]
    fn a_line_without_quotes_splits_as_the_tokenizer_splits_it(
        line in proptest::collection::vec(proptest::prop_oneof![
            proptest::sample::select(b",;\t 0.e-x#%\xff".to_vec()),
            proptest::prelude::any::<u8>(),
        ], 1..60),
        separator in proptest::sample::select(b",;\t".to_vec()),
    ) {
        let line: Vec<u8> = line.into_iter().filter(|b| !b"\"\r\n".contains(b)).collect();
        let mut bounds = Vec::new();
        proptest::prop_assert!(split(&line, separator, &mut bounds));
        let split: Vec<&[u8]> = bounds.iter().map(|&(a, b)| &line[a..b]).collect();
        // The tokenizer, given the line and its line break.
        let mut core = csv_core::ReaderBuilder::new().delimiter(separator).build();
        let (mut out, mut ends) = (vec![0; 256], vec![0; 128]);
        let input = [&line[..], b"\n"].concat();
        let (res, nin, _, n) = core.read_record(&input, &mut out, &mut ends);
        if line.is_empty() {
            return Ok(()); // an empty line is no record (a content line is never empty)
        }
        proptest::prop_assert_eq!(res, ReadRecordResult::Record);
        proptest::prop_assert_eq!(nin, input.len());
        let mut from = 0;
        let tokenized: Vec<&[u8]> = ends[..n].iter().map(|&end| { let f = &out[from..end]; from = end; f }).collect();
        proptest::prop_assert_eq!(split, tokenized);
    }
}

#[test]
fn a_line_with_a_quote_goes_to_the_tokenizer() {
    let mut bounds = Vec::new();
    assert!(!split(b"0,\"1,5\"", b',', &mut bounds));
    assert!(!split(b"0,1\"", b',', &mut bounds));
    assert!(split(b"0;1,5", b';', &mut bounds));
    assert_eq!(bounds, [(0, 1), (2, 5)]);
}

#[test]
fn the_row_estimate_is_bounded() {
    // 1e6 rows of 31 bytes, estimated from the first 256.
    let n = estimate_rows(31_000_000, 256 * 31 + 18, 256, 256 * 31, 4);
    assert!((1_000_000..1_060_000).contains(&n), "{n}");
    // Never more rows than the bytes can hold.
    assert!(estimate_rows(1000, 0, 256, 1, 4) <= 1000 / 7 + 1);
    assert_eq!(estimate_rows(100, 200, 256, 100, 4), 1);
}
