"""ctrlab's `lyap` against SciPy's `solve_continuous_lyapunov`, on the same
matrices, in the same run (issue 29: at N = 100 at most twice SciPy's time).

    python3 scripts/lyapunov_vs_scipy.py

Builds and runs `examples/lyapunov_bench.rs` (release) on problems written
to a temporary JSON file, times SciPy on the same matrices and prints one
table. Times are medians of several solves (wall clock, this machine, one
thread: `timing` pins SciPy's BLAS to one thread, as ctrlab runs on one).

Problems: the lab plant (tests/calling_style.rs `two_carts()`, Q = B Bᵀ)
and random stable models at n = 20 and 100 (seeded: A = G/√n − 1.5 I with
G N(0, 1), Q = H Hᵀ), the sizes of `benches/lyapunov.rs`.
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from timing import median_time, run_example  # noqa: E402  (sets the BLAS threads first)

import numpy as np  # noqa: E402
from scipy.linalg import solve_continuous_lyapunov  # noqa: E402


def two_carts():
    m1, m2, k1, k2, c1, c2 = 1.3, 0.7, 1000.0, 1000.0, 2.0, 1.0
    a = np.array(
        [
            [0.0, 1.0, 0.0, 0.0],
            [-(k1 + k2) / m1, -c1 / m1, k2 / m1, 0.0],
            [0.0, 0.0, 0.0, 1.0],
            [k2 / m2, 0.0, -k2 / m2, -c2 / m2],
        ]
    )
    b = np.array([[0.0], [0.0], [0.0], [1.0 / m2]])
    return a, b @ b.T


def random(n, seed):
    rng = np.random.default_rng(seed)
    a = rng.standard_normal((n, n)) / np.sqrt(n) - 1.5 * np.eye(n)
    h = rng.standard_normal((n, n))
    return a, h @ h.T


def main():
    cases = [("lab plant n=4", *two_carts(), 2001)]
    cases += [(f"random n={n}", *random(n, n), 201 if n < 100 else 41) for n in (20, 100)]
    payload = {
        "cases": [
            {"name": name, "a": a.tolist(), "q": q.tolist(), "repeats": repeats}
            for name, a, q, repeats in cases
        ]
    }
    ours = {line["name"]: line for line in run_example("lyapunov_bench", payload)}
    print(f"{'case':<16} {'ctrlab':>12} {'SciPy':>12} {'ratio':>7}  rel. residual")
    for name, a, q, repeats in cases:
        t = median_time(lambda: solve_continuous_lyapunov(a, -q), repeats)
        mine = ours[name]
        print(
            f"{name:<16} {mine['median_s'] * 1e3:>9.3f} ms {t * 1e3:>9.3f} ms "
            f"{mine['median_s'] / t:>7.2f}  {mine['relative_residual']:.1e}"
        )


if __name__ == "__main__":
    main()
