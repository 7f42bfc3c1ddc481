//! Local probe: interleaved best-of-N timings of eomgen vs ode_solvers on the double pendulum.
use std::cell::{Cell, RefCell};
use std::hint::black_box;
use std::time::Instant;

use eomgen::models::DoublePendulum;
use eomgen::{
    DormandPrince54, DormandPrince853, FirstOrder, Integrator, IntegratorOptions, ModelInfo,
    OdeSystem, OutputTimes, RhsError,
};
use ode_solvers::{Dop853, Dopri5, OutputType};

type PeerState = ode_solvers::SVector<f64, 4>;
const T_END: f64 = 10.0;

struct CountedRhs {
    system: RefCell<FirstOrder<DoublePendulum, 2>>,
    evals: Cell<usize>,
}
impl CountedRhs {
    fn eval(&self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        self.evals.set(self.evals.get() + 1);
        self.system.borrow_mut().rhs(t, y, dy)
    }
}
struct Eomgen<'a>(&'a CountedRhs);
impl OdeSystem for Eomgen<'_> {
    fn dim(&self) -> usize {
        4
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        self.0.eval(t, y, dy)
    }
}
struct Peer<'a>(&'a CountedRhs);
impl ode_solvers::System<f64, PeerState> for Peer<'_> {
    fn system(&self, t: f64, y: &PeerState, dy: &mut PeerState) {
        self.0.eval(t, y.as_slice(), dy.as_mut_slice()).unwrap();
    }
}

fn eom(rhs: &CountedRhs, y0: &[f64; 4], tol: f64, dop853: bool) -> [f64; 4] {
    let o = IntegratorOptions::default().with_rtol(tol).with_atol(tol).with_max_steps(1_000_000);
    let mut m: Box<dyn Integrator> = if dop853 {
        Box::new(DormandPrince853::new())
    } else {
        Box::new(DormandPrince54::new())
    };
    let s = m.integrate(&mut Eomgen(rhs), 0.0, y0, T_END, &OutputTimes::Steps, &o).unwrap();
    let (_, y) = s.last().unwrap();
    [y[0], y[1], y[2], y[3]]
}

fn peer(rhs: &CountedRhs, y0: &[f64; 4], tol: f64, dop853: bool) -> [f64; 4] {
    macro_rules! go {
        ($s:ident, $beta:expr, $a:expr, $b:expr) => {{
            let mut st = $s::from_param(Peer(rhs), 0.0, T_END, T_END, PeerState::from_column_slice(y0),
                tol, tol, 0.9, $beta, $a, $b, T_END, 0.0, 1_000_000, 1000, OutputType::Sparse);
            st.integrate().unwrap();
            let y = st.y_out().last().unwrap();
            [y[0], y[1], y[2], y[3]]
        }};
    }
    if dop853 { go!(Dop853, 0.0, 0.333, 6.0) } else { go!(Dopri5, 0.04, 0.2, 10.0) }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let reps: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(300);
    let tols: Vec<f64> = args.get(2).map(|s| s.split(',').map(|x| x.parse().unwrap()).collect())
        .unwrap_or(vec![1e-6, 1e-9, 1e-12]);
    let rhs = CountedRhs { system: RefCell::new(FirstOrder::new(DoublePendulum::default())), evals: Cell::new(0) };
    let init = ModelInfo::initial_state(&*rhs.system.borrow());
    let y0 = [init[0], init[1], init[2], init[3]];
    let reference = eom(&rhs, &y0, 1e-14, true);
    if let Some(mode) = args.get(3) {
        let dop = mode.contains("853");
        let t = Instant::now();
        for _ in 0..reps { for &tol in &tols { if mode.starts_with("peer") { black_box(peer(&rhs, black_box(&y0), tol, dop)); } else { black_box(eom(&rhs, black_box(&y0), tol, dop)); } } }
        println!("{mode}: {:.1} us per run", t.elapsed().as_secs_f64() * 1e6 / (reps * tols.len()) as f64);
        return;
    }
    for &dop853 in &[false, true] {
        for &tol in &tols {
            let mut best = [f64::INFINITY; 2];
            let mut evals = [0; 2];
            let mut err = [0.0; 2];
            for _ in 0..reps {
                for side in 0..2 {
                    rhs.evals.set(0);
                    let t = Instant::now();
                    let y = if side == 0 { eom(&rhs, black_box(&y0), tol, dop853) } else { peer(&rhs, black_box(&y0), tol, dop853) };
                    let el = t.elapsed().as_secs_f64();
                    black_box(y);
                    best[side] = best[side].min(el);
                    evals[side] = rhs.evals.get();
                    err[side] = y.iter().zip(&reference).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
                }
            }
            println!("{} tol {tol:e}: eomgen {:.1} us ({} rhs, err {:.2e}, {:.1} ns/rhs) peer {:.1} us ({} rhs, err {:.2e}) ratio {:.3}",
                if dop853 { "DOP853" } else { "DP54  " }, best[0]*1e6, evals[0], err[0], best[0]*1e9/evals[0] as f64, best[1]*1e6, evals[1], err[1], best[1]/best[0]);
        }
    }
}
#[allow(dead_code)]
fn unused() {}
