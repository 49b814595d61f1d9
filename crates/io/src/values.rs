//! Reading typed values out of the located tree: numbers, "x y z" vectors, names, colours, and
//! `Fields`, which hands out an object's entries and afterwards reports every entry nobody
//! asked for (pbrt-v4's `ReportUnused`), with a "did you mean" when a known key is close.

use std::borrow::Cow;

use glint_render::Vec3;
use smallvec::SmallVec;

use crate::desc::{ColorDesc, Located, Span};
use crate::diagnostic::{did_you_mean, Diagnostics, SceneError};
use crate::tree::{Node, Value, TEXT_KEY};

/// The entries of one object, taken one key at a time.
pub(crate) struct Fields<'tree> {
    /// How the object is named in messages: "a sphere shape", "the scene".
    what: Cow<'static, str>,
    span: Span,
    entries: &'tree [Node<'tree>],
    /// Which entries were taken (the course's objects have a handful).
    used: SmallVec<[bool; 16]>,
    known: Vec<&'static str>,
}

impl<'tree> Fields<'tree> {
    /// The entries of `node`, which must be an object (an empty XML element counts as one).
    pub fn of(
        node: &'tree Node<'tree>,
        what: impl Into<Cow<'static, str>>,
        diagnostics: &Diagnostics,
    ) -> Result<Fields<'tree>, SceneError> {
        let what = what.into();
        let entries: &[Node<'tree>] = match &node.value {
            Value::Object(entries) => entries,
            Value::Text(text) if text.trim().is_empty() => &[],
            _ => {
                return Err(diagnostics.error(
                    node.span,
                    format!(
                        "expected {what} (an object with parameters), found {}",
                        node.kind_name()
                    ),
                ))
            }
        };
        Ok(Fields {
            what,
            span: node.span,
            used: SmallVec::from_elem(false, entries.len()),
            entries,
            known: Vec::new(),
        })
    }

    pub fn span(&self) -> Span {
        self.span
    }

    pub fn what(&self) -> &str {
        &self.what
    }

    /// Renames the object once its type is known ("a light" becomes "an area light").
    pub fn set_what(&mut self, what: impl Into<Cow<'static, str>>) {
        self.what = what.into();
    }

    /// The first entry under any of `keys` (aliases), marking all of them used. A repeated key
    /// is reported: the course's parsers read the first one.
    pub fn take_any(
        &mut self,
        keys: &[&'static str],
        diagnostics: &mut Diagnostics,
    ) -> Option<&'tree Node<'tree>> {
        self.known.extend_from_slice(keys);
        let mut first: Option<&'tree Node<'tree>> = None;
        for (index, entry) in self.entries.iter().enumerate() {
            if !keys.contains(&entry.key) {
                continue;
            }
            self.used[index] = true;
            match first {
                None => first = Some(entry),
                Some(earlier) => diagnostics.warn(
                    entry.key_span,
                    format!(
                        "`{}` is given again in {} (first at line {}); only the first is used",
                        entry.raw_key, self.what, earlier.key_span.line
                    ),
                ),
            }
        }
        first
    }

    pub fn take(
        &mut self,
        key: &'static str,
        diagnostics: &mut Diagnostics,
    ) -> Option<&'tree Node<'tree>> {
        self.take_any(&[key], diagnostics)
    }

    /// Every entry under `key`, in order (repeated elements, array entries).
    pub fn take_all(&mut self, key: &'static str) -> Vec<&'tree Node<'tree>> {
        self.known.push(key);
        let mut found = Vec::new();
        for (index, entry) in self.entries.iter().enumerate() {
            if entry.key == key {
                self.used[index] = true;
                found.push(entry);
            }
        }
        found
    }

    /// Marks everything used: for objects whose type was not understood, where one warning
    /// about the type says enough.
    pub fn skip_rest(&mut self) {
        self.used.fill(true);
    }

    /// Reports every entry that was not taken.
    pub fn finish(self, diagnostics: &mut Diagnostics) {
        for (entry, used) in self.entries.iter().zip(&self.used) {
            if *used {
                continue;
            }
            if entry.key == TEXT_KEY {
                let text = match &entry.value {
                    Value::Text(text) => &**text,
                    _ => "",
                };
                diagnostics.warn(
                    entry.span,
                    format!(
                        "text `{}` is not used in {}; ignored",
                        excerpt(text),
                        self.what
                    ),
                );
            } else {
                let suggestion = did_you_mean(entry.key, self.known.iter().copied());
                diagnostics.warn(
                    entry.key_span,
                    format!(
                        "`{}` is not used in {}; ignored{suggestion}",
                        entry.raw_key, self.what
                    ),
                );
            }
        }
    }
}

/// The start of a long text, for messages.
fn excerpt(text: &str) -> String {
    const LIMIT: usize = 40;
    if text.chars().count() <= LIMIT {
        text.to_owned()
    } else {
        format!("{}...", text.chars().take(LIMIT).collect::<String>())
    }
}

/// A finite number: a JSON number, or text holding one (2019 JSON had `"focalLength": "1.0"`,
/// FORMAT.md 1.1, A20).
pub(crate) fn number(node: &Node, diagnostics: &Diagnostics) -> Result<f64, SceneError> {
    let text = match &node.value {
        Value::Number(text) | Value::Text(text) => text.trim(),
        _ => {
            return Err(diagnostics.error(
                node.span,
                format!(
                    "expected a number for `{}`, found {}",
                    node.raw_key,
                    node.kind_name()
                ),
            ))
        }
    };
    let value = parse_finite(text).ok_or_else(|| {
        diagnostics.error(
            node.span,
            format!("expected a number for `{}`, found `{text}`", node.raw_key),
        )
    })?;
    check_magnitude(node, &[value], diagnostics)?;
    Ok(value)
}

/// Largest magnitude of any number in a scene. The renderer works in 32-bit floats and
/// squares lengths (a sphere of radius 1e20 has NaN normals); the course's largest number is
/// 1000.
pub(crate) const MAX_MAGNITUDE: f64 = 1e7;

/// A located error when one of `values` is beyond ±`MAX_MAGNITUDE`.
fn check_magnitude(
    node: &Node,
    values: &[f64],
    diagnostics: &Diagnostics,
) -> Result<(), SceneError> {
    match values.iter().find(|value| value.abs() > MAX_MAGNITUDE) {
        Some(value) => Err(diagnostics.error(
            node.span,
            format!(
                "`{}` holds {value:e}, too large to render in 32-bit arithmetic (numbers must \
                 lie within ±{MAX_MAGNITUDE:e})",
                node.raw_key
            ),
        )),
        None => Ok(()),
    }
}

pub(crate) fn located_number(
    node: &Node,
    diagnostics: &Diagnostics,
) -> Result<Located<f64>, SceneError> {
    Ok(Located {
        value: number(node, diagnostics)?,
        span: node.span,
    })
}

/// A number that is finite even as the renderer's f32 (1e40 is not).
fn parse_finite(text: &str) -> Option<f64> {
    text.parse::<f64>()
        .ok()
        .filter(|value| value.is_finite() && (*value as f32).is_finite())
}

/// A 3-vector: "x y z" with any whitespace (or commas) between the numbers, or a JSON array.
/// Text is read the way the course's C++ parsers read it, with `>>` from a string stream
/// (FORMAT.md 1.1, A20): a fourth number is ignored, and a token such as `2.5.0` is read as far
/// as it is a number (2.5), the rest starting the next number (.0). Both are reported.
pub(crate) fn vector(node: &Node, diagnostics: &mut Diagnostics) -> Result<Vec3, SceneError> {
    let (numbers, irregular) = match &node.value {
        Value::Text(text) => {
            // Plain numbers (nearly every file): each token read once. Their stream reading
            // is the same numbers.
            let plain: Option<Vec<f64>> = text
                .split(|character: char| character.is_whitespace() || character == ',')
                .filter(|token| !token.is_empty())
                .map(parse_finite)
                .collect();
            match plain {
                Some(numbers) => (numbers, false),
                None => {
                    let (numbers, complete) = stream_numbers(text);
                    (
                        if complete || numbers.len() >= 3 {
                            numbers
                        } else {
                            Vec::new()
                        },
                        true,
                    )
                }
            }
        }
        Value::List(items) => {
            let numbers: Option<Vec<f64>> = items
                .iter()
                .map(|item| match &item.value {
                    Value::Number(text) | Value::Text(text) => parse_finite(text.trim()),
                    _ => None,
                })
                .collect();
            (numbers.unwrap_or_default(), false)
        }
        _ => (Vec::new(), false),
    };
    if numbers.len() < 3 {
        let found = match &node.value {
            Value::Text(text) => format!("`{text}`"),
            Value::Number(text) => format!("the single number `{text}`"),
            _ => node.kind_name().to_owned(),
        };
        return Err(diagnostics.error(
            node.span,
            format!(
                "expected three numbers (\"x y z\") for `{}`, found {found}",
                node.raw_key
            ),
        ));
    }
    check_magnitude(node, &numbers[..3], diagnostics)?;
    let vector = Vec3::new(numbers[0] as f32, numbers[1] as f32, numbers[2] as f32);
    if irregular {
        let text = match &node.value {
            Value::Text(text) => &**text,
            _ => "",
        };
        diagnostics.warn(
            node.span,
            format!(
                "`{text}` is not three plain numbers; read as {} {} {} as the course's C++ \
                 parser reads it",
                vector.x, vector.y, vector.z
            ),
        );
    } else if numbers.len() > 3 {
        diagnostics.warn(
            node.span,
            format!(
                "`{}` has {} numbers; only the first three are used",
                node.raw_key,
                numbers.len()
            ),
        );
    }
    Ok(vector)
}

/// Numbers read from `text` as a C++ `istream >> double` loop reads them: skip separators, take
/// the longest prefix that is a number, repeat. The flag says whether all of the text was read.
fn stream_numbers(text: &str) -> (Vec<f64>, bool) {
    let mut numbers = Vec::new();
    let mut rest = text;
    loop {
        rest = rest
            .trim_start_matches(|character: char| character.is_whitespace() || character == ',');
        if rest.is_empty() {
            return (numbers, true);
        }
        let token_end = rest
            .find(|character: char| character.is_whitespace() || character == ',')
            .unwrap_or(rest.len());
        // The longest prefix that is a number at all; one too large for f32 stops the read
        // rather than being cut short to a smaller number.
        let longest = (1..=token_end)
            .rev()
            .filter(|&end| rest.is_char_boundary(end))
            .find_map(|end| {
                let value = rest[..end].parse::<f64>().ok()?;
                value.is_finite().then_some((value, end))
            });
        match longest {
            Some((value, end)) if (value as f32).is_finite() => {
                numbers.push(value);
                rest = &rest[end..];
            }
            _ => return (numbers, false),
        }
    }
}

pub(crate) fn located_vector(
    node: &Node,
    diagnostics: &mut Diagnostics,
) -> Result<Located<Vec3>, SceneError> {
    Ok(Located {
        value: vector(node, diagnostics)?,
        span: node.span,
    })
}

/// A name, path or keyword. Numbers are accepted as their text (a shader named 5).
pub(crate) fn string(
    node: &Node,
    diagnostics: &Diagnostics,
) -> Result<Located<String>, SceneError> {
    match &node.value {
        Value::Text(text) | Value::Number(text) => Ok(Located {
            value: text.trim().to_owned(),
            span: node.span,
        }),
        _ => Err(diagnostics.error(
            node.span,
            format!(
                "expected text for `{}`, found {}",
                node.raw_key,
                node.kind_name()
            ),
        )),
    }
}

/// A yes/no flag: `0`/`1`, `true`/`false`, as a JSON value or text (`"visible": 0`).
pub(crate) fn flag(node: &Node, diagnostics: &Diagnostics) -> Result<bool, SceneError> {
    let parsed = match &node.value {
        Value::Bool(value) => Some(*value),
        Value::Number(text) | Value::Text(text) => match text.trim() {
            "true" | "yes" | "on" => Some(true),
            "false" | "no" | "off" => Some(false),
            other => parse_finite(other).map(|value| value != 0.0),
        },
        _ => None,
    };
    parsed.ok_or_else(|| {
        diagnostics.error(
            node.span,
            format!(
                "expected 0 or 1 for `{}`, found {}",
                node.raw_key,
                node.kind_name()
            ),
        )
    })
}

/// Largest magnitude of a colour, intensity or background component. The renderer multiplies
/// colours along a path in 32-bit floats (at most 3.4e38); components this far above any real
/// scene's (the course's largest is 60) cannot be rendered without overflowing to infinity.
pub(crate) const MAX_COLOR_COMPONENT: f32 = 1e6;

/// Checks a colour, intensity or background read from `node`: a component beyond
/// ±`MAX_COLOR_COMPONENT` is an error, a negative one a warning (it renders, as a colour that
/// takes light away, which is not physical).
pub(crate) fn check_color(
    node: &Node,
    color: Vec3,
    diagnostics: &mut Diagnostics,
) -> Result<Vec3, SceneError> {
    let components = color.to_array();
    if let Some(huge) = components
        .iter()
        .find(|component| component.abs() > MAX_COLOR_COMPONENT)
    {
        return Err(diagnostics.error(
            node.span,
            format!(
                "`{}` has the component {huge:e}, which cannot be rendered: colours and \
                 intensities must lie within ±{MAX_COLOR_COMPONENT:e}",
                node.raw_key
            ),
        ));
    }
    if let Some(negative) = components.iter().find(|component| **component < 0.0) {
        diagnostics.warn(
            node.span,
            format!(
                "`{}` has the negative component {negative}; light cannot be negative, so the \
                 image will not be physical",
                node.raw_key
            ),
        );
    }
    Ok(color)
}

/// A colour that is not textured ("r g b"), checked by `check_color`.
pub(crate) fn plain_color(node: &Node, diagnostics: &mut Diagnostics) -> Result<Vec3, SceneError> {
    let color = vector(node, diagnostics)?;
    check_color(node, color, diagnostics)
}

/// A colour parameter: "r g b", or an object with a texture name and a colour (FORMAT.md 3.4:
/// `{"tex": "...", "data": "r g b"}`; XML `<diffuse tex="...">r g b</diffuse>`; the converter's
/// older `{"_tex": "...", "__text": "r g b"}`). Without a colour a texture is used as is,
/// data = 1 1 1 (JL26, FORMAT.md 5). FORMAT.md A9: the renderer multiplies the two
/// (colour = data ⊙ texel), which is why both are kept.
pub(crate) fn color(node: &Node, diagnostics: &mut Diagnostics) -> Result<ColorDesc, SceneError> {
    if !matches!(node.value, Value::Object(_)) {
        return Ok(ColorDesc::constant(plain_color(node, diagnostics)?));
    }
    let what = format!("the colour `{}`", node.raw_key);
    let mut fields = Fields::of(node, what, diagnostics)?;
    let texture = match fields.take("tex", diagnostics) {
        Some(texture) => Some(string(texture, diagnostics)?),
        None => None,
    };
    let color = match fields.take_any(&["data", "text", TEXT_KEY], diagnostics) {
        Some(data) => plain_color(data, diagnostics)?,
        None => Vec3::ONE,
    };
    fields.finish(diagnostics);
    Ok(ColorDesc { color, texture })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_read_like_a_cpp_stream() {
        assert_eq!(stream_numbers("0 3.0   4.0"), (vec![0.0, 3.0, 4.0], true));
        assert_eq!(
            stream_numbers("0.0 2.5.0 5.0"),
            (vec![0.0, 2.5, 0.0, 5.0], true)
        );
        assert_eq!(stream_numbers("1, 2, 3"), (vec![1.0, 2.0, 3.0], true));
        assert_eq!(stream_numbers("1 abc 3"), (vec![1.0], false));
        assert_eq!(stream_numbers("1 2 3 nan"), (vec![1.0, 2.0, 3.0], false));
        assert_eq!(stream_numbers("1e39"), (vec![], false));
    }
}
