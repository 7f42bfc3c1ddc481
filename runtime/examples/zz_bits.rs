use eomgen_runtime::{IntegratorOptions, Method, OdeFn, OutputTimes};
use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};

fn main() {
    let names = [
        "euler", "midpoint", "rk4", "bs32", "dp54", "dop853", "vern6", "vern7", "vern8", "vern9",
    ];
    for name in names {
        let method: Method = name.parse().unwrap();
        for dim in [1usize, 2, 3, 4, 6, 8, 10] {
            for (tol, fixed, outputs) in [
                (1e-6, false, 0),
                (1e-10, false, 37),
                (1e-3, true, 0),
                (1e-8, false, 5),
            ] {
                let mut sys = OdeFn::new(dim, move |t: f64, y: &[f64], dy: &mut [f64]| {
                    let n = y.len();
                    for i in 0..n {
                        dy[i] = (y[(i + 1) % n] * 1.3).sin() - 0.2 * y[i]
                            + (t * 0.7).cos() * 0.3
                            + if n == 1 { -y[0] * y[0] } else { 0.0 };
                    }
                });
                let y0: Vec<f64> = (0..dim).map(|i| 0.3 + 0.1 * i as f64).collect();
                let mut options = IntegratorOptions::default().with_rtol(tol).with_atol(tol);
                if fixed {
                    options = options.with_fixed_step(true).with_dt(0.01);
                }
                let out = if outputs == 0 {
                    OutputTimes::Steps
                } else {
                    OutputTimes::At(
                        (1..=outputs)
                            .map(|k| 5.0 * k as f64 / outputs as f64)
                            .collect(),
                    )
                };
                let mut m = method.integrator();
                let sol = m.integrate(&mut sys, 0.0, &y0, 5.0, &out, &options);
                let mut h = DefaultHasher::new();
                match &sol {
                    Ok(s) => {
                        for (t, y) in s.iter() {
                            t.to_bits().hash(&mut h);
                            for v in y {
                                v.to_bits().hash(&mut h);
                            }
                        }
                        (s.stats.steps, s.stats.rejected, s.stats.rhs_evals).hash(&mut h);
                    }
                    Err(e) => format!("{e:?}").hash(&mut h),
                }
                println!(
                    "{name} dim {dim} tol {tol} fixed {fixed} out {outputs}: {:016x}",
                    h.finish()
                );
            }
        }
    }
}
