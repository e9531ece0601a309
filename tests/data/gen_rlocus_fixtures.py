"""Root locus and pole-zero map references for ctrlab's `freq::root_locus_at`
and `freq::pole_zero_map`, from python-control 0.10.2.

For each open loop L (transfer functions built with `control.tf`, the lab
plant as `control.ss` and its ZOH-sampled form from `control.c2d`):

- `loci`: `control.root_locus_map(L, gains=GAINS).loci`, the closed-loop
  poles of 1 + k L = 0 at each gain (python-control sorts them into
  branches; the test compares each gain's poles as a set);
- `poles`, `zeros`: `control.pole_zero_map(L)`, python-control's
  pole-zero map (no slycot: state-space zeros are python-control's own
  computation without it);
- `breakaway`, `crossing`: the closed forms named in each case, worked
  out by hand (not by python-control), where the case has one.

    python3 tests/data/gen_rlocus_fixtures.py > tests/data/rlocus_fixtures.json
"""

import json

import control as ct
import numpy as np


def cplx(v):
    v = sorted(np.asarray(v, dtype=complex).ravel(), key=lambda z: (z.real, z.imag))
    return [[float(z.real), float(z.imag)] for z in v]


GAINS = [0.0, 0.01, 0.1, 0.5, 1.0, 2.0, 5.0, 10.0, 60.0, 100.0, 1000.0, 1e5]


def lab_plant():
    m1, m2, k1, k2, b1, b2, g = 1.3, 0.7, 1000.0, 1000.0, 10.0, 5.0, 1.0
    a = np.array(
        [
            [0, 1, 0, 0],
            [-(k1 + k2) / m1, -b1 / m1, k2 / m1, 0],
            [0, 0, 0, 1],
            [k2 / m2, 0, -k2 / m2, -b2 / m2],
        ]
    )
    b = np.array([[0], [0], [0], [g / m2]])
    # u = -Kf3 x2_mm = -(1000 Kf3) x2: L = 1000 x2 / u, gain Kf3 (V/mm).
    c = np.array([[0, 0, 1000.0, 0]])
    return a, b, c


def case(name, sys, gains=GAINS, kind="tf", extra=None):
    locus = ct.root_locus_map(sys, gains=gains)
    pz = ct.pole_zero_map(sys)
    out = {
        "name": name,
        "kind": kind,
        "dt": None if sys.dt in (0, None) else float(sys.dt),
        "gains": [float(k) for k in gains],
        "loci": [cplx(row) for row in np.atleast_2d(locus.loci)],
        "poles": cplx(pz.poles),
        "zeros": cplx(pz.zeros),
    }
    if kind == "tf":
        out["num"] = [float(c) for c in np.ravel(sys.num[0][0])]
        out["den"] = [float(c) for c in np.ravel(sys.den[0][0])]
    else:
        out["a"] = np.asarray(sys.A, dtype=float).tolist()
        out["b"] = np.asarray(sys.B, dtype=float).tolist()
        out["c"] = np.asarray(sys.C, dtype=float).tolist()
        out["d"] = np.asarray(sys.D, dtype=float).tolist()
    out.update(extra or {})
    return out


cases = [
    # s² + 2 s + k: double root at −1 for k = 1.
    case("1/(s(s+2))", ct.tf([1], [1, 2, 0]), extra={"breakaway": [-1.0, 1.0]}),
    # s³ + 6 s² + 11 s + 6 + k on s = jω: 11 ω = ω³, 6 + k = 6 ω² → ω = √11, k = 60.
    case(
        "1/((s+1)(s+2)(s+3))",
        ct.tf([1], [1, 6, 11, 6]),
        extra={"crossing": [60.0, float(np.sqrt(11.0))]},
    ),
    case("(s+3)/(s(s+1)(s²+4s+8))", ct.tf([1, 3], np.polymul([1, 1, 0], [1, 4, 8]))),
    case("(s+1)(s+4)/((s+2)(s+3))", ct.tf(np.polymul([1, 1], [1, 4]), np.polymul([1, 2], [1, 3]))),
    # z² − 1.5 z + 0.5 + k (0.5) ... see tests/rlocus.rs for the closed form:
    # (z − 1)(z − 0.5) + k · 0.25 = 0 has |z|² = 0.5 + 0.25 k = 1 at k = 2,
    # where z = (1.5 ± j √(4·1 − 2.25)) / 2: cos θ = 0.75.
    case(
        "0.25/((z-1)(z-0.5)), dt 0.1",
        ct.tf([0.25], [1, -1.5, 0.5], 0.1),
        extra={"crossing": [2.0, float(np.arccos(0.75) / 0.1)]},
    ),
]

a, b, c = lab_plant()
lab = ct.ss(a, b, c, 0)
lab_gains = [0.0, 0.1, 0.5, 1.0, 5.0, 10.0, 20.0, 100.0]
cases.append(case("lab Kf3 loop, continuous", lab, gains=lab_gains, kind="ss"))
lab_d = ct.c2d(lab, 0.002, "zoh")
cases.append(case("lab Kf3 loop, ZOH 2 ms", lab_d, gains=lab_gains, kind="ss"))

print(
    json.dumps(
        {
            "generator": "tests/data/gen_rlocus_fixtures.py",
            "python_control": ct.__version__,
            "numpy": np.__version__,
            "cases": cases,
        },
        indent=1,
    )
)
