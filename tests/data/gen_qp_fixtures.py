#!/usr/bin/env python3
"""Generates tests/data/qp_fixtures.json: reference solutions of convex QPs of
the lab MPC's size for ctrlab's `design::mpc::DenseQp`.

    pip install osqp clarabel quadprog numpy scipy
    python3 tests/data/gen_qp_fixtures.py > tests/data/qp_fixtures.json

Each problem is

    minimise ½ xᵀ P x + qᵀ x + Σ_soft (linear·d + quadratic·d²/2)
    subject to l ≤ G x ≤ u on the hard rows,

d a soft row's distance of g x from [l, u]. The references do not use that
form: the soft rows get explicit slack variables s ≥ 0 with l − s ≤ g x and
g x ≤ u + s and the cost linear·s + quadratic·s²/2, and the slack problem is
solved by OSQP (eps_abs = eps_rel = 1e-10, polishing on, 10⁶ iterations at
most; its `x` is the reference) and again by Clarabel (interior point,
tolerances 1e-12) and, where the slack problem's Hessian is definite,
quadprog (Goldfarb–Idnani, a dense active-set method); the script fails
unless they agree, and it records how far apart they are.

Random cases: n = 10 … 40 variables; rows of an MPC's kinds: identity rows
(boxes on variables), first differences (rate limits), dense
lower-triangular rows (predicted outputs, from a decaying oscillation),
a few dense rows, sometimes a duplicated box row or an equality row; hard
and soft (linear and/or quadratic weights); some rows with one infinite
bound; some row groups in other units (×1e-3, ×1e3). Feasibility by
construction: a known point x0 (two decimals) satisfies every hard row, the
bounds being placed around G x0. The unconstrained minimiser is put far
from x0, so many rows bind. P = L Lᵀ + D with L's entries k/10 and D's
k/100, so P is written exactly (two decimals) and is definite in exact
arithmetic; G's entries are rounded to four significant digits, and the
bounds are computed from the rounded G. Every seventh case has a positive
semidefinite P of rank n/2 (no diagonal added; every variable then boxed by
hard, finite rows), whose x need not be unique (`x_unique: false`: compare
the objective only). Every number in the JSON is the problem: the
references were computed from the file's own numbers.

Named cases: the lab's two-cart plant (4 states, 1 input, ZOH at 2 ms),
condensed MPC with horizon 30 (input box, rate limits, soft position
limits on both carts at every step, natural units), once tracking a
setpoint next to the limits and once from a state beyond a limit (the soft
rows are then violated at the optimum); `random_full`: n = 40 with
every kind of row at its most (159 rows); and `mpc_random_*` (their own
seed, SEED + 1): random MPCs of the lab's size, horizon 20…40 on the
4-state plant with its parameters within ±20 %, one input or two (20…80
variables), box, rate and soft position rows (see `random_mpc`).

JSON: matrices as lists of rows, infinite bounds as null, rows as
{"hard": true} or {"linear": w1, "quadratic": w2}.
"""

import json
import sys

import numpy as np
import scipy
import scipy.linalg
import scipy.signal
import scipy.sparse as sp
import osqp
import clarabel
import quadprog

SEED = 31
OSQP_EPS = 1e-10
MPC_CASES = 12


def sig(v, digits=4):
    """v rounded to `digits` significant digits (0 stays 0)."""
    return float(f"{v:.{digits - 1}e}") if v != 0 else 0.0


def penalised_objective(p, q, g, lower, upper, rows, x):
    f = 0.5 * x @ p @ x + q @ x
    gx = g @ x
    for i, row in enumerate(rows):
        if "hard" in row:
            continue
        d = max(lower[i] - gx[i], gx[i] - upper[i], 0.0)
        f += row["linear"] * d + 0.5 * row["quadratic"] * d * d
    return float(f)


def slack_form(p, q, g, lower, upper, rows):
    """The problem with one slack variable per soft row with a finite bound:
    (P̂, q̂, A, l̂, û) for OSQP's l̂ ≤ A v ≤ û, v = [x; s]."""
    n = p.shape[0]
    soft = [i for i, r in enumerate(rows)
            if "hard" not in r and (np.isfinite(lower[i]) or np.isfinite(upper[i]))]
    k = len(soft)
    ph = np.zeros((n + k, n + k))
    ph[:n, :n] = p
    qh = np.concatenate([q, np.zeros(k)])
    a_rows, lo, hi = [], [], []
    for i, r in enumerate(rows):
        if "hard" in r:
            a_rows.append(np.concatenate([g[i], np.zeros(k)]))
            lo.append(lower[i])
            hi.append(upper[i])
    for s, i in enumerate(soft):
        w1, w2 = rows[i]["linear"], rows[i]["quadratic"]
        ph[n + s, n + s] = w2
        qh[n + s] = w1
        e = np.zeros(k)
        e[s] = 1.0
        if np.isfinite(upper[i]):  # g x − s ≤ u
            a_rows.append(np.concatenate([g[i], -e]))
            lo.append(-np.inf)
            hi.append(upper[i])
        if np.isfinite(lower[i]):  # g x + s ≥ l
            a_rows.append(np.concatenate([g[i], e]))
            lo.append(lower[i])
            hi.append(np.inf)
        a_rows.append(np.concatenate([np.zeros(n), e]))  # s ≥ 0
        lo.append(0.0)
        hi.append(np.inf)
    a = np.array(a_rows).reshape(len(a_rows), n + k)
    return ph, qh, a, np.array(lo), np.array(hi)


def solve_osqp(ph, qh, a, lo, hi):
    """OSQP at its defaults but the tolerances; where its adaptive ρ does
    not converge in 10⁶ iterations (one random case, whose rows span six
    orders of magnitude), again with fixed step sizes: the settings that
    solved are recorded."""
    for extra in [{}, {"adaptive_rho": False, "rho": 1.0}, {"adaptive_rho": False, "rho": 0.1}]:
        solver = osqp.OSQP()
        solver.setup(P=sp.csc_matrix(np.triu(ph)), q=qh, A=sp.csc_matrix(a), l=lo, u=hi,
                     eps_abs=OSQP_EPS, eps_rel=OSQP_EPS, eps_prim_inf=1e-12,
                     eps_dual_inf=1e-12, polishing=True, polish_refine_iter=10,
                     max_iter=1_000_000, verbose=False, **extra)
        res = solver.solve()
        if res.info.status == "solved":
            return res.x, res.info, extra
    raise AssertionError(res.info.status)


def solve_clarabel(ph, qh, a, lo, hi):
    """Clarabel: A v + s = b with s in the zero cone (equalities) or ≥ 0."""
    eq = [i for i in range(len(lo)) if lo[i] == hi[i]]
    ups = [i for i in range(len(lo)) if hi[i] < np.inf and lo[i] != hi[i]]
    los = [i for i in range(len(lo)) if lo[i] > -np.inf and lo[i] != hi[i]]
    amat = np.vstack([a[eq], a[ups], -a[los]])
    b = np.concatenate([hi[eq], hi[ups], -lo[los]])
    cones = []
    if eq:
        cones.append(clarabel.ZeroConeT(len(eq)))
    cones.append(clarabel.NonnegativeConeT(len(ups) + len(los)))
    s = clarabel.DefaultSettings()
    s.verbose = False
    s.tol_gap_abs = s.tol_gap_rel = s.tol_feas = s.tol_ktratio = 1e-12
    s.max_iter = 500
    solver = clarabel.DefaultSolver(sp.csc_matrix(np.triu(ph)), qh, sp.csc_matrix(amat), b,
                                    cones, s)
    sol = solver.solve()
    assert str(sol.status) in ("Solved", "AlmostSolved"), sol.status
    return np.array(sol.x), str(sol.status)


def solve_quadprog(ph, qh, a, lo, hi):
    """quadprog minimises ½ vᵀ G v − aᵀ v subject to Cᵀ v ≥ b (the first
    meq as equalities); it needs a definite G."""
    if np.linalg.eigvalsh(ph).min() <= 1e-12 * np.abs(ph).max():
        return None
    eq = [i for i in range(len(lo)) if lo[i] == hi[i]]
    ups = [i for i in range(len(lo)) if hi[i] < np.inf and lo[i] != hi[i]]
    los = [i for i in range(len(lo)) if lo[i] > -np.inf and lo[i] != hi[i]]
    c = np.vstack([a[eq], -a[ups], a[los]]).T
    b = np.concatenate([lo[eq], -hi[ups], lo[los]])
    try:
        return quadprog.solve_qp(ph, -qh, c, b, len(eq))[0]
    except ValueError as err:  # its own verdict, recorded
        return str(err)


def rel(a, b):
    return float(np.abs(a - b).max() / max(1.0, np.abs(b).max()))


def reference(name, p, q, g, lower, upper, rows, x_unique=True):
    # Round-trip through JSON text first: the references are of the file's
    # numbers exactly.
    data = json.loads(json.dumps(dict(p=p.tolist(), q=q.tolist(), g=g.tolist(),
                                      lower=[None if v == -np.inf else v for v in lower],
                                      upper=[None if v == np.inf else v for v in upper])))
    p, q, g = np.array(data["p"]), np.array(data["q"]), np.array(data["g"]).reshape(g.shape)
    lower = np.array([-np.inf if v is None else v for v in data["lower"]])
    upper = np.array([np.inf if v is None else v for v in data["upper"]])
    n = p.shape[0]
    ph, qh, a, lo, hi = slack_form(p, q, g, lower, upper, rows)
    v, info, extra = solve_osqp(ph, qh, a, lo, hi)
    x = v[:n]
    f = penalised_objective(p, q, g, lower, upper, rows, x)
    vc, cstatus = solve_clarabel(ph, qh, a, lo, hi)
    fc = penalised_objective(p, q, g, lower, upper, rows, vc[:n])
    check = {
        "clarabel_status": cstatus,
        "clarabel_x_rel": rel(vc[:n], x),
        "clarabel_objective_rel": abs(fc - f) / max(1.0, abs(f)),
    }
    vq = solve_quadprog(ph, qh, a, lo, hi)
    if isinstance(vq, str):
        check["quadprog_failed"] = vq
    elif vq is not None:
        fq = penalised_objective(p, q, g, lower, upper, rows, vq[:n])
        check["quadprog_x_rel"] = rel(vq[:n], x)
        check["quadprog_objective_rel"] = abs(fq - f) / max(1.0, abs(f))
    assert check["clarabel_objective_rel"] < 1e-7, (name, check)
    if x_unique:
        assert check["clarabel_x_rel"] < 1e-5, (name, check)
        assert check.get("quadprog_x_rel", 0.0) < 1e-6, (name, check)
    hard = [i for i, r in enumerate(rows) if "hard" in r]
    gx = g @ x
    violation = max([0.0] + [max(lower[i] - gx[i], gx[i] - upper[i]) for i in hard])
    return {
        "name": name,
        "n": n,
        "m": len(rows),
        "p": data["p"],
        "q": data["q"],
        "g": data["g"],
        "lower": data["lower"],
        "upper": data["upper"],
        "rows": rows,
        "x_unique": x_unique,
        "x": x.tolist(),
        "objective": f,
        "osqp": {
            "iterations": int(info.iter),
            "status_polish": int(info.status_polish),
            "settings": extra,
            "hard_violation": float(violation),
        },
        "check": check,
    }


def random_case(rng, index, full=False):
    """A random case; `full`: n = 40 with every kind of row at its most
    (40 boxes, 39 differences, two outputs at every step: 159 rows)."""
    n = 40 if full else int(rng.integers(10, 41))
    rank = n if index % 7 != 6 else n // 2
    lmat = rng.integers(-9, 10, size=(n, rank)) / 10.0
    diag = rng.integers(1, 100, n) / 100.0 if rank == n else np.zeros(n)
    p = np.round(lmat @ lmat.T + np.diag(diag), 2)
    p = np.round((p + p.T) / 2.0, 2)
    x0 = np.round(rng.uniform(-1.0, 1.0, n), 2)
    blocks = []
    # Boxes on (a subset of) the variables.
    box = sorted(rng.choice(n, size=int(rng.integers(n // 2, n + 1)), replace=False))
    if rank < n or full:
        box = list(range(n))  # a semidefinite P: every variable boxed
    blocks.append(("box", np.eye(n)[box]))
    # First differences.
    k = n - 1 if full else int(rng.integers(0, n))
    diff = np.zeros((k, n))
    for r in range(k):
        diff[r, r], diff[r, r + 1] = -1.0, 1.0
    blocks.append(("rate", diff))
    # Predicted outputs: lower-triangular Toeplitz rows of an impulse
    # response, one or two outputs.
    for _ in range(2 if full else int(rng.integers(0, 3))):
        w, zeta = rng.uniform(0.2, 1.0), rng.uniform(0.05, 0.5)
        h = np.array([np.exp(-zeta * w * t) * np.sin(w * t + 0.3) for t in range(n)])
        tri = np.array([[h[i - j] if j <= i else 0.0 for j in range(n)] for i in range(n)])
        take = range(n) if full else sorted(
            rng.choice(n, size=int(rng.integers(n // 2, n + 1)), replace=False))
        blocks.append(("output", tri[take]))
    blocks.append(("dense", rng.normal(size=(0 if full else int(rng.integers(0, 4)), n))))
    if rng.random() < 0.4 and not full:  # a duplicated box row
        blocks.append(("duplicate", np.eye(n)[[box[0]]]))
    g_parts = []
    for kind, blk in blocks:
        if len(blk) == 0:
            continue
        unit = 1.0
        if kind in ("output", "dense") and rng.random() < 0.3:
            unit = float(rng.choice([1e-3, 1e3]))
        g_parts.append(blk * unit)
    g = np.vstack(g_parts)
    g = np.vectorize(sig)(g)
    m = g.shape[0]
    gx0 = g @ x0
    lower, upper, rows = np.empty(m), np.empty(m), []
    scale = np.maximum(np.abs(g).max(axis=1), 1e-300)
    for i in range(m):
        # A semidefinite P's boxes (the first n rows) stay hard and finite:
        # a soft or open box could leave the problem unbounded below.
        semidefinite_box = rank < n and i < n
        soft = rng.random() < 0.3 and not semidefinite_box
        width = lambda: {0: 0.0, 1: np.inf}.get(int(rng.choice(4, p=[0.15, 0.15, 0.35, 0.35])),
                                               float(rng.uniform(0.0, 1.0)))
        lo_w, up_w = width(), width()
        if semidefinite_box:
            lo_w, up_w = min(lo_w, 1.0), min(up_w, 1.0)
        centre = gx0[i] + (rng.normal(0.0, 0.5) * scale[i] if soft else 0.0)
        lower[i] = centre - lo_w * scale[i]
        upper[i] = centre + up_w * scale[i]
        if not soft and rng.random() < 0.03:
            lower[i] = upper[i] = gx0[i]  # an equality row
        if soft:
            # A third of the cases keep every soft row's quadratic weight,
            # so quadprog (which needs a definite Hessian) checks them too.
            kind = int(rng.integers(0, 3)) if index % 3 else int(rng.integers(1, 3))
            w1 = float(sig(rng.uniform(0.1, 20.0), 3)) if kind != 1 else 0.0
            w2 = float(sig(rng.uniform(0.1, 50.0), 3)) if kind != 0 else 0.0
            rows.append({"linear": w1, "quadratic": w2})
        else:
            rows.append({"hard": True})
    # The unconstrained minimiser far from x0: q = −P xt (plus a part
    # outside P's range where P is singular; the boxes bound it).
    xt = x0 + rng.normal(0.0, 3.0, n)
    q = np.vectorize(lambda v: sig(v, 6))(-p @ xt + (rng.normal(0.0, 1.0, n) if rank < n else 0.0))
    name = "random_full" if full else f"random_{index:02}"
    return reference(name, p, q, g, lower, upper, rows, x_unique=rank == n)


def condensed_mpc(name, plant, x_init, r2, horizon, nu, u_prev, rate, soft, weights):
    """The condensed MPC of a two-cart plant (m1, m2, k1, k2, b1, b2; 4
    states, ZOH at 2 ms): `nu` = 1 force on cart 2, or 2 (cart 2, cart 1)
    in N; variables the inputs' deviations from their steady state for cart
    2 at `r2` m (least-norm for two inputs); hard input box ±24 N, hard rate
    rows ±`rate` N per step from `u_prev` on, soft |x1|, |x2| ≤ 48 mm at
    every step (`soft` = (linear, quadratic) per metre); cost
    Σ xᵀQx (DARE terminal) + rw Σ u² + sw Σ Δu²."""
    m1, m2, k1, k2, b1, b2 = plant
    a = np.array([[0.0, 1.0, 0.0, 0.0],
                  [-(k1 + k2) / m1, -b1 / m1, k2 / m1, 0.0],
                  [0.0, 0.0, 0.0, 1.0],
                  [k2 / m2, 0.0, -k2 / m2, -b2 / m2]])
    b = np.array([[0.0, 0.0], [0.0, 1.0 / m1], [0.0, 0.0], [1.0 / m2, 0.0]])[:, :nu]
    ad, bd, *_ = scipy.signal.cont2discrete((a, b, np.eye(4), np.zeros((4, nu))), 0.002, "zoh")
    q1, q2, rw, sw = weights
    qw = np.diag([q1, 0.0, q2, 0.0])
    pw = scipy.linalg.solve_discrete_are(ad, bd, qw + 1e-6 * np.eye(4), rw * np.eye(nu))
    h = horizon
    n = h * nu
    phi = np.vstack([np.linalg.matrix_power(ad, k + 1) for k in range(h)])
    gamma = np.zeros((4 * h, n))
    for k in range(h):
        for j in range(k + 1):
            gamma[4 * k:4 * k + 4, nu * j:nu * j + nu] = np.linalg.matrix_power(ad, k - j) @ bd
    qbar = scipy.linalg.block_diag(*([qw] * (h - 1) + [pw]))
    diff = np.eye(n) - np.eye(n, k=-nu)
    hess = 2.0 * (gamma.T @ qbar @ gamma + rw * np.eye(n) + sw * diff.T @ diff)
    hess = (hess + hess.T) / 2.0
    # Steady state: A xs + B us = 0 with x2 = r2 (continuous equilibria are
    # the ZOH model's too).
    kkt = np.vstack([np.hstack([a, b]), np.concatenate([[0.0, 0.0, 1.0, 0.0], np.zeros(nu)])])
    sol = np.linalg.lstsq(kkt, np.concatenate([np.zeros(4), [r2]]), rcond=None)[0]
    xs, us = sol[:4], sol[4:]
    u_prev = np.asarray(u_prev)[:nu]
    dx0 = np.asarray(x_init) - xs
    first = np.zeros((n, nu))
    first[:nu, :nu] = np.eye(nu)
    q = 2.0 * gamma.T @ qbar @ phi @ dx0 + 2.0 * sw * diff.T @ first @ (us - u_prev)
    pos = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
    out_g = np.vstack([pos @ gamma[4 * k:4 * k + 4] for k in range(h)])
    out_free = np.concatenate([pos @ phi[4 * k:4 * k + 4] @ dx0 for k in range(h)])
    ys = np.tile(pos @ xs, h)
    g = np.vstack([np.eye(n), diff, out_g])
    us_all = np.tile(us, h)
    lower = np.concatenate([-24.0 - us_all, np.full(n, -rate), -0.048 - ys - out_free])
    upper = np.concatenate([24.0 - us_all, np.full(n, rate), 0.048 - ys - out_free])
    lower[n:n + nu] += u_prev - us
    upper[n:n + nu] += u_prev - us
    rows = [{"hard": True}] * (2 * n) + [{"linear": soft[0], "quadratic": soft[1]}] * (2 * h)
    return reference(name, hess, q, g, lower, upper, rows)


LAB = (1.3, 0.7, 1000.0, 1000.0, 10.0, 5.0)


def lab_mpc(name, x_init, horizon=30):
    """The lab's plant, force on cart 2 (±24 N, ±2 N per step), cart 2 to
    45 mm (x1 = 22.5 mm, u = 22.5 N at steady state)."""
    return condensed_mpc(name, LAB, x_init, 0.045, horizon, 1, [0.0], 2.0, (1e5, 1e8),
                         (1e4, 1e6, 1e-3, 1e-2))


def random_mpc(rng, index):
    """A random MPC of the lab's size: the plant's parameters within ±20 %,
    horizon 20…40, one input (every third case two: 40…80 variables), a
    random setpoint, state (sometimes beyond a position limit), last input,
    rate limit and weights."""
    plant = tuple(v * rng.uniform(0.8, 1.2) for v in LAB)
    nu = 2 if index % 3 == 2 else 1
    horizon = int(rng.integers(20, 41))
    x_init = [rng.uniform(-0.06, 0.06), rng.uniform(-0.3, 0.3),
              rng.uniform(-0.06, 0.06), rng.uniform(-0.3, 0.3)]
    u_prev = rng.uniform(-24.0, 24.0, 2)
    soft = (sig(10 ** rng.uniform(3, 5), 3), sig(10 ** rng.uniform(6, 8), 3))
    weights = (sig(10 ** rng.uniform(3, 5), 3), sig(10 ** rng.uniform(5, 7), 3),
               sig(10 ** rng.uniform(-4, -2), 3), sig(10 ** rng.uniform(-3, -1), 3))
    return condensed_mpc(f"mpc_random_{index:02}", plant, x_init, rng.uniform(-0.04, 0.04),
                         horizon, nu, u_prev, float(rng.uniform(1.0, 4.0)), soft, weights)


def main():
    rng = np.random.default_rng(SEED)
    cases = [random_case(rng, i) for i in range(24)]
    cases += [random_case(rng, 24 + i, full=True) for i in range(1)]
    cases.append(lab_mpc("mpc_lab_h30_setpoint", [0.0, 0.0, 0.0, 0.0]))
    cases.append(lab_mpc("mpc_lab_h30_beyond_limit", [0.02, 0.0, 0.052, 0.4]))
    # A generator of its own, so the cases above stay what they were.
    mpc_rng = np.random.default_rng(SEED + 1)
    cases += [random_mpc(mpc_rng, i) for i in range(MPC_CASES)]
    json.dump({
        "source": "tests/data/gen_qp_fixtures.py",
        "versions": {
            "osqp": osqp.__version__,
            "clarabel": clarabel.__version__,
            "quadprog": getattr(quadprog, "__version__", "0.1.14"),
            "numpy": np.__version__,
            "scipy": scipy.__version__,
        },
        "osqp_settings": {"eps_abs": OSQP_EPS, "eps_rel": OSQP_EPS, "polishing": True,
                          "max_iter": 1_000_000},
        "cases": cases,
    }, sys.stdout, separators=(",", ":"))
    sys.stdout.write("\n")
    for c in cases:
        print(c["name"], c["n"], c["m"], c["osqp"], c["check"], file=sys.stderr)


if __name__ == "__main__":
    main()
