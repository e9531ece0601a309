"""ctrlab's `step_info` and two-stage identification against their peers, on
the same data, in the same run (issue 30, items 2 and 3).

    python3 scripts/ahead_metrics_ident.py

`rows(rounds, repeats)` returns one dict per comparison, `{"work",
"ctrlab_s", "peer", "peer_s", "target"}` (`target`: the least acceptable
`peer_s / ctrlab_s`); run alone, the script prints them as a table. Every
time is the minimum over `rounds × repeats` calls (wall clock, this
machine, one thread: `timing` pins NumPy's BLAS to one thread, as ctrlab
runs on one). The data are written by NumPy as raw little-endian `f64`
files that `examples/ahead_bench.rs` (built and run in release) reads, so
both sides see the same bits.

What is timed:

- `step_info`, 40 001 samples: a second-order step response (ζ = 0.3,
  ωn = 2 rad/s, 0 … 20 s every 0.5 ms). ctrlab: `step_info(t, y)` with the
  default options; python-control 0.10.2: `control.step_info(y, T=t)`.
  (The final values differ by definition — the crate averages the last 5 %
  of the record, python-control takes the last sample — and so the
  figures differ in the last digits; the work is the same.)
- two-stage identification: a square-wave run (±2 V every 0.2 s, 2 ms
  sampling) of a two-cart plant, its positions quantised like the rig's
  encoders. ctrlab: `identify_with(&recording, m1, m2, &options)` with the
  default options (central differences, equal springs) and classical
  standard errors, recording built outside the timed call. NumPy: what a
  NumPy user writes for the same estimate — the two stages' regressors
  from the sample arrays by vectorised finite differences (equations
  (6) and (9) of the lab, central scheme: exactly the rows ctrlab
  solves), `np.linalg.lstsq` for each stage (stage 2's `λ` needs stage 1's
  `k12`), and the classical standard errors `s² (ΦᵀΦ)⁻¹` from `lstsq`'s
  residual sum. The period T is the mean interval, as ctrlab's for a
  uniformly sampled record.
- Newey–West: ctrlab's default standard errors against ctrlab's own
  classical path on the same run (target 0.5: at most twice its time).
"""

import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from timing import run_example  # noqa: E402  (sets the BLAS threads first)

import time  # noqa: E402

import numpy as np  # noqa: E402
from scipy.linalg import expm  # noqa: E402

M1, M2 = 1.3, 0.7
DT = 0.002


def min_time(f, rounds, repeats):
    """The minimum wall time of `rounds × repeats` calls of `f`."""
    best = float("inf")
    f()
    for _ in range(rounds * repeats):
        t = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t)
    return best


def step_data():
    """A second-order step response sampled 40 001 times."""
    zeta, wn = 0.3, 2.0
    t = np.linspace(0.0, 20.0, 40001)
    wd = wn * np.sqrt(1.0 - zeta * zeta)
    y = 1.0 - np.exp(-zeta * wn * t) * (
        np.cos(wd * t) + zeta / np.sqrt(1.0 - zeta * zeta) * np.sin(wd * t)
    )
    return t, y


def run_data(n):
    """`n` samples of a square-wave run of the two-cart plant (ZOH, 2 ms),
    positions quantised to 102 400 counts/m."""
    k1 = k2 = 950.0
    b1, b2, gain = 12.3, 6.1, 8.5
    a = np.array(
        [
            [0.0, 1.0, 0.0, 0.0],
            [-(k1 + k2) / M1, -b1 / M1, k2 / M1, 0.0],
            [0.0, 0.0, 0.0, 1.0],
            [k2 / M2, 0.0, -k2 / M2, -b2 / M2],
        ]
    )
    b = np.array([0.0, 0.0, 0.0, gain / M2])
    big = np.zeros((5, 5))
    big[:4, :4] = a * DT
    big[:4, 4] = b * DT
    e = expm(big)
    ad, bd = e[:4, :4], e[:4, 4]
    t = np.arange(n) * DT
    u = np.where(np.floor(t / 0.2 + 1e-9) % 2 == 0, 2.0, -2.0)
    x = np.zeros(4)
    xs = np.empty((n, 2))
    for k in range(n):
        xs[k] = x[0], x[2]
        x = ad @ x + bd * u[k]
    q = np.round(xs * 102_400.0) / 102_400.0
    return t, u, np.ascontiguousarray(q[:, 0]), np.ascontiguousarray(q[:, 1])


def numpy_identify(t, u, x1, x2):
    """The two stages as a NumPy user writes them (central differences,
    equal springs), with classical standard errors."""
    T = (t[-1] - t[0]) / (len(t) - 1)
    t2 = T * T

    def pos(x):
        return (x[:-2] + 10.0 * x[1:-1] + x[2:]) * (1.0 / 12.0)

    p1, p2 = pos(x1), pos(x2)
    phi1 = np.column_stack((t2 * (2.0 * p1 - p2), T * 0.5 * (x1[2:] - x1[:-2])))
    lam1 = M1 * (2.0 * x1[1:-1] - x1[:-2] - x1[2:])
    th1, ssr1, _, _ = np.linalg.lstsq(phi1, lam1, rcond=None)
    k12 = th1[0]
    phi2 = np.column_stack((t2 * 0.5 * (u[:-2] + u[1:-1]), -T * 0.5 * (x2[2:] - x2[:-2])))
    lam2 = M2 * (x2[2:] - 2.0 * x2[1:-1] + x2[:-2]) + k12 * t2 * (p2 - p1)
    th2, ssr2, _, _ = np.linalg.lstsq(phi2, lam2, rcond=None)
    m = len(lam1)
    se1 = np.sqrt(np.diag(np.linalg.inv(phi1.T @ phi1)) * ssr1[0] / (m - 2))
    se2 = np.sqrt(np.diag(np.linalg.inv(phi2.T @ phi2)) * ssr2[0] / (m - 2))
    return th1, th2, se1, se2


def rows(rounds=3, repeats=5):
    import control

    with tempfile.TemporaryDirectory() as tmp:

        def save(name, array):
            path = os.path.join(tmp, name)
            np.asarray(array, dtype="<f8").tofile(path)
            return path

        t, y = step_data()
        cases = [
            {
                "name": "step_info",
                "kind": "step_info",
                "t": save("step_t", t),
                "y": save("step_y", y),
                "rounds": rounds,
                "repeats": repeats * 20,
            }
        ]
        runs = {}
        for n in (5000, 50_000, 500_000):
            runs[n] = run_data(n)
            tt, u, x1, x2 = runs[n]
            files = {k: save(f"{k}_{n}", v) for k, v in zip(("t", "u", "x1", "x2"), runs[n])}
            for cov in ("classical", "newey_west"):
                cases.append(
                    {
                        "name": f"ident {n} {cov}",
                        "kind": "ident",
                        "covariance": cov,
                        "m1": M1,
                        "m2": M2,
                        "rounds": rounds,
                        "repeats": repeats * (4 if n < 500_000 else 1),
                        **files,
                    }
                )
        ours = {line["name"]: line for line in run_example("ahead_bench", {"cases": cases})}

    out = []
    s_peer = min_time(lambda: control.step_info(y, T=t), rounds, repeats * 4)
    out.append(
        {
            "work": "step_info, 40 001 samples",
            "ctrlab_s": ours["step_info"]["min_s"],
            "peer": "python-control 0.10.2 step_info",
            "peer_s": s_peer,
            "target": 5.0,
        }
    )
    for n in (5000, 500_000):
        args = runs[n]
        th1, th2, _, _ = numpy_identify(*args)
        mine = ours[f"ident {n} classical"]
        # The same regressors: the same estimate (to rounding).
        for ours_v, numpy_v in ((mine["k12"], th1[0]), (mine["b1"], th1[1]),
                                (mine["gain"], th2[0]), (mine["b2"], th2[1])):
            assert abs(ours_v - numpy_v) <= 1e-8 * abs(numpy_v), (n, ours_v, numpy_v)
        s_peer = min_time(lambda: numpy_identify(*args), rounds, repeats * (4 if n < 500_000 else 1))
        out.append(
            {
                "work": f"two-stage identification, {n:,} samples (classical errors)".replace(",", " "),
                "ctrlab_s": mine["min_s"],
                "peer": "NumPy lstsq (regressors + 2 solves + std errors)",
                "peer_s": s_peer,
                "target": 6.0 if n == 500_000 else 1.0,
            }
        )
    for n in (5000, 50_000, 500_000):
        out.append(
            {
                "work": f"two-stage identification, {n:,} samples (Newey–West)".replace(",", " "),
                "ctrlab_s": ours[f"ident {n} newey_west"]["min_s"],
                "peer": "ctrlab, classical errors",
                "peer_s": ours[f"ident {n} classical"]["min_s"],
                "target": 0.5,
            }
        )
    return out


def main():
    print(f"{'work':<58} {'ctrlab':>10} {'peer':>10} {'ratio':>7} {'target':>7}  peer")
    for r in rows():
        ratio = r["peer_s"] / r["ctrlab_s"]
        print(
            f"{r['work']:<58} {r['ctrlab_s'] * 1e6:>7.1f} µs {r['peer_s'] * 1e6:>7.1f} µs "
            f"{ratio:>7.2f} {r['target']:>7.1f}  {r['peer']}"
        )


if __name__ == "__main__":
    main()
