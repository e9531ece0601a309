"""Issue 28's peer disagreements: python-control's own test cases on which
ctrlab answered differently, with python-control's and SciPy's answers.

- margins_gh523b: python-control's `test_stability_margins_discrete`
  (control/tests/margin_test.py, case "gh-523 b"): 5e4 / (s^4 + 101 s^3 +
  10101 s^2 + 10100 s + 10000) sampled by ZOH at 1 ms. The test's own
  reference row and rtol (1e-5), python-control's `stability_margins` of
  the sampled tf, the sampled tf itself, and the crossings solved by
  `brentq` on |L(e^{jw dt})| = 1 and Im L = 0 ("refined"). python-control
  returns no delay margin; "dm" is pm (rad, mod 2 pi) / wgc at its crossing.
- tf2ss_unstable: `test_tf2ss_unstable` (control/tests/statesp_test.py,
  python-control issue #935): a 16-state, badly scaled tf; the poles of
  the tf (np.roots) and of SciPy's `tf2ss` realisation (np.linalg.eigvals,
  LAPACK dgeev, balanced), compared there with `assert_allclose(rtol=1e-4)`.
- phase: `test_initial_phase`, `test_phase_wrap`,
  `test_phase_wrap_multiple_systems` (control/tests/freqresp_test.py):
  python-control `bode(sys, omega, plot=False, initial_phase=..,
  wrap_phase=..)` phases (rad) on a fixed grid, with each test's expected
  bounds and tolerance.
- static_gain: `scipy.signal.tf2ss([2], [1])` (one state) and python-control
  `tf2ss(tf([2], [1]))` (no state).

    python3 tests/data/gen_peer_cases_28.py > tests/data/peer_cases_28.json
"""

import json
import math
import warnings

import control as ct
import numpy as np
import scipy
import scipy.signal
from scipy.optimize import brentq


def rows(m):
    return np.atleast_2d(np.asarray(m, dtype=float)).tolist()


def cplx(v):
    return [[float(z.real), float(z.imag)] for z in v]


def margins_gh523b():
    cnum, cden, dt = [5e4], [1.0, 101.0, 10101.0, 10100.0, 10000.0], 1e-3
    tf = ct.TransferFunction(cnum, cden).sample(dt)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "numerical inaccuracy in 'poly'"
        gm, pm, sm, wpc, wgc, wms = ct.stability_margins(tf)
    num = np.asarray(tf.num[0][0], dtype=float)
    den = np.asarray(tf.den[0][0], dtype=float)

    def at(w):
        z = np.exp(1j * w * dt)
        return np.polyval(num, z) / np.polyval(den, z)

    wgc_r = brentq(lambda w: abs(at(w)) - 1.0, 0.9 * wgc, 1.1 * wgc, xtol=1e-15, rtol=1e-15)
    wpc_r = brentq(lambda w: at(w).imag, 0.9 * wpc, 1.1 * wpc, xtol=1e-15, rtol=1e-15)
    pm_r = float(np.angle(at(wgc_r), deg=True) % 360.0 - 180.0)
    gm_r = float(1.0 / abs(at(wpc_r)))
    cont = ct.TransferFunction(cnum, cden)
    cgm, cpm, _, cwpc, cwgc, _ = ct.stability_margins(cont)
    return {
        "source_test": "control/tests/margin_test.py::test_stability_margins_discrete (gh-523 b)",
        "cnum": cnum, "cden": cden, "dt": dt,
        "test_ref": {"gm": 18.8766, "pm": 26.3564, "sm": 0.406841,
                     "wpc": 9.76358, "wgc": 2.32933, "wms": 2.55986},
        "test_rtol": 1e-5,
        "num": num.tolist(), "den": den.tolist(),
        "python_control": {"gm": float(gm), "pm": float(pm), "sm": float(sm),
                           "wpc": float(wpc), "wgc": float(wgc), "wms": float(wms),
                           "dm": float((pm % 360.0) * math.pi / 180.0 / wgc),
                           "abs_l_at_wgc": float(abs(at(wgc)))},
        "refined": {"gm": gm_r, "pm": pm_r, "wpc": float(wpc_r), "wgc": float(wgc_r),
                    "dm": float((pm_r % 360.0) * math.pi / 180.0 / wgc_r)},
        "continuous": {"gm": float(cgm), "pm": float(cpm), "wpc": float(cwpc), "wgc": float(cwgc)},
    }


def tf2ss_unstable():
    num = [9.94004350e-13, 2.67602795e-11, 2.31058712e-10, 1.15119493e-09,
           5.04635153e-09, 1.34066064e-08, 2.11938725e-08, 2.39940325e-08,
           2.05897777e-08, 1.17092854e-08, 4.71236875e-09, 1.19497537e-09,
           1.90815347e-10, 1.00655454e-11, 1.47388887e-13, 8.40314881e-16,
           1.67195685e-18]
    den = [9.43513863e-11, 6.05312352e-08, 7.92752628e-07, 5.23764693e-06,
           1.82502556e-05, 1.24355899e-05, 8.68206174e-06, 2.73818482e-06,
           4.29133144e-07, 3.85554417e-08, 1.62631575e-09, 8.41098151e-12,
           9.85278302e-15, 4.07646645e-18, 5.55496497e-22, 3.06560494e-26,
           5.98908988e-31]
    tf_sys = ct.tf(num, den)
    ss_sys = ct.tf2ss(tf_sys, method="scipy")
    a, b, c, d = scipy.signal.tf2ss(num, den)
    return {
        "source_test": "control/tests/statesp_test.py::test_tf2ss_unstable (issue #935)",
        "num": num, "den": den,
        "rtol": 1e-4,
        "tf_poles": cplx(np.sort(tf_sys.poles())),
        "ss_poles": cplx(np.sort(ss_sys.poles())),
        "a": rows(a), "b": rows(b), "c": rows(c), "d": rows(d),
    }


def phase_cases():
    w = np.logspace(-2, 2, 41)
    out = []

    def bode(name, num, den, test, initial_phase=None, wrap_phase=None, **bounds):
        kw = {}
        if initial_phase is not None:
            kw["initial_phase"] = initial_phase
        if wrap_phase is not None:
            kw["wrap_phase"] = wrap_phase
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            _, phase, _ = ct.bode(ct.tf(num, den), w, plot=False, **kw)
        out.append({"name": name, "test": test, "num": num, "den": den,
                    "initial_phase": initial_phase, "wrap_phase": wrap_phase,
                    "phase": [float(p) for p in phase], **bounds})

    pi = math.pi
    for order, default in [(1, -pi / 2), (2, -pi), (3, -3 * pi / 2), (4, 0.0)]:
        den = [1.0] + [0.0] * order
        bode(f"order{order}, default", [1.0], den, "test_initial_phase", expected=default)
    for order, ip, expected in [(1, 180, 3 * pi / 2), (2, 180, pi), (3, 180, pi / 2),
                                (4, 180, 0.0), (4, -360, -2 * pi)]:
        den = [1.0] + [0.0] * order
        bode(f"order{order}, {ip}", [1.0], den, "test_initial_phase", initial_phase=ip,
             expected=expected)
    for order, wp, lo, hi in [(1, None, -pi / 2, 0.0), (1, True, -pi, pi), (1, -270, -3 * pi / 2, pi / 2),
                              (3, None, -3 * pi / 2, 0.0), (3, True, -pi, pi), (3, -270, -3 * pi / 2, pi / 2),
                              (5, True, -pi, pi), (5, -270, -3 * pi / 2, pi / 2)]:
        den = [1.0] + [0.0] * order
        bode(f"order{order}, wrap {wp}", [1.0], den, "test_phase_wrap", wrap_phase=wp,
             min_phase=lo, max_phase=hi)
    # zpk([], [1, 1], gain=1) = 1 / (s^2 - 2 s + 1)
    bode("unstable double pole", [1.0], [1.0, -2.0, 1.0], "test_phase_wrap_multiple_systems",
         min_phase=-2 * pi, max_phase=-pi)
    return {"omega": w.tolist(), "initial_phase_tolerance": 0.1, "cases": out}


def static_gain():
    a, b, c, d = scipy.signal.tf2ss([2.0], [1.0])
    pc = ct.tf2ss(ct.tf([2.0], [1.0]))
    return {
        "num": [2.0], "den": [1.0],
        "scipy": {"a": rows(a), "b": rows(b), "c": rows(c), "d": rows(d)},
        "python_control": {"states": int(pc.nstates), "d": rows(pc.D)},
    }


def main():
    print(json.dumps({
        "source": f"python-control {ct.__version__}, SciPy {scipy.__version__}, NumPy {np.__version__} "
                  "(no slycot), tests/data/gen_peer_cases_28.py",
        "margins_gh523b": margins_gh523b(),
        "tf2ss_unstable": tf2ss_unstable(),
        "phase": phase_cases(),
        "static_gain": static_gain(),
    }, indent=1))


if __name__ == "__main__":
    main()
