#!/usr/bin/env python3
"""Peer for host/examples/bench_allan.rs: allantools' overlapping Allan
deviation at octave tau on the same samples (raw little-endian f64 rate
data). A peer for comparison only, never a dependency of the Rust code.

    python3 bench/allan_peer.py FILE.f64                 # one column, tau0 = 1 s
    python3 bench/allan_peer.py FILE.f64 COLUMNS RATE    # COLUMNS columns one after
                                                         # the other, RATE Hz

Prints one JSON object: seconds and cpu_seconds (the oadev calls only,
every column: the samples are already in memory), load_seconds, peak_rss_mb (the process's
high-water mark), m and oadev (the first column) and, with COLUMNS,
columns: one oadev list per column.
"""
import json
import resource
import sys
import time

import numpy as np
import allantools


def main():
    path = sys.argv[1]
    columns = int(sys.argv[2]) if len(sys.argv) > 2 else 1
    rate = float(sys.argv[3]) if len(sys.argv) > 3 else 1.0
    t0 = time.perf_counter()
    y = np.fromfile(path, dtype="<f8").reshape(columns, -1)
    load = time.perf_counter() - t0
    t0 = time.perf_counter()
    c0 = time.process_time()
    results = [
        allantools.oadev(y[c], rate=rate, data_type="freq", taus="octave")
        for c in range(columns)
    ]
    seconds = time.perf_counter() - t0
    cpu_seconds = time.process_time() - c0
    peak_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    taus = results[0][0]
    print(json.dumps({
        "tool": "allantools " + allantools.__version__ + ", numpy " + np.__version__,
        "samples": int(y.shape[1]),
        "seconds": seconds,
        "cpu_seconds": cpu_seconds,
        "load_seconds": load,
        "peak_rss_mb": peak_kb / 1024.0,
        "m": [int(round(t * rate)) for t in taus],
        "oadev": [float(d) for d in results[0][1]],
        "columns": [[float(d) for d in r[1]] for r in results],
    }))


if __name__ == "__main__":
    main()
