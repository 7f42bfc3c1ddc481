//! Diagnostics of model files: what is wrong, where, and what would be right.

use super::located::Location;

/// One problem in a model file.
///
/// Rendered as `path:line:col: message`, then the offending source line with a caret, then
/// `help: …` when there is advice. The macro turns each into a compile error; `eomgen check`
/// prints the same text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostic {
    /// Where the problem is.
    pub location: Location,
    /// Lowercase message naming the key and value in backticks.
    pub message: String,
    /// What would be right, if known.
    pub help: Option<String>,
}

impl Diagnostic {
    /// A diagnostic at `location`.
    pub fn new(location: Location, message: impl Into<String>) -> Self {
        Self {
            location,
            message: message.into(),
            help: None,
        }
    }

    /// Adds advice on what would be right.
    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    /// The one-line form `path:line:col: message`.
    pub fn headline(&self, path: &str) -> String {
        format!("{path}:{}: {}", self.location, self.message)
    }

    /// The full form: headline, source line with a caret under the column, and help.
    pub fn render(&self, path: &str, source: &str) -> String {
        let mut out = self.headline(path);
        if let Some(line) = source
            .lines()
            .nth(self.location.line.saturating_sub(1) as usize)
        {
            let number = self.location.line.to_string();
            let pad = " ".repeat(number.len());
            let caret_pad: String = line
                .chars()
                .take(self.location.column.saturating_sub(1) as usize)
                .map(|c| if c == '\t' { '\t' } else { ' ' })
                .collect();
            out.push_str(&format!(
                "\n{pad} |\n{number} | {line}\n{pad} | {caret_pad}^"
            ));
        }
        if let Some(help) = &self.help {
            out.push_str(&format!("\n= help: {help}"));
        }
        out
    }
}

/// Collects every diagnostic of a file so that all are reported at once.
///
/// Must be finished with [`Diagnostics::finish`]; dropping it with unchecked diagnostics
/// is a programmer error caught in debug builds (serde's `Ctxt` pattern).
#[derive(Debug, Default)]
pub struct Diagnostics {
    list: Vec<Diagnostic>,
    checked: bool,
}

impl Diagnostics {
    /// An empty collector.
    pub fn new() -> Self {
        Self::default()
    }

    /// Records a diagnostic.
    pub fn push(&mut self, diagnostic: Diagnostic) {
        self.list.push(diagnostic);
    }

    /// Records `message` at `location`.
    pub fn error(&mut self, location: Location, message: impl Into<String>) {
        self.push(Diagnostic::new(location, message));
    }

    /// Whether nothing was recorded so far.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Ends collection: `Ok(())` if nothing was recorded, else every diagnostic sorted by
    /// location (stable for equal locations).
    ///
    /// # Errors
    /// The recorded diagnostics, in file order.
    pub fn finish(mut self) -> Result<(), Vec<Diagnostic>> {
        self.checked = true;
        let mut list = std::mem::take(&mut self.list);
        if list.is_empty() {
            Ok(())
        } else {
            list.sort_by_key(|d| d.location);
            Err(list)
        }
    }
}

impl Drop for Diagnostics {
    fn drop(&mut self) {
        debug_assert!(
            self.checked || self.list.is_empty() || std::thread::panicking(),
            "Diagnostics dropped without finish()"
        );
    }
}
