"""The soak's checks of one `cnc run` against the program's model (program.py) and the INI
(machine.py). Each check returns a Failure naming what failed and where, or None.

Finite differences of printed numbers: the trace prints positions with 6 decimals, so each is
within q/2 of the commanded value (q = 1e-6 mm). A first difference over one period T is then
off by at most q/T, a second difference (coefficients 1 -2 1) by 2q/T^2, a third (1 -3 3 -1) by
4q/T^3. The finite differences of a profile whose velocity, acceleration and jerk stay within
their limits stay within them too (each is a weighted mean of the derivative over the stencil),
so a sample passes when it is within limit * (1 + 1e-6) plus that rounding bound: at 1 kHz
0.001 mm/s, 2 mm/s^2 and 4000 mm/s^3 (a fifth of the mill's 20000 mm/s^3 jerk: only a jerk
excess above that shows). Distances from the path: each coordinate is within q/2, so a sample
is within sqrt(axes) * q/2 of where it was commanded."""

import bisect
import dataclasses
import math
import re

QUANTUM = 1e-6  # the trace's resolution (6 decimals)
REL = 1e-6  # relative slack on every limit


@dataclasses.dataclass
class Failure:
    check: str  # short name: exit, summary, stderr, end-point, velocity, ...
    detail: str
    program_line: int = 0  # 0 = not tied to a line
    trace_t_s: float = None

    def where(self, program):
        at = f"{program}:{self.program_line}" if self.program_line else program
        if self.trace_t_s is not None:
            at += f" (trace t={self.trace_t_s:.3f} s)"
        return at


@dataclasses.dataclass
class Trace:
    header: list
    t: list
    line: list
    axes: list  # per row: list of axis values in the machine's letter order
    joints: list  # per row: joint feedback


def read_trace(path, machine):
    with open(path, encoding="utf-8") as f:
        header = f.readline().strip().split(",")
        want = ["t", "line"] + list(machine.letters) + [f"j{j}" for j in range(len(machine.joints))] + ["vel"]
        if header != want:
            raise ValueError(f"{path}:1: header {header} is not {want}")
        n_ax, n_j = len(machine.letters), len(machine.joints)
        tr = Trace(header, [], [], [], [])
        for k, text in enumerate(f, start=2):
            cols = text.strip().split(",")
            if len(cols) != len(want):
                raise ValueError(f"{path}:{k}: {len(cols)} columns, expected {len(want)}")
            tr.t.append(float(cols[0]))
            tr.line.append(int(cols[1]))
            tr.axes.append([float(c) for c in cols[2:2 + n_ax]])
            tr.joints.append([float(c) for c in cols[2 + n_ax:2 + n_ax + n_j]])
    return tr


# --- the run's own report -------------------------------------------------------------------

def check_exit(rc, stdout):
    if rc != 0:
        return Failure("exit", f"exit status {rc}")
    for want in ("result: finished", "errors: none"):
        if want not in stdout.splitlines():
            return Failure("summary", f"no '{want}' in the summary")
    return None


# Lines on stderr a run may print: none on the machines whose joints the planner keeps within
# their limits. On 5axis-trt the planner keeps the motors within their velocity limits but plans
# only part of their acceleration (a turned table swings an axis's acceleration onto another
# motor, docs/components/motion.md), so motion's report of an acceleration excess at stop is
# expected there and is not a failure; a velocity excess is.
TRT_EXCESS = re.compile(r"^motion\.0: joint \d was commanded an acceleration of .* the "
                        r"kinematics ask more of this motor than the axis limits allow$")


# Another process's leftovers: a run that died (killed by a test's timeout) leaves its HAL
# instance, and the next run of any config removes it and says so.
STALE_INSTANCE = re.compile(r"^halrun: removed stale HAL instance '[^']*' left by dead process \d+$")


def check_stderr(stderr, machine):
    for text in stderr.splitlines():
        if not text.strip() or STALE_INSTANCE.match(text):
            continue
        if not machine.joints_planned() and TRT_EXCESS.match(text):
            continue
        return Failure("stderr", f"unexpected: {text}")
    return None


def check_end_point(stdout, model, machine):
    m = re.search(r"^final position \(mm\): (.*)$", stdout, re.M)
    if not m:
        return Failure("end-point", "no 'final position' in the summary")
    got = dict(re.findall(r"([a-z]) (-?[\d.]+)", m.group(1)))
    for k, l in enumerate(machine.letters):
        want = model.pos[k]
        if l not in got:
            return Failure("end-point", f"axis {l} missing from '{m.group(1)}'")
        # Printed with 4 decimals: 1e-4 mm plus the rounding of the print.
        if abs(float(got[l]) - want) > 1e-4 + 0.5e-4 + 1e-12:
            return Failure("end-point", f"{l} ended at {got[l]}, the program ends at {want:.4f}")
    return None


# --- the trace: numbers, limits, lines ------------------------------------------------------

def check_numbers(tr):
    for n, row in enumerate(tr.axes):
        if any(math.isnan(x) or math.isinf(x) for x in row + tr.joints[n]):
            return Failure("nan", "NaN or inf in the trace", tr.line[n], tr.t[n])
    return None


def check_lines(tr):
    for n in range(1, len(tr.line)):
        if tr.line[n] < tr.line[n - 1]:
            return Failure("line-order", f"line column went back from {tr.line[n - 1]} to {tr.line[n]}",
                           tr.line[n], tr.t[n])
    return None


def check_axis_limits(tr, machine, start):
    """Velocity, acceleration and jerk of each axis from differences of consecutive samples.
    The machine stood at `start` before the first row (three rows of rest are put in front)."""
    T = machine.period_s
    rows = [start] * 3 + tr.axes
    bounds = []
    for l in machine.letters:
        a = machine.axes[l]
        bounds.append((a.vel * (1 + REL) + QUANTUM / T, a.acc * (1 + REL) + 2 * QUANTUM / T ** 2,
                       a.jerk * (1 + REL) + 4 * QUANTUM / T ** 3 if a.jerk > 0 else math.inf))
    for n in range(3, len(rows)):
        p0, p1, p2, p3 = rows[n], rows[n - 1], rows[n - 2], rows[n - 3]
        for k, l in enumerate(machine.letters):
            v = (p0[k] - p1[k]) / T
            acc = (p0[k] - 2 * p1[k] + p2[k]) / T ** 2
            jerk = (p0[k] - 3 * p1[k] + 3 * p2[k] - p3[k]) / T ** 3
            for what, value, bound in (("velocity", v, bounds[k][0]), ("acceleration", acc, bounds[k][1]),
                                       ("jerk", jerk, bounds[k][2])):
                if abs(value) > bound:
                    i = n - 3
                    return Failure(what, f"axis {l} {what} {value:.6g}, limit {bound:.6g} with the "
                                         f"rounding allowance", tr.line[i], tr.t[i])
    return None


def check_joint_limits(tr, machine):
    for n, row in enumerate(tr.joints):
        for j, x in enumerate(row):
            lim = machine.joints[j]
            slack = 1.0 / lim.counts_per_mm + QUANTUM  # the simulated encoder's count
            if x < lim.min_mm - slack or x > lim.max_mm + slack:
                return Failure("joint-limit", f"joint {j} at {x} outside [{lim.min_mm}, {lim.max_mm}]",
                               tr.line[n], tr.t[n])
    return None


# --- the trace against the programmed path --------------------------------------------------

def _line_points(e, q):
    """[(distance, fraction)] of the nearest point of a line element."""
    d = e.dir
    if d is None:  # cached on the element: the check measures every sample against it
        d = e.dir = [b - a for a, b in zip(e.start, e.end)]
        e.inv_dd = 1.0 / sum(x * x for x in d)
    s = e.start
    t = 0.0
    for k in range(len(q)):
        t += (q[k] - s[k]) * d[k]
    t = min(1.0, max(0.0, t * e.inv_dd))
    acc = 0.0
    for k in range(len(q)):
        r = q[k] - s[k] - t * d[k]
        acc += r * r
    return [(math.sqrt(acc), t)]


def _arc_points(e, q):
    """[(distance, fraction)] of the nearest points of an arc or helix: both ends, and the
    minimum of the squared distance over the sweep (a grid of pi/16 steps, refined by a golden
    section search in the steps about the best). The squared distance from a point to the
    spiral-helix p(t) = C + r(t) (cos, sin)(theta0 + t) + (t / span) D is, with rho and tq the
    sample's radius and angle in the plane and W its offset in the other axes from the start,
    rho^2 + r(t)^2 - 2 r(t) rho cos(t - tq) + |W - (t / span) D|^2."""
    u, v, cu, cv, r0, th0, sweep, r1 = e.arc
    span = abs(sweep)
    sgn = 1 if sweep >= 0 else -1
    rho = math.hypot(q[u] - cu, q[v] - cv)
    tq = sgn * (math.atan2(q[v] - cv, q[u] - cu) - th0)
    others = [k for k in range(len(q)) if k not in (u, v)]
    D = [e.end[k] - e.start[k] for k in others]
    W = [q[k] - e.start[k] for k in others]

    def f2(t):
        g = t / span
        r = r0 + (r1 - r0) * g
        lin = 0.0
        for w, d in zip(W, D):
            lin += (w - g * d) ** 2
        return rho * rho + r * r - 2 * r * rho * math.cos(t - tq) + lin

    n = max(8, math.ceil(span / (math.pi / 16)))
    step = span / n
    grid = [f2(i * step) for i in range(n + 1)]
    out = [(math.dist(q, e.point(0.0)), 0.0), (math.dist(q, e.point(1.0)), 1.0)]
    # Every local minimum of the grid is refined: two can tie on the grid while only one holds
    # the true minimum (a sample just before a full circle's end: the grid points either side of
    # it are as near as the start).
    for k in range(n + 1):
        if (k > 0 and grid[k] > grid[k - 1]) or (k < n and grid[k] > grid[k + 1]):
            continue
        t = _golden(f2, max(0.0, (k - 1) * step), min(span, (k + 1) * step))
        out.append((math.dist(q, e.point(t / span)), t / span))
    return out


def _golden(f, lo, hi):
    g = 0.6180339887498949
    a, b = hi - g * (hi - lo), lo + g * (hi - lo)
    fa, fb = f(a), f(b)
    for _ in range(40):
        if fa < fb:
            hi, b, fb = b, a, fa
            a = hi - g * (hi - lo)
            fa = f(a)
        else:
            lo, a, fa = a, b, fb
            b = lo + g * (hi - lo)
            fb = f(b)
    return (lo + hi) / 2


def nearest_points(e, q):
    return _arc_points(e, q) if e.arc else _line_points(e, q)


def distance(e, q):
    return min(d for d, _ in nearest_points(e, q))


# The part of the path a sample is compared with: from BACK_MM behind the farthest point
# reached so far to AHEAD_MM ahead of it (a period moves the tool 0.2 mm at most; a blend
# belongs to two elements and can cut across short ones). Among points of the path equally
# near the sample (within the trace's resolution: a path through the same point twice, a full
# circle's start and end), the one that continues from the last sample's without going back
# counts. So the trace is matched to the path in order: a trace that goes back along its path by
# more than BACK_MM, or skips ahead, is measured from the wrong part of it and fails.
BACK_MM = 3.0
AHEAD_MM = 2.0


def _tolerance(els, i):
    """The blend tolerance along element i: the larger of its two corners' (a blend belongs to
    both moves, and an offset corner shifts the tool along the move before it)."""
    return max(els[i].tol_end_mm, els[i - 1].tol_end_mm if i > 0 else 0.0)


# On top of the rounding of the printed numbers: a long helix at tolerance 0 (soak seed 10, R56.8,
# Z 92.8 mm) had samples 0.98e-6 mm from it where the rounding explains 0.87e-6; the remaining
# 1e-7 mm was not traced (the soak's model or the planner's arithmetic). 1 nm is allowed for it.
ARITHMETIC_MM = 1e-6


def _allowed(els, i, axes):
    return (_tolerance(els, i) * (1 + REL) + els[i].extra_mm + math.sqrt(axes) * QUANTUM / 2
            + ARITHMETIC_MM)


def _pick(els, cum, indices, q, s_max, axes):
    """(excess, distance, path position s, element, element of the least excess) of the point of
    the path within the window about s_max that the sample is nearest to relative to its
    allowance (excess = distance - allowed there: a sample near two elements needs to be within
    the tolerance of one of them); None if every element lies outside the window. A nearest
    point outside the window is replaced by the window's end on that element. The sample passes
    when the least excess is <= 0; the path position is the nearest point's."""
    cands = []
    for i in indices:
        e = els[i]
        lo, hi = max(s_max - BACK_MM, cum[i]), min(s_max + AHEAD_MM, cum[i + 1])
        if lo > hi:
            continue  # the element lies outside the window
        allowed = _allowed(els, i, axes)
        for d, f in nearest_points(e, q):
            s = cum[i] + f * e.length_mm
            if not lo <= s <= hi:
                s = min(hi, max(lo, s))
                d = math.dist(q, e.point((s - cum[i]) / e.length_mm))
            cands.append((d - allowed, d, s, i))
    if not cands:
        return None
    best = min(cands)
    # Where the tool is on the path: the nearest point (ties, within the trace's resolution, to
    # the farthest along: a move reversing onto the one before). Not the farthest of the points
    # within their allowance: that ratchets ahead of the tool by up to the window each sample.
    dmin = min(c[1] for c in cands)
    _, _, s, i = max((c for c in cands if c[1] <= dmin + QUANTUM), key=lambda c: c[2])
    return best[0], best[1], s, i, best[3]


def _lines_near(els, cum, s):
    """The program lines a sample at path position s may be tagged with: those of the elements
    within BACK_MM behind and AHEAD_MM ahead, and the lines between them that do not move
    (modes, dwells, the end), so a line number from elsewhere in the program fails."""
    lo = max(0, bisect.bisect_left(cum, s - BACK_MM) - 1)
    hi = min(len(els) - 1, bisect.bisect_right(cum, s + AHEAD_MM))
    return (els[lo].line if lo > 0 else 0, els[hi].line if hi < len(els) - 1 else math.inf)


def check_path(tr, model):
    els = model.elements
    if not els:
        return None
    cum = [0.0]
    for e in els:
        cum.append(cum[-1] + e.length_mm)
    cur, s_max = 0, 0.0
    axes = len(els[0].start)
    for n, q in enumerate(tr.axes):
        pick = _pick(els, cum, [k for k in (cur, cur + 1) if k < len(els)], q, s_max, axes)
        if pick is None or pick[0] > 0:
            lo = max(0, bisect.bisect_left(cum, s_max - BACK_MM) - 1)
            hi = min(len(els), bisect.bisect_right(cum, s_max + AHEAD_MM) + 1)
            pick = _pick(els, cum, range(lo, hi), q, s_max, axes)
        excess, d, s, i, nearest = pick
        cur, s_max = i, max(s_max, s)
        if excess > 0:
            i = nearest
            return Failure("path", f"{d:.6f} mm from the programmed path (tolerance {_tolerance(els, i)} mm) "
                                   f"near program line {els[i].line}", tr.line[n], tr.t[n])
        lines = _lines_near(els, cum, s)
        if not lines[0] <= tr.line[n] <= lines[1]:
            return Failure("line-tag", f"the trace says line {tr.line[n]} where the tool is on the path of "
                                       f"line {els[i].line} (lines {lines[0]}..{lines[1]} lie within "
                                       f"{BACK_MM} mm behind, {AHEAD_MM} mm ahead)", tr.line[n], tr.t[n])
    if s_max < cum[-1] - AHEAD_MM:
        return Failure("path", f"the trace covered the path only up to {s_max:.3f} mm of its {cum[-1]:.3f} mm",
                       tr.line[-1], tr.t[-1])
    last = els[-1]
    if math.dist(tr.axes[-1], last.end) > 1e-4:
        return Failure("path", f"the trace ends at {tr.axes[-1]}, not at the program's last point {last.end}",
                       tr.line[-1], tr.t[-1])
    return None


def check_run(rc, stdout, stderr, trace_path, model, machine):
    """Every check, in order; the first failure or None."""
    for f in (lambda: check_exit(rc, stdout), lambda: check_stderr(stderr, machine),
              lambda: check_end_point(stdout, model, machine)):
        failure = f()
        if failure:
            return failure
    tr = read_trace(trace_path, machine)
    if not tr.t:
        return Failure("trace", "the trace is empty")
    start = [0.0] * len(machine.letters)
    for f in (lambda: check_numbers(tr), lambda: check_lines(tr),
              lambda: check_axis_limits(tr, machine, start), lambda: check_joint_limits(tr, machine),
              lambda: check_path(tr, model)):
        failure = f()
        if failure:
            return failure
    return None
