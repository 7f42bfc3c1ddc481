//! Opening a model as every command does: a bundled model by name or a model file by path
//! (compiled once per process), and the errors of a model that cannot be opened or read,
//! with a file's diagnostics rendered on their source lines.

use eomgen_symbolic::model::ReadError;

use super::error::CliError;
use super::output;

/// The model `name_or_path` names, with its default parameters: a bundled model, or a model
/// file compiled at run time ([`eomgen::ModelSource::open`]).
pub(super) fn find_model(name_or_path: &str) -> Result<Box<dyn eomgen::ModelInfo>, CliError> {
    Ok(open_model(name_or_path)?.instantiate())
}

/// The model `name_or_path` names, for a study that integrates or linearises the smooth
/// equations and does not take unilateral contacts into account: refused, with the reason,
/// for a model with `contacts:` (a result that ignored them would be wrong).
pub(super) fn find_smooth_model(
    name_or_path: &str,
    study: &str,
) -> Result<Box<dyn eomgen::ModelInfo>, CliError> {
    let model = find_model(name_or_path)?;
    smooth_only(model.as_ref(), study)?;
    Ok(model)
}

/// Refuses a model with unilateral contacts for `study` (see [`find_smooth_model`]).
pub(super) fn smooth_only(model: &dyn eomgen::ModelInfo, study: &str) -> Result<(), CliError> {
    let contacts = &model.description().contacts;
    if contacts.is_empty() {
        return Ok(());
    }
    Err(CliError::usage(format!(
        "`{}` has unilateral contacts ({}), which {study} does not take into account yet (it would use the smooth equations as if they were not there); `eomgen simulate` and `animate` run through the impacts",
        model.description().name,
        contacts.join(", ")
    )))
}

/// [`eomgen::ModelSource::open`] with its errors as the CLI reports them. A model is loaded
/// and compiled once per process: the commands that simulate a model several times (`report`,
/// the studies, `animate`) name it again by its path, and each use gets a fresh instance of
/// the same compiled code.
pub(super) fn open_model(name_or_path: &str) -> Result<eomgen::ModelSource, CliError> {
    open_model_with(name_or_path, eomgen::LoadOptions::default())
}

/// [`open_model`] with the options a file is compiled with. A file compiled with the
/// equations as MathML serves later uses that do not ask for them (the report's animation
/// reuses the report's model).
pub(super) fn open_model_with(
    name_or_path: &str,
    options: eomgen::LoadOptions,
) -> Result<eomgen::ModelSource, CliError> {
    // An input that no output may replace (`files::write`): the file the name resolves to
    // (a bundled model's name wins over a file of that name, which is then no input).
    if let Ok(eomgen::Resolved::File(path)) = eomgen::resolve(name_or_path) {
        super::files::read_input(&path);
    }
    type Files = Vec<(String, eomgen::LoadOptions, eomgen::ModelSource)>;
    static FILES: std::sync::Mutex<Files> = std::sync::Mutex::new(Vec::new());
    let serves = |o: &eomgen::LoadOptions| {
        eomgen::LoadOptions {
            equations_mathml: options.equations_mathml,
            ..*o
        } == options
            && (o.equations_mathml || !options.equations_mathml)
    };
    let cached = |files: &Files| {
        files
            .iter()
            .find(|(path, o, _)| path == name_or_path && serves(o))
            .map(|(_, _, s)| s.clone())
    };
    if let Ok(files) = FILES.lock()
        && let Some(source) = cached(&files)
    {
        return Ok(source);
    }
    let source = eomgen::ModelSource::open_with(name_or_path, options).map_err(open_error)?;
    if let Some(reason) = source.model().fallback_reason() {
        // Slower, but the same numbers: say so rather than run silently interpreted.
        output::errln!(
            "note: `{}` runs on the interpreter: {reason}",
            source.path()
        );
    }
    if let Ok(mut files) = FILES.lock() {
        files.push((name_or_path.to_string(), options, source.clone()));
    }
    Ok(source)
}

/// A model that could not be opened: an unknown name or an unreadable file is a usage error
/// (exit 2), and so is a file with mistakes, whose located diagnostics are rendered with
/// their source lines (and, for `--json`, given as JSON on standard output).
pub(super) fn open_error(error: eomgen::OpenError) -> CliError {
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
pub(super) fn diagnostics_error(
    path: &str,
    source: &str,
    diagnostics: &[eomgen_symbolic::model::Diagnostic],
) -> CliError {
    let text: Vec<String> = diagnostics.iter().map(|d| d.render(path, source)).collect();
    let summary = format!("{} error(s) in the model file `{path}`", diagnostics.len());
    // Pure rendering of the diagnostics, with the path as the user wrote it: no report.
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

/// Reads a bundled model by name or any file by path: `(display path, source)`.
pub(super) fn read_model(model: &str) -> Result<(String, String), CliError> {
    let resolved = eomgen::resolve(model).map_err(open_error)?;
    let display = resolved.path().to_string();
    let source = match &resolved {
        // Embedded in the binary: no file is read.
        eomgen::Resolved::Bundled(entry) => entry.source().to_string(),
        eomgen::Resolved::File(path) => {
            super::files::read_input(path);
            eomgen_symbolic::model::read_model_file(std::path::Path::new(path)).map_err(
                |e| match e {
                    ReadError::NotText { diagnostic, text } => {
                        diagnostics_error(&display, &text, &[diagnostic])
                    }
                    e => CliError::usage(format!("cannot read `{display}`: {e}")).before_output(),
                },
            )?
        }
    };
    Ok((display, source))
}
