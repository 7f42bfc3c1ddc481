//! The JIT module every compiled function lives in: built for the host, with the helpers of
//! [`crate::math`] it calls declared as imports, and its executable memory, freed with its
//! owner.

use std::sync::Mutex;

use cranelift_codegen::ir::{AbiParam, Signature, types};
use cranelift_codegen::settings::{self, Configurable};
use cranelift_jit::{ArenaMemoryProvider, JITBuilder, JITModule};
use cranelift_module::{FuncId, Linkage, Module, default_libcall_names};

use eomgen_symbolic::expr::Func;

use crate::math;

/// Why the model's functions could not be compiled to native code.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum CompileError {
    /// Cranelift has no code generator for this host (the run-time model then interprets
    /// its tapes).
    #[error("no native code generator for this host: {reason}")]
    UnsupportedHost {
        /// Cranelift's explanation.
        reason: String,
    },
    /// A function could not be compiled: Cranelift failed on it, or its program is
    /// malformed.
    #[error("could not compile `{function}` to native code: {reason}")]
    Function {
        /// The function of the model (`mass_matrix_and_forcing`, …).
        function: String,
        /// Cranelift's message.
        reason: String,
    },
    /// The compiled code could not be made executable (mapping or protecting memory failed).
    #[error("could not make the compiled code executable: {reason}")]
    Finalize {
        /// The operating system's or Cranelift's message.
        reason: String,
    },
}

/// A finalised module's executable memory, freed when dropped (with the function pointers
/// into it, which its owner holds beside it and never hands out).
pub(crate) struct ModuleMemory(Mutex<Option<JITModule>>);

impl ModuleMemory {
    /// Takes `module`, its definitions finalised.
    pub(crate) fn new(module: JITModule) -> Self {
        Self(Mutex::new(Some(module)))
    }
}

// SAFETY: after `finalize_definitions` the module is never used again except to free its
// memory in `Drop`, which has exclusive access; the code in it is immutable and reentrant
// (it reads only its arguments and writes only the buffers it is given), so calling it from
// several threads at once is sound. The `Mutex` makes the module's own `Sync` moot.
unsafe impl Send for ModuleMemory {}
// SAFETY: as above.
unsafe impl Sync for ModuleMemory {}

impl Drop for ModuleMemory {
    fn drop(&mut self) {
        let module = match self.0.get_mut() {
            Ok(m) => m.take(),
            Err(poisoned) => poisoned.into_inner().take(),
        };
        if let Some(module) = module {
            // SAFETY: the function pointers into this memory belong to the owner being
            // dropped with it; nothing else holds them (they never leave the crate).
            unsafe { module.free_memory() };
        }
    }
}

/// Which helper functions the code calls, by symbol name.
const HELPERS: [(&str, Func); 13] = [
    ("eomgen_sin", Func::Sin),
    ("eomgen_cos", Func::Cos),
    ("eomgen_tan", Func::Tan),
    ("eomgen_asin", Func::Asin),
    ("eomgen_acos", Func::Acos),
    ("eomgen_atan", Func::Atan),
    ("eomgen_sinh", Func::Sinh),
    ("eomgen_cosh", Func::Cosh),
    ("eomgen_tanh", Func::Tanh),
    ("eomgen_exp", Func::Exp),
    ("eomgen_ln", Func::Ln),
    ("eomgen_sign", Func::Sign),
    ("eomgen_step", Func::Step),
];

/// The helpers of [`crate::math`] declared as imports of a module.
pub(crate) struct Imports {
    pub(crate) unary: Vec<(Func, FuncId)>,
    pub(crate) sin_cos: FuncId,
    pub(crate) powf: FuncId,
    pub(crate) atan2: FuncId,
    pub(crate) fill_zero: FuncId,
}

/// Address space reserved for a module's code laid out in one piece, beyond
/// [`CODE_BYTES_PER_ITEM`] per item of its code: 64 MiB.
const CODE_RESERVE: usize = 64 << 20;

/// Address space reserved per item of a module's code laid out in one piece (a term of a Taylor
/// order's sums, an instruction of a tape), far more than Cranelift emits for one (a few
/// instructions of 4–9 bytes, with its spills).
const CODE_BYTES_PER_ITEM: usize = 1024;

/// How a module's functions are placed in memory.
#[derive(Debug, Clone, Copy)]
pub(crate) enum CodeLayout {
    /// Cranelift's default: each function that does not fit what is left of the last
    /// allocation gets pages of its own.
    Pages,
    /// One after the other in one region of address space reserved up front for this many
    /// items of code ([`CODE_RESERVE`] plus [`CODE_BYTES_PER_ITEM`] each; on Linux and macOS
    /// only what the code uses is committed). The Taylor orders, one function per order, each
    /// started at a page boundary otherwise, where the first-level instruction cache maps
    /// the same sets: the double pendulum's ran 3–5 % slower so (docs/performance.md). When
    /// the region cannot be reserved, the layout is [`CodeLayout::Pages`]; code beyond it
    /// fails to compile (for the Taylor orders: the runtime's kernels go on).
    Contiguous(usize),
}

/// A JIT module for the host, optimising for speed, that resolves the helpers of
/// [`crate::math`] by their symbol names, its functions placed as `layout` says. Frames larger
/// than a page are probed in line (a Taylor order keeps its partial sums on the stack).
///
/// # Errors
/// [`CompileError::UnsupportedHost`] when Cranelift has no code generator for the host.
pub(crate) fn new_module(layout: CodeLayout) -> Result<JITModule, CompileError> {
    let mut flags = settings::builder();
    let set = |flags: &mut settings::Builder, name: &str, value: &str| {
        flags
            .set(name, value)
            .map_err(|e| CompileError::UnsupportedHost {
                reason: format!("setting {name}={value}: {e}"),
            })
    };
    set(&mut flags, "opt_level", "speed")?;
    set(&mut flags, "use_colocated_libcalls", "false")?;
    set(&mut flags, "is_pic", "false")?;
    set(&mut flags, "enable_probestack", "true")?;
    set(&mut flags, "probestack_strategy", "inline")?;
    // The tapes are built correct by construction; the verifier doubles compile time.
    set(
        &mut flags,
        "enable_verifier",
        if cfg!(debug_assertions) {
            "true"
        } else {
            "false"
        },
    )?;
    let isa = cranelift_native::builder()
        .map_err(|reason| CompileError::UnsupportedHost {
            reason: reason.to_string(),
        })?
        .finish(settings::Flags::new(flags))
        .map_err(|e| CompileError::UnsupportedHost {
            reason: e.to_string(),
        })?;
    let mut builder = JITBuilder::with_isa(isa, default_libcall_names());
    if let CodeLayout::Contiguous(items) = layout {
        let reserve = items
            .saturating_mul(CODE_BYTES_PER_ITEM)
            .saturating_add(CODE_RESERVE);
        if let Ok(memory) = ArenaMemoryProvider::new_with_size(reserve) {
            builder.memory_provider(Box::new(memory));
        }
    }
    for (name, f) in HELPERS {
        builder.symbol(name, math::unary(f) as *const u8);
    }
    builder.symbol("eomgen_sin_cos", math::sin_cos as *const u8);
    builder.symbol("eomgen_powf", math::powf as *const u8);
    builder.symbol("eomgen_atan2", math::atan2 as *const u8);
    builder.symbol("eomgen_fill_zero", math::fill_zero as *const u8);
    Ok(JITModule::new(builder))
}

/// What a failure of Cranelift on `function` is.
pub(crate) fn failure(function: &str, e: &dyn std::fmt::Display) -> CompileError {
    CompileError::Function {
        function: function.to_string(),
        reason: e.to_string(),
    }
}

/// Declares the helpers the code calls as imports of `module`.
///
/// # Errors
/// [`CompileError::Function`] naming the helper Cranelift could not declare.
pub(crate) fn declare_imports(module: &mut JITModule) -> Result<Imports, CompileError> {
    let call_conv = module.isa().default_call_conv();
    let float_signature = |args: usize, returns: usize| {
        let mut s = Signature::new(call_conv);
        s.params
            .extend((0..args).map(|_| AbiParam::new(types::F64)));
        s.returns
            .extend((0..returns).map(|_| AbiParam::new(types::F64)));
        s
    };
    let declare = |module: &mut JITModule, name: &str, signature: &Signature| {
        module
            .declare_function(name, Linkage::Import, signature)
            .map_err(|e| failure(name, &e))
    };
    let mut unary = Vec::new();
    for (name, f) in HELPERS {
        unary.push((f, declare(module, name, &float_signature(1, 1))?));
    }
    let pointer = module.target_config().pointer_type();
    let mut fill_signature = Signature::new(call_conv);
    fill_signature.params.push(AbiParam::new(pointer));
    fill_signature.params.push(AbiParam::new(pointer));
    let imports = Imports {
        unary,
        sin_cos: declare(module, "eomgen_sin_cos", &float_signature(1, 2))?,
        powf: declare(module, "eomgen_powf", &float_signature(2, 1))?,
        atan2: declare(module, "eomgen_atan2", &float_signature(2, 1))?,
        fill_zero: declare(module, "eomgen_fill_zero", &fill_signature)?,
    };

    Ok(imports)
}
