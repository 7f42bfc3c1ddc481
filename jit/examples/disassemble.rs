//! Prints the machine code Cranelift generates for a model file's functions.
//!
//! ```sh
//! cargo run --release -p eomgen-jit --example disassemble -- models/double_pendulum.yaml
//! ```
//!
//! The listing comes from the compiler itself (`EOMGEN_JIT_DISASM`, which this example sets):
//! one block per function, in Cranelift's notation, with its spills and calls.

fn main() {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: disassemble FILE.yaml");
        std::process::exit(2);
    };
    // SAFETY: set before any other thread exists.
    unsafe { std::env::set_var("EOMGEN_JIT_DISASM", "1") };
    let options = eomgen_jit::LoadOptions {
        eager_jacobians: true,
        ..eomgen_jit::LoadOptions::default()
    };
    match eomgen_jit::JitModel::load_with(&path, options) {
        Ok(model) => eprintln!("{} bytes of machine code", model.code_bytes()),
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    }
}
