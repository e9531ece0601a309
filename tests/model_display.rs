//! `Display` for `StateSpace`: the header of each domain, precision, and
//! every matrix entry in its place (exactly with `{:#}`; the default's five
//! significant digits are checked in `tests/calling_style.rs`).

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

use ctrlab::{Cart, Discretization, MassSpring, StateSpace};
use nalgebra::{DMatrix, SMatrix, matrix};
use proptest::prelude::*;

/// One printed matrix: its name and its rows of cells.
type Block = (String, Vec<Vec<String>>);

/// The header line and the four blocks of a printed model. Panics on any
/// other layout.
fn blocks(text: &str) -> (String, Vec<Block>) {
    assert!(text.ends_with('\n'), "ends with a newline: {text:?}");
    let mut lines = text.lines();
    let header = lines.next().expect("a header line").to_string();
    let mut out: Vec<Block> = Vec::new();
    for line in lines {
        if let Some(name) = line.strip_suffix(" =") {
            out.push((name.to_string(), Vec::new()));
        } else {
            let (_, rows) = out.last_mut().expect("a row after a matrix name");
            // Every cell is two spaces and the right-aligned number.
            assert!(line.starts_with("  "), "row {line:?}");
            rows.push(line.split_whitespace().map(str::to_string).collect());
        }
    }
    let names: Vec<&str> = out.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["A", "B", "C", "D"], "{text}");
    (header, out)
}

/// The rows of `text` under matrix `name`, as printed (with alignment).
fn raw_rows<'a>(text: &'a str, name: &str) -> Vec<&'a str> {
    text.lines()
        .skip_while(|l| *l != format!("{name} ="))
        .skip(1)
        .take_while(|l| !l.ends_with(" ="))
        .collect()
}

fn as_dmatrix<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>) -> DMatrix<f64> {
    DMatrix::from_fn(R, C, |r, c| m[(r, c)])
}

/// Checks every entry of the four matrices appears in its place, formatted
/// by `cell`, and that each matrix's rows are right-aligned to one width.
fn check_entries<const N: usize, const M: usize, const P: usize, D: ctrlab::Domain>(
    sys: &StateSpace<N, M, P, D>,
    text: &str,
    cell: impl Fn(f64) -> String,
) {
    let (_, got) = blocks(text);
    let want = [
        ("A", as_dmatrix(sys.a())),
        ("B", as_dmatrix(sys.b())),
        ("C", as_dmatrix(sys.c())),
        ("D", as_dmatrix(sys.d())),
    ];
    for ((name, rows), (want_name, m)) in got.iter().zip(&want) {
        assert_eq!(name, want_name);
        assert_eq!(rows.len(), m.nrows(), "{name} rows\n{text}");
        for (r, row) in rows.iter().enumerate() {
            assert_eq!(row.len(), m.ncols(), "{name} row {r}\n{text}");
            for (c, cell_text) in row.iter().enumerate() {
                assert_eq!(*cell_text, cell(m[(r, c)]), "{name}[{r}, {c}]\n{text}");
            }
        }
        // Right-aligned: every cell as wide as the widest of its matrix.
        let width = m.iter().map(|&v| cell(v).len()).max().unwrap_or(0);
        for line in raw_rows(text, name) {
            assert_eq!(line.len(), m.ncols() * (2 + width), "{line:?}\n{text}");
        }
    }
}

#[test]
fn continuous_header_and_every_entry_exactly() {
    let sys = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let text = format!("{sys:#}");
    let (header, _) = blocks(&text);
    assert_eq!(header, "x' = A x + B u, y = C x + D u");
    // With `#` each entry is the shortest form that reads back exactly.
    check_entries(&sys, &text, |v| format!("{v}"));
    let (_, got) = blocks(&text);
    for (r, row) in got[0].1.iter().enumerate() {
        for (c, cell) in row.iter().enumerate() {
            assert_eq!(cell.parse::<f64>().unwrap(), sys.a()[(r, c)]);
        }
    }
    // 4 + 4 + 1 + 1 rows, four names, one header.
    assert_eq!(
        text.lines().count(),
        1 + (1 + 4) + (1 + 4) + (1 + 1) + (1 + 1)
    );
    // to_string is `{}`.
    assert_eq!(sys.to_string(), format!("{sys}"));
}

#[test]
fn discrete_header_shows_the_period() {
    let d = MassSpring::nominal()
        .state_space(Cart::One)
        .unwrap()
        .discretize(0.002, Discretization::Zoh)
        .unwrap();
    let text = format!("{d:#}");
    let (header, _) = blocks(&text);
    assert_eq!(
        header,
        "x[k+1] = A x[k] + B u[k], y[k] = C x[k] + D u[k], dt = 0.002 s"
    );
    check_entries(&d, &text, |v| format!("{v}"));
    // The header follows the period, not the precision.
    let text = format!("{:.1}", d);
    assert!(text.starts_with("x[k+1] = A x[k] + B u[k], y[k] = C x[k] + D u[k], dt = 0.002 s\n"));
    let odd = StateSpace::discrete(
        matrix![0.5],
        matrix![1.0],
        matrix![1.0],
        matrix![0.0],
        1.0 / 3.0,
    )
    .unwrap();
    assert!(odd.to_string().starts_with(&format!(
        "x[k+1] = A x[k] + B u[k], y[k] = C x[k] + D u[k], dt = {} s\n",
        1.0 / 3.0
    )));
}

#[test]
fn precision_applies_to_every_entry() {
    let sys = StateSpace::continuous(
        matrix![0.0, 1.0; -1234.5678, -0.000_44],
        matrix![0.0; 1.0 / 0.7],
        matrix![1.0, -2.5],
        matrix![0.125],
    )
    .unwrap();
    for p in [0, 1, 3, 6] {
        let text = format!("{sys:.p$}");
        check_entries(&sys, &text, |v| format!("{v:.p$}"));
    }
    let text = format!("{sys:.3}");
    assert_eq!(
        text,
        "x' = A x + B u, y = C x + D u\n\
         A =\n      0.000      1.000\n  -1234.568     -0.000\n\
         B =\n  0.000\n  1.429\n\
         C =\n   1.000  -2.500\n\
         D =\n  0.125\n"
    );
    // With `#`: the shortest exact form, aligned per matrix.
    assert_eq!(
        format!("{sys:#}"),
        "x' = A x + B u, y = C x + D u\n\
         A =\n           0           1\n  -1234.5678    -0.00044\n\
         B =\n                   0\n  1.4285714285714286\n\
         C =\n     1  -2.5\n\
         D =\n  0.125\n"
    );
}

#[test]
fn non_square_shapes_print_every_row_and_column() {
    // Two inputs, three outputs.
    let sys = StateSpace::continuous(
        matrix![-1.0, 2.0; 0.0, -3.0],
        matrix![1.0, 0.0; 0.0, 1.0],
        matrix![1.0, 0.0; 0.0, 1.0; 1.0, 1.0],
        matrix![0.0, 0.0; 0.0, 0.0; 0.5, -0.5],
    )
    .unwrap();
    let text = format!("{sys:#}");
    check_entries(&sys, &text, |v| format!("{v}"));
    let (_, got) = blocks(&text);
    let shapes: Vec<(usize, usize)> = got
        .iter()
        .map(|(_, rows)| (rows.len(), rows[0].len()))
        .collect();
    assert_eq!(shapes, [(2, 2), (2, 2), (3, 2), (3, 2)]);
}

proptest! {
    #[test]
    fn every_entry_appears_and_reads_back(
        a in proptest::array::uniform9(-1e6f64..1e6),
        b in proptest::array::uniform3(-1e-6f64..1e-6),
        c in proptest::array::uniform3(prop_oneof![Just(0.0), Just(-0.0), -10.0f64..10.0]),
        d in -1.0f64..1.0,
        dt in 1e-4f64..1.0,
        p in 0usize..8,
    ) {
        let sys = StateSpace::discrete(
            SMatrix::<f64, 3, 3>::from_row_slice(&a),
            SMatrix::<f64, 3, 1>::from_row_slice(&b),
            SMatrix::<f64, 1, 3>::from_row_slice(&c),
            matrix![d],
            dt,
        )
        .unwrap();
        let text = format!("{sys:#}");
        check_entries(&sys, &text, |v| format!("{v}"));
        let expected_header = format!("x[k+1] = A x[k] + B u[k], y[k] = C x[k] + D u[k], dt = {dt} s");
        prop_assert_eq!(text.lines().next(), Some(expected_header.as_str()));
        // The shortest form reads back to the same bits.
        let (_, got) = blocks(&text);
        for (r, row) in got[0].1.iter().enumerate() {
            for (k, cell) in row.iter().enumerate() {
                prop_assert_eq!(cell.parse::<f64>().unwrap().to_bits(), sys.a()[(r, k)].to_bits());
            }
        }
        let text = format!("{sys:.p$}");
        check_entries(&sys, &text, |v| format!("{v:.p$}"));
    }
}
