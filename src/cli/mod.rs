//! Command-line interface (clap): parsing, dispatch, and the rendering of errors.

mod animate;
mod check;
mod equations;
mod files;
mod floquet;
mod free_response;
mod frf;
mod modal_damping;
mod mode_plot;
mod modes;
pub(crate) mod output;
mod plot;
mod render;
mod report;
mod report_html;
mod roundoff;
mod simulate;
mod stability;
mod study;
mod values;
mod work_precision;

use clap::{Parser, Subcommand};
use output::outln;
use std::io::Write as _;
use std::process::ExitCode;

/// eomgen: equations of motion derived at compile time from model files, simulated.
#[derive(Debug, Parser)]
#[command(name = "eomgen", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// List the bundled models: name, degrees of freedom, description.
    List {
        /// Print a JSON list of {"name", "dof", "description"}.
        #[arg(long)]
        json: bool,
    },
    /// Integrate a model's equations of motion from its initial state.
    Simulate(simulate::SimulateArgs),
    /// Simulate a model and write its `draw:` lines moving as one self-contained HTML page
    /// (play/pause, speed, time scrubber, t and energy), optionally also a GIF.
    Animate(animate::AnimateArgs),
    /// Derive a model (bundled, or any YAML file) by Lagrange and by momentum balance at run
    /// time and cross-check them and the power balance; exit 1 if a check fails.
    Check(check::CheckArgs),
    /// Print a model's equations of motion M q'' = F (+ J^T lambda and J q'' = gamma with
    /// constraints) as text, LaTeX or JSON, derived at run time.
    Equations(equations::EquationsArgs),
    /// Equilibrium, exact linearisation (M, C, K), natural frequencies, mode shapes and
    /// damping ratios at an operating point (`--at hanging`).
    Modes(modes::ModesArgs),
    /// Frequency response from a load parameter to coordinates: Bode chart, resonance peaks,
    /// modal contributions (`--modal`), points checked by simulation (`--simulate K`).
    Frf(frf::FrfArgs),
    /// Print a generated model file: `n-link-pendulum N` or `n-mass-chain N`.
    New(equations::NewArgs),
    /// Run every model's checks (derivations, conservation, the reference values of its
    /// `checks:`) and write DIR/index.html (equations, figures, pass/fail tables) and
    /// DIR/report.json; exit 1 if a check fails.
    Report(report::ReportArgs),
    /// Numerical experiments: `work-precision`, `stability`, `euler-roundoff`,
    /// `constraint-methods`, `free-response`, `modal-damping`, `floquet`.
    #[command(subcommand)]
    Study(study::Study),
}

/// A CLI failure: the message for stderr and the exit code.
#[derive(Debug)]
pub struct CliError {
    /// What went wrong, with what would be right.
    pub message: String,
    /// Exit status (2 usage, 1 failure of the computation).
    pub code: u8,
    /// What `--json` prints on standard output for this error (model-file diagnostics).
    pub json: Option<serde_json::Value>,
}

impl CliError {
    fn usage(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            code: 2,
            json: None,
        }
    }
    fn failure(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            code: 1,
            json: None,
        }
    }
    /// The error of a model that could not be opened or read, which happens before any
    /// output: with `--json`, `{"error": message}` on standard output (the form of a model
    /// file's diagnostics, without them), so that a script reading the output always gets JSON.
    fn before_output(mut self) -> Self {
        if self.json.is_none() {
            self.json = Some(serde_json::json!({ "error": self.message }));
        }
        self
    }
}

/// `command` and all its subcommands with negative numbers allowed as values: `--t-end -1`
/// then reaches the option's own check ("must be positive") instead of clap's "unexpected
/// argument '-1'" (clap takes a value that starts with `-` for an option otherwise).
fn allow_negative_numbers(command: clap::Command) -> clap::Command {
    let names: Vec<String> = command
        .get_subcommands()
        .map(|s| s.get_name().to_string())
        .collect();
    names
        .iter()
        .fold(command.allow_negative_numbers(true), |command, name| {
            command.mut_subcommand(name, allow_negative_numbers)
        })
}

/// `args` with `--option VALUE` written `--option=VALUE` where `VALUE` starts with `-` but is
/// no option of the command (`--t-end -inf`, `--freqs -1..10`, `--at -pi/2`): clap takes
/// such a value for an unknown option otherwise ("unexpected argument '-inf'"), and only
/// plain negative numbers pass its `allow_negative_numbers`. The value then reaches the
/// option's own check. An option of the command after another (`--csv --json`) stays an
/// option, so a missing value is still reported as missing, and so does any word that
/// starts with `--` (`--csv --plot-phse`): no value starts with `--`, and a mistyped option
/// must be reported, not taken for a file name.
fn join_hyphen_values(
    command: &clap::Command,
    args: Vec<std::ffi::OsString>,
) -> Vec<std::ffi::OsString> {
    let mut current = command;
    let mut out = Vec::with_capacity(args.len());
    let mut rest = args.into_iter();
    if let Some(program) = rest.next() {
        out.push(program);
    }
    while let Some(arg) = rest.next() {
        let Some(text) = arg.to_str().map(str::to_string) else {
            out.push(arg);
            continue;
        };
        if text == "--" {
            // Everything after `--` is a positional value already.
            out.push(arg);
            out.extend(rest);
            break;
        }
        if let Some(sub) = current.find_subcommand(&text) {
            current = sub;
            out.push(arg);
            continue;
        }
        let takes_one_value = |a: &clap::Arg| {
            a.get_action().takes_values() && a.get_num_args().is_none_or(|n| n.max_values() == 1)
        };
        let option = if let Some(long) = text.strip_prefix("--") {
            current
                .get_arguments()
                .find(|a| a.get_long() == Some(long) && takes_one_value(a))
        } else if let Some(short) = text.strip_prefix('-').filter(|s| s.chars().count() == 1) {
            current
                .get_arguments()
                .find(|a| a.get_short() == short.chars().next() && takes_one_value(a))
        } else {
            None
        };
        let Some(option) = option else {
            out.push(arg);
            continue;
        };
        let Some(value) = rest.next() else {
            out.push(arg);
            break;
        };
        match value.to_str() {
            Some(v)
                if v.starts_with('-')
                    && !v.starts_with("--")
                    && v != "-"
                    && !is_option_of(current, v) =>
            {
                let name = option.get_long().map_or_else(
                    || format!("-{}", option.get_short().unwrap_or_default()),
                    |long| format!("--{long}"),
                );
                out.push(format!("{name}={v}").into());
            }
            _ => {
                out.push(arg);
                out.push(value);
            }
        }
    }
    out
}

/// Whether `text` (which starts with `-`) is an option of `command`: `--name`, `--name=…`,
/// exactly `-x` for one of its short names, `--help`, `-h`, `--version`, `-V`, or `--`. A
/// longer word with one dash is a value, even when it starts with a short name's letter: an
/// expression such as `-height + q` or `-omega` (`--stop-when`), not `-h` and `eight + q`.
fn is_option_of(command: &clap::Command, text: &str) -> bool {
    if let Some(long) = text.strip_prefix("--") {
        let name = long.split_once('=').map_or(long, |(name, _)| name);
        name.is_empty()
            || matches!(name, "help" | "version")
            || command.get_arguments().any(|a| a.get_long() == Some(name))
    } else {
        let mut rest = text[1..].chars();
        let short = rest.next();
        if rest.next().is_some() {
            return false;
        }
        matches!(short, Some('h' | 'V'))
            || command
                .get_arguments()
                .any(|a| a.get_short().is_some() && a.get_short() == short)
    }
}

/// Runs the CLI on the process arguments. Exit status: 0 success, 1 a failed computation or
/// a failed write (standard output or a file), 2 a usage error, 141 standard output closed by
/// its reader ([`output`]).
pub fn run() -> ExitCode {
    let command = allow_negative_numbers(<Cli as clap::CommandFactory>::command());
    let args = join_hyphen_values(&command, std::env::args_os().collect());
    let parsed = command
        .try_get_matches_from(args)
        .and_then(|matches| <Cli as clap::FromArgMatches>::from_arg_matches(&matches));
    let cli = match parsed {
        Ok(cli) => cli,
        // `--help`, `--version` (status 0, on standard output: a failed write of them is
        // reported as any other) and usage errors (status 2, on standard error: a message
        // that cannot be written there is dropped, the status still tells).
        Err(e) => {
            let code = u8::try_from(e.exit_code()).unwrap_or(2);
            return match e.print() {
                Ok(()) => ExitCode::from(code),
                Err(_) if e.use_stderr() => ExitCode::from(code),
                Err(io) => output_failure(&io, None),
            };
        }
    };
    let result = match cli.command {
        Command::List { json } => list(json),
        Command::Simulate(args) => simulate::run(&args),
        Command::Animate(args) => animate::run(&args),
        Command::Check(args) => check::run(&args),
        Command::Equations(args) => equations::run(&args),
        Command::New(args) => equations::new(&args),
        Command::Modes(args) => modes::run(&args),
        Command::Frf(args) => frf::run(&args),
        Command::Report(args) => report::run(&args),
        Command::Study(study) => study::run(&study),
    };
    if let Err(e) = &result
        && let Some(json) = &e.json
        && std::env::args().any(|a| a == "--json")
    {
        // Every command that reports numbers takes `--json`; an error with a JSON form
        // (a model file's diagnostics) is then printed as JSON on standard output too.
        outln!("{}", serde_json::to_string_pretty(json).unwrap_or_default());
    }
    // Standard output is complete (flushed) before any message on standard error.
    let written = output::finish();
    match (result, written) {
        (Ok(()), Ok(())) => ExitCode::SUCCESS,
        (Err(e), Ok(())) => {
            let _ = writeln!(std::io::stderr(), "error: {}", e.message);
            ExitCode::from(e.code)
        }
        (result, Err(io)) => output_failure(&io, result.err()),
    }
}

/// The end of a run whose standard output failed: the command's own error if it had one,
/// then the write error (none for a closed pipe, [`output::message`]). The status is the
/// command's when it failed (1); otherwise, and after a usage error whose JSON
/// (`check --json bad.yaml > /dev/full`) was not delivered, the failed write's
/// ([`output::status`]: 1, or 141 for a closed pipe).
fn output_failure(io: &std::io::Error, error: Option<CliError>) -> ExitCode {
    let mut stderr = std::io::stderr();
    if let Some(e) = &error {
        let _ = writeln!(stderr, "error: {}", e.message);
    }
    if let Some(message) = output::message(io) {
        let _ = writeln!(stderr, "error: {message}");
    }
    ExitCode::from(match error {
        Some(e) if e.code != 2 => e.code,
        _ => output::status(io),
    })
}

fn list(json: bool) -> Result<(), CliError> {
    let models: Vec<_> = eomgen::models::ALL.iter().map(|e| (e.make)()).collect();
    if json {
        let items: Vec<serde_json::Value> = models
            .iter()
            .map(|m| serde_json::json!({"name": m.description().name, "dof": m.num_dofs(), "description": m.description().summary}))
            .collect();
        outln!(
            "{}",
            serde_json::to_string_pretty(&items).map_err(|e| CliError::failure(e.to_string()))?
        );
    } else {
        let width = models
            .iter()
            .map(|m| m.description().name.len())
            .max()
            .unwrap_or(4);
        outln!("{:width$}  dof  description", "name");
        for m in &models {
            outln!(
                "{:width$}  {:>3}  {}",
                m.description().name,
                m.num_dofs(),
                m.description().summary
            );
        }
    }
    Ok(())
}

/// The model `name_or_path` names, with its default parameters: a bundled model, or a model
/// file compiled at run time ([`eomgen::ModelSource::open`]).
fn find_model(name_or_path: &str) -> Result<Box<dyn eomgen::ModelInfo>, CliError> {
    Ok(open_model(name_or_path)?.instantiate())
}

/// [`eomgen::ModelSource::open`] with its errors as the CLI reports them. A file is loaded
/// and compiled once per process: the commands that simulate a model several times (`report`,
/// the studies, `animate`) name it again by its path, and each use gets a fresh instance of
/// the same compiled code.
fn open_model(name_or_path: &str) -> Result<eomgen::ModelSource, CliError> {
    static FILES: std::sync::Mutex<Vec<(String, eomgen::ModelSource)>> =
        std::sync::Mutex::new(Vec::new());
    let cached = |files: &[(String, eomgen::ModelSource)]| {
        files
            .iter()
            .find(|(path, _)| path == name_or_path)
            .map(|(_, s)| s.clone())
    };
    if let Ok(files) = FILES.lock()
        && let Some(source) = cached(&files)
    {
        return Ok(source);
    }
    let source = eomgen::ModelSource::open(name_or_path).map_err(open_error)?;
    if let eomgen::ModelSource::File { path, model } = &source
        && let Some(reason) = model.fallback_reason()
    {
        // Slower, but the same numbers: say so rather than run silently interpreted.
        output::errln!("note: `{path}` runs on the interpreter: {reason}");
    }
    if source.is_file()
        && let Ok(mut files) = FILES.lock()
    {
        files.push((name_or_path.to_string(), source.clone()));
    }
    Ok(source)
}

/// A model that could not be opened: an unknown name or an unreadable file is a usage error
/// (exit 2), and so is a file with mistakes, whose located diagnostics are rendered with
/// their source lines (and, for `--json`, given as JSON on standard output).
fn open_error(error: eomgen::OpenError) -> CliError {
    let error = match error {
        eomgen::OpenError::Load(eomgen::LoadError::Diagnostics {
            path,
            text,
            diagnostics,
        }) => diagnostics_error(&path, &text, &diagnostics),
        eomgen::OpenError::Load(e @ eomgen::LoadError::Compile(_))
        | eomgen::OpenError::Load(e @ eomgen::LoadError::Generate(_)) => {
            CliError::failure(e.to_string())
        }
        other => CliError::usage(other.to_string()),
    };
    error.before_output()
}

/// The error of a model file with mistakes: every diagnostic rendered for the terminal, exit
/// 2, and the JSON object `{"error", "diagnostics": [{"file", "line", "column", "message",
/// "help"}]}` for `--json`.
fn diagnostics_error(
    path: &str,
    source: &str,
    diagnostics: &[eomgen_symbolic::model::Diagnostic],
) -> CliError {
    let text: Vec<String> = diagnostics.iter().map(|d| d.render(path, source)).collect();
    let summary = format!("{} error(s) in the model file `{path}`", diagnostics.len());
    let json = serde_json::json!({
        "error": summary,
        "diagnostics": diagnostics.iter().map(|d| serde_json::json!({
            "file": path,
            "line": d.location.line,
            "column": d.location.column,
            "message": d.message,
            "help": d.help,
        })).collect::<Vec<_>>(),
    });
    CliError {
        message: format!("{summary}\n{}", text.join("\n")),
        code: 2,
        json: Some(json),
    }
}
