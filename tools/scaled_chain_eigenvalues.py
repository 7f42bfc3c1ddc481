#!/usr/bin/env python3
"""Reference eigenvalues of a badly scaled spring-mass chain, to 60 digits (mpmath).

Six masses from 1e-3 to 2 kg between two walls, seven springs from 0.5 to 1e6 N/m, once
undamped and once with a dashpot beside each spring. The eigenvalues of the state matrix
A = [0 I; -M^-1 K  -M^-1 C] are computed with mpmath's eigensolver at 60 significant digits
and written, rounded to 17, with the matrices, to runtime/tests/fixtures/scaled_chain.json,
which the runtime's eigenvalue tests compare with (`cargo test -p eomgen-runtime --test
suite vibration::scaled_chain`).

    python3 tools/scaled_chain_eigenvalues.py
"""

import json
import os

import mpmath as mp

mp.mp.dps = 60

MASSES = [1e-3, 2.0, 0.05, 1.0, 0.3, 1e-2]
SPRINGS = [1e6, 0.5, 300.0, 2e4, 5.0, 1e5, 40.0]
DASHPOTS = [0.02, 1e-3, 0.5, 3.0, 1e-2, 0.1, 0.05]


def chain(coefficients):
    """The tridiagonal matrix of elements between walls and neighbours."""
    n = len(MASSES)
    k = [[0.0] * n for _ in range(n)]
    for e, c in enumerate(coefficients):
        # Element e joins mass e-1 (or the left wall) and mass e (or the right wall).
        ends = [i for i in (e - 1, e) if 0 <= i < n]
        for i in ends:
            k[i][i] += c
        if len(ends) == 2:
            a, b = ends
            k[a][b] -= c
            k[b][a] -= c
    return k


def eigenvalues(m, k, c):
    n = len(m)
    a = mp.zeros(2 * n, 2 * n)
    for i in range(n):
        a[i, n + i] = 1
        for j in range(n):
            a[n + i, j] = -mp.mpf(k[i][j]) / mp.mpf(m[i])
            a[n + i, n + j] = -mp.mpf(c[i][j]) / mp.mpf(m[i])
    values = mp.eig(a, left=False, right=False)
    values = sorted(values, key=lambda v: (abs(v), mp.im(v)))
    return [[float(mp.re(v)), float(mp.im(v))] for v in values]


def main():
    n = len(MASSES)
    k = chain(SPRINGS)
    c = chain(DASHPOTS)
    zero = [[0.0] * n for _ in range(n)]
    out = {
        "masses": MASSES,
        "stiffness_matrix": k,
        "damping_matrix": c,
        "undamped": eigenvalues(MASSES, k, zero),
        "damped": eigenvalues(MASSES, k, c),
    }
    here = os.path.dirname(os.path.abspath(__file__))
    path = os.path.join(here, "..", "runtime", "tests", "fixtures", "scaled_chain.json")
    with open(path, "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")
    print(f"wrote {os.path.normpath(path)}")


if __name__ == "__main__":
    main()
