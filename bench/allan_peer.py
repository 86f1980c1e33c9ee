#!/usr/bin/env python3
"""Peer for host/examples/bench_allan.rs: allantools' overlapping Allan
deviation at octave tau on the same samples (raw little-endian f64 rate data,
tau0 = 1 s). A peer for comparison only, never a dependency of the Rust code.

    python3 bench/allan_peer.py FILE.f64

Prints one JSON object: seconds (oadev call only, not the file read),
load_seconds, peak_rss_mb (the process's high-water mark), m, oadev.
"""
import json
import resource
import sys
import time

import numpy as np
import allantools


def main():
    path = sys.argv[1]
    t0 = time.perf_counter()
    y = np.fromfile(path, dtype="<f8")
    load = time.perf_counter() - t0
    t0 = time.perf_counter()
    taus, devs, _errs, _ns = allantools.oadev(y, rate=1.0, data_type="freq", taus="octave")
    seconds = time.perf_counter() - t0
    peak_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    print(json.dumps({
        "tool": "allantools " + allantools.__version__ + ", numpy " + np.__version__,
        "samples": int(y.size),
        "seconds": seconds,
        "load_seconds": load,
        "peak_rss_mb": peak_kb / 1024.0,
        "m": [int(round(t)) for t in taus],
        "oadev": [float(d) for d in devs],
    }))


if __name__ == "__main__":
    main()
