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

    /// The one-line form `path:line:col: message`, for a terminal: control characters
    /// escaped and long quotes shortened ([`printable`]).
    pub fn headline(&self, path: &str) -> String {
        format!(
            "{}:{}: {}",
            printable(path),
            self.location,
            printable(&self.message)
        )
    }

    /// The full form: headline, source line with a caret under the column, and help.
    ///
    /// What reaches the terminal is printable: a control character of the file (ESC, BEL,
    /// a bidirectional override) is shown escaped (`\u{1b}`), never sent as is, and a line
    /// longer than [`SNIPPET_WIDTH`] characters is shown as a window around the column, cut
    /// with `…`.
    pub fn render(&self, path: &str, source: &str) -> String {
        let mut out = self.headline(path);
        if let Some(line) = source
            .lines()
            .nth(self.location.line.saturating_sub(1) as usize)
        {
            let number = self.location.line.to_string();
            let pad = " ".repeat(number.len());
            let (shown, caret_pad) = snippet(line, self.location.column);
            out.push_str(&format!(
                "\n{pad} |\n{number} | {shown}\n{pad} | {caret_pad}^"
            ));
        }
        if let Some(help) = &self.help {
            out.push_str(&format!("\n= help: {}", printable(help)));
        }
        out
    }
}

/// Characters of a source line shown in a diagnostic: a longer line is cut to a window of
/// this many around the column.
pub const SNIPPET_WIDTH: usize = 100;

/// Characters of a message or help shown: a longer one keeps its start and end around a `…`
/// (a message quotes the file, and a name or key can be as long as a line).
pub const MESSAGE_WIDTH: usize = 1_000;

/// Whether `c` would act on a terminal rather than show: the C0 and C1 controls but tab,
/// and the bidirectional embeddings, overrides and isolates (which reorder what follows).
fn acts_on_terminal(c: char) -> bool {
    (c.is_control() && c != '\t') || matches!(c, '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}

/// How `c` is shown: itself, or escaped as `\u{1b}`.
fn shown(c: char) -> String {
    if acts_on_terminal(c) {
        format!("\\u{{{:x}}}", c as u32)
    } else {
        c.to_string()
    }
}

/// `text` for a terminal: control characters escaped (`\u{7}`), and when longer than
/// [`MESSAGE_WIDTH`] characters, its start and end around a `…`.
pub fn printable(text: &str) -> String {
    let count = text.chars().count();
    if count <= MESSAGE_WIDTH && !text.chars().any(acts_on_terminal) {
        return text.to_string();
    }
    let half = MESSAGE_WIDTH / 2;
    let mut out = String::new();
    for (i, c) in text.chars().enumerate() {
        if count > MESSAGE_WIDTH && i == half {
            out.push('…');
        }
        if count <= MESSAGE_WIDTH || i < half || i >= count - half {
            out.push_str(&shown(c));
        }
    }
    out
}

/// The part of `line` shown under a diagnostic at `column` (1-based), and the padding that
/// puts a caret under that column: at most [`SNIPPET_WIDTH`] characters around it, cut with
/// `…`, control characters escaped.
fn snippet(line: &str, column: u32) -> (String, String) {
    let chars: Vec<char> = line.chars().collect();
    let at = (column.saturating_sub(1) as usize).min(chars.len());
    let (start, end) = if chars.len() <= SNIPPET_WIDTH {
        (0, chars.len())
    } else {
        let start = at
            .saturating_sub(SNIPPET_WIDTH / 2)
            .min(chars.len() - SNIPPET_WIDTH);
        (start, start + SNIPPET_WIDTH)
    };
    let mut text = String::new();
    let mut pad = String::new();
    if start > 0 {
        text.push('…');
        pad.push(' ');
    }
    for (i, &c) in chars[start..end].iter().enumerate() {
        let s = shown(c);
        if start + i < at {
            // A tab stays a tab, so that the caret lines up as the line does.
            pad.extend(s.chars().map(|x| if x == '\t' { '\t' } else { ' ' }));
        }
        text.push_str(&s);
    }
    if end < chars.len() {
        text.push('…');
    }
    (text, pad)
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

/// A number in a diagnostic: 6 decimals between 1e-3 and 1e6 (trailing zeros dropped, as `1`,
/// `-0.5`, `0.001235`), 6 significant digits outside (`1.20000e-7`).
pub(crate) fn short(v: f64) -> String {
    if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e6) {
        format!("{v:.5e}")
    } else {
        let s = format!("{v:.6}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 28: ESC and BEL of a model file reached the terminal; a 500 kB line was
    /// printed whole.
    #[test]
    fn what_reaches_the_terminal_is_printable_and_short() {
        let at = Location { line: 1, column: 8 };
        let d = Diagnostic::new(at, "unknown key `a\u{1b}[2Jb`").with_help("bell \u{7}");
        let text = d.render("m\u{1b}.yaml", "bogus: a\u{1b}[2Jb\u{202e}x\n");
        assert!(
            !text.lines().any(|l| l.chars().any(acts_on_terminal)),
            "{text:?}"
        );
        assert_eq!(
            text,
            "m\\u{1b}.yaml:1:8: unknown key `a\\u{1b}[2Jb`\n  |\n1 | bogus: a\\u{1b}[2Jb\\u{202e}x\n  |        ^\n= help: bell \\u{7}"
        );
        // An escaped character before the column moves the caret by its escaped width.
        let d = Diagnostic::new(Location { line: 1, column: 3 }, "here");
        assert_eq!(
            d.render("m", "\u{7}xy"),
            "m:1:3: here\n  |\n1 | \\u{7}xy\n  |       ^"
        );

        let long = format!("{}X{}", "a".repeat(250_000), "b".repeat(250_000));
        let d = Diagnostic::new(
            Location {
                line: 1,
                column: 250_001,
            },
            format!("unknown name `{long}`"),
        );
        let text = d.render("m", &long);
        assert!(
            text.len() < 2 * (SNIPPET_WIDTH + MESSAGE_WIDTH) + 100,
            "{}",
            text.len()
        );
        let lines: Vec<&str> = text.lines().collect();
        // The window keeps the column, with the caret under the `X`.
        let caret = lines[3].find('^').unwrap();
        assert_eq!(
            lines[2].chars().nth(caret),
            Some('X'),
            "{}\n{}",
            lines[2],
            lines[3]
        );
        assert!(lines[2].contains("…aaa") && lines[2].ends_with("bbb…"));
        assert!(lines[0].contains("aaa…bbb"), "{}", lines[0]);
    }

    #[test]
    fn numbers_in_diagnostics_print_short() {
        for (v, s) in [
            (0.0, "0"),
            (1.0, "1"),
            (-0.5, "-0.5"),
            (0.001, "0.001"),
            (0.000_999_9, "9.99900e-4"),
            (1.2e-7, "1.20000e-7"),
            (999_999.0, "999999"),
            (1e6, "1.00000e6"),
            (-2.5e6, "-2.50000e6"),
            (1.0 / 3.0, "0.333333"),
        ] {
            assert_eq!(short(v), s, "{v}");
        }
    }
}
