//! Generalized speeds (`speeds:`): a lowered model's state switched from `(q, q̇)` to
//! `(q, u)`, Kane's equations in `u`, and Lagrange's equations carried into `u` for their
//! cross-check (T. R. Kane, D. A. Levinson, *Dynamics: Theory and Applications*,
//! McGraw-Hill, 1985, §2.12, §§6.1–6.3).
//!
//! The file defines each speed linear in the rates, `u = Y(q, t) q̇ + Z(q, t)`, so that the
//! kinematic equations are
//!
//! ```text
//! q̇ = W (u − Z),   W = Y⁻¹ = adj(Y) / det(Y)
//! ```
//!
//! with the determinant and the adjugate multiplied out. A velocity `v = A(q, t) q̇ + b(q, t)`
//! becomes `v = Σᵣ Vᵣ uᵣ + (b − Σᵣ Vᵣ Zᵣ)` with the partial velocities
//! `Vᵣ = (Σⱼ Aⱼ adj(Y)ⱼᵣ) / det(Y)`, the numerator multiplied out before the division: where
//! `A` is a row of `Y` (a body's angular velocity when its components are the speeds), the
//! numerator is `det(Y)` or 0 term by term (`Y adj(Y) = det(Y) I` holds as an identity of
//! polynomials in the entries), so the partial velocity is exactly 1 or 0. Where `det(Y)` is
//! a product (`cos θ` for Euler angles), the division is exact wherever the quotient has no
//! such factor: a point of a body turning with the speeds moves at `ω × r` without `1/cos θ`.
//!
//! Kane's equations are then, with `a` and `α` the time derivatives of `v` and `ω` along the
//! kinematic equations (linear in `u̇`),
//!
//! ```text
//! Σ_bodies m Vᵣ·(a − g) + Ωᵣ·(I α + ω × I ω) = Σ_loads Fᵣ,   r = 1 … n
//! ```
//!
//! and Lagrange's equations `M_q q̈ = F_q` (derived before the switch) carry into
//! `Wᵀ M_q W u̇ = Wᵀ (F_q − M_q Ẇ (u − Z) − M_q W Ż)`, which the checks compare.
//!
//! Beside `m` constraint rows the file gives `n − m` speeds, and each row's velocity form,
//! `A q̇ + b` (`J q̇ + Φ_t` for a holonomic `Φ(q, t) = 0`, which keeps its `Φ` for the drift),
//! is an auxiliary speed of its name (§§2.13, 4.4), the last rows of `Y`, held at 0 by the
//! constraint `u = 0` (`J = [0 I]`, `γ = 0`). The constraint forces
//! `Aᵀλ` on the coordinates are `[0; λ]` on the speeds (`A W = [0 I]`): Kane's rows of the
//! independent speeds at the auxiliary speeds 0 are the non-holonomic equations, and the
//! auxiliary rows give the multipliers, as in the rates.

use rustc_hash::FxHashMap;

use super::frames::{Vector3, cross, tensor_times};
use super::lower::{LoadInfo, Speeds};
use super::momentum::{LoadForces, dot, linear_in_accelerations, load_forces};
use super::{EquationsOfMotion, Formulation, Lagrange, MomentumBalance, SymbolicModel};
use crate::expr::{ExprArena, ExprId, Node, SymbolId};
use crate::model::diagnostic::Diagnostic;
use crate::model::file::ModelFile;

impl SymbolicModel {
    /// Lowers a checked model file (`mechanics/lower.rs`); with `speeds:`, then switches its
    /// state to the speeds (`mechanics/speeds.rs`).
    ///
    /// # Errors
    /// A diagnostic for anything the checks should have rejected (unknown name, wrong
    /// dimension; with a model that passed [`crate::model::load`] this does not happen), and
    /// the speeds' mistakes that only the lowered expressions show (a speed not linear in the
    /// rates, speeds that do not determine them).
    pub fn from_file(file: &ModelFile) -> Result<Self, Vec<Diagnostic>> {
        let (model, definitions, initial) = super::lower::lower_file(file)?;
        if file.speeds.is_empty() {
            return Ok(model);
        }
        switch(model, &definitions, initial, file)
    }
}

/// Kane's equations in generalized speeds: each body's momentum balance projected on the
/// partial velocities and partial angular velocities in the speeds (see the module docs).
#[derive(Debug, Clone, Copy, Default)]
pub struct Kane;

impl Kane {
    /// Whether the model is in generalized speeds, with bodies and no written `kinetic:`
    /// (as for [`super::MomentumBalance::applies_to`], which such a model does not take).
    pub fn applies_to(model: &SymbolicModel) -> bool {
        model.speeds.is_some() && !model.kinetic_written && !model.bodies.is_empty()
    }
}

impl Formulation for Kane {
    fn name(&self) -> &'static str {
        "kane"
    }

    /// For a model without speeds, [`MomentumBalance`]'s equations.
    fn derive(&self, model: &mut SymbolicModel) -> EquationsOfMotion {
        kane(model)
    }
}

/// The most speeds a model may have: the minors of their coefficients are indexed by bit sets
/// of 64 rows and columns (and a dense matrix of that size would not be expanded anyway).
pub(crate) const MAX_SPEEDS: usize = 64;

/// Switches `model`'s state to the speeds of `file`, whose definitions (in `q`, `q̇`, `t`, as
/// lowered) are `definitions` and whose `initial:` values (where the file gives speeds rather
/// than rates) are `initial`.
///
/// # Errors
/// A definition that is not linear in the rates, or speeds that do not determine the rates
/// (`det(∂u/∂q̇) = 0` identically), each located in `file`.
pub(crate) fn switch(
    mut model: SymbolicModel,
    definitions: &[ExprId],
    initial: Option<Vec<ExprId>>,
    file: &ModelFile,
) -> Result<SymbolicModel, Vec<Diagnostic>> {
    let n = model.num_dofs();
    // Each constraint row's velocity form, `J q̇ + Φ_t` or `A q̇ + b`, is an auxiliary speed
    // held at 0 (Kane & Levinson §§2.13, 4.4): with the file's speeds it determines the
    // rates, and its constraint becomes `uᵣ = 0` (see [`auxiliary_constraints`]).
    let auxiliary: Vec<(String, ExprId)> = (model.constraints.names.iter().cloned())
        .zip(model.constraints.velocity.iter().copied())
        .collect();
    let definitions: Vec<ExprId> = (definitions.iter().copied())
        .chain(auxiliary.iter().map(|(_, g)| *g))
        .collect();
    let names: Vec<String> = (file.speeds.iter().map(|s| s.name.value.clone()))
        .chain(auxiliary.iter().map(|(name, _)| name.clone()))
        .collect();
    if n > MAX_SPEEDS {
        let first = &file.speeds[0];
        return Err(vec![
            Diagnostic::new(
                first.name.location,
                format!("the model has {n} speeds; at most {MAX_SPEEDS} are derived"),
            )
            .with_help("write a model of this size in the coordinates' rates (remove `speeds`)"),
        ]);
    }
    // Bounded as every derivation is (a file of deeply nested rotations); the switch below
    // multiplies out no more than the partial velocities.
    super::limit_derivation(&mut model);
    let lagrange_q = Lagrange.derive(&mut model);
    let old: Vec<[SymbolId; 3]> = (0..n).map(|i| model.coordinate_symbols(i)).collect();
    let arena = &mut model.arena;
    let zero = arena.int(0);
    let at_rest: FxHashMap<SymbolId, ExprId> = old.iter().map(|s| (s[1], zero)).collect();
    let mut y = Vec::with_capacity(n * n);
    let mut offsets = Vec::with_capacity(n);
    let mut errors = Vec::new();
    for (r, &d) in definitions.iter().enumerate() {
        // Linear in the rates: coefficients free of them, and `d − Y q̇ − Z` multiplied out
        // free of them too (`abs` and `sign` have derivatives free of their argument).
        let row: Vec<ExprId> = old.iter().map(|s| arena.diff(d, s[1])).collect();
        let z = arena.substitute(d, &at_rest);
        let mut rest = vec![d, arena.neg(z)];
        for (c, s) in row.iter().zip(&old) {
            let rate = arena.symbol_expr(s[1]);
            let term = arena.times(*c, rate);
            rest.push(arena.neg(term));
        }
        let rest = arena.sum(&rest);
        let rest = arena.expand(rest);
        let rates_in = |arena: &ExprArena, e: ExprId| old.iter().any(|t| arena.depends_on(e, t[1]));
        // Multiplying out may leave equal terms apart (`√(2 + x)·√(2 + x)` and `2 + x`): a
        // rest that still reads the rates must then vanish at random states too.
        let nonlinear = row.iter().any(|&c| rates_in(arena, c))
            || (rates_in(arena, rest) && !vanishes(arena, &model.parameters, rest, d));
        // (A constraint row's linearity was checked where it was lowered.)
        if let (true, Some(speed)) = (nonlinear, file.speeds.get(r)) {
            errors.push(
                Diagnostic::new(speed.value.location, format!("speed `{}` is not linear in the rates", speed.name.value))
                    .with_help("a generalized speed is a combination of the rates with coefficients in the coordinates and `t`, such as `omega_B_x` or `theta1_dot + theta2_dot`"),
            );
        }
        y.extend(row);
        offsets.push(z);
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    let (determinant, adjugate) = determinant_and_adjugate(arena, &y, n);
    if arena.is_zero(determinant) {
        let first = &file.speeds[0];
        return Err(vec![
            Diagnostic::new(first.name.location, "the speeds do not determine the rates: the determinant of their coefficients in the rates is identically 0")
                .with_help("choose speeds that are independent combinations of the rates, one per degree of freedom, and independent of the constraints"),
        ]);
    }
    let inverse: Vec<ExprId> = adjugate
        .iter()
        .map(|&a| over_determinant(arena, a, determinant))
        .collect();

    // The model checks keep each speed's name and its `_dot` apart from every other name.
    let taken = |name: &str| {
        arena.symbol_id(name).is_some() || arena.symbol_id(&format!("{name}_dot")).is_some()
    };
    // (A speed named as a constraint row is the model checks' error; refused here too.)
    // Each speed declares its name and its rate `<name>_dot`: neither may be another's.
    let repeated = |r: usize| {
        names[..r].iter().any(|other| {
            let (a, b) = (other.as_str(), names[r].as_str());
            a == b || a.strip_suffix("_dot") == Some(b) || b.strip_suffix("_dot") == Some(a)
        })
    };
    if let Some(r) = (0..names.len()).find(|&r| taken(&names[r]) || repeated(r)) {
        let name = &names[r];
        let (what, location, help) = match file.speeds.get(r) {
            Some(speed) => ("speed name", speed.name.location, "rename the speed"),
            None => (
                "constraint row",
                (file.constraint_names().iter())
                    .find(|k| k.value == *name)
                    .map(|k| k.location)
                    .unwrap_or_default(),
                "rename the constraint: with `speeds`, each constraint row is an auxiliary speed of its name",
            ),
        };
        return Err(vec![
            Diagnostic::new(
                location,
                format!("{what} `{name}` (or its rate `{name}_dot`) is taken by another name of the model"),
            )
            .with_help(help),
        ]);
    }
    let pairs = arena.switch_to_speeds(&names);
    let u: Vec<ExprId> = pairs.iter().map(|[u, _]| *u).collect();
    for (c, new) in model.coordinates.iter_mut().zip(&pairs) {
        c[1] = new[0];
        c[2] = new[1];
    }
    let relative: Vec<ExprId> = u
        .iter()
        .zip(&offsets)
        .map(|(&u, &z)| arena.minus(u, z))
        .collect();
    let rates: Vec<ExprId> = (0..n)
        .map(|j| {
            let terms: Vec<ExprId> = (0..n)
                .map(|r| arena.times(inverse[j * n + r], relative[r]))
                .collect();
            arena.sum(&terms)
        })
        .collect();
    arena.set_coordinate_rates(rates.clone());
    let accelerations: Vec<ExprId> = rates.iter().map(|&r| arena.time_derivative(r)).collect();
    let speeds = Speeds {
        names,
        auxiliary: auxiliary.len(),
        on_the_constraints: false,
        coefficients: y,
        kinematic_equations: rates,
        inverse,
        offsets,
        lagrange: (Vec::new(), Vec::new()),
        determinant,
        adjugate,
    };

    // Every expression of the model in the speeds: `q̇` and `q̈` replaced, the definitions
    // and the bodies' angular velocities by their forms in `u` (partial velocities divided
    // out exactly).
    let mut values: FxHashMap<SymbolId, ExprId> = FxHashMap::default();
    for (j, s) in old.iter().enumerate() {
        values.insert(s[1], speeds.kinematic_equations[j]);
        values.insert(s[2], accelerations[j]);
    }
    let mut memo: FxHashMap<ExprId, ExprId> = FxHashMap::default();
    for (r, &d) in definitions.iter().enumerate() {
        memo.insert(d, u[r]);
    }
    for body in &model.bodies {
        if let Some(spatial) = &body.spatial {
            for &c in &spatial.angular_velocity {
                if let std::collections::hash_map::Entry::Vacant(entry) = memo.entry(c) {
                    let partials: Vec<ExprId> = old.iter().map(|s| arena.diff(c, s[1])).collect();
                    let rest = arena.substitute(c, &at_rest);
                    entry.insert(speeds.velocity(arena, &partials, rest));
                }
            }
        }
    }
    let mut sub = |arena: &mut ExprArena, e: ExprId| arena.substitute_memo(e, &values, &mut memo);
    model.kinetic = sub(arena, model.kinetic);
    model.potential = sub(arena, model.potential);
    for q in model
        .generalized_forces
        .iter_mut()
        .chain(model.written_forces.iter_mut())
    {
        *q = sub(arena, *q);
    }
    for body in &mut model.bodies {
        if let Some(spatial) = &mut body.spatial {
            spatial.angular_velocity = spatial.angular_velocity.map(|c| sub(arena, c));
        }
    }
    for load in &mut model.loads {
        match load {
            LoadInfo::Force { vector, .. } => vector.iter_mut().for_each(|c| *c = sub(arena, *c)),
            LoadInfo::Torque { value, .. } => *value = sub(arena, *value),
            LoadInfo::SpatialTorque { vector, .. } => *vector = vector.map(|c| sub(arena, c)),
            LoadInfo::Spring { stiffness, .. } => *stiffness = sub(arena, *stiffness),
            LoadInfo::Damper { coefficient, .. } => *coefficient = sub(arena, *coefficient),
        }
    }
    for event in &mut model.events {
        event.function = sub(arena, event.function);
    }
    // `M` too: Lagrange's `M` holds the rates where `T` is not quadratic in them.
    let lagrange_mass: Vec<ExprId> = (lagrange_q.mass_matrix.iter())
        .map(|&m| sub(arena, m))
        .collect();
    let lagrange_forcing: Vec<ExprId> = (lagrange_q.forcing.iter())
        .map(|&f| sub(arena, f))
        .collect();

    model.initial_qdot = match initial {
        // The auxiliary speeds start at 0, on their constraints.
        Some(mut u0) => {
            u0.resize(n, zero);
            u0
        }
        None => {
            // The state at t = 0 (a speed, or a constraint row, may read `t`).
            let mut start: FxHashMap<SymbolId, ExprId> = FxHashMap::default();
            start.insert(model.time_id, zero);
            for (j, s) in old.iter().enumerate() {
                start.insert(s[0], model.initial_q[j]);
                start.insert(s[1], model.initial_qdot[j]);
            }
            definitions
                .iter()
                .map(|&d| arena.substitute(d, &start))
                .collect()
        }
    };
    let lagrange = speeds.carried(arena, &lagrange_mass, &lagrange_forcing, &accelerations);
    if !auxiliary.is_empty() {
        model.constraints = auxiliary_constraints(arena, &model.constraints, &u);
    }
    model.speeds = Some(Speeds {
        lagrange: (lagrange.mass_matrix, lagrange.forcing),
        ..speeds
    });
    super::finish_derivation(&mut model, file)?;
    Ok(model)
}

/// The equations `eom` of `model` on its constraints, to be read: every
/// auxiliary speed 0 in `F`, `M`, the kinetic energy, the generalized forces and the kinematic
/// equations (as it is along every motion), so that the rows of the independent speeds are
/// Kane's equations for them (Kane & Levinson §6.1) and the auxiliary rows give the
/// multipliers. `eom` as it is for a model without auxiliary speeds. For printing only: the
/// Jacobians in the auxiliary speeds are lost.
pub fn on_the_constraints(model: &mut SymbolicModel, eom: &EquationsOfMotion) -> EquationsOfMotion {
    let Some(speeds) = model.speeds.as_mut().filter(|s| s.auxiliary > 0) else {
        return eom.clone();
    };
    let arena = &mut model.arena;
    let zero = arena.int(0);
    let n = arena.coordinates().len();
    let at_zero: FxHashMap<SymbolId, ExprId> = (arena.coordinates()[n - speeds.auxiliary..])
        .iter()
        .map(|s| (s[1], zero))
        .collect();
    let mut memo = FxHashMap::default();
    let mut on = |arena: &mut ExprArena, e: &mut ExprId| {
        *e = arena.substitute_memo(*e, &at_zero, &mut memo);
    };
    let mut out = eom.clone();
    for e in (out.mass_matrix.iter_mut())
        .chain(out.forcing.iter_mut())
        .chain(speeds.kinematic_equations.iter_mut())
        .chain(model.generalized_forces.iter_mut())
        .chain([&mut model.kinetic])
    {
        on(arena, e);
    }
    speeds.on_the_constraints = true;
    out
}

/// The constraints in the speeds: row `i` of `m` is `u_{n−m+i} = 0`, its auxiliary speed,
/// so `J = [0 I]`, the velocity residual is that speed and `γ = 0`; a holonomic row keeps
/// its `Φ(q, t)` (for the drift and Baumgarte's position term). The multipliers are the
/// constraint forces as in the rates: `Q = Aᵀλ` on the coordinates is `W̄ᵀAᵀλ = [0; λ]` on
/// the speeds, since `A W̄ = [0 I]`.
fn auxiliary_constraints(
    arena: &mut ExprArena,
    constraints: &super::ConstraintEquations,
    u: &[ExprId],
) -> super::ConstraintEquations {
    let (n, m) = (u.len(), constraints.len());
    let (zero, one) = (arena.int(0), arena.int(1));
    let mut jacobian = vec![zero; m * n];
    for i in 0..m {
        jacobian[i * n + n - m + i] = one;
    }
    super::ConstraintEquations {
        names: constraints.names.clone(),
        holonomic: constraints.holonomic,
        phi: constraints.phi.clone(),
        jacobian,
        velocity: u[n - m..].to_vec(),
        gamma: vec![zero; m],
    }
}

impl Speeds {
    /// `v = Σⱼ Aⱼ q̇ⱼ + b` in the speeds, `partials` the `Aⱼ` and `rest` the `b` (functions of
    /// `q` and `t`): `Σᵣ Vᵣ uᵣ + b − Σᵣ Vᵣ Zᵣ`, each `Vᵣ` divided out exactly where it can be
    /// (see the module docs).
    fn velocity(&self, arena: &mut ExprArena, partials: &[ExprId], rest: ExprId) -> ExprId {
        let n = partials.len();
        let mut terms = vec![rest];
        for r in 0..n {
            let mut numerator = Vec::new();
            for (j, &a) in partials.iter().enumerate() {
                if !arena.is_zero(a) {
                    numerator.push(arena.times(a, self.adjugate[j * n + r]));
                }
            }
            if numerator.is_empty() {
                continue;
            }
            let sum = arena.sum(&numerator);
            let expanded = arena.expand(sum);
            let v = over_determinant(arena, expanded, self.determinant);
            if arena.is_zero(v) {
                continue;
            }
            let u = arena.symbol_expr(arena.coordinates()[r][1]);
            let relative = arena.minus(u, self.offsets[r]);
            terms.push(arena.times(v, relative));
        }
        arena.sum(&terms)
    }

    /// Lagrange's `M_q q̈ = F_q` (`forcing` already in the speeds) carried into them:
    /// `Wᵀ M_q W u̇ = Wᵀ (F_q − M_q q̈₀)`, `q̈₀` the accelerations at `u̇ = 0`.
    fn carried(
        &self,
        arena: &mut ExprArena,
        mass: &[ExprId],
        forcing: &[ExprId],
        accelerations: &[ExprId],
    ) -> EquationsOfMotion {
        let n = forcing.len();
        let zero = arena.int(0);
        let rest: FxHashMap<SymbolId, ExprId> =
            arena.coordinates().iter().map(|s| (s[2], zero)).collect();
        let at_rest: Vec<ExprId> = accelerations
            .iter()
            .map(|&a| arena.substitute(a, &rest))
            .collect();
        let residual: Vec<ExprId> = (0..n)
            .map(|i| {
                let inertial: Vec<ExprId> = (0..n)
                    .map(|j| arena.times(mass[i * n + j], at_rest[j]))
                    .collect();
                let inertial = arena.sum(&inertial);
                arena.minus(forcing[i], inertial)
            })
            .collect();
        let w = &self.inverse;
        let mut mass_matrix = vec![zero; n * n];
        let mut carried_forcing = vec![zero; n];
        for r in 0..n {
            let f: Vec<ExprId> = (0..n)
                .map(|i| arena.times(w[i * n + r], residual[i]))
                .collect();
            let f = arena.sum(&f);
            carried_forcing[r] = arena.expand_if_cheaper(f);
            for s in r..n {
                let mut terms = Vec::new();
                for i in 0..n {
                    for j in 0..n {
                        if !arena.is_zero(mass[i * n + j]) {
                            terms.push(arena.product(&[
                                w[i * n + r],
                                mass[i * n + j],
                                w[j * n + s],
                            ]));
                        }
                    }
                }
                let m = arena.sum(&terms);
                let m = arena.expand_if_cheaper(m);
                mass_matrix[r * n + s] = m;
                mass_matrix[s * n + r] = m;
            }
        }
        EquationsOfMotion {
            num_dofs: n,
            mass_matrix,
            forcing: carried_forcing,
        }
    }
}

/// Whether `rest` is 0 to rounding (1e-12 relative to `1 + |scale|`) at 20 random states
/// (coordinates, rates and `t` in [−2, 2], parameters at their defaults) where it is finite,
/// and at least one is.
fn vanishes(
    arena: &ExprArena,
    parameters: &[super::ParameterInfo],
    rest: ExprId,
    scale: ExprId,
) -> bool {
    use crate::expr::SymbolKind;
    use rand::{RngExt, SeedableRng};
    let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(75);
    let mut evaluator = crate::expr::eval::Evaluator::new(arena, &[rest, scale]);
    let mut finite = 0;
    for _ in 0..20 {
        let mut bindings: Vec<f64> = (arena.symbols().iter())
            .map(|s| match s.kind {
                SymbolKind::Coordinate(_)
                | SymbolKind::Velocity(_)
                | SymbolKind::Retired
                | SymbolKind::Time => rng.random_range(-2.0..2.0),
                _ => 0.0,
            })
            .collect();
        for p in parameters {
            bindings[p.symbol.index()] = p.default;
        }
        let v = evaluator.eval(&bindings);
        if v[0].is_finite() && v[1].is_finite() {
            finite += 1;
            if v[0].abs() > 1e-12 * (1.0 + v[1].abs()) {
                return false;
            }
        }
    }
    finite > 0
}

/// `numerator / determinant`, multiplied out where the determinant is a product of factors
/// (so that the factors it shares with every term of the numerator cancel exactly).
fn over_determinant(arena: &mut ExprArena, numerator: ExprId, determinant: ExprId) -> ExprId {
    if arena.is_zero(numerator) {
        return numerator;
    }
    if matches!(arena.node(determinant), Node::Add(_)) {
        return arena.divide(numerator, determinant);
    }
    let q = arena.divide(numerator, determinant);
    arena.expand(q)
}

/// `det(Y)` and `adj(Y)` (row-major, `adj(Y)ⱼᵣ` the cofactor of `Yᵣⱼ`) of the `n × n`
/// row-major `y`, each multiplied out, by cofactor expansion along the first row of each
/// minor with every minor computed once (by its rows and columns), skipping zero entries: the
/// speeds' coefficient matrices are small or sparse (at most [`MAX_SPEEDS`], one bit each).
fn determinant_and_adjugate(
    arena: &mut ExprArena,
    y: &[ExprId],
    n: usize,
) -> (ExprId, Vec<ExprId>) {
    debug_assert!(n <= MAX_SPEEDS, "checked by `switch`");
    let all: u64 = if n == 64 { u64::MAX } else { (1u64 << n) - 1 };
    let mut memo: FxHashMap<(u64, u64), ExprId> = FxHashMap::default();
    let det = minor(arena, y, n, (all, all), &mut memo);
    let determinant = arena.expand(det);
    let mut adjugate = vec![arena.int(0); n * n];
    for r in 0..n {
        for j in 0..n {
            let m = minor(arena, y, n, (all & !(1 << r), all & !(1 << j)), &mut memo);
            let m = if (r + j) % 2 == 1 { arena.neg(m) } else { m };
            adjugate[j * n + r] = arena.expand(m);
        }
    }
    (determinant, adjugate)
}

/// The determinant of the rows and columns of `y` in the bit sets `(rows, columns)` (as
/// many of each), expanded along its first row.
fn minor(
    arena: &mut ExprArena,
    y: &[ExprId],
    n: usize,
    (rows, columns): (u64, u64),
    memo: &mut FxHashMap<(u64, u64), ExprId>,
) -> ExprId {
    if rows == 0 {
        return arena.int(1);
    }
    if let Some(&m) = memo.get(&(rows, columns)) {
        return m;
    }
    let r = rows.trailing_zeros() as usize;
    let mut terms = Vec::new();
    let mut sign_negative = false;
    for c in (0..n).filter(|&c| columns & (1 << c) != 0) {
        let entry = y[r * n + c];
        if !arena.is_zero(entry) {
            let sub = minor(arena, y, n, (rows & !(1 << r), columns & !(1 << c)), memo);
            if !arena.is_zero(sub) {
                let t = arena.times(entry, sub);
                terms.push(if sign_negative { arena.neg(t) } else { t });
            }
        }
        sign_negative = !sign_negative;
    }
    let m = arena.sum(&terms);
    memo.insert((rows, columns), m);
    m
}

/// Kane's equations in the speeds of `model` (see the module docs), `M u̇ = F`.
///
/// Without speeds, [`MomentumBalance`]'s equations (the same projection on the rates'
/// partial velocities).
fn kane(model: &mut SymbolicModel) -> EquationsOfMotion {
    // In the rates, Kane's equations are the momentum balance on their partial velocities.
    let Some(speeds) = model.speeds.clone() else {
        return MomentumBalance.derive(model);
    };
    let n = model.num_dofs();
    let symbols: Vec<[SymbolId; 3]> = (0..n).map(|i| model.coordinate_symbols(i)).collect();
    let time = model.time_symbol();
    let points: Vec<Vec<ExprId>> = model.points.iter().map(|(_, r)| r.clone()).collect();
    let bodies = model.bodies.clone();
    let gravity = model.gravity.clone();
    let arena = &mut model.arena;
    let mut residual: Vec<Vec<ExprId>> = vec![Vec::new(); n];
    let mut velocities: FxHashMap<usize, Vec<ExprId>> = FxHashMap::default();
    let mut velocity_of = |arena: &mut ExprArena, p: usize| -> Vec<ExprId> {
        velocities
            .entry(p)
            .or_insert_with(|| {
                points[p]
                    .iter()
                    .map(|&c| speeds.velocity_of_position(arena, c, &symbols, time))
                    .collect()
            })
            .clone()
    };
    let partials = |arena: &mut ExprArena, v: &[ExprId], r: usize| -> Vec<ExprId> {
        v.iter().map(|&c| arena.diff(c, symbols[r][1])).collect()
    };
    for body in &bodies {
        // m Vᵣ·(a − g)
        let v = velocity_of(arena, body.com);
        let mut a: Vec<ExprId> = v.iter().map(|&c| arena.time_derivative(c)).collect();
        if let Some(g) = &gravity {
            a = a.iter().zip(g).map(|(&a, &g)| arena.minus(a, g)).collect();
        }
        for (r, terms) in residual.iter_mut().enumerate() {
            let vr = partials(arena, &v, r);
            let d = dot(arena, &vr, &a);
            if !arena.is_zero(d) {
                terms.push(arena.times(body.mass, d));
            }
        }
        // Ωᵣ I α, planar
        if let Some((inertia, angle)) = body.rotation {
            let omega = speeds.velocity_of_position(arena, angle, &symbols, time);
            let alpha = arena.time_derivative(omega);
            for (r, terms) in residual.iter_mut().enumerate() {
                let w = arena.diff(omega, symbols[r][1]);
                if !arena.is_zero(w) {
                    terms.push(arena.product(&[inertia, alpha, w]));
                }
            }
        }
        // Ωᵣ·(I α + ω × I ω), in the body's axes
        if let Some(spatial) = &body.spatial {
            let w = spatial.angular_velocity;
            let alpha: Vector3 = w.map(|c| arena.time_derivative(c));
            let i_alpha = tensor_times(arena, &spatial.inertia, &alpha);
            let i_w = tensor_times(arena, &spatial.inertia, &w);
            let gyroscopic = cross(arena, &w, &i_w);
            let euler: Vec<ExprId> = (0..3)
                .map(|k| arena.plus(i_alpha[k], gyroscopic[k]))
                .collect();
            for (r, terms) in residual.iter_mut().enumerate() {
                let wr = partials(arena, &w, r);
                let d = dot(arena, &wr, &euler);
                if !arena.is_zero(d) {
                    terms.push(d);
                }
            }
        }
    }
    // − Σ loads: forces at points on their partial velocities, torques on the partial
    // angular velocities, and the written potential's and forces' `Qⱼ` carried by `W`.
    for load in &model.loads {
        let LoadForces { forces, torque } = match load {
            LoadInfo::SpatialTorque { body, vector } => {
                if let Some(spatial) = &bodies[*body].spatial {
                    for (r, terms) in residual.iter_mut().enumerate() {
                        let wr = partials(arena, &spatial.angular_velocity, r);
                        let power = dot(arena, vector, &wr);
                        if !arena.is_zero(power) {
                            terms.push(arena.neg(power));
                        }
                    }
                }
                LoadForces::default()
            }
            _ => load_forces(arena, &points, load),
        };
        for (point, f) in &forces {
            let v = velocity_of(arena, *point);
            for (r, terms) in residual.iter_mut().enumerate() {
                let vr = partials(arena, &v, r);
                let power = dot(arena, f, &vr);
                if !arena.is_zero(power) {
                    terms.push(arena.neg(power));
                }
            }
        }
        if let Some((angle, value)) = torque {
            let omega = speeds.velocity_of_position(arena, angle, &symbols, time);
            for (r, terms) in residual.iter_mut().enumerate() {
                let w = arena.diff(omega, symbols[r][1]);
                if !arena.is_zero(w) {
                    let t = arena.times(value, w);
                    terms.push(arena.neg(t));
                }
            }
        }
    }
    for (j, s) in symbols.iter().enumerate() {
        let dv = arena.diff(model.written_potential, s[0]);
        let q = arena.minus(model.written_forces[j], dv);
        if arena.is_zero(q) {
            continue;
        }
        for (r, terms) in residual.iter_mut().enumerate() {
            let w = speeds.inverse[j * n + r];
            if !arena.is_zero(w) {
                let t = arena.times(w, q);
                terms.push(arena.neg(t));
            }
        }
    }
    linear_in_accelerations(arena, &residual, &symbols)
}

impl Speeds {
    /// The time derivative of `e(q, t)` in the speeds, by [`Self::velocity`].
    fn velocity_of_position(
        &self,
        arena: &mut ExprArena,
        e: ExprId,
        symbols: &[[SymbolId; 3]],
        time: SymbolId,
    ) -> ExprId {
        let partials: Vec<ExprId> = symbols.iter().map(|s| arena.diff(e, s[0])).collect();
        let rest = arena.diff(e, time);
        self.velocity(arena, &partials, rest)
    }
}
