//! The energy routes to a one-degree-of-freedom model's equation of motion (lecture 10, HW11:
//! "derive the pendulum's equation as many ways as you can"): the energy equation `Ė = P_nc`
//! and the power balance `P = Ė_K`, each differentiated along the motion and read as an
//! equation in `q̈`.
//!
//! For one coordinate `q` with `T = ½ m(q) q̇²`, the rate of the total energy along the motion
//! is `Ė = q̇ (m q̈ + ½ m′ q̇² + V′)`, and it equals the power of the non-potential forces,
//! `Q q̇`. So `q̇ (m q̈ + ½ m′ q̇² + V′ − Q) = 0`: wherever `q̇ ≠ 0` this is Lagrange's equation.
//! [`EnergyRate`] derives it as `M′ q̈ = F′` with `M′ = ∂R/∂q̈ = m q̇` and `F′ = −R(q̈ = 0)`,
//! `R = Ė − Q q̇` — the factor `q̇` kept, since cancelling it is the reader's step, and the
//! comparison with Lagrange (at random states, where `q̇ ≠ 0`) solves for `q̈` anyway.
//!
//! [`PowerRoute`] is the work–energy theorem for the system of particles and bodies,
//! `Σ F·v + Σ τ θ̇ = dT/dt`, with every applied force's power computed from the point
//! kinematics — gravity on each body `m g·v_G`, forces at points, springs and dampers as
//! equal and opposite pairs along their lines, torques times the body's rate — rather than
//! from a potential: an independent route for a kinematic-form model. The reaction forces of
//! fixed, workless joints (a hinge at a fixed point, a rod of fixed length) do no work and do
//! not appear. A written `potential:` contributes `−dV/dt` and written generalized forces
//! `Q q̇`.
//!
//! Both routes give one scalar equation, so they determine the motion of a model with one
//! coordinate and no constraints only; and both need the energy to be exchanged only with the
//! loads: no explicit `t` in `T` or `V` (a driven support does work through its reaction), and
//! `T` a quadratic form in `q̇` (a driven motion can leave `T = ½ m (ṙ² + r² ω²)` with no `t`).
//! The power route also needs every load to act at points (and torques on angles) that do not
//! move with `t`: the power at a driven point is the driver's.
//!
//! # References
//! - A. Ruina and R. Pratap, *Introduction to Statics and Dynamics*, §§ 7.1 and 10.3 (the
//!   pendulum by energy and by power).
//! - H. Goldstein, *Classical Mechanics*, 3rd ed., § 1.2 (the work–energy theorem).

use super::momentum::{LoadForces, dot, linear_in_accelerations, load_forces};
use super::{EquationsOfMotion, Formulation, LoadInfo, SymbolicModel};
use crate::expr::{ExprArena, ExprId};

/// The energy equation `Ė = Σ Qᵢ q̇ᵢ` (`E = T + V`, `Q` the non-potential generalized
/// forces), read as an equation in `q̈` for a model with one coordinate: `M′ = m q̇`,
/// `F′ = −q̇ (½ m′ q̇² + V′ − Q)`.
#[derive(Debug, Clone, Copy, Default)]
pub struct EnergyRate;

/// The power balance `P = dT/dt` (the work–energy theorem), `P` the power of every applied
/// force and torque computed from the velocities of the points and bodies they act on, read
/// as an equation in `q̈` for a model with one coordinate.
#[derive(Debug, Clone, Copy, Default)]
pub struct PowerRoute;

/// Why the energy routes do not apply to `model`, or `None` when they do: one coordinate, no
/// constraints, neither `T` nor `V` depending on `t` explicitly, and `T` a quadratic form in
/// `q̇`.
pub fn energy_routes_skipped(model: &SymbolicModel) -> Option<&'static str> {
    let t = model.time_symbol();
    if model.num_dofs() != 1 {
        Some(
            "energy and power routes skipped: `Ė = P` and `P = dT/dt` are one equation each, which determines the motion of a model with one coordinate only",
        )
    } else if !model.constraints.is_empty() {
        Some(
            "energy and power routes skipped: with constraints, one energy equation does not determine the coordinates and the multipliers",
        )
    } else if model.speeds_hide_the_energy_form() {
        Some(
            "energy and power routes skipped: a generalized speed (or a constraint's auxiliary speed, A q̇ + b) has an offset Z(q, t) or a coefficient that depends on t (u = Y q̇ + Z), so T in the speeds shows neither its degree in q̇ nor its dependence on t",
        )
    } else if model.arena.depends_on(model.kinetic, t) || model.arena.depends_on(model.potential, t)
    {
        Some(
            "energy and power routes skipped: T or V depends explicitly on t (a driven support works through its reaction force)",
        )
    } else if !kinetic_is_quadratic_in_rate(model) {
        Some(
            "energy and power routes skipped: T is not a quadratic form in q̇ (a driven motion, such as a rod spun at a constant rate, gives T terms of degree 0 or 1 in q̇): then Ė is not q̇ times the equation of motion",
        )
    } else {
        None
    }
}

/// Whether `T = a q̇² + b q̇ + c` of a one-coordinate model has `b = c = 0` (homogeneous of
/// degree 2 in the rate, which `Ė = q̇ (m q̈ + ½ m′ q̇² + V′)` assumes), measured at a few
/// configurations and times with the parameters at their defaults: `c = T(q̇ = 0)` and
/// `2b = T(q̇ = 1) − T(q̇ = −1)`, each to 1e-12 relative to `|a| + 1`. A driven motion that
/// leaves no explicit `t` in `T` (a bead on a rod spun at a constant rate, `T = ½ m (ṙ² +
/// r² ω²)`) has `c ≠ 0`.
fn kinetic_is_quadratic_in_rate(model: &SymbolicModel) -> bool {
    let mut bindings = vec![0.0; model.arena.symbols().len()];
    for p in &model.parameters {
        bindings[p.symbol.index()] = p.default;
    }
    let [q, rate, _] = model.coordinate_symbols(0);
    let mut evaluator = crate::expr::eval::Evaluator::new(&model.arena, &[model.kinetic]);
    [(0.3, 0.0), (-1.1, 0.7), (2.0, 1.9)]
        .iter()
        .all(|&(qv, tv)| {
            bindings[q.index()] = qv;
            bindings[model.time_symbol().index()] = tv;
            let mut at = |v: f64| {
                bindings[rate.index()] = v;
                evaluator.eval(&bindings)[0]
            };
            let (c, plus, minus) = (at(0.0), at(1.0), at(-1.0));
            let a = (plus + minus) / 2.0 - c;
            let b = (plus - minus) / 2.0;
            let scale = 1e-12 * (a.abs() + 1.0);
            c.abs() <= scale && b.abs() <= scale
        })
}

impl EnergyRate {
    /// Whether the route applies ([`energy_routes_skipped`] is `None`).
    pub fn applies_to(model: &SymbolicModel) -> bool {
        energy_routes_skipped(model).is_none()
    }
}

impl PowerRoute {
    /// Whether the route applies: as [`EnergyRate`], and the model is in the kinematic form
    /// (bodies, no written `kinetic:`), where the power of the forces is not the rate of a
    /// written potential — for an energy-form model it would repeat [`EnergyRate`].
    pub fn applies_to(model: &SymbolicModel) -> bool {
        EnergyRate::applies_to(model)
            && !model.kinetic_written
            && !model.bodies.is_empty()
            && !loads_at_driven_points(model)
    }
}

/// Whether a spring, damper or force acts at a point whose position depends explicitly on
/// `t` (a driven support), or a torque on a body whose angle does: the power of the load there is supplied by the driver, not drawn
/// from the kinetic energy, so `P = dT/dt` with every load's `F·v` does not hold.
fn loads_at_driven_points(model: &SymbolicModel) -> bool {
    let t = model.time_symbol();
    let driven = |p: usize| {
        model.points[p]
            .1
            .iter()
            .any(|c| model.arena.depends_on(*c, t))
    };
    model.loads.iter().any(|load| match load {
        LoadInfo::Force { point, .. } => driven(*point),
        LoadInfo::Spring { between, .. } | LoadInfo::Damper { between, .. } => {
            between.iter().any(|p| driven(*p))
        }
        LoadInfo::Torque { angle, .. } => model.arena.depends_on(*angle, t),
        LoadInfo::SpatialTorque { .. } => false,
    })
}

impl Formulation for EnergyRate {
    fn name(&self) -> &'static str {
        "energy"
    }

    fn derive(&self, model: &mut SymbolicModel) -> EquationsOfMotion {
        let symbols = [model.coordinate_symbols(0)];
        let rate = model.arena.coordinate_rate(0);
        let arena = &mut model.arena;
        let energy = arena.plus(model.kinetic, model.potential);
        let de_dt = arena.time_derivative(energy);
        let power = arena.times(model.generalized_forces[0], rate);
        let residual = vec![de_dt, arena.neg(power)];
        linear_in_accelerations(arena, &[residual], &symbols)
    }
}

impl Formulation for PowerRoute {
    fn name(&self) -> &'static str {
        "power"
    }

    fn derive(&self, model: &mut SymbolicModel) -> EquationsOfMotion {
        let symbols = [model.coordinate_symbols(0)];
        let rate = model.arena.coordinate_rate(0);
        let points: Vec<Vec<ExprId>> = model.points.iter().map(|(_, r)| r.clone()).collect();
        let bodies = model.bodies.clone();
        let loads = model.loads.clone();
        let gravity = model.gravity.clone();
        let arena = &mut model.arena;
        let velocity = |arena: &mut ExprArena, p: usize| -> Vec<ExprId> {
            points[p]
                .iter()
                .map(|c| arena.time_derivative(*c))
                .collect()
        };
        // The power of each applied force and torque.
        let mut powers: Vec<ExprId> = Vec::new();
        if let Some(g) = &gravity {
            for body in &bodies {
                let v = velocity(arena, body.com);
                let w = dot(arena, g, &v);
                let p = arena.times(body.mass, w);
                powers.push(p);
            }
        }
        for load in &loads {
            if let LoadInfo::SpatialTorque { body, vector } = load {
                // τ·ω, both in the body frame's components.
                if let Some(s) = &bodies[*body].spatial {
                    let p = dot(arena, vector, &s.angular_velocity);
                    powers.push(p);
                }
                continue;
            }
            let LoadForces { forces, torque } = load_forces(arena, &points, load);
            for (point, f) in &forces {
                let v = velocity(arena, *point);
                let p = dot(arena, f, &v);
                powers.push(p);
            }
            if let Some((angle, value)) = torque {
                let w = arena.time_derivative(angle);
                let p = arena.times(value, w);
                powers.push(p);
            }
        }
        // What the file writes as energy: Q q̇ and (below) −dV/dt.
        powers.push(arena.times(model.written_forces[0], rate));
        // R = dT/dt + dV/dt − P.
        let de_k = arena.time_derivative(model.kinetic);
        let dv = arena.time_derivative(model.written_potential);
        let p = arena.sum(&powers);
        let residual = vec![de_k, dv, arena.neg(p)];
        linear_in_accelerations(arena, &[residual], &symbols)
    }
}
