#!/usr/bin/env python3
"""The simulator's error effects in NumPy, for a side-by-side speed figure.

Run by `cargo run --release -p triad-host --example bench_sim`, which quotes
the ratio; or alone: python3 bench/sim_numpy.py --samples 2000000

Same effects, same parameters and the same sample definition as the Rust
benchmark (one sample = both triads, 6 axes, plus temperature, static scene
at 1 kHz), written the way a NumPy user would: whole arrays at once. The
Gauss-Markov recursion has no vectorised NumPy primitive (scipy.signal.lfilter
would be one, SciPy is not assumed), so it uses the exact block closed form
x_i = phi^i (phi x_prev + sum_j phi^-j w_j) over blocks short enough that
phi^-j stays finite. NumPy's generator (PCG64, ziggurat normals) is not the
Rust one: the outputs agree in distribution, not bit for bit.

Prints one line per effect: "<effect> <samples per second>" (best of 3).
"""
import argparse
import math
import time

import numpy as np

G = 9.80665
TS = 1e-3


def gauss_markov(rng, n, sigma, tc, ts=TS):
    a = ts / tc
    phi = math.exp(-a)
    drive = sigma * math.sqrt(-math.expm1(-2.0 * a))
    w = rng.standard_normal((n, 3)) * drive
    prev = rng.standard_normal(3) * sigma
    block = int(min(4096, max(1, math.floor(300.0 / a))))
    j = np.arange(block)
    up = phi ** (-j.astype(float))
    down = phi ** j.astype(float)
    out = np.empty((n, 3))
    for s in range(0, n, block):
        m = min(block, n - s)
        c = np.cumsum(w[s:s + m] * up[:m, None], axis=0)
        out[s:s + m] = down[:m, None] * (phi * prev + c)
        prev = out[s + m - 1]
    return out


def bias_instability_tcs(terms=7, tau_min=1.0, tau_max=1e4, margin=1.0):
    lo, hi = math.log10(tau_min) - margin, math.log10(tau_max) + margin
    return [10 ** (lo + (hi - lo) * k / (terms - 1)) / 1.8926 for k in range(terms)]


S = np.array([[1e-3, 2e-4, -1e-4], [3e-4, -2e-3, 1e-4], [0.0, 5e-4, 5e-4]])
GS = np.diag([1e-4, 1e-4, 1e-4])


def triad(rng, name, y, f, temp, gyro):
    """Applies one effect (or all) to the truth y (n x 3)."""
    n = len(y)
    names = EFFECTS if name == "all" else [name]
    # The same order as the Rust simulator.
    if "temperature" in names:
        dt = (temp - 25.0)[:, None]
        y = y * (1.0 + 1e-4 * dt)
    if "turn_on_scale" in names:
        y = y * (1.0 + rng.standard_normal(3) * 1e-3)
    if "scale_misalignment" in names:
        y = y + y @ S.T
    if "constant_bias" in names:
        y = y + np.array([1e-2, -2e-2, 3e-2])
    if "turn_on_bias" in names:
        y = y + rng.standard_normal(3) * 1e-2
    if "temperature" in names:
        y = y + 1e-3 * dt
    if "gauss_markov" in names:
        y = y + gauss_markov(rng, n, 1e-3, 100.0)
    if "random_walk" in names:
        y = y + np.cumsum(rng.standard_normal((n, 3)) * (1e-4 * math.sqrt(TS)), axis=0)
    if "bias_instability" in names:
        for tc in bias_instability_tcs():
            y = y + gauss_markov(rng, n, 1e-3, tc)
    if "g_sensitivity" in names and gyro:
        y = y + f @ GS.T
    if "white_noise" in names:
        y = y + rng.standard_normal((n, 3)) * (1e-3 / math.sqrt(TS))
    if "quantisation" in names:
        y = np.round(y / 1e-4) * 1e-4
    if "saturation" in names:
        y = np.clip(y, -100.0, 100.0)
    return y


EFFECTS = [
    "white_noise", "gauss_markov", "random_walk", "bias_instability",
    "constant_bias", "turn_on_bias", "scale_misalignment", "turn_on_scale",
    "temperature", "g_sensitivity", "quantisation", "saturation",
]


def run(name, n, seed=1):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * TS
    temp = np.full(n, 25.0)
    f = np.broadcast_to(np.array([0.0, 0.0, G]), (n, 3)).copy()
    w = np.zeros((n, 3))
    a = triad(rng, name, f, f, temp, False)
    g = triad(rng, name, w, f, temp, True)
    return t, a, g


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--samples", type=int, default=2_000_000)
    args = p.parse_args()
    n = args.samples
    for name in EFFECTS + ["all"]:
        best = math.inf
        for _ in range(3):
            start = time.perf_counter()
            run(name, n)
            best = min(best, time.perf_counter() - start)
        print(f"{name} {n / best:.0f}", flush=True)


if __name__ == "__main__":
    main()
