//! A bound on the size of a derivation, with a located error in place of a run that would
//! not end in reasonable time and memory.
//!
//! The equations of a chain of 3-D frames each turning relative to a turning parent grew
//! exponentially with each nested rotation while expansion multiplied the rotations out:
//! `check` of a chain of single-axis hinges took 0.4, 2.2 and 24 s for 6, 7 and 8 of them,
//! and a 10-hinge chain did not end (2026-11-26). The expansion's caps
//! ([`crate::expr::ExprArena::expand_time_varying`], `expr/expand.rs`) now keep such
//! rotations nested: 6, 8 and 10 hinges check in 0.03–0.06 s and 16 in 0.3 s, and three
//! bodies in relative z-x-z rotations with an asymmetric inertia in 0.02 s where they took
//! 8.3 s
//! (docs/performance.md, "Derivations of 3-D chains"). The bound stays, as a
//! guard for what the caps do not catch: each derivation (Lagrange's, momentum balance, …)
//! may build [`DERIVATION_OPERAND_LIMIT`] operands. What comes after a derivation (the
//! plans, the native code, the Jacobians that `modes` and the implicit methods derive when
//! first used) is not bounded here.

use super::SymbolicModel;
use crate::model::diagnostic::Diagnostic;
use crate::model::file::ModelFile;

/// The operands a model's derivations may build ([`crate::expr::ExprArena::limit_operands`]):
/// about half a gigabyte of expressions, and about a minute of processor time for the
/// models that reach it.
pub const DERIVATION_OPERAND_LIMIT: u64 = 40_000_000;

/// Bounds the derivation of `model` that starts now to [`DERIVATION_OPERAND_LIMIT`]
/// operands more than the arena holds; call [`finish_derivation`] once it is done (before
/// another is bounded).
pub fn limit_derivation(model: &mut SymbolicModel) {
    let now = model.arena.operands();
    model
        .arena
        .limit_operands(Some(now.saturating_add(DERIVATION_OPERAND_LIMIT)));
}

/// After the derivations begun under [`limit_derivation`]: lifts the limit, or, if it was
/// passed (the expressions built are then meaningless), the located error that says so,
/// at the frame nested deepest.
///
/// # Errors
/// One diagnostic when the limit was passed.
pub fn finish_derivation(
    model: &mut SymbolicModel,
    file: &ModelFile,
) -> Result<(), Vec<Diagnostic>> {
    if !model.arena.over_limit() {
        model.arena.limit_operands(None);
        return Ok(());
    }
    let limit = format!(
        "the equations grew past {} million expression operands and their derivation was stopped",
        DERIVATION_OPERAND_LIMIT / 1_000_000
    );
    // The frame reached through the most rotations from the ground.
    let deepest = file
        .frames
        .iter()
        .map(|f| (chain(file, &f.name.value), f))
        .max_by_key(|(chain, _)| chain.iter().map(|(_, r)| r).sum::<usize>());
    let diagnostic = match deepest {
        Some((chain, frame)) if chain.iter().map(|(_, r)| r).sum::<usize>() > 1 => {
            let rotations: usize = chain.iter().map(|(_, r)| r).sum();
            let path: Vec<&str> = chain.iter().map(|(name, _)| name.as_str()).collect();
            Diagnostic::new(
                frame.name.location,
                format!(
                    "{limit}: frame `{}` is reached from N through {rotations} rotations nested in {} frame(s) (N → {}), and the equations of nested rotations grow steeply with each one",
                    frame.name.value,
                    chain.len(),
                    path.join(" → ")
                ),
            )
            .with_help(
                "frames given their angles relative to N (`parent: N`) keep the equations shallower; a chain of 16 single-axis hinges each relative to the one before derives in well under a second",
            )
        }
        _ => {
            let location = file
                .coordinates
                .first()
                .map(|c| c.name.location)
                .unwrap_or_default();
            Diagnostic::new(location, limit).with_help(
                "a model of this size needs fewer coordinates, or fewer bodies coupled to each other",
            )
        }
    };
    Err(vec![diagnostic])
}

/// The frames from the ground to `name`, outermost first, each with its number of rotations
/// (a parent that is not a frame of the file, the ground, ends it; a cycle, which the file's
/// checks refuse, is cut).
fn chain(file: &ModelFile, name: &str) -> Vec<(String, usize)> {
    let mut out = Vec::new();
    let mut current = name;
    while let Some(frame) = file.frames.iter().find(|f| f.name.value == current) {
        if out.len() > file.frames.len() {
            break;
        }
        out.push((frame.name.value.clone(), frame.rotations.len()));
        current = &frame.parent.value;
    }
    out.reverse();
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::{Formulation, Lagrange};

    /// A chain of `n` bodies, each frame turning about x or y relative to the one before.
    fn chain(n: usize) -> String {
        let mut s = format!(
            "name: chain\ndescription: A chain in relative rotations.\nparameters: {{ m: 1.0, l: 1.0, g: 9.81, I: 0.1 }}\ncoordinates: [{}]\nframes:\n",
            (1..=n)
                .map(|i| format!("q{i}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
        for i in 1..=n {
            let parent = if i == 1 {
                "N".to_string()
            } else {
                format!("B{}", i - 1)
            };
            let axis = if i % 2 == 1 { "x" } else { "y" };
            s += &format!("  B{i}: {{ parent: {parent}, axes: {axis}, angles: [q{i}] }}\n");
        }
        s += "points:\n  P0: [0, 0, 0]\n";
        for i in 1..=n {
            s += &format!("  P{i}: {{ from: P{}, B{i}: [0, 0, -l] }}\n", i - 1);
        }
        s += "bodies:\n";
        for i in 1..=n {
            s += &format!("  b{i}: {{ mass: m, com: P{i}, frame: B{i}, inertia: [I, I, I] }}\n");
        }
        s + "gravity: [0, 0, -g]\ninitial: { q1: 0.1 }\n"
    }

    /// Past its limit a derivation ends with a located error at the frame nested deepest,
    /// naming the chain; under it the limit is lifted and the equations are the unlimited
    /// derivation's. (A limit of 2,000 operands more than the lowering's on a 4-body chain;
    /// `DERIVATION_OPERAND_LIMIT` itself stops a 10-level chain after about 11 s, which is
    /// not run here.)
    #[test]
    fn a_derivation_past_its_limit_is_a_located_error_at_the_deepest_frame() {
        let source = chain(4);
        let file = crate::model::load("chain.yaml", &source).unwrap();
        let mut model = SymbolicModel::from_file(&file).unwrap();
        // The lowering's operands and 2,000 more.
        model
            .arena
            .limit_operands(Some(model.arena.operands() + 2_000));
        let _ = Lagrange.derive(&mut model);
        assert!(model.arena.over_limit());
        let errors = finish_derivation(&mut model, &file).unwrap_err();
        assert_eq!(errors.len(), 1);
        let e = &errors[0];
        assert_eq!(
            (e.location.line, e.location.column),
            (9, 3),
            "{}",
            e.message
        );
        assert!(
            e.message.contains("`B4`")
                && e.message
                    .contains("4 rotations nested in 4 frame(s) (N → B1 → B2 → B3 → B4)"),
            "{}",
            e.message
        );

        let mut limited = SymbolicModel::from_file(&file).unwrap();
        limit_derivation(&mut limited);
        let a = Lagrange.derive(&mut limited);
        finish_derivation(&mut limited, &file).unwrap();
        assert!(!limited.arena.over_limit());
        let mut free = SymbolicModel::from_file(&file).unwrap();
        let b = Lagrange.derive(&mut free);
        let printed = |m: &SymbolicModel, e: &crate::mechanics::EquationsOfMotion| {
            e.mass_matrix
                .iter()
                .chain(&e.forcing)
                .map(|&x| {
                    crate::expr::print::Printer::new(&m.arena, crate::expr::print::Syntax::Text)
                        .print(x)
                })
                .collect::<Vec<_>>()
        };
        assert_eq!(printed(&limited, &a), printed(&free, &b));
    }
}
