"""Chirp fixtures from SciPy (scipy.signal.chirp, phi=-90 so the sweep is a sine
starting at 0): used by tests/signals.rs. Run: python3 tests/data/gen_chirp_fixtures.py"""
import json, numpy as np, scipy, scipy.signal as ss
out = {"source": f"scipy {scipy.__version__} scipy.signal.chirp(t, f0, t1, f1, method, phi=-90)", "cases": []}
for (f0, f1, T, method) in [(0.5, 20.0, 20.0, "linear"), (30.0, 2.0, 5.0, "linear"),
                            (0.2, 25.0, 30.0, "logarithmic"), (10.0, 1.0, 4.0, "logarithmic")]:
    t = np.linspace(0.0, T, 1001)
    y = ss.chirp(t, f0=f0, t1=T, f1=f1, method=method, phi=-90)
    out["cases"].append({"f0": f0, "f1": f1, "duration": T, "method": method,
                         "t": t.tolist(), "y": y.tolist()})
json.dump(out, open("tests/data/chirp_fixtures.json", "w"))
