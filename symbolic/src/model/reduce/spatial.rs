//! The sections of 3-D models and of constraints on the kinematics, as the writer emits them:
//! `frames:`, points written in frames or as wheel contacts, 3-D bodies, forces and torques in
//! frames, constraints on points, `nonholonomic:` (expressions and rolling contacts) and drawn
//! wheels. Each entry is written in the form the schema reads (`super::super::schema`), its
//! expressions through [`Reducer::rewrite`].

use super::*;
use crate::model::Located;
use crate::model::file::{
    Axis, Frame, GROUND_FRAME, InertiaTensor, Point, RelativePosition, RollingContact, WheelContact,
};

/// `[x, y]` of axes.
fn axes_list(axes: &[Axis]) -> String {
    let letters: Vec<String> = axes.iter().map(|a| a.letter().to_string()).collect();
    format!("[{}]", letters.join(", "))
}

/// `, in: F` for a frame other than the ground's, else nothing.
pub(super) fn in_frame(frame: Option<&Located<String>>) -> String {
    match frame {
        Some(f) if f.value != GROUND_FRAME => format!(", in: {}", f.value),
        _ => String::new(),
    }
}

impl Reducer<'_> {
    /// `frames:`, each as its successive rotations about the newest frame's axes (a frame
    /// written `about: parent` was read into that order, which gives the same orientation).
    pub(super) fn write_frames(&mut self, w: &mut String) -> Result<(), ReduceError> {
        use std::fmt::Write as _;
        if self.file.frames.is_empty() {
            return Ok(());
        }
        let _ = writeln!(w, "frames:");
        for frame in &self.file.frames {
            let text = self.frame_text(frame)?;
            let _ = writeln!(w, "  {}: {text}", frame.name.value);
        }
        Ok(())
    }

    fn frame_text(&mut self, frame: &Frame) -> Result<String, ReduceError> {
        let place = format!("frame `{}`", frame.name.value);
        let angles = frame
            .rotations
            .iter()
            .map(|r| self.rewrite(&r.angle, &place))
            .collect::<Result<Vec<_>, _>>()?;
        let axes: String = frame
            .rotations
            .iter()
            .map(|r| r.axis.value.letter())
            .collect();
        Ok(match angles.as_slice() {
            [angle] => format!(
                "{{ parent: {}, axis: {axes}, angle: {} }}",
                frame.parent.value,
                flow(angle)
            ),
            _ => format!(
                "{{ parent: {}, axes: {axes}, angles: {} }}",
                frame.parent.value,
                list(&angles)
            ),
        })
    }

    /// A point's value: its components, the point plus vectors in frames, or a wheel contact.
    pub(super) fn point_text(&mut self, p: &Point) -> Result<String, ReduceError> {
        let place = format!("point `{}`", p.name.value);
        if let Some(wheel) = &p.wheel {
            return Ok(format!("{{ wheel: {} }}", self.wheel_text(wheel, &place)?));
        }
        if let Some(RelativePosition { from, vectors }) = &p.relative {
            let mut parts = Vec::new();
            if let Some(from) = from {
                parts.push(format!("from: {}", from.value));
            }
            for (frame, vector) in vectors {
                let components = vector
                    .iter()
                    .map(|e| self.rewrite(e, &place))
                    .collect::<Result<Vec<_>, _>>()?;
                parts.push(format!("{}: {}", frame.value, list(&components)));
            }
            return Ok(format!("{{ {} }}", parts.join(", ")));
        }
        let parts = p
            .position
            .iter()
            .map(|e| self.rewrite(e, &place))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(list(&parts))
    }

    /// `{ centre: G, frame: R, axle: y, radius: r }`.
    fn wheel_text(&mut self, wheel: &WheelContact, place: &str) -> Result<String, ReduceError> {
        let radius = self.rewrite(&wheel.radius, place)?;
        Ok(format!(
            "{{ centre: {}, frame: {}, axle: {}, radius: {} }}",
            wheel.centre.value,
            wheel.frame.value,
            wheel.axle.value.letter(),
            flow(&radius)
        ))
    }

    /// A 3-D body: `{ mass: m, com: G, frame: B, inertia: … }`, the inertia as three moments
    /// when its products are not written, else as the map of the entries written.
    pub(super) fn spatial_body_text(
        &mut self,
        place: &str,
        (mass, com, frame, inertia): (&Expr, &str, &str, &InertiaTensor),
    ) -> Result<String, ReduceError> {
        let mass = self.rewrite(mass, place)?;
        let mut entries = Vec::new();
        for (key, entry) in InertiaTensor::KEYS.iter().zip(&inertia.entries) {
            if let Some(e) = entry {
                entries.push((*key, self.rewrite(e, place)?));
            }
        }
        let principal = inertia.entries[3..].iter().all(Option::is_none)
            && inertia.entries[..3].iter().all(Option::is_some);
        let inertia = if principal {
            let moments: Vec<String> = entries.into_iter().map(|(_, e)| e).collect();
            list(&moments)
        } else {
            let parts: Vec<String> = entries
                .into_iter()
                .map(|(k, e)| format!("{k}: {}", flow(&e)))
                .collect();
            format!("{{ {} }}", parts.join(", "))
        };
        Ok(format!(
            "{{ mass: {}, com: {com}, frame: {frame}, inertia: {inertia} }}",
            flow(&mass)
        ))
    }

    /// The constraints on points of `constraints:`, one line each.
    pub(super) fn point_constraint_lines(&self, w: &mut String) {
        use std::fmt::Write as _;
        for c in &self.file.point_constraints {
            let _ = writeln!(
                w,
                "  {}: {{ point: {}, along: {}{} }}",
                c.name.value,
                c.point.value,
                c.along.value.letter(),
                in_frame(c.frame.as_ref())
            );
        }
    }

    /// `nonholonomic:`: the constraints written as expressions, then the rolling contacts.
    pub(super) fn write_nonholonomic(&mut self, w: &mut String) -> Result<(), ReduceError> {
        use std::fmt::Write as _;
        let file = self.file;
        if file.nonholonomic.is_empty() && file.rolling.is_empty() {
            return Ok(());
        }
        let _ = writeln!(w, "nonholonomic:");
        for (name, e) in &file.nonholonomic {
            let place = format!("non-holonomic constraint `{}`", name.value);
            let text = self.rewrite(e, &place)?;
            let _ = writeln!(w, "  {}: {}", name.value, flow(&text));
        }
        for RollingContact {
            name,
            body,
            point,
            along,
            frame,
        } in &file.rolling
        {
            let axes: Vec<Axis> = along.iter().map(|a| a.value).collect();
            let _ = writeln!(
                w,
                "  {}: {{ body: {}, point: {}, along: {}{} }}",
                name.value,
                body.value,
                point.value,
                axes_list(&axes),
                in_frame(frame.as_ref())
            );
        }
        Ok(())
    }

    /// `wheels: [...]` of `draw:`, if any.
    pub(super) fn drawn_wheels(&mut self) -> Result<Option<String>, ReduceError> {
        if self.file.draw.wheels.is_empty() {
            return Ok(None);
        }
        let mut wheels = Vec::new();
        for wheel in &self.file.draw.wheels {
            wheels.push(self.wheel_text(wheel, "`draw: wheels:`")?);
        }
        Ok(Some(format!("wheels: [{}]", wheels.join(", "))))
    }
}
