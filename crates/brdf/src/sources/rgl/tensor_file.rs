//! The tensor file of Mitsuba 3 (`mitsuba/core/tensor.h`, `mi.tensor_io`) and rgl-epfl's
//! brdf-loader, the container of RGL `.bsdf` materials.
//!
//! Layout, little-endian: the 12 bytes `tensor_file\0`, the version `1, 0`, a `u32` field
//! count, then per field a `u16` name length, the name (UTF-8), a `u16` rank, a `u8` type code
//! ([`Dtype`]), a `u64` byte offset of the data and `rank` × `u64` extents. Each field's data is
//! stored row-major (the last extent fastest) at its offset; writers align offsets to 8 bytes
//! because Mitsuba maps the file and reads the floats in place.
//!
//! Parsing never allocates more than the file's own length: a field whose extents overflow or
//! whose data runs past the end of the file is an error naming the field.

/// A field's element type, with the code the file stores (Mitsuba's `Struct::Type`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dtype {
    /// `u8` (code 1).
    U8,
    /// `i8` (code 2).
    I8,
    /// `u16` (code 3).
    U16,
    /// `i16` (code 4).
    I16,
    /// `u32` (code 5).
    U32,
    /// `i32` (code 6).
    I32,
    /// `u64` (code 7).
    U64,
    /// `i64` (code 8).
    I64,
    /// IEEE half (code 9).
    F16,
    /// `f32` (code 10).
    F32,
    /// `f64` (code 11).
    F64,
}

impl Dtype {
    /// The type of a stored code; `None` for 0 (invalid) and codes above 11.
    pub fn from_code(code: u8) -> Option<Self> {
        use Dtype::*;
        [U8, I8, U16, I16, U32, I32, U64, I64, F16, F32, F64]
            .get(usize::from(code).checked_sub(1)?)
            .copied()
    }

    /// The stored code.
    pub fn code(self) -> u8 {
        self as u8 + 1
    }

    /// Bytes per element.
    pub fn size(self) -> usize {
        use Dtype::*;
        match self {
            U8 | I8 => 1,
            U16 | I16 | F16 => 2,
            U32 | I32 | F32 => 4,
            U64 | I64 | F64 => 8,
        }
    }
}

/// One field of a tensor file: its type, its extents and where its bytes lie in the file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Field {
    /// Element type.
    pub dtype: Dtype,
    /// Extents, outermost first.
    pub shape: Vec<usize>,
    /// The data's byte range in the file.
    pub bytes: std::ops::Range<usize>,
}

impl Field {
    /// Number of elements.
    pub fn len(&self) -> usize {
        self.shape.iter().product()
    }

    /// Whether the field holds no element.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A parsed tensor file: the bytes and the field table.
#[derive(Debug)]
pub struct TensorFile {
    bytes: Vec<u8>,
    fields: Vec<(String, Field)>,
}

/// The magic bytes.
const MAGIC: &[u8; 12] = b"tensor_file\0";
/// Data offsets of written files are multiples of this.
const ALIGN: usize = 8;

/// A little-endian reader over the header that fails with a message instead of panicking.
struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Cursor<'_> {
    fn take(&mut self, n: usize, what: &str) -> Result<&[u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or_else(|| format!("the header ends inside {what}"))?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }

    fn u8(&mut self, what: &str) -> Result<u8, String> {
        Ok(self.take(1, what)?[0])
    }

    fn u16(&mut self, what: &str) -> Result<u16, String> {
        Ok(u16::from_le_bytes(self.take(2, what)?.try_into().unwrap()))
    }

    fn u32(&mut self, what: &str) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.take(4, what)?.try_into().unwrap()))
    }

    fn u64(&mut self, what: &str) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.take(8, what)?.try_into().unwrap()))
    }
}

impl TensorFile {
    /// Parses the header of `bytes` and checks that every field's data lies inside them.
    pub fn parse(bytes: Vec<u8>) -> Result<Self, String> {
        let mut c = Cursor {
            bytes: &bytes,
            at: 0,
        };
        if c.take(12, "the magic bytes")? != MAGIC {
            return Err("not a tensor file (it does not start with `tensor_file`)".into());
        }
        let version = [c.u8("the version")?, c.u8("the version")?];
        if version != [1, 0] {
            return Err(format!(
                "tensor file version {}.{}, only 1.0 is known",
                version[0], version[1]
            ));
        }
        let count = c.u32("the field count")?;
        let mut fields: Vec<(String, Field)> = Vec::new();
        for i in 0..count {
            let what = format!("field {i}");
            let name_len = c.u16(&what)?;
            let name = std::str::from_utf8(c.take(name_len.into(), &what)?)
                .map_err(|_| format!("the name of field {i} is not UTF-8"))?
                .to_owned();
            let rank = c.u16(&name)?;
            let code = c.u8(&name)?;
            let dtype = Dtype::from_code(code)
                .ok_or_else(|| format!("field `{name}`: unknown type code {code}"))?;
            let offset = c.u64(&name)?;
            let mut shape = Vec::new();
            let mut size = dtype.size() as u64;
            for _ in 0..rank {
                let n = c.u64(&name)?;
                size = size
                    .checked_mul(n)
                    .ok_or_else(|| format!("field `{name}`: its extents overflow"))?;
                shape.push(n as usize);
            }
            let end = offset
                .checked_add(size)
                .filter(|&e| e <= bytes.len() as u64);
            let Some(end) = end else {
                return Err(format!(
                    "field `{name}`: {size} bytes at offset {offset} run past the end of the \
                     file ({} bytes): truncated?",
                    bytes.len()
                ));
            };
            if fields.iter().any(|(n, _)| *n == name) {
                return Err(format!("field `{name}` appears twice"));
            }
            let field = Field {
                dtype,
                shape,
                bytes: offset as usize..end as usize,
            };
            fields.push((name, field));
        }
        Ok(TensorFile { bytes, fields })
    }

    /// The field called `name`.
    pub fn field(&self, name: &str) -> Option<&Field> {
        self.fields.iter().find(|(n, _)| n == name).map(|(_, f)| f)
    }

    /// The names of the fields, in the file's order.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.fields.iter().map(|(n, _)| n.as_str())
    }

    /// A floating-point field (f16, f32 or f64) as f64 values with its shape; an error naming
    /// the field when it is absent or of another type.
    pub fn floats(&self, name: &str) -> Result<(Vec<f64>, &[usize]), String> {
        let f = self
            .field(name)
            .ok_or_else(|| format!("no field `{name}`"))?;
        let b = &self.bytes[f.bytes.clone()];
        let v: Vec<f64> = match f.dtype {
            Dtype::F32 => b
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().unwrap()).into())
                .collect(),
            Dtype::F64 => b
                .chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
                .collect(),
            Dtype::F16 => b
                .chunks_exact(2)
                .map(|c| half_to_f64(u16::from_le_bytes(c.try_into().unwrap())))
                .collect(),
            other => return Err(format!("field `{name}` holds {other:?}, not floats")),
        };
        Ok((v, &f.shape))
    }

    /// A `u8` field's bytes; an error naming the field when it is absent or of another type.
    pub fn u8s(&self, name: &str) -> Result<&[u8], String> {
        let f = self
            .field(name)
            .ok_or_else(|| format!("no field `{name}`"))?;
        if f.dtype != Dtype::U8 {
            return Err(format!("field `{name}` holds {:?}, not u8", f.dtype));
        }
        Ok(&self.bytes[f.bytes.clone()])
    }
}

/// An IEEE 754 half as f64.
fn half_to_f64(h: u16) -> f64 {
    let sign = if h >> 15 == 1 { -1.0 } else { 1.0 };
    let exp = i32::from((h >> 10) & 0x1f);
    let frac = f64::from(h & 0x3ff);
    sign * match exp {
        0 => frac * 2f64.powi(-24),
        31 if frac == 0.0 => f64::INFINITY,
        31 => f64::NAN,
        e => (1.0 + frac / 1024.0) * 2f64.powi(e - 15),
    }
}

/// Fields gathered for writing, in order.
#[derive(Default)]
pub struct TensorWriter {
    fields: Vec<(String, Dtype, Vec<usize>, Vec<u8>)>,
}

impl TensorWriter {
    /// Adds an f32 field of `shape` (row-major `values`).
    pub fn f32s(&mut self, name: &str, shape: &[usize], values: &[f32]) {
        debug_assert_eq!(shape.iter().product::<usize>(), values.len());
        let bytes = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.fields
            .push((name.into(), Dtype::F32, shape.to_vec(), bytes));
    }

    /// Adds a one-dimensional u8 field.
    pub fn u8s(&mut self, name: &str, values: &[u8]) {
        self.fields
            .push((name.into(), Dtype::U8, vec![values.len()], values.to_vec()));
    }

    /// The file's bytes: the header, then every field's data at an 8-byte aligned offset.
    pub fn to_bytes(&self) -> Vec<u8> {
        let header: usize = 18
            + self
                .fields
                .iter()
                .map(|(n, _, s, _)| 2 + n.len() + 2 + 1 + 8 + 8 * s.len())
                .sum::<usize>();
        let mut offsets = Vec::new();
        let mut at = header;
        for (_, _, _, data) in &self.fields {
            at = at.div_ceil(ALIGN) * ALIGN;
            offsets.push(at);
            at += data.len();
        }
        let mut out = Vec::with_capacity(at);
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&[1, 0]);
        out.extend_from_slice(&(self.fields.len() as u32).to_le_bytes());
        for ((name, dtype, shape, _), offset) in self.fields.iter().zip(&offsets) {
            out.extend_from_slice(&(name.len() as u16).to_le_bytes());
            out.extend_from_slice(name.as_bytes());
            out.extend_from_slice(&(shape.len() as u16).to_le_bytes());
            out.push(dtype.code());
            out.extend_from_slice(&(*offset as u64).to_le_bytes());
            for &n in shape {
                out.extend_from_slice(&(n as u64).to_le_bytes());
            }
        }
        debug_assert_eq!(out.len(), header);
        for ((_, _, _, data), &offset) in self.fields.iter().zip(&offsets) {
            out.resize(offset, 0);
            out.extend_from_slice(data);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn written_fields_read_back_aligned() {
        let mut w = TensorWriter::default();
        w.u8s("description", b"abc");
        w.f32s("theta_i", &[3], &[0.0, 0.5, 1.5]);
        w.f32s("grid", &[2, 2], &[1.0, 2.0, 3.0, 4.0]);
        let t = TensorFile::parse(w.to_bytes()).unwrap();
        assert_eq!(t.u8s("description").unwrap(), b"abc");
        let (v, shape) = t.floats("grid").unwrap();
        assert_eq!((v, shape), (vec![1.0, 2.0, 3.0, 4.0], &[2usize, 2][..]));
        for name in ["theta_i", "grid"] {
            assert_eq!(t.field(name).unwrap().bytes.start % ALIGN, 0);
        }
        assert!(t.floats("description").unwrap_err().contains("not floats"));
        assert!(t.floats("vndf").unwrap_err().contains("no field `vndf`"));
    }

    #[test]
    fn damaged_headers_are_errors_not_panics() {
        let mut w = TensorWriter::default();
        w.f32s("ndf", &[2, 3], &[0.0; 6]);
        let good = w.to_bytes();
        // Every truncation of the file is an error.
        for n in 0..good.len() {
            assert!(TensorFile::parse(good[..n].to_vec()).is_err(), "{n} bytes");
        }
        let mut bad = good.clone();
        bad[0] = b'T';
        assert!(
            TensorFile::parse(bad)
                .unwrap_err()
                .contains("not a tensor file")
        );
        // Extents whose product overflows u64: the first extent is at byte 18+2+3+2+1+8.
        let mut bad = good.clone();
        bad[34..42].copy_from_slice(&u64::MAX.to_le_bytes());
        assert!(TensorFile::parse(bad).unwrap_err().contains("overflow"));
        let mut bad = good;
        bad[25] = 0; // the type code
        assert!(
            TensorFile::parse(bad)
                .unwrap_err()
                .contains("unknown type code 0")
        );
    }

    #[test]
    fn halves_decode() {
        assert_eq!(half_to_f64(0x3c00), 1.0);
        assert_eq!(half_to_f64(0xc000), -2.0);
        assert_eq!(half_to_f64(0x0001), 2f64.powi(-24));
        assert_eq!(half_to_f64(0x7c00), f64::INFINITY);
    }
}
