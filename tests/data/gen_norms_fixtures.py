"""Fixtures for ctrlab's `analysis::h2_norm` and `analysis::hinf_norm`
(issue 29, item 3), from python-control 0.10.2 (no slycot: its SciPy path)
and an independent NumPy/SciPy reference.

    python3 tests/data/gen_norms_fixtures.py > tests/data/norms_fixtures.json

Each case: A, B, C, D, dt (null for continuous), and
- `h2_control`: python-control `norm(sys, 2)` (SciPy `lyap`/`dlyap`; for
  continuous cases D = 0);
- `h2_reference`: `√trace(C W Cᵀ (+ D Dᵀ))` with SciPy's
  `solve_continuous_lyapunov` / `solve_discrete_lyapunov` directly
  (python-control returns inf when the rounded Gramian has an eigenvalue
  below zero, a nearly uncontrollable mode: 3 of these cases);
- `hinf_control`: python-control `norm(sys, 'inf', tol=1e-10)` (SciPy path:
  bisection on the Hamiltonian's eigenvalues with `np.isclose(re, 0)`);
- `hinf_grid`, `peak_grid`: the largest singular value of G on a dense grid
  (4000 log-spaced points over the poles' range, plus every pole's |λ| and
  ω = 0, and the Nyquist frequency / ω → ∞ as `D`), then the best grid
  point polished by SciPy's bounded `minimize_scalar` (xatol 1e-12 relative)
  between its neighbours; peak frequency in rad/s (null: ω → ∞).

Models: `control.rss` / `control.drss` (seeded NumPy global state, as
python-control draws from it), n = 2..10, SISO and 2 × 2 (n even) or 2 × 3 (n odd; python-control's SciPy path
fails on a non-square model, so those have only the NumPy reference), with
the feedthrough python-control draws (zeroed for continuous H2), and the
lab plant (force on cart 2 to its position, tests/calling_style.rs
`two_carts()`), continuous and Tustin-sampled at 2 ms.
"""

import json
import os
import sys
import warnings

import control
import numpy as np
from scipy.linalg import solve_continuous_lyapunov, solve_discrete_lyapunov
from scipy.optimize import minimize_scalar
from scipy.signal import cont2discrete

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen_lyapunov_fixtures import two_carts as lyapunov_two_carts  # noqa: E402

warnings.simplefilter("ignore")


def rows(m):
    return np.atleast_2d(np.asarray(m, dtype=float)).tolist()


def sigma_max(a, b, c, d, dt, w):
    n = a.shape[0]
    s = 1j * w if dt is None else np.exp(1j * w * dt)
    g = c @ np.linalg.solve(s * np.eye(n) - a, b) + d
    return np.linalg.svd(g, compute_uv=False)[0]


def hinf_grid(a, b, c, d, dt):
    poles = np.linalg.eigvals(a)
    if dt is None:
        mags = np.abs(poles)
        lo, hi = max(mags.min(), 1e-6) / 1e3, mags.max() * 1e3
        grid = np.concatenate([[0.0], np.logspace(np.log10(lo), np.log10(hi), 4000), mags])
    else:
        nyq = np.pi / dt
        s = np.log(poles.astype(complex) + 0j) / dt
        mags = np.minimum(np.abs(s), nyq)
        grid = np.concatenate(
            [[0.0], np.logspace(np.log10(nyq) - 6, np.log10(nyq), 4000), mags, [nyq]]
        )
    grid = np.unique(grid)
    vals = np.array([sigma_max(a, b, c, d, dt, w) for w in grid])
    k = int(np.argmax(vals))
    best, peak = vals[k], grid[k]
    if 0 < k < len(grid) - 1:
        lo, hi = grid[k - 1], grid[k + 1]
        r = minimize_scalar(
            lambda w: -sigma_max(a, b, c, d, dt, w),
            bounds=(lo, hi),
            method="bounded",
            options={"xatol": 1e-12 * max(hi, 1e-300)},
        )
        if -r.fun > best:
            best, peak = -r.fun, r.x
    sd = np.linalg.svd(d, compute_uv=False)[0] if d.size else 0.0
    if dt is None and sd > best:
        return sd, None
    return float(best), float(peak)


def two_carts():
    """The lab plant of gen_lyapunov_fixtures.py, output: cart 2's position."""
    a, b = lyapunov_two_carts()
    return a, b, np.array([[0.0, 0.0, 1.0, 0.0]]), np.zeros((1, 1))


def case(name, a, b, c, d, dt):
    sys = control.ss(a, b, c, d) if dt is None else control.ss(a, b, c, d, dt)
    out = {"name": name, "a": rows(a), "b": rows(b), "c": rows(c), "d": rows(d), "dt": dt}
    if dt is None and np.any(d != 0):
        out["h2_control"] = None
    else:
        v = float(control.norm(sys, 2))
        out["h2_control"] = v if np.isfinite(v) else "inf"  # JSON has no inf
    # The same formula without python-control's checks (it returns inf
    # when the rounded Gramian has an eigenvalue below 0, as for a nearly
    # uncontrollable mode): SciPy's Lyapunov solvers directly.
    if dt is None and np.any(d != 0):
        out["h2_reference"] = None
    elif dt is None:
        w = solve_continuous_lyapunov(a, -b @ b.T)
        out["h2_reference"] = float(np.sqrt(max(np.trace(c @ w @ c.T), 0.0)))
    else:
        w = solve_discrete_lyapunov(a, b @ b.T)
        out["h2_reference"] = float(np.sqrt(max(np.trace(c @ w @ c.T + d @ d.T), 0.0)))
    try:
        out["hinf_control"] = float(control.norm(sys, "inf", tol=1e-10))
    except control.ControlArgument:
        out["hinf_control"] = None  # discrete pole at z = 0
    except ValueError:
        # python-control 0.10.2's SciPy path builds R = γ² I_p − DᵀD with
        # I the size of the outputs: a non-square model fails.
        out["hinf_control"] = None
    out["hinf_grid"], out["peak_grid"] = hinf_grid(a, b, c, d, dt)
    return out


def main():
    np.random.seed(29)
    cases = []
    for n in range(2, 11):
        for outputs, inputs in ((1, 1), (2, 2) if n % 2 == 0 else (2, 3)):
            s = control.rss(n, outputs, inputs)
            cases.append(case(f"rss n={n} {outputs}x{inputs}", s.A, s.B, s.C, s.D, None))
            if n % 3 == 0:
                z = np.zeros_like(s.D)
                cases.append(case(f"rss n={n} {outputs}x{inputs} D=0", s.A, s.B, s.C, z, None))
            dsys = control.drss(n, outputs, inputs, dt=0.1)
            cases.append(case(f"drss n={n} {outputs}x{inputs}", dsys.A, dsys.B, dsys.C, dsys.D, 0.1))
    a, b, c, d = two_carts()
    cases.append(case("lab plant", a, b, c, d, None))
    ad, bd, cd, dd, _ = cont2discrete((a, b, c, d), 0.002, method="bilinear")
    cases.append(case("lab plant tustin 2 ms", ad, bd, cd, dd, 0.002))
    print(json.dumps({"cases": cases}, indent=1))


if __name__ == "__main__":
    main()
