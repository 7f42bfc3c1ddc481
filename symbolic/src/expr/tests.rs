//! Tests of the expression engine: hash-consing, canonical forms, derivatives against
//! central differences, CSE and printing preserve values.

use super::cse::plan;
use super::eval::Evaluator;
use super::print::{Printer, Syntax};
use super::*;
use proptest::prelude::*;

fn arena_xy() -> (ExprArena, ExprId, ExprId, SymbolId, SymbolId) {
    let mut a = ExprArena::new();
    let x = a.symbol("x", SymbolKind::Parameter);
    let y = a.symbol("y", SymbolKind::Parameter);
    let sx = SymbolId(0);
    let sy = SymbolId(1);
    (a, x, y, sx, sy)
}

#[test]
fn hash_consing_gives_one_id_per_structure() {
    let (mut a, x, y, _, _) = arena_xy();
    let s1 = a.plus(x, y);
    let s2 = a.plus(y, x);
    assert_eq!(s1, s2);
    let p1 = a.times(x, y);
    let p2 = a.times(y, x);
    assert_eq!(p1, p2);
    let n = a.len();
    let s3 = a.sin(s1);
    let s4 = a.sin(s2);
    assert_eq!(s3, s4);
    assert_eq!(a.len(), n + 1);
}

#[test]
fn canonical_folding() {
    let (mut a, x, y, _, _) = arena_xy();
    let zero = a.int(0);
    let one = a.int(1);
    assert_eq!(a.plus(x, zero), x);
    assert_eq!(a.times(x, one), x);
    assert_eq!(a.times(x, zero), zero);
    assert_eq!(a.pow(x, one), x);
    assert_eq!(a.pow(x, zero), one);
    // like terms: 2x + 3x = 5x
    let two = a.int(2);
    let three = a.int(3);
    let five = a.int(5);
    let t2 = a.times(two, x);
    let t3 = a.times(three, x);
    let t5 = a.times(five, x);
    assert_eq!(a.plus(t2, t3), t5);
    // x - x = 0
    assert_eq!(a.minus(x, x), zero);
    // x * x = x^2; x^2 / x = x
    let xx = a.times(x, x);
    let x2 = a.pow(x, two);
    assert_eq!(xx, x2);
    assert_eq!(a.divide(x2, x), x);
    // (2 x y)^2 = 4 x^2 y^2
    let p = a.product(&[two, x, y]);
    let sq = a.pow(p, two);
    let four = a.int(4);
    let y2 = a.pow(y, two);
    assert_eq!(sq, a.product(&[four, x2, y2]));
    // constants fold exactly: 1/2 + 1/2 = 1
    let half = a.constant(Constant::rational(1, 2).unwrap());
    assert_eq!(a.plus(half, half), one);
    // nested sums flatten: (x + y) + x = 2x + y
    let s = a.plus(x, y);
    let s2 = a.plus(s, x);
    let expected = a.plus(t2, y);
    assert_eq!(s2, expected);
}

#[test]
fn pythagorean_identity_collapses_in_sums() {
    let mut a = ExprArena::new();
    let [q, qd, _] = a.coordinate("q");
    let l = a.symbol("l", SymbolKind::Parameter);
    // v = (−l sin q q̇, l cos q q̇): v·v = l² q̇²
    let s = a.sin(q);
    let c = a.cos(q);
    let ls = a.product(&[l, s, qd]);
    let vx = a.neg(ls);
    let vy = a.product(&[l, c, qd]);
    let two = a.int(2);
    let vx2 = a.pow(vx, two);
    let vy2 = a.pow(vy, two);
    let v2 = a.plus(vx2, vy2);
    let l2 = a.pow(l, two);
    let qd2 = a.pow(qd, two);
    assert_eq!(v2, a.times(l2, qd2));
    // bare squares: sin² + cos² + 1 = 2
    let s2 = a.pow(s, two);
    let c2 = a.pow(c, two);
    let one = a.int(1);
    assert_eq!(a.sum(&[s2, c2, one]), two);
    // unequal coefficients are left alone: 2 sin² + cos² is not folded
    let t = a.times(two, s2);
    let e = a.plus(t, c2);
    assert!(matches!(a.node(e), Node::Add(_)));
}

/// A term with two `sin²` factors pairs with its partner through either: `sin²θ cos²φ +
/// sin²θ sin²φ = sin²θ` (the heavy top's `M₁₁`, whose first `sin²` factor, `sin²θ`, has no
/// `cos²θ` partner there), and so does `sin²θ sin²φ + cos²θ sin²φ = sin²φ`; a term a fold
/// makes is paired in turn, with a term met before it too.
#[test]
fn pythagorean_identity_pairs_through_any_sine_square() {
    let mut a = ExprArena::new();
    let [theta, _, _] = a.coordinate("theta");
    let [phi, _, _] = a.coordinate("phi");
    let m = a.symbol("m", SymbolKind::Parameter);
    let two = a.int(2);
    let (st, sp, cp, ct) = (a.sin(theta), a.sin(phi), a.cos(phi), a.cos(theta));
    let [st2, sp2, cp2, ct2] = [st, sp, cp, ct].map(|f| a.pow(f, two));
    let cos_term = a.product(&[m, st2, cp2]);
    let sin_term = a.product(&[m, st2, sp2]);
    let expected = a.times(m, st2);
    assert_eq!(a.plus(cos_term, sin_term), expected);
    let first = a.product(&[m, st2, sp2]);
    let second = a.product(&[m, ct2, sp2]);
    let expected = a.times(m, sp2);
    assert_eq!(a.plus(first, second), expected);
    // Every product of sin² or cos² of θ and of φ: 1 (two folds make the terms of a third).
    let four = [[st2, sp2], [st2, cp2], [ct2, sp2], [ct2, cp2]].map(|[x, y]| a.times(x, y));
    assert_eq!(a.sum(&four), a.int(1));
    // A fold that makes the cos² partner of a term examined before it: m sin²θ beside
    // m cos²θ cos²φ + m cos²θ sin²φ = m cos²θ (a spring's length² written in spherical
    // coordinates about another axis), whatever the order the terms are met in.
    let lone = a.times(m, st2);
    let pair = [a.product(&[m, ct2, cp2]), a.product(&[m, ct2, sp2])];
    assert_eq!(a.sum(&[lone, pair[0], pair[1]]), m);
    assert_eq!(a.sum(&[pair[1], pair[0], lone]), m);
}

#[test]
fn trig_parity_shares_one_node() {
    let (mut a, x, _, _, _) = arena_xy();
    let nx = a.neg(x);
    let c1 = a.cos(nx);
    let c2 = a.cos(x);
    assert_eq!(c1, c2);
    let s1 = a.sin(nx);
    let s2 = a.sin(x);
    assert_eq!(s1, a.neg(s2));
}

#[test]
fn derivative_of_pendulum_energy() {
    let (mut a, x, y, sx, _) = arena_xy();
    // d/dx (x^2 sin y) = 2 x sin y
    let two = a.int(2);
    let x2 = a.pow(x, two);
    let s = a.sin(y);
    let e = a.times(x2, s);
    let d = a.diff(e, sx);
    let expected = a.product(&[two, x, s]);
    assert_eq!(d, expected);
}

#[test]
fn time_derivative_uses_chain_rule() {
    let mut a = ExprArena::new();
    let [q, qd, qdd] = a.coordinate("q");
    let l = a.symbol("l", SymbolKind::Parameter);
    // d/dt (l sin q) = l cos q q̇ ; d²/dt² = l (cos q q̈ − sin q q̇²)
    let s = a.sin(q);
    let x = a.times(l, s);
    let v = a.time_derivative(x);
    let c = a.cos(q);
    assert_eq!(v, a.product(&[l, c, qd]));
    let acc = a.time_derivative(v);
    let two = a.int(2);
    let qd2 = a.pow(qd, two);
    let t1 = a.product(&[l, c, qdd]);
    let t2 = a.product(&[l, s, qd2]);
    assert_eq!(acc, a.minus(t1, t2));
}

/// The terms of a chain's `M₂₃`, one per bar below the joint, collect into
/// `l₂ l₃ (½ m₃ + m₄) cos(θ₂ − θ₃)`, and the negated sum shares the inner sum of masses.
#[test]
fn collection_factors_the_mass_below_a_joint() {
    let mut a = ExprArena::new();
    let [q2, _, _] = a.coordinate("theta2");
    let [q3, _, _] = a.coordinate("theta3");
    let [m3, m4, l2, l3] = ["m3", "m4", "l2", "l3"].map(|p| a.symbol(p, SymbolKind::Parameter));
    let d = a.minus(q2, q3);
    let c = a.cos(d);
    let half = a.constant(Constant::rational(1, 2).unwrap());
    let t3 = a.product(&[half, m3, l2, l3, c]);
    let t4 = a.product(&[m4, l2, l3, c]);
    let e = a.plus(t3, t4);
    let collected = a.collect_time_varying(e);
    let h3 = a.times(half, m3);
    let masses = a.plus(h3, m4);
    assert_eq!(collected, a.product(&[l2, l3, masses, c]));
    assert!(a.tree_operation_count(&[collected]) < a.tree_operation_count(&[e]));
    let ne = a.neg(e);
    let ne = a.expand_time_varying(ne);
    let n_collected = a.collect_time_varying(ne);
    let minus_one = a.int(-1);
    assert_eq!(n_collected, a.product(&[minus_one, l2, l3, masses, c]));
}

/// A number every coefficient of a group shares comes out of the sum of masses:
/// `½ m₁ ẋ² + ½ m₂ ẋ²` → `½ (m₁ + m₂) ẋ²`; a sign stays the only number pulled out of
/// `½ m₁ ẋ² + m₂ ẋ²`.
#[test]
fn collection_pulls_out_a_shared_number() {
    let mut a = ExprArena::new();
    let [_, xd, _] = a.coordinate("x");
    let [m1, m2] = ["m1", "m2"].map(|p| a.symbol(p, SymbolKind::Parameter));
    let half = a.constant(Constant::rational(1, 2).unwrap());
    let two = a.int(2);
    let xd2 = a.pow(xd, two);
    let t1 = a.product(&[half, m1, xd2]);
    let t2 = a.product(&[half, m2, xd2]);
    let e = a.plus(t1, t2);
    let collected = a.collect_time_varying(e);
    let masses = a.plus(m1, m2);
    assert_eq!(collected, a.product(&[half, masses, xd2]));
    let t2 = a.product(&[m2, xd2]);
    let e = a.plus(t1, t2);
    let collected = a.collect_time_varying(e);
    let h1 = a.times(half, m1);
    let masses = a.plus(h1, m2);
    assert_eq!(collected, a.product(&[masses, xd2]));
}

/// A number multiplying a sum of masses moves into it when that leaves fewer non-unit
/// coefficients: `2 l² (m₁/6 + m₂/2) θ̇` → `l² (m₁/3 + m₂) θ̇` (the mass matrix of a chain
/// from its collected `T`), while `½ (m₁ + m₂)` and `−(m₁ + m₂)` keep their number outside.
#[test]
fn collection_absorbs_a_number_into_a_sum_of_masses() {
    let mut a = ExprArena::new();
    let [_, qd, _] = a.coordinate("theta");
    let [m1, m2, l] = ["m1", "m2", "l"].map(|p| a.symbol(p, SymbolKind::Parameter));
    let c = |a: &mut ExprArena, n: i64, d: i64| a.constant(Constant::rational(n, d).unwrap());
    let two = a.int(2);
    let l2 = a.pow(l, two);
    let (sixth, half, third) = (c(&mut a, 1, 6), c(&mut a, 1, 2), c(&mut a, 1, 3));
    let s1 = a.times(sixth, m1);
    let s2 = a.times(half, m2);
    let masses = a.plus(s1, s2);
    let e = a.product(&[two, l2, masses, qd]);
    let absorbed = a.collect_time_varying(e);
    let t1 = a.times(third, m1);
    let expected_masses = a.plus(t1, m2);
    assert_eq!(absorbed, a.product(&[l2, expected_masses, qd]));
    assert!(a.tree_operation_count(&[absorbed]) < a.tree_operation_count(&[e]));
    let plain = a.plus(m1, m2);
    for number in [half, a.int(-1)] {
        let e = a.product(&[number, plain, qd]);
        assert_eq!(a.collect_time_varying(e), e);
    }
}

/// A square of a long sum (a chain's `|v|²`) is multiplied out, with each cross term once:
/// 40 terms give 820, beyond the 512-term guard against products of many sums.
#[test]
fn long_squares_are_multiplied_out() {
    let mut a = ExprArena::new();
    let rates: Vec<ExprId> = (0..40).map(|i| a.coordinate(&format!("q{i}"))[1]).collect();
    let v = a.sum(&rates);
    let two = a.int(2);
    let v2 = a.pow(v, two);
    let x = a.expand(v2);
    let Node::Add(terms) = a.node(x) else {
        panic!("not multiplied out: {:?}", a.node(x));
    };
    assert_eq!(terms.len(), 40 * 41 / 2);
    let bindings: Vec<f64> = (0..a.symbols().len())
        .map(|k| 0.1 * k as f64 - 2.0)
        .collect();
    assert!(close(a.eval(x, &bindings), a.eval(v2, &bindings), 1e-12));
    // Three sums of 10 terms (1000 products) stay a product.
    let short: Vec<ExprId> = rates[..10].to_vec();
    let w = a.sum(&short);
    let three = a.int(3);
    let w3 = a.pow(w, three);
    assert_eq!(a.expand(w3), w3);
}

/// A vector carried through rotations nested in rotations (a point of a chain of 3-D bodies
/// in relative rotations, each rotation `cos q vⱼ − sin q vₖ` of the sums before it) is
/// multiplied out while its expansion is small or shallow, and its parts are kept as they are
/// past the caps (more than 64 terms from sums nested more than two levels deep), where its
/// terms would
/// grow by a constant factor with each rotation (here, turning `(0, 0, 1)` about x and y in
/// turn, as the Fibonacci numbers: 3 terms at four rotations, 55 at ten, 144 at twelve).
/// Kept or not, the expansion equals the input at a random state (to 1e-12).
#[test]
fn nested_rotations_are_kept_past_the_expansion_caps() {
    let mut a = ExprArena::new();
    let angles: Vec<ExprId> = (0..12).map(|i| a.coordinate(&format!("q{i}"))[0]).collect();
    let (zero, one) = (a.int(0), a.int(1));
    let mut v = [zero, zero, one];
    let bindings: Vec<f64> = (0..a.symbols().len())
        .map(|k| 0.37 * k as f64 - 1.1)
        .collect();
    let mut expanded = Vec::new();
    for (level, &q) in angles.iter().enumerate() {
        // About x, then y, then x, …
        let (j, k) = if level % 2 == 0 { (1, 2) } else { (2, 0) };
        let (c, s) = (a.cos(q), a.sin(q));
        let (cj, sk, sj, ck) = (
            a.times(c, v[j]),
            a.times(s, v[k]),
            a.times(s, v[j]),
            a.times(c, v[k]),
        );
        v[j] = a.minus(cj, sk);
        v[k] = a.plus(sj, ck);
        let x = a.expand_time_varying(v[k]);
        assert!(
            close(a.eval(x, &bindings), a.eval(v[k], &bindings), 1e-12),
            "level {level}"
        );
        expanded.push((v[k], x));
    }
    let terms = |a: &ExprArena, e: ExprId| match a.node(e) {
        Node::Add(t) => t.len(),
        _ => 1,
    };
    // Four rotations: multiplied out into its monomials, none of them holding a sum.
    let (input, x) = expanded[3];
    assert_ne!(input, x);
    let Node::Add(monomials) = a.node(x) else {
        panic!("not multiplied out: {:?}", a.node(x));
    };
    assert_eq!(monomials.len(), 3);
    for &m in monomials {
        if let Node::Mul(factors) = a.node(m) {
            assert!(factors.iter().all(|&f| !matches!(a.node(f), Node::Add(_))));
        }
    }
    // Ten: 55 terms, multiplied out. Eleven (89 terms): kept, the sum itself. Twelve (144):
    // its parts from the rotation before are kept, so the expansion stops at them, fewer
    // terms, some holding a sum.
    let (input, x) = expanded[9];
    assert_eq!(terms(&a, x), 55, "{input:?}");
    assert_eq!(expanded[10].0, expanded[10].1);
    for (&(_, x), full) in expanded[10..].iter().zip([89, 144]) {
        assert!(terms(&a, x) < full, "{} terms", terms(&a, x));
        let Node::Add(monomials) = a.node(x) else {
            panic!("not a sum: {:?}", a.node(x));
        };
        let holds_a_sum = |m: ExprId| match a.node(m) {
            Node::Mul(factors) => factors.iter().any(|&f| matches!(a.node(f), Node::Add(_))),
            _ => false,
        };
        assert!(monomials.iter().any(|&m| holds_a_sum(m)));
    }
}

/// A display printer prints an expression as a tree up to `DISPLAY_LIMIT` operations and a
/// note past it (a DAG whose tree doubles per level: `e ← e·sin(e) + x`, 16 levels), in every
/// syntax; the code printer (`Printer::new`) still prints it whole, and below the limit both
/// print the same (for a sum that does not start with a negative term, which the display
/// printer moves behind a positive one).
#[test]
fn display_printers_print_a_note_past_the_limit() {
    use super::print::DISPLAY_LIMIT;
    let mut a = ExprArena::new();
    let x = a.coordinate("x")[0];
    let mut e = x;
    let mut small = None;
    for _ in 0..16 {
        let s = a.sin(e);
        let p = a.times(e, s);
        e = a.plus(p, x);
        if a.tree_operation_count(&[e]) <= DISPLAY_LIMIT {
            small = Some(e);
        }
    }
    let (small, operations) = (
        small.expect("a level under the limit"),
        a.tree_operation_count(&[e]),
    );
    assert!(operations > DISPLAY_LIMIT);
    for syntax in [Syntax::Text, Syntax::Latex, Syntax::MathMl] {
        let shown = Printer::for_display(&a, syntax).print(e);
        assert!(
            shown.contains(&format!("not printed: {operations} operations")),
            "{shown}"
        );
        assert!(shown.len() < 200, "{shown}");
        assert_eq!(
            Printer::for_display(&a, syntax).print(small),
            Printer::new(&a, syntax).print(small)
        );
    }
    assert!(Printer::new(&a, Syntax::Text).print(e).len() > 100_000);
    // Code is printed whole; LaTeX's `--` would be an en dash.
    assert_eq!(
        Printer::for_display(&a, Syntax::Rust).print(e),
        Printer::new(&a, Syntax::Rust).print(e)
    );
    let latex = Printer::for_display(&a, Syntax::Latex).print(e);
    assert!(
        latex.contains("-{}-rust") && !latex.contains("--"),
        "{latex}"
    );
}

/// The cached small integers are the hash-consed constants, and integers at the ends of the
/// range do not overflow the cache's slot arithmetic.
#[test]
fn small_integers_are_the_constants() {
    let mut a = ExprArena::new();
    for n in [-2, -1, 0, 1, 2, 3, i64::MIN, i64::MAX] {
        let cached = a.int(n);
        assert_eq!(a.int(n), cached);
        assert_eq!(a.constant(Constant::int(n)), cached, "{n}");
    }
}

/// A sum of two terms is one node whatever their order (the pair memo is keyed by the
/// ordered pair).
#[test]
fn two_term_sums_ignore_order() {
    let (mut a, x, y, _, _) = arena_xy();
    let s = a.sin(x);
    let xy = a.times(x, y);
    let u = a.plus(s, xy);
    let v = a.plus(xy, s);
    assert_eq!(u, v);
    let zero = a.int(0);
    assert_eq!(a.sum(&[s, xy]), a.sum(&[xy, s, zero]));
}

/// Expansion of the time-varying part only keeps a sum of parameters as one factor:
/// `((R − r) sin φ)²` → `(R − r)² sin² φ`, not `R² sin² φ − 2 R r sin² φ + r² sin² φ`.
#[test]
fn time_varying_expansion_keeps_parameter_sums() {
    let mut a = ExprArena::new();
    let [phi, _, _] = a.coordinate("phi");
    let big = a.symbol("R", SymbolKind::Parameter);
    let small = a.symbol("r", SymbolKind::Parameter);
    let arm = a.minus(big, small);
    let s = a.sin(phi);
    let c = a.cos(phi);
    let x = a.times(arm, s);
    let y = a.times(arm, c);
    let two = a.int(2);
    let x2 = a.pow(x, two);
    let y2 = a.pow(y, two);
    let v2 = a.plus(x2, y2);
    // The Pythagorean identity applies to the multiplied-out time-varying part.
    assert_eq!(a.expand_time_varying(v2), a.pow(arm, two));
    let full = a.expand(v2);
    assert!(matches!(a.node(full), Node::Add(_)));
}

/// The per-node summaries agree with a walk: `depends_on` and `diff` see the same
/// dependencies, and `tree_operation_count` is the tree count.
#[test]
fn node_summaries() {
    let mut a = ExprArena::new();
    let [q, qd, _] = a.coordinate("q");
    let l = a.symbol("l", SymbolKind::Parameter);
    let s = a.sin(q);
    let e = a.product(&[l, s, qd]);
    let ids: Vec<SymbolId> = (0..a.symbols().len() as u32).map(SymbolId).collect();
    assert!(a.depends_on(e, ids[0]) && a.depends_on(e, ids[1]) && !a.depends_on(e, ids[2]));
    assert!(a.contains_time_varying(e) && !a.contains_time_varying(l));
    let d = a.diff(e, ids[2]);
    assert!(a.is_zero(d));
    // l·sin(q)·q̇ twice: 2 multiplications and 1 call per tree, plus the sum.
    let twice = a.plus(e, s);
    assert_eq!(a.tree_operation_count(&[e]), 3);
    assert_eq!(a.tree_operation_count(&[twice]), 5);
}

/// A random expression tree over two symbols, built into an arena.
#[derive(Debug, Clone)]
enum Tree {
    X,
    Y,
    Num(i8),
    Add(Box<Tree>, Box<Tree>),
    Mul(Box<Tree>, Box<Tree>),
    Div(Box<Tree>, Box<Tree>),
    Pow(Box<Tree>, i8),
    Sqrt(Box<Tree>),
    F(Func, Box<Tree>),
    Atan2(Box<Tree>, Box<Tree>),
}

fn tree() -> impl Strategy<Value = Tree> {
    let leaf = prop_oneof![Just(Tree::X), Just(Tree::Y), (-5i8..=5).prop_map(Tree::Num)];
    leaf.prop_recursive(5, 40, 3, |inner| {
        let smooth = prop_oneof![
            Just(Func::Sin),
            Just(Func::Cos),
            Just(Func::Tan),
            Just(Func::Atan),
            Just(Func::Sinh),
            Just(Func::Cosh),
            Just(Func::Tanh),
            Just(Func::Exp),
        ];
        prop_oneof![
            (inner.clone(), inner.clone()).prop_map(|(a, b)| Tree::Add(a.into(), b.into())),
            (inner.clone(), inner.clone()).prop_map(|(a, b)| Tree::Mul(a.into(), b.into())),
            (inner.clone(), inner.clone()).prop_map(|(a, b)| Tree::Div(a.into(), b.into())),
            (inner.clone(), -3i8..=3).prop_map(|(a, n)| Tree::Pow(a.into(), n)),
            inner.clone().prop_map(|a| Tree::Sqrt(a.into())),
            (smooth, inner.clone()).prop_map(|(f, a)| Tree::F(f, a.into())),
            (inner.clone(), inner).prop_map(|(a, b)| Tree::Atan2(a.into(), b.into())),
        ]
    })
}

fn build(a: &mut ExprArena, t: &Tree, x: ExprId, y: ExprId) -> ExprId {
    match t {
        Tree::X => x,
        Tree::Y => y,
        Tree::Num(n) => a.int(i64::from(*n)),
        Tree::Add(p, q) => {
            let (p, q) = (build(a, p, x, y), build(a, q, x, y));
            a.plus(p, q)
        }
        Tree::Mul(p, q) => {
            let (p, q) = (build(a, p, x, y), build(a, q, x, y));
            a.times(p, q)
        }
        Tree::Div(p, q) => {
            let (p, q) = (build(a, p, x, y), build(a, q, x, y));
            a.divide(p, q)
        }
        Tree::Pow(p, n) => {
            let p = build(a, p, x, y);
            let n = a.int(i64::from(*n));
            a.pow(p, n)
        }
        Tree::Sqrt(p) => {
            let p = build(a, p, x, y);
            let sq = a.times(p, p);
            let one = a.int(1);
            let s = a.plus(sq, one);
            a.sqrt(s)
        }
        Tree::F(f, p) => {
            let p = build(a, p, x, y);
            a.func(*f, p)
        }
        Tree::Atan2(p, q) => {
            let (p, q) = (build(a, p, x, y), build(a, q, x, y));
            a.atan2(p, q)
        }
    }
}

/// Direct evaluation of the tree, independent of the arena. Any non-finite intermediate
/// value makes the result NaN (so the property tests skip the state): `atan2(y, x/0)` is
/// finite, but its derivative at a division by an exact zero is not defined.
fn eval_tree(t: &Tree, x: f64, y: f64) -> f64 {
    let v = eval_node(t, x, y);
    if v.is_finite() { v } else { f64::NAN }
}

fn eval_node(t: &Tree, x: f64, y: f64) -> f64 {
    match t {
        Tree::X => x,
        Tree::Y => y,
        Tree::Num(n) => f64::from(*n),
        Tree::Add(p, q) => eval_tree(p, x, y) + eval_tree(q, x, y),
        Tree::Mul(p, q) => eval_tree(p, x, y) * eval_tree(q, x, y),
        Tree::Div(p, q) => eval_tree(p, x, y) / eval_tree(q, x, y),
        Tree::Pow(p, n) => eval_tree(p, x, y).powi(i32::from(*n)),
        Tree::Sqrt(p) => {
            let v = eval_tree(p, x, y);
            (v * v + 1.0).sqrt()
        }
        Tree::F(f, p) => f.apply(eval_tree(p, x, y)),
        Tree::Atan2(p, q) => {
            let (a, b) = (eval_tree(p, x, y), eval_tree(q, x, y));
            // On the branch cut (a = ±0, b ≤ 0, including b = −0) the value is ±π or 0 by
            // the signs of zeros, which canonical folding (x·0 = +0, 0/x = +0) does not keep:
            // skip such states.
            if a == 0.0 && b <= 0.0 {
                f64::NAN
            } else {
                a.atan2(b)
            }
        }
    }
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * (1.0 + a.abs().max(b.abs()))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, .. ProptestConfig::default() })]

    /// Canonicalisation preserves values: the arena's evaluation equals direct evaluation of
    /// the tree. Tolerance 1e-9 relative: canonical reordering changes rounding only.
    #[test]
    fn canonical_form_preserves_value(t in tree(), x in -2.0f64..2.0, y in -2.0f64..2.0) {
        let direct = eval_tree(&t, x, y);
        prop_assume!(direct.is_finite() && direct.abs() < 1e6);
        let (mut a, ex, ey, _, _) = arena_xy();
        let e = build(&mut a, &t, ex, ey);
        let v = a.eval(e, &[x, y]);
        prop_assert!(close(v, direct, 1e-9), "arena {v} vs direct {direct}");
    }

    /// `eval(diff(e, x))` equals the central difference `(e(x+h) − e(x−h))/2h`. With
    /// h = 1e-5 the truncation error is O(h² e''') and roundoff O(ε|e|/h), about 1e-10 for
    /// moderate e; we require 1e-5 relative, and skip states where e is huge or near a
    /// singularity (the difference quotient itself is then meaningless).
    #[test]
    fn derivative_matches_central_difference(t in tree(), x in -2.0f64..2.0, y in -2.0f64..2.0) {
        let h = 1e-5;
        let f0 = eval_tree(&t, x, y);
        let fp = eval_tree(&t, x + h, y);
        let fm = eval_tree(&t, x - h, y);
        let fpp = eval_tree(&t, x + 2.0 * h, y);
        let fmm = eval_tree(&t, x - 2.0 * h, y);
        prop_assume!([f0, fp, fm, fpp, fmm].iter().all(|v| v.is_finite() && v.abs() < 1e4));
        let fd = (fp - fm) / (2.0 * h);
        let fd2 = (fpp - fmm) / (4.0 * h);
        // Skip near-singular points where two step sizes disagree.
        prop_assume!(close(fd, fd2, 1e-6));
        let (mut a, ex, ey, sx, _) = arena_xy();
        let e = build(&mut a, &t, ex, ey);
        let d = a.diff(e, sx);
        let v = a.eval(d, &[x, y]);
        prop_assert!(close(v, fd, 1e-5), "diff {v} vs central difference {fd}");
    }

    /// Distributive expansion preserves values. Multiplying out turns a few large factors into
    /// many monomials whose sum may cancel, so rounding can grow to ~1e-10 of the value scale;
    /// the bound is 1e-6·(1 + |value|), far below any wrong term (states where the tree has a
    /// non-finite intermediate are skipped).
    #[test]
    fn expansion_preserves_value(t in tree(), x in -2.0f64..2.0, y in -2.0f64..2.0) {
        let direct = eval_tree(&t, x, y);
        prop_assume!(direct.is_finite() && direct.abs() < 1e4);
        let (mut a, ex, ey, _, _) = arena_xy();
        let e = build(&mut a, &t, ex, ey);
        let expanded = a.expand(e);
        let v = a.eval(expanded, &[x, y]);
        prop_assert!((v - direct).abs() <= 1e-6 * (1.0 + direct.abs()), "expanded {v} vs direct {direct}");
    }

    /// Collection by time-varying factors (after multiplying out) preserves values, with `x`
    /// a coordinate and `y` a parameter so that both kinds of factor occur.
    #[test]
    fn collection_preserves_value(t in tree(), x in -2.0f64..2.0, y in -2.0f64..2.0) {
        let direct = eval_tree(&t, x, y);
        prop_assume!(direct.is_finite() && direct.abs() < 1e4);
        let mut a = ExprArena::new();
        let [ex, _, _] = a.coordinate("x");
        let ey = a.symbol("y", SymbolKind::Parameter);
        let e = build(&mut a, &t, ex, ey);
        let expanded = a.expand_time_varying(e);
        let collected = a.collect_time_varying(expanded);
        let mut bindings = vec![0.0; a.symbols().len()];
        bindings[0] = x;
        bindings[3] = y;
        let v = a.eval(collected, &bindings);
        prop_assert!((v - direct).abs() <= 1e-6 * (1.0 + direct.abs()), "collected {v} vs direct {direct}");
    }

    /// CSE preserves values: evaluating the plan's temporaries then roots (through the text
    /// printer's definitions) equals direct evaluation; and the plan never costs more
    /// operations than the trees.
    #[test]
    fn cse_plan_preserves_value(t in tree(), u in tree(), x in -2.0f64..2.0, y in -2.0f64..2.0) {
        let (mut a, ex, ey, sx, _) = arena_xy();
        let e1 = build(&mut a, &t, ex, ey);
        let e2 = build(&mut a, &u, ex, ey);
        let d = a.diff(e1, sx);
        let roots = [e1, e2, d];
        let p = plan(&a, &roots, "t");
        prop_assert!(p.operation_count() <= a.tree_operation_count(&roots));
        // The count alone (for choosing between forms) is the plan's.
        prop_assert_eq!(cse::operation_count(&a, &roots), p.operation_count());
        // Evaluate temporaries in order with a tiny interpreter over the plan.
        let mut values: rustc_hash::FxHashMap<ExprId, f64> = Default::default();
        let mut direct = Evaluator::new(&a, &roots);
        let expected = direct.eval(&[x, y]);
        for temp in &p.temporaries {
            match *temp {
                cse::Temporary::Single(e) => {
                    let v = a.eval(e, &[x, y]);
                    values.insert(e, v);
                }
                cse::Temporary::SinCos { arg, sin, cos } => {
                    let (s, c) = a.eval(arg, &[x, y]).sin_cos();
                    values.insert(sin, s);
                    values.insert(cos, c);
                }
            }
        }
        for (r, ex) in roots.iter().zip(&expected) {
            let v = values.get(r).copied().unwrap_or_else(|| a.eval(*r, &[x, y]));
            prop_assert!(v == *ex || (v.is_nan() && ex.is_nan()) || close(v, *ex, 1e-12));
        }
    }
}

#[test]
fn cse_shares_sin_cos_and_repeated_terms() {
    let mut a = ExprArena::new();
    let [q, qd, _] = a.coordinate("q");
    let l = a.symbol("l", SymbolKind::Parameter);
    let s = a.sin(q);
    let c = a.cos(q);
    let ls = a.times(l, s);
    let lc = a.times(l, c);
    let v = a.product(&[ls, qd]);
    let w = a.product(&[lc, qd]);
    let p = plan(&a, &[v, w, s], "t");
    let pairs = p
        .temporaries
        .iter()
        .filter(|t| matches!(t, cse::Temporary::SinCos { .. }))
        .count();
    assert_eq!(pairs, 1, "{:?}", p.temporaries);
    assert_eq!(p.name_of(s), Some("t0_s"));
    assert_eq!(cse::operation_count(&a, &[v, w, s]), p.operation_count());
}

#[test]
fn printing() {
    let mut a = ExprArena::new();
    let [q, qd, _] = a.coordinate("theta1");
    let m = a.symbol("m", SymbolKind::Parameter);
    let l = a.symbol("l", SymbolKind::Parameter);
    let two = a.int(2);
    let half = a.constant(Constant::rational(1, 2).unwrap());
    let l2 = a.pow(l, two);
    let qd2 = a.pow(qd, two);
    let t = a.product(&[half, m, l2, qd2]);
    let text = Printer::new(&a, Syntax::Text).print(t);
    assert_eq!(text, "m*l^2*theta1_dot^2/2");
    let rust = Printer::new(&a, Syntax::Rust).print(t);
    assert_eq!(rust, "0.5_f64 * m * l.powi(2) * theta1_dot.powi(2)");
    let latex = Printer::new(&a, Syntax::Latex).print(t);
    assert_eq!(latex, "\\frac{m l^{2} \\dot{\\theta}_{1}^{2}}{2}");
    let c = a.cos(q);
    let v = a.times(m, c);
    let g = a.symbol("g", SymbolKind::Parameter);
    let mg = a.times(m, g);
    let e = a.minus(mg, v);
    assert_eq!(
        Printer::new(&a, Syntax::Text).print(e),
        "m*g - m*cos(theta1)"
    );
    // MathML: the same structure as the LaTeX, every subexpression one element.
    let mathml = Printer::new(&a, Syntax::MathMl).print(t);
    assert_eq!(
        mathml,
        "<mfrac><mrow><mi>m</mi><mo>\u{2062}</mo><msup><mi>l</mi><mn>2</mn></msup><mo>\u{2062}</mo><msup><msub><mover accent=\"true\"><mi>θ</mi><mo>\u{2d9}</mo></mover><mn>1</mn></msub><mn>2</mn></msup></mrow><mn>2</mn></mfrac>"
    );
    assert_eq!(
        Printer::new(&a, Syntax::MathMl).print(e),
        "<mrow><mrow><mi>m</mi><mo>\u{2062}</mo><mi>g</mi></mrow><mo>\u{2212}</mo><mrow><mi>m</mi><mo>\u{2062}</mo><mrow><mi>cos</mi><mo>\u{2061}</mo><mrow><mo>(</mo><msub><mi>θ</mi><mn>1</mn></msub><mo>)</mo></mrow></mrow></mrow></mrow>"
    );
}

#[test]
fn operation_counts() {
    let (mut a, x, y, _, _) = arena_xy();
    let s = a.plus(x, y);
    let p = a.times(s, s); // (x+y)^2: pow node
    let q = a.sin(s);
    let r = a.plus(p, q);
    // trees: r = p + q: 1; p = s^2: 1 + s(1); q = sin s: 1 + s(1) → 5
    assert_eq!(a.tree_operation_count(&[r]), 5);
    // shared: s once → 4
    assert_eq!(plan(&a, &[r], "t").operation_count(), 4);
}

/// Issue 28: quadratic drag `|v| v` from rest failed the implicit methods on a Jacobian that
/// was not finite. The derivatives of `abs`, `sign` and `step` are finite everywhere:
/// `d|x|/dx = sign(x)` with `sign(0) = 0`, and `sign' = step' = 0` (0 at the kink too).
#[test]
fn derivatives_at_kinks_are_finite() {
    let (mut a, x, y, sx, _) = arena_xy();
    let abs = a.func(Func::Abs, x);
    let drag = a.times(abs, x);
    let sign = a.func(Func::Sign, x);
    let step = a.func(Func::Step, x);
    let shifted = a.minus(x, y);
    let step_shifted = a.func(Func::Step, shifted);
    let abs_shifted = a.func(Func::Abs, shifted);
    let cases = [drag, abs, sign, step, step_shifted, abs_shifted];
    let derivatives: Vec<ExprId> = cases.iter().map(|&e| a.diff(e, sx)).collect();
    for (x0, y0) in [(0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (-0.5, 2.0), (2.0, -1.0)] {
        let values: Vec<f64> = derivatives.iter().map(|&d| a.eval(d, &[x0, y0])).collect();
        // d(|x| x)/dx = 2|x|; d|x|/dx = sign(x); sign' = step' = 0.
        let expected = [
            2.0 * x0.abs(),
            Func::Sign.apply(x0),
            0.0,
            0.0,
            0.0,
            Func::Sign.apply(x0 - y0),
        ];
        assert_eq!(values, expected, "at x = {x0}, y = {y0}");
    }
    assert_eq!(Func::Sign.apply(0.0), 0.0);
    assert_eq!(Func::Sign.apply(-0.0), 0.0);
}

/// The node rules of the readable forms, each on the smallest expression that needs it,
/// printed as a textbook writes it and equal in value to the expression as built (at three
/// states, to 1e-14 relative): double angles, a fraction over a common divisor (`together`),
/// a denominator's fractions cleared, a sign taken out of a sum, and a positive term printed
/// first.
#[test]
fn readable_rules_print_textbook_forms() {
    let mut a = ExprArena::new();
    let [th, thd, _] = a.coordinate("theta");
    let [psi, _, _] = a.coordinate("psi");
    let p = |a: &mut ExprArena, name: &str| a.symbol(name, SymbolKind::Parameter);
    let (i1, i3, l, r, m, g) = (
        p(&mut a, "I1"),
        p(&mut a, "I3"),
        p(&mut a, "l"),
        p(&mut a, "r"),
        p(&mut a, "m"),
        p(&mut a, "g"),
    );
    let (two, minus_one, minus_two) = (a.int(2), a.int(-1), a.int(-2));
    let (s, c) = (a.sin(psi), a.cos(psi));
    let (s2, c2) = (a.pow(s, two), a.pow(c, two));
    let i13 = a.minus(i1, i3);
    let i31 = a.minus(i3, i1);
    let x = a.times(i13, c2);
    let y = a.times(i31, s2);
    let double_cos = a.plus(x, y);
    let double_sin = a.product(&[two, thd, s, c]);
    // D = l² − r² sin²θ; −1/D + r² cos²θ/D²
    let (st, ct) = (a.sin(th), a.cos(th));
    let (l2, r2, st2, ct2) = (a.pow(l, two), a.pow(r, two), a.pow(st, two), a.pow(ct, two));
    let r2st2 = a.times(r2, st2);
    let d = a.minus(l2, r2st2);
    let (d1, d2) = (a.pow(d, minus_one), a.pow(d, minus_two));
    let first = a.neg(d1);
    let second = a.product(&[r2, ct2, d2]);
    let together = a.plus(first, second);
    // 1/(1 − r² sin²θ/l²)
    let l_2 = a.pow(l, minus_two);
    let fraction = a.product(&[r2st2, l_2]);
    let one = a.int(1);
    let one_minus = a.minus(one, fraction);
    let cleared = a.pow(one_minus, minus_one);
    // g − m (r + l) θ̇ written m θ̇ (−r − l) + g, and −g + m r θ̇
    let nr = a.neg(r);
    let nl = a.neg(l);
    let negative = a.plus(nr, nl);
    let term = a.product(&[m, thd, negative]);
    let sign = a.plus(term, g);
    let ng = a.neg(g);
    let mrt = a.product(&[m, r, thd]);
    let order = a.plus(ng, mrt);
    let cases = [
        (double_cos, "(I1 - I3)*cos(2*psi)"),
        (double_sin, "theta_dot*sin(2*psi)"),
        (together, "(r^2 - l^2)/(l^2 - r^2*sin(theta)^2)^2"),
        (cleared, "l^2/(l^2 - r^2*sin(theta)^2)"),
        (sign, "g - theta_dot*m*(l + r)"),
        (order, "theta_dot*r*m - g"),
    ];
    let readable: Vec<ExprId> = cases.iter().map(|&(e, _)| a.readable(e)).collect();
    let printer = Printer::for_display(&a, Syntax::Text);
    let printed: Vec<String> = readable.iter().map(|&e| printer.print(e)).collect();
    let expected: Vec<&str> = cases.iter().map(|&(_, text)| text).collect();
    assert_eq!(printed, expected);
    let mut roots: Vec<ExprId> = cases.iter().map(|&(e, _)| e).collect();
    roots.extend(&readable);
    let mut evaluator = Evaluator::new(&a, &roots);
    for k in 0..3 {
        let bindings: Vec<f64> = (0..a.symbols().len())
            .map(|i| 0.3 + 0.17 * i as f64 + 0.41 * k as f64)
            .collect();
        let v = evaluator.eval(&bindings);
        for i in 0..cases.len() {
            let (x, y) = (v[i], v[cases.len() + i]);
            assert!(
                (x - y).abs() <= 1e-14 * x.abs().max(1.0),
                "{}: {x} against {y}",
                expected[i]
            );
        }
    }
}
