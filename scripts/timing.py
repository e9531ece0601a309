"""What the side-by-side timing scripts share. Import it before NumPy: it
pins the BLAS libraries to one thread (ctrlab runs on one), unless the
caller set them."""

import os
import time

for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def median_time(f, repeats):
    """The median wall time of `repeats` calls of `f`, in seconds."""
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return sorted(times)[len(times) // 2]
