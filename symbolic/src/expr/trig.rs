//! Sines and cosines of sums of angles, rewritten by the addition theorems when the sines and
//! cosines of the angles themselves are computed anyway.
//!
//! A chain of bodies with absolute angles has `sin θᵢ`, `cos θᵢ` in its potential energy and
//! `sin(θᵢ − θⱼ)`, `cos(θᵢ − θⱼ)` in its mass matrix and gyroscopic terms. Evaluated as they
//! stand, these cost one `sin_cos` per angle and one more per pair; with
//! `sin(a ± b) = sin a cos b ± cos a sin b` and `cos(a ± b) = cos a cos b ∓ sin a sin b` the
//! pairs cost four multiplications and two additions each, and every angle one `sin_cos`
//! (which costs little more than the `cos` it replaces). This is what a hand-written
//! double pendulum does.
//!
//! Only arguments that are sums of terms `±x`, with every `x` itself the bare argument of a
//! sine or cosine among the roots, are rewritten, so the rewrite never adds a trigonometric
//! call. The absolute error of the expanded form is a few ulps of 1 (the products of numbers
//! of magnitude ≤ 1), no worse than that of forming `a − b` before the call.

use super::{ExprArena, ExprId, Func, Node};
use rustc_hash::{FxHashMap, FxHashSet};

/// Rewrites `roots` with the sines and cosines of sums of angles expanded (see the module
/// docs); returns the new roots in the same order (a root is unchanged, same id, when nothing
/// below it is rewritten). New nodes are added to `arena`; existing ones are untouched.
pub fn expand_angle_sums(arena: &mut ExprArena, roots: &[ExprId]) -> Vec<ExprId> {
    let reachable = arena.reachable(roots);
    let base: FxHashSet<ExprId> = reachable
        .iter()
        .filter_map(|&e| match arena.node(e) {
            Node::Func(Func::Sin | Func::Cos, u) if !matches!(arena.node(*u), Node::Add(_)) => {
                Some(*u)
            }
            _ => None,
        })
        .collect();
    let any = reachable.iter().any(|&e| match arena.node(e) {
        Node::Func(Func::Sin | Func::Cos, u) => angle_terms(arena, *u, &base).is_some(),
        _ => false,
    });
    if !any {
        return roots.to_vec();
    }

    let mut map: FxHashMap<ExprId, ExprId> = FxHashMap::default();
    let mut sums: FxHashMap<Vec<(bool, ExprId)>, (ExprId, ExprId)> = FxHashMap::default();
    for &e in &reachable {
        let node = arena.node(e).clone();
        let new = match node {
            Node::Const(_) | Node::Pi | Node::Symbol(_) => e,
            Node::Func(f @ (Func::Sin | Func::Cos), u) => match angle_terms(arena, u, &base) {
                Some(terms) => {
                    let terms: Vec<(bool, ExprId)> =
                        terms.into_iter().map(|(neg, x)| (neg, map[&x])).collect();
                    let (s, c) = sin_cos_of_sum(arena, &terms, &mut sums);
                    if f == Func::Sin { s } else { c }
                }
                None => rebuild(arena, e, &node, &map),
            },
            _ => rebuild(arena, e, &node, &map),
        };
        map.insert(e, new);
    }
    roots.iter().map(|r| map[r]).collect()
}

/// `u` as `Σ ±xₖ` with every `xₖ` in `base` (at least two terms), or `None`.
fn angle_terms(
    arena: &ExprArena,
    u: ExprId,
    base: &FxHashSet<ExprId>,
) -> Option<Vec<(bool, ExprId)>> {
    let Node::Add(terms) = arena.node(u) else {
        return None;
    };
    terms
        .iter()
        .map(|&t| {
            if base.contains(&t) {
                return Some((false, t));
            }
            match arena.node(t) {
                Node::Mul(f) if f.len() == 2 => {
                    let minus_one = arena
                        .as_constant(f[0])
                        .is_some_and(|c| c.negated().is_one());
                    (minus_one && base.contains(&f[1])).then_some((true, f[1]))
                }
                _ => None,
            }
        })
        .collect()
}

/// `(sin, cos)` of `Σ ±xₖ` by the addition theorems, peeling off the first term; the sums of
/// the remaining terms are shared through `memo`.
fn sin_cos_of_sum(
    arena: &mut ExprArena,
    terms: &[(bool, ExprId)],
    memo: &mut FxHashMap<Vec<(bool, ExprId)>, (ExprId, ExprId)>,
) -> (ExprId, ExprId) {
    if let Some(&sc) = memo.get(terms) {
        return sc;
    }
    let (neg, x) = terms[0];
    let sin_x = arena.sin(x);
    let s1 = if neg { arena.neg(sin_x) } else { sin_x };
    let c1 = arena.cos(x);
    let result = if terms.len() == 1 {
        (s1, c1)
    } else {
        let (s2, c2) = sin_cos_of_sum(arena, &terms[1..], memo);
        let a = arena.times(s1, c2);
        let b = arena.times(c1, s2);
        let sin = raw_sum(arena, a, b);
        let c = arena.times(c1, c2);
        let d = arena.times(s1, s2);
        let minus_d = arena.neg(d);
        let cos = raw_sum(arena, c, minus_d);
        (sin, cos)
    };
    memo.insert(terms.to_vec(), result);
    result
}

/// `a + b` interned as it stands: the canonical [`ExprArena::sum`] would recognise the
/// addition theorem and fold the sum back into one sine or cosine.
fn raw_sum(arena: &mut ExprArena, a: ExprId, b: ExprId) -> ExprId {
    let terms = if a <= b { [a, b] } else { [b, a] };
    arena.add(Node::Add(Box::new(terms)))
}

/// `node` (the node `e`) with its children replaced by their images, interned as it stands
/// (canonical construction could fold a rewritten sum back); `e` itself when no child
/// changed.
fn rebuild(
    arena: &mut ExprArena,
    e: ExprId,
    node: &Node,
    map: &FxHashMap<ExprId, ExprId>,
) -> ExprId {
    let children: Vec<ExprId> = node.children().iter().map(|c| map[c]).collect();
    if children.as_slice() == node.children() {
        return e;
    }
    arena.add(match node {
        Node::Const(_) | Node::Pi | Node::Symbol(_) => return e,
        Node::Add(_) => Node::Add(children.into_boxed_slice()),
        Node::Mul(_) => Node::Mul(children.into_boxed_slice()),
        Node::Pow(_) => Node::Pow([children[0], children[1]]),
        Node::Func(f, _) => Node::Func(*f, children[0]),
        Node::Atan2(_) => Node::Atan2([children[0], children[1]]),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sines and cosines among the nodes reachable from `roots`.
    fn trig_calls(arena: &ExprArena, roots: &[ExprId]) -> Vec<ExprId> {
        arena
            .reachable(roots)
            .into_iter()
            .filter(|&e| matches!(arena.node(e), Node::Func(Func::Sin | Func::Cos, _)))
            .collect()
    }

    /// A triple pendulum's angle pairs and a three-term sum (relative angles), rewritten:
    /// the values agree with the direct form to a few ulps of the terms' size (the
    /// expansion's error bound), and only sines and cosines of the bare angles remain.
    #[test]
    fn sums_of_angles_are_expanded_and_agree() {
        let mut a = ExprArena::new();
        let [t1, _, _] = a.coordinate("theta1");
        let [t2, _, _] = a.coordinate("theta2");
        let [t3, _, _] = a.coordinate("theta3");
        let d12 = a.minus(t1, t2);
        let d13 = a.minus(t1, t3);
        let sum = a.sum(&[t1, t2, t3]);
        let s12 = a.sin(d12);
        let c13 = a.cos(d13);
        let s123 = a.sin(sum);
        let c123 = a.cos(sum);
        let gravity: Vec<ExprId> = [t1, t2, t3].iter().map(|&t| a.cos(t)).collect();
        let g = a.sum(&gravity);
        let prod = a.times(s12, c13);
        let roots = [s12, c13, s123, c123, g, prod];
        let new = expand_angle_sums(&mut a, &roots);
        assert_ne!(new[..4], roots[..4]);
        assert_eq!(new[4], roots[4], "a root without angle sums keeps its id");
        for e in trig_calls(&a, &new) {
            let Node::Func(_, u) = a.node(e) else {
                unreachable!()
            };
            assert!(
                matches!(a.node(*u), Node::Symbol(_)),
                "left a sine or cosine of {:?}",
                a.node(*u)
            );
        }
        let mut rng = <rand::rngs::Xoshiro256PlusPlus as rand::SeedableRng>::seed_from_u64(
            0x2545_f491_4f6c_dd1d,
        );
        for _ in 0..200 {
            let mut values = vec![0.0; a.symbols().len()];
            for v in values.iter_mut() {
                *v = rand::RngExt::random_range(&mut rng, -10.0..10.0);
            }
            for (r, n) in roots.iter().zip(&new) {
                let (x, y) = (a.eval(*r, &values), a.eval(*n, &values));
                // |angles| ≤ 30: forming the sum before the call loses up to 30 ε; the
                // expansion's own error is a few ε.
                assert!((x - y).abs() <= 64.0 * f64::EPSILON * 30.0, "{x} vs {y}");
            }
        }
    }

    /// Repeated angles and coefficients: `θ1 + θ1` is the canonical `2·θ1`, a term of its own;
    /// `cos(2θ1 − θ2)` is split when `sin 2θ1` and `cos θ2` are computed anyway, while in
    /// `sin(θ1 − 2θ2)` the term `−2θ2` is neither `±` an angle whose sine is computed nor
    /// split further, so that call is kept. Values agree with the direct form (tolerance as
    /// in the test above: |angles| ≤ 30).
    #[test]
    fn repeated_angles_and_coefficients() {
        let mut a = ExprArena::new();
        let [t1, _, _] = a.coordinate("theta1");
        let [t2, _, _] = a.coordinate("theta2");
        let twice = a.sum(&[t1, t1]);
        let two = a.int(2);
        assert_eq!(twice, a.times(two, t1), "θ1 + θ1 is 2·θ1");
        let s2 = a.sin(twice);
        let c2 = a.cos(t2);
        let d = a.minus(twice, t2);
        let split = a.cos(d);
        let two_t2 = a.times(two, t2);
        let e = a.minus(t1, two_t2);
        let kept = a.sin(e);
        let s1 = a.sin(t1);
        let roots = [s2, c2, split, kept, s1];
        let new = expand_angle_sums(&mut a, &roots);
        assert_ne!(new[2], roots[2], "cos(2θ1 − θ2) is split");
        assert_eq!(new[3], roots[3], "sin(θ1 − 2θ2) is kept");
        let arguments: Vec<ExprId> = trig_calls(&a, &new)
            .into_iter()
            .map(|c| match a.node(c) {
                Node::Func(_, u) => *u,
                _ => unreachable!(),
            })
            .collect();
        let mut expected = vec![twice, t1, t2, e];
        expected.sort();
        let mut arguments = arguments;
        arguments.sort();
        arguments.dedup();
        assert_eq!(arguments, expected);
        for k in 0..100 {
            let values = [0.37 * k as f64 - 15.0, 11.0 - 0.29 * k as f64];
            let mut bindings = vec![0.0; a.symbols().len()];
            let ids: Vec<usize> = a
                .symbols()
                .iter()
                .enumerate()
                .filter(|(_, s)| s.name == "theta1" || s.name == "theta2")
                .map(|(i, _)| i)
                .collect();
            bindings[ids[0]] = values[0];
            bindings[ids[1]] = values[1];
            for (r, n) in roots.iter().zip(&new) {
                let (x, y) = (a.eval(*r, &bindings), a.eval(*n, &bindings));
                assert!((x - y).abs() <= 64.0 * f64::EPSILON * 30.0, "{x} vs {y}");
            }
        }
    }

    /// An angle whose own sine and cosine are not computed is not split: the rewrite never
    /// adds a call.
    #[test]
    fn sums_of_angles_not_otherwise_needed_are_kept() {
        let mut a = ExprArena::new();
        let [t1, _, _] = a.coordinate("theta1");
        let [t2, _, _] = a.coordinate("theta2");
        let d = a.minus(t1, t2);
        let s = a.sin(d);
        let c1 = a.cos(t1);
        let root = a.times(s, c1);
        assert_eq!(expand_angle_sums(&mut a, &[root]), vec![root]);
    }
}
