//! Reading an accessor's values out of its buffer view, every byte range checked first: the
//! element layout (component type, count per element, normalisation, stride), sparse
//! substitution, and the zeros of an accessor without a view (glTF 2.0 §3.6.2).

use gltf::Accessor;
use gltf::accessor::{DataType, Dimensions};

/// The bytes of every buffer, in the file's order.
pub(super) type BufferData<'d> = &'d [std::borrow::Cow<'d, [u8]>];

/// Reads `accessor` as `N` numbers per element (`dimensions` must match), each converted to `f32`
/// (normalised integers to [0, 1] or [-1, 1]); the error is a reason, without the accessor's name.
pub(super) fn read_floats<const N: usize>(
    accessor: &Accessor,
    dimensions: Dimensions,
    buffers: BufferData,
) -> Result<Vec<[f32; N]>, String> {
    if accessor.dimensions() != dimensions {
        return Err(format!("holds {:?} elements; lumiere reads {dimensions:?} here", accessor.dimensions()));
    }
    let kind = accessor.data_type();
    let normalized = accessor.normalized();
    read(accessor, buffers, [0.0; N], |bytes| {
        std::array::from_fn(|i| component(kind, normalized, &bytes[i * kind.size()..]))
    })
}

/// Reads `accessor` as vertex indices: unsigned integers of one, two or four bytes, one per element.
pub(super) fn read_indices(accessor: &Accessor, buffers: BufferData) -> Result<Vec<u32>, String> {
    if accessor.dimensions() != Dimensions::Scalar || accessor.normalized() {
        return Err("indices must be scalars, not normalised".to_string());
    }
    let kind = accessor.data_type();
    if !matches!(kind, DataType::U8 | DataType::U16 | DataType::U32) {
        return Err(format!("indices of type {kind:?}; they must be unsigned integers"));
    }
    read(accessor, buffers, 0, |bytes| unsigned(kind, bytes))
}

/// One component of type `kind` at the start of `bytes`, as a float: normalised integers map to
/// [0, 1] (unsigned) or [-1, 1] (signed, the most negative value clamped), as the format says.
fn component(kind: DataType, normalized: bool, bytes: &[u8]) -> f32 {
    let pair = || [bytes[0], bytes[1]];
    match (kind, normalized) {
        (DataType::I8, true) => (f32::from(bytes[0] as i8) / 127.0).max(-1.0),
        (DataType::I8, false) => f32::from(bytes[0] as i8),
        (DataType::U8, true) => f32::from(bytes[0]) / 255.0,
        (DataType::U8, false) => f32::from(bytes[0]),
        (DataType::I16, true) => (f32::from(i16::from_le_bytes(pair())) / 32767.0).max(-1.0),
        (DataType::I16, false) => f32::from(i16::from_le_bytes(pair())),
        (DataType::U16, true) => f32::from(u16::from_le_bytes(pair())) / 65535.0,
        (DataType::U16, false) => f32::from(u16::from_le_bytes(pair())),
        (DataType::U32, _) => u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]) as f32,
        (DataType::F32, _) => f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
    }
}

fn unsigned(kind: DataType, bytes: &[u8]) -> u32 {
    match kind {
        DataType::U8 => u32::from(bytes[0]),
        DataType::U16 => u32::from(u16::from_le_bytes([bytes[0], bytes[1]])),
        _ => u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
    }
}

/// The elements of `accessor`, each decoded by `decode` from its bytes (exactly one element's);
/// an accessor without a view holds `zero`s, as the format says.
fn read<T: Copy>(
    accessor: &Accessor,
    buffers: BufferData,
    zero: T,
    decode: impl Fn(&[u8]) -> T,
) -> Result<Vec<T>, String> {
    let count = accessor.count();
    let element = accessor.size();
    let mut values = Vec::new();
    match accessor.view() {
        Some(view) => {
            let stride = view.stride().unwrap_or(element);
            if stride < element {
                return Err(format!("a stride of {stride} bytes for elements of {element}"));
            }
            let bytes = view_bytes(&view, buffers)?;
            let start = accessor.offset();
            let needed = (count as u128).checked_sub(1).map_or(0, |last| last * stride as u128 + element as u128);
            if start as u128 + needed > bytes.len() as u128 {
                return Err(format!(
                    "{count} elements of {element} bytes, {stride} apart, from byte {start} of buffer view {}, which has {} bytes",
                    view.index(),
                    bytes.len()
                ));
            }
            values.try_reserve_exact(count).map_err(|_| format!("no memory left for {count} elements"))?;
            values.extend((0..count).map(|i| decode(&bytes[start + i * stride..start + i * stride + element])));
        }
        None => {
            values.try_reserve_exact(count).map_err(|_| format!("no memory left for {count} elements"))?;
            values.resize(count, zero);
        }
    }
    if let Some(sparse) = accessor.sparse() {
        substitute(&sparse, count, element, buffers, &decode, &mut values)?;
    }
    Ok(values)
}

/// A buffer view's bytes, checked to lie in its buffer.
pub(super) fn view_bytes<'d>(view: &gltf::buffer::View, buffers: BufferData<'d>) -> Result<&'d [u8], String> {
    let buffer = &buffers[view.buffer().index()];
    let (start, length) = (view.offset(), view.length());
    match start.checked_add(length) {
        Some(end) if end <= buffer.len() => Ok(&buffer[start..end]),
        _ => Err(format!(
            "buffer view {} spans bytes {start} to {} of buffer {}, which has {}",
            view.index(),
            start as u128 + length as u128,
            view.buffer().index(),
            buffer.len()
        )),
    }
}

/// Replaces the elements a sparse accessor lists with its values.
fn substitute<T>(
    sparse: &gltf::accessor::sparse::Sparse,
    count: usize,
    element: usize,
    buffers: BufferData,
    decode: &impl Fn(&[u8]) -> T,
    values: &mut [T],
) -> Result<(), String> {
    let changed = sparse.count();
    if changed > count {
        return Err(format!("a sparse substitution of {changed} elements in an accessor of {count}"));
    }
    let indices = sparse.indices();
    let index_size = match indices.index_type() {
        gltf::accessor::sparse::IndexType::U8 => 1,
        gltf::accessor::sparse::IndexType::U16 => 2,
        gltf::accessor::sparse::IndexType::U32 => 4,
    };
    let index_kind = [DataType::U8, DataType::U16, DataType::U8, DataType::U32][index_size - 1];
    let index_bytes = sparse_range(&indices.view(), indices.offset(), changed, index_size, buffers, "indices")?;
    let value_bytes =
        sparse_range(&sparse.values().view(), sparse.values().offset(), changed, element, buffers, "values")?;
    for i in 0..changed {
        let at = unsigned(index_kind, &index_bytes[i * index_size..]) as usize;
        let Some(slot) = values.get_mut(at) else {
            return Err(format!("sparse index {at} out of range: the accessor has {count} elements"));
        };
        *slot = decode(&value_bytes[i * element..(i + 1) * element]);
    }
    Ok(())
}

/// The bytes of `count` tightly packed items of `size` bytes from `offset` in `view`.
fn sparse_range<'d>(
    view: &gltf::buffer::View,
    offset: usize,
    count: usize,
    size: usize,
    buffers: BufferData<'d>,
    what: &str,
) -> Result<&'d [u8], String> {
    let bytes = view_bytes(view, buffers)?;
    let needed = offset as u128 + count as u128 * size as u128;
    if needed > bytes.len() as u128 {
        return Err(format!(
            "sparse {what}: {count} of {size} bytes from byte {offset} of buffer view {}, which has {}",
            view.index(),
            bytes.len()
        ));
    }
    Ok(&bytes[offset..needed as usize])
}
