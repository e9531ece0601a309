"""Fixtures for `analysis::{dlyapchol, gram, hsvd, balred}` (tests/gram.rs).

Written independently of the Rust: SciPy's `solve_continuous_lyapunov` /
`solve_discrete_lyapunov` for the Gramians, SciPy's Cholesky and NumPy's SVD
for the Hankel singular values (cross-checked here against
sqrt(eig(Wc Wo))), and the square-root balanced truncation written out in
NumPy (Tombs & Postlethwaite 1987 / Laub et al. 1987), whose reduced models
are stored with their frequency responses (realisations differ by signs,
responses do not).

    python3 tests/data/gen_gram_fixtures.py > tests/data/gram_fixtures.json
"""

import json
import sys

import numpy as np
import scipy
import scipy.linalg as sla


def stable_continuous(rng, n):
    a = rng.standard_normal((n, n))
    shift = np.max(np.linalg.eigvals(a).real)
    return a - (shift + 0.3 + rng.uniform()) * np.eye(n)


def stable_discrete(rng, n, radius):
    a = rng.standard_normal((n, n))
    return a * (radius / np.max(np.abs(np.linalg.eigvals(a))))


def gramians(a, b, c, discrete):
    if discrete:
        wc = sla.solve_discrete_lyapunov(a, b @ b.T)
        wo = sla.solve_discrete_lyapunov(a.T, c.T @ c)
    else:
        wc = sla.solve_continuous_lyapunov(a, -b @ b.T)
        wo = sla.solve_continuous_lyapunov(a.T, -c.T @ c)
    return (wc + wc.T) / 2, (wo + wo.T) / 2


def balanced_truncation(a, b, c, wc, wo, r):
    lc = sla.cholesky(wc, lower=True)
    lo = sla.cholesky(wo, lower=True)
    u, s, vt = np.linalg.svd(lo.T @ lc)
    si = np.diag(s[:r] ** -0.5)
    t = lc @ vt[:r].T @ si
    w = lo @ u[:, :r] @ si
    assert np.allclose(w.T @ t, np.eye(r), atol=1e-9)
    return w.T @ a @ t, w.T @ b, c @ t, s


def response(a, b, c, d, points):
    n = a.shape[0]
    return [c @ np.linalg.solve(z * np.eye(n) - a, b) + d for z in points]


def grid(discrete, dt):
    if discrete:
        w = np.linspace(1e-3, np.pi / dt, 120)
        return w, np.exp(1j * w * dt)
    w = np.logspace(-3, 3, 120)
    return w, 1j * w


def cx(m):
    return [[[float(v.real), float(v.imag)] for v in row] for row in m]


def main():
    rng = np.random.default_rng(20261126)
    out = {
        "versions": {"numpy": np.__version__, "scipy": scipy.__version__},
        "dlyapchol": [],
        "models": [],
    }
    # Discrete Lyapunov factors: X from SciPy.
    for n, m, radius in [(1, 1, 0.5), (2, 1, 0.9), (3, 2, 0.7), (5, 1, 0.95),
                         (10, 2, 0.8), (20, 3, 0.9), (6, 1, 0.999)]:
        a = stable_discrete(rng, n, radius)
        b = rng.standard_normal((n, m))
        x = sla.solve_discrete_lyapunov(a, b @ b.T)
        out["dlyapchol"].append({"a": a.tolist(), "b": b.tolist(), "x": x.tolist()})
    # Models for gram / hsvd / balred.
    specs = [(False, 4, 1, 1, [1, 2]), (False, 6, 2, 1, [2, 3]),
             (False, 10, 2, 2, [3, 5]), (True, 4, 1, 1, [1, 2]),
             (True, 8, 1, 2, [2, 4]), (True, 12, 2, 2, [4, 6])]
    for discrete, n, m, p, orders in specs:
        dt = 0.05
        a = stable_discrete(rng, n, 0.85) if discrete else stable_continuous(rng, n)
        b = rng.standard_normal((n, m))
        c = rng.standard_normal((p, n))
        d = rng.standard_normal((p, m))
        wc, wo = gramians(a, b, c, discrete)
        w, pts = grid(discrete, dt)
        full = response(a, b, c, d, pts)
        hsv = None
        reduced = []
        for r in orders:
            ar, br, cr, hsv = balanced_truncation(a, b, c, wc, wo, r)
            # The bound, checked here too (spectral norm over the grid).
            g = response(ar, br, cr, d, pts)
            err = max(np.linalg.norm(x - y, 2) for x, y in zip(full, g))
            bound = 2 * hsv[r:].sum()
            assert err <= bound * (1 + 1e-9), (err, bound)
            reduced.append({"order": r, "a": ar.tolist(), "b": br.tolist(),
                            "c": cr.tolist(), "bound": float(bound),
                            "max_error": float(err), "response": [cx(x) for x in g]})
        eig = np.sort(np.sqrt(np.abs(np.linalg.eigvals(wc @ wo).real)))[::-1]
        assert np.allclose(eig, hsv, rtol=1e-7, atol=1e-10 * hsv[0]), (eig, hsv)
        out["models"].append({
            "discrete": discrete, "dt": dt if discrete else None,
            "a": a.tolist(), "b": b.tolist(), "c": c.tolist(), "d": d.tolist(),
            "wc": wc.tolist(), "wo": wo.tolist(), "hsv": hsv.tolist(),
            "omega": w.tolist(), "reduced": reduced,
        })
    json.dump(out, sys.stdout)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
