//! The lowering of `bodies:` and of the energies written in the file into the terms of `T`
//! and `V`.

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
