#!/usr/bin/env python3
"""Pin, parameter and function names of our components against LinuxCNC's.

Loads every component we ship (one instance, default arguments) in our halrun and in
LinuxCNC's halrun, reads `show pin`, `show param` and `show funct` from both and prints what
differs: names only one side has, and type, direction or floating-point flag differences.
A shipped HAL file can only load unchanged when these agree. Run through pins_diff.sh.
"""

import argparse
import os
import re
import subprocess
import sys
import tempfile

# Arguments without which a component does not load on one side or the other.
LOAD_ARGS = {
    "weighted_sum": "wsum_sizes=2",
    "bitslice": "personality=8",
    "debounce": "cfg=2",
    "sampler": "cfg=fb depth=16",
    "streamer": "cfg=fb depth=16",
}
THREADS_LINE = "loadrt threads name1=servo-thread period1=1000000"
NOISE = ("Running with fallback_uid", "Note: Using POSIX", "To run under a debugger", "sudo env RTAPI")


def hal_text(components):
    lines = [THREADS_LINE]
    lines += [f"loadrt {c} {LOAD_ARGS.get(c, '')}".rstrip() for c in components]
    lines += ["show pin", "show param", "show funct"]
    return "\n".join(lines) + "\n"


def parse_show(text):
    """{(kind, name): attributes} from the three show tables of either halrun."""
    items, kind = {}, None
    for line in text.splitlines():
        if any(n in line for n in NOISE):
            continue
        head = line.strip()
        if head.startswith("Component Pins"):
            kind = "pin"
            continue
        if head.startswith("Parameters"):
            kind = "param"
            continue
        if head.startswith("Exported Functions"):
            kind = "funct"
            continue
        f = head.split()
        if not kind or len(f) < 3 or f[0] == "Owner" or not re.match(r"^\d+$", f[0]):
            continue
        f = [w for w in f if w not in ("==>", "<==", "<=>")]
        if kind == "funct":
            fp = "YES" if "YES" in f else "NO"
            name = f[-1]
            if name.startswith("servo-thread"):
                continue
            items[(kind, name)] = fp
        else:
            typ, direction, name = f[1], f[2], f[4] if len(f) > 4 else f[-1]
            if name.startswith("servo-thread"):
                continue
            items[(kind, name)] = f"{typ} {direction} = {normal_value(f[3])}"
    return items


def normal_value(text):
    """A shown value in one spelling for both runtimes: TRUE/FALSE, integers, %g floats."""
    if text in ("TRUE", "FALSE"):
        return text
    try:
        return str(int(text, 16) if text.lower().startswith("0x") else int(text))
    except ValueError:
        pass
    try:
        return f"{float(text):.6g}"
    except ValueError:
        return text


def run(cmd, cwd):
    p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL)
    return p.returncode, p.stdout + p.stderr


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--components", required=True)
    ap.add_argument("--halrun", required=True, help="our halrun")
    ap.add_argument("--linuxcnc-halrun", required=True)
    ap.add_argument("--linuxcnc-modules", default="/usr/lib/linuxcnc/modules")
    a = ap.parse_args()

    ours = sorted(f[:-3] for f in os.listdir(a.components) if f.endswith(".so"))
    theirs = {f[:-3] for f in os.listdir(a.linuxcnc_modules) if f.endswith(".so")}
    common = [c for c in ours if c in theirs]
    only_ours = [c for c in ours if c not in theirs]
    with tempfile.TemporaryDirectory() as tmp:
        results = {}
        for comp in common:
            path = os.path.join(tmp, f"{comp}.hal")
            with open(path, "w") as f:
                f.write(hal_text([comp]))
            rc1, out1 = run([a.halrun, "--sim-clock", "--instance", f"pinsdiff-{os.getpid()}", "-f", path], tmp)
            rc2, out2 = run([a.linuxcnc_halrun, "-f", path], tmp)
            if rc2 != 0:
                run([a.linuxcnc_halrun, "-U"], tmp)
            results[comp] = (rc1, out1, rc2, out2)
            print(f"[{comp}] ours rc={rc1}, LinuxCNC rc={rc2}", file=sys.stderr)

    total_diff = 0
    print("# Pins, params and functions: ours against LinuxCNC 2.9\n")
    if only_ours:
        print(f"Not in LinuxCNC (not compared): {', '.join(only_ours)}\n")
    print("Compared: name, type, direction and the value right after loadrt (the default),\n"
          "per-function timing objects (`<funct>.time`, `.tmax`, `.tmax-increased`) included.\n")
    for comp in common:
        rc1, out1, rc2, out2 = results[comp]
        a_items = parse_show(out1)
        b_items = parse_show(out2)
        lines = []
        # halcompile names instances after the component with '_' turned into '-'.
        dashed = comp.replace("_", "-")
        if dashed != comp and any(n.startswith(dashed + ".") for _, n in b_items) \
                and any(n.startswith(comp + ".") for _, n in a_items):
            lines.append(f"  prefix: ours '{comp}.N', LinuxCNC '{dashed}.N' (compared below after renaming)")
            a_items = {(k, dashed + n[len(comp):] if n.startswith(comp + ".") else n): v
                       for (k, n), v in a_items.items()}
        if rc1 != 0:
            lines.append(f"  ours failed to load: {out1.strip().splitlines()[-1] if out1.strip() else rc1}")
        if rc2 != 0:
            lines.append(f"  LinuxCNC failed to load: {out2.strip().splitlines()[-1] if out2.strip() else rc2}")
        for key in sorted(set(a_items) | set(b_items)):
            kind, name = key
            if key not in b_items:
                lines.append(f"  only ours     {kind:<5} {name} ({a_items[key]})")
            elif key not in a_items:
                lines.append(f"  only LinuxCNC {kind:<5} {name} ({b_items[key]})")
            elif a_items[key] != b_items[key]:
                lines.append(f"  differs       {kind:<5} {name}: ours {a_items[key]}, LinuxCNC {b_items[key]}")
        status = "same" if not lines else f"{len(lines)} differences"
        if len(lines) == 1 and lines[0].startswith("  prefix:"):
            status = "same apart from the instance prefix"
        print(f"- {comp}: {status}")
        for line in lines:
            print(line)
        total_diff += len(lines)
    print(f"\ncomponents compared: {len(common)}; differences: {total_diff}")


if __name__ == "__main__":
    main()
