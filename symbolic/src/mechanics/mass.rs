//! Mass-matrix diagnostics (issue 8, item 2): a model whose mass matrix `M = ∂²T/∂q̇∂q̇ᵀ` is
//! singular cannot be integrated as `M q̈ = F`, so the macro and `eomgen check` refuse it with
//! the reason:
//!
//! - a coordinate without inertia (its row of `M` is identically zero), and whether it
//!   appears in no energy and no load at all;
//! - `M` singular at every one of 16 random states, drawn about the start as `eomgen check`
//!   draws them (a combination of rates that carries no kinetic energy, as
//!   `T = m (ẋ + ẏ)²/2`);
//! - `M` singular at the file's initial state (the coordinates' own singularity, as the
//!   horizontal-position coordinate of a pendulum at the horizontal).
//!
//! Models with constraints are not checked here: their `M` may be singular while the
//! constrained system `[M Jᵀ; J 0]` is not.

use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

use crate::expr::eval::Evaluator;
use crate::expr::{Symbol, SymbolKind};
use crate::model::diagnostic::Diagnostic;
use crate::model::file::ModelFile;
use crate::model::located::Location;

use super::{EquationsOfMotion, SymbolicModel};

/// Random states tried for "singular everywhere".
const STATES: usize = 16;

/// The largest diagonal entry of `m` in magnitude (`n × n`, row-major).
fn largest_diagonal(m: &[f64], n: usize) -> f64 {
    (0..n).map(|i| m[i * n + i].abs()).fold(0.0f64, f64::max)
}

/// Whether the symmetric `m` (`n × n`, row-major) is positive definite: every pivot of its
/// `L D Lᵀ` factorisation above `1e-12` of `reference`, or of its largest diagonal entry if
/// that is larger. A reference measured elsewhere (the size of `M` at other states) finds a
/// matrix that is small as a whole, as a 1 × 1 `M` near a singular configuration.
///
/// The factorisation works within the envelope of `m` (row `i` from its first non-zero entry
/// on): `L` has no entry left of it, so the terms left out are zeros, and the pivots are those
/// of the dense factorisation. A banded or diagonal `M` (a chain of masses) then costs `O(n)`
/// to `O(n b²)` instead of `n³/6`.
fn positive_definite(m: &[f64], n: usize, reference: f64) -> bool {
    // A zero, infinite or NaN scale fails every pivot below (`dj <= 0`, `dj <= ∞`, NaN).
    let scale = largest_diagonal(m, n).max(reference);
    // The first column of each row's envelope (a NaN counts as non-zero).
    let first: Vec<usize> = (0..n)
        .map(|i| (0..i).find(|&j| m[i * n + j] != 0.0).unwrap_or(i))
        .collect();
    let mut l = vec![0.0f64; n * n];
    let mut d = vec![0.0f64; n];
    for j in 0..n {
        let dj = m[j * n + j]
            - (first[j]..j)
                .map(|k| l[j * n + k].powi(2) * d[k])
                .sum::<f64>();
        if dj.is_nan() || dj <= 1e-12 * scale {
            return false;
        }
        d[j] = dj;
        for i in j + 1..n {
            if first[i] > j {
                continue;
            }
            let v = m[i * n + j]
                - (first[i].max(first[j])..j)
                    .map(|k| l[i * n + k] * l[j * n + k] * d[k])
                    .sum::<f64>();
            l[i * n + j] = v / dj;
        }
    }
    true
}

/// The diagnostics of a singular mass matrix of `eom` (derived from `file`); empty when `M`
/// is fine or the model has constraints.
pub fn mass_matrix_diagnostics(
    model: &SymbolicModel,
    eom: &EquationsOfMotion,
    file: &ModelFile,
) -> Vec<Diagnostic> {
    if !file.constraints.is_empty() || !file.nonholonomic.is_empty() || !file.rolling.is_empty() {
        return Vec::new();
    }
    let n = eom.num_dofs;
    let out = no_inertia_diagnostics(model, eom, file);
    if !out.is_empty() || n == 0 {
        return out;
    }
    numeric_diagnostics(model, eom, file)
}

/// One diagnostic per coordinate of `file` whose row of the mass matrix of `eom` is
/// identically zero (telling whether it appears in no energy and no load at all).
fn no_inertia_diagnostics(
    model: &SymbolicModel,
    eom: &EquationsOfMotion,
    file: &ModelFile,
) -> Vec<Diagnostic> {
    let n = eom.num_dofs;
    let arena = &model.arena;
    let mut out = Vec::new();
    for (i, coordinate) in file.coordinates.iter().enumerate().take(n) {
        if !(0..n).all(|j| arena.is_zero(eom.mass(i, j))) {
            continue;
        }
        let name = &coordinate.name.value;
        let [q, _, _] = model.coordinate_symbols(i);
        let unused = arena.is_zero(eom.forcing[i]) && !arena.depends_on(model.potential, q);
        let message = if unused {
            format!(
                "coordinate `{name}` appears in no energy and no load: its row of the mass matrix and its generalized force are zero"
            )
        } else {
            format!(
                "coordinate `{name}` has no inertia: the kinetic energy does not depend on `{name}_dot`, so the mass matrix is singular everywhere"
            )
        };
        out.push(Diagnostic::new(coordinate.name.location, message).with_help(
            "give it inertia (a body that moves with it, or a term in `kinetic`), or remove the coordinate",
        ));
    }
    out
}

/// The diagnostics of a mass matrix of `eom` singular at every random state tried or at the
/// initial state of `file` (for a model of at least one degree of freedom whose every
/// coordinate has inertia).
fn numeric_diagnostics(
    model: &SymbolicModel,
    eom: &EquationsOfMotion,
    file: &ModelFile,
) -> Vec<Diagnostic> {
    let n = eom.num_dofs;
    let arena = &model.arena;
    let mut out = Vec::new();
    // Numerically: at random states, then at the initial state.
    let symbols = arena.symbols().to_vec();
    // Each parameter's default at its symbol (not a search by name per symbol: a file of
    // many parameters would be quadratic).
    let defaults: Vec<(usize, f64)> = model
        .parameters
        .iter()
        .map(|p| (p.symbol.index(), p.default))
        .collect();
    let mut evaluator = Evaluator::new(arena, &eom.mass_matrix);
    let mut bindings = vec![0.0; symbols.len()];
    for &(k, v) in &defaults {
        bindings[k] = v;
    }
    let (regular, typical) = sample_mass_matrix(model, &symbols, &mut evaluator, &mut bindings, n);
    let first = file.coordinates.first().map(|c| c.name.location);
    if regular == 0 {
        if let Some(location) = first {
            out.push(singular_everywhere(file, location));
        }
        return out;
    }
    // The initial state: q from `initial:` (rates do not enter M), t = 0.
    let mut initial = Evaluator::new(arena, &model.initial_q);
    for (k, s) in symbols.iter().enumerate() {
        if matches!(
            s.kind,
            SymbolKind::Coordinate(_) | SymbolKind::Velocity(_) | SymbolKind::Time
        ) {
            bindings[k] = 0.0;
        }
    }
    let q0 = initial.eval(&bindings);
    for (i, &v) in q0.iter().enumerate().take(n) {
        let [q, _, _] = model.coordinate_symbols(i);
        bindings[q.index()] = v;
    }
    if !positive_definite(&evaluator.eval(&bindings), n, typical) {
        out.extend(singular_at_start(file, &q0, first));
    }
    out
}

/// Evaluates the `n × n` mass matrix (by `evaluator`) at [`STATES`] random states about the
/// start (drawn into `bindings`, which hold the parameters' defaults): the number of states
/// where it is positive definite, and the median of its largest diagonal entry there (0 if
/// none).
fn sample_mass_matrix(
    model: &SymbolicModel,
    symbols: &[Symbol],
    evaluator: &mut Evaluator,
    bindings: &mut [f64],
    n: usize,
) -> (usize, f64) {
    let state_box = model.state_box();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(0x6d61_7373);
    let mut regular = 0;
    let mut sizes = Vec::with_capacity(STATES);
    for _ in 0..STATES {
        for (k, s) in symbols.iter().enumerate() {
            match s.kind {
                SymbolKind::Coordinate(_) | SymbolKind::Velocity(_) => {
                    bindings[k] = state_box.at(k, rng.random_range(-2.0..2.0));
                }
                SymbolKind::Time => bindings[k] = rng.random_range(0.0..5.0),
                _ => {}
            }
        }
        let m = evaluator.eval(bindings);
        if positive_definite(&m, n, 0.0) {
            regular += 1;
            sizes.push(largest_diagonal(&m, n));
        }
    }
    // The typical size of M where it is regular: the reference at the initial state.
    sizes.sort_by(f64::total_cmp);
    let typical = sizes.get(sizes.len() / 2).copied().unwrap_or(0.0);
    (regular, typical)
}

/// The diagnostic, at `location`, of a mass matrix singular at every random state tried.
fn singular_everywhere(file: &ModelFile, location: Location) -> Diagnostic {
    let rates: Vec<String> = file
        .coordinates
        .iter()
        .map(|c| format!("`{}_dot`", c.name.value))
        .collect();
    Diagnostic::new(
        location,
        format!(
            "the mass matrix is singular at every state tried ({STATES} random states): some combination of {} carries no kinetic energy",
            rates.join(", ")
        ),
    )
    .with_help(
        "M = ∂²T/∂q̇∂q̇ must be positive definite; use independent coordinates, or make a dependent one a constraint",
    )
}

/// The diagnostic of a mass matrix singular or not finite at the initial coordinates `q0`,
/// at the first `initial:` entry of `file` or else at `first` (none without either).
fn singular_at_start(file: &ModelFile, q0: &[f64], first: Option<Location>) -> Option<Diagnostic> {
    let location = file
        .initial
        .first()
        .map(|(name, _)| name.location)
        .or(first);
    let location = location?;
    let point: Vec<String> = file
        .coordinates
        .iter()
        .zip(q0)
        .map(|(c, v)| format!("{} = {v}", c.name.value))
        .collect();
    Some(
        Diagnostic::new(
            location,
            format!(
                "the mass matrix is singular or not finite at the initial state ({})",
                point.join(", ")
            ),
        )
        .with_help(
            "the coordinates are singular there; start elsewhere, or choose coordinates that stay regular along the motion",
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Leading principal minors of a 3 × 3 matrix (Sylvester's criterion), computed by their
    /// determinant formulas: an independent test of positive definiteness.
    fn minors(m: &[f64]) -> [f64; 3] {
        let d2 = m[0] * m[4] - m[1] * m[3];
        let d3 = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6])
            + m[2] * (m[3] * m[7] - m[4] * m[6]);
        [m[0], d2, d3]
    }

    /// Against Sylvester's criterion on 2,000 random symmetric 3 × 3 matrices (entries in
    /// [−1, 1], diagonal shifted by [0, 2]), leaving out those within 1e-6 of the boundary.
    #[test]
    fn positive_definiteness_agrees_with_sylvester() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(9);
        let (mut yes, mut no) = (0, 0);
        for _ in 0..2000 {
            let mut m = [0.0; 9];
            for i in 0..3 {
                for j in i..3 {
                    let v = rng.random_range(-1.0..1.0);
                    m[i * 3 + j] = v;
                    m[j * 3 + i] = v;
                }
                m[i * 3 + i] += rng.random_range(0.0..2.0);
            }
            let d = minors(&m);
            if d.iter().any(|x| x.abs() < 1e-6) {
                continue;
            }
            let expected = d.iter().all(|x| *x > 0.0);
            assert_eq!(
                positive_definite(&m, 3, 0.0),
                expected,
                "{m:?}: minors {d:?}"
            );
            if expected {
                yes += 1;
            } else {
                no += 1;
            }
        }
        assert!(yes > 200 && no > 200, "{yes} {no}");
    }

    /// The bound is relative to the largest diagonal entry: a pivot of 1e-13 of it is
    /// singular, one of 1e-11 is not, at any overall scale; zero, NaN or infinite
    /// matrices are not positive definite.
    #[test]
    fn the_pivot_bound_is_relative() {
        for scale in [1e-20, 1.0, 1e20] {
            let diag = |a: f64, b: f64| [a * scale, 0.0, 0.0, b * scale];
            assert!(positive_definite(&diag(1.0, 1e-11), 2, 0.0), "{scale}");
            assert!(!positive_definite(&diag(1.0, 1e-13), 2, 0.0), "{scale}");
            assert!(!positive_definite(&diag(1e-13, 1.0), 2, 0.0), "{scale}");
        }
        assert!(!positive_definite(&[0.0; 4], 2, 0.0));
        assert!(!positive_definite(&[1.0, 0.0, 0.0, f64::NAN], 2, 0.0));
        assert!(!positive_definite(&[f64::INFINITY, 0.0, 0.0, 1.0], 2, 0.0));
        assert!(positive_definite(&[2.0], 1, 0.0));
        // Against a reference: 1e-13 of it is singular, 1e-11 is not.
        assert!(!positive_definite(&[1e-13], 1, 1.0));
        assert!(positive_definite(&[1e-11], 1, 1.0));
    }

    /// The factorisation within the envelope decides as the dense one does: on random
    /// symmetric 12 × 12 matrices, banded (bandwidth 2) and block-diagonal, diagonally
    /// shifted so that about half are positive definite, against a dense `L D Lᵀ` with the
    /// same pivot bound (matrices within 1e-6 of the bound left out).
    #[test]
    fn the_envelope_decides_as_the_dense_factorisation() {
        let n = 12;
        let dense = |m: &[f64]| -> f64 {
            let scale = largest_diagonal(m, n);
            let mut l = vec![0.0f64; n * n];
            let mut d = vec![0.0f64; n];
            let mut smallest = f64::INFINITY;
            for j in 0..n {
                let dj = m[j * n + j] - (0..j).map(|k| l[j * n + k].powi(2) * d[k]).sum::<f64>();
                smallest = smallest.min(dj / scale);
                if dj <= 1e-12 * scale {
                    return smallest;
                }
                d[j] = dj;
                for i in j + 1..n {
                    let v = m[i * n + j]
                        - (0..j)
                            .map(|k| l[i * n + k] * l[j * n + k] * d[k])
                            .sum::<f64>();
                    l[i * n + j] = v / dj;
                }
            }
            smallest
        };
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(12);
        let (mut yes, mut no) = (0, 0);
        for case in 0..2000 {
            let pattern = |i: usize, j: usize| {
                if case % 2 == 0 {
                    i.abs_diff(j) <= 2
                } else {
                    i / 4 == j / 4
                }
            };
            let mut m = vec![0.0; n * n];
            for i in 0..n {
                for j in 0..=i {
                    if pattern(i, j) {
                        let v = rng.random_range(-1.0..1.0);
                        m[i * n + j] = v;
                        m[j * n + i] = v;
                    }
                }
                m[i * n + i] += rng.random_range(0.0..4.0);
            }
            let smallest = dense(&m);
            if (smallest - 1e-12).abs() < 1e-6 {
                continue;
            }
            let expected = smallest > 1e-12;
            assert_eq!(positive_definite(&m, n, 0.0), expected, "{m:?}");
            if expected {
                yes += 1;
            } else {
                no += 1;
            }
        }
        assert!(yes > 100 && no > 100, "{yes} {no}");
    }
}
