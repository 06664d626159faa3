# EX-15: 37 holes on a triangular lattice (pitch 20, row spacing 17.321) in rows of 4,5,6,7,6,5,4
# centred on X0, walked left-to-right then right-to-left; every hole drilled to Z-15.
# Usage: python3 check_geometry.py expected
import re, sys
text = open(sys.argv[1]).read()
exp = []
for i, n in enumerate([4, 5, 6, 7, 6, 5, 4]):
    y = 51.963 - 17.321 * i
    xs = [-(n - 1) * 10 + 20 * k for k in range(n)]
    exp += [(x, y) for x in (xs if i % 2 == 0 else xs[::-1])]
got = [(float(a), float(b)) for a, b in re.findall(r'feed X(\S+) Y(\S+) Z-15\n', text)]
assert len(re.findall(r"^\d+ feed ", text, re.M)) == 37, "37 feed moves"
assert len(got) == 37, len(got)
worst = max(abs(g[0] - e[0]) + abs(g[1] - e[1]) for g, e in zip(got, exp))
print("37 holes, worst deviation", round(worst, 6), "first", got[0], "last", got[-1])
assert worst < 1e-3
