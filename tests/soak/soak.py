#!/usr/bin/env python3
"""End-to-end soak of `cnc run` on the sim configs with seeded random programs (docs/soak.md).

    tests/soak/soak.py --seeds 1-200 --configs all
    tests/soak/soak.py --seeds 17 --configs corexy --keep     # one case, its files kept

Each (config, seed) writes a program (program.py), runs `cnc run INI PROG --sim-clock --trace
T.csv --settings-dir TMP`, and checks the run, its summary and its trace (check.py). A failure
keeps the program, trace and output in OUT/CONFIG-sSEED/, prints one line naming the check and
the program line, and (unless --no-shrink) writes the smallest program found that still fails
the same check as shrunk.ngc."""

import argparse
import concurrent.futures
import os
import shutil
import subprocess
import sys
import tempfile
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from check import TRT_EXCESS, Failure, check_run  # noqa: E402
from machine import read_machine  # noqa: E402
from program import ProgramError, generate, model_of  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
CONFIGS = ("mill", "mill-servo", "gantry", "corexy", "5axis-trt")


def parse_seeds(text):
    seeds = []
    for part in text.split(","):
        if "-" in part:
            a, b = part.split("-")
            seeds.extend(range(int(a), int(b) + 1))
        else:
            seeds.append(int(part))
    return seeds


def run_program(cnc, machine, lines, workdir, timeout_s):
    """Runs the program in workdir; returns (failure or None, model)."""
    prog = os.path.join(workdir, "prog.ngc")
    with open(prog, "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    model = model_of(lines, machine)
    trace = os.path.join(workdir, "trace.csv")
    settings = os.path.join(workdir, "settings")
    shutil.rmtree(settings, ignore_errors=True)
    os.makedirs(settings)
    # All offsets 0 whatever the config's own folder holds (a *.var left there by a run without
    # --settings-dir): the model assumes program = machine coordinates.
    open(os.path.join(settings, machine.parameter_file), "w").close()
    cmd = [cnc, "run", machine.ini_path, prog, "--sim-clock", "--trace", trace, "--settings-dir", settings,
           "--timeout", "600"]
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout_s)
    except subprocess.TimeoutExpired:
        return Failure("timeout", f"cnc run took more than {timeout_s} s of wall time"), model
    with open(os.path.join(workdir, "stdout.txt"), "w") as f:
        f.write(p.stdout)
    with open(os.path.join(workdir, "stderr.txt"), "w") as f:
        f.write(p.stderr)
    try:
        return check_run(p.returncode, p.stdout, p.stderr, trace, model, machine), model
    except (ValueError, OSError) as e:
        return Failure("trace", str(e)), model


def shrink(cnc, machine, lines, failure, workdir, timeout_s, budget_s):
    """Drops lines (largest chunks first) while the program still fails the same check; lines
    the model refuses once others are gone (an arc whose start moved) are skipped."""
    deadline = time.monotonic() + budget_s
    best = list(lines)
    chunk = max(1, len(best) // 4)
    while chunk >= 1 and time.monotonic() < deadline:
        i = 1  # keep the first line (modes and feed)
        changed = False
        while i < len(best) - 1 and time.monotonic() < deadline:
            cand = best[:i] + best[i + chunk:]
            if cand[-1] not in ("M30", "M2"):
                i += 1
                continue
            try:
                model_of(cand, machine)
            except ProgramError:
                i += chunk
                continue
            f, _ = run_program(cnc, machine, cand, workdir, timeout_s)
            if f and f.check == failure.check:
                best, changed = cand, True
            else:
                i += chunk
        if not changed:
            chunk //= 2
    return best


def excess_reported(workdir):
    """Whether motion reported joint acceleration excesses (tolerated on 5axis-trt)."""
    try:
        with open(os.path.join(workdir, "stderr.txt"), encoding="utf-8") as f:
            return any(TRT_EXCESS.match(line) for line in f)
    except OSError:
        return False


def soak_one(args, config, seed):
    machine = read_machine(os.path.join(ROOT, "configs", "sim", config + ".ini"))
    lines = generate(machine, seed, args.steps, args.arc_end_off)
    work = tempfile.mkdtemp(prefix=f"soak-{config}-{seed}-")
    try:
        t0 = time.monotonic()
        failure, model = run_program(args.cnc, machine, lines, work, args.run_timeout)
        elapsed = time.monotonic() - t0
        noted = excess_reported(work)
        if failure is None and not args.keep:
            return config, seed, None, elapsed, noted
        out = os.path.join(args.out, f"{config}-s{seed}")
        shutil.rmtree(out, ignore_errors=True)
        os.makedirs(out)
        for name in ("prog.ngc", "trace.csv", "stdout.txt", "stderr.txt"):
            if os.path.exists(os.path.join(work, name)):
                shutil.copy(os.path.join(work, name), out)
        if failure is None:
            return config, seed, None, elapsed, noted
        prog = os.path.join(out, "prog.ngc")
        text = f"{failure.check}: {failure.where(prog)}: {failure.detail}"
        if not args.no_shrink:
            small = shrink(args.cnc, machine, lines, failure, work, args.run_timeout, args.shrink_s)
            with open(os.path.join(out, "shrunk.ngc"), "w") as f:
                f.write("\n".join(small) + "\n")
            f2, _ = run_program(args.cnc, machine, small, work, args.run_timeout)
            if f2:
                text += f"\n    shrunk to {len(small)} lines: {f2.check}: " \
                        f"{f2.where(os.path.join(out, 'shrunk.ngc'))}: {f2.detail}"
        with open(os.path.join(out, "failure.txt"), "w") as f:
            f.write(f"config {config} seed {seed}\n{text}\n")
        return config, seed, text, elapsed, noted
    finally:
        shutil.rmtree(work, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", default="1-20", help="seeds, e.g. 1-200 or 3,7,9-12")
    ap.add_argument("--configs", default="all", help="comma-separated sim configs, or all: " + " ".join(CONFIGS))
    ap.add_argument("--steps", type=int, default=30, help="generator steps per program (each writes 1-25 lines)")
    ap.add_argument("--cnc", default=os.path.join(ROOT, "build", "bin", "cnc"), help="the cnc binary")
    ap.add_argument("--out", default=os.path.join(tempfile.gettempdir(), "soak-out"),
                    help="folder for failures (and --keep); default /tmp/soak-out")
    ap.add_argument("--jobs", type=int, default=1, help="runs at once")
    ap.add_argument("--keep", action="store_true", help="keep every case's files, not only failures")
    ap.add_argument("--no-shrink", action="store_true", help="do not shrink failing programs")
    ap.add_argument("--shrink-s", type=float, default=120, help="wall seconds to spend shrinking one failure")
    ap.add_argument("--run-timeout", type=float, default=300, help="wall seconds one cnc run may take")
    ap.add_argument("--arc-end-off", type=float, default=0.0,
                    help="also write I J arcs whose end is off the circle by up to this many mm, many "
                         "of them nearly full circles (0 = none; docs/soak.md says why it is off)")
    ap.add_argument("--print-program", action="store_true", help="print the programs, run nothing")
    args = ap.parse_args()
    configs = CONFIGS if args.configs == "all" else tuple(args.configs.split(","))
    seeds = parse_seeds(args.seeds)
    if args.print_program:
        for c in configs:
            m = read_machine(os.path.join(ROOT, "configs", "sim", c + ".ini"))
            for s in seeds:
                print(f"; {c} seed {s}\n" + "\n".join(generate(m, s, args.steps, args.arc_end_off)))
        return 0
    if not os.access(args.cnc, os.X_OK):
        print(f"soak: {args.cnc}: not an executable (build the cnc target, or pass --cnc)", file=sys.stderr)
        return 2
    args.out = os.path.abspath(args.out)
    t0 = time.monotonic()
    failures = 0
    noted = []
    jobs = [(c, s) for s in seeds for c in configs]
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        for config, seed, text, elapsed, excess in pool.map(lambda cs: soak_one(args, *cs), jobs):
            if excess:
                noted.append(f"{config}/{seed}")
            if text:
                failures += 1
                print(f"FAIL {config} seed {seed}: {text}", flush=True)
            elif args.jobs == 1 and len(jobs) <= 20:
                print(f"ok   {config} seed {seed} ({elapsed:.2f} s)", flush=True)
    print(f"soak: {len(jobs)} runs ({len(seeds)} seeds x {len(configs)} configs), {failures} failed, "
          f"{time.monotonic() - t0:.0f} s")
    if noted:
        print(f"soak: motion reported joint acceleration excesses (tolerated on 5axis-trt) in "
              f"{len(noted)} runs: {' '.join(noted[:20])}{' ...' if len(noted) > 20 else ''}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
