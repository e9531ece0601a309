#!/usr/bin/env python3
"""Generates tests/data/dyn_fixtures.json: python-control and SciPy results
for a model whose size is chosen at run time, for ctrlab's DynStateSpace.

    pip install control scipy numpy
    python3 tests/data/gen_dyn_fixtures.py > tests/data/dyn_fixtures.json

The model is a chain of N = 7 coupled first-order sections, built by the
same loop in tests/dyn.rs (`chain(7)`):

    A[i][i]   = -(1 + 0.5 i)
    A[i+1][i] = 2 + i          (section i drives section i + 1)
    A[i][i+1] = -0.3 (i + 1)   (and is pushed back by it)
    B = [e_0, e_3]             (force on the first and the fourth section)
    C = [e_6; e_0]             (the last and the first section measured)
    D = 0

Recorded: the poles (sorted by real part, then imaginary part, as ctrlab
sorts them), python-control's damp (wn, zeta), dcgain, ctrb and obsv and
NumPy's matrix_rank of each, SciPy cont2discrete ZOH and Tustin at
dt = 0.05 s, python-control step_info of channel (output 0, input 0) on
ctrlab's time_grid(t_end, grid_dt) (k * grid_dt), python-control place
(SciPy place_poles, YT) on (A, B) and acker on (A, B[:, 0]) with the
targets listed.
"""

import json
import sys

import numpy as np
import scipy
import scipy.signal
import control as ct

N = 7


def chain(n):
    a = np.zeros((n, n))
    for i in range(n):
        a[i, i] = -(1.0 + 0.5 * i)
        if i + 1 < n:
            a[i + 1, i] = 2.0 + i
            a[i, i + 1] = -0.3 * (i + 1)
    b = np.zeros((n, 2))
    b[0, 0] = 1.0
    b[3, 1] = 1.0
    c = np.zeros((2, n))
    c[0, n - 1] = 1.0
    c[1, 0] = 1.0
    d = np.zeros((2, 2))
    return a, b, c, d


def mat(m):
    return [[float(v) for v in row] for row in np.atleast_2d(np.asarray(m, dtype=float))]


def cplx(v):
    return [[float(np.real(p)), float(np.imag(p))] for p in v]


def sort_poles(p):
    return sorted(p, key=lambda z: (np.real(z), np.imag(z)))


a, b, c, d = chain(N)
sys_c = ct.ss(a, b, c, d)
poles = sort_poles(np.linalg.eigvals(a))
wn, zeta, damp_poles = ct.damp(sys_c, doprint=False)
# damp's order is its own: sort its rows the same way as the poles.
order = sorted(range(N), key=lambda i: (np.real(damp_poles[i]), np.imag(damp_poles[i])))

dt = 0.05
zoh = scipy.signal.cont2discrete((a, b, c, d), dt, method="zoh")
tustin = scipy.signal.cont2discrete((a, b, c, d), dt, method="bilinear")
sys_d = ct.ss(zoh[0], zoh[1], zoh[2], zoh[3], dt)

t_end, grid_dt = 15.0, 0.001
t = np.arange(int(round(t_end / grid_dt)) + 1) * grid_dt
siso = ct.ss(a, b[:, [0]], c[[0], :], d[[0], [0]])
info = ct.step_info(siso, T=t)

targets = [complex(-2, 1), complex(-2, -1), -3, -4, -5, complex(-6, 2), complex(-6, -2)]
k_place = ct.place(a, b, targets)
achieved = sort_poles(np.linalg.eigvals(a - b @ k_place))
k_acker = ct.acker(a, b[:, [0]], targets)

out = {
    "source": f"python-control {ct.__version__}, SciPy {scipy.__version__}, NumPy {np.__version__}",
    "n": N,
    "A": mat(a),
    "B": mat(b),
    "C": mat(c),
    "D": mat(d),
    "poles": cplx(poles),
    "damp_wn": [float(wn[i]) for i in order],
    "damp_zeta": [float(zeta[i]) for i in order],
    "dcgain": mat(ct.dcgain(sys_c)),
    "ctrb": mat(ct.ctrb(a, b)),
    "ctrb_rank": int(np.linalg.matrix_rank(ct.ctrb(a, b))),
    "obsv": mat(ct.obsv(a, c)),
    "obsv_rank": int(np.linalg.matrix_rank(ct.obsv(a, c))),
    "dt": dt,
    "zoh": {"A": mat(zoh[0]), "B": mat(zoh[1]), "C": mat(zoh[2]), "D": mat(zoh[3])},
    "tustin": {"A": mat(tustin[0]), "B": mat(tustin[1]), "C": mat(tustin[2]), "D": mat(tustin[3])},
    "zoh_poles": cplx(sort_poles(np.linalg.eigvals(zoh[0]))),
    "zoh_dcgain": mat(ct.dcgain(sys_d)),
    "step_info": {
        "t_end": t_end,
        "grid_dt": grid_dt,
        "output": 0,
        "input": 0,
        **{k: float(v) for k, v in info.items()},
    },
    "place": {
        "targets": cplx(targets),
        "K": mat(k_place),
        "achieved": cplx(achieved),
    },
    "acker": {"targets": cplx(targets), "K": mat(k_acker)},
}
json.dump(out, sys.stdout, indent=1)
sys.stdout.write("\n")
