"""The soak's programs: a seeded generator of valid G-code for a sim config, and the soak's own
model of what such a program asks for (the path as lines and arcs, the blend tolerance at each
corner, the end point), computed from the program text without the project's interpreter, so
that a mistake of the interpreter shows as a difference.

The model covers only the subset the generator writes (absolute mm, NcStudio dialect):
G0 G1 G2 G3 (I J K or R; helices), G17 G18 G19, G61, G64 [P], G09, G04 P (milliseconds), F
(mm/min), A and C on 5-axis machines, M30 / M2. G0 is split as the NcStudio dialect does
(docs/interp.md, G00-2): Z first when it rises, last when it falls."""

import dataclasses
import math
import random
import re

from machine import workspace

TWO_PI = 2 * math.pi
WORD = re.compile(r"([A-Z])\s*([-+]?(?:\d+\.?\d*|\.\d+))")


class ProgramError(Exception):
    """A line the model refuses (the generator never writes one; shrinking can make one)."""


@dataclasses.dataclass
class Element:
    """One piece of the programmed path, in the trace's axis order (mm, degrees for A C)."""
    line: int  # 1-based program line
    start: list
    end: list
    tol_end_mm: float  # blend tolerance of the corner at its end; 0 = exact stop there
    rapid: bool
    feed_mm_s: float
    # (u, v, cu, cv, radius at the start, theta0, sweep, radius at the end) for arcs and helices
    arc: tuple = None
    length_mm: float = 0.0
    extra_mm: float = 0.0  # allowance on top of the tolerance (an arc end off its circle)
    dir: list = None  # end - start, cached by the path check
    inv_dd: float = 0.0

    def point(self, f):
        """The point at fraction f of the element (0..1)."""
        p = [s + (e - s) * f for s, e in zip(self.start, self.end)]
        if self.arc:
            u, v, cu, cv, r0, th0, sweep, r1 = self.arc
            th = th0 + sweep * f
            r = r0 + (r1 - r0) * f
            p[u] = cu + r * math.cos(th)
            p[v] = cv + r * math.sin(th)
        return p


def fmt_num(x):
    s = f"{x:.4f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def round4(x):
    return float(fmt_num(x))


class Model:
    """Runs the subset: feed it program lines one by one (step), read the elements and state."""

    PLANES = {17: (0, 1, 2), 18: (2, 0, 1), 19: (1, 2, 0)}  # (first, second, normal) as interp/

    def __init__(self, letters, default_tol_mm):
        self.letters = letters
        self.pos = [0.0] * len(letters)
        self.plane = 17
        self.motion = 0
        self.feed_mm_min = None
        self.default_tol = default_tol_mm
        self.tol = default_tol_mm
        self.elements = []
        self.ended = False
        self.line_no = 0

    def step(self, text):
        self.line_no += 1
        words = self._words(text)
        g9 = False
        dwell = None
        f_word = None
        for letter, value in words:
            if letter == "G":
                code = round(value)
                if code in (0, 1, 2, 3):
                    self.motion = code
                elif code in self.PLANES:
                    self.plane = code
                elif code == 61:
                    self.tol = 0.0
                elif code == 64:
                    p = dict(words).get("P", 0.0)
                    self.tol = p if p > 0 else self.default_tol
                elif code == 9:
                    g9 = True
                elif code == 4:
                    dwell = dict(words).get("P")
                elif code not in (21, 90, 40, 49, 80, 54):
                    raise ProgramError(f"line {self.line_no}: G{code} outside the soak's subset")
            elif letter == "F":
                f_word = value
            elif letter == "M":
                if round(value) in (2, 30):
                    self.ended = True
                    self._stop_here()
        if f_word is not None:
            # An F in a block whose motion mode is G00 is the rapid speed (FEATURES G00-3; a bare
            # F while G00 is modal too, and it is the feed as well while no feed was set).
            if self.motion != 0 or self.feed_mm_min is None:
                self.feed_mm_min = f_word
        targets = {l.lower(): v for l, v in words if l.lower() in self.letters}
        centre = {l: v for l, v in words if l in "IJK"}
        radius = dict(words).get("R")
        if dwell is not None:
            self._stop_here()
            return
        if not targets and not centre:
            return
        end = list(self.pos)
        for l, v in targets.items():
            end[self.letters.index(l)] = v
        before = len(self.elements)
        if self.motion in (0, 1):
            self._line(end, rapid=self.motion == 0)
        else:
            self._arc(end, centre, radius, ccw=self.motion == 3)
        if g9 and len(self.elements) > before:
            self.elements[-1].tol_end_mm = 0.0
        self.pos = end

    def _words(self, text):
        code = re.sub(r"\(.*?\)", "", text.split(";")[0]).upper()
        if code.strip() in ("", "%"):
            return []
        words = [(m.group(1), float(m.group(2))) for m in WORD.finditer(code)]
        if not words and code.strip():
            raise ProgramError(f"line {self.line_no}: cannot read {text!r}")
        return words

    def _stop_here(self):
        if self.elements:
            self.elements[-1].tol_end_mm = 0.0

    def _feed(self):
        if self.feed_mm_min is None or self.feed_mm_min <= 0:
            raise ProgramError(f"line {self.line_no}: feed move without F")
        return self.feed_mm_min / 60.0

    def _push(self, start, end, rapid, arc=None, length=None):
        if length is None:
            length = math.dist(start, end)
        if length < 1e-9:
            return
        self.elements.append(Element(self.line_no, list(start), list(end), self.tol, rapid,
                                     0.0 if rapid else self._feed(), arc, length))

    def _line(self, end, rapid):
        start = self.pos
        z = self.letters.index("z")
        others = any(abs(e - s) > 1e-9 for k, (s, e) in enumerate(zip(start, end)) if k != z)
        dz = end[z] - start[z]
        if rapid and abs(dz) > 1e-9 and others:
            mid = list(start) if dz > 0 else list(end)
            mid[z] = end[z] if dz > 0 else start[z]
            self._push(start, mid, True)
            start = mid
        if not rapid:
            self._feed()
        self._push(start, end, rapid)

    def _arc(self, end, centre, radius, ccw):
        u, v, _ = self.PLANES[self.plane]
        if max(u, v) > 2:
            raise ProgramError(f"line {self.line_no}: arc plane outside XYZ")
        s = self.pos
        su, sv, eu, ev = s[u], s[v], end[u], end[v]
        letter_u, letter_v = "IJK"[u], "IJK"[v]
        if radius is not None:
            if centre:
                raise ProgramError(f"line {self.line_no}: arc has both R and I/J/K")
            cu, cv = self._centre_from_radius(su, sv, eu, ev, radius, ccw)
        else:
            cu = su + centre.get(letter_u, 0.0)
            cv = sv + centre.get(letter_v, 0.0)
        r0 = math.hypot(su - cu, sv - cv)
        r1 = math.hypot(eu - cu, ev - cv)
        # The interpreter accepts an end up to 0.01 mm off the circle (FEATURES ARC-11); the
        # planner refuses more than max(0.005, 0.1 % of the radius). The programmed path is then
        # the arc about the programmed centre whose radius goes from the start's to the end's
        # (LinuxCNC's spiral). A planner may realise it otherwise: ours moves the centre onto the
        # chord's bisector, which for the rounding of 4 decimals moves the path by a few
        # 1e-5 mm, but for an end near the start by much more (docs/soak.md, finding 2). The
        # check allows that difference, up to 1 um (extra_mm).
        if r0 < 1e-9 or abs(r1 - r0) > max(0.005, 1e-3 * r0):
            raise ProgramError(f"line {self.line_no}: arc end not on the circle ({r0} vs {r1})")
        th0 = math.atan2(sv - cv, su - cu)
        sweep = math.atan2(ev - cv, eu - cu) - th0
        if ccw and sweep <= 1e-12:
            sweep += TWO_PI
        if not ccw and sweep >= -1e-12:
            sweep -= TWO_PI
        rest = math.sqrt(sum((e - b) ** 2 for k, (b, e) in enumerate(zip(s, end)) if k not in (u, v)))
        self._push(s, end, False, (u, v, cu, cv, r0, th0, sweep, r1), math.hypot((r0 + r1) / 2 * sweep, rest))
        if abs(r1 - r0) > 1e-12:
            el = self.elements[-1]
            el.extra_mm = abs(r1 - r0) + min(1e-3, _bisector_offset(el, su, sv, eu, ev))

    def _centre_from_radius(self, su, sv, eu, ev, radius, ccw):
        chord = math.hypot(eu - su, ev - sv)
        r = abs(radius)
        if chord < 1e-9 or chord > 2 * r + 0.01:
            raise ProgramError(f"line {self.line_no}: R arc impossible (chord {chord}, R {radius})")
        h = math.sqrt(max(0.0, r * r - chord * chord / 4))
        mu, mv = (su + eu) / 2, (sv + ev) / 2
        # Left of the chord for a short CCW arc (R > 0) and a long CW one (R < 0).
        left = ccw == (radius > 0)
        nu, nv = -(ev - sv) / chord, (eu - su) / chord
        sign = 1 if left else -1
        return mu + sign * h * nu, mv + sign * h * nv


def _bisector_offset(el, su, sv, eu, ev):
    """How far the arc with its centre moved onto the chord's perpendicular bisector (as
    motion/src/geometry.cpp does) lies from the element's spiral, over 256 points along both."""
    u, v, cu, cv, r0, th0, sweep, r1 = el.arc
    chord_u, chord_v = eu - su, ev - sv
    chord = math.hypot(chord_u, chord_v)
    if chord < 1e-9:
        return 0.0
    mu, mv = (su + eu) / 2, (sv + ev) / 2
    nu, nv = -chord_v / chord, chord_u / chord
    t = (cu - mu) * nu + (cv - mv) * nv
    bu, bv = mu + t * nu, mv + t * nv
    rb = math.hypot(su - bu, sv - bv)
    b0 = math.atan2(sv - bv, su - bu)
    b_sweep = math.atan2(ev - bv, eu - bu) - b0
    if sweep > 0 and b_sweep <= 1e-12:
        b_sweep += TWO_PI
    if sweep < 0 and b_sweep >= -1e-12:
        b_sweep -= TWO_PI
    worst = 0.0
    for k in range(257):
        f = k / 256
        p = el.point(f)
        # Distance of the planner's point at the same fraction from the spiral, and back, in
        # the plane (the other axes move alike in both).
        a = b0 + b_sweep * f
        q = (bu + rb * math.cos(a), bv + rb * math.sin(a))
        worst = max(worst, abs(math.hypot(q[0] - cu, q[1] - cv) - (r0 + (r1 - r0) * f)),
                    abs(math.hypot(p[u] - bu, p[v] - bv) - rb))
    return worst


def model_of(lines, machine):
    m = Model(machine.letters, machine.blend_tolerance_mm)
    for text in lines:
        m.step(text)
    return m


class Generator:
    """Writes a random valid program for one machine, line by line, keeping the tool in the
    workspace; the model follows every line, so the generator knows where it is."""

    TOLERANCES = (0.001, 0.005, 0.01, 0.02, 0.05, 0.1, 0.5)
    ANGLES_DEG = (0.05, 0.5, 2, 10, 30, 45, 60, 89, 90, 91, 120, 150, 170, 178, 179.5, 180)
    MAX_MOVE_S = 0.4

    def __init__(self, machine, seed, arc_end_off=0.0):
        self.m = machine
        self.arc_end_off = arc_end_off
        self.rng = random.Random(seed)
        self.box = workspace(machine)
        self.model = Model(machine.letters, machine.blend_tolerance_mm)
        self.lines = []
        self.feed = 1200.0
        self.lin = [l for l in machine.letters if machine.linear(l)]
        self.rot = [l for l in machine.letters if l in "ac"]
        self.pending_feed = False

    def emit(self, text):
        self.lines.append(text)
        self.model.step(text)

    def p(self, letter):
        return self.model.pos[self.m.letters.index(letter)]

    def inside(self, pt):
        return all(self.box[l][0] <= pt[l] <= self.box[l][1] for l in pt)

    def words(self, pt):
        return " ".join(f"{l.upper()}{fmt_num(v)}" for l, v in pt.items())

    def random_point(self, letters=None):
        return {l: round4(self.rng.uniform(*self.box[l])) for l in (letters or self.lin)}

    def length(self, lo=1e-4, hi=150.0):
        return math.exp(self.rng.uniform(math.log(lo), math.log(hi)))

    def direction(self):
        kind = self.rng.random()
        if kind < 0.3:  # along one axis
            d = {l: 0.0 for l in self.lin}
            d[self.rng.choice(self.lin)] = self.rng.choice((-1.0, 1.0))
            return d
        dims = self.lin if kind < 0.65 else self.rng.sample(self.lin, 2)
        while True:
            d = {l: self.rng.gauss(0, 1) for l in dims}
            n = math.sqrt(sum(x * x for x in d.values()))
            if n > 1e-3:
                return {l: x / n for l, x in d.items()}

    def rotate_towards(self, d, angle_deg):
        """A unit direction at angle_deg from d (linear axes)."""
        while True:
            w = {l: self.rng.gauss(0, 1) for l in d}
            dot = sum(w[l] * d[l] for l in d)
            w = {l: w[l] - dot * d[l] for l in d}
            n = math.sqrt(sum(x * x for x in w.values()))
            if n > 1e-3:
                break
        a = math.radians(angle_deg)
        return {l: math.cos(a) * d[l] + math.sin(a) * w[l] / n for l in d}

    def cap_length(self, length, feed_mm_min):
        return min(length, feed_mm_min / 60.0 * self.MAX_MOVE_S)

    def line_to(self, d, length, code="G1", extra=""):
        """A move of about `length` along d, shortened to stay inside; False if none fits."""
        here = {l: self.p(l) for l in d}
        for _ in range(8):
            pt = {l: round4(here[l] + d[l] * length) for l in d}
            if self.inside(pt):
                moved = {l: v for l, v in pt.items() if v != here[l] or self.rng.random() < 0.2}
                if not moved:
                    moved = pt
                feed = self.feed_word() if code == "G1" else ""
                self.emit(f"{code}{extra} {self.words(moved)}{feed}".replace("  ", " "))
                return True
            length /= 3
        return False

    # The kinds of step; each writes one or a few lines.
    def step_rapid(self):
        letters = self.rng.sample(self.lin, self.rng.randint(1, len(self.lin)))
        # Now and then a rapid speed of its own (F in a G00 block, FEATURES G00-3), also above
        # the machine's (clamped there).
        rapid_f = f" F{fmt_num(round(self.length(600, 12000), 1))}" if self.rng.random() < 0.1 else ""
        self.emit(f"G0 {self.words(self.random_point(letters))}{rapid_f}")

    def step_line(self):
        self.maybe_feed()
        length = self.cap_length(self.length(), self.feed)
        self.line_to(self.direction(), length)

    def step_corner(self):
        self.maybe_feed()
        d = self.direction()
        angle = self.rng.choice(self.ANGLES_DEG) if self.rng.random() < 0.7 else self.rng.uniform(0, 180)
        self.line_to(d, self.cap_length(self.length(0.05, 40), self.feed))
        self.line_to(self.rotate_towards(d, angle), self.cap_length(self.length(0.05, 40), self.feed))

    def step_polyline(self):
        """A curve as CAM writes it: many short lines turning a little each."""
        self.maybe_feed()
        d = self.direction()
        seg = self.length(1e-3, 2.0)
        turn = self.rng.choice((0.5, 2, 5, 15))
        for _ in range(self.rng.randint(3, 25)):
            if not self.line_to(d, seg * self.rng.uniform(0.5, 1.5)):
                break
            d = self.rotate_towards(d, self.rng.uniform(0, turn))

    def set_plane(self):
        plane = self.rng.choice((17, 17, 18, 19))
        if plane != self.model.plane or self.rng.random() < 0.2:
            self.emit(f"G{plane}")
        return Model.PLANES[plane]

    def arc_common(self):
        """Plane, start, centre, radius, direction (counter-clockwise?) and start angle of an arc
        whose whole circle fits in the workspace."""
        u, v, n = self.set_plane()
        lu, lv, ln = "xyz"[u], "xyz"[v], "xyz"[n]
        su, sv = self.p(lu), self.p(lv)
        r_max = min(60.0, (self.box[lu][1] - self.box[lu][0]) / 2.2, (self.box[lv][1] - self.box[lv][0]) / 2.2)
        for _ in range(20):
            r = self.length(0.05, r_max)
            phi = self.rng.uniform(0, TWO_PI)
            cu, cv = round4(su - r * math.cos(phi)), round4(sv - r * math.sin(phi))
            r = math.hypot(su - cu, sv - cv)
            fits = (self.box[lu][0] <= cu - r and cu + r <= self.box[lu][1] and
                    self.box[lv][0] <= cv - r and cv + r <= self.box[lv][1])
            if fits and r > 0.02:
                ccw = self.rng.random() < 0.5
                return (lu, lv, ln), (su, sv), (cu, cv), r, ccw, math.atan2(sv - cv, su - cu)
        return None

    def helix_end(self, ln, arc_len):
        if self.rng.random() < 0.6:
            return {}
        lo, hi = self.box[ln]
        here = self.p(ln)
        dz = self.rng.uniform(-1, 1) * min(arc_len, 20.0)
        return {ln: round4(min(hi, max(lo, here + dz)))}

    def arc_feed(self, arc_len):
        self.maybe_feed()
        if arc_len / (self.feed / 60.0) > self.MAX_MOVE_S:
            self.set_feed(max(self.feed, min(6000.0, arc_len / self.MAX_MOVE_S * 60.0)))

    def step_arc(self, by_radius=False, full=False):
        found = self.arc_common()
        if not found:
            return
        (lu, lv, ln), (su, sv), (cu, cv), r, ccw, th0 = found
        if full:
            sweep = TWO_PI
        elif by_radius:
            sweep = self.rng.uniform(0.02, 0.95 * math.pi) if self.rng.random() < 0.5 else \
                self.rng.uniform(1.05 * math.pi, 1.9 * math.pi)
        else:
            sweep = self.rng.uniform(0.001, 1.9 * math.pi)
        th1 = th0 + (sweep if ccw else -sweep)
        end = {} if full else {lu: round4(cu + r * math.cos(th1)), lv: round4(cv + r * math.sin(th1))}
        if not full and math.hypot(end[lu] - su, end[lv] - sv) < 2e-4:
            return
        self.arc_feed(r * sweep)
        end.update(self.helix_end(ln, r * sweep))
        code = "G3" if ccw else "G2"
        if by_radius:
            chord = math.hypot(end[lu] - su, end[lv] - sv)
            if chord > 1.9 * r:  # nearly a half circle: R is ill-conditioned there
                return
            rr = round4(r if sweep <= math.pi else -r)
            self.emit(f"{code} {self.words(end)} R{fmt_num(rr)}{self.feed_word()}")
        else:
            i, j = "IJK"["xyz".index(lu)], "IJK"["xyz".index(lv)]
            self.emit(f"{code} {self.words(end)} {i}{fmt_num(cu - su)} {j}{fmt_num(cv - sv)}{self.feed_word()}"
                      .replace("  ", " "))

    def step_arc_off(self):
        """An I J arc whose end is off its circle by up to arc_end_off mm (the interpreter and the
        planner accept max(0.01 mm, 0.1 % of the radius)), half of them nearly full circles (end
        within a few degrees of the start, which the planner refuses when the circle through
        both ends would leave the programmed one: docs/soak.md, finding 2)."""
        found = self.arc_common()
        if not found:
            return
        (lu, lv, ln), (su, sv), (cu, cv), r, ccw, th0 = found
        sweep = self.rng.uniform(1.97, 1.9999) * math.pi if self.rng.random() < 0.5 else \
            self.rng.uniform(0.3, 1.9) * math.pi
        th1 = th0 + (sweep if ccw else -sweep)
        off = min(self.arc_end_off, 0.99 * max(0.01, 1e-3 * r)) * self.rng.uniform(0.3, 1.0)
        r_end = r + self.rng.choice((-1, 1)) * off
        end = {lu: round4(cu + r_end * math.cos(th1)), lv: round4(cv + r_end * math.sin(th1))}
        if abs(math.hypot(end[lu] - cu, end[lv] - cv) - r) > 0.99 * max(0.005, 1e-3 * r):
            return
        self.arc_feed(r * sweep)
        i, j = "IJK"["xyz".index(lu)], "IJK"["xyz".index(lv)]
        code = "G3" if ccw else "G2"
        self.emit(f"{code} {self.words(end)} {i}{fmt_num(cu - su)} {j}{fmt_num(cv - sv)}{self.feed_word()}")

    def step_mode(self):
        r = self.rng.random()
        if r < 0.25:
            self.emit("G61")
        elif r < 0.4:
            self.emit("G64")
        else:
            self.emit(f"G64 P{fmt_num(self.rng.choice(self.TOLERANCES))}")

    def step_exact_stop(self):
        self.maybe_feed()
        self.line_to(self.direction(), self.cap_length(self.length(0.01, 50), self.feed), extra=" G09")

    def step_dwell(self):
        self.emit(f"G04 P{self.rng.choice((1, 5, 20, 100, 250))}")

    def set_feed(self, f):
        """The feed of the next feed move: F goes into that move's block, as a bare F while G00
        is modal would set the rapid speed instead (FEATURES G00-3)."""
        self.feed = round(f, 1)
        self.pending_feed = True

    def feed_word(self):
        if not self.pending_feed:
            return ""
        self.pending_feed = False
        return f" F{fmt_num(self.feed)}"

    def maybe_feed(self):
        if self.rng.random() < 0.25:
            self.set_feed(self.length(30, 9000))

    def step_rotary(self):
        """A and C on the table-tilting machine: alone, or with a short linear move, rapid or fed
        (up to 9000 mm/min: the planner keeps the motors within their velocity limits under this
        kinematics, docs/components/motion.md)."""
        if not self.rot:
            return self.step_line()
        letters = self.rng.sample(self.rot, self.rng.randint(1, len(self.rot)))
        target = {}
        for l in letters:
            lo, hi = self.box[l]
            target[l] = round4(min(hi, max(lo, self.p(l) + self.rng.uniform(-1, 1) * self.length(0.01, 120))))
        if self.rng.random() < 0.3:
            self.emit(f"G0 {self.words(target)}")
            return
        if self.rng.random() < 0.5:
            self.set_feed(self.length(30, 9000))
        if self.rng.random() < 0.4:
            d = self.direction()
            step = self.length(0.01, 20)
            here = {l: self.p(l) for l in d}
            pt = {l: round4(here[l] + d[l] * step) for l in d}
            if self.inside(pt):
                target.update(pt)
        self.emit(f"G1 {self.words(target)}{self.feed_word()}")

    STEPS = (("rapid", 8), ("line", 20), ("corner", 14), ("polyline", 8), ("arc", 10),
             ("arc_r", 7), ("circle", 3), ("mode", 8), ("exact_stop", 4), ("dwell", 3),
             ("feed", 5), ("rotary", 10), ("arc_off", 6))

    def run_step(self, kind):
        {
            "rapid": self.step_rapid,
            "line": self.step_line,
            "corner": self.step_corner,
            "polyline": self.step_polyline,
            "arc": self.step_arc,
            "arc_r": lambda: self.step_arc(by_radius=True),
            "circle": lambda: self.step_arc(full=True),
            "mode": self.step_mode,
            "exact_stop": self.step_exact_stop,
            "dwell": self.step_dwell,
            "feed": lambda: self.set_feed(self.length(30, 9000)),
            "rotary": self.step_rotary,
            "arc_off": self.step_arc_off,
        }[kind]()

    def generate(self, steps):
        self.emit("G90 G21 G17 G64")
        self.set_feed(self.length(300, 6000))
        self.emit(f"G0 {self.words(self.random_point())}")
        kinds, weights = [], []
        for k, w in self.STEPS:
            if (k != "rotary" or self.rot) and (k != "arc_off" or self.arc_end_off > 0):
                kinds.append(k)
                weights.append(w)
        for _ in range(steps):
            self.run_step(self.rng.choices(kinds, weights)[0])
        self.emit(self.rng.choice(("M30", "M2")))
        return self.lines


def generate(machine, seed, steps=30, arc_end_off=0.0):
    return Generator(machine, seed, arc_end_off).generate(steps)
