"""Issue 28, minimal realisations: references for ctrlab's
`DynStateSpace::minimal_realization`, `TransferFunction::minimal_realization`
and the minimal MIMO `TransferMatrix::to_state_space`.

python-control 0.10.2's state-space `minreal` needs Slycot (`tb01pd`), not
installed here, and its MIMO `tf2ss` needs Slycot (`td04ad`) too, so the
state-space references come from an independent method: a Kalman
decomposition with SciPy (`scipy.linalg.orth` of the controllability
matrix, then `scipy.linalg.null_space` of the observability matrix of the
controllable part), giving the minimal state count and poles; the
frequency response is python-control's of the ORIGINAL model (`ct.ss`,
`frequency_response`), which any realisation must reproduce. Transfer
function pole-zero cancellation is python-control's own `minreal`.

    python3 tests/data/gen_minreal_fixtures.py > tests/data/minreal_fixtures.json
"""

import json

import control as ct
import numpy as np
import scipy
import scipy.linalg as la


def rows(m):
    return np.atleast_2d(np.asarray(m, dtype=float)).tolist()


def cplx(v):
    v = sorted(np.asarray(v, dtype=complex), key=lambda z: (z.real, z.imag))
    return [[float(z.real), float(z.imag)] for z in v]


def kalman_minimal(a, b, c):
    n = a.shape[0]
    ctrb = np.hstack([np.linalg.matrix_power(a, k) @ b for k in range(n)])
    qc = la.orth(ctrb, rcond=1e-10)
    a1, c1 = qc.T @ a @ qc, c @ qc
    m = a1.shape[0]
    obsv = np.vstack([c1 @ np.linalg.matrix_power(a1, k) for k in range(m)])
    unobs = la.null_space(obsv, rcond=1e-10)
    # Orthogonal complement of the unobservable subspace.
    qo = la.null_space(unobs.T) if unobs.size else np.eye(m)
    return qc @ qo


W = np.logspace(-2, 2, 9)


def ss_case(name, a, b, c, d):
    a, b, c, d = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (a, b, c, d))
    q = kalman_minimal(a, b, c)
    am = q.T @ a @ q
    sys = ct.ss(a, b, c, d)
    resp = sys(1j * W)  # outputs x inputs x freqs
    resp = np.reshape(resp, (c.shape[0], b.shape[1], len(W)))
    return {
        "name": name, "a": rows(a), "b": rows(b), "c": rows(c), "d": rows(d),
        "states": int(q.shape[1]),
        "poles": cplx(np.linalg.eigvals(am)) if q.shape[1] else [],
        "omega": W.tolist(),
        "response_re": resp.real.tolist(), "response_im": resp.imag.tolist(),
    }


def ss_cases():
    out = []
    # 1/(s+1) plus an uncontrollable state at -2 and an unobservable one at -3.
    out.append(ss_case("uncontrollable_and_unobservable",
                       np.diag([-1.0, -2.0, -3.0]), [[1.0], [0.0], [1.0]],
                       [[1.0, 1.0, 0.0]], [[0.0]]))
    # A non-diagonal case: a random 3-state plant embedded in 5 states by a
    # similarity transform with an uncontrollable and an unobservable mode.
    rng = np.random.default_rng(28)
    a0 = rng.normal(size=(3, 3)) - 3 * np.eye(3)
    b0 = rng.normal(size=(3, 2))
    c0 = rng.normal(size=(2, 3))
    a = np.zeros((5, 5)); a[:3, :3] = a0; a[3, 3] = -0.5; a[4, 4] = -7.0
    a[3, 0] = 0.3  # state 3 sees the plant but does not reach the output
    a[0, 4] = 0.2  # state 4 drives the plant but no input reaches it
    b = np.zeros((5, 2)); b[:3] = b0; b[3] = [1.0, -1.0]
    c = np.zeros((2, 5)); c[:, :3] = c0; c[:, 4] = [0.5, 1.0]
    t = la.qr(rng.normal(size=(5, 5)))[0]
    out.append(ss_case("mimo_embedded", t.T @ a @ t, t.T @ b, c @ t, rng.normal(size=(2, 2))))
    # A duplicated SISO mode: two copies of 1/(s+2) in parallel (one state).
    out.append(ss_case("parallel_copies", np.diag([-2.0, -2.0]), [[1.0], [1.0]],
                       [[1.0, 1.0]], [[0.0]]))
    return out


def tf_cases():
    out = []
    for num, den in [([2.0, 2.0], [1.0, 4.0, 3.0]),
                     ([1.0, 3.0, 2.0], [1.0, 6.0, 11.0, 6.0]),
                     ([1.0, 2.0, 5.0], [1.0, 3.0, 7.0, 5.0]),
                     ([1.0, 1.0 + 1e-9], [1.0, 3.0, 2.0]),
                     ([1.0, 1.5], [1.0, 3.0, 2.0])]:
        m = ct.tf(num, den).minreal()
        out.append({"num": num, "den": den,
                    "min_num": np.asarray(m.num[0][0], dtype=float).tolist(),
                    "min_den": np.asarray(m.den[0][0], dtype=float).tolist()})
    return out


def mimo_tf():
    # [1/(s+1), 1/(s+2); 1/(s+1), 1/(s+2)]: entry by entry 4 states, minimal 2.
    # [1/(s+1), 2/(s+1); 1/(s+2), 1/(s+1)] ... general case: 3 states.
    cases = []
    for name, entries in [
        ("rank_one", [[([1.0], [1.0, 1.0]), ([1.0], [1.0, 2.0])],
                      [([1.0], [1.0, 1.0]), ([1.0], [1.0, 2.0])]]),
        ("three_states", [[([1.0], [1.0, 1.0]), ([2.0], [1.0, 1.0])],
                          [([1.0], [1.0, 2.0]), ([1.0, 0.0], [1.0, 3.0, 2.0])]]),
    ]:
        num = [[e[0] for e in r] for r in entries]
        den = [[e[1] for e in r] for r in entries]
        g = ct.tf(num, den)
        # Entry-by-entry realisation, then the Kalman reduction above.
        parts = [[ct.tf2ss(ct.tf(*e)) for e in r] for r in entries]
        p, m = len(entries), len(entries[0])
        n = sum(s.nstates for r in parts for s in r)
        a = np.zeros((n, n)); b = np.zeros((n, m)); c = np.zeros((p, n)); d = np.zeros((p, m))
        at = 0
        for i in range(p):
            for j in range(m):
                s = parts[i][j]; k = s.nstates
                a[at:at + k, at:at + k] = s.A; b[at:at + k, j:j + 1] = s.B
                c[i:i + 1, at:at + k] = s.C; d[i, j] = s.D[0, 0]
                at += k
        q = kalman_minimal(a, b, c)
        resp = np.reshape(g(1j * W), (p, m, len(W)))
        cases.append({"name": name, "num": num, "den": den, "entrywise_states": n,
                      "states": int(q.shape[1]),
                      "poles": cplx(np.linalg.eigvals(q.T @ a @ q)),
                      "omega": W.tolist(),
                      "response_re": resp.real.tolist(), "response_im": resp.imag.tolist()})
    return cases


print(json.dumps({
    "versions": {"control": ct.__version__, "scipy": scipy.__version__, "numpy": np.__version__},
    "ss": ss_cases(), "tf": tf_cases(), "mimo_tf": mimo_tf(),
}, indent=1))
