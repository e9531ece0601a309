"""ctrlab's `hinf_norm` and `h2_norm` against python-control 0.10.2's
`norm(sys, 'inf')` and `norm(sys, 2)` (no slycot: its SciPy path), on the
same models, in the same run (issue 29, item 3: H∞ at N = 100 at most
twice python-control's time, and far faster at the lab's 4 states).

    python3 scripts/norms_vs_python.py

Builds and runs `examples/norms_bench.rs` (release) on models written to
a temporary JSON file, times python-control on the same matrices and
prints one table. Times are medians of several calls (wall clock, this
machine, one thread: `timing` pins NumPy's BLAS to one thread, as ctrlab
runs on one). python-control's H∞ is a bisection to its default relative
`tol = 1e-6`; ctrlab's is to `HINF_RTOL = 1e-10`.

Models: the lab plant (tests/calling_style.rs `two_carts()`, force on
cart 2 to its position) and random stable SISO models at n = 20 and 100
(seeded: A = G/√n − 1.5 I with G N(0, 1), B, C N(0, 1), D = 0), the sizes
of `benches/norms.rs`.
"""

import os
import sys
import warnings

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from timing import median_time, run_example  # noqa: E402  (sets the BLAS threads first)

import control  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "data"))
from gen_norms_fixtures import two_carts  # noqa: E402  (the fixtures' lab plant)

warnings.simplefilter("ignore")


def random(n, seed):
    rng = np.random.default_rng(seed)
    a = rng.standard_normal((n, n)) / np.sqrt(n) - 1.5 * np.eye(n)
    b = rng.standard_normal((n, 1))
    c = rng.standard_normal((1, n))
    return a, b, c, np.zeros((1, 1))


def main():
    cases = [("lab plant n=4", *two_carts(), 501)]
    cases += [(f"random n={n}", *random(n, n), 51 if n < 100 else 9) for n in (20, 100)]
    payload = {
        "cases": [
            {"name": name, "a": a.tolist(), "b": b.tolist(), "c": c.tolist(),
             "d": d.tolist(), "repeats": repeats}
            for name, a, b, c, d, repeats in cases
        ]
    }
    ours = {line["name"]: line for line in run_example("norms_bench", payload)}
    print(f"{'case':<15} {'norm':<4} {'ctrlab':>11} {'python-control':>15} {'ratio':>7}  "
          f"{'rel. diff':>9}")
    for name, a, b, c, d, repeats in cases:
        sys_ = control.ss(a, b, c, d)
        mine = ours[name]
        for label, key, f in (
            ("inf", "hinf", lambda: control.norm(sys_, "inf")),
            ("2", "h2", lambda: control.norm(sys_, 2)),
        ):
            value = f()
            t = median_time(f, repeats)
            ctr = mine[f"{key}_median_s"]
            # python-control's H2 is inf when the rounded Gramian has an
            # eigenvalue below zero (a single input's Gramian of a random
            # model is that ill-conditioned at n = 20 and 100).
            diff = (f"{abs(mine[key] - value) / abs(value):>9.1e}" if np.isfinite(value)
                    else f"{'(py: inf)':>9}")
            print(f"{name:<15} {label:<4} {ctr * 1e3:>8.3f} ms {t * 1e3:>12.3f} ms "
                  f"{ctr / t:>7.3f}  {diff}")


if __name__ == "__main__":
    main()
