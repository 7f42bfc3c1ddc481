//! The Taylor program's sines and cosines of sums of angles (`codegen::taylor`: pairs formed
//! by the addition theorems run as one `sin_cos` of the sum) against the tape as it stands:
//! random tapes of those shapes (every mix of `Add`/`Sub`, operand order, negated products and
//! factors, `SinCos`/`CosOfSinCos` and separate `sin`/`cos` calls, differences both ways,
//! sines without their cosine, sums of sums) and random products that are no identity; every
//! output's series to order 9 from the program (orders ≥ 1 start as NaN, so an op run before
//! what it reads, or a dropped op still needed, shows) against the tape evaluated over series
//! directly, to 1e-9 relative (the two differ by rounding only).

use eomgen_description::taylor::SeriesOp;
use eomgen_symbolic::codegen::program::FunctionTape;
use eomgen_symbolic::codegen::tape::{Input, Instruction, Tape};
use eomgen_symbolic::codegen::taylor::taylor_program;
use eomgen_symbolic::expr::Func;

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn coin(&mut self) -> bool {
        self.next() & 1 == 1
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

struct B {
    ins: Vec<Instruction>,
}
impl B {
    fn push(&mut self, i: Instruction) -> u32 {
        self.ins.push(i);
        (self.ins.len() - 1) as u32
    }
    /// A slot with value `sign · a · b`, in a random form.
    fn prod(&mut self, r: &mut Rng, neg: bool, a: u32, b: u32) -> u32 {
        let (a, b) = if r.coin() { (a, b) } else { (b, a) };
        if !neg {
            match r.below(3) {
                0 => self.push(Instruction::Mul(a, b)),
                1 => {
                    let na = self.push(Instruction::Neg(a));
                    let nb = self.push(Instruction::Neg(b));
                    self.push(Instruction::Mul(na, nb))
                }
                _ => {
                    let na = self.push(Instruction::Neg(a));
                    let m = self.push(Instruction::Mul(na, b));
                    self.push(Instruction::Neg(m))
                }
            }
        } else {
            match r.below(3) {
                0 => {
                    let m = self.push(Instruction::Mul(a, b));
                    self.push(Instruction::Neg(m))
                }
                1 => {
                    let na = self.push(Instruction::Neg(a));
                    self.push(Instruction::Mul(na, b))
                }
                _ => {
                    let nb = self.push(Instruction::Neg(b));
                    self.push(Instruction::Mul(a, nb))
                }
            }
        }
    }
    /// `s1·A·B + s2·C·D` in a random form.
    fn sum(&mut self, r: &mut Rng, t1: (bool, u32, u32), t2: (bool, u32, u32)) -> u32 {
        let (t1, t2) = if r.coin() { (t1, t2) } else { (t2, t1) };
        if r.coin() {
            let p = self.prod(r, t1.0, t1.1, t1.2);
            let q = self.prod(r, t2.0, t2.1, t2.2);
            self.push(Instruction::Add(p, q))
        } else {
            let p = self.prod(r, t1.0, t1.1, t1.2);
            let q = self.prod(r, !t2.0, t2.1, t2.2);
            self.push(Instruction::Sub(p, q))
        }
    }
}

const K: usize = 9;

fn series_sin_cos(a: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let mut s = vec![a[0].sin()];
    let mut c = vec![a[0].cos()];
    for k in 1..=K {
        let kf = k as f64;
        let mut vs = 0.0;
        let mut vc = 0.0;
        for j in 1..=k {
            vs += j as f64 * a[j] * c[k - j];
            vc += j as f64 * a[j] * s[k - j];
        }
        s.push(vs / kf);
        c.push(-vc / kf);
    }
    (s, c)
}

fn cauchy(a: &[f64], b: &[f64], k: usize) -> f64 {
    (0..=k).map(|j| a[j] * b[k - j]).sum()
}

/// The tape as it stands, over series.
fn reference(tape: &Tape, inputs: &dyn Fn(Input) -> Vec<f64>) -> Vec<Vec<f64>> {
    let mut v: Vec<Vec<f64>> = Vec::new();
    for ins in &tape.instructions {
        let x = match *ins {
            Instruction::Input(i) => inputs(i),
            Instruction::Const(c) => {
                let mut s = vec![0.0; K + 1];
                s[0] = c;
                s
            }
            Instruction::Neg(a) => v[a as usize].iter().map(|x| -x).collect(),
            Instruction::Add(a, b) => (0..=K)
                .map(|k| v[a as usize][k] + v[b as usize][k])
                .collect(),
            Instruction::Sub(a, b) => (0..=K)
                .map(|k| v[a as usize][k] - v[b as usize][k])
                .collect(),
            Instruction::Mul(a, b) => (0..=K)
                .map(|k| cauchy(&v[a as usize], &v[b as usize], k))
                .collect(),
            Instruction::Call(Func::Sin, a) | Instruction::SinCos(a) => {
                series_sin_cos(&v[a as usize]).0
            }
            Instruction::Call(Func::Cos, a) => series_sin_cos(&v[a as usize]).1,
            Instruction::CosOfSinCos(s) => {
                let Instruction::SinCos(a) = tape.instructions[s as usize] else {
                    panic!()
                };
                series_sin_cos(&v[a as usize]).1
            }
            other => panic!("{other:?}"),
        };
        v.push(x);
    }
    v
}

/// The program: order 0 from the extended tape, orders >= 1 by its ops; NaN where nothing
/// writes.
fn program_series(
    plan: &eomgen_symbolic::codegen::taylor::TaylorPlan,
    inputs: &dyn Fn(Input) -> Vec<f64>,
) -> Vec<Vec<f64>> {
    let tape = &plan.order_zero;
    let mut s: Vec<Vec<f64>> = vec![vec![f64::NAN; K + 1]; tape.instructions.len()];
    for (k, ins) in tape.instructions.iter().enumerate() {
        let v0 = match *ins {
            Instruction::Input(i) => {
                s[k] = inputs(i);
                continue;
            }
            Instruction::Const(c) => c,
            Instruction::Neg(a) => -s[a as usize][0],
            Instruction::Add(a, b) => s[a as usize][0] + s[b as usize][0],
            Instruction::Sub(a, b) => s[a as usize][0] - s[b as usize][0],
            Instruction::Mul(a, b) => s[a as usize][0] * s[b as usize][0],
            Instruction::Call(Func::Sin, a) | Instruction::SinCos(a) => s[a as usize][0].sin(),
            Instruction::Call(Func::Cos, a) => s[a as usize][0].cos(),
            Instruction::CosOfSinCos(x) => {
                let Instruction::SinCos(a) = tape.instructions[x as usize] else {
                    panic!()
                };
                s[a as usize][0].cos()
            }
            other => panic!("{other:?}"),
        };
        s[k][0] = v0;
    }
    for k in 1..=K {
        let kf = k as f64;
        for op in plan.program.ops.iter() {
            match *op {
                SeriesOp::Neg { out, a } => s[out as usize][k] = -s[a as usize][k],
                SeriesOp::Copy { out, a } => s[out as usize][k] = s[a as usize][k],
                SeriesOp::Add { out, a, b } => {
                    s[out as usize][k] = s[a as usize][k] + s[b as usize][k]
                }
                SeriesOp::Sub { out, a, b } => {
                    s[out as usize][k] = s[a as usize][k] - s[b as usize][k]
                }
                SeriesOp::Mul { out, a, b } => {
                    s[out as usize][k] = cauchy(&s[a as usize], &s[b as usize], k)
                }
                SeriesOp::Scale { out, a, constant } => {
                    s[out as usize][k] = s[a as usize][k] * s[constant as usize][0]
                }
                SeriesOp::SinCos { sin, cos, a } => {
                    let mut vs = 0.0;
                    let mut vc = 0.0;
                    for j in 1..=k {
                        vs += j as f64 * s[a as usize][j] * s[cos as usize][k - j];
                        vc += j as f64 * s[a as usize][j] * s[sin as usize][k - j];
                    }
                    s[sin as usize][k] = vs / kf;
                    s[cos as usize][k] = -vc / kf;
                }
                other => panic!("{other:?}"),
            }
        }
    }
    s
}

#[test]
fn random_addition_theorem_tapes() {
    let mut r = Rng(0x9e37_79b9_7f4a_7c15);
    let mut total_pairs = 0;
    let mut total_chains = 0;
    for case in 0..2000 {
        let mut b = B { ins: Vec::new() };
        let n = 6usize;
        let angles: Vec<u32> = (0..3)
            .map(|i| b.push(Instruction::Input(Input::Coordinate(i))))
            .collect();
        let vel: Vec<u32> = (0..n as u32)
            .map(|i| b.push(Instruction::Input(Input::Velocity(i))))
            .collect();
        // (sin, cos, terms) of each angle.
        let mut trig: Vec<(u32, u32, usize)> = Vec::new();
        for &a in &angles {
            match r.below(3) {
                0 => {
                    let s = b.push(Instruction::SinCos(a));
                    let c = b.push(Instruction::CosOfSinCos(s));
                    trig.push((s, c, 1));
                }
                1 => {
                    let s = b.push(Instruction::Call(Func::Sin, a));
                    let c = b.push(Instruction::Call(Func::Cos, a));
                    trig.push((s, c, 1));
                }
                _ => {
                    let c = b.push(Instruction::Call(Func::Cos, a));
                    let s = b.push(Instruction::Call(Func::Sin, a));
                    trig.push((s, c, 1));
                }
            }
        }
        let mut candidates: Vec<u32> = Vec::new();
        let steps = 2 + r.below(14);
        for _ in 0..steps {
            let i = r.below(trig.len());
            let j = r.below(trig.len());
            let (si, ci, ti) = trig[i];
            let (sj, cj, tj) = trig[j];
            let minus = r.coin();
            match r.below(8) {
                // A valid pair, in random order (sine first or cosine first), maybe only one.
                0..=4 => {
                    let want = r.below(4); // 0: both, 1: sine only, 2: cosine only, 3: both, cos first
                    let sine = |b: &mut B, r: &mut Rng| b.sum(r, (false, si, cj), (minus, ci, sj));
                    let cosine =
                        |b: &mut B, r: &mut Rng| b.sum(r, (false, ci, cj), (!minus, si, sj));
                    let (s, c) = match want {
                        0 => {
                            let s = sine(&mut b, &mut r);
                            (Some(s), Some(cosine(&mut b, &mut r)))
                        }
                        1 => (Some(sine(&mut b, &mut r)), None),
                        2 => (None, Some(cosine(&mut b, &mut r))),
                        _ => {
                            let c = cosine(&mut b, &mut r);
                            (Some(sine(&mut b, &mut r)), Some(c))
                        }
                    };
                    candidates.extend(s);
                    candidates.extend(c);
                    if let (Some(s), Some(c)) = (s, c) {
                        // Sometimes as sin(−θ): −S.
                        if r.below(4) == 0 {
                            let ns = b.push(Instruction::Neg(s));
                            trig.push((ns, c, ti + tj));
                        } else {
                            trig.push((s, c, ti + tj));
                        }
                    }
                }
                // Random sign patterns of random products (mostly not identities).
                _ => {
                    let f = [si, ci, sj, cj];
                    let t1 = (r.coin(), f[r.below(4)], f[r.below(4)]);
                    let t2 = (r.coin(), f[r.below(4)], f[r.below(4)]);
                    candidates.push(b.sum(&mut r, t1, t2));
                }
            }
        }
        let _ = total_chains;
        total_chains += trig.iter().filter(|t| t.2 > 2).count();
        // Outputs: n*n + n, candidates (sometimes times a velocity) padded with velocities.
        let mut outputs = Vec::new();
        for &c in &candidates {
            if outputs.len() == n * n + n {
                break;
            }
            if r.coin() {
                let v = vel[r.below(n)];
                outputs.push(b.push(Instruction::Mul(c, v)));
            } else {
                outputs.push(c);
            }
        }
        while outputs.len() < n * n + n {
            outputs.push(vel[r.below(n)]);
        }
        let tape = Tape {
            instructions: b.ins.clone(),
            outputs: outputs.clone(),
        };
        tape.validate().unwrap();
        let split = outputs.len();
        let plan = taylor_program(
            &FunctionTape {
                tape: tape.clone(),
                split,
            },
            n,
            0,
        )
        .unwrap();
        plan.order_zero.validate().unwrap();
        let coefs: Vec<Vec<f64>> = (0..12)
            .map(|_| (0..=K).map(|_| r.unit()).collect())
            .collect();
        let inputs = |i: Input| -> Vec<f64> {
            match i {
                Input::Coordinate(i) => coefs[i as usize].clone(),
                Input::Velocity(i) => coefs[4 + i as usize].clone(),
                _ => panic!(),
            }
        };
        let want = reference(&tape, &inputs);
        let got = program_series(&plan, &inputs);
        // The program's slots are those of the numbered tape (`Tape::numbered`, which the
        // program is built from), the reference's those of `tape`: outputs by position.
        let numbered = tape.numbered();
        total_pairs += plan
            .program
            .ops
            .iter()
            .filter(|op| matches!(op, SeriesOp::SinCos { sin, .. } if (*sin as usize) < numbered.instructions.len() && matches!(numbered.instructions[*sin as usize], Instruction::Add(..) | Instruction::Sub(..))))
            .count();
        assert_eq!(plan.order_zero.outputs.len(), outputs.len());
        for (&o, &p) in outputs.iter().zip(plan.order_zero.outputs.iter()) {
            for k in 0..=K {
                let (w, g) = (want[o as usize][k], got[p as usize][k]);
                assert!(
                    (w - g).abs() <= 1e-9 * w.abs().max(1.0),
                    "case {case}: output {o} order {k}: want {w}, got {g}\n{:?}\nops {:?}",
                    tape,
                    plan.program.ops
                );
            }
        }
    }
    assert!(total_pairs > 100);
}
