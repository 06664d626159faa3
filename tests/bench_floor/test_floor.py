#!/usr/bin/python3
"""Tests of bench/floor/floor.py, the numerical floor for sections (docs/benchmarks.md, "A
numerical floor for sections"). Run one case: test_floor.py BENCH_MOTION_BINARY TestFloor.NAME

The expected values are worked out by hand below; the soundness cases pin the MILP's samples to
our planner's trace (a real motion that keeps the contract) and require it to be feasible.
"""
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "bench", "floor"))
try:
    import numpy as np
    import floor  # noqa: E402
except SystemExit as e:  # floor.py exits with the install hint when SciPy is missing
    print(e, file=sys.stderr)
    sys.exit(1)

BENCH_MOTION = None  # set from argv
A = 1000.0
V = 100.0
P = 0.01


def write_program(text):
    fd, path = tempfile.mkstemp(suffix=".ngc", prefix="floor_test_")
    with os.fdopen(fd, "w") as f:
        f.write(text)
    return path


def floor_of(text, first, last, step_ms, **kw):
    path = write_program(text)
    try:
        moves = floor.parse_program(path)
        a, b = floor.section_vertices(moves, first, last)
        return floor.section_floor(moves, a, b, step_ms=step_ms, **kw)
    finally:
        os.unlink(path)


def model_of(text, first, last, step_ms, horizon_s, lead=25, group_deg=0.0, reach=False):
    path = write_program(text)
    try:
        moves = floor.parse_program(path)
    finally:
        os.unlink(path)
    a, b = floor.section_vertices(moves, first, last)
    return floor.make_model(moves, a, b, V, A, step_ms, lead, lead, horizon_s,
                            group_turn_deg=group_deg, reach_vertices=reach), moves


# tp_default's opening: a hop up and back down to where the row starts.
HOP = "G21 G90\nG0 Z1\nG1 Z0 F600\nG1 X1 F3000\nM2\n"


class TestFloor(unittest.TestCase):
    def test_line_rest_to_rest_is_the_discrete_bang_bang(self):
        # G1 X4 at 100 mm/s from rest to rest: T* = 2 sqrt(L / A) = 0.12649 s (peak 63 mm/s,
        # below V). With steps d_j = q_(j+1) - q_j, j = 0..N (q_0 = 0, q_(N+1) = L, rest on
        # both sides), |d_j - d_(j-1)| <= A h^2 gives d_j <= A h^2 min(j + 1, N + 1 - j), whose
        # sum over M = N + 1 terms is A h^2 p (p + 1) for M = 2p and A h^2 (p + 1)^2 for
        # M = 2p + 1. At h = 2 ms, A h^2 = 0.004 mm: N = 61 (M = 62, p = 31) reaches
        # 0.004 * 992 = 3.968 < 4 mm, N = 62 (M = 63) reaches 0.004 * 1024 = 4.096 mm. So the
        # floor is exactly 62 h = 0.124 s, inside [T* - 2h, T*] = [0.1225, 0.1265].
        res = floor_of("G21 G90\nG1 X4 F6000\nM2\n", 2, 2, 2.0)
        self.assertEqual(res.samples_proved, 62)
        self.assertAlmostEqual(res.floor_s, 0.124, places=9)
        self.assertLessEqual(res.floor_s, 2 * math.sqrt(4 / A))
        self.assertGreaterEqual(res.floor_s, 2 * math.sqrt(4 / A) - 2 * 2e-3)

    def test_line_at_feed_is_length_over_feed_plus_ramps(self):
        # G1 X10 F1800 (30 mm/s): T* = L / F + F / A = 0.33333 + 0.03 = 0.36333 s. Discretely
        # d_j <= min(A h^2 min(j + 1, N + 1 - j), F h) with F h = 0.06 mm = 15 A h^2: the two
        # ramps hold 0.004 (1 + ... + 14) = 0.42 mm each and the M - 28 middle steps 0.06 mm
        # each: 0.84 + 0.06 (M - 28) >= 10 needs M >= 180.67, so N = M - 1 >= 180: 0.360 s,
        # inside [T* - 2h, T*].
        res = floor_of("G21 G90\nG1 X10 F1800\nM2\n", 2, 2, 2.0)
        self.assertEqual(res.samples_proved, 180)
        self.assertAlmostEqual(res.floor_s, 0.360, places=9)

    def test_right_angle_corner_is_not_weaker_than_the_analytic_bound_by_more_than_the_grid(self):
        # X4 then Y4 at F3000 (50 mm/s), P0.01. The analytic bound's argument
        # (RightAngleCornerIsTwoRampsToSqrt4AP in tests/bench_motion/test_accel_bound.cpp):
        # each axis passes the corner at most at c = sqrt(4 A P) = 6.3246 mm/s, each line
        # ramps from rest to F and down to c, and the corner square costs 2P of length:
        #   2 (F / A + (F - c) / A) + (2L - 2P - 2 (F^2 / 2A + (F^2 - c^2) / 2A)) / F
        # = 0.24775 s (bench_motion prints the same bound, 0.248 s, for this program). The
        # discrete relaxation is a different argument, neither is below the other by
        # construction; both lose to the grid. The rest-to-rest line loses at most 2h, and the
        # corner may lose a little more (samples straddle the corner region): horizon
        # hand - 2h - 1 ms must already be infeasible.
        c, F, L = math.sqrt(4 * A * P), 50.0, 4.0
        hand = 2 * (F / A + (F - c) / A) + (2 * L - 2 * P - 2 * (F * F / (2 * A) +
                                                                  (F * F - c * c) / (2 * A))) / F
        self.assertAlmostEqual(hand, 0.24775, places=5)
        h = 2e-3
        u = int(math.floor((hand - 2 * h - 1e-3) / h))
        model, _ = model_of("G21 G90\nG1 X4 F3000\nG1 Y4\nM2\n", 2, 3, 2.0, u * h)
        res = model.solve(time_limit_s=60, feasibility=True)
        self.assertEqual(res.status, "infeasible in horizon", f"horizon {u * h:.3f} s")

    def test_hop_is_free_under_the_path_contract_but_not_when_vertices_are_reached(self):
        # HOP from rest at the origin, section lines 2-3 (G0 Z1, G1 Z0 F600) ending at the
        # origin, where the X line starts. The path-distance contract lets the tool stay at the
        # origin (the hop retraces itself): a 12 ms horizon is feasible. Reaching vertices:
        # while G1 Z0 is the current move the tool is within P of its start along it, z >= 0.99
        # at some instant tau' >= t_2; at t_3 it is in the corner region with the X line, so
        # z <= P = 0.01; in between it is on the F600 move, at most 10 mm/s: t_3 - tau' >=
        # 0.98 / 10 = 98 ms. Before tau' it climbed from rest at z = 0 to 0.99 with |z''| <= A:
        # tau' >= sqrt(2 * 0.99 / A) = 44.50 ms. So t_3 - t_a >= 142.50 ms. At h = 4 ms (2 ms
        # costs HiGHS ten times the CPU) the grid may lose 2h and a little at the turn: 132 ms
        # must already be infeasible.
        h = 4e-3
        model, _ = model_of(HOP, 2, 3, 4.0, 3 * h, lead=10)
        self.assertEqual(model.solve(time_limit_s=60, feasibility=True).status, "feasible")
        hand = math.sqrt(2 * (1 - P) / A) + (1 - 2 * P) / 10.0
        self.assertAlmostEqual(hand, 0.14250, places=5)
        u = int(math.floor((hand - 2 * h - 1e-3) / h))
        self.assertEqual(u, 33)
        model, _ = model_of(HOP, 2, 3, 4.0, u * h, lead=10, reach=True)
        res = model.solve(time_limit_s=60, feasibility=True)
        self.assertEqual(res.status, "infeasible in horizon", f"horizon {u * h:.3f} s")

    def _trace_is_feasible(self, text, group_deg=0.0, free_assignment=False, reach=False):
        """Our planner's trace of text (a real motion within P) pinned as the samples of the
        whole program's section must satisfy every row of the MILP: the kinematic rows, the
        tubes (or chain hulls), the feed rows and the windows of elements each sample may be
        on. The samples' elements are the earliest monotone choice that holds each sample
        (free_assignment: HiGHS chooses them)."""
        path = write_program(text)
        trace_path = path + ".trace"
        try:
            subprocess.run([BENCH_MOTION, path, "--jerk", "0", "--trace-out", trace_path],
                           check=True, stdout=subprocess.DEVNULL)
            with open(trace_path) as f:
                trace = [tuple(float(x) for x in line.split()[:3]) for line in f if line.strip()]
            moves = floor.parse_program(path)
        finally:
            for p in (path, trace_path):
                if os.path.exists(p):
                    os.unlink(p)
        # Sample k of the trace is q(k ms); q(0) is the start; the motion is at rest at the
        # end from the last sample on, so t_b <= len(trace) ms and N <= len(trace).
        lead = 10
        model = floor.make_model(moves, 0, len(moves), V, A, 1.0, lead, lead,
                                 (len(trace) + 1) * 1e-3, group_turn_deg=group_deg,
                                 reach_vertices=reach)
        if reach:  # the test is about those rows: the program must have some
            self.assertTrue(model.reach_clauses())
        fixed = {k: moves[0].start for k in range(-lead, 1)}
        for k, q in enumerate(trace, 1):
            fixed[k] = q
        for k in range(len(trace) + 1, len(trace) + 1 + lead):
            fixed[k] = moves[-1].end
        assignment = None
        if not free_assignment:
            windows, assignment, cur = model.windows(), {}, 0
            for k in sorted(windows):
                lo, hi = windows[k]
                if k > 0:
                    cur = max(cur, model.ea + 1)
                q = np.array(fixed[k]) * floor.UNIT_PER_MM - model.origin
                holds = [e for e in range(max(lo, cur), hi + 1)
                         if max(n @ q - r for n, r in model.el_rows(e)) <= 2 * floor.SLACK]
                self.assertTrue(holds, f"sample {k} {fixed[k]} is on no element of its window "
                                f"{lo}..{hi} at or after {cur}")
                cur = cur if cur in holds else holds[0]
                assignment[k] = cur
        # The trace has 6 decimals: each coordinate is within 0.5e-6 mm of the motion's.
        res = model.solve(time_limit_s=60, feasibility=True, fixed=fixed, fixed_tol_mm=1e-6,
                          assignment=assignment)
        self.assertEqual(res.status, "feasible", "our planner's motion violates a row")

    def test_planner_trace_satisfies_the_relaxation_at_a_right_angle(self):
        self._trace_is_feasible("G21 G90\nG1 X4 F6000\nG1 Y4\nM2\n", free_assignment=True)

    def test_planner_trace_satisfies_the_relaxation_on_a_row_end_with_rapids(self):
        # A tp_default-like row end (0.5 mm steps bending into a 5 mm step and back), a rapid
        # lift and move, and a slow plunge: every kind of feed row (50, 10 mm/s and rapids)
        # and chains taken as hulls (group_deg 10).
        prog = ("G21 G90\nG1 X0.5 Y0.05 Z-0.01 F3000\nG1 X1.0 Y0.08 Z-0.015\n"
                "G1 X1.5 Y0.09 Z-0.016\nG1 X1.5 Y5.09\nG1 X1.0 Y5.08\nG1 X0.5 Y5.05\n"
                "G0 Z2\nG0 X0 Y8\nG1 Z0 F600\nM2\n")
        self._trace_is_feasible(prog, group_deg=10.0)

    def test_planner_trace_satisfies_the_relaxation_in_three_dimensions(self):
        self._trace_is_feasible("G21 G90 G64 P0.02\nG1 X3 Y1 Z-1 F4000\nG1 X3.5 Y3 Z0\n"
                                "G0 X0 Y0 Z1\nM2\n")

    def test_planner_trace_satisfies_the_relaxation_around_an_arc(self):
        # A half circle (its hull rows and the arc's feed, 40 mm/s) between two lines, as
        # before tp_default's line 831.
        self._trace_is_feasible("G21 G90\nG1 X2 F2400\nG3 X7 Y0 I2.5 J0\nG1 Y4 F4000\nM2\n")

    def test_planner_trace_satisfies_the_reach_vertices_rows(self):
        # tp_default's opening (the hop, the zero-length G1 and a row step), then a right
        # angle: our planner reaches Z1 and turns the hop where it is programmed, and its
        # offset corner passes the right angle 0.99 P from each line, within P of the vertex
        # along both moves. HiGHS chooses the assignment (the earliest one would keep the
        # whole hop on the G0).
        prog = ("G21 G90 G17\nG0 X0 Y0 Z1\nG1 Z0 F600\nG1 X0 Y0 Z0 F3000\n"
                "G1 X0.5 Y0.0998 Z-0.0006\nG1 Y1\nM2\n")
        self._trace_is_feasible(prog, free_assignment=True, reach=True)

    @unittest.skipUnless(shutil.which("cbc"), "cbc (coinor-cbc) is not installed")
    def test_cbc_agrees_with_highs(self):
        # G1 X10 F1800 at h = 2 ms (worked out in line_at_feed_is_length_over_feed_plus_ramps:
        # N >= 180 exactly): 360 ms infeasible, 362 ms feasible; the hop with reached vertices
        # at h = 4 ms: 132 ms infeasible (worked out above). Both solvers must say the same.
        line = "G21 G90\nG1 X10 F1800\nM2\n"
        cases = [(line, 2, 2, 2.0, 25, 0.360, False, "infeasible in horizon"),
                 (line, 2, 2, 2.0, 25, 0.362, False, "feasible"),
                 (HOP, 2, 3, 4.0, 10, 0.132, True, "infeasible in horizon")]
        for text, first, last, step_ms, lead, horizon_s, reach, want in cases:
            for solver in ("highs", "cbc"):
                model, _ = model_of(text, first, last, step_ms, horizon_s, lead=lead,
                                    reach=reach)
                model.solver = solver
                res = model.solve(time_limit_s=60, feasibility=True)
                self.assertEqual(res.status, want, f"{solver}, horizon {horizon_s} s")

    def test_floor_is_below_the_planner_on_a_short_u_turn(self):
        # The bisection itself: its floor may not exceed the time of a real motion.
        prog = "G21 G90\nG1 X3 F3000\nG1 Y0.5\nG1 X0\nM2\n"
        path = write_program(prog)
        try:
            out = subprocess.run([BENCH_MOTION, path, "--jerk", "0"], check=True,
                                 capture_output=True, text=True).stdout
        finally:
            os.unlink(path)
        ours_s = float(out.split("motion time ")[1].split(" s")[0])
        # A 4 ms grid and a horizon just past our time keep the bisection short.
        res = floor_of(prog, 2, 4, 4.0, time_limit_s=60, horizon_s=ours_s + 0.008)
        self.assertLessEqual(res.floor_s, ours_s)
        # and it says more than the plain length / feed bound (7 mm at 50 mm/s = 0.14 s)
        self.assertGreater(res.floor_s, 0.14)

    def test_unsupported_words_are_refused_with_file_and_line(self):
        path = write_program("G21 G90\nG1 X1 F600\nG4 P1\n")
        try:
            with self.assertRaises(floor.ProgramError) as ctx:
                floor.parse_program(path)
            self.assertIn(f"{path}:3:", str(ctx.exception))
            self.assertIn("G4", str(ctx.exception))
        finally:
            os.unlink(path)
        path = write_program("G21 G90\nG1 X1\n")
        try:
            with self.assertRaises(floor.ProgramError) as ctx:
                floor.parse_program(path)
            self.assertIn(f"{path}:2:", str(ctx.exception))
        finally:
            os.unlink(path)


if __name__ == "__main__":
    BENCH_MOTION = sys.argv.pop(1)
    unittest.main()
