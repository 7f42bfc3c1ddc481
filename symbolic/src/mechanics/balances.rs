//! The user's own momentum balances (`balances:`), written as the course writes them (HW19:
//! AMB/O of the whole arm and AMB/E of the forearm; HW20: AMB/centre and LMB·î′).
//!
//! For a set S of bodies and a point A, fixed or moving, angular momentum balance in the plane
//! with absolute accelerations is
//!
//! ```text
//! Σ_{b∈S} [ (r_G − r_A) × m a_G + I θ̈ ] = Σ_{b∈S} (r_G − r_A) × m g + Σ τ_b  (+ reactions)
//! ```
//!
//! which holds for any A because it uses `r_{G/A} × m a_G` (HW4, HW15 a). Linear momentum
//! balance along `e` is `Σ m a_G·e = Σ m g·e (+ reactions)`. The user chooses balances whose
//! reaction terms vanish; if they do not, the result differs from Lagrange's, which
//! `eomgen check` reports. `M′` is in general not symmetric.
//!
//! An `amb` entry with `form: h_dot` is written `Σ M_A = dH_A/dt` with
//! `H_A = Σ (r_G − r_A) × m v_G + I θ̇` instead. Since
//! `dH_A/dt = Σ (r_G − r_A) × m a_G + I θ̈ − v_A × m v_G`, that form is right only when
//! `v_A × v_G = 0` — a fixed point or the centre of mass — and `eomgen check` catches it about
//! any other moving point (the mistake HW4 and HW15 warn of).
//!
//! [`HandEquations`] are the file's own equations of motion (`checks: equations_of_motion`),
//! written by hand: compared with Lagrange like any other derivation.

use super::lower::{BalanceInfo, LoadInfo};
use super::momentum::linear_in_accelerations;
use super::{EquationsOfMotion, Formulation, SymbolicModel};
use crate::expr::{ExprArena, ExprId};
use crate::model::file::AmbForm;

/// One set of the model's `balances:` as equations of motion: the set at index `set` of
/// [`SymbolicModel::balance_sets`] (the only one in the plain list form).
#[derive(Debug, Clone, Copy, Default)]
pub struct UserBalances {
    /// Index into [`SymbolicModel::balance_sets`].
    pub set: usize,
}

impl UserBalances {
    /// Whether the model has balances. [`crate::model::load`] refuses a file whose count of
    /// balances in a set differs from its count of coordinates, so they are then one per
    /// coordinate.
    pub fn applies_to(model: &SymbolicModel) -> bool {
        !model.balances.is_empty()
    }
}

fn cross_z(arena: &mut ExprArena, a: &[ExprId], b: &[ExprId]) -> ExprId {
    let p = arena.times(a[0], b[1]);
    let q = arena.times(a[1], b[0]);
    arena.minus(p, q)
}

impl Formulation for UserBalances {
    fn name(&self) -> &'static str {
        "balances"
    }

    fn derive(&self, model: &mut SymbolicModel) -> EquationsOfMotion {
        let n = model.num_dofs();
        let symbols: Vec<_> = (0..n).map(|i| model.coordinate_symbols(i)).collect();
        let points: Vec<Vec<ExprId>> = model.points.iter().map(|(_, r)| r.clone()).collect();
        let bodies = model.bodies.clone();
        let loads = model.loads.clone();
        let gravity = model.gravity.clone();
        let range = model
            .balance_sets
            .get(self.set)
            .map_or(0..model.balances.len(), |s| s.range.clone());
        let balances = model.balances[range].to_vec();
        let frames = model.frames.clone();
        let arena = &mut model.arena;
        let planar = Planar {
            points: &points,
            bodies: &bodies,
            loads: &loads,
            gravity: &gravity,
        };
        let mut residuals: Vec<Vec<ExprId>> = Vec::with_capacity(balances.len());
        for balance in &balances {
            let mut terms = Vec::new();
            let (chosen, about, along, form) = match balance {
                BalanceInfo::Amb {
                    about,
                    bodies: chosen,
                    form,
                    axis: Some(axis),
                } => {
                    residuals.push(spatial_amb(
                        arena,
                        &frames,
                        &points,
                        &bodies,
                        &loads,
                        gravity.as_deref(),
                        chosen,
                        *about,
                        *form,
                        axis,
                    ));
                    continue;
                }
                BalanceInfo::Amb {
                    about,
                    bodies,
                    form,
                    axis: None,
                } => (bodies, Some(*about), None, *form),
                BalanceInfo::Lmb { along, bodies } => {
                    (bodies, None, Some(along.clone()), AmbForm::RCrossMa)
                }
            };
            for &b in chosen {
                planar.body_terms(arena, b, about, along.as_deref(), form, &mut terms);
            }
            residuals.push(terms);
        }
        linear_in_accelerations(arena, &residuals, &symbols)
    }
}

/// What the terms of a planar balance ([`UserBalances`]) are built from: the model's points,
/// bodies, loads and gravity.
struct Planar<'a> {
    /// Each point's position, by index.
    points: &'a [Vec<ExprId>],
    /// The model's bodies.
    bodies: &'a [super::lower::BodyInfo],
    /// The model's loads.
    loads: &'a [LoadInfo],
    /// Gravity's components, if any.
    gravity: &'a Option<Vec<ExprId>>,
}

impl Planar<'_> {
    /// Appends to `terms` the terms of body `b` in an angular momentum balance about the
    /// point `about` (in the form `form`) or, without `about`, in a linear momentum balance
    /// along `along`.
    fn body_terms(
        &self,
        arena: &mut ExprArena,
        b: usize,
        about: Option<usize>,
        along: Option<&[ExprId]>,
        form: AmbForm,
        terms: &mut Vec<ExprId>,
    ) {
        let body = &self.bodies[b];
        let r = &self.points[body.com];
        let v: Vec<ExprId> = r.iter().map(|c| arena.time_derivative(*c)).collect();
        let a: Vec<ExprId> = v.iter().map(|c| arena.time_derivative(*c)).collect();
        let ma: Vec<ExprId> = a.iter().map(|c| arena.times(body.mass, *c)).collect();
        let mg: Vec<ExprId> = self
            .gravity
            .as_ref()
            .map(|g| g.iter().map(|c| arena.times(body.mass, *c)).collect())
            .unwrap_or_default();
        if let Some(about) = about {
            self.amb_terms(arena, b, about, form, (&v, &ma, &mg), terms);
        } else if let Some(e) = along {
            let t: Vec<ExprId> = ma.iter().zip(e).map(|(x, y)| arena.times(*x, *y)).collect();
            terms.push(arena.sum(&t));
            if !mg.is_empty() {
                let t: Vec<ExprId> = mg.iter().zip(e).map(|(x, y)| arena.times(*x, *y)).collect();
                let s = arena.sum(&t);
                terms.push(arena.neg(s));
            }
        }
    }

    /// Appends to `terms` the terms of body `b` in an angular momentum balance about the
    /// point `about` in the form `form`, given the body's velocity `v`, `m a_G` and `m g`
    /// (empty without gravity), then the torques on it.
    fn amb_terms(
        &self,
        arena: &mut ExprArena,
        b: usize,
        about: usize,
        form: AmbForm,
        (v, ma, mg): (&[ExprId], &[ExprId], &[ExprId]),
        terms: &mut Vec<ExprId>,
    ) {
        let body = &self.bodies[b];
        let r = &self.points[body.com];
        let rel: Vec<ExprId> = r
            .iter()
            .zip(&self.points[about])
            .map(|(x, y)| arena.minus(*x, *y))
            .collect();
        if !mg.is_empty() {
            let m = cross_z(arena, &rel, mg);
            terms.push(arena.neg(m));
        }
        match form {
            AmbForm::RCrossMa => {
                terms.push(cross_z(arena, &rel, ma));
                if let Some((inertia, angle)) = body.rotation {
                    let w = arena.time_derivative(angle);
                    let alpha = arena.time_derivative(w);
                    terms.push(arena.times(inertia, alpha));
                }
            }
            AmbForm::HDot => {
                // H_A = r_G/A × m v_G + I ω, differentiated as a whole.
                let mv: Vec<ExprId> = v.iter().map(|c| arena.times(body.mass, *c)).collect();
                let mut h = cross_z(arena, &rel, &mv);
                if let Some((inertia, angle)) = body.rotation {
                    let w = arena.time_derivative(angle);
                    let iw = arena.times(inertia, w);
                    h = arena.plus(h, iw);
                }
                terms.push(arena.time_derivative(h));
            }
            AmbForm::HRelDot => {
                // H_A/rel = r_G/A × m (v_G − v_A) + I ω, differentiated as a whole.
                let rel_v: Vec<ExprId> = v
                    .iter()
                    .zip(&self.points[about])
                    .map(|(vg, ra)| {
                        let va = arena.time_derivative(*ra);
                        let d = arena.minus(*vg, va);
                        arena.times(body.mass, d)
                    })
                    .collect();
                let mut h = cross_z(arena, &rel, &rel_v);
                if let Some((inertia, angle)) = body.rotation {
                    let w = arena.time_derivative(angle);
                    let iw = arena.times(inertia, w);
                    h = arena.plus(h, iw);
                }
                terms.push(arena.time_derivative(h));
            }
        }
        for load in self.loads {
            if let LoadInfo::Torque {
                body: on, value, ..
            } = load
                && *on == b
            {
                terms.push(arena.neg(*value));
            }
        }
    }
}

/// The terms of a 3-D angular momentum balance about the point `about` along the axis `e`
/// (ground-frame components) of the bodies `chosen`:
/// `Σ [(r_G − r_A) × m a_G + I_G α + ω × I_G ω − (r_G − r_A) × m g − τ]·e` (`form: r_x_ma`,
/// right about any point), or with `form: h_dot` the derivative of
/// `H_A = Σ (r_G − r_A) × m v_G + I_G ω` in place of the inertial terms (right about a fixed
/// point or the centre of mass). `I_G`, `ω`, `α` and the torques are in the body frame's
/// components and carried into the ground frame's; `α` is the time derivative of `ω`'s body
/// components (the derivatives in the body and in the ground frame agree for `ω`).
#[allow(clippy::too_many_arguments)]
fn spatial_amb(
    arena: &mut ExprArena,
    frames: &super::frames::Frames,
    points: &[Vec<ExprId>],
    bodies: &[super::lower::BodyInfo],
    loads: &[LoadInfo],
    gravity: Option<&[ExprId]>,
    chosen: &[usize],
    about: usize,
    form: AmbForm,
    e: &[ExprId],
) -> Vec<ExprId> {
    use super::frames::{cross, tensor_times};
    let three = |v: &[ExprId]| [v[0], v[1], v[2]];
    let project = |arena: &mut ExprArena, v: &[ExprId; 3]| {
        let t: Vec<ExprId> = v.iter().zip(e).map(|(a, b)| arena.times(*a, *b)).collect();
        arena.sum(&t)
    };
    let mut terms = Vec::new();
    for &b in chosen {
        let body = &bodies[b];
        let r = &points[body.com];
        let rel: Vec<ExprId> = r
            .iter()
            .zip(&points[about])
            .map(|(x, y)| arena.minus(*x, *y))
            .collect();
        let rel = three(&rel);
        let v: Vec<ExprId> = r.iter().map(|c| arena.time_derivative(*c)).collect();
        if let Some(g) = gravity {
            let mg: Vec<ExprId> = g.iter().map(|c| arena.times(body.mass, *c)).collect();
            let moment = cross(arena, &rel, &three(&mg));
            let m = project(arena, &moment);
            terms.push(arena.neg(m));
        }
        match form {
            AmbForm::RCrossMa => {
                let ma: Vec<ExprId> = v
                    .iter()
                    .map(|c| {
                        let a = arena.time_derivative(*c);
                        arena.times(body.mass, a)
                    })
                    .collect();
                let moment = cross(arena, &rel, &three(&ma));
                terms.push(project(arena, &moment));
                if let Some(s) = &body.spatial {
                    let h_dot = angular_momentum_rate(arena, frames, s);
                    terms.push(project(arena, &h_dot));
                }
            }
            AmbForm::HDot | AmbForm::HRelDot => {
                // H_A = r_G/A × m v_G + I_G ω; relative to A (`h_rel_dot`), v_G − v_A.
                let mv: Vec<ExprId> = v
                    .iter()
                    .zip(&points[about])
                    .map(|(vg, ra)| {
                        let vg = if form == AmbForm::HRelDot {
                            let va = arena.time_derivative(*ra);
                            arena.minus(*vg, va)
                        } else {
                            *vg
                        };
                        arena.times(body.mass, vg)
                    })
                    .collect();
                let mut h = cross(arena, &rel, &three(&mv));
                if let Some(s) = &body.spatial {
                    let i_w = tensor_times(arena, &s.inertia, &s.angular_velocity);
                    let i_w = frames.express(arena, i_w, s.frame, 0);
                    for (x, y) in h.iter_mut().zip(i_w) {
                        *x = arena.plus(*x, y);
                    }
                }
                let h_dot = h.map(|c| arena.time_derivative(c));
                terms.push(project(arena, &h_dot));
            }
        }
        for load in loads {
            if let LoadInfo::SpatialTorque { body: on, vector } = load
                && *on == b
                && let Some(s) = &body.spatial
            {
                let tau = frames.express(arena, *vector, s.frame, 0);
                let m = project(arena, &tau);
                terms.push(arena.neg(m));
            }
        }
    }
    terms
}

/// `Ḣ_G = I α + ω × I ω` of a 3-D body about its centre of mass (Euler's equations; Kane &
/// Levinson §4.11), computed in its frame and carried to the ground's components.
pub(super) fn angular_momentum_rate(
    arena: &mut ExprArena,
    frames: &super::frames::Frames,
    body: &super::SpatialBody,
) -> super::frames::Vector3 {
    use super::frames::{cross, tensor_times};
    let w = body.angular_velocity;
    let alpha = w.map(|c| arena.time_derivative(c));
    let i_alpha = tensor_times(arena, &body.inertia, &alpha);
    let i_w = tensor_times(arena, &body.inertia, &w);
    let gyro = cross(arena, &w, &i_w);
    let h_dot = [0, 1, 2].map(|i| arena.plus(i_alpha[i], gyro[i]));
    frames.express(arena, h_dot, body.frame, 0)
}

/// The equations of motion the file states as derived by hand (`checks:
/// equations_of_motion`), each `lhs − rhs = 0` split into `M′ q̈ = f′` by its coefficients of
/// the accelerations. Any set of independent combinations of the true equations passes the
/// comparison in `eomgen check`; a dropped or wrong term does not.
#[derive(Debug, Clone, Copy, Default)]
pub struct HandEquations;

impl HandEquations {
    /// Whether the model states its equations of motion. [`crate::model::load`] refuses a
    /// file whose count of equations differs from its count of coordinates.
    pub fn applies_to(model: &SymbolicModel) -> bool {
        !model.hand_equations.is_empty()
    }
}

impl Formulation for HandEquations {
    fn name(&self) -> &'static str {
        "by_hand"
    }

    fn derive(&self, model: &mut SymbolicModel) -> EquationsOfMotion {
        let n = model.num_dofs();
        let symbols: Vec<_> = (0..n).map(|i| model.coordinate_symbols(i)).collect();
        let residuals: Vec<Vec<ExprId>> = model.hand_equations.iter().map(|r| vec![*r]).collect();
        linear_in_accelerations(&mut model.arena, &residuals, &symbols)
    }
}
