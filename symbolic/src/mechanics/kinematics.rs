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
