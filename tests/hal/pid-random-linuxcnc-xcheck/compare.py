#!/usr/bin/env python3
# Checks this case's expected output against LinuxCNC 2.9's recording of the same HAL setup
# (linuxcnc.txt: `halrun -f linuxcnc.hal` on LinuxCNC, one halsampler line per cycle, floats
# with 6 decimals). Prints the worst difference per signal; exits 1 on any mismatch.
import os, sys
here = os.path.dirname(os.path.abspath(__file__))
signals = ['p0-output', 'p0-error', 'p0-errorI', 'p0-errorD', 'p0-commandD', 'p0-saturated', 'p1-output', 'p1-error', 'p1-errorI', 'p1-errorD', 'p1-commandD', 'p1-saturated']
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
