//! glTF accessors read with every check the file's word needs: the declared type and component
//! type against what the semantic allows (glTF 2.0 §3.7.2.1, and the animation sampler table of
//! §3.11), the buffer view inside its buffer, every element inside its view, sparse indices
//! increasing and in range, and the decoded size against the decoded-bytes budget.
//!
//! Written here rather than taken from the `gltf` crate's reader, which reads an accessor as
//! whatever Rust type the caller asks for (a POSITION stored as UNSIGNED_BYTE VEC2 came back as
//! float VEC3 read from the wrong bytes), panics on float indices and answers "no data" for an
//! accessor that runs past its buffer.

use crate::limits::Budget;
use anyhow::{Result, anyhow, bail};
use gltf::json::accessor::{ComponentType, Type};
use gltf::json::validation::Checked;

/// The buffers of a file, as loaded, and its JSON.
pub struct Data<'a> {
    pub root: &'a gltf::json::Root,
    pub buffers: &'a [Vec<u8>],
}

/// How a semantic may be stored: its type and the (component type, normalized) pairs allowed.
#[derive(Clone, Copy, Debug)]
pub struct Expect {
    pub ty: Type,
    pub components: &'static [(ComponentType, bool)],
}

use ComponentType::{F32, I8, I16, U8, U16, U32};
const FLOAT: &[(ComponentType, bool)] = &[(F32, false)];

pub const POSITION: Expect = Expect { ty: Type::Vec3, components: FLOAT };
pub const NORMAL: Expect = Expect { ty: Type::Vec3, components: FLOAT };
pub const TANGENT: Expect = Expect { ty: Type::Vec4, components: FLOAT };
pub const TEXCOORD: Expect =
    Expect { ty: Type::Vec2, components: &[(F32, false), (U8, true), (U16, true)] };
/// What KHR_mesh_quantization adds to each (its table "Extending Mesh Attributes"): positions
/// as any 8- or 16-bit integer, normalized or not; normals and tangents as normalized signed
/// integers; texture coordinates as signed integers too.
pub const Q_POSITION: Expect = Expect {
    ty: Type::Vec3,
    components: &[
        (F32, false),
        (I8, false),
        (I8, true),
        (U8, false),
        (U8, true),
        (I16, false),
        (I16, true),
        (U16, false),
        (U16, true),
    ],
};
pub const Q_NORMAL: Expect =
    Expect { ty: Type::Vec3, components: &[(F32, false), (I8, true), (I16, true)] };
pub const Q_TANGENT: Expect = Expect { ty: Type::Vec4, ..Q_NORMAL };
pub const Q_TEXCOORD: Expect = Expect { ty: Type::Vec2, ..Q_POSITION };

/// COLOR_0 is VEC3 or VEC4 (glTF 2.0 §3.7.2.1).
pub const COLOR_RGB: Expect =
    Expect { ty: Type::Vec3, components: &[(F32, false), (U8, true), (U16, true)] };
pub const COLOR_RGBA: Expect = Expect { ty: Type::Vec4, ..COLOR_RGB };
pub const INDICES: Expect =
    Expect { ty: Type::Scalar, components: &[(U8, false), (U16, false), (U32, false)] };
/// Skins (glTF 2.0 §3.7.3.1): JOINTS_n as unsigned integers, WEIGHTS_n as floats or
/// normalized unsigned integers, inverse bind matrices as float MAT4.
pub const JOINTS: Expect = Expect { ty: Type::Vec4, components: &[(U8, false), (U16, false)] };
pub const WEIGHTS: Expect =
    Expect { ty: Type::Vec4, components: &[(F32, false), (U8, true), (U16, true)] };
pub const MATRICES: Expect = Expect { ty: Type::Mat4, components: FLOAT };
/// Morph target displacements (§3.7.2.2), and what KHR_mesh_quantization adds: signed
/// integers, normalized or not, for positions; normalized signed ones for normals and tangents.
pub const TARGET: Expect = Expect { ty: Type::Vec3, components: FLOAT };
pub const Q_TARGET_POSITION: Expect = Expect {
    ty: Type::Vec3,
    components: &[(F32, false), (I8, false), (I8, true), (I16, false), (I16, true)],
};
pub const Q_TARGET_DIRECTION: Expect = Q_NORMAL;
/// A weights channel's output (§3.11's sampler table).
pub const WEIGHTS_KEYS: Expect = Expect {
    ty: Type::Scalar,
    components: &[(F32, false), (I8, true), (U8, true), (I16, true), (U16, true)],
};
pub const KEY_TIMES: Expect = Expect { ty: Type::Scalar, components: FLOAT };
pub const TRANSLATION: Expect = Expect { ty: Type::Vec3, components: FLOAT };
pub const SCALE: Expect = Expect { ty: Type::Vec3, components: FLOAT };
pub const ROTATION: Expect = Expect {
    ty: Type::Vec4,
    components: &[(F32, false), (I8, true), (U8, true), (I16, true), (U16, true)],
};

fn type_name(t: Type) -> &'static str {
    match t {
        Type::Scalar => "SCALAR",
        Type::Vec2 => "VEC2",
        Type::Vec3 => "VEC3",
        Type::Vec4 => "VEC4",
        Type::Mat2 => "MAT2",
        Type::Mat3 => "MAT3",
        Type::Mat4 => "MAT4",
    }
}

fn component_name(c: ComponentType, normalized: bool) -> String {
    let n = match c {
        I8 => "BYTE",
        U8 => "UNSIGNED_BYTE",
        I16 => "SHORT",
        U16 => "UNSIGNED_SHORT",
        U32 => "UNSIGNED_INT",
        F32 => "FLOAT",
    };
    if normalized { format!("normalized {n}") } else { n.to_string() }
}

fn allowed(e: &Expect) -> String {
    let c: Vec<String> = e.components.iter().map(|&(c, n)| component_name(c, n)).collect();
    format!("{} of {}", type_name(e.ty), c.join(" or "))
}

/// An accessor's elements as floats (normalized integers mapped as glTF says), `count` x the
/// type's component count, flat.
pub fn read_f32(
    data: &Data,
    index: usize,
    expect: Expect,
    budget: &mut Budget,
    what: &str,
) -> Result<Vec<f32>> {
    let (component, normalized, raw) = read_raw(data, index, expect, budget, what)?;
    let size = component.size();
    Ok(raw
        .chunks_exact(size)
        .map(|b| match (component, normalized) {
            (F32, _) => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            (U8, true) => b[0] as f32 / 255.0,
            (I8, true) => (b[0] as i8 as f32 / 127.0).max(-1.0),
            (U16, true) => u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
            (I16, true) => (i16::from_le_bytes([b[0], b[1]]) as f32 / 32767.0).max(-1.0),
            // KHR_mesh_quantization's integers, taken as they are (the node's transform or the
            // texture transform scales them).
            (U8, false) => b[0] as f32,
            (I8, false) => b[0] as i8 as f32,
            (U16, false) => u16::from_le_bytes([b[0], b[1]]) as f32,
            (I16, false) => i16::from_le_bytes([b[0], b[1]]) as f32,
            // Not allowed by any `Expect` that reads floats.
            _ => 0.0,
        })
        .collect())
}

/// An index accessor's values.
pub fn read_indices(
    data: &Data,
    index: usize,
    budget: &mut Budget,
    what: &str,
) -> Result<Vec<u32>> {
    let (component, _, raw) = read_raw(data, index, INDICES, budget, what)?;
    Ok(match component {
        U8 => raw.iter().map(|&b| b as u32).collect(),
        U16 => raw.chunks_exact(2).map(|b| u16::from_le_bytes([b[0], b[1]]) as u32).collect(),
        _ => raw.chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect(),
    })
}

/// Checks the accessor against `expect` and returns its elements packed (no stride), with sparse
/// substitution applied.
fn read_raw(
    data: &Data,
    index: usize,
    expect: Expect,
    budget: &mut Budget,
    what: &str,
) -> Result<(ComponentType, bool, Vec<u8>)> {
    let here = format!("{what} (accessors[{index}])");
    let acc = data.root.accessors.get(index).ok_or_else(|| anyhow!("{here}: no such accessor"))?;
    let (ty, component) = match (&acc.type_, &acc.component_type) {
        (Checked::Valid(t), Checked::Valid(c)) => (*t, c.0),
        _ => bail!("{here}: unknown type or componentType"),
    };
    if ty != expect.ty || !expect.components.contains(&(component, acc.normalized)) {
        bail!(
            "{here} is {} of {}; Hush reads it as {}",
            type_name(ty),
            component_name(component, acc.normalized),
            allowed(&expect)
        );
    }
    let elem = component.size() * ty.multiplicity();
    let count = usize::try_from(acc.count.0)
        .map_err(|_| anyhow!("{here}: count {} is too large", acc.count.0))?;
    let bytes = (count as u64).saturating_mul(elem as u64);
    // The packed bytes and their decoded form (4 bytes a component) live together for a while.
    budget.decode(
        bytes.saturating_add((count as u64).saturating_mul(ty.multiplicity() as u64 * 4)),
        &here,
    )?;
    let mut out = vec![0u8; count * elem];
    if count == 0 {
        return Ok((component, acc.normalized, out));
    }
    if let Some(view) = &acc.buffer_view {
        let offset = acc.byte_offset.map_or(0, |o| o.0);
        let (bytes, stride) = view_elements(data, view.value(), offset, count, elem, &here)?;
        for (i, dst) in out.chunks_exact_mut(elem).enumerate() {
            dst.copy_from_slice(&bytes[i * stride..i * stride + elem]);
        }
    }
    // Without a bufferView the base values are zeros (glTF 2.0 §3.6.2.3).
    if let Some(sparse) = &acc.sparse {
        let n = usize::try_from(sparse.count.0).unwrap_or(usize::MAX);
        if n == 0 || n > count {
            bail!("{here}: sparse.count {} must be in 1..={count}", sparse.count.0);
        }
        let ic = match &sparse.indices.component_type {
            Checked::Valid(c) => c.0,
            Checked::Invalid => bail!(
                "{here}: sparse.indices.componentType must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT"
            ),
        };
        let isize_ = ic.size();
        let (ib, istride) = view_elements(
            data,
            sparse.indices.buffer_view.value(),
            sparse.indices.byte_offset.0,
            n,
            isize_,
            &format!("{here} sparse.indices"),
        )?;
        let (vb, vstride) = view_elements(
            data,
            sparse.values.buffer_view.value(),
            sparse.values.byte_offset.0,
            n,
            elem,
            &format!("{here} sparse.values"),
        )?;
        let mut previous: Option<usize> = None;
        for k in 0..n {
            let b = &ib[k * istride..k * istride + isize_];
            let i = match ic {
                U8 => b[0] as usize,
                U16 => u16::from_le_bytes([b[0], b[1]]) as usize,
                _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize,
            };
            if i >= count || previous.is_some_and(|p| i <= p) {
                bail!(
                    "{here}: sparse index {i} at {k} is out of range or not increasing (count {count})"
                );
            }
            previous = Some(i);
            out[i * elem..(i + 1) * elem].copy_from_slice(&vb[k * vstride..k * vstride + elem]);
        }
    }
    Ok((component, acc.normalized, out))
}

/// The bytes of buffer view `view` from `offset` that hold `count` elements of `elem` bytes, and
/// the stride between them: checked to lie inside the view, and the view inside its buffer.
fn view_elements<'a>(
    data: &'a Data,
    view: usize,
    offset: u64,
    count: usize,
    elem: usize,
    here: &str,
) -> Result<(&'a [u8], usize)> {
    let v = data
        .root
        .buffer_views
        .get(view)
        .ok_or_else(|| anyhow!("{here}: no bufferViews[{view}]"))?;
    let buffer = data
        .buffers
        .get(v.buffer.value())
        .ok_or_else(|| anyhow!("{here}: bufferViews[{view}] names a missing buffer"))?;
    let start = v.byte_offset.map_or(0, |o| o.0);
    let len = v.byte_length.0;
    let end = start.checked_add(len).filter(|&e| e <= buffer.len() as u64).ok_or_else(|| {
        anyhow!(
            "{here}: bufferViews[{view}] (bytes {start}..{}) runs past its buffer of {} bytes",
            start.saturating_add(len),
            buffer.len()
        )
    })?;
    let view_bytes = &buffer[start as usize..end as usize];
    let stride = v.byte_stride.map_or(elem, |s| s.0);
    if stride < elem {
        bail!(
            "{here}: bufferViews[{view}].byteStride {stride} is less than the element's {elem} bytes"
        );
    }
    let need = (count as u64 - 1)
        .checked_mul(stride as u64)
        .and_then(|x| x.checked_add(elem as u64))
        .and_then(|x| x.checked_add(offset));
    match need {
        Some(n) if n <= len => Ok((&view_bytes[offset as usize..], stride)),
        _ => bail!(
            "{here}: {count} elements of {elem} bytes (stride {stride}) from byte {offset} run past bufferViews[{view}] of {len} bytes"
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::limits::Limits;

    fn root(accessors: serde_json::Value, views: serde_json::Value) -> gltf::json::Root {
        serde_json::from_value(serde_json::json!({
            "asset": {"version": "2.0"}, "buffers": [{"byteLength": 64}], "bufferViews": views, "accessors": accessors
        }))
        .unwrap()
    }

    #[test]
    fn reads_checked_elements_and_refuses_the_rest() {
        let mut buf: Vec<u8> = (0..16).flat_map(|i| (i as f32).to_le_bytes()).collect();
        buf[0..4].copy_from_slice(&[1, 2, 0, 0]);
        let buffers = [buf];
        let r = root(
            serde_json::json!([
                {"bufferView": 0, "byteOffset": 4, "componentType": 5126, "count": 2, "type": "VEC3"},
                {"bufferView": 0, "componentType": 5121, "count": 2, "type": "VEC2"},
                {"bufferView": 0, "componentType": 5126, "count": 6, "type": "VEC3"},
                {"bufferView": 0, "componentType": 5126, "count": 4, "type": "SCALAR"},
                {"bufferView": 1, "componentType": 5121, "count": 4, "type": "SCALAR"},
                {"componentType": 5126, "count": 3, "type": "SCALAR",
                 "sparse": {"count": 1, "indices": {"bufferView": 1, "componentType": 5121}, "values": {"bufferView": 0, "byteOffset": 8}}},
                {"bufferView": 2, "componentType": 5126, "count": 1, "type": "SCALAR"}
            ]),
            serde_json::json!([{"buffer": 0, "byteLength": 64}, {"buffer": 0, "byteLength": 4}, {"buffer": 0, "byteOffset": 60, "byteLength": 8}]),
        );
        let data = Data { root: &r, buffers: &buffers };
        let mut b = Budget::new(Limits::default());
        assert_eq!(
            read_f32(&data, 0, POSITION, &mut b, "p").unwrap(),
            vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
        );
        let e = read_f32(&data, 1, POSITION, &mut b, "POSITION").unwrap_err().to_string();
        assert!(e.contains("VEC2 of UNSIGNED_BYTE") && e.contains("VEC3 of FLOAT"), "{e}");
        let e = read_f32(&data, 2, POSITION, &mut b, "p").unwrap_err().to_string();
        assert!(e.contains("run past bufferViews[0]"), "{e}");
        let e = read_indices(&data, 3, &mut b, "indices").unwrap_err().to_string();
        assert!(e.contains("SCALAR of FLOAT"), "{e}");
        assert_eq!(read_indices(&data, 4, &mut b, "i").unwrap(), vec![1, 2, 0, 0]);
        // Sparse over zeros: index 1 takes the value 2.0 (bytes 8..12).
        assert_eq!(read_f32(&data, 5, KEY_TIMES, &mut b, "s").unwrap(), vec![0.0, 2.0, 0.0]);
        let e = read_f32(&data, 6, KEY_TIMES, &mut b, "t").unwrap_err().to_string();
        assert!(e.contains("runs past its buffer"), "{e}");
        let mut small = Budget::new(Limits { decoded_bytes: 16, ..Limits::default() });
        let e = read_f32(&data, 0, POSITION, &mut small, "p").unwrap_err().to_string();
        assert!(e.contains("decoded-bytes"), "{e}");
    }
}
