//! The Taylor method of a `model!`-generated model as Rust tokens: its `taylor` accessor and
//! its `impl TaylorFunctions`, printed from the [`TaylorPlan`] of [`super::taylor`].

use eomgen_description::taylor::{SeriesOp, Slot, TaylorProgram, TaylorUnsupported};

use super::tape::{Input, Instruction};
use super::taylor::TaylorPlan;
use crate::expr::Func;

/// The Taylor method of a generated model: the accessor `taylor` of its `impl
/// MechanicalSystem<N>` (the model itself, or the reason there is none), and its `impl
/// TaylorFunctions` (none without a program): `program` (the program as a `static`),
/// `order_zero` (the extended tape as straight-line code), `order` (one call of the op's kernel,
/// `eomgen::__private::taylor::{mul, sin_cos, …}`, per op, with its slots as constants, for
/// any order), `fused_orders` and `orders`: in optimised builds, the orders `k = 1 …` a step can run
/// with `k` known (`TaylorProgram::highest_unrolled_order`) in one function, each order's
/// kernel calls compiled for that `k` (sums of a known length, coefficients at known
/// offsets) followed by its solve (`taylor::motion_order`, with the slots of `F`, of the
/// varying entries of `M` and of the inputs as a constant `MotionLayout`), so that the
/// values of one order pass to the next in registers — that function compiled twice on
/// x86-64, the second copy with AVX2 and FMA enabled and run where the processor has them
/// (`taylor::host_features`; the same bits); debug builds run the same orders with `k` a
/// variable.
///
/// `parameters` are the fields of the struct, in parameter order; `name` is the struct.
///
/// # Errors
/// Only if a constant of the tape is not finite (a bug: the loader refuses such values).
// Long: most of it is one `quote!` template, the generated `impl TaylorFunctions` as it is
// printed; split, the template would only be harder to read against its output.
pub(super) fn methods(
    taylor: &Result<TaylorPlan, TaylorUnsupported>,
    krate: &proc_macro2::TokenStream,
    parameters: &[proc_macro2::Ident],
    name: &proc_macro2::Ident,
) -> Result<(proc_macro2::TokenStream, proc_macro2::TokenStream), String> {
    use quote::quote;
    let t = quote!(#krate::__private::taylor);
    let cow = quote!(::std::borrow::Cow);
    let plan = match taylor {
        Ok(plan) => plan,
        Err(reason) => {
            let reason = unsupported_tokens(reason, &t, &cow);
            let accessor = quote! {
                fn taylor(&self) -> ::core::result::Result<&dyn #t::TaylorFunctions, #t::TaylorUnsupported> {
                    ::core::result::Result::Err(#reason)
                }
            };
            return Ok((accessor, proc_macro2::TokenStream::new()));
        }
    };
    let program = &plan.program;
    let ProgramTokens {
        statics,
        time,
        coupled,
        inputs,
        slots,
    } = program_static(program, &t, &cow);
    let (statements, stores) = order_zero(plan, krate, parameters)?;
    let calls: Vec<_> = program.ops.iter().map(|op| call_tokens(op, &t)).collect();
    // The orders whose compiled code a step can run (`TaylorProgram::unrolled_code_fits`):
    // compiling the others would only lengthen the build.
    let unrolled: Vec<usize> = (1..=program.highest_unrolled_order()).collect();
    // The fused orders' layout (`orders`): the program's derived lists, as constants
    // (the run-time `series_of_motion` reads the same lists from the program).
    let n = program.forcing.len();
    let highest = unrolled.len();
    let next = highest + 1;
    let forcing_slots = program.forcing.iter();
    let accelerations = program.acceleration_slot();
    let accessor = quote! {
        fn taylor(&self) -> ::core::result::Result<&dyn #t::TaylorFunctions, #t::TaylorUnsupported> {
            ::core::result::Result::Ok(self)
        }
    };
    let functions = quote! {
        fn program(&self) -> &#t::TaylorProgram {
            #statics
            &PROGRAM
        }
        #[allow(unused_variables)]
        fn order_zero(&self, __c: usize, __s: &mut [f64]) {
            #statements
            #(#stores)*
        }
        #[inline(never)]
        fn order(&self, __k: usize, __c: usize, __s: &mut [f64]) {
            // Any order, any stride: the orders a step runs with `k` known are in
            // `orders` (the same bits).
            #[inline(always)]
            fn __ops<const __K: usize>(__k: usize, __c: usize, __s: &mut [f64]) {
                #(#calls)*
            }
            __ops::<0>(__k, __c, __s);
        }
        fn fused_orders(&self) -> usize {
            #highest
        }
        #[inline(never)]
        fn orders(
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
            // Debug builds run the same orders with `k` a variable (one variant to compile;
            // the same bits).
            #[cfg(debug_assertions)]
            let __next = {
                let __s = &mut __s[..(#slots + #n) * #t::UNROLLED_CAPACITY];
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
            let __next = {
                #[inline(always)]
                fn __fused(
                    __solve: &mut #t::MotionSolve<'_>,
                    __order: usize,
                    __s: &mut [f64],
                    __out: &mut [f64],
                ) -> usize {
                    // A known length: the compiler drops the bounds checks of the constant
                    // offsets (in each copy: the one for AVX2 and FMA is not inlined here).
                    let __s = &mut __s[..(#slots + #n) * #t::UNROLLED_CAPACITY];
                    if __order == 0 {
                        return 0;
                    }
                    #t::motion_order::<#n, 0>(&__LAYOUT, __solve, 0, __s, __out);
                    #(
                        if #unrolled >= __order {
                            return #unrolled;
                        }
                        __ops::<#unrolled>(#unrolled, #t::UNROLLED_CAPACITY, __s);
                        #t::motion_order::<#n, #unrolled>(&__LAYOUT, __solve, #unrolled, __s, __out);
                    )*
                    #next
                }
                // The same code compiled a second time with AVX2 and FMA enabled, run where
                // the processor has them (`eomgen_runtime::taylor::host_features`): the same
                // operations, so the same bits (Rust neither contracts nor reassociates).
                #[cfg(target_arch = "x86_64")]
                #[target_feature(enable = "avx2,fma")]
                unsafe fn __fused_avx2(
                    __solve: &mut #t::MotionSolve<'_>,
                    __order: usize,
                    __s: &mut [f64],
                    __out: &mut [f64],
                ) -> usize {
                    __fused(__solve, __order, __s, __out)
                }
                #[cfg(target_arch = "x86_64")]
                let __next = if #t::host_features() {
                    // SAFETY: the processor has AVX2 and FMA (`host_features`).
                    unsafe { __fused_avx2(__solve, __order, __s, __out) }
                } else {
                    __fused(__solve, __order, __s, __out)
                };
                #[cfg(not(target_arch = "x86_64"))]
                let __next = __fused(__solve, __order, __s, __out);
                __next
            };
            __next
        }
    };
    let implementation = quote! {
        #[automatically_derived]
        #[allow(clippy::all, clippy::approx_constant, non_snake_case)]
        impl #t::TaylorFunctions for #name {
            #functions
        }
    };
    Ok((accessor, implementation))
}

/// The tokens of a generated model's program: its `static PROGRAM: TaylorProgram` (the
/// program as constants) and the pieces of it that the fused orders name again.
struct ProgramTokens {
    statics: proc_macro2::TokenStream,
    time: proc_macro2::TokenStream,
    coupled: Vec<proc_macro2::TokenStream>,
    inputs: Vec<proc_macro2::TokenStream>,
    slots: usize,
}

/// The [`ProgramTokens`] of `program`.
fn program_static(
    program: &TaylorProgram,
    t: &proc_macro2::TokenStream,
    cow: &proc_macro2::TokenStream,
) -> ProgramTokens {
    use quote::quote;
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
    let ops: Vec<_> = program.ops.iter().map(|op| op_tokens(op, t)).collect();
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
    let convolutions = derived.convolutions;
    let branch_points = derived.branch_points.iter();
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
                branch_points: #cow::Borrowed(&[#(#branch_points),*]),
            },
        };
    };
    ProgramTokens {
        statics,
        time,
        coupled,
        inputs,
        slots,
    }
}

/// Order 0 of a generated model's series: the statements of the extended tape (each value a
/// `let __vK: f64`) and the stores of every value but the state's into its slot.
///
/// # Errors
/// Only if a constant of the tape is not finite (a bug: the loader refuses such values).
// Long: one match arm per instruction kind of the tape, each the Rust of that operation.
fn order_zero(
    plan: &TaylorPlan,
    krate: &proc_macro2::TokenStream,
    parameters: &[proc_macro2::Ident],
) -> Result<(proc_macro2::TokenStream, Vec<proc_macro2::TokenStream>), String> {
    use quote::quote;
    // Order 0: the extended tape, every value stored in its slot.
    let value = |v: u32| super::rust_tokens::ident(&format!("__v{v}"));
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
            Instruction::Const(c) => super::rust_tokens::float(c)?,
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
                quote!(#private::powf(#x, #y))
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
                        let method = super::rust_tokens::ident(other.name())?;
                        let method = if other == Func::Ln {
                            super::rust_tokens::ident("ln")?
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
    Ok((statements, stores))
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
        TaylorUnsupported::Contacts { count } => {
            quote!(#t::TaylorUnsupported::Contacts { count: #count })
        }
        TaylorUnsupported::Stabilization { name } => {
            let name: &str = name;
            quote!(#t::TaylorUnsupported::Stabilization { name: #cow::Borrowed(#name) })
        }
        TaylorUnsupported::Speeds => quote!(#t::TaylorUnsupported::Speeds),
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
/// `order`, the kernel [`SeriesOp`]'s dispatch (`apply`) calls for the run-time model.
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
