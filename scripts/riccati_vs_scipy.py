"""ctrlab's continuous Riccati solver against SciPy's, on the same matrices,
in the same run; and ctrlab's LQR at the lab's size against python-control.

    python3 scripts/riccati_vs_scipy.py

Builds and runs `examples/riccati_bench.rs` (release) on problems written to
a temporary JSON file, times `scipy.linalg.solve_continuous_are` and, for
the lab plant, `control.lqr` on the same matrices, and prints one table.
Times are medians of several solves (wall clock, this machine, one
thread: set OPENBLAS_NUM_THREADS=1 etc. below so SciPy's LAPACK is not
given more cores than ctrlab).

For the lab plant the table's ctrlab column is `care` (run-time sized); the
last line adds the fixed-size `lqr` a lab program calls, on the same plant.

Problems: the lab plant (MassSpring::nominal, cart 2; Q = diag(0, 0, 1e6, 0),
R = 1), random stabilisable problems at n = 20, 60, 100 (seeded: A with
N(0, 1/n) entries shifted to have unstable modes, B n × n/10, Q = I, R = I),
a lightly damped chain at n = 100, and SciPy's CAREX 18 (n = 100).
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from timing import ROOT, median_time, run_example  # noqa: E402  (sets the BLAS threads first)

import json  # noqa: E402

import numpy as np  # noqa: E402
from scipy.linalg import solve_continuous_are  # noqa: E402



def lab_plant():
    with open(os.path.join(ROOT, "tests/data/mass_spring_nominal.json")) as f:
        d = json.load(f)
    a, b = np.array(d["a"], float), np.array(d["b"], float).reshape(4, -1)
    return a, b, np.diag([0.0, 0.0, 1e6, 0.0]), np.eye(1)


def random_problem(n, seed):
    rng = np.random.default_rng(seed)
    a = rng.standard_normal((n, n)) / np.sqrt(n) + 0.2 * np.eye(n)
    b = rng.standard_normal((n, max(1, n // 10)))
    return a, b, np.eye(n), np.eye(b.shape[1])


def chain(n):
    # Masses and springs in a line, light damping, a force on the first.
    k = 2 * np.eye(n // 2) - np.eye(n // 2, k=1) - np.eye(n // 2, k=-1)
    a = np.block([[np.zeros((n // 2, n // 2)), np.eye(n // 2)], [-k, -0.01 * np.eye(n // 2)]])
    b = np.zeros((n, 1))
    b[n // 2, 0] = 1.0
    return a, b, np.eye(n), np.eye(1)


def carex18():
    with open(os.path.join(ROOT, "tests/data/riccati_fixtures.json")) as f:
        case = json.load(f)["carex"][17]
    return tuple(np.array(case[k]["re"], float) for k in "abqr")


def main():
    problems = [
        ("lab plant", lab_plant(), 200),
        ("random", random_problem(20, 1), 50),
        ("random", random_problem(60, 2), 10),
        ("random", random_problem(100, 3), 7),
        ("chain", chain(100), 7),
        ("CAREX 18", carex18(), 7),
    ]
    cases = [
        {"name": f"{name} n={p[0].shape[0]}", "a": p[0].tolist(), "b": p[1].tolist(),
         "q": p[2].tolist(), "r": p[3].tolist(), "repeats": reps}
        for name, p, reps in problems
    ]
    ours = run_example("riccati_bench", {"cases": cases})

    print(f"{'problem':<18} {'ctrlab (ms)':>12} {'SciPy (ms)':>11} {'ratio':>6}  "
          f"{'ctrlab |res|max':>15} {'SciPy |res|max':>15}")
    for (name, (a, b, q, r), reps), mine in zip(problems, ours):
        t = median_time(lambda: solve_continuous_are(a, b, q, r), reps)
        x = solve_continuous_are(a, b, q, r)
        xb = x @ b
        res = x @ a + a.T @ x + q - xb @ np.linalg.solve(r, xb.T)
        print(f"{mine['name']:<18} {mine['median_s'] * 1e3:12.3f} {t * 1e3:11.3f} "
              f"{mine['median_s'] / t:6.2f}  {mine['max_abs_residual']:15.2e} {np.abs(res).max():15.2e}")

    try:
        import control
    except ImportError:
        print("python-control not installed: no control.lqr comparison", file=sys.stderr)
        return
    a, b, q, r = lab_plant()
    t = median_time(lambda: control.lqr(a, b, q, r), 200)
    mine, fixed = ours[0]["median_s"], ours[0]["fixed_lqr_median_s"]
    print(f"\nlab plant (n=4): control.lqr {t * 1e3:.3f} ms; "
          f"ctrlab lqr (fixed size) {fixed * 1e6:.1f} µs, {t / fixed:.0f}× faster; "
          f"ctrlab care (run-time sized) {mine * 1e6:.1f} µs, {t / mine:.0f}× faster")


if __name__ == "__main__":
    main()
