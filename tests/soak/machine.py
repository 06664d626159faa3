"""A sim config as the soak sees it: axis letters, limits and joints, read from its INI."""

import configparser
import dataclasses
import math
import os


@dataclasses.dataclass
class AxisLimits:
    min_mm: float
    max_mm: float
    vel: float  # mm/s (deg/s for A B C)
    acc: float  # /s^2
    jerk: float  # /s^3, 0 = unlimited


@dataclasses.dataclass
class JointLimits:
    min_mm: float
    max_mm: float
    counts_per_mm: float  # the simulated encoder's resolution (INPUT_SCALE)


@dataclasses.dataclass
class Machine:
    ini_path: str
    name: str  # the INI's base name: mill, gantry, ...
    letters: str  # lower case, once each, in [TRAJ]COORDINATES order (the trace's columns)
    axes: dict  # letter -> AxisLimits
    joints: list  # JointLimits per joint
    period_s: float
    blend_tolerance_mm: float
    kinematics: str  # first word of [KINS]KINEMATICS
    parameter_file: str  # [RS274NGC]PARAMETER_FILE (base name)
    kins: dict  # the [KINS] section, lower-case keys

    def linear(self, letter):
        return letter in "xyzuvw"

    def joints_planned(self):
        """True when the planner keeps the joints within their limits (linear kinematics);
        kins_xyzac_trt only has its joint velocities checked as commanded (docs/cnc-run.md)."""
        return self.kinematics != "kins_xyzac_trt"


def _number(section, key, where):
    try:
        return float(section[key])
    except KeyError:
        raise ValueError(f"{where}: [{section.name}]{key.upper()} missing") from None
    except ValueError:
        raise ValueError(f"{where}: [{section.name}]{key.upper()} = {section[key]!r} is not a number") from None


def read_machine(ini_path):
    parser = configparser.ConfigParser(strict=False, interpolation=None, comment_prefixes=("#", ";"))
    with open(ini_path, encoding="utf-8") as f:
        parser.read_file(f)
    coords = parser["TRAJ"]["COORDINATES"].replace(" ", "").lower()
    letters = "".join(dict.fromkeys(coords))
    axes = {}
    for l in letters:
        s = parser[f"AXIS_{l.upper()}"]
        axes[l] = AxisLimits(_number(s, "min_limit", ini_path), _number(s, "max_limit", ini_path),
                             _number(s, "max_velocity", ini_path), _number(s, "max_acceleration", ini_path),
                             float(s.get("max_jerk", "0")))
    joints = []
    count = int(parser["KINS"]["JOINTS"])
    for j in range(count):
        s = parser[f"JOINT_{j}"]
        joints.append(JointLimits(_number(s, "min_limit", ini_path), _number(s, "max_limit", ini_path),
                                  float(s.get("input_scale", "1000"))))
    name = os.path.splitext(os.path.basename(ini_path))[0]
    return Machine(ini_path=ini_path, name=name, letters=letters, axes=axes, joints=joints,
                   period_s=float(parser["EMCMOT"]["SERVO_PERIOD"]) * 1e-9,
                   blend_tolerance_mm=float(parser["TRAJ"].get("BLEND_TOLERANCE", "0.01")),
                   kinematics=parser["KINS"]["KINEMATICS"].split()[0],
                   parameter_file=parser["RS274NGC"].get("PARAMETER_FILE", name + ".var"),
                   kins={k: v for k, v in parser["KINS"].items()})


def workspace(machine):
    """Per-axis [lo, hi] the generator keeps every programmed point in (blends stay within 0.5 mm
    of the path, so the margin keeps the tool inside the soft limits).

    5axis-trt: a cube of 50 mm about the A axis' pivot (0, 0, Z_ROT_POINT), in which every joint also stays inside its travel whatever A and C are."""
    box = {}
    for l, a in machine.axes.items():
        if machine.linear(l):
            margin = max(2.0, 0.02 * (a.max_mm - a.min_mm))
            box[l] = (a.min_mm + margin, a.max_mm - margin)
    if machine.kinematics == "kins_xyzac_trt":
        pivot_z = float(machine.kins.get("z_rot_point", "0")) + float(machine.kins.get("z_offset", "0"))
        half = 25.0
        box["x"] = (-half, half)
        box["y"] = (-half, half)
        box["z"] = (pivot_z - half, pivot_z + half)
        assert math.sqrt(3) * half < -pivot_z - 5, "the cube must clear the joints' Z travel"
    for l in "ac":
        if l in machine.axes:
            a = machine.axes[l]
            box[l] = (max(a.min_mm + 5, -400.0), min(a.max_mm - 5, 400.0))
    return box
