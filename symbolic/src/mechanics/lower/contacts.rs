//! The lowering of wheel contacts (`points:` on a rolling wheel), with what they draw (rolling
//! contacts, `nonholonomic:` entries: `model/elements/nonholonomic.rs`).

use super::*;

impl Lowering<'_> {
    /// A wheel's contact point: its centre less the radius along the unit vector of the
    /// wheel's plane (normal to the axle `a`) nearest the ground frame's `z`:
    /// `r_C = r_centre − r (n − (n·a) a)/|n − (n·a) a|`, `n = N.z`, computed in the wheel
    /// frame's components (where `a` is a unit axis and the projection drops one component)
    /// and carried into the ground frame's.
    pub(super) fn wheel_contact(
        &mut self,
        wheel: &crate::model::file::WheelContact,
        points: &Points,
        frames: &Frames,
    ) -> Vec<ExprId> {
        let (Some(centre), Some(frame)) = (
            point(points, &wheel.centre.value),
            frames.index(&wheel.frame.value),
        ) else {
            self.errors.push(Diagnostic::new(
                wheel.centre.location,
                "a wheel contact names an unknown point or frame",
            ));
            return vec![self.arena.int(0); 3];
        };
        let (zero, one) = (self.arena.int(0), self.arena.int(1));
        let mut n = frames.express(&mut self.arena, [zero, zero, one], 0, frame);
        n[wheel.axle.value.index()] = zero;
        let n2 = self.dot(&n, &n);
        // The wheel's plane has no direction nearest the ground's z when its axle is that z
        // in every configuration (a disc lying flat): `r/|n|` times components that are all 0
        // would put the contact point at the centre, silently.
        if self.arena.is_zero(n2) {
            self.errors.push(
                Diagnostic::new(
                    wheel.axle.location,
                    format!(
                        "the wheel centred at `{}` has its axle `{}` of frame `{}` along the ground's z in every configuration: a wheel lying flat has no lowest point of its rim",
                        wheel.centre.value,
                        wheel.axle.value.letter(),
                        wheel.frame.value
                    ),
                )
                .with_help("a wheel contact needs an axle that is not vertical (the axle `y` of a frame that leans and steers); for a disc sliding flat, write its contact point directly"),
            );
            return vec![zero; 3];
        }
        let length = self.arena.sqrt(n2);
        let radius = self.expr(&wheel.radius);
        let scale = self.arena.divide(radius, length);
        let down = n.map(|c| {
            let t = self.arena.times(scale, c);
            self.arena.neg(t)
        });
        let down = frames.express(&mut self.arena, down, frame, 0);
        points[centre]
            .1
            .iter()
            .zip(down)
            .map(|(c, d)| self.arena.plus(*c, d))
            .collect()
    }

    /// Points on the rim of a drawn wheel (every 15°, named `<centre>.rim<k>`, added after the
    /// file's points) and the segments that draw it: the rim and four spokes, which turn
    /// with the wheel's frame.
    pub(super) fn drawn_wheel(
        &mut self,
        wheel: &crate::model::file::WheelContact,
        points: &mut Points,
        frames: &Frames,
    ) -> Vec<[usize; 2]> {
        const RIM: usize = 24;
        let (Some(centre), Some(frame)) = (
            point(points, &wheel.centre.value),
            frames.index(&wheel.frame.value),
        ) else {
            return Vec::new();
        };
        let axle = wheel.axle.value.index();
        let (u, v) = ((axle + 1) % 3, (axle + 2) % 3);
        let radius = self.expr(&wheel.radius);
        let zero = self.arena.int(0);
        let first = points.len();
        for k in 0..RIM {
            let angle = std::f64::consts::TAU * k as f64 / RIM as f64;
            let mut r = [zero; 3];
            for (slot, f) in [(u, angle.cos()), (v, angle.sin())] {
                let c = self
                    .arena
                    .constant(Constant::float(f).unwrap_or(Constant::ZERO));
                r[slot] = self.arena.times(radius, c);
            }
            let r = frames.express(&mut self.arena, r, frame, 0);
            let position: Vec<ExprId> = points[centre]
                .1
                .iter()
                .zip(r)
                .map(|(a, b)| self.arena.plus(*a, b))
                .collect();
            points.push((format!("{}.rim{k}", wheel.centre.value), position));
        }
        (0..RIM)
            .map(|k| [first + k, first + (k + 1) % RIM])
            .chain((0..4).map(|s| [centre, first + s * RIM / 4]))
            .collect()
    }
}
