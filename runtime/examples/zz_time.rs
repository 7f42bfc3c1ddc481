use eomgen_runtime::{IntegratorOptions, Method, OdeFn, OutputTimes};
use std::time::Instant;

fn main() {
    let names = ["dp54", "bs32", "vern6", "vern7", "vern9"];
    let rounds = 15;
    let mut times = vec![vec![]; names.len() * 2];
    for _ in 0..rounds {
        for (k, name) in names.iter().enumerate() {
            let method: Method = name.parse().unwrap();
            for (d, dense) in [false, true].iter().enumerate() {
                let mut sys = OdeFn::new(4, |t: f64, y: &[f64], dy: &mut [f64]| {
                    dy[0] = y[2];
                    dy[1] = y[3];
                    dy[2] = -(y[0]).sin() - 0.1 * (y[1] - y[0]).sin() + 0.01 * t.cos();
                    dy[3] = -(y[1]).sin() + 0.1 * (y[1] - y[0]).sin();
                });
                let options = IntegratorOptions::default()
                    .with_rtol(1e-10)
                    .with_atol(1e-10);
                let out = if *dense {
                    OutputTimes::At((1..=2000).map(|k| 0.01 * k as f64).collect())
                } else {
                    OutputTimes::Steps
                };
                let mut m = method.integrator();
                let start = Instant::now();
                for _ in 0..20 {
                    let s = m
                        .integrate(&mut sys, 0.0, &[1.0, 0.5, 0.0, 0.0], 20.0, &out, &options)
                        .unwrap();
                    std::hint::black_box(s);
                }
                times[2 * k + d].push(start.elapsed().as_secs_f64() / 20.0);
            }
        }
    }
    for (k, name) in names.iter().enumerate() {
        for d in 0..2 {
            let t = &mut times[2 * k + d];
            t.sort_by(|a, b| a.partial_cmp(b).unwrap());
            println!("{name} dense {d}: median {:.1} us", t[t.len() / 2] * 1e6);
        }
    }
}
