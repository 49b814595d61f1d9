//! The properties of one Mitsuba object (`<float name=...>`, `<rgb>`, `<transform>`, nested
//! objects and `<ref>`s), read once from its element and then asked for by name and type.
//! What no one asks for is an unknown property: a located error, as in Mitsuba.

use std::cell::Cell;

use glint_render::Matrix4;

use crate::desc::Span;
use crate::diagnostic::SceneError;

use super::parse::Element;
use super::spectrum::check_increasing;
use super::Files;

/// One property's value as written.
#[derive(Clone, Debug)]
pub(crate) enum Value<'e> {
    Float(f64),
    Integer(i64),
    Boolean(bool),
    String(String),
    Rgb([f64; 3]),
    /// A single value (`uniform`) or wavelength:value pairs.
    Spectrum(Spectrum),
    Point([f64; 3]),
    Vector([f64; 3]),
    Transform(Matrix4),
    /// A nested object (`<bsdf type=...>` inside a shape).
    Object(&'e Element),
    /// `<ref id="..."/>`.
    Ref(String),
}

#[derive(Clone, Debug)]
pub(crate) enum Spectrum {
    Uniform(f64),
    Sampled {
        wavelengths: Vec<f64>,
        values: Vec<f64>,
    },
    /// `filename=...`: read when used, from the scene's search folders.
    File(String),
}

impl Value<'_> {
    pub fn kind(&self) -> &'static str {
        match self {
            Value::Float(_) => "a float",
            Value::Integer(_) => "an integer",
            Value::Boolean(_) => "a boolean",
            Value::String(_) => "a string",
            Value::Rgb(_) => "an rgb",
            Value::Spectrum(_) => "a spectrum",
            Value::Point(_) => "a point",
            Value::Vector(_) => "a vector",
            Value::Transform(_) => "a transform",
            Value::Object(_) => "an object",
            Value::Ref(_) => "a reference",
        }
    }
}

/// A property: its name (`_arg_N` for unnamed objects), value and where it was written.
#[derive(Debug)]
pub(crate) struct Property<'e> {
    pub name: String,
    pub value: Value<'e>,
    pub file: usize,
    pub span: Span,
    pub queried: Cell<bool>,
}

/// The properties of one object element.
pub(crate) struct Props<'e> {
    pub element: &'e Element,
    pub plugin: String,
    pub list: Vec<Property<'e>>,
}

/// Object tags: elements that are plugins rather than values.
pub(crate) const OBJECT_TAGS: &[&str] = &[
    "bsdf",
    "emitter",
    "shape",
    "texture",
    "sensor",
    "film",
    "sampler",
    "integrator",
    "rfilter",
    "medium",
    "phase",
    "volume",
    "spectrum",
];

impl<'e> Props<'e> {
    /// Reads the property children of `element`.
    pub fn read(element: &'e Element, files: &Files) -> Result<Props<'e>, SceneError> {
        let error = |span: Span, message: String| files.error(element.file, span, message);
        let plugin = element.value("type").unwrap_or("scene").to_owned();
        let mut list: Vec<Property<'e>> = Vec::new();
        // The line each name was first given at: a scene holds thousands of objects, and
        // searching the list for each would be quadratic.
        let mut named: std::collections::HashMap<String, u32> = std::collections::HashMap::new();
        let mut unnamed = 0;
        for child in &element.children {
            let at = |span| (child.file, span);
            let name = child.value("name").map(str::to_owned);
            let need_name = || {
                name.clone().ok_or_else(|| {
                    files.error(
                        child.file,
                        child.span,
                        format!("<{}> needs a `name` attribute", child.tag),
                    )
                })
            };
            let need = |attribute: &str| {
                child.attribute(attribute).ok_or_else(|| {
                    files.error(
                        child.file,
                        child.span,
                        format!("<{}> needs a `{attribute}` attribute", child.tag),
                    )
                })
            };
            let is_spectrum_object = child.tag == "spectrum" && child.value("type").is_some();
            let value = match child.tag.as_str() {
                "float" => {
                    let attribute = need("value")?;
                    check_attributes(child, &["name", "value"], files)?;
                    Value::Float(parse_float(&attribute.value).ok_or_else(|| {
                        files.error(
                            child.file,
                            attribute.span,
                            format!(
                                "could not parse floating point value \"{}\"",
                                attribute.value
                            ),
                        )
                    })?)
                }
                "integer" => {
                    let attribute = need("value")?;
                    check_attributes(child, &["name", "value"], files)?;
                    Value::Integer(attribute.value.trim().parse::<i64>().map_err(|_| {
                        files.error(
                            child.file,
                            attribute.span,
                            format!("could not parse integer value \"{}\"", attribute.value),
                        )
                    })?)
                }
                "boolean" => {
                    let attribute = need("value")?;
                    check_attributes(child, &["name", "value"], files)?;
                    Value::Boolean(match attribute.value.trim().to_lowercase().as_str() {
                        "true" => true,
                        "false" => false,
                        _ => {
                            return Err(files.error(
                                child.file,
                                attribute.span,
                                format!(
                                    "could not parse boolean value \"{}\": must be \"true\" or \
                                     \"false\"",
                                    attribute.value
                                ),
                            ))
                        }
                    })
                }
                "string" => {
                    check_attributes(child, &["name", "value"], files)?;
                    Value::String(need("value")?.value.clone())
                }
                "rgb" => {
                    let attribute = need("value")?;
                    check_attributes(child, &["name", "value"], files)?;
                    let numbers = parse_list(&attribute.value);
                    Value::Rgb(match numbers.as_deref() {
                        Some([v]) => [*v; 3],
                        Some([r, g, b]) => [*r, *g, *b],
                        _ => {
                            return Err(files.error(
                                child.file,
                                attribute.span,
                                format!(
                                    "<rgb> needs one or three numbers, not \"{}\"",
                                    attribute.value
                                ),
                            ))
                        }
                    })
                }
                "spectrum" if !is_spectrum_object => {
                    check_attributes(child, &["name", "value", "filename"], files)?;
                    match (child.attribute("value"), child.attribute("filename")) {
                        (Some(value), None) => Value::Spectrum(
                            parse_spectrum(&value.value)
                                .map_err(|why| files.error(child.file, value.span, why))?,
                        ),
                        (None, Some(file)) => Value::Spectrum(Spectrum::File(file.value.clone())),
                        _ => {
                            return Err(files.error(
                                child.file,
                                child.span,
                                "<spectrum> needs either `value` or `filename` (not both)",
                            ))
                        }
                    }
                }
                "point" | "vector" => {
                    check_attributes(child, &["name", "value", "x", "y", "z"], files)?;
                    let xyz = parse_xyz(child, 0.0, files)?;
                    if child.tag == "point" {
                        Value::Point(xyz)
                    } else {
                        Value::Vector(xyz)
                    }
                }
                "transform" => {
                    check_attributes(child, &["name"], files)?;
                    Value::Transform(parse_transform(child, files)?)
                }
                "ref" => {
                    check_attributes(child, &["name", "id"], files)?;
                    Value::Ref(need("id")?.value.clone())
                }
                tag if OBJECT_TAGS.contains(&tag) => Value::Object(child),
                "lookat" | "translate" | "rotate" | "scale" | "matrix" => {
                    return Err(error(
                        child.span,
                        format!("<{}> can only appear inside a <transform>", child.tag),
                    ))
                }
                other => {
                    return Err(files.error(
                        child.file,
                        child.span,
                        format!("unknown element <{other}>"),
                    ))
                }
            };
            let name = match value {
                Value::Object(_) | Value::Ref(_) => name.unwrap_or_else(|| {
                    unnamed += 1;
                    format!("_arg_{}", unnamed - 1)
                }),
                _ => need_name()?,
            };
            let (file, span) = at(child.span);
            if !name.starts_with("_arg_") {
                if let Some(line) = named.get(&name) {
                    return Err(files.error(
                        file,
                        span,
                        format!("property `{name}` given twice (first at line {line})"),
                    ));
                }
                named.insert(name.clone(), span.line);
            }
            list.push(Property {
                name,
                value,
                file,
                span,
                queried: Cell::new(false),
            });
        }
        Ok(Props {
            element,
            plugin,
            list,
        })
    }

    pub fn get(&self, name: &str) -> Option<&Property<'e>> {
        let property = self.list.iter().find(|p| p.name == name)?;
        property.queried.set(true);
        Some(property)
    }

    pub fn has(&self, name: &str) -> bool {
        self.list.iter().any(|p| p.name == name)
    }

    /// The unnamed nested objects and references, in order (marked as used).
    pub fn unnamed(&self) -> Vec<&Property<'e>> {
        self.list
            .iter()
            .filter(|p| p.name.starts_with("_arg_"))
            .inspect(|p| p.queried.set(true))
            .collect()
    }

    /// Marks `name` as read without using it.
    pub fn ignore(&self, name: &str) {
        if let Some(property) = self.list.iter().find(|p| p.name == name) {
            property.queried.set(true);
        }
    }

    fn wrong_type(&self, files: &Files, property: &Property, wanted: &str) -> SceneError {
        files.error(
            property.file,
            property.span,
            format!(
                "`{}` of `{}` must be {wanted}, not {}",
                property.name,
                self.plugin,
                property.value.kind()
            ),
        )
    }

    pub fn float(&self, files: &Files, name: &str, default: f64) -> Result<f64, SceneError> {
        Ok(self.float_opt(files, name)?.unwrap_or(default))
    }

    pub fn float_opt(&self, files: &Files, name: &str) -> Result<Option<f64>, SceneError> {
        let Some(property) = self.get(name) else {
            return Ok(None);
        };
        match property.value {
            Value::Float(value) => Ok(Some(value)),
            Value::Integer(value) => Ok(Some(value as f64)),
            _ => Err(self.wrong_type(files, property, "a float")),
        }
    }

    pub fn integer(&self, files: &Files, name: &str, default: i64) -> Result<i64, SceneError> {
        let Some(property) = self.get(name) else {
            return Ok(default);
        };
        match property.value {
            Value::Integer(value) => Ok(value),
            _ => Err(self.wrong_type(files, property, "an integer")),
        }
    }

    pub fn boolean(&self, files: &Files, name: &str, default: bool) -> Result<bool, SceneError> {
        let Some(property) = self.get(name) else {
            return Ok(default);
        };
        match property.value {
            Value::Boolean(value) => Ok(value),
            _ => Err(self.wrong_type(files, property, "a boolean")),
        }
    }

    pub fn string(
        &self,
        files: &Files,
        name: &str,
    ) -> Result<Option<(String, Span, usize)>, SceneError> {
        let Some(property) = self.get(name) else {
            return Ok(None);
        };
        match &property.value {
            Value::String(value) => Ok(Some((value.clone(), property.span, property.file))),
            _ => Err(self.wrong_type(files, property, "a string")),
        }
    }

    /// A point or vector (Mitsuba keeps them apart; Glint takes either where one is asked).
    pub fn vector(&self, files: &Files, name: &str) -> Result<Option<[f64; 3]>, SceneError> {
        let Some(property) = self.get(name) else {
            return Ok(None);
        };
        match property.value {
            Value::Point(value) | Value::Vector(value) => Ok(Some(value)),
            _ => Err(self.wrong_type(files, property, "a point or vector")),
        }
    }

    pub fn transform(&self, files: &Files, name: &str) -> Result<Option<Matrix4>, SceneError> {
        let Some(property) = self.get(name) else {
            return Ok(None);
        };
        match &property.value {
            Value::Transform(value) => Ok(Some(*value)),
            _ => Err(self.wrong_type(files, property, "a transform")),
        }
    }

    /// The first property nobody asked for, as Mitsuba's "unreferenced property" error.
    pub fn check_all_used(&self, files: &Files) -> Result<(), SceneError> {
        match self.list.iter().find(|p| !p.queried.get()) {
            None => Ok(()),
            Some(property) => {
                let known: Vec<&str> = Vec::new();
                let _ = known;
                Err(files.error(
                    property.file,
                    property.span,
                    format!(
                        "unknown property `{}` of `{}` ({} {})",
                        property.name,
                        self.plugin,
                        self.element.tag,
                        "plugin; Mitsuba would refuse it too"
                    ),
                ))
            }
        }
    }
}

/// Refuses attributes other than `allowed` (and `name`), as Mitsuba's `check_attributes`.
fn check_attributes(element: &Element, allowed: &[&str], files: &Files) -> Result<(), SceneError> {
    for attribute in &element.attributes {
        if !allowed.contains(&attribute.name.as_str()) {
            return Err(files.error(
                element.file,
                attribute.span,
                format!(
                    "unexpected attribute `{}` in <{}>",
                    attribute.name, element.tag
                ),
            ));
        }
    }
    Ok(())
}

/// A number as Mitsuba reads one (surrounding spaces allowed).
pub(crate) fn parse_float(text: &str) -> Option<f64> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|value| value.is_finite())
}

/// Numbers separated by commas and/or spaces.
pub(crate) fn parse_list(text: &str) -> Option<Vec<f64>> {
    text.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|word| !word.is_empty())
        .map(parse_float)
        .collect()
}

fn parse_spectrum(text: &str) -> Result<Spectrum, String> {
    let words: Vec<&str> = text
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|word| !word.is_empty())
        .collect();
    if let [single] = words.as_slice() {
        if !single.contains(':') {
            return parse_float(single)
                .map(Spectrum::Uniform)
                .ok_or_else(|| format!("could not parse uniform spectrum value \"{single}\""));
        }
    }
    let mut wavelengths = Vec::new();
    let mut values = Vec::new();
    for word in words {
        let pair: Vec<&str> = word.split(':').collect();
        let [w, v] = pair.as_slice() else {
            return Err(format!(
                "invalid spectrum value \"{word}\" (expected wavelength:value pairs)"
            ));
        };
        match (parse_float(w), parse_float(v)) {
            (Some(w), Some(v)) => {
                wavelengths.push(w);
                values.push(v);
            }
            _ => return Err(format!("could not parse wavelength:value pair \"{word}\"")),
        }
    }
    check_increasing(&wavelengths)?;
    Ok(Spectrum::Sampled {
        wavelengths,
        values,
    })
}

/// x, y, z attributes or a `value` of one or three numbers; missing components `default`.
fn parse_xyz(element: &Element, default: f64, files: &Files) -> Result<[f64; 3], SceneError> {
    if let Some(value) = element.attribute("value") {
        if ["x", "y", "z"]
            .iter()
            .any(|axis| element.attribute(axis).is_some())
        {
            return Err(files.error(
                element.file,
                value.span,
                "cannot mix `value` with `x`, `y`, `z`",
            ));
        }
        return match parse_list(&value.value).as_deref() {
            Some([v]) => Ok([*v; 3]),
            Some([x, y, z]) => Ok([*x, *y, *z]),
            _ => Err(files.error(
                element.file,
                value.span,
                format!(
                    "`value` must hold one or three numbers, not \"{}\"",
                    value.value
                ),
            )),
        };
    }
    let mut xyz = [default; 3];
    for (slot, axis) in xyz.iter_mut().zip(["x", "y", "z"]) {
        if let Some(attribute) = element.attribute(axis) {
            *slot = parse_float(&attribute.value).ok_or_else(|| {
                files.error(
                    element.file,
                    attribute.span,
                    format!("could not parse `{axis}` value \"{}\"", attribute.value),
                )
            })?;
        }
    }
    Ok(xyz)
}

/// Three numbers of a `lookat` attribute.
fn parse_three(
    element: &Element,
    name: &str,
    files: &Files,
) -> Result<Option<[f64; 3]>, SceneError> {
    let Some(attribute) = element.attribute(name) else {
        return Ok(None);
    };
    match parse_list(&attribute.value).as_deref() {
        Some([x, y, z]) => Ok(Some([*x, *y, *z])),
        _ => Err(files.error(
            element.file,
            attribute.span,
            format!(
                "`{name}` must hold three numbers, not \"{}\"",
                attribute.value
            ),
        )),
    }
}

fn vec3(a: [f64; 3]) -> [f64; 3] {
    a
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let length = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    a.map(|value| value / length)
}

/// A `<transform>`: its operations in order, each applied after (left of) the ones before.
fn parse_transform(element: &Element, files: &Files) -> Result<Matrix4, SceneError> {
    let mut m = Matrix4::IDENTITY;
    for op in &element.children {
        let fail = |message: String| files.error(op.file, op.span, message);
        let next = match op.tag.as_str() {
            "translate" => {
                check_attributes(op, &["value", "x", "y", "z"], files)?;
                let [x, y, z] = parse_xyz(op, 0.0, files)?;
                let mut t = Matrix4::IDENTITY;
                t.m[0][3] = x;
                t.m[1][3] = y;
                t.m[2][3] = z;
                t
            }
            "scale" => {
                check_attributes(op, &["value", "x", "y", "z"], files)?;
                let [x, y, z] = parse_xyz(op, 1.0, files)?;
                let mut s = Matrix4::IDENTITY;
                s.m[0][0] = x;
                s.m[1][1] = y;
                s.m[2][2] = z;
                s
            }
            "rotate" => {
                check_attributes(op, &["value", "x", "y", "z", "angle"], files)?;
                let axis = parse_xyz(op, 0.0, files)?;
                if axis == [0.0; 3] {
                    return Err(fail("the rotation axis cannot be zero".into()));
                }
                let angle = op
                    .attribute("angle")
                    .ok_or_else(|| fail("<rotate> needs an `angle`".into()))?;
                let degrees = parse_float(&angle.value).ok_or_else(|| {
                    files.error(
                        op.file,
                        angle.span,
                        format!("could not parse angle \"{}\"", angle.value),
                    )
                })?;
                rotation(normalize(axis), degrees)
            }
            "lookat" => {
                check_attributes(op, &["origin", "target", "up"], files)?;
                let origin = parse_three(op, "origin", files)?
                    .ok_or_else(|| fail("<lookat> needs an `origin`".into()))?;
                let target = parse_three(op, "target", files)?
                    .ok_or_else(|| fail("<lookat> needs a `target`".into()))?;
                let mut up = parse_three(op, "up", files)?.unwrap_or([0.0; 3]);
                let dir = normalize(sub(target, origin));
                if up == [0.0; 3] {
                    up = any_orthogonal(dir);
                }
                let left = normalize(cross(up, dir));
                let new_up = cross(dir, left);
                let mut l = Matrix4::IDENTITY;
                for row in 0..3 {
                    l.m[row][0] = left[row];
                    l.m[row][1] = new_up[row];
                    l.m[row][2] = dir[row];
                    l.m[row][3] = vec3(origin)[row];
                }
                if l.m.iter().flatten().any(|value| !value.is_finite()) {
                    return Err(fail("invalid lookat transformation (origin equals target, or up is parallel to the view)".into()));
                }
                l
            }
            "matrix" => {
                check_attributes(op, &["value"], files)?;
                let value = op
                    .attribute("value")
                    .ok_or_else(|| fail("<matrix> needs a `value`".into()))?;
                let numbers = parse_list(&value.value).unwrap_or_default();
                let n = match numbers.len() {
                    16 => 4,
                    9 => 3,
                    count => {
                        return Err(files.error(
                            op.file,
                            value.span,
                            format!("a matrix needs 9 or 16 numbers, not {count}"),
                        ))
                    }
                };
                let mut matrix = Matrix4::IDENTITY;
                for row in 0..n {
                    for column in 0..n {
                        matrix.m[row][column] = numbers[row * n + column];
                    }
                }
                matrix
            }
            other => return Err(fail(format!("unexpected <{other}> inside <transform>"))),
        };
        m = next.mul(&m);
    }
    Ok(m)
}

/// A unit vector orthogonal to `d` (the `up` Mitsuba makes when none is given).
fn any_orthogonal(d: [f64; 3]) -> [f64; 3] {
    let sign = 1f64.copysign(d[2]);
    let a = -1.0 / (sign + d[2]);
    let b = d[0] * d[1] * a;
    [1.0 + sign * d[0] * d[0] * a, sign * b, -sign * d[0]]
}

/// Rotation by `degrees` about the unit `axis` (right-handed).
fn rotation(axis: [f64; 3], degrees: f64) -> Matrix4 {
    let (sin, cos) = degrees.to_radians().sin_cos();
    let [x, y, z] = axis;
    let mut r = Matrix4::IDENTITY;
    r.m[0][0] = x * x + (1.0 - x * x) * cos;
    r.m[0][1] = x * y * (1.0 - cos) - z * sin;
    r.m[0][2] = x * z * (1.0 - cos) + y * sin;
    r.m[1][0] = x * y * (1.0 - cos) + z * sin;
    r.m[1][1] = y * y + (1.0 - y * y) * cos;
    r.m[1][2] = y * z * (1.0 - cos) - x * sin;
    r.m[2][0] = x * z * (1.0 - cos) - y * sin;
    r.m[2][1] = y * z * (1.0 - cos) + x * sin;
    r.m[2][2] = z * z + (1.0 - z * z) * cos;
    r
}
