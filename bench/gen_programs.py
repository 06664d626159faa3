#!/usr/bin/env python3
"""Writes the generated motion-bench programs into bench/ (deterministic: no randomness, fixed
formatting, so a rerun reproduces the committed files byte for byte).

  surface_3d.ngc     a 3D surface finished in 0.05 mm segments at F6000
  pocket_sharp.ngc   a rectangular pocket with sharp corners at G64 P0.05
  tangent_arcs.ngc   a run of small tangent arcs (radii 0.5, 1, 1.5 mm, alternating sense)

Only the G-code subset both controls run: G0 G1 G2 G3 (I J form) G17 G21 G90 G64 P, F, M2.

  bench/gen_programs.py            write the programs beside this script
  bench/gen_programs.py --check    exit 1 if a committed program differs from what it writes
"""
import math
import pathlib
import sys

HEADER = "G21 G90 G17"


def fmt(value):
    """4 decimals, no negative zero: both controls read it exactly the same way."""
    text = f"{value:.4f}"
    return "0.0000" if text == "-0.0000" else text


def surface_z_mm(x_mm, y_mm):
    return -1.0 + 0.5 * math.sin(2 * math.pi * x_mm / 10.0) * math.cos(2 * math.pi * y_mm / 15.0)


def surface_3d():
    """Zig-zag rows along X over a 25 x 19 mm patch; every move, the row links included, is
    0.05 mm in XY with Z following the surface: 10 380 segments at F6000 (100 mm/s = vmax)."""
    step_mm, row_len_steps, rows, row_pitch_steps = 0.05, 500, 20, 20
    lines = ["(surface_3d.ngc: written by bench/gen_programs.py; 3D surface, 0.05 mm segments)",
             HEADER, "G0 Z1", f"G1 Z{fmt(surface_z_mm(0, 0))} F6000"]
    x_i, y_i = 0, 0

    def move():
        x, y = x_i * step_mm, y_i * step_mm
        lines.append(f"G1 X{fmt(x)} Y{fmt(y)} Z{fmt(surface_z_mm(x, y))}")

    for row in range(rows):
        direction = 1 if row % 2 == 0 else -1
        for _ in range(row_len_steps):
            x_i += direction
            move()
        if row + 1 < rows:
            for _ in range(row_pitch_steps):
                y_i += 1
                move()
    lines += ["G0 Z5", "G0 X0 Y0", "M2"]
    return lines


def rectangle(lines, x0, y0, x1, y1):
    lines += [f"G1 X{fmt(x1)} Y{fmt(y0)}", f"G1 X{fmt(x1)} Y{fmt(y1)}",
              f"G1 X{fmt(x0)} Y{fmt(y1)}", f"G1 X{fmt(x0)} Y{fmt(y0)}"]


def pocket_sharp():
    """A 30 x 20 mm pocket, 1 mm deep, at F6000: concentric rectangles stepping in by 1 mm (90
    degree corners, 135 degree step-ins), then a zig-zag floor pass (two 90 degree corners
    every 1 mm): about 90 sharp corners."""
    lines = ["(pocket_sharp.ngc: written by bench/gen_programs.py; sharp-cornered pocket)",
             HEADER, "G64 P0.05", "G0 Z1", "G1 Z-1.0000 F600", "F6000"]
    width, height, step = 30.0, 20.0, 1.0
    inset = 0.0
    while height - 2 * inset > step:
        x0, y0, x1, y1 = inset, inset, width - inset, height - inset
        if inset > 0:
            lines.append(f"G1 X{fmt(x0)} Y{fmt(y0)}")
        rectangle(lines, x0, y0, x1, y1)
        inset += step
    y, forward = 0.0, True
    lines.append("G1 X0 Y0")
    while y < height:
        lines.append(f"G1 X{fmt(width if forward else 0.0)} Y{fmt(y)}")
        y = min(height, y + step)
        lines.append(f"G1 X{fmt(width if forward else 0.0)} Y{fmt(y)}")
        forward = not forward
    lines += ["G0 Z5", "G0 X0 Y0", "M2"]
    return lines


def tangent_arcs():
    """240 half circles along X, radii cycling 0.5, 1, 1.5 mm, G3 and G2 alternating so each
    joins the next tangentially (a serpentine). F2400 = 40 mm/s, above what centripetal
    acceleration allows on the 0.5 and 1 mm radii (sqrt(1000 * r) = 22.4, 31.6 mm/s)."""
    lines = ["(tangent_arcs.ngc: written by bench/gen_programs.py; small tangent arcs)",
             HEADER, "G0 Z1", "G1 Z0 F600", "F2400"]
    x = 0.0
    radii = (0.5, 1.0, 1.5)
    for i in range(240):
        r = radii[i % 3]
        code = "G3" if i % 2 == 0 else "G2"
        x += 2 * r
        lines.append(f"{code} X{fmt(x)} Y0 I{fmt(r)} J0")
    lines += ["G0 Z5", "G0 X0 Y0", "M2"]
    return lines


PROGRAMS = {"surface_3d.ngc": surface_3d, "pocket_sharp.ngc": pocket_sharp,
            "tangent_arcs.ngc": tangent_arcs}


def main(argv):
    check = "--check" in argv[1:]
    here = pathlib.Path(__file__).resolve().parent
    stale = []
    for name, make in PROGRAMS.items():
        text = "\n".join(make()) + "\n"
        path = here / name
        if check:
            if not path.exists() or path.read_text() != text:
                stale.append(name)
        else:
            path.write_text(text)
    if stale:
        print(f"{argv[0]}: out of date (rerun without --check): {' '.join(stale)}",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
