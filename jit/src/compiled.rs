//! A model's functions as they are held and called: native code or the interpreter's tapes,
//! with the extents checked before a call ([`Compiled`]), and the two functions every
//! right-hand side calls, held where their call is shortest ([`HotRoutine`], [`FusedRhs`]).

use std::cell::RefCell;

use eomgen_symbolic::codegen::program::FunctionTape;
use eomgen_symbolic::codegen::tape::{Input, Instruction};

use crate::native::{CompileError, FirstOrderFn, NativeCode, NativeFn};
use crate::{Backend, Inputs, native};

/// How many values a function reads from each input and writes to each output buffer
/// (largest index + 1), checked before native code is called.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Extent {
    pub(crate) parameters: usize,
    pub(crate) q: usize,
    pub(crate) qdot: usize,
    pub(crate) acceleration: usize,
    pub(crate) lambda: usize,
    pub(crate) out0: usize,
    pub(crate) out1: usize,
    /// `f64`s of scratch space the native code needs (0 for none).
    pub(crate) scratch: usize,
}

impl Extent {
    pub(crate) fn of(function: &FunctionTape) -> Extent {
        let mut e = Extent::default();
        for instruction in &function.tape.instructions {
            if let Instruction::Input(input) = instruction {
                let (slot, i) = match *input {
                    Input::Parameter(i) => (&mut e.parameters, i),
                    Input::Coordinate(i) => (&mut e.q, i),
                    Input::Velocity(i) => (&mut e.qdot, i),
                    Input::Acceleration(i) => (&mut e.acceleration, i),
                    Input::Multiplier(i) => (&mut e.lambda, i),
                    Input::Time => continue,
                };
                *slot = (*slot).max(i as usize + 1);
            }
        }
        let split = function.split.min(function.tape.outputs.len());
        e.out0 = split;
        e.out1 = function.tape.outputs.len() - split;
        e
    }

    #[inline(always)]
    pub(crate) fn admits(&self, inputs: &Inputs<'_>, out0: usize, out1: usize) -> bool {
        inputs.parameters.len() >= self.parameters
            && inputs.q.len() >= self.q
            && inputs.qdot.len() >= self.qdot
            && inputs.acceleration.len() >= self.acceleration
            && inputs.lambda.len() >= self.lambda
            && out0 >= self.out0
            && out1 >= self.out1
    }
}

/// Functions as native code, or as tapes for the interpreter, with their extents.
#[derive(Debug)]
pub(crate) struct Compiled {
    /// The tapes, kept only when there is no native code (they are what the interpreter
    /// runs; with native code they would only take memory: megabytes for a long chain).
    pub(crate) tapes: Vec<FunctionTape>,
    pub(crate) extents: Vec<Extent>,
    pub(crate) native: Option<NativeCode>,
}

impl Compiled {
    /// Compiles `functions` with `backend` (`None`: native, interpreting on an unsupported
    /// host, whose reason is returned).
    pub(crate) fn new(
        functions: &[(&str, &FunctionTape)],
        first_order: Option<(&FunctionTape, usize)>,
        backend: Option<Backend>,
    ) -> Result<(Compiled, Option<CompileError>), CompileError> {
        let (native, fallback_reason) = match backend {
            Some(Backend::Interpreter) => (None, None),
            forced => match native::compile(functions, first_order) {
                Ok(code) => (Some(code), None),
                Err(reason @ CompileError::UnsupportedHost { .. })
                    if forced != Some(Backend::Native) =>
                {
                    (None, Some(reason))
                }
                Err(e) => return Err(e),
            },
        };
        let mut compiled = Compiled::interpreted(functions);
        if let Some(native) = &native {
            for (extent, &scratch) in compiled.extents.iter_mut().zip(&native.scratch) {
                extent.scratch = scratch;
            }
            compiled.tapes = Vec::new();
        }
        compiled.native = native;
        Ok((compiled, fallback_reason))
    }

    /// The same functions for the interpreter.
    pub(crate) fn interpreted(functions: &[(&str, &FunctionTape)]) -> Compiled {
        Compiled {
            tapes: functions.iter().map(|(_, f)| (*f).clone()).collect(),
            extents: functions.iter().map(|(_, f)| Extent::of(f)).collect(),
            native: None,
        }
    }
}

thread_local! {
    /// The interpreter's values, and the scratch space of large native functions, reused
    /// between evaluations on a thread.
    pub(crate) static SCRATCH: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

/// Calls native code `f` of a routine whose extent is `extent`.
///
/// # Safety
/// `f` must be the native code compiled from the tape `extent` was computed from, and
/// `extent.admits(inputs, out0.len(), out1.len())` must hold.
#[inline(always)]
pub(crate) unsafe fn call_native(
    f: NativeFn,
    extent: &Extent,
    inputs: &Inputs<'_>,
    out0: &mut [f64],
    out1: &mut [f64],
) {
    let (out0, out1) = (out0.as_mut_ptr(), out1.as_mut_ptr());
    if extent.scratch == 0 {
        // SAFETY: the tape reads at most `extent` values of each input and writes
        // `extent.out0` and `extent.out1` values; the caller checked the slices. It uses no
        // scratch space.
        unsafe { call(f, inputs, out0, out1, std::ptr::null_mut()) }
    } else {
        // SAFETY: as above; `with_scratch` supplies `extent.scratch` values of scratch space.
        unsafe { with_scratch(f, extent.scratch, inputs, out0, out1) }
    }
}

/// The call itself.
///
/// # Safety
/// As [`call_native`], with `scratch` holding the scratch values the code uses.
#[inline(always)]
pub(crate) unsafe fn call(
    f: NativeFn,
    inputs: &Inputs<'_>,
    out0: *mut f64,
    out1: *mut f64,
    scratch: *mut f64,
) {
    // SAFETY: guaranteed by the caller.
    unsafe {
        f(
            inputs.parameters.as_ptr(),
            inputs.q.as_ptr(),
            inputs.qdot.as_ptr(),
            inputs.acceleration.as_ptr(),
            inputs.lambda.as_ptr(),
            inputs.t,
            out0,
            out1,
            scratch,
        )
    }
}

/// A call of code that keeps values in the per-thread scratch buffer (functions of more than
/// 1,500 instructions, `native.rs`): out of line, so that the small functions' calls, inlined
/// into the caller's right-hand side, stay short.
///
/// # Safety
/// As [`call_native`], with `scratch` the code's scratch size.
#[cold]
#[inline(never)]
pub(crate) unsafe fn with_scratch(
    f: NativeFn,
    scratch: usize,
    inputs: &Inputs<'_>,
    out0: *mut f64,
    out1: *mut f64,
) {
    SCRATCH.with(|buffer| match buffer.try_borrow_mut() {
        Ok(mut buffer) => {
            if buffer.len() < scratch {
                buffer.resize(scratch, 0.0);
            }
            // SAFETY: guaranteed by the caller; the buffer holds `scratch` values.
            unsafe { call(f, inputs, out0, out1, buffer.as_mut_ptr()) }
        }
        // Re-entered on this thread (cannot happen: the code calls no model code).
        // SAFETY: as above, with a buffer of its own.
        Err(_) => unsafe { call(f, inputs, out0, out1, vec![0.0; scratch].as_mut_ptr()) },
    });
}

/// A compiled fused right-hand side whose call needs only the lengths of `y` and `ẏ` checked
/// (its tape reads `q` and `q̇` of a model of `n` degrees of freedom, at most the model's
/// parameters, no accelerations or multipliers).
#[derive(Debug, Clone, Copy)]
pub(crate) struct FusedRhs {
    pub(crate) f: FirstOrderFn,
    pub(crate) n: usize,
}

impl FusedRhs {
    /// `f`, of a tape with `extent`, if it reads no more than said above.
    pub(crate) fn new(
        f: FirstOrderFn,
        extent: &Extent,
        n: usize,
        parameters: usize,
    ) -> Option<FusedRhs> {
        let simple = extent.parameters <= parameters
            && extent.q <= n
            && extent.qdot <= n
            && extent.acceleration == 0
            && extent.lambda == 0
            && extent.out0 == 2 * n;
        simple.then_some(FusedRhs { f, n })
    }
}

/// Native code whose call needs only the lengths of `q`, `q̇` and the two outputs checked: it
/// reads at most the model's parameters (whose number is fixed), no accelerations, no
/// multipliers, and uses no scratch space. Checking four lengths rather than the whole
/// [`Extent`] and skipping the scratch buffer keeps the right-hand side's call of
/// `mass_matrix_and_forcing` short (`benches/runtime_model.rs`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct HotRoutine {
    pub(crate) f: NativeFn,
    pub(crate) q: usize,
    pub(crate) qdot: usize,
    pub(crate) out0: usize,
    pub(crate) out1: usize,
}

impl HotRoutine {
    /// `f` with `extent`, if its call needs no more than four lengths checked (see above).
    pub(crate) fn new(f: NativeFn, extent: &Extent, parameters: usize) -> Option<HotRoutine> {
        let simple = extent.parameters <= parameters
            && extent.acceleration == 0
            && extent.lambda == 0
            && extent.scratch == 0;
        simple.then_some(HotRoutine {
            f,
            q: extent.q,
            qdot: extent.qdot,
            out0: extent.out0,
            out1: extent.out1,
        })
    }
}
