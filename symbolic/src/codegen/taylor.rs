//! A model's Taylor recurrences ([`TaylorProgram`]) from the tape of `M` and `F`.
//!
//! The tape of [`ModelFunction::MassMatrixAndForcing`](super::plan::ModelFunction) — the plan
//! both backends compile — is read as a program over series: each instruction is a slot, and
//! [`taylor_program`] gives each instruction that depends on the state its recurrence
//! ([`SeriesOp`]). Order 0 is the tape itself, extended by the auxiliary values some
//! recurrences need (the cosine of a lone sine, `tan²`, `√(1 − a²)`, `x² + y²`): those are
//! appended as instructions, so the order-0 values of the tape's own instructions are the
//! right-hand side's to the bit, and both backends evaluate the extended tape as they evaluate
//! any tape. Constant instructions (parameters and numbers only) keep their order 0 alone.
//!
//! Source: the decomposition of Biscani & Izzo (2021), heyoka's `taylor_decompose`, with
//! hidden partners (`sin`↔`cos`, `tan`↔`tan²`); the recurrences of Jorba & Zou (2005, §2.1).

use std::borrow::Cow;

use eomgen_description::taylor::{DerivedLists, SeriesOp, Slot, TaylorProgram, TaylorUnsupported};

use crate::expr::Func;

use super::program::FunctionTape;
use super::tape::{Input, Instruction, Tape};

/// The Taylor recurrences of a model's `M q̈ = F` and the order-0 tape they extend.
#[derive(Debug, Clone, PartialEq)]
pub struct TaylorPlan {
    /// The recurrences of orders `k ≥ 1` and the slots of the state, `M` and `F`.
    pub program: TaylorProgram,
    /// Order 0: the tape of `M` and `F` with the auxiliary instructions appended; slot `s` is
    /// instruction `s`. Its outputs are those of the tape of `M` and `F`.
    pub order_zero: Tape,
}

/// Builds the Taylor recurrences of the tape of `M` (column-major, `n × n`) and `F` (`n`), the
/// run-time compiler's [`ModelProgram::mass_matrix_and_forcing`](super::program::ModelProgram).
///
/// # Errors
/// [`TaylorUnsupported::Constraints`] if `constraints > 0`;
/// [`TaylorUnsupported::Functions`] naming each function without a recurrence (`abs`, `sign`,
/// `step`, `pow` with a variable exponent) that the equations use.
pub fn taylor_program(
    tape: &FunctionTape,
    n: usize,
    constraints: usize,
) -> Result<TaylorPlan, TaylorUnsupported> {
    if constraints > 0 {
        return Err(TaylorUnsupported::Constraints { count: constraints });
    }
    let mut builder = Builder::new(&tape.tape);
    builder.build();
    if !builder.unsupported.is_empty() {
        return Err(TaylorUnsupported::Functions {
            names: Cow::Owned(builder.unsupported.into_iter().map(Cow::Owned).collect()),
        });
    }
    let outputs = &tape.tape.outputs;
    let (mass, forcing) = outputs.split_at((n * n).min(outputs.len()));
    let Builder {
        order_zero,
        constant,
        mut ops,
        zeroed,
        coordinates,
        velocities,
        time,
        ..
    } = builder;
    // Constants read as whole series are zeroed above order 0 before anything reads them.
    let zero_ops: Vec<SeriesOp> = zeroed
        .into_iter()
        .map(|out| SeriesOp::Zero { out })
        .collect();
    ops.splice(0..0, zero_ops);
    let program = TaylorProgram {
        slots: order_zero.instructions.len(),
        coordinates: Cow::Owned(fit(coordinates, n)),
        velocities: Cow::Owned(fit(velocities, n)),
        time,
        mass_matrix: Cow::Owned(mass.to_vec()),
        forcing: Cow::Owned(forcing.to_vec()),
        constant: Cow::Owned(constant),
        ops: Cow::Owned(ops),
        derived: DerivedLists::default(),
    }
    .with_derived();
    Ok(TaylorPlan {
        program,
        order_zero,
    })
}

/// `slots` padded or cut to `n` entries.
fn fit(mut slots: Vec<Option<Slot>>, n: usize) -> Vec<Option<Slot>> {
    slots.resize(n, None);
    slots
}

struct Builder<'a> {
    tape: &'a Tape,
    order_zero: Tape,
    constant: Vec<bool>,
    ops: Vec<SeriesOp>,
    zeroed: Vec<Slot>,
    coordinates: Vec<Option<Slot>>,
    velocities: Vec<Option<Slot>>,
    time: Option<Slot>,
    unsupported: Vec<String>,
}

impl<'a> Builder<'a> {
    fn new(tape: &'a Tape) -> Self {
        Self {
            tape,
            order_zero: tape.clone(),
            constant: Vec::with_capacity(tape.instructions.len()),
            ops: Vec::new(),
            zeroed: Vec::new(),
            coordinates: Vec::new(),
            velocities: Vec::new(),
            time: None,
            unsupported: Vec::new(),
        }
    }

    fn is_constant(&self, v: Slot) -> bool {
        self.constant[v as usize]
    }

    /// Appends an auxiliary instruction to the order-0 tape; its slot.
    fn aux(&mut self, instruction: Instruction, constant: bool) -> Slot {
        let slot = self.order_zero.instructions.len() as Slot;
        self.order_zero.instructions.push(instruction);
        self.constant.push(constant);
        slot
    }

    /// Records instruction `k` as the slot of input `i` of `list` (refusing an input read
    /// twice).
    fn input(&mut self, k: usize, list: fn(&mut Self) -> &mut Vec<Option<Slot>>, i: usize) {
        let slots = list(self);
        if slots.len() <= i {
            slots.resize(i + 1, None);
        }
        match slots[i] {
            // The tapes bind each symbol once; an input read twice would need its order 0
            // copied too, so it is refused rather than half supported.
            Some(_) => self.refuse("an input read twice"),
            None => slots[i] = Some(k as Slot),
        }
    }

    fn refuse(&mut self, name: &str) {
        if !self.unsupported.iter().any(|n| n == name) {
            self.unsupported.push(name.to_string());
        }
    }

    /// A constant read as a whole series: zeroed above order 0.
    fn as_series(&mut self, v: Slot) -> Slot {
        if self.is_constant(v) && !self.zeroed.contains(&v) {
            self.zeroed.push(v);
        }
        v
    }

    fn build(&mut self) {
        let count = self.tape.instructions.len();
        // The flags of the tape's own instructions come first: auxiliary slots are appended
        // after them, so `constant[k]` is instruction `k`'s.
        for k in 0..count {
            let constant = match self.tape.instructions[k] {
                Instruction::Input(input) => match input {
                    Input::Parameter(_) => true,
                    Input::Coordinate(i) => {
                        self.input(k, |b| &mut b.coordinates, i as usize);
                        false
                    }
                    Input::Velocity(i) => {
                        self.input(k, |b| &mut b.velocities, i as usize);
                        false
                    }
                    Input::Time => {
                        match self.time {
                            Some(_) => self.refuse("an input read twice"),
                            None => self.time = Some(k as Slot),
                        }
                        false
                    }
                    Input::Acceleration(_) | Input::Multiplier(_) => {
                        self.refuse("an acceleration or multiplier input");
                        false
                    }
                },
                Instruction::Const(_) => true,
                instruction => operands(instruction)
                    .iter()
                    .all(|&v| self.constant[v as usize]),
            };
            self.constant.push(constant);
        }
        for k in 0..count {
            if self.constant[k] {
                continue;
            }
            let out = k as Slot;
            let instruction = self.tape.instructions[k];
            if let Some(op) = self.op(out, instruction) {
                self.ops.push(op);
            }
        }
    }

    /// The recurrence of the non-constant instruction `out`.
    fn op(&mut self, out: Slot, instruction: Instruction) -> Option<SeriesOp> {
        let c = |b: &Self, v: Slot| b.is_constant(v);
        Some(match instruction {
            Instruction::Input(_) | Instruction::Const(_) => return None,
            Instruction::Neg(a) => SeriesOp::Neg { out, a },
            Instruction::Add(a, b) => match (c(self, a), c(self, b)) {
                (false, false) => SeriesOp::Add { out, a, b },
                (false, true) => SeriesOp::Copy { out, a },
                _ => SeriesOp::Copy { out, a: b },
            },
            Instruction::Sub(a, b) => match (c(self, a), c(self, b)) {
                (false, false) => SeriesOp::Sub { out, a, b },
                (false, true) => SeriesOp::Copy { out, a },
                _ => SeriesOp::Neg { out, a: b },
            },
            Instruction::Mul(a, b) => match (c(self, a), c(self, b)) {
                (false, false) => SeriesOp::Mul { out, a, b },
                (false, true) => SeriesOp::Scale {
                    out,
                    a,
                    constant: b,
                },
                _ => SeriesOp::Scale {
                    out,
                    a: b,
                    constant: a,
                },
            },
            Instruction::Div(a, b) => match (c(self, a), c(self, b)) {
                (false, false) => SeriesOp::Div { out, a, b },
                (false, true) => SeriesOp::DivByConstant {
                    out,
                    a,
                    constant: b,
                },
                _ => SeriesOp::ConstantDiv { out, b },
            },
            Instruction::Sqrt(a) => SeriesOp::Sqrt { out, a },
            Instruction::Abs(_) => {
                self.refuse("abs");
                return None;
            }
            Instruction::Powf(a, b) => {
                if c(self, b) {
                    SeriesOp::PowConstant {
                        out,
                        a,
                        exponent: b,
                    }
                } else {
                    self.refuse("pow (a variable exponent)");
                    return None;
                }
            }
            Instruction::Atan2(y, x) => {
                let (y, x) = (self.as_series(y), self.as_series(x));
                let xx = self.aux(Instruction::Mul(x, x), false);
                let yy = self.aux(Instruction::Mul(y, y), false);
                let norm = self.aux(Instruction::Add(xx, yy), false);
                SeriesOp::Atan2 { out, y, x, norm }
            }
            Instruction::SinCos(a) => SeriesOp::SinCos {
                sin: out,
                cos: out + 1,
                a,
            },
            Instruction::CosOfSinCos(_) => return None,
            Instruction::Call(f, a) => match f {
                Func::Sin => {
                    let cos = self.aux(Instruction::Call(Func::Cos, a), false);
                    SeriesOp::SinCos { sin: out, cos, a }
                }
                Func::Cos => {
                    let sin = self.aux(Instruction::Call(Func::Sin, a), false);
                    SeriesOp::SinCos { sin, cos: out, a }
                }
                Func::Sinh => {
                    let cosh = self.aux(Instruction::Call(Func::Cosh, a), false);
                    SeriesOp::SinhCosh { sinh: out, cosh, a }
                }
                Func::Cosh => {
                    let sinh = self.aux(Instruction::Call(Func::Sinh, a), false);
                    SeriesOp::SinhCosh { sinh, cosh: out, a }
                }
                Func::Tan => {
                    let square = self.aux(Instruction::Mul(out, out), false);
                    SeriesOp::Tan { out, a, square }
                }
                Func::Tanh => {
                    let square = self.aux(Instruction::Mul(out, out), false);
                    SeriesOp::Tanh { out, a, square }
                }
                Func::Asin | Func::Acos => {
                    let square = self.aux(Instruction::Mul(a, a), false);
                    let one = self.aux(Instruction::Const(1.0), true);
                    let difference = self.aux(Instruction::Sub(one, square), false);
                    let root = self.aux(Instruction::Sqrt(difference), false);
                    SeriesOp::Asin {
                        out,
                        a,
                        root,
                        acos: f == Func::Acos,
                    }
                }
                Func::Atan => {
                    let square = self.aux(Instruction::Mul(a, a), false);
                    SeriesOp::Atan { out, a, square }
                }
                Func::Exp => SeriesOp::Exp { out, a },
                Func::Ln => SeriesOp::Ln { out, a },
                Func::Abs | Func::Sign | Func::Step => {
                    self.refuse(f.name());
                    return None;
                }
            },
        })
    }
}

/// The operands of an instruction.
fn operands(instruction: Instruction) -> Vec<Slot> {
    match instruction {
        Instruction::Input(_) | Instruction::Const(_) => vec![],
        Instruction::Neg(x)
        | Instruction::Sqrt(x)
        | Instruction::Abs(x)
        | Instruction::Call(_, x)
        | Instruction::SinCos(x)
        | Instruction::CosOfSinCos(x) => vec![x],
        Instruction::Add(x, y)
        | Instruction::Sub(x, y)
        | Instruction::Mul(x, y)
        | Instruction::Div(x, y)
        | Instruction::Powf(x, y)
        | Instruction::Atan2(x, y) => vec![x, y],
    }
}

/// The Taylor methods of a generated `impl MechanicalSystem<N>`: `taylor_program` (the
/// program as a `static`, or the reason there is none), `taylor_order_zero` (the extended
/// tape as straight-line code), `taylor_order` (one call of the op's kernel,
/// `eomgen::__private::taylor::{mul, sin_cos, …}`, per op, with its slots as constants, for
/// any order) and `taylor_orders`: in optimised builds, the orders `k = 1 …` a step can run
/// with `k` known (`TaylorProgram::highest_unrolled_order`) in one function, each order's
/// kernel calls compiled for that `k` (sums of a known length, coefficients at known
/// offsets) followed by its solve (`taylor::motion_order`, with the slots of `F`, of the
/// varying entries of `M` and of the inputs as a constant `MotionLayout`), so that the
/// values of one order pass to the next in registers; debug builds run the same orders with
/// `k` a variable.
///
/// `parameters` are the fields of the struct, in parameter order.
///
/// # Errors
/// Only if a constant of the tape is not finite (a bug: the loader refuses such values).
pub(super) fn methods(
    taylor: &Result<TaylorPlan, TaylorUnsupported>,
    krate: &proc_macro2::TokenStream,
    parameters: &[proc_macro2::Ident],
) -> Result<proc_macro2::TokenStream, String> {
    use quote::quote;
    let t = quote!(#krate::__private::taylor);
    let cow = quote!(::std::borrow::Cow);
    let plan = match taylor {
        Ok(plan) => plan,
        Err(reason) => {
            let reason = unsupported_tokens(reason, &t, &cow);
            return Ok(quote! {
                fn taylor_program(&self) -> ::core::result::Result<&#t::TaylorProgram, #t::TaylorUnsupported> {
                    ::core::result::Result::Err(#reason)
                }
            });
        }
    };
    let program = &plan.program;
    let slot_list = |slots: &[Option<Slot>]| {
        let items = slots.iter().map(|s| match s {
            Some(s) => quote!(::core::option::Option::Some(#s)),
            None => quote!(::core::option::Option::None),
        });
        quote!(#cow::Borrowed(&[#(#items),*]))
    };
    let coordinates = slot_list(&program.coordinates);
    let velocities = slot_list(&program.velocities);
    let time = match program.time {
        Some(s) => quote!(::core::option::Option::Some(#s)),
        None => quote!(::core::option::Option::None),
    };
    let mass = program.mass_matrix.iter();
    let forcing = program.forcing.iter();
    let constant = program.constant.iter();
    let ops: Vec<_> = program.ops.iter().map(|op| op_tokens(op, &t)).collect();
    let slots = program.slots;
    let derived = &program.derived;
    let coupled: Vec<_> = derived
        .varying_mass_entries
        .iter()
        .map(|(i, l, slot)| quote!((#i, #l, #slot)))
        .collect();
    let inputs: Vec<_> = derived
        .inputs
        .iter()
        .map(|(slot, index)| quote!((#slot, #index)))
        .collect();
    let (convolutions, branch_points) = (derived.convolutions, derived.branch_points);
    let statics = quote! {
        static PROGRAM: #t::TaylorProgram = #t::TaylorProgram {
            slots: #slots,
            coordinates: #coordinates,
            velocities: #velocities,
            time: #time,
            mass_matrix: #cow::Borrowed(&[#(#mass),*]),
            forcing: #cow::Borrowed(&[#(#forcing),*]),
            constant: #cow::Borrowed(&[#(#constant),*]),
            ops: #cow::Borrowed(&[#(#ops),*]),
            derived: #t::DerivedLists {
                varying_mass_entries: #cow::Borrowed(&[#(#coupled),*]),
                inputs: #cow::Borrowed(&[#(#inputs),*]),
                convolutions: #convolutions,
                branch_points: #branch_points,
            },
        };
    };
    // Order 0: the extended tape, every value stored in its slot.
    let value = |v: u32| super::ident(&format!("__v{v}"));
    let mut statements = proc_macro2::TokenStream::new();
    let private = quote!(#krate::__private);
    for (k, instruction) in plan.order_zero.instructions.iter().enumerate() {
        let k32 = k as u32;
        let name = value(k32)?;
        let v = |x: &u32| value(*x);
        let expression = match *instruction {
            Instruction::Input(Input::Parameter(i)) => {
                let field = &parameters[i as usize];
                quote!(self.#field)
            }
            Instruction::Input(_) => quote!(__s[#k * __c]),
            // A constant without a literal (NaN stands for a missing parameter) as `f64`'s.
            Instruction::Const(c) if c.is_nan() => quote!(f64::NAN),
            Instruction::Const(c) if c.is_infinite() && c > 0.0 => quote!(f64::INFINITY),
            Instruction::Const(c) if c.is_infinite() => quote!(f64::NEG_INFINITY),
            Instruction::Const(c) => super::float(c)?,
            Instruction::Neg(x) => {
                let x = v(&x)?;
                quote!(-#x)
            }
            Instruction::Add(x, y) => {
                let (x, y) = (v(&x)?, v(&y)?);
                quote!(#x + #y)
            }
            Instruction::Sub(x, y) => {
                let (x, y) = (v(&x)?, v(&y)?);
                quote!(#x - #y)
            }
            Instruction::Mul(x, y) => {
                let (x, y) = (v(&x)?, v(&y)?);
                quote!(#x * #y)
            }
            Instruction::Div(x, y) => {
                let (x, y) = (v(&x)?, v(&y)?);
                quote!(#x / #y)
            }
            Instruction::Sqrt(x) => {
                let x = v(&x)?;
                quote!(#x.sqrt())
            }
            Instruction::Abs(x) => {
                let x = v(&x)?;
                quote!(#x.abs())
            }
            Instruction::Powf(x, y) => {
                let (x, y) = (v(&x)?, v(&y)?);
                quote!(#x.powf(#y))
            }
            Instruction::Atan2(y, x) => {
                let (y, x) = (v(&y)?, v(&x)?);
                quote!(#y.atan2(#x))
            }
            Instruction::SinCos(x) => {
                let x = v(&x)?;
                let cos = value(k32 + 1)?;
                statements.extend(quote!(let (#name, #cos): (f64, f64) = #private::sin_cos(#x);));
                continue;
            }
            Instruction::CosOfSinCos(_) => continue,
            Instruction::Call(f, x) => {
                let x = v(&x)?;
                match f {
                    Func::Sin => quote!(#private::sin(#x)),
                    Func::Cos => quote!(#private::cos(#x)),
                    Func::Sign => quote!(#private::sign(#x)),
                    Func::Step => quote!(#private::step(#x)),
                    other => {
                        let method = super::ident(other.name())?;
                        let method = if other == Func::Ln {
                            super::ident("ln")?
                        } else {
                            method
                        };
                        quote!(#x.#method())
                    }
                }
            }
        };
        statements.extend(quote!(let #name: f64 = #expression;));
    }
    let stores = plan
        .order_zero
        .instructions
        .iter()
        .enumerate()
        .filter(|(_, i)| !matches!(i, Instruction::Input(input) if !matches!(input, Input::Parameter(_))))
        .map(|(k, _)| {
            let name = value(k as u32)?;
            Ok(quote!(__s[#k * __c] = #name;))
        })
        .collect::<Result<Vec<_>, String>>()?;
    let calls: Vec<_> = program.ops.iter().map(|op| call_tokens(op, &t)).collect();
    // The orders whose compiled code a step can run (`TaylorProgram::unrolled_code_fits`):
    // compiling the others would only lengthen the build.
    let unrolled: Vec<usize> = (1..=program.highest_unrolled_order()).collect();
    // The fused orders' layout (`taylor_orders`): the program's derived lists, as constants
    // (the run-time `series_of_motion` reads the same lists from the program).
    let n = program.forcing.len();
    let highest = unrolled.len();
    let next = highest + 1;
    let forcing_slots = program.forcing.iter();
    let accelerations = program.acceleration_slot();
    Ok(quote! {
        fn taylor_program(&self) -> ::core::result::Result<&#t::TaylorProgram, #t::TaylorUnsupported> {
            #statics
            ::core::result::Result::Ok(&PROGRAM)
        }
        #[allow(unused_variables)]
        fn taylor_order_zero(&self, __c: usize, __s: &mut [f64]) {
            #statements
            #(#stores)*
        }
        #[inline(never)]
        fn taylor_order(&self, __k: usize, __c: usize, __s: &mut [f64]) {
            // Any order, any stride: the orders a step runs with `k` known are in
            // `taylor_orders` (the same bits).
            #[inline(always)]
            fn __ops<const __K: usize>(__k: usize, __c: usize, __s: &mut [f64]) {
                #(#calls)*
            }
            __ops::<0>(__k, __c, __s);
        }
        fn taylor_fused_orders(&self) -> usize {
            #highest
        }
        #[inline(never)]
        fn taylor_orders(
            &self,
            __solve: &mut #t::MotionSolve<'_>,
            __order: usize,
            __s: &mut [f64],
            __out: &mut [f64],
        ) -> usize {
            #[inline(always)]
            fn __ops<const __K: usize>(__k: usize, __c: usize, __s: &mut [f64]) {
                #(#calls)*
            }
            const __LAYOUT: #t::MotionLayout<'static> = #t::MotionLayout {
                forcing: &[#(#forcing_slots),*],
                coupled: &[#(#coupled),*],
                inputs: &[#(#inputs),*],
                time: #time,
                accelerations: #accelerations,
            };
            if !__solve.unrolled() {
                return 0;
            }
            // A known length: the compiler drops the bounds checks of the constant offsets.
            let __s = &mut __s[..(#slots + #n) * #t::UNROLLED_CAPACITY];
            // Debug builds run the same orders with `k` a variable (one variant to compile;
            // the same bits).
            #[cfg(debug_assertions)]
            let __next = {
                let __end = __order.min(#next);
                for __k in 0..__end {
                    if __k > 0 {
                        __ops::<0>(__k, #t::UNROLLED_CAPACITY, __s);
                    }
                    #t::motion_order::<#n, 0>(&__LAYOUT, __solve, __k, __s, __out);
                }
                __end
            };
            #[cfg(not(debug_assertions))]
            let __next = 'fused: {
                if __order == 0 {
                    break 'fused 0;
                }
                #t::motion_order::<#n, 0>(&__LAYOUT, __solve, 0, __s, __out);
                #(
                    if #unrolled >= __order {
                        break 'fused #unrolled;
                    }
                    __ops::<#unrolled>(#unrolled, #t::UNROLLED_CAPACITY, __s);
                    #t::motion_order::<#n, #unrolled>(&__LAYOUT, __solve, #unrolled, __s, __out);
                )*
                #next
            };
            __next
        }
    })
}

fn unsupported_tokens(
    reason: &TaylorUnsupported,
    t: &proc_macro2::TokenStream,
    cow: &proc_macro2::TokenStream,
) -> proc_macro2::TokenStream {
    use quote::quote;
    match reason {
        TaylorUnsupported::Constraints { count } => {
            quote!(#t::TaylorUnsupported::Constraints { count: #count })
        }
        TaylorUnsupported::Functions { names } => {
            let names = names.iter().map(|n| {
                let n: &str = n;
                quote!(#cow::Borrowed(#n))
            });
            quote!(#t::TaylorUnsupported::Functions { names: #cow::Borrowed(&[#(#names),*]) })
        }
        TaylorUnsupported::NotGenerated => quote!(#t::TaylorUnsupported::NotGenerated),
    }
}

/// A [`SeriesOp`] as a constant expression.
fn op_tokens(op: &SeriesOp, t: &proc_macro2::TokenStream) -> proc_macro2::TokenStream {
    use quote::quote;
    match *op {
        SeriesOp::Neg { out, a } => quote!(#t::SeriesOp::Neg { out: #out, a: #a }),
        SeriesOp::Copy { out, a } => quote!(#t::SeriesOp::Copy { out: #out, a: #a }),
        SeriesOp::Add { out, a, b } => quote!(#t::SeriesOp::Add { out: #out, a: #a, b: #b }),
        SeriesOp::Sub { out, a, b } => quote!(#t::SeriesOp::Sub { out: #out, a: #a, b: #b }),
        SeriesOp::Mul { out, a, b } => quote!(#t::SeriesOp::Mul { out: #out, a: #a, b: #b }),
        SeriesOp::Scale { out, a, constant } => {
            quote!(#t::SeriesOp::Scale { out: #out, a: #a, constant: #constant })
        }
        SeriesOp::Div { out, a, b } => quote!(#t::SeriesOp::Div { out: #out, a: #a, b: #b }),
        SeriesOp::DivByConstant { out, a, constant } => {
            quote!(#t::SeriesOp::DivByConstant { out: #out, a: #a, constant: #constant })
        }
        SeriesOp::ConstantDiv { out, b } => quote!(#t::SeriesOp::ConstantDiv { out: #out, b: #b }),
        SeriesOp::Sqrt { out, a } => quote!(#t::SeriesOp::Sqrt { out: #out, a: #a }),
        SeriesOp::PowConstant { out, a, exponent } => {
            quote!(#t::SeriesOp::PowConstant { out: #out, a: #a, exponent: #exponent })
        }
        SeriesOp::Exp { out, a } => quote!(#t::SeriesOp::Exp { out: #out, a: #a }),
        SeriesOp::Ln { out, a } => quote!(#t::SeriesOp::Ln { out: #out, a: #a }),
        SeriesOp::SinCos { sin, cos, a } => {
            quote!(#t::SeriesOp::SinCos { sin: #sin, cos: #cos, a: #a })
        }
        SeriesOp::SinhCosh { sinh, cosh, a } => {
            quote!(#t::SeriesOp::SinhCosh { sinh: #sinh, cosh: #cosh, a: #a })
        }
        SeriesOp::Tan { out, a, square } => {
            quote!(#t::SeriesOp::Tan { out: #out, a: #a, square: #square })
        }
        SeriesOp::Tanh { out, a, square } => {
            quote!(#t::SeriesOp::Tanh { out: #out, a: #a, square: #square })
        }
        SeriesOp::Asin { out, a, root, acos } => {
            quote!(#t::SeriesOp::Asin { out: #out, a: #a, root: #root, acos: #acos })
        }
        SeriesOp::Atan { out, a, square } => {
            quote!(#t::SeriesOp::Atan { out: #out, a: #a, square: #square })
        }
        SeriesOp::Atan2 { out, y, x, norm } => {
            quote!(#t::SeriesOp::Atan2 { out: #out, y: #y, x: #x, norm: #norm })
        }
        SeriesOp::Zero { out } => quote!(#t::SeriesOp::Zero { out: #out }),
    }
}

/// The call of an op's kernel (`eomgen_runtime::taylor::{mul, sin_cos, …}`) in
/// `taylor_order`, the kernel [`SeriesOp`]'s dispatch (`apply`) calls for the run-time model.
fn call_tokens(op: &SeriesOp, t: &proc_macro2::TokenStream) -> proc_macro2::TokenStream {
    use quote::quote;
    let args = |kernel: &str, slots: &[Slot]| {
        let kernel = proc_macro2::Ident::new(kernel, proc_macro2::Span::call_site());
        quote!(#t::#kernel::<__K>(__k, __c, __s, #(#slots),*);)
    };
    match *op {
        SeriesOp::Neg { out, a } => args("neg", &[out, a]),
        SeriesOp::Copy { out, a } => args("copy", &[out, a]),
        SeriesOp::Add { out, a, b } => args("add", &[out, a, b]),
        SeriesOp::Sub { out, a, b } => args("sub", &[out, a, b]),
        SeriesOp::Mul { out, a, b } => args("mul", &[out, a, b]),
        SeriesOp::Scale { out, a, constant } => args("scale", &[out, a, constant]),
        SeriesOp::Div { out, a, b } => args("div", &[out, a, b]),
        SeriesOp::DivByConstant { out, a, constant } => {
            args("div_by_constant", &[out, a, constant])
        }
        SeriesOp::ConstantDiv { out, b } => args("constant_div", &[out, b]),
        SeriesOp::Sqrt { out, a } => args("sqrt", &[out, a]),
        SeriesOp::PowConstant { out, a, exponent } => args("pow_constant", &[out, a, exponent]),
        SeriesOp::Exp { out, a } => args("exp", &[out, a]),
        SeriesOp::Ln { out, a } => args("ln", &[out, a]),
        SeriesOp::SinCos { sin, cos, a } => args("sin_cos", &[sin, cos, a]),
        SeriesOp::SinhCosh { sinh, cosh, a } => args("sinh_cosh", &[sinh, cosh, a]),
        SeriesOp::Tan { out, a, square } => {
            quote!(#t::tan_or_tanh::<__K>(__k, __c, __s, #out, #a, #square, 1.0);)
        }
        SeriesOp::Tanh { out, a, square } => {
            quote!(#t::tan_or_tanh::<__K>(__k, __c, __s, #out, #a, #square, -1.0);)
        }
        SeriesOp::Asin { out, a, root, acos } => {
            quote!(#t::asin::<__K>(__k, __c, __s, #out, #a, #root, #acos);)
        }
        SeriesOp::Atan { out, a, square } => args("atan", &[out, a, square]),
        SeriesOp::Atan2 { out, y, x, norm } => args("atan2", &[out, y, x, norm]),
        SeriesOp::Zero { out } => args("zero", &[out]),
    }
}
