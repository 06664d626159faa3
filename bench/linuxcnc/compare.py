#!/usr/bin/env python3
"""Section-by-section comparison of two motion traces of one program (ours against LinuxCNC's).

    bench/linuxcnc/compare.py PROGRAM OURS_TRACE LINUXCNC_TRACE [--lines N,M,...] [--min-gain MS]

A trace is one "X Y Z" line per servo period while the machine moves (`bench_motion
--trace-out`, `bench/linuxcnc/run.sh --trace`), 1 ms apart. Each sample is placed on the
programmed path: the nearest point of the moves around the one it was last placed on (the
current move or, once at its end or nearer to them, one of the four after it, so a corner cut
short or a chain of short moves is followed), its distance along the path never going back. A programmed end point counts as
passed at the first sample placed at or past it, so a corner that is cut is passed where the
trace crosses from one move onto the next. For each program line the table gives the time at
which each trace passes its end point, the difference (positive: LinuxCNC is ahead), how much
of that difference arose in the section that ends there, and each trace's largest distance
from the path in that section (the nearest of the moves considered; compare with G64 P).

Only the programs the bench's tp_default is made of are understood: G0 G1 G2 G3 in the XY
plane (G17), absolute (G90), millimetres, words X Y Z I J F and the modal codes G17 G21 G90
G64 M2 M30; anything else is refused with the line that has it.
"""
import argparse
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # bench/ngc_words.py
from ngc_words import words_of  # noqa: E402

IGNORED_G = {17, 21, 90, 64, 40, 49, 80, 94}
# A sample this close to a move's end (along it) may be placed on the moves after it: a
# reversal (G0 Z1, G1 Z0) may turn up to P short of its end, and both traces do.
END_MM = 0.02


class Move:
    def __init__(self, line, kind, start, end, centre=None, clockwise=False):
        self.line, self.kind, self.start, self.end = line, kind, start, end
        self.centre, self.clockwise = centre, clockwise
        if kind == "arc":
            cx, cy = centre
            self.r = math.hypot(start[0] - cx, start[1] - cy)
            a0 = math.atan2(start[1] - cy, start[0] - cx)
            a1 = math.atan2(end[1] - cy, end[0] - cx)
            sweep = a1 - a0
            if clockwise and sweep >= 0:
                sweep -= 2 * math.pi
            if not clockwise and sweep <= 0:
                sweep += 2 * math.pi
            self.a0, self.sweep = a0, sweep
            self.length = math.hypot(self.r * sweep, end[2] - start[2])
        else:
            self.length = math.dist(start, end)

    def nearest(self, p):
        """(distance from p, distance along the move of the nearest point)."""
        if self.kind == "arc":
            cx, cy = self.centre
            ang = math.atan2(p[1] - cy, p[0] - cx)
            # Angle along the sweep's direction, clamped to the sweep.
            rel = (ang - self.a0) * (1 if self.sweep > 0 else -1) % (2 * math.pi)
            span = abs(self.sweep)
            if rel > span:
                rel = span if rel - span < 2 * math.pi - rel else 0.0
            u = rel / span
            th = self.a0 + self.sweep * u
            q = (cx + self.r * math.cos(th), cy + self.r * math.sin(th),
                 self.start[2] + (self.end[2] - self.start[2]) * u)
            return math.dist(p, q), u * self.length
        d = [self.end[k] - self.start[k] for k in range(3)]
        if self.length == 0:
            return math.dist(p, self.start), 0.0
        u = sum((p[k] - self.start[k]) * d[k] for k in range(3)) / self.length**2
        u = min(1.0, max(0.0, u))
        q = [self.start[k] + u * d[k] for k in range(3)]
        return math.dist(p, q), u * self.length


def parse_program(path):
    moves, pos, mode = [], [0.0, 0.0, 0.0], None
    with open(path) as f:
        for number, text in enumerate(f, 1):
            try:
                words = words_of(text)
            except ValueError as e:
                sys.exit(f"{path}:{number}: {e}")
            if not words:
                continue
            target, ij, new_mode = list(pos), [0.0, 0.0], None
            axes = False
            for letter, v, value in words:
                if letter == "G":
                    if v in (0, 1, 2, 3):
                        new_mode = int(v)
                    elif v not in IGNORED_G:
                        sys.exit(f"{path}:{number}: G{value} is not understood here")
                elif letter in "XYZ":
                    target["XYZ".index(letter)] = v
                    axes = True
                elif letter in "IJ":
                    ij["IJ".index(letter)] = v
                elif letter == "M" and v in (2, 30):
                    return moves
                elif letter not in "FP":
                    sys.exit(f"{path}:{number}: word {letter}{value} is not understood here")
            mode = new_mode if new_mode is not None else mode
            if not axes:
                continue
            if mode in (2, 3):
                centre = (pos[0] + ij[0], pos[1] + ij[1])
                moves.append(Move(number, "arc", tuple(pos), tuple(target), centre, mode == 2))
            elif mode in (0, 1):
                moves.append(Move(number, "rapid" if mode == 0 else "line", tuple(pos),
                                  tuple(target)))
            else:
                sys.exit(f"{path}:{number}: axis words before any motion mode")
            pos = target
    return moves


def read_trace(path):
    with open(path) as f:
        return [tuple(float(x) for x in line.split()[:3]) for line in f if line.strip()]


def place(moves, trace):
    """For each move, the first sample index at or past its end, and each sample's distance."""
    cum = [0.0]
    for m in moves:
        cum.append(cum[-1] + m.length)
    passed = [None] * len(moves)
    dist = []
    cur, along, nxt = 0, 0.0, 0  # nxt: the first move whose end is not yet passed
    for i, p in enumerate(trace):
        # The current move, and a later one (of the next four) once the sample is at the
        # current one's end (its nearest point there is within END_MM of the end) or strictly
        # nearer to that later move: a move that retraces the one before (G0 Z1, G1 Z0) is not
        # taken for it, and a corner cut short is crossed where the trace passes the normal
        # through the corner (or, past 90 degrees, the bisector).
        d_cur, s_cur = moves[cur].nearest(p)
        best = (d_cur, cur, s_cur)
        at_end = s_cur >= moves[cur].length - END_MM
        for j in range(cur + 1, min(len(moves), cur + 5)):
            d, s = moves[j].nearest(p)
            if (at_end and d <= best[0] + 1e-12) or d < best[0] - 1e-9:
                best = (d, j, s)
        d, j, s = best
        # The distance from the path: the nearest of the moves around, before ones included.
        dist.append(min([d] + [moves[k].nearest(p)[0] for k in range(max(0, cur - 2), cur)]))
        if cum[j] + s >= along:
            along, cur = cum[j] + s, j
        while nxt < len(moves) and along >= cum[nxt + 1] - 1e-9:
            passed[nxt] = i
            nxt += 1
    last = len(trace) - 1
    return [last if x is None else x for x in passed], dist


def print_sections(spec, moves, po, do, pl, dl, period):
    ms = period * 1e3
    print(f"{'lines':>9} {'ours s':>8} {'LCNC s':>8} {'LCNC gains ms':>13} {'ours max mm':>11} "
          f"{'LCNC max mm':>11}")
    index = {m.line: k for k, m in enumerate(moves)}
    for part in spec.split(","):
        first, last = (int(x) for x in part.split("-"))
        if first not in index or last not in index:
            sys.exit(f"--sections: no move on line {first if first not in index else last}")
        k0, k1 = index[first], index[last]
        o0, l0 = (po[k0 - 1], pl[k0 - 1]) if k0 > 0 else (-1, -1)
        to, tl = (po[k1] - o0) * period, (pl[k1] - l0) * period
        mo = max(do[o0 + 1:po[k1] + 1], default=0.0)
        ml = max(dl[l0 + 1:pl[k1] + 1], default=0.0)
        print(f"{part:>9} {to:8.3f} {tl:8.3f} {(to - tl) * 1e3:13.0f} {mo:11.4f} {ml:11.4f}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("program")
    ap.add_argument("ours")
    ap.add_argument("linuxcnc")
    ap.add_argument("--lines", help="print only these program lines (comma separated)")
    ap.add_argument("--min-gain", type=float, default=None,
                    help="print only sections where the difference changes by at least this, ms")
    ap.add_argument("--sections", help="instead, one row per section of program lines: "
                    "FIRST-LAST,... (the time each trace spends from the end of the line before "
                    "FIRST to the end of LAST, and the largest distances from the path there)")
    ap.add_argument("--period", type=float, default=1e-3, help="servo period, s")
    args = ap.parse_args()
    moves = parse_program(args.program)
    ours, lcnc = read_trace(args.ours), read_trace(args.linuxcnc)
    po, do = place(moves, ours)
    pl, dl = place(moves, lcnc)
    want = set(int(x) for x in args.lines.split(",")) if args.lines else None
    ms = args.period * 1e3
    if args.sections:
        print_sections(args.sections, moves, po, do, pl, dl, args.period)
        return
    print(f"{'line':>5} {'kind':5} {'ours s':>8} {'LCNC s':>8} {'LCNC ahead ms':>13} "
          f"{'section ms':>10} {'ours max mm':>11} {'LCNC max mm':>11}")
    prev_diff, prev_o, prev_l = 0.0, 0, 0
    for k, m in enumerate(moves):
        to, tl = (po[k] + 1) * args.period, (pl[k] + 1) * args.period
        diff = (po[k] - pl[k]) * ms
        mo = max(do[prev_o:po[k] + 1], default=0.0)
        ml = max(dl[prev_l:pl[k] + 1], default=0.0)
        section = diff - prev_diff
        show = (want is None or m.line in want) and (
            args.min_gain is None or abs(section) >= args.min_gain)
        if show:
            print(f"{m.line:5d} {m.kind:5} {to:8.3f} {tl:8.3f} {diff:13.0f} {section:10.0f} "
                  f"{mo:11.4f} {ml:11.4f}")
        prev_diff, prev_o, prev_l = diff, po[k], pl[k]
    print(f"end: ours {len(ours) * args.period:.3f} s, LinuxCNC {len(lcnc) * args.period:.3f} s "
          f"(samples)")


if __name__ == "__main__":
    main()
