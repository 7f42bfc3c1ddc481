//! Cost of the generated equations of motion at run time, against a hand-written reference.
//!
//! Every explicit integrator spends most of its time in the right-hand side
//! `ẏ = [q̇; M⁻¹F]`, so this is where generated code has to be as good as code a careful
//! person writes. The group `rhs_double_pendulum` times one evaluation of it for the bundled
//! double pendulum (`models/double_pendulum.yaml`) at a fixed, generic state:
//!
//! - `rhs_generated_double_pendulum`: [`FirstOrder`]`<`[`DoublePendulum`]`>::rhs`, i.e. the
//!   generated `mass_matrix_and_forcing` followed by the runtime's solve (2 × 2: Cramer's rule) of
//!   `M q̈ = F` ([`eomgen::solve_spd`]);
//! - `rhs_handwritten_double_pendulum`: the same physics derived by hand and written to be
//!   cheap ([`HandwrittenDoublePendulum`]), with the same sine and cosine (the `libm` crate,
//!   as the generated code) and solved with the *same* `solve_spd`, so the difference between
//!   the two is the cost of the generated equations alone;
//! - `rhs_handwritten_explicit_solve_double_pendulum`: the hand-written equations with the
//!   2 × 2 system solved by the explicit formula, a floor for what any generator could reach
//!   with a general-purpose solve.
//!
//! Before timing, the hand-written `M` and `F` and all three right-hand sides are checked
//! against the generated ones at several states (relative 1e-12), so the benches compare the
//! same equations.
//!
//! `simulate_double_pendulum_10s_dp54_1e-10` is the end-to-end figure: a full Dormand–Prince
//! 5(4) integration from the model's initial state to `t = 10 s` at `rtol = atol = 1e-10`,
//! storing every step. Its step and right-hand-side counts are printed once, so the share of
//! the right-hand side in the total can be read off.
//!
//! Run with `cargo bench --bench rhs`.

use std::hint::black_box;

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
eomgen::model!("../models/double_pendulum.yaml");
use eomgen::{
    DormandPrince54, FirstOrder, Integrator, IntegratorOptions, MechanicalSystem, ModelInfo,
    OdeSystem, OutputTimes, RhsError,
};
use nalgebra::{Matrix2, Vector2};

/// The state at which the right-hand sides are timed, `[θ₁, θ₂, θ̇₁, θ̇₂]` (rad, rad/s): no
/// angle or rate is zero and no trigonometric value is special, so nothing can fold away.
const STATE: [f64; 4] = [0.4, 1.9, -0.8, 1.3];

/// Further states at which the hand-written equations are checked.
const CHECK_STATES: [[f64; 4]; 3] = [
    [-2.3, 0.7, 2.1, -0.45],
    [1.2, -1.7, 0.33, 3.2],
    [3.0, 2.5, -1.9, -0.6],
];

/// Parameters used for the right-hand-side benches: all different from each other and from
/// 1, so that a mix-up of `m1` and `m2` or `l1` and `l2` in the hand-written equations fails
/// the check instead of going unnoticed.
fn parameters() -> HandwrittenDoublePendulum {
    HandwrittenDoublePendulum {
        m1: 1.3,
        m2: 0.7,
        l1: 0.9,
        l2: 1.4,
        g: 9.81,
    }
}

/// The double pendulum of two uniform bars, derived by hand.
///
/// Absolute angles `θ₁`, `θ₂` from +x, gravity along −y, bar `i` of mass `mᵢ`, length `lᵢ`,
/// centroidal inertia `mᵢ lᵢ²/12`, centre of mass at its middle. With `c₁₂ = cos(θ₁ − θ₂)`,
/// `s₁₂ = sin(θ₁ − θ₂)` and the coupling `a = m₂ l₁ l₂/2`:
///
/// ```text
/// T = ½ (m₁/3 + m₂) l₁² θ̇₁² + ½ (m₂/3) l₂² θ̇₂² + a c₁₂ θ̇₁ θ̇₂
/// V = (m₁/2 + m₂) g l₁ sin θ₁ + (m₂/2) g l₂ sin θ₂
///
/// M = [ (m₁/3 + m₂) l₁²   a c₁₂     ]     F = [ −a s₁₂ θ̇₂² − (m₁/2 + m₂) g l₁ cos θ₁ ]
///     [ a c₁₂             m₂ l₂²/3  ]         [  a s₁₂ θ̇₁² − (m₂/2) g l₂ cos θ₂       ]
/// ```
///
/// Written for speed: one `sin_cos` per angle (needed for gravity anyway), `c₁₂` and `s₁₂` by
/// the angle-difference identities instead of two more trigonometric calls, the coupling `a`
/// computed once. Parameters are read from the struct at every call, as the generated code
/// reads its fields, rather than folded into constants.
#[derive(Debug, Clone, Copy)]
struct HandwrittenDoublePendulum {
    m1: f64,
    m2: f64,
    l1: f64,
    l2: f64,
    g: f64,
}

impl HandwrittenDoublePendulum {
    /// `M` and `F` at `(q, q̇)`.
    #[inline]
    fn mass_matrix_and_forcing(
        &self,
        q: &Vector2<f64>,
        qdot: &Vector2<f64>,
    ) -> (Matrix2<f64>, Vector2<f64>) {
        let Self { m1, m2, l1, l2, g } = *self;
        let (s1, c1) = libm::sincos(q[0]);
        let (s2, c2) = libm::sincos(q[1]);
        let c12 = c1 * c2 + s1 * s2;
        let s12 = s1 * c2 - c1 * s2;
        let a = 0.5 * m2 * l1 * l2;
        let m12 = a * c12;
        let gyroscopic = a * s12;
        let mass_matrix = Matrix2::new((m1 / 3.0 + m2) * l1 * l1, m12, m12, m2 * l2 * l2 / 3.0);
        let forcing = Vector2::new(
            -gyroscopic * qdot[1] * qdot[1] - (0.5 * m1 + m2) * g * l1 * c1,
            gyroscopic * qdot[0] * qdot[0] - 0.5 * m2 * g * l2 * c2,
        );
        (mass_matrix, forcing)
    }

    /// `ẏ` with `M q̈ = F` solved by [`eomgen::solve_spd`], exactly as [`FirstOrder::rhs`]
    /// does (same splitting, factorisation, solve and finiteness check).
    ///
    /// # Errors
    /// As [`FirstOrder::rhs`].
    #[inline]
    fn rhs_solve_spd(&self, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let q = Vector2::from_column_slice(&y[..2]);
        let qdot = Vector2::from_column_slice(&y[2..4]);
        let (m, f) = self.mass_matrix_and_forcing(&q, &qdot);
        let qdd = eomgen::solve_spd(&m, &f).ok_or(RhsError::SingularMassMatrix)?;
        if let Some(i) = qdd.iter().position(|v| !v.is_finite()) {
            return Err(RhsError::NonFinite { index: 2 + i });
        }
        dy[..2].copy_from_slice(qdot.as_slice());
        dy[2..4].copy_from_slice(qdd.as_slice());
        Ok(())
    }

    /// `ẏ` with `M q̈ = F` solved by the explicit 2 × 2 formula
    /// `q̈ = [M₂₂ F₁ − M₁₂ F₂, M₁₁ F₂ − M₁₂ F₁] / det M`.
    ///
    /// # Errors
    /// [`RhsError::SingularMassMatrix`] unless `M₁₁ > 0` and `det M > 0` (Sylvester's
    /// criterion, the condition under which Cholesky succeeds); [`RhsError::NonFinite`] as
    /// [`FirstOrder::rhs`].
    #[inline]
    fn rhs_explicit(&self, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let q = Vector2::new(y[0], y[1]);
        let qdot = Vector2::new(y[2], y[3]);
        let (m, f) = self.mass_matrix_and_forcing(&q, &qdot);
        let (m11, m12, m22) = (m[(0, 0)], m[(0, 1)], m[(1, 1)]);
        let det = m11 * m22 - m12 * m12;
        if !(m11 > 0.0 && det > 0.0) {
            return Err(RhsError::SingularMassMatrix);
        }
        let inv_det = 1.0 / det;
        let qdd = [
            (m22 * f[0] - m12 * f[1]) * inv_det,
            (m11 * f[1] - m12 * f[0]) * inv_det,
        ];
        if let Some(i) = qdd.iter().position(|v| !v.is_finite()) {
            return Err(RhsError::NonFinite { index: 2 + i });
        }
        dy[0] = qdot[0];
        dy[1] = qdot[1];
        dy[2] = qdd[0];
        dy[3] = qdd[1];
        Ok(())
    }
}

/// The generated double pendulum with the same parameters as `hand`.
fn generated(hand: &HandwrittenDoublePendulum) -> DoublePendulum {
    DoublePendulum {
        m1: hand.m1,
        m2: hand.m2,
        l1: hand.l1,
        l2: hand.l2,
        g: hand.g,
    }
}

/// Asserts `|a − b| ≤ 1e-12 max(|a|, |b|)`.
fn assert_close(a: f64, b: f64, what: &str) {
    assert!(
        (a - b).abs() <= 1e-12 * a.abs().max(b.abs()),
        "{what}: generated {a:e}, hand-written {b:e} (relative difference {:e})",
        (a - b).abs() / a.abs().max(b.abs())
    );
}

/// Checks that the hand-written `M`, `F` and right-hand sides equal the generated ones at
/// every state of [`STATE`] and [`CHECK_STATES`], for the bench parameters and the model's
/// defaults.
///
/// # Panics
/// On the first entry that differs by more than 1e-12 relative.
fn check_handwritten_matches_generated() {
    let defaults = DoublePendulum::default();
    let default_hand = HandwrittenDoublePendulum {
        m1: defaults.m1,
        m2: defaults.m2,
        l1: defaults.l1,
        l2: defaults.l2,
        g: defaults.g,
    };
    for hand in [parameters(), default_hand] {
        let mut system = FirstOrder::new(generated(&hand));
        for y in std::iter::once(STATE).chain(CHECK_STATES) {
            let q = Vector2::new(y[0], y[1]);
            let qdot = Vector2::new(y[2], y[3]);
            let (m_gen, f_gen) = system.system.mass_matrix_and_forcing(&q, &qdot, 0.0);
            let (m_hand, f_hand) = hand.mass_matrix_and_forcing(&q, &qdot);
            for (k, (a, b)) in m_gen.iter().zip(m_hand.iter()).enumerate() {
                assert_close(*a, *b, &format!("M[{}][{}] at {y:?}", k % 2, k / 2));
            }
            for (k, (a, b)) in f_gen.iter().zip(f_hand.iter()).enumerate() {
                assert_close(*a, *b, &format!("F[{k}] at {y:?}"));
            }
            let mut dy_gen = [0.0; 4];
            let mut dy_spd = [0.0; 4];
            let mut dy_explicit = [0.0; 4];
            system.rhs(0.0, &y, &mut dy_gen).expect("generated rhs");
            hand.rhs_solve_spd(&y, &mut dy_spd)
                .expect("hand-written rhs");
            hand.rhs_explicit(&y, &mut dy_explicit)
                .expect("hand-written explicit rhs");
            for k in 0..4 {
                assert_close(
                    dy_gen[k],
                    dy_spd[k],
                    &format!("ẏ[{k}] (solve_spd) at {y:?}"),
                );
                assert_close(
                    dy_gen[k],
                    dy_explicit[k],
                    &format!("ẏ[{k}] (explicit) at {y:?}"),
                );
            }
        }
    }
}

fn rhs(c: &mut Criterion) {
    check_handwritten_matches_generated();

    // The systems go through `black_box` so that their parameters are unknown to the
    // optimiser, as they are in a real simulation where the user sets them at run time.
    // `b.iter` rather than `iter_batched`: a call reads `y` and overwrites `dy`, so there is
    // no per-iteration state to set up, and `iter_batched`'s input/output vectors would add
    // memory traffic comparable to the ~10 ns being measured and blur the ratio.
    let hand = parameters();
    let mut group = c.benchmark_group("rhs_double_pendulum");
    group.bench_function("rhs_generated_double_pendulum", |b| {
        let mut system = black_box(FirstOrder::new(generated(&hand)));
        let mut dy = [0.0; 4];
        b.iter(|| {
            system.rhs(0.0, black_box(&STATE), &mut dy).unwrap();
            black_box(&dy);
        })
    });
    group.bench_function("rhs_handwritten_double_pendulum", |b| {
        let system = black_box(hand);
        let mut dy = [0.0; 4];
        b.iter(|| {
            system.rhs_solve_spd(black_box(&STATE), &mut dy).unwrap();
            black_box(&dy);
        })
    });
    group.bench_function("rhs_handwritten_explicit_solve_double_pendulum", |b| {
        let system = black_box(hand);
        let mut dy = [0.0; 4];
        b.iter(|| {
            system.rhs_explicit(black_box(&STATE), &mut dy).unwrap();
            black_box(&dy);
        })
    });
    group.finish();
}

fn simulate(c: &mut Criterion) {
    let options = IntegratorOptions::default()
        .with_rtol(1e-10)
        .with_atol(1e-10);
    let (t0, t_end) = (0.0, 10.0);
    let new_system = || FirstOrder::new(DoublePendulum::default());
    let y0 = ModelInfo::initial_state(&new_system());

    // One run outside the timing, for the work counts and a sanity check of the result.
    let mut system = new_system();
    let solution = DormandPrince54::new()
        .integrate(&mut system, t0, &y0, t_end, &OutputTimes::Steps, &options)
        .expect("the double pendulum integrates to 10 s");
    let (t_last, y_last) = solution.last().expect("at least one sample");
    let energy_drift = system.energy(t_last, y_last) - system.energy(t0, &y0);
    let stats = solution.stats;
    eprintln!(
        "simulate_double_pendulum_10s_dp54_1e-10: {} steps, {} rejected, {} rhs evaluations, \
         {} samples, energy drift {energy_drift:.2e} J, wall time of this run {:.3} ms",
        stats.steps,
        stats.rejected,
        stats.rhs_evals,
        solution.len(),
        stats.wall_time_s * 1e3
    );

    let mut group = c.benchmark_group("simulate");
    group.bench_function("simulate_double_pendulum_10s_dp54_1e-10", |b| {
        b.iter_batched(
            || (new_system(), y0.clone()),
            |(mut system, y0)| {
                DormandPrince54::new()
                    .integrate(
                        &mut system,
                        t0,
                        black_box(&y0),
                        t_end,
                        &OutputTimes::Steps,
                        &options,
                    )
                    .expect("the double pendulum integrates to 10 s")
            },
            BatchSize::LargeInput,
        )
    });
    group.finish();
}

criterion_group!(benches, rhs, simulate);
criterion_main!(benches);
