//! How one value of a model file is read: a name, a text, an expression (with exact
//! locations, even across lines), a vector, a pair of points, one of a few words, a
//! positive number — each reporting a value of the wrong kind with an example.

use super::*;

/// More `(` than `)`: an expression that may have been cut at a `,`.
pub(super) fn opens_more_than_it_closes(text: &str) -> bool {
    text.matches('(').count() > text.matches(')').count()
}

/// Whether `text` closes a `(` it did not open: the rest of a cut expression.
pub(super) fn closes_first(text: &str) -> bool {
    let mut depth = 0usize;
    for c in text.chars() {
        match c {
            '(' => depth += 1,
            ')' if depth == 0 => return true,
            ')' => depth -= 1,
            _ => {}
        }
    }
    false
}

/// Whether the source after `end` is `, …)`: YAML ended a value at a `,` of a flow collection
/// (`{ angle: atan2(y, x) }`) and the rest of the expression follows.
pub(super) fn cut_in_source(source: &str, end: Location) -> bool {
    let Some(line) = source.lines().nth(end.line.saturating_sub(1) as usize) else {
        return false;
    };
    let byte = line
        .char_indices()
        .nth(end.column.saturating_sub(1) as usize)
        .map_or(line.len(), |(i, _)| i);
    let offset = source
        .lines()
        .take(end.line.saturating_sub(1) as usize)
        .map(|l| l.len() + 1)
        .sum::<usize>()
        + byte;
    let Some(rest) = source.get(offset..) else {
        return false;
    };
    let Some(after) = rest.trim_start().strip_prefix(',') else {
        return false;
    };
    let piece: String = after
        .chars()
        .take_while(|c| !matches!(c, ',' | ']' | '}'))
        .collect();
    closes_first(&piece)
}

impl Ctx<'_> {
    /// The items of the list `node`; reports anything else.
    pub(crate) fn seq<'n>(
        &mut self,
        node: &'n YamlNode,
        what: &str,
        example: &str,
    ) -> Option<&'n [YamlNode]> {
        match &node.kind {
            YamlKind::Seq(items) => Some(items),
            other => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!("{what} must be a list, found {}", other.describe()),
                    )
                    .with_help(format!("write it like `{example}`")),
                );
                None
            }
        }
    }

    /// The text of the scalar `node`; reports anything else.
    pub(super) fn text(
        &mut self,
        node: &YamlNode,
        what: &str,
        example: &str,
    ) -> Option<Located<String>> {
        match &node.kind {
            YamlKind::Scalar { text, .. } => Some(Located::new(text.clone(), node.location)),
            other => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!("{what} must be text, found {}", other.describe()),
                    )
                    .with_help(format!("write it like `{example}`")),
                );
                None
            }
        }
    }

    /// A name (identifier) written as a value, such as the point of `at: P`.
    pub(crate) fn name(&mut self, node: &YamlNode, what: &str) -> Option<Located<String>> {
        let t = match &node.kind {
            YamlKind::Scalar { text, .. } => Located::new(text.trim().to_string(), node.location),
            other => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!("{what} must be a name, found {}", other.describe()),
                    )
                    .with_help("a name starts with a letter and contains letters, digits and `_`"),
                );
                return None;
            }
        };
        if !is_identifier(&t.value) {
            self.error(
                Diagnostic::new(t.location, format!("{what} `{}` is not a name", t.value))
                    .with_help("a name starts with a letter and contains letters, digits and `_`"),
            );
            return None;
        }
        Some(t)
    }

    /// A name written as a key, such as a point's in `points: { P: … }`.
    pub(crate) fn key_name(&mut self, key: &Located<String>, what: &str) -> bool {
        if is_identifier(&key.value) {
            return true;
        }
        self.error(
            Diagnostic::new(
                key.location,
                format!("{what} `{}` is not a name", key.value),
            )
            .with_help("a name starts with a letter and contains letters, digits and `_`"),
        );
        false
    }

    /// An expression written as a scalar; its locations are exact even across lines.
    pub(crate) fn expr(&mut self, node: &YamlNode, what: &str) -> Option<Expr> {
        let text = self.scalar_expr_text(node, what)?;
        self.parse_part(node, &text, 0, text.chars().count())
    }

    /// The text of a scalar that should hold an expression; reports anything else.
    pub(super) fn scalar_expr_text(&mut self, node: &YamlNode, what: &str) -> Option<String> {
        let text = match &node.kind {
            YamlKind::Scalar { text, .. } => text,
            other => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!("{what} must be an expression, found {}", other.describe()),
                    )
                    .with_help("write a number or an expression such as `m*g*l*cos(theta)`"),
                );
                return None;
            }
        };
        Some(text.clone())
    }

    /// Parses characters `from..to` of the scalar `node` (whose text is `text`) as an
    /// expression, with exact file locations.
    pub(super) fn parse_part(
        &mut self,
        node: &YamlNode,
        text: &str,
        from: usize,
        to: usize,
    ) -> Option<Expr> {
        let start = node.location;
        let locations = char_locations_in_lines(&self.lines, start, text);
        let locate = |i: usize| match &locations {
            Some(l) => l.get(from + i).or(l.last()).copied().unwrap_or(start),
            None => start.offset(from + i),
        };
        let part: String = text.chars().skip(from).take(to - from).collect();
        match parse_expr_mapped(&part, &locate) {
            Ok(e) => Some(e),
            Err(d) => {
                let end = locate(part.chars().count());
                let cut = opens_more_than_it_closes(&part)
                    && !matches!(node.kind, YamlKind::Scalar { quoted: true, .. })
                    && cut_in_source(self.source, end);
                let d = if cut {
                    d.with_help(
                        "inside `[…]` or `{…}`, YAML splits values at every `,`: quote an expression that contains a `,`, as in `\"atan2(y, x)\"`",
                    )
                } else {
                    d
                };
                self.error(d);
                None
            }
        }
    }

    /// A list of 2 or 3 expressions.
    pub(crate) fn vector(
        &mut self,
        node: &YamlNode,
        what: &str,
        example: &str,
    ) -> Option<Vec<Expr>> {
        let items = match &node.kind {
            YamlKind::Seq(items) => items,
            other => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!(
                            "{what} must be a list of 2 or 3 expressions, found {}",
                            other.describe()
                        ),
                    )
                    .with_help(format!("write it like `{example}`")),
                );
                return None;
            }
        };
        // `[atan2(y, x), 0]` reaches us as `atan2(y`, `x)`, `0`: say so rather than count.
        let cut = items
            .iter()
            .enumerate()
            .find(|(i, item)| {
                let unquoted = |n: &YamlNode| match &n.kind {
                    YamlKind::Scalar {
                        text,
                        quoted: false,
                    } => Some(text.clone()),
                    _ => None,
                };
                unquoted(item).is_some_and(|t| opens_more_than_it_closes(&t))
                    && items
                        .get(i + 1)
                        .and_then(unquoted)
                        .is_some_and(|t| closes_first(&t))
            })
            .map(|(_, item)| item);
        if let Some(item) = cut {
            self.error(
                Diagnostic::new(
                    item.location,
                    format!(
                        "{what}: {} is cut at a `,`",
                        item.kind.describe()
                    ),
                )
                .with_help(
                    "inside `[…]`, YAML splits values at every `,`: quote a component that contains a `,`, as in `\"atan2(y, x)\"`",
                ),
            );
            return None;
        }
        if !(2..=3).contains(&items.len()) {
            self.error(
                Diagnostic::new(
                    node.location,
                    format!(
                        "{what} has {} component{}; expected 2 (planar) or 3 (spatial)",
                        items.len(),
                        if items.len() == 1 { "" } else { "s" }
                    ),
                )
                .with_help(format!("write it like `{example}`")),
            );
            return None;
        }
        let out: Vec<Option<Expr>> = items.iter().map(|i| self.expr(i, what)).collect();
        out.into_iter().collect()
    }

    /// `[A, B]`: two point names.
    pub(crate) fn point_pair(
        &mut self,
        node: &YamlNode,
        what: &str,
    ) -> Option<[Located<String>; 2]> {
        let items = self.seq(node, what, "[A, B]")?;
        if items.len() != 2 {
            self.error(
                Diagnostic::new(
                    node.location,
                    format!("{what} must name two points, found {}", items.len()),
                )
                .with_help("write it like `[A, B]`"),
            );
            return None;
        }
        let a = self.name(&items[0], "a point");
        let b = self.name(&items[1], "a point");
        Some([a?, b?])
    }

    /// Axes of a frame: `x`, `y` or `z` (one, for `axis`, `along` or `axle`), or a word of
    /// them (`zxz`, for a frame's successive rotations, `axes`).
    pub(crate) fn axes(&mut self, node: &YamlNode, single: bool) -> Option<Vec<Located<Axis>>> {
        let what = if single { "`axis`" } else { "`axes`" };
        let text = match &node.kind {
            YamlKind::Scalar { text, .. } => text.trim().to_string(),
            _ => String::new(),
        };
        let axes: Option<Vec<Located<Axis>>> = text
            .chars()
            .enumerate()
            .map(|(i, c)| {
                let axis = match c {
                    'x' => Axis::X,
                    'y' => Axis::Y,
                    'z' => Axis::Z,
                    _ => return None,
                };
                Some(Located::new(axis, node.location.offset(i)))
            })
            .collect();
        match axes {
            Some(a) if !a.is_empty() && (!single || a.len() == 1) => Some(a),
            _ => {
                let help = if single {
                    "a simple rotation is about the `x`, `y` or `z` axis (write `axis: z`; to turn the other way, negate the angle)"
                } else {
                    "write the axes of the successive rotations as one word of `x`, `y` and `z`, as in `axes: zxz` (Euler angles) or `axes: zyx` (yaw, pitch, roll)"
                };
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!(
                            "{what} must be {}, found {}",
                            if single {
                                "x, y or z"
                            } else {
                                "a word of x, y and z"
                            },
                            node.kind.describe()
                        ),
                    )
                    .with_help(help),
                );
                None
            }
        }
    }

    /// One of a few words, as a scalar; an error lists them (with a "did you mean").
    pub(crate) fn choice<T: Copy>(
        &mut self,
        node: &YamlNode,
        what: &str,
        options: &[(&str, T)],
    ) -> Option<T> {
        let words: Vec<&str> = options.iter().map(|(w, _)| *w).collect();
        let text = match &node.kind {
            YamlKind::Scalar { text, .. } => text.trim(),
            _ => "",
        };
        if let Some((_, value)) = options.iter().find(|(w, _)| *w == text) {
            return Some(*value);
        }
        let help = match closest(text, &words) {
            Some(c) if !text.is_empty() => format!("did you mean `{c}`?"),
            _ => format!("write one of: {}", words.join(", ")),
        };
        self.error(
            Diagnostic::new(
                node.location,
                format!(
                    "{what} must be one of {}, found {}",
                    words.join(", "),
                    node.kind.describe()
                ),
            )
            .with_help(help),
        );
        None
    }

    /// A positive finite number written as a plain scalar (`1e-9`).
    pub(super) fn positive_number(&mut self, node: &YamlNode, what: &str) -> Option<f64> {
        let value = match &node.kind {
            YamlKind::Scalar { text, .. } => text.trim().parse::<f64>().ok(),
            _ => None,
        };
        match value {
            Some(v) if v.is_finite() && v > 0.0 => Some(v),
            _ => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!(
                            "{what} must be a positive number, found {}",
                            node.kind.describe()
                        ),
                    )
                    .with_help("write a number such as `1e-9`"),
                );
                None
            }
        }
    }

    /// The optional positive number `key` of `f`, `default` when absent.
    pub(super) fn number_or(
        &mut self,
        f: &Entries,
        key: &str,
        what: &str,
        default: f64,
    ) -> Option<f64> {
        match get(f, key) {
            None => Some(default),
            Some(n) => self.positive_number(n, &format!("`{key}` of {what}")),
        }
    }

    /// A list of expressions.
    pub(crate) fn expr_list(
        &mut self,
        node: &YamlNode,
        what: &str,
        example: &str,
    ) -> Option<Vec<Expr>> {
        let items = self.seq(node, what, example)?;
        let mut out = Vec::with_capacity(items.len());
        let mut complete = true;
        for item in items {
            match self.expr(item, &format!("a value of {what}")) {
                Some(e) => out.push(e),
                None => complete = false,
            }
        }
        complete.then_some(out)
    }

    /// The two sides of `lhs = rhs` in the scalar `node`, or the expression alone (`rhs`
    /// `None`) when it has no `=`. `what` names the value and `help` says what to write when
    /// it has two `=`.
    pub(super) fn sides(
        &mut self,
        node: &YamlNode,
        what: &str,
        help: &str,
    ) -> Option<(Expr, Option<Expr>)> {
        let text = self.scalar_expr_text(node, what)?;
        let chars: Vec<char> = text.chars().collect();
        let equals: Vec<usize> = (0..chars.len()).filter(|&i| chars[i] == '=').collect();
        match equals.as_slice() {
            [] => Some((self.parse_part(node, &text, 0, chars.len())?, None)),
            [i] => {
                let lhs = self.parse_part(node, &text, 0, *i);
                let rhs = self.parse_part(node, &text, i + 1, chars.len());
                Some((lhs?, Some(rhs?)))
            }
            [_, second, ..] => {
                let start = node.location;
                let at = char_locations_in_lines(&self.lines, start, &text)
                    .and_then(|l| l.get(*second).copied())
                    .unwrap_or_else(|| start.offset(*second));
                self.error(
                    Diagnostic::new(at, format!("{what} has one `=`, this is a second"))
                        .with_help(help),
                );
                None
            }
        }
    }
}
