//! Kinematics on demand: the angular velocity and acceleration of a model's frames and the
//! position, velocity and acceleration of its points, with their partial velocities, as
//! expressions of the coordinates, their rates and accelerations, the parameters and `t` —
//! what SymPy's `B.ang_vel_in(N)`, `B.ang_acc_in(N)`, `P.vel(N)`, `P.acc(N)` and
//! `partial_velocity` give (Kane & Levinson, *Dynamics: Theory and Applications*, 1985,
//! §§2.1–2.7 and 2.14; lecture 18 for the 3-D angular velocity).
//!
//! Every derivative is the arena's total time derivative (the chain rule through `q` and `q̇`,
//! and `∂/∂t`), so a frame turned by an angle that is a function of `t` or of several
//! coordinates is handled as any other. The partial velocities are taken with the
//! coordinate rates as generalized speeds: `∂v_P/∂q̇ᵢ` (m per coordinate unit) and
//! `∂ω/∂q̇ᵢ`.

use super::SymbolicModel;
use super::frames::Vector3;
use crate::expr::ExprId;

/// The angular motion of one frame `F` in the ground frame `N`.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameKinematics {
    /// The frame's name.
    pub name: String,
    /// `^N ω^F` in `F`'s own components (rad/s): the body-fixed `p, q, r`.
    pub angular_velocity: Vector3,
    /// `^N ω^F` in `N`'s components (rad/s).
    pub angular_velocity_ground: Vector3,
    /// `^N α^F = ^N d/dt ω` in `F`'s components (rad/s²); as `ω × ω = 0`, also the
    /// component-wise derivative of [`Self::angular_velocity`].
    pub angular_acceleration: Vector3,
    /// Per coordinate `qᵢ`, the partial angular velocity `∂ω/∂q̇ᵢ` in `F`'s components.
    pub partial_angular_velocities: Vec<Vector3>,
}

/// The motion of one point `P` in the ground frame `N`, in `N`'s components (2 of them for a
/// planar model, 3 for a spatial one).
#[derive(Debug, Clone, PartialEq)]
pub struct PointKinematics {
    /// The point's name.
    pub name: String,
    /// `r_P` from `N`'s origin (m).
    pub position: Vec<ExprId>,
    /// `^N v_P = ^N d/dt r_P` (m/s).
    pub velocity: Vec<ExprId>,
    /// `^N a_P` (m/s²).
    pub acceleration: Vec<ExprId>,
    /// Per coordinate `qᵢ`, the partial velocity `∂v_P/∂q̇ᵢ`.
    pub partial_velocities: Vec<Vec<ExprId>>,
}

impl SymbolicModel {
    /// The names of the model's frames, the ground `N` first.
    pub fn frame_names(&self) -> &[String] {
        self.frames.names()
    }

    /// The kinematics of the frame `frame` (an index into [`Self::frame_names`]).
    pub fn frame_kinematics(&mut self, frame: usize) -> FrameKinematics {
        let w = self.frames.angular_velocity(&mut self.arena, frame);
        let ground = self
            .frames
            .angular_velocity_in_ground(&mut self.arena, frame);
        let alpha = w.map(|c| self.arena.time_derivative(c));
        let partial_angular_velocities = (0..self.num_dofs())
            .map(|i| {
                let rate = self.coordinate_symbols(i)[1];
                w.map(|c| self.arena.diff(c, rate))
            })
            .collect();
        FrameKinematics {
            name: self.frames.names()[frame].clone(),
            angular_velocity: w,
            angular_velocity_ground: ground,
            angular_acceleration: alpha,
            partial_angular_velocities,
        }
    }

    /// The kinematics of the point `point` (an index into [`Self::points`]).
    pub fn point_kinematics(&mut self, point: usize) -> PointKinematics {
        let (name, position) = self.points[point].clone();
        let velocity: Vec<ExprId> = (position.iter())
            .map(|&c| self.arena.time_derivative(c))
            .collect();
        let acceleration = (velocity.iter())
            .map(|&c| self.arena.time_derivative(c))
            .collect();
        let partial_velocities = (0..self.num_dofs())
            .map(|i| {
                let rate = self.coordinate_symbols(i)[1];
                (velocity.iter())
                    .map(|&c| self.arena.diff(c, rate))
                    .collect()
            })
            .collect();
        PointKinematics {
            name,
            position,
            velocity,
            acceleration,
            partial_velocities,
        }
    }
}

/// The resultant force and moment that everything but gravity and the bodies' own torques
/// exerts on a set of bodies — at a pivot the model leaves implicit, the joint's reaction —
/// from their momentum balances (Newton–Euler; Kane & Levinson §§4.1–4.4):
///
/// ```text
/// R   = Σ m a_G − Σ m g
/// M_P = Σ [(r_G − r_P) × m a_G + Ḣ_G] − Σ (r_G − r_P) × m g − Σ τ
/// ```
///
/// with `Ḣ_G = I α + ω × I ω` of a 3-D body (in its frame, carried to `N`) and `I θ̈` of a
/// planar one, as expressions of `q`, `q̇` and `q̈` (whose values the equations of motion
/// give).
#[derive(Debug, Clone, PartialEq)]
pub struct Reaction {
    /// The bodies' names.
    pub bodies: Vec<String>,
    /// The point the moment is taken about.
    pub at: String,
    /// `R` in `N`'s components (N): 2 for a planar model, 3 for a spatial one.
    pub force: Vec<ExprId>,
    /// `M_P` in `N`'s components (N·m): the `z` component alone for a planar model.
    pub moment: Vec<ExprId>,
}

/// Why a reaction cannot be computed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ReactionError {
    /// A body of the set is not the model's.
    #[error("the model has no body `{name}` (its bodies: {})", known.join(", "))]
    UnknownBody {
        /// The name asked for.
        name: String,
        /// The model's bodies.
        known: Vec<String>,
    },
    /// The point is not the model's.
    #[error("the model has no point `{name}` (its points: {})", known.join(", "))]
    UnknownPoint {
        /// The name asked for.
        name: String,
        /// The model's points.
        known: Vec<String>,
    },
    /// The model has loads (or energies) whose share on the set its file does not say.
    #[error(
        "the reaction is what acts on the bodies besides gravity and their own torques, but `{model}` also has {what}, which the file does not attribute to bodies: it cannot be separated out"
    )]
    UnattributedLoads {
        /// The model.
        model: String,
        /// Forces, springs, dampers, generalized forces or a written energy.
        what: &'static str,
    },
}

impl SymbolicModel {
    /// The reaction on the bodies `bodies` (names) about the point `at`: see [`Reaction`].
    ///
    /// # Errors
    /// [`ReactionError::UnknownBody`] or [`ReactionError::UnknownPoint`] for a name the model
    /// does not have; [`ReactionError::UnattributedLoads`] when it has forces, interactions,
    /// springs, dampers, written generalized forces or a written potential or kinetic energy
    /// (acting at points or on coordinates, not on bodies).
    pub fn reaction(&mut self, bodies: &[String], at: &str) -> Result<Reaction, ReactionError> {
        use super::LoadInfo;
        use super::frames::cross;
        let known: Vec<String> = self.bodies.iter().map(|b| b.name.clone()).collect();
        let chosen = (bodies.iter())
            .map(|name| {
                known
                    .iter()
                    .position(|k| k == name)
                    .ok_or_else(|| ReactionError::UnknownBody {
                        name: name.clone(),
                        known: known.clone(),
                    })
            })
            .collect::<Result<Vec<usize>, _>>()?;
        let p = (self.points.iter().position(|(n, _)| n == at)).ok_or_else(|| {
            ReactionError::UnknownPoint {
                name: at.to_string(),
                known: self.points.iter().map(|(n, _)| n.clone()).collect(),
            }
        })?;
        let mut chosen = chosen;
        chosen.dedup();
        chosen.sort_unstable();
        chosen.dedup();
        let unattributed = (self.loads.iter()).find_map(|l| match l {
            LoadInfo::Force { .. } => Some("forces or interactions"),
            LoadInfo::Spring { .. } => Some("springs"),
            LoadInfo::Damper { .. } => Some("dampers"),
            _ => None,
        });
        let written = self.written_forces.iter().any(|f| !self.arena.is_zero(*f));
        let potential = !self.arena.is_zero(self.written_potential);
        let unattributed = unattributed
            .or(written.then_some("generalized forces"))
            .or(potential.then_some("a written potential"))
            .or(self.kinetic_written.then_some("a written kinetic energy"));
        if let Some(what) = unattributed {
            return Err(ReactionError::UnattributedLoads {
                model: self.name.clone(),
                what,
            });
        }
        let dim = self.points[p].1.len();
        let zero = self.arena.int(0);
        let arena = &mut self.arena;
        let pad = |v: &[ExprId]| [v[0], v[1], if v.len() > 2 { v[2] } else { zero }];
        let mut force = [zero; 3];
        let mut moment = [zero; 3];
        let add = |arena: &mut crate::expr::ExprArena, sum: &mut [ExprId; 3], v: [ExprId; 3]| {
            for (s, x) in sum.iter_mut().zip(v) {
                *s = arena.plus(*s, x);
            }
        };
        let at_point = pad(&self.points[p].1);
        for &b in &chosen {
            let body = &self.bodies[b];
            let r = pad(&self.points[body.com].1);
            let a = r.map(|c| {
                let v = arena.time_derivative(c);
                arena.time_derivative(v)
            });
            let mut net = a.map(|c| arena.times(body.mass, c));
            if let Some(g) = &self.gravity {
                let g = pad(g);
                net = [0, 1, 2].map(|i| {
                    let w = arena.times(body.mass, g[i]);
                    arena.minus(net[i], w)
                });
            }
            add(arena, &mut force, net);
            let rel = [0, 1, 2].map(|i| arena.minus(r[i], at_point[i]));
            let arm = cross(arena, &rel, &net);
            add(arena, &mut moment, arm);
            if let Some((inertia, angle)) = body.rotation {
                let rate = arena.time_derivative(angle);
                let accel = arena.time_derivative(rate);
                let spin = arena.times(inertia, accel);
                add(arena, &mut moment, [zero, zero, spin]);
            }
            if let Some(s) = &body.spatial {
                let h_dot = super::balances::angular_momentum_rate(arena, &self.frames, s);
                add(arena, &mut moment, h_dot);
            }
            for load in &self.loads {
                match load {
                    LoadInfo::Torque {
                        body: on, value, ..
                    } if *on == b => {
                        let minus = arena.neg(*value);
                        add(arena, &mut moment, [zero, zero, minus]);
                    }
                    LoadInfo::SpatialTorque { body: on, vector } if *on == b => {
                        if let Some(s) = &body.spatial {
                            let tau = self.frames.express(arena, *vector, s.frame, 0);
                            let minus = tau.map(|c| arena.neg(c));
                            add(arena, &mut moment, minus);
                        }
                    }
                    _ => {}
                }
            }
        }
        Ok(Reaction {
            bodies: bodies.to_vec(),
            at: at.to_string(),
            force: force[..dim].to_vec(),
            moment: if dim == 2 {
                vec![moment[2]]
            } else {
                moment.to_vec()
            },
        })
    }
}
