//! `M q̈ = F` as a series: the factor of `M⁰` once a step ([`factor_mass`]) and, order by
//! order, the accelerations and the state's next order ([`motion_order`]), dense in registers
//! for small `n` or over the factor's non-zero entries.

use super::slots::{at, known, put, series};
use crate::ode::RhsError;
use eomgen_description::taylor::{Slot, UNROLLED_CAPACITY};

/// Two values side by side, aligned for one 16-byte load: the unit of the scratch a run-time
/// backend's compiled orders keep between orders ([`MotionSolve::lanes`]).
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(16))]
pub struct Lanes(pub [f64; 2]);

/// Where [`motion_order`] finds the series of `F`, of the entries of `M` that vary and of the
/// accelerations, and where it writes the state's next order: the same lists for a program whether
/// the run-time [`series_of_motion`](super::series_of_motion) builds them from the program or the
/// `model!` macro prints them as constants (so that the compiler folds the loops over them into
/// straight-line code).
#[derive(Debug, Clone, Copy)]
pub struct MotionLayout<'a> {
    /// `F`'s slots ([`TaylorProgram::forcing`](super::TaylorProgram::forcing)), one per coordinate,
    /// then `γ`'s, one per constraint.
    pub forcing: &'a [Slot],
    /// [`DerivedLists::varying_mass_entries`](super::DerivedLists::varying_mass_entries).
    pub coupled: &'a [(u32, u32, Slot)],
    /// [`DerivedLists::inputs`](super::DerivedLists::inputs).
    pub inputs: &'a [(Slot, u32)],
    /// [`TaylorProgram::time`](super::TaylorProgram::time).
    pub time: Option<Slot>,
    /// [`TaylorProgram::acceleration_slot`](super::TaylorProgram::acceleration_slot).
    pub accelerations: Slot,
}

/// `M⁰`'s factor and the stride of one [`series_of_motion`](super::series_of_motion), for
/// [`motion_order`], and the workspace's scratch for a run-time backend's compiled orders
/// ([`Self::lanes`]).
#[derive(Debug)]
pub struct MotionSolve<'a> {
    /// The unknowns of each order: `n` accelerations, then `m` multipliers.
    pub(super) n: usize,
    /// `n`.
    pub(super) coordinates: usize,
    pub(super) c: usize,
    /// `L` has no zero below its diagonal.
    pub(super) dense: bool,
    pub(super) nonzeros: &'a [(u32, u32, f64)],
    /// `L`, row-major `n × n`.
    pub(super) lower: &'a [f64],
    pub(super) inverse_pivots: &'a [f64],
    pub(super) reciprocals: &'a [f64],
    pub(super) rhs: &'a mut [f64],
    pub(super) lanes: &'a mut Vec<Lanes>,
}

impl MotionSolve<'_> {
    /// At least `units` of the workspace's scratch for a run-time backend, kept between
    /// steps (grown when a backend asks for more, never shrunk): what the orders of one step
    /// wrote is there for the orders above, in that step.
    #[inline]
    pub fn lanes(&mut self, units: usize) -> &mut [Lanes] {
        if self.lanes.len() < units {
            self.lanes.resize(units, Lanes::default());
        }
        &mut self.lanes[..]
    }

    /// Whether the workspace has the stride of the code compiled for each order
    /// ([`UNROLLED_CAPACITY`]), the one [`motion_order`] with `K ≠ 0` needs.
    #[inline]
    pub fn unrolled(&self) -> bool {
        self.c == UNROLLED_CAPACITY
    }

    /// How [`motion_order`] solves with the step's factor, for a run-time backend that does
    /// the same in its own code ([`FactorForm`]): one test of the factor's shape a step.
    #[inline(always)]
    pub fn factor_form(&self) -> FactorForm<'_> {
        let n = self.n;
        if n == self.coordinates {
            if self.nonzeros.is_empty() {
                return FactorForm::Diagonal(&self.inverse_pivots[..n]);
            }
            if n <= FIXED_DEGREES {
                let factor = (&self.lower[..n * n], &self.inverse_pivots[..n]);
                return if self.dense {
                    FactorForm::Dense(factor.0, factor.1)
                } else {
                    FactorForm::Small(factor.0, factor.1)
                };
            }
        }
        FactorForm::General
    }
}

/// The shape of the step's factor `M⁰ = L D Lᵀ` ([`MotionSolve::factor_form`]), as
/// [`motion_order`] solves with it: `L z = b` row by row, `z ← D⁻¹ z`, then `Lᵀ x = z` from
/// the last row up. `L` is row-major `n × n` with its unit diagonal implied, `D⁻¹` has `n`
/// values.
#[derive(Debug, Clone, Copy)]
pub enum FactorForm<'a> {
    /// `L` is the identity (a diagonal `M`, no constraints): `x = D⁻¹ b` alone.
    Diagonal(&'a [f64]),
    /// `(L, D⁻¹)` with no zero below `L`'s diagonal and `n ≤ 6`: solved in registers.
    Dense(&'a [f64], &'a [f64]),
    /// `(L, D⁻¹)` with zeros below `L`'s diagonal and `n ≤ 6`, whose updates a backend must
    /// skip, as the solve over `L`'s non-zero entries does (`b − 0·x` is not `b` for `b = −0`
    /// or `x` infinite).
    Small(&'a [f64], &'a [f64]),
    /// Any other: more unknowns, or constraints ([`motion_order_at`]).
    General,
}

/// The largest `n` whose solves [`motion_order`] compiles for a known `n` (dense `L` in
/// registers).
const FIXED_DEGREES: usize = 6;

/// Order `k` of the accelerations `a` (into their slots) and order `k + 1` of the state
/// (into `out` and the input slots), once every slot holds its orders `≤ k`: `M⁰ a^[k] =
/// F^[k] − Σⱼ₌₁ᵏ M^[j] a^[k−j]` solved with the step's factor, `q^[k+1] = q̇^[k] / (k + 1)`,
/// `q̇^[k+1] = a^[k] / (k + 1)`, and `t`'s order `k + 1`.
///
/// `N` is `n` (the dense solve, `L` in registers, for `n ≤ 6`; larger `n` take the other),
/// or 0 for the solve over `L`'s non-zero entries, which the function takes anyway when `L`
/// has a zero below its diagonal; `K` is `k` for the code compiled for that order (the workspace
/// then has [`MotionSolve::unrolled`]'s stride), or 0. Every variant computes the same
/// bits. The orders follow each other through this function (order `k + 1` of every op
/// waits for `a^[k]`): the `model!` macro's code inlines it after each order's ops, with its
/// `layout` a constant.
///
/// # Panics
/// If `out` has fewer than `(k + 2) · 2n` entries, or `layout` and `s` are not those of the
/// [`series_of_motion`](super::series_of_motion) `solve` comes from.
#[inline(always)]
pub fn motion_order<const N: usize, const K: usize>(
    layout: &MotionLayout<'_>,
    solve: &mut MotionSolve<'_>,
    k: usize,
    s: &mut [f64],
    out: &mut [f64],
) {
    if N != 0 && N <= FIXED_DEGREES && solve.dense {
        dense_order::<N, K>(layout, solve, k, s, out);
    } else {
        sparse_order::<K>(layout, solve, k, s, out);
    }
}

/// Order `k` of `M a = F` as [`motion_order`] computes it, for a run-time `n` and `k` (the
/// variant compiled for them): what a run-time backend's own fused orders call between its
/// orders (the JIT's Cranelift code), the same bits as a compiled model's.
///
/// # Panics
/// If `s` or `out` is too short for the layout and `k` (a program and workspace that do not
/// belong together).
pub fn motion_order_at(
    layout: &MotionLayout<'_>,
    solve: &mut MotionSolve<'_>,
    k: usize,
    s: &mut [f64],
    out: &mut [f64],
) {
    accelerations(layout, solve, k, s, out);
}

/// [`motion_order`] for the run-time `n` and `k`: the variant compiled for them.
#[inline]
pub(super) fn accelerations(
    layout: &MotionLayout<'_>,
    solve: &mut MotionSolve<'_>,
    k: usize,
    s: &mut [f64],
    out: &mut [f64],
) {
    /// One variant, out of line (the dispatch would otherwise inline 7 × 20 of them).
    #[inline(never)]
    fn variant<const N: usize, const K: usize>(
        layout: &MotionLayout<'_>,
        solve: &mut MotionSolve<'_>,
        k: usize,
        s: &mut [f64],
        out: &mut [f64],
    ) {
        motion_order::<N, K>(layout, solve, k, s, out);
    }
    let unrolled = solve.unrolled();
    macro_rules! orders {
        ($n:literal; $($order:literal)*) => {
            match k {
                $($order if unrolled => variant::<$n, $order>(layout, solve, k, s, out),)*
                _ => variant::<$n, 0>(layout, solve, k, s, out),
            }
        };
    }
    const _: () = assert!(FIXED_DEGREES == 6);
    if !solve.dense {
        return unrolled_orders!(orders, 0);
    }
    match solve.n {
        1 => unrolled_orders!(orders, 1),
        2 => unrolled_orders!(orders, 2),
        3 => unrolled_orders!(orders, 3),
        4 => unrolled_orders!(orders, 4),
        5 => unrolled_orders!(orders, 5),
        6 => unrolled_orders!(orders, 6),
        _ => unrolled_orders!(orders, 0),
    }
}

/// [`motion_order`] with `L` dense, `n = N`.
#[inline(always)]
fn dense_order<const N: usize, const K: usize>(
    layout: &MotionLayout<'_>,
    solve: &MotionSolve<'_>,
    k: usize,
    s: &mut [f64],
    out: &mut [f64],
) {
    let (k, c) = known::<K>(k, solve.c);
    let mut b = [0.0; N];
    for (r, &slot) in b.iter_mut().zip(layout.forcing) {
        *r = at(s, c, slot, k);
    }
    coupled_sums::<K>(k, c, s, layout, &mut b);
    // L z = b, z ← D⁻¹ z, Lᵀ x = z, with L full (no zero below its diagonal).
    let lower = &solve.lower[..N * N];
    for i in 0..N {
        for j in 0..i {
            b[i] -= lower[i * N + j] * b[j];
        }
    }
    for (x, d) in b.iter_mut().zip(solve.inverse_pivots) {
        *x *= d;
    }
    for i in (0..N).rev() {
        for j in 0..i {
            b[j] -= lower[i * N + j] * b[i];
        }
    }
    next_order(layout, solve.reciprocals, k, c, s, &b, N, out);
}

/// [`motion_order`] over `L`'s non-zero entries, any `n`.
#[inline(always)]
fn sparse_order<const K: usize>(
    layout: &MotionLayout<'_>,
    solve: &mut MotionSolve<'_>,
    k: usize,
    s: &mut [f64],
    out: &mut [f64],
) {
    let (k, c) = known::<K>(k, solve.c);
    let b = &mut *solve.rhs;
    for (r, &slot) in b.iter_mut().zip(layout.forcing) {
        *r = at(s, c, slot, k);
    }
    coupled_sums::<K>(k, c, s, layout, b);
    self::solve(solve.nonzeros, solve.inverse_pivots, b);
    next_order(
        layout,
        solve.reciprocals,
        k,
        c,
        s,
        b,
        solve.coordinates,
        out,
    );
}

/// Stores `a^[k] = b` (`[q̈^[k]; λ^[k]]` with constraints) and the state's order `k + 1` (see
/// [`motion_order`]); `n` is the number of coordinates (`b`'s first `n` entries are `q̈^[k]`).
#[inline(always)]
#[allow(clippy::too_many_arguments)] // the solve's pieces, inlined into each variant
fn next_order(
    layout: &MotionLayout<'_>,
    reciprocals: &[f64],
    k: usize,
    c: usize,
    s: &mut [f64],
    b: &[f64],
    n: usize,
    out: &mut [f64],
) {
    let dim = 2 * n;
    let inverse = reciprocals[k];
    let (now, next) = out[k * dim..(k + 2) * dim].split_at_mut(dim);
    let (q_next, v_next) = next.split_at_mut(n);
    for i in 0..n {
        put(s, c, layout.accelerations + i as Slot, k, b[i]);
        q_next[i] = now[n + i] * inverse;
        v_next[i] = b[i] * inverse;
    }
    for (i, &multiplier) in b.iter().enumerate().skip(n) {
        put(s, c, layout.accelerations + i as Slot, k, multiplier);
    }
    if k + 1 < c {
        for &(slot, index) in layout.inputs {
            put(s, c, slot, k + 1, next[index as usize]);
        }
        if let Some(slot) = layout.time {
            put(s, c, slot, k + 1, if k == 0 { 1.0 } else { 0.0 });
        }
    }
}

/// `b[i] −= Σⱼ₌₁ᵏ M_il^[j] a_l^[k−j]` for each entry `(i, l, slot)` of `M` that varies (`k`
/// known when `K ≠ 0`; nothing at `k = 0`).
#[inline(always)]
fn coupled_sums<const K: usize>(
    k: usize,
    c: usize,
    s: &[f64],
    layout: &MotionLayout<'_>,
    b: &mut [f64],
) {
    let (k, c) = known::<K>(k, c);
    if k == 0 {
        return;
    }
    for &(i, l, slot) in layout.coupled {
        let m = &s[slot as usize * c + 1..][..k];
        let a = &series(s, c, layout.accelerations + l)[..k];
        // The sum apart from `b` (`F^[k]`, the order's last value), in increasing `j`:
        // formed while the order's ops run, then one subtraction (subtracting term by term
        // from `b` made the whole sum wait for `F^[k]`: 3–4 % of a double-pendulum run at
        // 10⁻⁹ and 10⁻¹²; the term of `a^[k−1]`, the newest, last instead of first: no
        // change).
        let mut sum = 0.0;
        for (x, y) in m.iter().zip(a.iter().rev()) {
            sum += x * y;
        }
        b[i as usize] -= sum;
    }
}

/// Where [`factor_mass`] writes the factor of an `unknowns × unknowns` matrix whose first
/// `positive` pivots are positive and the rest negative (see [`factor`]).
pub(super) struct Factors<'a> {
    pub(super) unknowns: usize,
    pub(super) positive: usize,
    pub(super) lower: &'a mut [f64],
    pub(super) pivots: &'a mut [f64],
    pub(super) inverse_pivots: &'a mut [f64],
    pub(super) nonzeros: &'a mut Vec<(u32, u32, f64)>,
}

/// [`factor`] of `M` (entry `e` column-major is `mass(e)`; `[M Jᵀ; J 0]` with constraints,
/// [`RhsError::SingularConstraintMatrix`] when a pivot of its constraints' block fails), then the list of the factor's
/// entries below the diagonal that are not zero, which the solves of every order visit (a
/// model's `M` is often sparse: bodies that do not share a coordinate).
#[inline(always)]
pub(super) fn factor_mass(
    mass: impl Fn(usize) -> f64,
    factors: Factors<'_>,
) -> Result<(), RhsError> {
    let Factors {
        unknowns: n,
        positive,
        lower,
        pivots,
        inverse_pivots,
        nonzeros,
    } = factors;
    factor(
        n,
        positive,
        |i, j| mass(i + j * n),
        lower,
        pivots,
        inverse_pivots,
    )
    .map_err(|pivot| {
        if pivot < positive {
            RhsError::SingularMassMatrix
        } else {
            RhsError::SingularConstraintMatrix
        }
    })?;
    nonzeros.clear();
    if n == 2 {
        // Two unknowns (the closed form's): the one entry below the diagonal, without the
        // loops' bookkeeping (41 instructions a step on the double pendulum).
        if lower[2] != 0.0 {
            nonzeros.push((1, 0, lower[2]));
        }
        return Ok(());
    }
    for i in 0..n {
        for (j, &l) in lower[i * n..i * n + i].iter().enumerate() {
            if l != 0.0 {
                nonzeros.push((i as u32, j as u32, l));
            }
        }
    }
    Ok(())
}

/// `L D Lᵀ` of the symmetric `n × n` matrix `m(i, j)` (lower triangle read) into `lower`
/// (row-major, unit diagonal implied), `pivots` (`D`) and `inverse_pivots` (`D⁻¹`, so that
/// each order's solve multiplies where it would divide), with the first `positive` pivots
/// positive and the rest negative; else `Err` with the first pivot that is not.
///
/// With `positive = n` that is `M` positive definite. With `positive = n` coordinates and
/// `m` constraints, `[M Jᵀ; J 0]` factors so exactly when `M` is positive definite and `J`
/// has full row rank: the last `m` pivots are those of the Schur complement `−J M⁻¹ Jᵀ`,
/// negative definite (the range-space method; Nocedal & Wright, *Numerical Optimization*,
/// 2nd ed., §16.2, and §16.1 on the inertia of such a matrix), so no pivoting is needed and
/// the factor's solves are `M`'s and those of the complement.
#[inline]
fn factor(
    n: usize,
    positive: usize,
    m: impl Fn(usize, usize) -> f64,
    lower: &mut [f64],
    pivots: &mut [f64],
    inverse_pivots: &mut [f64],
) -> Result<(), usize> {
    if n == 2 && positive == 2 {
        // The second pivot as `det M / M₁₁`, so that its reciprocal `M₁₁ / det M` does not
        // wait for the first (the two divisions run side by side; one after the other they
        // lay on the path from a step's order 0 to its order 1). Only where `det M` and that
        // reciprocal are normal numbers: `M₁₁ M₂₂` overflows or underflows for entries
        // beyond about 1e±154, where the loop below, which never forms it, still factors.
        let (m11, m21, m22) = (m(0, 0), m(1, 0), m(1, 1));
        let det = m11 * m22 - m21 * m21;
        let inverse_det = 1.0 / det;
        let second = m11 * inverse_det;
        if m11 > 0.0 && m11.is_finite() && det.is_normal() && det > 0.0 && second.is_normal() {
            let inverse = 1.0 / m11;
            pivots[0] = m11;
            inverse_pivots[0] = inverse;
            lower[2] = m21 * inverse;
            pivots[1] = det * inverse;
            inverse_pivots[1] = second;
            return Ok(());
        }
    }
    // The loops below with `n` a constant for the usual sizes, so that they unroll (the same
    // operations in the same order; the loops over any `n` took 328 instructions a step for
    // the heavy top's 3 × 3 `M`).
    match n {
        3 => factor_loops(3, positive, m, lower, pivots, inverse_pivots),
        4 => factor_loops(4, positive, m, lower, pivots, inverse_pivots),
        5 => factor_loops(5, positive, m, lower, pivots, inverse_pivots),
        6 => factor_loops(6, positive, m, lower, pivots, inverse_pivots),
        _ => factor_loops(n, positive, m, lower, pivots, inverse_pivots),
    }
}

/// [`factor`]'s loops (`L D Lᵀ` column by column), in line in each of its size's copies.
#[inline(always)]
fn factor_loops(
    n: usize,
    positive: usize,
    m: impl Fn(usize, usize) -> f64,
    lower: &mut [f64],
    pivots: &mut [f64],
    inverse_pivots: &mut [f64],
) -> Result<(), usize> {
    let (lower, pivots, inverse_pivots) = (
        &mut lower[..n * n],
        &mut pivots[..n],
        &mut inverse_pivots[..n],
    );
    for j in 0..n {
        let mut d = m(j, j);
        for k in 0..j {
            d -= lower[j * n + k] * lower[j * n + k] * pivots[k];
        }
        // Not of its sign (positive, then negative), or NaN.
        let signed = if j < positive { d } else { -d };
        if signed.is_nan() || signed <= 0.0 {
            return Err(j);
        }
        let inverse = 1.0 / d;
        pivots[j] = d;
        inverse_pivots[j] = inverse;
        for i in j + 1..n {
            let mut v = m(i, j);
            for k in 0..j {
                v -= lower[i * n + k] * lower[j * n + k] * pivots[k];
            }
            lower[i * n + j] = v * inverse;
        }
    }
    Ok(())
}

/// Solves `L D Lᵀ x = b` in place, with `L`'s entries below the diagonal that are not zero
/// listed row by row as `(row, column, value)` and `inverse_pivots` = `D⁻¹`.
#[inline(always)]
fn solve(nonzeros: &[(u32, u32, f64)], inverse_pivots: &[f64], b: &mut [f64]) {
    // L z = b, row by row: each row's earlier entries are final when it is reached.
    for &(i, j, l) in nonzeros {
        b[i as usize] -= l * b[j as usize];
    }
    for (x, d) in b.iter_mut().zip(inverse_pivots) {
        *x *= d;
    }
    // Lᵀ x = z, from the last row of L up: x[row] is final before its column is updated.
    for &(i, j, l) in nonzeros.iter().rev() {
        b[j as usize] -= l * b[i as usize];
    }
}

#[cfg(test)]
mod tests {
    use super::factor;

    /// `L D Lᵀ` reproduces the matrix (to rounding: a few ulps of its largest entry), for two
    /// coordinates (the closed form) and three (the loops), and a matrix that is not positive
    /// definite, or NaN, has no factor.
    #[test]
    fn factor_reproduces_the_matrix_and_refuses_what_is_not_positive_definite() {
        let cases: [&[f64]; 3] = [
            &[4.0, 1.5, 1.5, 2.0],
            &[1e-3, 2e-4, 2e-4, 5e2],
            &[4.0, 1.0, 0.5, 1.0, 3.0, -0.7, 0.5, -0.7, 2.0],
        ];
        for m in cases {
            let n = (m.len() as f64).sqrt() as usize;
            let (mut lower, mut d, mut inverse) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
            factor(n, n, |i, j| m[i + j * n], &mut lower, &mut d, &mut inverse).expect("a factor");
            let l = |i: usize, j: usize| match i.cmp(&j) {
                std::cmp::Ordering::Equal => 1.0,
                std::cmp::Ordering::Greater => lower[i * n + j],
                std::cmp::Ordering::Less => 0.0,
            };
            let largest = m.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            for i in 0..n {
                assert!(
                    (d[i] * inverse[i] - 1.0).abs() < 4.0 * f64::EPSILON,
                    "{m:?}"
                );
                for j in 0..n {
                    let v: f64 = (0..n).map(|k| l(i, k) * d[k] * l(j, k)).sum();
                    assert!(
                        (v - m[i + j * n]).abs() <= 8.0 * f64::EPSILON * largest,
                        "{m:?}: ({i}, {j}) {v}"
                    );
                }
            }
        }
        // The index-1 matrix `[M Jᵀ; J 0]` of two coordinates and one constraint: positive
        // pivots for `M`, a negative one for `−J M⁻¹ Jᵀ`, and `L D Lᵀ` reproduces it. (Entry
        // `(r, c)`, each row and column from 2 on a constraint `j`.)
        let index_one = |m: [f64; 4], j: [f64; 2]| {
            move |r: usize, c: usize| match (r < 2, c < 2) {
                (true, true) => m[r + 2 * c],
                (true, false) => j[r],
                (false, true) => j[c],
                (false, false) => 0.0,
            }
        };
        let (m, j) = ([4.0, 1.0, 1.0, 3.0], [0.6, 0.8]);
        let kkt = index_one(m, j);
        let (mut lower, mut d, mut inverse) = (vec![0.0; 9], vec![0.0; 3], vec![0.0; 3]);
        factor(3, 2, kkt, &mut lower, &mut d, &mut inverse).expect("a factor");
        assert!(d[0] > 0.0 && d[1] > 0.0 && d[2] < 0.0, "{d:?}");
        // −J M⁻¹ Jᵀ with M⁻¹ = [3 −1; −1 4] / 11.
        let schur = -(3.0 * 0.36 - 2.0 * 0.48 + 4.0 * 0.64) / 11.0;
        assert!(
            (d[2] - schur).abs() <= 4.0 * f64::EPSILON * schur.abs(),
            "{d:?}"
        );
        for r in 0..3 {
            for c in 0..3 {
                let l = |i: usize, k: usize| match i.cmp(&k) {
                    std::cmp::Ordering::Equal => 1.0,
                    std::cmp::Ordering::Greater => lower[i * 3 + k],
                    std::cmp::Ordering::Less => 0.0,
                };
                let v: f64 = (0..3).map(|k| l(r, k) * d[k] * l(c, k)).sum();
                assert!(
                    (v - kkt(r, c)).abs() <= 8.0 * f64::EPSILON * 4.0,
                    "({r}, {c}) {v}"
                );
            }
        }
        // The same constraint twice (dependent rows, a 4 × 4 matrix): the second constraint's
        // pivot is 0, the constraints' block fails (index ≥ n); an `M` that is not positive
        // definite fails within the coordinates' block (index < n).
        let (mut lower, mut d, mut inverse) = (vec![0.0; 16], vec![0.0; 4], vec![0.0; 4]);
        let dependent = factor(4, 2, index_one(m, j), &mut lower, &mut d, &mut inverse);
        assert_eq!(dependent, Err(3));
        let indefinite = index_one([1.0, 2.0, 2.0, 1.0], j);
        let (mut lower, mut d, mut inverse) = (vec![0.0; 9], vec![0.0; 3], vec![0.0; 3]);
        assert_eq!(
            factor(3, 2, indefinite, &mut lower, &mut d, &mut inverse),
            Err(1)
        );
        // Beyond the closed form's range (`M₁₁ M₂₂` overflows or underflows): the loop's
        // factor, exact for these diagonal and scaled matrices.
        for scale in [1e160, 1e200, 1e-160, 1e-170] {
            let m = [scale, 0.5 * scale, 0.5 * scale, scale];
            let (mut lower, mut d, mut inverse) = ([0.0; 4], [0.0; 2], [0.0; 2]);
            factor(2, 2, |i, j| m[i + j * 2], &mut lower, &mut d, &mut inverse).expect("a factor");
            assert_eq!((d[0], lower[2]), (scale, 0.5), "{scale:e}");
            assert!(
                (d[1] / (0.75 * scale) - 1.0).abs() < 4.0 * f64::EPSILON,
                "{scale:e}: {d:?}"
            );
            assert!(
                (inverse[1] * d[1] - 1.0).abs() < 4.0 * f64::EPSILON,
                "{scale:e}"
            );
        }
        let refused: [&[f64]; 4] = [
            &[1.0, 2.0, 2.0, 1.0],
            &[-1.0, 0.0, 0.0, 1.0],
            &[1.0, f64::NAN, f64::NAN, 1.0],
            &[1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        ];
        for m in refused {
            let n = (m.len() as f64).sqrt() as usize;
            let (mut lower, mut d, mut inverse) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
            assert!(
                factor(n, n, |i, j| m[i + j * n], &mut lower, &mut d, &mut inverse).is_err(),
                "{m:?}"
            );
        }
    }
}
