"""A peer measurement (not used by the product): how long SymPy takes on the Whipple bicycle.

Runs SymPy's own benchmark-bicycle test, `sympy.physics.mechanics.tests.test_kane3.test_bicycle`
(shipped with SymPy: the bicycle of Meijaard et al. 2007 derived with `KanesMethod`,
linearised about upright straight rolling and compared with the paper's state matrices at
several speeds), and prints its wall time and SymPy's version, for docs/performance.md beside
`cargo bench --bench bicycle` (eomgen derives the same model, with its Jacobians, and sweeps
201 speeds).

Run: python3 tools/sympy_bicycle.py
"""
import time

import sympy
from sympy.physics.mechanics.tests.test_kane3 import test_bicycle

start = time.perf_counter()
test_bicycle()
elapsed = time.perf_counter() - start
print(f"SymPy {sympy.__version__}: test_kane3.test_bicycle (KanesMethod, linearisation, "
      f"comparison with the paper) took {elapsed:.1f} s")
