//! The cross-check's report: every derivation that applies, compared with Lagrange's
//! symbolically and at sampled states, with a note on each comparison that fails.

use super::*;

/// Derives `file` by every applicable formulation and cross-checks them at `states` random
/// states (q and q̇ in the `StateBox` about their start: within
/// `2 max(1, |start|)` of it; t in [0, 5]; parameters within ±10 % of their defaults, or in
/// [0.1, 0.5] where the default is 0).
/// A state is compared where Lagrange's `M` and `F` are finite and `M` is regular
/// ([`CheckReport::states`]); a report that compared no state does not pass.
///
/// # Errors
/// The diagnostics of a model that does not lower, or one of whose derivations grows past
/// [`crate::mechanics::DERIVATION_OPERAND_LIMIT`].
pub fn check_model(
    file: &ModelFile,
    states: usize,
    seed: u64,
) -> Result<CheckReport, Vec<Diagnostic>> {
    let mut model = SymbolicModel::from_file(file)?;
    let mut notes = Vec::new();
    let (lagrange, lagrange_stats) = timed(&mut model, &Lagrange, Lagrange.name(), file)?;
    let problems = crate::mechanics::mass_matrix_diagnostics(&model, &lagrange, file);
    if !problems.is_empty() {
        return Err(problems);
    }
    let Derived {
        derivations,
        others,
        balance_set_of,
    } = derive_others(&mut model, file, (lagrange_stats, seed), &mut notes)?;
    let symbolic_equal: Vec<Option<bool>> = others
        .iter()
        .map(|(name, b)| {
            (name == MomentumBalance.name() || name == Kane.name()).then(|| {
                let arena = &mut model.arena;
                lagrange
                    .mass_matrix
                    .iter()
                    .zip(&b.mass_matrix)
                    .chain(lagrange.forcing.iter().zip(&b.forcing))
                    .all(|(x, y)| {
                        let d = arena.minus(*x, *y);
                        let e = arena.expand_bounded(d);
                        arena.is_zero(e)
                    })
            })
        })
        .collect();

    let ts = model.time_symbol();
    let explicit_time =
        model.arena.depends_on(model.kinetic, ts) || model.arena.depends_on(model.potential, ts);
    let Sampled {
        max_rel,
        row_rel,
        power_rel,
        quadratic,
        states: sampled,
    } = sample_states(&mut model, &lagrange, &others, states, seed);
    let compared = sampled.compared;
    // (When nothing was compared, the report fails with `nothing_compared()` as its reason.)
    notes.extend(sampled.skipped_note());
    let comparisons: Vec<Comparison> = others
        .iter()
        .zip(&max_rel)
        .zip(&symbolic_equal)
        .map(|(((name, _), worst), symbolic)| Comparison {
            a: "lagrange",
            b: name.clone(),
            max_rel_residual: *worst,
            symbolic_equal: *symbolic,
            states: compared,
            expect_disagreement: false,
        })
        .collect();
    let mut comparisons = comparisons;
    for (c, set) in comparisons.iter_mut().zip(&balance_set_of) {
        c.expect_disagreement = set.is_some_and(|s| model.balance_sets[s].expect_disagreement);
    }
    comparison_notes(
        &model,
        file,
        (&comparisons, &balance_set_of, &row_rel),
        &mut notes,
    );
    let power_balance = if model.speeds_hide_the_energy_form() {
        notes.push("power balance skipped: a generalized speed (or a constraint's auxiliary speed, A q̇ + b) has an offset Z(q, t) or a coefficient that depends on t (u = Y q̇ + Z), so T in the speeds shows neither its degree in q̇ nor its dependence on t".to_string());
        None
    } else if explicit_time {
        notes.push("power balance skipped: T or V depends explicitly on t".to_string());
        None
    } else if !quadratic {
        notes.push("power balance skipped: T is not a quadratic form in the rates".to_string());
        None
    } else {
        Some(PowerBalance {
            max_rel_residual: power_rel,
        })
    };
    let initial_constraints = initial_constraints(&model);
    let mut report = CheckReport {
        model: model.name.clone(),
        comparisons,
        power_balance,
        derivations,
        notes,
        initial_constraints,
        states: sampled,
    };
    if let Some(reason) = report.not_cross_checked() {
        // Said once, as the reason the check fails.
        report.notes.retain(|n| n != NO_MOMENTUM_BALANCE);
        report.notes.push(reason.to_string());
    }
    Ok(report)
}

/// The derivations other than Lagrange's that apply to `model` (the momentum balance, the
/// file's sets of balances, its equations by hand, the energy routes), in that order, with
/// their statistics after Lagrange's; what they are not applied for goes to `notes`.
struct Derived {
    /// Lagrange's statistics, then each of `others`'.
    derivations: Vec<DerivationStats>,
    /// Each derivation's name and equations.
    others: Vec<(String, EquationsOfMotion)>,
    /// The index in `model.balance_sets` of each of `others` that is a set of balances.
    balance_set_of: Vec<Option<usize>>,
}

/// [`Derived`] for `model`.
///
/// # Errors
/// The diagnostics of a derivation that fails.
fn derive_others(
    model: &mut SymbolicModel,
    file: &ModelFile,
    (lagrange_stats, seed): (DerivationStats, u64),
    notes: &mut Vec<String>,
) -> Result<Derived, Vec<Diagnostic>> {
    let n = model.num_dofs();
    let mut derivations = vec![lagrange_stats];
    let mut others: Vec<(String, EquationsOfMotion)> = Vec::new();
    // The index in `model.balance_sets` of each of `others` that is a set of balances.
    let mut balance_set_of: Vec<Option<usize>> = Vec::new();
    let momentum: Option<&dyn Formulation> = if Kane::applies_to(model) {
        Some(&Kane)
    } else if MomentumBalance::applies_to(model) {
        Some(&MomentumBalance)
    } else {
        None
    };
    if let Some(momentum) = momentum {
        let (eom, stats) = timed(model, momentum, momentum.name(), file)?;
        derivations.push(stats);
        others.push((momentum.name().to_string(), eom));
        balance_set_of.push(None);
    } else {
        notes.push(NO_MOMENTUM_BALANCE.to_string());
    }
    for name in integrable_nonholonomic(model, seed) {
        notes.push(format!(
            "non-holonomic constraint `{name}` is integrable (holonomic in disguise): its 1-form ω = A dq + b dt has ω ∧ dω = 0 at every state tried, so it could be written as Φ(q, t) = 0 under `constraints:`"
        ));
    }
    if UserBalances::applies_to(model) {
        for set in 0..model.balance_sets.len() {
            let name = model.balance_sets[set].name.clone();
            let (eom, stats) = timed(model, &UserBalances { set }, &name, file)?;
            derivations.push(stats);
            others.push((name, eom));
            balance_set_of.push(Some(set));
        }
    }
    if HandEquations::applies_to(model) {
        let (eom, stats) = timed(model, &HandEquations, HandEquations.name(), file)?;
        derivations.push(stats);
        others.push((HandEquations.name().to_string(), eom));
        balance_set_of.push(None);
    }
    // Lecture 10's energy routes: one equation each, for one coordinate.
    if let Some(reason) = energy_routes_skipped(model) {
        if n == 1 {
            notes.push(reason.to_string());
        }
    } else {
        for route in [&EnergyRate as &dyn Formulation, &PowerRoute] {
            if route.name() == PowerRoute.name() && !PowerRoute::applies_to(model) {
                continue;
            }
            let (eom, stats) = timed(model, route, route.name(), file)?;
            derivations.push(stats);
            others.push((route.name().to_string(), eom));
            balance_set_of.push(None);
        }
    }
    Ok(Derived {
        derivations,
        others,
        balance_set_of,
    })
}

/// The notes on the comparisons with Lagrange that fail or that the file states should fail
/// (`expect: disagree`): which set of equations, and the likely cause.
fn comparison_notes(
    model: &SymbolicModel,
    file: &ModelFile,
    (comparisons, balance_set_of, row_rel): (&[Comparison], &[Option<usize>], &[Vec<f64>]),
    notes: &mut Vec<String>,
) {
    for (k, (c, set)) in comparisons.iter().zip(balance_set_of).enumerate() {
        if c.expect_disagreement {
            let which = set.map_or_else(String::new, |s| balance_set_label(model, s));
            let why = set.and_then(|s| moving_point_form(model, s));
            notes.push(if c.passed(CHECK_TOLERANCE) {
                match why {
                    Some(why) => format!("{which} disagree with Lagrange, as the file states: {why}"),
                    None => format!("{which} disagree with Lagrange, as the file states"),
                }
            } else if c.max_rel_residual.is_nan() {
                format!("{which} are not finite at some of the states where Lagrange's are (a function outside its domain, such as sqrt or asin, or an overflow): a set stated to disagree must still give finite equations")
            } else {
                format!("{which} agree with Lagrange, but the file states that they disagree (`expect: disagree`): here the form holds, or the set is not the one meant")
            });
            continue;
        }
        if c.max_rel_residual.is_nan() || c.max_rel_residual > 1e-8 {
            let singular = c.max_rel_residual.is_infinite();
            let balances = set.map(|s| balance_set_label(model, s));
            if c.max_rel_residual.is_nan() {
                let which = balances.clone().unwrap_or_else(|| {
                    if c.b == HandEquations.name() {
                        "the equations of motion written by hand".to_string()
                    } else {
                        format!("the equations of the {} derivation", c.b)
                    }
                });
                notes.push(format!("{which} are not finite at some of the states where Lagrange's are (a function outside its domain, such as sqrt or asin, or an overflow)"));
            } else if let (Some(set), Some(which)) = (set, balances) {
                notes.push(if singular {
                    format!("{which} are not independent: their M′ is singular")
                } else if let Some(why) = moving_point_form(model, *set) {
                    format!("{which} disagree with Lagrange: {why}")
                } else {
                    format!("{which} disagree with Lagrange: a chosen balance leaves a reaction force in, or misses a load (choose balances about the joints whose reactions they must eliminate)")
                });
            } else if c.b == EnergyRate.name() || c.b == PowerRoute.name() {
                notes.push(if singular {
                    format!("the {} route is singular at a compared state (q̇ = 0 there: the route's equation is q̇ times the equation of motion)", c.b)
                } else {
                    format!("the {} route disagrees with Lagrange: a load's power is missing or a force does work that the equations do not see", c.b)
                });
            } else if c.b == HandEquations.name() {
                notes.push(if singular {
                    "the equations of motion written by hand are not independent: their M′ is singular".to_string()
                } else {
                    format!(
                        "the equations of motion written by hand disagree with Lagrange{}: a term is missing, has the wrong sign or the wrong factor (`eomgen equations` prints Lagrange's)",
                        wrong_hand_equations(file, &row_rel[k])
                    )
                });
            }
        }
    }
}
