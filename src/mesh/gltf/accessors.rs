//! Accessor data decoded with every byte range checked: the `gltf` crate's own readers assume
//! a valid file.

use ::gltf::Accessor;
use ::gltf::accessor::{DataType, Dimensions};

/// Where an accessor's elements lie: the buffer, the first byte, the stride and element size.
struct Layout<'b> {
    data: &'b [u8],
    start: usize,
    stride: usize,
    element: usize,
}

/// Checks that `count` elements of `element` bytes at `offset` with `stride` fit in `view`, and
/// `view` in its buffer; names the accessor (or `what`) and the view when they do not.
fn layout<'b>(
    view: &::gltf::buffer::View<'_>,
    offset: usize,
    count: usize,
    element: usize,
    stride: Option<usize>,
    buffers: &'b [Vec<u8>],
    what: &str,
) -> std::result::Result<Layout<'b>, String> {
    let v = view.index();
    let buffer = view.buffer();
    let data = buffers.get(buffer.index()).map_or(&[][..], Vec::as_slice);
    let view_end = view.offset().checked_add(view.length());
    let Some(view_data) = view_end.and_then(|end| data.get(view.offset()..end).filter(|_| end <= buffer.length()))
    else {
        return Err(format!(
            "buffer view {v}: bytes {}..{} lie past the end of buffer {} ({} bytes)",
            view.offset(),
            view.offset() as u128 + view.length() as u128,
            buffer.index(),
            buffer.length()
        ));
    };
    let stride = stride.unwrap_or(element);
    if stride < element {
        return Err(format!(
            "{what}: buffer view {v} has byteStride {stride}, less than the {element}-byte element size"
        ));
    }
    let end = match count {
        0 => Some(offset),
        _ => (count - 1).checked_mul(stride).and_then(|s| s.checked_add(offset)).and_then(|s| s.checked_add(element)),
    };
    match end {
        Some(end) if end <= view_data.len() => Ok(Layout { data: view_data, start: offset, stride, element }),
        _ => Err(format!(
            "{what}: {count} elements of {element} bytes at offset {offset} (stride {stride}) run past the end of buffer view {v} ({} bytes)",
            view_data.len()
        )),
    }
}

/// Reads element `i`'s components of type `t` from `layout` (in range: [`layout`] checked it).
fn components(layout: &Layout<'_>, i: usize, t: DataType, into: &mut Vec<f64>) {
    let at = layout.start + i * layout.stride;
    let bytes = layout.data.get(at..at + layout.element).unwrap_or_default();
    let size = t.size();
    for c in bytes.chunks_exact(size) {
        let value = match t {
            DataType::I8 => f64::from(c[0] as i8),
            DataType::U8 => f64::from(c[0]),
            DataType::I16 => f64::from(i16::from_le_bytes([c[0], c[1]])),
            DataType::U16 => f64::from(u16::from_le_bytes([c[0], c[1]])),
            DataType::U32 => f64::from(u32::from_le_bytes([c[0], c[1], c[2], c[3]])),
            DataType::F32 => f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]])),
        };
        into.push(value);
    }
}

/// Whether a sparse accessor without a buffer view, `count` elements of `element` bytes, is as
/// large as the file's data can account for. Such an accessor is all zeros but the
/// substitutions, so its count alone sizes the allocation: a few bytes of JSON could declare
/// gigabytes. Where it is used (morph-target deltas, a sparse position array) its elements
/// stand beside another accessor's that are stored, so its stored size may not exceed all the
/// buffers' bytes together.
fn viewless_size_ok(count: usize, element: usize, buffers: &[Vec<u8>]) -> std::result::Result<(), String> {
    let backed: usize = buffers.iter().map(Vec::len).sum();
    match count.checked_mul(element) {
        Some(size) if size <= backed => Ok(()),
        _ => Err(format!(
            "count {count} without a buffer view ({element}-byte elements) exceeds the {backed} bytes of the file's buffers"
        )),
    }
}

/// All of an accessor's components, as stored (not normalised), sparse substitutions applied.
pub(super) fn accessor_values(
    accessor: &Accessor<'_>,
    buffers: &[Vec<u8>],
    dims: usize,
) -> std::result::Result<Vec<f64>, String> {
    let what = format!("accessor {}", accessor.index());
    let t = accessor.data_type();
    let element = t.size() * dims;
    let count = accessor.count();
    let mut values = Vec::new();
    match accessor.view() {
        Some(view) => {
            let l = layout(&view, accessor.offset(), count, element, view.stride(), buffers, &what)?;
            values.reserve(count * dims);
            for i in 0..count {
                components(&l, i, t, &mut values);
            }
        }
        // Only a sparse accessor has no view; its count is not bounded by any buffer's size.
        None => {
            viewless_size_ok(count, element, buffers).map_err(|problem| format!("{what}: {problem}"))?;
            values.resize(count * dims, 0.0);
        }
    }
    if let Some(sparse) = accessor.sparse() {
        let n = sparse.count();
        let indices = sparse.indices();
        let index_type = match indices.index_type() {
            ::gltf::accessor::sparse::IndexType::U8 => DataType::U8,
            ::gltf::accessor::sparse::IndexType::U16 => DataType::U16,
            ::gltf::accessor::sparse::IndexType::U32 => DataType::U32,
        };
        let sparse_what = format!("{what} (sparse indices)");
        let il = layout(&indices.view(), indices.offset(), n, index_type.size(), None, buffers, &sparse_what)?;
        let vl = layout(
            &sparse.values().view(),
            sparse.values().offset(),
            n,
            element,
            None,
            buffers,
            &format!("{what} (sparse values)"),
        )?;
        let mut index = Vec::with_capacity(1);
        let mut substitute = Vec::with_capacity(dims);
        for k in 0..n {
            index.clear();
            substitute.clear();
            components(&il, k, index_type, &mut index);
            components(&vl, k, t, &mut substitute);
            let target = index.first().map_or(usize::MAX, |&i| i as usize);
            let slot = target.checked_mul(dims).and_then(|s| values.get_mut(s..s + dims));
            let Some(slot) = slot else {
                return Err(format!("{what}: sparse index {target} is past the accessor's {count} elements"));
            };
            slot.copy_from_slice(&substitute);
        }
    }
    Ok(values)
}

/// An attribute accessor as `N`-component float vectors (normalised if the accessor says so).
pub(super) fn read_vectors<const N: usize>(
    accessor: &Accessor<'_>,
    buffers: &[Vec<u8>],
    name: &str,
) -> std::result::Result<Vec<[f32; N]>, String> {
    let dims = accessor.dimensions().multiplicity();
    let matrix = matches!(accessor.dimensions(), Dimensions::Mat2 | Dimensions::Mat3 | Dimensions::Mat4);
    if dims != N || matrix {
        return Err(format!(
            "accessor {} ({name}) has type {:?}; expected {}",
            accessor.index(),
            accessor.dimensions(),
            ["SCALAR", "VEC2", "VEC3", "VEC4"].get(N - 1).unwrap_or(&"?")
        ));
    }
    let t = accessor.data_type();
    let normalised = accessor.normalized();
    let values = accessor_values(accessor, buffers, dims)?;
    let mut out = Vec::with_capacity(values.len() / N);
    for (i, chunk) in values.chunks_exact(N).enumerate() {
        let mut v = [0.0f32; N];
        for (slot, &raw) in v.iter_mut().zip(chunk) {
            *slot = if normalised { normalise(raw, t) } else { raw as f32 };
            if !slot.is_finite() {
                return Err(format!("accessor {} ({name}): element {i} has a non-finite value", accessor.index()));
            }
        }
        out.push(v);
    }
    Ok(out)
}

/// glTF's normalised-integer decoding (spec section 3.11).
pub(super) fn normalise(raw: f64, t: DataType) -> f32 {
    (match t {
        DataType::I8 => (raw / 127.0).max(-1.0),
        DataType::U8 => raw / 255.0,
        DataType::I16 => (raw / 32767.0).max(-1.0),
        DataType::U16 => raw / 65535.0,
        DataType::U32 => raw / f64::from(u32::MAX),
        DataType::F32 => raw,
    }) as f32
}

/// A primitive's index accessor: unsigned integer scalars, each below `vertex_count`.
pub(super) fn read_indices(
    accessor: &Accessor<'_>,
    buffers: &[Vec<u8>],
    vertex_count: usize,
) -> std::result::Result<Vec<u32>, String> {
    let a = accessor.index();
    if accessor.dimensions() != Dimensions::Scalar
        || !matches!(accessor.data_type(), DataType::U8 | DataType::U16 | DataType::U32)
    {
        return Err(format!(
            "accessor {a} (indices) has type {:?} of {:?}; expected SCALAR of an unsigned integer type",
            accessor.dimensions(),
            accessor.data_type()
        ));
    }
    let values = accessor_values(accessor, buffers, 1)?;
    let mut indices = Vec::with_capacity(values.len());
    for (i, &v) in values.iter().enumerate() {
        if v >= vertex_count as f64 {
            return Err(format!(
                "accessor {a} (indices): index {i} is {v}, but the primitive has {vertex_count} vertices"
            ));
        }
        indices.push(v as u32);
    }
    Ok(indices)
}

/// Where each element of `accessor` is stored: its buffer, each element's first byte in that
/// buffer, and the element size. What rewriting an accessor in place needs; a sparse accessor,
/// or one without a buffer view, is refused (its elements are not all stored in one place).
pub(super) fn element_offsets(
    accessor: &Accessor<'_>,
    buffers: &[Vec<u8>],
) -> std::result::Result<(usize, Vec<usize>, usize), String> {
    let what = format!("accessor {}", accessor.index());
    let (Some(view), None) = (accessor.view(), accessor.sparse()) else {
        return Err(format!("{what} is sparse: its elements are not stored in one place"));
    };
    let element = accessor.size();
    let l = layout(&view, accessor.offset(), accessor.count(), element, view.stride(), buffers, &what)?;
    let first = view.offset() + l.start;
    Ok((view.buffer().index(), (0..accessor.count()).map(|i| first + i * l.stride).collect(), element))
}
