#!/usr/bin/python3
"""A numerical lower bound (floor) on the time any motion needs for a stretch of a program.

    bench/floor/floor.py PROGRAM --lines A-B [--step-ms 1] [--lead-in 25] [--lead-out 25]
                         [--horizon-ms MS] [--tolerance P] [--vmax 100] [--amax 1000]
                         [--reach-vertices] [--solver highs|cbc]

The floor holds for every motion that keeps the path-distance contract of docs/benchmarks.md
("The contract it assumes"): per-axis |v| <= V and |a| <= A, instants t_0 <= ... <= t_n with
the tool within P_i of move S_i during [t_(i-1), t_i] and, on a feed move, no faster than F_i.
--reach-vertices adds a stricter clause (SectionModel.reach_clauses): during [t_(i-1), t_i]
the tool also gets within P_i of both end points of a line or rapid S_i, along it.
The section A-B runs from t_a (the end of line A-1's move, the vertex c_a) to t_b (the end of
line B's move); the floor bounds t_b - t_a from below.

It is a discrete relaxation solved as a MILP (docs/benchmarks.md, "A numerical floor for
sections", has the argument step by step): the samples q_k = q(t_a + k h) of any such motion
satisfy every constraint of the MILP, so the MILP's optimum (or the solver's proved dual bound
when it stops early) can only be lower than the real section time. The solver is HiGHS through
SciPy, or COIN-OR CBC's cbc binary (--solver cbc) on the MILP written as MPS.

Programs: the subset tp_default is made of: G0 G1 (X Y Z F), G2 G3 in the XY plane (G17; only
as outer hulls, which are weak, see the docs), G64 P, G17 G21 G90, M2/M30. Anything else is
refused with FILE:LINE and the cause.
"""
import argparse
import math
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # bench/ngc_words.py
from ngc_words import words_of  # noqa: E402

try:
    from scipy.optimize import Bounds, LinearConstraint, linprog, milp
    from scipy.sparse import coo_matrix
except ImportError:  # pragma: no cover - the message is the point
    sys.exit("floor.py needs SciPy >= 1.9 (Debian: apt-get install python3-scipy; "
             "scripts/deps.sh installs it). Run it with /usr/bin/python3.")

# The MILP's length unit is the micrometre: the quantities that matter (A h^2 = 1-4 um, P = 10 um)
# are then far above HiGHS's absolute tolerances (1e-7), which in millimetres they were not:
# HiGHS 1.2's presolve declared a real motion infeasible with millimetres.
UNIT_PER_MM = 1000.0
# Every constraint's right-hand side is widened by this much (model units: 1e-6 mm), so that a
# real motion's samples satisfy the discrete constraints with room to spare after rounding of
# the problem data and HiGHS's own tolerances: widening only weakens the floor.
SLACK = 1e-3


class ProgramError(Exception):
    """Bad or unsupported input: the message starts with FILE:LINE."""


@dataclass
class Move:
    """One programmed move, or a rest state before the start / after the end (kind 'rest')."""
    kind: str              # 'line', 'rapid', 'arc', 'rest'
    start: np.ndarray
    end: np.ndarray
    feed_mm_s: float       # Euclidean feed limit; math.inf on rapids, 0 at rest
    tol_mm: float          # P_i (0 at rest)
    line: int = 0          # program line (0 for rest states and moves given directly)
    centre: np.ndarray = None   # arcs: centre (XY plane), clockwise flag
    clockwise: bool = False

    def direction(self):
        d = self.end - self.start
        n = np.linalg.norm(d)
        return d / n if n > 0 else None


# ----------------------------------------------------------------------------------------------
# Reading the program subset

MODAL_OK = {17, 21, 90, 64}


def parse_program(path, default_tol_mm=0.01, start=(0.0, 0.0, 0.0)):
    """The program's moves with P per move (the larger of the G64 P at its two ends)."""
    raw = []  # (line, kind, start, end, feed_mm_s, tol, centre, cw)
    pos = np.array(start, dtype=float)
    mode, feed_mm_s, tol = None, None, default_tol_mm
    with open(path) as f:
        for number, text in enumerate(f, 1):
            where = f"{path}:{number}"
            try:
                words = words_of(text)
            except ValueError as e:
                raise ProgramError(f"{where}: {e}") from None
            if not words:
                continue
            target, ij, new_mode, axes, p_word, ended = pos.copy(), [0.0, 0.0], None, False, None, False
            g64 = False
            for letter, v, value in words:
                if letter == "G":
                    if v in (0, 1, 2, 3):
                        new_mode = int(v)
                    elif v == 64:
                        g64 = True
                    elif v not in MODAL_OK:
                        raise ProgramError(f"{where}: G{value} is not supported by the floor "
                                           "(only G0 G1 G2 G3 G17 G21 G64 G90)")
                elif letter in "XYZ":
                    target["XYZ".index(letter)] = v
                    axes = True
                elif letter in "IJ":
                    ij["IJ".index(letter)] = v
                elif letter == "F":
                    if v <= 0:
                        raise ProgramError(f"{where}: F must be positive")
                    feed_mm_s = v / 60.0
                elif letter == "P":
                    p_word = v
                elif letter == "M" and v in (2, 30):
                    ended = True
                else:
                    raise ProgramError(f"{where}: word {letter}{value} is not supported by the "
                                       "floor")
            if p_word is not None:
                if not g64:
                    raise ProgramError(f"{where}: P without G64")
                if p_word <= 0:
                    raise ProgramError(f"{where}: G64 P must be positive (G61 is not supported)")
                tol = p_word
            elif g64:
                raise ProgramError(f"{where}: G64 without P is not supported")
            mode = new_mode if new_mode is not None else mode
            if axes:
                if mode is None:
                    raise ProgramError(f"{where}: axis words before any motion mode")
                if mode != 0 and feed_mm_s is None:
                    raise ProgramError(f"{where}: feed move without an F word before it")
                if mode in (2, 3):
                    centre = np.array([pos[0] + ij[0], pos[1] + ij[1]])
                    r0 = math.hypot(*(pos[:2] - centre))
                    r1 = math.hypot(*(target[:2] - centre))
                    if r0 <= 0 or abs(r0 - r1) > 1e-3:
                        raise ProgramError(f"{where}: arc radii differ ({r0:.4f}, {r1:.4f})")
                    raw.append((number, "arc", pos.copy(), target.copy(), feed_mm_s, tol,
                                centre, mode == 2))
                else:
                    raw.append((number, "rapid" if mode == 0 else "line", pos.copy(),
                                target.copy(), math.inf if mode == 0 else feed_mm_s, tol,
                                None, False))
                pos = target
            if ended:
                break
    if not raw:
        raise ProgramError(f"{path}: no moves")
    moves = []
    for k, (number, kind, s, e, fd, t, c, cw) in enumerate(raw):
        # P_i: the larger of the tolerances of the corners at both ends.
        t_max = max(r[5] for r in raw[max(0, k - 1):k + 2])
        moves.append(Move(kind, s, e, fd, t_max, number, c, cw))
    return moves


def in_model_units(moves):
    """Copies of moves with lengths in micrometres (feeds in um/s)."""
    k = UNIT_PER_MM
    return [Move(m.kind, m.start * k, m.end * k, m.feed_mm_s * k, m.tol_mm * k, m.line,
                 None if m.centre is None else m.centre * k, m.clockwise) for m in moves]


def make_model(moves, a, b, v_mm_s=100.0, a_mm_s2=1000.0, step_ms=1.0, lead_in=25,
               lead_out=25, horizon_s=None, perp_count=8, group_turn_deg=0.0,
               reach_vertices=False):
    """The section model for programmed moves in mm (vertex a is the end of move a, moves
    numbered from 1), built in model units (micrometres). reach_vertices: the stricter
    contract in which every move reaches both its end points (SectionModel.reach_clauses)."""
    mv = moves_with_rest(in_model_units(moves))
    k = UNIT_PER_MM
    lim = Limits(k * (np.full(3, float(v_mm_s)) if np.isscalar(v_mm_s) else
                      np.asarray(v_mm_s, float)),
                 k * (np.full(3, float(a_mm_s2)) if np.isscalar(a_mm_s2) else
                      np.asarray(a_mm_s2, float)))
    if horizon_s is None:
        horizon_s = default_horizon_s(mv, a, b, lim)
    return SectionModel(mv, a, b, lim, step_ms * 1e-3, lead_in, lead_out, horizon_s,
                        perp_count, group_turn_deg, reach_vertices)


def moves_with_rest(moves):
    """Index 0: at rest at c_0 before the start; n + 1: at rest at c_n after the end."""
    first, last = moves[0].start, moves[-1].end
    return ([Move("rest", first.copy(), first.copy(), 0.0, 0.0)] + list(moves) +
            [Move("rest", last.copy(), last.copy(), 0.0, 0.0)])


def section_vertices(moves, first_line, last_line):
    """(a, b): the section runs from vertex a (end of the move before first_line) to b."""
    index = {m.line: i for i, m in enumerate(moves, 1)}
    for ln in (first_line, last_line):
        if ln not in index:
            raise ProgramError(f"--lines: no move on line {ln}")
    a, b = index[first_line] - 1, index[last_line]
    if b <= a:
        raise ProgramError("--lines: the section must hold at least one move")
    return a, b


# ----------------------------------------------------------------------------------------------
# Outer polyhedra of the tubes {x : dist(x, S_i) <= P_i}

def _unit(v):
    n = np.linalg.norm(v)
    return v / n if n > 1e-12 else None


def _perpendicular_dirs(u, hints, count):
    """count unit directions spread evenly in the plane normal to u, the first one along the
    first hint's part normal to u (so the turning plane of a corner is cut exactly)."""
    e1 = None
    for h in hints:
        if h is not None:
            e1 = _unit(h - np.dot(h, u) * u)
            if e1 is not None:
                break
    if e1 is None:
        trial = np.eye(3)[int(np.argmin(np.abs(u)))]
        e1 = _unit(trial - np.dot(trial, u) * u)
    e2 = np.cross(u, e1)
    return [math.cos(2 * math.pi * j / count) * e1 + math.sin(2 * math.pi * j / count) * e2
            for j in range(count)]


def _arc_support(m, n):
    """max over the arc of n . p (exact: a sinusoid in the angle plus the linear z term)."""
    cx, cy = m.centre
    r = math.hypot(m.start[0] - cx, m.start[1] - cy)
    a0 = math.atan2(m.start[1] - cy, m.start[0] - cx)
    a1 = math.atan2(m.end[1] - cy, m.end[0] - cx)
    sweep = a1 - a0
    if m.clockwise and sweep >= -1e-12:
        sweep -= 2 * math.pi
    if not m.clockwise and sweep <= 1e-12:
        sweep += 2 * math.pi
    dz = m.end[2] - m.start[2]

    def value(s):  # s in [0, 1] along the sweep
        th = a0 + sweep * s
        return (n[0] * (cx + r * math.cos(th)) + n[1] * (cy + r * math.sin(th)) +
                n[2] * (m.start[2] + dz * s))

    best = max(value(0.0), value(1.0))
    # Stationary points of r(n_x cos + n_y sin)(th) + n_z dz s: solve on a fine grid then
    # refine; the grid's maximum plus the curvature term bounds the true maximum from above.
    steps = 720
    vals = [value(j / steps) for j in range(steps + 1)]
    grid_max = max(vals)
    # Between grid points the function exceeds the chord by at most r |n_xy| (dth)^2 / 8.
    dth = abs(sweep) / steps
    pad = r * math.hypot(n[0], n[1]) * dth * dth / 8
    return max(best, grid_max + pad)


def _chamfers(u, perp):
    """Directions at 45 degrees between +-u and every other normal: they cut the corners of
    the prism at the tube's rounded ends (any direction gives a valid row)."""
    return [(s * u + n) / math.sqrt(2) for s in (1.0, -1.0) for n in perp[::2]]


def tube_rows(moves, i, perp_count=8):
    """Rows (n, rhs) with n . x <= rhs for every x within P_i of move i (outer polyhedron)."""
    m = moves[i]
    rows = []
    if m.kind == "rest" or m.direction() is None:
        for j in range(3):
            e = np.eye(3)[j]
            for s in (1.0, -1.0):
                rows.append((s * e, s * m.end[j] + m.tol_mm))
        return rows
    if m.kind == "arc":
        dirs = [np.array([math.cos(2 * math.pi * j / 16), math.sin(2 * math.pi * j / 16), 0.0])
                for j in range(16)]
        dirs += [np.array([0, 0, 1.0]), np.array([0, 0, -1.0])]
        for n in dirs:
            rows.append((n, _arc_support(m, n) + m.tol_mm))
        return rows
    u = m.direction()
    hints = []
    for k in (i + 1, i - 1):
        if 0 <= k < len(moves) and moves[k].kind in ("line", "rapid"):
            hints.append(moves[k].direction())
    perp = _perpendicular_dirs(u, hints, perp_count)
    dirs = [u, -u] + perp + _chamfers(u, perp)
    for n in dirs:
        n = np.where(np.abs(n) < 1e-12, 0.0, n)
        rows.append((n, max(np.dot(n, m.start), np.dot(n, m.end)) + m.tol_mm))
    return rows


def group_moves(moves, a, b, turn_deg):
    """Elements (i0, i1), consecutive and covering every move: chains of lines of one kind and
    feed whose every direction is within turn_deg of the chain's chord, never across the
    section's ends a and b. turn_deg = 0 gives one element per move."""
    groups, i, last = [], 0, len(moves) - 1
    cos_max = math.cos(math.radians(turn_deg))
    while i <= last:
        j = i
        if turn_deg > 0 and moves[i].kind in ("line", "rapid"):
            while j + 1 <= last and j not in (a, b) and _chain_ok(moves, i, j + 1, cos_max):
                j += 1
        groups.append((i, j))
        i = j + 1
    return groups


def _chain_ok(moves, i0, i1, cos_max):
    first = moves[i0]
    for i in range(i0, i1 + 1):
        m = moves[i]
        if m.kind != first.kind or m.feed_mm_s != first.feed_mm_s or m.direction() is None:
            return False
    chord = _unit(moves[i1].end - moves[i0].start)
    if chord is None:
        return False
    return all(np.dot(moves[i].direction(), chord) >= cos_max for i in range(i0, i1 + 1))


def chain_rows(moves, i0, i1, perp_count=8):
    """Rows holding every point within P of any move of the chain i0..i1: supports of the
    convex hull of the chain's vertices, grown by the largest P of the chain."""
    pts = [moves[i0].start] + [moves[i].end for i in range(i0, i1 + 1)]
    tol = max(moves[i].tol_mm for i in range(i0, i1 + 1))
    u = _unit(moves[i1].end - moves[i0].start)
    hints = [moves[k].direction() for k in (i1 + 1, i0 - 1)
             if 0 <= k < len(moves) and moves[k].kind in ("line", "rapid")]
    hints += [moves[i].direction() for i in range(i0, i1 + 1)]
    perp = _perpendicular_dirs(u, hints, perp_count)
    dirs = [u, -u] + perp + _chamfers(u, perp)
    rows = []
    for n in dirs:
        n = np.where(np.abs(n) < 1e-12, 0.0, n)
        rows.append((n, max(float(np.dot(n, p)) for p in pts) + tol))
    return rows


def rows_box(rows_list):
    """The box of the intersection of several row sets (LP per axis end); None if empty."""
    A = np.array([n for rows in rows_list for n, _ in rows])
    b = np.array([r for rows in rows_list for _, r in rows])
    lo, hi = np.zeros(3), np.zeros(3)
    for j in range(3):
        for sign in (1.0, -1.0):
            c = np.zeros(3)
            c[j] = -sign
            res = linprog(c, A_ub=A, b_ub=b + SLACK, bounds=[(None, None)] * 3,
                          method="highs")
            if res.status == 2:
                return None
            if res.status != 0:
                raise RuntimeError(f"corner region LP failed: {res.message}")
            if sign > 0:
                hi[j] = -res.fun + SLACK
            else:
                lo[j] = res.fun - SLACK
    return lo, hi


def rows_min(rows_list, n):
    """min of n . x over the intersection of several row sets (an LP), less SLACK."""
    A = np.array([m for rows in rows_list for m, _ in rows])
    b = np.array([r for rows in rows_list for _, r in rows])
    res = linprog(np.asarray(n, float), A_ub=A, b_ub=b + SLACK, bounds=[(None, None)] * 3,
                  method="highs")
    if res.status != 0:
        raise RuntimeError(f"corner region LP failed: {res.message}")
    return res.fun - SLACK


# ----------------------------------------------------------------------------------------------
# The problem

@dataclass
class Limits:
    """Per-axis limits. Like Move's fields, named for millimetres but in model units (um)
    inside SectionModel (make_model converts)."""
    v_mm_s: np.ndarray
    a_mm_s2: np.ndarray


@dataclass
class FloorResult:
    floor_s: float            # the proved lower bound on t_b - t_a
    status: str               # 'optimal', 'time limit (dual bound)', 'infeasible in horizon'
    samples_proved: int       # N: t_b - t_a >= N h
    relaxed_s: float          # the time of the MILP's best trajectory (information only)
    gap: float
    solve_s: float
    step_s: float
    horizon_s: float
    variables: int
    binaries: int
    rows: int
    trajectory: list = field(default_factory=list)
    cpu_s: float = 0.0         # CPU time of the solver(s): HiGHS in-process, cbc as a child


class SectionModel:
    """Builds and solves the MILP for the section from vertex a to vertex b of moves (rest
    states included at 0 and n + 1)."""

    def __init__(self, moves, a, b, limits, step_s, lead_in, lead_out, horizon_s,
                 perp_count=8, group_turn_deg=0.0, reach_vertices=False):
        self.mv, self.a, self.b = moves, a, b
        self.reach_vertices = reach_vertices
        # The MILP assigns samples to elements: single moves, or chains of nearly collinear
        # lines taken as the convex hull of their tubes (group_moves).
        self.el = group_moves(moves, a, b, group_turn_deg)
        self.ea = next(e for e, (i0, i1) in enumerate(self.el) if i1 == a)
        self.eb = next(e for e, (i0, i1) in enumerate(self.el) if i1 == b)
        self._el_rows = {}
        # HiGHS 1.2 (SciPy 1.10) presolve declared a real motion infeasible (the soundness
        # test), so proofs run without it; --presolve turns it on for quick exploration.
        self.presolve = False
        self.solver = "highs"   # or "cbc" (run_cbc)
        self.lim, self.h = limits, step_s
        self.k_in, self.k_out = lead_in, lead_out
        self.U = max(1, int(math.ceil(horizon_s / step_s)))  # at most U - 1 samples past t_a
        self.perp_count = perp_count
        self._rows, self._region, self._min_time = {}, {}, {}
        self.origin = moves[a].end.copy()

    # -- geometry ------------------------------------------------------------------------
    def rows(self, i):
        if i not in self._rows:
            self._rows[i] = [(n, r - np.dot(n, self.origin))
                             for n, r in tube_rows(self.mv, i, self.perp_count)]
        return self._rows[i]

    def region(self, v):
        """Box of the corner region R_v (within P of moves v and v + 1), local coordinates."""
        if v not in self._region:
            box = rows_box([self.rows(v), self.rows(v + 1)])
            if box is None:
                raise ProgramError(f"the moves at vertex {v} do not meet within their "
                                   "tolerances")
            self._region[v] = box
        return self._region[v]

    def el_rows(self, e):
        """Rows of element e: its move's tube, or the hull of a chain's tubes."""
        if e not in self._el_rows:
            i0, i1 = self.el[e]
            if i0 == i1:
                self._el_rows[e] = self.rows(i0)
            else:
                self._el_rows[e] = [(n, r - np.dot(n, self.origin))
                                    for n, r in chain_rows(self.mv, i0, i1, self.perp_count)]
        return self._el_rows[e]

    def el_box(self, e):
        return rows_box([self.el_rows(e)])

    def el_feed(self, e):
        i0, i1 = self.el[e]
        return max(self.mv[i].feed_mm_s for i in range(i0, i1 + 1))

    def el_dirs(self, e):
        i0, i1 = self.el[e]
        return [self.mv[i].direction() for i in range(i0, i1 + 1)
                if self.mv[i].kind in ("line", "rapid") and self.mv[i].direction() is not None]

    def _direct_time(self, u, v):
        """t_v - t_u >= the gap between the boxes of R_u and R_v at the axis speeds, and at
        the largest feed of moves u+1..v when all of them are feed moves."""
        lu, hu = self.region(u)
        lv, hv = self.region(v)
        gap = np.maximum(0.0, np.maximum(lv - hu, lu - hv))
        t = float(np.max(gap / self.lim.v_mm_s))
        fmax = max(self.mv[i].feed_mm_s for i in range(u + 1, v + 1))
        if math.isfinite(fmax) and fmax > 0:
            t = max(t, float(np.linalg.norm(gap)) / fmax)
        return t

    def min_time(self, u, v):
        """A lower bound on t_v - t_u for u <= v (in either order of the arguments): the
        larger of the direct gap and the sum of the gaps between consecutive corner regions,
        since t_v - t_u is the sum of t_(w+1) - t_w."""
        u, v = min(u, v), max(u, v)
        if u == v:
            return 0.0
        key = (u, v)
        if key not in self._min_time:
            chain = self.min_time(u, v - 1) + self._direct_time(v - 1, v) if v - 1 > u else \
                self._direct_time(u, v)
            self._min_time[key] = max(chain, self._direct_time(u, v))
        return self._min_time[key]

    # -- the stricter contract: every move reaches both its end points ----------------------
    def reach_clauses(self):
        """[(i, n, r)]: while move i is the current one (at some instant of [t_(i-1), t_i]) the
        tool reaches n . x >= r (local model units): n = u_i, r = u_i . c_i - P_i (it gets to
        within P of its end, along itself) and n = -u_i, r = -u_i . c_(i-1) - P_i (it starts
        within P of its start). Only lines and rapids of the section; a clause that the corner
        region at that end already implies (it holds at t_i, or at t_(i-1)) is left out, so
        only reversals and turns sharper than about 90 degrees keep theirs."""
        clauses = []
        for i in range(self.a + 1, self.b + 1):
            m = self.mv[i]
            u = m.direction()
            if m.kind not in ("line", "rapid") or u is None:
                continue
            for n, c, v in ((u, m.end, i), (-u, m.start, i - 1)):
                r = float(np.dot(n, c - self.origin)) - m.tol_mm
                if rows_min([self.rows(v), self.rows(v + 1)], n) < r:
                    clauses.append((i, n, r))
        return clauses

    def el_of(self, i):
        return next(e for e, (i0, i1) in enumerate(self.el) if i0 <= i <= i1)

    # -- which moves each sample may be on ------------------------------------------------
    def windows(self):
        """{k: (lo, hi)}: the elements sample k may be on (sample 0 is q(t_a), in R_a)."""
        a, b, h, U, n_el = self.a, self.b, self.h, self.U, len(self.el)
        ea, eb, el = self.ea, self.eb, self.el
        win = {}
        # Lead-in: on element e at s_k means s_k <= t_v for v, the vertex after e, and
        # t_a - t_v >= min_time(v, a), so |k| h >= that.
        lo = ea
        for k in range(-1, -self.k_in - 1, -1):
            while lo > 0 and self.min_time(el[lo - 1][1], a) <= -k * h + 1e-12:
                lo -= 1
            win[k] = (lo, ea)
        # Section and lead-out: on element e at s_k means s_k > t_v for v, the vertex before
        # e, and t_v - t_a >= min_time(a, v). Within the horizon (t_b < U h) a sample on
        # element e <= eb has t_b - t_v >= min_time(v, b) for v, the vertex after e.
        hi = ea + 1
        last = U - 1 + self.k_out
        for k in range(1, last + 1):
            while hi + 1 < n_el and self.min_time(a, el[hi][1]) < k * h + 1e-12:
                hi += 1
            if k >= U:
                lo_k = eb + 1
            else:
                lo_k = ea + 1
                while lo_k < eb and self.min_time(el[lo_k][1], b) >= (U - k) * h + 1e-12:
                    lo_k += 1
            win[k] = (lo_k, hi)
        # Keep the windows monotone in k (true of the real assignment).
        ks = sorted(win)
        for k0, k1 in zip(ks, ks[1:]):
            if win[k1][0] < win[k0][0]:
                win[k1] = (win[k0][0], win[k1][1])
        for k1, k0 in zip(reversed(ks), list(reversed(ks))[1:]):
            if win[k0][1] > win[k1][1]:
                win[k0] = (win[k0][0], win[k1][1])
        return win

    # -- the MILP ---------------------------------------------------------------------------
    def solve(self, time_limit_s=120.0, verbose=False, feasibility=False,
              fixed=None, fixed_tol_mm=0.0, assignment=None, mps_path=None):
        """The MILP for this horizon. feasibility=True drops the objective: HiGHS then stops
        at the first solution, and a proof of infeasibility shows t_b - t_a >= U h.
        fixed: {k: xyz} pins samples (within fixed_tol_mm) to a given motion, to test that a
        real motion satisfies every row; assignment: {k: element} pins the samples' elements
        as well (for tests and debugging). mps_path: write the MILP there in free MPS format
        (for a second solver, e.g. `cbc FILE solve`) instead of solving it."""
        t_start = time.monotonic()
        a, h, lim = self.a, self.h, self.lim
        ea, eb = self.ea, self.eb
        win = self.windows()

        def beyond_horizon():
            # No real motion is this fast: every one has t_b - t_a >= U h.
            return FloorResult(self.U * h, "infeasible in horizon", self.U, math.nan, math.nan,
                               time.monotonic() - t_start, h, self.U * h, 0, 0, 0)

        if any(hi < lo for lo, hi in win.values()):
            return beyond_horizon()
        ks = sorted(list(win) + [0])
        vp = _VarPool()
        qidx = {k: vp.add(3) for k in ks}
        zidx = {}  # (k, v) -> var: sample k is past vertex v (m(k) > v)
        for k in ks:
            if k != 0:
                for v in range(win[k][0], win[k][1]):
                    zidx[(k, v)] = vp.add(1, 0.0, 1.0, integer=True)

        def zval(k, v, left=True):
            """z_(k,v) as (var or None, constant). Sample 0 counts as m = a + 1 when it is the
            left end of a step and as m = a when it is the right end."""
            if k == 0:
                return None, 1.0 if (ea + 1 if left else ea) > v else 0.0
            lo, hi = win[k]
            if v < lo:
                return None, 1.0
            if v >= hi:
                return None, 0.0
            return zidx[(k, v)], 0.0

        # q_k within the reach of R_a and the box of the moves it may be on.
        ra_lo, ra_hi = self.region(a)
        boxes = {}
        for k in ks:
            reach = abs(k) * h * lim.v_mm_s + SLACK
            blo, bhi = ra_lo - reach, ra_hi + reach
            if k != 0:
                for i in range(win[k][0], win[k][1] + 1):
                    if i not in boxes:
                        boxes[i] = self.el_box(i)
                mlo = np.min([boxes[i][0] for i in range(win[k][0], win[k][1] + 1)], axis=0)
                mhi = np.max([boxes[i][1] for i in range(win[k][0], win[k][1] + 1)], axis=0)
                blo, bhi = np.maximum(blo, mlo), np.minimum(bhi, mhi)
            if fixed is not None and k in fixed:
                want = np.asarray(fixed[k], float) * UNIT_PER_MM - self.origin
                tol = fixed_tol_mm * UNIT_PER_MM
                if np.any(want < blo - tol) or np.any(want > bhi + tol):
                    raise AssertionError(f"sample {k} at {fixed[k]} is outside its box "
                                         f"{(blo + self.origin) / UNIT_PER_MM} .. "
                                         f"{(bhi + self.origin) / UNIT_PER_MM}")
                tol = fixed_tol_mm * UNIT_PER_MM
                blo, bhi = want - tol, want + tol
            if np.any(blo > bhi):
                return beyond_horizon()
            vp.lo[qidx[k]:qidx[k] + 3] = blo
            vp.hi[qidx[k]:qidx[k] + 3] = bhi
        cons = _Rows()
        if assignment is not None:
            for (k, v), var in zidx.items():
                if k in assignment:
                    vp.lo[var] = vp.hi[var] = 1.0 if assignment[k] > v else 0.0
        # Kinematics between consecutive samples (the grid is t_a + k h for every k).
        for k0, k1 in zip(ks, ks[1:]):
            for j in range(3):
                vh = lim.v_mm_s[j] * h + SLACK
                cons.add([(qidx[k1] + j, 1.0), (qidx[k0] + j, -1.0)], -vh, vh)
        for km, k0, k1 in zip(ks, ks[1:], ks[2:]):
            for j in range(3):
                ah2 = lim.a_mm_s2[j] * h * h + SLACK
                cons.add([(qidx[k1] + j, 1.0), (qidx[k0] + j, -2.0), (qidx[km] + j, 1.0)],
                         -ah2, ah2)
        # Sample 0 is q(t_a): in R_a, within P of both moves a and a + 1.
        for i in (a, a + 1):
            for n, r in self.rows(i):
                cons.add(_dot(qidx[0], n), -np.inf, r + SLACK)
        # Tubes: sample k on move i (z_(k,i-1) = 1, z_(k,i) = 0) is within P_i of it.
        for k in ks:
            if k != 0:
                self._tube_rows(k, win[k], qidx[k], zval, vp, cons)
        # The assignment is monotone: z_(k,v) >= z_(k,v+1) and z_(k+1,v) >= z_(k,v).
        after = dict(zip(ks, ks[1:]))
        for (k, v), var in zidx.items():
            nxt = zidx.get((k, v + 1))
            if nxt is not None:
                cons.add([(var, 1.0), (nxt, -1.0)], 0.0, np.inf)
            k1 = after.get(k)
            if k1 is None or k1 == 0:
                continue
            later, c = zval(k1, v, left=False)
            if later is not None:
                cons.add([(later, 1.0), (var, -1.0)], 0.0, np.inf)
            elif c == 0.0:
                vp.hi[var] = 0.0
        # Feed: on [s_k, s_k+1] the tool is on moves m(k)..m(k+1) only, so |q_k+1 - q_k| <= h
        # times the largest feed among them (nothing if a rapid is among them).
        for k0, k1 in zip(ks, ks[1:]):
            self._feed_rows(k0, k1, win, qidx, zval, vp, cons)
        if self.reach_vertices and not self._reach_rows(ks, qidx, zval, vp, cons):
            return beyond_horizon()
        # Objective: N = the number of samples k >= 1 not past b (s_k <= t_b).
        cost = np.zeros(vp.count)
        const = 0.0
        for k in ks:
            if k > 0:
                z, c = zval(k, eb)
                if z is None:
                    const += 1.0 - c
                else:
                    cost[z] -= 1.0
                    const += 1.0
        A = cons.matrix(vp.count)
        if mps_path is not None:
            write_mps(mps_path, np.zeros(vp.count) if feasibility else cost, vp, A, cons)
            return None
        objective = np.zeros(vp.count) if feasibility else cost
        run = run_cbc if self.solver == "cbc" else run_highs
        ans = run(objective, vp, A, cons, time_limit_s, verbose, self.presolve)
        solve_s = time.monotonic() - t_start
        if ans.infeasible:
            res = beyond_horizon()
            res.cpu_s = ans.cpu_s
            return res
        count = (float(cost @ ans.x) + const) if ans.x is not None else \
            (ans.objective + const if not feasibility and ans.found else math.nan)
        if feasibility or ans.dual_bound is None:
            # Nothing proved by this solve beyond what the caller already knows.
            return FloorResult(0.0, "feasible" if ans.found else "unknown", 0,
                               count * h, math.nan, solve_s, h, self.U * h, vp.count,
                               len(zidx), len(cons.lo), cpu_s=ans.cpu_s)
        # N is an integer, so the dual bound rounds up.
        proved = max(0, int(math.ceil(ans.dual_bound + const - 1e-6)))
        status = "optimal" if ans.optimal else "time limit (dual bound)"
        traj = []
        if ans.x is not None:
            traj = [(k, (ans.x[qidx[k]:qidx[k] + 3] + self.origin) / UNIT_PER_MM) for k in ks]
        return FloorResult(proved * h, status, proved, count * h, ans.gap, solve_s, h,
                           self.U * h, vp.count, len(zidx), len(cons.lo), traj, ans.cpu_s)

    def _tube_rows(self, k, window, q, zval, vp, cons):
        """Sample k lies within P_i of the element i it is on, written as the convex hull of
        the disjunction (q_k = sum of q_k^i, q_k^i in y_i times element i's polytope, y_i = 1
        on the element the sample is on): a tighter LP than big-M rows."""
        lo, hi = window
        if lo == hi:
            for n, r in self.el_rows(lo):
                cons.add(_dot(q, n), -np.inf, r + SLACK)
            return
        parts = []
        for i in range(lo, hi + 1):
            zin, cin = zval(k, i - 1)
            zout, cout = zval(k, i)
            # y_i = z_(k,i-1) - z_(k,i) as constant + terms
            y_const = (cin if zin is None else 0.0) - (cout if zout is None else 0.0)
            y_terms = ([(zin, 1.0)] if zin is not None else []) + \
                      ([(zout, -1.0)] if zout is not None else [])
            if not y_terms and y_const <= 0.0:
                continue
            parts.append((i, y_const, y_terms))
        sums = [[(q + j, 1.0)] for j in range(3)]
        for i, y_const, y_terms in parts:
            qi = vp.add(3)
            for j in range(3):
                sums[j].append((qi + j, -1.0))
            for n, r in self.el_rows(i):
                rr = r + SLACK
                # n . q^i <= rr * y_i
                coefs = _dot(qi, n) + [(var, -rr * c) for var, c in y_terms]
                cons.add(coefs, -np.inf, rr * y_const)
        for j in range(3):
            cons.add(sums[j], 0.0, 0.0)

    def _reach_rows(self, ks, qidx, zval, vp, cons):
        """The clauses of reach_clauses on the grid. Move i reaches n . x >= r at an instant
        tau of [t_(i-1), t_i]. Between samples, k h <= tau <= (k+1) h, n . q has a second
        derivative of at most A_n = sum |n_j| A_j, so it exceeds its chord by at most
        A_n h^2 / 8: the larger of n . q_k and n . q_(k+1), sample s (or tau / h itself when
        tau is on the grid), is >= r - A_n h^2 / 8. Since 0 <= tau < t_b < U h, 0 <= s <= U.
        A monotone binary p_k = [s <= k] marks the pick (p_(-1) = 0, p_U = 1, the pick is where
        p steps up, with a big-M row there), tied to the assignment: (s - 1) h < tau <= t_i,
        so a sample k past move i has k >= s (z_(k,i) <= p_k); t_(i-1) <= tau < (s + 1) h, so
        sample k + 1 is past move i - 1 once k >= s (p_k <= z_(k+1,i-1)). False when the
        window leaves no sample for a clause: no motion keeps it within the horizon."""
        h, have = self.h, set(ks)
        top = self.U
        for i, n, r in self.reach_clauses():
            e = self.el_of(i)
            need = r - float(np.dot(np.abs(n), self.lim.a_mm_s2)) * h * h / 8 - SLACK
            # p[k] as (var or None, constant) for k = -1 .. U
            p = {-1: (None, 0.0), top: (None, 1.0)}
            for k in range(0, top):
                p[k] = (vp.add(1, 0.0, 1.0, integer=True), 0.0)
            for k in range(-1, top + 1):
                if k in have and k != 0:
                    z, c = zval(k, e, left=False)  # z_(k,e) <= p_k
                    if not _le(cons, vp, (z, c), p[k]):
                        return False
                if k + 1 in have and k + 1 != 0:
                    z, c = zval(k + 1, e - 1, left=False)  # p_k <= z_(k+1,e-1)
                    if not _le(cons, vp, p[k], (z, c)):
                        return False
                if k >= 0 and not _le(cons, vp, p[k - 1], p[k]):
                    return False
            for s in range(0, top + 1):
                q = qidx[s]
                low = sum(min(n[j] * vp.lo[q + j], n[j] * vp.hi[q + j]) for j in range(3))
                big = need - low
                if big <= 0:
                    continue
                # n . q_s >= need - big (1 - p_s + p_(s-1))
                coefs = _dot(q, n)
                const = need - big
                for (var, c), sign in ((p[s], big), (p[s - 1], -big)):
                    if var is None:
                        const += sign * c
                    else:
                        coefs.append((var, -sign))
                cons.add(coefs, const, np.inf)
        return True

    def _feed_rows(self, k0, k1, win, qidx, zval, vp, cons):
        ea, h, lim = self.ea, self.h, self.lim
        lo = win[k0][0] if k0 != 0 else ea + 1
        hi = win[k1][1] if k1 != 0 else ea
        touched = range(lo, hi + 1)
        feed = {e: self.el_feed(e) for e in touched}
        levels = sorted(set(feed.values()))
        if not levels or not math.isfinite(levels[0]):
            return
        # |d| <= F h implies n . d <= F h for any unit n: the axes, the directions of the
        # lines touched, and for arcs the diagonals of their plane.
        dirs = [s * np.eye(3)[j] for j in range(3) for s in (1.0, -1.0)]
        for e in touched:
            for u in self.el_dirs(e):
                dirs += [u, -u]
            if self.mv[self.el[e][0]].kind == "arc":
                dirs += [np.array([x, y, 0.0]) / math.sqrt(2) for x in (-1, 1) for y in (-1, 1)]
        wmap = {}

        def touch_var(i):
            """w <= 1 - z_(k0,i) and w <= z_(k1,i-1): 0 unless the step may touch move i."""
            if i not in wmap:
                z0, c0 = zval(k0, i, left=True)
                z1, c1 = zval(k1, i - 1, left=False)
                if (z0 is None and c0 == 1.0) or (z1 is None and c1 == 0.0):
                    wmap[i] = None
                else:
                    w = vp.add(1, 0.0, 1.0)
                    if z0 is not None:
                        cons.add([(w, 1.0), (z0, 1.0)], -np.inf, 1.0)
                    if z1 is not None:
                        cons.add([(w, 1.0), (z1, -1.0)], -np.inf, 0.0)
                    wmap[i] = w
            return wmap[i]

        for f in levels:
            if not math.isfinite(f):
                break
            wv = [touch_var(i) for i in touched if feed[i] > f]
            wv = [w for w in wv if w is not None]
            for n in dirs:
                big = float(np.dot(np.abs(n), lim.v_mm_s)) * h
                if big <= f * h:
                    continue
                coefs = [(qidx[k1] + j, n[j]) for j in range(3) if n[j] != 0.0] + \
                        [(qidx[k0] + j, -n[j]) for j in range(3) if n[j] != 0.0]
                coefs += [(w, -(big - f * h)) for w in wv]
                cons.add(coefs, -np.inf, f * h + SLACK)
            if not wv:
                break  # an unconditional row at this level: higher levels add nothing


@dataclass
class SolverAnswer:
    """What a MILP solver says, in the terms the floor needs. A solve that stopped on its time
    limit without a solution is neither infeasible nor found: it proves nothing."""
    infeasible: bool
    found: bool               # a solution (feasibility: the horizon is not proved)
    optimal: bool
    objective: float          # of the best solution found
    dual_bound: float         # None when the solver gives none
    gap: float
    cpu_s: float
    x: np.ndarray = None      # the solution, where the solver hands it back


def run_highs(cost, vp, A, cons, time_limit_s, verbose, presolve):
    cpu0 = time.process_time()
    res = milp(cost, integrality=np.array(vp.integer, float),
               bounds=Bounds(np.array(vp.lo), np.array(vp.hi)),
               constraints=LinearConstraint(A, np.array(cons.lo), np.array(cons.hi)),
               options={"time_limit": time_limit_s, "mip_rel_gap": 0.0, "disp": verbose,
                        "presolve": presolve})
    cpu_s = time.process_time() - cpu0
    if res.status == 2:
        return SolverAnswer(True, False, False, math.nan, None, math.nan, cpu_s)
    if res.status not in (0, 1):
        raise RuntimeError(f"HiGHS: {res.message}")
    found = res.x is not None
    return SolverAnswer(False, found, res.status == 0, float(cost @ res.x) if found else math.nan,
                        res.mip_dual_bound,
                        res.mip_gap if res.mip_gap is not None else math.nan, cpu_s, res.x)


CBC_BINARY = "cbc"


def run_cbc(cost, vp, A, cons, time_limit_s, verbose, presolve):
    """COIN-OR CBC on the MILP written as free MPS (`cbc FILE sec T solve`), its verdict read
    from its 'Result - ' line. CBC's own preprocessing stays on, as in the cross-checks the
    docs quote; presolve (HiGHS's) is ignored."""
    if shutil.which(CBC_BINARY) is None:
        raise RuntimeError("--solver cbc needs the cbc binary (Debian: apt-get install "
                           "coinor-cbc; bench/floor/run.sh installs it)")
    with tempfile.TemporaryDirectory(prefix="floor_cbc_") as tmp:
        path = os.path.join(tmp, "floor.mps")
        write_mps(path, cost, vp, A, cons)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        run = subprocess.run([CBC_BINARY, path, "sec", repr(float(time_limit_s)), "solve",
                              "quit"], capture_output=True, text=True)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu_s = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if verbose:
        print(run.stdout, end="")
    return parse_cbc(run.stdout, run.returncode, cpu_s)


def parse_cbc(text, returncode, cpu_s):
    """CBC's verdict from its log: 'Result - Problem proven infeasible' (also 'Linear
    relaxation infeasible'), 'Result - Optimal solution found', 'Result - Stopped on time
    limit' (with or without a solution: 'Objective value:' is printed only with one); when
    its first LP is infeasible it prints only 'Problem is infeasible - T seconds'."""
    lines = text.splitlines()
    result = next((ln.split("Result - ", 1)[1].strip() for ln in lines
                   if ln.startswith("Result - ")), None)
    if result is None and any(ln.startswith("Problem is infeasible") for ln in lines):
        result = "Problem proven infeasible"
    if result is None:
        tail = "\n".join(text.splitlines()[-5:])
        raise RuntimeError(f"cbc gave no result (exit {returncode}):\n{tail}")

    def number(label):
        for ln in text.splitlines():
            if ln.strip().startswith(label):
                try:
                    return float(ln.split(":", 1)[1].split()[0])
                except (IndexError, ValueError):
                    return None
        return None

    low = result.lower()
    if "infeasible" in low:
        return SolverAnswer(True, False, False, math.nan, None, math.nan, cpu_s)
    objective = number("Objective value")
    found = objective is not None and "no feasible" not in low
    if low.startswith("optimal solution found"):
        return SolverAnswer(False, True, True, objective, objective, 0.0, cpu_s)  # proved optimal
    if low.startswith("stopped"):
        # A stopped solve proves nothing here (its bound is not read: --single is HiGHS only).
        return SolverAnswer(False, found, False, objective if found else math.nan, None,
                            math.nan, cpu_s)
    raise RuntimeError(f"cbc: unexpected result '{result}'")


class _VarPool:
    def __init__(self):
        self.lo, self.hi, self.integer = [], [], []

    @property
    def count(self):
        return len(self.lo)

    def add(self, n, lo=-np.inf, hi=np.inf, integer=False):
        first = len(self.lo)
        self.lo += [lo] * n
        self.hi += [hi] * n
        self.integer += [1 if integer else 0] * n
        return first


class _Rows:
    def __init__(self):
        self.i, self.j, self.v, self.lo, self.hi = [], [], [], [], []

    def add(self, coefs, lo, hi):
        r = len(self.lo)
        for j, val in coefs:
            if val != 0.0:
                self.i.append(r)
                self.j.append(j)
                self.v.append(val)
        self.lo.append(lo)
        self.hi.append(hi)

    def matrix(self, ncols):
        return coo_matrix((self.v, (self.i, self.j)), shape=(len(self.lo), ncols)).tocsr()


def write_mps(path, cost, vp, A, cons):
    """The MILP in free MPS: rows r0.., columns x0.., integers between markers."""
    with open(path, "w") as f:
        f.write("NAME floor\nROWS\n N obj\n")
        kinds = []
        for r, (lo, hi) in enumerate(zip(cons.lo, cons.hi)):
            kind = "E" if lo == hi else "L" if math.isfinite(hi) else "G"
            kinds.append(kind)
            f.write(f" {kind} r{r}\n")
        f.write("COLUMNS\n")
        csc = A.tocsc()
        in_int = False
        for j in range(csc.shape[1]):
            if vp.integer[j] != in_int:
                f.write(f" M{j} 'MARKER' '{'INTORG' if vp.integer[j] else 'INTEND'}'\n")
                in_int = bool(vp.integer[j])
            if cost[j] != 0.0:
                f.write(f" x{j} obj {cost[j]!r}\n")
            for k in range(csc.indptr[j], csc.indptr[j + 1]):
                f.write(f" x{j} r{csc.indices[k]} {csc.data[k]!r}\n")
            if csc.indptr[j] == csc.indptr[j + 1] and cost[j] == 0.0:
                f.write(f" x{j} obj 0\n")
        if in_int:
            f.write(" Mend 'MARKER' 'INTEND'\n")
        f.write("RHS\n")
        for r, kind in enumerate(kinds):
            rhs = cons.hi[r] if kind in ("L", "E") else cons.lo[r]
            if rhs != 0.0:
                f.write(f" rhs r{r} {rhs!r}\n")
        f.write("RANGES\n")
        for r, kind in enumerate(kinds):
            if kind == "L" and math.isfinite(cons.lo[r]):
                f.write(f" rng r{r} {cons.hi[r] - cons.lo[r]!r}\n")
        f.write("BOUNDS\n")
        for j, (lo, hi) in enumerate(zip(vp.lo, vp.hi)):
            if lo == hi:
                f.write(f" FX bnd x{j} {lo!r}\n")
                continue
            if not math.isfinite(lo) and not math.isfinite(hi):
                f.write(f" FR bnd x{j}\n")
                continue
            f.write(f" LO bnd x{j} {lo!r}\n" if math.isfinite(lo) else f" MI bnd x{j}\n")
            if math.isfinite(hi):
                f.write(f" UP bnd x{j} {hi!r}\n")
        f.write("ENDATA\n")


def _le(cons, vp, x, y):
    """Row x <= y for (var or None, constant) pairs; False if both are constants and x > y."""
    (xv, xc), (yv, yc) = x, y
    if xv is None and yv is None:
        return xc <= yc
    if xv is None:
        if xc > 0.0:
            vp.lo[yv] = max(vp.lo[yv], xc)
        return True
    if yv is None:
        vp.hi[xv] = min(vp.hi[xv], yc)
        return True
    cons.add([(xv, 1.0), (yv, -1.0)], -np.inf, 0.0)
    return True


def _dot(first_var, n):
    return [(first_var + j, float(n[j])) for j in range(3) if n[j] != 0.0]




def section_floor(moves, a, b, v_mm_s=100.0, a_mm_s2=1000.0, step_ms=1.0, lead_in=25,
                  lead_out=25, horizon_s=None, time_limit_s=120.0, perp_count=8,
                  verbose=False, group_turn_deg=0.0, search=True, log=None, presolve=False,
                  reach_vertices=False, solver="highs"):
    """The floor on t_b - t_a for moves (programmed moves; vertex a is the end of move a,
    moves numbered from 1). search=True: bisection on the horizon with feasibility MILPs
    (each infeasible one proves t_b - t_a >= U h); search=False: one MILP minimising the
    section's sample count within horizon_s. solver: "highs" (SciPy) or "cbc" (run_cbc)."""
    h = step_ms * 1e-3

    def model(hz):
        m = make_model(moves, a, b, v_mm_s, a_mm_s2, step_ms, lead_in, lead_out, hz,
                       perp_count, group_turn_deg, reach_vertices)
        m.presolve, m.solver = presolve, solver
        return m

    if horizon_s is None:
        horizon_s = model(None).U * h

    if not search:
        if solver != "highs":
            # CBC's dual bound on a stopped solve is not read reliably yet: feasibility only.
            raise ProgramError("--single needs --solver highs")
        return model(horizon_s).solve(time_limit_s, verbose)
    top = model(horizon_s)
    # The corner regions' gaps alone: t_b - t_a >= min_time(a, b).
    lo = int(math.floor(top.min_time(a, b) / h + 1e-9))
    hi = top.U
    total_s, total_cpu_s, steps, relaxed = 0.0, 0.0, [], math.nan

    def attempt(u):
        nonlocal total_s, total_cpu_s
        res = model(u * h).solve(time_limit_s, verbose, feasibility=True)
        total_s += res.solve_s
        total_cpu_s += res.cpu_s
        steps.append((u, res.status, res.solve_s))
        if log:
            log(f"  horizon {u * h * 1e3:.0f} ms: {steps[-1][1]} ({res.solve_s:.1f} s, "
                f"{solver} CPU {res.cpu_s:.1f} s)")
        return res

    # The top horizon first: while even it is infeasible, the floor is at least that, and a
    # longer one is tried (up to four times).
    for _ in range(4):
        res = attempt(hi)
        if res.status != "infeasible in horizon":
            if res.status == "feasible":
                relaxed = min(relaxed, res.relaxed_s) if relaxed == relaxed else res.relaxed_s
            break
        lo, hi = hi, int(math.ceil(hi * 1.5))
    else:
        return FloorResult(lo * h, "infeasible up to the last horizon tried", lo, relaxed,
                           math.nan, total_s, h, lo * h, 0, 0, 0, steps, total_cpu_s)
    while hi - lo > 1:
        u = (lo + hi) // 2
        res = attempt(u)
        if res.status == "infeasible in horizon":
            lo = u
        else:
            if res.status == "feasible":
                relaxed = min(relaxed, res.relaxed_s) if relaxed == relaxed else res.relaxed_s
            hi = u
    status = f"bisection, {solver}" + ("" if presolve or solver != "highs" else
                                       " without presolve")
    if any(st.startswith("unknown") for _, st, _ in steps):
        status += " (solves that hit the time limit count as not proved)"
    return FloorResult(lo * h, status, lo, relaxed, math.nan, total_s, h, hi * h, 0, 0, 0,
                       steps, total_cpu_s)


def default_horizon_s(mv, a, b, lim):
    """1.3 x the section's length at its speed limits plus 0.1 s: only a search limit. A floor
    found at the horizon's end is reported as such (any slower motion is slower still)."""
    t = 0.0
    for i in range(a + 1, b + 1):
        m = mv[i]
        u = m.direction()
        if u is None:
            continue
        length = np.linalg.norm(m.end - m.start) if m.kind != "arc" else \
            math.pi * np.linalg.norm(m.start[:2] - m.centre)
        along = float(np.min(lim.v_mm_s / np.maximum(np.abs(u), 1e-12)))
        t += length / min(m.feed_mm_s, along)
    return 1.3 * t + 0.1


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("program")
    ap.add_argument("--lines", required=True, help="A-B: from the end of line A-1's move to "
                    "the end of line B's move")
    ap.add_argument("--step-ms", type=float, default=1.0, help="grid step h (default 1)")
    ap.add_argument("--lead-in", type=int, default=25, help="samples before t_a (default 25)")
    ap.add_argument("--lead-out", type=int, default=25, help="samples after t_b (default 25)")
    ap.add_argument("--horizon-ms", type=float, default=None,
                    help="longest section time searched (default 1.3 x length / speed + 100)")
    ap.add_argument("--tolerance", type=float, default=0.01,
                    help="G64 P where the program sets none (default 0.01, the bench's)")
    ap.add_argument("--vmax", type=float, default=100.0, help="per-axis mm/s (default 100)")
    ap.add_argument("--amax", type=float, default=1000.0, help="per-axis mm/s^2 (default 1000)")
    ap.add_argument("--perp", type=int, default=8,
                    help="directions normal to each line in its tube's polygon (default 8)")
    ap.add_argument("--group-deg", type=float, default=0.0,
                    help="take chains of lines turning less than this from their chord as one "
                    "element, the hull of their tubes (default 0: every move on its own)")
    ap.add_argument("--reach-vertices", action="store_true",
                    help="the stricter contract: while a line or rapid is the current move, the "
                    "tool gets within P of both its end points along it (a plunge reaches its "
                    "depth); its floors hold only for motions that keep this too")
    ap.add_argument("--single", action="store_true",
                    help="one MILP minimising the count within the horizon (its dual bound is "
                    "the floor) instead of the bisection on the horizon")
    ap.add_argument("--prove-ms", type=float, default=None,
                    help="only try to prove t_b - t_a >= this (one feasibility MILP at this "
                    "horizon, e.g. with a longer --time-limit after a bisection)")
    ap.add_argument("--export-mps", metavar="FILE",
                    help="with --prove-ms: write that MILP in free MPS format instead of "
                    "solving it (to check a proof with another solver: cbc FILE solve)")
    ap.add_argument("--presolve", action="store_true",
                    help="use HiGHS's presolve (faster, but HiGHS 1.2's once declared a real "
                    "motion infeasible: not for proofs)")
    ap.add_argument("--solver", choices=("highs", "cbc"), default="highs",
                    help="HiGHS through SciPy (default) or COIN-OR CBC (the cbc binary, "
                    "coinor-cbc, on the MILP written as MPS)")
    ap.add_argument("--time-limit", type=float, default=300.0,
                    help="each solve's time limit, s (cbc counts CPU seconds)")
    ap.add_argument("--verbose", action="store_true", help="the solver's log")
    ap.add_argument("--trajectory", help="write the relaxed trajectory (k x y z) here")
    args = ap.parse_args()
    if args.trajectory and not args.single:
        # A bisection keeps no motion, only which horizons were proved: say so rather than
        # write nothing.
        ap.error("--trajectory needs --single (a bisection or --prove-ms keeps no trajectory)")
    try:
        first, last = (int(x) for x in args.lines.split("-"))
    except ValueError:
        sys.exit(f"--lines: expected A-B, got '{args.lines}'")
    try:
        moves = parse_program(args.program, args.tolerance)
        a, b = section_vertices(moves, first, last)
        contract = " (--reach-vertices contract)" if args.reach_vertices else ""
        if args.prove_ms is not None:
            model = make_model(moves, a, b, args.vmax, args.amax, args.step_ms, args.lead_in,
                               args.lead_out, args.prove_ms * 1e-3, args.perp, args.group_deg,
                               args.reach_vertices)
            model.presolve, model.solver = args.presolve, args.solver
            if args.export_mps:
                model.solve(feasibility=True, mps_path=args.export_mps)
                print(f"lines {first}-{last}, horizon {model.U * model.h * 1e3:.0f} ms: "
                      f"written to {args.export_mps}")
                return
            res = model.solve(args.time_limit, args.verbose, feasibility=True)
            verdict = {"infeasible in horizon": f"proved: t_b - t_a >= {model.U * model.h:.3f} s",
                       "feasible": "not proved: the relaxation has a motion this fast",
                       "unknown": "not proved: time limit"}[res.status]
            print(f"lines {first}-{last}{contract}, horizon {model.U * model.h * 1e3:.0f} ms: "
                  f"{verdict} ({res.solve_s:.1f} s; {args.solver} CPU {res.cpu_s:.1f} s)")
            return
        res = section_floor(moves, a, b, args.vmax, args.amax, args.step_ms, args.lead_in,
                            args.lead_out, None if args.horizon_ms is None else
                            args.horizon_ms * 1e-3, args.time_limit, args.perp, args.verbose,
                            args.group_deg, not args.single, log=print,
                            presolve=args.presolve, reach_vertices=args.reach_vertices,
                            solver=args.solver)
    except ProgramError as e:
        sys.exit(str(e))
    if args.single:
        print(f"lines {first}-{last}{contract}: floor {res.floor_s:.3f} s ({res.status}; N >= "
              f"{res.samples_proved} steps of {res.step_s * 1e3:g} ms), best relaxed trajectory "
              f"{res.relaxed_s:.3f} s, gap {res.gap:.3g}, solve {res.solve_s:.1f} s "
              f"({args.solver} CPU {res.cpu_s:.1f} s), horizon "
              f"{res.horizon_s:.3f} s, {res.variables} variables ({res.binaries} binary), "
              f"{res.rows} rows")
        if res.samples_proved >= round(res.horizon_s / res.step_s) - 1:
            print("note: the floor reached the horizon's end; raise --horizon-ms")
    else:
        feasible = [u for u, st, _ in res.trajectory if st == "feasible"]
        found = (f"the fastest relaxed motion found takes {res.relaxed_s:.3f} s"
                 if res.relaxed_s == res.relaxed_s else
                 f"feasible at {min(feasible) * res.step_s * 1e3:.0f} ms" if feasible else
                 "no relaxed motion found")
        print(f"lines {first}-{last}{contract}: floor {res.floor_s:.3f} s ({res.status}; N >= "
              f"{res.samples_proved} steps of {res.step_s * 1e3:g} ms; {found}), solves "
              f"{res.solve_s:.1f} s ({args.solver} CPU {res.cpu_s:.1f} s)")
    if args.trajectory and args.single and res.trajectory:
        with open(args.trajectory, "w") as f:
            for k, q in res.trajectory:
                f.write(f"{k} {q[0]:.6f} {q[1]:.6f} {q[2]:.6f}\n")


if __name__ == "__main__":
    main()
