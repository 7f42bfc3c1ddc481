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
//! `G`, `γ_c`) and solved by LU, or through the Schur complement where held rows repeat
//! each other ([`HeldEquations::solve`]): a phase is where a ball rests or a foot stands,
//! not where the work of a run is spent.
//!
//! Also here, what a phase starts and ends with: which contacts start closed ([`touching`]),
//! how a closing contact is held ([`closing_hold`]), and the contacts' event functions
//! ([`contact_events`]), including a sliding contact's response to its own normal force
//! ([`ContactPhase::sliding_response`], Painlevé's paradox).

use nalgebra::{DMatrix, DVector};

use crate::model_info::ModelInfo;
use crate::ode::{EventSpec, OdeSystem, RhsError};
use eomgen_description::taylor::TaylorUnsupported;

/// How a closed contact is held.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Hold {
    /// Its normal row alone (frictionless).
    Normal,
    /// Its normal row and its slip's row: it sticks, the tangential force `λ_T` its
    /// multiplier, while `|λ_T| ≤ μ λ_N`.
    Stick,
    /// Its normal row, sliding with `s = ±1` the sign of its slip `v_t = T q̇`: the force on
    /// the system is `(G − μ s T)ᵀ λ_N` (Coulomb's kinetic friction opposes the slip).
    Slide(f64),
}

/// A model with the contacts `closed` held ([`OdeSystem`]); its own events are the model's.
pub(crate) struct ContactPhase<'m> {
    /// The model.
    pub(crate) model: &'m mut dyn ModelInfo,
    /// The closed contacts (indices into the model's contacts), ascending.
    pub(crate) closed: Vec<usize>,
    /// For each of [`Self::closed`], how it is held.
    pub(crate) holds: Vec<Hold>,
    /// The model's own events (with the terminal flags set on it).
    specs: Vec<EventSpec>,
}

/// The forces of a closed contact: normal `λ_N` (pushing when positive) and tangential `λ_T`
/// (along `T`; `−μ s λ_N` while it slides, 0 without friction), N.
pub(crate) type ContactForces = (f64, f64);

impl<'m> ContactPhase<'m> {
    /// `model` with the contacts `closed` held as `holds` says.
    pub(crate) fn new(model: &'m mut dyn ModelInfo, closed: Vec<usize>, holds: Vec<Hold>) -> Self {
        let specs = model.as_ode().event_specs().to_vec();
        Self {
            model,
            closed,
            holds,
            specs,
        }
    }

    /// The rows held besides the model's: `(contact, tangential)` for each closed contact's
    /// normal row, then its slip's row if it sticks.
    fn rows(&self) -> Vec<(usize, bool)> {
        let mut rows = Vec::new();
        for (&c, &hold) in self.closed.iter().zip(&self.holds) {
            rows.push((c, false));
            if hold == Hold::Stick {
                rows.push((c, true));
            }
        }
        rows
    }

    /// `q̈` (`n`) and the closed contacts' forces (one pair per closed contact, in the order
    /// of [`Self::closed`]) at `(t, y)`.
    ///
    /// # Errors
    /// [`RhsError::SingularConstraintMatrix`] if no finite solution is found (rows that repeat
    /// each other are solved, [`HeldEquations::solve`]).
    pub(crate) fn solve(
        &self,
        t: f64,
        y: &[f64],
    ) -> Result<(Vec<f64>, Vec<ContactForces>), RhsError> {
        let n = self.model.num_dofs();
        let (mass, forcing) = self.model.mass_matrix_and_forcing(t, y);
        let own = self.model.constraint_equations(t, y);
        let contacts = self.model.contact_values(t, y);
        let rows = self.rows();
        let m = own.jacobian.nrows();
        let k = m + rows.len();
        // The held rows `A` (what `A q̈ = b` holds) and the directions their multipliers push
        // along (`A` itself but for a sliding contact's `G − μ s T`), both `k × n`.
        let mut held = DMatrix::<f64>::zeros(k, n);
        let mut pushes = DMatrix::<f64>::zeros(k, n);
        let mut b = DVector::<f64>::zeros(k);
        for i in 0..m {
            for j in 0..n {
                held[(i, j)] = own.jacobian[(i, j)];
                pushes[(i, j)] = own.jacobian[(i, j)];
            }
            b[i] = own.gamma[i];
        }
        for (r, &(c, tangential)) in rows.iter().enumerate() {
            let (row, gamma) = if tangential {
                (
                    &contacts.tangent[c * n..(c + 1) * n],
                    contacts.tangent_gamma[c],
                )
            } else {
                (&contacts.normal[c * n..(c + 1) * n], contacts.gamma[c])
            };
            // The force's direction: the row itself, but `G − μ s T` for a sliding contact.
            let slide = match self.hold_of(c) {
                Hold::Slide(s) if !tangential => contacts.friction[c] * s,
                _ => 0.0,
            };
            for j in 0..n {
                held[(m + r, j)] = row[j];
                pushes[(m + r, j)] = row[j] - slide * contacts.tangent[c * n + j];
            }
            b[m + r] = gamma;
        }
        let equations = HeldEquations {
            mass: &mass,
            forcing: &forcing,
            held: &held,
            pushes: &pushes,
            b: &b,
        };
        let solution = equations
            .solve()
            .ok_or(RhsError::SingularConstraintMatrix)?;
        let accelerations = solution.rows(0, n).iter().copied().collect();
        let mut forces = vec![(0.0, 0.0); self.closed.len()];
        let mut r = n + m;
        for (i, (&c, &hold)) in self.closed.iter().zip(&self.holds).enumerate() {
            forces[i].0 = -solution[r];
            r += 1;
            match hold {
                Hold::Stick => {
                    forces[i].1 = -solution[r];
                    r += 1;
                }
                Hold::Slide(s) => forces[i].1 = -contacts.friction[c] * s * forces[i].0,
                Hold::Normal => {}
            }
        }
        Ok((accelerations, forces))
    }

    /// For the sliding contact `c` at `(t, y)`, how its normal acceleration answers its own
    /// normal force while it slides, relative to how it would without friction:
    /// `b = G W (G − μ s T)ᵀ / G W Gᵀ`, `W` the inverse mass through the other rows held.
    /// At `b ≤ 0` sliding has no consistent normal force (it grows without bound as `b → 0`):
    /// Painlevé's paradox (Génot & Brogliato 1999). `None` where `W` is singular.
    pub(crate) fn sliding_response(&self, c: usize, t: f64, y: &[f64]) -> Option<f64> {
        let Hold::Slide(s) = self.hold_of(c) else {
            return None;
        };
        let n = self.model.num_dofs();
        let (mass, _) = self.model.mass_matrix_and_forcing(t, y);
        let own = self.model.constraint_equations(t, y);
        let contacts = self.model.contact_values(t, y);
        let own_rows: Vec<Vec<f64>> = (0..own.jacobian.nrows())
            .map(|i| (0..n).map(|j| own.jacobian[(i, j)]).collect())
            .collect();
        let mut held: Vec<&[f64]> = own_rows.iter().map(Vec::as_slice).collect();
        for (k, tangential) in self.rows() {
            if k == c {
                continue;
            }
            let rows = if tangential {
                &contacts.tangent
            } else {
                &contacts.normal
            };
            held.push(&rows[k * n..(k + 1) * n]);
        }
        let m = held.len();
        let mut matrix = DMatrix::<f64>::zeros(n + m, n + m);
        matrix.view_mut((0, 0), (n, n)).copy_from(&mass);
        for (i, row) in held.iter().enumerate() {
            for j in 0..n {
                matrix[(n + i, j)] = row[j];
                matrix[(j, n + i)] = row[j];
            }
        }
        let normal = &contacts.normal[c * n..(c + 1) * n];
        let tangent = &contacts.tangent[c * n..(c + 1) * n];
        let mu_s = contacts.friction[c] * s;
        let rhs = DMatrix::from_fn(n + m, 2, |i, col| match (i < n, col) {
            (true, 0) => normal[i],
            (true, _) => normal[i] - mu_s * tangent[i],
            _ => 0.0,
        });
        let w = matrix.lu().solve(&rhs)?;
        let along = |col: usize| (0..n).map(|j| normal[j] * w[(j, col)]).sum::<f64>();
        let frictionless = along(0);
        (frictionless > 0.0).then(|| along(1) / frictionless)
    }

    /// How the closed contact `c` is held.
    fn hold_of(&self, c: usize) -> Hold {
        (self.closed.iter().position(|&k| k == c)).map_or(Hold::Normal, |i| self.holds[i])
    }
}

/// The equations of a phase at one state: `M q̈ + Pᵀ λ = F`, `A q̈ = b`.
struct HeldEquations<'a> {
    /// `M` (`n × n`).
    mass: &'a DMatrix<f64>,
    /// `F` (`n`).
    forcing: &'a DVector<f64>,
    /// The held rows `A` (`k × n`).
    held: &'a DMatrix<f64>,
    /// The directions the multipliers push along, `P` (`k × n`).
    pushes: &'a DMatrix<f64>,
    /// `b` (`k`).
    b: &'a DVector<f64>,
}

impl HeldEquations<'_> {
    /// `[q̈; λ]` (`n + k`) of `M q̈ + Pᵀ λ = F`, `A q̈ = b`; `None` if no solution is found.
    ///
    /// By LU of the whole matrix `[M Pᵀ; A 0]` when its pivots are all above 1e-12 of its largest
    /// entry. Rows that repeat each other (a box standing, sticking, on two feet: their slips'
    /// rows are equal) leave that matrix singular but the equations consistent: `q̈` is still
    /// unique, and the multipliers are taken of least norm (an even share). Then `λ` solves the
    /// Schur complement `A M⁻¹ Pᵀ λ = A M⁻¹ F − b` by SVD (least norm, singular values below
    /// 1e-12 of its largest entry dropped) and `q̈ = M⁻¹ (F − Pᵀ λ)`, with `M` by Cholesky (`q̈`
    /// is unique where `P = A`; a sliding contact's `P ≠ A`). An SVD of the whole matrix
    /// instead, whose smallest kept singular values (about those of `A M⁻¹ Aᵀ`) are 3e-7 of its
    /// largest (`M`'s) for a braking car at rest, loses that ratio: `q̈` came out with noise of
    /// 1e-10 m/s² from one evaluation to the next, which held DOP853 at 1e-12 to steps of 4 ms
    /// for a car at rest. Last, if `M` is not positive definite or the Schur complement's
    /// solution is not finite, that SVD.
    fn solve(&self) -> Option<DVector<f64>> {
        let (n, k) = (self.mass.nrows(), self.held.nrows());
        let mut matrix = DMatrix::<f64>::zeros(n + k, n + k);
        matrix.view_mut((0, 0), (n, n)).copy_from(self.mass);
        matrix.view_mut((n, 0), (k, n)).copy_from(self.held);
        (matrix.view_mut((0, n), (n, k))).copy_from(&self.pushes.transpose());
        let mut rhs = DVector::<f64>::zeros(n + k);
        rhs.rows_mut(0, n).copy_from(self.forcing);
        rhs.rows_mut(n, k).copy_from(self.b);
        let scale = matrix.amax().max(f64::MIN_POSITIVE);
        let lu = matrix.clone().lu();
        let pivots_fine = (0..n + k).all(|i| lu.u()[(i, i)].abs() > 1e-12 * scale);
        let finite = |x: &DVector<f64>| x.iter().all(|v| v.is_finite());
        if pivots_fine {
            return lu.solve(&rhs).filter(finite);
        }
        (self.by_schur_complement().filter(finite))
            .or_else(|| matrix.svd(true, true).solve(&rhs, 1e-12 * scale).ok())
            .filter(finite)
    }

    /// [`Self::solve`]'s least-norm solution through the Schur complement `A M⁻¹ Pᵀ`; `None`
    /// if `M` is not positive definite.
    fn by_schur_complement(&self) -> Option<DVector<f64>> {
        let cholesky = self.mass.clone().cholesky()?;
        let free = cholesky.solve(self.forcing);
        if self.held.nrows() == 0 {
            return Some(free);
        }
        let inverse_mass_pushes = cholesky.solve(&self.pushes.transpose());
        let schur = self.held * &inverse_mass_pushes;
        let scale = schur.amax().max(f64::MIN_POSITIVE);
        let multipliers = (schur.svd(true, true))
            .solve(&(self.held * &free - self.b), 1e-12 * scale)
            .ok()?;
        let accelerations = free - inverse_mass_pushes * &multipliers;
        let n = self.mass.nrows();
        let k = self.held.nrows();
        Some(DVector::from_fn(n + k, |i, _| {
            if i < n {
                accelerations[i]
            } else {
                multipliers[i - n]
            }
        }))
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
    /// `ġ = 0`, and a sticking one's speeds onto `v_t = 0` (`Δq = −Gᵀ (G Gᵀ)⁻¹ g`, then the
    /// same for `q̇` with the rows `G` and `T`; one Gauss–Newton step each,
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
            // Positions onto `g = 0`; speeds onto `ġ = 0` and, where it sticks, `v_t = 0`.
            let held: Vec<(usize, bool)> = (self.rows().into_iter())
                .filter(|&(_, tangential)| level == 1 || !tangential)
                .collect();
            let k = held.len();
            let row_of = |r: usize, j: usize| {
                let (c, tangential) = held[r];
                let rows = if tangential {
                    &values.tangent
                } else {
                    &values.normal
                };
                rows[c * n + j]
            };
            let rows = DMatrix::from_fn(k, n, row_of);
            let qdot = &y[n..2 * n];
            let residual = DVector::from_fn(k, |r, _| match (level, held[r]) {
                (0, (c, _)) => values.gaps[c],
                (_, (c, false)) => values.rates[c],
                (_, (c, true)) => values.slip(c, qdot),
            });
            let gram = &rows * rows.transpose();
            // Least norm where rows repeat each other (two feet's equal slip rows).
            let scale = gram.amax().max(f64::MIN_POSITIVE);
            let multipliers = gram
                .svd(true, true)
                .solve(&residual, 1e-12 * scale)
                .map_err(|_| RhsError::SingularConstraintMatrix)?;
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
        Err(TaylorUnsupported::Contacts {
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

/// Which contacts start closed, and how: touching (`|g| ≤ atol`), with a normal speed within
/// `atol` of 0 (in m/s), and with a normal force that pushes when they are held (all
/// touching contacts held together; none if that is singular). A contact with friction
/// sticks if it does not slip (`|v_t| ≤ atol`), else slides. A ball at rest on its floor
/// starts closed; one that touches it while moving along it too.
pub(super) fn touching(
    model: &mut dyn ModelInfo,
    (t, y): (f64, &[f64]),
    atol: f64,
) -> (Vec<bool>, Vec<Hold>) {
    let values = model.contact_values(t, y);
    let m = values.gaps.len();
    let candidates: Vec<usize> = (0..m)
        .filter(|&c| values.gaps[c].abs() <= atol && values.rates[c].abs() <= atol)
        .collect();
    let (mut closed, mut holds) = (vec![false; m], vec![Hold::Normal; m]);
    if candidates.is_empty() {
        return (closed, holds);
    }
    let wanted: Vec<Hold> = (candidates.iter())
        .map(|&c| closing_hold(model, c, (t, &y[y.len() / 2..]), atol, y))
        .collect();
    let phase = ContactPhase::new(model, candidates.clone(), wanted.clone());
    if let Ok((_, forces)) = phase.solve(t, y) {
        for ((&c, (normal, _)), hold) in candidates.iter().zip(forces).zip(wanted) {
            closed[c] = normal > 0.0;
            if closed[c] {
                holds[c] = hold;
            }
        }
    }
    (closed, holds)
}

/// How contact `c` is held when it closes at `(t, y)` with speeds `qdot`: frictionless, or
/// with friction sticking where its slip is within `atol` of 0, else sliding with its slip's
/// sign.
pub(super) fn closing_hold(
    model: &mut dyn ModelInfo,
    c: usize,
    (t, qdot): (f64, &[f64]),
    atol: f64,
    y: &[f64],
) -> Hold {
    let values = model.contact_values(t, y);
    if values.friction[c] <= 0.0 {
        return Hold::Normal;
    }
    let slip = values.slip(c, qdot);
    if slip.abs() <= atol {
        Hold::Stick
    } else {
        Hold::Slide(slip.signum())
    }
}

/// The contacts' event functions at `(t, y)` into `events` (one per contact): an open
/// contact's gap, a closed one's normal force `λ_N` (it opens where `λ_N` falls through 0),
/// a sticking one's `min(λ_N, μ λ_N − |λ_T|)` (it opens, or starts to slip, where that falls
/// through 0), a sliding one's `min(λ_N, s v_t)` (it opens, or its slip stops); `friction`
/// holds each contact's `μ`.
///
/// An open contact at a zero at the phase's start `(t*, g*)` (`starting`: struck, released
/// or touching there) gives `(g − g*)/(t − t*)` instead (its rate `ġ` at `t*`): it leaves
/// from a gap of 0 (to rounding, of either sign), so its gap would start at a zero that the
/// sign test between two steps cannot see past, and a short flight that rises and lands
/// within one step would be missed. The quotient starts at `ġ⁺ ≥ 0` and turns negative
/// where the gap returns to `g*` (within rounding of 0). `values` is scratch of `5 m_c`
/// entries.
///
/// # Errors
/// As [`ContactPhase::solve`], with a contact closed.
pub(super) fn contact_events(
    phase: &mut ContactPhase<'_>,
    (t, y): (f64, &[f64]),
    (starting, friction): (&[(usize, f64, f64)], &[f64]),
    values: &mut [f64],
    events: &mut [f64],
) -> Result<(), RhsError> {
    phase.model.contact_gaps(t, y, values);
    let m = events.len();
    events.copy_from_slice(&values[..m]);
    for &(c, start, gap) in starting {
        events[c] = if t > start {
            (values[c] - gap) / (t - start)
        } else {
            values[m + c]
        };
    }
    if !phase.closed.is_empty() {
        let (_, forces) = phase.solve(t, y)?;
        let slides = phase.holds.iter().any(|h| matches!(h, Hold::Slide(_)));
        let sliding = slides.then(|| phase.model.contact_values(t, y));
        let n = y.len() / 2;
        for ((&c, (normal, tangential)), &hold) in phase.closed.iter().zip(forces).zip(&phase.holds)
        {
            events[c] = match hold {
                Hold::Normal => normal,
                Hold::Stick => normal.min(friction[c] * normal - tangential.abs()),
                Hold::Slide(s) => {
                    let slip = (sliding.as_ref()).map_or(0.0, |v| v.slip(c, &y[n..2 * n]));
                    let response = phase.sliding_response(c, t, y).unwrap_or(1.0);
                    normal.min(s * slip).min(response)
                }
            };
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A braking car at rest on both wheels, stuck (HW16's model, `braking_car_side`): `q =
    /// (x, y, θ)`, four held rows for three coordinates (at `θ = 0` the two slips' rows are
    /// equal). Pushed along the road by `F_x` or not, at `θ = 0` and `1e-3`: `q̈ = 0` to
    /// rounding of `g`, the multipliers balance `F` (`Aᵀ λ = F`) and are of least norm (`λ`
    /// orthogonal to `Aᵀ`'s null vector). At `θ = 0` statics give the loads `N_F = m g b / (a
    /// + b)`, `N_R = m g a / (a + b)` without `F_x`, and the two slips share `F_x` evenly.
    #[test]
    fn repeated_rows_give_the_static_forces_and_no_acceleration() {
        let (m, inertia, a, b, h, g) = (1500.0, 2500.0, 1.2, 1.4, 0.55, 9.81);
        let weight = m * g;
        for (theta, push) in [(0.0, 0.0), (0.0, -3000.0), (1e-3, 0.0), (1e-3, -3000.0)] {
            let (s, c) = f64::sin_cos(theta);
            let mass = DMatrix::from_diagonal(&DVector::from_vec(vec![m, m, inertia]));
            let forcing = DVector::from_vec(vec![push, -weight, 0.0]);
            // Front normal, front slip, rear normal, rear slip: the gradients of the contact
            // points' heights and positions along the road.
            let held = DMatrix::from_row_slice(
                4,
                3,
                &[
                    0.0,
                    1.0,
                    a * c + h * s, //
                    1.0,
                    0.0,
                    -a * s + h * c, //
                    0.0,
                    1.0,
                    -b * c + h * s, //
                    1.0,
                    0.0,
                    b * s + h * c,
                ],
            );
            let equations = HeldEquations {
                mass: &mass,
                forcing: &forcing,
                held: &held,
                pushes: &held,
                b: &DVector::zeros(4),
            };
            let x = equations.solve().unwrap();
            let case = format!("θ = {theta:e}, F_x = {push}");
            // q̈ to rounding of g (the whole matrix's SVD left 1e-10 m/s² here).
            for i in 0..3 {
                assert!(x[i].abs() < 1e-14 * g, "q̈[{i}] = {:e}, {case}", x[i]);
            }
            let multipliers = x.rows(3, 4).into_owned();
            let balance = held.transpose() * &multipliers - &forcing;
            assert!(
                balance.amax() < 1e-12 * weight,
                "Aᵀλ − F = {balance}, {case}"
            );
            // Aᵀ's null vector: the signed 3 × 3 minors of `A` without each row.
            let null = DVector::from_fn(4, |i, _| {
                let minor = held.clone().remove_row(i);
                let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
                sign * minor.fixed_view::<3, 3>(0, 0).determinant()
            });
            assert!((held.transpose() * &null).amax() < 1e-12 * null.amax());
            let along = null.dot(&multipliers) / null.norm();
            assert!(along.abs() < 1e-12 * weight, "λ·v = {along:e}, {case}");
            if theta == 0.0 {
                assert!((x[4] - push / 2.0).abs() < 1e-12 * weight, "{case}");
                assert!((x[6] - push / 2.0).abs() < 1e-12 * weight, "{case}");
            }
            if theta == 0.0 && push == 0.0 {
                // The multipliers are minus the forces (`M q̈ + Aᵀ λ = F`).
                let (front, rear) = (weight * b / (a + b), weight * a / (a + b));
                assert!((-x[3] - front).abs() < 1e-12 * weight, "N_F = {}", -x[3]);
                assert!((-x[5] - rear).abs() < 1e-12 * weight, "N_R = {}", -x[5]);
            }
        }
    }

    /// With no held row (a free phase) and a mass matrix whose LU pivot test fails, the
    /// Schur complement's path gives `M⁻¹ F`.
    #[test]
    fn no_held_row_gives_the_free_motion() {
        let mass = DMatrix::from_diagonal(&DVector::from_vec(vec![1.0, 1e-13]));
        let forcing = DVector::from_vec(vec![2.0, 3e-13]);
        let none = DMatrix::zeros(0, 2);
        let equations = HeldEquations {
            mass: &mass,
            forcing: &forcing,
            held: &none,
            pushes: &none,
            b: &DVector::zeros(0),
        };
        let x = equations.solve().unwrap();
        assert!(
            (x[0] - 2.0).abs() < 1e-15 && (x[1] - 3.0).abs() < 1e-12,
            "{x}"
        );
    }
}
