#!/usr/bin/env python3
"""Writes an OBJ of real content for measuring how fast large files load (docs/scenes.md,
"Large files"): an N x N grid of vertices on a gently curved sheet, written as
`v %.6f %.6f %.6f` lines, then 2 (N - 1)^2 triangles as `f a b c` lines. N = 3700 gives
1.13 GB (13.7 M vertices, 27.4 M triangles); N = 1000 gives 75 MB.

  python3 scripts/make_grid_obj.py 3700 /tmp/big.obj
"""
import math
import sys


def main():
    if len(sys.argv) != 3 or not sys.argv[1].isdigit() or int(sys.argv[1]) < 2:
        sys.exit("usage: make_grid_obj.py N OUT.obj  (N >= 2 vertices a side)")
    n = int(sys.argv[1])
    with open(sys.argv[2], 'w', buffering=1 << 24) as out:
        for j in range(n):
            y = j / (n - 1)
            out.write(''.join('v %.6f %.6f %.6f\n' % (i / (n - 1), y,
                                                    0.1 * math.sin(7 * i / n) * math.cos(5 * y))
                              for i in range(n)))
        for j in range(n - 1):
            rows = []
            for i in range(n - 1):
                a = j * n + i + 1
                b, c, d = a + 1, a + n, a + n + 1
                rows.append('f %d %d %d\nf %d %d %d\n' % (a, b, d, a, d, c))
            out.write(''.join(rows))


if __name__ == '__main__':
    main()
