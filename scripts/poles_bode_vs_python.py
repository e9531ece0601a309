"""ctrlab's `poles()` at N = 100 against NumPy's `eigvals` (LAPACK dgeev),
and its 1000-point Bode of the lab plant against python-control's
frequency response, on the same data in the same run.

    python3 scripts/poles_bode_vs_python.py

Builds and runs `examples/poles_bode_bench.rs` (release) on a seeded
100 × 100 matrix with N(0, 1) entries written to a temporary JSON file,
times NumPy and python-control on the same inputs, and prints one table.
Times are medians (wall clock, one thread: OPENBLAS_NUM_THREADS=1 etc.).
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from timing import ROOT, median_time, run_example  # noqa: E402  (sets the BLAS threads first)

import json  # noqa: E402

import numpy as np  # noqa: E402

REPEATS = 20


def main():
    a = np.random.default_rng(1).standard_normal((100, 100))
    [mine] = run_example("poles_bode_bench", {"a": a.tolist(), "repeats": REPEATS})

    numpy_poles = median_time(lambda: np.linalg.eigvals(a), REPEATS)
    largest = np.linalg.eigvals(a).real.max()
    print(f"{'what':<40} {'ctrlab':>10} {'Python':>10}")
    print(f"{'poles, N = 100 (ms) vs numpy eigvals':<40} {mine['poles_median_s'] * 1e3:10.3f} "
          f"{numpy_poles * 1e3:10.3f}   (largest Re: {mine['largest_pole_re']:.12f} / {largest:.12f})")

    try:
        import control
    except ImportError:
        print("python-control not installed: no frequency-response comparison")
        return
    with open(os.path.join(ROOT, "tests/data/mass_spring_nominal.json")) as f:
        d = json.load(f)
    pa, pb = np.array(d["a"], float), np.array(d["b"], float).reshape(4, -1)
    pc = np.array([mine["plant_c"]], float)
    sys = control.ss(pa, pb, pc, np.zeros((1, pb.shape[1])))
    w = np.logspace(0, 3, 1000)

    def response():
        r = control.frequency_response(sys, w)
        return r.magnitude, r.phase

    t = median_time(response, 10 * REPEATS)
    print(f"{'1000-point Bode, lab plant (µs)':<40} {mine['bode_median_s'] * 1e6:10.1f} "
          f"{t * 1e6:10.1f}   (python-control frequency_response)")


if __name__ == "__main__":
    main()
