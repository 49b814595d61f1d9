//! glTF accessors read from their buffers with every range checked first: an accessor that
//! overruns its buffer view, a view that overruns its buffer, a stride shorter than an element
//! or a sparse index past the end is a located error, never a panic or a read out of bounds.
//! The count is bounded before anything is allocated (a sparse accessor needs no data for
//! its base, so its count alone could otherwise ask for any memory).

use gltf::accessor::{DataType, Dimensions};

use crate::diagnostic::{Diagnostics, SceneError};
use crate::gltf::locate::Locator;

pub(crate) struct Accessors<'a, 't> {
    pub buffers: &'a [Vec<u8>],
    pub locator: &'a Locator<'t>,
    pub diagnostics: &'a Diagnostics<'t>,
    /// The most elements one accessor may hold.
    pub max_elements: u64,
}

fn component_size(data_type: DataType) -> u64 {
    match data_type {
        DataType::I8 | DataType::U8 => 1,
        DataType::I16 | DataType::U16 => 2,
        DataType::U32 | DataType::F32 => 4,
    }
}

fn dimension_count(dimensions: Dimensions) -> u64 {
    match dimensions {
        Dimensions::Scalar => 1,
        Dimensions::Vec2 => 2,
        Dimensions::Vec3 => 3,
        Dimensions::Vec4 | Dimensions::Mat2 => 4,
        Dimensions::Mat3 => 9,
        Dimensions::Mat4 => 16,
    }
}

/// One component at the start of `bytes` as f32, normalised as the specification says
/// for integer types marked `normalized`.
#[inline]
fn component(bytes: &[u8], data_type: DataType, normalized: bool) -> f32 {
    match data_type {
        DataType::F32 => f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
        DataType::U8 => {
            let v = f32::from(bytes[0]);
            if normalized {
                v / 255.0
            } else {
                v
            }
        }
        DataType::I8 => {
            let v = f32::from(bytes[0] as i8);
            if normalized {
                (v / 127.0).max(-1.0)
            } else {
                v
            }
        }
        DataType::U16 => {
            let v = f32::from(u16::from_le_bytes([bytes[0], bytes[1]]));
            if normalized {
                v / 65535.0
            } else {
                v
            }
        }
        DataType::I16 => {
            let v = f32::from(i16::from_le_bytes([bytes[0], bytes[1]]));
            if normalized {
                (v / 32767.0).max(-1.0)
            } else {
                v
            }
        }
        DataType::U32 => u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]) as f32,
    }
}

#[inline]
fn integer(bytes: &[u8], data_type: DataType) -> u32 {
    match data_type {
        DataType::U8 => u32::from(bytes[0]),
        DataType::U16 => u32::from(u16::from_le_bytes([bytes[0], bytes[1]])),
        _ => u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
    }
}

impl Accessors<'_, '_> {
    fn error(&self, path: &str, message: String) -> SceneError {
        self.diagnostics
            .error(self.locator.span(path, self.diagnostics), message)
    }

    /// The bytes of `view`, checked against its buffer.
    fn view_bytes(&self, view: &gltf::buffer::View) -> Result<&[u8], SceneError> {
        let buffer = &self.buffers[view.buffer().index()];
        let start = view.offset() as u64;
        let end = start.checked_add(view.length() as u64);
        match end {
            Some(end) if end <= buffer.len() as u64 && end <= view.buffer().length() as u64 => {
                Ok(&buffer[start as usize..end as usize])
            }
            _ => Err(self.error(
                &format!("bufferViews[{}]", view.index()),
                format!(
                    "the buffer view's bytes {}..{} overrun its buffer of {} bytes",
                    start,
                    end.map_or("∞".to_string(), |e| e.to_string()),
                    view.buffer().length()
                ),
            )),
        }
    }

    /// The bytes of `count` elements of `element` bytes every `stride` from `offset` in
    /// `view`, checked.
    #[allow(clippy::too_many_arguments)]
    fn strided<'b>(
        &self,
        bytes: &'b [u8],
        offset: u64,
        stride: u64,
        count: u64,
        element: u64,
        at: &str,
        what: &str,
    ) -> Result<&'b [u8], SceneError> {
        if count == 0 {
            return Ok(&[]);
        }
        let end = stride
            .checked_mul(count - 1)
            .and_then(|s| s.checked_add(element))
            .and_then(|s| s.checked_add(offset));
        match end {
            Some(end) if end <= bytes.len() as u64 => Ok(&bytes[offset as usize..end as usize]),
            _ => Err(self.error(
                at,
                format!(
                    "{what} needs {} bytes from offset {offset} but its buffer view holds {}",
                    end.map_or("more than 2^64".to_string(), |e| (e - offset).to_string()),
                    bytes.len()
                ),
            )),
        }
    }

    fn check_count(&self, accessor: &gltf::Accessor, at: &str) -> Result<u64, SceneError> {
        let count = accessor.count() as u64;
        if count > self.max_elements {
            return Err(self.error(
                at,
                format!(
                    "the accessor holds {count} elements, more than the limit of {} \
                     (--max-triangles raises it)",
                    self.max_elements
                ),
            ));
        }
        Ok(count)
    }

    /// The accessor's elements as f32, `n` components each (`n` its dimension count), with
    /// sparse substitution; `dimensions` lists what the caller accepts.
    pub(crate) fn floats(
        &self,
        accessor: &gltf::Accessor,
        dimensions: &[Dimensions],
        what: &str,
    ) -> Result<Vec<f32>, SceneError> {
        let at = format!("accessors[{}]", accessor.index());
        if !dimensions.contains(&accessor.dimensions()) {
            return Err(self.error(
                &format!("{at}.type"),
                format!(
                    "{what} must be {}, not {:?}",
                    dimensions
                        .iter()
                        .map(|d| format!("{d:?}").to_uppercase())
                        .collect::<Vec<_>>()
                        .join(" or "),
                    accessor.dimensions()
                ),
            ));
        }
        let count = self.check_count(accessor, &at)?;
        let n = dimension_count(accessor.dimensions());
        let data_type = accessor.data_type();
        let normalized = accessor.normalized();
        let size = component_size(data_type);
        let element = n * size;
        let mut out = vec![0.0f32; (count * n) as usize];
        if let Some(view) = accessor.view() {
            let bytes = self.view_bytes(&view)?;
            let stride = view.stride().map_or(element, |s| s as u64);
            if stride < element {
                return Err(self.error(
                    &format!("bufferViews[{}].byteStride", view.index()),
                    format!(
                        "a stride of {stride} bytes is shorter than {what}'s elements of {element}"
                    ),
                ));
            }
            let data = self.strided(
                bytes,
                accessor.offset() as u64,
                stride,
                count,
                element,
                &at,
                what,
            )?;
            for (i, slot) in out.chunks_exact_mut(n as usize).enumerate() {
                let base = i * stride as usize;
                for (c, value) in slot.iter_mut().enumerate() {
                    let at = base + c * size as usize;
                    *value = component(&data[at..at + size as usize], data_type, normalized);
                }
            }
        }
        if let Some(sparse) = accessor.sparse() {
            let at = format!("{at}.sparse");
            let indices = self.sparse_indices(&sparse, count, &at)?;
            let values_view = sparse.values().view();
            let bytes = self.view_bytes(&values_view)?;
            let data = self.strided(
                bytes,
                sparse.values().offset() as u64,
                element,
                indices.len() as u64,
                element,
                &format!("{at}.values"),
                "the sparse values",
            )?;
            for (k, &index) in indices.iter().enumerate() {
                let base = k * element as usize;
                for c in 0..n as usize {
                    let at = base + c * size as usize;
                    out[index as usize * n as usize + c] =
                        component(&data[at..at + size as usize], data_type, normalized);
                }
            }
        }
        Ok(out)
    }

    fn sparse_indices(
        &self,
        sparse: &gltf::accessor::sparse::Sparse,
        count: u64,
        at: &str,
    ) -> Result<Vec<u32>, SceneError> {
        let n = sparse.count() as u64;
        if n > count {
            return Err(self.error(
                &format!("{at}.count"),
                format!("{n} sparse values for an accessor of {count} elements"),
            ));
        }
        let indices = sparse.indices();
        let (data_type, size) = match indices.index_type() {
            gltf::accessor::sparse::IndexType::U8 => (DataType::U8, 1),
            gltf::accessor::sparse::IndexType::U16 => (DataType::U16, 2),
            gltf::accessor::sparse::IndexType::U32 => (DataType::U32, 4),
        };
        let bytes = self.view_bytes(&indices.view())?;
        let data = self.strided(
            bytes,
            indices.offset() as u64,
            size,
            n,
            size,
            &format!("{at}.indices"),
            "the sparse indices",
        )?;
        let out: Vec<u32> = data
            .chunks_exact(size as usize)
            .map(|b| integer(b, data_type))
            .collect();
        if let Some(bad) = out.iter().find(|&&i| u64::from(i) >= count) {
            return Err(self.error(
                &format!("{at}.indices"),
                format!("a sparse index {bad} is past the accessor's {count} elements"),
            ));
        }
        Ok(out)
    }

    /// A primitive's indices: SCALAR unsigned byte, short or int, not normalised.
    pub(crate) fn indices(&self, accessor: &gltf::Accessor) -> Result<Vec<u32>, SceneError> {
        let at = format!("accessors[{}]", accessor.index());
        let data_type = accessor.data_type();
        if accessor.dimensions() != Dimensions::Scalar
            || !matches!(data_type, DataType::U8 | DataType::U16 | DataType::U32)
            || accessor.normalized()
        {
            return Err(self.error(
                &at,
                "indices must be SCALAR unsigned bytes, shorts or ints, not normalized".into(),
            ));
        }
        // Integers up to 2^32 do not fit an f32 exactly: read them as integers.
        let count = self.check_count(accessor, &at)?;
        let size = component_size(data_type);
        let mut out = vec![0u32; count as usize];
        if let Some(view) = accessor.view() {
            let bytes = self.view_bytes(&view)?;
            let stride = view.stride().map_or(size, |s| s as u64);
            if stride < size {
                return Err(self.error(
                    &format!("bufferViews[{}].byteStride", view.index()),
                    format!("a stride of {stride} bytes is shorter than an index"),
                ));
            }
            let data = self.strided(
                bytes,
                accessor.offset() as u64,
                stride,
                count,
                size,
                &at,
                "the indices",
            )?;
            for (i, slot) in out.iter_mut().enumerate() {
                let at = i * stride as usize;
                *slot = integer(&data[at..at + size as usize], data_type);
            }
        }
        if let Some(sparse) = accessor.sparse() {
            let at = format!("{at}.sparse");
            let indices = self.sparse_indices(&sparse, count, &at)?;
            let bytes = self.view_bytes(&sparse.values().view())?;
            let data = self.strided(
                bytes,
                sparse.values().offset() as u64,
                size,
                indices.len() as u64,
                size,
                &format!("{at}.values"),
                "the sparse values",
            )?;
            for (k, &index) in indices.iter().enumerate() {
                let at = k * size as usize;
                out[index as usize] = integer(&data[at..at + size as usize], data_type);
            }
        }
        Ok(out)
    }
}
