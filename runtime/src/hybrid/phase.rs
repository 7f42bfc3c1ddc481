//! A contact phase: the motion with some contacts closed, each held as a holonomic
//! constraint `g = 0` whose multiplier is its normal force `λ_N ≥ 0`.
//!
//! With the model's own constraint rows `J` (and `γ`) and the closed contacts' rows `G_c`
//! (and `γ_c`), `q̈` and the multipliers solve
//!
//! ```text
//! [ M   Aᵀ ] [ q̈ ]   [ F ]          [ J   ]        [ γ   ]
//! [ A   0  ] [ λ ] = [ b ],    A =  [ G_c ],  b =  [ γ_c ]
//! ```
//!
//! so `M q̈ = F − Jᵀλ_J + G_cᵀ λ_N` with `λ_N = −λ_c`: a contact pushes along its gap's
//! gradient. A closed contact opens when `λ_N` falls through 0 (Pfeiffer & Glocker 1996,
//! §7.2: the transition from contact to separation).
//!
//! The matrix is assembled from the model's functions at each evaluation (`M`, `F`, `J`, `γ`,
//! `G`, `γ_c`) and solved by LU: a phase is where a ball rests or a foot stands, not where
//! the work of a run is spent.

use nalgebra::{DMatrix, DVector};

use crate::model_info::ModelInfo;
use crate::ode::{EventSpec, OdeSystem, RhsError};
use eomgen_description::taylor::TaylorUnsupported;

/// A model with the contacts `closed` held ([`OdeSystem`]); its own events are the model's.
pub(crate) struct ContactPhase<'m> {
    /// The model.
    pub(crate) model: &'m mut dyn ModelInfo,
    /// The closed contacts (indices into the model's contacts), ascending.
    pub(crate) closed: Vec<usize>,
    /// The model's own events (with the terminal flags set on it).
    specs: Vec<EventSpec>,
}

impl<'m> ContactPhase<'m> {
    /// `model` with the contacts `closed` held.
    pub(crate) fn new(model: &'m mut dyn ModelInfo, closed: Vec<usize>) -> Self {
        let specs = model.as_ode().event_specs().to_vec();
        Self {
            model,
            closed,
            specs,
        }
    }

    /// `q̈` (`n`) and the closed contacts' normal forces `λ_N` (one per closed contact, in
    /// the order of [`Self::closed`]) at `(t, y)`.
    ///
    /// # Errors
    /// [`RhsError::SingularConstraintMatrix`] if the matrix is singular (contacts that
    /// repeat each other or the model's constraints).
    pub(crate) fn solve(&self, t: f64, y: &[f64]) -> Result<(Vec<f64>, Vec<f64>), RhsError> {
        let n = self.model.num_dofs();
        let (mass, forcing) = self.model.mass_matrix_and_forcing(t, y);
        let own = self.model.constraint_equations(t, y);
        let contacts = self.model.contact_values(t, y);
        let m = own.jacobian.nrows();
        let k = m + self.closed.len();
        let mut matrix = DMatrix::<f64>::zeros(n + k, n + k);
        let mut rhs = DVector::<f64>::zeros(n + k);
        matrix.view_mut((0, 0), (n, n)).copy_from(&mass);
        rhs.rows_mut(0, n).copy_from(&forcing);
        for i in 0..m {
            for j in 0..n {
                matrix[(n + i, j)] = own.jacobian[(i, j)];
                matrix[(j, n + i)] = own.jacobian[(i, j)];
            }
            rhs[n + i] = own.gamma[i];
        }
        for (r, &c) in self.closed.iter().enumerate() {
            let row = m + r;
            for j in 0..n {
                let g = contacts.normal[c * n + j];
                matrix[(n + row, j)] = g;
                matrix[(j, n + row)] = g;
            }
            rhs[n + row] = contacts.gamma[c];
        }
        let solution = matrix
            .lu()
            .solve(&rhs)
            .filter(|x| x.iter().all(|v| v.is_finite()))
            .ok_or(RhsError::SingularConstraintMatrix)?;
        let accelerations = solution.rows(0, n).iter().copied().collect();
        let normal_forces = (0..self.closed.len())
            .map(|r| -solution[n + m + r])
            .collect();
        Ok((accelerations, normal_forces))
    }
}

/// With no contact closed, the model's own first-order form (the same steps and bits as a
/// run without contacts); else the motion with the closed contacts held.
impl OdeSystem for ContactPhase<'_> {
    fn dim(&self) -> usize {
        2 * self.model.num_dofs()
    }

    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        if self.closed.is_empty() {
            return self.model.as_ode_mut().rhs(t, y, dy);
        }
        let n = self.model.num_dofs();
        let (accelerations, _) = self.solve(t, y)?;
        dy[..n].copy_from_slice(&y[n..2 * n]);
        dy[n..2 * n].copy_from_slice(&accelerations);
        match dy.iter().position(|v| !v.is_finite()) {
            Some(index) => Err(RhsError::NonFinite { index }),
            None => Ok(()),
        }
    }

    fn jacobian(&mut self, t: f64, y: &[f64], jac: &mut [f64]) -> Result<bool, RhsError> {
        if self.closed.is_empty() {
            return self.model.as_ode_mut().jacobian(t, y, jac);
        }
        Ok(false)
    }

    fn second_order_dim(&self) -> Option<usize> {
        Some(self.model.num_dofs())
    }

    /// The model's own drift control (its projection onto its constraints, if it has
    /// one), then the closed contacts' positions and speeds projected onto `g = 0` and
    /// `ġ = 0` (`Δq = −Gᵀ (G Gᵀ)⁻¹ g`, then the same for `q̇`; one Gauss–Newton step each,
    /// which a step's drift needs): held at the acceleration level alone, a closed contact
    /// drifts off its surface with the integration error.
    fn after_step(&mut self, t: f64, y: &mut [f64]) -> Result<bool, RhsError> {
        let changed = self.model.as_ode_mut().after_step(t, y)?;
        if self.closed.is_empty() {
            return Ok(changed);
        }
        let n = self.model.num_dofs();
        for level in 0..2 {
            let values = self.model.contact_values(t, y);
            let k = self.closed.len();
            let rows = DMatrix::from_fn(k, n, |r, j| values.normal[self.closed[r] * n + j]);
            let residual = DVector::from_fn(k, |r, _| {
                let c = self.closed[r];
                if level == 0 {
                    values.gaps[c]
                } else {
                    values.rates[c]
                }
            });
            let gram = &rows * rows.transpose();
            let multipliers = gram
                .lu()
                .solve(&residual)
                .ok_or(RhsError::SingularConstraintMatrix)?;
            let correction = rows.transpose() * multipliers;
            for j in 0..n {
                y[level * n + j] -= correction[j];
            }
        }
        Ok(true)
    }

    fn event_specs(&self) -> &[EventSpec] {
        &self.specs
    }

    fn event_values(&mut self, t: f64, y: &[f64], g: &mut [f64]) -> Result<(), RhsError> {
        self.model.as_ode_mut().event_values(t, y, g)
    }

    fn taylor_support(&self) -> Result<(), TaylorUnsupported> {
        if self.closed.is_empty() {
            return self.model.as_ode().taylor_support();
        }
        Err(TaylorUnsupported::Constraints {
            count: self.closed.len(),
        })
    }

    fn taylor_coefficients(
        &mut self,
        t: f64,
        y: &[f64],
        order: usize,
        out: &mut [f64],
    ) -> Result<(), RhsError> {
        self.model
            .as_ode_mut()
            .taylor_coefficients(t, y, order, out)
    }

    fn taylor_branch_step(&self, order: usize, h: f64) -> f64 {
        self.model.as_ode().taylor_branch_step(order, h)
    }
}
