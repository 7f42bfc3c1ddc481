//! The branch check of a step ([`branch_step`](super::branch_step)): square roots and real
//! powers whose argument may reach 0 within the step, where the series would continue past
//! the branch point.

use eomgen_description::taylor::{SeriesOp, Slot, TaylorProgram};

/// `x.fract() == 0.0` (false for infinities and NaN), without the call `trunc` is in the
/// runtime's baseline build (8 % of the branch check's instructions on the figure eight):
/// every finite `f64` of magnitude `2⁵²` or more is an integer, and below that `(|x| + 2⁵²) −
/// 2⁵²` is `|x|` rounded to an integer (both operations exact but the first's rounding), so it
/// equals `|x|` exactly for the integers. A conversion to `i64` and back, as before, took
/// about 22 instructions with its saturation for large and NaN values: on the figure eight
/// (three powers) 34 and 56 instructions fewer a step at 10⁻⁶ in two counts, whose run-time
/// model moves by up to ±40 between counts (`tools/step_instructions.py`).
fn is_integer(x: f64) -> bool {
    const EXACT: f64 = 4_503_599_627_370_496.0; // 2⁵²
    let a = x.abs();
    a < f64::INFINITY && (a >= EXACT || (a + EXACT) - EXACT == a)
}

/// [`branch_step`](super::branch_step) on the series `s` of stride `c`.
pub(super) fn largest_step(
    program: &TaylorProgram,
    s: &[f64],
    c: usize,
    order: usize,
    h: f64,
) -> f64 {
    // Through a constant series the step is infinite: nothing to bound; nor without a root
    // or power.
    if !h.is_finite() || order == 0 || program.derived.branch_points.is_empty() {
        return h;
    }
    // Orders 0 … order − 1 of the program's slots are computed.
    let degree = order - 1;
    let mut limit = h;
    for &index in program.derived.branch_points.iter() {
        // An index past the ops (a `derived` not made from this program) names no op.
        let Some(&op) = program.ops.get(index as usize) else {
            continue;
        };
        let (out, argument, alpha) = match op {
            SeriesOp::Sqrt { out, a } => (out, Argument::Slot(a), 0.5),
            SeriesOp::Asin { a, root, .. } => (root, Argument::OneMinusSquare(a), 0.5),
            SeriesOp::PowConstant { out, a, exponent } => {
                let alpha = s[exponent as usize * c];
                if is_integer(alpha) {
                    continue;
                }
                (out, Argument::Slot(a), alpha)
            }
            _ => continue,
        };
        // A root or a real power of a positive argument is positive; anything else (a
        // model's NaN, an exact 0) is not this check's to judge.
        // Order 0 read as it is: the series at τ = 0 by Horner's rule would be the same value
        // for the finite series a step has here (`series_of_motion` refuses any other), after
        // a chain of `order` dependent multiply–adds (two of three such chains per power
        // per step, on the figure eight's r⁻³).
        let f = &s[out as usize * c..][..=degree];
        let start = f[0];
        if !(start > 0.0 && start < f64::INFINITY) {
            continue;
        }
        // Where the argument's series cannot fall below half its start in the step
        // (Σₖ₌₁ |gᵏ| τᵏ < g⁰/2), the branch point g = 0 is away from the step and f = g^α is
        // its series (the usual case, decided by one sum); for `Asin`'s root, whose argument
        // 1 − a² has no series of its own, where f cannot change sign (Σₖ₌₁ |fᵏ| τᵏ < f⁰).
        let moved = |series: &[f64]| {
            series[1..]
                .iter()
                .rev()
                .fold(0.0, |v, &x| v * limit + x.abs())
                * limit
        };
        let far = match argument {
            Argument::Slot(a) => {
                let g = &s[a as usize * c..][..=degree];
                moved(g) < 0.5 * g[0]
            }
            Argument::OneMinusSquare(_) => moved(f) < start,
        };
        if !far && let Some(off) = first_off_branch(s, c, degree, (out, argument, alpha), limit) {
            limit = 0.5 * off;
        }
    }
    limit
}

/// The argument of a root or power: a slot, or `1 − a²` of `Asin`'s slot `a`.
#[derive(Clone, Copy)]
enum Argument {
    Slot(Slot),
    OneMinusSquare(Slot),
}

/// [`branch_step`](super::branch_step)'s samples of `f = g^α` (`out`, its `argument` and `α`) over
/// `[0, limit]` in `series` (stride `c`, orders to `degree`): the first point where `f` or `g` has
/// left its sign, or `f` is no longer `g^α` to 10⁻³, or either is not finite (bisected to `limit /
/// 2³⁴`); `None` where every sample is on the branch, or where the argument at `τ = 0` is not
/// positive (NaN included). A function of its own, out of line, so that the loop over the points,
/// which the usual step leaves without a sample, keeps its registers.
#[cold]
#[inline(never)]
fn first_off_branch(
    series: &[f64],
    c: usize,
    degree: usize,
    (out, argument, alpha): (Slot, Argument, f64),
    limit: f64,
) -> Option<f64> {
    let value = |slot: Slot, tau: f64| {
        series[slot as usize * c..][..=degree]
            .iter()
            .rev()
            .fold(0.0, |v, &x| v * tau + x)
    };
    let argument_at = |tau: f64| match argument {
        Argument::Slot(a) => value(a, tau),
        Argument::OneMinusSquare(a) => {
            let x = value(a, tau);
            1.0 - x * x
        }
    };
    // Also skips a NaN argument.
    if argument_at(0.0).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let start = series[out as usize * c];
    // Written so that a NaN is off the branch.
    let off = |tau: f64| {
        let (f, g) = (value(out, tau), argument_at(tau));
        let on = f > 0.0 && g > 0.0 && (f - g.powf(alpha)).abs() <= 1e-3 * f.max(start);
        !on
    };
    const SAMPLES: usize = 16;
    let j = (1..=SAMPLES).find(|&j| off(limit * j as f64 / SAMPLES as f64))?;
    let (mut below, mut above) = (
        limit * (j - 1) as f64 / SAMPLES as f64,
        limit * j as f64 / SAMPLES as f64,
    );
    for _ in 0..30 {
        let middle = 0.5 * (below + above);
        if off(middle) {
            above = middle;
        } else {
            below = middle;
        }
    }
    Some(above)
}

#[cfg(test)]
mod tests {
    use super::is_integer;

    /// `is_integer` is `fract() == 0` on the integers, the halves around them, the limits of
    /// the exact conversion and the values that are not finite.
    #[test]
    fn is_integer_is_fract_equal_to_zero() {
        let exact = 4_503_599_627_370_496.0_f64;
        let mut cases = vec![
            0.0,
            -0.0,
            1.5,
            -1.5,
            0.5,
            1e-300,
            exact,
            exact - 0.5,
            exact + 1.0,
            9.3e18,
            1e300,
            f64::MAX,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MIN_POSITIVE,
        ];
        cases.extend((-40..=40).map(|i| i as f64 * 0.25));
        for x in cases {
            for x in [
                x,
                -x,
                f64::from_bits(x.to_bits() + 1),
                f64::from_bits(x.to_bits().wrapping_sub(1)),
            ] {
                assert_eq!(is_integer(x), x.fract() == 0.0, "{x:e}");
            }
        }
    }
}
