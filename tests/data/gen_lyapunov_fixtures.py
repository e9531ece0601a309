"""Lyapunov and Sylvester reference solutions from SciPy and python-control.

Random stable models (continuous: A shifted so that max Re(eig) < 0;
discrete: scaled to a spectral radius < 1), sizes 1 to 50, each with its
seed; Sylvester cases with random non-symmetric A and B (complex
eigenvalues, so 2x2 Schur blocks occur); SciPy's own real test cases
(scipy/linalg/tests/test_solvers.py, TestSolveLyapunov and
TestSolveSylvester); and named cases: the lab's two-cart plant with
Q = B B^T, a scalar, a defective (Jordan) A, and a pair of eigenvalues
close to the singularity.

Every case stores ctrlab's convention (see tests/lyapunov.rs):
  lyap:      A X + X A^T + Q = 0   = solve_continuous_lyapunov(a, -q)
  dlyap:     A X A^T - X + Q = 0   = solve_discrete_lyapunov(a, q)
  sylvester: A X + X B = C         = solve_sylvester(a, b, c)
and python-control's lyap / dlyap are checked against SciPy's here (no
slycot: python-control calls SciPy), their largest difference recorded.

    python3 tests/data/gen_lyapunov_fixtures.py > tests/data/lyapunov_fixtures.json
"""

import json

import control
import numpy as np
import scipy
from scipy.linalg import solve_continuous_lyapunov, solve_discrete_lyapunov, solve_sylvester

SIZES = [1, 2, 3, 5, 10, 20, 50]


def rows(m):
    return np.atleast_2d(np.asarray(m, dtype=float)).tolist()


def stable_continuous(rng, n):
    a = rng.standard_normal((n, n))
    shift = max(np.linalg.eigvals(a).real) + rng.uniform(0.1, 1.0)
    return a - shift * np.eye(n)


def stable_discrete(rng, n):
    a = rng.standard_normal((n, n))
    rho = max(abs(np.linalg.eigvals(a)))
    return a * rng.uniform(0.5, 0.95) / rho


def symmetric(rng, n):
    g = rng.standard_normal((n, n))
    return g @ g.T


def two_carts():
    """tests/calling_style.rs two_carts(): the lab's plant, force on cart 2."""
    m1, m2, k1, k2, c1, c2 = 1.3, 0.7, 1000.0, 1000.0, 2.0, 1.0
    a = np.array(
        [
            [0.0, 1.0, 0.0, 0.0],
            [-(k1 + k2) / m1, -c1 / m1, k2 / m1, 0.0],
            [0.0, 0.0, 0.0, 1.0],
            [k2 / m2, 0.0, -k2 / m2, -c2 / m2],
        ]
    )
    b = np.array([[0.0], [0.0], [0.0], [1.0 / m2]])
    return a, b


control_diff = {"lyap": 0.0, "dlyap": 0.0}


def lyap_case(name, a, q, seed=None):
    x = solve_continuous_lyapunov(a, -q)
    if np.array_equal(q, q.T):  # python-control takes a symmetric Q only
        xc = control.lyap(a, q)
        control_diff["lyap"] = max(control_diff["lyap"], float(np.max(abs(xc - x)) / np.max(abs(x))))
    return {"name": name, "seed": seed, "a": rows(a), "q": rows(q), "x": rows(x)}


def dlyap_case(name, a, q, seed=None):
    x = solve_discrete_lyapunov(a, q)
    if np.array_equal(q, q.T):  # python-control takes a symmetric Q only
        xc = control.dlyap(a, q)
        control_diff["dlyap"] = max(control_diff["dlyap"], float(np.max(abs(xc - x)) / np.max(abs(x))))
    return {"name": name, "seed": seed, "a": rows(a), "q": rows(q), "x": rows(x)}


def sylvester_case(name, a, b, c, seed=None):
    x = solve_sylvester(a, b, c)
    return {"name": name, "seed": seed, "a": rows(a), "b": rows(b), "c": rows(c), "x": rows(x)}


def main():
    lyap, dlyap, sylv = [], [], []
    for n in SIZES:
        for seed in ([1000 + n, 2000 + n] if n <= 10 else [1000 + n]):
            rng = np.random.default_rng(seed)
            lyap.append(lyap_case(f"random_{n}", stable_continuous(rng, n), symmetric(rng, n), seed))
            rng = np.random.default_rng(seed + 1)
            dlyap.append(dlyap_case(f"random_{n}", stable_discrete(rng, n), symmetric(rng, n), seed + 1))
            rng = np.random.default_rng(seed + 2)
            m = max(1, n - 1 if n > 2 else n)
            a = rng.standard_normal((m, m)) + 3.0 * np.eye(m)
            b = rng.standard_normal((n, n)) + 3.0 * np.eye(n)
            sylv.append(sylvester_case(f"random_{m}x{n}", a, b, rng.standard_normal((m, n)), seed + 2))

    a, b = two_carts()
    lyap.append(lyap_case("two_carts_gramian", a, b @ b.T))
    ad = scipy.linalg.expm(a * 0.002)
    bd = np.linalg.solve(a, (ad - np.eye(4)) @ b)
    dlyap.append(dlyap_case("two_carts_zoh_2ms_gramian", ad, bd @ bd.T))
    lyap.append(lyap_case("scalar", np.array([[-2.0]]), np.array([[9.0]])))
    dlyap.append(dlyap_case("scalar", np.array([[0.5]]), np.array([[1.0]])))
    jordan = np.array([[-1.0, 1.0, 0.0], [0.0, -1.0, 1.0], [0.0, 0.0, -1.0]])
    lyap.append(lyap_case("jordan_3", jordan, np.eye(3)))
    dlyap.append(dlyap_case("jordan_3", 0.5 * np.eye(3) + np.diag([1.0, 1.0], 1), np.eye(3)))
    # Eigenvalues -1e-6 +- 1i: lambda + conj(lambda) = -2e-6, nearly singular.
    near = np.array([[-1e-6, 1.0], [-1.0, -1e-6]])
    lyap.append(lyap_case("near_singular_pair", near, np.eye(2)))
    # Eigenvalues (1 - 1e-6) e^{+-0.5i}: |lambda|^2 = 1 - 2e-6.
    r, th = 1.0 - 1e-6, 0.5
    dlyap.append(
        dlyap_case("near_unit_circle", r * np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]]), np.eye(2))
    )
    # SciPy's own real cases (TestSolveLyapunov.cases: in SciPy's sign, so
    # stored with q -> -q for lyap; dlyap has the same sign).
    scipy_lyap = [
        ("scipy_2x2", np.array([[1.0, 2.0], [3.0, 4.0]]), np.array([[9.0, 10.0], [11.0, 12.0]])),
        (
            "scipy_kitagawa_1977",
            np.array([[3, 9, 5, 1, 4], [1, 2, 3, 8, 4], [4, 6, 6, 6, 3], [1, 5, 2, 0, 7], [5, 3, 3, 1, 5]], float),
            np.array([[2, 4, 1, 0, 1], [4, 1, 0, 2, 0], [1, 0, 3, 0, 3], [0, 2, 0, 1, 0], [1, 0, 3, 0, 4]], float),
        ),
        (
            "scipy_companion_11",
            np.vstack([np.arange(0.100, 0.0095, -0.009)[None, :], np.eye(11)[:-1]]),
            np.eye(11),
        ),
        ("scipy_gh4176", np.array([[0.0, 1.0], [-0.5, -1.0]]), np.array([[0.0, 0.0], [0.0, 9.0]])),
    ]
    for name, a, q in scipy_lyap:
        lyap.append(lyap_case(name, a, -q))
        dlyap.append(dlyap_case(name, a, q))
    sylv.append(
        sylvester_case(
            "scipy_2x2", np.array([[1.0, 2.0], [0.0, 4.0]]), np.array([[5.0, 6.0], [0.0, 8.0]]),
            np.array([[9.0, 10.0], [11.0, 12.0]]),
        )
    )
    sylv.append(
        sylvester_case(
            "scipy_4x4_blocks",
            np.array([[1.0, 0, 0, 0], [0, 1.0, 2.0, 0.0], [0, 0, 3.0, -4], [0, 0, 2, 5]]),
            np.array([[2.0, 0, 0, 1.0], [0, 1.0, 0.0, 0.0], [0, 0, 1.0, -1], [0, 0, 1, 1]]),
            np.eye(4),
        )
    )
    sylv.append(
        sylvester_case(
            "scipy_not_square",
            np.array([[8.0, 1, 6], [3, 5, 7], [4, 9, 2]]),
            np.array([[2.0, 3], [4, 5]]),
            np.array([[1.0, 2], [3, 4], [5, 6]]),
        )
    )
    sylv.append(sylvester_case("scipy_trivial", np.eye(2), np.array([[1.0]]), np.array([[2.0], [2.0]])))

    out = {
        "generator": "tests/data/gen_lyapunov_fixtures.py",
        "versions": {
            "scipy": scipy.__version__,
            "control": control.__version__,
            "numpy": np.__version__,
        },
        # SciPy's own criterion (test_solvers.py, TestSolveLyapunov.check_*
        # and TestSolveSylvester.check_case): assert_array_almost_equal at
        # its default decimal=6, every entry of the residual below 1.5e-6.
        "scipy_residual_atol": 1.5e-6,
        "control_vs_scipy_max_rel_diff": control_diff,
        "lyap": lyap,
        "dlyap": dlyap,
        "sylvester": sylv,
    }
    print(json.dumps(out))


if __name__ == "__main__":
    main()
