//! Course XML (FORMAT.md 2) into the located tree, with roxmltree.

use std::borrow::Cow;

use crate::desc::Span;
use crate::diagnostic::{Diagnostics, SceneError};
use crate::limits::{
    MemoryBudget, TEXT_BYTES_PER_BYTE, XML_BYTES_PER_ATTRIBUTE, XML_BYTES_PER_TAG,
};
use crate::tree::{Node, Value, TEXT_KEY};

/// Parses `text` and returns the root element as a node keyed by its tag name.
pub(crate) fn parse<'text>(
    text: &'text str,
    diagnostics: &Diagnostics,
    memory: &mut MemoryBudget,
) -> Result<Node<'text>, SceneError> {
    check_nesting(text, diagnostics, memory)?;
    let document = roxmltree::Document::parse(text).map_err(|error| {
        let span = match error {
            // roxmltree has no position for these and says 1:1; the problem is where the text
            // stops (a truncated file).
            roxmltree::Error::UnexpectedEndOfStream | roxmltree::Error::UnclosedRootNode => {
                diagnostics.span_at(text.len())
            }
            _ => {
                let position = error.pos();
                Span {
                    line: position.row,
                    column: position.col,
                }
            }
        };
        // roxmltree puts " at line:col" into its messages; the diagnostic says where already.
        let message = error
            .to_string()
            .replace(&format!(" at {}", error.pos()), "");
        diagnostics.error(span, format!("malformed XML: {message}"))
    })?;
    convert_element(document.root_element(), text, diagnostics, 0)
}

/// Far deeper than any scene needs (the course's deepest is 4). roxmltree and the conversion
/// below descend recursively, so a file nested thousands deep would overflow the stack before
/// it could report anything; such files are refused up front.
pub(crate) const MAX_NESTING: usize = 100;

/// Counts open and close tags outside comments, CDATA and declarations, and fails where the
/// nesting gets too deep, or where what the parse will hold (`memory`, charged with the text,
/// each tag and each attribute) passes the memory budget: so a file of millions of elements
/// is refused, at the element where the budget ran out, before roxmltree builds anything.
/// Malformed markup is left for roxmltree to report.
pub(crate) fn check_nesting(
    text: &str,
    diagnostics: &Diagnostics,
    memory: &mut MemoryBudget,
) -> Result<(), SceneError> {
    match scan(text.as_bytes(), memory) {
        None => Ok(()),
        Some(Stop::TooDeep(start)) => Err(diagnostics.error(
            diagnostics.span_at(start),
            format!("elements nested more than {MAX_NESTING} levels deep; not a scene file"),
        )),
        Some(Stop::OverBudget(start)) => Err(diagnostics.error(
            diagnostics.span_at(start),
            memory.refusal("the file's elements"),
        )),
    }
}

/// Where and why `scan` stopped a file.
#[derive(Debug, PartialEq)]
enum Stop {
    /// The open tag that nests deeper than `MAX_NESTING` starts here.
    TooDeep(usize),
    /// The tag where the memory budget ran out starts here.
    OverBudget(usize),
}

/// Where the open tag that nests deeper than `MAX_NESTING` starts, if one does.
#[cfg(test)]
fn too_deep(bytes: &[u8]) -> Option<usize> {
    match scan(bytes, &mut MemoryBudget::unlimited()) {
        Some(Stop::TooDeep(start)) => Some(start),
        _ => None,
    }
}

fn scan(bytes: &[u8], memory: &mut MemoryBudget) -> Option<Stop> {
    if !memory.charge((bytes.len() as u64).saturating_mul(TEXT_BYTES_PER_BYTE)) {
        return Some(Stop::OverBudget(0));
    }
    let skip_past = |from: usize, pattern: &[u8]| -> usize {
        memchr::memmem::find(&bytes[from..], pattern)
            .map_or(bytes.len(), |position| from + position + pattern.len())
    };
    let mut depth = 0usize;
    let mut index = 0;
    while let Some(offset) = memchr::memchr(b'<', &bytes[index..]) {
        let start = index + offset;
        if !memory.charge(XML_BYTES_PER_TAG) {
            return Some(Stop::OverBudget(start));
        }
        let rest = &bytes[start..];
        if rest.starts_with(b"<!--") {
            index = skip_past(start, b"-->");
        } else if rest.starts_with(b"<![CDATA[") {
            index = skip_past(start, b"]]>");
        } else if rest.starts_with(b"<?") || rest.starts_with(b"<!") {
            index = skip_past(start, b">");
        } else if rest.starts_with(b"</") {
            depth = depth.saturating_sub(1);
            index = skip_past(start, b">");
        } else {
            // An open tag: find its end outside quoted attribute values.
            let mut end = start + 1;
            loop {
                let Some(offset) = memchr::memchr3(b'"', b'\'', b'>', &bytes[end..]) else {
                    end = bytes.len();
                    break;
                };
                end += offset;
                if bytes[end] == b'>' {
                    break;
                }
                // A quoted value: an attribute.
                if !memory.charge(XML_BYTES_PER_ATTRIBUTE) {
                    return Some(Stop::OverBudget(start));
                }
                // A quote: on past its closing twin.
                let Some(offset) = memchr::memchr(bytes[end], &bytes[end + 1..]) else {
                    end = bytes.len();
                    break;
                };
                end += 1 + offset + 1;
            }
            let self_closing = end < bytes.len() && bytes[end - 1] == b'/';
            if !self_closing {
                depth += 1;
                if depth > MAX_NESTING {
                    return Some(Stop::TooDeep(start));
                }
            }
            index = (end + 1).min(bytes.len());
        }
    }
    None
}

fn convert_element<'text>(
    element: roxmltree::Node<'_, 'text>,
    text: &'text str,
    diagnostics: &Diagnostics,
    depth: usize,
) -> Result<Node<'text>, SceneError> {
    let element_span = diagnostics.span_at(element.range().start);
    if depth > MAX_NESTING {
        return Err(diagnostics.error(
            element_span,
            format!("elements nested more than {MAX_NESTING} levels deep; not a scene file"),
        ));
    }
    let mut entries = Vec::new();
    for attribute in element.attributes() {
        entries.push(Node::new(
            attribute.name(),
            diagnostics.span_at(attribute.range().start),
            diagnostics.span_at(attribute.range_value().start),
            Value::Text(borrowed(attribute.value_storage())),
        ));
    }
    // The element's text: its one text child as the file has it, or its text children joined.
    let mut element_text: Option<Cow<'text, str>> = None;
    let mut text_offset = None;
    for child in element.children() {
        if child.is_element() {
            entries.push(convert_element(child, text, diagnostics, depth + 1)?);
        } else if child.is_text() {
            let Some(content) = child.text_storage() else {
                continue;
            };
            if text_offset.is_none() && !content.trim().is_empty() {
                // Point at the first character of the value, not at the whitespace before it.
                let raw = &text[child.range()];
                let leading = raw.len() - raw.trim_start().len();
                text_offset = Some(child.range().start + leading);
            }
            element_text = Some(match element_text {
                None => borrowed(content),
                Some(before) => Cow::Owned(before.into_owned() + content),
            });
        }
    }
    let trimmed = match element_text {
        None => Cow::Borrowed(""),
        Some(Cow::Borrowed(content)) => Cow::Borrowed(content.trim()),
        Some(Cow::Owned(content)) => Cow::Owned(content.trim().to_owned()),
    };
    let has_structure = !entries.is_empty();
    let tag = element.tag_name().name();
    if !has_structure {
        let span = text_offset.map_or(element_span, |offset| diagnostics.span_at(offset));
        return Ok(Node::new(tag, element_span, span, Value::Text(trimmed)));
    }
    if let Some(offset) = text_offset {
        let span = diagnostics.span_at(offset);
        let mut text_node = Node::new(TEXT_KEY, span, span, Value::Text(trimmed));
        // Messages about the text name the element it belongs to.
        text_node.raw_key = tag;
        entries.push(text_node);
    }
    Ok(Node::new(
        tag,
        element_span,
        element_span,
        Value::Object(entries),
    ))
}

/// A value as the file has it, or a copy where roxmltree had to rewrite it (entities).
fn borrowed<'text>(storage: &roxmltree::StringStorage<'text>) -> Cow<'text, str> {
    match storage {
        roxmltree::StringStorage::Borrowed(text) => Cow::Borrowed(text),
        roxmltree::StringStorage::Owned(text) => Cow::Owned(text.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scan as first written, a byte at a time: the definition `too_deep` must keep.
    fn too_deep_bytewise(bytes: &[u8]) -> Option<usize> {
        let skip_past = |from: usize, pattern: &[u8]| -> usize {
            bytes[from..]
                .windows(pattern.len())
                .position(|window| window == pattern)
                .map_or(bytes.len(), |position| from + position + pattern.len())
        };
        let mut depth = 0usize;
        let mut index = 0;
        while let Some(offset) = bytes[index..].iter().position(|&byte| byte == b'<') {
            let start = index + offset;
            let rest = &bytes[start..];
            if rest.starts_with(b"<!--") {
                index = skip_past(start, b"-->");
            } else if rest.starts_with(b"<![CDATA[") {
                index = skip_past(start, b"]]>");
            } else if rest.starts_with(b"<?") || rest.starts_with(b"<!") {
                index = skip_past(start, b">");
            } else if rest.starts_with(b"</") {
                depth = depth.saturating_sub(1);
                index = skip_past(start, b">");
            } else {
                let mut end = start + 1;
                let mut quote = None;
                while end < bytes.len() {
                    match (quote, bytes[end]) {
                        (None, b'"' | b'\'') => quote = Some(bytes[end]),
                        (Some(open), byte) if byte == open => quote = None,
                        (None, b'>') => break,
                        _ => {}
                    }
                    end += 1;
                }
                let self_closing = end < bytes.len() && bytes[end - 1] == b'/';
                if !self_closing {
                    depth += 1;
                    if depth > MAX_NESTING {
                        return Some(start);
                    }
                }
                index = (end + 1).min(bytes.len());
            }
        }
        None
    }

    /// Documents of tags, quotes, comments, CDATA and declarations in random order, nested to
    /// around the limit: the same answer as the byte-at-a-time scan, truncated anywhere.
    #[test]
    fn the_nesting_scan_agrees_with_its_definition() {
        const PIECES: [&str; 16] = [
            "<a>",
            "</a>",
            "<a/>",
            "<b x='>'>",
            "<c y=\">/\">",
            "<d z='\"'/>",
            "<!-- <a> -->",
            "<![CDATA[<a>]]>",
            "<?pi <a>?>",
            "<!DOCTYPE x>",
            "'",
            "\"",
            ">",
            "<",
            "/",
            "text ",
        ];
        let mut state = 0x9e37_79b9_u32;
        let mut next = |bound: usize| {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as usize % bound
        };
        let mut deep = 0;
        for _ in 0..400 {
            // Mostly opening tags, so that some documents pass the limit.
            let opening = next(4);
            let mut document = String::new();
            for _ in 0..next(300) {
                let piece = if next(4) < opening {
                    "<a>"
                } else {
                    PIECES[next(16)]
                };
                document.push_str(piece);
            }
            let bytes = document.as_bytes();
            for cut in [bytes.len(), bytes.len() / 2, bytes.len().saturating_sub(1)] {
                let expected = too_deep_bytewise(&bytes[..cut]);
                assert_eq!(too_deep(&bytes[..cut]), expected, "{:?}", &document[..cut]);
                deep += usize::from(expected.is_some());
            }
        }
        assert!(deep > 50, "only {deep} documents reach the limit");
    }
}
