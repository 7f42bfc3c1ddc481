//! The bodies of the 3-D view: each 3-D body's orientation at a state, composed from the
//! model description's frames (`R = R_parent R₁ … Rₖ`, each `Rᵢ` a simple rotation or Euler
//! parameters; Kane & Levinson, *Dynamics: Theory and Applications*, 1985, §1.3 and
//! §1.7–1.9), and the solid it is drawn as: the file's `draw: shapes:` entry, or the uniform
//! box of its mass and inertia.
//!
//! The rotations are the file's own expressions, evaluated numerically (as the outputs are):
//! the orientation is not among the functions compiled for a model, and evaluating a few
//! angles per frame costs far less than the frame's integration. The test
//! `tests/animation3d.rs` holds it to the symbolic frames of every bundled 3-D model.

use eomgen_runtime::ModelInfo;
use eomgen_runtime::description::{FrameSpec, RotationSpec, Shape};
use eomgen_symbolic::model::parser::{eval_expr, parse_expr};
use eomgen_symbolic::model::{Expr, Location};
use nalgebra::{DMatrix, Matrix3, Rotation3, UnitQuaternion, Vector3};

use super::AnimationError;
use crate::expressions::parameter_lookup;

/// A solid the 3-D view draws, in its own axes: a box along x, y, z; a cylinder along y (the
/// view's convention); a sphere. Sizes in m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Solid {
    /// A box with these sides.
    Box([f64; 3]),
    /// A cylinder of this radius and length along its own y axis.
    Cylinder {
        /// The radius (m).
        radius: f64,
        /// The length (m).
        length: f64,
    },
    /// A sphere of this radius.
    Sphere(f64),
}

/// A body the 3-D view draws: at its centre of mass, turned with its frame.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawnBody {
    /// The body's name.
    pub name: String,
    /// Its solid.
    pub solid: Solid,
    /// Whether the solid is the default from the inertia (no `draw: shapes:` entry).
    pub from_inertia: bool,
    /// Index of its frame among the parsed frames; `None` for the ground frame itself.
    frame: Option<usize>,
    /// The solid's axes in the body frame (columns): a cylinder's y onto its axis, a box
    /// from the inertia onto the principal axes.
    local: Matrix3<f64>,
    /// Index of its centre of mass among the model's points.
    pub(super) centre: usize,
}

/// One rotation, parsed.
#[derive(Debug, Clone, PartialEq)]
enum Rotation {
    /// About a unit axis (normalised here) by an angle.
    Axis([Expr; 3], Expr),
    /// Euler parameters `[e1, e2, e3]` and `e0` (normalised where evaluated).
    Quaternion([Expr; 3], Expr),
}

/// The orientations of a model's 3-D bodies at any state.
#[derive(Debug, Clone, PartialEq)]
pub struct Poses {
    /// Each frame's name, parent (an index into this list, `None` for the ground) and
    /// rotations.
    frames: Vec<(String, Option<usize>, Vec<Rotation>)>,
    /// The bodies drawn, in the description's order.
    pub bodies: Vec<DrawnBody>,
}

impl Poses {
    /// The 3-D bodies of `model` (its description's frames and body centres) with their
    /// solids, sizes evaluated at the model's parameter values.
    ///
    /// # Errors
    /// [`AnimationError::Description`] when an expression of the description does not parse
    /// or evaluate, or a size is not positive.
    pub fn of(model: &dyn ModelInfo) -> Result<Self, AnimationError> {
        let description = model.description();
        let error = |what: String| AnimationError::Description {
            model: description.name.to_string(),
            what,
        };
        let names: Vec<&str> = description.frames.iter().map(|f| &*f.name).collect();
        let mut frames = Vec::with_capacity(names.len());
        for f in description.frames.iter() {
            let (parent, rotations) = parse_frame(f, &names).map_err(error)?;
            frames.push((f.name.to_string(), parent, rotations));
        }
        let lookup = parameter_lookup(model);
        let value = |text: &str, what: &str| -> Result<f64, AnimationError> {
            let v = evaluate(&parse(text, what).map_err(error)?, &lookup, what).map_err(error)?;
            if v > 0.0 {
                Ok(v)
            } else {
                Err(error(format!("{what} is {v}, not positive")))
            }
        };
        let mut bodies = Vec::new();
        for c in description.body_centres.iter() {
            // A particle or a planar body has no frame; a 3-D body's frame is among the
            // described frames, or the ground itself (which they leave out).
            if c.frame.is_empty() {
                continue;
            }
            let frame = names.iter().position(|n| *n == &*c.frame);
            let Some(centre) = description.point_index(&c.point) else {
                continue;
            };
            let what = |s: &str| format!("the {s} of the shape of `{}`", c.body);
            let (solid, local) = match &c.shape {
                Some(Shape::Box { sides }) => {
                    let [a, b, d] = [0, 1, 2].map(|i| value(&sides[i], &what("side")));
                    (Solid::Box([a?, b?, d?]), Matrix3::identity())
                }
                Some(Shape::Cylinder {
                    radius,
                    length,
                    axis,
                }) => (
                    Solid::Cylinder {
                        radius: value(radius, &what("radius"))?,
                        length: value(length, &what("length"))?,
                    },
                    y_onto(*axis),
                ),
                Some(Shape::Disc { radius, axis }) => {
                    let radius = value(radius, &what("radius"))?;
                    let length = radius / 12.0;
                    (Solid::Cylinder { radius, length }, y_onto(*axis))
                }
                Some(Shape::Sphere { radius }) => (
                    Solid::Sphere(value(radius, &what("radius"))?),
                    Matrix3::identity(),
                ),
                None => {
                    let mass = value(&c.mass, &format!("the mass of `{}`", c.body))?;
                    let mut inertia = [0.0; 6];
                    for (slot, text) in inertia.iter_mut().zip(c.inertia.iter()) {
                        let what = format!("the inertia of `{}`", c.body);
                        *slot = evaluate(&parse(text, &what).map_err(error)?, &lookup, &what)
                            .map_err(error)?;
                    }
                    inertia_box(mass, inertia)
                }
            };
            bodies.push(DrawnBody {
                name: c.body.to_string(),
                from_inertia: c.shape.is_none(),
                solid,
                frame,
                local,
                centre,
            });
        }
        Ok(Self { frames, bodies })
    }

    /// Every frame's orientation at `(t, q)`: `R` taking the frame's components to the
    /// ground's.
    ///
    /// # Errors
    /// A message naming the frame and `t` when an angle is not finite or a name is unknown.
    fn orientations(
        &self,
        model: &dyn ModelInfo,
        t: f64,
        q: &[f64],
    ) -> Result<Vec<Matrix3<f64>>, String> {
        let description = model.description();
        let parameters = parameter_lookup(model);
        let lookup = |n: &str| -> Option<f64> {
            if n == "t" {
                return Some(t);
            }
            match description.coordinate_index(n) {
                Some(i) => q.get(i).copied(),
                None => parameters(n),
            }
        };
        let mut out: Vec<Matrix3<f64>> = Vec::with_capacity(self.frames.len());
        for (name, parent, rotations) in &self.frames {
            let mut r = parent.map_or(Matrix3::identity(), |p| out[p]);
            for rotation in rotations {
                r *= rotation_matrix(rotation, &lookup)
                    .map_err(|e| format!("frame `{name}` at t = {t}: {e}"))?;
            }
            out.push(r);
        }
        Ok(out)
    }

    /// Each body's pose at `(t, q)`: the centre (m, from `points`, the model's point positions
    /// there) and the unit quaternion `[x, y, z, w]` of its frame's axes in the ground's.
    ///
    /// # Errors
    /// [`AnimationError::Description`] when an angle does not evaluate to a finite number.
    pub fn at(
        &self,
        model: &dyn ModelInfo,
        t: f64,
        q: &[f64],
        points: &[[f64; 3]],
    ) -> Result<Vec<[f64; 7]>, AnimationError> {
        let frames =
            self.orientations(model, t, q)
                .map_err(|what| AnimationError::Description {
                    model: model.description().name.to_string(),
                    what,
                })?;
        Ok(self
            .bodies
            .iter()
            .map(|b| {
                let q = b
                    .frame
                    .map_or(UnitQuaternion::identity(), |f| quaternion(&frames[f]));
                let p = points[b.centre];
                [p[0], p[1], p[2], q.i, q.j, q.k, q.w]
            })
            .collect())
    }

    /// Each frame's orientation at `(t, q)` by name, in the description's order (for tests
    /// and the kinematics' cross-checks).
    ///
    /// # Errors
    /// As [`Poses::at`].
    pub fn frame_orientations(
        &self,
        model: &dyn ModelInfo,
        t: f64,
        q: &[f64],
    ) -> Result<Vec<(String, Matrix3<f64>)>, AnimationError> {
        let description = model.description();
        let frames =
            self.orientations(model, t, q)
                .map_err(|what| AnimationError::Description {
                    model: description.name.to_string(),
                    what,
                })?;
        Ok(description
            .frames
            .iter()
            .map(|f| f.name.to_string())
            .zip(frames)
            .collect())
    }
}

impl DrawnBody {
    /// The unit quaternion `[x, y, z, w]` of the solid's axes in the body frame's.
    pub fn local_quaternion(&self) -> [f64; 4] {
        let q = quaternion(&self.local);
        [q.i, q.j, q.k, q.w]
    }

    /// The solid's largest dimension (m).
    pub fn extent(&self) -> f64 {
        match self.solid {
            Solid::Box(s) => s[0].max(s[1]).max(s[2]),
            Solid::Cylinder { radius, length } => (2.0 * radius).max(length),
            Solid::Sphere(r) => 2.0 * r,
        }
    }
}

/// The unit quaternion of a rotation matrix (orthonormal to rounding: the closed form, not
/// `from_matrix`'s iteration).
fn quaternion(r: &Matrix3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*r))
}

/// The rotation taking a cylinder's own y axis onto the frame's axis `axis` (0, 1, 2).
fn y_onto(axis: usize) -> Matrix3<f64> {
    match axis {
        // y → x: a quarter turn about −z.
        0 => Matrix3::new(0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        // y → z: a quarter turn about x.
        2 => Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0),
        _ => Matrix3::identity(),
    }
}

/// The uniform box of mass `m` (kg) and centroidal inertia `[xx, yy, zz, xy, yz, xz]`
/// (kg·m²): sides `aᵢ = √(6 (Iⱼ + Iₖ − Iᵢ)/m)` along the principal axes (Meriam & Kraige,
/// *Dynamics*, Appendix D: `Iᵢ = m (aⱼ² + aₖ²)/12`). A side the inertia makes zero or
/// negative (a thin disc, a rod) is drawn a twentieth of the largest; a body without inertia
/// as a small sphere.
fn inertia_box(m: f64, i: [f64; 6]) -> (Solid, Matrix3<f64>) {
    let [xx, yy, zz, xy, yz, xz] = i;
    let tensor = DMatrix::from_row_slice(3, 3, &[xx, xy, xz, xy, yy, yz, xz, yz, zz]);
    // The runtime's bounded solver: the one the modes use (none of its own in the program).
    let Some(eigen) = eomgen_runtime::linalg::symmetric_eigen(tensor) else {
        return (Solid::Sphere(0.0), Matrix3::identity());
    };
    let p = eigen.eigenvalues;
    let squares = [0, 1, 2].map(|k| 6.0 * (p[(k + 1) % 3] + p[(k + 2) % 3] - p[k]) / m);
    let largest = squares.iter().copied().fold(0.0, f64::max).sqrt();
    if !(largest.is_finite() && largest > 0.0) {
        return (Solid::Sphere(0.0), Matrix3::identity());
    }
    let sides = squares.map(|s| s.max(0.0).sqrt().max(largest / 20.0));
    let v = &eigen.eigenvectors;
    let column = |k: usize| Vector3::new(v[(0, k)], v[(1, k)], v[(2, k)]);
    // A proper rotation: the third axis the cross product of the first two.
    let axes = Matrix3::from_columns(&[column(0), column(1), column(0).cross(&column(1))]);
    (Solid::Box(sides), axes)
}

/// A frame of the description, parsed: its parent's index among `names` (`None`: the
/// ground) and its rotations.
fn parse_frame(f: &FrameSpec, names: &[&str]) -> Result<(Option<usize>, Vec<Rotation>), String> {
    let parent = names.iter().position(|n| *n == &*f.parent);
    let what = |s: &str| format!("{s} of frame `{}`", f.name);
    let mut rotations = Vec::with_capacity(f.rotations.len());
    for RotationSpec {
        axis,
        angle,
        quaternion,
    } in f.rotations.iter()
    {
        let axis = [0, 1, 2].map(|i| parse(&axis[i], &what("an axis")));
        let [a, b, c] = axis;
        let axis = [a?, b?, c?];
        let angle = parse(angle, &what("an angle"))?;
        rotations.push(if *quaternion {
            Rotation::Quaternion(axis, angle)
        } else {
            Rotation::Axis(axis, angle)
        });
    }
    Ok((parent, rotations))
}

/// `text` parsed; `what` names it in the message.
fn parse(text: &str, what: &str) -> Result<Expr, String> {
    parse_expr(text, Location { line: 1, column: 1 })
        .map_err(|d| format!("{what} `{text}` does not parse: {}", d.message))
}

/// `e` evaluated, finite; `what` names it in the message.
fn evaluate(e: &Expr, lookup: &dyn Fn(&str) -> Option<f64>, what: &str) -> Result<f64, String> {
    match eval_expr(e, lookup) {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) => Err(format!("{what} is {v}")),
        Err(d) => Err(format!("{what}: {}", d.message)),
    }
}

/// The matrix of one rotation, taking components in the turned frame to the frame before:
/// Rodrigues' `cos a I + sin a [k]ₓ + (1 − cos a) k kᵀ` about the unit axis `k`, or the
/// Euler parameters' `((e0² − e·e) I + 2 e eᵀ + 2 e0 [e]ₓ)/|q|²` (Kane & Levinson §1.3).
fn rotation_matrix(
    r: &Rotation,
    lookup: &dyn Fn(&str) -> Option<f64>,
) -> Result<Matrix3<f64>, String> {
    let vector = |v: &[Expr; 3]| -> Result<Vector3<f64>, String> {
        let [a, b, c] = [0, 1, 2].map(|i| evaluate(&v[i], lookup, "a rotation's axis"));
        Ok(Vector3::new(a?, b?, c?))
    };
    let cross = |k: &Vector3<f64>| k.cross_matrix();
    match r {
        Rotation::Axis(axis, angle) => {
            let k = vector(axis)?.normalize();
            let a = evaluate(angle, lookup, "a rotation's angle")?;
            let (s, c) = a.sin_cos();
            Ok(Matrix3::identity() * c + cross(&k) * s + k * k.transpose() * (1.0 - c))
        }
        Rotation::Quaternion(e, e0) => {
            let e = vector(e)?;
            let e0 = evaluate(e0, lookup, "an Euler parameter")?;
            let norm = e0 * e0 + e.norm_squared();
            if norm.is_nan() || norm <= 0.0 {
                return Err("the Euler parameters are all zero".to_string());
            }
            Ok((Matrix3::identity() * (e0 * e0 - e.norm_squared())
                + e * e.transpose() * 2.0
                + cross(&e) * (2.0 * e0))
                / norm)
        }
    }
}
