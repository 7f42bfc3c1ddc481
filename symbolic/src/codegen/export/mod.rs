//! A model's equations as source code for other tools: C (C99 and `<math.h>`), MATLAB or
//! Octave, and Python with NumPy.
//!
//! The code is printed from the tapes a model compiled at run time evaluates
//! ([`ModelProgram::from_file`], with the exact Jacobians of
//! [`Derivation::jacobians`](super::program::Derivation::jacobians)): one
//! straight-line function per tape, every operation of the tape a local value, so the
//! exported functions compute what eomgen computes, operation by operation. Only the
//! library functions differ (the C library's `sin`, NumPy's `np.sin`, …, against the `libm`
//! crate's; `pow` for a half-integer exponent, which eomgen takes through a square root,
//! `eomgen_runtime::functions::powf`), which moves a value by an ulp or a few: the tests
//! hold the exported C and Python to eomgen's values within `1e-13` relative at random
//! states.
//!
//! # What is exported
//! With `n` coordinates, `m` constraints of which `m_h` holonomic, the state `y = [q; q̇]`
//! (`2n`) and the parameters `p` in file order (their defaults exported with them):
//!
//! | function | returns |
//! |---|---|
//! | `initial_state(p)` | `y(0)` (`2n`) |
//! | `mass_matrix_and_forcing(t, q, qd, p)` | `M` (`n × n`), `F` (`n`) of `M q̈ = F` |
//! | `rhs(t, y, p)` | `ẏ = [q̇; q̈]` (`2n`): `q̈` from `M q̈ = F`, or with constraints from `[M Jᵀ; J 0][q̈; λ] = [F; γ]` |
//! | `multipliers(t, q, qd, p)` | `λ` (`m`), with constraints only |
//! | `forcing_jacobian_q(t, q, qd, p)`, `forcing_jacobian_qdot(t, q, qd, p)` | `∂F/∂q`, `∂F/∂q̇` (`n × n`) |
//! | `mass_matrix_product_jacobian(t, q, a, p)` | `∂(M a)/∂q` (`n × n`) |
//! | `kinetic_energy(t, q, qd, p)`, `potential_energy(t, q, p)` | `T`, `V` |
//! | `point_positions(t, q, p)` | `[x, y, z]` of each point (`points × 3`) |
//! | `coordinate_rates(t, q, qd, p)` | with generalized speeds, `q̇ = W (u − Z)` (`n`) |
//! | `constraint_residuals(t, q, p)` | `Φ` (`m_h`), with constraints only |
//! | `constraint_jacobian(t, q, p)`, `constraint_gamma(t, q, qd, p)` | `J` (`m × n`), `γ` (`m`), with constraints only |
//!
//! A model in generalized speeds (`speeds:`) has the speeds `u` where the others have `q̇`:
//! its state is `y = [q; u]`, every `qd` argument is `u`, `M` and `F` are Kane's
//! `M u̇ = F`, and `rhs` returns `[q̇; u̇]` with `q̇` from `coordinate_rates`.
//!
//! Matrices are row-major arrays in C (`M[i*n + j]`), two-dimensional arrays in NumPy and
//! matrices in MATLAB. Contacts, impacts and events are not exported: they need the
//! event-driven integration of eomgen itself.
//!
//! # Sources
//! Lectures 8–11 (the equations `M q̈ = F` and, with constraints, the index-1 system); the
//! linear solve of the right-hand side is Gaussian elimination with partial pivoting in C
//! (Golub & Van Loan, *Matrix Computations*, 4th ed., §3.4), `numpy.linalg.solve` and
//! MATLAB's `\` otherwise.

use std::fmt::Write;

mod c;
mod matlab;
mod python;

use super::GenerateError;
use super::program::{FunctionTape, JacobianProgram, ModelProgram};
use super::tape::{Input, Instruction, Tape, Value};
use crate::expr::Func;
use crate::model::ModelFile;

/// A language [`export`] prints.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Language {
    /// C99 with `<math.h>`: one source file, its functions prefixed with the model's name.
    C,
    /// MATLAB or Octave: one function file `NAME.m` whose function returns a struct of the
    /// model's functions (handles to the file's local functions) and its parameters.
    Matlab,
    /// Python 3 with NumPy: one module.
    Python,
}

impl Language {
    /// Every language, in the order of [`Language::name`]'s list.
    pub const ALL: [Language; 3] = [Language::C, Language::Matlab, Language::Python];

    /// `c`, `matlab` or `python`.
    pub fn name(self) -> &'static str {
        match self {
            Language::C => "c",
            Language::Matlab => "matlab",
            Language::Python => "python",
        }
    }

    /// The file name extension of the exported code (`c`, `m`, `py`).
    pub fn extension(self) -> &'static str {
        match self {
            Language::C => "c",
            Language::Matlab => "m",
            Language::Python => "py",
        }
    }
}

/// The equations of a loaded model file as source code in `language` (see the module
/// documentation for the functions and their shapes). `source_display` names the file in
/// the code's header; `values` replace the file's values of the parameters they name in the
/// exported defaults (a model whose parameters were set after loading).
///
/// # Errors
/// [`GenerateError::Diagnostics`] for a model that cannot be derived (as `eomgen::model!`
/// reports it); [`GenerateError::Emit`] for a name of `values` that is not a parameter, or
/// if a function reads an input its exported signature does not have (a bug of the
/// exporter, named in the message).
pub fn export(
    file: &ModelFile,
    source_display: &str,
    language: Language,
    values: &[(String, f64)],
) -> Result<String, GenerateError> {
    let (program, derivation) = ModelProgram::from_file(file)?;
    let jacobians = derivation.jacobians();
    let mut model = Exported::new(&program, &jacobians, source_display);
    for (name, value) in values {
        match model.parameters.iter_mut().find(|(n, _)| n == name) {
            Some(slot) => slot.1 = *value,
            None => {
                let known: Vec<&str> = model.parameters.iter().map(|(n, _)| n.as_str()).collect();
                return Err(GenerateError::Emit(format!(
                    "`{name}` is not a parameter of the model (parameters: {})",
                    known.join(", ")
                )));
            }
        }
    }
    for function in &model.functions {
        function.check_inputs().map_err(GenerateError::Emit)?;
    }
    Ok(match language {
        Language::C => model.c(),
        Language::Matlab => model.matlab(),
        Language::Python => model.python(),
    })
}

/// An argument of an exported function.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Arg {
    /// `t`.
    Time,
    /// `q` (`n`).
    Q,
    /// `qd` (`n`).
    Qd,
    /// `a` (`n`), the vector of `∂(M a)/∂q`.
    A,
    /// `p`, the parameters.
    P,
}

impl Arg {
    fn name(self) -> &'static str {
        match self {
            Arg::Time => "t",
            Arg::Q => "q",
            Arg::Qd => "qd",
            Arg::A => "a",
            Arg::P => "p",
        }
    }
}

/// What an output is: a number (`T`), a vector (`F`, even of one entry) or a matrix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Shape {
    Scalar,
    Vector,
    Matrix,
}

/// An output of an exported function, its entries row-major (`rows × cols`).
struct Output {
    name: &'static str,
    rows: usize,
    cols: usize,
    shape: Shape,
    values: Vec<Value>,
}

impl Output {
    fn vector(name: &'static str, values: &[Value]) -> Self {
        Output {
            name,
            rows: values.len(),
            cols: 1,
            shape: Shape::Vector,
            values: values.to_vec(),
        }
    }

    /// A number: the tape's one output.
    fn scalar(name: &'static str, values: &[Value]) -> Self {
        Output {
            shape: Shape::Scalar,
            ..Output::vector(name, values)
        }
    }

    /// A matrix from its entries in column-major order.
    fn column_major(name: &'static str, rows: usize, cols: usize, values: &[Value]) -> Self {
        let values = (0..rows * cols)
            .map(|k| values[(k / cols) + (k % cols) * rows])
            .collect();
        Output {
            name,
            rows,
            cols,
            shape: Shape::Matrix,
            values,
        }
    }

    /// A matrix from its entries in row-major order.
    fn row_major(name: &'static str, rows: usize, cols: usize, values: &[Value]) -> Self {
        Output {
            name,
            rows,
            cols,
            shape: Shape::Matrix,
            values: values.to_vec(),
        }
    }
}

/// One exported function: a tape, its arguments and its outputs.
struct Function<'a> {
    name: &'static str,
    doc: String,
    args: &'static [Arg],
    tape: &'a Tape,
    outputs: Vec<Output>,
}

impl Function<'_> {
    /// Every input the tape reads is among the arguments.
    fn check_inputs(&self) -> Result<(), String> {
        for instruction in &self.tape.instructions {
            if let Instruction::Input(input) = instruction {
                let arg = match input {
                    Input::Parameter(_) => Arg::P,
                    Input::Coordinate(_) => Arg::Q,
                    Input::Velocity(_) => Arg::Qd,
                    Input::Acceleration(_) => Arg::A,
                    Input::Time => Arg::Time,
                    Input::Multiplier(_) => {
                        return Err(format!("`{}` reads a multiplier", self.name));
                    }
                };
                if !self.args.contains(&arg) {
                    return Err(format!(
                        "`{}` reads `{}`, which is not among its arguments",
                        self.name,
                        arg.name()
                    ));
                }
            }
        }
        Ok(())
    }

    /// Which instructions the outputs need (a `sin_cos`'s cosine needs the angle, not the
    /// sine).
    fn live(&self) -> Vec<bool> {
        let instructions = &self.tape.instructions;
        let mut live = vec![false; instructions.len()];
        for output in &self.outputs {
            for &v in &output.values {
                live[v as usize] = true;
            }
        }
        for k in (0..instructions.len()).rev() {
            if !live[k] {
                continue;
            }
            let mut mark = |v: Value| live[v as usize] = true;
            match instructions[k] {
                Instruction::Input(_) | Instruction::Const(_) => {}
                Instruction::CosOfSinCos(s) => match instructions[s as usize] {
                    Instruction::SinCos(x) => mark(x),
                    _ => mark(s),
                },
                other => {
                    other.map_operands(|v| {
                        mark(v);
                        v
                    });
                }
            }
        }
        live
    }
}

/// A model's exported functions and the data printed with them.
struct Exported<'a> {
    name: String,
    source: String,
    coordinates: Vec<String>,
    /// The generalized speeds' names, empty in the coordinates' rates.
    speeds: Vec<String>,
    parameters: Vec<(String, f64)>,
    constraints: Vec<String>,
    holonomic: usize,
    points: Vec<String>,
    initial_state: Function<'a>,
    /// What the model has that is not exported (contacts, events), as header lines.
    omitted: Vec<String>,
    /// Whether some initial values are the file's guesses (`{ guess: … }`), which eomgen
    /// solves with their rates from the constraints before integrating.
    guesses: bool,
    functions: Vec<Function<'a>>,
}

/// The arguments of each kind of function.
const STATE: &[Arg] = &[Arg::Time, Arg::Q, Arg::Qd, Arg::P];
const CONFIGURATION: &[Arg] = &[Arg::Time, Arg::Q, Arg::P];
const PRODUCT: &[Arg] = &[Arg::Time, Arg::Q, Arg::A, Arg::P];
const PARAMETERS: &[Arg] = &[Arg::P];

impl<'a> Exported<'a> {
    fn new(program: &'a ModelProgram, jacobians: &'a JacobianProgram, source: &str) -> Self {
        let d = &program.description;
        let n = d.coordinates.len();
        let outputs = |f: &FunctionTape| f.tape.outputs.clone();
        let motion = &program.mass_matrix_and_forcing;
        let (mass, forcing) = motion.tape.outputs.split_at(motion.split);
        let mut functions = vec![
            Function {
                name: "mass_matrix_and_forcing",
                doc: format!("M ({n} x {n}, symmetric) and F ({n}) of M q'' = F"),
                args: STATE,
                tape: &motion.tape,
                outputs: vec![
                    Output::column_major("M", n, n, mass),
                    Output::vector("F", forcing),
                ],
            },
            Function {
                name: "kinetic_energy",
                doc: "the kinetic energy T".to_string(),
                args: STATE,
                tape: &program.kinetic_energy.tape,
                outputs: vec![Output::scalar("T", &outputs(&program.kinetic_energy))],
            },
            Function {
                name: "potential_energy",
                doc: "the potential energy V".to_string(),
                args: CONFIGURATION,
                tape: &program.potential_energy.tape,
                outputs: vec![Output::scalar("V", &outputs(&program.potential_energy))],
            },
        ];
        for (name, label, doc, args, f) in [
            (
                "forcing_jacobian_q",
                "dF_dq",
                format!("dF/dq ({n} x {n}; entry (i, j) is dF_i/dq_j)"),
                STATE,
                &jacobians.forcing_jacobian_q,
            ),
            (
                "forcing_jacobian_qdot",
                "dF_dqd",
                format!("dF/dqd ({n} x {n})"),
                STATE,
                &jacobians.forcing_jacobian_qdot,
            ),
            (
                "mass_matrix_product_jacobian",
                "dMa_dq",
                format!("d(M a)/dq ({n} x {n}) for a vector a ({n})"),
                PRODUCT,
                &jacobians.mass_matrix_product_jacobian,
            ),
        ] {
            functions.push(Function {
                name,
                doc,
                args,
                tape: &f.tape,
                outputs: vec![Output::column_major(label, n, n, &f.tape.outputs)],
            });
        }
        if !d.points.is_empty() {
            functions.push(Function {
                name: "point_positions",
                doc: format!("[x, y, z] of each point ({} x 3)", d.points.len()),
                args: CONFIGURATION,
                tape: &program.point_positions.tape,
                outputs: vec![Output::row_major(
                    "r",
                    d.points.len(),
                    3,
                    &outputs(&program.point_positions),
                )],
            });
        }
        functions.extend(constraint_functions(
            program,
            !program.description.speeds.is_empty(),
        ));
        if d.has_speeds() {
            functions.push(Function {
                name: "coordinate_rates",
                doc: format!(
                    "the coordinates' rates q' = W(q, t) (u - Z(q, t)) ({n}) from the speeds u (qd)"
                ),
                args: STATE,
                tape: &program.coordinate_rates.tape,
                outputs: vec![Output::vector("qdot", &outputs(&program.coordinate_rates))],
            });
        }
        Exported {
            name: identifier(&d.name),
            source: source.to_string(),
            coordinates: d.coordinates.iter().map(|c| c.to_string()).collect(),
            speeds: d.speeds.iter().map(|u| u.to_string()).collect(),
            parameters: d
                .parameters
                .iter()
                .map(|p| (p.name.to_string(), p.default))
                .collect(),
            constraints: d.constraints.iter().map(|c| c.to_string()).collect(),
            holonomic: d.holonomic_constraints,
            points: d.points.iter().map(|p| p.to_string()).collect(),
            guesses: !d.initial_guesses.is_empty(),
            omitted: omitted(d),
            initial_state: Function {
                name: "initial_state",
                doc: format!("y(0) = [q(0); qd(0)] ({})", 2 * n),
                args: PARAMETERS,
                tape: &program.initial_state.tape,
                outputs: vec![Output::vector("y0", &outputs(&program.initial_state))],
            },
            functions,
        }
    }

    fn n(&self) -> usize {
        self.coordinates.len()
    }

    fn m(&self) -> usize {
        self.constraints.len()
    }

    /// The header's lines (without comment markers): what the code is and its conventions.
    fn header(&self, language: Language) -> Vec<String> {
        let (n, m) = (self.n(), self.m());
        let entry = |array: &str, i: usize| match language {
            Language::Matlab => format!("{array}({})", i + 1),
            _ => format!("{array}[{i}]"),
        };
        let mut lines = vec![
            format!(
                "The equations of motion of `{}` ({}), generated by eomgen {}.",
                self.name,
                self.source,
                env!("CARGO_PKG_VERSION")
            ),
            String::new(),
            format!("State y = [q; qd] ({} values):", 2 * n),
        ];
        for (i, c) in self.coordinates.iter().enumerate() {
            let second = match self.speeds.get(i) {
                Some(u) => format!("{u} (a generalized speed)"),
                None => format!("{c}_dot"),
            };
            lines.push(format!(
                "  {} = {c}, {} = {second}",
                entry("q", i),
                entry("qd", i)
            ));
        }
        if !self.speeds.is_empty() {
            lines.push(
                "qd holds the generalized speeds u: M u' = F are Kane's equations, and rhs takes q' from coordinate_rates.".to_string(),
            );
        }
        lines.push("Parameters p, in this order, with the file's values:".to_string());
        for (i, (name, value)) in self.parameters.iter().enumerate() {
            lines.push(format!(
                "  {} = {name} = {}",
                entry("p", i),
                literal(*value)
            ));
        }
        // In speeds the constraints are over the speeds (a non-holonomic row is its
        // auxiliary speed, held at 0).
        let a = if self.speeds.is_empty() { "q''" } else { "u'" };
        if m > 0 {
            lines.push(format!(
                "Constraints ({m}, the first {} holonomic): [M J'; J 0][{a}; lambda] = [F; gamma], so M {a} = F - J' lambda:",
                self.holonomic
            ));
            for (i, c) in self.constraints.iter().enumerate() {
                lines.push(format!("  {}: {c}", entry("lambda", i)));
            }
        }
        if m > 0 {
            // (Projection steps along dPhi/dq, which a model in speeds does not export.)
            lines.push(format!(
                "rhs integrates the index-1 system: the constraints drift by each step's error, as under any such integration (eomgen {} them).",
                if self.speeds.is_empty() {
                    "projects or stabilises"
                } else {
                    "stabilises"
                }
            ));
        }
        if !self.points.is_empty() {
            lines.push(format!(
                "Points (rows of point_positions): {}",
                self.points.join(", ")
            ));
        }
        lines.extend(self.omitted.iter().cloned());
        lines.push(String::new());
        lines.push("Functions:".to_string());
        lines.push(format!(
            "  initial_state(p): {}{}",
            self.initial_state.doc,
            if self.guesses {
                ", the file's values: some are guesses, which eomgen solves with their rates from the constraints"
            } else {
                ""
            }
        ));
        lines.push(match self.speeds.is_empty() {
            true => format!(
                "  rhs(t, y, p): dy/dt = [qd; q''] ({}), q'' {}",
                2 * n,
                if m > 0 {
                    "from the constraints' index-1 system"
                } else {
                    "from M q'' = F"
                }
            ),
            false => format!(
                "  rhs(t, y, p): dy/dt = [q'; u'] ({}), q' from coordinate_rates, u' {}",
                2 * n,
                if m > 0 {
                    "from the constraints' index-1 system (J over the speeds: each constraint row's auxiliary speed held at 0)"
                } else {
                    "from M u' = F"
                }
            ),
        });
        if m > 0 {
            lines.push(format!("  multipliers(t, q, qd, p): lambda ({m})"));
        }
        for f in &self.functions {
            let args: Vec<&str> = f.args.iter().map(|a| a.name()).collect();
            lines.push(format!("  {}({}): {}", f.name, args.join(", "), f.doc));
        }
        lines
    }
}

/// What a model has that the export leaves out, one sentence each.
fn omitted(d: &eomgen_description::ModelDescription) -> Vec<String> {
    let mut lines = Vec::new();
    if !d.contacts.is_empty() {
        lines.push(format!(
            "Not exported: the contacts ({}), their impacts, friction and changes of support; rhs is the motion while none is closed.",
            d.contacts.join(", ")
        ));
    }
    if !d.events.is_empty() {
        let names: Vec<&str> = d.events.iter().map(|e| e.name.as_ref()).collect();
        lines.push(format!("Not exported: the events ({}).", names.join(", ")));
    }
    lines
}

/// The constraints' functions of a constrained model (`Φ` where some are holonomic, `J`,
/// `γ`); none without constraints.
fn constraint_functions(program: &ModelProgram, speeds: bool) -> Vec<Function<'_>> {
    let a = if speeds { "u'" } else { "q''" };
    let d = &program.description;
    let (n, m) = (d.coordinates.len(), d.constraints.len());
    let outputs = |f: &FunctionTape| f.tape.outputs.clone();
    let mut functions = Vec::new();
    if m == 0 {
        return functions;
    }
    let holonomic = d.holonomic_constraints;
    if holonomic > 0 {
        functions.push(Function {
            name: "constraint_residuals",
            doc: format!("Phi ({holonomic}), the holonomic constraints"),
            args: CONFIGURATION,
            tape: &program.constraint_residuals.tape,
            outputs: vec![Output::vector(
                "Phi",
                &outputs(&program.constraint_residuals),
            )],
        });
    }
    functions.push(Function {
        name: "constraint_jacobian",
        doc: format!("J ({m} x {n}) of the constraints J {a} = gamma"),
        args: CONFIGURATION,
        tape: &program.constraint_jacobian.tape,
        outputs: vec![Output::row_major(
            "J",
            m,
            n,
            &outputs(&program.constraint_jacobian),
        )],
    });
    functions.push(Function {
        name: "constraint_gamma",
        doc: format!("gamma ({m}) of the constraints J {a} = gamma"),
        args: STATE,
        tape: &program.constraint_gamma.tape,
        outputs: vec![Output::vector("gamma", &outputs(&program.constraint_gamma))],
    });
    functions
}

/// The statements computing the live values of `f`'s tape: one local per operation (inputs
/// and constants are written where they are used).
fn body(s: &mut String, f: &Function, language: Language, prefix: &str) {
    let live = f.live();
    let tape = f.tape;
    for (k, instruction) in tape.instructions.iter().enumerate() {
        if !live[k] {
            continue;
        }
        let x = |v: Value| operand(tape, v, language);
        let call = |name: &str, v: Value| format!("{name}({})", x(v));
        let expr = match *instruction {
            // Written where they are used (`operand`).
            Instruction::Input(_) | Instruction::Const(_) => continue,
            Instruction::Neg(a) => format!("-{}", x(a)),
            Instruction::Add(a, b) => format!("{} + {}", x(a), x(b)),
            Instruction::Sub(a, b) => format!("{} - {}", x(a), x(b)),
            Instruction::Mul(a, b) => format!("{} * {}", x(a), x(b)),
            Instruction::Div(a, b) => format!("{} / {}", x(a), x(b)),
            Instruction::Sqrt(a) => call(function_name(language, "sqrt", prefix).as_str(), a),
            Instruction::Abs(a) => call(function_name(language, "abs", prefix).as_str(), a),
            Instruction::Call(g, a) => match (language, g) {
                // 0 for NaN, as eomgen's `sign` and `step`.
                (Language::Matlab, Func::Step) => format!("double({} >= 0)", x(a)),
                (Language::Matlab, Func::Sign) => {
                    format!("double({0} > 0) - double({0} < 0)", x(a))
                }
                (Language::Python, Func::Step) => format!("_step({})", x(a)),
                (Language::Python, Func::Sign) => format!("_sign({})", x(a)),
                _ => call(function_name(language, g.name(), prefix).as_str(), a),
            },
            Instruction::Powf(a, b) => match language {
                Language::C => format!("pow({}, {})", x(a), x(b)),
                Language::Python => format!("np.power({}, {})", x(a), x(b)),
                Language::Matlab => format!("{} ^ {}", x(a), x(b)),
            },
            Instruction::Atan2(a, b) => match language {
                Language::Python => format!("np.arctan2({}, {})", x(a), x(b)),
                _ => format!("atan2({}, {})", x(a), x(b)),
            },
            Instruction::SinCos(a) => call(function_name(language, "sin", prefix).as_str(), a),
            Instruction::CosOfSinCos(sc) => match tape.instructions[sc as usize] {
                Instruction::SinCos(a) => call(function_name(language, "cos", prefix).as_str(), a),
                _ => format!("cos({})", x(sc)),
            },
        };
        // MATLAB gives a complex number where the others give NaN (a negative base's real
        // power, the square root or logarithm of a negative number, asin or acos past ±1).
        let complex_in_matlab = matches!(
            instruction,
            Instruction::Powf(..)
                | Instruction::Sqrt(_)
                | Instruction::Call(Func::Ln | Func::Asin | Func::Acos, _)
        );
        let expr = if language == Language::Matlab && complex_in_matlab {
            format!("real_or_nan({expr})")
        } else {
            expr
        };
        let _ = match language {
            Language::C => writeln!(s, "    const double v{k} = {expr};"),
            Language::Python => writeln!(s, "    v{k} = {expr}"),
            Language::Matlab => writeln!(s, "v{k} = {expr};"),
        };
    }
}

/// A function's name in `language` (`name` as the model files write it).
fn function_name(language: Language, name: &str, prefix: &str) -> String {
    match language {
        Language::C => match name {
            "abs" => "fabs".to_string(),
            "ln" => "log".to_string(),
            "sign" | "step" => format!("{prefix}_{name}"),
            other => other.to_string(),
        },
        Language::Python => match name {
            "ln" => "np.log".to_string(),
            "asin" => "np.arcsin".to_string(),
            "acos" => "np.arccos".to_string(),
            "atan" => "np.arctan".to_string(),
            other => format!("np.{other}"),
        },
        Language::Matlab => match name {
            "ln" => "log".to_string(),
            other => other.to_string(),
        },
    }
}

/// How value `v` is written where it is used: an input as its argument's entry, a constant
/// as a literal, an operation as its local.
fn operand(tape: &Tape, v: Value, language: Language) -> String {
    let entry = |array: &str, i: u32| match language {
        Language::Matlab => format!("{array}({})", i + 1),
        _ => format!("{array}[{i}]"),
    };
    match tape.instructions[v as usize] {
        Instruction::Input(input) => match input {
            Input::Parameter(i) => entry("p", i),
            Input::Coordinate(i) => entry("q", i),
            Input::Velocity(i) => entry("qd", i),
            Input::Acceleration(i) => entry("a", i),
            // Refused by `check_inputs` before anything is printed.
            Input::Multiplier(i) => entry("lambda", i),
            Input::Time => "t".to_string(),
        },
        Instruction::Const(c) => literal_in(c, language),
        _ => format!("v{v}"),
    }
}

/// `x` as a literal that reads back to the same `f64` in every language (a negative one in
/// parentheses).
fn literal_in(x: f64, language: Language) -> String {
    if x.is_nan() {
        return match language {
            Language::C => "NAN",
            Language::Python => "np.nan",
            Language::Matlab => "NaN",
        }
        .to_string();
    }
    if x.is_infinite() {
        let inf = match language {
            Language::C => "INFINITY",
            Language::Python => "np.inf",
            Language::Matlab => "Inf",
        };
        return if x > 0.0 {
            inf.to_string()
        } else {
            format!("(-{inf})")
        };
    }
    let text = literal(x);
    if x.is_sign_negative() {
        format!("({text})")
    } else {
        text
    }
}

/// The shortest decimal that reads back to `x` (`1.0`, `0.5`, `1e-5`).
fn literal(x: f64) -> String {
    format!("{x:?}")
}

/// `name` as an identifier of every language: letters, digits and `_`, not starting with a
/// digit.
fn identifier(name: &str) -> String {
    let mut id: String = name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if !id.starts_with(|c: char| c.is_ascii_alphabetic()) {
        id.insert_str(0, "model_");
    }
    id
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn literals_read_back_to_the_same_value() {
        for x in [
            0.5,
            10.0,
            1e-5,
            -2.5,
            1.0 / 3.0,
            6.02214076e23,
            f64::MIN_POSITIVE,
        ] {
            let text = literal_in(x, Language::C);
            let parsed: f64 = text.trim_matches(|c| c == '(' || c == ')').parse().unwrap();
            assert_eq!(parsed.to_bits(), x.to_bits(), "{text}");
        }
        assert_eq!(literal_in(-1.0, Language::Python), "(-1.0)");
        assert_eq!(literal_in(f64::INFINITY, Language::Matlab), "Inf");
        assert_eq!(literal_in(f64::NEG_INFINITY, Language::C), "(-INFINITY)");
    }

    #[test]
    fn identifiers_are_valid_in_every_language() {
        assert_eq!(identifier("double_pendulum"), "double_pendulum");
        assert_eq!(identifier("2-link arm"), "model_2_link_arm");
        assert_eq!(identifier("_x"), "model__x");
    }

    /// MATLAB's `sqrt`, `^`, `log`, `asin` and `acos` of arguments out of their real domain
    /// return NaN, as eomgen's do, not a complex number; `sign` is 0 for NaN in MATLAB and
    /// Python; a model named as one of the file's local functions gets another name.
    #[test]
    fn out_of_domain_values_and_clashing_names_are_handled() {
        let source = "name: rhs\ncoordinates: [x]\nkinetic: x_dot^2/2\npotential: sqrt(x) + x^1.5 + ln(x) + asin(x) + acos(x) + sign(x)\ninitial: {x: 0.5}\n";
        let file = crate::model::load("rhs.yaml", source).unwrap();
        let matlab = export(&file, "rhs.yaml", Language::Matlab, &[]).unwrap();
        assert!(
            matlab.starts_with("function model = rhs_model()"),
            "{matlab}"
        );
        for f in ["sqrt(", "log(", "asin(", "acos("] {
            assert!(
                matlab.contains(&format!("real_or_nan({f}")),
                "{f}: {matlab}"
            );
        }
        assert!(matlab.contains("real_or_nan(q(1) ^ 1.5)"), "{matlab}");
        assert!(
            matlab.contains("double(q(1) > 0) - double(q(1) < 0)"),
            "{matlab}"
        );
        let python = export(&file, "rhs.yaml", Language::Python, &[]).unwrap();
        assert!(python.contains("_sign(q[0])"), "{python}");
    }

    #[test]
    fn matrices_are_written_row_major() {
        // Column-major [a c; b d] as tape outputs [a, b, c, d].
        let o = Output::column_major("M", 2, 2, &[0, 1, 2, 3]);
        assert_eq!(o.values, [0, 2, 1, 3]);
        let o = Output::column_major("B", 2, 3, &[0, 1, 2, 3, 4, 5]);
        assert_eq!(o.values, [0, 2, 4, 1, 3, 5]);
    }
}
