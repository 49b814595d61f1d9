//! Mitsuba 3's XML into one owned element tree: `<include>`s spliced in, `<default>`s and
//! `$name` substituted into every attribute, `<path>` folders collected, every element and
//! attribute keeping its file and `Span`.

use std::path::{Path, PathBuf};

use crate::assets::{Assets, TooLarge};
use crate::desc::Span;
use crate::diagnostic::{Diagnostics, SceneError};
use crate::limits::Limits;

use super::Files;

/// How deep `<include>`s may nest: deeper is a cycle or a mistake (Mitsuba stops too).
const MAX_INCLUDE_DEPTH: usize = 15;

/// Elements of all files together, far above any real scene.
const MAX_ELEMENTS: usize = 5_000_000;

/// One element of the scene, from whichever file it came.
#[derive(Clone, Debug)]
pub(crate) struct Element {
    /// Unique over the whole load: what shared objects are remembered by.
    pub index: usize,
    pub tag: String,
    pub file: usize,
    pub span: Span,
    pub attributes: Vec<Attribute>,
    pub children: Vec<Element>,
}

/// An attribute after `$name` substitution.
#[derive(Clone, Debug)]
pub(crate) struct Attribute {
    pub name: String,
    pub value: String,
    /// Where its value starts.
    pub span: Span,
}

impl Element {
    pub fn attribute(&self, name: &str) -> Option<&Attribute> {
        self.attributes
            .iter()
            .find(|attribute| attribute.name == name)
    }

    pub fn value(&self, name: &str) -> Option<&str> {
        self.attribute(name)
            .map(|attribute| attribute.value.as_str())
    }
}

/// What parsing gives: the root `<scene>` and the folders `<path>` added, newest first.
pub(crate) struct Parsed {
    pub root: Element,
    pub search_paths: Vec<PathBuf>,
}

struct Parser<'a> {
    files: &'a mut Files,
    assets: &'a dyn Assets,
    limits: &'a Limits,
    /// `$name` values: the caller's defines first, then `<default>`s not already defined.
    parameters: Vec<(String, String)>,
    search_paths: Vec<PathBuf>,
    /// Files being read, outermost first: an include of one of them is a cycle.
    stack: Vec<PathBuf>,
    elements: usize,
    /// What the files' parses hold, all of them together.
    memory: crate::limits::MemoryBudget,
}

/// Parses the scene file `files[0]` and what it includes.
pub(crate) fn parse(
    files: &mut Files,
    defines: &[(String, String)],
    assets: &dyn Assets,
    limits: &Limits,
) -> Result<Parsed, SceneError> {
    let mut parser = Parser {
        parameters: defines.to_vec(),
        files,
        assets,
        limits,
        search_paths: Vec::new(),
        stack: Vec::new(),
        elements: 0,
        memory: crate::limits::MemoryBudget::new(limits),
    };
    let mut roots = parser.parse_file(0)?;
    let root = roots.pop().expect("a file parses into its root element");
    if root.tag != "scene" {
        return Err(parser.files.error(
            root.file,
            root.span,
            "the root element of a Mitsuba scene must be <scene>",
        ));
    }
    let search_paths = parser.search_paths;
    Ok(Parsed { root, search_paths })
}

impl Parser<'_> {
    /// The root element of file `file`, as a one-element list.
    fn parse_file(&mut self, file: usize) -> Result<Vec<Element>, SceneError> {
        let text = self.files.text(file);
        let path = self.files.path(file).to_path_buf();
        let diagnostics = Diagnostics::new(&path, &text);
        crate::xml::check_nesting(&text, &diagnostics, &mut self.memory)?;
        let document = roxmltree::Document::parse(&text).map_err(|error| {
            let span = match error {
                roxmltree::Error::UnexpectedEndOfStream | roxmltree::Error::UnclosedRootNode => {
                    diagnostics.span_at(text.len())
                }
                _ => Span {
                    line: error.pos().row,
                    column: error.pos().col,
                },
            };
            let message = error
                .to_string()
                .replace(&format!(" at {}", error.pos()), "");
            diagnostics.error(span, format!("malformed XML: {message}"))
        })?;
        self.stack.push(path);
        let root = self.convert(document.root_element(), file, &diagnostics, 0)?;
        self.stack.pop();
        Ok(root.into_iter().collect())
    }

    /// One element and its children; `None` for the elements that only act while parsing
    /// (`default`, `path`) and for includes, whose elements go to `out` instead.
    fn convert(
        &mut self,
        node: roxmltree::Node,
        file: usize,
        diagnostics: &Diagnostics,
        depth: usize,
    ) -> Result<Option<Element>, SceneError> {
        let mut out = Vec::new();
        self.convert_into(node, file, diagnostics, depth, &mut out)?;
        Ok(out.pop())
    }

    fn convert_into(
        &mut self,
        node: roxmltree::Node,
        file: usize,
        diagnostics: &Diagnostics,
        depth: usize,
        out: &mut Vec<Element>,
    ) -> Result<(), SceneError> {
        let span = diagnostics.span_at(node.range().start);
        if depth > crate::xml::MAX_NESTING {
            return Err(diagnostics.error(span, "elements nested too deep; not a scene file"));
        }
        self.elements += 1;
        if self.elements > MAX_ELEMENTS {
            return Err(diagnostics.error(span, "too many elements; not a scene file"));
        }
        let tag = node.tag_name().name().to_owned();
        let mut attributes = Vec::new();
        for attribute in node.attributes() {
            let value_span = diagnostics.span_at(attribute.range_value().start);
            let value = self.substitute(attribute.value(), value_span, diagnostics)?;
            attributes.push(Attribute {
                name: attribute.name().to_owned(),
                value,
                span: value_span,
            });
        }
        let element = Element {
            index: self.elements,
            tag,
            file,
            span,
            attributes,
            children: Vec::new(),
        };
        match element.tag.as_str() {
            "default" => {
                let (name, value) = (
                    required(&element, "name", diagnostics)?,
                    required(&element, "value", diagnostics)?,
                );
                if name.is_empty() {
                    return Err(diagnostics.error(span, "<default> needs a non-empty name"));
                }
                // A define from the caller (or an earlier default) wins, as Mitsuba's -D does.
                if !self.parameters.iter().any(|(key, _)| key == name) {
                    self.parameters.push((name.to_owned(), value.to_owned()));
                }
                return Ok(());
            }
            "path" => {
                let value = required(&element, "value", diagnostics)?;
                let folder = Path::new(value);
                let folder = if folder.is_absolute() {
                    folder.to_path_buf()
                } else {
                    self.files.folder(file).join(folder)
                };
                // Newest first, as Mitsuba's file resolver prepends.
                self.search_paths.insert(0, folder);
                return Ok(());
            }
            "include" => return self.include(&element, diagnostics, out),
            _ => {}
        }
        let mut element = element;
        let mut children = Vec::new();
        for child in node.children() {
            if child.is_element() {
                self.convert_into(child, file, diagnostics, depth + 1, &mut children)?;
            } else if child.is_text() && child.text().is_some_and(|text| !text.trim().is_empty()) {
                let at = diagnostics.span_at(child.range().start);
                return Err(
                    diagnostics.error(at, "Mitsuba scenes put values in attributes, not text")
                );
            }
        }
        element.children = children;
        out.push(element);
        Ok(())
    }

    /// Splices an included file's elements into `out`: a `<scene>` root's children, or the
    /// root itself.
    fn include(
        &mut self,
        element: &Element,
        diagnostics: &Diagnostics,
        out: &mut Vec<Element>,
    ) -> Result<(), SceneError> {
        let name = required(element, "filename", diagnostics)?;
        let span = element
            .attribute("filename")
            .map_or(element.span, |a| a.span);
        if self.stack.len() > MAX_INCLUDE_DEPTH {
            return Err(diagnostics.error(
                span,
                format!("includes nested more than {MAX_INCLUDE_DEPTH} deep"),
            ));
        }
        // Mitsuba's resolver, as its parser builds it for an include: the including file's
        // folder, the folders of the files that include that one (innermost first), the
        // `<path>` folders (newest first), then the scene's own folder.
        let mut candidates = vec![self.files.folder(element.file).join(name)];
        // `stack` runs from the scene file to the including one, both named elsewhere.
        let between = self.stack.get(1..self.stack.len().saturating_sub(1));
        candidates.extend(
            between
                .unwrap_or_default()
                .iter()
                .rev()
                .map(|file| file.parent().unwrap_or(Path::new("")).join(name)),
        );
        candidates.extend(self.search_paths.iter().map(|folder| folder.join(name)));
        candidates.push(self.files.folder(0).join(name));
        let Some(path) = candidates
            .iter()
            .find(|path| self.assets.exists(path))
            .cloned()
        else {
            return Err(diagnostics.error(span, format!("included file \"{name}\" not found")));
        };
        let normal = lexical(&path);
        if self.stack.iter().any(|open| lexical(open) == normal) {
            return Err(diagnostics.error(
                span,
                format!(
                    "\"{name}\" includes itself (through {} file(s))",
                    self.stack.len()
                ),
            ));
        }
        let bytes = self
            .assets
            .read_at_most(&path, self.limits.max_file_bytes)
            .map_err(|error| {
                let why = match TooLarge::of(&error) {
                    Some(too_large) => format!("{too_large} (--max-file-size raises it)"),
                    None => error.to_string(),
                };
                diagnostics.error(span, format!("cannot read included file \"{name}\": {why}"))
            })?;
        let text = String::from_utf8(bytes).map_err(|_| {
            diagnostics.error(span, format!("included file \"{name}\" is not UTF-8 text"))
        })?;
        let text = text
            .strip_prefix('\u{feff}')
            .map(str::to_owned)
            .unwrap_or(text);
        let index = self.files.add(path, text);
        let mut roots = self.parse_file(index)?;
        let root = roots.pop().expect("a file parses into its root element");
        if root.tag == "scene" {
            out.extend(root.children);
        } else {
            out.push(root);
        }
        Ok(())
    }

    /// `value` with every `$name` replaced, longest names first as Mitsuba does; a `$` left
    /// over is an undefined parameter. `\$` stays a dollar sign.
    fn substitute(
        &self,
        value: &str,
        span: Span,
        diagnostics: &Diagnostics,
    ) -> Result<String, SceneError> {
        if !value.contains('$') {
            return Ok(value.to_owned());
        }
        let mut parameters: Vec<&(String, String)> = self.parameters.iter().collect();
        parameters.sort_by_key(|(key, _)| std::cmp::Reverse(key.len()));
        let mut text = value.to_owned();
        for (key, replacement) in parameters {
            let pattern = format!("${key}");
            let mut from = 0;
            while let Some(found) = text[from..].find(&pattern) {
                let at = from + found;
                if at > 0 && text.as_bytes()[at - 1] == b'\\' {
                    from = at + pattern.len();
                    continue;
                }
                text.replace_range(at..at + pattern.len(), replacement);
                // Past the replacement: a value naming itself is not expanded again.
                from = at + replacement.len();
                if text.len() > 1 << 20 {
                    return Err(diagnostics.error(span, "the value grows too long by substitution"));
                }
            }
        }
        let bytes = text.as_bytes();
        for (at, &byte) in bytes.iter().enumerate() {
            if byte == b'$' && !(at > 0 && bytes[at - 1] == b'\\') {
                let name: String = text[at + 1..]
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                    .collect();
                return Err(diagnostics.error(span, format!("undefined parameter: ${name}")));
            }
        }
        Ok(text.replace("\\$", "$"))
    }
}

/// The value of attribute `name`, or a located error.
fn required<'e>(
    element: &'e Element,
    name: &str,
    diagnostics: &Diagnostics,
) -> Result<&'e str, SceneError> {
    element.value(name).ok_or_else(|| {
        diagnostics.error(
            element.span,
            format!("<{}> needs a `{name}` attribute", element.tag),
        )
    })
}

/// `path` with `.` dropped and `..` applied, to compare files without a file system.
fn lexical(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for component in path.components() {
        match component {
            std::path::Component::CurDir => {}
            std::path::Component::ParentDir => {
                if !out.pop() {
                    out.push("..");
                }
            }
            other => out.push(other),
        }
    }
    out
}
