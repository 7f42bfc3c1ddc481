//! Reference frames as chains of simple rotations from the ground frame `N`: vectors carried
//! between frames, and the angular velocity of a frame in `N`.
//!
//! A frame is its parent turned by successive simple rotations, each by an angle `a` about
//! an axis fixed in both the frame before and the frame after it (Kane & Levinson, *Dynamics:
//! Theory and Applications*, McGraw-Hill 1985, §1.7–1.9 and §2.4–2.5). A rotation by `a` about
//! axis `i` (with `j`, `k` the next axes in cyclic order) carries components in the turned
//! frame to the frame before it as
//!
//! ```text
//! v′ⱼ = cos a vⱼ − sin a vₖ,   v′ₖ = sin a vⱼ + cos a vₖ,   v′ᵢ = vᵢ
//! ```
//!
//! and back by the transpose. Vectors are carried through the tree of frames rotation by
//! rotation, up to the lowest common ancestor and down again, never by multiplied-out
//! direction-cosine matrices, which keeps the expressions as short as the chain allows.
//!
//! Angular velocity is the sum of the simple angular velocities along the chain (the
//! addition theorem, Kane & Levinson §2.4): `^N ω^F = Σ ȧₖ eₖ`, each axis `eₖ` carried into
//! `F`'s components — no derivative of a rotation matrix is taken.

use crate::expr::{ExprArena, ExprId};

/// A 3-vector of expressions: components along the axes of some frame.
pub type Vector3 = [ExprId; 3];

/// The axis of a simple rotation, fixed in the frames before and after it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RotationAxis {
    /// The frame's own axis `0`, `1` or `2` (x, y, z).
    Principal(usize),
    /// An oblique axis: its unit vector's components (constants), the same in both frames.
    Unit(Vector3),
    /// Euler parameters: the vector part `(e1, e2, e3)` of the rotation, whose scalar part
    /// `e0` is the rotation's "angle" (Kane & Levinson §1.3; the rotation is the one of the
    /// normalised parameters, so a drift of their norm does not deform the frame).
    Quaternion(Vector3),
}

impl From<usize> for RotationAxis {
    fn from(axis: usize) -> Self {
        RotationAxis::Principal(axis)
    }
}

/// The frames of a model: index 0 is the ground frame `N`, the others follow in file order.
#[derive(Debug, Clone, Default)]
pub struct Frames {
    /// Names, `N` first.
    names: Vec<String>,
    /// Parent of each frame (index); the ground's is itself.
    parents: Vec<usize>,
    /// Each frame's rotations from its parent, in the order they are applied: `(axis, angle)`.
    rotations: Vec<Vec<(RotationAxis, ExprId)>>,
}

impl Frames {
    /// Only the ground frame `N`.
    pub fn ground(name: &str) -> Self {
        Self {
            names: vec![name.to_string()],
            parents: vec![0],
            rotations: vec![Vec::new()],
        }
    }

    /// Adds frame `name`, turned from `parent` (an index) by `rotations` (an axis, its index
    /// 0–2 or an oblique unit vector, and an angle, in the order applied); returns its index.
    pub fn add<A: Into<RotationAxis>>(
        &mut self,
        name: &str,
        parent: usize,
        rotations: Vec<(A, ExprId)>,
    ) -> usize {
        self.names.push(name.to_string());
        self.parents.push(parent);
        self.rotations
            .push(rotations.into_iter().map(|(a, e)| (a.into(), e)).collect());
        self.names.len() - 1
    }

    /// The frames' names, the ground's first.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The parent (an index) of the frame of index `frame`; the ground's is itself.
    pub fn parent(&self, frame: usize) -> usize {
        self.parents[frame]
    }

    /// The rotations that turn the parent of the frame of index `frame` into it, in the order
    /// applied: `(axis, angle)`.
    pub fn rotations(&self, frame: usize) -> &[(RotationAxis, ExprId)] {
        &self.rotations[frame]
    }

    /// The index of the frame called `name`.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// The frames from the ground down to `frame`, both included.
    fn path(&self, frame: usize) -> Vec<usize> {
        let mut path = vec![frame];
        let mut f = frame;
        while f != 0 {
            f = self.parents[f];
            path.push(f);
        }
        path.reverse();
        path
    }

    /// `v`, given in `from`'s components, in `to`'s components.
    pub fn express(&self, arena: &mut ExprArena, v: Vector3, from: usize, to: usize) -> Vector3 {
        let (up, down) = (self.path(from), self.path(to));
        let common = up.iter().zip(&down).take_while(|(a, b)| a == b).count();
        let mut v = v;
        // Up from `from` to the common ancestor: each frame's rotations undone, last first.
        for &f in up[common..].iter().rev() {
            for &(axis, angle) in self.rotations[f].iter().rev() {
                v = rotate(arena, v, axis, angle, false);
            }
        }
        // Down to `to`: each frame's rotations applied, first first.
        for &f in &down[common..] {
            for &(axis, angle) in &self.rotations[f] {
                v = rotate(arena, v, axis, angle, true);
            }
        }
        v
    }

    /// `^N ω^F`, the angular velocity of `frame` in the ground frame, in `frame`'s components
    /// (rad/s): the simple angular velocities `ȧ e` of the rotations from `N` down to it,
    /// each carried into its components.
    pub fn angular_velocity(&mut self, arena: &mut ExprArena, frame: usize) -> Vector3 {
        let zero = arena.int(0);
        let mut w = [zero; 3];
        for f in self.path(frame).into_iter().skip(1) {
            for &(axis, angle) in &self.rotations[f] {
                w = rotate(arena, w, axis, angle, true);
                let rate = arena.time_derivative(angle);
                match axis {
                    RotationAxis::Principal(i) => w[i] = arena.plus(w[i], rate),
                    RotationAxis::Unit(k) => {
                        for (wi, ki) in w.iter_mut().zip(k) {
                            let part = arena.times(ki, rate);
                            *wi = arena.plus(*wi, part);
                        }
                    }
                    RotationAxis::Quaternion(e) => {
                        let own = quaternion_rate(arena, e, angle, false);
                        for (wi, part) in w.iter_mut().zip(own) {
                            *wi = arena.plus(*wi, part);
                        }
                    }
                }
            }
        }
        w
    }
}

impl Frames {
    /// `^N ω^F` in the ground's components (rad/s): the sum of the simple angular velocities
    /// `ȧ e` of the rotations from `N` down to `frame`, each axis `e` carried up to `N`
    /// through the rotations before it (Kane & Levinson §2.4, the addition theorem), so that
    /// each term keeps only the angles above its own rotation (`φ̇ N.z + θ̇ A.x + ψ̇ B.z` for
    /// Euler angles, rather than the frame's components turned back through every angle).
    pub fn angular_velocity_in_ground(&self, arena: &mut ExprArena, frame: usize) -> Vector3 {
        let zero = arena.int(0);
        let mut w = [zero; 3];
        let path = self.path(frame);
        for (depth, &f) in path.iter().enumerate().skip(1) {
            for (j, &(axis, angle)) in self.rotations[f].iter().enumerate() {
                let rate = arena.time_derivative(angle);
                // The rotation's own angular velocity in the frame before it: its rate about
                // its axis (the same before and after it), or the Euler parameters' rates.
                let mut e = match axis {
                    RotationAxis::Quaternion(e) => quaternion_rate(arena, e, angle, true),
                    _ if arena.is_zero(rate) => continue,
                    RotationAxis::Principal(i) => {
                        let mut e = [zero; 3];
                        e[i] = rate;
                        e
                    }
                    RotationAxis::Unit(k) => k.map(|c| arena.times(c, rate)),
                };
                // Up through the frame's rotations before it, then through its ancestors'.
                for &(a, angle) in self.rotations[f][..j].iter().rev() {
                    e = rotate(arena, e, a, angle, false);
                }
                for &g in path[1..depth].iter().rev() {
                    for &(a, angle) in self.rotations[g].iter().rev() {
                        e = rotate(arena, e, a, angle, false);
                    }
                }
                for (wi, ei) in w.iter_mut().zip(e) {
                    *wi = arena.plus(*wi, ei);
                }
            }
        }
        w
    }
}

/// Components `v` carried across one simple rotation by `angle` about `axis`: from the frame
/// before it into the turned frame (`into_turned`), or back.
fn rotate(
    arena: &mut ExprArena,
    v: Vector3,
    axis: RotationAxis,
    angle: ExprId,
    into_turned: bool,
) -> Vector3 {
    let axis = match axis {
        RotationAxis::Principal(i) => i,
        RotationAxis::Unit(k) => return rotate_oblique(arena, v, k, angle, into_turned),
        RotationAxis::Quaternion(e) => return rotate_quaternion(arena, v, e, angle, into_turned),
    };
    let (j, k) = ((axis + 1) % 3, (axis + 2) % 3);
    if arena.is_zero(v[j]) && arena.is_zero(v[k]) {
        return v;
    }
    let (c, s) = (arena.cos(angle), arena.sin(angle));
    // Into the turned frame the rotation is transposed: `−sin a` where the way back has
    // `sin a`.
    let s = if into_turned { arena.neg(s) } else { s };
    let cj = arena.times(c, v[j]);
    let sk = arena.times(s, v[k]);
    let sj = arena.times(s, v[j]);
    let ck = arena.times(c, v[k]);
    let mut out = v;
    out[j] = arena.minus(cj, sk);
    out[k] = arena.plus(sj, ck);
    out
}

/// [`rotate`] by the Euler parameters `(e0, e)` (Kane & Levinson §1.3, eq. 1.3.3, normalised):
/// back into the frame before the rotation `v′ = ((e0² − e·e) v + 2 (e·v) e + 2 e0 e × v)/|q|²`,
/// into the turned frame the same with `−e0`, `|q|² = e0² + e·e`.
fn rotate_quaternion(
    arena: &mut ExprArena,
    v: Vector3,
    e: Vector3,
    e0: ExprId,
    into_turned: bool,
) -> Vector3 {
    let s = if into_turned { arena.neg(e0) } else { e0 };
    let e0_squared = arena.times(e0, e0);
    let products: Vec<ExprId> = e.iter().map(|c| arena.times(*c, *c)).collect();
    let e_squared = arena.sum(&products);
    let norm = arena.plus(e0_squared, e_squared);
    let scale = arena.minus(e0_squared, e_squared);
    let dots: Vec<ExprId> = e.iter().zip(&v).map(|(a, b)| arena.times(*a, *b)).collect();
    let ev = arena.sum(&dots);
    let two = arena.int(2);
    let exv = cross(arena, &e, &v);
    [0, 1, 2].map(|i| {
        let a = arena.times(scale, v[i]);
        let b = arena.product(&[two, ev, e[i]]);
        let c = arena.product(&[two, s, exv[i]]);
        let sum = arena.sum(&[a, b, c]);
        arena.divide(sum, norm)
    })
}

/// The angular velocity of a rotation by the Euler parameters `(e0, e)` relative to the frame
/// before it: `2 (e0 ė − ė0 e ∓ e × ė)/|q|²` in the turned frame's components (`−`) or in the
/// frame before it (`+`, `in_parent`) (Kane & Levinson §2.1, eq. 2.1.9, for any norm).
fn quaternion_rate(arena: &mut ExprArena, e: Vector3, e0: ExprId, in_parent: bool) -> Vector3 {
    let e_dot = e.map(|c| arena.time_derivative(c));
    let e0_dot = arena.time_derivative(e0);
    let exd = cross(arena, &e, &e_dot);
    let e0_squared = arena.times(e0, e0);
    let products: Vec<ExprId> = e.iter().map(|c| arena.times(*c, *c)).collect();
    let e_squared = arena.sum(&products);
    let norm = arena.plus(e0_squared, e_squared);
    let two = arena.int(2);
    [0, 1, 2].map(|i| {
        let a = arena.times(e0, e_dot[i]);
        let b = arena.times(e0_dot, e[i]);
        let c = if in_parent { exd[i] } else { arena.neg(exd[i]) };
        let b = arena.neg(b);
        let sum = arena.sum(&[a, b, c]);
        let twice = arena.times(two, sum);
        arena.divide(twice, norm)
    })
}

/// [`rotate`] about the unit vector `k` by Rodrigues' formula (Kane & Levinson §1.2):
/// `v′ = cos a v + sin a (k × v) + (1 − cos a)(k · v) k` back into the frame before the
/// rotation, with `−sin a` into the turned frame.
fn rotate_oblique(
    arena: &mut ExprArena,
    v: Vector3,
    k: Vector3,
    angle: ExprId,
    into_turned: bool,
) -> Vector3 {
    let (c, s) = (arena.cos(angle), arena.sin(angle));
    let s = if into_turned { arena.neg(s) } else { s };
    let kxv = cross(arena, &k, &v);
    let products: Vec<ExprId> = k.iter().zip(&v).map(|(a, b)| arena.times(*a, *b)).collect();
    let kv = arena.sum(&products);
    let one = arena.int(1);
    let versine = arena.minus(one, c);
    let along = arena.times(versine, kv);
    let mut out = v;
    for i in 0..3 {
        let cv = arena.times(c, v[i]);
        let sk = arena.times(s, kxv[i]);
        let ak = arena.times(along, k[i]);
        out[i] = arena.sum(&[cv, sk, ak]);
    }
    out
}

/// `a × b`.
pub fn cross(arena: &mut ExprArena, a: &Vector3, b: &Vector3) -> Vector3 {
    let mut out = *a;
    for (i, slot) in out.iter_mut().enumerate() {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        let p = arena.times(a[j], b[k]);
        let q = arena.times(a[k], b[j]);
        *slot = arena.minus(p, q);
    }
    out
}

/// `I v` for the symmetric tensor `I` given as `[xx, yy, zz, xy, yz, xz]`.
pub fn tensor_times(arena: &mut ExprArena, inertia: &[ExprId; 6], v: &Vector3) -> Vector3 {
    let [xx, yy, zz, xy, yz, xz] = *inertia;
    let rows = [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]];
    rows.map(|row| {
        let terms: Vec<ExprId> = row
            .iter()
            .zip(v)
            .map(|(a, b)| arena.times(*a, *b))
            .collect();
        arena.sum(&terms)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Numbers of `v` at `q = values` (coordinates in order), rates from `rates`.
    fn numbers(arena: &ExprArena, v: &Vector3, values: &[f64], rates: &[f64]) -> [f64; 3] {
        let mut bindings = vec![0.0; 64];
        for (i, s) in arena.coordinates().iter().enumerate() {
            bindings[s[0].0 as usize] = values[i];
            bindings[s[1].0 as usize] = rates[i];
        }
        v.map(|e| arena.eval(e, &bindings))
    }

    /// A rotation by `a` about the oblique unit axis `k = (0, sin b, cos b)` is the z rotation
    /// conjugated by an x rotation, `R_x(−b) R_z(a) R_x(b)`: carried to the ground, a vector
    /// and the angular velocity agree with that chain of three principal rotations to
    /// rounding, and the angular velocity is `ȧ k` in the ground's components.
    #[test]
    fn an_oblique_axis_is_a_conjugated_principal_rotation() {
        let mut arena = ExprArena::new();
        let [a, _, _] = arena.coordinate("a");
        let (sb, cb) = (0.6, 0.8);
        let b = f64::atan2(sb, cb);
        let k = [arena.float(0.0), arena.float(sb), arena.float(cb)];
        let (minus_b, plus_b) = (arena.float(-b), arena.float(b));
        let mut frames = Frames::ground("N");
        let oblique = frames.add("B", 0, vec![(RotationAxis::Unit(k), a)]);
        let chain = frames.add(
            "C",
            0,
            vec![
                (RotationAxis::Principal(0), minus_b),
                (RotationAxis::Principal(2), a),
                (RotationAxis::Principal(0), plus_b),
            ],
        );
        let v = [arena.float(0.3), arena.float(-1.2), arena.float(0.7)];
        let (from_oblique, from_chain) = (
            frames.express(&mut arena, v, oblique, 0),
            frames.express(&mut arena, v, chain, 0),
        );
        let w = frames.angular_velocity(&mut arena, oblique);
        let w_ground = frames.express(&mut arena, w, oblique, 0);
        let w_chain = frames.angular_velocity(&mut arena, chain);
        let w_chain_ground = frames.express(&mut arena, w_chain, chain, 0);
        for (q, r) in [(0.4, 1.7), (-2.1, -0.3)] {
            let (x, y) = (
                numbers(&arena, &from_oblique, &[q], &[r]),
                numbers(&arena, &from_chain, &[q], &[r]),
            );
            let (wo, wc) = (
                numbers(&arena, &w_ground, &[q], &[r]),
                numbers(&arena, &w_chain_ground, &[q], &[r]),
            );
            for i in 0..3 {
                assert!((x[i] - y[i]).abs() < 1e-14, "{x:?} {y:?}");
                assert!((wo[i] - wc[i]).abs() < 1e-14, "{wo:?} {wc:?}");
            }
            let expected = [0.0, sb * r, cb * r];
            for i in 0..3 {
                assert!((wo[i] - expected[i]).abs() < 1e-15, "{wo:?}");
            }
            // The axis is fixed: carried up it is unchanged.
            let kk = frames.express(&mut arena, k, oblique, 0);
            let kn = numbers(&arena, &kk, &[q], &[r]);
            assert!(
                (kn[1] - sb).abs() < 1e-15 && (kn[2] - cb).abs() < 1e-15,
                "{kn:?}"
            );
        }
    }

    /// A z-x-z (Euler angle) chain: the angular velocity in the body's components is the
    /// textbook `ω = (φ̇ sin θ sin ψ + θ̇ cos ψ, φ̇ sin θ cos ψ − θ̇ sin ψ, φ̇ cos θ + ψ̇)`
    /// (Goldstein, *Classical Mechanics*, 3rd ed., eq. 4.87), and carrying a vector down and
    /// up again gives it back.
    #[test]
    fn euler_angles_give_the_textbook_angular_velocity() {
        let mut a = ExprArena::new();
        let [phi, _, _] = a.coordinate("phi");
        let [theta, _, _] = a.coordinate("theta");
        let [psi, _, _] = a.coordinate("psi");
        let mut frames = Frames::ground("N");
        let b = frames.add("B", 0, vec![(2, phi), (0, theta), (2, psi)]);
        let w = frames.angular_velocity(&mut a, b);
        let (q, r) = ([0.3, 1.1, -0.7], [0.5, -0.2, 1.3]);
        let got = numbers(&a, &w, &q, &r);
        let (st, ct) = (q[1].sin(), q[1].cos());
        let (sp, cp) = (q[2].sin(), q[2].cos());
        let want = [
            r[0] * st * sp + r[1] * cp,
            r[0] * st * cp - r[1] * sp,
            r[0] * ct + r[2],
        ];
        for i in 0..3 {
            assert!((got[i] - want[i]).abs() < 1e-14, "{got:?} {want:?}");
        }
        // The body's z axis in N: (sin θ sin φ, −sin θ cos φ, cos θ).
        let (one, zero) = (a.int(1), a.int(0));
        let z = frames.express(&mut a, [zero, zero, one], b, 0);
        let got = numbers(&a, &z, &q, &r);
        let want = [st * q[0].sin(), -st * q[0].cos(), ct];
        for i in 0..3 {
            assert!((got[i] - want[i]).abs() < 1e-15, "{got:?} {want:?}");
        }
        let back = frames.express(&mut a, z, 0, b);
        let got = numbers(&a, &back, &q, &r);
        assert!((got[0]).abs() < 1e-15 && got[1].abs() < 1e-15 && (got[2] - 1.0).abs() < 1e-15);
        // In N's components, summed rotation by rotation: φ̇ N.z + θ̇ A.x + ψ̇ B.z, equal to
        // the body components carried up (Goldstein §4.9), and of that textbook form.
        let summed = frames.angular_velocity_in_ground(&mut a, b);
        let carried = frames.express(&mut a, w, b, 0);
        let (got, want) = (numbers(&a, &summed, &q, &r), numbers(&a, &carried, &q, &r));
        let textbook = [
            r[1] * q[0].cos() + r[2] * st * q[0].sin(),
            r[1] * q[0].sin() - r[2] * st * q[0].cos(),
            r[0] + r[2] * ct,
        ];
        for i in 0..3 {
            assert!((got[i] - want[i]).abs() < 1e-14, "{got:?} {want:?}");
            assert!((got[i] - textbook[i]).abs() < 1e-14, "{got:?} {textbook:?}");
        }
    }
}
