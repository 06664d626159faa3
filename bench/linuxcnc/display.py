#!/usr/bin/python3
"""Headless LinuxCNC "display" for the motion bench: runs one program and records its time.

linuxcnc starts it as `display.py -ini FILE` ([DISPLAY] DISPLAY in bench.ini) once task, motion
and io are up; when it exits, linuxcnc shuts the whole stack down. The program comes from
LCNC_BENCH_PROGRAM; the result goes to LCNC_BENCH_OUT as key=value lines:

  motion_s  servo cycles with motion.in-position FALSE x the servo period (bench.hal)
  runs      how many separate motions that time was made of (1 = no stop mid-program)
  wall_s    wall-clock seconds from AUTO_RUN until the program is idle and in position
  error     LinuxCNC's first error message, if any (the run then counts as failed)
  trace_samples, trace_overruns  with LCNC_BENCH_TRACE set (run.sh --trace): how many servo
            cycles halsampler copied to that file (X Y Z per line, trace.hal) and how many the
            sampler FIFO dropped (must be 0 for a usable trace)

Needs Debian's /usr/bin/python3 (the linuxcnc module is built for it).
"""
import os
import subprocess
import sys
import time

import linuxcnc

START_TIMEOUT_S = 30.0
STEP_TIMEOUT_S = 10.0


def halcmd(*args):
    return subprocess.run(["halcmd", *args], check=True, capture_output=True,
                          text=True).stdout.strip()


class Bench:
    def __init__(self):
        self.stat = linuxcnc.stat()
        self.cmd = linuxcnc.command()
        self.errors = linuxcnc.error_channel()
        self.first_error = None

    def check_errors(self):
        msg = self.errors.poll()
        while msg:
            kind, text = msg
            if kind in (linuxcnc.NML_ERROR, linuxcnc.OPERATOR_ERROR) and not self.first_error:
                self.first_error = text.strip().replace("\n", " ")
            msg = self.errors.poll()
        if self.first_error:
            raise RuntimeError(self.first_error)

    def wait_for(self, what, predicate, timeout_s=STEP_TIMEOUT_S, period_s=0.001):
        deadline = time.monotonic() + timeout_s
        while True:
            self.stat.poll()
            self.check_errors()
            if predicate(self.stat):
                return
            if time.monotonic() > deadline:
                raise RuntimeError(f"timed out waiting for {what}")
            time.sleep(period_s)

    def machine_on_homed_auto(self):
        self.wait_for("task", lambda s: s.task_state != 0, START_TIMEOUT_S, 0.05)
        self.cmd.state(linuxcnc.STATE_ESTOP_RESET)
        self.cmd.wait_complete()
        self.cmd.state(linuxcnc.STATE_ON)
        self.cmd.wait_complete()
        self.wait_for("machine on", lambda s: s.task_state == linuxcnc.STATE_ON)
        self.cmd.mode(linuxcnc.MODE_MANUAL)
        self.cmd.wait_complete()
        self.cmd.home(-1)
        self.cmd.wait_complete()
        self.wait_for("homing", lambda s: all(s.homed[j] for j in range(s.joints)))
        self.cmd.mode(linuxcnc.MODE_AUTO)
        self.cmd.wait_complete()
        self.wait_for("auto mode", lambda s: s.task_mode == linuxcnc.MODE_AUTO)

    def run(self, program, trace_path=None):
        self.cmd.program_open(program)
        self.cmd.wait_complete()
        tracer = None
        if trace_path:
            # halsampler drains the FIFO while the program runs; it only fills while moving.
            tracer = subprocess.Popen(["halsampler", "-c", "0", trace_path])
        halcmd("sets", "bench-reset", "FALSE")
        start = time.monotonic()
        self.cmd.auto(linuxcnc.AUTO_RUN, 0)
        self.wait_for("the program to start",
                      lambda s: s.interp_state != linuxcnc.INTERP_IDLE or s.queue > 0)
        # Poll at 1 ms; only wall_s depends on it (to +-1 ms), motion_s comes from HAL. The
        # task can look idle and in position for a moment before motion has started (seen on
        # short programs: a run that counted nothing), so the end also needs a counted motion.
        self.wait_for("the program to end",
                      lambda s: s.interp_state == linuxcnc.INTERP_IDLE and s.queue == 0
                      and s.inpos and int(halcmd("getp", "bench-runs.count")) > 0,
                      timeout_s=3600)
        wall_s = time.monotonic() - start
        motion_s = halcmd("getp", "bench-time.out")
        if float(motion_s) <= 0:
            raise RuntimeError("the program ended without a counted motion")
        result = {
            "motion_s": motion_s,
            "runs": halcmd("getp", "bench-runs.count"),
            "wall_s": f"{wall_s:.4f}",
        }
        if tracer:
            result.update(self.stop_trace(tracer, trace_path))
        return result

    @staticmethod
    def stop_trace(tracer, trace_path):
        # The FIFO is empty once halsampler has written one line per sampled cycle.
        expected = int(halcmd("getp", "sampler.0.curr-depth") or 0)
        deadline = time.monotonic() + STEP_TIMEOUT_S
        while expected > 0 and time.monotonic() < deadline:
            time.sleep(0.05)
            expected = int(halcmd("getp", "sampler.0.curr-depth"))
        time.sleep(0.2)
        tracer.terminate()
        tracer.wait()
        with open(trace_path) as f:
            samples = sum(1 for _ in f)
        return {"trace_samples": samples,
                "trace_overruns": halcmd("getp", "sampler.0.overruns")}


def main():
    program = os.environ["LCNC_BENCH_PROGRAM"]
    out_path = os.environ["LCNC_BENCH_OUT"]
    bench = Bench()
    try:
        bench.machine_on_homed_auto()
        result = bench.run(program, os.environ.get("LCNC_BENCH_TRACE"))
    except Exception as exc:  # any failure is reported to run.sh, which exits non-zero
        result = {"error": str(exc)}
    with open(out_path, "w") as out:
        for key, value in result.items():
            out.write(f"{key}={value}\n")
    return 0 if "error" not in result else 1


if __name__ == "__main__":
    sys.exit(main())
