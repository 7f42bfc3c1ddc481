//! The `eomgen` command line: list, simulate (more commands arrive with later features).

mod cli;

fn main() -> std::process::ExitCode {
    cli::run()
}
