//! Hairer's DOP853: the explicit Runge–Kutta method of order 8 by Dormand and Prince, with
//! embedded error estimators of orders 5 and 3 and a dense output of order 7.
// The coefficients are transcribed with every digit their source prints, so that they can
// be checked against it; the compiler rounds them to f64.
#![allow(clippy::excessive_precision)]

use std::mem::swap;

use crate::ode::OdeSystem;

use super::Integrator;
use super::controller::PiController;
use super::dense_output::{DenseOutput, hermite};
use super::driver::{self, Control, Problem};
use super::error::IntegrationFailure;
use super::explicit_rk::{combine_any, error_ratio, sum_fixed, weighted_sum_any, write_update};
use super::options::ErrorWeights;
use super::solution::Solution;
use super::stepper::{AttemptTimes, CheckedRhs, StepEnds, StepFailure, Stepper, first_non_finite};

/// Number of stages of a step (the twelfth at `c = 1`; `F` at the new state is a thirteenth,
/// shared with the next step).
const STAGES: usize = 12;
/// Stages including the three extra ones of the dense output.
const EXTENDED_STAGES: usize = 16;
/// The order the step-size selection uses: the combined estimate behaves as `O(h⁸)`
/// (DOP853's `IORD = 8`, so the exponent is `1/8`).
const ERROR_ORDER: u32 = 7;

// The coefficients of DOP853 exactly as Hairer's `dop853.f` prints them (30 significant
// digits; the nodes c₂ … c₅ and the coefficients that depend on them involve √6, so they are
// not rationals). 0-based stage indices: stage 12 is `F(t + h, y₁)`, stages 13–15 are the
// extra stages of the dense output (Fortran's stages 14–16).

/// Nodes `cᵢ` of all sixteen stages.
static C: [f64; EXTENDED_STAGES] = [
    0.0,
    0.526001519587677318785587544488e-01,
    0.789002279381515978178381316732e-01,
    0.118350341907227396726757197510e+00,
    0.281649658092772603273242802490e+00,
    0.333333333333333333333333333333e+00,
    0.25e+00,
    0.307692307692307692307692307692e+00,
    0.651282051282051282051282051282e+00,
    0.6e+00,
    0.857142857142857142857142857142e+00,
    1.0,
    1.0,
    0.1e+00,
    0.2e+00,
    0.777777777777777777777777777778e+00,
];

/// `aᵢⱼ` for `j < i`, row `i` of the extended tableau (row 12 is `b`).
static A: [&[f64]; EXTENDED_STAGES] = [
    &[],
    &[5.26001519587677318785587544488e-2],
    &[
        1.97250569845378994544595329183e-2,
        5.91751709536136983633785987549e-2,
    ],
    &[
        2.95875854768068491816892993775e-2,
        0.0,
        8.87627564304205475450678981324e-2,
    ],
    &[
        2.41365134159266685502369798665e-1,
        0.0,
        -8.84549479328286085344864962717e-1,
        9.24834003261792003115737966543e-1,
    ],
    &[
        3.7037037037037037037037037037e-2,
        0.0,
        0.0,
        1.70828608729473871279604482173e-1,
        1.25467687566822425016691814123e-1,
    ],
    &[
        3.7109375e-2,
        0.0,
        0.0,
        1.70252211019544039314978060272e-1,
        6.02165389804559606850219397283e-2,
        -1.7578125e-2,
    ],
    &[
        3.70920001185047927108779319836e-2,
        0.0,
        0.0,
        1.70383925712239993810214054705e-1,
        1.07262030446373284651809199168e-1,
        -1.53194377486244017527936158236e-2,
        8.27378916381402288758473766002e-3,
    ],
    &[
        6.24110958716075717114429577812e-1,
        0.0,
        0.0,
        -3.36089262944694129406857109825e0,
        -8.68219346841726006818189891453e-1,
        2.75920996994467083049415600797e1,
        2.01540675504778934086186788979e1,
        -4.34898841810699588477366255144e1,
    ],
    &[
        4.77662536438264365890433908527e-1,
        0.0,
        0.0,
        -2.48811461997166764192642586468e0,
        -5.90290826836842996371446475743e-1,
        2.12300514481811942347288949897e1,
        1.52792336328824235832596922938e1,
        -3.32882109689848629194453265587e1,
        -2.03312017085086261358222928593e-2,
    ],
    &[
        -9.3714243008598732571704021658e-1,
        0.0,
        0.0,
        5.18637242884406370830023853209e0,
        1.09143734899672957818500254654e0,
        -8.14978701074692612513997267357e0,
        -1.85200656599969598641566180701e1,
        2.27394870993505042818970056734e1,
        2.49360555267965238987089396762e0,
        -3.0467644718982195003823669022e0,
    ],
    &[
        2.27331014751653820792359768449e0,
        0.0,
        0.0,
        -1.05344954667372501984066689879e1,
        -2.00087205822486249909675718444e0,
        -1.79589318631187989172765950534e1,
        2.79488845294199600508499808837e1,
        -2.85899827713502369474065508674e0,
        -8.87285693353062954433549289258e0,
        1.23605671757943030647266201528e1,
        6.43392746015763530355970484046e-1,
    ],
    &B,
    &[
        5.61675022830479523392909219681e-2,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        2.53500210216624811088794765333e-1,
        -2.46239037470802489917441475441e-1,
        -1.24191423263816360469010140626e-1,
        1.5329179827876569731206322685e-1,
        8.20105229563468988491666602057e-3,
        7.56789766054569976138603589584e-3,
        -8.298e-3,
    ],
    &[
        3.18346481635021405060768473261e-2,
        0.0,
        0.0,
        0.0,
        0.0,
        2.83009096723667755288322961402e-2,
        5.35419883074385676223797384372e-2,
        -5.49237485713909884646569340306e-2,
        0.0,
        0.0,
        -1.08347328697249322858509316994e-4,
        3.82571090835658412954920192323e-4,
        -3.40465008687404560802977114492e-4,
        1.41312443674632500278074618366e-1,
    ],
    &[
        -4.28896301583791923408573538692e-1,
        0.0,
        0.0,
        0.0,
        0.0,
        -4.69762141536116384314449447206e0,
        7.68342119606259904184240953878e0,
        4.06898981839711007970213554331e0,
        3.56727187455281109270669543021e-1,
        0.0,
        0.0,
        0.0,
        -1.39902416515901462129418009734e-3,
        2.9475147891527723389556272149e0,
        -9.15095847217987001081870187138e0,
    ],
];

/// Weights `bᵢ` of the eighth-order solution (`dop853.f`'s `B1`, `B6` … `B12`).
static B: [f64; STAGES] = [
    5.42937341165687622380535766363e-2,
    0.0,
    0.0,
    0.0,
    0.0,
    4.45031289275240888144113950566e0,
    1.89151789931450038304281599044e0,
    -5.8012039600105847814672114227e0,
    3.1116436695781989440891606237e-1,
    -1.52160949662516078556178806805e-1,
    2.01365400804030348374776537501e-1,
    4.47106157277725905176885569043e-2,
];

/// Stages 1–4 (rows 0–3 of the stepper's `k`) have no weight in `b`, nor in either error
/// estimate: of a step's stages, only these are checked for finiteness on their own when the
/// error is estimated (a non-finite value elsewhere shows in the candidate).
const UNWEIGHTED_ROWS: usize = 4;

/// Weights of the third-order embedded solution, on stages 0, 8 and 11 (`BHH1` … `BHH3`).
static B_THIRD: [(usize, f64); 3] = [
    (0, 0.244094488188976377952755905512e+00),
    (8, 0.733846688281611857341361741547e+00),
    (11, 0.220588235294117647058823529412e-01),
];

/// `b − b̂⁽⁵⁾`, the error weights of the fifth-order embedded solution (`ER1`, `ER6` … `ER12`).
static ERROR_FIFTH: [f64; STAGES] = [
    0.1312004499419488073250102996e-01,
    0.0,
    0.0,
    0.0,
    0.0,
    -0.1225156446376204440720569753e+01,
    -0.4957589496572501915214079952e+00,
    0.1664377182454986536961530415e+01,
    -0.3503288487499736816886487290e+00,
    0.3341791187130174790297318841e+00,
    0.8192320648511571246570742613e-01,
    -0.2235530786388629525884427845e-01,
];

/// The dense-output coefficients `d₄ … d₇` over the sixteen stages (`D41` … `D716`).
static DENSE: [[f64; EXTENDED_STAGES]; 4] = [
    [
        -0.84289382761090128651353491142e+01,
        0.0,
        0.0,
        0.0,
        0.0,
        0.56671495351937776962531783590e+00,
        -0.30689499459498916912797304727e+01,
        0.23846676565120698287728149680e+01,
        0.21170345824450282767155149946e+01,
        -0.87139158377797299206789907490e+00,
        0.22404374302607882758541771650e+01,
        0.63157877876946881815570249290e+00,
        -0.88990336451333310820698117400e-01,
        0.18148505520854727256656404962e+02,
        -0.91946323924783554000451984436e+01,
        -0.44360363875948939664310572000e+01,
    ],
    [
        0.10427508642579134603413151009e+02,
        0.0,
        0.0,
        0.0,
        0.0,
        0.24228349177525818288430175319e+03,
        0.16520045171727028198505394887e+03,
        -0.37454675472269020279518312152e+03,
        -0.22113666853125306036270938578e+02,
        0.77334326684722638389603898808e+01,
        -0.30674084731089398182061213626e+02,
        -0.93321305264302278729567221706e+01,
        0.15697238121770843886131091075e+02,
        -0.31139403219565177677282850411e+02,
        -0.93529243588444783865713862664e+01,
        0.35816841486394083752465898540e+02,
    ],
    [
        0.19985053242002433820987653617e+02,
        0.0,
        0.0,
        0.0,
        0.0,
        -0.38703730874935176555105901742e+03,
        -0.18917813819516756882830838328e+03,
        0.52780815920542364900561016686e+03,
        -0.11573902539959630126141871134e+02,
        0.68812326946963000169666922661e+01,
        -0.10006050966910838403183860980e+01,
        0.77771377980534432092869265740e+00,
        -0.27782057523535084065932004339e+01,
        -0.60196695231264120758267380846e+02,
        0.84320405506677161018159903784e+02,
        0.11992291136182789328035130030e+02,
    ],
    [
        -0.25693933462703749003312586129e+02,
        0.0,
        0.0,
        0.0,
        0.0,
        -0.15418974869023643374053993627e+03,
        -0.23152937917604549567536039109e+03,
        0.35763911791061412378285349910e+03,
        0.93405324183624310003907691704e+02,
        -0.37458323136451633156875139351e+02,
        0.10409964950896230045147246184e+03,
        0.29840293426660503123344363579e+02,
        -0.43533456590011143754432175058e+02,
        0.96324553959188282948394950600e+02,
        -0.39177261675615439165231486172e+02,
        -0.14972683625798562581422125276e+03,
    ],
];

/// `out = Σⱼ wⱼ stage(j)` over the `j` with a non-zero weight, summed from 0 in the order of
/// `j`: the dense-output stages, which are not contiguous (the step's own stages go through
/// the explicit Runge–Kutta stage sum). `weights` has at most [`EXTENDED_STAGES`] entries.
///
/// Summed four components at a time, the sums in registers: summed stage by stage into
/// `out`, every addition waited for the store of the previous one (sixteen stages, four rows
/// and three extra stages per step with an output time), and summed one component at a time,
/// for the previous addition of the same component. The additions of each component are the
/// same, in the same order, so the values are too.
fn weighted_sum<'a>(out: &mut [f64], weights: &[f64], stage: impl Fn(usize) -> &'a [f64]) {
    let n = out.len();
    // The stages with a weight, in order, each looked up once.
    let mut terms: [(f64, &[f64]); EXTENDED_STAGES] = [(0.0, &[]); EXTENDED_STAGES];
    let mut count = 0;
    for (j, &w) in weights.iter().enumerate() {
        if w != 0.0 {
            terms[count] = (w, &stage(j)[..n]);
            count += 1;
        }
    }
    let terms = &terms[..count];
    // Four components at a time: four independent sums in registers, so that one's
    // additions need not wait for another's.
    let mut blocks = out.chunks_exact_mut(4);
    for (b, block) in (&mut blocks).enumerate() {
        let mut acc = [0.0f64; 4];
        for &(w, row) in terms {
            let row = &row[4 * b..4 * b + 4];
            for (a, &x) in acc.iter_mut().zip(row) {
                *a += w * x;
            }
        }
        block.copy_from_slice(&acc);
    }
    let start = n - blocks.into_remainder().len();
    for i in start..n {
        let mut acc = 0.0;
        for &(w, row) in terms {
            acc += w * row[i];
        }
        out[i] = acc;
    }
}

/// The DOP853 stepper, with all buffers allocated once.
///
/// During a step, stage 0 is `F(t, y)` (`f`), stages 1–11 are rows 0–10 of `k`. After an
/// accepted step, stage 0 of that step is `f_prev`, stage 12 (`F` at its end) is `f`, and the
/// dense-output stages 13–15, evaluated on demand, are rows 11–13 of `k`.
#[derive(Debug, Clone)]
pub(crate) struct Dop853Stepper {
    dim: usize,
    /// Ends of the last accepted step and the candidate's time.
    ends: StepEnds,
    y_new: Vec<f64>,
    /// Stage input, then error terms.
    scratch: Vec<f64>,
    /// `Σ bᵢ kᵢ` of the last attempt.
    increment: Vec<f64>,
    /// Stages 1–11 and 13–15, row-major: `14 × dim`.
    k: Vec<f64>,
    /// `h Σ dᵣⱼ kⱼ` for `r = 4 … 7`, row-major `4 × dim`, once prepared.
    dense: Vec<f64>,
    dense_ready: bool,
}

impl Dop853Stepper {
    /// A stepper for a system of dimension `dim`.
    pub(crate) fn new(dim: usize) -> Self {
        Self {
            dim,
            ends: StepEnds::new(dim),
            y_new: vec![0.0; dim],
            scratch: vec![0.0; dim],
            increment: vec![0.0; dim],
            k: vec![0.0; (EXTENDED_STAGES - 2) * dim],
            dense: vec![0.0; 4 * dim],
            dense_ready: false,
        }
    }
}

/// Row of `k` holding stage `j` (stages 0 and 12 live elsewhere).
#[inline]
fn k_row(j: usize) -> usize {
    debug_assert!(j != 0 && j != STAGES);
    if j < STAGES { j - 1 } else { j - 2 }
}

impl DenseOutput for Dop853Stepper {
    fn interval(&self) -> (f64, f64) {
        self.ends.interval()
    }

    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let h = self.ends.t - self.ends.t_prev;
        if h == 0.0 {
            out.copy_from_slice(&self.ends.y);
            return;
        }
        debug_assert!(self.dense_ready, "prepare_dense_output before interpolate");
        let n = self.dim;
        let theta = (t - self.ends.t_prev) / h;
        let theta1 = 1.0 - theta;
        let d = |r: usize, i: usize| self.dense[r * n + i];
        for (i, o) in out.iter_mut().enumerate() {
            // dop853.f's CONTD8: the Hermite part, then the septic correction
            // D = d₄ + θ(d₅ + (1 − θ)(d₆ + θ d₇)).
            let correction = d(0, i) + theta * (d(1, i) + theta1 * (d(2, i) + theta * d(3, i)));
            *o = hermite(
                theta,
                self.ends.y_prev[i],
                self.ends.y[i],
                h * self.ends.f_prev[i],
                h * self.ends.f[i],
                correction,
            );
        }
    }
}

impl Dop853Stepper {
    /// Stage `I` (1 … 11) for `D` components: its input `y + h Σⱼ aᵢⱼ kⱼ` into `scratch`,
    /// then `F` there into row `I − 1` of `k`, unchecked (see [`CheckedRhs::eval_stage`]).
    #[inline(always)]
    fn stage_fixed<const I: usize, const D: usize>(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        times: AttemptTimes,
    ) -> Result<(), StepFailure> {
        let d = if D == 0 { self.dim } else { D };
        let (earlier, rest) = self.k.split_at_mut((I - 1) * d);
        if D == 0 {
            combine_any(
                &mut self.scratch,
                &self.ends.y,
                times.h,
                A[I],
                &self.ends.f,
                earlier,
                d,
            );
        } else {
            let sum = sum_fixed::<D>(A[I], &self.ends.f, earlier);
            write_update::<D>(&mut self.scratch, &self.ends.y, times.h, &sum);
        }
        match rhs.eval_stage(times.at(C[I]), &self.scratch[..d], &mut rest[..d]) {
            Ok(()) => Ok(()),
            Err(failure) => Err(CheckedRhs::stage_failure(
                earlier,
                d,
                |r| row_time(times, r),
                failure,
            )),
        }
    }

    /// Stages 1 … 11, then `increment = Σ bᵢ kᵢ` and `y_new = y + h · increment`, for `D`
    /// components, unrolled: with the stage index and the dimension known to the compiler,
    /// each stage input is a fixed sequence of multiply–adds with the non-zero coefficients
    /// of [`A`] as constants, in registers, instead of a loop over the row that tests every
    /// coefficient. On the double pendulum this executes ~85 fewer instructions per
    /// evaluation of `F` (callgrind) and made a run ~8 % faster. `D = 0` is any dimension
    /// (`self.dim`), in blocks of four components with the coefficients still constants
    /// ([`combine_any`]).
    fn stages_fixed<const D: usize>(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        times: AttemptTimes,
    ) -> Result<(), StepFailure> {
        self.stage_fixed::<1, D>(rhs, times)?;
        self.stage_fixed::<2, D>(rhs, times)?;
        self.stage_fixed::<3, D>(rhs, times)?;
        self.stage_fixed::<4, D>(rhs, times)?;
        self.stage_fixed::<5, D>(rhs, times)?;
        self.stage_fixed::<6, D>(rhs, times)?;
        self.stage_fixed::<7, D>(rhs, times)?;
        self.stage_fixed::<8, D>(rhs, times)?;
        self.stage_fixed::<9, D>(rhs, times)?;
        self.stage_fixed::<10, D>(rhs, times)?;
        self.stage_fixed::<11, D>(rhs, times)?;
        if D == 0 {
            let n = self.dim;
            let stages = &self.k[..(STAGES - 1) * n];
            weighted_sum_any(&mut self.increment, &B, &self.ends.f, stages, n);
            for ((y_new, &yi), &inc) in self.y_new.iter_mut().zip(&self.ends.y).zip(&self.increment)
            {
                *y_new = yi + times.h * inc;
            }
            weighted_sum_any(&mut self.scratch, &ERROR_FIFTH, &self.ends.f, stages, n);
            return Ok(());
        }
        let stages = &self.k[..(STAGES - 1) * D];
        let increment = sum_fixed::<D>(&B, &self.ends.f, stages);
        self.increment[..D].copy_from_slice(&increment);
        write_update::<D>(&mut self.y_new, &self.ends.y, times.h, &increment);
        // The fifth-order error estimate's sum, with its weights folded in as constants too.
        let error = sum_fixed::<D>(&ERROR_FIFTH, &self.ends.f, stages);
        self.scratch[..D].copy_from_slice(&error);
        Ok(())
    }
}

/// Time of row `r` of `k`, which holds stage `r + 1`.
fn row_time(times: AttemptTimes, r: usize) -> f64 {
    times.at(C[r + 1])
}

impl Stepper for Dop853Stepper {
    stepper_state_from_ends!();

    fn reset(&mut self, rhs: &mut CheckedRhs<'_>, t0: f64, y0: &[f64]) -> Result<(), StepFailure> {
        self.ends.reset(rhs, t0, y0)?;
        self.dense_ready = false;
        Ok(())
    }

    fn attempt(
        &mut self,
        rhs: &mut CheckedRhs<'_>,
        t_new: f64,
        weights: &ErrorWeights,
        estimate_error: bool,
    ) -> Result<Option<f64>, StepFailure> {
        let n = self.dim;
        let times = AttemptTimes::new(self.ends.t, t_new);
        let h = times.h;
        self.ends.t_new = t_new;
        self.dense_ready = false;
        // The stages also leave the fifth-order error sum in `scratch`.
        match n {
            2 => self.stages_fixed::<2>(rhs, times)?,
            4 => self.stages_fixed::<4>(rhs, times)?,
            6 => self.stages_fixed::<6>(rhs, times)?,
            8 => self.stages_fixed::<8>(rhs, times)?,
            _ => self.stages_fixed::<0>(rhs, times)?,
        }
        let stages = &self.k[..(STAGES - 1) * n];
        let stage_time = |r| row_time(times, r);
        if estimate_error {
            // Every other stage has a weight in the candidate (and so in both estimates);
            // a non-finite one shows there, and is then searched for.
            CheckedRhs::check_stages(&stages[..UNWEIGHTED_ROWS * n], n, stage_time)?;
        } else {
            CheckedRhs::check_stages(stages, n, stage_time)?;
        }
        let f = &self.ends.f;
        if let Some(index) = first_non_finite(&self.y_new) {
            // A non-finite stage that made it so is reported at its own time.
            CheckedRhs::check_stages(stages, n, stage_time)?;
            return Err(StepFailure::NonFiniteState { t: t_new, index });
        }
        if !estimate_error {
            return Ok(None);
        }
        if n == 0 {
            return Ok(Some(0.0));
        }
        // dop853.f's estimate: with err₅ = Σ (bᵢ − b̂⁽⁵⁾ᵢ) kᵢ and err₃ = Σ (bᵢ − b̂⁽³⁾ᵢ) kᵢ
        // in the weighted norm (sums of squares E₅², E₃²),
        // err = |h| E₅² / √(n (E₅² + 0.01 E₃²)), which behaves as O(h⁸) (err₅ ~ h⁶, err₃ ~ h⁴)
        // and is large when either estimate is.
        let (mut fifth, mut third) = (0.0, 0.0);
        for i in 0..n {
            let scale = weights.scale(i, self.ends.y[i].abs().max(self.y_new[i].abs()));
            let inverse = 1.0 / scale;
            let mut e3 = self.increment[i];
            for &(j, w) in &B_THIRD {
                e3 -= w * if j == 0 {
                    f[i]
                } else {
                    stages[(j - 1) * n + i]
                };
            }
            let ratio = |e: f64| error_ratio(e, scale, inverse);
            fifth += ratio(self.scratch[i]).powi(2);
            third += ratio(e3).powi(2);
        }
        // E₅ = 0 makes the estimate 0 whatever E₃ is (even a subnormal E₃², whose 0.01·E₃²
        // underflows to a zero D); otherwise D ≥ E₅² > 0.
        if fifth == 0.0 {
            return Ok(Some(0.0));
        }
        let denominator = fifth + 0.01 * third;
        // The square of the estimate, which needs no square root (the controller takes its
        // logarithm).
        // (h E₅²)² / (n D) without forming (h E₅²)², which could overflow first. Every stage
        // with a weight in either estimate has one in the candidate, which is finite, so a
        // non-finite result comes from an error where the scale is zero, or from E₅²
        // overflowing: the controller rejects it and shrinks the step. (E₃² overflowing
        // alone, which needs atol ≲ 1e-150 with rtol = 0, makes D infinite and the estimate
        // 0, as in dop853.f.)
        Ok(Some(h * h * fifth * (fifth / (n as f64 * denominator))))
    }

    fn accept(&mut self, rhs: &mut CheckedRhs<'_>) -> Result<(), StepFailure> {
        rhs.eval(self.ends.t_new, &self.y_new, &mut self.ends.f_prev)?;
        swap(&mut self.ends.f, &mut self.ends.f_prev);
        swap(&mut self.ends.y_prev, &mut self.ends.y);
        swap(&mut self.ends.y, &mut self.y_new);
        self.ends.t_prev = self.ends.t;
        self.ends.t = self.ends.t_new;
        self.dense_ready = false;
        Ok(())
    }

    /// The three extra stages of the step (at `c = 0.1, 0.2, 7/9`) and the coefficients
    /// `h Σ dᵣⱼ kⱼ`, as `dop853.f` computes them when dense output is requested.
    fn prepare_dense_output(&mut self, rhs: &mut CheckedRhs<'_>) -> Result<(), StepFailure> {
        if self.dense_ready || self.ends.t == self.ends.t_prev {
            return Ok(());
        }
        let n = self.dim;
        let h = self.ends.t - self.ends.t_prev;
        for i in STAGES + 1..EXTENDED_STAGES {
            {
                let (f_prev, f, k) = (&self.ends.f_prev, &self.ends.f, &self.k);
                let stage = |j: usize| match j {
                    0 => f_prev.as_slice(),
                    STAGES => f.as_slice(),
                    _ => &k[k_row(j) * n..(k_row(j) + 1) * n],
                };
                weighted_sum(&mut self.scratch, A[i], stage);
            }
            for (s, &yi) in self.scratch.iter_mut().zip(&self.ends.y_prev) {
                *s = yi + h * *s;
            }
            let row = k_row(i);
            rhs.eval(
                self.ends.t_prev + C[i] * h,
                &self.scratch,
                &mut self.k[row * n..(row + 1) * n],
            )?;
        }
        let (f_prev, f, k) = (&self.ends.f_prev, &self.ends.f, &self.k);
        let stage = |j: usize| match j {
            0 => f_prev.as_slice(),
            STAGES => f.as_slice(),
            _ => &k[k_row(j) * n..(k_row(j) + 1) * n],
        };
        for (r, d) in DENSE.iter().enumerate() {
            let row = &mut self.dense[r * n..(r + 1) * n];
            weighted_sum(row, d, stage);
            for v in row.iter_mut() {
                *v *= h;
            }
        }
        self.dense_ready = true;
        Ok(())
    }
}

/// DOP853, Hairer's eighth-order Dormand–Prince method: adaptive steps from a combined
/// estimate of its embedded fifth- and third-order solutions, dense output of order 7.
///
/// Twelve stages per step (eleven new evaluations of `F` per attempt, one more at the
/// accepted state, shared with the next step), with the eighth-order solution propagated.
/// The error estimate of `dop853.f`,
///
/// ```text
/// err = |h| E₅² / √(n (E₅² + 0.01 E₃²)),   E_p² = Σᵢ (errᵢ⁽ᵖ⁾ / (atolᵢ + rtolᵢ max(|yᵢ|, |y_newᵢ|)))²,
/// ```
///
/// behaves as `O(h⁸)`; steps are accepted when `err ≤ 1`, and the [`PiController`]
/// (`dop853.f`'s defaults, [`PiController::dop853`], unless replaced with
/// [`with_controller`](Self::with_controller)) proposes the next one. The first step is `dt` if
/// given, else chosen automatically (Hairer–Nørsett–Wanner I, §II.4).
///
/// Dense output ([`OutputTimes::At`](super::OutputTimes::At)) is Hairer's continuous extension of
/// order 7: three more evaluations of `F`, made only for steps that contain a requested time. With
/// [`IntegratorOptions::fixed_step`](super::IntegratorOptions::fixed_step) the method takes
/// constant steps `dt` without error control. `dop853.f`'s stiffness detection is not implemented.
///
/// # Examples
/// ```
/// use eomgen_runtime::{DormandPrince853, Integrator, IntegratorOptions, OdeFn, OutputTimes};
///
/// // ẍ = −x, x(0) = 1, ẋ(0) = 0: x(t) = cos t.
/// let mut oscillator = OdeFn::new(2, |_t: f64, y: &[f64], dy: &mut [f64]| {
///     dy[0] = y[1];
///     dy[1] = -y[0];
/// });
/// let options = IntegratorOptions::default().with_rtol(1e-12).with_atol(1e-12);
/// let solution = DormandPrince853::new().integrate(
///     &mut oscillator,
///     0.0,
///     &[1.0, 0.0],
///     10.0,
///     &OutputTimes::At(vec![2.5, 7.25, 10.0]),
///     &options,
/// )?;
/// for (t, y) in solution.iter() {
///     assert!((y[0] - t.cos()).abs() < 1e-10);
/// }
/// # Ok::<(), eomgen_runtime::IntegrationFailure>(())
/// ```
///
/// # References
/// - E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations I*, 2nd ed.,
///   Springer, 1993, §II.10 (the method, its error estimators and dense output),
///   doi:10.1007/978-3-540-78862-1; and the code `dop853.f` (version of 2004), whose
///   coefficients are used here.
/// - P. J. Prince, J. R. Dormand, "High order embedded Runge–Kutta formulae", J. Comput. Appl.
///   Math. 7(1), 67–75, 1981, doi:10.1016/0771-050X(81)90010-3.
#[derive(Debug, Clone)]
pub struct DormandPrince853 {
    controller: PiController,
}

pi_controlled_integrator!(
    DormandPrince853,
    name: "dop853",
    order: 8,
    error_order: ERROR_ORDER,
    controller: PiController::dop853(),
    new_doc: "The method with [`PiController::dop853`].",
    stepper: |dim| Dop853Stepper::new(dim),
);

#[cfg(test)]
mod tests;
