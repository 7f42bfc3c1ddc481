//! The eigenvalues of an operating point against a parameter (`eomgen study parameter-sweep`):
//! the root locus of a steady motion or an equilibrium over a range of one parameter (a
//! bicycle's speed, a top's spin), and the values where the stability changes, each refined
//! by bisection.
//!
//! At every value the operating point is found again (its rates, expressions of the
//! parameters, follow the value; a family picked by a held value — an entry that holds a
//! coordinate, finds a rate or turns — from the motion found at the value before) and
//! linearised as `eomgen modes` does: the reduced state
//! matrix of [`crate::linear::steady`] for a steady motion or a model with non-holonomic
//! constraints, and the state matrix of `M δq̈ + C δq̇ + K δq = 0`
//! ([`crate::linear::eigenvalues`]) for an equilibrium.
//!
//! A *stability change* lies between two neighbouring values whose numbers of eigenvalues
//! with a positive real part differ; bisection on that number narrows it to
//! `1e-12 max(1, |value|)` (about 40 halvings), and the eigenvalue nearest the imaginary axis
//! there says whether a real eigenvalue crossed (through 0, a divergence such as a capsize)
//! or a complex pair (at `±iω`, a flutter or weave). Locating the change on the count rather
//! than on a tracked eigenvalue's real part needs no tracking, and is exact wherever the
//! count is: it is decided by the eigenvalues' signs, which the reduced matrices give to
//! rounding away from the crossing.

use std::collections::BTreeMap;

use nalgebra::Complex;
use serde::Serialize;

use super::floquet::SweepAxis;
use super::operating_point::{OperatingPointError, OperatingPointOptions};
use super::steady::{SteadyAnalysisError, is_steady_motion, steady_motion_analysis_from};
use crate::linear::eigenvalues::{Stability, linear_stability};
use crate::linear::modal::ModalError;
use crate::linear::modal::linearize;
use crate::linear::steady::raw_eigenvalues;
use crate::model_info::ModelInfo;

/// Options of [`parameter_sweep`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterSweepOptions {
    /// The parameter and its values (ascending).
    pub axis: SweepAxis,
    /// The operating point at every value.
    pub operating_point: OperatingPointOptions,
    /// Whether to refine every stability change by bisection (default `true`).
    pub refine: bool,
}

/// Why a sweep could not start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ParameterSweepError {
    /// The model has no such parameter.
    #[error("`{model}` has no parameter `{name}` (it has: {})", known.join(", "))]
    UnknownParameter {
        /// The model.
        model: String,
        /// The name asked for.
        name: String,
        /// Its parameters.
        known: Vec<String>,
    },
    /// The linearised equations depend on `t` at the first value where that was found (a
    /// parametric excitation, a moving constraint): a property of the model, which `modes`
    /// refuses too; the sweep stops there, as the equations frozen at `t₀` have no modes.
    #[error("{source}")]
    TimeDependent {
        /// The parameter's value where it was found.
        value: f64,
        /// What depends on `t` ([`ModalError::TimeDependent`]).
        source: ModalError,
    },
    /// No value of the sweep gave eigenvalues: the first failure.
    #[error("no value of the sweep could be analysed; at {value}: {reason}")]
    EveryPointFailed {
        /// The first value.
        value: f64,
        /// Why it failed there.
        reason: String,
    },
}

/// The eigenvalues at one value of the parameter, or why there are none.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepPoint {
    /// The parameter's value.
    pub value: f64,
    /// The eigenvalues (1/s), by ascending `|s|`, `[re, im]` in JSON; empty when it failed.
    #[serde(serialize_with = "crate::serde_matrix::complex_list")]
    pub eigenvalues: Vec<Complex<f64>>,
    /// The verdict (`None` when it failed).
    pub stability: Option<Stability>,
    /// Why the operating point or its linearisation failed there (`None` when it did not).
    pub error: Option<String>,
    /// What a steady motion's search found there, by name (the coordinates it finds and the
    /// rates it finds: a bicycle turn's lean and speed); empty for an equilibrium or a
    /// failure, and then left out of the JSON.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub found: BTreeMap<String, f64>,
}

/// How an eigenvalue crossed the imaginary axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Crossing {
    /// A real eigenvalue through 0 (a divergence: the capsize of a bicycle).
    Real,
    /// A complex pair through `±iω` (a flutter: the weave of a bicycle).
    Complex,
    /// A real eigenvalue through infinity: a pole of the linearisation, where a stiffness or
    /// an inertia is singular (`k/(a − 1)` at `a = 1`), not a crossing of the axis.
    Pole,
}

/// Whether a change makes the operating point more stable as the parameter grows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// Fewer eigenvalues with a positive real part above the value.
    Stabilising,
    /// More above the value.
    Destabilising,
}

/// A value of the parameter where the stability changes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StabilityChange {
    /// The parameter's value: refined by bisection, then by regula falsi on the
    /// characteristic polynomial (a real eigenvalue) or the secant on the real part (a
    /// complex pair from the left half-plane).
    pub value: f64,
    /// Real or complex crossing.
    pub eigenvalue: Crossing,
    /// Stabilising or destabilising with growing value.
    pub direction: Direction,
    /// `|Im s|` of the crossing eigenvalue (rad/s; 0 for a real one).
    pub frequency: f64,
    /// A bracket of the crossing, `[below, above]`: for a real eigenvalue, where the
    /// characteristic polynomial's coefficient changes sign; otherwise where the bisection on
    /// the number of unstable eigenvalues ended.
    pub bracket: [f64; 2],
}

/// The eigenvalues against a parameter and the stability changes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterSweep {
    /// The model.
    pub model: String,
    /// The parameter.
    pub parameter: String,
    /// The operating point's name.
    pub operating_point: String,
    /// One entry per value, in order.
    pub points: Vec<SweepPoint>,
    /// Every stability change, in ascending value.
    pub stability_changes: Vec<StabilityChange>,
}

impl ParameterSweep {
    /// The eigenvalues tracked across the sweep: `slots` series of `(value, s)`, each point's
    /// eigenvalues matched to the previous point's by nearest neighbour in the complex plane
    /// (greedy), so that a chart draws each eigenvalue as one curve. Points that failed or
    /// have a different number of eigenvalues start the matching afresh.
    pub fn tracked(&self) -> Vec<Vec<(f64, Complex<f64>)>> {
        let mut series: Vec<Vec<(f64, Complex<f64>)>> = Vec::new();
        let mut last: Vec<Complex<f64>> = Vec::new();
        for p in &self.points {
            if p.eigenvalues.is_empty() {
                continue;
            }
            let mut order: Vec<Complex<f64>> = p.eigenvalues.clone();
            if last.len() == order.len() {
                let mut free = order.clone();
                order = last
                    .iter()
                    .map(|prev| {
                        let (k, _) =
                            free.iter()
                                .enumerate()
                                .fold((0, f64::INFINITY), |(bk, bd), (k, s)| {
                                    let d = (s - prev).norm();
                                    if d < bd { (k, d) } else { (bk, bd) }
                                });
                        free.swap_remove(k)
                    })
                    .collect();
            }
            if series.len() < order.len() {
                series.resize(order.len(), Vec::new());
            }
            for (slot, s) in order.iter().enumerate() {
                series[slot].push((p.value, *s));
            }
            last = order;
        }
        series
    }
}

/// The eigenvalues of an operating point ([`eigenvalues_at`]).
#[derive(Debug, Clone, PartialEq)]
pub struct PointEigenvalues {
    /// The eigenvalues as `eomgen modes` reports them (real parts at rounding set to 0).
    pub eigenvalues: Vec<Complex<f64>>,
    /// The verdict from them.
    pub stability: Stability,
    /// The eigenvalues of the state matrix with nothing set to 0, by which a change of sign
    /// is located.
    pub raw: Vec<Complex<f64>>,
    /// The steady motion's state `(q*, q̇*)` (length `2n`); `None` for an equilibrium.
    pub state: Option<Vec<f64>>,
    /// [`SweepPoint::found`].
    pub found: BTreeMap<String, f64>,
}

/// Why the eigenvalues at one value could not be found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SweepPointError {
    /// The steady motion or its linearisation failed.
    #[error(transparent)]
    Steady(#[from] SteadyAnalysisError),
    /// The equilibrium was not found.
    #[error(transparent)]
    OperatingPoint(#[from] OperatingPointError),
    /// The linearisation about the equilibrium failed.
    #[error(transparent)]
    Modal(#[from] ModalError),
}

/// The eigenvalues of `model` at its operating point for the current parameters: the
/// reduced state matrix's for a steady motion, `M δq̈ + C δq̇ + K δq = 0`'s for an
/// equilibrium.
///
/// # Errors
/// [`SweepPointError`]: no operating point, or a linearisation that fails there.
pub fn eigenvalues_at(
    model: &mut dyn ModelInfo,
    options: &OperatingPointOptions,
) -> Result<PointEigenvalues, SweepPointError> {
    eigenvalues_from(model, options, None)
}

/// [`eigenvalues_at`], a steady motion's search started from the state `from` where given
/// ([`steady_motion_analysis_from`]).
fn eigenvalues_from(
    model: &mut dyn ModelInfo,
    options: &OperatingPointOptions,
    from: Option<&[f64]>,
) -> Result<PointEigenvalues, SweepPointError> {
    if is_steady_motion(model, &options.start) {
        let a = steady_motion_analysis_from(model, options, from)?;
        let raw = raw_eigenvalues(&a.linearization.state_matrix).ok_or(
            ModalError::EigenvaluesDidNotConverge {
                size: a.linearization.state_matrix.nrows(),
                q: a.steady_motion.q.clone(),
            },
        )?;
        return Ok(PointEigenvalues {
            eigenvalues: a.eigenvalues,
            stability: a.stability,
            raw,
            state: Some(a.steady_motion.state()),
            found: a.found,
        });
    }
    let point = super::operating_point::operating_point(model, options)?;
    // As `modes`: equations that change with t have no modes frozen at t₀ (a load that only
    // moves the equilibrium is allowed).
    crate::linear::time_dependence::time_dependence(&*model, point.q(), point.t)?;
    let n = model.num_dofs();
    let lin = linearize(model, point.q(), &vec![0.0; n], point.t)?;
    let s = linear_stability(&lin)?;
    let a = lin.state_matrix()?;
    let raw = raw_eigenvalues(&a).ok_or(ModalError::EigenvaluesDidNotConverge {
        size: a.nrows(),
        q: lin.q.clone(),
    })?;
    Ok(PointEigenvalues {
        eigenvalues: s.eigenvalues,
        stability: s.stability,
        raw,
        state: None,
        found: BTreeMap::new(),
    })
}

/// Number of eigenvalues with a positive real part, among the verdict's eigenvalues (real
/// parts at rounding already 0, as `modes` prints them): the count agrees with each point's
/// printed verdict.
fn unstable_count(eigenvalues: &[Complex<f64>]) -> usize {
    eigenvalues.iter().filter(|s| s.re > 0.0).count()
}

/// How many of a point's verdict eigenvalues are exactly 0 (a family of steady motions, a
/// conserved quantity, a rigid-body mode).
fn zero_count(point: &PointEigenvalues) -> usize {
    point.eigenvalues.iter().filter(|s| s.norm() == 0.0).count()
}

/// The stability change between two neighbouring values `[(v, eigenvalues); 2]` whose
/// numbers of unstable eigenvalues `counts` differ, with `at(v)` the eigenvalues at `v`:
/// bisection on the count to 1e-12 relative, then, for a real eigenvalue, the sign change of
/// the characteristic polynomial's coefficient of `s^z` (`z` the zeros both values share),
/// kept where the crossing eigenvalue is at rounding of zero there; for a complex pair from
/// the left half-plane, the secant on its real part.
fn locate_change(
    at: &mut impl FnMut(f64) -> Option<PointEigenvalues>,
    [(v_a, a), (v_b, b)]: [(f64, &PointEigenvalues); 2],
    [count_a, count_b]: [usize; 2],
) -> StabilityChange {
    let ([lo, hi], unstable_side) = bisect_on_count(at, [v_a, v_b], [count_a, count_b]);
    let (unstable_grid, stable_grid) = if count_a > count_b { (a, b) } else { (b, a) };
    // The crossing eigenvalue: the unstable one nearest the axis on that side.
    let side = unstable_side.unwrap_or_else(|| unstable_grid.clone());
    let crossing = side
        .eigenvalues
        .iter()
        .copied()
        .filter(|s| s.re > 0.0)
        .min_by(|x, y| x.re.total_cmp(&y.re))
        .unwrap_or_default();
    // Real or complex is read at the grid value on the unstable side, away from the
    // crossing: a real pair that meets at zero and leaves as an imaginary pair (a spinning
    // body, a rolling disc) is split by rounding into a complex pair right at the crossing.
    let complex = unstable_grid
        .eigenvalues
        .iter()
        .filter(|s| s.re > 0.0)
        .min_by(|x, y| x.re.total_cmp(&y.re))
        .is_some_and(|s| s.im.abs() > 1e-6 * s.norm());
    let mut value = 0.5 * (lo + hi);
    let mut bracket = [lo, hi];
    // Through infinity rather than 0: near the change an eigenvalue is far larger than any
    // at the grid value on the unstable side (it grows without bound towards the pole),
    // whichever it is (another unstable one may be nearer the axis).
    let largest = |p: &PointEigenvalues| p.eigenvalues.iter().fold(0.0f64, |m, s| m.max(s.norm()));
    let pole = !complex && largest(&side) > 1e3 * largest(unstable_grid);
    if pole {
    } else if complex {
        // Only where the pair comes from (or goes into) the left half-plane: where it meets
        // another pair on the imaginary axis and leaves it (a gyroscopic system's Krein
        // collision, the sleeping top), the real part grows as a square root, and the
        // bisection's count is the better locator.
        let transversal = stable_grid
            .eigenvalues
            .iter()
            .min_by(|x, y| (*x - crossing).norm().total_cmp(&(*y - crossing).norm()))
            .is_some_and(|s| s.re < 0.0);
        if transversal {
            value = secant_on_real_part(at, crossing, [lo, hi], [v_a, v_b], value);
        }
    } else if let Some((root, around)) =
        real_crossing(at, [a, b], stable_grid, [lo, hi], [v_a, v_b])
    {
        value = root;
        bracket = around;
    }
    StabilityChange {
        value,
        eigenvalue: if pole {
            Crossing::Pole
        } else if complex {
            Crossing::Complex
        } else {
            Crossing::Real
        },
        direction: if count_b < count_a {
            Direction::Stabilising
        } else {
            Direction::Destabilising
        },
        // At the refined value: the pair's frequency where its real part is 0.
        frequency: if complex {
            crossing_frequency(at, value, crossing)
        } else {
            0.0
        },
        bracket,
    }
}

/// Bisection of [`locate_change`] on the number of unstable eigenvalues between the grid
/// values `[v_a, v_b]` (counts `[count_a, count_b]`) to `1e-12 max(1, |v|)`, at most 200
/// halvings: the final bracket `[lo, hi]` (`lo` on `v_a`'s side) and the eigenvalues last
/// found on the side with more unstable ones, if any.
fn bisect_on_count(
    at: &mut impl FnMut(f64) -> Option<PointEigenvalues>,
    [v_a, v_b]: [f64; 2],
    [count_a, count_b]: [usize; 2],
) -> ([f64; 2], Option<PointEigenvalues>) {
    let (mut lo, mut hi) = (v_a, v_b);
    // The eigenvalues on the side with more unstable ones, as near the crossing as the
    // bisection gets.
    let mut unstable_side: Option<PointEigenvalues> = None;
    for _ in 0..200 {
        if hi - lo <= 1e-12 * lo.abs().max(hi.abs()).max(1.0) {
            break;
        }
        // A midpoint where the linearisation fails (a pole exactly there) is moved once.
        let mut mid = 0.5 * (lo + hi);
        let point = match at(mid) {
            Some(point) => point,
            None => {
                mid = lo + 0.381_966 * (hi - lo);
                let Some(point) = at(mid) else { break };
                point
            }
        };
        let count = unstable_count(&point.eigenvalues);
        if count == count_a {
            lo = mid;
        } else {
            hi = mid;
        }
        if count == count_a.max(count_b) {
            unstable_side = Some(point);
        }
    }
    ([lo, hi], unstable_side)
}

/// A real eigenvalue's crossing of 0 for [`locate_change`]: the sign change of the
/// characteristic polynomial's coefficient of `s^z` (`z` the zeros both grid points `a`, `b`
/// share) near the bisection's `[lo, hi]` within the grid values `[v_a, v_b]`, as
/// `(root, bracket)`; `None` when there is none or the crossing eigenvalue is not near zero
/// there (above `1e-3` of its size at the grid point `stable_grid`).
fn real_crossing(
    at: &mut impl FnMut(f64) -> Option<PointEigenvalues>,
    [a, b]: [&PointEigenvalues; 2],
    stable_grid: &PointEigenvalues,
    [lo, hi]: [f64; 2],
    [v_a, v_b]: [f64; 2],
) -> Option<(f64, [f64; 2])> {
    // A real eigenvalue through 0: the coefficient of `s^z` in `det(sI − A)` changes
    // sign there, smooth where the eigenvalue is not (a pair that meets at 0 and leaves
    // as an imaginary pair, whose real part grows as a square root).
    let z = zero_count(a).min(zero_count(b));
    let size = stable_grid.raw.len();
    let mut coefficient = |v: f64| -> Option<f64> {
        let raw = at(v)?.raw;
        (raw.len() == size).then(|| characteristic_coefficient(&raw, z))
    };
    if let Some((root, around)) = sign_change(&mut coefficient, [lo, hi], [v_a, v_b]) {
        // Kept where the crossing eigenvalue (the `z + 1`-th smallest) is near zero, a
        // thousandth of its size on the stable side (near a crossing where a pair meets at
        // 0 beside a zero, the computed eigenvalues of the near-triple zero carry
        // `(ε ‖A‖)^(1/3)`): a slow eigenvalue, or a pole, also changes the coefficient's
        // sign.
        let nearest = |raw: &[Complex<f64>]| {
            let mut m: Vec<f64> = raw.iter().map(|s| s.norm()).collect();
            m.sort_by(f64::total_cmp);
            m.get(z).copied()
        };
        let there = at(root).and_then(|p| nearest(&p.raw));
        if let (Some(there), Some(away)) = (there, nearest(&stable_grid.raw))
            && there <= 1e-3 * away
        {
            return Some((root, around));
        }
    }
    None
}

/// `|Im s|` (rad/s) at `value` of the raw eigenvalue nearest `crossing` (a complex pair's
/// frequency where its real part is 0); `crossing`'s own when `at(value)` fails.
fn crossing_frequency(
    at: &mut impl FnMut(f64) -> Option<PointEigenvalues>,
    value: f64,
    crossing: Complex<f64>,
) -> f64 {
    at(value)
        .and_then(|p| {
            p.raw
                .iter()
                .copied()
                .min_by(|x, y| (*x - crossing).norm().total_cmp(&(*y - crossing).norm()))
        })
        .unwrap_or(crossing)
        .im
        .abs()
}

/// A complex pair's crossing refined by the secant method on its real part (smooth in the
/// parameter), followed as the raw eigenvalue nearest `crossing`: this removes the bias of
/// the count, which ends the bisection where the verdict's real part leaves rounding (below
/// `1e-9 |s|`) rather than at 0. Steps stay between the grid values `[grid_lo, grid_hi]`; the
/// result is kept where the real part is below `1e-12 |s|` there, `value` otherwise.
fn secant_on_real_part(
    at: &mut impl FnMut(f64) -> Option<PointEigenvalues>,
    crossing: Complex<f64>,
    [lo, hi]: [f64; 2],
    [grid_lo, grid_hi]: [f64; 2],
    value: f64,
) -> f64 {
    let mut real_part = |v: f64| -> Option<f64> {
        let raw = at(v)?.raw;
        raw.iter()
            .min_by(|x, y| (*x - crossing).norm().total_cmp(&(*y - crossing).norm()))
            .map(|s| s.re)
    };
    let width = (hi - lo).max(1e-9 * lo.abs().max(1.0));
    let (mut v0, mut v1) = (lo - width, hi + width);
    let (Some(mut f0), Some(mut f1)) = (real_part(v0), real_part(v1)) else {
        return value;
    };
    for _ in 0..12 {
        if f1 == f0 {
            break;
        }
        let v2 = v1 - f1 * (v1 - v0) / (f1 - f0);
        if !v2.is_finite() || v2 < grid_lo.min(grid_hi) || v2 > grid_lo.max(grid_hi) {
            break;
        }
        let Some(f2) = real_part(v2) else { break };
        (v0, f0, v1, f1) = (v1, f1, v2, f2);
        if (v1 - v0).abs() <= 1e-15 * v1.abs().max(1.0) {
            break;
        }
    }
    if f1.abs() <= 1e-12 * crossing.norm()
        && v1 >= grid_lo.min(grid_hi)
        && v1 <= grid_lo.max(grid_hi)
    {
        v1
    } else {
        value
    }
}

/// A sign change of `g` near `[lo, hi]` inside `grid` (the two values of the sweep around
/// it), refined by the Illinois variant of regula falsi (Dowell & Jarratt, BIT 11, 1971) to
/// a bracket of `1e-15` of the value: `(root, bracket)`. The search widens `[lo, hi]` tenfold
/// on each side until `g` differs in sign at its ends (the bisection on the count of unstable
/// eigenvalues ends where the crossing one passes the rounding bound, not at 0); `None` if
/// `g` fails or keeps its sign up to the grid values.
fn sign_change(
    g: &mut impl FnMut(f64) -> Option<f64>,
    [lo, hi]: [f64; 2],
    [grid_lo, grid_hi]: [f64; 2],
) -> Option<(f64, [f64; 2])> {
    let mut width = (hi - lo).max(1e-12 * lo.abs().max(hi.abs()).max(1.0));
    let (mut a, mut b);
    let (mut fa, mut fb);
    loop {
        a = (lo - width).max(grid_lo);
        b = (hi + width).min(grid_hi);
        fa = g(a)?;
        fb = g(b)?;
        if fa == 0.0 {
            return Some((a, [a, a]));
        }
        if fb == 0.0 {
            return Some((b, [b, b]));
        }
        if (fa < 0.0) != (fb < 0.0) {
            break;
        }
        if a == grid_lo && b == grid_hi {
            return None;
        }
        width *= 10.0;
    }
    let mut side = 0i8;
    for _ in 0..100 {
        // Relative to the grid's values too, so that a root at 0 ends as quickly.
        if (b - a).abs() <= 1e-15 * a.abs().max(b.abs()).max(grid_lo.abs().max(grid_hi.abs())) {
            break;
        }
        let c = (a * fb - b * fa) / (fb - fa);
        // A step at an end (or outside, by rounding) is a bisection instead.
        let c = if c > a.min(b) && c < a.max(b) {
            c
        } else {
            0.5 * (a + b)
        };
        let fc = g(c)?;
        if fc == 0.0 {
            return Some((c, [c, c]));
        }
        if (fc < 0.0) == (fb < 0.0) {
            (b, fb) = (c, fc);
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        } else {
            (a, fa) = (c, fc);
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        }
    }
    let root = (a * fb - b * fa) / (fb - fa);
    let root = if root.is_finite() && root >= a.min(b) && root <= a.max(b) {
        root
    } else {
        0.5 * (a + b)
    };
    Some((root, [a.min(b), a.max(b)]))
}

/// The coefficient of `s^z` in `det(sI − A) = ∏(s − λᵢ)` (real for a real `A`), from the
/// eigenvalues `λᵢ`: where a real eigenvalue crosses 0 with `z` others at 0, it changes sign,
/// and unlike the eigenvalues it is a polynomial in the entries of `A` (and well conditioned
/// where they are not: a pair that meets at 0 and leaves as an imaginary pair).
fn characteristic_coefficient(eigenvalues: &[Complex<f64>], z: usize) -> f64 {
    // Coefficients of the monic polynomial, lowest degree first.
    let mut c = vec![Complex::new(1.0, 0.0)];
    for &l in eigenvalues {
        let mut next = vec![Complex::new(0.0, 0.0); c.len() + 1];
        for (k, &ck) in c.iter().enumerate() {
            next[k + 1] += ck;
            next[k] -= ck * l;
        }
        c = next;
    }
    c.get(z).map_or(0.0, |v| v.re)
}

/// Runs the sweep: the eigenvalues at every value of `options.axis`, then every stability
/// change refined by bisection. `progress(done, total)` is called after each value (for a
/// progress bar). The parameter is left at its value before the call.
///
/// # Errors
/// [`ParameterSweepError::UnknownParameter`]; [`ParameterSweepError::EveryPointFailed`] when
/// no value could be analysed (a sweep of failures is not a result).
pub fn parameter_sweep(
    model: &mut dyn ModelInfo,
    options: &ParameterSweepOptions,
    mut progress: impl FnMut(usize, usize),
) -> Result<ParameterSweep, ParameterSweepError> {
    let name = &options.axis.name;
    let d = model.description();
    let Some(index) = d.parameters.iter().position(|p| p.name == *name) else {
        return Err(ParameterSweepError::UnknownParameter {
            model: d.name.to_string(),
            name: name.clone(),
            known: d.parameters.iter().map(|p| p.name.to_string()).collect(),
        });
    };
    let before = model.parameter_values()[index];
    // A family of steady motions picked by a held value (a bicycle's turns as their held
    // lean grows: an entry that holds a coordinate, finds a rate or turns) is followed from
    // value to value: each value's search starts from the motion found at the one before
    // (continuation), and from the entry's guess if that fails. Any other entry starts from
    // its own guess at every value, whose held rates (expressions of the parameter) may
    // lead elsewhere than the last motion found.
    let spec = super::operating_point::steady_motion_spec(model, &options.operating_point.start);
    let follow = spec.turning.is_some()
        || !spec.held_coordinates.is_empty()
        || !spec.solved_rates.is_empty();
    let mut last: Option<Vec<f64>> = None;
    let at = |model: &mut dyn ModelInfo, value: f64, from: Option<&[f64]>| {
        // The name is known, so setting it cannot fail.
        let _ = model.set_parameter(name, value);
        let from = from.filter(|_| follow);
        match eigenvalues_from(model, &options.operating_point, from) {
            Err(_) if from.is_some() => eigenvalues_from(model, &options.operating_point, None),
            found => found,
        }
    };
    let total = options.axis.values.len();
    let mut points = Vec::with_capacity(total);
    // Per point, its eigenvalues (the verdict's and the raw ones).
    let mut raws: Vec<Option<PointEigenvalues>> = Vec::with_capacity(total);
    for (k, &value) in options.axis.values.iter().enumerate() {
        points.push(match at(model, value, last.as_deref()) {
            Ok(found) => {
                if let Some(y) = &found.state {
                    last = Some(y.clone());
                }
                let point = SweepPoint {
                    value,
                    eigenvalues: found.eigenvalues.clone(),
                    stability: Some(found.stability),
                    error: None,
                    found: found.found.clone(),
                };
                raws.push(Some(found));
                point
            }
            Err(SweepPointError::Modal(source @ ModalError::TimeDependent { .. })) => {
                let _ = model.set_parameter(name, before);
                return Err(ParameterSweepError::TimeDependent { value, source });
            }
            Err(reason) => {
                raws.push(None);
                SweepPoint {
                    value,
                    eigenvalues: Vec::new(),
                    stability: None,
                    error: Some(reason.to_string()),
                    found: BTreeMap::new(),
                }
            }
        });
        progress(k + 1, total);
    }
    if let Some(first) = points.first()
        && points.iter().all(|p| p.error.is_some())
    {
        let _ = model.set_parameter(name, before);
        return Err(ParameterSweepError::EveryPointFailed {
            value: first.value,
            reason: first.error.clone().unwrap_or_default(),
        });
    }
    let mut stability_changes = Vec::new();
    if options.refine {
        stability_changes = refine_changes(&points, &raws, &mut |v: f64, from: Option<&[f64]>| {
            at(model, v, from).ok()
        });
    }
    let _ = model.set_parameter(name, before);
    Ok(ParameterSweep {
        model: model.description().name.to_string(),
        parameter: name.clone(),
        operating_point: options
            .operating_point
            .start
            .resolve(model)
            .map(|(label, _)| label)
            .unwrap_or_default(),
        points,
        stability_changes,
    })
}

/// Every stability change of a sweep, in ascending value: between each two neighbouring
/// `points` that both gave eigenvalues (`raws`, one per point) and whose numbers of unstable
/// eigenvalues differ, located by [`locate_change`] with `at(v, from)` the eigenvalues at
/// `v`, a steady motion's search started from the state `from` (the lower neighbour's).
fn refine_changes(
    points: &[SweepPoint],
    raws: &[Option<PointEigenvalues>],
    at: &mut impl FnMut(f64, Option<&[f64]>) -> Option<PointEigenvalues>,
) -> Vec<StabilityChange> {
    let counts: Vec<Option<usize>> = raws
        .iter()
        .map(|seen| seen.as_ref().map(|p| unstable_count(&p.eigenvalues)))
        .collect();
    let mut stability_changes = Vec::new();
    for k in 1..points.len() {
        let (Some(count_a), Some(count_b)) = (counts[k - 1], counts[k]) else {
            continue;
        };
        if count_a == count_b {
            continue;
        }
        let grid = [
            (points[k - 1].value, raws[k - 1].as_ref()),
            (points[k].value, raws[k].as_ref()),
        ];
        let (Some(a), Some(b)) = (grid[0].1, grid[1].1) else {
            continue;
        };
        let from = a.state.clone();
        let change = locate_change(
            &mut |v: f64| at(v, from.as_deref()),
            [(grid[0].0, a), (grid[1].0, b)],
            [count_a, count_b],
        );
        stability_changes.push(change);
    }
    stability_changes
}
