//! Figures people read (issue 27): every SVG the crate and lab5 write has
//! no two text boxes overlapping, and every legend entry's curve drawn and
//! in sight (not hidden under curves drawn after it).
//!
//! The checks read the SVG as plotters writes it: `<text>` with x, y, dy
//! (0.76em: y is the top; 0.5ex: the middle; -0.5ex: the bottom; none: the
//! baseline), text-anchor, font-size and an optional rotate(θ, x, y);
//! `<polyline>`s with stroke, stroke-width and points; `<circle>`s. A
//! text's box is 0.6 × font-size per character wide and one font-size
//! tall. A legend swatch is a short horizontal polyline (or a small
//! circle) with a start-anchored text just to its right; its curve is a
//! polyline (circles) of the same colour that is not a swatch.
//!
//! `the_lab5_figures` is ignored by default: it needs lab5's output, in
//! `LAB5_FIGURES` (a directory) or from the release binary (`cargo build
//! --release --example lab5`), run on a temporary directory.
#![cfg(all(feature = "plot", feature = "lab"))]

#[path = "common/example.rs"]
mod example;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A text's box, px: left, top, right, bottom.
#[derive(Debug, Clone)]
struct TextBox {
    text: String,
    rect: [f64; 4],
    font: f64,
    anchor_start: bool,
    y_mid: f64,
}

/// A polyline: colour, width, points; its index in drawing order.
#[derive(Debug, Clone)]
struct Line {
    color: String,
    width: f64,
    points: Vec<(f64, f64)>,
    order: usize,
}

/// A circle: fill colour, centre, radius.
#[derive(Debug, Clone)]
struct Dot {
    color: String,
    centre: (f64, f64),
    r: f64,
}

#[derive(Debug, Default)]
struct Svg {
    texts: Vec<TextBox>,
    lines: Vec<Line>,
    dots: Vec<Dot>,
}

fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let end = tag[start..].find('"')? + start;
    Some(&tag[start..end])
}

fn num(tag: &str, name: &str) -> f64 {
    attr(tag, name).and_then(|v| v.parse().ok()).unwrap_or(0.0)
}

fn unescape(s: &str) -> String {
    s.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&#39;", "'")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

fn parse(svg: &str) -> Svg {
    let mut out = Svg::default();
    let mut rest = svg;
    let mut order = 0;
    while let Some(i) = rest.find('<') {
        rest = &rest[i..];
        let Some(end) = rest.find('>') else { break };
        let tag = &rest[..=end];
        order += 1;
        if tag.starts_with("<text") {
            let close = rest.find("</text>").unwrap_or(end);
            let text = unescape(rest[end + 1..close].trim());
            out.texts.push(text_box(tag, text));
            rest = &rest[close..];
            continue;
        } else if tag.starts_with("<polyline") {
            let points = attr(tag, "points")
                .unwrap_or("")
                .split_whitespace()
                .filter_map(|p| {
                    let (x, y) = p.split_once(',')?;
                    Some((x.parse().ok()?, y.parse().ok()?))
                })
                .collect();
            out.lines.push(Line {
                color: attr(tag, "stroke").unwrap_or("").to_ascii_uppercase(),
                width: num(tag, "stroke-width").max(1.0),
                points,
                order,
            });
        } else if tag.starts_with("<circle") {
            out.dots.push(Dot {
                color: attr(tag, "fill").unwrap_or("").to_ascii_uppercase(),
                centre: (num(tag, "cx"), num(tag, "cy")),
                r: num(tag, "r"),
            });
        }
        rest = &rest[end + 1..];
    }
    out
}

fn text_box(tag: &str, text: String) -> TextBox {
    let (x, y, font) = (num(tag, "x"), num(tag, "y"), num(tag, "font-size"));
    let w = 0.6 * font * text.chars().count() as f64;
    let h = font;
    let top = match attr(tag, "dy") {
        Some("0.76em") => 0.0,
        Some("0.5ex") => -0.5 * h,
        Some("-0.5ex") => -h,
        _ => -0.8 * h,
    };
    let anchor = attr(tag, "text-anchor").unwrap_or("start");
    let left = match anchor {
        "middle" => -0.5 * w,
        "end" => -w,
        _ => 0.0,
    };
    // Relative to the anchor point, then rotated about it.
    let (l, t, r, b) = (left, top, left + w, top + h);
    let rotation = attr(tag, "transform")
        .and_then(|t| t.strip_prefix("rotate("))
        .and_then(|t| t.split(',').next())
        .and_then(|a| a.trim().parse::<f64>().ok())
        .unwrap_or(0.0);
    let [l, t, r, b] = match rotation as i64 {
        90 => [-b, l, -t, r],
        180 => [-r, -b, -l, -t],
        270 => [t, -r, b, -l],
        _ => [l, t, r, b],
    };
    TextBox {
        text,
        rect: [x + l, y + t, x + r, y + b],
        font,
        anchor_start: anchor == "start" && rotation == 0.0,
        y_mid: y + 0.5 * (t + b),
    }
}

/// Pairs of text boxes that overlap by more than half a pixel each way.
fn collisions(svg: &Svg) -> Vec<String> {
    let texts: Vec<&TextBox> = svg.texts.iter().filter(|t| !t.text.is_empty()).collect();
    let mut found = Vec::new();
    for (i, a) in texts.iter().enumerate() {
        for b in &texts[i + 1..] {
            let dx = a.rect[2].min(b.rect[2]) - a.rect[0].max(b.rect[0]);
            let dy = a.rect[3].min(b.rect[3]) - a.rect[1].max(b.rect[1]);
            if dx > 0.5 && dy > 0.5 {
                found.push(format!("{:?} and {:?} overlap", a.text, b.text));
            }
        }
    }
    found
}

/// A legend entry: its label and colour, and the polylines (indices)
/// that make up its swatch.
struct Entry {
    label: String,
    color: String,
    swatch: Vec<usize>,
    dot: bool,
}

fn is_short_horizontal(l: &Line) -> Option<(f64, f64, f64)> {
    let [(x0, y0), (x1, y1)] = l.points[..] else {
        return None;
    };
    let len = (x1 - x0).abs();
    (y0 == y1 && (6.0..=40.0).contains(&len)).then_some((x0.min(x1), x0.max(x1), y0))
}

fn legend(svg: &Svg) -> Vec<Entry> {
    let mut entries = Vec::new();
    for t in svg
        .texts
        .iter()
        .filter(|t| t.anchor_start && !t.text.is_empty())
    {
        let near = |right: f64, y: f64| {
            let gap = t.rect[0] - right;
            (2.0..=16.0).contains(&gap) && (y - t.y_mid).abs() <= 0.6 * t.font
        };
        let line = svg
            .lines
            .iter()
            .enumerate()
            .find(|(_, l)| is_short_horizontal(l).is_some_and(|(_, right, y)| near(right, y)));
        if let Some((i, l)) = line {
            let (left, _, y) = is_short_horizontal(l).unwrap();
            // A dashed swatch: the pieces of the same colour on its row.
            let swatch = svg
                .lines
                .iter()
                .enumerate()
                .filter(|(_, m)| {
                    m.color == l.color
                        && is_short_horizontal(m).is_some_and(|(a, b, my)| {
                            my == y && a >= left - 30.0 && b <= left + 40.0
                        })
                })
                .map(|(j, _)| j)
                .chain([i])
                .collect();
            entries.push(Entry {
                label: t.text.clone(),
                color: l.color.clone(),
                swatch,
                dot: false,
            });
        } else if let Some(d) = svg
            .dots
            .iter()
            .find(|d| d.r <= 6.0 && near(d.centre.0 + d.r, d.centre.1))
        {
            entries.push(Entry {
                label: t.text.clone(),
                color: d.color.clone(),
                swatch: Vec::new(),
                dot: true,
            });
        }
    }
    entries
}

/// The distance from `p` to the segment `a`–`b`.
fn distance(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len2 = dx * dx + dy * dy;
    let s = if len2 > 0.0 {
        (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((p.0 - a.0 - s * dx).powi(2) + (p.1 - a.1 - s * dy).powi(2)).sqrt()
}

/// The share of `curve`'s length (sampled every 2 px) not covered by the
/// polylines of other colours drawn after it.
fn visible_share(svg: &Svg, curve: &[&Line]) -> f64 {
    const CELL: f64 = 8.0;
    let color = &curve[0].color;
    let first = curve.iter().map(|l| l.order).min().unwrap_or(0);
    let mut grid: HashMap<(i64, i64), Vec<(usize, usize)>> = HashMap::new();
    for (li, l) in svg.lines.iter().enumerate() {
        if &l.color == color || l.order <= first {
            continue;
        }
        for (si, w) in l.points.windows(2).enumerate() {
            let (x0, x1) = (w[0].0.min(w[1].0), w[0].0.max(w[1].0));
            let (y0, y1) = (w[0].1.min(w[1].1), w[0].1.max(w[1].1));
            for cx in ((x0 / CELL).floor() as i64)..=((x1 / CELL).floor() as i64) {
                for cy in ((y0 / CELL).floor() as i64)..=((y1 / CELL).floor() as i64) {
                    grid.entry((cx, cy)).or_default().push((li, si));
                }
            }
        }
    }
    let (mut seen, mut total) = (0usize, 0usize);
    for l in curve {
        for w in l.points.windows(2) {
            let len = distance(w[1], w[0], w[0]);
            let n = (len / 2.0).ceil().max(1.0) as usize;
            for k in 0..=n {
                let s = k as f64 / n as f64;
                let p = (
                    w[0].0 + s * (w[1].0 - w[0].0),
                    w[0].1 + s * (w[1].1 - w[0].1),
                );
                let cell = ((p.0 / CELL).floor() as i64, (p.1 / CELL).floor() as i64);
                let covered = (-1..=1).any(|dx| {
                    (-1..=1).any(|dy| {
                        grid.get(&(cell.0 + dx, cell.1 + dy)).is_some_and(|segs| {
                            segs.iter().any(|&(li, si)| {
                                let m = &svg.lines[li];
                                m.order > l.order
                                    && distance(p, m.points[si], m.points[si + 1]) + 0.5 * l.width
                                        <= 0.5 * m.width + 0.5
                            })
                        })
                    })
                });
                total += 1;
                seen += usize::from(!covered);
            }
        }
    }
    if total == 0 {
        0.0
    } else {
        seen as f64 / total as f64
    }
}

/// Whether the box `rect` lies over a point of any curve (a polyline that
/// is not a legend swatch, sampled every 2 px).
fn covers(rect: &[f64; 4], svg: &Svg, entries: &[Entry]) -> bool {
    svg.lines.iter().enumerate().any(|(j, l)| {
        !entries.iter().any(|f| f.swatch.contains(&j))
            && l.points.windows(2).any(|w| {
                let n = (distance(w[1], w[0], w[0]) / 2.0).ceil().max(1.0) as usize;
                (0..=n).any(|k| {
                    let s = k as f64 / n as f64;
                    let (x, y) = (
                        w[0].0 + s * (w[1].0 - w[0].0),
                        w[0].1 + s * (w[1].1 - w[0].1),
                    );
                    x > rect[0] && x < rect[2] && y > rect[1] && y < rect[3]
                })
            })
    })
}

/// Every problem of one figure: colliding text, legend entries twice, a
/// legend entry without its curve, or with its curve out of sight.
fn problems(svg_text: &str) -> Vec<String> {
    let svg = parse(svg_text);
    let mut found = collisions(&svg);
    let entries = legend(&svg);
    for (i, e) in entries.iter().enumerate() {
        if entries[..i].iter().any(|f| f.label == e.label) {
            found.push(format!("legend entry {:?} drawn twice", e.label));
            continue;
        }
        if e.dot {
            let n = svg.dots.iter().filter(|d| d.color == e.color).count();
            if n < 2 {
                found.push(format!("legend entry {:?}: no points drawn", e.label));
            }
            continue;
        }
        let curve: Vec<&Line> = svg
            .lines
            .iter()
            .enumerate()
            .filter(|(j, l)| l.color == e.color && !entries.iter().any(|f| f.swatch.contains(j)))
            .map(|(_, l)| l)
            .collect();
        if curve.is_empty() {
            found.push(format!(
                "legend entry {:?}: no curve of its colour {}",
                e.label, e.color
            ));
            continue;
        }
        if let Some(t) = svg.texts.iter().find(|t| t.text == e.label)
            && covers(&t.rect, &svg, &entries)
        {
            found.push(format!("legend entry {:?} covers a curve", e.label));
        }
        let share = visible_share(&svg, &curve);
        if share < 0.02 {
            found.push(format!(
                "legend entry {:?}: its curve is hidden under later ones ({:.1} % in sight)",
                e.label,
                100.0 * share
            ));
        }
    }
    found
}

fn check(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    problems(&text)
        .into_iter()
        .map(|p| format!("{}: {p}", path.display()))
        .collect()
}

#[test]
fn the_checks_catch_colliding_labels_and_missing_or_hidden_curves() {
    let text = |x: i32, s: &str| {
        format!(r#"<text x="{x}" y="10" dy="0.5ex" text-anchor="start" font-size="11">{s}</text>"#)
    };
    // "9.0" and "10.0" as the old Bode axis had them.
    let svg = format!("<svg>{}{}</svg>", text(100, "9.0"), text(115, "10.0"));
    assert_eq!(problems(&svg).len(), 1, "{:?}", problems(&svg));
    let svg = format!("<svg>{}{}</svg>", text(100, "9.0"), text(125, "10.0"));
    assert!(problems(&svg).is_empty(), "{:?}", problems(&svg));
    let swatch = r##"<polyline stroke="#FF0000" stroke-width="2" points="70,10 94,10 "/>"##;
    let legend = format!("{swatch}{}", text(100, "x2"));
    assert_eq!(problems(&format!("<svg>{legend}</svg>")).len(), 1);
    let curve = r##"<polyline stroke="#FF0000" stroke-width="2" points="0,100 50,120 100,100 "/>"##;
    assert!(problems(&format!("<svg>{legend}{curve}</svg>")).is_empty());
    // The same curve drawn over by a wider one of another colour.
    let over = curve.replace("FF0000", "0000FF").replace("\"2\"", "\"3\"");
    assert_eq!(
        problems(&format!("<svg>{legend}{curve}{over}</svg>")).len(),
        1
    );
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn the_crate_figures_have_no_colliding_text_and_every_legend_curve_in_sight() {
    use ctrlab::freq::{
        FrequencyUnit, TransferFunction, bode, bode_marked_svg, bode_svg, logspace, nyquist,
        nyquist_svg,
    };
    use ctrlab::plot::{Reference, Series, responses_svg, responses_with_references_svg};
    use ctrlab::{Cart, MassSpring};

    let dir = temp_dir("figures-crate");
    let t: Vec<f64> = (0..6001).map(|k| k as f64 * 0.0005).collect();
    let ys: Vec<(String, Vec<f64>)> = [0.1, 1.0, 10.0, 30.0, 100.0, 300.0]
        .iter()
        .map(|&w: &f64| {
            let y = t
                .iter()
                .map(|t| 28.5 * (1.0 - (-t * w.sqrt()).exp() * (w * t).cos()))
                .collect();
            (format!("Kf = [0 0 10 {w}]"), y)
        })
        .collect();
    let series: Vec<Series<'_>> = ys.iter().map(|(l, y)| Series::new(l, &t, y)).collect();
    let mut files = Vec::new();
    let path = dir.join("responses.svg");
    responses_svg(&path, "Six responses", "t (s)", "x2 (mm)", &series).unwrap();
    files.push(path);
    let path = dir.join("references.svg");
    let refs = [Reference::new("setpoint 30 mm", 30.0)];
    responses_with_references_svg(
        &path,
        "With a setpoint",
        ("t (s)", "x2 (mm)"),
        &series,
        &refs,
    )
    .unwrap();
    files.push(path);
    // Small values, wide ranges: long labels.
    let small: Vec<f64> = t.iter().map(|t| 1e-4 * (t * 3.0).sin() + 0.00123).collect();
    let path = dir.join("small.svg");
    responses_svg(
        &path,
        "Small",
        "t (s)",
        "x (m)",
        &[Series::new("x", &t, &small)],
    )
    .unwrap();
    files.push(path);

    let nominal = MassSpring::nominal();
    let w = logspace(-0.5, 2.2, 600).unwrap();
    let b2 = bode(&nominal.state_space(Cart::Two).unwrap(), &w).unwrap();
    let b1 = bode(&nominal.state_space(Cart::One).unwrap(), &w).unwrap();
    let path = dir.join("bode.svg");
    bode_svg(
        &path,
        "Plant",
        FrequencyUnit::Hertz,
        &[("force to x2", &b2)],
    )
    .unwrap();
    files.push(path);
    let path = dir.join("bode_marked.svg");
    let curves = [("force to x1", &b1), ("force to x2", &b2)];
    let marks = [("mode 1", 18.0), ("mode 2", 45.0)];
    bode_marked_svg(
        &path,
        "Plant, modes",
        FrequencyUnit::RadPerSecond,
        &curves,
        &marks,
    )
    .unwrap();
    files.push(path);
    let l = TransferFunction::continuous(&[2.0], &[1.0, 3.0, 3.0, 1.0]).unwrap();
    let n = nyquist(&l, &logspace(-2.0, 2.0, 400).unwrap()).unwrap();
    let path = dir.join("nyquist.svg");
    nyquist_svg(&path, "2/(s + 1)³", &[("L", &n)]).unwrap();
    files.push(path);

    let found: Vec<String> = files.iter().flat_map(|f| check(f)).collect();
    assert!(found.is_empty(), "{}", found.join("\n"));
}

/// The lab5 example's binary next to this test's (or `LAB5`).
fn lab5_binary() -> PathBuf {
    example::example_binary(
        "lab5",
        "LAB5",
        "cargo build --release --example lab5, or set LAB5_FIGURES",
    )
}

#[test]
#[ignore = "needs lab5's figures: LAB5_FIGURES=DIR, or the release lab5 binary"]
fn the_lab5_figures() {
    let dir = match std::env::var_os("LAB5_FIGURES") {
        Some(dir) => PathBuf::from(dir),
        None => {
            let dir = temp_dir("figures-lab5");
            let status = Command::new(lab5_binary())
                .arg("--out")
                .arg(&dir)
                .stdout(std::process::Stdio::null())
                .status()
                .expect("lab5 runs");
            assert!(status.success(), "lab5 failed: {status}");
            dir
        }
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "svg"))
        .collect();
    files.sort();
    let names: Vec<String> = files
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    for expected in [
        "table1.svg",
        "table2.svg",
        "identification.svg",
        "table3.svg",
        "table4.svg",
        "bode.svg",
        "table5.svg",
        "table6.svg",
        "design.svg",
    ] {
        assert!(
            names.iter().any(|n| n == expected),
            "{expected} missing in {names:?}"
        );
    }
    let found: Vec<String> = files.iter().flat_map(|f| check(f)).collect();
    assert!(
        found.is_empty(),
        "{} problems:\n{}",
        found.len(),
        found.join("\n")
    );
}
