"""Fixtures for d2c (the inverse of each discretisation), logm and the
discrete Sylvester (Stein) equation: tests/data/d2c_fixtures.json.

SciPy has no d2c: each case is a random continuous model (A, B, C, D), its
discretisation by scipy.signal.cont2discrete at several periods with each
method ('zoh', 'bilinear', 'euler', 'backward_diff'), and the continuous
model itself as what d2c must recover. For ZOH the continuous A and B are
also computed independently from the discrete ones by scipy.linalg.logm of
[[Ad, Bd], [0, I]]. The Stein cases' X comes from a dense Kronecker solve
in NumPy, (B^T kron A - I) vec X = -vec C.

Run: python3 tests/data/gen_d2c_fixtures.py (SciPy 1.17.1, NumPy).
"""

import json

import numpy as np
import scipy
import scipy.linalg as la
from scipy.signal import cont2discrete

rng = np.random.default_rng(20261126)


def model(n, m, p, stable, max_rate):
    """A random real model with eigenvalues of modulus <= max_rate (1/s)."""
    q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    t = np.zeros((n, n))
    i = 0
    while i < n:
        if i + 1 < n and rng.random() < 0.5:
            re = rng.uniform(0.05, 0.6) * max_rate
            im = rng.uniform(0.1, 0.7) * max_rate
            t[i:i + 2, i:i + 2] = [[-re if stable else re, im], [-im, -re if stable else re]]
            i += 2
        else:
            r = rng.uniform(0.05, 0.9) * max_rate
            t[i, i] = -r if stable or rng.random() < 0.5 else r
            i += 1
    t += np.triu(rng.standard_normal((n, n)) * 0.3 * max_rate, 2)
    a = q @ t @ q.T
    b = rng.standard_normal((n, m))
    c = rng.standard_normal((p, n))
    d = rng.standard_normal((p, m))
    return a, b, c, d


def tolist(x):
    return np.asarray(x, dtype=float).tolist()


cases = []
shapes = [(1, 1, 1), (2, 1, 1), (3, 2, 1), (4, 1, 2), (6, 2, 2)]
for k, (n, m, p) in enumerate(shapes):
    for stable in (True, False):
        a, b, c, d = model(n, m, p, stable, max_rate=10.0)
        for dt in (0.005, 0.05, 0.2):
            for method in ("zoh", "bilinear", "euler", "backward_diff"):
                ad, bd, cd, dd, _ = cont2discrete((a, b, c, d), dt, method=method)
                case = {
                    "name": f"{'stable' if stable else 'unstable'}-{n}x{m}x{p}-dt{dt}-{method}",
                    "method": method,
                    "dt": dt,
                    "a": tolist(a), "b": tolist(b), "c": tolist(c), "d": tolist(d),
                    "ad": tolist(ad), "bd": tolist(bd), "cd": tolist(cd), "dd": tolist(dd),
                }
                if method == "zoh":
                    aug = np.block([[ad, bd], [np.zeros((m, n)), np.eye(m)]])
                    log = la.logm(aug)
                    assert np.abs(log.imag).max() == 0.0 if np.iscomplexobj(log) else True
                    log = np.real(log)
                    case["logm_a"] = tolist(log[:n, :n] / dt)
                    case["logm_b"] = tolist(log[:n, n:] / dt)
                cases.append(case)

logm_cases = []
for n in (1, 2, 3, 5, 8):
    for kind in ("exp", "spd", "rotation"):
        if kind == "exp":
            x = rng.standard_normal((n, n)) * 0.8
            mtx = la.expm(x)
        elif kind == "spd":
            g = rng.standard_normal((n, n))
            mtx = g @ g.T + n * np.eye(n)
        else:
            # Complex pairs at angles up to 3 rad, one unit-modulus block.
            q, _ = np.linalg.qr(rng.standard_normal((n, n)))
            t = np.diag(rng.uniform(0.3, 3.0, n))
            for i in range(0, n - 1, 2):
                th = rng.uniform(0.5, 3.0)
                r = rng.uniform(0.5, 2.0)
                t[i:i + 2, i:i + 2] = r * np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
            mtx = q @ t @ q.T
        log = la.logm(mtx)
        logm_cases.append({"name": f"{kind}-{n}", "m": tolist(mtx), "log": tolist(np.real(log))})

stein_cases = []
for (m, n) in ((1, 1), (2, 3), (3, 2), (4, 4), (5, 3), (7, 6)):
    for kind in ("inside", "mixed"):
        a = rng.standard_normal((m, m))
        b = rng.standard_normal((n, n))
        if kind == "inside":
            a *= 0.9 / max(abs(np.linalg.eigvals(a)))
            b *= 0.9 / max(abs(np.linalg.eigvals(b)))
        else:
            a *= 1.5 / max(abs(np.linalg.eigvals(a)))
            b *= 0.5 / max(abs(np.linalg.eigvals(b)))
        c = rng.standard_normal((m, n))
        k = np.kron(b.T, a) - np.eye(m * n)
        x = np.linalg.solve(k, -c.flatten(order="F")).reshape((m, n), order="F")
        stein_cases.append({"name": f"{kind}-{m}x{n}", "a": tolist(a), "b": tolist(b),
                            "c": tolist(c), "x": tolist(x)})

out = {
    "generator": "tests/data/gen_d2c_fixtures.py",
    "scipy": scipy.__version__,
    "numpy": np.__version__,
    "d2c": cases,
    "logm": logm_cases,
    "stein": stein_cases,
}
with open("tests/data/d2c_fixtures.json", "w") as f:
    json.dump(out, f, indent=1)
print(len(cases), len(logm_cases), len(stein_cases))
