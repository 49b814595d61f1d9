//! Course JSON (FORMAT.md 3) into the located tree, with jsonc-parser: its AST keeps the byte
//! range of every value, which serde-style parsers throw away.
//!
//! The JSON accepted is RFC 8259 plus two extensions hand-edited files sometimes have: comments
//! (`// ...` and `/* ... */`) and trailing commas. Everything else jsonc-parser could be lenient
//! about is refused with a located error: unquoted or numeric keys (`{camera: ...}`) and
//! single-quoted strings (`'red'`).

use std::borrow::Cow;

use jsonc_parser::ast;
use jsonc_parser::common::Ranged;

use crate::diagnostic::{Diagnostics, SceneError};
use crate::limits::{MemoryBudget, JSON_BYTES_PER_VALUE, TEXT_BYTES_PER_BYTE};
use crate::tree::{Node, Value};

/// Parses `text` into jsonc-parser's syntax tree of its top-level value; `tree` makes the
/// located tree of it, borrowing its keys and strings.
pub(crate) fn parse<'text>(
    text: &'text str,
    diagnostics: &Diagnostics,
    memory: &mut MemoryBudget,
) -> Result<ast::Value<'text>, SceneError> {
    check_nesting(text, diagnostics, memory)?;
    let options = jsonc_parser::ParseOptions {
        allow_comments: true,
        allow_trailing_commas: true,
        allow_loose_object_property_names: false,
    };
    let result =
        jsonc_parser::parse_to_ast(text, &jsonc_parser::CollectOptions::default(), &options)
            .map_err(|error| {
                diagnostics.error(
                    diagnostics.span_at(error.range().start),
                    format!("malformed JSON: {}", error.kind()),
                )
            })?;
    let value = result.value.ok_or_else(|| {
        diagnostics.error(
            diagnostics.span_at(text.len()),
            "malformed JSON: the file holds no value",
        )
    })?;
    check_commas(&value, text, diagnostics)?;
    Ok(value)
}

/// Refuses two members of an object, or two elements of an array, with no comma between
/// them, which jsonc-parser lets through: RFC 8259 requires it, and a missing comma is the
/// commonest slip in a hand-edited file. The error is at the end of the value the comma
/// should follow. The recursion is as deep as the nesting, which `check_nesting` bounds.
fn check_commas(
    value: &ast::Value<'_>,
    text: &str,
    diagnostics: &Diagnostics,
) -> Result<(), SceneError> {
    let missing = |before: usize, after: usize, closer: char, what: &str| {
        let next = diagnostics.span_at(after);
        diagnostics.error(
            diagnostics.span_at(before),
            format!(
                "malformed JSON: expected `,` or `{closer}` here: a comma is missing before the \
                 next {what} (line {}, column {})",
                next.line, next.column
            ),
        )
    };
    match value {
        ast::Value::Object(object) => {
            for pair in object.properties.windows(2) {
                let (end, start) = (pair[0].range.end, pair[1].range.start);
                if !has_comma(&text[end..start]) {
                    return Err(missing(end, start, '}', "member"));
                }
            }
            for property in &object.properties {
                check_commas(&property.value, text, diagnostics)?;
            }
        }
        ast::Value::Array(array) => {
            for pair in array.elements.windows(2) {
                let (end, start) = (pair[0].end(), pair[1].start());
                if !has_comma(&text[end..start]) {
                    return Err(missing(end, start, ']', "element"));
                }
            }
            for element in &array.elements {
                check_commas(element, text, diagnostics)?;
            }
        }
        _ => {}
    }
    Ok(())
}

/// Whether `between`, the text between two values that jsonc-parser read one after the other
/// (white space, comments and commas only), holds a comma outside its comments.
fn has_comma(between: &str) -> bool {
    let bytes = between.as_bytes();
    let mut index = 0;
    while index < bytes.len() {
        match bytes[index] {
            b',' => return true,
            b'/' if bytes.get(index + 1) == Some(&b'/') => {
                while index < bytes.len() && bytes[index] != b'\n' {
                    index += 1;
                }
            }
            b'/' if bytes.get(index + 1) == Some(&b'*') => {
                index += 2;
                while index < bytes.len() && !bytes[index..].starts_with(b"*/") {
                    index += 1;
                }
                index += 1;
            }
            _ => {}
        }
        index += 1;
    }
    false
}

/// The top-level value as a node with an empty key.
pub(crate) fn tree<'a>(value: &'a ast::Value<'_>, diagnostics: &Diagnostics) -> Node<'a> {
    let span = diagnostics.span_at(value.start());
    Node::new("", span, span, convert(value, diagnostics))
}

/// Far deeper than any scene needs (the course's deepest is 5). jsonc-parser descends
/// recursively, so a file nested thousands deep would overflow the stack before it could report
/// anything; such files are refused up front.
pub(crate) const MAX_NESTING: usize = 100;

/// Counts brackets outside strings and comments, and fails where the nesting gets too deep,
/// where a string is single-quoted (which jsonc-parser would accept), or where what the parse
/// will hold (`memory`, charged with the text and each value) passes the memory budget: a
/// value starts after each `[`, `{`, `:` and `,`, so counting those bounds the values from
/// above before jsonc-parser builds any of them.
fn check_nesting(
    text: &str,
    diagnostics: &Diagnostics,
    memory: &mut MemoryBudget,
) -> Result<(), SceneError> {
    let bytes = text.as_bytes();
    let over_budget = |memory: &MemoryBudget, index: usize| {
        diagnostics.error(
            diagnostics.span_at(index),
            memory.refusal("the file's values"),
        )
    };
    if !memory.charge(
        (bytes.len() as u64)
            .saturating_mul(TEXT_BYTES_PER_BYTE)
            .saturating_add(JSON_BYTES_PER_VALUE),
    ) {
        return Err(over_budget(memory, 0));
    }
    let mut depth = 0usize;
    let mut index = 0;
    while index < bytes.len() {
        match bytes[index] {
            b'\'' => {
                return Err(diagnostics.error(
                    diagnostics.span_at(index),
                    "malformed JSON: strings must be in double quotes (\"...\"), not single quotes",
                ))
            }
            quote @ b'"' => {
                index += 1;
                while index < bytes.len() && bytes[index] != quote {
                    index += if bytes[index] == b'\\' { 2 } else { 1 };
                }
            }
            b'/' if bytes.get(index + 1) == Some(&b'/') => {
                while index < bytes.len() && bytes[index] != b'\n' {
                    index += 1;
                }
            }
            b'/' if bytes.get(index + 1) == Some(&b'*') => {
                index += 2;
                while index < bytes.len() && !bytes[index..].starts_with(b"*/") {
                    index += 1;
                }
                index += 1;
            }
            b':' | b',' if !memory.charge(JSON_BYTES_PER_VALUE) => {
                return Err(over_budget(memory, index));
            }
            b'{' | b'[' => {
                if !memory.charge(JSON_BYTES_PER_VALUE) {
                    return Err(over_budget(memory, index));
                }
                depth += 1;
                if depth > MAX_NESTING {
                    return Err(diagnostics.error(
                        diagnostics.span_at(index),
                        format!("nested more than {MAX_NESTING} levels deep; not a scene file"),
                    ));
                }
            }
            b'}' | b']' => depth = depth.saturating_sub(1),
            _ => {}
        }
        index += 1;
    }
    Ok(())
}

fn convert<'a>(value: &'a ast::Value<'_>, diagnostics: &Diagnostics) -> Value<'a> {
    match value {
        ast::Value::StringLit(string) => Value::Text(Cow::Borrowed(&string.value)),
        ast::Value::NumberLit(number) => Value::Number(Cow::Borrowed(number.value)),
        ast::Value::BooleanLit(boolean) => Value::Bool(boolean.value),
        ast::Value::NullKeyword(_) => Value::Null,
        ast::Value::Array(array) => Value::List(
            array
                .elements
                .iter()
                .map(|element| {
                    let span = diagnostics.span_at(element.start());
                    Node::new("", span, span, convert(element, diagnostics))
                })
                .collect(),
        ),
        ast::Value::Object(object) => {
            let mut entries = Vec::new();
            for property in &object.properties {
                let name = property.name.as_str();
                let key_span = diagnostics.span_at(property.name.start());
                match &property.value {
                    // The converter's repeated elements (FORMAT.md 3.1): one entry per element.
                    ast::Value::Array(array)
                        if array
                            .elements
                            .iter()
                            .any(|element| matches!(element, ast::Value::Object(_))) =>
                    {
                        for element in &array.elements {
                            entries.push(Node::new(
                                name,
                                key_span,
                                diagnostics.span_at(element.start()),
                                convert(element, diagnostics),
                            ));
                        }
                    }
                    value => entries.push(Node::new(
                        name,
                        key_span,
                        diagnostics.span_at(value.start()),
                        convert(value, diagnostics),
                    )),
                }
            }
            Value::Object(entries)
        }
    }
}
