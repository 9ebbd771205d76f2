"""Shared helpers of the peer benchmark scripts: timing and the result table."""

import statistics
import time


def best_time(fn, repeat=5, warmup=1):
    """Median wall-clock seconds of ``fn()`` over ``repeat`` runs after ``warmup`` runs."""
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def print_table(title, rows):
    """Prints rows of (workload, ours_s, peer_name, peer_s) with the ratio peer/ours."""
    print(f"{title}")
    print(f"{'workload':<36} {'ours (s)':>10} {'peer':<28} {'peer (s)':>10} {'ratio':>7}")
    for workload, ours, peer_name, peer in rows:
        print(f"{workload:<36} {ours:>10.4f} {peer_name:<28} {peer:>10.4f} {peer / ours:>7.2f}")
