"""Reference for the rolling disc's steady turn (`models/rolling_disc.yaml`, entry `turning`).

An independent derivation: Kane's method with the disc's angular velocity components in the
lean frame as generalized speeds, the rolling constraints eliminating the contact point's
rates (SymPy's `KanesMethod`), against eomgen's Lagrange multipliers and its linearisation in
the turning frame. The reduced equations in (lean, u1, u2, u3) do not contain the heading,
the spin or the contact point, so a steady turn is their equilibrium and its linearisation
needs no turning frame.

Given the heading rate Omega and the spin rate w (the file's `yaw_dot` and `spin_dot`), it
finds the lean of the steady turn (Brent's method in mpmath at 30 digits), checks the closed
form g tan(lean) = v^2 (3/(2 R_G) + r sin(lean)/(4 R_G^2)) with v and R_G those of the
centre, and prints the eigenvalues of the linearisation at 30 digits.

    python3 tools/coin_turn_reference.py
"""

import mpmath as mp
import sympy as sp
from sympy.physics import mechanics as me

mp.mp.dps = 30

M, R, G = 1, sp.Rational(1, 5), sp.Rational(981, 100)
OMEGA, SPIN = -1, sp.Rational(15, 2)

q_yaw, q_lean, q_spin, qx, qy = me.dynamicsymbols("yaw lean spin x y")
u1, u2, u3 = me.dynamicsymbols("u1 u2 u3")
ux, uy = me.dynamicsymbols("ux uy")

N = me.ReferenceFrame("N")
Y = N.orientnew("Y", "Axis", [q_yaw, N.z])
L = Y.orientnew("L", "Axis", [q_lean, Y.x])
D = L.orientnew("D", "Axis", [q_spin, L.y])
# Generalized speeds: the disc's angular velocity in L, u1 L.x + u2 L.y + u3 L.z.
D.set_ang_vel(N, u1 * L.x + u2 * L.y + u3 * L.z)

O = me.Point("O")
O.set_vel(N, 0)
C = O.locatenew("C", qx * N.x + qy * N.y)
C.set_vel(N, ux * N.x + uy * N.y)
Gc = C.locatenew("G", R * L.z)
# Rolling: the disc's material point at C is at rest, so v_G = w_D x (G - C).
Gc.set_vel(N, D.ang_vel_in(N).cross(R * L.z))

# ω = yaw' N.z + lean' Y.x + spin' L.y, in L: N.z = sin(lean) L.y + cos(lean) L.z.
kinematic = [
    q_lean.diff() - u1,
    q_spin.diff() + q_yaw.diff() * sp.sin(q_lean) - u2,
    q_yaw.diff() * sp.cos(q_lean) - u3,
]
I_d = M * R**2 / 4
disc = me.RigidBody(
    "disc", Gc, D, M, (me.inertia(L, I_d, 2 * I_d, I_d), Gc)
)
kane = me.KanesMethod(
    N, q_ind=[q_yaw, q_lean, q_spin], u_ind=[u1, u2, u3], kd_eqs=kinematic
)
fr, frstar = kane.kanes_equations([disc], [(Gc, -M * G * N.z)])
mm = kane.mass_matrix_full
fo = kane.forcing_full
rhs = mm.LUsolve(fo)
# State (yaw, lean, spin, u1, u2, u3); reduced: (lean, u1, u2, u3).
states = [q_yaw, q_lean, q_spin, u1, u2, u3]
reduced = [1, 3, 4, 5]
syms = sp.symbols("s0:6")
f = sp.Matrix([rhs[i] for i in reduced]).subs(dict(zip(states, syms)))
f = sp.simplify(f)
jac = f.jacobian([syms[i] for i in reduced])
fn = sp.lambdify(syms, f, "mpmath")
jn = sp.lambdify(syms, jac, "mpmath")


def speeds(lean):
    # Steady: lean' = 0, yaw' = Omega, spin' = w.
    return (0, SPIN + OMEGA * mp.sin(lean), OMEGA * mp.cos(lean))


def residual(lean):
    s = (0, lean, 0) + speeds(lean)
    return fn(*s)[1]  # u1' (the lean's acceleration); u2', u3' vanish by symmetry


lean = mp.findroot(residual, (mp.mpf("0.1"), mp.mpf("0.4")), solver="anderson")
state = (0, lean, 0) + speeds(lean)
print("lean =", mp.nstr(lean, 25))
print("residuals =", [mp.nstr(v, 3) for v in fn(*state)])
rc = abs(float(R) * SPIN / OMEGA)
rg = rc - R * mp.sin(lean)
v = abs(OMEGA) * rg
closed = v**2 * (mp.mpf(3) / (2 * rg) + R * mp.sin(lean) / (4 * rg**2)) - G * mp.tan(lean)
print("closed form g tan(lean) - v^2 (...) =", mp.nstr(closed, 3))
a = mp.matrix(jn(*state).tolist())
for e in sorted(mp.eig(a)[0], key=lambda z: (abs(z), mp.im(z))):
    print("eigenvalue", mp.nstr(mp.re(e), 20), mp.nstr(mp.im(e), 20))
