#!/usr/bin/env python3
"""Inverse NARX model: evflow against a Python peer on the same data (issue 6, point 12).

One run of this script
  1. runs `evflow bench narx --export DIR --curve` (release build): records the
     training data (3066 samples, random binary sequence on the simulated lab,
     85 g, 5 cm/s, force high-passed at 10 Hz) and a held-out recording, trains
     the default network (15-10-5 tanh + linear output, one feedback tap, ten
     input taps, look-ahead from the cross-correlation, Levenberg-Marquardt,
     early stopping on the last 15 %), and reports training time per epoch,
     the held-out closed-loop error of the model each epoch budget gives, and
     closed-loop inference throughput;
  2. trains the same network in numpy on the same exported data, from the same
     initial weights, with the same regressor, normalization (mapminmax) and
     validation block, by two Levenberg-Marquardt peers:
       * scipy.optimize.least_squares(method="lm") (MINPACK lmder) with the
         analytic Jacobian, early stopping on the validation block through
         the Jacobian callback (MINPACK evaluates it once per accepted step);
       * "numpy trainlm": MATLAB trainlm's update dX = -(J'J + mu I)^-1 J'e
         with numpy (BLAS) and a Cholesky solve, the algorithm evflow runs;
  3. scores every peer model closed loop on the held-out recording exactly as
     evflow does (the first `known` samples fed back with the true u, then its
     own estimates; output clamped to the normalized range), checks the Python
     closed loop against evflow's on evflow's trained weights, times the
     closed loop one sample per step in a numpy loop (the honest peer of
     one-sample-per-tick streaming), and prints the time each side needs to
     reach the same closed-loop error and the throughput ratio.

Everything runs on one core (evflow is single-threaded; BLAS is pinned to one
thread through the usual environment variables).

Usage: python3 bench/narx_peer.py [--samples 3066] [--py-inference 200000]
Needs: numpy, scipy and a release build of evflow (cargo build --release -p evflow).
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
import scipy  # noqa: E402
from scipy.linalg import cho_factor, cho_solve, LinAlgError  # noqa: E402
from scipy.optimize import least_squares  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


# --- the network -------------------------------------------------------------

class Net:
    """tanh hidden layers, one linear output; weights flat as evflow lays them
    out: layer after layer, the weight matrix row-major then the biases."""

    def __init__(self, inputs, hidden):
        self.sizes = [inputs] + list(hidden) + [1]
        self.offsets = []
        n = 0
        for r, s in zip(self.sizes[:-1], self.sizes[1:]):
            self.offsets.append(n)
            n += s * (r + 1)
        self.n_params = n

    def layers(self, w):
        out = []
        for off, r, s in zip(self.offsets, self.sizes[:-1], self.sizes[1:]):
            out.append((w[off:off + s * r].reshape(s, r), w[off + s * r:off + s * r + s]))
        return out

    def forward(self, w, X):
        """Outputs for the rows of X, and the activations of every layer."""
        acts = [X]
        a = X
        layers = self.layers(w)
        for i, (W, b) in enumerate(layers):
            z = a @ W.T + b
            a = z if i + 1 == len(layers) else np.tanh(z)
            acts.append(a)
        return a[:, 0], acts

    def jacobian(self, w, X):
        """dy/dw for every row of X (N x P), by backpropagation."""
        y, acts = self.forward(w, X)
        n = X.shape[0]
        J = np.empty((n, self.n_params))
        layers = self.layers(w)
        delta = np.ones((n, 1))
        for l in range(len(layers) - 1, -1, -1):
            W, _ = layers[l]
            s, r = W.shape
            off = self.offsets[l]
            a_prev = acts[l]
            J[:, off:off + s * r] = (delta[:, :, None] * a_prev[:, None, :]).reshape(n, s * r)
            J[:, off + s * r:off + s * r + s] = delta
            if l > 0:
                delta = (delta @ W) * (1.0 - a_prev * a_prev)
        return y, J


class MapMinMax:
    def __init__(self, lo, hi):
        self.min, self.max = lo, hi
        g = 2.0 / (hi - lo)
        self.gain = g if np.isfinite(g) and g > 0 else 1.0

    def apply(self, x):
        return (x - self.min) * self.gain - 1.0

    def reverse(self, y):
        return (y + 1.0) / self.gain + self.min


def regressors(xn, yn, kf, kx, d):
    """Open-loop rows [y[n-1] .. y[n-kf], x[n+d] .. x[n-kx]] and targets y[n]."""
    first = max(kf, kx)
    rows = len(xn) - first - max(d, 0)
    n = np.arange(first, first + rows)
    cols = [yn[n - k] for k in range(1, kf + 1)] + [xn[n + d - j] for j in range(kx + d + 1)]
    return np.stack(cols, axis=1), yn[n]


# --- closed loop and scores (as nodes/src/narx/closed_loop.rs and eval.rs) ---

def closed_loop(net, w, kf, kx, d, xmap, ymap, x, u=None, known=0):
    """Runs the network closed loop over force x, one sample per step; element
    n of the result estimates u[n]. The first `known` samples feed back the
    true u (the loop's initial states). Histories start at 0 N and u = 0."""
    assert d >= 0, "the peer handles look-ahead d >= 0"
    layers = net.layers(w)
    hidden = layers[:-1]
    w4, c4 = layers[-1][0][0], layers[-1][1][0]
    x0 = xmap.apply(0.0)
    y0 = min(max(ymap.apply(0.0), -1.0), 1.0)
    row = np.empty(kf + kx + d + 1)
    row[:kf] = y0
    row[kf:] = x0
    xg, xmin = xmap.gain, xmap.min
    yg, ymin = ymap.gain, ymap.min
    lat = d
    total = len(x) + lat
    est = np.empty(len(x))
    for t in range(total):
        v = x[t] if t < len(x) else 0.0
        if not np.isfinite(v):
            v = 0.0
        row[kf + 1:] = row[kf:-1]
        row[kf] = (v - xmin) * xg - 1.0
        h = row
        for W, b in hidden:
            h = np.tanh(W @ h + b)
        y = float(w4 @ h + c4)
        y = -1.0 if y < -1.0 else (1.0 if y > 1.0 else y)
        n = t - lat
        if kf > 0:
            fb = y
            if u is not None and 0 <= n < known:
                fb = min(max((u[n] - ymin) * yg - 1.0, -1.0), 1.0)
            row[1:kf] = row[0:kf - 1]
            row[0] = fb
        if n >= 0:
            est[n] = (y + 1.0) / yg + ymin
    return est


def score(est, ref):
    """Sign agreement, transition agreement and RMS as evflow's eval::score."""
    m = ref != 0.0
    sign = float(np.mean(est[m] * ref[m] > 0.0))
    rms = float(np.sqrt(np.mean((est[m] - ref[m]) ** 2)))
    trans = float(np.mean((ref[1:] * ref[:-1] < 0.0) == (est[1:] * est[:-1] < 0.0)))
    return {"sign_agreement": sign, "transition_agreement": trans, "rms": rms}


# --- trainers -------------------------------------------------------------------

class ValidationStop(Exception):
    pass


class Tracker:
    """Early stopping as MATLAB (and evflow): an iterate with a lower
    validation MSE becomes the best; a higher one counts a failure; max_fail
    failures in a row stop. Keeps the best weights after every iteration so
    the model any iteration budget gives can be scored afterwards."""

    def __init__(self, net, Xv, tv, max_fail, start):
        self.net, self.Xv, self.tv, self.max_fail, self.start = net, Xv, tv, max_fail, start
        self.best = np.inf
        self.best_w = None
        self.fails = 0
        self.history = []  # (iteration, seconds, best weights so far)

    def update(self, w):
        y, _ = self.net.forward(w, self.Xv)
        v = float(np.mean((y - self.tv) ** 2))
        if v < self.best or self.best_w is None:
            self.best, self.best_w, self.fails = v, w.copy(), 0
        elif v > self.best:
            self.fails += 1
        self.history.append((len(self.history), time.perf_counter() - self.start, self.best_w))
        return self.fails >= self.max_fail


def train_scipy_lm(net, w0, X, t, Xv, tv, max_fail, max_nfev):
    start = time.perf_counter()
    tr = Tracker(net, Xv, tv, max_fail, start)
    calls = {"fun": 0, "jac": 0}

    def fun(w):
        calls["fun"] += 1
        y, _ = net.forward(w, X)
        return y - t

    def jac(w):
        calls["jac"] += 1
        if tr.update(w):
            raise ValidationStop()
        return net.jacobian(w, X)[1]

    stop = "validation_stop"
    try:
        r = least_squares(fun, w0, jac=jac, method="lm", max_nfev=max_nfev)
        tr.update(r.x)
        stop = r.message
    except ValidationStop:
        pass
    seconds = time.perf_counter() - start
    return tr, seconds, stop, calls


def train_numpy_trainlm(net, w0, X, t, Xv, tv, opts):
    """MATLAB trainlm, as evflow's train/lm.rs: J'J + mu I by Cholesky, mu x0.1
    after an improving step, x10 otherwise, stops at mu_max, min_grad,
    max_epochs or max_fail validation failures."""
    start = time.perf_counter()
    tr = Tracker(net, Xv, tv, opts["max_fail"], start)
    w = w0.copy()
    y, _ = net.forward(w, X)
    perf = float(np.mean((y - t) ** 2))
    tr.update(w)
    mu = opts["mu"]
    n, p = X.shape[0], net.n_params
    stop = "max_epochs"
    for _ in range(opts["max_epochs"]):
        y, J = net.jacobian(w, X)
        e = y - t
        jtj = J.T @ J
        jte = J.T @ e
        if 2.0 * np.linalg.norm(jte) / n < opts["min_grad"]:
            stop = "min_grad"
            break
        improved = False
        while mu <= opts["mu_max"]:
            try:
                c = cho_factor(jtj + mu * np.eye(p), lower=True, check_finite=False)
                trial = w - cho_solve(c, jte, check_finite=False)
                y2, _ = net.forward(trial, X)
                perf2 = float(np.mean((y2 - t) ** 2))
                if perf2 < perf:
                    w, perf, improved = trial, perf2, True
                    mu *= opts["mu_dec"]
                    break
            except LinAlgError:
                pass
            mu *= opts["mu_inc"]
        if not improved:
            stop = "mu_max"
            break
        if tr.update(w):
            stop = "validation_stop"
            break
    seconds = time.perf_counter() - start
    return tr, seconds, stop, len(tr.history) - 1


# --- the run --------------------------------------------------------------------

def load_csv(path):
    a = np.loadtxt(path, delimiter=",", skiprows=1)
    return a[:, 0].copy(), a[:, 1].copy()


def first_reaching(curve, target):
    """(seconds, iteration) of the first point whose transition agreement reaches target."""
    for it, secs, s in curve:
        if s["transition_agreement"] >= target:
            return secs, it
    return None, None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    target_dir = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
    ap.add_argument("--exe", default=os.path.join(target_dir, "release", "evflow"))
    ap.add_argument("--samples", type=int, default=3066, help="training samples")
    ap.add_argument("--excitation", default="rbs", choices=["rbs", "prbs20"])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--inference", type=int, default=10_000_000, help="closed-loop samples timed in evflow")
    ap.add_argument("--py-inference", type=int, default=200_000, help="closed-loop samples timed in numpy")
    ap.add_argument("--keep", help="keep the exported data in this directory")
    a = ap.parse_args()
    if not os.path.exists(a.exe):
        subprocess.run(["cargo", "build", "--release", "-p", "evflow"], cwd=ROOT, check=True)

    with tempfile.TemporaryDirectory() as tmp:
        d = a.keep or tmp
        cmd = [a.exe, "bench", "narx", "--curve", "--export", d, "--samples", str(a.samples),
               "--excitation", a.excitation, "--seed", str(a.seed), "--inference-samples", str(a.inference)]
        print("$ " + " ".join(cmd[1:]), file=sys.stderr)
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        setup = json.load(open(os.path.join(d, "setup.json")))
        rust = json.load(open(os.path.join(d, "rust.json")))
        x, u = load_csv(os.path.join(d, "train.csv"))
        xh, uh = load_csv(os.path.join(d, "heldout.csv"))

    kf, kx, dd = setup["delays"]["feedback"], setup["delays"]["input"], setup["delays"]["lookahead"]
    nm = setup["normalization"]
    # The peer fits its own mapminmax; it must equal evflow's.
    assert (x.min(), x.max()) == (nm["x"]["min"], nm["x"]["max"]), "force range differs"
    assert (u.min(), u.max()) == (nm["y"]["min"], nm["y"]["max"]), "actuation range differs"
    xmap, ymap = MapMinMax(x.min(), x.max()), MapMinMax(u.min(), u.max())
    X, t = regressors(xmap.apply(x), ymap.apply(u), kf, kx, dd)
    n_tr, n_va = setup["train_rows"], setup["validation_rows"]
    assert n_tr + n_va == len(t), (n_tr, n_va, len(t))
    Xt, tt, Xv, tv = X[:n_tr], t[:n_tr], X[n_tr:], t[n_tr:]
    net = Net(X.shape[1], setup["hidden"])
    w0 = np.array(setup["initial_weights"])
    assert w0.size == net.n_params
    known = setup["known"]

    def heldout(w):
        return score(closed_loop(net, w, kf, kx, dd, xmap, ymap, xh, uh, known)[known:], uh[known:])

    # The Python closed loop on evflow's trained weights must give evflow's score.
    check = heldout(np.array(rust["weights"]))
    diff = max(abs(check[k] - rust["heldout"][k]) for k in check)
    # And the open-loop validation MSE (same regressors, same split).
    yv, _ = net.forward(np.array(rust["weights"]), Xv)
    vdiff = abs(float(np.mean((yv - tv) ** 2)) - rust["validation_mse"]) / rust["validation_mse"]

    lm = setup["lm"]
    peers = {}
    tr, secs, stop, calls = train_scipy_lm(net, w0, Xt, tt, Xv, tv, lm["max_fail"], 100 * net.n_params)
    peers["scipy least_squares lm"] = (tr, secs, stop, len(tr.history) - 1)
    tr, secs, stop, epochs = train_numpy_trainlm(net, w0, Xt, tt, Xv, tv, lm)
    peers["numpy trainlm"] = (tr, secs, stop, epochs)

    curves = {"evflow": [(c["epoch"], c["seconds"], c["heldout"]) for c in rust["curve"]]}
    for name, (tr, _, _, _) in peers.items():
        curves[name] = [(it, s, heldout(w)) for it, s, w in tr.history]
    finals = {"evflow": rust["heldout"]}
    for name, (tr, _, _, _) in peers.items():
        finals[name] = curves[name][-1][2]

    # Closed-loop throughput: numpy, one sample per step, on the held-out force.
    wr = np.array(rust["weights"])
    reps = max(1, -(-a.py_inference // len(xh)))
    xs = np.tile(xh, reps)[:a.py_inference]
    t0 = time.perf_counter()
    closed_loop(net, wr, kf, kx, dd, xmap, ymap, xs)
    py_secs = time.perf_counter() - t0
    py_rate = len(xs) / py_secs
    rs_rate = rust["inference"]["samples_per_second"]

    target = min(max(s["transition_agreement"] for _, _, s in c) for c in curves.values())
    print(f"numpy {np.__version__}, scipy {scipy.__version__}; {a.samples} training samples ({a.excitation}), "
          f"{len(xh)} held-out; {X.shape[1]} inputs (taps: feedback {kf}, input {kx}, look-ahead {dd}), "
          f"hidden {'-'.join(map(str, setup['hidden']))}, {net.n_params} weights")
    print(f"check on evflow's trained weights: held-out closed-loop scores differ by {diff:.1e}, "
          f"open-loop validation MSE by {vdiff:.1e} (relative)")
    print()
    print("| trainer | training time | epochs / iterations | stop | held-out transitions | sign | RMS "
          f"| time to transitions ≥ {target:.3f} |")
    print("|---|---:|---:|---|---:|---:|---:|---:|")
    rt, _ = first_reaching(curves["evflow"], target)
    rows = [("evflow LM (Rust)", rust["train_seconds"], rust["epochs"], rust["stop"], finals["evflow"], rt, None)]
    for name, (tr, secs, stop, its) in peers.items():
        pt, _ = first_reaching(curves[name], target)
        rows.append((name, secs, its, stop, finals[name], pt, rt))
    for name, secs, its, stop, s, reach, ref in rows:
        ratio = f" ({reach / ref:.1f}× evflow)" if reach is not None and ref else ""
        reach_s = f"{reach:.3f} s{ratio}" if reach is not None else "not reached"
        print(f"| {name} | {secs:.3f} s | {its} | {str(stop)[:40]} | {s['transition_agreement']:.3f} "
              f"| {s['sign_agreement']:.3f} | {s['rms']:.3f} | {reach_s} |")
    print()
    print("| closed-loop inference | samples/s | ns/sample |")
    print("|---|---:|---:|")
    print(f"| evflow (Rust, {rust['inference']['samples']} samples) | {rs_rate / 1e6:.2f} M | {1e9 / rs_rate:.0f} |")
    print(f"| numpy loop ({len(xs)} samples) | {py_rate / 1e6:.4f} M | {1e9 / py_rate:.0f} |")
    print(f"| ratio evflow / numpy | {rs_rate / py_rate:.0f}× | |")
    print()
    print(f"evflow fit wall time (alignment, regressors, LM, scoring): {rust['fit_seconds']:.3f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
