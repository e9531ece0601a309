"""Issue 28's hard Riccati cases: weights nine decades either side of 1,
Q = diag(1e9, 1e-9), R = 1, B = [1; 1], on a controllable A (distinct real
eigenvalues, both excited by B):

- care: A = diag(1, 2), SciPy's `solve_continuous_are(a, b, q, r)`;
- dare: A = diag(1.1, 1.2), SciPy's `solve_discrete_are(a, b, q, r)`.

For each, SciPy's X with its relative residual (‖Res‖_F / ‖X‖_F) and
closed-loop poles, and the reference X: Newton–Kleinman (continuous) or
Hewer (discrete) iterations in 60-digit mpmath arithmetic from SciPy's
stabilising gain, run until the step is below 1e-50 relative, with its
gain and closed-loop poles. SciPy 1.17's answers miss the equation by
1.7e-3 (care) and 4.3e-2 (dare) relative; the reference solves it to
rounding of the 60-digit arithmetic.

    python3 tests/data/gen_riccati_hard_28.py > tests/data/riccati_hard_28.json
"""

import json

import mpmath as mp
import numpy as np
import scipy
from scipy.linalg import solve_continuous_are, solve_discrete_are

mp.mp.dps = 60


def rows(m):
    return [[float(v) for v in row] for row in np.atleast_2d(np.asarray(m, dtype=float))]


def mrows(m):
    return [[float(m[i, j]) for j in range(m.cols)] for i in range(m.rows)]


def cplx(v):
    return [[float(z.real), float(z.imag)] for z in sorted(v, key=lambda z: (z.real, z.imag))]


def lyap(a, c):
    """X with a^T X + X a + c = 0, by the Kronecker linear system."""
    n = a.rows
    k = mp.zeros(n * n, n * n)
    for i in range(n):
        for j in range(n):
            for p in range(n):
                # (a^T X)_{ij} = sum_p a_{pi} X_{pj};  (X a)_{ij} = sum_p X_{ip} a_{pj}
                k[i * n + j, p * n + j] += a[p, i]
                k[i * n + j, i * n + p] += a[p, j]
    x = mp.lu_solve(k, -mp.matrix([c[i, j] for i in range(n) for j in range(n)]))
    return mp.matrix([[x[i * n + j] for j in range(n)] for i in range(n)])


def stein(a, c):
    """X with X - a^T X a = c."""
    n = a.rows
    k = mp.eye(n * n)
    for i in range(n):
        for j in range(n):
            for p in range(n):
                for s in range(n):
                    k[i * n + j, p * n + s] -= a[p, i] * a[s, j]
    x = mp.lu_solve(k, mp.matrix([c[i, j] for i in range(n) for j in range(n)]))
    return mp.matrix([[x[i * n + j] for j in range(n)] for i in range(n)])


def fro(m):
    return mp.sqrt(sum(m[i, j] ** 2 for i in range(m.rows) for j in range(m.cols)))


def reference(a, b, q, r, k0, discrete):
    a, b, q, r = (mp.matrix(rows(m)) for m in (a, b, q, r))
    k = mp.matrix(rows(k0))
    x_old = None
    for _ in range(200):
        a_c = a - b * k
        if discrete:
            x = stein(a_c, q + k.T * r * k)
            k = mp.inverse(r + b.T * x * b) * (b.T * x * a)
        else:
            x = lyap(a_c, q + k.T * r * k)
            k = mp.inverse(r) * b.T * x
        if x_old is not None and fro(x - x_old) <= mp.mpf("1e-50") * fro(x):
            break
        x_old = x
    if discrete:
        res = a.T * x * a - x - a.T * x * b * k + q
    else:
        res = a.T * x + x * a - x * b * k + q
    poles = np.linalg.eigvals(np.array(mrows(a - b * k)))
    return x, k, float(fro(res) / fro(x)), poles


def case(a, discrete):
    b = np.array([[1.0], [1.0]])
    q = np.diag([1e9, 1e-9])
    r = np.array([[1.0]])
    if discrete:
        x = solve_discrete_are(a, b, q, r)
        k = np.linalg.solve(r + b.T @ x @ b, b.T @ x @ a)
        res = a.T @ x @ a - x - a.T @ x @ b @ k + q
    else:
        x = solve_continuous_are(a, b, q, r)
        k = np.linalg.solve(r, b.T @ x)
        res = a.T @ x + x @ a - x @ b @ k + q
    x_ref, k_ref, res_ref, poles_ref = reference(a, b, q, r, k, discrete)
    return {
        "a": rows(a),
        "b": rows(b),
        "q": rows(q),
        "r": rows(r),
        "scipy_x": rows(x),
        "scipy_residual": float(np.linalg.norm(res) / np.linalg.norm(x)),
        "scipy_poles": cplx(np.linalg.eigvals(a - b @ k)),
        "x": mrows(x_ref),
        "k": mrows(k_ref),
        "residual": res_ref,
        "poles": cplx(poles_ref),
    }


def main():
    print(json.dumps({
        "scipy": scipy.__version__,
        "care": case(np.diag([1.0, 2.0]), discrete=False),
        "dare": case(np.diag([1.1, 1.2]), discrete=True),
    }, indent=1))


if __name__ == "__main__":
    main()
