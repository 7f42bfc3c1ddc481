//! Equations → Rust tokens: a struct named after the model and an
//! `impl MechanicalSystem<N>` with straight-line, CSE'd, allocation-free bodies.
//!
//! Each generated function prints one plan of [`plan`] (the plans the run-time compiler
//! lowers to tapes, [`program::ModelProgram`]): it binds only the symbols it uses, computes
//! `sin_cos` once per angle, and builds its nalgebra static matrix from a stack array. The
//! items are built as tokens with `quote!`; only the expressions come as text, from the
//! printer that the tapes follow operation by operation ([`crate::expr::print`]). Output is
//! deterministic: it depends only on the model file.

mod describe;
pub mod export;
mod listing;
pub mod plan;
pub mod program;
mod rust_tokens;
pub mod tape;
pub mod taylor;
mod taylor_tokens;

pub use describe::{describe, description_tokens};
pub use listing::{
    ConstraintKind, ConstraintListing, EquationsListing, GeneralizedForce, equations_latex,
    equations_mathml, equations_text, readable_equations,
};

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use crate::expr::cse::{CsePlan, Temporary};
use crate::expr::print::{Printer, Syntax};
use crate::expr::{ExprArena, ExprId, SymbolId, SymbolKind};
use crate::mechanics::{EquationsOfMotion, SymbolicModel};
use crate::model::schema::RUST_KEYWORDS;
use plan::ModelFunction;
use rust_tokens::{float, ident, index, tokens};

/// Why [`generate`] produced no code.
#[derive(Debug, Clone)]
pub enum GenerateError {
    /// Mistakes of the model file found after loading it (lowering, singular mass matrix),
    /// each located in the file.
    Diagnostics(Vec<crate::model::Diagnostic>),
    /// The printed code did not tokenize (a bug of the printer; the message has the source).
    Emit(String),
}

/// The first steps of every compilation of a model file, by the macro ([`generate`]) or at run
/// time ([`program::ModelProgram::from_file`]): lowering, one derivation
/// ([`crate::mechanics::preferred_equations`]) and the mass-matrix diagnostics.
///
/// # Errors
/// [`GenerateError::Diagnostics`] for a model that cannot be lowered, whose derivation grows
/// past [`crate::mechanics::DERIVATION_OPERAND_LIMIT`] or whose mass matrix is singular
/// ([`crate::mechanics::mass_matrix_diagnostics`]).
fn derive(
    file: &crate::model::ModelFile,
) -> Result<(SymbolicModel, EquationsOfMotion), GenerateError> {
    let mut model = SymbolicModel::from_file(file).map_err(GenerateError::Diagnostics)?;
    crate::mechanics::limit_derivation(&mut model);
    let (eom, _) = crate::mechanics::preferred_equations(&mut model);
    crate::mechanics::finish_derivation(&mut model, file).map_err(GenerateError::Diagnostics)?;
    let problems = crate::mechanics::mass_matrix_diagnostics(&model, &eom, file);
    if !problems.is_empty() {
        return Err(GenerateError::Diagnostics(problems));
    }
    Ok((model, eom))
}

/// The code `eomgen::model!` generates for a loaded model file: lowering, one derivation
/// ([`crate::mechanics::preferred_equations`]), the mass-matrix diagnostics, the plans of
/// every function with the exact Jacobians ([`plan::EmitPlans::of`]), then [`emit`]. The macro and `eomgen equations --rust` both call this, so what the
/// CLI prints is what is compiled; a model compiled at run time is derived by the same steps
/// and lowered from the same plans ([`program::ModelProgram::from_file`]).
///
/// # Errors
/// [`GenerateError::Diagnostics`] for a model that cannot be lowered or whose mass matrix is
/// singular ([`crate::mechanics::mass_matrix_diagnostics`]); [`GenerateError::Emit`] as
/// [`emit`].
pub fn generate(
    file: &crate::model::ModelFile,
    options: &EmitOptions,
) -> Result<TokenStream, GenerateError> {
    let (model, eom) = derive(file)?;
    let plans = plan::EmitPlans::of(&model, &eom);
    emit(&model, &eom, &plans, options)
        .map(|(tokens, _)| tokens)
        .map_err(GenerateError::Emit)
}

/// Where the generated code finds the runtime.
#[derive(Debug, Clone)]
pub struct EmitOptions {
    /// Path of the facade crate that re-exports `MechanicalSystem` and has a hidden
    /// `__private` module with `nalgebra`, `sign`, `step`, `sin`, `cos`, `powf` and `taylor`
    /// (default `::eomgen`).
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

/// One function body: symbol bindings and temporaries, and the returned values (in root
/// order).
struct Body {
    statements: TokenStream,
    values: Vec<TokenStream>,
}

/// The body of one planned function: the symbols its roots use bound in symbol order, the
/// plan's temporaries, and its roots as expressions.
fn body(arena: &ExprArena, plan: &CsePlan, helpers: &str) -> Result<Body, String> {
    let helper_path = tokens(helpers)?;
    let mut statements = TokenStream::new();
    let mut used: Vec<SymbolId> = arena
        .reachable(&plan.roots)
        .iter()
        .filter_map(|e| match arena.node(*e) {
            crate::expr::Node::Symbol(s) => Some(*s),
            _ => None,
        })
        .collect();
    used.sort();
    for s in used {
        let info = arena.symbol_info(s);
        let local = ident(&local_name(&info.name))?;
        let source = match info.kind {
            SymbolKind::Parameter => {
                let field = ident(&field_name(&info.name))?;
                quote!(self.#field)
            }
            SymbolKind::Coordinate(i) => {
                let i = index(i as usize);
                quote!(__q[#i])
            }
            SymbolKind::Velocity(i) => {
                let i = index(i as usize);
                quote!(__qdot[#i])
            }
            SymbolKind::Acceleration(i) => {
                let i = index(i as usize);
                quote!(__a[#i])
            }
            SymbolKind::Time => quote!(__t),
            SymbolKind::Auxiliary => quote!(0.0_f64),
            // Replaced in every expression of a model with speeds; a NaN if one were left.
            SymbolKind::Retired => quote!(f64::NAN),
            SymbolKind::Multiplier(i) => {
                let i = index(i as usize);
                quote!(__lambda.get(#i).copied().unwrap_or(f64::NAN))
            }
        };
        statements.extend(quote!(let #local: f64 = #source;));
    }
    let names = |e: ExprId| plan.name_of(e).map(str::to_string);
    let printer = Printer::new(arena, Syntax::Rust)
        .with_symbol_names(|s| local_name(&arena.symbol_info(s).name))
        .with_temporaries(names)
        .with_rust_helpers(helpers);
    for temp in &plan.temporaries {
        match *temp {
            Temporary::Single(e) => {
                let (name, _) = plan.temporary_names(temp);
                let name = ident(&name)?;
                let definition = tokens(&printer.print_definition(e))?;
                statements.extend(quote!(let #name: f64 = #definition;));
            }
            Temporary::SinCos { arg, .. } => {
                let (s, c) = plan.temporary_names(temp);
                let s = ident(&s)?;
                let c = ident(&c.unwrap_or_default())?;
                let a = tokens(&printer.print(arg))?;
                statements.extend(quote!(let (#s, #c): (f64, f64) = #helper_path::sin_cos(#a);));
            }
        }
    }
    let values = plan
        .roots
        .iter()
        .map(|r| tokens(&printer.print(*r)))
        .collect::<Result<_, _>>()?;
    Ok(Body { statements, values })
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
fn write_out(values: &[TokenStream]) -> TokenStream {
    values
        .iter()
        .enumerate()
        .map(|(i, x)| {
            let i = index(i);
            quote!(if let Some(__o) = __out.get_mut(#i) { *__o = #x; })
        })
        .collect()
}

/// Generates the struct and its `MechanicalSystem` implementation: the struct with one field
/// per parameter, its `Default`, the model's description as a `static`, and one method per
/// plan of `plans` ([`plan::EmitPlans::of`] of the same `model` and `eom`: every function of
/// [`ModelFunction::ALL`] the model has; the trait's defaults stand for the others).
///
/// # Errors
/// Only if the printed code fails to tokenize, which would be a bug in the printer; the
/// message carries the offending source.
pub fn emit(
    model: &SymbolicModel,
    eom: &EquationsOfMotion,
    plans: &plan::EmitPlans,
    options: &EmitOptions,
) -> Result<(TokenStream, EmitStats), String> {
    let n = model.num_dofs();
    let krate = tokens(&options.crate_path)?;
    let helpers = format!("{}::__private", options.crate_path);
    let na = quote!(#krate::__private::nalgebra);
    let name = ident(&struct_name(&model.name))?;
    let dim = index(n);
    let vec_t = quote!(#na::SVector<f64, #dim>);
    let mat_t = quote!(#na::SMatrix<f64, #dim, #dim>);

    // The struct, one field per parameter, and its defaults.
    let doc = format!(
        "{}\n\nGenerated by `eomgen::model!` from `{}`: {} degree(s) of freedom ({}).",
        model.description,
        options.source_display,
        n,
        model.coordinate_names.join(", ")
    );
    let ParameterTokens {
        fields,
        defaults,
        values,
        setters,
    } = parameter_tokens(model)?;
    // Tracking of the model file for rebuilds.
    let tracked = options.tracked_files.iter().map(|f| {
        quote!(
            const _: &[u8] = ::core::include_bytes!(#f);
        )
    });
    let mut methods = parameter_methods(model, eom, &krate, (&values, &setters))?;

    let types = Types {
        na: na.clone(),
        dim: dim.clone(),
        n,
        vec_t: vec_t.clone(),
        mat_t: mat_t.clone(),
    };
    // Printed in the trait's order, whatever order they were planned in.
    for function in ModelFunction::ALL {
        if let Some((arena, plan)) = plans.get(function) {
            let body = body(arena, plan, &helpers)?;
            methods.extend(function_method(function, body, model, &types));
        }
    }
    let (accessor, taylor_functions) = taylor_items(model, plans, &krate, &name)?;
    methods.extend(accessor);
    let stats = emit_stats(model, eom, plans);
    let tokens = quote! {
        #[doc = #doc]
        #[derive(Debug, Clone, Copy, PartialEq)]
        #[allow(non_snake_case)]
        pub struct #name {
            #(#fields)*
        }
        #[automatically_derived]
        #[allow(clippy::all, clippy::approx_constant, non_snake_case)]
        impl ::core::default::Default for #name {
            fn default() -> Self {
                Self { #(#defaults)* }
            }
        }
        #(#tracked)*
        #[automatically_derived]
        #[allow(clippy::all, clippy::approx_constant, non_snake_case)]
        impl #krate::MechanicalSystem<#dim> for #name {
            #methods
        }
        #taylor_functions
    };
    Ok((tokens, stats))
}

/// The tokens of the model's parameters, one entry per parameter in order.
struct ParameterTokens {
    /// The struct's fields, each with its doc comment.
    fields: Vec<TokenStream>,
    /// The fields' initializers in `Default`.
    defaults: Vec<TokenStream>,
    /// The fields read (`self.field`), for `parameter_values`.
    values: Vec<TokenStream>,
    /// The match arms of `set_parameter`.
    setters: Vec<TokenStream>,
}

/// The struct's field, default, value and setter of each parameter of `model`.
///
/// # Errors
/// If a parameter's field name or default fails to tokenize.
fn parameter_tokens(model: &SymbolicModel) -> Result<ParameterTokens, String> {
    let mut fields = Vec::new();
    let mut defaults = Vec::new();
    let mut values = Vec::new();
    let mut setters = Vec::new();
    for p in &model.parameters {
        let unit = p
            .unit
            .as_deref()
            .map(|u| format!(" ({u})"))
            .unwrap_or_default();
        let field_doc = format!("Parameter `{}`{unit}; default {:?}.", p.name, p.default);
        let field = ident(&field_name(&p.name))?;
        let default = float(p.default)?;
        let parameter = &p.name;
        fields.push(quote!(#[doc = #field_doc] pub #field: f64,));
        defaults.push(quote!(#field: #default,));
        values.push(quote!(self.#field));
        setters.push(quote!(#parameter => { self.#field = value; Ok(()) }));
    }
    Ok(ParameterTokens {
        fields,
        defaults,
        values,
        setters,
    })
}

/// The first methods of the generated impl: `description`, `parameter_values` (from the
/// parameters' `values`) and `set_parameter` (from their `setters`).
///
/// # Errors
/// If the description fails to tokenize.
fn parameter_methods(
    model: &SymbolicModel,
    eom: &EquationsOfMotion,
    krate: &TokenStream,
    (values, setters): (&[TokenStream], &[TokenStream]),
) -> Result<TokenStream, String> {
    let model_name = &model.name;
    let known = model
        .parameters
        .iter()
        .map(|p| p.name.as_str())
        .collect::<Vec<_>>()
        .join(", ");
    let description = describe::description_tokens(&describe::describe(model, eom, true), krate)?;

    Ok(quote! {
        fn description(&self) -> &#krate::ModelDescription {
            static DESCRIPTION: #krate::ModelDescription = #description;
            &DESCRIPTION
        }
        fn parameter_values(&self) -> ::std::vec::Vec<f64> { ::std::vec![#(#values),*] }
        fn set_parameter(&mut self, name: &str, value: f64) -> ::core::result::Result<(), #krate::UnknownParameter> {
            match name {
                #(#setters)*
                _ => Err(#krate::UnknownParameter {
                    model: #model_name.to_string(),
                    name: name.to_string(),
                    known: #known.to_string(),
                }),
            }
        }
    })
}

/// The Taylor accessor method of the generated impl and the free functions it names.
///
/// # Errors
/// If a parameter's field name or the generated code fails to tokenize.
fn taylor_items(
    model: &SymbolicModel,
    plans: &plan::EmitPlans,
    krate: &TokenStream,
    name: &proc_macro2::Ident,
) -> Result<(TokenStream, TokenStream), String> {
    let n = model.num_dofs();
    // The Taylor recurrences, from the tape of `M` and `F` the run-time compiler builds too.
    // The compiled code's fused orders solve `M q̈ = F` only: a constrained model's series
    // are the run-time compiler's.
    let taylor = match model.constraints.len() {
        _ if model.speeds.is_some() => Err(eomgen_description::taylor::TaylorUnsupported::Speeds),
        0 => taylor::taylor_program(
            &program::mass_matrix_and_forcing_tape(model, &plans.state),
            n,
            0,
        ),
        count => Err(eomgen_description::taylor::TaylorUnsupported::Constraints { count }),
    };
    let parameter_fields = model
        .parameters
        .iter()
        .map(|p| ident(&field_name(&p.name)))
        .collect::<Result<Vec<_>, _>>()?;
    taylor_tokens::methods(&taylor, krate, &parameter_fields, name)
}

/// The operation counts of `M` and `F` of `eom` before and after common subexpressions.
fn emit_stats(
    model: &SymbolicModel,
    eom: &EquationsOfMotion,
    plans: &plan::EmitPlans,
) -> EmitStats {
    let both: Vec<ExprId> = [eom.mass_matrix.clone(), eom.forcing.clone()].concat();
    EmitStats {
        ops_before_cse: model.arena.tree_operation_count(&both),
        ops_after_cse: plans
            .get(ModelFunction::MassMatrixAndForcing)
            .map_or(0, |(_, plan)| plan.operation_count()),
    }
}

/// The types a generated method names: nalgebra's path, `N` as a literal, and the vector
/// and matrix types of size `N`.
struct Types {
    na: TokenStream,
    dim: Literal,
    n: usize,
    vec_t: TokenStream,
    mat_t: TokenStream,
}

/// One method of the generated `impl MechanicalSystem<N>`: the function's signature, its body
/// (bindings and temporaries) and its outputs built into what the trait returns (static
/// matrices row-major from a stack array, slices written entry by entry).
fn function_method(
    function: ModelFunction,
    body: Body,
    model: &SymbolicModel,
    types: &Types,
) -> TokenStream {
    let Body {
        statements,
        values: v,
    } = body;
    let (signature, result) = signature_and_result(function, &v, model, types);
    quote! {
        #[allow(unused_variables, non_snake_case, clippy::all)]
        #[inline]
        #signature {
            #statements
            #result
        }
    }
}

/// The signature of the method of `function` and the expression or stores that build its
/// outputs `v` into what the trait returns.
// Long: one arm per `ModelFunction` (twenty-two), each the trait method's signature beside the
// shape of its result; a table, kept whole so that a signature is read next to its outputs.
fn signature_and_result(
    function: ModelFunction,
    v: &[TokenStream],
    model: &SymbolicModel,
    types: &Types,
) -> (TokenStream, TokenStream) {
    let Types {
        na,
        dim,
        n,
        vec_t,
        mat_t,
    } = types;
    let n = *n;
    let matrix =
        |v: &[TokenStream]| quote!(#na::SMatrix::<f64, #dim, #dim>::from_row_slice(&[#(#v),*]));
    let vector =
        |v: &[TokenStream]| quote!(#na::SVector::<f64, #dim>::from_column_slice(&[#(#v),*]));
    let q_args = quote!(__q: &#vec_t);
    let qd_args = quote!(__q: &#vec_t, __qdot: &#vec_t);
    match function {
        ModelFunction::InitialState => (quote!(fn initial_state(&self) -> (#vec_t, #vec_t)), {
            let (q, qdot) = (vector(&v[..n]), vector(&v[n..]));
            quote!((#q, #qdot))
        }),
        ModelFunction::MassMatrix => (
            quote!(fn mass_matrix(&self, #q_args, __t: f64) -> #mat_t),
            matrix(v),
        ),
        ModelFunction::Forcing => (
            quote!(fn forcing(&self, #qd_args, __t: f64) -> #vec_t),
            vector(v),
        ),
        ModelFunction::MassMatrixAndForcing => (
            quote!(fn mass_matrix_and_forcing(&self, #qd_args, __t: f64) -> (#mat_t, #vec_t)),
            {
                let (m, f) = (matrix(&v[..n * n]), vector(&v[n * n..]));
                quote!((#m, #f))
            },
        ),
        ModelFunction::ForcingJacobianQ => (
            quote!(fn forcing_jacobian_q(&self, #qd_args, __t: f64) -> #mat_t),
            matrix(v),
        ),
        ModelFunction::ForcingJacobianQdot => (
            quote!(fn forcing_jacobian_qdot(&self, #qd_args, __t: f64) -> #mat_t),
            matrix(v),
        ),
        ModelFunction::MassMatrixProductJacobian => (
            quote!(fn mass_matrix_product_jacobian(&self, #q_args, __t: f64, __a: &#vec_t) -> #mat_t),
            matrix(v),
        ),
        ModelFunction::KineticEnergy => (
            quote!(fn kinetic_energy(&self, #qd_args, __t: f64) -> f64),
            v[0].clone(),
        ),
        ModelFunction::PotentialEnergy => (
            quote!(fn potential_energy(&self, #q_args, __t: f64) -> f64),
            v[0].clone(),
        ),
        ModelFunction::PointPositions => (
            quote!(fn point_positions(&self, #q_args, __t: f64, __out: &mut [[f64; 3]])),
            point_stores(model, v),
        ),
        ModelFunction::ConstraintResiduals => (
            quote!(fn constraint_residuals(&self, #q_args, __t: f64, __out: &mut [f64])),
            write_out(v),
        ),
        ModelFunction::ConstraintJacobian => (
            quote!(fn constraint_jacobian(&self, #q_args, __t: f64, __out: &mut [f64])),
            write_out(v),
        ),
        ModelFunction::ConstraintVelocityResiduals => (
            quote!(fn constraint_velocity_residuals(&self, #qd_args, __t: f64, __out: &mut [f64])),
            write_out(v),
        ),
        ModelFunction::ConstraintGamma => (
            quote!(fn constraint_gamma(&self, #qd_args, __t: f64, __out: &mut [f64])),
            write_out(v),
        ),
        ModelFunction::EventValues => (
            quote!(fn event_values(&self, #qd_args, __t: f64, __a: &#vec_t, __lambda: &[f64], __out: &mut [f64])),
            write_out(v),
        ),
        ModelFunction::EquilibriumGuesses => (
            quote!(fn equilibrium_guesses(&self, __out: &mut [f64])),
            write_out(v),
        ),
        ModelFunction::ContactGaps => (
            quote!(fn contact_gaps(&self, #qd_args, __t: f64, __out: &mut [f64])),
            write_out(v),
        ),
        ModelFunction::ContactJacobian => (
            quote!(fn contact_jacobian(&self, #q_args, __t: f64, __out: &mut [f64])),
            write_out(v),
        ),
        ModelFunction::ContactCoefficients => (
            quote!(fn contact_coefficients(&self, __out: &mut [f64])),
            write_out(v),
        ),
        ModelFunction::SupportChanges => (
            quote!(fn support_changes(&self, #q_args, __t: f64, __out: &mut [f64])),
            write_out(v),
        ),
        ModelFunction::CoordinateRates => (
            quote!(fn coordinate_rates(&self, #qd_args, __t: f64) -> #vec_t),
            vector(v),
        ),
        ModelFunction::CoordinateRatesJacobian => (
            quote!(fn coordinate_rates_jacobian(&self, #qd_args, __t: f64) -> (#mat_t, #mat_t)),
            {
                let (d_q, d_u) = (matrix(&v[..n * n]), matrix(&v[n * n..]));
                quote!((#d_q, #d_u))
            },
        ),
    }
}

/// Stores of `point_positions`: `[x, y, z]` per point from its flattened components `v`, 2-D
/// points with `z = 0`.
fn point_stores(model: &SymbolicModel, v: &[TokenStream]) -> TokenStream {
    // The loader gives every point 2 or 3 components.
    debug_assert!(model.points.iter().all(|(_, r)| r.len() <= 3));
    let mut components = v.iter();
    model
        .points
        .iter()
        .enumerate()
        .map(|(i, (_, r))| {
            let c: Vec<TokenStream> = (0..3)
                .map(
                    |k| match (k < r.len()).then(|| components.next()).flatten() {
                        Some(x) => x.clone(),
                        None => quote!(0.0_f64),
                    },
                )
                .collect();
            let i = index(i);
            quote!(if let Some(__p) = __out.get_mut(#i) { *__p = [#(#c),*]; })
        })
        .collect()
}
