//! TOML files the simulator reads (scenarios, run configurations, campaigns): mistakes located
//! in the text ([`LocatedError`]: file, line, column, the field's dotted path, the line quoted
//! with a caret), and dotted-path edits of a document ([`set_path`]).

use std::collections::HashMap;
use std::ops::Range;
use std::path::PathBuf;

use toml::{Table, Value};

/// A mistake in a TOML file the simulator reads (a scenario, a run configuration, a campaign, or a
/// file one of them names), located in its text.
#[derive(Debug, thiserror::Error)]
pub enum LocatedError {
    /// The scenario file itself could not be read.
    #[error("{}: cannot read the scenario: {error}", path.display())]
    Io {
        /// The scenario file.
        path: PathBuf,
        /// The underlying error (in the message, not repeated as a source).
        error: std::io::Error,
    },
    /// A located mistake: syntax, unknown key, wrong type, bad value, inconsistent fields, a
    /// named file that cannot be read or parsed.
    #[error("{file}:{line}:{column}: `{field}`: {message}{snippet}")]
    Invalid {
        /// The file at fault (the scenario, or the pose file it names).
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column (characters).
        column: usize,
        /// The field, e.g. `obstacles[1].radius_m` (`(file)` for a top-level syntax error).
        field: String,
        /// What is wrong.
        message: String,
        /// The offending line quoted, with a caret under the column (starts with a newline).
        snippet: String,
    },
}

impl LocatedError {
    /// An error located at byte `span` of `text`, with the field given.
    pub(crate) fn at(
        file: &str,
        text: &str,
        span: Range<usize>,
        field: &str,
        message: String,
    ) -> Self {
        let (line, column, line_text) = locate(text, span.start);
        let width = text.get(span.clone()).map_or(1, |s| {
            s.lines().next().map_or(1, |l| l.chars().count().max(1))
        });
        let gutter = line.to_string().len();
        let snippet = format!(
            "\n {line} | {line_text}\n {:gutter$} | {:pad$}{}",
            "",
            "",
            "^".repeat(width.min(line_text.chars().count().saturating_sub(column - 1).max(1))),
            pad = column - 1
        );
        LocatedError::Invalid {
            file: file.to_string(),
            line,
            column,
            field: field.to_string(),
            message,
            snippet,
        }
    }

    /// An error from toml's deserializer: the field is read off the text around the span.
    pub(crate) fn toml(file: &str, text: &str, err: &toml::de::Error) -> Self {
        let span = err.span().unwrap_or(0..0);
        let start = floor_boundary(text, span.start);
        let field = field_at(text, start);
        LocatedError::at(
            file,
            text,
            start..span.end.max(start),
            &field,
            err.message().to_string(),
        )
    }
}

fn floor_boundary(text: &str, offset: usize) -> usize {
    let mut o = offset.min(text.len());
    while !text.is_char_boundary(o) {
        o -= 1;
    }
    o
}

/// 1-based line and column (in characters) of byte `offset`, and the text of that line.
fn locate(text: &str, offset: usize) -> (usize, usize, &str) {
    let offset = floor_boundary(text, offset);
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let line_end = text[offset..].find('\n').map_or(text.len(), |i| offset + i);
    let line = text[..offset].matches('\n').count() + 1;
    let column = text[line_start..offset].chars().count() + 1;
    (
        line,
        column,
        text[line_start..line_end].trim_end_matches('\r'),
    )
}

fn is_key_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.'
}

/// The dotted path of the field at byte `offset` of a TOML text, as `table[index].key`: the last
/// table header before it, and the key on its line (or the last key of a multi-line value).
/// A reading of the text for error messages, not a TOML parser.
fn field_at(text: &str, offset: usize) -> String {
    let mut header = String::new();
    let mut counts: HashMap<String, usize> = HashMap::new();
    let mut key: Option<String> = None;
    let mut line_start = 0;
    for raw in text.split_inclusive('\n') {
        if line_start > offset {
            break;
        }
        let line = raw.trim_end_matches(['\n', '\r']);
        let trimmed = line.trim_start();
        let on_error_line = offset < line_start + raw.len() || line_start + raw.len() == text.len();
        if let Some(name) = table_header(trimmed, "[[", "]]") {
            let n = counts.entry(name.clone()).or_insert(0);
            header = format!("{name}[{n}]");
            *n += 1;
            key = None;
        } else if let Some(name) = table_header(trimmed, "[", "]") {
            header = name;
            key = None;
        } else if on_error_line {
            let col = (offset - line_start).min(line.len());
            // A key starting at the offset (an unknown key's span starts there) counts too.
            let rest = &line[col..];
            let word_end = rest.find(|c: char| !is_key_char(c)).unwrap_or(rest.len());
            let prefix = if word_end > 0 && rest[word_end..].trim_start().starts_with('=') {
                format!("{}{} =", &line[..col], &rest[..word_end])
            } else {
                line[..col].to_string()
            };
            if let Some(k) = keys_before(&prefix) {
                key = Some(k);
            }
        } else if let Some(k) = keys_before(line) {
            // A key opening a line (its value may continue on the following lines).
            if line.starts_with(|c: char| is_key_char(c) || c == ' ') {
                key = Some(k.split('.').next().unwrap_or(&k).to_string());
            }
        }
        line_start += raw.len();
    }
    match (header.is_empty(), key) {
        (true, None) => "(file)".to_string(),
        (true, Some(k)) => k,
        (false, None) => header,
        (false, Some(k)) => format!("{header}.{k}"),
    }
}

/// The table name of a header line `[name]` or `[[name]]` (not of a line of an array value).
fn table_header(line: &str, open: &str, close: &str) -> Option<String> {
    let rest = line.strip_prefix(open)?;
    let (name, after) = rest.split_once(close)?;
    let after = after.trim_start();
    let name_ok = !name.trim().is_empty()
        && name
            .chars()
            .all(|c| is_key_char(c) || c == ' ' || c == '"' || c == '\'');
    (name_ok && (after.is_empty() || after.starts_with('#'))).then(|| name.trim().to_string())
}

/// The key path at the end of `prefix` (one line): inline-table keys joined with dots.
fn keys_before(prefix: &str) -> Option<String> {
    let mut stack: Vec<String> = Vec::new();
    let mut last: Option<String> = None;
    let mut word = String::new();
    let mut in_string: Option<char> = None;
    for c in prefix.chars() {
        if let Some(q) = in_string {
            if c == q {
                in_string = None;
            }
            continue;
        }
        match c {
            '"' | '\'' => in_string = Some(c),
            '#' => break,
            '=' => {
                if !word.is_empty() {
                    last = Some(std::mem::take(&mut word));
                }
            }
            '{' => {
                stack.push(last.take().unwrap_or_default());
                word.clear();
            }
            '}' => {
                last = stack.pop();
                word.clear();
            }
            c if is_key_char(c) => word.push(c),
            ' ' | '\t' => {}
            _ => word.clear(),
        }
    }
    let mut parts: Vec<String> = stack.into_iter().filter(|s| !s.is_empty()).collect();
    parts.extend(last);
    (!parts.is_empty()).then(|| parts.join("."))
}

/// Sets `value` at dotted `path` of `doc`: a table merges key by key into a table there.
pub fn set_path(doc: &mut Table, path: &str, value: Value) {
    let (head, rest) = match path.split_once('.') {
        Some((h, r)) => (h, Some(r)),
        None => (path, None),
    };
    match rest {
        Some(rest) => {
            let entry = doc
                .entry(head)
                .or_insert_with(|| Value::Table(Table::new()));
            if !entry.is_table() {
                *entry = Value::Table(Table::new());
            }
            if let Value::Table(t) = entry {
                set_path(t, rest, value);
            }
        }
        None => match (doc.get_mut(head), value) {
            (Some(Value::Table(old)), Value::Table(new)) => {
                for (k, v) in new {
                    set_path(old, &k, v);
                }
            }
            (_, v) => {
                doc.insert(head.to_string(), v);
            }
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_paths_read_off_the_text() {
        let text = "name = \"a\"\n[vehicle]\nstart = { x_m = 1, y_m = \"b\" }\n[[objects]]\nid = \"x\"\n[[objects]]\nradius_m = -1\n[route]\nwaypoints_m = [\n  [0, 0],\n  [1, nan],\n]\n";
        let at = |s: &str| field_at(text, text.find(s).expect("in text"));
        assert_eq!(at("\"b\""), "vehicle.start.y_m");
        assert_eq!(at("-1"), "objects[1].radius_m");
        assert_eq!(at("[1, nan]"), "route.waypoints_m");
        assert_eq!(at("\"a\""), "name");
    }
}
