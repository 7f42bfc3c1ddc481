//! Equations of motion whose size is known only at run time.
//!
//! [`DynMechanicalSystem`] is [`MechanicalSystem`] with slices in
//! place of nalgebra's static vectors and matrices: what a model compiled at run time (from any
//! model file, with no rebuild) implements. (Inside this crate every [`MechanicalSystem<N>`] is
//! one through a private adapter, so that the constrained solve and [`ModelInfo`](crate::ModelInfo)
//! are written once; outside it, a compiled model is reached through
//! [`FirstOrder`](crate::FirstOrder) and `ModelInfo`.) Its first-order form is
//! [`DynFirstOrder`](crate::DynFirstOrder), which implements [`ModelInfo`](crate::ModelInfo),
//! so every analysis that takes a `Box<dyn ModelInfo>` takes such a model unchanged.

use nalgebra::SVector;

use crate::system::{MechanicalSystem, ModelDescription, UnknownParameter};
use crate::taylor::{TaylorFunctions, TaylorUnsupported};

/// Equations of motion `M(q, t) q̈ = F(q, q̇, t)` of a mechanism with `n` degrees of freedom,
/// `n` known at run time.
///
/// Every method means what the method of the same name of
/// [`MechanicalSystem`] means; values are written into caller-owned
/// slices so that an evaluation allocates nothing.
///
/// # Shapes
/// `q`, `qdot`, `a`: length `n = num_dofs()`. Matrices (`mass`, the Jacobians): `n × n`,
/// **column-major** (nalgebra's storage order: entry `(i, j)` is `out[i + j n]`). Other outputs
/// as documented per method.
///
/// # Units
/// SI, angles in rad; `F` in N or N·m per coordinate; energies in J.
pub trait DynMechanicalSystem {
    /// Everything about the model that is not a function of the state
    /// ([`MechanicalSystem::description`]).
    fn description(&self) -> &ModelDescription;
    /// Number of degrees of freedom `n` (the description's coordinates).
    fn num_dofs(&self) -> usize {
        self.description().num_dofs()
    }
    /// Current parameter values, in the order of [`ModelDescription::parameters`].
    fn parameter_values(&self) -> Vec<f64>;
    /// Sets parameter `name` to `value`.
    ///
    /// # Errors
    /// [`UnknownParameter`] if the model has no such parameter.
    fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), UnknownParameter>;
    /// Initial state `q(0)`, `q̇(0)` from the file's `initial:` block, with the current
    /// parameter values, written into `q` and `qdot` (length `n` each).
    fn initial_state(&self, q: &mut [f64], qdot: &mut [f64]);

    /// `M(q, t)` (`n × n`, column-major) into `mass` and `F(q, q̇, t)` (length `n`) into
    /// `forcing`, sharing subexpressions (the hot path of every integrator). Every entry is
    /// written, both triangles of `M`: callers reuse their buffers.
    fn mass_matrix_and_forcing(
        &self,
        q: &[f64],
        qdot: &[f64],
        t: f64,
        mass: &mut [f64],
        forcing: &mut [f64],
    );
    /// The first-order right-hand side `ẏ = [q̇; M⁻¹F]` of a model without constraints, in its
    /// coordinates' rates (not in generalized speeds), in one call, where the model has it as
    /// one function (a run-time model of up to four degrees of freedom: the equations and the
    /// solve compiled together, `eomgen_jit`'s `first_order` module), with its verdict: `Some(true)` where `M` is positive definite, as
    /// [`crate::linalg::solve_spd`] tests it (`M₀₀` and `det M` for `n = 2`, the pivots of
    /// `M = L D Lᵀ` otherwise, each positive and not NaN), and every `q̈` is finite;
    /// `Some(false)` otherwise; `None`, writing nothing, where the model has no such function.
    /// The model's kinematic equations are not applied: `q̇` is copied from `y`.
    ///
    /// # Shapes
    /// `y = [q; q̇]` and `dy` of length `2n`. `dy`'s `q̈` is [`crate::linalg::solve_spd`]'s to
    /// the bit where `M` is positive definite, and meaningless otherwise. The verdict says
    /// only whether both tests pass: `DynFirstOrder` computes a failing case again, by
    /// `M` and `F` and the solve, for the error it reports.
    fn first_order_rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) -> Option<bool> {
        let _ = (t, y, dy);
        None
    }
    /// Exact `∂F/∂q` (`n × n`, column-major; entry `(i, j)` is `∂Fᵢ/∂qⱼ`) into `out`.
    fn forcing_jacobian_q(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]);
    /// Exact `∂F/∂q̇` (`n × n`, column-major) into `out`.
    fn forcing_jacobian_qdot(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]);
    /// Exact `∂(M(q, t) a)/∂q` for a fixed `a` (`n × n`, column-major; entry `(i, k)` is
    /// `Σⱼ ∂Mᵢⱼ/∂qₖ aⱼ`) into `out`.
    fn mass_matrix_product_jacobian(&self, q: &[f64], t: f64, a: &[f64], out: &mut [f64]);
    /// Kinetic energy `T(q, q̇, t)` (J).
    fn kinetic_energy(&self, q: &[f64], qdot: &[f64], t: f64) -> f64;
    /// Potential energy `V(q, t)` (J).
    fn potential_energy(&self, q: &[f64], t: f64) -> f64;
    /// Positions of the points (m), `[x, y, z]` (`z = 0` for 2-D models), into `out` (length
    /// `description().points.len()`).
    fn point_positions(&self, q: &[f64], t: f64, out: &mut [[f64; 3]]);

    /// `Φ(q, t)` of the holonomic constraints into `out` (length
    /// [`ModelDescription::holonomic_constraints`]).
    fn constraint_residuals(&self, q: &[f64], t: f64, out: &mut [f64]);
    /// The constraint Jacobian `J` (`m × n`, **row-major**, as
    /// [`MechanicalSystem::constraint_jacobian`])
    /// into `out`.
    fn constraint_jacobian(&self, q: &[f64], t: f64, out: &mut [f64]);
    /// Velocity-level residuals (length `m`) into `out`.
    fn constraint_velocity_residuals(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]);
    /// `γ` of `J q̈ = γ` (length `m`) into `out`.
    fn constraint_gamma(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]);
    /// The guesses of [`ModelDescription::equilibria`], `n` coordinates each, one after the other.
    fn equilibrium_guesses(&self, out: &mut [f64]);
    /// [`MechanicalSystem::contact_gaps`]: `g`, `ġ`, `γ`, `γ_T`, then `v_s` (`5 m_c`) into `out`. The default
    /// (a model without contacts) writes nothing.
    fn contact_gaps(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]) {
        let _ = (q, qdot, t, out);
    }
    /// [`MechanicalSystem::contact_jacobian`]: `G`, then `T` (`2 m_c × n`, row-major) into
    /// `out`.
    fn contact_jacobian(&self, q: &[f64], t: f64, out: &mut [f64]) {
        let _ = (q, t, out);
    }
    /// [`MechanicalSystem::contact_coefficients`]: `[e₁, μ₁, μ_s1, …]` (`3 m_c`) into `out`.
    fn contact_coefficients(&self, out: &mut [f64]) {
        let _ = out;
    }
    /// [`MechanicalSystem::support_changes`] into `out`.
    fn support_changes(&self, q: &[f64], t: f64, out: &mut [f64]) {
        let _ = (q, t, out);
    }
    /// The event functions `gᵢ(q, q̇, q̈, λ, t)` into `out` (one per event); `lambda` may be
    /// shorter than `m` (a function that reads a missing multiplier gets NaN).
    fn event_values(
        &self,
        q: &[f64],
        qdot: &[f64],
        t: f64,
        qddot: &[f64],
        lambda: &[f64],
        out: &mut [f64],
    );

    /// [`MechanicalSystem::coordinate_rates`]: `q̇` (length `n`) into `out`; the default
    /// copies `qdot` (a model in the coordinates' rates).
    fn coordinate_rates(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]) {
        let _ = (q, t);
        rates_are_the_state(self.num_dofs(), qdot, out);
    }
    /// [`MechanicalSystem::coordinate_rates_jacobian`]: `∂q̇/∂q` into `d_q` and `∂q̇/∂u`
    /// into `d_u` (`n × n`, column-major each); the default writes `0` and `I`.
    fn coordinate_rates_jacobian(
        &self,
        q: &[f64],
        qdot: &[f64],
        t: f64,
        d_q: &mut [f64],
        d_u: &mut [f64],
    ) {
        let _ = (q, qdot, t);
        rates_are_the_state_jacobian(self.num_dofs(), d_q, d_u);
    }

    /// [`MechanicalSystem::taylor`].
    ///
    /// # Errors
    /// [`TaylorUnsupported`] naming what is missing.
    fn taylor(&self) -> Result<&dyn TaylorFunctions, TaylorUnsupported> {
        Err(TaylorUnsupported::NotGenerated)
    }
}

/// The coordinates' rates of a model in the rates (no generalized speeds): the state's second
/// half `qdot` itself, its first `n` entries into `out`. The default of
/// [`DynMechanicalSystem::coordinate_rates`], for an implementation that has both kinds.
pub fn rates_are_the_state(n: usize, qdot: &[f64], out: &mut [f64]) {
    out[..n].copy_from_slice(&qdot[..n]);
}

/// The Jacobians of [`rates_are_the_state`]: `0` into `d_q` and `I` into `d_u` (`n × n`,
/// column-major each). The default of [`DynMechanicalSystem::coordinate_rates_jacobian`].
pub fn rates_are_the_state_jacobian(n: usize, d_q: &mut [f64], d_u: &mut [f64]) {
    d_q[..n * n].fill(0.0);
    d_u[..n * n].fill(0.0);
    for i in 0..n {
        d_u[i + i * n] = 1.0;
    }
}

/// A [`MechanicalSystem<N>`] seen as a [`DynMechanicalSystem`]: the one place where the
/// compile-time-sized interface is mapped to the slices of the run-time one (static vectors
/// and matrices copied from and to the slices; the description is the system's own).
///
/// With it, what is written once over [`DynMechanicalSystem`] serves the models compiled by
/// `eomgen::model!` too: the constrained solve, drift and projection of
/// [`ConstraintWorkspace`](crate::ConstraintWorkspace), and the size-erased
/// [`ModelInfo`](crate::ModelInfo) of [`FirstOrder`](crate::FirstOrder). (A blanket
/// `impl<S: MechanicalSystem<N>, const N: usize> DynMechanicalSystem for S` is not possible:
/// `N` would not be constrained by the implementing type.) The compiled models' hot path,
/// `FirstOrder::rhs` and its Jacobian, does not go through here.
///
/// `repr(transparent)`, so that [`Self::from_ref`] and [`Self::from_mut`] view a borrowed `S`
/// in place: a wrapper lends the names it returns with the borrow of the system itself.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[repr(transparent)]
pub(crate) struct StaticSystem<S, const N: usize>(pub S);

impl<S, const N: usize> StaticSystem<S, N> {
    /// `system` seen through the adapter, borrowed in place.
    pub fn from_ref(system: &S) -> &Self {
        // SAFETY: `StaticSystem<S, N>` is `repr(transparent)` over its only field, an `S`, so
        // the two have the same layout and alignment; the lifetime is kept.
        unsafe { &*(system as *const S).cast::<Self>() }
    }

    /// `system` seen through the adapter, mutably borrowed in place.
    pub fn from_mut(system: &mut S) -> &mut Self {
        // SAFETY: as in `from_ref`; the unique borrow of `system` becomes the unique borrow of
        // the wrapper.
        unsafe { &mut *(system as *mut S).cast::<Self>() }
    }
}

fn vector<const N: usize>(x: &[f64]) -> SVector<f64, N> {
    SVector::<f64, N>::from_column_slice(&x[..N])
}

impl<S: MechanicalSystem<N>, const N: usize> DynMechanicalSystem for StaticSystem<S, N> {
    fn description(&self) -> &ModelDescription {
        self.0.description()
    }
    fn num_dofs(&self) -> usize {
        N
    }
    fn parameter_values(&self) -> Vec<f64> {
        self.0.parameter_values()
    }
    fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), UnknownParameter> {
        self.0.set_parameter(name, value)
    }
    fn initial_state(&self, q: &mut [f64], qdot: &mut [f64]) {
        let (q0, qdot0) = self.0.initial_state();
        q[..N].copy_from_slice(q0.as_slice());
        qdot[..N].copy_from_slice(qdot0.as_slice());
    }
    fn mass_matrix_and_forcing(
        &self,
        q: &[f64],
        qdot: &[f64],
        t: f64,
        mass: &mut [f64],
        forcing: &mut [f64],
    ) {
        let (m, f) = self
            .0
            .mass_matrix_and_forcing(&vector::<N>(q), &vector::<N>(qdot), t);
        mass[..N * N].copy_from_slice(m.as_slice());
        forcing[..N].copy_from_slice(f.as_slice());
    }
    fn forcing_jacobian_q(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]) {
        let j = self
            .0
            .forcing_jacobian_q(&vector::<N>(q), &vector::<N>(qdot), t);
        out[..N * N].copy_from_slice(j.as_slice());
    }
    fn forcing_jacobian_qdot(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]) {
        let j = self
            .0
            .forcing_jacobian_qdot(&vector::<N>(q), &vector::<N>(qdot), t);
        out[..N * N].copy_from_slice(j.as_slice());
    }
    fn mass_matrix_product_jacobian(&self, q: &[f64], t: f64, a: &[f64], out: &mut [f64]) {
        let j = self
            .0
            .mass_matrix_product_jacobian(&vector::<N>(q), t, &vector::<N>(a));
        out[..N * N].copy_from_slice(j.as_slice());
    }
    fn coordinate_rates(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]) {
        let rates = self
            .0
            .coordinate_rates(&vector::<N>(q), &vector::<N>(qdot), t);
        out[..N].copy_from_slice(rates.as_slice());
    }
    fn coordinate_rates_jacobian(
        &self,
        q: &[f64],
        qdot: &[f64],
        t: f64,
        d_q: &mut [f64],
        d_u: &mut [f64],
    ) {
        let (a, b) = self
            .0
            .coordinate_rates_jacobian(&vector::<N>(q), &vector::<N>(qdot), t);
        d_q[..N * N].copy_from_slice(a.as_slice());
        d_u[..N * N].copy_from_slice(b.as_slice());
    }
    fn kinetic_energy(&self, q: &[f64], qdot: &[f64], t: f64) -> f64 {
        self.0
            .kinetic_energy(&vector::<N>(q), &vector::<N>(qdot), t)
    }
    fn potential_energy(&self, q: &[f64], t: f64) -> f64 {
        self.0.potential_energy(&vector::<N>(q), t)
    }
    fn point_positions(&self, q: &[f64], t: f64, out: &mut [[f64; 3]]) {
        self.0.point_positions(&vector::<N>(q), t, out);
    }
    fn constraint_residuals(&self, q: &[f64], t: f64, out: &mut [f64]) {
        self.0.constraint_residuals(&vector::<N>(q), t, out);
    }
    fn constraint_jacobian(&self, q: &[f64], t: f64, out: &mut [f64]) {
        self.0.constraint_jacobian(&vector::<N>(q), t, out);
    }
    fn constraint_velocity_residuals(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]) {
        self.0
            .constraint_velocity_residuals(&vector::<N>(q), &vector::<N>(qdot), t, out);
    }
    fn constraint_gamma(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]) {
        self.0
            .constraint_gamma(&vector::<N>(q), &vector::<N>(qdot), t, out);
    }
    fn equilibrium_guesses(&self, out: &mut [f64]) {
        self.0.equilibrium_guesses(out);
    }
    fn contact_gaps(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]) {
        self.0
            .contact_gaps(&vector::<N>(q), &vector::<N>(qdot), t, out);
    }
    fn contact_jacobian(&self, q: &[f64], t: f64, out: &mut [f64]) {
        self.0.contact_jacobian(&vector::<N>(q), t, out);
    }
    fn contact_coefficients(&self, out: &mut [f64]) {
        self.0.contact_coefficients(out);
    }
    fn support_changes(&self, q: &[f64], t: f64, out: &mut [f64]) {
        self.0.support_changes(&vector::<N>(q), t, out);
    }
    fn event_values(
        &self,
        q: &[f64],
        qdot: &[f64],
        t: f64,
        qddot: &[f64],
        lambda: &[f64],
        out: &mut [f64],
    ) {
        self.0.event_values(
            &vector::<N>(q),
            &vector::<N>(qdot),
            t,
            &vector::<N>(qddot),
            lambda,
            out,
        );
    }
    fn taylor(&self) -> Result<&dyn TaylorFunctions, TaylorUnsupported> {
        self.0.taylor()
    }
}

#[cfg(test)]
mod tests {
    use std::borrow::Cow;

    use eomgen_description::Parameter;
    use nalgebra::{Matrix2, Vector2};

    use super::*;
    use crate::{DynFirstOrder, FirstOrder, ModelInfo, OdeSystem};

    /// A two-degree-of-freedom system whose every matrix has distinct entries (a transposed
    /// or misplaced copy shows), with points, an equilibrium guess and parameters.
    #[derive(Debug, Clone)]
    struct Skewed {
        k: f64,
    }

    impl MechanicalSystem<2> for Skewed {
        fn description(&self) -> &ModelDescription {
            static DESCRIPTION: ModelDescription = ModelDescription {
                name: Cow::Borrowed("skewed"),
                summary: Cow::Borrowed("a test system"),
                coordinates: Cow::Borrowed(&[Cow::Borrowed("x"), Cow::Borrowed("y")]),
                parameters: Cow::Borrowed(&[Parameter {
                    name: Cow::Borrowed("k"),
                    default: 3.0,
                }]),
                points: Cow::Borrowed(&[Cow::Borrowed("p"), Cow::Borrowed("r")]),
                equilibria: Cow::Borrowed(&[Cow::Borrowed("rest"), Cow::Borrowed("off")]),
                equations_text: Cow::Borrowed("text"),
                equations_latex: Cow::Borrowed("latex"),
                ..ModelDescription::EMPTY
            };
            &DESCRIPTION
        }
        fn parameter_values(&self) -> Vec<f64> {
            vec![self.k]
        }
        fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), UnknownParameter> {
            match name {
                "k" => {
                    self.k = value;
                    Ok(())
                }
                _ => Err(UnknownParameter {
                    model: "skewed".into(),
                    name: name.into(),
                    known: "k".into(),
                }),
            }
        }
        fn initial_state(&self) -> (SVector<f64, 2>, SVector<f64, 2>) {
            (Vector2::new(0.3, -0.2), Vector2::new(0.1, 0.7))
        }
        fn mass_matrix(&self, q: &SVector<f64, 2>, _t: f64) -> nalgebra::SMatrix<f64, 2, 2> {
            let c = 0.4 * q[1].cos();
            Matrix2::new(2.0 + q[0] * q[0], c, c, 1.5)
        }
        fn forcing(&self, q: &SVector<f64, 2>, qdot: &SVector<f64, 2>, t: f64) -> SVector<f64, 2> {
            Vector2::new(
                -self.k * q[0] + 0.3 * qdot[1] * q[1] + t.sin(),
                -2.0 * self.k * q[1] - 0.7 * qdot[0] * q[0],
            )
        }
        fn mass_matrix_and_forcing(
            &self,
            q: &SVector<f64, 2>,
            qdot: &SVector<f64, 2>,
            t: f64,
        ) -> (nalgebra::SMatrix<f64, 2, 2>, SVector<f64, 2>) {
            (self.mass_matrix(q, t), self.forcing(q, qdot, t))
        }
        fn forcing_jacobian_q(
            &self,
            _q: &SVector<f64, 2>,
            qdot: &SVector<f64, 2>,
            _t: f64,
        ) -> nalgebra::SMatrix<f64, 2, 2> {
            Matrix2::new(-self.k, 0.3 * qdot[1], -0.7 * qdot[0], -2.0 * self.k)
        }
        fn forcing_jacobian_qdot(
            &self,
            q: &SVector<f64, 2>,
            _qdot: &SVector<f64, 2>,
            _t: f64,
        ) -> nalgebra::SMatrix<f64, 2, 2> {
            Matrix2::new(0.0, 0.3 * q[1], -0.7 * q[0], 0.0)
        }
        fn mass_matrix_product_jacobian(
            &self,
            q: &SVector<f64, 2>,
            _t: f64,
            a: &SVector<f64, 2>,
        ) -> nalgebra::SMatrix<f64, 2, 2> {
            let dc = -0.4 * q[1].sin();
            Matrix2::new(2.0 * q[0] * a[0], dc * a[1], 0.0, dc * a[0])
        }
        fn kinetic_energy(&self, q: &SVector<f64, 2>, qdot: &SVector<f64, 2>, t: f64) -> f64 {
            0.5 * qdot.dot(&(self.mass_matrix(q, t) * qdot))
        }
        fn potential_energy(&self, q: &SVector<f64, 2>, _t: f64) -> f64 {
            0.5 * self.k * (q[0] * q[0] + 2.0 * q[1] * q[1])
        }
        fn point_positions(&self, q: &SVector<f64, 2>, _t: f64, out: &mut [[f64; 3]]) {
            out[0] = [q[0], 0.0, 0.0];
            out[1] = [q[0], q[1], 1.0];
        }
        fn equilibrium_guesses(&self, out: &mut [f64]) {
            out.copy_from_slice(&[0.0, 0.0, 0.5, -0.5]);
        }
    }

    /// The adapter against the compiled system itself: `FirstOrder` (its own right-hand side,
    /// its `ModelInfo` through `StaticSystem`) and `DynFirstOrder` of the adapter (the
    /// run-time path throughout) agree to the bit with each other and with the
    /// `MechanicalSystem` methods, entry by entry; the matrices have distinct entries, so a
    /// transposed or misplaced copy fails.
    #[test]
    fn static_system_is_the_compiled_system_on_slices() {
        let system = Skewed { k: 3.0 };
        let mut compiled = FirstOrder::new(system.clone());
        let mut runtime = DynFirstOrder::new(StaticSystem::<_, 2>(system.clone()));
        let y = [0.3, -0.2, 0.1, 0.7];
        let t = 0.25;
        let (q, qdot) = (Vector2::new(y[0], y[1]), Vector2::new(y[2], y[3]));
        for model in [&mut compiled as &mut dyn ModelInfo, &mut runtime] {
            assert_eq!(model.num_dofs(), 2);
            assert_eq!(model.description().coordinate_names(), ["x", "y"]);
            assert_eq!(model.initial_state(), y);
            let (m, f) = model.mass_matrix_and_forcing(t, &y);
            let (m0, f0) = system.mass_matrix_and_forcing(&q, &qdot, t);
            assert_eq!(m.as_slice(), m0.as_slice());
            assert_eq!(f.as_slice(), f0.as_slice());
            let (jq, jv) = model.forcing_jacobians(t, &y);
            assert_eq!(jq[(0, 1)], 0.3 * y[3]);
            assert_eq!(
                jq.as_slice(),
                system.forcing_jacobian_q(&q, &qdot, t).as_slice()
            );
            assert_eq!(
                jv.as_slice(),
                system.forcing_jacobian_qdot(&q, &qdot, t).as_slice()
            );
            let a = [0.9, -1.1];
            let pj = model.mass_matrix_product_jacobian(t, &y, &a);
            let pj0 = system.mass_matrix_product_jacobian(&q, t, &Vector2::new(a[0], a[1]));
            assert_eq!(pj.as_slice(), pj0.as_slice());
            assert_eq!(
                model.kinetic_energy(t, &y),
                system.kinetic_energy(&q, &qdot, t)
            );
            assert_eq!(
                model.potential_energy(t, &y),
                system.potential_energy(&q, t)
            );
            assert_eq!(
                model.point_positions(t, &y),
                [[0.3, 0.0, 0.0], [0.3, -0.2, 1.0]]
            );
            assert_eq!(
                model.equilibrium_guesses(),
                [("rest", vec![0.0, 0.0]), ("off", vec![0.5, -0.5])]
            );
            assert!(model.set_parameter("k", 4.0).is_ok());
            assert_eq!(model.parameter_values(), [4.0]);
            assert!(model.set_parameter("c", 1.0).is_err());
            model.set_parameter("k", 3.0).unwrap();
        }
        let (mut dc, mut dr) = ([0.0; 4], [0.0; 4]);
        compiled.rhs(t, &y, &mut dc).unwrap();
        runtime.rhs(t, &y, &mut dr).unwrap();
        assert_eq!(dc, dr);
        let (mut jc, mut jr) = ([0.0; 16], [0.0; 16]);
        assert!(compiled.jacobian(t, &y, &mut jc).unwrap());
        assert!(runtime.jacobian(t, &y, &mut jr).unwrap());
        assert_eq!(jc, jr);
    }
}
