//! Prints the Rust code that `eomgen::model!` generates for a model file.
//!
//! `cargo run -p eomgen-symbolic --example generate -- models/double_pendulum.yaml`

use eomgen_symbolic::codegen::{self, EmitOptions};
use eomgen_symbolic::mechanics::{SymbolicModel, preferred_equations};

fn main() {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: generate MODEL.yaml");
        std::process::exit(2);
    };
    let source = match std::fs::read_to_string(&path) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("cannot read {path}: {e}");
            std::process::exit(2);
        }
    };
    fn report(path: &str, source: &str, d: Vec<eomgen_symbolic::model::Diagnostic>) -> ! {
        for x in d {
            eprintln!("{}", x.render(path, source));
        }
        std::process::exit(1);
    }
    let file =
        eomgen_symbolic::model::load(&path, &source).unwrap_or_else(|d| report(&path, &source, d));
    let mut model = SymbolicModel::from_file(&file).unwrap_or_else(|d| report(&path, &source, d));
    let (eom, method) = preferred_equations(&mut model);
    eprintln!("equations from {method}");
    let plans = codegen::plan::EmitPlans::of(&model, &eom);
    match codegen::emit(&model, &eom, &plans, &EmitOptions::default()) {
        Ok((tokens, stats)) => {
            println!("{tokens}");
            eprintln!(
                "ops before CSE {}, after {}",
                stats.ops_before_cse, stats.ops_after_cse
            );
        }
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    }
}
