//! The first-order right-hand side `ẏ = [q̇; M⁻¹F]` of a small unconstrained model as one
//! tape: `mass_matrix_and_forcing` followed by the solve, compiled into one function.
//!
//! The right-hand side is the hot path of every explicit integrator. Called as two steps —
//! the native `mass_matrix_and_forcing`, then
//! [`solve_spd`](eomgen_runtime::linalg::solve_spd) in Rust — `M` and `F` go through memory
//! between them and the solve cannot start until the call has returned; the code of
//! `eomgen::model!` has the solve inlined after the equations. One function does the same
//! for a run-time model.
//!
//! The solve is `solve_spd`'s, operation for operation, so the result is the same to the bit:
//! the closed forms for one and two degrees of freedom, and the square-root-free `L D Lᵀ`
//! factorisation with its forward and back substitutions for three and four (Golub & Van
//! Loan, *Matrix Computations*, 4th ed., §4.1.2). Larger models keep the two steps (the
//! factorisation's code grows as `n³`, and their equations dominate the cost anyway).
//!
//! # Outputs
//! The tape's outputs are `ẏ` (`2n` values: `q̇`, then `q̈`), then the `n` values whose
//! positivity is Sylvester's criterion, as `solve_spd` tests it: `M₀₀` and `det M` for
//! `n = 2`, the pivots `dⱼ` of `D` otherwise. The native function stores `ẏ` and returns its
//! verdict on the others: 1 if every pivot is positive (a NaN is not) and every `q̈` finite,
//! else 0 (`M` not positive definite and `q̈` meaningless, or a `q̈` not finite). Judged in
//! the function, on values still in registers, the verdict costs the caller one test: on two
//! masses the right-hand side went from 135 to 103 instructions a call with the values tested
//! one at a time (6.96–6.98 ns), and from 8.15 to 6.50 ns with them tested two at a time
//! (14 instructions rather than 22): 1.18× to 0.95× the time of `model!`'s
//! (`benches/runtime_model.rs`, docs/performance.md), against reading the pivots and `q̈` back
//! from memory.

use eomgen_symbolic::codegen::program::FunctionTape;
use eomgen_symbolic::codegen::tape::{Input, Instruction, Tape, Value};

/// The largest number of degrees of freedom given a fused right-hand side.
pub(crate) const FUSED_UP_TO: usize = 4;

/// The tape of `ẏ = [q̇; M⁻¹F]` for a model of `n` degrees of freedom (`1 ≤ n ≤`
/// [`FUSED_UP_TO`]) whose `mass_matrix_and_forcing` tape is `mass_and_forcing` (outputs: `M`
/// column-major, then `F`); `None` for other sizes or a tape of another shape. Outputs as the
/// module documentation says.
pub(crate) fn first_order_tape(mass_and_forcing: &FunctionTape, n: usize) -> Option<FunctionTape> {
    let source = &mass_and_forcing.tape;
    if !(1..=FUSED_UP_TO).contains(&n)
        || mass_and_forcing.split != n * n
        || source.outputs.len() != n * n + n
    {
        return None;
    }
    let mut tape = Writer {
        instructions: source.instructions.clone(),
    };
    let m = |i: usize, j: usize| source.outputs[i + j * n];
    let f: Vec<Value> = source.outputs[n * n..].to_vec();
    let (qddot, pivots) = match n {
        1 => (
            vec![tape.push(Instruction::Div(f[0], m(0, 0)))],
            vec![m(0, 0)],
        ),
        2 => cramer(&mut tape, [m(0, 0), m(1, 0), m(1, 1)], [f[0], f[1]]),
        _ => ldlt(&mut tape, n, m, f),
    };
    let velocities: Vec<Value> = (0..n)
        .map(|i| tape.input(Input::Velocity(i as u32)))
        .collect();
    let mut outputs = velocities;
    outputs.extend(qddot);
    let split = outputs.len();
    outputs.extend(pivots);
    Some(FunctionTape {
        tape: Tape {
            instructions: tape.instructions,
            outputs,
        },
        split,
    })
}

/// A tape being extended.
struct Writer {
    instructions: Vec<Instruction>,
}

impl Writer {
    fn push(&mut self, instruction: Instruction) -> Value {
        self.instructions.push(instruction);
        (self.instructions.len() - 1) as Value
    }

    /// The tape's instruction reading `input`, added if it has none.
    fn input(&mut self, input: Input) -> Value {
        match self
            .instructions
            .iter()
            .position(|i| *i == Instruction::Input(input))
        {
            Some(k) => k as Value,
            None => self.push(Instruction::Input(input)),
        }
    }

    /// `x − y·z`, as `x -= y * z` rounds it.
    fn sub_product(&mut self, x: Value, y: Value, z: Value) -> Value {
        let product = self.push(Instruction::Mul(y, z));
        self.push(Instruction::Sub(x, product))
    }
}

/// `M = [a b; b c]`: `x = [c f₀ − b f₁, a f₁ − b f₀] · (1/(a c − b²))`; the criterion's
/// values `a` and `a c − b²`.
fn cramer(
    tape: &mut Writer,
    [a, b, c]: [Value; 3],
    [f0, f1]: [Value; 2],
) -> (Vec<Value>, Vec<Value>) {
    let ac = tape.push(Instruction::Mul(a, c));
    let det = tape.sub_product(ac, b, b);
    let one = tape.push(Instruction::Const(1.0));
    let inverse = tape.push(Instruction::Div(one, det));
    let cf0 = tape.push(Instruction::Mul(c, f0));
    let x0 = tape.sub_product(cf0, b, f1);
    let x0 = tape.push(Instruction::Mul(x0, inverse));
    let af1 = tape.push(Instruction::Mul(a, f1));
    let x1 = tape.sub_product(af1, b, f0);
    let x1 = tape.push(Instruction::Mul(x1, inverse));
    (vec![x0, x1], vec![a, det])
}

/// `M = L D Lᵀ` and `x = L⁻ᵀ D⁻¹ L⁻¹ f` in `solve_spd`'s order of operations; the pivots
/// `dⱼ`.
fn ldlt(
    tape: &mut Writer,
    n: usize,
    m: impl Fn(usize, usize) -> Value,
    f: Vec<Value>,
) -> (Vec<Value>, Vec<Value>) {
    let one = tape.push(Instruction::Const(1.0));
    let mut l = vec![vec![0 as Value; n]; n];
    let mut d = vec![0 as Value; n];
    let mut inv_d = vec![0 as Value; n];
    for j in 0..n {
        // dⱼ −= lⱼₖ · lⱼₖ · dₖ, left to right.
        let mut dj = m(j, j);
        for k in 0..j {
            let square = tape.push(Instruction::Mul(l[j][k], l[j][k]));
            dj = tape.sub_product(dj, square, d[k]);
        }
        d[j] = dj;
        inv_d[j] = tape.push(Instruction::Div(one, dj));
        for i in j + 1..n {
            let mut v = m(i, j);
            for k in 0..j {
                let product = tape.push(Instruction::Mul(l[i][k], l[j][k]));
                v = tape.sub_product(v, product, d[k]);
            }
            l[i][j] = tape.push(Instruction::Mul(v, inv_d[j]));
        }
    }
    let mut x = f;
    for i in 0..n {
        for k in 0..i {
            x[i] = tape.sub_product(x[i], l[i][k], x[k]);
        }
    }
    for i in 0..n {
        x[i] = tape.push(Instruction::Mul(x[i], inv_d[i]));
    }
    for i in (0..n).rev() {
        for k in i + 1..n {
            x[i] = tape.sub_product(x[i], l[k][i], x[k]);
        }
    }
    (x, d)
}
