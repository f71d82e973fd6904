#!/usr/bin/python3
"""Tolerance study through the Python API: serial vs threads vs a Dask LocalCluster.

The study: variants of the seed's peg-and-block task (examples/peg_block_face_down.yaml) whose
object uncertainty (both objects: dx = dy = dz, and dtheta) is swept over a grid; each variant is
planned, and the study reports which uncertainty the plan survives without errors (how many
sensing steps phase 2 inserts, how many errors remain). The same variants are planned three ways
in one run:
  serial    spar.plan in a loop;
  threads   concurrent.futures.ThreadPoolExecutor (spar.plan releases the GIL);
  dask      spar.dask.plan_many on a LocalCluster of worker processes (scenarios travel as text);
and the results must be equal. Reported: wall time, throughput, speed-up over serial and the
overhead per task (extra core-seconds per plan: workers x wall - serial, over the plans).

Usage: PYTHONPATH=build/python bench/python_bench.py [--quick] [--variants N] [--workers N]
"""
import argparse
import concurrent.futures
import json
import math
import os
import pathlib
import time

import spar
import spar.dask

SOURCE = pathlib.Path(__file__).resolve().parents[1]
SCENARIO = SOURCE / "examples/peg_block_face_down.yaml"
NOMINAL = "uncertainty: {dx: 0.11, dy: 0.11, dz: 0.11, dtheta: 5.5}"


def variants(count):
    """`count` scenario texts: a sqrt(count) x sqrt(count) grid of (length, angle) uncertainty."""
    text = SCENARIO.read_text()
    assert text.count(NOMINAL) == 2, "the example's object uncertainty changed"
    side = math.ceil(count ** 0.5)
    rows = math.ceil(count / side)
    out = []
    for i in range(count):
        length = 0.01 + 0.29 * (i // side) / max(1, rows - 1)  # inches
        angle = 0.5 + 9.5 * (i % side) / max(1, side - 1)      # degrees
        swept = f"uncertainty: {{dx: {length:.4f}, dy: {length:.4f}, dz: {length:.4f}, " \
                f"dtheta: {angle:.3f}}}"
        out.append((length, angle, text.replace(NOMINAL, swept)))
    return out


def comparable(report):
    report = json.loads(json.dumps(report))
    report["family"]["search"].pop("seconds", None)
    return report


def _echo(chunk, options):
    return [len(text) for text in chunk]


def timed(function):
    start = time.perf_counter()
    result = function()
    return time.perf_counter() - start, result


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="40 variants (CI smoke run)")
    parser.add_argument("--variants", type=int, default=1000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--chunk-size", type=int, default=8)
    args = parser.parse_args()
    count = 40 if args.quick else args.variants
    load_before = os.getloadavg()

    # What one plan costs with and without the chosen instance's extras.
    nominal = SCENARIO.read_text()
    full, _ = timed(lambda: spar.plan(nominal))
    fast_options = {"probability": False, "chosen_extras": False}
    fast, _ = timed(lambda: spar.plan(nominal, **fast_options))
    no_probability, _ = timed(lambda: spar.plan(nominal, probability=False))
    print(f"one plan of the example: {full:.3f} s with every extra, {no_probability:.3f} s "
          f"without probability/tolerances, {fast:.3f} s without any chosen-instance extra")

    study = variants(count)
    texts = [text for _, _, text in study]

    serial_time, serial = timed(lambda: [spar.plan(t, **fast_options) for t in texts])

    def threads():
        with concurrent.futures.ThreadPoolExecutor(args.workers) as pool:
            return list(pool.map(lambda t: spar.plan(t, **fast_options), texts))

    thread_time, threaded = timed(threads)

    import distributed
    start_time, cluster = timed(lambda: distributed.LocalCluster(
        n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=None,
        silence_logs=40))
    with distributed.Client(cluster) as client:
        client.run(lambda: __import__("spar"))  # import on the workers before timing
        dask_time, distributed_results = timed(lambda: spar.dask.plan_many(
            client, texts, chunk_size=args.chunk_size, **fast_options))
        # Dask's own cost: the same chunks of scenario text out and a result back, no planning.
        echo_time, _ = timed(lambda: spar.dask.map_chunks(
            client, _echo, texts, chunk_size=args.chunk_size))
    cluster.close()

    expected = [comparable(r) for r in serial]
    assert [comparable(r) for r in threaded] == expected, "threads differ from serial"
    assert [comparable(r) for r in distributed_results] == expected, "dask differs from serial"

    load_after = os.getloadavg()
    print(f"\n{count} variants, {args.workers} workers, chunk size {args.chunk_size}; load "
          f"average {load_before[0]:.1f} before, {load_after[0]:.1f} after; "
          f"{os.cpu_count()} cores")
    print("| mode | wall s | plans/s | speed-up | overhead per task (core-ms) |")
    print("|---|---|---|---|---|")
    for mode, wall, workers in [("serial", serial_time, 1), ("threads", thread_time, args.workers),
                                ("dask LocalCluster", dask_time, args.workers)]:
        overhead = (workers * wall - serial_time) / count * 1e3
        print(f"| {mode} | {wall:.2f} | {count / wall:.2f} | {serial_time / wall:.2f}x | "
              f"{overhead:+.1f} |")
    print(f"(LocalCluster start-up: {start_time:.2f} s, not included; the same chunks sent "
          f"and answered without planning: {echo_time:.2f} s, {echo_time / count * 1e3:.2f} ms "
          "per task)")

    print("\ntolerance study: outcome (errors left, range-scans inserted) by object uncertainty")
    outcomes = {}  # outcome -> [(length, angle)]
    for (length, angle, _), report in zip(study, serial):
        chosen = report.get("chosen") or {}
        scans = sum(1 for step in chosen.get("steps", []) if step["action"] == "range-scan")
        outcomes.setdefault((report["status"], chosen.get("errors"), scans), []).append(
            (length, angle))
    for (status, errors, scans), points in sorted(outcomes.items(), key=lambda o: o[1][0]):
        lengths = [p[0] for p in points]
        angles = [p[1] for p in points]
        print(f"  {status}, {errors} errors, {scans} range-scans: {len(points)} variants, "
              f"+-{min(lengths):.3f}..{max(lengths):.3f} in, {min(angles):.1f}..{max(angles):.1f} "
              "deg")


if __name__ == "__main__":
    main()
