//! Verner's "most efficient" explicit Runge–Kutta pairs 6(5), 7(6), 8(7) and 9(8), each with
//! the interpolant of its own order: rows of [`Tableau`], stepped by the one explicit
//! Runge–Kutta stepper.
//!
//! A step propagates the higher-order solution (local extrapolation) and estimates its error
//! by the embedded one. The interpolant needs stages beyond the step's: they are evaluated
//! only for a step that contains a requested output time or an event
//! ([`Stepper::prepare_dense_output`](super::stepper::Stepper::prepare_dense_output)), as
//! OrdinaryDiffEq.jl's `lazy` option does.

use super::Integrator;
use super::controller::PiController;
use super::driver::{self, Control, Problem};
use super::error::IntegrationFailure;
use super::explicit_rk::ExplicitRk;
use super::solution::Solution;
use super::tableau::Tableau;
use crate::ode::OdeSystem;

/// The PI controller OrdinaryDiffEq.jl gives these pairs: exponents `β₁ = 7/(10p)` on the
/// current error and `β₂ = 2/(5p)` on the previous one (`p` the propagated order), safety 0.9,
/// step ratios in `[0.2, 10]`.
fn verner_controller(order: u32) -> PiController {
    let p = f64::from(order);
    PiController::new(0.7 / p, 0.4 / p)
}

/// Defines one public Verner pair: the type, its documentation and its integrator.
macro_rules! verner_pair {
    (
        $(#[$doc:meta])*
        $ty:ident,
        name: $name:literal,
        order: $order:literal,
        tableau: $tableau:expr $(,)?
    ) => {
        $(#[$doc])*
        #[derive(Debug, Clone)]
        pub struct $ty {
            controller: PiController,
        }

        pi_controlled_integrator!(
            $ty,
            name: $name,
            order: $order,
            error_order: $order - 1,
            controller: verner_controller($order),
            new_doc: "The method with OrdinaryDiffEq.jl's PI controller for its order: \
                      `PiController::new(0.7 / p, 0.4 / p)`.",
            stepper: |dim| ExplicitRk::new($tableau, dim),
        );
    };
}

verner_pair!(
    /// Verner's "most efficient" 6(5) pair (OrdinaryDiffEq.jl's `Vern6`): adaptive steps from
    /// the embedded fifth-order solution, the sixth-order one propagated, dense output of
    /// order 6.
    ///
    /// Nine stages, first same as last: eight evaluations of `F` per step. The error estimate is
    /// the RMS norm of `h Σ (bᵢ − b̂ᵢ) kᵢ` over `atol + rtol max(|y|, |y_new|)`; steps are accepted
    /// when it is at most 1, and the [`PiController`] (OrdinaryDiffEq.jl's defaults, `β₁ =
    /// 7/(10p)`, `β₂ = 2/(5p)`, unless replaced with [`with_controller`](Self::with_controller))
    /// proposes the next one. The interpolant (Verner's, of order 6) costs three more evaluations,
    /// made only for steps that contain a requested output time or an event. With
    /// [`IntegratorOptions::fixed_step`](super::IntegratorOptions::fixed_step) the method takes
    /// constant steps `dt` without error control.
    ///
    /// # Examples
    /// ```
    /// use eomgen_runtime::{Integrator, IntegratorOptions, OdeFn, OutputTimes, Verner65};
    ///
    /// // ẍ = −x, x(0) = 1, ẋ(0) = 0: x(t) = cos t.
    /// let mut oscillator = OdeFn::new(2, |_t: f64, y: &[f64], dy: &mut [f64]| {
    ///     dy[0] = y[1];
    ///     dy[1] = -y[0];
    /// });
    /// let options = IntegratorOptions::default().with_rtol(1e-10).with_atol(1e-10);
    /// let solution = Verner65::new().integrate(
    ///     &mut oscillator,
    ///     0.0,
    ///     &[1.0, 0.0],
    ///     10.0,
    ///     &OutputTimes::At(vec![2.5, 7.25, 10.0]),
    ///     &options,
    /// )?;
    /// for (t, y) in solution.iter() {
    ///     assert!((y[0] - t.cos()).abs() < 1e-8);
    /// }
    /// # Ok::<(), eomgen_runtime::IntegrationFailure>(())
    /// ```
    ///
    /// # References
    /// - J. H. Verner, "Numerically optimal Runge–Kutta pairs with interpolants", Numer.
    ///   Algorithms 53(2–3), 383–396, 2010, doi:10.1007/s11075-009-9290-3.
    /// - The coefficients: J. H. Verner, `RKV65.IIIXb.Efficient.00000144617.081204.RATOnWeb`,
    ///   <https://www.sfu.ca/~jverner/> (used with acknowledgement of the source, as its
    ///   author asks).
    /// - C. Rackauckas, Q. Nie, "DifferentialEquations.jl", J. Open Res. Softw. 5(1), 15,
    ///   2017, doi:10.5334/jors.151 (the controller defaults of OrdinaryDiffEq.jl).
    Verner65,
    name: "vern6",
    order: 6,
    tableau: Tableau::vern6(),
);

verner_pair!(
    /// Verner's "most efficient" 7(6) pair (OrdinaryDiffEq.jl's `Vern7`): adaptive steps from
    /// the embedded sixth-order solution, the seventh-order one propagated, dense output of
    /// order 7.
    ///
    /// Ten stages (the tenth enters only the error estimate), and `F` at the new state: ten
    /// evaluations of `F` per step. Error norm, acceptance and controller as for
    /// [`Verner65`]. The interpolant costs five more evaluations (its first extra stage is `F`
    /// at the step's end), made only for steps that contain a requested output time or an
    /// event. Verner's coefficients of 2008 for it satisfy the conditions of order 6 exactly
    /// and those of order 7 to about 3e-7, so its error is of order 7 until it reaches about
    /// 3e-7 · h⁸ · (the size of the elementary differentials), then of order 6.
    ///
    /// # References
    /// - J. H. Verner, "Numerically optimal Runge–Kutta pairs with interpolants", Numer.
    ///   Algorithms 53(2–3), 383–396, 2010, doi:10.1007/s11075-009-9290-3.
    /// - The coefficients: J. H. Verner, `RKV76.IIa.Efficient.00001675585.081206.OnWeb`,
    ///   <https://www.sfu.ca/~jverner/> (used with acknowledgement of the source, as its
    ///   author asks).
    Verner76,
    name: "vern7",
    order: 7,
    tableau: Tableau::vern7(),
);

verner_pair!(
    /// Verner's "most efficient" 8(7) pair (OrdinaryDiffEq.jl's `Vern8`): adaptive steps from
    /// the embedded seventh-order solution, the eighth-order one propagated, dense output of
    /// order 8.
    ///
    /// Thirteen stages and `F` at the new state: thirteen evaluations of `F` per step. Error
    /// norm, acceptance and controller as for [`Verner65`]. The interpolant costs seven more
    /// evaluations (its first extra stage is `F` at the step's end), made only for steps that
    /// contain a requested output time or an event.
    ///
    /// # References
    /// - J. H. Verner, "Numerically optimal Runge–Kutta pairs with interpolants", Numer.
    ///   Algorithms 53(2–3), 383–396, 2010, doi:10.1007/s11075-009-9290-3.
    /// - The coefficients: J. H. Verner, `RKV87.IIa.Efficient.000000282866.081208.FLOAT40OnWeb`,
    ///   <https://www.sfu.ca/~jverner/> (used with acknowledgement of the source, as its
    ///   author asks).
    Verner87,
    name: "vern8",
    order: 8,
    tableau: Tableau::vern8(),
);

verner_pair!(
    /// Verner's "most efficient" 9(8) pair (OrdinaryDiffEq.jl's `Vern9`): adaptive steps from
    /// the embedded eighth-order solution, the ninth-order one propagated, dense output of
    /// order 9.
    ///
    /// Sixteen stages and `F` at the new state: sixteen evaluations of `F` per step. Error
    /// norm, acceptance and controller as for [`Verner65`]. The interpolant costs nine more
    /// evaluations (its first extra stage is `F` at the step's end), made only for steps that
    /// contain a requested output time or an event. Meant for tolerances of 1e-12 and below.
    ///
    /// # References
    /// - J. H. Verner, "Numerically optimal Runge–Kutta pairs with interpolants", Numer.
    ///   Algorithms 53(2–3), 383–396, 2010, doi:10.1007/s11075-009-9290-3.
    /// - The coefficients: J. H. Verner, `RKV98.IIa.Efficient.000000349.081209.FLOAT6040OnWeb`,
    ///   <https://www.sfu.ca/~jverner/> (used with acknowledgement of the source, as its
    ///   author asks).
    Verner98,
    name: "vern9",
    order: 9,
    tableau: Tableau::vern9(),
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::dense_output::DenseOutput;
    use crate::integrate::options::ErrorWeights;
    use crate::integrate::stability_function::{StabilityPolynomial, explicit_tableau_methods};
    use crate::integrate::stepper::{CheckedRhs, StepFailure, Stepper};
    use crate::integrate::tableau::tests::tree_residuals;
    use crate::ode::{OdeFn, RhsError};

    /// A pair's tableau with its interpolant, under the names of the source's tables.
    struct Pair {
        tableau: Tableau,
        order: u32,
        stages: usize,
        fsal: bool,
        c: &'static [f64],
        a: &'static [&'static [f64]],
        b: &'static [f64],
        error: &'static [f64],
        degree: usize,
        interpolant: &'static [f64],
        nodes: &'static [f64],
        node_weights: &'static [f64],
    }

    impl Pair {
        fn new(tableau: Tableau) -> Self {
            let interpolant = tableau.interpolant().expect("an interpolant");
            Self {
                tableau,
                order: tableau.order(),
                stages: tableau.num_stages(),
                fsal: tableau.is_fsal(),
                c: interpolant.c,
                a: interpolant.a,
                b: tableau.b(),
                error: tableau.error_weights().expect("error weights"),
                degree: interpolant.degree,
                interpolant: interpolant.r,
                nodes: interpolant.nodes,
                node_weights: interpolant.node_weights,
            }
        }

        fn num_all_stages(&self) -> usize {
            self.c.len()
        }

        fn end_stage(&self) -> usize {
            self.tableau.end_stage()
        }

        fn interpolant_weights(&self, theta: f64) -> Vec<f64> {
            self.tableau
                .interpolant()
                .expect("an interpolant")
                .weights(theta)
        }
    }

    /// The four pairs, by name.
    fn pairs() -> [(&'static str, Pair); 4] {
        [
            ("vern6", Pair::new(Tableau::vern6())),
            ("vern7", Pair::new(Tableau::vern7())),
            ("vern8", Pair::new(Tableau::vern8())),
            ("vern9", Pair::new(Tableau::vern9())),
        ]
    }

    /// The full `S × S` matrix `A` of the first `stages` stages.
    fn full_a(tableau: &Pair, stages: usize) -> Vec<Vec<f64>> {
        (0..stages)
            .map(|i| {
                let mut row = vec![0.0; stages];
                row[..i].copy_from_slice(tableau.a[i]);
                row
            })
            .collect()
    }

    /// `w` padded with zeros to `len` entries.
    fn pad(w: &[f64], len: usize) -> Vec<f64> {
        let mut padded = vec![0.0; len];
        padded[..w.len()].copy_from_slice(w);
        padded
    }

    /// The residuals of the order conditions `Σ bᵢ Φᵢ(τ) = θ^|τ|/γ(τ)` for every tree up to
    /// `max_order`, each relative to the size of its terms, `Σ |bᵢ| Φᵢ(τ)` with `|aᵢⱼ|` (the
    /// sum of the absolute values of what the condition adds up; at least 1/γ), as
    /// `(|τ|, relative residual)`.
    fn relative_residuals(
        a: &[Vec<f64>],
        b: &[f64],
        max_order: u32,
        theta: f64,
    ) -> Vec<(u32, f64)> {
        let abs_a: Vec<Vec<f64>> = a
            .iter()
            .map(|row| row.iter().map(|x| x.abs()).collect())
            .collect();
        let abs_b: Vec<f64> = b.iter().map(|x| x.abs()).collect();
        // θ = 0 leaves the weighted sum itself (θ^|τ| = 0 for |τ| ≥ 1).
        let sizes = tree_residuals(&abs_a, &abs_b, max_order, 0.0);
        tree_residuals(a, b, max_order, theta)
            .into_iter()
            .zip(sizes)
            .map(|((order, residual), (_, size))| {
                (order, residual.abs() / size.max(f64::MIN_POSITIVE))
            })
            .collect()
    }

    /// The largest relative residual of the conditions up to `order` and that of order
    /// `order + 1` alone (the absolute residual there, to show the order is not higher).
    fn worst(a: &[Vec<f64>], b: &[f64], order: u32, theta: f64) -> (f64, f64) {
        let up_to = relative_residuals(a, b, order, theta)
            .into_iter()
            .map(|(_, r)| r)
            .fold(0.0, f64::max);
        let next = tree_residuals(a, b, order + 1, theta)
            .into_iter()
            .filter(|&(o, _)| o == order + 1)
            .map(|(_, r)| r.abs())
            .fold(0.0, f64::max);
        (up_to, next)
    }

    /// Bound on the relative residual of an order condition. The coefficients are the
    /// nearest doubles to exact values (rationals, numbers of Q(√6) and 40-digit decimals
    /// whose conditions hold to ~1e-35, checked in exact arithmetic when they were
    /// transcribed), so each term carries a relative rounding of a few ε = 2.2e-16 and the
    /// sum of up to ~26 terms per stage, over nested sums, ~30 ε of the size of its terms:
    /// 1e-14. (Observed at most ~2e-15; a wrong digit in any coefficient that enters a
    /// condition moves it by far more, and a condition of the next order fails by ≥ 1e-7.)
    const TOLERANCE: f64 = 1e-14;

    /// Bound on the relative residual of the interpolant's conditions: its weights `bᵢ(θ)`
    /// are evaluated in `f64` from coefficients up to 1.2e5 (6(5)) and 1.5e4 (8(7)) that
    /// cancel to weights of size ~1–70, and each coefficient is itself rounded, which costs
    /// up to ~1e4 ε relative to the weights' size (observed 1.3e-14 for 6(5), 2.3e-12 for
    /// 8(7)). A wrong digit among a coefficient's first ten moves a residual by more.
    const INTERPOLANT_TOLERANCE: f64 = 1e-11;

    #[test]
    fn shapes_are_consistent() {
        for (name, t) in &pairs() {
            let all = t.num_all_stages();
            assert_eq!(t.a.len(), all, "{name}");
            for (i, row) in t.a.iter().enumerate() {
                assert_eq!(row.len(), i, "{name} row {i}");
            }
            assert_eq!(t.b.len(), t.stages, "{name}");
            assert_eq!(t.error.len(), t.stages, "{name}");
            assert_eq!(t.interpolant.len(), all * t.degree, "{name}");
            assert_eq!(t.degree, t.order as usize, "{name}");
            assert_eq!(t.c[0], 0.0);
            // F at the step's end: node 1, and its row of `a` is `b`.
            let end = t.end_stage();
            assert_eq!(t.c[end], 1.0, "{name}");
            assert_eq!(t.a[end], &t.b[..end], "{name}");
            if t.fsal {
                assert_eq!(t.b[t.stages - 1], 0.0, "{name}");
            }
        }
    }

    /// `Σⱼ aᵢⱼ = cᵢ` for every stage, the interpolant's included, to a few rounding units of
    /// the row's size `Σⱼ |aᵢⱼ|` (rows of Verner 6(5)'s extra stages reach 7600 in size).
    #[test]
    fn rows_sum_to_the_nodes() {
        for (name, t) in &pairs() {
            for (i, row) in t.a.iter().enumerate() {
                let sum: f64 = row.iter().sum();
                let size: f64 = row.iter().map(|x| x.abs()).sum::<f64>().max(1.0);
                let error = (sum - t.c[i]).abs() / size;
                assert!(
                    error < 8.0 * f64::EPSILON,
                    "{name} row {i}: {sum} vs {} ({error:e})",
                    t.c[i]
                );
            }
        }
    }

    /// The propagated weights satisfy every order condition up to `p` (1, 2, 4, 9, 20, 48, 115,
    /// 286 trees of orders 1 … 8 and 9: 37 for order 6, 85, 200 and 486 for 9) and fail one of
    /// order `p + 1`; the embedded weights `b̂ = b − e` up to `p − 1` and fail one of order `p`.
    #[test]
    fn weights_have_orders_p_and_p_minus_1() {
        for (name, t) in &pairs() {
            let p = t.order;
            let a = full_a(t, t.stages);
            let (up_to, next) = worst(&a, t.b, p, 1.0);
            println!(
                "{name}: b up to order {p}: {up_to:.1e}; order {}: {next:.1e}",
                p + 1
            );
            assert!(up_to < TOLERANCE, "{name}: {up_to:e}");
            assert!(next > 1e-8, "{name}: order {} too ({next:e})", p + 1);
            let embedded: Vec<f64> = t.b.iter().zip(t.error).map(|(b, e)| b - e).collect();
            let (up_to, next) = worst(&a, &embedded, p - 1, 1.0);
            println!(
                "{name}: b̂ up to order {}: {up_to:.1e}; order {p}: {next:.1e}",
                p - 1
            );
            assert!(up_to < TOLERANCE, "{name} embedded: {up_to:e}");
            assert!(next > 1e-8, "{name} embedded: order {p} too ({next:e})");
        }
    }

    /// The interpolant's weights `bᵢ(θ)` satisfy the order conditions of their order at
    /// θ = 0.1, 0.2, …, 0.9 (the extra stages and the polynomials together): order `p` for
    /// 6(5), 8(7) and 9(8). For 7(6), Verner's coefficients of 2008 satisfy those of order 6
    /// exactly and those of order 7 only to ~3e-7 (absolute; the trees `[τ]` with `τ` of order
    /// 6, where the extra stages' conditions `Σⱼ aᵢⱼ cⱼ⁶ = cᵢ⁷/7` are not met): that is
    /// asserted as it is, at 1e-6.
    #[test]
    fn interpolants_have_their_orders() {
        for (name, t) in &pairs() {
            let a = full_a(t, t.num_all_stages());
            let exact_order = if t.order == 7 { 6 } else { t.order };
            let mut largest = (0.0f64, 0.0f64);
            for k in 1..10 {
                let theta = f64::from(k) / 10.0;
                let weights = t.interpolant_weights(theta);
                let (up_to, _) = worst(&a, &weights, exact_order, theta);
                assert!(
                    up_to < INTERPOLANT_TOLERANCE,
                    "{name} at θ = {theta}: {up_to:e}"
                );
                let order_p = tree_residuals(&a, &weights, t.order, theta)
                    .into_iter()
                    .map(|(_, r)| r.abs())
                    .fold(0.0, f64::max);
                largest = (largest.0.max(up_to), largest.1.max(order_p));
            }
            println!(
                "{name}: interpolant up to order {exact_order}: {:.1e} relative; order {}: {:.1e}",
                largest.0, t.order, largest.1
            );
            if t.order == 7 {
                assert!(
                    largest.1 < 1e-6 && largest.1 > 1e-8,
                    "{name}: {:e}",
                    largest.1
                );
            }
        }
    }

    /// The weights at the nodes, by which the stepper evaluates the interpolant, are Verner's
    /// polynomials there (to the rounding of evaluating those, `8 ε Σₘ |rᵢₘ| θᵐ`), and being
    /// free of the polynomials' cancellation they satisfy the order conditions of the
    /// interpolant's order (6 for 7(6)) to [`TOLERANCE`], like the step's weights.
    #[test]
    fn node_weights_are_the_interpolants() {
        for (name, t) in &pairs() {
            let all = t.num_all_stages();
            let a = full_a(t, all);
            assert_eq!(t.nodes.len(), t.degree, "{name}");
            assert_eq!(t.nodes[t.degree - 1], 1.0, "{name}");
            let exact_order = if t.order == 7 { 6 } else { t.order };
            for (j, &theta) in t.nodes.iter().enumerate() {
                let at_node = &t.node_weights[j * all..(j + 1) * all];
                let from_r = t.interpolant_weights(theta);
                for (i, row) in t.interpolant.chunks_exact(t.degree).enumerate() {
                    let size: f64 = row
                        .iter()
                        .enumerate()
                        .map(|(m, r)| (r * theta.powi(m as i32 + 1)).abs())
                        .sum();
                    let difference = (at_node[i] - from_r[i]).abs();
                    assert!(
                        difference <= 8.0 * f64::EPSILON * size.max(1.0),
                        "{name} node {j} stage {i}"
                    );
                }
                let (up_to, _) = worst(&a, at_node, exact_order, theta);
                assert!(up_to < TOLERANCE, "{name} at θ = {theta}: {up_to:e}");
            }
        }
    }

    /// At θ = 1 the interpolant's weights are the step's (`bᵢ(1) = bᵢ`, zero on the extra
    /// stages), so it ends on the step's end; at θ = 0 they vanish. Bound: each `bᵢ(1)` sums
    /// up to nine coefficients of size up to ~1.2e5 (6(5)'s extra stages), rounded to a few ε
    /// of that size.
    #[test]
    fn interpolants_end_on_the_step() {
        for (name, t) in &pairs() {
            let b = pad(t.b, t.num_all_stages());
            let at_one = t.interpolant_weights(1.0);
            for (i, row) in t.interpolant.chunks_exact(t.degree).enumerate() {
                let size: f64 = row.iter().map(|x| x.abs()).sum::<f64>().max(1.0);
                let error = (at_one[i] - b[i]).abs() / size;
                assert!(
                    error < 8.0 * f64::EPSILON,
                    "{name} stage {i}: {} vs {} ({error:e})",
                    at_one[i],
                    b[i]
                );
            }
            assert!(t.interpolant_weights(0.0).iter().all(|&w| w == 0.0));
        }
    }

    /// `ẏ = y²`, `y(0) = 1/2`: `y(t) = 1/(2 − t)`, whose derivatives grow like `k!/(2 − t)ᵏ⁺¹`
    /// (every elementary differential enters the error).
    fn blow_up() -> OdeFn<impl FnMut(f64, &[f64], &mut [f64])> {
        OdeFn::new(1, |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = y[0] * y[0])
    }

    /// The largest error of the dense output over one step of size `h` from `t = 0`, at
    /// θ = 0.1 … 0.9, against `1/(2 − t)`; and the evaluations of `F` before and after the
    /// dense output was prepared (twice).
    fn one_step_interpolation_error(t: &Pair, h: f64) -> (f64, usize, usize) {
        let mut system = blow_up();
        let mut rhs = CheckedRhs::new(&mut system);
        let mut stepper = ExplicitRk::new(t.tableau, 1);
        stepper.reset(&mut rhs, 0.0, &[0.5]).unwrap();
        let weights = ErrorWeights::uniform(1, 1e-6, 1e-6);
        stepper.attempt(&mut rhs, h, &weights, true).unwrap();
        stepper.accept(&mut rhs).unwrap();
        let before = rhs.evals();
        stepper.prepare_dense_output(&mut rhs).unwrap();
        stepper.prepare_dense_output(&mut rhs).unwrap();
        let after = rhs.evals();
        let mut out = [0.0];
        let mut largest = 0.0f64;
        for k in 1..10 {
            let time = h * f64::from(k) / 10.0;
            stepper.interpolate(time, &mut out);
            largest = largest.max((out[0] - 1.0 / (2.0 - time)).abs());
        }
        stepper.interpolate(h, &mut out);
        assert_eq!(out[0], stepper.y()[0]);
        (largest, before, after)
    }

    /// One step costs `s − 1` evaluations of `F` plus `F` at the new state (none for the FSAL
    /// 6(5)): 8, 10, 13 and 16 per step; the dense output adds 3, 5, 7 and 9, once per step.
    /// Its local error is `O(h^(p+1))`: halving `h` divides it by at least `2^(p+0.5)`.
    ///
    /// Only the lower side is asserted, on one halving per pair chosen where the error lies
    /// between ~1e-6 and ~1e-12 (observed orders 7.3, 8.3, 11.2 and 12.2 for 6(5) … 9(8)):
    /// on this problem (a pole at t = 2) larger steps are pre-asymptotic (orders above
    /// `p + 1`), and below ~1e-13 the coefficients' rounding (the rᵢₘ reach 1.5e4 for 8(7))
    /// leaves an `O(h²)` floor (2e-12 at h = 0.2 and 5e-13 at h = 0.1 for 8(7), computed in
    /// exact arithmetic with the doubles of the tableau, against 3e-13 at h = 0.2 with the
    /// exact coefficients). An interpolant of a lower order fails the bound.
    #[test]
    fn dense_output_costs_its_extra_stages_and_has_local_order_p_plus_1() {
        for (name, t) in &pairs() {
            let mut errors = Vec::new();
            let steps: [f64; 2] = match t.order {
                6 | 7 => [0.2, 0.1],
                _ => [0.8, 0.4],
            };
            for h in steps {
                let (error, before, after) = one_step_interpolation_error(t, h);
                let per_step = if t.fsal { t.stages - 1 } else { t.stages };
                assert_eq!(before, 1 + per_step, "{name}");
                let extra = t.num_all_stages() - t.end_stage() - 1;
                assert_eq!(after - before, extra, "{name}");
                errors.push(error);
            }
            let orders: Vec<f64> = errors.windows(2).map(|e| (e[0] / e[1]).log2()).collect();
            println!("{name}: interpolation errors {errors:?}, orders {orders:.2?}");
            for order in orders {
                let expected = f64::from(t.order + 1);
                assert!(order > expected - 0.5, "{name}: {order} in {errors:?}");
            }
        }
    }

    /// A NaN in a stage without weight in the candidate and in the error estimate (6(5)'s
    /// stage at `c = 0.06`; `F` ignores `y`, so nothing else could show it) is reported at its
    /// own time, by the stage sums for a fixed dimension (2) and the general ones (3); and a
    /// NaN in a weighted stage (`c = 0.4973`) at its time too, not as a non-finite state.
    #[test]
    fn a_non_finite_stage_is_reported_at_its_time() {
        for (c_nan, dim) in [(0.06, 2), (0.06, 3), (0.4973, 2), (0.4973, 3)] {
            let t_nan = c_nan * 0.5;
            let mut system = OdeFn::new(dim, move |t: f64, _y: &[f64], dy: &mut [f64]| {
                dy.fill(if (t - t_nan).abs() < 1e-6 {
                    f64::NAN
                } else {
                    1.0
                });
            });
            let mut rhs = CheckedRhs::new(&mut system);
            let mut stepper = ExplicitRk::new(Tableau::vern6(), dim);
            stepper.reset(&mut rhs, 0.0, &vec![0.0; dim]).unwrap();
            let weights = ErrorWeights::uniform(dim, 1e-6, 1e-6);
            match stepper.attempt(&mut rhs, 0.5, &weights, true).unwrap_err() {
                StepFailure::Rhs {
                    t,
                    error: RhsError::NonFinite { index: 0 },
                } => assert!((t - t_nan).abs() < 1e-15, "t = {t}"),
                other => panic!("{other:?}"),
            }
            assert_eq!(stepper.t(), 0.0);
        }
    }

    /// The tableau's stability polynomial agrees with one step of the implementation on the
    /// nilpotent shift system (`StabilityPolynomial::of_method`), to rounding, and matches
    /// `eᶻ` to order `p` exactly (not `p + 1`: its degree is `s`).
    #[test]
    fn stability_polynomials_match_the_implementation() {
        for (tableau, mut method) in explicit_tableau_methods()
            .into_iter()
            .filter(|(t, _)| t.interpolant().is_some())
        {
            let (polynomial, stages) = (
                StabilityPolynomial::of_tableau(&tableau),
                tableau.num_stages(),
            );
            let stepped = StabilityPolynomial::of_method(method.as_mut(), stages).unwrap();
            for (a, b) in polynomial.coefficients().iter().zip(stepped.coefficients()) {
                assert!((a - b).abs() < 1e-14, "{}: {a} vs {b}", method.name());
            }
            assert_eq!(
                polynomial.order(),
                method.order() as usize,
                "{}",
                method.name()
            );
        }
    }
}
