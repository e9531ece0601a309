#!/usr/bin/env python3
"""Generates tests/data/hac_fixtures.json: Newey-West (HAC) covariances of
ordinary least squares from statsmodels, for ctrlab's `Covariance::NeweyWest`.

    pip install statsmodels numpy
    python3 tests/data/gen_hac_fixtures.py > tests/data/hac_fixtures.json

Every case holds the regressor X (a list of rows), y, the segment starts
(row indices where a new segment begins; [] for one series), the number of
lags L, and statsmodels' estimate, covariance and standard errors:

- one series: `OLS(y, X).fit(cov_type="HAC", cov_kwds={"maxlags": L,
  "use_correction": True})` (Bartlett weights 1 - l/(L+1), the small-sample
  factor n/(n-p));
- segments: `cov_type="hac-panel"` with `groups` (one label per segment) and
  its default `use_correction="hac"`, the same factor: Bartlett sums within
  each segment, none across;
- "auto" cases: the bandwidth by Newey and West's (1994) automatic
  selection for the Bartlett kernel, computed here with NumPy from the
  paper's formulas (see `automatic_lags`), then statsmodels' covariance at
  that bandwidth as above; `rule_of_thumb` is statsmodels' own default
  bandwidth, floor(4 (n/100)^(2/9)), the selection's pre-bandwidth.

The equation errors are the second difference of white noise (what
differencing quantised positions gives), some scaled with the regressor
(heteroskedastic), and the columns span several orders of magnitude.
"""

import json
import sys

import numpy as np
import statsmodels
import statsmodels.api as sm
from statsmodels.stats import sandwich_covariance as sw


def second_difference_noise(rng, n, scale=1.0):
    w = rng.normal(0.0, scale, n + 2)
    return w[2:] - 2.0 * w[1:-1] + w[:-2]


def rule_of_thumb(n):
    return int(np.floor(4.0 * (n / 100.0) ** (2.0 / 9.0)))


def automatic_lags(X, resid, starts):
    """Newey & West (1994), Bartlett kernel, without prewhitening.

    The series is each row's influence on the estimate, (X'X)^-1 x_t e_t;
    h_t sums its columns, each divided by its root sum of squares.
    sigma_j = sum_t h_t h_{t-j} within segments (the 1/n cancels), for
    j <= n_pre = floor(4 (n/100)^(2/9)); s0 = sigma_0 + 2 sum sigma_j,
    s1 = 2 sum j sigma_j; L = floor(1.1447 |s1/s0|^(2/3) n^(1/3)), capped at
    min(1000, n // 4) (and at the cap when s0 <= 0).
    """
    n = len(resid)
    influence = np.linalg.solve(X.T @ X, (X * resid[:, None]).T).T
    norms = np.sqrt((influence**2).sum(axis=0))
    h = (influence / np.where(norms > 0, norms, 1.0)).sum(axis=1)
    pre = rule_of_thumb(n)
    cap = min(1000, n // 4)
    if pre == 0:
        return 0
    bounds = [0, *starts, n]
    sigma = np.zeros(pre + 1)
    for a, b in zip(bounds[:-1], bounds[1:]):
        seg = h[a:b]
        for j in range(min(pre, len(seg) - 1) + 1):
            sigma[j] += seg[j:] @ seg[: len(seg) - j]
    s0 = sigma[0] + 2.0 * sigma[1:].sum()
    s1 = 2.0 * (np.arange(pre + 1) * sigma).sum()
    if not s0 > 0:
        return cap
    gamma = 1.1447 * abs(s1 / s0) ** (2.0 / 3.0)
    return min(int(np.floor(gamma * n ** (1.0 / 3.0))), cap)


def case(name, X, y, lags, starts=(), auto=False):
    res = sm.OLS(y, X).fit()
    if auto:
        lags = automatic_lags(X, np.asarray(res.resid), list(starts))
    if starts:
        bounds = [0, *starts, len(y)]
        groups = np.concatenate(
            [np.full(b - a, g) for g, (a, b) in enumerate(zip(bounds[:-1], bounds[1:]))]
        )
        cov = res.get_robustcov_results(
            cov_type="hac-panel", groups=groups, maxlags=lags
        ).cov_params()
    else:
        cov = res.get_robustcov_results(
            cov_type="HAC", maxlags=lags, use_correction=True
        ).cov_params()
    cov = np.asarray(cov)
    return {
        "name": name,
        "lags": lags,
        "automatic": auto,
        "rule_of_thumb": rule_of_thumb(len(y)),
        "segment_starts": list(starts),
        "X": X.tolist(),
        "y": y.tolist(),
        "theta": np.asarray(res.params).tolist(),
        "cov": cov.tolist(),
        "std_errors": np.sqrt(np.diag(cov)).tolist(),
        "classical_cov": np.asarray(res.cov_params()).tolist(),
    }


def main():
    rng = np.random.default_rng(20240612)
    cases = []

    # A line with a sine: three columns of different scales.
    n = 200
    t = np.arange(n) / n
    X = np.column_stack([np.ones(n), 1e3 * t, 1e-3 * np.sin(12.0 * t)])
    y = X @ np.array([0.5, 2e-3, 700.0]) + second_difference_noise(rng, n, 0.1)
    for lags in (0, 1, 2, 5, 12):
        cases.append(case(f"series_lags_{lags}", X, y, lags))
    cases.append(case("series_auto", X, y, None, auto=True))

    # Heteroskedastic errors (scaled with |x|) on two columns.
    n = 150
    x = rng.normal(0.0, 1.0, n)
    X2 = np.column_stack([x, x**2 + 0.1 * rng.normal(0.0, 1.0, n)])
    y2 = X2 @ np.array([1.5, -0.7]) + (0.2 + np.abs(x)) * second_difference_noise(rng, n, 0.05)
    for lags in (0, 3, 9):
        cases.append(case(f"heteroskedastic_lags_{lags}", X2, y2, lags))
    cases.append(case("heteroskedastic_auto", X2, y2, None, auto=True))

    # Three segments, one shorter than the bandwidth.
    n = 200
    starts = (50, 57)
    s = np.arange(n) * 0.01
    X3 = np.column_stack([np.ones(n), np.cos(3.0 * s), s])
    y3 = X3 @ np.array([0.1, 2.0, -1.0]) + second_difference_noise(rng, n, 0.3)
    for lags in (4, 10):
        cases.append(case(f"segments_lags_{lags}", X3, y3, lags, starts))
    cases.append(case("segments_auto", X3, y3, None, starts, auto=True))

    # White errors: the automatic bandwidth stays small.
    n = 300
    X4 = np.column_stack([np.ones(n), rng.normal(0.0, 1.0, n)])
    y4 = X4 @ np.array([1.0, 0.5]) + rng.normal(0.0, 0.2, n)
    cases.append(case("white_auto", X4, y4, None, auto=True))

    json.dump(
        {
            "generator": "tests/data/gen_hac_fixtures.py",
            "statsmodels": statsmodels.__version__,
            "numpy": np.__version__,
            "cases": cases,
        },
        sys.stdout,
        indent=1,
    )
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
