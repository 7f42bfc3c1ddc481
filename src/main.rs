//! The `eomgen` command line (`src/cli/`): parses the arguments, calls one library function per
//! command and renders its report; `eomgen --help` lists the commands, docs/cli.md describes them.

mod cli;

fn main() -> std::process::ExitCode {
    cli::run()
}
