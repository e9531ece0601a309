#!/usr/bin/env python3
"""Generates tests/data/response_fixtures.json: python-control's step,
impulse and initial-condition responses, for ctrlab's sim::step_response,
sim::impulse_response and sim::initial_response.

    pip install control scipy numpy
    python3 tests/data/gen_response_fixtures.py > tests/data/response_fixtures.json

Definitions (python-control 0.10.2, control/timeresp.py):
- step_response: u = 1 on one input from t = 0, x(0) = 0.
- impulse_response: continuous, the free response from x(0) = B[:, j]
  (the D*delta(t) term is dropped, with a warning); discrete, the response
  to the unit-area pulse u[0] = 1/dt on input j.
- initial_response: the free response from x(0) = X0, u = 0.

Each case holds the model (matrices as lists of rows; "dt" null for a
continuous model), the grid (t_end, grid_dt: ctrlab's time_grid, i.e.
k * grid_dt for k = 0..round(t_end / grid_dt), the times python-control was
given), x0, and the responses: "step" and "impulse" as
[input][output][sample], "initial" as [output][sample].
"""

import json
import sys
import warnings

import numpy as np
import scipy
import control as ct


def mat(m):
    return [[float(v) for v in row] for row in np.atleast_2d(np.asarray(m, dtype=float))]


def case(name, sys, t_end, grid_dt, x0):
    n = int(round(t_end / grid_dt))
    t = np.arange(n + 1) * grid_dt
    step, impulse = [], []
    for j in range(sys.ninputs):
        r = ct.step_response(sys, t, input=j, squeeze=False)
        step.append([[float(v) for v in r.outputs[i, 0, :]] for i in range(sys.noutputs)])
        with warnings.catch_warnings():
            # "System has direct feedthrough": the Dirac term is dropped,
            # as ctrlab drops it.
            warnings.simplefilter("ignore")
            r = ct.impulse_response(sys, t, input=j, squeeze=False)
        impulse.append([[float(v) for v in r.outputs[i, 0, :]] for i in range(sys.noutputs)])
    r = ct.initial_response(sys, t, X0=np.asarray(x0, dtype=float), squeeze=False)
    initial = [[float(v) for v in r.outputs[i, :]] for i in range(sys.noutputs)]
    return {
        "name": name,
        "dt": None if sys.dt == 0 else float(sys.dt),
        "a": mat(sys.A), "b": mat(sys.B), "c": mat(sys.C), "d": mat(sys.D),
        "t_end": t_end, "grid_dt": grid_dt,
        "x0": [float(v) for v in x0],
        "step": step, "impulse": impulse, "initial": initial,
    }


def main():
    cases = []
    # python-control's own test system siso_ss1 (timeresp_test.py), with
    # and without its feedthrough D = 9, on its grid linspace(0, 1, 10).
    a = [[1.0, -2.0], [3.0, -4.0]]
    b = [[5.0], [7.0]]
    c = [[6.0, 8.0]]
    cases.append(case("siso_ss1", ct.ss(a, b, c, [[9.0]]), 1.0, 1.0 / 9.0, [0.5, 1.0]))
    cases.append(case("siso_ss2", ct.ss(a, b, c, [[0.0]]), 1.0, 1.0 / 9.0, [0.5, 1.0]))

    # A lightly damped second-order plant with a zero and a feedthrough,
    # sampled (ZOH) at 0.1 s: y[0] = D/dt in the impulse response.
    cont = ct.ss([[0.0, 1.0], [-4.0, -0.8]], [[0.0], [4.0]], [[1.0, 0.5]], [[0.25]])
    cases.append(case("sampled_second_order", ct.c2d(cont, 0.1, "zoh"), 3.0, 0.1, [1.0, -1.0]))
    cases.append(case("second_order", cont, 3.0, 0.05, [1.0, -1.0]))

    # A coupled continuous MIMO model: three states, two inputs, two outputs.
    mimo = ct.ss(
        [[-1.0, 0.5, 0.0], [-0.5, -1.0, 0.3], [0.0, -0.2, -3.0]],
        [[1.0, 0.0], [0.0, 0.5], [0.4, 1.0]],
        [[1.0, 0.0, 1.0], [0.0, 2.0, -1.0]],
        [[0.0, 0.1], [0.0, 0.0]],
    )
    cases.append(case("mimo_continuous", mimo, 5.0, 0.05, [1.0, 0.0, -1.0]))

    # MATLAB's stepinfo MIMO example: ss(A, B, C, D, 0.2).
    matlab = ct.ss(
        [[0.68, -0.34], [0.34, 0.68]],
        [[0.18, -0.05], [0.04, 0.11]],
        [[0.0, -1.53], [-1.12, -1.10]],
        [[0.0, 0.0], [0.06, -0.37]],
        0.2,
    )
    cases.append(case("matlab_mimo_discrete", matlab, 6.0, 0.2, [1.0, 1.0]))

    out = {
        "source": f"python-control {ct.__version__}, SciPy {scipy.__version__}, "
                  f"NumPy {np.__version__} (tests/data/gen_response_fixtures.py)",
        "cases": cases,
    }
    json.dump(out, sys.stdout, indent=1)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
