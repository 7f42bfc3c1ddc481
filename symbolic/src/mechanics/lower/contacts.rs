//! What a drawn wheel (`draw: wheels:`) draws (wheel contact points: `model/elements/point.rs`;
//! rolling contacts, `nonholonomic:` entries: `model/elements/nonholonomic.rs`).

use super::*;

impl Lowering<'_> {
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
