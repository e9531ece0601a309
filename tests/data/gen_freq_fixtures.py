#!/usr/bin/env python3
"""Generates tests/data/freq_fixtures.json: python-control's frequency
responses, margins, bandwidth, transfer functions, zeros and zpk data,
for ctrlab::freq.

    pip install control scipy numpy
    python3 tests/data/gen_freq_fixtures.py > tests/data/freq_fixtures.json

python-control 0.10.2 without Slycot: ss2tf and tf2ss go through SciPy's
ss2tf/tf2ss, StateSpace.zeros() through SciPy's QZ on the Rosenbrock
pencil (square systems only).

Each case holds the model (matrices as lists of rows, "dt" null for a
continuous model), the frequencies "omega" (rad/s) and the response
"re"/"im" as [output][input][k] (python-control `frequency_response`).
SISO cases also hold:
- "num"/"den": python-control ss2tf (SciPy), descending powers;
- "poles", "zeros" as [re, im] pairs: poles of the model, zeros from
  StateSpace.zeros() with the QZ's spurious huge values (infinite zeros
  perturbed by rounding, |z| > 1e6) removed;
- "zpk_gain": the gain of ct.zpk form, num[first non-negligible] / den[0];
- "margins" of the loop L = loop_gain * G: python-control
  stability_margins(method="poly") (gm, pm in degrees, wpc, wgc; null for inf/nan) and the
  delay margin min over returnall=True's gain crossovers wc_i > 0 of
  ((pm_i mod 360) * pi / 180) / wc_i, seconds (python-control has none);
  "refined": the phase and gain crossovers polished by brentq on the
  state-space loop evaluated directly, and gm, pm, dm there (the delay
  margin's minimum over every polished gain crossover);
- "bandwidth" (continuous only): python-control bandwidth(sys) at -3 dB
  (python-control evaluates a discrete model at z = j w there, so discrete
  bandwidths are not taken from it).
The "tf2ss" case holds SciPy's tf2ss of a biproper transfer function.
"""

import json
import math

import numpy as np
import scipy
import control as ct


def mat(m):
    return [[float(v) for v in row] for row in np.atleast_2d(np.asarray(m, dtype=float))]


def cplx(v):
    return [[float(np.real(x)), float(np.imag(x))] for x in np.atleast_1d(v)]


def fnum(x):
    x = float(x)
    return x if math.isfinite(x) else None


def refined(loop, wpc, wgc, wgcs):
    """The crossings polished by brentq (xtol 1e-15) on the state-space
    loop, evaluated directly, in a bracket of 1e-6 relative around
    python-control's: its polynomial roots near |z| = 1 carry ~1e-9."""
    def at(w):
        return complex(loop(np.exp(1j * w * loop.dt)) if loop.dt else loop(1j * w))
    out = {}
    if math.isfinite(wpc):
        w = scipy.optimize.brentq(lambda w: at(w).imag, wpc * (1 - 1e-6), wpc * (1 + 1e-6), xtol=1e-15)
        out["wpc"], out["gm"] = w, 1.0 / abs(at(w))
    def polish(wc):
        f = lambda w: abs(at(w)) - 1.0
        lo, hi = wc * (1 - 1e-6), wc * (1 + 1e-6)
        # A crossing python-control found that does not change sign within
        # the bracket (a touch) is kept as found.
        w = scipy.optimize.brentq(f, lo, hi, xtol=1e-15) if f(lo) * f(hi) < 0 else wc
        return w, float(np.remainder(np.angle(at(w), deg=True), 360.0) - 180.0)
    if math.isfinite(wgc):
        out["wgc"], out["pm"] = polish(wgc)
    dms = []
    for wc in wgcs:
        if wc > 0:
            w, pm = polish(wc)
            dms.append(float(np.remainder(pm, 360.0) * math.pi / 180.0 / w))
    if dms:
        out["dm"] = min(dms)
    return out


def case(name, sys, omega, loop_gain=None):
    resp = ct.frequency_response(sys, omega, squeeze=False)
    fr = np.asarray(resp.complex).reshape(sys.noutputs, sys.ninputs, len(omega))  # [output][input][k]
    out = {
        "name": name,
        "dt": None if sys.dt == 0 else float(sys.dt),
        "a": mat(sys.A), "b": mat(sys.B), "c": mat(sys.C), "d": mat(sys.D),
        "omega": [float(w) for w in omega],
        "re": [[[float(v) for v in fr[i, j].real] for j in range(sys.ninputs)] for i in range(sys.noutputs)],
        "im": [[[float(v) for v in fr[i, j].imag] for j in range(sys.ninputs)] for i in range(sys.noutputs)],
        "poles": cplx(np.sort_complex(sys.poles())),
    }
    if sys.ninputs == sys.noutputs:
        z = sys.zeros()
        out["zeros"] = cplx(np.sort_complex(z[np.abs(z) < 1e6]))
    if sys.ninputs == 1 and sys.noutputs == 1:
        g = ct.ss2tf(sys)
        num = np.asarray(g.num[0][0], dtype=float)
        den = np.asarray(g.den[0][0], dtype=float)
        out["num"] = [float(v) for v in num]
        out["den"] = [float(v) for v in den]
        lead = num[np.abs(num) > 1e-9 * np.max(np.abs(num))][0]
        out["zpk_gain"] = float(lead / den[0])
        if loop_gain is not None:
            loop = loop_gain * g
            # method="poly" throughout: for this discrete loop "best" falls
            # back to interpolated frequency data (|num| << |den|).
            gm, pm, sm, wpc, wgc, wms = ct.stability_margins(loop, method="poly")
            gms, pms, sms, wpcs, wgcs, wmss = ct.stability_margins(loop, returnall=True, method="poly")
            dms = [(np.remainder(p, 360.0) * math.pi / 180.0) / w for p, w in zip(pms, wgcs) if w > 0]
            out["margins"] = {
                "loop_gain": float(loop_gain),
                "gm": fnum(gm), "pm": fnum(pm), "wpc": fnum(wpc), "wgc": fnum(wgc),
                "dm": fnum(min(dms)) if dms else None,
                "refined": refined(loop_gain * sys, wpc, wgc, wgcs),
            }
        if sys.dt == 0:
            try:
                bw = ct.bandwidth(sys)
                out["bandwidth"] = fnum(bw)
            except Exception:
                out["bandwidth"] = None
    return out


def main():
    cases = []
    w = np.logspace(-2, 3, 61)

    # A second-order lag, 10 / (s^2 + 2 s + 10), realised by tf2ss.
    lag = ct.ss(ct.tf([10.0], [1.0, 2.0, 10.0]))
    cases.append(case("lag2", lag, w, loop_gain=1.0))

    # A type-1 loop: an integrator, 10 / (s (s + 1) (s + 5)).
    integ = ct.ss(ct.tf([10.0], [1.0, 6.0, 5.0, 0.0]))
    cases.append(case("integrator", integ, w, loop_gain=1.0))

    # Biproper with a feedthrough: (0.5 s^3 + 2 s^2 + s + 3) / (s^3 + 3 s^2 + 4 s + 2).
    bip = ct.ss(ct.tf([0.5, 2.0, 1.0, 3.0], [1.0, 3.0, 4.0, 2.0]))
    cases.append(case("biproper", bip, w, loop_gain=2.0))

    # Discrete: 2 / (s + 1)^3 sampled with ZOH at 0.1 s.
    cont = ct.ss(ct.tf([2.0], [1.0, 3.0, 3.0, 1.0]))
    disc = ct.sample_system(cont, 0.1, method="zoh")
    wd = np.logspace(-2, np.log10(0.99 * np.pi / 0.1), 61)
    cases.append(case("discrete", disc, wd, loop_gain=1.0))

    # MIMO, 3 states, 2 x 2, D = 0 and C B invertible (relative degree 1).
    mimo = ct.ss([[-1.0, 0.5, 0.0], [-0.5, -2.0, 1.0], [0.0, -1.0, -3.0]],
                 [[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]],
                 [[1.0, 0.0, 0.5], [0.0, 1.0, 0.0]],
                 [[0.0, 0.0], [0.0, 0.0]])
    cases.append(case("mimo", mimo, w))

    # The lab plant: force on cart 2 to its position, under P control of
    # 2000 N/m for the margins.
    with open("tests/data/mass_spring_nominal.json") as f:
        lab = json.load(f)
    plant = ct.ss(np.array(lab["a"]), np.array(lab["b"]), [[0.0, 0.0, 1.0, 0.0]], [[0.0]])
    cases.append(case("lab_plant", plant, np.logspace(0, 3, 61), loop_gain=2000.0))

    # SciPy's tf2ss of a biproper transfer function.
    a, b, c, d = scipy.signal.tf2ss([0.5, 2.0, 1.0, 3.0], [2.0, 6.0, 8.0, 4.0])
    tf2ss = {"num": [0.5, 2.0, 1.0, 3.0], "den": [2.0, 6.0, 8.0, 4.0],
             "a": mat(a), "b": mat(b), "c": mat(c), "d": mat(d)}

    print(json.dumps({
        "source": f"python-control {ct.__version__}, SciPy {scipy.__version__}, NumPy {np.__version__}",
        "cases": cases,
        "tf2ss": tf2ss,
    }, indent=1))


if __name__ == "__main__":
    main()
