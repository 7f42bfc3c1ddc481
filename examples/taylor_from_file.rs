//! The Taylor method on a bundled model three ways, in the same run: compiled by `model!`,
//! loaded from its file with its orders compiled to native code from the first series
//! (`LoadOptions::eager_taylor`), and loaded from its file with the runtime's kernels alone
//! (the interpreter backend, whose Taylor orders are what a file-loaded model runs before it
//! has computed `eomgen::COMPILE_TAYLOR_AFTER` series). All three compute the same bits
//! (`tests/taylor_coefficients.rs`); this times them.
//!
//! ```sh
//! cargo run --release --example taylor_from_file -- double_pendulum 1e-9 200
//! ```
//!
//! Arguments: a bundled model's name (`double_pendulum`, `figure_eight`, `heavy_top` or
//! `two_body`, the four compiled into this example by `model!`), the tolerance (`rtol = atol`), the number of timed runs
//! of each (default 100), alternated A B C A B C …, and optionally one variant alone (`model`,
//! `file` or `kernels`, for a profiler); each run integrates the model's initial
//! state over 0–10 s with every step recorded. Prints, per variant, the median time of a run
//! and the first run's (which includes compiling the orders for the eager variant), and the
//! steps.

use std::hint::black_box;
use std::time::Instant;

use eomgen::{
    Backend, DynFirstOrder, FirstOrder, Integrator, IntegratorOptions, JitModel, LoadOptions,
    ModelInfo, OutputTimes, Taylor,
};

mod double_pendulum {
    eomgen::model!("../models/double_pendulum.yaml");
}
mod figure_eight {
    eomgen::model!("../models/figure_eight.yaml");
}
mod heavy_top {
    eomgen::model!("../models/heavy_top.yaml");
}
mod two_body {
    eomgen::model!("../models/two_body.yaml");
}

/// The model `name` compiled into this example by `model!`.
fn compiled(name: &str) -> Result<Box<dyn ModelInfo>, String> {
    Ok(match name {
        "double_pendulum" => Box::new(FirstOrder::new(double_pendulum::DoublePendulum::default())),
        "figure_eight" => Box::new(FirstOrder::new(figure_eight::FigureEight::default())),
        "heavy_top" => Box::new(FirstOrder::new(heavy_top::HeavyTop::default())),
        "two_body" => Box::new(FirstOrder::new(two_body::TwoBody::default())),
        _ => {
            return Err(format!(
                "`{name}` is not compiled into this example: double_pendulum, figure_eight, heavy_top or two_body"
            ));
        }
    })
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args
        .first()
        .ok_or("usage: taylor_from_file MODEL TOL [RUNS]")?;
    let tol: f64 = args
        .get(1)
        .ok_or("usage: taylor_from_file MODEL TOL [RUNS]")?
        .parse()
        .map_err(|e| format!("the tolerance: {e}"))?;
    let runs: usize = match args.get(2) {
        Some(r) => r.parse().map_err(|e| format!("the number of runs: {e}"))?,
        None => 100,
    };
    if runs == 0 {
        return Err("the number of runs must be at least 1".into());
    }
    let path = format!("{}/models/{name}.yaml", env!("CARGO_MANIFEST_DIR"));
    let load = |options: LoadOptions| -> Result<Box<dyn ModelInfo>, String> {
        let model = JitModel::load_with(&path, options).map_err(|e| format!("{path}: {e}"))?;
        Ok(Box::new(DynFirstOrder::new(model)))
    };
    let mut variants: Vec<(&str, Box<dyn ModelInfo>)> = vec![
        ("compiled (model!)", compiled(name)?),
        (
            "file, orders compiled",
            load(LoadOptions {
                eager_taylor: true,
                ..LoadOptions::default()
            })?,
        ),
        (
            "file, runtime kernels",
            load(LoadOptions {
                backend: Some(Backend::Interpreter),
                ..LoadOptions::default()
            })?,
        ),
    ];
    // An optional fourth argument keeps one variant (for a profiler): `model`, `file` or
    // `kernels`.
    if let Some(only) = args.get(3) {
        let keep = match only.as_str() {
            "model" => 0,
            "file" => 1,
            "kernels" => 2,
            other => return Err(format!("the variant `{other}`: model, file or kernels")),
        };
        variants = variants.into_iter().skip(keep).take(1).collect();
    }
    let options = IntegratorOptions::default().with_rtol(tol).with_atol(tol);
    let mut times = vec![Vec::with_capacity(runs); variants.len()];
    let mut steps = vec![0; variants.len()];
    for _ in 0..runs {
        for (i, (label, model)) in variants.iter_mut().enumerate() {
            let y0 = model.initial_state();
            let start = Instant::now();
            let solution = Taylor::new()
                .integrate(
                    model.as_mut(),
                    0.0,
                    &y0,
                    10.0,
                    &OutputTimes::Steps,
                    &options,
                )
                .map_err(|e| format!("{label}: {e}"))?;
            times[i].push(start.elapsed().as_secs_f64());
            steps[i] = solution.stats.steps;
            black_box(solution);
        }
    }
    for (i, (label, _)) in variants.iter().enumerate() {
        let first = times[i][0];
        let mut sorted = times[i].clone();
        sorted.sort_by(f64::total_cmp);
        println!(
            "{label:<24} median {:8.1} µs   first {:8.3} ms   {} steps",
            sorted[sorted.len() / 2] * 1e6,
            first * 1e3,
            steps[i]
        );
    }
    Ok(())
}
