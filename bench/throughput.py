#!/usr/bin/env python3
"""Offline throughput of PRBS -> Butterworth HP (4th order, 10 Hz) -> gain -> sink.

Times evflow (the processing loop reported by `evflow run --json`) and the same
chain in numpy/scipy (scipy.signal.max_len_seq -> sosfilt -> multiply -> stats),
in one run on one machine, and prints samples/s for both and their ratio.
Both run on one core (evflow is single-threaded; numpy/scipy are pinned to one
thread through the usual environment variables).

Usage: python3 bench/throughput.py [--repeat 5]
Needs: numpy, scipy (pip install numpy scipy) and a release build of evflow.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[var] = "1"

import numpy as np  # noqa: E402
from scipy import signal  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
GRAPH = os.path.join(ROOT, "bench", "throughput.toml")


def evflow_run(exe):
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "r.json")
        subprocess.run([exe, "run", GRAPH, "--quiet", "--json", out, "--out", d], check=True, stdout=subprocess.DEVNULL)
        with open(out) as f:
            r = json.load(f)
    return r["ticks"], r["seconds"], r["summaries"]["sink"]["values"]


def scipy_run(n_order, periods):
    t0 = time.perf_counter()
    seq, _ = signal.max_len_seq(n_order)
    u = np.tile(seq.astype(np.float64) * 2.0 - 1.0, periods)
    sos = signal.butter(4, 10.0, btype="highpass", fs=1000.0, output="sos")
    y = signal.sosfilt(sos, u) * 1.2
    stats = (y.size, y.mean(), np.sqrt(np.mean(y * y)), y.min(), y.max())
    return u.size, time.perf_counter() - t0, stats


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=5, help="runs of each; the best is kept")
    ap.add_argument("--exe", default=os.path.join(ROOT, "target", "release", "evflow"))
    a = ap.parse_args()
    if not os.path.exists(a.exe):
        subprocess.run(["cargo", "build", "--release", "-p", "evflow"], cwd=ROOT, check=True)
    best_e = best_s = float("inf")
    for _ in range(a.repeat):
        n_e, t_e, vals = evflow_run(a.exe)
        best_e = min(best_e, t_e)
        n_s, t_s, stats = scipy_run(23, 2)
        best_s = min(best_s, t_s)
    assert n_e == n_s, (n_e, n_s)
    # Same filter, same gain: the RMS of the two outputs must agree closely
    # (the PRBS taps differ, the spectrum does not).
    rel = abs(vals["rms"] - stats[2]) / stats[2]
    print(f"samples            {n_e}")
    print(f"evflow             {n_e / best_e / 1e6:8.1f} M samples/s  ({best_e * 1e3:.0f} ms)")
    print(f"numpy/scipy        {n_s / best_s / 1e6:8.1f} M samples/s  ({best_s * 1e3:.0f} ms)")
    print(f"ratio evflow/scipy {best_s / best_e:8.2f}x")
    print(f"output RMS         evflow {vals['rms']:.6f}  scipy {stats[2]:.6f}  (rel. diff {rel:.2e})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
