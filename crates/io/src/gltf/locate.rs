//! Where a value of a glTF file's JSON is: the line and column of a path such as
//! `meshes[0].primitives[1].attributes["POSITION"]`, so that every error the importer raises
//! points into the file. serde keeps no positions; jsonc-parser's syntax tree does.

use jsonc_parser::ast;
use jsonc_parser::common::Ranged;

use crate::desc::Span;
use crate::diagnostic::Diagnostics;

/// The JSON's syntax tree, parsed once (lazily: only a load that reports something pays).
pub(crate) struct Locator<'text> {
    text: &'text str,
    tree: std::cell::OnceCell<Option<ast::Value<'text>>>,
}

/// One step of a path.
#[derive(Debug, PartialEq)]
enum Step<'a> {
    Field(&'a str),
    Index(usize),
}

impl<'text> Locator<'text> {
    pub(crate) fn new(text: &'text str) -> Locator<'text> {
        Locator {
            text,
            tree: std::cell::OnceCell::new(),
        }
    }

    /// The place of the value at `path`, or of the deepest part of it that exists (a missing
    /// member is reported at its object); line 1, column 1 when nothing can be found.
    pub(crate) fn span(&self, path: &str, diagnostics: &Diagnostics) -> Span {
        let tree = self.tree.get_or_init(|| {
            jsonc_parser::parse_to_ast(
                self.text,
                &jsonc_parser::CollectOptions::default(),
                &jsonc_parser::ParseOptions::default(),
            )
            .ok()
            .and_then(|result| result.value)
        });
        let Some(mut value) = tree.as_ref() else {
            return Span { line: 1, column: 1 };
        };
        let mut start = value.start();
        for step in steps(path) {
            let next = match (value, step) {
                (ast::Value::Object(object), Step::Field(name)) => object
                    .properties
                    .iter()
                    .find(|p| p.name.as_str() == name)
                    .map(|p| &p.value),
                (ast::Value::Array(array), Step::Index(i)) => array.elements.get(i),
                _ => None,
            };
            match next {
                Some(next) => {
                    value = next;
                    start = next.start();
                }
                None => break,
            }
        }
        diagnostics.span_at(start)
    }
}

/// `a.b[2]["c"]` as its steps; `value_str` suffixes (`: "x"`) that gltf-json appends are
/// dropped.
fn steps(path: &str) -> Vec<Step<'_>> {
    let mut out = Vec::new();
    let mut rest = path;
    while !rest.is_empty() {
        if let Some(r) = rest.strip_prefix('.') {
            rest = r;
            continue;
        }
        if let Some(r) = rest.strip_prefix("[\"") {
            let end = r.find("\"]").unwrap_or(r.len());
            out.push(Step::Field(&r[..end]));
            rest = r.get(end + 2..).unwrap_or("");
        } else if let Some(r) = rest.strip_prefix('[') {
            let end = r.find(']').unwrap_or(r.len());
            match r[..end].parse() {
                Ok(i) => out.push(Step::Index(i)),
                Err(_) => break,
            }
            rest = r.get(end + 1..).unwrap_or("");
        } else {
            let end = rest.find(['.', '[', ' ', ':']).unwrap_or(rest.len());
            if end == 0 {
                break;
            }
            out.push(Step::Field(&rest[..end]));
            rest = &rest[end..];
            if rest.starts_with([' ', ':']) {
                break;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn paths_split_into_steps() {
        assert_eq!(
            steps("meshes[0].primitives[12].attributes[\"POSITION\"]"),
            vec![
                Step::Field("meshes"),
                Step::Index(0),
                Step::Field("primitives"),
                Step::Index(12),
                Step::Field("attributes"),
                Step::Field("POSITION"),
            ]
        );
        assert_eq!(steps("asset"), vec![Step::Field("asset")]);
    }

    #[test]
    fn a_path_finds_its_line_and_column() {
        let text = "{\n  \"meshes\": [\n    {\"primitives\": [{\"attributes\": {\"POSITION\": 7}}]}\n  ]\n}";
        let diagnostics = Diagnostics::new(Path::new("m.gltf"), text);
        let locator = Locator::new(text);
        let span = locator.span(
            "meshes[0].primitives[0].attributes[\"POSITION\"]",
            &diagnostics,
        );
        assert_eq!((span.line, span.column), (3, 49));
        // A missing member is reported at the deepest value that exists.
        let span = locator.span("meshes[0].primitives[3]", &diagnostics);
        assert_eq!((span.line, span.column), (3, 20));
    }
}
