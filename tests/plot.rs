//! SVG figures (feature `plot`): content, thinning and errors.
#![cfg(feature = "plot")]

use ctrlab::Error;
use ctrlab::plot::{MAX_POINTS, PlotError, Series, responses_svg};

fn temp_svg(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("ctrlab-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn writes_title_labels_legend_and_one_line_per_series() {
    let t: Vec<f64> = (0..50).map(|k| k as f64 * 0.02).collect();
    let y1: Vec<f64> = t.iter().map(|t| t * 30.0).collect();
    let y2: Vec<f64> = t.iter().map(|t| 30.0 - t).collect();
    let path = temp_svg("two.svg");
    responses_svg(
        &path,
        "Two series",
        "t (s)",
        "x2 (mm)",
        &[
            Series::new("rising", &t, &y1),
            Series::new("falling", &t, &y2),
        ],
    )
    .unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    for text in ["Two series", "t (s)", "x2 (mm)", "rising", "falling"] {
        assert!(svg.contains(text), "missing {text}");
    }
    // Two data lines (legend swatches are separate short paths).
    let lines = svg.matches("<polyline").count();
    assert!(lines >= 2, "{lines} polylines");
}

#[test]
fn long_series_are_thinned() {
    let n = 10 * MAX_POINTS;
    let t: Vec<f64> = (0..n).map(|k| k as f64).collect();
    let path = temp_svg("long.svg");
    responses_svg(&path, "long", "t", "y", &[Series::new("ramp", &t, &t)]).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    let line = svg
        .split("<polyline")
        .skip(1)
        .map(|p| {
            p.split("points=\"")
                .nth(1)
                .unwrap_or("")
                .split('"')
                .next()
                .unwrap_or("")
        })
        .max_by_key(|pts| pts.len())
        .unwrap();
    let points = line.split_whitespace().count();
    assert!(
        points <= MAX_POINTS + 1 && points > MAX_POINTS / 2,
        "{points} points"
    );
}

#[test]
fn bad_series_and_unwritable_paths_are_errors() {
    let path = temp_svg("bad.svg");
    assert!(matches!(
        responses_svg(&path, "", "", "", &[Series::new("s", &[0.0, 1.0], &[0.0])]),
        Err(PlotError::Data(Error::LengthMismatch {
            expected: 2,
            found: 1,
            ..
        }))
    ));
    assert!(matches!(
        responses_svg(&path, "", "", "", &[Series::new("s", &[f64::NAN], &[0.0])]),
        Err(PlotError::Data(Error::InvalidData { .. }))
    ));
    assert!(matches!(
        responses_svg(&path, "", "", "", &[]),
        Err(PlotError::Data(Error::InvalidData { .. }))
    ));
    let nowhere = temp_svg("no/such/dir/x.svg");
    assert!(matches!(
        responses_svg(
            &nowhere,
            "",
            "",
            "",
            &[Series::new("s", &[0.0, 1.0], &[0.0, 1.0])]
        ),
        Err(PlotError::Write { .. })
    ));
    // The backend's I/O error is kept as the source, and the path is named.
    let err = responses_svg(
        &nowhere,
        "",
        "",
        "",
        &[Series::new("s", &[0.0, 1.0], &[0.0, 1.0])],
    )
    .unwrap_err();
    assert!(err.to_string().contains("no/such/dir"), "{err}");
    assert!(std::error::Error::source(&err).is_some());
}
