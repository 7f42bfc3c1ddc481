//! The Gauss–Newton iteration of [`periodic_orbit`]: from the start, minimum-norm steps
//! `Δ = −J⁺ b` on the augmented shooting system, damped until the merit decreases, with the
//! integration tolerance tightened as the residual falls (see the parent's documentation for
//! the method).

use super::*;

/// The augmented Jacobian at an iterate, decomposed for a minimum-norm step.
struct Linearisation {
    /// Its singular value decomposition (`(n + 1 or n + 2) × (n or n + 1)`).
    svd: SVD<f64, Dyn, Dyn>,
    /// The largest singular value.
    sigma_max: f64,
    /// The first cut `max(ε σ_max, κ merit)` of the singular values.
    cut: f64,
    /// The number of singular values above `cut`.
    rank: usize,
}

/// The outcome of one damped Gauss–Newton step.
struct DampedStep {
    /// The evaluation at the step taken, if one reduced the merit.
    accepted: Option<Evaluation>,
    /// The number of singular values kept for the last step tried.
    rank: usize,
    /// The damping factor of the last step tried (1 = a full Newton step).
    damping: f64,
}

impl Newton<'_> {
    /// The integration tolerance of an evaluation reached from an iterate of merit `merit`
    /// (units of `y`): `1e-4 merit²`, at most [`LOOSEST_TOL`], at least the tolerance asked
    /// for.
    ///
    /// Far from the orbit the residual needs no 12 digits: Newton's next residual is about
    /// the square of the current one, and each evaluation integrates at 1e-4 of that (at most
    /// LOOSEST_TOL, at least the tolerance asked for), then again more tightly if its residual
    /// turns out smaller than RESOLUTION_FACTOR resolves (`evaluate_resolved`), so that every
    /// step and every comparison of merits uses residuals that are not integration error;
    /// convergence is only declared on an evaluation at the tolerance asked for.
    fn tol_for(&self, merit: f64) -> f64 {
        self.final_tol.max((1e-4 * merit * merit).min(LOOSEST_TOL))
    }

    /// Gauss–Newton from `start` (`n` entries) at the options' period guess until the
    /// residual `‖φ_T(y₀) − y₀‖₂ ≤ tol (1 + ‖y₀‖₂)` (and the energy row's `|H − E| ≤ tol (1 +
    /// |E|)`) on an evaluation at the tolerance asked for; the work of every integration is
    /// added to `stats`.
    ///
    /// # Errors
    /// [`PeriodicOrbitError::NotConverged`] (too many iterations, or no damped step reduced
    /// the merit), [`PeriodicOrbitError::Collapsed`], and the evaluations' errors.
    pub(super) fn solve(
        &self,
        model: &mut dyn ModelInfo,
        start: Vec<f64>,
        stats: &mut Stats,
    ) -> Result<Solution, PeriodicOrbitError> {
        let options = self.options;
        let mut history = Vec::new();
        let mut current = evaluate_resolved(
            model,
            self.shooting,
            start,
            options.period,
            self.tol_for(f64::INFINITY),
            self.final_tol,
            stats,
        )?;
        let mut iterations = 0;
        let rank_used = loop {
            let allowed = options.tol * (1.0 + norm(&current.y));
            let energy_ok = match (self.shooting.energy, current.energy_residual) {
                (Some(e), Some(r)) => r.abs() <= options.tol * (1.0 + e.abs()),
                _ => true,
            };
            let mut step = NewtonStep {
                residual: current.residual_norm,
                energy_residual: current.energy_residual,
                period: current.period,
                rank: None,
                damping: None,
            };
            let linear = self.linearise(model, &current, iterations)?;
            if current.residual_norm <= allowed && energy_ok {
                if current.tol > self.final_tol {
                    let y = current.y.clone();
                    current = evaluate(
                        model,
                        self.shooting,
                        y,
                        current.period,
                        self.final_tol,
                        stats,
                    )?;
                    continue;
                }
                history.push(step);
                break linear.rank;
            }
            if iterations >= options.max_iterations {
                history.push(step);
                return Err(PeriodicOrbitError::NotConverged {
                    iterations,
                    residual: current.residual_norm,
                    allowed,
                    period: current.period,
                    stalled: false,
                });
            }
            let DampedStep {
                accepted,
                rank,
                damping,
            } = self.damped_step(model, &current, &linear, stats)?;
            step.rank = Some(rank);
            step.damping = Some(damping);
            history.push(step);
            iterations += 1;
            match accepted {
                Some(candidate) => current = candidate,
                None => {
                    return Err(PeriodicOrbitError::NotConverged {
                        iterations,
                        residual: current.residual_norm,
                        allowed,
                        period: current.period,
                        stalled: true,
                    });
                }
            }
        };
        Ok(Solution {
            current,
            iterations,
            rank: rank_used,
            history,
        })
    }

    /// The augmented Jacobian at `current` ([`jacobian`]) and its SVD, with the first cut of
    /// its singular values and the rank above it; first refuses an iterate that collapsed to
    /// an equilibrium ([`PeriodicOrbitError::Collapsed`]: `T` below 1e-6 of the guess, or a
    /// travel `‖f(y₀)‖ T` below `1e-9 (1 + ‖y₀‖)`) after `iterations` steps.
    fn linearise(
        &self,
        model: &mut dyn ModelInfo,
        current: &Evaluation,
        iterations: usize,
    ) -> Result<Linearisation, PeriodicOrbitError> {
        let travel_floor = |y: &[f64]| 1e-9 * (1.0 + norm(y));
        let f0 = rhs(model, &current.y)?;
        let travel = norm(&f0) * current.period;
        if current.period < 1e-6 * self.options.period || travel < travel_floor(&current.y) {
            return Err(PeriodicOrbitError::Collapsed {
                iterations,
                period: current.period,
                travel,
            });
        }
        // The Jacobian at the current iterate, also for the symmetry count at the solution.
        let jacobian = jacobian(model, self.shooting, current, &f0)?;
        let svd = jacobian.svd(true, true);
        let sigma_max = svd.singular_values.max();
        let cut = (RANK_TOLERANCE * sigma_max).max(SYMMETRY_FACTOR * current.merit);
        let rank = svd.singular_values.iter().filter(|s| **s > cut).count();
        Ok(Linearisation {
            svd,
            sigma_max,
            cut,
            rank,
        })
    }

    /// One damped minimum-norm step from `current`: `Δ = −J⁺ b` over the singular values above
    /// each cut in turn (`κ‖r‖`, a tenth and a hundredth of it, then `ε σ_max`), halved up to
    /// [`MAX_HALVINGS`] times until the merit decreases. A failed or non-finite integration
    /// counts as a larger merit; any other error is returned.
    fn damped_step(
        &self,
        model: &mut dyn ModelInfo,
        current: &Evaluation,
        linear: &Linearisation,
        stats: &mut Stats,
    ) -> Result<DampedStep, PeriodicOrbitError> {
        let &Linearisation {
            ref svd,
            sigma_max,
            cut,
            rank,
        } = linear;
        let n = self.shooting.n;
        let rhs_vector = right_hand_side(self.shooting, current);
        // Δ = −J⁺ b over the kept singular values (nalgebra zeroes those ≤ the cut): the
        // minimum-norm least-squares step, damped until the merit decreases. Far from the
        // orbit the cut κ‖r‖ may drop a direction the step needs (the period's, when the
        // residual is large); then the cut is lowered tenfold, twice, then to ε σ_max.
        let floor = RANK_TOLERANCE * sigma_max;
        let mut cuts: Vec<f64> = [cut, 0.1 * cut, 0.01 * cut, floor]
            .into_iter()
            .filter(|c| *c >= floor)
            .collect();
        cuts.dedup();
        let mut accepted = None;
        let (mut used_rank, mut damping) = (rank, 1.0);
        'cuts: for &level in &cuts {
            let Ok(solution) = svd.solve(&rhs_vector, level) else {
                break;
            };
            let delta = -solution;
            used_rank = svd.singular_values.iter().filter(|s| **s > level).count();
            damping = 1.0;
            // Keep the period within a factor 2 of the current one (its unknown is the
            // relative change ΔT/T).
            if self.shooting.free_period && delta[n].abs() > 0.5 {
                damping = 0.5 / delta[n].abs();
            }
            for _ in 0..MAX_HALVINGS {
                let y: Vec<f64> = current
                    .y
                    .iter()
                    .zip(delta.iter())
                    .map(|(y, d)| y + damping * d)
                    .collect();
                let period = if self.shooting.free_period {
                    current.period * (1.0 + damping * delta[n])
                } else {
                    current.period
                };
                match evaluate_resolved(
                    model,
                    self.shooting,
                    y,
                    period,
                    self.tol_for(current.merit),
                    self.final_tol,
                    stats,
                ) {
                    Ok(candidate) if candidate.merit < current.merit => {
                        accepted = Some(candidate);
                        break 'cuts;
                    }
                    // A failed integration or a larger residual: a shorter step.
                    Ok(_)
                    | Err(PeriodicOrbitError::Floquet(FloquetError::IntegrationFailed {
                        ..
                    }))
                    | Err(PeriodicOrbitError::Floquet(FloquetError::NonFinite { .. })) => {
                        damping *= 0.5;
                    }
                    Err(e) => return Err(e),
                }
            }
        }
        Ok(DampedStep {
            accepted,
            rank: used_rank,
            damping,
        })
    }
}
