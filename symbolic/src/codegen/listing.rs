//! The equations of motion as a reader sees them: `eomgen equations` (text, LaTeX, JSON) and
//! the `equations_text`/`equations_latex` of every generated model.
//!
//! A constrained model's equations are the ones the runtime solves,
//!
//! ```text
//! M(q, t) q̈ + Jᵀ(q, t) λ = F(q, q̇, t),     J q̈ = γ(q, q̇, t),
//! ```
//!
//! with `λ` the Lagrange multipliers (the constraint forces, in the sign of the runtime's
//! `lagrange_multipliers`), each holonomic constraint `Φ(q, t) = 0` with its row `J = ∂Φ/∂q`
//! and each non-holonomic one `A(q, t) q̇ + b = 0` with its row `J = A` (docs/model-format.md,
//! *Constraints*; lectures 8–10 of the course, method II.1).

use std::fmt::Write as _;

use crate::expr::print::{Printer, Syntax};
use crate::expr::{ExprId, SymbolKind};
use crate::mechanics::{EquationsOfMotion, SymbolicModel};

/// Whether a constraint restricts positions or only velocities.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ConstraintKind {
    /// `Φ(q, t) = 0`.
    Holonomic,
    /// `A(q, t) q̇ + b(q, t) = 0`, linear in the rates.
    Nonholonomic,
}

/// One constraint as printed: its equation, its row of the constraint Jacobian and its `γ`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ConstraintListing {
    /// The constraint's name in the file.
    pub name: String,
    /// Holonomic or non-holonomic.
    pub kind: ConstraintKind,
    /// The expression that is zero: `Φ(q, t)`, or `A q̇ + b`.
    pub equation: String,
    /// Its row of the constraint Jacobian `J` (length `n`): `∂Φ/∂qⱼ`, or `Aⱼ`.
    pub jacobian: Vec<String>,
    /// `γ` of `J q̈ = γ` (the constraint differentiated once more in time, minus its
    /// acceleration terms).
    pub gamma: String,
}

/// A unilateral contact as printed: its gap, the gap's row `G` and its coefficients.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ContactListing {
    /// The contact's name in the file.
    pub name: String,
    /// The gap `g(q, t) ≥ 0` (m).
    pub gap: String,
    /// Its row `G = ∂g/∂q` (length `n`), the direction of its normal impulse `Gᵀ Λ_N`.
    pub jacobian: Vec<String>,
    /// Newton's coefficient of restitution `e`.
    pub restitution: String,
    /// Coulomb's friction coefficient `μ` (`0` for a frictionless contact).
    pub friction: String,
    /// For a change of support, the coordinates after it (`R(q)`, one per coordinate), and
    /// where it lands (`when`, `1` when the file gives none); left out of the JSON otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub support: Option<SupportListing>,
}

/// A change of support as `equations` prints it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SupportListing {
    /// The coordinates after the change, in coordinate order.
    pub relabel: Vec<String>,
    /// Where a strike lands (positive).
    pub when: String,
}

/// A generalized force that is not zero.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct GeneralizedForce {
    /// The coordinate it acts on.
    pub coordinate: String,
    /// `Q` for that coordinate (N or N·m).
    pub expression: String,
}

/// The equations of motion of a model printed in one syntax ([`Syntax::Text`] parses back
/// with the model parser; [`Syntax::Latex`] for documents).
///
/// # Shapes
/// `n` coordinates and `m` constraints: `mass_matrix` is `n × n` (rows), `forcing` has `n`
/// entries, `constraints` `m` (holonomic first).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EquationsListing {
    /// The generalized coordinates `q`, in order.
    pub coordinates: Vec<String>,
    /// The kinetic energy `T` (J).
    pub kinetic_energy: String,
    /// The potential energy `V` (J).
    pub potential_energy: String,
    /// The generalized forces that are not zero.
    pub generalized_forces: Vec<GeneralizedForce>,
    /// `M(q, t)`, by rows.
    pub mass_matrix: Vec<Vec<String>>,
    /// `F(q, q̇, t)`.
    pub forcing: Vec<String>,
    /// The constraints, holonomic then non-holonomic; empty for an unconstrained model, whose
    /// equations are `M q̈ = F`.
    pub constraints: Vec<ConstraintListing>,
    /// The unilateral contacts (`contacts:`); left out of the JSON when there are none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub contacts: Vec<ContactListing>,
    /// The generalized speeds `u` (`speeds:`), in order; left out of the JSON when the state
    /// holds the rates, whose equations are `M q̈ = F`. With speeds they are `M u̇ = F`.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub speeds: Vec<String>,
    /// With speeds, the kinematic equations `q̇ⱼ = …` in `q`, `u` and `t`, one per
    /// coordinate; left out of the JSON otherwise.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub kinematic_equations: Vec<String>,
}

impl EquationsListing {
    /// Prints the equations `eom` of `model` in `syntax`.
    pub fn of(model: &SymbolicModel, eom: &EquationsOfMotion, syntax: Syntax) -> Self {
        let p = Printer::for_display(&model.arena, syntax);
        let n = eom.num_dofs;
        let c = &model.constraints;
        let constraints = (0..c.len())
            .map(|k| {
                let holonomic = k < c.holonomic;
                ConstraintListing {
                    name: c.names[k].clone(),
                    kind: if holonomic {
                        ConstraintKind::Holonomic
                    } else {
                        ConstraintKind::Nonholonomic
                    },
                    equation: p.print(if holonomic { c.phi[k] } else { c.velocity[k] }),
                    jacobian: (0..n).map(|j| p.print(c.jacobian[k * n + j])).collect(),
                    gamma: p.print(c.gamma[k]),
                }
            })
            .collect();
        Self {
            coordinates: model.coordinate_names.clone(),
            kinetic_energy: p.print(model.kinetic),
            potential_energy: p.print(model.potential),
            generalized_forces: model
                .generalized_forces
                .iter()
                .enumerate()
                .filter(|(_, q)| !model.arena.is_zero(**q))
                .map(|(i, q)| GeneralizedForce {
                    coordinate: model.coordinate_names[i].clone(),
                    expression: p.print(*q),
                })
                .collect(),
            mass_matrix: (0..n)
                .map(|i| (0..n).map(|j| p.print(eom.mass(i, j))).collect())
                .collect(),
            forcing: eom.forcing.iter().map(|f| p.print(*f)).collect(),
            constraints,
            contacts: (model.contacts.iter())
                .map(|c| ContactListing {
                    name: c.name.clone(),
                    gap: p.print(c.gap),
                    jacobian: c.jacobian.iter().map(|g| p.print(*g)).collect(),
                    restitution: p.print(c.restitution),
                    friction: p.print(c.friction),
                    support: c.support.as_ref().map(|s| SupportListing {
                        relabel: s.relabel.iter().map(|r| p.print(*r)).collect(),
                        when: p.print(s.when),
                    }),
                })
                .collect(),
            speeds: model.speeds.iter().flat_map(|s| s.names.clone()).collect(),
            kinematic_equations: (model.speeds.iter())
                .flat_map(|s| s.kinematic_equations.iter().map(|e| p.print(*e)))
                .collect(),
        }
    }
}

/// `eom` and `model`'s energies, generalized forces, constraint and contact expressions in
/// the forms a person reads ([`crate::expr::ExprArena::readable`]: multiplied out where that
/// cancels, `sin² + cos² = 1`, common factors pulled out; each the shorter of that and the
/// written form), for the listings, within a budget of arena growth
/// ([`crate::expr::ExprArena::readable_within`]): the values are unchanged, and `model` is then
/// for printing only (its expressions are no longer the shapes the code generator shares).
pub fn readable_equations(model: &mut SymbolicModel, eom: &EquationsOfMotion) -> EquationsOfMotion {
    let arena = &mut model.arena;
    let start = arena.len();
    let each = |arena: &mut crate::expr::ExprArena, v: &mut Vec<ExprId>| {
        for x in v.iter_mut() {
            *x = arena.readable_within(*x, start);
        }
    };
    let mut mass_matrix = eom.mass_matrix.clone();
    let mut forcing = eom.forcing.clone();
    each(arena, &mut mass_matrix);
    each(arena, &mut forcing);
    each(arena, &mut model.generalized_forces);
    let c = &mut model.constraints;
    for v in [&mut c.phi, &mut c.jacobian, &mut c.velocity, &mut c.gamma] {
        each(arena, v);
    }
    for contact in &mut model.contacts {
        each(arena, &mut contact.jacobian);
        contact.gap = arena.readable_within(contact.gap, start);
    }
    if let Some(speeds) = &mut model.speeds {
        each(arena, &mut speeds.kinematic_equations);
    }
    model.kinetic = arena.readable_within(model.kinetic, start);

    model.potential = arena.readable_within(model.potential, start);
    EquationsOfMotion {
        num_dofs: eom.num_dofs,
        mass_matrix,
        forcing,
    }
}

/// The equations as text: `q` (with generalized speeds, `u` and the kinematic equations
/// `q̇ = W u`), `T`, `V`, `Q`, then `M` (upper triangle) and `F` entry by entry; for a constrained model `M q'' + J^T lambda = F` and `J q'' = gamma` with the
/// non-zero entries of `J`, each `γ`, and each constraint's equation.
pub fn equations_text(model: &SymbolicModel, eom: &EquationsOfMotion) -> String {
    let e = EquationsListing::of(model, eom, Syntax::Text);
    let n = e.coordinates.len();
    let mut s = String::new();
    let _ = writeln!(s, "q = [{}]", e.coordinates.join(", "));
    let rate = if e.speeds.is_empty() {
        "q''"
    } else {
        let _ = writeln!(s, "u = [{}]", e.speeds.join(", "));
        let form = if model.speeds_have_offsets() {
            "q' = W(q, t) (u - Z(q, t))"
        } else {
            "q' = W(q, t) u"
        };
        if let Some(sp) = model.speeds.as_ref().filter(|sp| sp.on_the_constraints) {
            let (independent, auxiliary) = e.speeds.split_at(e.speeds.len() - sp.auxiliary);
            let _ = writeln!(
                s,
                "on the constraints: the auxiliary speeds {} at 0, where the rows of {} are Kane's equations of the independent speeds",
                auxiliary.join(", "),
                independent.join(", ")
            );
        }
        let _ = writeln!(s, "{form} (the kinematic equations) with");
        for (q, k) in e.coordinates.iter().zip(&e.kinematic_equations) {
            let _ = writeln!(s, "  {q}' = {k}");
        }
        "u'"
    };
    let _ = writeln!(s, "T = {}", e.kinetic_energy);
    let _ = writeln!(s, "V = {}", e.potential_energy);
    for q in &e.generalized_forces {
        let _ = writeln!(s, "Q[{}] = {}", q.coordinate, q.expression);
    }
    if e.constraints.is_empty() {
        let _ = writeln!(s, "M {rate} = F with");
    } else {
        let names: Vec<&str> = e.constraints.iter().map(|c| c.name.as_str()).collect();
        let _ = writeln!(
            s,
            "M {rate} + J^T lambda = F and J {rate} = gamma, lambda = [{}] (the constraint forces), with",
            names.join(", ")
        );
    }
    // With speeds, `J`'s columns are the speeds'; a non-holonomic row is then its auxiliary
    // speed, held at 0 (Kane's equations of the independent speeds are the rows above at 0).
    let columns = if e.speeds.is_empty() {
        &e.coordinates
    } else {
        &e.speeds
    };
    for (i, row) in e.mass_matrix.iter().enumerate() {
        for (j, m) in row.iter().enumerate().skip(i) {
            let _ = writeln!(s, "  M[{i},{j}] = {m}");
        }
    }
    for (i, f) in e.forcing.iter().enumerate() {
        let _ = writeln!(s, "  F[{i}] = {f}");
    }
    for c in &e.constraints {
        for (j, entry) in c.jacobian.iter().enumerate() {
            if entry != "0" {
                let _ = writeln!(s, "  J[{},{}] = {entry}", c.name, columns[j]);
            }
        }
        let _ = writeln!(s, "  gamma[{}] = {}", c.name, c.gamma);
    }
    if !e.constraints.is_empty() {
        let _ = writeln!(s, "where");
        for c in &e.constraints {
            let what = match c.kind {
                ConstraintKind::Holonomic => "holonomic: Phi(q, t) = 0",
                ConstraintKind::Nonholonomic if !e.speeds.is_empty() => {
                    "non-holonomic: its auxiliary speed A q' + b, held at 0"
                }
                ConstraintKind::Nonholonomic => "non-holonomic: A q' + b = 0",
            };
            let _ = writeln!(s, "  {}: {} = 0 ({what})", c.name, c.equation);
        }
    }
    if !e.contacts.is_empty() {
        let _ = writeln!(
            s,
            "contacts (unilateral: g >= 0; an impact where g = 0 and g' < 0, impulse G^T Lambda_N)"
        );
        for c in &e.contacts {
            let _ = writeln!(s, "  g[{}] = {}", c.name, c.gap);
            for (j, entry) in c.jacobian.iter().enumerate() {
                if entry != "0" {
                    let _ = writeln!(s, "  G[{},{}] = {entry}", c.name, e.coordinates[j]);
                }
            }
            let _ = writeln!(
                s,
                "  e[{}] = {}, mu[{}] = {}",
                c.name, c.restitution, c.name, c.friction
            );
            if let Some(support) = &c.support {
                let after: Vec<String> = (e.coordinates.iter().zip(&support.relabel))
                    .map(|(q, r)| format!("{q} -> {r}"))
                    .collect();
                let _ = writeln!(
                    s,
                    "  {} changes the support where {} > 0: the landing foot sticks, the stance foot leaves, {}",
                    c.name,
                    support.when,
                    after.join(", ")
                );
            }
        }
    }
    debug_assert!(e.mass_matrix.len() == n);
    s
}

/// The equations as LaTeX (`amsmath`): `T`, `V` and `M(q) q̈ = F`; for a constrained model
/// `M q̈ + Jᵀλ = F`, `J q̈ = γ` and each constraint's equation `= 0`.
pub fn equations_latex(model: &SymbolicModel, eom: &EquationsOfMotion) -> String {
    let e = EquationsListing::of(model, eom, Syntax::Latex);
    let p = Printer::for_display(&model.arena, Syntax::Latex);
    let n = e.coordinates.len();
    let bmatrix = |rows: &[String]| {
        format!(
            "\\begin{{bmatrix}} {} \\end{{bmatrix}}",
            rows.join(" \\\\ ")
        )
    };
    let mut s = String::new();
    // With generalized speeds, the kinematic equations first.
    for (q, k) in e.coordinates.iter().zip(&e.kinematic_equations) {
        let rate = crate::expr::print::latex_symbol(&format!("{q}_dot"));
        let _ = writeln!(s, "{rate} = {k}\\\\");
    }
    let _ = writeln!(s, "T = {}", e.kinetic_energy);
    let _ = writeln!(s, "\\\\\nV = {}", e.potential_energy);
    let rows: Vec<String> = e.mass_matrix.iter().map(|row| row.join(" & ")).collect();
    let acc: Vec<String> = (0..n).map(|i| p.print(model.coordinates[i][2])).collect();
    if e.constraints.is_empty() {
        let _ = writeln!(
            s,
            "\\\\\n{} {} = {}",
            bmatrix(&rows),
            bmatrix(&acc),
            bmatrix(&e.forcing)
        );
        return s;
    }
    // Jᵀ is n × m: row i holds the i-th entry of every constraint's row of J.
    let transposed: Vec<String> = (0..n)
        .map(|i| {
            e.constraints
                .iter()
                .map(|c| c.jacobian[i].as_str())
                .collect::<Vec<_>>()
                .join(" & ")
        })
        .collect();
    let multipliers: Vec<String> = e
        .constraints
        .iter()
        .map(|c| format!("\\lambda_{{\\mathrm{{{}}}}}", c.name.replace('_', "\\_")))
        .collect();
    let jacobian: Vec<String> = e
        .constraints
        .iter()
        .map(|c| c.jacobian.join(" & "))
        .collect();
    let gamma: Vec<String> = e.constraints.iter().map(|c| c.gamma.clone()).collect();
    let _ = writeln!(
        s,
        "\\\\\n{} {} + {} {} = {}",
        bmatrix(&rows),
        bmatrix(&acc),
        bmatrix(&transposed),
        bmatrix(&multipliers),
        bmatrix(&e.forcing)
    );
    let _ = writeln!(
        s,
        "\\\\\n{} {} = {}",
        bmatrix(&jacobian),
        bmatrix(&acc),
        bmatrix(&gamma)
    );
    for c in &e.constraints {
        let _ = writeln!(s, "\\\\\n{} = 0", c.equation);
    }
    s
}

/// The equations as MathML, one `<math display="block">` element per line: `T = …`,
/// `V = …`, each generalised force `Q_q = …` that is not zero, then one equation of motion
/// per coordinate, `Σⱼ M_ij q̈ⱼ + Σₖ J_ki λₖ = F_i` (zero terms left out; the multipliers of
/// constrained models, `[M Jᵀ; J 0][q̈; λ] = [F; γ]`), and `Φₖ = 0` for each holonomic
/// constraint. For HTML pages rendered without scripts or network (MathML Core).
///
/// The left-hand sides are built as expressions in a copy of the model's arena, so that the
/// model (and the plans made on its arena) stays as it was.
pub fn equations_mathml(model: &SymbolicModel, eom: &EquationsOfMotion) -> Vec<String> {
    let n = eom.num_dofs;
    let mut arena = model.arena.clone();
    let mut lhs = Vec::with_capacity(n);
    let multipliers: Vec<ExprId> = model
        .constraints
        .names
        .iter()
        .enumerate()
        .map(|(k, name)| arena.symbol(&format!("lambda_{name}"), SymbolKind::Multiplier(k as u32)))
        .collect();
    for i in 0..n {
        let mut terms = Vec::new();
        for j in 0..n {
            let m = eom.mass(i, j);
            if !arena.is_zero(m) {
                let acceleration = model.coordinates[j][2];
                terms.push(arena.product(&[m, acceleration]));
            }
        }
        for (k, lambda) in multipliers.iter().enumerate() {
            let j = model.constraints.jacobian[k * n + i];
            if !arena.is_zero(j) {
                terms.push(arena.product(&[j, *lambda]));
            }
        }
        lhs.push(arena.sum(&terms));
    }
    let p = Printer::for_display(&arena, Syntax::MathMl);
    let line = |body: String| format!("<math display=\"block\">{body}</math>");
    let equals = "<mo>=</mo>";
    let mut out = vec![
        line(format!("<mi>T</mi>{equals}{}", p.print(model.kinetic))),
        line(format!("<mi>V</mi>{equals}{}", p.print(model.potential))),
    ];
    for (i, q) in model.generalized_forces.iter().enumerate() {
        if !arena.is_zero(*q) {
            out.push(line(format!(
                "<msub><mi>Q</mi>{}</msub>{equals}{}",
                crate::expr::print::mathml_symbol(&model.coordinate_names[i]),
                p.print(*q)
            )));
        }
    }
    for (l, f) in lhs.iter().zip(&eom.forcing) {
        out.push(line(format!("{}{equals}{}", p.print(*l), p.print(*f))));
    }
    for phi in &model.constraints.phi {
        out.push(line(format!("{}{equals}<mn>0</mn>", p.print(*phi))));
    }
    out
}
