//! One located tree for both file formats. The course's JSON files were made by a mechanical
//! XML-to-JSON conversion (FORMAT.md 3.1): attributes became `_`-prefixed keys, element text
//! became strings and repeated elements became arrays. Undoing that conversion here lets one
//! reader (`read.rs`) interpret both formats, so XML and JSON twins cannot drift apart.
//!
//! The mapping:
//! * XML attribute `name="x"` and JSON key `"_name": "x"` are both an entry `name` (leading
//!   underscores are dropped: JL26 accepts `type` as well as `_type`, FORMAT.md 3.2);
//! * an XML element with only text is a `Text` entry; one with attributes or child elements is
//!   an `Object` whose entries are its attributes, then its children, then its text as `#text`;
//! * a JSON array of objects is expanded into repeated entries with the array's key, exactly
//!   as repeated XML elements (so `"light": {...}` and `"light": [{...}]` read alike, 3.2);
//!   other arrays (`"center": [1, 2, 3]`) stay a `List`.

use std::borrow::Cow;

use crate::desc::Span;

/// Key under which an XML element's text is kept when the element also has attributes or
/// children (`<diffuse tex="earth">1 1 1</diffuse>`, `<rotate axis="X">45</rotate>`).
pub(crate) const TEXT_KEY: &str = "#text";

/// Keys and values are borrowed (`'text`): from the file's text for XML, where they appear in
/// it as they read (text roxmltree rewrote, for entities, CDATA or text split around a
/// processing instruction, is copied), and from jsonc-parser's syntax tree for JSON, which the
/// loader keeps while the tree is read. A tree of a 100,000-shape file then holds one
/// allocation per object rather than several per entry.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Node<'text> {
    /// The key with leading underscores removed; empty for list elements.
    pub key: &'text str,
    /// The key as written, for messages.
    pub raw_key: &'text str,
    /// Where the key (XML: the element or attribute) starts.
    pub key_span: Span,
    /// Where the value starts.
    pub span: Span,
    pub value: Value<'text>,
}

#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Value<'text> {
    /// XML text or attribute value, or a JSON string.
    Text(Cow<'text, str>),
    /// A JSON number literal, still as text.
    Number(Cow<'text, str>),
    Bool(bool),
    Null,
    /// A JSON array that is not a list of objects.
    List(Vec<Node<'text>>),
    /// XML element with attributes or children, or a JSON object.
    Object(Vec<Node<'text>>),
}

impl<'text> Node<'text> {
    pub fn new(
        raw_key: &'text str,
        key_span: Span,
        span: Span,
        value: Value<'text>,
    ) -> Node<'text> {
        Node {
            key: raw_key.trim_start_matches('_'),
            raw_key,
            key_span,
            span,
            value,
        }
    }

    /// How the value reads in a message ("a number", "an object").
    pub fn kind_name(&self) -> &'static str {
        match self.value {
            Value::Text(_) => "text",
            Value::Number(_) => "a number",
            Value::Bool(_) => "a boolean",
            Value::Null => "null",
            Value::List(_) => "a list",
            Value::Object(_) => "an object",
        }
    }
}
