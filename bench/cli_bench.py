#!/usr/bin/python3
"""`spar plan` end to end: the wall clock of the whole process on the seed's four experiments.

Issue 24's target: `spar plan EXAMPLE --json` of each seed experiment within 100 ms, process start
to exit (loading the scenario, both phases, the extras, the report). Measured here in one run,
side by side with two floors no plan can go below, and optionally with another spar binary:
  /bin/true         starting any process on this machine;
  spar --version    starting spar: the dynamic loader (Debian's libfcl alone is ~29 000
                    relocations, resolved at load) and static initialisers, no planning;
  --base BIN        another build of spar (e.g. the previous commit's), the same commands.
Each command's CPU time (user + system, all its threads: getrusage of the waited-for child) is
reported beside its wall clock: a plan's CPU divided by the machine's cores is a third floor, what
a perfect split of its work over the cores would take (ratio cpu_per_core: wall / that floor).
Each round runs every command once, in an order that alternates between rounds so that a slow
moment of the machine falls on each alike. A plan must exit 0 or 3 and print JSON with a chosen
plan, or the bench stops: a failure is not timed.

Usage: bench/cli_bench.py [--quick] [--spar build/cli/spar] [--base OTHER_SPAR] [--runs N]
"""
import argparse
import json
import os
import pathlib
import resource
import statistics
import subprocess
import sys
import time

SOURCE = pathlib.Path(__file__).resolve().parents[1]
EXAMPLES = ["peg_block_face_down", "peg_block_on_sides", "peg_block_face_up", "peg_block_on_back"]
TARGET_MS = 100.0


def children_cpu_s():
    """CPU seconds (user + system) of every child process this one has waited for."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_ms(command, check_plan):
    """Wall clock and CPU time (all its threads) of `command` in ms; for a plan, checks its exit
    status and JSON first."""
    cpu_before = children_cpu_s()
    start = time.perf_counter()
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    elapsed = 1e3 * (time.perf_counter() - start)
    cpu = 1e3 * (children_cpu_s() - cpu_before)
    if check_plan:
        if done.returncode not in (0, 3):
            sys.exit(f"cli_bench: {' '.join(map(str, command))} exited {done.returncode}: "
                     f"{done.stderr.decode(errors='replace').strip()}")
        if "chosen" not in json.loads(done.stdout):
            sys.exit(f"cli_bench: {' '.join(map(str, command))}: no chosen plan in the JSON")
    elif done.returncode != 0:
        sys.exit(f"cli_bench: {' '.join(map(str, command))} exited {done.returncode}")
    return elapsed, cpu


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="5 rounds instead of 21")
    parser.add_argument("--spar", default=str(SOURCE / "build/cli/spar"))
    parser.add_argument("--base", help="another spar binary, timed alternately with --spar")
    parser.add_argument("--runs", type=int, help="rounds (default 21, --quick 5)")
    args = parser.parse_args()
    if args.runs is not None and args.runs < 1:
        parser.error(f"--runs must be at least 1, got {args.runs}")
    runs = args.runs or (5 if args.quick else 21)
    binaries = {"spar": args.spar}
    if args.base:
        binaries["base"] = args.base
    for name, path in binaries.items():
        if not pathlib.Path(path).is_file():
            sys.exit(f"cli_bench: {name} binary {path} not found (build first)")

    # (row label, binary name or None, command, is a plan)
    commands = [("process floor: /bin/true", None, ["/bin/true"], False)]
    for name, path in binaries.items():
        commands.append((f"{name}: --version (start-up floor)", name, [path, "--version"], False))
        for example in EXAMPLES:
            commands.append((f"{name}: plan {example}", name,
                             [path, "plan", str(SOURCE / "examples" / f"{example}.yaml"),
                              "--json"], True))
    times = {label: [] for label, _, _, _ in commands}
    cpu = {label: [] for label, _, _, _ in commands}
    for command in commands:  # a warm-up round: files in the page cache, not timed
        run_ms(command[2], command[3])
    for round_index in range(runs):
        order = commands if round_index % 2 == 0 else list(reversed(commands))
        for label, _, command, is_plan in order:
            wall, used = run_ms(command, is_plan)
            times[label].append(wall)
            cpu[label].append(used)

    rounds = f"{runs} round" + ("s" if runs != 1 else "")
    print(f"spar plan end to end: wall clock of the process, {rounds} alternated "
          f"(ms: min / median / max), and the median CPU time of all its threads\n")
    print(f"{'command':<44} {'min':>8} {'median':>8} {'max':>8} {'CPU':>8}  "
          f"target <= {TARGET_MS:.0f} ms")
    for label, name, _, is_plan in commands:
        values = times[label]
        verdict = ""
        if is_plan:
            verdict = "met" if statistics.median(values) <= TARGET_MS else "missed"
        print(f"{label:<44} {min(values):8.1f} {statistics.median(values):8.1f} "
              f"{max(values):8.1f} {statistics.median(cpu[label]):8.1f}  {verdict}")
    print()
    cores = os.cpu_count() or 1
    floor = statistics.median(times["spar: --version (start-up floor)"])
    for example in EXAMPLES:
        plan = statistics.median(times[f"spar: plan {example}"])
        print(f"ratio plan_{example} startup_floor {plan / floor:.2f}  "
              f"(planning and reporting after start-up: {plan - floor:.1f} ms)")
        used = statistics.median(cpu[f"spar: plan {example}"])
        print(f"ratio plan_{example} cpu_per_core {plan / (used / cores):.2f}  (CPU {used:.1f} ms "
              f"on {cores} cores: no schedule finishes before {used / cores:.1f} ms)")
        if args.base:
            base = statistics.median(times[f"base: plan {example}"])
            print(f"ratio plan_{example} base {base / plan:.3f}  (base / spar, medians)")


if __name__ == "__main__":
    main()
