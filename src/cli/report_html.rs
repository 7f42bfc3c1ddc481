//! The page of `eomgen report`: one self-contained HTML file (inline CSS, no script, no
//! network) with a summary table and one section per model — description, equations of
//! motion in MathML, pass/fail table, figures (SVG files next to the page, referenced
//! relatively) and the model's animation when there is one.

use std::fmt::Write as _;

use super::render::escape;
use eomgen::checks::CheckRow;

/// A figure of a model's section: the file (relative to the report's directory) and what
/// it shows.
#[derive(Debug, Clone, serde::Serialize)]
pub(super) struct Figure {
    /// Relative path, `model/kind.svg`.
    pub file: String,
    /// Caption.
    pub caption: String,
}

/// Everything the report shows for one model.
#[derive(Debug, Clone)]
pub(super) struct ModelReport {
    /// The model's name.
    pub name: String,
    /// `description:`.
    pub description: String,
    /// The comment block at the top of the model file (its source and reference values).
    pub header: String,
    /// Degrees of freedom.
    pub dof: usize,
    /// The equations of motion, one `<math>` element per line.
    pub equations: Vec<String>,
    /// The derivation they come from, as the page titles it (`momentum balance`).
    pub derivation: &'static str,
    /// Charts.
    pub figures: Vec<Figure>,
    /// The model's animation (a self-contained HTML file relative to the report's
    /// directory), embedded when present.
    pub animation: Option<String>,
    /// The pass/fail table.
    pub checks: Vec<CheckRow>,
    /// What could not be drawn or was skipped, and why.
    pub notes: Vec<String>,
    /// Wall time (s).
    pub time_s: f64,
}

impl ModelReport {
    /// Whether every check passed.
    pub fn passed(&self) -> bool {
        self.checks.iter().all(|c| c.passed)
    }
}

const STYLE: &str = r#"
:root { --pass: #1a7f37; --fail: #cf222e; --line: #d0d7de; --muted: #57606a; }
* { box-sizing: border-box; }
body { font-family: system-ui, -apple-system, "Segoe UI", "DejaVu Sans", sans-serif; margin: 0;
  color: #1f2328; background: #fff; line-height: 1.45; }
header, main { max-width: 1200px; margin: 0 auto; padding: 0 1.5rem; }
header { padding-top: 1.5rem; }
h1 { margin: 0 0 .3rem; font-size: 1.8rem; }
h2 { margin: 2.5rem 0 .3rem; padding-top: 1rem; border-top: 2px solid var(--line); font-size: 1.4rem; }
h3 { margin: 1.2rem 0 .4rem; font-size: 1.05rem; color: var(--muted); }
a { color: #0969da; }
.lead { color: var(--muted); margin: .2rem 0 1rem; }
table { border-collapse: collapse; width: 100%; font-size: .9rem; }
th, td { border: 1px solid var(--line); padding: .25rem .5rem; text-align: left; vertical-align: top; }
th { background: #f6f8fa; }
td.num { font-family: ui-monospace, "DejaVu Sans Mono", monospace; text-align: right; white-space: nowrap; }
.pass { color: var(--pass); font-weight: 600; }
.fail { color: var(--fail); font-weight: 600; }
tr.failed td { background: #ffebe9; }
.badge { font-size: .85rem; padding: .1rem .5rem; border-radius: 1rem; border: 1px solid currentColor; margin-left: .5rem; vertical-align: middle; }
details { margin: .4rem 0; }
details pre { background: #f6f8fa; padding: .6rem; overflow-x: auto; font-size: .8rem; }
.equations { overflow-x: auto; border-left: 3px solid var(--line); padding-left: .8rem; }
.equations div { margin: .35rem 0; white-space: nowrap; }
.equations math { font-size: 1.1rem; display: inline math; }
.figures { display: grid; grid-template-columns: repeat(auto-fill, minmax(360px, 1fr)); gap: 1rem; }
figure { margin: 0; border: 1px solid var(--line); padding: .3rem; }
figure img { width: 100%; height: auto; display: block; }
figcaption { font-size: .8rem; color: var(--muted); padding: .2rem; }
iframe.animation { width: 100%; height: 520px; border: 1px solid var(--line); }
ul.notes { font-size: .85rem; color: var(--muted); }
footer { max-width: 1200px; margin: 2rem auto; padding: 0 1.5rem 2rem; color: var(--muted); font-size: .85rem; }
"#;

/// A number for the tables: ten decimals in `[1e-3, 1e5)`, else four significant digits in
/// exponent form; `—` for a missing or non-finite value.
fn number(v: Option<f64>) -> String {
    match v {
        Some(0.0) => "0".to_string(),
        Some(v) if v.is_finite() && (1e-3..1e5).contains(&v.abs()) => {
            let s = format!("{v:.10}");
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        }
        Some(v) if v.is_finite() => format!("{v:.3e}"),
        _ => "—".to_string(),
    }
}

/// The report page for `reports` (already sorted); `timing` adds each model's wall time.
pub(super) fn page(reports: &[ModelReport], timing: bool) -> String {
    let total: usize = reports.iter().map(|r| r.checks.len()).sum();
    let failed: usize = reports
        .iter()
        .map(|r| r.checks.iter().filter(|c| !c.passed).count())
        .sum();
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>eomgen report</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<header>\n<h1>eomgen report</h1>\n"
    );
    let status = if failed == 0 {
        "<span class=\"pass\">all passed</span>".to_string()
    } else {
        format!("<span class=\"fail\">{failed} failed</span>")
    };
    let _ = writeln!(
        h,
        "<p class=\"lead\">{} models, {total} checks: {status}. A check passes when |computed − expected| ≤ tolerance · max(1, |expected|); drifts and residuals are computed against 0 with their bound as tolerance.</p>",
        reports.len()
    );
    h.push_str("<table>\n<tr><th>model</th><th>dof</th><th>description</th><th>checks</th>");
    if timing {
        h.push_str("<th>time (s)</th>");
    }
    h.push_str("</tr>\n");
    for r in reports {
        let passed = r.checks.iter().filter(|c| c.passed).count();
        let class = if r.passed() { "pass" } else { "fail" };
        let _ = write!(
            h,
            "<tr><td><a href=\"#{id}\">{id}</a></td><td class=\"num\">{}</td><td>{}</td><td class=\"{class}\">{passed}/{}</td>",
            r.dof,
            escape(&r.description),
            r.checks.len(),
            id = escape(&r.name),
        );
        if timing {
            let _ = write!(h, "<td class=\"num\">{:.3}</td>", r.time_s);
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</table>\n</header>\n<main>\n");
    for r in reports {
        section(&mut h, r);
    }
    h.push_str("</main>\n<footer>Generated by <code>eomgen report</code>; the same content is in <a href=\"report.json\">report.json</a>.</footer>\n</body>\n</html>\n");
    h
}

fn section(h: &mut String, r: &ModelReport) {
    let passed = r.checks.iter().filter(|c| c.passed).count();
    let (class, word) = if r.passed() {
        ("pass", "passed")
    } else {
        ("fail", "failed")
    };
    let _ = writeln!(
        h,
        "<section id=\"{id}\">\n<h2>{id} <span class=\"badge {class}\">{word} {passed}/{}</span></h2>\n<p class=\"lead\">{} — {} degree(s) of freedom</p>",
        r.checks.len(),
        escape(&r.description),
        r.dof,
        id = escape(&r.name),
    );
    if !r.header.is_empty() {
        let _ = writeln!(
            h,
            "<details><summary>From the model file: source, coordinates and reference values</summary><pre>{}</pre></details>",
            escape(&r.header)
        );
    }
    if !r.equations.is_empty() {
        let _ = writeln!(
            h,
            "<h3>Equations of motion ({})</h3>\n<div class=\"equations\">",
            r.derivation
        );
        for e in &r.equations {
            // One line each, left-aligned and scrollable: block math would be centred and
            // clipped on the left when wider than the page.
            let _ = writeln!(h, "<div>{e}</div>");
        }
        h.push_str("</div>\n");
    }
    h.push_str("<h3>Checks</h3>\n<table>\n<tr><th>check</th><th>computed</th><th>expected</th><th>tolerance</th><th>pass</th></tr>\n");
    for c in &r.checks {
        row(h, c);
    }
    h.push_str("</table>\n");
    if let Some(animation) = &r.animation {
        let src = escape(animation);
        let _ = writeln!(
            h,
            "<h3>Animation</h3>\n<iframe class=\"animation\" src=\"{src}\" title=\"{} animation\"></iframe>\n<p><a href=\"{src}\">open the animation</a></p>",
            escape(&r.name)
        );
    }
    if !r.figures.is_empty() {
        h.push_str("<h3>Figures</h3>\n<div class=\"figures\">\n");
        for f in &r.figures {
            let _ = writeln!(
                h,
                "<figure><a href=\"{src}\"><img src=\"{src}\" alt=\"{cap}\" loading=\"lazy\"></a><figcaption>{cap}</figcaption></figure>",
                src = escape(&f.file),
                cap = escape(&f.caption)
            );
        }
        h.push_str("</div>\n");
    }
    if !r.notes.is_empty() {
        h.push_str("<ul class=\"notes\">\n");
        for n in &r.notes {
            let _ = writeln!(h, "<li>{}</li>", escape(n));
        }
        h.push_str("</ul>\n");
    }
    h.push_str("</section>\n");
}

fn row(h: &mut String, c: &CheckRow) {
    let (class, mark) = if c.passed {
        ("pass", "pass")
    } else {
        ("fail", "FAIL")
    };
    let computed = match (&c.computed, &c.note) {
        (None, Some(note)) => format!("<td>{}</td>", escape(note)),
        _ => format!("<td class=\"num\">{}</td>", number(c.computed)),
    };
    let _ = writeln!(
        h,
        "<tr{}><td>{}</td>{computed}<td class=\"num\">{}</td><td class=\"num\">{:.0e}</td><td class=\"{class}\">{mark}</td></tr>",
        if c.passed { "" } else { " class=\"failed\"" },
        escape(&c.check),
        number(Some(c.expected)),
        c.tolerance,
    );
}
