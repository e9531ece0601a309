//! The regressor columns of equations (6) and (9), per [`Scheme`](super::Scheme):
//! any range of a stage's rows, segment by segment ([`Spec::fill`]), so
//! that a stage is built whole or streamed in blocks.

use super::SpringModel;
use super::timing::Segment;

/// The finite differences of a [`Scheme`](super::Scheme), as monomorphised
/// kernels: a runtime `match` on the scheme inside the per-sample column
/// loops keeps them from vectorising (measured: 50 µs → 80 µs for 5000
/// samples).
pub(super) trait Differences {
    /// `T ·` velocity at a row from `[x(k−1), x(k), x(k+1)]`: the velocity
    /// regressor of equations (6)/(9), in position units.
    fn vel(x: [f64; 3]) -> f64;
    /// The position the spring terms use, from `[x(k−1), x(k), x(k+1)]`.
    fn pos(x: [f64; 3]) -> f64;
    /// The input the second difference at `k` sees, from `u(k−1)`, `u(k)`.
    fn input(previous: f64, current: f64) -> f64;
}

/// `[x(k−1), x(k), x(k+1)]` for the rows `k = 1 … len − 2`, from shifted
/// slices: no bounds check per sample, so the column loops vectorise.
fn triples(x: &[f64]) -> impl Iterator<Item = [f64; 3]> + '_ {
    let m = x.len().saturating_sub(2);
    x[..m]
        .iter()
        .zip(&x[1..m + 1])
        .zip(&x[2..m + 2])
        .map(|((&a, &b), &c)| [a, b, c])
}

/// `(u(k−1), u(k))` for the same rows.
fn input_pairs(u: &[f64]) -> impl Iterator<Item = (f64, f64)> + '_ {
    let m = u.len().saturating_sub(2);
    u[..m].iter().zip(&u[1..m + 1]).map(|(&a, &b)| (a, b))
}

/// `x(k+1) − 2 x(k) + x(k−1)`.
#[inline(always)]
fn second_difference(x: [f64; 3]) -> f64 {
    x[2] - 2.0 * x[1] + x[0]
}

/// [`Scheme::Lab`](super::Scheme::Lab): equations (6)–(11) as written.
pub(super) struct LabDifferences;

impl Differences for LabDifferences {
    #[inline(always)]
    fn vel(x: [f64; 3]) -> f64 {
        x[1] - x[0]
    }
    #[inline(always)]
    fn pos(x: [f64; 3]) -> f64 {
        x[1]
    }
    #[inline(always)]
    fn input(_previous: f64, current: f64) -> f64 {
        current
    }
}

/// [`Scheme::Central`](super::Scheme::Central).
pub(super) struct CentralDifferences;

impl Differences for CentralDifferences {
    #[inline(always)]
    fn vel(x: [f64; 3]) -> f64 {
        0.5 * (x[2] - x[0])
    }
    /// The central second difference is exactly the triangle-weighted mean
    /// of `x''` over `[t(k−1), t(k+1)]`, so the spring forces it balances are
    /// that mean of `x` too, `(x(k−1) + 10 x(k) + x(k+1)) / 12` to O(T⁴); the
    /// plain `x(k)` is off by `T² x''/12`, an error in phase with the springs
    /// that otherwise leaks into the small damping `b2` (0.5 % seen on
    /// plausible plants). Times the rounded `1/12` rather than divided by
    /// 12: a division per row and column was a fifth of the
    /// identification's time, and the product is within an ulp of it.
    #[inline(always)]
    fn pos(x: [f64; 3]) -> f64 {
        (x[0] + 10.0 * x[1] + x[2]) * (1.0 / 12.0)
    }
    #[inline(always)]
    fn input(previous: f64, current: f64) -> f64 {
        0.5 * (previous + current)
    }
}

/// The validated channels and the segments their rows come from.
pub(super) struct Data<'a> {
    pub u: &'a [f64],
    pub x1: &'a [f64],
    pub x2: &'a [f64],
    pub segments: Vec<Segment>,
    /// Rows over all segments.
    pub rows: usize,
}

/// Per row, the direction (+1 or −1) in which a cart clearly moves
/// throughout the row's window `[t(k−1), t(k+1)]`, or 0 where it does not.
pub(super) struct Motion {
    pub direction: Vec<f64>,
    /// Rows with a direction.
    pub moving: usize,
}

/// Where position `x` clearly moves through a row's window: it moves the
/// same way faster than `min_speed` over the sampling interval just before
/// the window, `[t(k−3), t(k−2)]`, and the one just after it,
/// `[t(k+2), t(k+3)]`.
///
/// Those four samples are not among the row's own `k−1, k, k+1`, so which
/// rows are kept does not depend on the rows' measurement noise: choosing
/// on the row's own samples (its end speeds) selects rows by the noise in
/// their second difference, and on the simulated rig that biased `K` by
/// +0.2 % and the springs by −0.1 to −0.3 %. A cart moving the same way
/// 10 ms apart (at 2 ms) has neither stopped nor reversed in between: that
/// would take two reversals, far above the plant's modes. Rows within three
/// samples of a segment's ends have no such intervals and are left out.
pub(super) fn motion(x: &[f64], data: &Data<'_>, min_speed: f64) -> Motion {
    let mut direction = Vec::with_capacity(data.rows);
    for seg in &data.segments {
        let threshold = min_speed * seg.dt;
        let x = &x[seg.start..seg.end];
        // Row k = 1 … len − 2 of the segment.
        direction.extend((1..x.len() - 1).map(|k| {
            if k < 3 || k + 3 >= x.len() {
                return 0.0;
            }
            let (before, after) = (x[k - 2] - x[k - 3], x[k + 3] - x[k + 2]);
            if before > threshold && after > threshold {
                1.0
            } else if before < -threshold && after < -threshold {
                -1.0
            } else {
                0.0
            }
        }));
    }
    let moving = direction.iter().filter(|&&d| d != 0.0).count();
    Motion { direction, moving }
}

/// Which stage's columns, `[Φ | λ]`.
#[derive(Debug, Clone, Copy)]
pub(super) enum Kind {
    /// Stage 1 (equation (6)): the springs (`[k12]` equal, `[k1, k2]`
    /// separate), `b1`, then `F1` with the Coulomb column; `λ` from `m1`.
    First { springs: SpringModel, m1: f64 },
    /// Stage 2 (equations (9)–(11)): `[K, b2]`, then `F2`; `λ` holds `k2
    /// z` with `k2` from stage 1, `z` the spring column [`Spec::fill`]
    /// also writes on request.
    Second { m2: f64, k2: f64 },
    /// Stage 2 with cart 2's mass free, divided by it: `[K, b2, k2, (F2)]
    /// / m2` on `[input, −velocity, −z, (Coulomb)]`, `λ` the bare second
    /// difference; `k2` (stage 1's) maps the estimate to `[K, b2, m2,
    /// (F2)]`.
    FreeMass { k2: f64 },
}

/// One stage: its columns, the data, and the rows it keeps (with the
/// Coulomb column, those where its cart moves).
pub(super) struct Spec<'s, 'a> {
    pub kind: Kind,
    pub data: &'s Data<'a>,
    pub keep: Option<&'s Motion>,
    /// Parameters (columns of `Φ`).
    pub p: usize,
}

/// Where a column's values go: into a slice, or appended to a vector
/// (then nothing is written twice, not even zeros first).
pub(super) enum Target<'o> {
    Slice(&'o mut [f64]),
    Push(&'o mut Vec<f64>),
}

/// Where [`Spec::fill`] writes: columns of a slice `stride` apart, or
/// appended one after the other to a vector.
pub(super) enum Out<'o> {
    Slices(&'o mut [f64], usize),
    Push(&'o mut Vec<f64>),
}

/// The columns of an [`Out`], one after the other.
struct Cols<'o> {
    slices: Option<std::slice::ChunksMut<'o, f64>>,
    push: Option<&'o mut Vec<f64>>,
}

impl<'o> Cols<'o> {
    fn new(out: Out<'o>) -> Self {
        match out {
            Out::Slices(buf, stride) => Self {
                slices: Some(buf.chunks_mut(stride)),
                push: None,
            },
            Out::Push(buf) => Self {
                slices: None,
                push: Some(buf),
            },
        }
    }

    fn next(&mut self) -> Target<'_> {
        match (&mut self.slices, &mut self.push) {
            (Some(slices), _) => Target::Slice(slices.next().unwrap_or_default()),
            (None, Some(buf)) => Target::Push(buf),
            (None, None) => Target::Slice(&mut []),
        }
    }
}

/// The segments that hold rows `from .. to` (global row numbers), each
/// with the part of them it holds, as its own rows `a .. b`.
fn segment_rows<'d>(
    data: &'d Data<'_>,
    (from, to): (usize, usize),
) -> impl Iterator<Item = (&'d Segment, usize, usize)> + 'd {
    let first = data.segments.partition_point(|s| s.row0 + s.rows() <= from);
    data.segments[first..]
        .iter()
        .take_while(move |seg| seg.row0 < to)
        .map(move |seg| {
            let (a, b) = (
                from.max(seg.row0) - seg.row0,
                to.min(seg.row0 + seg.rows()) - seg.row0,
            );
            (seg, a, b)
        })
}

/// Writes `rows(segment, a, b)` (the segment's rows `a .. b`) for the
/// rows `from .. to` of the segments (global row numbers), in order, to
/// `out`; with `keep`, only the rows whose direction is not 0. Returns the
/// rows written.
fn put<I: Iterator<Item = f64>>(
    mut out: Target<'_>,
    data: &Data<'_>,
    (from, to): (usize, usize),
    keep: Option<&Motion>,
    mut rows: impl FnMut(&Segment, usize, usize) -> I,
) -> usize {
    let mut at = 0;
    for (seg, a, b) in segment_rows(data, (from, to)) {
        let values = rows(seg, a, b);
        let direction = keep.map(|m| &m.direction[seg.row0 + a..seg.row0 + b]);
        match (&mut out, direction) {
            (Target::Slice(out), None) => {
                for (o, v) in out[at..at + (b - a)].iter_mut().zip(values) {
                    *o = v;
                }
                at += b - a;
            }
            (Target::Slice(out), Some(direction)) => {
                for (v, &d) in values.zip(direction) {
                    if d != 0.0 {
                        out[at] = v;
                        at += 1;
                    }
                }
            }
            (Target::Push(out), None) => {
                out.extend(values);
                at += b - a;
            }
            (Target::Push(out), Some(direction)) => {
                let before = out.len();
                out.extend(
                    values
                        .zip(direction)
                        .filter(|&(_, &d)| d != 0.0)
                        .map(|(v, _)| v),
                );
                at += out.len() - before;
            }
        }
    }
    at
}

/// `x`'s samples for rows `a .. b` of `seg` (each row's `k − 1, k, k + 1`).
fn samples<'x>(x: &'x [f64], seg: &Segment, a: usize, b: usize) -> &'x [f64] {
    &x[seg.start + a..seg.start + b + 2]
}

impl Spec<'_, '_> {
    /// Columns of `[Φ | λ]`.
    pub fn width(&self) -> usize {
        self.p + 1
    }

    /// Writes the rows `from .. to` (global row numbers; with `compact`
    /// only those the stage keeps, else all, the Coulomb column 0 where a
    /// cart rests) of `[Φ | λ]`, then stage 2's `z` with `with_z`, to `out`.
    /// Returns the rows written. Each value is the same expression,
    /// evaluated in the same order, whatever the range.
    pub fn fill<D: Differences>(
        &self,
        (from, to): (usize, usize),
        compact: bool,
        with_z: bool,
        out: Out<'_>,
    ) -> usize {
        if self.keep.is_none() {
            self.fill_every_row::<D>((from, to), with_z, out)
        } else {
            self.fill_by_columns::<D>((from, to), compact, with_z, out)
        }
    }

    /// [`fill`](Self::fill) a column at a time, each column's rows
    /// filtered by [`keep`](Self::keep) when `compact`.
    pub(super) fn fill_by_columns<D: Differences>(
        &self,
        (from, to): (usize, usize),
        compact: bool,
        with_z: bool,
        out: Out<'_>,
    ) -> usize {
        let data = self.data;
        let (u, x1, x2) = (data.u, data.x1, data.x2);
        let keep = self.keep.filter(|_| compact);
        let range = (from, to);
        let mut cols = Cols::new(out);
        let rows;
        // `T² (x2 − x1)` at the spring terms' positions.
        let spring = |seg: &Segment, a, b| {
            let t2 = seg.dt * seg.dt;
            triples(samples(x2, seg, a, b))
                .zip(triples(samples(x1, seg, a, b)))
                .map(move |(x2, x1)| t2 * (D::pos(x2) - D::pos(x1)))
        };
        let coulomb = |col: Target<'_>, scale: f64| {
            if let Some(motion) = self.keep {
                put(col, data, range, keep, |seg, a, b| {
                    let t2 = seg.dt * seg.dt;
                    motion.direction[seg.row0 + a..seg.row0 + b]
                        .iter()
                        .map(move |&d| scale * t2 * d)
                });
            }
        };
        match self.kind {
            Kind::First { springs, m1 } => {
                match springs {
                    // `k12 T² [2x1(k) − x2(k)]`.
                    SpringModel::Equal => {
                        rows = put(cols.next(), data, range, keep, |seg, a, b| {
                            let t2 = seg.dt * seg.dt;
                            triples(samples(x1, seg, a, b))
                                .zip(triples(samples(x2, seg, a, b)))
                                .map(move |(x1, x2)| t2 * (2.0 * D::pos(x1) - D::pos(x2)))
                        });
                    }
                    // `k1 T² x1(k) + k2 T² [x1(k) − x2(k)]`.
                    SpringModel::Separate => {
                        rows = put(cols.next(), data, range, keep, |seg, a, b| {
                            let t2 = seg.dt * seg.dt;
                            triples(samples(x1, seg, a, b)).map(move |x| t2 * D::pos(x))
                        });
                        put(cols.next(), data, range, keep, |seg, a, b| {
                            let t2 = seg.dt * seg.dt;
                            triples(samples(x1, seg, a, b))
                                .zip(triples(samples(x2, seg, a, b)))
                                .map(move |(x1, x2)| t2 * (D::pos(x1) - D::pos(x2)))
                        });
                    }
                }
                put(cols.next(), data, range, keep, |seg, a, b| {
                    let t = seg.dt;
                    triples(samples(x1, seg, a, b)).map(move |x| t * D::vel(x))
                });
                if self.keep.is_some() {
                    coulomb(cols.next(), 1.0);
                }
                // The lab's own order of operations, as its MATLAB `lamda`.
                put(cols.next(), data, range, keep, |seg, a, b| {
                    triples(samples(x1, seg, a, b)).map(move |x| m1 * (2.0 * x[1] - x[0] - x[2]))
                });
            }
            Kind::Second { .. } | Kind::FreeMass { .. } => {
                rows = put(cols.next(), data, range, keep, |seg, a, b| {
                    let t2 = seg.dt * seg.dt;
                    input_pairs(samples(u, seg, a, b)).map(move |(a, b)| t2 * D::input(a, b))
                });
                put(cols.next(), data, range, keep, |seg, a, b| {
                    let t = seg.dt;
                    triples(samples(x2, seg, a, b)).map(move |x| -t * D::vel(x))
                });
                if let Kind::Second { m2, k2 } = self.kind {
                    if self.keep.is_some() {
                        coulomb(cols.next(), -1.0);
                    }
                    put(cols.next(), data, range, keep, |seg, a, b| {
                        let t2 = seg.dt * seg.dt;
                        triples(samples(x2, seg, a, b))
                            .zip(triples(samples(x1, seg, a, b)))
                            .map(move |(x2, x1)| {
                                m2 * second_difference(x2) + k2 * t2 * (D::pos(x2) - D::pos(x1))
                            })
                    });
                    if with_z {
                        put(cols.next(), data, range, keep, spring);
                    }
                } else {
                    put(cols.next(), data, range, keep, |seg, a, b| {
                        spring(seg, a, b).map(|v| -v)
                    });
                    if self.keep.is_some() {
                        coulomb(cols.next(), -1.0);
                    }
                    put(cols.next(), data, range, keep, |seg, a, b| {
                        triples(samples(x2, seg, a, b)).map(second_difference)
                    });
                }
            }
        }
        rows
    }
}

/// The samples a row of the segment reads: `x1`, `x2` at `k − 1, k, k + 1`
/// and `u` at `k − 1, k`.
type Around = ([f64; 3], [f64; 3], (f64, f64));

impl Spec<'_, '_> {
    /// [`fill`](Self::fill) of a stage that keeps every row: each row's
    /// columns computed at once from the samples around it (the same
    /// operations in the same order as the column by column fill, so the
    /// same values bit for bit), the samples read once.
    fn fill_every_row<D: Differences>(
        &self,
        (from, to): (usize, usize),
        with_z: bool,
        out: Out<'_>,
    ) -> usize {
        match self.kind {
            Kind::First {
                springs: SpringModel::Equal,
                m1,
            } => self.rows_into::<3>((from, to), out, move |dt, (x1, x2, _)| {
                let t2 = dt * dt;
                [
                    t2 * (2.0 * D::pos(x1) - D::pos(x2)),
                    dt * D::vel(x1),
                    m1 * (2.0 * x1[1] - x1[0] - x1[2]),
                ]
            }),
            Kind::First {
                springs: SpringModel::Separate,
                m1,
            } => self.rows_into::<4>((from, to), out, move |dt, (x1, x2, _)| {
                let t2 = dt * dt;
                [
                    t2 * D::pos(x1),
                    t2 * (D::pos(x1) - D::pos(x2)),
                    dt * D::vel(x1),
                    m1 * (2.0 * x1[1] - x1[0] - x1[2]),
                ]
            }),
            Kind::Second { m2, k2 } => {
                let row = move |dt: f64, (x1, x2, (a, b)): Around| {
                    let t2 = dt * dt;
                    [
                        t2 * D::input(a, b),
                        -dt * D::vel(x2),
                        m2 * second_difference(x2) + k2 * t2 * (D::pos(x2) - D::pos(x1)),
                        t2 * (D::pos(x2) - D::pos(x1)),
                    ]
                };
                if with_z {
                    self.rows_into::<4>((from, to), out, row)
                } else {
                    self.rows_into::<3>((from, to), out, move |dt, around| {
                        let [a, b, c, _] = row(dt, around);
                        [a, b, c]
                    })
                }
            }
            Kind::FreeMass { .. } => {
                self.rows_into::<4>((from, to), out, move |dt, (x1, x2, (a, b))| {
                    let t2 = dt * dt;
                    [
                        t2 * D::input(a, b),
                        -dt * D::vel(x2),
                        -(t2 * (D::pos(x2) - D::pos(x1))),
                        second_difference(x2),
                    ]
                })
            }
        }
    }

    /// Rows `from .. to` (every one kept) of `W` columns, each row's
    /// values from `row(dt, samples)` with its segment's period.
    fn rows_into<const W: usize>(
        &self,
        (from, to): (usize, usize),
        out: Out<'_>,
        row: impl Fn(f64, Around) -> [f64; W],
    ) -> usize {
        let data = self.data;
        let count = to.saturating_sub(from);
        let (buf, stride) = match out {
            Out::Slices(buf, stride) => (buf, stride),
            Out::Push(v) => {
                let at = v.len();
                v.resize(at + W * count, 0.0);
                (&mut v[at..], count)
            }
        };
        let mut chunks = buf.chunks_mut(stride.max(1));
        let mut cols: [&mut [f64]; W] = std::array::from_fn(|_| chunks.next().unwrap_or_default());
        let mut written = 0;
        for (seg, a, b) in segment_rows(data, (from, to)) {
            let len = b - a;
            let x1 = &samples(data.x1, seg, a, b)[..len + 2];
            let x2 = &samples(data.x2, seg, a, b)[..len + 2];
            let u = &samples(data.u, seg, a, b)[..len + 1];
            // This segment's rows of each column, the rest kept for the next.
            let mut out: [&mut [f64]; W] = std::array::from_fn(|j| {
                let col = std::mem::take(&mut cols[j]);
                let (head, tail) = col.split_at_mut(len.min(col.len()));
                cols[j] = tail;
                head
            });
            debug_assert!(out.iter().all(|c| c.len() == len), "room for the rows");
            let len = out.iter().map(|c| c.len()).min().unwrap_or(0);
            let dt = seg.dt;
            for i in 0..len {
                let around = (
                    [x1[i], x1[i + 1], x1[i + 2]],
                    [x2[i], x2[i + 1], x2[i + 2]],
                    (u[i], u[i + 1]),
                );
                for (col, v) in out.iter_mut().zip(row(dt, around)) {
                    col[i] = v;
                }
            }
            written += len;
        }
        written
    }
}
