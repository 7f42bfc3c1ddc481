//! Butcher tableaus of explicit Runge–Kutta methods, with the coefficients as exact rationals
//! as printed in their sources (Verner's pairs, in tableau/verner.rs, also as the decimals
//! their source prints).

/// The coefficients of an explicit Runge–Kutta method, with an optional embedded error
/// estimator and dense-output correction.
///
/// ```text
///   c₁ = 0 |
///   c₂     | a₂₁
///   ⋮      | ⋮          ⋱
///   cₛ     | aₛ₁  …  aₛ,ₛ₋₁
///  --------+----------------------
///          | b₁   …  bₛ₋₁   bₛ     order p   (the solution that is propagated)
///          | b̂₁   …  b̂ₛ₋₁   b̂ₛ     order p̂   (the embedded solution, for error estimation)
/// ```
///
/// One step of size `h` from `(t, y)`:
///
/// ```text
/// kᵢ = F(t + cᵢ h, y + h Σⱼ<ᵢ aᵢⱼ kⱼ),   y₁ = y + h Σᵢ bᵢ kᵢ,   err = h Σᵢ (bᵢ − b̂ᵢ) kᵢ
/// ```
///
/// A tableau is *FSAL* (first same as last) when its last row of `a` equals `b` and
/// `cₛ = 1`: the last stage is then `F(t + h, y₁)`, the first stage of the next step.
///
/// Dense output over a step is the cubic Hermite interpolant of `(y, F(t, y))` and
/// `(y₁, F(t + h, y₁))`, plus, when the tableau has one, a quartic correction
/// `θ²(1 − θ)² h Σᵢ dᵢ kᵢ` at `t + θh` (this is how Hairer writes Shampine's continuous
/// extension of the Dormand–Prince pair); or, for Verner's pairs, an interpolant of the
/// pair's order with extra stages of its own (see [`Tableau::vern6`]).
///
/// Every explicit Runge–Kutta method of the crate but DOP853 is one of these rows, stepped by
/// one stepper. DOP853 keeps its own: its error estimate combines two embedded solutions
/// nonlinearly, and its steps are pinned bit for bit against Hairer's code.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tableau {
    name: &'static str,
    order: u32,
    embedded_order: Option<u32>,
    c: &'static [f64],
    a: &'static [&'static [f64]],
    b: &'static [f64],
    b_embedded: Option<&'static [f64]>,
    /// `b − b̂`, written as exact rationals rather than computed, to keep the error estimate
    /// free of cancellation.
    error_weights: Option<&'static [f64]>,
    dense_correction: Option<&'static [f64]>,
    fsal: bool,
    /// How the stage sums are formed.
    sums: StageSums,
    /// The interpolant with extra stages, for a pair that has one (Verner's).
    interpolant: Option<&'static Interpolant>,
}

/// How a stepper forms the stage sums `Σⱼ wⱼ kⱼ` of a tableau.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum StageSums {
    /// As written.
    Plain,
    /// With differences, `Σⱼ wⱼ kⱼ = (Σⱼ wⱼ) k₀ + Σⱼ≥₁ wⱼ (kⱼ − k₀)`, where `Σⱼ aᵢⱼ = cᵢ`,
    /// `Σ bⱼ = 1` and `Σ (bⱼ − b̂ⱼ) = 0` are exact: the coefficients' rounding then multiplies
    /// differences of size `O(h)` rather than the stages. For pairs whose coefficients are
    /// large (Verner 6(5): `aᵢⱼ` up to 207 and `b` of ±73 on two stages at `c = 0.9995` and
    /// 1), where in the plain form the rounding of the row sums alone (the stages' times off
    /// by ~1e-14 h) left a floor of 1.2e-12 on the global error of 6(5) with constant steps
    /// over `[0, 8]` (the test system of `tests/verner.rs`, whatever the step count), and
    /// 5e-14 for 8(7).
    Differences,
}

/// An interpolant of a pair's order over its step, with stages of its own (Verner's): its
/// weights `bᵢ(θ)` at `t + θh` over all the stages, those of the step and the extra ones.
///
/// Stages `0 … s − 1` make a step; `F` at the step's end is stage `s − 1` for an FSAL pair,
/// else stage `s` (the first extra stage, whose row of `a` is `b`, and the next step's first
/// stage). The remaining rows of `a` are the extra stages, evaluated from the step's start.
#[derive(Debug, PartialEq)]
pub(crate) struct Interpolant {
    /// Nodes of all stages, the extra ones included.
    pub(crate) c: &'static [f64],
    /// Row `i`: `aᵢ₀ … aᵢ,ᵢ₋₁`, for all stages.
    pub(crate) a: &'static [&'static [f64]],
    /// Degree of the weights `bᵢ(θ)` in θ.
    pub(crate) degree: usize,
    /// `rᵢₘ` of `bᵢ(θ) = Σₘ rᵢₘ θᵐ` (`m = 1 … degree`), stage-major: `all stages × degree`,
    /// as the source publishes them. The stepper uses `node_weights`, computed from these;
    /// the tests check the order conditions on these and the one against the other.
    #[cfg_attr(not(test), allow(dead_code))]
    pub(crate) r: &'static [f64],
    /// Nodes `θ₁ < … < θ_degree = 1` at which the interpolant is represented.
    pub(crate) nodes: &'static [f64],
    /// `bᵢ(θⱼ)`, node-major: `degree × all stages`.
    pub(crate) node_weights: &'static [f64],
}

impl Interpolant {
    /// Number of stages, the extra ones included.
    pub(crate) fn num_all_stages(&self) -> usize {
        self.c.len()
    }

    /// The weights `bᵢ(θ)` at `θ`, one per stage.
    #[cfg(test)]
    pub(crate) fn weights(&self, theta: f64) -> Vec<f64> {
        self.r
            .chunks_exact(self.degree)
            .map(|r| r.iter().rev().fold(0.0, |acc, &x| acc * theta + x) * theta)
            .collect()
    }
}

/// Explicit Euler, `c`.
static EULER_C: [f64; 1] = [0.0];
/// Explicit Euler, `a`.
static EULER_A: [&[f64]; 1] = [&[]];
/// Explicit Euler, `b`.
static EULER_B: [f64; 1] = [1.0];

/// Explicit midpoint, `c`.
static MIDPOINT_C: [f64; 2] = [0.0, 1.0 / 2.0];
/// Explicit midpoint, `a`.
static MIDPOINT_A: [&[f64]; 2] = [&[], &[1.0 / 2.0]];
/// Explicit midpoint, `b`.
static MIDPOINT_B: [f64; 2] = [0.0, 1.0];

/// Bogacki–Shampine 3(2), `c`.
static BS32_C: [f64; 4] = [0.0, 1.0 / 2.0, 3.0 / 4.0, 1.0];
/// Bogacki–Shampine 3(2), `a` (row `i` holds `aᵢ₁ … aᵢ,ᵢ₋₁`).
static BS32_A: [&[f64]; 4] = [
    &[],
    &[1.0 / 2.0],
    &[0.0, 3.0 / 4.0],
    &[2.0 / 9.0, 1.0 / 3.0, 4.0 / 9.0],
];
/// Bogacki–Shampine 3(2), `b` (third order; equal to the last row of `a`).
static BS32_B: [f64; 4] = [2.0 / 9.0, 1.0 / 3.0, 4.0 / 9.0, 0.0];
/// Bogacki–Shampine 3(2), `b̂` (second order).
static BS32_B_EMBEDDED: [f64; 4] = [7.0 / 24.0, 1.0 / 4.0, 1.0 / 3.0, 1.0 / 8.0];
/// Bogacki–Shampine 3(2), `b − b̂` in lowest terms.
static BS32_ERROR: [f64; 4] = [-5.0 / 72.0, 1.0 / 12.0, 1.0 / 9.0, -1.0 / 8.0];

/// Classical Runge–Kutta, `c`.
static RK4_C: [f64; 4] = [0.0, 1.0 / 2.0, 1.0 / 2.0, 1.0];
/// Classical Runge–Kutta, `a` (row `i` holds `aᵢ₁ … aᵢ,ᵢ₋₁`).
static RK4_A: [&[f64]; 4] = [&[], &[1.0 / 2.0], &[0.0, 1.0 / 2.0], &[0.0, 0.0, 1.0]];
/// Classical Runge–Kutta, `b`.
static RK4_B: [f64; 4] = [1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0];

/// Dormand–Prince 5(4), `c`.
static DOPRI5_C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
/// Dormand–Prince 5(4), `a` (row `i` holds `aᵢ₁ … aᵢ,ᵢ₋₁`).
static DOPRI5_A: [&[f64]; 7] = [
    &[],
    &[1.0 / 5.0],
    &[3.0 / 40.0, 9.0 / 40.0],
    &[44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0],
    &[
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
    ],
    &[
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
    ],
    &[
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
/// Dormand–Prince 5(4), `b` (fifth order; equal to the last row of `a`).
static DOPRI5_B: [f64; 7] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
    0.0,
];
/// Dormand–Prince 5(4), `b̂` (fourth order).
static DOPRI5_B_EMBEDDED: [f64; 7] = [
    5179.0 / 57600.0,
    0.0,
    7571.0 / 16695.0,
    393.0 / 640.0,
    -92097.0 / 339200.0,
    187.0 / 2100.0,
    1.0 / 40.0,
];
/// Dormand–Prince 5(4), `b − b̂` in lowest terms.
static DOPRI5_ERROR: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];
/// Shampine's continuous extension of Dormand–Prince 5(4), as Hairer's `dopri5.f` writes it.
static DOPRI5_DENSE: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

impl Tableau {
    /// The explicit (forward) Euler method: one stage, first order, no error estimate.
    ///
    /// ```text
    ///  0 |
    /// ---+---
    ///    | 1
    /// ```
    ///
    /// # References
    /// L. Euler, *Institutionum calculi integralis* I, §650, 1768; E. Hairer, S. P. Nørsett,
    /// G. Wanner, *Solving Ordinary Differential Equations I*, 2nd ed., Springer, 1993, §I.7,
    /// doi:10.1007/978-3-540-78862-1.
    pub fn euler() -> Self {
        Self {
            name: "euler",
            order: 1,
            embedded_order: None,
            c: &EULER_C,
            a: &EULER_A,
            b: &EULER_B,
            b_embedded: None,
            error_weights: None,
            dense_correction: None,
            fsal: false,
            sums: StageSums::Plain,
            interpolant: None,
        }
    }

    /// The explicit midpoint rule (Runge's second-order method): two stages, no error estimate.
    ///
    /// ```text
    ///  0   |
    ///  1/2 | 1/2
    /// -----+---------
    ///      | 0    1
    /// ```
    ///
    /// # References
    /// C. Runge, "Über die numerische Auflösung von Differentialgleichungen", Math. Ann. 46,
    /// 167–178, 1895, doi:10.1007/BF01446807; Hairer, Nørsett, Wanner I, §II.1.
    pub fn midpoint() -> Self {
        Self {
            name: "midpoint",
            order: 2,
            embedded_order: None,
            c: &MIDPOINT_C,
            a: &MIDPOINT_A,
            b: &MIDPOINT_B,
            b_embedded: None,
            error_weights: None,
            dense_correction: None,
            fsal: false,
            sums: StageSums::Plain,
            interpolant: None,
        }
    }

    /// The Bogacki–Shampine 3(2) pair (MATLAB's `ode23`): four stages (three per step, FSAL),
    /// third-order solution, second-order embedded estimate.
    ///
    /// ```text
    ///  0   |
    ///  1/2 | 1/2
    ///  3/4 | 0     3/4
    ///  1   | 2/9   1/3   4/9
    /// -----+------------------------
    ///   b  | 2/9   1/3   4/9   0
    ///   b̂  | 7/24  1/4   1/3   1/8
    /// ```
    ///
    /// Its dense output is the cubic Hermite interpolant of the step's end values and
    /// derivatives (both are stages of the step, so it costs no evaluation); it is the
    /// third-order continuous extension that Bogacki and Shampine give for the pair.
    ///
    /// # References
    /// P. Bogacki, L. F. Shampine, "A 3(2) pair of Runge–Kutta formulas", Appl. Math. Lett.
    /// 2(4), 321–325, 1989, doi:10.1016/0893-9659(89)90079-7.
    pub fn bs32() -> Self {
        Self {
            name: "bs32",
            order: 3,
            embedded_order: Some(2),
            c: &BS32_C,
            a: &BS32_A,
            b: &BS32_B,
            b_embedded: Some(&BS32_B_EMBEDDED),
            error_weights: Some(&BS32_ERROR),
            dense_correction: None,
            fsal: true,
            sums: StageSums::Plain,
            interpolant: None,
        }
    }

    /// The classical fourth-order Runge–Kutta method ("RK4"): four stages, no error estimate.
    ///
    /// ```text
    ///  0   |
    ///  1/2 | 1/2
    ///  1/2 | 0    1/2
    ///  1   | 0    0    1
    /// -----+--------------------
    ///      | 1/6  1/3  1/3  1/6
    /// ```
    ///
    /// Its dense output is the cubic Hermite interpolant (continuous extension of order 3).
    ///
    /// # References
    /// W. Kutta, "Beitrag zur näherungsweisen Integration totaler Differentialgleichungen",
    /// Zeitschrift für Mathematik und Physik 46, 435–453, 1901. (No DOI.)
    pub fn rk4() -> Self {
        Self {
            name: "rk4",
            order: 4,
            embedded_order: None,
            c: &RK4_C,
            a: &RK4_A,
            b: &RK4_B,
            b_embedded: None,
            error_weights: None,
            dense_correction: None,
            fsal: false,
            sums: StageSums::Plain,
            interpolant: None,
        }
    }

    /// The Dormand–Prince 5(4) pair ("DOPRI5"): seven stages (six per step, FSAL), fifth-order
    /// solution, fourth-order embedded estimate, fourth-order dense output.
    ///
    /// ```text
    ///  0    |
    ///  1/5  | 1/5
    ///  3/10 | 3/40        9/40
    ///  4/5  | 44/45      −56/15       32/9
    ///  8/9  | 19372/6561 −25360/2187  64448/6561  −212/729
    ///  1    | 9017/3168  −355/33      46732/5247  49/176   −5103/18656
    ///  1    | 35/384      0           500/1113    125/192  −2187/6784    11/84
    /// ------+------------------------------------------------------------------------
    ///   b   | 35/384      0           500/1113    125/192  −2187/6784    11/84     0
    ///   b̂   | 5179/57600  0           7571/16695  393/640  −92097/339200 187/2100  1/40
    /// ```
    ///
    /// The dense-output correction (see [`Tableau`]) has
    /// `d = (−12715105075/11282082432, 0, 87487479700/32700410799,
    /// −10690763975/1880347072, 701980252875/199316789632, −1453857185/822651844,
    /// 69997945/29380423)`.
    ///
    /// # References
    /// - J. R. Dormand, P. J. Prince, "A family of embedded Runge–Kutta formulae",
    ///   J. Comput. Appl. Math. 6(1), 19–26, 1980, doi:10.1016/0771-050X(80)90013-3.
    /// - L. F. Shampine, "Some practical Runge–Kutta formulas", Math. Comp. 46(173), 135–150,
    ///   1986, doi:10.1090/S0025-5718-1986-0815836-3 (the continuous extension).
    /// - E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations I*,
    ///   2nd ed., Springer, 1993, §II.5–II.6, doi:10.1007/978-3-540-78862-1.
    pub fn dopri5() -> Self {
        Self {
            name: "dp54",
            order: 5,
            embedded_order: Some(4),
            c: &DOPRI5_C,
            a: &DOPRI5_A,
            b: &DOPRI5_B,
            b_embedded: Some(&DOPRI5_B_EMBEDDED),
            error_weights: Some(&DOPRI5_ERROR),
            dense_correction: Some(&DOPRI5_DENSE),
            fsal: true,
            sums: StageSums::Plain,
            interpolant: None,
        }
    }

    /// Short name of the method (`"euler"`, `"midpoint"`, `"rk4"`, `"bs32"`, `"dp54"`,
    /// `"vern6"` … `"vern9"`), as a front end selects it.
    pub fn name(&self) -> &'static str {
        self.name
    }

    /// Order `p` of the propagated solution.
    pub fn order(&self) -> u32 {
        self.order
    }

    /// Order `p̂` of the embedded solution, or `None` without an error estimator.
    pub fn embedded_order(&self) -> Option<u32> {
        self.embedded_order
    }

    /// Number of stages `s`.
    pub fn num_stages(&self) -> usize {
        self.c.len()
    }

    /// The nodes `c`, `s` entries.
    pub fn c(&self) -> &'static [f64] {
        self.c
    }

    /// Row `i` of `a` below the diagonal: `aᵢ₁ … aᵢ,ᵢ₋₁` (`i` entries, 0-based `i < s`).
    ///
    /// # Panics
    /// If `i >= num_stages()`.
    pub fn a(&self, i: usize) -> &'static [f64] {
        self.a[i]
    }

    /// The weights `b` of the propagated solution, `s` entries.
    pub fn b(&self) -> &'static [f64] {
        self.b
    }

    /// The weights `b̂` of the embedded solution, `s` entries, if the tableau gives them:
    /// `None` without an embedded solution, and for Verner's pairs, which give `b − b̂` alone
    /// (their [`embedded_order`](Self::embedded_order) is `Some`).
    pub fn b_embedded(&self) -> Option<&'static [f64]> {
        self.b_embedded
    }

    /// Whether the last stage of a step is the first stage of the next (first same as last).
    pub fn is_fsal(&self) -> bool {
        self.fsal
    }

    /// The error weights `b − b̂`, `s` entries, if the tableau has an embedded solution.
    pub(crate) fn error_weights(&self) -> Option<&'static [f64]> {
        self.error_weights
    }

    /// The weights `d` of the quartic dense-output correction, `s` entries, if any.
    pub(crate) fn dense_correction(&self) -> Option<&'static [f64]> {
        self.dense_correction
    }

    /// How the stage sums are formed.
    pub(crate) fn sums(&self) -> StageSums {
        self.sums
    }

    /// The interpolant with extra stages, if the pair has one.
    pub(crate) fn interpolant(&self) -> Option<&'static Interpolant> {
        self.interpolant
    }

    /// The stage that is `F` at the step's end, for a pair with an interpolant: `s − 1` for
    /// an FSAL pair, else `s` (the interpolant's first extra stage).
    pub(crate) fn end_stage(&self) -> usize {
        if self.fsal {
            self.num_stages() - 1
        } else {
            self.num_stages()
        }
    }
}

mod verner;

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// `A c`, for the lower-triangular `a` of `tableau` and a vector `v`.
    pub(crate) fn a_times(tableau: &Tableau, v: &[f64]) -> Vec<f64> {
        (0..tableau.num_stages())
            .map(|i| tableau.a(i).iter().zip(v).map(|(a, v)| a * v).sum())
            .collect()
    }

    fn dot(u: &[f64], v: &[f64]) -> f64 {
        u.iter().zip(v).map(|(u, v)| u * v).sum()
    }

    fn times(u: &[f64], v: &[f64]) -> Vec<f64> {
        u.iter().zip(v).map(|(u, v)| u * v).collect()
    }

    /// The order conditions `Σ bᵢ Φᵢ(τ) = 1/γ(τ)` for every rooted tree `τ` with at most
    /// `order` vertices (1 + 1 + 2 + 4 + 9 trees up to order 5), as `(weight, 1/γ)` pairs.
    pub(crate) fn order_conditions(tableau: &Tableau, b: &[f64], order: u32) -> Vec<(f64, f64)> {
        let c = tableau.c().to_vec();
        let ones = vec![1.0; c.len()];
        let c2 = times(&c, &c);
        let c3 = times(&c2, &c);
        let ac = a_times(tableau, &c);
        let ac2 = a_times(tableau, &c2);
        let aac = a_times(tableau, &ac);
        let mut conditions = vec![(dot(b, &ones), 1.0)];
        if order >= 2 {
            conditions.push((dot(b, &c), 1.0 / 2.0));
        }
        if order >= 3 {
            conditions.push((dot(b, &c2), 1.0 / 3.0));
            conditions.push((dot(b, &ac), 1.0 / 6.0));
        }
        if order >= 4 {
            conditions.push((dot(b, &c3), 1.0 / 4.0));
            conditions.push((dot(b, &times(&c, &ac)), 1.0 / 8.0));
            conditions.push((dot(b, &ac2), 1.0 / 12.0));
            conditions.push((dot(b, &aac), 1.0 / 24.0));
        }
        if order >= 5 {
            conditions.push((dot(b, &times(&c3, &c)), 1.0 / 5.0));
            conditions.push((dot(b, &times(&c2, &ac)), 1.0 / 10.0));
            conditions.push((dot(b, &times(&ac, &ac)), 1.0 / 20.0));
            conditions.push((dot(b, &times(&c, &ac2)), 1.0 / 15.0));
            conditions.push((dot(b, &times(&c, &aac)), 1.0 / 30.0));
            conditions.push((dot(b, &a_times(tableau, &c3)), 1.0 / 20.0));
            conditions.push((dot(b, &a_times(tableau, &times(&c, &ac))), 1.0 / 40.0));
            conditions.push((dot(b, &a_times(tableau, &ac2)), 1.0 / 60.0));
            conditions.push((dot(b, &a_times(tableau, &aac)), 1.0 / 120.0));
        }
        conditions
    }

    /// A rooted tree (Butcher's trees, which index the order conditions of Runge–Kutta
    /// methods): its subtrees as indices into the list it belongs to, its order `|τ|` (number
    /// of vertices) and its density `γ(τ) = |τ| Π γ(subtrees)`.
    pub(crate) struct RootedTree {
        pub(crate) children: Vec<usize>,
        pub(crate) order: u32,
        pub(crate) density: f64,
    }

    /// Every rooted tree with at most `max_order` vertices, each once, by increasing order:
    /// a tree of order `n` is a root with a multiset of trees whose orders sum to `n − 1`
    /// (generated as non-decreasing index sequences, so no multiset appears twice).
    /// There are 1, 1, 2, 4, 9, 20, 48, 115 trees of orders 1 … 8 (OEIS A000081).
    pub(crate) fn rooted_trees(max_order: u32) -> Vec<RootedTree> {
        fn children_sets(
            trees: &[RootedTree],
            available: usize,
            remaining: u32,
            first: usize,
            current: &mut Vec<usize>,
            out: &mut Vec<Vec<usize>>,
        ) {
            if remaining == 0 {
                out.push(current.clone());
                return;
            }
            for index in first..available {
                if trees[index].order <= remaining {
                    current.push(index);
                    let rest = remaining - trees[index].order;
                    children_sets(trees, available, rest, index, current, out);
                    current.pop();
                }
            }
        }
        let mut trees: Vec<RootedTree> = Vec::new();
        for order in 1..=max_order {
            let available = trees.len();
            let mut sets = Vec::new();
            children_sets(&trees, available, order - 1, 0, &mut Vec::new(), &mut sets);
            for children in sets {
                let density =
                    f64::from(order) * children.iter().map(|&c| trees[c].density).product::<f64>();
                trees.push(RootedTree {
                    children,
                    order,
                    density,
                });
            }
        }
        trees
    }

    /// The order conditions of the method `(A, b)` (any `A`, explicit or implicit, given as
    /// full rows) for every tree up to `max_order`, as residuals
    /// `Σᵢ bᵢ Φᵢ(τ) − θ^|τ|/γ(τ)` paired with `|τ|`, where
    /// `Φᵢ(τ) = Πₖ (A Φ(τₖ))ᵢ` over the subtrees `τₖ` (Butcher; Hairer–Nørsett–Wanner I,
    /// §II.2, Theorem 2.13). With `θ = 1` they are the conditions for order `max_order`;
    /// with `b = b(θ)` the weights of a continuous extension at `θ`, those for its order.
    pub(crate) fn tree_residuals(
        a: &[Vec<f64>],
        b: &[f64],
        max_order: u32,
        theta: f64,
    ) -> Vec<(u32, f64)> {
        let s = b.len();
        let trees = rooted_trees(max_order);
        let mut phi: Vec<Vec<f64>> = Vec::with_capacity(trees.len());
        // A Φ(τ) for each tree, reused by its parents.
        let mut a_phi: Vec<Vec<f64>> = Vec::with_capacity(trees.len());
        let mut residuals = Vec::with_capacity(trees.len());
        for tree in &trees {
            let mut p = vec![1.0; s];
            for &child in &tree.children {
                for (pi, api) in p.iter_mut().zip(&a_phi[child]) {
                    *pi *= api;
                }
            }
            let ap: Vec<f64> = (0..s)
                .map(|i| (0..s).map(|j| a[i][j] * p[j]).sum())
                .collect();
            let weight: f64 = b.iter().zip(&p).map(|(b, p)| b * p).sum();
            residuals.push((
                tree.order,
                weight - theta.powi(tree.order as i32) / tree.density,
            ));
            phi.push(p);
            a_phi.push(ap);
        }
        residuals
    }

    /// The full `s × s` matrix `A` of an explicit tableau.
    pub(crate) fn full_a(tableau: &Tableau) -> Vec<Vec<f64>> {
        let s = tableau.num_stages();
        (0..s)
            .map(|i| {
                let mut row = vec![0.0; s];
                row[..i].copy_from_slice(tableau.a(i));
                row
            })
            .collect()
    }

    /// Asserts that `b` satisfies every condition up to `order` to `tolerance`, and (for
    /// `strict`) that some condition of order `order + 1` fails.
    pub(crate) fn assert_tree_order(
        label: &str,
        a: &[Vec<f64>],
        b: &[f64],
        order: u32,
        tolerance: f64,
        strict: bool,
    ) {
        for (k, (o, residual)) in tree_residuals(a, b, order, 1.0).into_iter().enumerate() {
            assert!(
                residual.abs() < tolerance,
                "{label}: tree {k} of order {o}: residual {residual:e}"
            );
        }
        if strict {
            let fails = tree_residuals(a, b, order + 1, 1.0)
                .into_iter()
                .any(|(o, residual)| o == order + 1 && residual.abs() > 1e-6);
            assert!(fails, "{label}: has order {} too", order + 1);
        }
    }

    #[test]
    fn tree_counts_are_those_of_oeis_a000081() {
        let trees = rooted_trees(8);
        let counts: Vec<usize> = (1..=8)
            .map(|o| trees.iter().filter(|t| t.order == o).count())
            .collect();
        assert_eq!(counts, vec![1, 1, 2, 4, 9, 20, 48, 115]);
        // The bushy tree of order 4 (root with three leaves) has density 4; the tall one 24.
        let densities: Vec<f64> = trees
            .iter()
            .filter(|t| t.order == 4)
            .map(|t| t.density)
            .collect();
        assert!(densities.contains(&4.0) && densities.contains(&24.0));
    }

    /// The tree conditions agree with the hand-written ones up to order 5.
    #[test]
    fn tree_conditions_agree_with_the_explicit_list() {
        let tableau = Tableau::dopri5();
        let residuals = tree_residuals(&full_a(&tableau), tableau.b(), 5, 1.0);
        let explicit = order_conditions(&tableau, tableau.b(), 5);
        assert_eq!(residuals.len(), explicit.len());
        let mut from_trees: Vec<f64> = residuals.iter().map(|(_, r)| *r).collect();
        let mut listed: Vec<f64> = explicit.iter().map(|(w, e)| w - e).collect();
        from_trees.sort_by(f64::total_cmp);
        listed.sort_by(f64::total_cmp);
        for (x, y) in from_trees.iter().zip(&listed) {
            assert!((x - y).abs() < 1e-15);
        }
    }

    /// Every explicit tableau: row sums `Σⱼ aᵢⱼ = cᵢ`, the shape rules, and the order
    /// conditions of its propagated and embedded weights (exactly its order, not one more).
    #[test]
    fn every_tableau_has_its_orders() {
        for tableau in [
            Tableau::euler(),
            Tableau::midpoint(),
            Tableau::rk4(),
            Tableau::bs32(),
            Tableau::dopri5(),
        ] {
            check_shape(&tableau);
            let a = full_a(&tableau);
            assert_tree_order(
                tableau.name(),
                &a,
                tableau.b(),
                tableau.order(),
                1e-14,
                true,
            );
            match (tableau.b_embedded(), tableau.embedded_order()) {
                (Some(b_hat), Some(order)) => {
                    let label = format!("{} embedded", tableau.name());
                    assert_tree_order(&label, &a, b_hat, order, 1e-14, true);
                    for ((e, b), b_hat) in tableau
                        .error_weights()
                        .unwrap()
                        .iter()
                        .zip(tableau.b())
                        .zip(b_hat)
                    {
                        assert!((e - (b - b_hat)).abs() < 1e-16, "{}", tableau.name());
                    }
                }
                (None, None) => {}
                _ => panic!("{}: embedded weights and order go together", tableau.name()),
            }
        }
    }

    /// Every row's embedded solution is described consistently: an embedded order with error
    /// weights `b − b̂` of `s` entries, and `b̂` itself, when given, equal to `b` less them;
    /// neither without an estimator. (Verner's orders are checked in `verner`'s tests.)
    #[test]
    fn every_row_describes_its_embedded_solution_consistently() {
        let rows = crate::integrate::stability_function::explicit_tableau_methods();
        assert_eq!(rows.len(), 9);
        for (tableau, _) in rows {
            let name = tableau.name();
            match (tableau.embedded_order(), tableau.error_weights()) {
                (Some(p), Some(e)) => {
                    assert_eq!(p + 1, tableau.order(), "{name}");
                    assert_eq!(e.len(), tableau.num_stages(), "{name}");
                    if let Some(b_hat) = tableau.b_embedded() {
                        for ((e, b), b_hat) in e.iter().zip(tableau.b()).zip(b_hat) {
                            assert!((e - (b - b_hat)).abs() < 1e-16, "{name}");
                        }
                    }
                }
                (None, None) => assert!(tableau.b_embedded().is_none(), "{name}"),
                _ => panic!("{name}: embedded order and error weights go together"),
            }
            assert_eq!(tableau.b().len(), tableau.num_stages(), "{name}");
            assert_eq!(
                tableau.interpolant().is_some(),
                name.starts_with("vern"),
                "{name}"
            );
        }
    }

    fn assert_order(tableau: &Tableau, b: &[f64], order: u32) {
        for (k, (weight, expected)) in order_conditions(tableau, b, order).into_iter().enumerate() {
            assert!(
                (weight - expected).abs() < 1e-14,
                "{}: condition {k}: {weight} != {expected}",
                tableau.name()
            );
        }
    }

    fn check_shape(tableau: &Tableau) {
        let s = tableau.num_stages();
        assert_eq!(tableau.b().len(), s);
        assert_eq!(tableau.c()[0], 0.0);
        for i in 0..s {
            let row = tableau.a(i);
            assert_eq!(row.len(), i, "{}: row {i}", tableau.name());
            // Row sums equal the nodes (the stages are consistent in t).
            let sum: f64 = row.iter().sum();
            assert!((sum - tableau.c()[i]).abs() < 1e-14, "row {i}: {sum}");
        }
        if tableau.is_fsal() {
            assert_eq!(tableau.a(s - 1), &tableau.b()[..s - 1]);
            assert_eq!(tableau.b()[s - 1], 0.0);
            assert_eq!(tableau.c()[s - 1], 1.0);
        }
    }

    #[test]
    fn rk4_has_order_4() {
        let tableau = Tableau::rk4();
        check_shape(&tableau);
        assert_order(&tableau, tableau.b(), tableau.order());
        // …and not 5: at least one fifth-order condition fails.
        assert!(
            order_conditions(&tableau, tableau.b(), 5)
                .iter()
                .any(|(w, e)| (w - e).abs() > 1e-6)
        );
    }

    #[test]
    fn dopri5_has_orders_5_and_4() {
        let tableau = Tableau::dopri5();
        check_shape(&tableau);
        assert_order(&tableau, tableau.b(), 5);
        let embedded = tableau.b_embedded().unwrap();
        assert_order(&tableau, embedded, 4);
        assert!(
            order_conditions(&tableau, embedded, 5)
                .iter()
                .any(|(w, e)| (w - e).abs() > 1e-6)
        );
        // The error weights written out are b − b̂.
        for ((e, b), b_hat) in tableau
            .error_weights()
            .unwrap()
            .iter()
            .zip(tableau.b())
            .zip(embedded)
        {
            assert!((e - (b - b_hat)).abs() < 1e-16);
        }
    }
}
