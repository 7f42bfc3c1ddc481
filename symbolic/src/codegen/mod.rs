//! Equations → Rust tokens: a struct named after the model and an
//! `impl MechanicalSystem<N>` with straight-line, CSE'd, allocation-free bodies.
//!
//! Each generated function is planned by [`crate::expr::cse::plan`] over exactly the
//! expressions it returns, binds only the symbols it uses, computes `sin_cos` once per angle,
//! and builds its nalgebra static matrix from a stack array. Output is deterministic: it
//! depends only on the model file.

mod describe;
mod listing;
pub mod program;
pub mod tape;

pub use describe::{describe, description_source};
pub use listing::{
    ConstraintKind, ConstraintListing, EquationsListing, GeneralizedForce, equations_latex,
    equations_text,
};

use std::fmt::Write as _;

use proc_macro2::TokenStream;

use crate::expr::cse::{self, CsePlan, Temporary};
use crate::expr::print::{Printer, Syntax};
use crate::expr::{ExprArena, ExprId, SymbolId, SymbolKind, trig};
use crate::mechanics::{EquationsOfMotion, Jacobians, SymbolicModel};
use crate::model::schema::RUST_KEYWORDS;

/// Why [`generate`] produced no code.
#[derive(Debug, Clone)]
pub enum GenerateError {
    /// Mistakes of the model file found after loading it (lowering, singular mass matrix),
    /// each located in the file.
    Diagnostics(Vec<crate::model::Diagnostic>),
    /// The printed code did not tokenize (a bug of the printer; the message has the source).
    Emit(String),
}

/// The code `eomgen::model!` generates for a loaded model file: lowering, one derivation
/// ([`crate::mechanics::preferred_equations`]), the mass-matrix diagnostics, the exact
/// Jacobians, then [`emit`]. The macro and `eomgen equations --rust` both call this, so what the
/// CLI prints is what is compiled; a model compiled at run time is planned from the same steps
/// ([`program::ModelProgram::from_file`]).
///
/// # Errors
/// [`GenerateError::Diagnostics`] for a model that cannot be lowered or whose mass matrix is
/// singular ([`crate::mechanics::mass_matrix_diagnostics`]); [`GenerateError::Emit`] as
/// [`emit`].
pub fn generate(
    file: &crate::model::ModelFile,
    options: &EmitOptions,
) -> Result<TokenStream, GenerateError> {
    let mut model = SymbolicModel::from_file(file).map_err(GenerateError::Diagnostics)?;
    let (eom, _) = crate::mechanics::preferred_equations(&mut model);
    let problems = crate::mechanics::mass_matrix_diagnostics(&model, &eom, file);
    if !problems.is_empty() {
        return Err(GenerateError::Diagnostics(problems));
    }
    let jacobians = Jacobians::of(&mut model, &eom);
    emit(&model, &eom, &jacobians, options)
        .map(|(tokens, _)| tokens)
        .map_err(GenerateError::Emit)
}

/// Where the generated code finds the runtime.
#[derive(Debug, Clone)]
pub struct EmitOptions {
    /// Path of the facade crate that re-exports `MechanicalSystem` and has a hidden
    /// `__private` module with `nalgebra`, `sign` and `step` (default `::eomgen`).
    pub crate_path: String,
    /// Absolute paths of files to track with `include_bytes!` so that editing them rebuilds.
    pub tracked_files: Vec<String>,
    /// How the model file is named in the generated docs.
    pub source_display: String,
}

impl Default for EmitOptions {
    fn default() -> Self {
        Self {
            crate_path: "::eomgen".to_string(),
            tracked_files: Vec::new(),
            source_display: String::new(),
        }
    }
}

/// Statistics of the generated code, for `eomgen check` and benchmarks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct EmitStats {
    /// Operations of `M` and `F` evaluated as trees (no sharing).
    pub ops_before_cse: u64,
    /// Operations of the CSE'd `mass_matrix_and_forcing`.
    pub ops_after_cse: u64,
}

pub use crate::model::schema::struct_name;

/// A symbol's local variable name in generated code: its own name, a keyword as a raw
/// identifier (`r#type`, so that it cannot meet another name, as a suffix `type_` could), and
/// a name of the generator's own (`__q`) with a `_` suffix. The loader refuses the keywords
/// that are not raw identifiers ([`crate::model::schema::UNRAW_KEYWORDS`]).
pub fn local_name(name: &str) -> String {
    if name.starts_with("__") {
        format!("{name}_")
    } else {
        field_name(name)
    }
}

/// Source of one function body: symbol bindings, temporaries, and the returned values
/// (printed as Rust expressions, in root order).
struct Body {
    code: String,
    values: Vec<String>,
}

fn body(arena: &mut ExprArena, roots: &[ExprId], helpers: &str) -> (Body, CsePlan) {
    let roots = &trig::expand_angle_sums(arena, roots)[..];
    let arena: &ExprArena = arena;
    let plan = cse::plan(arena, roots, "__e");
    let reachable = arena.reachable(roots);
    let mut code = String::new();
    // Bind the symbols used, in symbol order.
    let mut used: Vec<SymbolId> = reachable
        .iter()
        .filter_map(|e| match arena.node(*e) {
            crate::expr::Node::Symbol(s) => Some(*s),
            _ => None,
        })
        .collect();
    used.sort();
    for s in used {
        let info = arena.symbol_info(s);
        let local = local_name(&info.name);
        let source = match info.kind {
            SymbolKind::Parameter => format!("self.{}", field_name(&info.name)),
            SymbolKind::Coordinate(i) => format!("__q[{i}]"),
            SymbolKind::Velocity(i) => format!("__qdot[{i}]"),
            SymbolKind::Acceleration(i) => format!("__a[{i}]"),
            SymbolKind::Time => "__t".to_string(),
            SymbolKind::Auxiliary => "0.0_f64".to_string(),
            SymbolKind::Multiplier(i) => format!("__lambda.get({i}).copied().unwrap_or(f64::NAN)"),
        };
        let _ = writeln!(code, "let {local}: f64 = {source};");
    }
    let plan_ref = &plan;
    let names = move |e: ExprId| plan_ref.name_of(e).map(str::to_string);
    let printer = Printer::new(arena, Syntax::Rust)
        .with_symbol_names(|s| local_name(&arena.symbol_info(s).name))
        .with_temporaries(names)
        .with_rust_helpers(helpers);
    for temp in &plan.temporaries {
        match *temp {
            Temporary::Single(e) => {
                let (name, _) = plan.temporary_names(temp);
                let _ = writeln!(code, "let {name}: f64 = {};", printer.print_definition(e));
            }
            Temporary::SinCos { arg, .. } => {
                let (s, c) = plan.temporary_names(temp);
                let c = c.unwrap_or_default();
                let a = printer.print(arg);
                let _ = writeln!(
                    code,
                    "let ({s}, {c}): (f64, f64) = {helpers}::sin_cos({a});"
                );
            }
        }
    }
    let values = roots.iter().map(|r| printer.print(*r)).collect();
    drop(printer);
    (Body { code, values }, plan)
}

/// A parameter's field: its name, a keyword as a raw identifier (`r#type`).
fn field_name(name: &str) -> String {
    if RUST_KEYWORDS.contains(&name) {
        format!("r#{name}")
    } else {
        name.to_string()
    }
}

/// Statements that write `values` into the slice `__out` (entries beyond its length are
/// skipped, so a short slice cannot panic).
fn write_out(values: &[String]) -> String {
    values
        .iter()
        .enumerate()
        .map(|(i, x)| format!("if let Some(__o) = __out.get_mut({i}) {{ *__o = {x}; }}\n"))
        .collect()
}

fn string_literal(s: &str) -> String {
    format!("{s:?}")
}

/// Generates the struct and its `MechanicalSystem` implementation.
///
/// # Errors
/// Only if the printed code fails to tokenize, which would be a bug in the printer; the
/// message carries the offending source.
pub fn emit(
    model: &SymbolicModel,
    eom: &EquationsOfMotion,
    jacobians: &Jacobians,
    options: &EmitOptions,
) -> Result<(TokenStream, EmitStats), String> {
    let n = model.num_dofs();
    let krate = &options.crate_path;
    let private = format!("{krate}::__private");
    let na = format!("{private}::nalgebra");
    let name = struct_name(&model.name);
    let vec_t = format!("{na}::SVector<f64, {n}>");
    let mat_t = format!("{na}::SMatrix<f64, {n}, {n}>");
    let mut src = String::new();

    // The struct, one field per parameter.
    let doc = format!(
        "{}\n\nGenerated by `eomgen::model!` from `{}`: {} degree(s) of freedom ({}).",
        model.description,
        options.source_display,
        n,
        model.coordinate_names.join(", ")
    );
    let _ = writeln!(src, "#[doc = {}]", string_literal(&doc));
    let _ = writeln!(src, "#[derive(Debug, Clone, Copy, PartialEq)]");
    let _ = writeln!(src, "#[allow(non_snake_case)]");
    let _ = writeln!(src, "pub struct {name} {{");
    for p in &model.parameters {
        let unit = p
            .unit
            .as_deref()
            .map(|u| format!(" ({u})"))
            .unwrap_or_default();
        let _ = writeln!(
            src,
            "#[doc = {}] pub {}: f64,",
            string_literal(&format!(
                "Parameter `{}`{unit}; default {:?}.",
                p.name, p.default
            )),
            field_name(&p.name)
        );
    }
    let _ = writeln!(src, "}}");
    let _ = writeln!(
        src,
        "#[automatically_derived] #[allow(clippy::all, clippy::approx_constant, non_snake_case)] impl ::core::default::Default for {name} {{ fn default() -> Self {{ Self {{"
    );
    for p in &model.parameters {
        let _ = writeln!(src, "{}: {:?}_f64,", field_name(&p.name), p.default);
    }
    let _ = writeln!(src, "}} }} }}");

    // Tracking of the model file for rebuilds.
    for f in &options.tracked_files {
        let _ = writeln!(
            src,
            "const _: &[u8] = ::core::include_bytes!({});",
            string_literal(f)
        );
    }

    let mut imp = String::new();
    let description = describe::describe(model, eom);
    let _ = writeln!(
        imp,
        "fn description(&self) -> &{krate}::ModelDescription {{ static DESCRIPTION: {krate}::ModelDescription = {}; &DESCRIPTION }}",
        describe::description_source(&description, krate)
    );
    let values: Vec<String> = model
        .parameters
        .iter()
        .map(|p| format!("self.{}", field_name(&p.name)))
        .collect();
    let _ = writeln!(
        imp,
        "fn parameter_values(&self) -> ::std::vec::Vec<f64> {{ ::std::vec![{}] }}",
        values.join(", ")
    );
    let _ = writeln!(
        imp,
        "fn set_parameter(&mut self, name: &str, value: f64) -> ::core::result::Result<(), {krate}::UnknownParameter> {{ match name {{"
    );
    for p in &model.parameters {
        let _ = writeln!(
            imp,
            "{} => {{ self.{} = value; Ok(()) }}",
            string_literal(&p.name),
            field_name(&p.name)
        );
    }
    let _ = writeln!(
        imp,
        "_ => Err({krate}::UnknownParameter {{ model: {}.to_string(), name: name.to_string(), known: {}.to_string() }}) }} }}",
        string_literal(&model.name),
        string_literal(
            &model
                .parameters
                .iter()
                .map(|p| p.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        )
    );

    let helpers = private.as_str();
    // The bodies may add nodes (the angle-sum rewrite); the model's own arena stays as it is.
    let mut arena = model.arena.clone();
    let mut emit_fn = |signature: &str,
                       roots: &[ExprId],
                       build: &dyn Fn(&[String]) -> String|
     -> CsePlan {
        let (b, plan) = body(&mut arena, roots, helpers);
        let _ = writeln!(
            imp,
            "#[allow(unused_variables, non_snake_case, clippy::all)] #[inline] {signature} {{\n{}{}\n}}",
            b.code,
            build(&b.values)
        );
        plan
    };

    let mat_e = format!("{na}::SMatrix::<f64, {n}, {n}>");
    let vec_e = format!("{na}::SVector::<f64, {n}>");
    let matrix = |vals: &[String]| format!("{mat_e}::from_row_slice(&[{}])", vals.join(", "));
    let vector = |vals: &[String]| format!("{vec_e}::from_column_slice(&[{}])", vals.join(", "));
    let q_args = format!("__q: &{vec_t}");
    let qd_args = format!("__q: &{vec_t}, __qdot: &{vec_t}");

    emit_fn(
        &format!("fn initial_state(&self) -> ({vec_t}, {vec_t})"),
        &[model.initial_q.clone(), model.initial_qdot.clone()].concat(),
        &|v| format!("({}, {})", vector(&v[..n]), vector(&v[n..])),
    );
    emit_fn(
        &format!("fn mass_matrix(&self, {q_args}, __t: f64) -> {mat_t}"),
        &eom.mass_matrix,
        &|v| matrix(v),
    );
    emit_fn(
        &format!("fn forcing(&self, {qd_args}, __t: f64) -> {vec_t}"),
        &eom.forcing,
        &|v| vector(v),
    );
    let both: Vec<ExprId> = [eom.mass_matrix.clone(), eom.forcing.clone()].concat();
    let plan = emit_fn(
        &format!("fn mass_matrix_and_forcing(&self, {qd_args}, __t: f64) -> ({mat_t}, {vec_t})"),
        &both,
        &|v| format!("({}, {})", matrix(&v[..n * n]), vector(&v[n * n..])),
    );
    let stats = EmitStats {
        ops_before_cse: model.arena.tree_operation_count(&both),
        ops_after_cse: plan.operation_count(),
    };
    emit_fn(
        &format!("fn forcing_jacobian_q(&self, {qd_args}, __t: f64) -> {mat_t}"),
        &jacobians.forcing_q,
        &|v| matrix(v),
    );
    emit_fn(
        &format!("fn forcing_jacobian_qdot(&self, {qd_args}, __t: f64) -> {mat_t}"),
        &jacobians.forcing_qdot,
        &|v| matrix(v),
    );
    emit_fn(
        &format!(
            "fn mass_matrix_product_jacobian(&self, {q_args}, __t: f64, __a: &{vec_t}) -> {mat_t}"
        ),
        &jacobians.mass_product_q,
        &|v| matrix(v),
    );
    emit_fn(
        &format!("fn kinetic_energy(&self, {qd_args}, __t: f64) -> f64"),
        &[model.kinetic],
        &|v| v[0].clone(),
    );
    emit_fn(
        &format!("fn potential_energy(&self, {q_args}, __t: f64) -> f64"),
        &[model.potential],
        &|v| v[0].clone(),
    );
    // Point components, flattened; 2-D points get z = 0.
    let point_roots: Vec<ExprId> = model
        .points
        .iter()
        .flat_map(|(_, r)| r.iter().copied())
        .collect();
    let dims: Vec<usize> = model.points.iter().map(|(_, r)| r.len()).collect();
    emit_fn(
        &format!("fn point_positions(&self, {q_args}, __t: f64, __out: &mut [[f64; 3]])"),
        &point_roots,
        &|v| {
            let mut s = String::new();
            let mut offset = 0;
            for (i, d) in dims.iter().enumerate() {
                let c: Vec<String> = (0..3)
                    .map(|k| {
                        if k < *d {
                            v[offset + k].clone()
                        } else {
                            "0.0_f64".to_string()
                        }
                    })
                    .collect();
                offset += d;
                let _ = writeln!(
                    s,
                    "if let Some(__p) = __out.get_mut({i}) {{ *__p = [{}]; }}",
                    c.join(", ")
                );
            }
            s
        },
    );
    // Constraints: the trait's defaults stand for an unconstrained model.
    let c = &model.constraints;
    if !c.is_empty() {
        emit_fn(
            &format!("fn constraint_residuals(&self, {q_args}, __t: f64, __out: &mut [f64])"),
            &c.phi,
            &|v| write_out(v),
        );
        emit_fn(
            &format!("fn constraint_jacobian(&self, {q_args}, __t: f64, __out: &mut [f64])"),
            &c.jacobian,
            &|v| write_out(v),
        );
        emit_fn(
            &format!(
                "fn constraint_velocity_residuals(&self, {qd_args}, __t: f64, __out: &mut [f64])"
            ),
            &c.velocity,
            &|v| write_out(v),
        );
        emit_fn(
            &format!("fn constraint_gamma(&self, {qd_args}, __t: f64, __out: &mut [f64])"),
            &c.gamma,
            &|v| write_out(v),
        );
    }
    if !model.events.is_empty() {
        let roots: Vec<ExprId> = model.events.iter().map(|e| e.function).collect();
        emit_fn(
            &format!(
                "fn event_values(&self, {qd_args}, __t: f64, __a: &{vec_t}, __lambda: &[f64], __out: &mut [f64])"
            ),
            &roots,
            &|v| write_out(v),
        );
    }
    if !model.equilibria.is_empty() {
        let roots: Vec<ExprId> = model
            .equilibria
            .iter()
            .flat_map(|(_, guess)| guess.iter().copied())
            .collect();
        emit_fn(
            "fn equilibrium_guesses(&self, __out: &mut [f64])",
            &roots,
            &|v| write_out(v),
        );
    }
    let _ = writeln!(
        src,
        "#[automatically_derived] #[allow(clippy::all, clippy::approx_constant, non_snake_case)] impl {krate}::MechanicalSystem<{n}> for {name} {{\n{imp}\n}}"
    );
    let tokens: TokenStream = src
        .parse()
        .map_err(|e| format!("generated code does not tokenize ({e}):\n{src}"))?;
    Ok((tokens, stats))
}

/// The equations as MathML, one `<math display="block">` element per line: `T = …`,
/// `V = …`, each generalised force `Q_q = …` that is not zero, then one equation of motion
/// per coordinate, `Σⱼ M_ij q̈ⱼ + Σₖ J_ki λₖ = F_i` (zero terms left out; the multipliers of
/// constrained models, `[M Jᵀ; J 0][q̈; λ] = [F; γ]`), and `Φₖ = 0` for each holonomic
/// constraint. For HTML pages rendered without scripts or network (MathML Core).
///
/// The left-hand sides are built as expressions in the model's arena, which is why the model
/// is borrowed mutably; nothing already in it changes.
pub fn equations_mathml(model: &mut SymbolicModel, eom: &EquationsOfMotion) -> Vec<String> {
    let n = eom.num_dofs;
    let mut lhs = Vec::with_capacity(n);
    let constraints = model.constraints.names.clone();
    let multipliers: Vec<ExprId> = constraints
        .iter()
        .enumerate()
        .map(|(k, name)| {
            model
                .arena
                .symbol(&format!("lambda_{name}"), SymbolKind::Multiplier(k as u32))
        })
        .collect();
    for i in 0..n {
        let mut terms = Vec::new();
        for j in 0..n {
            let m = eom.mass(i, j);
            if !model.arena.is_zero(m) {
                let acceleration = model.coordinates[j][2];
                terms.push(model.arena.product(&[m, acceleration]));
            }
        }
        for (k, lambda) in multipliers.iter().enumerate() {
            let j = model.constraints.jacobian[k * n + i];
            if !model.arena.is_zero(j) {
                terms.push(model.arena.product(&[j, *lambda]));
            }
        }
        lhs.push(model.arena.sum(&terms));
    }
    let p = Printer::new(&model.arena, Syntax::MathMl);
    let line = |body: String| format!("<math display=\"block\">{body}</math>");
    let equals = "<mo>=</mo>";
    let mut out = vec![
        line(format!("<mi>T</mi>{equals}{}", p.print(model.kinetic))),
        line(format!("<mi>V</mi>{equals}{}", p.print(model.potential))),
    ];
    for (i, q) in model.generalized_forces.iter().enumerate() {
        if !model.arena.is_zero(*q) {
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
