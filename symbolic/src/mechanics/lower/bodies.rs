//! The lowering of `bodies:` and of the energies written in the file into the terms of `T`
//! and `V`.

use super::*;
use crate::model::elements::energy;

impl Lowering<'_> {
    /// The energies and generalized forces written as such (`elements::energy`).
    pub(super) fn energies_written(&mut self, terms: &mut Terms, coordinate_names: &[String]) {
        let file = self.file;
        let lowered = energy::lower(file.written_energies(), coordinate_names, self);
        terms.kinetic.extend(lowered.kinetic);
        terms.potential.extend(lowered.potential);
        for (i, q) in lowered.forces {
            terms.forces[i].push(q);
        }
    }

    /// Bodies (`elements::body`): their terms of `T` and, with gravity, of `V`. Returns
    /// what the derivations read of them.
    pub(super) fn bodies(
        &mut self,
        gravity: Option<&[ExprId]>,
        terms: &mut Terms,
    ) -> Vec<BodyInfo> {
        let file = self.file;
        let mut infos = Vec::new();
        for body in &file.bodies {
            if let Some(lowered) = body.lower(gravity, terms.half, self) {
                terms.kinetic.extend(lowered.kinetic);
                terms.potential.extend(lowered.potential);
                infos.push(lowered.info);
            }
        }
        infos
    }
}
