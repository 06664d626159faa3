#!/usr/bin/env python3
# Checks a *-linuxcnc-xcheck case's expected output against LinuxCNC 2.9's recording of the
# same HAL setup (linuxcnc.txt: `halrun -f linuxcnc.hal` on LinuxCNC, one halsampler line per
# cycle, floats with 6 decimals). The case's `signals` file names the recorded columns, in
# order. Prints the worst difference per signal; exits 1 on any mismatch.
#   usage: tests/hal/xcheck_compare.py tests/hal/pid-linuxcnc-xcheck
import os, sys
here = os.path.abspath(sys.argv[1])
signals = open(os.path.join(here, 'signals')).read().split()
ours = [l.strip() for l in open(os.path.join(here, 'expected')) if l.strip() and not l.startswith('exit ')]
ref = [l.split() for l in open(os.path.join(here, 'linuxcnc.txt'))]
value = lambda v: 1.0 if v == 'TRUE' else 0.0 if v == 'FALSE' else float(v)
worst = dict.fromkeys(signals, 0.0)
bad = 0
for k, row in enumerate(ref):
    for j, s in enumerate(signals):
        a, b = value(ours[k * len(signals) + j]), float(row[j])
        d = abs(a - b)
        worst[s] = max(worst[s], d)
        if d > 1.5e-6 * max(1.0, abs(b)):
            bad += 1
            print(f'cycle {k + 1} {s}: ours {a} LinuxCNC {b}')
print('cycles', len(ref), 'worst difference', worst)
sys.exit(1 if bad else 0)
