//! `EXT_meshopt_compression` (what gltfpack writes): buffer views stored compressed by
//! meshoptimizer's vertex and index codecs, decoded at load into the bytes the view describes,
//! so that the accessors read them as they read any view.
//!
//! The vertex and triangle codecs are meshoptimizer's own (the `meshopt` crate builds its C++
//! source): the format is defined by that implementation, and its decoders check every read
//! against the input's length (a malformed stream is an error code, not a read past the end).
//! The index-sequence codec (mode INDICES) and the filters (octahedral, quaternion,
//! exponential) are written here from the extension's specification, because the crate binds
//! them only as unsafe calls and the workspace forbids unsafe code. Each view's decoded size is
//! charged to the decoded-bytes budget before anything is allocated.

use crate::limits::Budget;
use anyhow::{Result, anyhow, bail};
use gltf::json::Root;
use serde_json::Value;

pub const EXTENSION: &str = "EXT_meshopt_compression";

/// Whether buffer `b` is a fallback buffer: no data of its own (no uri), only the space the
/// compressed views decode into.
pub fn is_fallback(b: &gltf::Buffer) -> bool {
    b.extension_value(EXTENSION)
        .and_then(|e| e.get("fallback"))
        .and_then(Value::as_bool)
        .unwrap_or(false)
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Mode {
    Attributes,
    Triangles,
    Indices,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Filter {
    None,
    Octahedral,
    Quaternion,
    Exponential,
}

/// One compressed view, as its extension object describes it.
struct Compressed {
    buffer: usize,
    offset: usize,
    length: usize,
    stride: usize,
    count: usize,
    mode: Mode,
    filter: Filter,
}

fn parse(e: &Value, here: &str) -> Result<Compressed> {
    let int = |key: &str, default: Option<u64>| -> Result<usize> {
        let v = match e.get(key) {
            Some(v) => v.as_u64().ok_or_else(|| anyhow!("{here}: {key} is not a count"))?,
            None => default.ok_or_else(|| anyhow!("{here}: {key} is missing"))?,
        };
        usize::try_from(v).map_err(|_| anyhow!("{here}: {key} {v} is too large"))
    };
    let mode = match e.get("mode").and_then(Value::as_str) {
        Some("ATTRIBUTES") => Mode::Attributes,
        Some("TRIANGLES") => Mode::Triangles,
        Some("INDICES") => Mode::Indices,
        m => bail!("{here}: mode {m:?} is not ATTRIBUTES, TRIANGLES or INDICES"),
    };
    let filter = match e.get("filter").and_then(Value::as_str) {
        None | Some("NONE") => Filter::None,
        Some("OCTAHEDRAL") => Filter::Octahedral,
        Some("QUATERNION") => Filter::Quaternion,
        Some("EXPONENTIAL") => Filter::Exponential,
        Some(f) => bail!("{here}: unknown filter {f:?}"),
    };
    let c = Compressed {
        buffer: int("buffer", None)?,
        offset: int("byteOffset", Some(0))?,
        length: int("byteLength", None)?,
        stride: int("byteStride", None)?,
        count: int("count", None)?,
        mode,
        filter,
    };
    // The limits of the extension's specification ("Compressing Buffer Views").
    let stride_ok = match (c.mode, c.filter) {
        (Mode::Attributes, Filter::None) => {
            c.stride.is_multiple_of(4) && (4..=256).contains(&c.stride)
        }
        (Mode::Attributes, Filter::Octahedral) => c.stride == 4 || c.stride == 8,
        (Mode::Attributes, Filter::Quaternion) => c.stride == 8,
        (Mode::Attributes, Filter::Exponential) => {
            c.stride.is_multiple_of(4) && (4..=256).contains(&c.stride)
        }
        (_, Filter::None) => c.stride == 2 || c.stride == 4,
        _ => false,
    };
    if !stride_ok {
        bail!(
            "{here}: byteStride {} does not suit mode {:?} with filter {:?}",
            c.stride,
            c.mode,
            c.filter
        );
    }
    if c.mode == Mode::Triangles && !c.count.is_multiple_of(3) {
        bail!("{here}: TRIANGLES count {} is not a multiple of 3", c.count);
    }
    Ok(c)
}

/// Decode every compressed view of `root` into the bytes of `buffers` that the view itself
/// names (its buffer, byteOffset and byteLength: a fallback buffer's space, or uncompressed
/// data that the decoded bytes equal).
/// Returns warnings for views it leaves as they are.
pub fn decompress(root: &Root, buffers: &mut [Vec<u8>], budget: &mut Budget) -> Result<()> {
    for (i, view) in root.buffer_views.iter().enumerate() {
        let Some(e) = view.extensions.as_ref().and_then(|x| x.others.get(EXTENSION)) else {
            continue;
        };
        let here = format!("bufferViews[{i}].extensions.{EXTENSION}");
        let c = parse(e, &here)?;
        let size = c
            .count
            .checked_mul(c.stride)
            .ok_or_else(|| anyhow!("{here}: {} x {} bytes overflows", c.count, c.stride))?;
        if size as u64 != view.byte_length.0 {
            bail!(
                "{here}: decodes to {} x {} = {size} bytes, the view holds {}",
                c.count,
                c.stride,
                view.byte_length.0
            );
        }
        budget.decode(size as u64, &here)?;
        let source = buffers
            .get(c.buffer)
            .and_then(|b| b.get(c.offset..c.offset.checked_add(c.length)?))
            .ok_or_else(|| {
                anyhow!(
                    "{here}: bytes {}..+{} lie outside buffers[{}]",
                    c.offset,
                    c.length,
                    c.buffer
                )
            })?
            .to_vec();
        let mut out = vec![0u8; size];
        decode(&c, &source, &mut out).map_err(|e| anyhow!("{here}: {e}"))?;
        let start = view.byte_offset.map_or(0, |o| o.0) as usize;
        let target = buffers
            .get_mut(view.buffer.value())
            .and_then(|b| b.get_mut(start..start.checked_add(size)?))
            .ok_or_else(|| {
                anyhow!(
                    "bufferViews[{i}]: bytes {start}..+{size} lie outside buffers[{}]",
                    view.buffer.value()
                )
            })?;
        target.copy_from_slice(&out);
    }
    Ok(())
}

fn decode(c: &Compressed, src: &[u8], out: &mut [u8]) -> Result<(), String> {
    let codec = |e: meshopt::Error| e.to_string();
    let decoded = match c.mode {
        Mode::Attributes => vertex_bytes(src, c.count, c.stride).map_err(codec),
        Mode::Triangles if c.stride == 2 => meshopt::decode_index_buffer::<u16>(src, c.count)
            .map(|v| v.iter().flat_map(|i| i.to_le_bytes()).collect())
            .map_err(codec),
        Mode::Triangles => meshopt::decode_index_buffer::<u32>(src, c.count)
            .map(|v| v.iter().flat_map(|i| i.to_le_bytes()).collect())
            .map_err(codec),
        Mode::Indices => index_sequence(src, c.count, c.stride),
    }
    .map_err(|e| format!("the compressed data does not decode ({e})"))?;
    if decoded.len() != out.len() {
        return Err(format!("decoded {} bytes where {} were expected", decoded.len(), out.len()));
    }
    out.copy_from_slice(&decoded);
    match c.filter {
        Filter::None => {}
        Filter::Octahedral if c.stride == 4 => out.chunks_exact_mut(4).for_each(octahedral8),
        Filter::Octahedral => out.chunks_exact_mut(8).for_each(octahedral16),
        Filter::Quaternion => out.chunks_exact_mut(8).for_each(quaternion),
        Filter::Exponential => out.chunks_exact_mut(4).for_each(exponential),
    }
    Ok(())
}

/// Mode INDICES, the index-sequence codec ("Mode 2: indices" of the extension's specification):
/// a header byte 0xd1, then per index a varint whose low bit picks one of two baselines and
/// whose other bits are the zigzag delta from it, then a 4-byte tail. Used for the indices of
/// strips, fans, lines and points. Little-endian indices of `stride` bytes out.
fn index_sequence(src: &[u8], count: usize, stride: usize) -> Result<Vec<u8>, String> {
    const TAIL: usize = 4;
    // A stream at least as long as its shortest valid encoding, one byte per index, so that a
    // count far beyond the data is refused before the output is filled.
    if src.len() < 1 + count + TAIL {
        return Err(format!("{} bytes cannot hold {count} indices", src.len()));
    }
    // Version 1 is what the specification requires; version 0 streams of older encoders
    // decode the same way.
    if src[0] != 0xd1 && src[0] != 0xd0 {
        return Err(format!("header {:#04x} is not an index sequence's 0xd1", src[0]));
    }
    let end = src.len() - TAIL;
    let mut at = 1;
    let mut last = [0u32; 2];
    let mut out = Vec::with_capacity(count * stride);
    for _ in 0..count {
        if at >= end {
            return Err(format!("the stream ends before index {}", out.len() / stride));
        }
        // Seven bits a byte, low group first, at most five bytes.
        let mut v = 0u32;
        for k in 0..5 {
            let byte = *src.get(at).ok_or("a varint runs past the end")?;
            at += 1;
            v |= u32::from(byte & 0x7f).wrapping_shl(7 * k);
            if byte < 0x80 {
                break;
            }
        }
        let baseline = (v & 1) as usize;
        let delta = (v >> 2) ^ (v >> 1 & 1).wrapping_neg();
        let index = last[baseline].wrapping_add(delta);
        last[baseline] = index;
        if stride == 2 {
            out.extend_from_slice(&(index as u16).to_le_bytes());
        } else {
            out.extend_from_slice(&index.to_le_bytes());
        }
    }
    Ok(out)
}

/// One vertex of N bytes, for the vertex codec (which decodes elements of a type's size).
#[derive(Clone, Copy)]
struct Bytes<const N: usize>([u8; N]);

impl<const N: usize> Default for Bytes<N> {
    fn default() -> Self {
        Bytes([0; N])
    }
}

fn vertices<const N: usize>(src: &[u8], count: usize) -> meshopt::Result<Vec<u8>> {
    Ok(meshopt::decode_vertex_buffer::<Bytes<N>>(src, count)?.iter().flat_map(|v| v.0).collect())
}

/// The vertex codec at a stride the extension allows (a multiple of 4 up to 256).
fn vertex_bytes(src: &[u8], count: usize, stride: usize) -> meshopt::Result<Vec<u8>> {
    match stride {
        4 => vertices::<4>(src, count),
        8 => vertices::<8>(src, count),
        12 => vertices::<12>(src, count),
        16 => vertices::<16>(src, count),
        20 => vertices::<20>(src, count),
        24 => vertices::<24>(src, count),
        28 => vertices::<28>(src, count),
        32 => vertices::<32>(src, count),
        36 => vertices::<36>(src, count),
        40 => vertices::<40>(src, count),
        44 => vertices::<44>(src, count),
        48 => vertices::<48>(src, count),
        52 => vertices::<52>(src, count),
        56 => vertices::<56>(src, count),
        60 => vertices::<60>(src, count),
        64 => vertices::<64>(src, count),
        68 => vertices::<68>(src, count),
        72 => vertices::<72>(src, count),
        76 => vertices::<76>(src, count),
        80 => vertices::<80>(src, count),
        84 => vertices::<84>(src, count),
        88 => vertices::<88>(src, count),
        92 => vertices::<92>(src, count),
        96 => vertices::<96>(src, count),
        100 => vertices::<100>(src, count),
        104 => vertices::<104>(src, count),
        108 => vertices::<108>(src, count),
        112 => vertices::<112>(src, count),
        116 => vertices::<116>(src, count),
        120 => vertices::<120>(src, count),
        124 => vertices::<124>(src, count),
        128 => vertices::<128>(src, count),
        132 => vertices::<132>(src, count),
        136 => vertices::<136>(src, count),
        140 => vertices::<140>(src, count),
        144 => vertices::<144>(src, count),
        148 => vertices::<148>(src, count),
        152 => vertices::<152>(src, count),
        156 => vertices::<156>(src, count),
        160 => vertices::<160>(src, count),
        164 => vertices::<164>(src, count),
        168 => vertices::<168>(src, count),
        172 => vertices::<172>(src, count),
        176 => vertices::<176>(src, count),
        180 => vertices::<180>(src, count),
        184 => vertices::<184>(src, count),
        188 => vertices::<188>(src, count),
        192 => vertices::<192>(src, count),
        196 => vertices::<196>(src, count),
        200 => vertices::<200>(src, count),
        204 => vertices::<204>(src, count),
        208 => vertices::<208>(src, count),
        212 => vertices::<212>(src, count),
        216 => vertices::<216>(src, count),
        220 => vertices::<220>(src, count),
        224 => vertices::<224>(src, count),
        228 => vertices::<228>(src, count),
        232 => vertices::<232>(src, count),
        236 => vertices::<236>(src, count),
        240 => vertices::<240>(src, count),
        244 => vertices::<244>(src, count),
        248 => vertices::<248>(src, count),
        252 => vertices::<252>(src, count),
        256 => vertices::<256>(src, count),
        _ => unreachable!("strides are checked by parse"),
    }
}

// The filters of the extension's Appendix B, on decoded elements in place.

/// Filter 1 on 8-bit components: octahedral X, Y and the encoding's 1.0 in, a unit vector out.
fn octahedral8(e: &mut [u8]) {
    let c = [e[0], e[1], e[2]].map(|b| b as i8 as f32);
    let n = octahedral(c, 127.0);
    for k in 0..3 {
        e[k] = n[k] as i8 as u8;
    }
}

fn octahedral16(e: &mut [u8]) {
    let c = [0, 2, 4].map(|k| i16::from_le_bytes([e[k], e[k + 1]]) as f32);
    let n = octahedral(c, 32767.0);
    for k in 0..3 {
        e[2 * k..2 * k + 2].copy_from_slice(&(n[k] as i16).to_le_bytes());
    }
}

fn octahedral(c: [f32; 3], max: f32) -> [f32; 3] {
    let one = if c[2] == 0.0 { 1.0 } else { c[2] };
    let (mut x, mut y) = (c[0] / one, c[1] / one);
    let z = 1.0 - x.abs() - y.abs();
    // The lower hemisphere folds back over the diagonals.
    let t = z.min(0.0);
    x -= t.copysign(x);
    y -= t.copysign(y);
    let len = (x * x + y * y + z * z).sqrt().max(f32::MIN_POSITIVE);
    [x, y, z].map(|v| (v / len * max).round())
}

/// Filter 2: three components of a unit quaternion scaled by sqrt(2) and, in the last, the
/// encoding's 1.0 with the index of the omitted (largest, positive) component in its low bits.
fn quaternion(e: &mut [u8]) {
    let q = [0, 2, 4, 6].map(|k| i16::from_le_bytes([e[k], e[k + 1]]));
    let one = (q[3] | 3) as f32;
    let [x, y, z] = [q[0], q[1], q[2]].map(|v| v as f32 / one * std::f32::consts::FRAC_1_SQRT_2);
    let w = (1.0 - x * x - y * y - z * z).max(0.0).sqrt();
    let largest = (q[3] & 3) as usize;
    let mut out = [0i16; 4];
    for (k, v) in [w, x, y, z].into_iter().enumerate() {
        out[(largest + k) % 4] = (v * 32767.0).round() as i16;
    }
    for k in 0..4 {
        e[2 * k..2 * k + 2].copy_from_slice(&out[k].to_le_bytes());
    }
}

/// Filter 3: a signed 8-bit exponent over a signed 24-bit mantissa, 2^e x m as f32.
fn exponential(e: &mut [u8]) {
    let v = i32::from_le_bytes([e[0], e[1], e[2], e[3]]);
    let (exp, mantissa) = (v >> 24, (v << 8) >> 8);
    let f = 2f32.powi(exp) * mantissa as f32;
    e.copy_from_slice(&f.to_le_bytes());
}

#[cfg(test)]
mod tests {
    use super::index_sequence;

    /// meshoptimizer 0.22's `meshopt_encodeIndexSequence` of these indices: one-byte and
    /// multi-byte varints, both baselines, deltas of either sign.
    const INDICES: [u32; 9] = [0, 300, 70000, 5, 70001, 100000000, 1, 16777219, 16777218];
    const ENCODED: [u8; 28] = [
        209, 0, 177, 9, 192, 139, 17, 155, 9, 4, 237, 135, 222, 190, 1, 190, 139, 17, 243, 135,
        222, 158, 1, 3, 0, 0, 0, 0,
    ];

    #[test]
    fn index_sequences_decode_as_meshoptimizer_encoded_them() {
        let out = index_sequence(&ENCODED, INDICES.len(), 4).unwrap();
        let got: Vec<u32> =
            out.chunks_exact(4).map(|b| u32::from_le_bytes(b.try_into().unwrap())).collect();
        assert_eq!(got, INDICES);
        // The 16-bit form keeps the low half, as the reference decoder does.
        let out = index_sequence(&ENCODED, INDICES.len(), 2).unwrap();
        assert_eq!(u16::from_le_bytes([out[2], out[3]]), 300);
    }

    #[test]
    fn broken_index_sequences_are_errors() {
        // Cut short, a count past the data, a wrong header, long varints running into the tail.
        assert!(index_sequence(&ENCODED[..20], INDICES.len(), 4).is_err());
        assert!(index_sequence(&ENCODED, 30, 4).is_err());
        let mut bad = ENCODED;
        bad[0] = 0xa1;
        assert!(index_sequence(&bad, INDICES.len(), 4).is_err());
        let mut run = [0xffu8; 12];
        run[0] = 0xd1;
        assert!(index_sequence(&run, 3, 4).is_err());
    }
}
