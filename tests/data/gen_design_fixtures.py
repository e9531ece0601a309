#!/usr/bin/env python3
"""Generates tests/data/design_fixtures.json: reference values for ctrlab's
design functions from python-control (and SciPy underneath it).

    pip install control scipy numpy
    python3 tests/data/gen_design_fixtures.py > tests/data/design_fixtures.json

Cases:
- "place": python-control `place` (SciPy `place_poles`, Tits-Yang) on
  multi-input systems: the gain, the achieved poles, and the Frobenius norm
  of the gain.
- "lqe" / "dlqe": python-control `lqe(A, G, C, QN, RN)` / `dlqe(...)`: the
  gain L, the Riccati solution P, the estimator poles; for dlqe also the
  current-estimator gain M = P C' (C P C' + RN)^-1 computed here by NumPy
  (python-control returns only the predictor gain L = A M).
- "lqi": python-control `lqr(sys, Q, R, integral_action=C_i)` (continuous
  and discrete): K, S, E on python-control's augmented state.

Matrices are lists of rows; complex numbers are [re, im] pairs.
"""

import json
import sys

import numpy as np
import scipy
import scipy.signal
import control as ct

# The lab's nominal plant (docs/lab.md), force input.
M1, M2, K1, K2, B1, B2 = 1.3, 0.7, 1000.0, 1000.0, 10.0, 5.0
A_LAB = np.array([
    [0.0, 1.0, 0.0, 0.0],
    [-(K1 + K2) / M1, -B1 / M1, K2 / M1, 0.0],
    [0.0, 0.0, 0.0, 1.0],
    [K2 / M2, 0.0, -K2 / M2, -B2 / M2],
])
B_LAB = np.array([[0.0], [0.0], [0.0], [1.0 / M2]])
# A force on each cart: two inputs.
B_LAB2 = np.array([[0.0, 0.0], [1.0 / M1, 0.0], [0.0, 0.0], [0.0, 1.0 / M2]])
POSITIONS = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
T = 0.002
COUNT = 0.080 / 8192.0  # m per encoder count

# python-control's testPlace system (from SciPy's place_poles example).
A_SCIPY = np.array([[1.380, -0.2077, 6.715, -5.676],
                    [-0.5814, -4.290, 0, 0.6750],
                    [1.067, 4.273, -6.654, 5.893],
                    [0.0480, 4.273, 1.343, -2.104]])
B_SCIPY = np.array([[0, 5.679],
                    [1.136, 1.136],
                    [0, 0],
                    [-3.146, 0]])


def mat(m):
    return [[float(v) for v in row] for row in np.atleast_2d(np.asarray(m, dtype=float))]


def cplx(v):
    return [[float(np.real(z)), float(np.imag(z))] for z in np.asarray(v).ravel()]


def zoh(a, b):
    d = ct.c2d(ct.ss(a, b, np.eye(a.shape[0]), 0), T, method="zoh")
    return np.asarray(d.A), np.asarray(d.B)


def place_case(name, a, b, poles, discrete=False):
    k = ct.place(a, b, poles)
    achieved = np.linalg.eigvals(a - b @ k)
    return {
        "name": name,
        "discrete": discrete,
        "a": mat(a),
        "b": mat(b),
        "poles": cplx(poles),
        "gain": mat(k),
        "gain_norm": float(np.linalg.norm(k)),
        "achieved": cplx(np.sort_complex(achieved)),
    }


def lqe_case(name, a, g, c, qn, rn, discrete=False):
    fn = ct.dlqe if discrete else ct.lqe
    l, p, e = fn(a, g, c, qn, rn)
    case = {
        "name": name,
        "a": mat(a),
        "g": mat(g),
        "c": mat(c),
        "qn": mat(qn),
        "rn": mat(rn),
        "gain": mat(l),
        "covariance": mat(p),
        "poles": cplx(np.sort_complex(e)),
    }
    if discrete:
        m = p @ c.T @ np.linalg.inv(c @ p @ c.T + rn)
        case["current_gain"] = mat(m)
    return case


def lqi_case(name, a, b, ci, q, r, dt=None):
    sys_ = ct.ss(a, b, np.eye(a.shape[0]), 0, dt) if dt else ct.ss(a, b, np.eye(a.shape[0]), 0)
    k, s, e = ct.lqr(sys_, q, r, integral_action=ci)
    return {
        "name": name,
        "dt": dt,
        "a": mat(a),
        "b": mat(b),
        "ci": mat(ci),
        "q_pc": mat(q),
        "r": mat(r),
        "gain_pc": mat(k),
        "riccati_pc": mat(s),
        "poles": cplx(np.sort_complex(e)),
    }


def main():
    rng = np.random.default_rng(13)
    a5 = rng.standard_normal((5, 5))
    b53 = rng.standard_normal((5, 3))
    ad, bd2 = zoh(A_LAB, B_LAB2)
    place = [
        place_case("scipy_example", A_SCIPY, B_SCIPY,
                   [-0.5 + 1j, -0.5 - 1j, -5.0566, -8.6659]),
        place_case("repeated_and_complex", A_SCIPY, B_SCIPY,
                   [-2.0, -2.0, -1.0 + 1j, -1.0 - 1j]),
        place_case("two_carts_two_forces", A_LAB, B_LAB2,
                   [-20 + 20j, -20 - 20j, -40.0, -40.0]),
        place_case("two_carts_two_pairs", A_LAB, B_LAB2,
                   [-10 + 30j, -10 - 30j, -15 + 15j, -15 - 15j]),
        place_case("two_carts_discrete", ad, bd2,
                   [0.9 + 0.05j, 0.9 - 0.05j, 0.8, 0.8], discrete=True),
        place_case("random_5x3_triple", a5, b53,
                   [-1.0, -1.0, -1.0, -2.0 + 0.5j, -2.0 - 0.5j]),
    ]

    a3 = np.array([[-1.0, 0.5, 0.0], [0.0, -2.0, 1.0], [0.3, 0.0, -0.5]])
    g3 = np.array([[1.0, 0.0], [0.0, 1.0], [0.5, 0.5]])
    c3 = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    qn3 = np.array([[2.0, 0.3], [0.3, 1.0]])
    rn3 = np.array([[0.1, 0.02], [0.02, 0.2]])
    rn_lab = np.eye(2) * COUNT**2 / 12.0
    a3d = np.asarray(ct.c2d(ct.ss(a3, g3, c3, 0), 0.1).A)
    lqe = [
        # python-control's test_LQE.
        lqe_case("python_control_scalar", np.array([[0.0]]), np.array([[0.1]]),
                 np.array([[1.0]]), np.array([[10.0]]), np.array([[2.0]])),
        lqe_case("three_states_two_outputs", a3, g3, c3, qn3, rn3),
        lqe_case("lab_positions", A_LAB, B_LAB, POSITIONS, np.array([[1.0]]), rn_lab),
    ]
    add, bdd = zoh(A_LAB, B_LAB)
    dlqe = [
        lqe_case("three_states_two_outputs", a3d, g3, c3, qn3, rn3, discrete=True),
        lqe_case("lab_positions", add, bdd, POSITIONS, np.array([[1.0]]), rn_lab,
                 discrete=True),
        lqe_case("lab_positions_noisy_force", add, bdd, POSITIONS, np.array([[100.0]]),
                 np.eye(2) * 1e-8, discrete=True),
    ]

    ci2 = np.array([[0.0, 0.0, 1.0, 0.0]])
    a4 = rng.standard_normal((4, 4)) - 2.0 * np.eye(4)
    b42 = rng.standard_normal((4, 2))
    a4d = np.asarray(ct.c2d(ct.ss(a4, b42, np.eye(4), 0), 0.1).A)
    b4d = np.asarray(ct.c2d(ct.ss(a4, b42, np.eye(4), 0), 0.1).B)
    lqi = [
        lqi_case("lab_cart2", A_LAB, B_LAB, ci2,
                 np.diag([0.0, 0.0, 1e6, 0.0, 1e8]), np.array([[1.0]])),
        # Discrete: python-control integrates without T, so 1e8 T^2 here is
        # 1e8 on MATLAB's (and ctrlab's) T-scaled integrator.
        lqi_case("lab_cart2_discrete", add, bdd, ci2,
                 np.diag([0.0, 0.0, 1e6, 0.0, 1e8 * T * T]), np.array([[1.0]]), dt=T),
        # python-control's test_lqr_integral_* shape: integrate two states.
        lqi_case("mimo_two_integrators", a4, b42, np.eye(2, 4), np.eye(6), np.eye(2)),
        lqi_case("mimo_two_integrators_discrete", a4d, b4d, np.eye(2, 4), np.eye(6),
                 np.eye(2), dt=0.1),
    ]

    out = {
        "source": f"python-control {ct.__version__}, SciPy {scipy.__version__}, "
                  f"NumPy {np.__version__} (tests/data/gen_design_fixtures.py)",
        "place": place,
        "lqe": lqe,
        "dlqe": dlqe,
        "lqi": lqi,
    }
    json.dump(out, sys.stdout, indent=1)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
