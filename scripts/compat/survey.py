#!/usr/bin/env python3
"""LinuxCNC HAL-file compatibility survey.

Takes every HAL file LinuxCNC ships (already copied and gunzipped into TREE by survey.sh),
finds the config (INI) each belongs to, decides whether it loads only components we ship and,
for those, loads it with our `halrun --sim-clock` (with its INI) and records OK or the exact
error. A file that needs pins made by earlier HAL files of its config is retried after those
files when they too use only our components. Writes results.tsv and summary.md into OUT.
"""

import argparse
import collections
import os
import re
import subprocess
import sys

# halcmd verbs our runtime and HAL-language front end accept (hal/src/runtime.cpp command
# table plus the script-level ones); anything else a shipped file uses is reported.
OUR_VERBS = set(
    "loadrt unload unloadrt net newsig delsig linkps linksp linkpp unlinkp setp getp sets gets "
    "ptype stype addf delf newthread delthread start stop show list save alias unalias lock "
    "unlock status echo source loadusr waitusr".split())

# Pin-name prefixes of objects a LinuxCNC GUI creates (postgui files wire to them).
GUI_PREFIXES = ("pyvcp.", "gladevcp.", "qtvcp.", "qtdragon.", "gmoccapy.", "axisui.", "touchy.",
                "gscreen.", "woodpecker.", "qtplasmac.", "plasmac.", "halui.", "hal_manualtoolchange.")


def read_logical_lines(path):
    """Lines with comments removed and backslash continuations joined: (line_no, text)."""
    out, pending, start = [], "", 0
    with open(path, errors="replace") as f:
        for n, raw in enumerate(f, 1):
            line = raw.rstrip("\n")
            if not pending:
                start = n
            if line.rstrip().endswith("\\"):
                pending += line.rstrip()[:-1] + " "
                continue
            text = re.sub(r"(^|\s)#.*", "", pending + line).strip()
            pending = ""
            if text:
                out.append((start, text))
    return out


def expand_includes(path, depth=0):
    """The INI's lines with `#INCLUDE file` replaced by the file, as LinuxCNC's launcher does."""
    lines = []
    with open(path, errors="replace") as f:
        for raw in f:
            m = re.match(r"^#INCLUDE\s+(\S+)", raw)
            inc = os.path.join(os.path.dirname(path), os.path.expanduser(m.group(1))) if m else ""
            if m and depth < 10 and os.path.exists(inc):
                lines += expand_includes(inc, depth + 1)
            else:
                lines.append(raw if raw.endswith("\n") else raw + "\n")
    return lines


class Ini:
    """LinuxCNC-style INI reading: repeated keys kept in order, first wins for substitution.
    Keys may be indented; lines without '=' are ignored (LinuxCNC's reader does both)."""

    def __init__(self, path, lines):
        self.path = path
        self.values = collections.defaultdict(list)
        section = None
        if True:
            for raw in lines:
                line = raw.strip()
                if not line or line[0] in "#;":
                    continue
                m = re.match(r"^\[([^\]]+)\]", line)
                if m:
                    section = m.group(1).strip()
                    continue
                if "=" in line and section:
                    key, value = line.split("=", 1)
                    self.values[(section, key.strip())].append(value.strip())

    def get(self, section, key):
        v = self.values.get((section, key))
        return v[0] if v else None

    def all(self, section, key):
        return self.values.get((section, key), [])


def substitute(text, ini):
    """[SECTION]KEY and [SECTION](KEY) from the INI; unknown ones are left as written."""
    def repl(m):
        if ini is None:
            return m.group(0)
        v = ini.get(m.group(1), m.group(2) or m.group(3))
        return v if v is not None else m.group(0)
    return re.sub(r"\[([A-Za-z0-9_]+)\](?:\(([A-Za-z0-9_]+)\)|([A-Za-z0-9_]+))", repl, text)


def ini_references(path):
    """The (section, key) pairs a HAL file substitutes."""
    refs = set()
    for _, text in read_logical_lines(path):
        for m in re.finditer(r"\[([A-Za-z0-9_]+)\](?:\(([A-Za-z0-9_]+)\)|([A-Za-z0-9_]+))", text):
            refs.add((m.group(1), m.group(2) or m.group(3)))
    return refs


def parse_hal(path, ini):
    """Components loaded (loadrt), programs started (loadusr), verbs and syntax notes."""
    loadrt, loadusr, verbs, notes = [], [], collections.Counter(), set()
    for _, text in read_logical_lines(path):
        if re.search(r"\[[A-Za-z0-9_]+\]\([A-Za-z0-9_]+\)", text):
            notes.add("[SECTION](KEY) substitution")
        words = substitute(text, ini).split()
        verb = words[0]
        if len(words) >= 3 and words[1] == "=":
            notes.add("'pin = value' assignment")
            verbs["<pin = value>"] += 1
            continue
        verbs[verb] += 1
        if verb == "loadrt" and len(words) > 1:
            loadrt.append(words[1])
        elif verb == "loadusr":
            args = words[1:]
            while args and args[0].startswith("-"):
                opt = args.pop(0)
                if opt in ("-Wn", "-n") and args:
                    args.pop(0)
            if args:
                loadusr.append(os.path.basename(args[0]))
    return loadrt, loadusr, verbs, notes


def resolve_halfile(entry, ini_dir, hallib):
    """An INI HALFILE entry -> path (LIB: means the hallib directory; else the INI's dir, then hallib)."""
    name = entry.split()[0] if entry.split() else entry
    if name.startswith("LIB:"):
        return os.path.join(hallib, name[4:])
    for base in (ini_dir, hallib):
        p = os.path.normpath(os.path.join(base, name))
        if os.path.exists(p):
            return p
    return os.path.normpath(os.path.join(ini_dir, name))


class Config:
    def __init__(self, ini_path, hallib):
        lines = expand_includes(ini_path)
        with open(ini_path, errors="replace") as f:
            has_include = any(re.match(r"^#INCLUDE\s", line) for line in f)
        # Both halruns get the expanded INI, as LinuxCNC's launcher hands halcmd one.
        self.run_ini = ini_path + ".expanded" if has_include else ini_path
        if has_include:
            with open(self.run_ini, "w") as f:
                f.writelines(lines)
        self.ini_path = ini_path
        self.ini = Ini(self.run_ini, lines)
        d = os.path.dirname(ini_path)
        self.halfiles = [resolve_halfile(e, d, hallib) for e in self.ini.all("HAL", "HALFILE")]
        self.posttask = [resolve_halfile(e, d, hallib) for e in self.ini.all("HAL", "POSTTASK_HALFILE")]
        self.postgui = [resolve_halfile(e, d, hallib) for e in self.ini.all("HAL", "POSTGUI_HALFILE")]
        self.shutdown = [resolve_halfile(e, d, hallib) for e in self.ini.all("HAL", "SHUTDOWN")]
        self.twopass = self.ini.get("HAL", "TWOPASS") is not None
        self.display = (self.ini.get("DISPLAY", "DISPLAY") or "").split()[:1]

    def role_of(self, path):
        """(role, files that run before it in this config) or None."""
        if path in self.halfiles:
            return "HALFILE", self.halfiles[: self.halfiles.index(path)]
        if path in self.posttask:
            return "POSTTASK_HALFILE", self.halfiles + self.posttask[: self.posttask.index(path)]
        if path in self.postgui:
            return "POSTGUI_HALFILE", self.halfiles + self.posttask + self.postgui[: self.postgui.index(path)]
        if path in self.shutdown:
            return "SHUTDOWN", self.halfiles + self.posttask + self.postgui
        return None


def is_hal_file(name):
    return name.endswith(".hal") or ".hal." in name


def run_halrun(halrun, hal_file, ini, cwd, instance, timeout_s):
    cmd = [halrun, "--sim-clock", "--instance", instance]
    if ini:
        cmd += ["-i", ini]
    cmd += ["-f", hal_file]
    try:
        p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=timeout_s,
                           stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        subprocess.run([halrun, "-U", "--instance", instance], capture_output=True)
        return 124, f"timed out after {timeout_s} s"
    text = (p.stderr.strip() or p.stdout.strip()).splitlines()
    errors = [t for t in text if re.match(r"^\S+:\d+: ", t) or t.startswith("halrun:")]
    return p.returncode, (errors[0] if errors else (text[-1] if text else ""))


def run_syntax_check(checker, hal_file, ini, cwd):
    """Every line tokenized by our HAL front end without running it: list of problems."""
    cmd = [checker] + (["-i", ini] if ini else []) + [hal_file]
    p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=60)
    return [line for line in p.stdout.splitlines() if line.strip()]


def run_linuxcnc(halrun, hal_file, ini, cwd, scratch, timeout_s):
    """The same file under LinuxCNC's own halrun (the reference): (rc, first error line)."""
    target = hal_file
    if not hal_file.endswith(".hal"):  # LinuxCNC's halrun picks the interpreter by extension
        target = os.path.join(scratch, os.path.basename(hal_file).replace(".", "_") + ".hal")
        with open(hal_file, errors="replace") as src, open(target, "w") as dst:
            dst.write(src.read())
    cmd = [halrun] + (["-i", ini] if ini else []) + ["-f", target]
    try:
        p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=timeout_s,
                           stdin=subprocess.DEVNULL)
        rc, text = p.returncode, (p.stdout + p.stderr).splitlines()
    except subprocess.TimeoutExpired:
        rc, text = 124, [f"timed out after {timeout_s} s"]
    if rc != 0:
        subprocess.run([halrun, "-U"], capture_output=True, timeout=60)
    noise = ("Running with fallback_uid", "Note: Using POSIX", "To run under a debugger", "sudo env RTAPI")
    text = [t.strip() for t in text if t.strip() and not any(n in t for n in noise)]
    errors = [t for t in text if re.match(r"^\S+:\d+: ", t) or "ERROR" in t or "rror" in t]
    return rc, (errors[0] if errors else (text[-1] if text else ""))


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--tree", required=True, help="copied, gunzipped LinuxCNC files")
    ap.add_argument("--hallib", required=True, help="hallib directory inside the tree")
    ap.add_argument("--components", required=True, help="directory with our component .so files")
    ap.add_argument("--halrun", required=True, help="our halrun")
    ap.add_argument("--programs", default="halsampler,halstreamer", help="userspace programs we ship")
    ap.add_argument("--out", required=True)
    ap.add_argument("--timeout", type=int, default=20)
    ap.add_argument("--syntax-check", default="", help="our hal_syntax_check program")
    ap.add_argument("--linuxcnc-halrun", default="",
                    help="LinuxCNC's halrun: also load every file we load with it, as the reference")
    a = ap.parse_args()

    # LinuxCNC module names we answer to through <name>.alias files (trivkins, motmod) count too.
    ours = {os.path.splitext(f)[0] for f in os.listdir(a.components)
            if f.endswith(".so") or f.endswith(".alias")} | {"threads"}
    our_programs = set(a.programs.split(","))
    files, inis = [], []
    for root, _, names in os.walk(a.tree):
        for n in names:
            p = os.path.normpath(os.path.join(root, n))
            if is_hal_file(n):
                files.append(p)
            elif n.endswith(".ini"):
                inis.append(p)
    files.sort()
    configs = []
    for p in sorted(inis):
        try:
            configs.append(Config(p, a.hallib))
        except OSError:
            pass

    def owner(path):
        """The config running this file: one in the same directory first, else any."""
        found = [(c, c.role_of(path)) for c in configs if c.role_of(path)]
        same_dir = [x for x in found if os.path.dirname(x[0].ini_path) == os.path.dirname(path)]
        return (same_dir or found or [(None, None)])[0]

    parsed = {}

    def parse(path, ini):
        key = (path, ini.path if ini else None)
        if key not in parsed:
            parsed[key] = parse_hal(path, ini) if os.path.exists(path) else None
        return parsed[key]

    os.makedirs(a.out, exist_ok=True)
    rows, all_verbs = [], collections.Counter()
    for n, path in enumerate(files):
        cfg, role = owner(path)
        ini = cfg.ini if cfg else None
        if ini is None:  # a lone file using [SECTION]KEY: the INI next to it that resolves most
            near = [c for c in configs if os.path.dirname(c.ini_path) == os.path.dirname(path)]
            refs = ini_references(path)
            if near and refs:
                cfg = max(near, key=lambda c: sum(c.ini.get(sec, key) is not None for sec, key in refs))
                ini = cfg.ini
        loadrt, loadusr, verbs, notes = parse(path, ini)
        all_verbs.update(verbs)
        missing = sorted(set(loadrt) - ours)
        missing_prog = sorted(set(loadusr) - our_programs)
        unknown_verbs = sorted(v for v in verbs if v not in OUR_VERBS)
        rel = os.path.relpath(path, a.tree)
        row = dict(file=rel, ini=os.path.relpath(cfg.ini_path, a.tree) if cfg else "",
                   role=role[0] if role else "", twopass="yes" if cfg and cfg.twopass else "",
                   loadrt=" ".join(loadrt), loadusr=" ".join(loadusr), missing=" ".join(missing),
                   missing_programs=" ".join(missing_prog), unknown_verbs=" ".join(unknown_verbs),
                   notes="; ".join(sorted(notes)), syntax="", status="", detail="", linuxcnc="",
                   linuxcnc_detail="")
        if a.syntax_check:
            problems = run_syntax_check(a.syntax_check, path, cfg.run_ini if cfg else None,
                                        os.path.dirname(cfg.ini_path) if cfg else os.path.dirname(path))
            row["syntax"] = " | ".join(problems)
        if missing:
            row["status"], row["detail"] = "missing-component", " ".join(missing)
        elif missing_prog:
            row["status"], row["detail"] = "missing-program", " ".join(missing_prog)
        else:
            cwd = os.path.dirname(cfg.ini_path) if cfg else os.path.dirname(path)
            inst = f"compat-{os.getpid()}-{n}"
            rc, err = run_halrun(a.halrun, path, cfg.run_ini if cfg else None, cwd, inst, a.timeout)
            if rc == 0:
                row["status"] = "OK"
            else:
                row["status"], row["detail"] = "load-error", err
                before = role[1] if role else []
                if before and re.search(r"does not exist|no pin|no signal|no function|no thread", err):
                    ctx_missing, ctx_prog, ctx_other = set(), set(), []
                    for b in before:
                        if not b.endswith(".hal") or not os.path.exists(b):
                            ctx_other.append(os.path.basename(b))
                            continue
                        lr, lu, _, _ = parse(b, ini)
                        ctx_missing |= set(lr) - ours
                        ctx_prog |= set(lu) - our_programs
                    gui = role[0] != "HALFILE" and any(p in err for p in GUI_PREFIXES)
                    if ctx_missing or ctx_prog or ctx_other or gui:
                        why = []
                        if ctx_missing:
                            why.append("components " + " ".join(sorted(ctx_missing)))
                        if ctx_prog:
                            why.append("programs " + " ".join(sorted(ctx_prog)))
                        if ctx_other:
                            why.append("non-HAL files " + " ".join(ctx_other))
                        if gui:
                            why.append("GUI " + " ".join(cfg.display or ["?"]))
                        row["status"] = "needs-context"
                        row["detail"] = f"{err} || earlier files need: {'; '.join(why)}"
                    else:
                        wrapper = os.path.join(cwd, f".compat-survey-{os.getpid()}-{n}.hal")
                        with open(wrapper, "w") as w:
                            for b in before + [path]:
                                w.write(f"source {b}\n")
                        rc2, err2 = run_halrun(a.halrun, wrapper, cfg.run_ini, cwd, inst, a.timeout)
                        os.unlink(wrapper)
                        row["status"] = "OK-with-context" if rc2 == 0 else "load-error-with-context"
                        row["detail"] = "" if rc2 == 0 else err2
        if row["status"] == "load-error" and not role and re.search(r"does not exist", row["detail"]):
            row["status"] = "fragment"  # in no INI's HAL lists: loaded by a GUI panel or by hand
        if a.linuxcnc_halrun and not row["status"].startswith("missing"):
            cwd = os.path.dirname(cfg.ini_path) if cfg else os.path.dirname(path)
            rc, err = run_linuxcnc(a.linuxcnc_halrun, path, cfg.run_ini if cfg else None, cwd, a.out,
                                   a.timeout)
            row["linuxcnc"], row["linuxcnc_detail"] = ("OK" if rc == 0 else "error"), ("" if rc == 0 else err)
        prefix = os.path.normpath(a.tree) + os.sep
        for k in ("detail", "syntax", "linuxcnc_detail"):
            row[k] = row[k].replace(prefix, "")  # paths relative to the copied tree, as in `file`
        rows.append(row)
        print(f"[{n + 1}/{len(files)}] {row['status']:<24} {rel}", file=sys.stderr)

    cols = list(rows[0].keys())
    with open(os.path.join(a.out, "results.tsv"), "w") as f:
        f.write("\t".join(cols) + "\n")
        for r in rows:
            f.write("\t".join(r[c].replace("\t", " ") for c in cols) + "\n")
    write_summary(a, rows, ours, all_verbs)


def syntax_kind(problem):
    """A syntax-check message with file, line and names taken out, for grouping."""
    msg = re.sub(r"^(hal_syntax_check: )?\S+?:\d+: ", "", problem)
    msg = re.sub(r"\[[A-Za-z0-9_]+\]\(?[A-Za-z0-9_]+\)?", "[SECTION]KEY", msg)
    msg = re.sub(r"in '[^']*'", "in '...'", msg)
    msg = re.sub(r"INI file '[^']*'", "the INI file", msg)
    return msg


def write_summary(a, rows, ours, all_verbs):
    status = collections.Counter(r["status"] for r in rows)
    comp_files = collections.Counter()
    only = collections.Counter()
    for r in rows:
        m = r["missing"].split()
        comp_files.update(m)
        if len(m) == 1:
            only[m[0]] += 1
    prog_files = collections.Counter(p for r in rows for p in r["missing_programs"].split())
    out = []
    out.append(f"# LinuxCNC HAL files: compatibility survey\n")
    out.append(f"files: {len(rows)}; our components: {len(ours)} (incl. built-in threads)\n")
    out.append("| status | files |\n|---|---|")
    for s, c in status.most_common():
        out.append(f"| {s} | {c} |")
    out.append("\n## Missing components (files loading it; files where it is the only one missing)\n")
    out.append("| component | files | only missing one |\n|---|---|---|")
    for c, k in comp_files.most_common():
        out.append(f"| {c} | {k} | {only.get(c, 0)} |")
    out.append("\n## Missing userspace programs (files with only our components otherwise)\n")
    out.append("| program | files |\n|---|---|")
    for c, k in prog_files.most_common():
        out.append(f"| {c} | {k} |")
    out.append("\n## Verbs used in all files (count of lines)\n")
    out.append(", ".join(f"{v}: {k}{'' if v in OUR_VERBS else ' (NOT ours)'}" for v, k in all_verbs.most_common()))
    if any(r["syntax"] for r in rows):
        out.append("\n## Syntax problems found by hal_syntax_check (all files, nothing run)\n")
        kinds = collections.Counter()
        for r in rows:
            for problem in r["syntax"].split(" | ") if r["syntax"] else []:
                kinds[syntax_kind(problem)] += 1
        out.append("| problem | lines |\n|---|---|")
        for k, n in kinds.most_common():
            out.append(f"| {k} | {n} |")
        for r in rows:
            if r["syntax"]:
                first = r["syntax"].split(" | ")
                more = f" (+{len(first) - 1} more)" if len(first) > 1 else ""
                out.append(f"- {r['file']}: {first[0]}{more}")
    notes = collections.Counter(n for r in rows for n in r["notes"].split("; ") if n)
    if notes:
        out.append("\n## Syntax notes\n")
        for n, k in notes.most_common():
            out.append(f"- {n}: {k} files")
    if any(r["linuxcnc"] for r in rows):
        out.append("\n## Against LinuxCNC's own halrun (same file, same INI, standalone)\n")
        pairs = collections.Counter((r["status"], r["linuxcnc"]) for r in rows if r["linuxcnc"])
        out.append("| ours | LinuxCNC | files |\n|---|---|---|")
        for (ours_s, lc), k in sorted(pairs.items()):
            out.append(f"| {ours_s} | {lc} | {k} |")
        worse = [r for r in rows if r["linuxcnc"] == "OK" and not r["status"].startswith("OK")]
        out.append("\n### LinuxCNC loads it, we do not\n")
        for r in worse:
            out.append(f"- {r['file']} [{r['status']}]: {r['detail']}")
    out.append("\n## Loaded (OK / OK-with-context)\n")
    for r in rows:
        if r["status"].startswith("OK"):
            lc = f"; LinuxCNC: {r['linuxcnc']}" if r["linuxcnc"] else ""
            out.append(f"- {r['file']} ({r['status']}{lc})")
    out.append("\n## Load errors\n")
    for r in rows:
        if r["status"] in ("load-error", "load-error-with-context", "needs-context", "fragment"):
            lc = f" || LinuxCNC: {r['linuxcnc']} {r['linuxcnc_detail']}" if r["linuxcnc"] else ""
            out.append(f"- {r['file']} [{r['status']}]: {r['detail']}{lc}")
    text = "\n".join(out) + "\n"
    with open(os.path.join(a.out, "summary.md"), "w") as f:
        f.write(text)
    print(text)


if __name__ == "__main__":
    main()
