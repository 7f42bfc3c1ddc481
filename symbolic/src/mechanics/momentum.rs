//! Momentum balance, derived from the kinematics alone (syllabus lectures 6–7, 11–12, 19;
//! HW19 a, HW20): never from `T` or `V`.
//!
//! For each body, linear momentum balance `m a_G = ΣF` and angular momentum balance about the
//! centre of mass `I_G θ̈ = ΣM_G` are projected on the partial velocities `∂r/∂qᵢ` and partial
//! angular velocities `∂θ/∂qᵢ` (d'Alembert's principle in Kane's form), which eliminates every
//! workless constraint force. Accelerations come from differentiating the point and angle
//! expressions twice; gravity is a force `m g` at each centre of mass, springs are equal and
//! opposite forces along the line of their points. The result `M′ q̈ = F′` must give the same
//! `q̈` as Lagrange's equations.
//!
//! # References
//! T. R. Kane, D. A. Levinson, *Dynamics: Theory and Applications*, McGraw-Hill, 1985, ch. 6.

use rustc_hash::FxHashMap;

use super::lower::LoadInfo;
use super::{EquationsOfMotion, Formulation, SymbolicModel};
use crate::expr::ExprId;

/// Momentum balance of each body projected on the partial velocities (Kane / d'Alembert).
#[derive(Debug, Clone, Copy, Default)]
pub struct MomentumBalance;

impl MomentumBalance {
    /// Whether the model can be derived from its kinematics alone: it has bodies and no
    /// energy-form pieces (`kinetic`, `potential`, `generalized_forces`).
    pub fn applies_to(model: &SymbolicModel) -> bool {
        !model.uses_energy_form && !model.bodies.is_empty()
    }
}

impl Formulation for MomentumBalance {
    fn name(&self) -> &'static str {
        "momentum"
    }

    /// # Panics
    /// Never; for a model where [`MomentumBalance::applies_to`] is false the energy-form
    /// pieces are ignored, so callers check it first.
    fn derive(&self, model: &mut SymbolicModel) -> EquationsOfMotion {
        let n = model.num_dofs();
        let symbols: Vec<_> = (0..n).map(|i| model.coordinate_symbols(i)).collect();
        let points: Vec<Vec<ExprId>> = model.points.iter().map(|(_, r)| r.clone()).collect();
        let bodies = model.bodies.clone();
        let loads = model.loads.clone();
        let gravity = model.gravity.clone();
        let arena = &mut model.arena;

        let dot = |arena: &mut crate::expr::ExprArena, a: &[ExprId], b: &[ExprId]| {
            let t: Vec<ExprId> = a.iter().zip(b).map(|(x, y)| arena.times(*x, *y)).collect();
            arena.sum(&t)
        };
        let partial = |arena: &mut crate::expr::ExprArena, r: &[ExprId], i: usize| -> Vec<ExprId> {
            r.iter().map(|c| arena.diff(*c, symbols[i][0])).collect()
        };

        // Residual Rᵢ = Σ (m a_G·∂r_G/∂qᵢ + I θ̈ ∂θ/∂qᵢ) − Σ F·∂r_P/∂qᵢ − Σ τ ∂θ/∂qᵢ.
        let mut residual: Vec<Vec<ExprId>> = vec![Vec::new(); n];
        for body in &bodies {
            let r = &points[body.com];
            let v: Vec<ExprId> = r.iter().map(|c| arena.time_derivative(*c)).collect();
            let a: Vec<ExprId> = v.iter().map(|c| arena.time_derivative(*c)).collect();
            let mut applied: Vec<ExprId> = Vec::new();
            if let Some(g) = &gravity {
                applied = g.iter().map(|gk| arena.times(body.mass, *gk)).collect();
            }
            let alpha = body.rotation.map(|(inertia, angle)| {
                let w = arena.time_derivative(angle);
                let acc = arena.time_derivative(w);
                (inertia, angle, acc)
            });
            for i in 0..n {
                let dr = partial(arena, r, i);
                let ma = dot(arena, &a, &dr);
                residual[i].push(arena.times(body.mass, ma));
                if !applied.is_empty() {
                    let fg = dot(arena, &applied, &dr);
                    residual[i].push(arena.neg(fg));
                }
                if let Some((inertia, angle, acc)) = alpha {
                    let dth = arena.diff(angle, symbols[i][0]);
                    residual[i].push(arena.product(&[inertia, acc, dth]));
                }
            }
        }
        for load in &loads {
            // Each load as forces at points (and torques), projected on partial velocities.
            let mut forces: Vec<(usize, Vec<ExprId>)> = Vec::new();
            let mut torque: Option<(ExprId, ExprId)> = None;
            match load {
                LoadInfo::Force { point, vector } => forces.push((*point, vector.clone())),
                LoadInfo::Torque { angle, value, .. } => torque = Some((*angle, *value)),
                LoadInfo::Spring {
                    between: [pa, pb],
                    stiffness,
                    rest_length,
                } => {
                    // F_A = −k (|d| − ℓ₀) d/|d| with d = r_A − r_B; F_B = −F_A.
                    let d = separation(arena, &points, *pa, *pb);
                    let scale = match rest_length {
                        None => arena.neg(*stiffness),
                        Some(l0) => {
                            let d2 = dot(arena, &d, &d);
                            let len = arena.sqrt(d2);
                            let ratio = arena.divide(*l0, len);
                            let one = arena.int(1);
                            let s = arena.minus(ratio, one);
                            arena.times(*stiffness, s)
                        }
                    };
                    forces.extend(equal_and_opposite(arena, *pa, *pb, &d, scale));
                }
                LoadInfo::Damper {
                    between: [pa, pb],
                    coefficient,
                } => {
                    // F_A = −c (ḋ·d) d/(d·d); F_B = −F_A.
                    let d = separation(arena, &points, *pa, *pb);
                    let dd: Vec<ExprId> = d.iter().map(|c| arena.time_derivative(*c)).collect();
                    let rate = dot(arena, &d, &dd);
                    let d2 = dot(arena, &d, &d);
                    let cr = arena.times(*coefficient, rate);
                    let q = arena.divide(cr, d2);
                    let scale = arena.neg(q);
                    forces.extend(equal_and_opposite(arena, *pa, *pb, &d, scale));
                }
            }
            for i in 0..n {
                for (point, f) in &forces {
                    let dr = partial(arena, &points[*point], i);
                    let p = dot(arena, f, &dr);
                    residual[i].push(arena.neg(p));
                }
                if let Some((angle, value)) = torque {
                    let dth = arena.diff(angle, symbols[i][0]);
                    let p = arena.times(value, dth);
                    residual[i].push(arena.neg(p));
                }
            }
        }

        linear_in_accelerations(arena, &residual, &symbols)
    }
}

/// `d = r_A − r_B` for points `a` and `b`.
fn separation(
    arena: &mut crate::expr::ExprArena,
    points: &[Vec<ExprId>],
    a: usize,
    b: usize,
) -> Vec<ExprId> {
    points[a]
        .iter()
        .zip(&points[b])
        .map(|(x, y)| arena.minus(*x, *y))
        .collect()
}

/// The pair of forces `s·d` on `a` and `−s·d` on `b` (a spring or damper along the line).
fn equal_and_opposite(
    arena: &mut crate::expr::ExprArena,
    a: usize,
    b: usize,
    d: &[ExprId],
    scale: ExprId,
) -> [(usize, Vec<ExprId>); 2] {
    let fa: Vec<ExprId> = d.iter().map(|c| arena.times(scale, *c)).collect();
    let fb: Vec<ExprId> = fa.iter().map(|c| arena.neg(*c)).collect();
    [(a, fa), (b, fb)]
}

/// Equations `Rₖ(q, q̇, q̈, t) = 0`, each linear in `q̈`, as `M′ q̈ = F′`:
/// `M′ₖⱼ = ∂Rₖ/∂q̈ⱼ`, `F′ₖ = −Rₖ(q̈ = 0)`, multiplied out if that is cheaper after CSE.
pub(crate) fn linear_in_accelerations(
    arena: &mut crate::expr::ExprArena,
    residual: &[Vec<ExprId>],
    symbols: &[[crate::expr::SymbolId; 3]],
) -> EquationsOfMotion {
    let zero = arena.int(0);
    let at_rest: FxHashMap<_, _> = symbols.iter().map(|s| (s[2], zero)).collect();
    let mut mass_matrix = Vec::with_capacity(residual.len() * symbols.len());
    let mut forcing = Vec::with_capacity(residual.len());
    for terms in residual {
        let r = arena.sum(terms);
        for s in symbols {
            mass_matrix.push(arena.diff(r, s[2]));
        }
        let r0 = arena.substitute(r, &at_rest);
        forcing.push(arena.neg(r0));
    }
    let (mass_matrix, forcing) = super::cheaper_of_raw_and_expanded(arena, mass_matrix, forcing);
    EquationsOfMotion {
        num_dofs: symbols.len(),
        mass_matrix,
        forcing,
    }
}
