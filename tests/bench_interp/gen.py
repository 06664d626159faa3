#!/usr/bin/env python3
"""Writes the interpreter benchmark programs, in NcStudio syntax (for `cnc check`) and in
LinuxCNC 2.9 syntax (for `rs274 -g`), so both interpreters see the same motion.

    gen.py KIND COUNT DIALECT OUT
      KIND     surfacing | arcs | loop
      COUNT    lines (surfacing), arcs (arcs) or subprogram calls (loop)
      DIALECT  ncstudio | linuxcnc

Every program starts with the same preamble (G21 G90 G17 G54, feed set) so neither side
depends on a machine default. Coordinates are written with 3 decimals; all arc end points are
exact multiples of 0.001 so both interpreters' end-point checks pass without tolerance games.
"""
import sys

# Inner subprogram: two feed moves per call, out and back, so the loop stays in one place.
LOOP_MOVES_PER_CALL = 2
# Calls of the inner subprogram made by one call of the outer one (the inner repeat count).
LOOP_INNER_REPEAT = 200
ARC_RADIUS_MM = 10.0


def preamble(out):
    out.write("G21 G90 G17 G54\nG0 X0 Y0 Z5\nG1 Z0 F3000\n")


def epilogue(out, dialect):
    out.write("G0 Z5\nM30\n" if dialect == "ncstudio" else "G0 Z5\nM2\n")


def surfacing(out, count):
    """Zig-zag raster over a 100 x 100 mm field with a slowly varying Z: every line a full
    `G1 X Y Z F` block, as a CAM surfacing finish pass writes them."""
    row_points = 200
    step_mm = 100.0 / row_points
    lines = []
    for i in range(count):
        row, col = divmod(i, row_points)
        x = col * step_mm if row % 2 == 0 else (row_points - col) * step_mm
        y = (row % 200) * 0.5
        z = -((i * 7) % 1000) / 1000.0
        lines.append(f"G1 X{x:.3f} Y{y:.3f} Z{z:.3f} F2000\n")
    out.writelines(lines)


def arcs(out, count):
    """First half: G3 half circles with I J and a Z change (helical), alternating between
    (R,0) and (-R,0). Second half: G3 quarter arcs given by R, around the same circle.
    Each arc starts where the previous one ended."""
    r = ARC_RADIUS_MM
    out.write(f"G1 X{r:.3f} Y0 Z0\n")
    helical = count // 2
    lines = []
    for i in range(helical):
        if i % 2 == 0:
            lines.append(f"G3 X{-r:.3f} Y0 Z-1.000 I{-r:.3f} J0\n")
        else:
            lines.append(f"G3 X{r:.3f} Y0 Z0 I{r:.3f} J0\n")
    if helical % 2 == 1:  # end the helical half back at (R,0) so the quarter arcs start there
        lines.append(f"G1 X{r:.3f} Y0 Z0\n")
    quarter_ends = [(0.0, r), (-r, 0.0), (0.0, -r), (r, 0.0)]
    for i in range(count - helical):
        x, y = quarter_ends[i % 4]
        lines.append(f"G3 X{x:.3f} Y{y:.3f} R{r:.3f}\n")
    out.writelines(lines)


def loop(out, count, dialect):
    """A two-move subprogram called COUNT times through two nested repeat levels:
    the main program repeats the outer subprogram COUNT/200 times, which repeats the inner one
    200 times. COUNT must be a multiple of 200."""
    if count % LOOP_INNER_REPEAT:
        sys.exit(f"gen.py: loop count {count} is not a multiple of {LOOP_INNER_REPEAT}")
    outer = count // LOOP_INNER_REPEAT
    if dialect == "ncstudio":
        # NcStudio: the program text comes first, subprograms O.... end with M17 after M30.
        out.write(f"G65 P1000 L{outer}\n")
        epilogue(out, dialect)
        out.write(f"O1000\nG65 P2000 L{LOOP_INNER_REPEAT}\nM17\n")
        out.write("O2000\nG1 X1.000\nG1 X0\nM17\n")
    else:
        # LinuxCNC: subroutines are defined before they are called; repeat blocks for L.
        body = (
            "o2000 sub\nG1 X1.000\nG1 X0\no2000 endsub\n"
            f"o1000 sub\no1100 repeat [{LOOP_INNER_REPEAT}]\no2000 call\no1100 endrepeat\n"
            "o1000 endsub\n"
        )
        out.write(body)
        out.write(f"G21 G90 G17 G54\nG0 X0 Y0 Z5\nG1 Z0 F3000\n")
        out.write(f"o1200 repeat [{outer}]\no1000 call\no1200 endrepeat\n")
        epilogue(out, dialect)


def main(argv):
    if len(argv) != 5 or argv[1] not in ("surfacing", "arcs", "loop") \
            or argv[3] not in ("ncstudio", "linuxcnc"):
        sys.exit(__doc__)
    kind, count, dialect, path = argv[1], int(argv[2]), argv[3], argv[4]
    with open(path, "w") as out:
        if kind == "loop":
            if dialect == "ncstudio":
                preamble(out)
            loop(out, count, dialect)
            return
        preamble(out)
        if kind == "surfacing":
            surfacing(out, count)
        else:
            arcs(out, count)
        epilogue(out, dialect)


if __name__ == "__main__":
    main(sys.argv)
