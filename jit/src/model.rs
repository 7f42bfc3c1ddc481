//! [`JitModel`]: a model file loaded, derived and compiled at run time.

use std::borrow::Cow;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

use eomgen_runtime::dynamic::{rates_are_the_state, rates_are_the_state_jacobian};
use eomgen_runtime::taylor::{
    DerivedLists, FactorForm, MotionLayout, MotionSolve, TaylorFunctions, TaylorProgram,
    TaylorUnsupported, UNROLLED_CAPACITY,
};
use eomgen_runtime::{DynMechanicalSystem, ModelDescription, UnknownParameter};
use eomgen_symbolic::codegen::GenerateError;
use eomgen_symbolic::codegen::program::{Derivation, ModelProgram};
use eomgen_symbolic::codegen::taylor::{TaylorPlan, model_taylor_plan};
use eomgen_symbolic::model::{Diagnostic, ReadError, read_model_file};

use crate::compiled::{Compiled, Extent, FusedRhs, HotRoutine, SCRATCH, call, call_native};
use crate::first_order::first_order_tape;
use crate::native::CompileError;
use crate::taylor::{FACTOR_DENSE, FACTOR_DIAGONAL, FACTOR_SMALL, NativeOrders, OrderFrame};
use crate::{Backend, Inputs, interpret};

/// Why a model file could not be made into a run-time model.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LoadError {
    /// The file could not be read: the operating system's error, or a file larger than
    /// [`eomgen_symbolic::model::MAX_FILE_BYTES`].
    #[error("cannot read `{path}`: {source}")]
    Read {
        /// The path as given.
        path: String,
        /// Why ([`ReadError::Io`] or [`ReadError::TooLarge`]; a file that is not UTF-8 is
        /// [`LoadError::Diagnostics`]).
        source: ReadError,
    },
    /// The file has mistakes: the located diagnostics `eomgen::model!` reports for it (YAML,
    /// schema, cross-object rules, units, and after the derivation a singular mass matrix).
    #[error("{} error(s) in the model file `{path}`", diagnostics.len())]
    Diagnostics {
        /// The path as given (the diagnostics' file name).
        path: String,
        /// The file's text, for rendering the diagnostics with their source lines
        /// ([`Diagnostic::render`]).
        text: String,
        /// Every mistake found, in file order.
        diagnostics: Vec<Diagnostic>,
    },
    /// A function of the model could not be compiled to native code.
    #[error(transparent)]
    Compile(#[from] CompileError),
    /// The derived code could not be planned (a bug of the code generator; the message says
    /// where).
    #[error("{0}")]
    Generate(String),
}

/// How [`JitModel::load_with`] builds a model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LoadOptions {
    /// Force a backend: `None` (the default) compiles to native code and falls back to the
    /// interpreter only where Cranelift has no code generator for the host;
    /// `Some(Backend::Interpreter)` never compiles; `Some(Backend::Native)` makes an
    /// unsupported host an error ([`CompileError::UnsupportedHost`]).
    pub backend: Option<Backend>,
    /// Derive and compile the exact Jacobians (`∂F/∂q`, `∂F/∂q̇`, `∂(M a)/∂q`) at load time
    /// rather than when first used (the default: simulation with an explicit method never
    /// uses them, and for a 40-link chain they are three quarters of the code).
    pub eager_jacobians: bool,
    /// Print the equations as MathML into the description
    /// ([`ModelDescription::equations_mathml`](eomgen_runtime::ModelDescription::equations_mathml))
    /// at load time; without it that field is `None`. Compiled models always carry it.
    pub equations_mathml: bool,
    /// Compile the Taylor method's orders to native code at the first Taylor series, rather
    /// than after [`COMPILE_TAYLOR_AFTER`] of them computed by the runtime's kernels (the
    /// same bits either way; with the interpreter backend they are never compiled).
    pub eager_taylor: bool,
}

/// The functions of a model: the first sixteen in the order of [`ModelProgram::functions`],
/// then the Jacobians in the order of
/// [`JacobianProgram::functions`](eomgen_symbolic::codegen::program::JacobianProgram::functions).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Routine {
    InitialState = 0,
    MassMatrixAndForcing = 1,
    KineticEnergy = 2,
    PotentialEnergy = 3,
    PointPositions = 4,
    ConstraintResiduals = 5,
    ConstraintJacobian = 6,
    ConstraintVelocityResiduals = 7,
    ConstraintGamma = 8,
    EventValues = 9,
    EquilibriumGuesses = 10,
    ContactGaps = 11,
    ContactJacobian = 12,
    ContactCoefficients = 13,
    SupportChanges = 14,
    CoordinateRates = 15,
    ForcingJacobianQ = 16,
    ForcingJacobianQdot = 17,
    MassMatrixProductJacobian = 18,
    CoordinateRatesJacobian = 19,
}

/// Index of the first Jacobian routine.
const JACOBIANS: usize = Routine::ForcingJacobianQ as usize;

/// The Jacobians, compiled when first needed, and why they are interpreted if they are.
#[derive(Debug)]
struct LazyJacobians {
    compiled: Compiled,
    fallback_reason: Option<CompileError>,
}

/// What clones of a model share: the planned functions and their native code.
#[derive(Debug)]
struct Code {
    program: ModelProgram,
    core: Compiled,
    backend: Option<Backend>,
    fallback_reason: Option<CompileError>,
    /// The derivation the Jacobians come from, until they are compiled.
    derivation: Mutex<Option<Derivation>>,
    jacobians: OnceLock<LazyJacobians>,
    /// The Taylor recurrences ([`eomgen_symbolic::codegen::taylor`]), or why there are none.
    taylor: Result<TaylorPlan, TaylorUnsupported>,
    /// The recurrences' orders compiled to native code ([`Code::taylor_orders`]; `None`:
    /// interpreted, Cranelift having failed on them or no order fitting the cache).
    taylor_orders: OnceLock<Option<NativeOrders>>,
    /// Taylor series computed so far without the compiled orders.
    taylor_series: AtomicUsize,
    /// How many before they are compiled ([`LoadOptions::eager_taylor`]).
    compile_taylor_after: usize,
}

/// Taylor series a run-time model computes with the runtime's kernels before its orders are
/// compiled to native code: compiling the double pendulum's 18 orders costs 20–30 ms, what
/// about 20,000 of its series at tol 1e-9 cost with the kernels (1.3 µs each, against 0.5 µs
/// compiled), so a run never pays more than about twice what the better choice in hindsight
/// costs (the rent-or-buy rule), and a short run pays nothing. (Compiling them on a thread of
/// their own from the 1,000th series instead made runs of 10–30 ms 10–20 % slower in wall
/// time and 50–75 % in processor time on the 2-core development machine, and runs of 60 ms
/// 22 % faster: docs/performance.md.)
pub const COMPILE_TAYLOR_AFTER: usize = 20_000;

impl Code {
    /// Whether the Taylor orders may be compiled to native code: a model with recurrences
    /// and the native backend.
    fn taylor_native(&self) -> bool {
        self.taylor.is_ok() && self.backend != Some(Backend::Interpreter)
    }

    /// The Taylor orders compiled to native code ([`crate::taylor`]) once they are: from the
    /// first series with [`LoadOptions::eager_taylor`], else from series
    /// [`COMPILE_TAYLOR_AFTER`] + 1. `None` before, and for good if Cranelift fails on them or
    /// no order fits the instruction cache; until then the series are the runtime's kernels'
    /// (`evaluate_order`, the same bits).
    fn taylor_orders(&self) -> Option<&NativeOrders> {
        if let Some(compiled) = self.taylor_orders.get() {
            return compiled.as_ref();
        }
        if !self.taylor_native()
            || self.taylor_series.fetch_add(1, Ordering::Relaxed) < self.compile_taylor_after
        {
            return None;
        }
        // Compiled outside the cell's lock (a thread racing here may compile them too, and
        // one result is kept): a process forked while the lock is held would wait on it for
        // good.
        let compiled = self.compile_orders();
        let _ = self.taylor_orders.set(compiled);
        self.taylor_orders.get().and_then(Option::as_ref)
    }

    /// Compiles the Taylor orders; `None` if Cranelift fails or panics on them (the orders
    /// are then the kernels' for good, not a compilation attempted again at every series),
    /// or no order fits the instruction cache. Out of line: inlined, its frame (Cranelift's
    /// context) made every call of the orders probe its stack.
    #[cold]
    #[inline(never)]
    fn compile_orders(&self) -> Option<NativeOrders> {
        let plan = self.taylor.as_ref().ok()?;
        std::panic::catch_unwind(|| {
            crate::taylor::compile_orders(plan, self.program.description.parameters.len())
        })
        .ok()?
        .ok()
        .flatten()
    }

    /// The Jacobians, derived and compiled on first use. A function Cranelift cannot compile
    /// is interpreted instead (the reason is kept: [`JitModel::fallback_reason`]).
    fn jacobians(&self) -> &LazyJacobians {
        self.jacobians.get_or_init(|| {
            let derivation = match self.derivation.lock() {
                Ok(mut d) => d.take(),
                Err(poisoned) => poisoned.into_inner().take(),
            };
            let program = derivation.map(Derivation::jacobians).unwrap_or_default();
            let functions = program.functions();
            match Compiled::new(&functions, None, self.backend) {
                Ok((compiled, fallback_reason)) => LazyJacobians {
                    compiled,
                    fallback_reason,
                },
                Err(reason) => LazyJacobians {
                    compiled: Compiled::interpreted(&functions),
                    fallback_reason: Some(reason),
                },
            }
        })
    }
}

/// A model file compiled at run time: the equations of motion of any file, with no rebuild.
///
/// Built by [`JitModel::load`] (or [`JitModel::from_source`]); implements
/// [`DynMechanicalSystem`], so [`eomgen_runtime::DynFirstOrder::new`] makes it a
/// [`eomgen_runtime::ModelInfo`] for every analysis. Parameters start at the file's defaults
/// and are set by name ([`DynMechanicalSystem::set_parameter`]). Cloning is cheap: clones
/// share the compiled code (and each has its own parameter values).
///
/// # Panics
/// The evaluation methods panic if a slice is shorter than the shapes of
/// [`DynMechanicalSystem`] require (a programmer error; the native code is never called
/// with too short a buffer).
#[derive(Debug, Clone)]
pub struct JitModel {
    code: Arc<Code>,
    parameters: Vec<f64>,
    /// The native `mass_matrix_and_forcing`, held here rather than behind the `Arc` because
    /// every right-hand side calls it.
    mass_and_forcing: Option<HotRoutine>,
    /// The native `ẏ = [q̇; M⁻¹F]` of a small unconstrained model ([`crate::first_order`]),
    /// held here for the same reason.
    first_order: Option<FusedRhs>,
}

impl JitModel {
    /// Loads, checks, derives and compiles the model file at `path` (native code, or the
    /// interpreter where the host has no code generator).
    ///
    /// # Errors
    /// [`LoadError::Read`] if the file cannot be read or is larger than
    /// [`eomgen_symbolic::model::MAX_FILE_BYTES`]; [`LoadError::Diagnostics`] with every
    /// located mistake of the file, as `eomgen::model!` reports them; [`LoadError::Compile`]
    /// naming the function that could not be compiled.
    pub fn load(path: impl AsRef<std::path::Path>) -> Result<JitModel, LoadError> {
        Self::load_with(path, LoadOptions::default())
    }

    /// [`Self::load`] with options.
    ///
    /// # Errors
    /// As [`Self::load`].
    pub fn load_with(
        path: impl AsRef<std::path::Path>,
        options: LoadOptions,
    ) -> Result<JitModel, LoadError> {
        let path = path.as_ref();
        let display = path.display().to_string();
        let source = read_model_file(path).map_err(|e| match e {
            ReadError::NotText { diagnostic, text } => LoadError::Diagnostics {
                path: display.clone(),
                text,
                diagnostics: vec![diagnostic],
            },
            source => LoadError::Read {
                path: display.clone(),
                source,
            },
        })?;
        Self::from_source_with(&display, &source, options)
    }

    /// Builds the model of a file's text; `path` names the file in diagnostics.
    ///
    /// # Errors
    /// As [`Self::load`], but for reading.
    pub fn from_source(path: &str, source: &str) -> Result<JitModel, LoadError> {
        Self::from_source_with(path, source, LoadOptions::default())
    }

    /// [`Self::from_source`] with options.
    ///
    /// # Errors
    /// As [`Self::load`], but for reading.
    pub fn from_source_with(
        path: &str,
        source: &str,
        options: LoadOptions,
    ) -> Result<JitModel, LoadError> {
        let diagnostics = |diagnostics: Vec<Diagnostic>| LoadError::Diagnostics {
            path: path.to_string(),
            text: source.to_string(),
            diagnostics,
        };
        let file = eomgen_symbolic::model::load(path, source).map_err(diagnostics)?;
        let (program, derivation) = ModelProgram::from_file(&file).map_err(|e| match e {
            GenerateError::Diagnostics(d) => diagnostics(d),
            GenerateError::Emit(message) => LoadError::Generate(message),
        })?;
        Self::from_program(program, derivation, options)
    }

    /// Compiles a planned model ([`ModelProgram::from_file`]); the Jacobians are derived from
    /// `derivation` when first used (or now, with [`LoadOptions::eager_jacobians`]).
    ///
    /// # Errors
    /// [`LoadError::Compile`] naming the function that could not be compiled (or the host,
    /// with `Some(Backend::Native)`).
    pub fn from_program(
        program: ModelProgram,
        derivation: Derivation,
        options: LoadOptions,
    ) -> Result<JitModel, LoadError> {
        // The fused right-hand side, compiled with the model's own functions where they are
        // compiled; not in generalized speeds, whose rates are not `q̇ = u`.
        let n = program.num_dofs();
        let fused = (program.description.constraints.is_empty()
            && !program.description.has_speeds()
            && options.backend != Some(Backend::Interpreter))
        .then(|| first_order_tape(&program.mass_matrix_and_forcing, n))
        .flatten();
        let (core, fallback_reason) = Compiled::new(
            &program.functions(),
            fused.as_ref().map(|f| (f, n)),
            options.backend,
        )?;
        // The tapes live on in `core`; the program keeps the names and constants.
        let mut program = program;
        if options.equations_mathml {
            program.description.equations_mathml = Some(
                derivation
                    .equations_mathml()
                    .into_iter()
                    .map(std::borrow::Cow::Owned)
                    .collect(),
            );
        }
        let taylor = model_taylor_plan(&program);
        program.clear_tapes();
        let parameters: Vec<f64> = program.description.parameter_defaults();
        let code = Arc::new(Code {
            program,
            core,
            backend: options.backend,
            fallback_reason,
            derivation: Mutex::new(Some(derivation)),
            jacobians: OnceLock::new(),
            taylor,
            taylor_orders: OnceLock::new(),
            taylor_series: AtomicUsize::new(0),
            compile_taylor_after: if options.eager_taylor {
                0
            } else {
                COMPILE_TAYLOR_AFTER
            },
        });
        if options.eager_jacobians
            && let Some(e @ CompileError::Function { .. }) = &code.jacobians().fallback_reason
        {
            return Err(e.clone().into());
        }
        let index = Routine::MassMatrixAndForcing as usize;
        let mass_and_forcing = code
            .core
            .native
            .as_ref()
            .and_then(|n| n.functions[index])
            .and_then(|f| HotRoutine::new(f, &code.core.extents[index], parameters.len()));
        let first_order = code
            .core
            .native
            .as_ref()
            .and_then(|native| native.first_order)
            .zip(fused.as_ref())
            .and_then(|(f, tape)| FusedRhs::new(f, &Extent::of(tape), n, parameters.len()));
        Ok(JitModel {
            code,
            parameters,
            mass_and_forcing,
            first_order,
        })
    }

    /// Which evaluator runs this model's functions (its Jacobians, compiled when first used,
    /// run natively too unless [`Self::fallback_reason`] says otherwise).
    pub fn backend(&self) -> Backend {
        if self.code.core.native.is_some() {
            Backend::Native
        } else {
            Backend::Interpreter
        }
    }

    /// Why functions of the model are interpreted although native code was asked for: the
    /// host has no code generator, or (for the Jacobians, compiled on first use) Cranelift
    /// failed on one; `None` when everything compiled so far runs natively or the
    /// interpreter was chosen.
    pub fn fallback_reason(&self) -> Option<&CompileError> {
        self.code.fallback_reason.as_ref().or_else(|| {
            self.code
                .jacobians
                .get()
                .and_then(|j| j.fallback_reason.as_ref())
        })
    }

    /// Bytes of machine code of the model's functions so far (0 when interpreted; the
    /// Jacobians count once compiled). The executable memory mapped for them is this rounded
    /// up to whole pages, and is unmapped when the last clone of the model is dropped.
    pub fn code_bytes(&self) -> usize {
        let bytes = |c: &Compiled| c.native.as_ref().map_or(0, |n| n.code_bytes);
        bytes(&self.code.core) + self.code.jacobians.get().map_or(0, |j| bytes(&j.compiled))
    }

    /// [`Self::run`] out of the caller's line: the path of the hot routine when it is not
    /// native.
    #[cold]
    #[inline(never)]
    fn run_cold(
        &self,
        routine: Routine,
        q: &[f64],
        qdot: &[f64],
        t: f64,
        out0: &mut [f64],
        out1: &mut [f64],
    ) {
        self.run(routine, self.inputs(q, qdot, t), out0, out1);
    }

    fn run(&self, routine: Routine, inputs: Inputs<'_>, out0: &mut [f64], out1: &mut [f64]) {
        let (compiled, index) = match routine as usize {
            i if i < JACOBIANS => (&self.code.core, i),
            i => (&self.code.jacobians().compiled, i - JACOBIANS),
        };
        let Some(extent) = compiled.extents.get(index) else {
            return;
        };
        assert!(
            extent.admits(&inputs, out0.len(), out1.len()),
            "model `{}`: a slice passed to {routine:?} is shorter than its shape",
            self.code.program.description.name
        );
        if let Some(native) = &compiled.native {
            // An empty tape (a model without constraints, events, …) has no code and no
            // outputs to write.
            if let Some(f) = native.functions[index] {
                // SAFETY: `f` was compiled from this routine's tape, of which `extent` is the
                // extent, and `admits` checked every slice above.
                unsafe { call_native(f, extent, &inputs, out0, out1) }
            }
            return;
        }
        let Some(tape) = compiled.tapes.get(index) else {
            return;
        };
        SCRATCH.with(|scratch| match scratch.try_borrow_mut() {
            Ok(mut values) => interpret::evaluate(tape, &inputs, &mut values, out0, out1),
            // Re-entered on this thread (cannot happen: evaluation calls no model code); use a
            // fresh buffer rather than fail.
            Err(_) => interpret::evaluate(tape, &inputs, &mut Vec::new(), out0, out1),
        });
    }

    #[inline(always)]
    fn inputs<'a>(&'a self, q: &'a [f64], qdot: &'a [f64], t: f64) -> Inputs<'a> {
        Inputs {
            parameters: &self.parameters,
            q,
            qdot,
            acceleration: &[],
            lambda: &[],
            t,
        }
    }
}

impl DynMechanicalSystem for JitModel {
    fn description(&self) -> &ModelDescription {
        &self.code.program.description
    }
    #[inline]
    fn taylor(&self) -> Result<&dyn TaylorFunctions, TaylorUnsupported> {
        match &self.code.taylor {
            Ok(_) => Ok(Recurrences::of(self)),
            Err(reason) => Err(reason.clone()),
        }
    }
    fn parameter_values(&self) -> Vec<f64> {
        self.parameters.clone()
    }
    fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), UnknownParameter> {
        match self.code.program.description.parameter_index(name) {
            Some(i) => {
                self.parameters[i] = value;
                Ok(())
            }
            None => Err(UnknownParameter {
                model: self.code.program.description.name.to_string(),
                name: name.to_string(),
                known: self.code.program.description.parameter_names().join(", "),
            }),
        }
    }
    fn initial_state(&self, q: &mut [f64], qdot: &mut [f64]) {
        let n = self.num_dofs();
        let mut out = vec![0.0; 2 * n];
        self.run(
            Routine::InitialState,
            self.inputs(&[], &[], 0.0),
            &mut out,
            &mut [],
        );
        q[..n].copy_from_slice(&out[..n]);
        qdot[..n].copy_from_slice(&out[n..]);
    }
    // Inlined into the caller's right-hand side (another crate), where most sizes are known:
    // a call level less on the hot path of every integrator.
    #[inline(always)]
    fn mass_matrix_and_forcing(
        &self,
        q: &[f64],
        qdot: &[f64],
        t: f64,
        mass: &mut [f64],
        forcing: &mut [f64],
    ) {
        if let Some(hot) = self.mass_and_forcing
            && q.len() >= hot.q
            && qdot.len() >= hot.qdot
            && mass.len() >= hot.out0
            && forcing.len() >= hot.out1
        {
            let inputs = self.inputs(q, qdot, t);
            // SAFETY: `hot.f` is the native code of this routine's tape; it reads at most
            // `hot.q` and `hot.qdot` values of `q` and `q̇` (checked above), at most the
            // model's parameters and no accelerations or multipliers (`HotRoutine::new`),
            // writes `hot.out0` and `hot.out1` values (checked above) and uses no scratch.
            unsafe {
                call(
                    hot.f,
                    &inputs,
                    mass.as_mut_ptr(),
                    forcing.as_mut_ptr(),
                    std::ptr::null_mut(),
                )
            }
        } else {
            // Interpreted, a large function, or a slice too short (which `run` reports).
            self.run_cold(Routine::MassMatrixAndForcing, q, qdot, t, mass, forcing);
        }
    }
    #[inline(always)]
    fn first_order_rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) -> Option<bool> {
        let FusedRhs { f, n } = self.first_order?;
        if y.len() < 2 * n || dy.len() < 2 * n {
            return None;
        }
        // SAFETY: `f` is the native code of the fused tape (`first_order_tape`); it reads at
        // most `2n` values of `y` and the model's parameters and writes `2n` values to `dy`
        // (`FusedRhs::new`; the lengths are checked above).
        let verdict = unsafe { f(self.parameters.as_ptr(), y.as_ptr(), t, dy.as_mut_ptr()) };
        Some(verdict != 0)
    }
    fn forcing_jacobian_q(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]) {
        self.run(
            Routine::ForcingJacobianQ,
            self.inputs(q, qdot, t),
            out,
            &mut [],
        );
    }
    fn forcing_jacobian_qdot(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]) {
        self.run(
            Routine::ForcingJacobianQdot,
            self.inputs(q, qdot, t),
            out,
            &mut [],
        );
    }
    fn mass_matrix_product_jacobian(&self, q: &[f64], t: f64, a: &[f64], out: &mut [f64]) {
        let inputs = Inputs {
            acceleration: a,
            ..self.inputs(q, &[], t)
        };
        self.run(Routine::MassMatrixProductJacobian, inputs, out, &mut []);
    }
    fn coordinate_rates(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]) {
        if !self.code.program.description.has_speeds() {
            return rates_are_the_state(self.num_dofs(), qdot, out);
        }
        self.run(
            Routine::CoordinateRates,
            self.inputs(q, qdot, t),
            out,
            &mut [],
        );
    }
    fn coordinate_rates_jacobian(
        &self,
        q: &[f64],
        qdot: &[f64],
        t: f64,
        d_q: &mut [f64],
        d_u: &mut [f64],
    ) {
        if !self.code.program.description.has_speeds() {
            return rates_are_the_state_jacobian(self.num_dofs(), d_q, d_u);
        }
        // Every entry is written: a zero entry is a constant of the tape.
        self.run(
            Routine::CoordinateRatesJacobian,
            self.inputs(q, qdot, t),
            d_q,
            d_u,
        );
    }
    fn kinetic_energy(&self, q: &[f64], qdot: &[f64], t: f64) -> f64 {
        let mut out = [0.0];
        self.run(
            Routine::KineticEnergy,
            self.inputs(q, qdot, t),
            &mut out,
            &mut [],
        );
        out[0]
    }
    fn potential_energy(&self, q: &[f64], t: f64) -> f64 {
        let mut out = [0.0];
        self.run(
            Routine::PotentialEnergy,
            self.inputs(q, &[], t),
            &mut out,
            &mut [],
        );
        out[0]
    }
    fn point_positions(&self, q: &[f64], t: f64, out: &mut [[f64; 3]]) {
        let flat = out.as_flattened_mut();
        self.run(
            Routine::PointPositions,
            self.inputs(q, &[], t),
            flat,
            &mut [],
        );
    }
    fn constraint_residuals(&self, q: &[f64], t: f64, out: &mut [f64]) {
        self.run(
            Routine::ConstraintResiduals,
            self.inputs(q, &[], t),
            out,
            &mut [],
        );
    }
    fn constraint_jacobian(&self, q: &[f64], t: f64, out: &mut [f64]) {
        self.run(
            Routine::ConstraintJacobian,
            self.inputs(q, &[], t),
            out,
            &mut [],
        );
    }
    fn constraint_velocity_residuals(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]) {
        self.run(
            Routine::ConstraintVelocityResiduals,
            self.inputs(q, qdot, t),
            out,
            &mut [],
        );
    }
    fn constraint_gamma(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]) {
        self.run(
            Routine::ConstraintGamma,
            self.inputs(q, qdot, t),
            out,
            &mut [],
        );
    }
    fn equilibrium_guesses(&self, out: &mut [f64]) {
        self.run(
            Routine::EquilibriumGuesses,
            self.inputs(&[], &[], 0.0),
            out,
            &mut [],
        );
    }
    fn contact_gaps(&self, q: &[f64], qdot: &[f64], t: f64, out: &mut [f64]) {
        self.run(Routine::ContactGaps, self.inputs(q, qdot, t), out, &mut []);
    }
    fn contact_jacobian(&self, q: &[f64], t: f64, out: &mut [f64]) {
        self.run(
            Routine::ContactJacobian,
            self.inputs(q, &[], t),
            out,
            &mut [],
        );
    }
    fn contact_coefficients(&self, out: &mut [f64]) {
        self.run(
            Routine::ContactCoefficients,
            self.inputs(&[], &[], 0.0),
            out,
            &mut [],
        );
    }
    fn support_changes(&self, q: &[f64], t: f64, out: &mut [f64]) {
        self.run(
            Routine::SupportChanges,
            self.inputs(q, &[], t),
            out,
            &mut [],
        );
    }
    fn event_values(
        &self,
        q: &[f64],
        qdot: &[f64],
        t: f64,
        qddot: &[f64],
        lambda: &[f64],
        out: &mut [f64],
    ) {
        let needed = self.code.core.extents[Routine::EventValues as usize];
        // A multiplier the caller does not have reads NaN, as in the compiled model.
        let padded: Vec<f64>;
        let lambda = if lambda.len() >= needed.lambda {
            lambda
        } else {
            padded = (0..needed.lambda)
                .map(|i| lambda.get(i).copied().unwrap_or(f64::NAN))
                .collect();
            &padded
        };
        let inputs = Inputs {
            acceleration: qddot,
            lambda,
            ..self.inputs(q, qdot, t)
        };
        self.run(Routine::EventValues, inputs, out, &mut []);
    }
}

/// The program of no model: what [`TaylorFunctions::program`] of a [`JitModel`] without
/// recurrences would read ([`Recurrences`], which [`DynMechanicalSystem::taylor`] never hands
/// out for such a model).
static EMPTY_PROGRAM: TaylorProgram = TaylorProgram {
    slots: 0,
    coordinates: Cow::Borrowed(&[]),
    velocities: Cow::Borrowed(&[]),
    time: None,
    mass_matrix: Cow::Borrowed(&[]),
    forcing: Cow::Borrowed(&[]),
    constant: Cow::Borrowed(&[]),
    ops: Cow::Borrowed(&[]),
    derived: DerivedLists {
        varying_mass_entries: Cow::Borrowed(&[]),
        inputs: Cow::Borrowed(&[]),
        convolutions: 0,
        branch_points: Cow::Borrowed(&[]),
    },
};

/// A [`JitModel`] that has recurrences, as its Taylor method ([`TaylorFunctions`]):
/// [`DynMechanicalSystem::taylor`] hands the model out as this type only then, so that no
/// caller runs the Taylor method of a model without recurrences.
#[repr(transparent)]
struct Recurrences(JitModel);

impl Recurrences {
    /// `model` as its Taylor method (which reads [`EMPTY_PROGRAM`] without recurrences).
    fn of(model: &JitModel) -> &Self {
        // SAFETY: `Recurrences` is `repr(transparent)` over `JitModel`: the same layout.
        unsafe { &*std::ptr::from_ref(model).cast::<Self>() }
    }
}

/// The model's Taylor method: order 0 compiled with the orders (at their stride) or interpreted, orders on
/// the runtime's kernels (the trait's default `order`, the definitions the compiled model's
/// code inlines) until they are compiled ([`Code::taylor_orders`]); the same bits.
impl TaylorFunctions for Recurrences {
    fn program(&self) -> &TaylorProgram {
        match &self.0.code.taylor {
            Ok(plan) => &plan.program,
            // Not handed out without a plan.
            Err(_) => &EMPTY_PROGRAM,
        }
    }
    fn order_zero(&self, capacity: usize, series: &mut [f64]) {
        if let Ok(plan) = &self.0.code.taylor {
            // Compiled with the orders (at their stride), else interpreted: the same bits.
            if let Some(Some(orders)) = self.0.code.taylor_orders.get()
                && capacity == UNROLLED_CAPACITY
                && series.len() >= plan.order_zero.instructions.len() * UNROLLED_CAPACITY
            {
                // SAFETY: `series` holds every instruction's slot at the stride of 25
                // (checked above) and the caller has written the inputs' order 0;
                // `parameters` holds the model's parameters, the count the code was
                // compiled for.
                unsafe { (orders.order_zero)(series.as_mut_ptr(), self.0.parameters.as_ptr()) };
                return;
            }
            interpret::order_zero_in_place(&plan.order_zero, &self.0.parameters, capacity, series);
        }
    }
    fn orders(
        &self,
        solve: &mut MotionSolve<'_>,
        order: usize,
        series: &mut [f64],
        out: &mut [f64],
    ) -> usize {
        let (Ok(plan), Some(orders)) = (&self.0.code.taylor, self.0.code.taylor_orders()) else {
            return 0;
        };
        let program = &plan.program;
        let n = program.coordinates.len();
        // The code's offsets assume the stride of 25 and every slot present, and the orders
        // it computes (below `order`, to `highest`) write `out` to the next one.
        let computed = order.min(orders.highest + 1);
        if !solve.unrolled()
            || series.len() < (program.slots + program.forcing.len()) * UNROLLED_CAPACITY
            || out.len() < (computed + 1) * 2 * n
        {
            return 0;
        }
        // With a diagonal factor, or any of `n ≤ 6`, the code solves in line (the same
        // operations as `motion_order`'s), else it calls `solve_order`.
        let (lower, inverse_pivots, mode) = match solve.factor_form() {
            FactorForm::Diagonal(inverse) if inverse.len() == n => {
                (std::ptr::null(), inverse.as_ptr(), FACTOR_DIAGONAL)
            }
            FactorForm::Dense(lower, inverse) if lower.len() == n * n && inverse.len() == n => {
                (lower.as_ptr(), inverse.as_ptr(), FACTOR_DENSE)
            }
            FactorForm::Small(lower, inverse) if lower.len() == n * n && inverse.len() == n => {
                (lower.as_ptr(), inverse.as_ptr(), FACTOR_SMALL)
            }
            _ => (std::ptr::null(), std::ptr::null(), 0),
        };
        // The scratch of the workspace, kept between steps.
        let scratch = solve.lanes(orders.scratch_units).as_mut_ptr();
        let (series_len, out_len) = (series.len(), out.len());
        let (series, out) = (series.as_mut_ptr(), out.as_mut_ptr());
        // What `solve_order` needs, only where the code calls it (the factors solved in line
        // never do): built at every step, it was about 25 stores.
        let mut context = (mode == 0).then(|| OrderContext {
            layout: MotionLayout {
                forcing: &program.forcing,
                coupled: &program.derived.varying_mass_entries,
                inputs: &program.derived.inputs,
                time: program.time,
                accelerations: program.acceleration_slot(),
            },
            solve,
            series,
            series_len,
            out,
            out_len,
        });
        let frame = OrderFrame {
            context: context.as_mut().map_or(std::ptr::null_mut(), |context| {
                (&raw mut *context).cast::<u8>()
            }),
            solve: solve_order,
            lower,
            inverse_pivots,
            factor: mode,
        };
        for function in &orders.orders[..computed] {
            // SAFETY: `series` holds every slot at the stride of 25 with the orders below `k`
            // computed (by the calls before this one), and `out` every order the code writes
            // (checked above); `frame`'s `lower` and `inverse_pivots`, when not null, hold
            // `n × n` and `n` values that nothing writes during the call, and the code calls
            // `solve_order` only with `factor` 0 (every constrained model's), for which the
            // context is built (`solve_order` refuses a null one);
            // `scratch` holds the units the orders
            // use, with the orders below `k` written by the calls before, and nothing
            // `solve_order` reaches (`motion_order_at`) touches the workspace's lanes, so
            // they are not reallocated under the code; `series`, `out`, `scratch` and `frame`
            // are not used otherwise until the call returns.
            let status = unsafe { function(series, scratch, out, &raw const frame) };
            if status != 0 {
                return 0;
            }
        }
        computed
    }
    fn fused_orders(&self) -> usize {
        // None before they are compiled: until then the workspace's stride follows the
        // kernels' rule (`TaylorProgram::unrolled_code_fits`), as for a model without them.
        self.0
            .code
            .taylor_orders
            .get()
            .and_then(Option::as_ref)
            .map_or(0, |orders| orders.highest)
    }
}

/// What the compiled Taylor orders pass to [`solve_order`] between orders.
struct OrderContext<'a, 'b> {
    layout: MotionLayout<'a>,
    solve: &'a mut MotionSolve<'b>,
    series: *mut f64,
    series_len: usize,
    out: *mut f64,
    out_len: usize,
}

/// Order `k` of `M a = F` for the compiled Taylor orders
/// ([`eomgen_runtime::taylor::motion_order_at`]); non-zero if it panicked (the orders then
/// stop and report none computed, and the step computes them again by the runtime's
/// kernels: a panic must not unwind through the compiled code).
extern "C" fn solve_order(context: *mut u8, k: usize) -> u8 {
    // Built only for the factors the code does not solve in line (`orders`), which include
    // every constrained model's; a call without it is refused, and the step computes its
    // orders by the runtime's kernels.
    if context.is_null() {
        return 1;
    }
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        // SAFETY: `context` is the `OrderContext` of the `orders` call in progress,
        // whose `series` and `out` are exclusively lent to this call chain.
        let context = unsafe { &mut *context.cast::<OrderContext<'_, '_>>() };
        let series = unsafe { std::slice::from_raw_parts_mut(context.series, context.series_len) };
        let out = unsafe { std::slice::from_raw_parts_mut(context.out, context.out_len) };
        eomgen_runtime::taylor::motion_order_at(&context.layout, context.solve, k, series, out);
    }));
    u8::from(result.is_err())
}
