//! The frames of a model file and the frames and points that other sections name.

use super::*;
use crate::model::elements::{body, frame, point, shape};

impl Checker<'_> {
    // Rule: frames have distinct names other than the ground `N` and `from`; each frame's
    // parent is `N` or a frame defined before it (so that frames form a tree); a point
    // written from another point names one defined before it, and its vectors known frames.
    pub(super) fn frames(&mut self) {
        let file = self.file;
        frame::rules(&file.frames, self);
        let frames = frame_names(file);
        point::origin_rules(&file.points, self);
        body::frame_rules(&file.bodies, self);
        for w in &file.draw.wheels {
            self.point(&w.centre);
            self.frame(&w.frame, &frames);
            self.resolve(&w.radius, Depends::Constant, "the radius of a drawn wheel");
        }
        shape::rules(&file.draw.shapes, self);
    }

    /// Reports `name` if it is not one of `frames`.
    pub(super) fn frame(&mut self, name: &Located<String>, frames: &[&str]) {
        if frames.contains(&name.value.as_str()) || self.incomplete.has_name(&name.value) {
            return;
        }
        let d = self.unknown_frame_message(name, frames);
        self.error(d);
    }

    /// "unknown frame", with the closest of `frames`.
    pub(super) fn unknown_frame_message(
        &self,
        name: &Located<String>,
        frames: &[&str],
    ) -> Diagnostic {
        let d = Diagnostic::new(name.location, format!("unknown frame `{}`", name.value));
        match closest(&name.value, frames) {
            Some(c) => d.with_help(format!("did you mean `{c}`?")),
            None => d.with_help(format!(
                "frames are: {} (the ground); declare one under `frames:`",
                frames.join(", ")
            )),
        }
    }

    /// Reports `name` if it is not a point.
    pub(super) fn point(&mut self, name: &Located<String>) {
        let n = name.value.as_str();
        if self.points.contains(&n)
            || self.incomplete.has_name(n)
            || self.section_lost("points", self.points.is_empty())
        {
            return;
        }
        let d = Diagnostic::new(name.location, format!("unknown point `{n}`"));
        let d = match closest(n, &self.points) {
            Some(c) => d.with_help(format!("did you mean `{c}`?")),
            None if self.points.is_empty() => d.with_help("declare it under `points:`"),
            None => d.with_help(format!("points are: {}", self.points.join(", "))),
        };
        self.error(d);
    }
}

/// The frames a model may name: its own, in file order, then the ground.
pub(super) fn frame_names(file: &ModelFile) -> Vec<&str> {
    (file.frames.iter())
        .map(|f| f.name.value.as_str())
        .chain([GROUND_FRAME])
        .collect()
}
