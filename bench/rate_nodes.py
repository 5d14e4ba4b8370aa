#!/usr/bin/env python3
"""`decimate` and `resample` against scipy, in one run, one core each.

Chains (bench/rate_decimate.toml, bench/rate_resample.toml): a 10 kHz 50 Hz
sine of 100 s (1 M samples) decimated to 1 kHz, and a 44.1 kHz 50 Hz sine of
30 s (1.323 M samples) resampled to 1 kHz. evflow's figure is the rate node's
own time from `evflow run --json` (building it — the filter design — and
processing); scipy's is the call on the same signal, filter design included:

- `signal.upfirdn(h, x, 1, 10)` with h = `signal.firwin(661, 450, window=
  ('kaiser', 10.17), fs=10000)`, the same filter `decimate` designs (Kaiser,
  101 dB, pass to 400 Hz, stop from 500 Hz), polyphase like it;
- `signal.decimate(x, 10, ftype='fir')`, scipy's own default (a 201-tap
  Hamming FIR, about 53 dB), for scale;
- `signal.resample_poly(x, 10, 441)` (scipy's default Kaiser β = 5 filter of
  8821 taps) beside `resample` at quality balanced (a 5648-tap sinc) and
  fast (cubic).

Input samples per second, best of --repeat runs; the output RMS of each
(0.7071 for a 50 Hz sine) is printed as a check.

Usage: python3 bench/rate_nodes.py [--repeat 5]
Needs: numpy, scipy and a release build of evflow.
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


def evflow_node(exe, graph, node, *sets):
    """(node seconds, output RMS) of one run."""
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "r.json")
        args = [exe, "run", os.path.join(ROOT, "bench", graph), "--quiet", "--json", out, "--out", d]
        for s in sets:
            args += ["--set", s]
        subprocess.run(args, check=True, stdout=subprocess.DEVNULL)
        with open(out) as f:
            r = json.load(f)
    seconds = next(t["seconds"] for t in r["times"] if t["node"] == node)
    return seconds, r["summaries"]["sink"]["values"]["rms"]


def timed(f, x):
    t0 = time.perf_counter()
    y = f(x)
    return time.perf_counter() - t0, float(np.sqrt(np.mean(y[len(y) // 10 :] ** 2)))


def sine(fs, seconds):
    return np.sin(2 * np.pi * 50.0 * np.arange(int(fs * seconds)) / fs)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=5, help="runs of each; the best is kept")
    ap.add_argument("--exe", default=os.path.join(ROOT, "target", "release", "evflow"))
    a = ap.parse_args()
    if not os.path.exists(a.exe):
        subprocess.run(["cargo", "build", "--release", "-p", "evflow"], cwd=ROOT, check=True)
    x10k, x44k = sine(10_000.0, 100.0), sine(44_100.0, 30.0)
    beta = 0.1102 * (101.0 - 8.7)
    peers = {
        "scipy upfirdn, same 661-tap filter": (x10k, lambda x: signal.upfirdn(signal.firwin(661, 450.0, window=("kaiser", beta), fs=10_000.0), x, 1, 10)),
        "scipy decimate (201-tap Hamming FIR)": (x10k, lambda x: signal.decimate(x, 10, ftype="fir")),
        "scipy resample_poly 10/441": (x44k, lambda x: signal.resample_poly(x, 10, 441)),
    }
    ours = {
        "evflow decimate (661 taps)": (x10k.size, ("rate_decimate.toml", "down")),
        "evflow resample balanced": (x44k.size, ("rate_resample.toml", "res", "quality=balanced")),
        "evflow resample fast": (x44k.size, ("rate_resample.toml", "res", "quality=fast")),
    }
    best = {}
    for _ in range(a.repeat):
        for name, (n, args) in ours.items():
            t, rms = evflow_node(a.exe, *args)
            best[name] = min(best.get(name, (float("inf"), rms)), (t, rms))
        for name, (x, f) in peers.items():
            t, rms = timed(f, x)
            best[name] = min(best.get(name, (float("inf"), rms)), (t, rms))
    sizes = {**{k: v[0] for k, v in ours.items()}, **{k: v[0].size for k, v in peers.items()}}
    print(f"{'':40} {'input samples/s':>16} {'time':>9} {'output RMS':>11}")
    for name, (t, rms) in best.items():
        print(f"{name:40} {sizes[name] / t / 1e6:13.1f} M {t * 1e3:7.1f} ms {rms:11.6f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
