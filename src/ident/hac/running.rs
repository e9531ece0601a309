//! Running sums, four at a time: a block split in four quarters, each
//! summed by its own chain, then each quarter offset by the totals before
//! it. One chain of dependent adds would cost about four cycles an
//! element; four independent ones overlap.

/// The four quarters of `x` (`block` long each) and the rest.
fn quarters(x: &[f64], block: usize) -> ([&[f64]; 4], &[f64]) {
    let (head, rest) = x.split_at(4 * block);
    let (a, b) = head.split_at(2 * block);
    let ((q0, q1), (q2, q3)) = (a.split_at(block), b.split_at(block));
    ([q0, q1, q2, q3], rest)
}

/// The four quarters of `x` (`block` long each) and the rest.
fn quarters_mut(x: &mut [f64], block: usize) -> ([&mut [f64]; 4], &mut [f64]) {
    let (head, rest) = x.split_at_mut(4 * block);
    let (a, b) = head.split_at_mut(2 * block);
    let ((q0, q1), (q2, q3)) = (a.split_at_mut(block), b.split_at_mut(block));
    ([q0, q1, q2, q3], rest)
}

/// The running sums `out[k] = Σ_{i ≤ k} x[i] · scale` (`out` as long as
/// `x`), returning the total.
pub(super) fn prefix_sums(x: &[f64], scale: f64, out: &mut [f64]) -> f64 {
    let block = x.len() / 4;
    let ([x0, x1, x2, x3], rest) = quarters(x, block);
    let ([o0, o1, o2, o3], out_rest) = quarters_mut(out, block);
    // Quarters of one length: no bounds checks inside.
    let (x1, x2, x3) = (&x1[..block], &x2[..block], &x3[..block]);
    let (o0, o1, o2, o3) = (
        &mut o0[..block],
        &mut o1[..block],
        &mut o2[..block],
        &mut o3[..block],
    );
    let mut sums = [0.0; 4];
    for i in 0..x0.len() {
        sums[0] += x0[i] * scale;
        o0[i] = sums[0];
        sums[1] += x1[i] * scale;
        o1[i] = sums[1];
        sums[2] += x2[i] * scale;
        o2[i] = sums[2];
        sums[3] += x3[i] * scale;
        o3[i] = sums[3];
    }
    let mut offset = 0.0 + sums[0];
    for (out, &sum) in [o1, o2, o3].into_iter().zip(&sums[1..]) {
        out.iter_mut().for_each(|v| *v += offset);
        offset += sum;
    }
    for (v, &x) in out_rest.iter_mut().zip(rest) {
        offset += x * scale;
        *v = offset;
    }
    offset
}

/// What a row adds to a running sum: `x`, `x − old`, or `−old`.
#[derive(Debug, Clone, Copy)]
pub(super) enum Step<'a> {
    Add(&'a [f64]),
    Replace(&'a [f64], &'a [f64]),
    Drop(&'a [f64]),
}

/// `out[k] = carry + Σ_{i ≤ k} d[i] · scale` with `d` the rows' steps
/// (`out.len()` of them), returning `carry + Σ d · scale`: the difference,
/// the running sum and the carry in one pass and one offset.
pub(super) fn running(step: Step<'_>, scale: f64, carry: f64, out: &mut [f64]) -> f64 {
    match step {
        Step::Add(x) => run(out, scale, carry, |[a], i| a[i], [x]),
        Step::Replace(x, old) => run(out, scale, carry, |[a, b], i| a[i] - b[i], [x, old]),
        Step::Drop(old) => run(out, scale, carry, |[b], i| -b[i], [old]),
    }
}

/// [`running`] with the step `d(inputs, i)` of inputs as long as `out`.
#[inline(always)]
fn run<const K: usize>(
    out: &mut [f64],
    scale: f64,
    carry: f64,
    d: impl Fn([&[f64]; K], usize) -> f64,
    inputs: [&[f64]; K],
) -> f64 {
    let n = out.len();
    let block = n / 4;
    let ins: [([&[f64]; 4], &[f64]); K] = std::array::from_fn(|k| quarters(&inputs[k][..n], block));
    let quarter = |q: usize| -> [&[f64]; K] { std::array::from_fn(|k| &ins[k].0[q][..block]) };
    let (q0, q1, q2, q3) = (quarter(0), quarter(1), quarter(2), quarter(3));
    let ([o0, o1, o2, o3], out_rest) = quarters_mut(out, block);
    let (o0, o1, o2, o3) = (
        &mut o0[..block],
        &mut o1[..block],
        &mut o2[..block],
        &mut o3[..block],
    );
    let mut sums = [0.0; 4];
    for i in 0..block {
        sums[0] += d(q0, i) * scale;
        o0[i] = sums[0];
        sums[1] += d(q1, i) * scale;
        o1[i] = sums[1];
        sums[2] += d(q2, i) * scale;
        o2[i] = sums[2];
        sums[3] += d(q3, i) * scale;
        o3[i] = sums[3];
    }
    let mut offset = carry;
    for (out, &sum) in [o0, o1, o2, o3].into_iter().zip(&sums) {
        if offset != 0.0 {
            out.iter_mut().for_each(|v| *v += offset);
        }
        offset += sum;
    }
    let rest: [&[f64]; K] = std::array::from_fn(|k| ins[k].1);
    for (i, v) in out_rest.iter_mut().enumerate() {
        offset += d(rest, i) * scale;
        *v = offset;
    }
    offset
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The four-chain sums are the sequential ones, to rounding, for every
    /// length (shorter than the four quarters, and with a rest).
    #[test]
    fn running_sums_are_the_sequential_ones() {
        for n in [0, 1, 3, 4, 5, 17, 1000, 1003] {
            let x: Vec<f64> = (0..n).map(|k| ((k * 7919) % 13) as f64 - 6.5).collect();
            let old: Vec<f64> = (0..n).map(|k| ((k * 31) % 7) as f64 - 3.0).collect();
            let mut out = vec![f64::NAN; n];
            let total = prefix_sums(&x, 0.5, &mut out);
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * (1.0 + b.abs());
            let mut sum = 0.0;
            for (k, (&x, &got)) in x.iter().zip(&out).enumerate() {
                sum += x * 0.5;
                assert!(close(got, sum), "n {n}, k {k}: {got} vs {sum}");
            }
            assert!(close(total, sum), "n {n}");
            for (step, f) in [
                (Step::Add(&x), &(|i: usize| x[i]) as &dyn Fn(usize) -> f64),
                (Step::Replace(&x, &old), &|i: usize| x[i] - old[i]),
                (Step::Drop(&old), &|i: usize| -old[i]),
            ] {
                let total = running(step, 0.25, 3.0, &mut out);
                let mut sum = 3.0;
                for (k, &got) in out.iter().enumerate() {
                    sum += f(k) * 0.25;
                    assert!(close(got, sum), "n {n}, k {k}: {got} vs {sum}");
                }
                assert!(close(total, sum), "n {n}");
            }
        }
    }
}
