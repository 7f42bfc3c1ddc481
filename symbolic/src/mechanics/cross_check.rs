//! Cross-checks of a model at run time, with no code generation (issue 4; `eomgen check`):
//! Lagrange against momentum balance, and the power balance `dE/dt = P`.

use std::time::Instant;

use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};
use rustc_hash::FxHashMap;

use super::BalanceInfo;
use super::lower::StateBox;
pub use super::numeric::solve;
use super::{
    EnergyRate, EquationsOfMotion, Formulation, HandEquations, Kane, Lagrange, MomentumBalance,
    PowerRoute, SymbolicModel, UserBalances, energy_routes_skipped,
};
use crate::expr::eval::Evaluator;
use crate::expr::{ExprId, Symbol, SymbolKind, cse};
use crate::model::diagnostic::Diagnostic;
use crate::model::file::{AmbForm, ModelFile};

mod report;

pub use report::check_model;

/// Cost and time of one derivation.
#[derive(Debug, Clone, PartialEq)]
pub struct DerivationStats {
    /// Formulation name (`lagrange`, `momentum`, `energy`, `power`, `by_hand`, and
    /// `balances` or the name of each set of balances).
    pub name: String,
    /// Wall time of the derivation of `M` and `F` (s).
    pub time_s: f64,
    /// Operations of `M` and `F` as trees.
    pub ops: u64,
    /// Operations after common-subexpression elimination.
    pub ops_after_cse: u64,
}

/// Two derivations compared.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// First formulation.
    pub a: &'static str,
    /// Second formulation ([`DerivationStats::name`]).
    pub b: String,
    /// Largest relative residual of `b`'s equations at `a`'s accelerations over the random
    /// states and `b`'s rows, `|Σⱼ M′ᵢⱼ q̈_a,ⱼ − F′ᵢ| / (Σⱼ |M′ᵢⱼ q̈_a,ⱼ| + |F′ᵢ|)`: a backward
    /// error, at rounding for equal derivations whatever the conditioning of `M` (where the
    /// two q̈ differ by ε·cond(M)). Infinite where `b`'s `M′` is singular, NaN where `b` is
    /// not finite at a state where `a` is (a failure).
    pub max_rel_residual: f64,
    /// Whether `M_a − M_b` and `F_a − F_b` simplify to zero after expansion; `None` where
    /// the rows are not expected to match (user balances are combinations of the equations).
    pub symbolic_equal: Option<bool>,
    /// Number of states compared.
    pub states: usize,
    /// Whether the file states that `b` disagrees with `a` (a set of balances with `expect:
    /// disagree`, kept to show a wrong form): the comparison passes when they differ.
    pub expect_disagreement: bool,
}

impl Comparison {
    /// Whether the comparison passed at relative tolerance `tolerance`: `b` agrees with `a`
    /// to it, or, where [`Self::expect_disagreement`], differs by more (and is finite).
    pub fn passed(&self, tolerance: f64) -> bool {
        if self.expect_disagreement {
            self.max_rel_residual > tolerance && !self.max_rel_residual.is_nan()
        } else {
            self.max_rel_residual <= tolerance
        }
    }
}

/// The power balance `dE/dt = Σ Qᵢ q̇ᵢ`, with `E = T + V` and `Q` the non-potential forces.
#[derive(Debug, Clone, PartialEq)]
pub struct PowerBalance {
    /// Largest `|dE/dt − P| / max(|dE/dt|, |P|, Σ|Fᵢ q̇ᵢ|)` over the states.
    pub max_rel_residual: f64,
}

/// Bound on the constraint residuals of the file's `initial:` state, as the runtime's
/// (`make_consistent`): a start farther from `Φ = 0` or `Φ̇ = 0` is refused by `simulate`.
pub const INITIAL_CONSTRAINT_TOLERANCE: f64 = 1e-9;

/// Relative tolerance of the cross-checks (`eomgen check`, the report's derivation rows): the
/// derivations differ only by rounding (~1e-14).
pub const CHECK_TOLERANCE: f64 = 1e-8;

/// Random states `eomgen check` compares by default.
pub const DEFAULT_CHECK_STATES: usize = 200;

/// Seed of the random states (the same states on every run).
pub const CHECK_SEED: u64 = 0x5EED;

/// The constraint residuals of the file's `initial:` state (t = 0, parameters at their
/// defaults), when no coordinate is a `{ guess: … }` (else the runtime solves the start).
#[derive(Debug, Clone, PartialEq)]
pub struct InitialConstraints {
    /// The constraint with the largest residual.
    pub constraint: String,
    /// Its residual: `|Φ|` (the constraint's unit) or, if larger, `|Φ̇|` (per s), or of the
    /// non-holonomic `A q̇ + b`; NaN where it is undefined.
    pub residual: f64,
    /// Whether it is the velocity residual (`Φ̇` or `A q̇ + b`) rather than `Φ`.
    pub velocity: bool,
}

impl InitialConstraints {
    /// Whether the start satisfies every constraint to [`INITIAL_CONSTRAINT_TOLERANCE`].
    pub fn passed(&self) -> bool {
        self.residual <= INITIAL_CONSTRAINT_TOLERANCE
    }
}

/// Everything `eomgen check` reports for one model.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckReport {
    /// Model name.
    pub model: String,
    /// Pairwise comparisons of derivations.
    pub comparisons: Vec<Comparison>,
    /// The power balance; `None` when it does not hold by construction (explicit time in `T`
    /// or `V`, or `T` not quadratic in `q̇`, as for a driven base), with the reason in `notes`.
    pub power_balance: Option<PowerBalance>,
    /// Derivation statistics per formulation.
    pub derivations: Vec<DerivationStats>,
    /// Why a check was skipped.
    pub notes: Vec<String>,
    /// The constraint residuals of `initial:`; `None` without constraints or when the start
    /// has guesses to be solved.
    pub initial_constraints: Option<InitialConstraints>,
    /// How many of the random states were compared, and why the others were skipped.
    pub states: SampledStates,
}

/// How many random states [`check_model`] compared, and why it skipped the others: a state
/// is compared only where Lagrange's `M` and `F` are finite and `M` is regular.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct SampledStates {
    /// States drawn.
    pub drawn: usize,
    /// States compared.
    pub compared: usize,
    /// States skipped because Lagrange's `M` or `F` was not finite there (a function outside
    /// its domain, such as `sqrt` or `ln` of a negative number, or an overflow).
    pub not_finite: usize,
    /// States skipped because Lagrange's `M` was singular there (or `q̈` overflowed).
    pub singular: usize,
}

impl SampledStates {
    /// Why nothing was compared, when no state was (`None` when some state was): a check
    /// over no state is never a pass.
    pub fn nothing_compared(&self) -> Option<String> {
        (self.compared == 0).then(|| {
            format!(
                "no state compared: of {} random states (q, q̇ within 2·max(1, |start|) of their start in `initial:`, t in [0, 5]), {}",
                self.drawn,
                self.skipped()
            )
        })
    }

    /// Why states were skipped, when some were (`None` when every state was compared):
    /// `3 had a non-finite M or F (…), 2 a singular M`.
    pub fn skipped_note(&self) -> Option<String> {
        (self.compared > 0 && self.compared < self.drawn).then(|| {
            format!(
                "compared {} of {} random states: {}",
                self.compared,
                self.drawn,
                self.skipped()
            )
        })
    }

    fn skipped(&self) -> String {
        let mut parts = Vec::new();
        if self.not_finite > 0 {
            parts.push(format!(
                "{} had a non-finite Lagrange M or F (a function outside its domain, such as sqrt or ln of a negative number, or an overflow)",
                self.not_finite
            ));
        }
        if self.singular > 0 {
            parts.push(format!(
                "{} had a singular Lagrange M (the comparison solves M q̈ = F without the constraints)",
                self.singular
            ));
        }
        if parts.is_empty() {
            "none was drawn".to_string()
        } else {
            parts.join(", ")
        }
    }
}

/// The note of a model that momentum balance cannot derive.
const NO_MOMENTUM_BALANCE: &str =
    "momentum balance needs bodies and no written `kinetic:`: compared nothing";

impl CheckReport {
    /// Why the derivation was not cross-checked, when no second derivation independent of
    /// Lagrange's was compared with it (`None` when one was): a model with no bodies, or one
    /// that writes `kinetic:`, and no `balances:` or hand-written `equations_of_motion:`. The
    /// energy equation ([`EnergyRate`]) does not count: it differentiates the same `T` and
    /// `V` that Lagrange's equations do, so it checks the derivation, not the model's energies.
    pub fn not_cross_checked(&self) -> Option<&'static str> {
        self.comparisons.iter().all(|c| c.b == EnergyRate.name()).then_some(
            "not cross-checked: only Lagrange's equations (and the energy equation, from the same T and V) apply (momentum balance needs bodies and no written `kinetic:`); add the equations of motion derived by hand under `checks: equations_of_motion:`",
        )
    }

    /// Whether every check passed at relative tolerance `tolerance`; never when no random
    /// state was compared ([`SampledStates::nothing_compared`]) or no second derivation was
    /// ([`Self::not_cross_checked`]).
    pub fn passed(&self, tolerance: f64) -> bool {
        self.states.compared > 0
            && self.not_cross_checked().is_none()
            && self.comparisons.iter().all(|c| c.passed(tolerance))
            && self
                .power_balance
                .as_ref()
                .is_none_or(|p| p.max_rel_residual <= tolerance)
            && self
                .initial_constraints
                .as_ref()
                .is_none_or(InitialConstraints::passed)
    }
}

impl CheckReport {
    /// The report as `eomgen check --json` prints it ([`CheckSummary`]), judged at relative
    /// tolerance `tolerance`; with `with_times` the derivations' wall times are included
    /// (they are the one figure that differs between two identical runs).
    pub fn summary(&self, tolerance: f64, with_times: bool) -> CheckSummary {
        // A residual over no state is null, not 0.
        let sampled = self.states.compared > 0;
        CheckSummary {
            model: self.model.clone(),
            tolerance,
            failure: self
                .states
                .nothing_compared()
                .or_else(|| self.not_cross_checked().map(str::to_string)),
            passed: self.passed(tolerance),
            checks: self
                .comparisons
                .iter()
                .map(|c| ComparisonSummary {
                    a: c.a,
                    b: c.b.clone(),
                    max_rel_residual: sampled.then_some(c.max_rel_residual),
                    symbolic_equal: c.symbolic_equal,
                    states: c.states,
                    expect_disagreement: c.expect_disagreement,
                })
                .collect(),
            power_balance: self.power_balance.as_ref().map(|p| PowerBalanceSummary {
                max_rel_residual: sampled.then_some(p.max_rel_residual),
            }),
            initial_constraints: self.initial_constraints.as_ref().map(|c| {
                InitialConstraintsSummary {
                    constraint: c.constraint.clone(),
                    residual: c.residual,
                    velocity: c.velocity,
                    tolerance: INITIAL_CONSTRAINT_TOLERANCE,
                    passed: c.passed(),
                }
            }),
            states: self.states,
            derivation: self
                .derivations
                .iter()
                .map(|d| {
                    let summary = DerivationSummary {
                        time_s: with_times.then_some(d.time_s),
                        ops: d.ops,
                        ops_after_cse: d.ops_after_cse,
                    };
                    (d.name.clone(), summary)
                })
                .collect(),
            notes: self.notes.clone(),
        }
    }
}

/// A [`CheckReport`] as `eomgen check --json` prints it ([`CheckReport::summary`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CheckSummary {
    /// The model's name.
    pub model: String,
    /// The relative tolerance the checks were judged at.
    pub tolerance: f64,
    /// Why nothing was compared ([`SampledStates::nothing_compared`]) or nothing was
    /// cross-checked ([`CheckReport::not_cross_checked`]); null otherwise.
    pub failure: Option<String>,
    /// Whether every check passed ([`CheckReport::passed`]).
    pub passed: bool,
    /// The comparisons of `q̈` between derivations.
    pub checks: Vec<ComparisonSummary>,
    /// The power balance check (null when the model has none).
    pub power_balance: Option<PowerBalanceSummary>,
    /// The initial state's constraint residual (null without constraints or with guesses).
    pub initial_constraints: Option<InitialConstraintsSummary>,
    /// How many random states were drawn, compared and skipped.
    pub states: SampledStates,
    /// Each derivation's size (and wall time, when asked for), by name.
    pub derivation: std::collections::BTreeMap<String, DerivationSummary>,
    /// Notes on what was found.
    pub notes: Vec<String>,
}

/// One [`Comparison`] in a [`CheckSummary`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ComparisonSummary {
    /// The first derivation's name.
    pub a: &'static str,
    /// The second's.
    pub b: String,
    /// [`Comparison::max_rel_residual`] (null when no state was compared).
    pub max_rel_residual: Option<f64>,
    /// [`Comparison::symbolic_equal`].
    pub symbolic_equal: Option<bool>,
    /// The states compared.
    pub states: usize,
    /// [`Comparison::expect_disagreement`] (left out when false).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub expect_disagreement: bool,
}

/// The [`PowerBalance`] in a [`CheckSummary`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PowerBalanceSummary {
    /// [`PowerBalance::max_rel_residual`] (null when no state was compared).
    pub max_rel_residual: Option<f64>,
}

/// The [`InitialConstraints`] in a [`CheckSummary`], with the tolerance it is judged at.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct InitialConstraintsSummary {
    /// [`InitialConstraints::constraint`].
    pub constraint: String,
    /// [`InitialConstraints::residual`].
    pub residual: f64,
    /// [`InitialConstraints::velocity`].
    pub velocity: bool,
    /// [`INITIAL_CONSTRAINT_TOLERANCE`].
    pub tolerance: f64,
    /// [`InitialConstraints::passed`].
    pub passed: bool,
}

/// One derivation's size in a [`CheckSummary`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct DerivationSummary {
    /// [`DerivationStats::time_s`] (s; left out unless asked for).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_s: Option<f64>,
    /// [`DerivationStats::ops`].
    pub ops: u64,
    /// [`DerivationStats::ops_after_cse`].
    pub ops_after_cse: u64,
}

/// The largest constraint residual of the file's `initial:` state (t = 0, parameters at
/// their defaults); `None` without constraints or with `{ guess: … }` coordinates.
fn initial_constraints(model: &SymbolicModel) -> Option<InitialConstraints> {
    let c = &model.constraints;
    if c.is_empty() || !model.initial_guesses.is_empty() {
        return None;
    }
    let symbols = model.arena.symbols().to_vec();
    // Parameters at their defaults, every other symbol 0.
    let parameters = defaults_by_symbol(model);
    let starts: Vec<ExprId> = model
        .initial_q
        .iter()
        .chain(&model.initial_qdot)
        .copied()
        .collect();
    let start = Evaluator::new(&model.arena, &starts)
        .eval(&parameters)
        .to_vec();
    let n = model.num_dofs();
    let bindings: Vec<f64> = symbols
        .iter()
        .zip(&parameters)
        .map(|(s, p)| match s.kind {
            SymbolKind::Coordinate(i) => start[i as usize],
            SymbolKind::Velocity(i) => start[n + i as usize],
            _ => *p,
        })
        .collect();
    let roots: Vec<ExprId> = c.phi.iter().chain(&c.velocity).copied().collect();
    let values = Evaluator::new(&model.arena, &roots)
        .eval(&bindings)
        .to_vec();
    let mut worst: Option<InitialConstraints> = None;
    for (k, v) in values.iter().enumerate() {
        let (i, velocity) = if k < c.holonomic {
            (k, false)
        } else {
            (k - c.holonomic, true)
        };
        let residual = if v.is_nan() { f64::NAN } else { v.abs() };
        let larger = worst
            .as_ref()
            .is_none_or(|w| residual > w.residual || (residual.is_nan() && !w.residual.is_nan()));
        if larger {
            worst = Some(InitialConstraints {
                constraint: c.names[i].clone(),
                residual,
                velocity,
            });
        }
    }
    worst
}

///
/// Each derivation may build [`super::DERIVATION_OPERAND_LIMIT`] operands.
///
/// # Errors
/// The located error of a derivation past that limit ([`super::finish_derivation`]).
fn timed(
    model: &mut SymbolicModel,
    f: &dyn Formulation,
    name: &str,
    file: &ModelFile,
) -> Result<(EquationsOfMotion, DerivationStats), Vec<Diagnostic>> {
    let start = Instant::now();
    super::limit_derivation(model);
    let eom = f.derive(model);
    super::finish_derivation(model, file)?;
    let time_s = start.elapsed().as_secs_f64();
    let roots: Vec<ExprId> = eom
        .mass_matrix
        .iter()
        .chain(&eom.forcing)
        .copied()
        .collect();
    let stats = DerivationStats {
        name: name.to_string(),
        time_s,
        ops: model.arena.tree_operation_count(&roots),
        ops_after_cse: cse::operation_count(&model.arena, &roots),
    };
    Ok((eom, stats))
}

/// Which hand-written equations fail at Lagrange's accelerations (`row_rel` as
/// [`Sampled::row_rel`], above the check's tolerance): ` in equation 2 (line 58)`, or nothing
/// when no single row shows it.
fn wrong_hand_equations(file: &ModelFile, row_rel: &[f64]) -> String {
    let wrong: Vec<String> = row_rel
        .iter()
        .enumerate()
        .filter(|(_, r)| r.is_nan() || **r > CHECK_TOLERANCE)
        .map(|(k, _)| match file.checks.equations_of_motion.get(k) {
            Some(e) => format!("{} (line {})", k + 1, e.location.line),
            None => (k + 1).to_string(),
        })
        .collect();
    match wrong.len() {
        0 => String::new(),
        1 => format!(" in equation {}", wrong[0]),
        _ => format!(" in equations {}", wrong.join(", ")),
    }
}

/// How the notes of [`check_model`] name a set of balances: `the balances` in the plain
/// list form, `` the balances `NAME` `` for a named set.
fn balance_set_label(model: &SymbolicModel, set: usize) -> String {
    match model.balance_sets.get(set) {
        Some(s) if model.balance_sets.len() > 1 || s.name != "balances" => {
            format!("the balances `{}`", s.name)
        }
        _ => "the balances".to_string(),
    }
}

/// Why a set of balances that disagrees with Lagrange is wrong, when it takes an `amb` in a
/// form that holds only about a fixed point or a special moving one: `form: h_dot` about a
/// moving point A misses `v_A × m v_G` (it holds only where `v_A × v_G = 0`), `form:
/// h_rel_dot` misses `r_G/A × m a_A` (it holds only where `r_G/A × a_A = 0`). `None` when
/// the set has neither about a point that moves.
fn moving_point_form(model: &SymbolicModel, set: usize) -> Option<String> {
    let range = model.balance_sets.get(set)?.range.clone();
    let n = model.num_dofs();
    model.balances[range].iter().find_map(|b| {
        let BalanceInfo::Amb { about, form, .. } = b else {
            return None;
        };
        let point = &model.points[*about];
        let moves = point.1.iter().any(|c| {
            model.arena.depends_on(*c, model.time_symbol())
                || (0..n).any(|i| model.arena.depends_on(*c, model.coordinate_symbols(i)[0]))
        });
        if !moves {
            return None;
        }
        let about = &point.0;
        match form {
            AmbForm::HDot => Some(format!("the `amb` about `{about}` has `form: h_dot`, Σ M_A = dH_A/dt with H_A = Σ r_G/A × m v_G (absolute velocities), which misses v_A × m v_G about a moving point: it holds only where v_A × v_G = 0 (A fixed or the centre of mass); use the default `form: r_x_ma`")),
            AmbForm::HRelDot => Some(format!("the `amb` about `{about}` has `form: h_rel_dot`, Σ M_A = dH_A/rel/dt with velocities relative to A, which misses r_G/A × m a_A about an accelerating point: it holds only where r_G/A × a_A = 0 (A fixed, the centre of mass, or accelerating along the line to it); use the default `form: r_x_ma`")),
            AmbForm::RCrossMa => None,
        }
    })
}

/// What [`check_model`] measures at random states: q̈ of each other derivation against
/// Lagrange's, the power balance, and whether `T` is homogeneous of degree 2 in the rates.
#[derive(Debug, Clone, PartialEq)]
struct Sampled {
    /// Per other derivation, the largest of [`Self::row_rel`] over its rows (infinite where
    /// its `M′` is singular, NaN where its `M′` or `F′` is not finite at a compared state).
    max_rel: Vec<f64>,
    /// Per other derivation and per row `k` of its `M′ q̈ = F′`, the largest residual
    /// `|Σⱼ M′ₖⱼ q̈_L,ⱼ − F′ₖ|` at Lagrange's accelerations relative to the size of its terms
    /// `Σⱼ |M′ₖⱼ q̈_L,ⱼ| + |F′ₖ|`: which equation of a set is wrong (every true equation of
    /// motion holds at Lagrange's q̈, to rounding).
    row_rel: Vec<Vec<f64>>,
    /// The largest `|dE/dt − Σ Qᵢ q̇ᵢ|` along Lagrange's q̈, relative to the largest of
    /// `|dE/dt|`, `|Σ Qᵢ q̇ᵢ|` and `Σ |Fᵢ q̇ᵢ|`.
    power_rel: f64,
    /// `T(q, 2q̇) = 4 T(q, q̇)` at every state (to 1e-9 relative).
    quadratic: bool,
    /// The states compared (where Lagrange's `M` and `F` were finite and `M` regular) and
    /// why the others were skipped.
    states: SampledStates,
}

/// Samples `states` random states (q, q̇ within `2 max(1, |start|)` of their start in
/// `initial:`, t in [0, 5], parameters within ±10 % of their defaults or, where the default
/// is 0, in [0.1, 0.5]; from `seed`) and compares
/// `others` with `lagrange` there.
fn sample_states(
    model: &mut SymbolicModel,
    lagrange: &EquationsOfMotion,
    others: &[(String, EquationsOfMotion)],
    states: usize,
    seed: u64,
) -> Sampled {
    let n = model.num_dofs();
    // Power balance: d(T + V)/dt along the motion against Σ Qᵢ q̇ᵢ.
    let energy = model.arena.plus(model.kinetic, model.potential);
    let de_dt = model.arena.time_derivative(energy);
    let rates: Vec<ExprId> = (0..n).map(|i| model.arena.coordinate_rate(i)).collect();
    let power_terms: Vec<ExprId> = (0..n)
        .map(|i| model.arena.times(model.generalized_forces[i], rates[i]))
        .collect();
    let power = model.arena.sum(&power_terms);

    let mut roots: Vec<ExprId> = lagrange
        .mass_matrix
        .iter()
        .chain(&lagrange.forcing)
        .copied()
        .collect();
    let lagrange_len = roots.len();
    for (_, b) in others {
        roots.extend(b.mass_matrix.iter().chain(&b.forcing));
    }
    // The constraints' J and γ, for a model whose M is singular off the constraints (Euler
    // parameters: nothing moves along their norm), compared through the KKT system.
    let constraint_start = roots.len();
    let m = model.constraints.len();
    roots.extend(
        model
            .constraints
            .jacobian
            .iter()
            .chain(&model.constraints.gamma),
    );
    roots.push(model.kinetic);
    let mut evaluator = Evaluator::new(&model.arena, &roots);
    // The power balance at the solved accelerations, apart: re-evaluating every root for it
    // would copy all the mass matrices again (three million values for a 1000-mass chain).
    let mut power_balance = Evaluator::new(&model.arena, &[de_dt, power]);
    let mut v = vec![0.0; roots.len()];
    // T at doubled rates, for the homogeneity test T(q, 2q̇) = 4 T(q, q̇).
    let mut kinetic_only = Evaluator::new(&model.arena, &[model.kinetic]);

    // Xoshiro256++ (portable: the same states for a seed on every platform and release).
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut max_rel: Vec<f64> = vec![0.0; others.len()];
    let mut row_rel: Vec<Vec<f64>> = vec![vec![0.0; n]; others.len()];
    let mut power_rel: f64 = 0.0;
    // In speeds with an offset, `T(q, u)` says nothing of `T`'s degree in `q̇`: not tested,
    // the power balance skipped.
    let mut quadratic = !model.speeds_hide_the_energy_form();
    let symbols = model.arena.symbols().to_vec();
    let defaults = defaults_by_symbol(model);
    let state_box = model.state_box();
    // Where each coordinate's rate is bound.
    let rate_slots: Vec<usize> = (0..n)
        .map(|i| model.coordinate_symbols(i)[1].index())
        .collect();
    // In speeds beside constraints, the auxiliary speeds (the last ones) are drawn at 0, on
    // the velocity constraints as every motion is (so the constraint forces do no work), and
    // every derivation goes through the KKT system: `M` may be singular along an auxiliary
    // speed (Euler parameters' norm), where rounding would leave a tiny pivot.
    let auxiliary = model.speeds.as_ref().map_or(0, |s| s.auxiliary);
    let mut sampled = SampledStates {
        drawn: states,
        ..SampledStates::default()
    };
    for _ in 0..states {
        let t = rng.random_range(0.0..5.0);
        let mut bindings = draw_bindings(&mut rng, &symbols, &defaults, &state_box, t);
        for &slot in &rate_slots[n - auxiliary..] {
            bindings[slot] = 0.0;
        }
        evaluator.eval_into(&bindings, &mut v);
        let nn = n * n;
        if !v[..nn + n].iter().all(|x| x.is_finite()) {
            sampled.not_finite += 1;
            continue;
        }
        let constraints = (m > 0).then(|| &v[constraint_start..constraint_start + m * n + m]);
        // With constraints, a derivation whose M is singular (as along the norm of Euler
        // parameters, where nothing moves) sends every derivation through the KKT system.
        let regular = |base: usize| {
            solve(
                v[base..base + nn].to_vec(),
                v[base + nn..base + nn + n].to_vec(),
            )
            .filter(|qdd| qdd.iter().all(|x| x.is_finite()))
        };
        let others_regular =
            (0..others.len()).all(|k| regular(lagrange_len + k * (nn + n)).is_some());
        let unconstrained =
            regular(0).filter(|_| constraints.is_none() || (others_regular && auxiliary == 0));
        let qdd = match (unconstrained, constraints) {
            (Some(qdd), _) => {
                compare_others(&v, &qdd, (lagrange_len, n), &mut row_rel, &mut max_rel);
                qdd
            }
            // M singular, as it is along the norm of Euler parameters: the accelerations the
            // constraints determine, of each derivation, compared.
            (None, Some(jg)) => match kkt_accelerations(&v[..nn + n], jg, n, m) {
                Some(qdd) => {
                    compare_constrained(
                        &v,
                        &qdd,
                        jg,
                        (lagrange_len, n, m),
                        &mut row_rel,
                        &mut max_rel,
                    );
                    qdd
                }
                None => {
                    sampled.singular += 1;
                    continue;
                }
            },
            (None, None) => {
                sampled.singular += 1;
                continue;
            }
        };
        sampled.compared += 1;
        // T homogeneous of degree 2 in q̇?
        let t1 = v[v.len() - 1];
        if homogeneity_fails(&mut kinetic_only, &symbols, &bindings, t1) {
            quadratic = false;
        }
        let forcing = &v[nn..nn + n];
        let rel = power_residual(
            &mut power_balance,
            &symbols,
            &bindings,
            &qdd,
            forcing,
            &rate_slots,
        );
        power_rel = power_rel.max(rel);
    }
    Sampled {
        max_rel,
        row_rel,
        power_rel,
        quadratic,
        states: sampled,
    }
}

/// The value of every symbol at one random state at time `t`, drawn from `rng` in the order
/// of `symbols` (parameters about their `defaults`, coordinates and rates within
/// `state_box`, every other symbol 0).
fn draw_bindings(
    rng: &mut Xoshiro256PlusPlus,
    symbols: &[Symbol],
    defaults: &[f64],
    state_box: &StateBox,
    t: f64,
) -> Vec<f64> {
    let mut bindings = vec![0.0; symbols.len()];
    for (i, s) in symbols.iter().enumerate() {
        bindings[i] = match s.kind {
            // A parameter whose default is 0 (a forcing amplitude or damping switched
            // off) would hide every term it multiplies: it takes a value in [0.1, 0.5].
            SymbolKind::Parameter if defaults[i] == 0.0 => rng.random_range(0.1..0.5),
            SymbolKind::Parameter => defaults[i] * rng.random_range(0.9..1.1),
            SymbolKind::Coordinate(_) | SymbolKind::Velocity(_) => {
                state_box.at(i, rng.random_range(-2.0..2.0))
            }
            SymbolKind::Time => t,
            _ => 0.0,
        };
    }
    bindings
}

/// Compares each other derivation with Lagrange's accelerations `qdd` at one state, whose
/// values `v` hold Lagrange's `M` and `F` (`n` rows) and then, from `lagrange_len`, each other
/// derivation's `M′` and `F′`: updates the largest relative residual of each row
/// (`row_rel`) and of each derivation (`max_rel`).
fn compare_others(
    v: &[f64],
    qdd: &[f64],
    (lagrange_len, n): (usize, usize),
    row_rel: &mut [Vec<f64>],
    max_rel: &mut [f64],
) {
    let nn = n * n;
    // Each row of each other derivation at Lagrange's accelerations: a backward error,
    // at rounding for a right derivation whatever the conditioning of M (two solves of
    // a cond(M) = 4e9 system differ by ε·cond(M) = 9e-7 in q̈, each exact to rounding).
    let mut here = vec![0.0f64; max_rel.len()];
    for (k, rows) in row_rel.iter_mut().enumerate() {
        let base = lagrange_len + k * (nn + n);
        for (i, worst) in rows.iter_mut().enumerate() {
            let terms = (0..n).map(|j| v[base + i * n + j] * qdd[j]);
            let residual = terms.clone().sum::<f64>() - v[base + nn + i];
            let size = terms.map(f64::abs).sum::<f64>() + v[base + nn + i].abs();
            let rel = residual.abs() / size.max(f64::MIN_POSITIVE);
            *worst = if rel.is_nan() { rel } else { worst.max(rel) };
            here[k] = if rel.is_nan() { rel } else { here[k].max(rel) };
        }
    }
    for (k, worst) in max_rel.iter_mut().enumerate() {
        let base = lagrange_len + k * (nn + n);
        // The other derivation not finite where Lagrange's is (a function outside its
        // domain) is a disagreement, not a state to skip: NaN, kept (`max` would drop it).
        if worst.is_nan() || !v[base..base + nn + n].iter().all(|x| x.is_finite()) {
            *worst = f64::NAN;
            continue;
        }
        match solve(
            v[base..base + nn].to_vec(),
            v[base + nn..base + nn + n].to_vec(),
        ) {
            // Its own M′ singular: its equations do not determine q̈.
            Some(other) if other.iter().any(|x| !x.is_finite()) => *worst = f64::INFINITY,
            Some(_) if here[k].is_nan() => *worst = f64::NAN,
            Some(_) => *worst = worst.max(here[k]),
            None => *worst = f64::INFINITY,
        }
    }
}

/// `q̈` of `[M Jᵀ; J 0][q̈; λ] = [F; γ]`, `mf` holding `M` (`n × n`, row-major) and `F`, `jg`
/// holding `J` (`m × n`) and `γ`; `None` where the system is singular or the result not
/// finite.
fn kkt_accelerations(mf: &[f64], jg: &[f64], n: usize, m: usize) -> Option<Vec<f64>> {
    let k = n + m;
    let mut a = vec![0.0; k * k];
    let mut b = vec![0.0; k];
    for r in 0..n {
        for c in 0..n {
            a[r * k + c] = mf[r * n + c];
        }
        b[r] = mf[n * n + r];
    }
    for i in 0..m {
        for c in 0..n {
            let j = jg[i * n + c];
            a[(n + i) * k + c] = j;
            a[c * k + n + i] = j;
        }
        b[n + i] = jg[m * n + i];
    }
    let x = solve(a, b)?;
    let qdd = x[..n].to_vec();
    qdd.iter().all(|v| v.is_finite()).then_some(qdd)
}

/// [`compare_others`] for a model whose `M` is singular off its constraints: each other
/// derivation's accelerations from the KKT system with the same `J` and `γ` (`jg`, `m`
/// constraints) against Lagrange's `qdd`, relative to the largest of them and 1.
fn compare_constrained(
    v: &[f64],
    qdd: &[f64],
    jg: &[f64],
    (lagrange_len, n, m): (usize, usize, usize),
    row_rel: &mut [Vec<f64>],
    max_rel: &mut [f64],
) {
    let nn = n * n;
    let scale = qdd.iter().fold(1.0f64, |s, x| s.max(x.abs()));
    for (k, (rows, worst)) in row_rel.iter_mut().zip(max_rel.iter_mut()).enumerate() {
        let base = lagrange_len + k * (nn + n);
        let Some(other) = kkt_accelerations(&v[base..base + nn + n], jg, n, m) else {
            *worst = f64::INFINITY;
            continue;
        };
        for (i, row) in rows.iter_mut().enumerate() {
            let rel = (other[i] - qdd[i]).abs() / scale;
            *row = if rel.is_nan() { rel } else { row.max(rel) };
            *worst = if rel.is_nan() { rel } else { worst.max(rel) };
        }
    }
}

/// Whether `T(q, 2q̇)` differs from `4 T(q, q̇)` by more than 1e-9 relative at the state
/// `bindings`, where `T` is `t1` (false where the difference is NaN).
fn homogeneity_fails(
    kinetic_only: &mut Evaluator,
    symbols: &[Symbol],
    bindings: &[f64],
    t1: f64,
) -> bool {
    let mut doubled = bindings.to_vec();
    for (i, s) in symbols.iter().enumerate() {
        if let SymbolKind::Velocity(_) = s.kind {
            doubled[i] *= 2.0;
        }
    }
    let t2 = kinetic_only.eval(&doubled)[0];
    (t2 - 4.0 * t1).abs() > 1e-9 * (1.0 + t1.abs())
}

/// `|dE/dt − Σ Qᵢ q̇ᵢ|` at the state `bindings` with the solved accelerations `qdd`,
/// relative to the largest of `|dE/dt|`, `|Σ Qᵢ q̇ᵢ|` and `Σ |Fᵢ q̇ᵢ|` (`forcing` is `F`,
/// `rate_slots` where each rate is bound).
fn power_residual(
    power_balance: &mut Evaluator,
    symbols: &[Symbol],
    bindings: &[f64],
    qdd: &[f64],
    forcing: &[f64],
    rate_slots: &[usize],
) -> f64 {
    // dE/dt with the solved accelerations.
    let mut with_acc = bindings.to_vec();
    for (i, s) in symbols.iter().enumerate() {
        if let SymbolKind::Acceleration(j) = s.kind {
            with_acc[i] = qdd[j as usize];
        }
    }
    let w = power_balance.eval(&with_acc);
    let (de, p) = (w[0], w[1]);
    let fq: f64 = (0..forcing.len())
        .map(|i| (forcing[i] * bindings[rate_slots[i]]).abs())
        .sum();
    let scale = de.abs().max(p.abs()).max(fq).max(f64::MIN_POSITIVE);
    (de - p).abs() / scale
}

/// Each parameter's default at the index of its symbol (0 for every other symbol): looked up
/// by index rather than by name, so that binding a state is linear in the number of symbols.
fn defaults_by_symbol(model: &SymbolicModel) -> Vec<f64> {
    let mut defaults = vec![0.0; model.arena.symbols().len()];
    for p in &model.parameters {
        defaults[p.symbol.index()] = p.default;
    }
    defaults
}

/// Names of the non-holonomic constraints that are integrable, by Frobenius' condition on the
/// 1-form `ω = Σ aᵢ dqᵢ + b dt` of `A q̇ + b = 0`: `ω ∧ dω = 0`, i.e. for every triple of the
/// variables `(q, t)`, `a_i(∂_j a_k − ∂_k a_j) + a_j(∂_k a_i − ∂_i a_k) + a_k(∂_i a_j − ∂_j a_i)
/// = 0` (one constraint at a time; with fewer than three variables every 1-form is
/// integrable). Checked at 50 random states to 1e-9 relative to the terms' size.
fn integrable_nonholonomic(model: &mut SymbolicModel, seed: u64) -> Vec<String> {
    let c = model.constraints.clone();
    let n = model.num_dofs();
    let symbols: Vec<[crate::expr::SymbolId; 3]> =
        (0..n).map(|i| model.coordinate_symbols(i)).collect();
    let ts = model.time_symbol();
    let mut variables: Vec<crate::expr::SymbolId> = symbols.iter().map(|s| s[0]).collect();
    variables.push(ts);
    let mut found = Vec::new();
    // In speeds, a constraint's row is its auxiliary speed's: `A` and `b` are that speed's
    // coefficients and offset (the constraint itself reads `u = 0`).
    let speeds = model.speeds.clone();
    for r in c.holonomic..c.len() {
        let arena = &mut model.arena;
        let zero = arena.int(0);
        let at_rest: FxHashMap<_, _> = symbols.iter().map(|s| (s[1], zero)).collect();
        let coefficients: Vec<ExprId> = match &speeds {
            Some(sp) => {
                let row = n - c.len() + r;
                let mut a = sp.coefficients[row * n..(row + 1) * n].to_vec();
                a.push(sp.offsets[row]);
                a
            }
            None => {
                let mut a: Vec<ExprId> = (0..n).map(|j| c.jacobian[r * n + j]).collect();
                a.push(arena.substitute(c.velocity[r], &at_rest));
                a
            }
        };
        let k = coefficients.len();
        if k < 3 {
            found.push(c.names[r].clone());
            continue;
        }
        let mut d = vec![zero; k * k]; // d[i k + j] = ∂c_i/∂x_j
        for i in 0..k {
            for j in 0..k {
                d[i * k + j] = arena.diff(coefficients[i], variables[j]);
            }
        }
        let mut terms: Vec<ExprId> = Vec::new();
        for i in 0..k {
            for j in i + 1..k {
                for l in j + 1..k {
                    let curl = |arena: &mut crate::expr::ExprArena, a: usize, b: usize| {
                        arena.minus(d[b * k + a], d[a * k + b])
                    };
                    let (cjk, cki, cij) = (curl(arena, j, l), curl(arena, l, i), curl(arena, i, j));
                    let t1 = arena.times(coefficients[i], cjk);
                    let t2 = arena.times(coefficients[j], cki);
                    let t3 = arena.times(coefficients[l], cij);
                    terms.push(arena.sum(&[t1, t2, t3]));
                    terms.extend([t1, t2, t3]);
                }
            }
        }
        let mut evaluator = Evaluator::new(&model.arena, &terms);
        let defaults = defaults_by_symbol(model);
        let state_box = model.state_box();
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed ^ 0x5DEE_CE66);
        let mut integrable = true;
        for _ in 0..50 {
            let bindings: Vec<f64> = model
                .arena
                .symbols()
                .iter()
                .enumerate()
                .map(|(i, s)| match s.kind {
                    SymbolKind::Parameter => defaults[i],
                    _ => state_box.at(i, rng.random_range(-2.0..2.0)),
                })
                .collect();
            let v = evaluator.eval(&bindings);
            for triple in v.chunks(4) {
                let scale = triple[1..].iter().fold(1e-300f64, |m, x| m.max(x.abs()));
                // A NaN residual (outside the domain) counts as "not shown integrable".
                if triple[0].is_nan() || triple[0].abs() > 1e-9 * scale {
                    integrable = false;
                }
            }
        }
        if integrable {
            found.push(c.names[r].clone());
        }
    }
    found
}

#[cfg(test)]
mod tests;
