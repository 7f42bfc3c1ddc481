//! The lowering of `bodies:` (planar and spatial) and of the energies written in the file into the
//! terms of `T` and `V`.

use super::*;

impl Lowering<'_> {
    /// The energies and generalized forces written as such (`kinetic:`, `potential:`,
    /// `generalized_forces:`).
    pub(super) fn energies_written(&mut self, terms: &mut Terms, coordinate_names: &[String]) {
        let file = self.file;
        if let Some(k) = &file.kinetic {
            let e = self.expr(k);
            terms.kinetic.push(e);
        }
        if let Some(v) = &file.potential {
            let e = self.expr(v);
            terms.potential.push(e);
        }
        for (name, q) in &file.generalized_forces {
            let e = self.expr(q);
            match coordinate_names.iter().position(|c| *c == name.value) {
                Some(i) => terms.forces[i].push(e),
                None => self.errors.push(Diagnostic::new(
                    name.location,
                    format!("`{}` is not a coordinate", name.value),
                )),
            }
        }
    }

    /// Bodies: T = ½ m v_G·v_G (+ ½ I ω² for planar rigid bodies, + ½ ω·I_G ω for 3-D
    /// ones), V = −m g·r_G. Returns the bodies (a planar rigid body's angle in its
    /// `rotation`).
    pub(super) fn bodies(
        &mut self,
        points: &Points,
        frames: &mut Frames,
        gravity: Option<&[ExprId]>,
        terms: &mut Terms,
    ) -> Vec<BodyInfo> {
        let half = terms.half;
        let mut body_infos: Vec<BodyInfo> = Vec::new();
        for body in &self.file.bodies {
            let (mass, at, rigid) = match &body.kind {
                BodyKind::Particle { mass, at } => (mass, at, None),
                BodyKind::Rigid {
                    mass,
                    inertia,
                    com,
                    angle,
                } => (mass, com, Some((inertia, angle))),
                BodyKind::Spatial { mass, com, .. } => (mass, com, None),
            };
            let m = self.expr(mass);
            let Some(ip) = point(points, &at.value) else {
                self.errors.push(Diagnostic::new(
                    at.location,
                    format!("unknown point `{}`", at.value),
                ));
                continue;
            };
            let r = points[ip].1.clone();
            let v: Vec<ExprId> = r.iter().map(|c| self.arena.time_derivative(*c)).collect();
            let v2 = self.dot(&v, &v);
            terms.kinetic.push(self.arena.product(&[half, m, v2]));
            if let Some(g) = gravity {
                let gr = self.dot(g, &r);
                let mgr = self.arena.times(m, gr);
                terms.potential.push(self.arena.neg(mgr));
            }
            let mut rotation = None;
            if let Some((inertia, angle)) = rigid {
                let i = self.expr(inertia);
                let th = self.expr(angle);
                rotation = Some((i, th));
                let w = self.arena.time_derivative(th);
                let two = self.arena.int(2);
                let w2 = self.arena.pow(w, two);
                terms.kinetic.push(self.arena.product(&[half, i, w2]));
            }
            let spatial = match &body.kind {
                BodyKind::Spatial { frame, inertia, .. } => {
                    self.spatial_body(frames, frame, inertia, terms)
                }
                _ => None,
            };
            body_infos.push(BodyInfo {
                name: body.name.value.clone(),
                mass: m,
                com: ip,
                rotation,
                spatial,
            });
        }
        body_infos
    }

    /// A 3-D body's angular velocity (from its frame's rotations) and inertia tensor, with
    /// its rotational kinetic energy `½ ω·I_G ω` (body components) added to `T`.
    fn spatial_body(
        &mut self,
        frames: &mut Frames,
        frame: &Located<String>,
        inertia: &crate::model::file::InertiaTensor,
        terms: &mut Terms,
    ) -> Option<SpatialBody> {
        let Some(f) = frames.index(&frame.value) else {
            self.errors.push(Diagnostic::new(
                frame.location,
                format!("unknown frame `{}`", frame.value),
            ));
            return None;
        };
        let zero = self.arena.int(0);
        let inertia = inertia
            .entries
            .clone()
            .map(|e| e.map_or(zero, |e| self.expr(&e)));
        let w = frames.angular_velocity(&mut self.arena, f);
        let iw = crate::mechanics::frames::tensor_times(&mut self.arena, &inertia, &w);
        let wiw = self.dot(&w, &iw);
        terms.kinetic.push(self.arena.times(terms.half, wiw));
        Some(SpatialBody {
            frame: f,
            angular_velocity: w,
            inertia,
        })
    }
}
