#!/usr/bin/env python3
# Checks this case's expected output against LinuxCNC 2.9's recording of the same HAL setup
# (linuxcnc.txt: `halrun -f linuxcnc.hal` on LinuxCNC, one halsampler line per cycle, floats
# with 6 decimals). Prints the worst difference per signal; exits 1 on any mismatch.
import os, sys
here = os.path.dirname(os.path.abspath(__file__))
signals = ['e0-counts', 'e0-rawcounts', 'e0-counts-latched', 'e0-position', 'e0-position-latched', 'e0-velocity', 'e0-position-interpolated', 'e0-velocity-rpm', 'e0-index-enable', 'e1-counts', 'e1-rawcounts', 'e1-counts-latched', 'e1-position', 'e1-position-latched', 'e1-velocity', 'e1-position-interpolated', 'e1-velocity-rpm', 'e1-index-enable']
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
