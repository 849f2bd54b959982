//! Mutations of bytes and of JSON tokens, and the target of the loaders of bytes (JSON text,
//! `.glb`, EXR, `.bsdf`): seeds mutated into a fresh buffer each case.

use crate::gltf::glb;
use crate::harness::{SplitMix64, Target};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Overwrites of one byte.
pub const BYTES: [u8; 4] = [0x00, 0xFF, 0x7F, 0x80];
/// Overwrites of 4 bytes (little-endian): sizes, counts, offsets, f32s.
const WORDS: [u32; 12] = [
    0,
    1,
    0xFFFF_FFFF,
    0x7FFF_FFFF,
    0x8000_0000,
    0xFFFF,
    0x1_0000,
    0x7FC0_0000, // f32 NaN
    0x7F80_0000, // f32 ∞
    0xFF80_0000, // f32 −∞
    0x7F7F_FFFF, // f32::MAX
    0x0000_0001, // smallest subnormal f32
];

/// Where a byte mutation lands: half the time in the first 512 bytes, where headers are.
fn position(rng: &mut SplitMix64, len: usize) -> usize {
    if rng.percent(50) {
        rng.below(len.min(512))
    } else {
        rng.below(len)
    }
}

/// Applies one to four byte-level mutations to `buf`, describing them in `log`; `buf` stays
/// under `max_len`.
fn mutate_bytes(rng: &mut SplitMix64, buf: &mut Vec<u8>, max_len: usize, log: &mut String) {
    let ops = 1 + rng.below(4).min(rng.below(4));
    for _ in 0..ops {
        let len = buf.len();
        match rng.below(10) {
            0 | 1 if len > 0 => {
                let (at, bit) = (position(rng, len), rng.below(8));
                buf[at] ^= 1 << bit;
                let _ = write!(log, " flip bit {bit} of byte {at};");
            }
            2 if len > 0 => {
                let (at, v) = (position(rng, len), rng.pick(&BYTES));
                buf[at] = v;
                let _ = write!(log, " byte {at} = {v:#04x};");
            }
            3 if len >= 4 => {
                let (at, v) = (position(rng, len - 3), rng.pick(&WORDS));
                buf[at..at + 4].copy_from_slice(&v.to_le_bytes());
                let _ = write!(log, " u32 at {at} = {v:#x};");
            }
            4 if len > 0 => {
                let at = position(rng, len);
                let v = rng.next() as u8;
                buf[at] = v;
                let _ = write!(log, " byte {at} = {v:#04x};");
            }
            5 => {
                let to = if rng.percent(50) {
                    rng.below(len.min(64) + 1)
                } else {
                    rng.below(len + 1)
                };
                buf.truncate(to);
                let _ = write!(log, " truncate to {to};");
            }
            6 if len < max_len => {
                let at = position(rng, len + 1);
                let n = 1 + rng.below(16);
                let fill = rng.pick(&[0x00u8, 0xFF, 0x7F, 0x80, b'0', b'9', b'"', b'[', b'{']);
                let random = rng.percent(50);
                let bytes: Vec<u8> = (0..n)
                    .map(|_| if random { rng.next() as u8 } else { fill })
                    .collect();
                buf.splice(at..at, bytes);
                let _ = write!(log, " insert {n} bytes at {at};");
            }
            7 if len > 0 => {
                let at = position(rng, len);
                let n = 1 + rng.below((len - at).min(64));
                buf.drain(at..at + n);
                let _ = write!(log, " delete {n} bytes at {at};");
            }
            8 if len > 0 && len < max_len => {
                let from = position(rng, len);
                let n = (1 + rng.below(256)).min(len - from).min(max_len - len);
                let chunk = buf[from..from + n].to_vec();
                let at = position(rng, len + 1);
                buf.splice(at..at, chunk);
                let _ = write!(log, " duplicate {n} bytes from {from} at {at};");
            }
            9 if len > 1 => {
                let (from, to) = (position(rng, len), position(rng, len));
                let n = (1 + rng.below(64)).min(len - from).min(len - to);
                buf.copy_within(from..from + n, to);
                let _ = write!(log, " copy {n} bytes from {from} over {to};");
            }
            _ => {}
        }
    }
}

/// JSON numbers (and values of other types) that replace a number.
const NUMBERS: [&str; 26] = [
    "-1",
    "0",
    "1",
    "2",
    "-0.0",
    "0.5",
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "1e309",
    "5e-324",
    "1e-400",
    "18446744073709551615",
    "18446744073709551616",
    "-9223372036854775809",
    "4294967295",
    "4294967296",
    "2147483648",
    "65536",
    "NaN",
    "\"NaN\"",
    "\"inf\"",
    "Infinity",
    "-Infinity",
    "null",
    "\"1\"",
];

/// JSON values that replace a string.
const STRINGS: [&str; 16] = [
    "\"\"",
    "\"NaN\"",
    "\"-inf\"",
    "\"\\u0000\"",
    "\"\\ud800\"",
    "\"data:application/octet-stream;base64,\"",
    "\"data:application/octet-stream;base64,AAAA\"",
    "\"data:image/png;base64,iVBORw0KGgo=\"",
    "\"missing.bin\"",
    "\"VEC3\"",
    "\"SCALAR\"",
    "\"MAT4\"",
    "\"ggx\"",
    "\"beckmann\"",
    "\"tabulated\"",
    "0",
];

/// Values of any type that replace any value.
const VALUES: [&str; 8] = ["null", "true", "0", "-1", "\"x\"", "[]", "{}", "[[]]"];

#[derive(Clone, Copy, PartialEq)]
enum Tok {
    Num,
    Str,
    Arr,
    Obj,
}

/// The tokens of JSON text: numbers, strings, and whole arrays and objects (`start..end`,
/// brackets included).
fn json_tokens(s: &[u8]) -> Vec<(Tok, usize, usize)> {
    let mut out = Vec::new();
    let mut open: Vec<usize> = Vec::new();
    let mut i = 0;
    while i < s.len() {
        match s[i] {
            b'"' => {
                let start = i;
                i += 1;
                while i < s.len() && s[i] != b'"' {
                    i += if s[i] == b'\\' { 2 } else { 1 };
                }
                i = (i + 1).min(s.len());
                out.push((Tok::Str, start, i));
                continue;
            }
            b'-' | b'0'..=b'9' => {
                let start = i;
                while i < s.len() && matches!(s[i], b'-' | b'+' | b'.' | b'e' | b'E' | b'0'..=b'9')
                {
                    i += 1;
                }
                out.push((Tok::Num, start, i));
                continue;
            }
            b'[' | b'{' => {
                open.push(out.len());
                let kind = if s[i] == b'[' { Tok::Arr } else { Tok::Obj };
                out.push((kind, i, i));
            }
            b']' | b'}' => {
                if let Some(k) = open.pop() {
                    out[k].2 = i + 1;
                }
            }
            _ => {}
        }
        i += 1;
    }
    out.retain(|t| t.2 > t.1);
    out
}

/// The top-level elements (`start..end`) of the array or object `s[open..close]`.
fn elements(s: &[u8], open: usize, close: usize) -> Vec<(usize, usize)> {
    let (mut out, mut depth, mut start, mut i) = (Vec::new(), 0usize, open + 1, open + 1);
    while i < close - 1 {
        match s[i] {
            b'"' => {
                i += 1;
                while i < close - 1 && s[i] != b'"' {
                    i += if s[i] == b'\\' { 2 } else { 1 };
                }
            }
            b'[' | b'{' => depth += 1,
            b']' | b'}' => depth = depth.saturating_sub(1),
            b',' if depth == 0 => {
                out.push((start, i));
                start = i + 1;
            }
            _ => {}
        }
        i += 1;
    }
    if s[start..close - 1].iter().any(|b| !b.is_ascii_whitespace()) {
        out.push((start, close - 1));
    }
    out
}

/// Applies one to three token-level mutations to JSON text, describing them in `log`; the
/// text stays under `max_len`.
fn mutate_json(rng: &mut SplitMix64, text: &mut Vec<u8>, max_len: usize, log: &mut String) {
    let ops = 1 + rng.below(3).min(rng.below(3));
    for _ in 0..ops {
        let toks = json_tokens(text);
        let of = |kind: Tok| -> Vec<(usize, usize)> {
            toks.iter()
                .filter(|t| t.0 == kind)
                .map(|t| (t.1, t.2))
                .collect()
        };
        let replace = |text: &mut Vec<u8>, (a, b): (usize, usize), with: &[u8]| {
            text.splice(a..b, with.iter().copied());
        };
        match rng.below(8) {
            // A number, half the time an integer (sizes, counts, indices are).
            0 | 1 => {
                let mut nums = of(Tok::Num);
                if rng.percent(50) {
                    nums.retain(|&(a, b)| !text[a..b].iter().any(|c| b".eE".contains(c)));
                }
                if nums.is_empty() {
                    continue;
                }
                let span = nums[rng.below(nums.len())];
                let with = rng.pick(&NUMBERS);
                let _ = write!(
                    log,
                    " number `{}` at {} = {with};",
                    String::from_utf8_lossy(&text[span.0..span.1]),
                    span.0
                );
                replace(text, span, with.as_bytes());
            }
            2 => {
                let strs = of(Tok::Str);
                if strs.is_empty() {
                    continue;
                }
                let span = strs[rng.below(strs.len())];
                let with = rng.pick(&STRINGS);
                let _ = write!(log, " string at {} = {with};", span.0);
                replace(text, span, with.as_bytes());
            }
            // An array or object emptied.
            3 => {
                let mut spans = of(Tok::Arr);
                spans.extend(of(Tok::Obj));
                if spans.is_empty() {
                    continue;
                }
                let (a, b) = spans[rng.below(spans.len())];
                let with = [text[a], text[b - 1]];
                let _ = write!(
                    log,
                    " {}{} at {a} emptied;",
                    with[0] as char, with[1] as char
                );
                replace(text, (a, b), &with);
            }
            // An array's (or object's) elements repeated 2 to 4 times.
            4 => {
                let mut spans = of(Tok::Arr);
                if rng.percent(25) {
                    spans = of(Tok::Obj);
                }
                spans.retain(|&(a, b)| b - a < max_len.saturating_sub(text.len()) / 4);
                if spans.is_empty() {
                    continue;
                }
                let (a, b) = spans[rng.below(spans.len())];
                let inner = text[a + 1..b - 1].to_vec();
                if inner.iter().all(|c| c.is_ascii_whitespace()) {
                    continue;
                }
                let times = 2 + rng.below(3);
                let mut with = vec![text[a]];
                for t in 0..times {
                    if t > 0 {
                        with.push(b',');
                    }
                    with.extend_from_slice(&inner);
                }
                with.push(text[b - 1]);
                let _ = write!(log, " elements of the {} at {a} ×{times};", text[a] as char);
                replace(text, (a, b), &with);
            }
            // An element of an array or object dropped (the first, the last, or any).
            5 => {
                let mut spans = of(Tok::Arr);
                spans.extend(of(Tok::Obj));
                if spans.is_empty() {
                    continue;
                }
                let (a, b) = spans[rng.below(spans.len())];
                let els = elements(text, a, b);
                if els.is_empty() {
                    continue;
                }
                let k = match rng.below(3) {
                    0 => 0,
                    1 => els.len() - 1,
                    _ => rng.below(els.len()),
                };
                // With its comma: the one after it, or before it for the last.
                let (mut x, mut y) = els[k];
                if k + 1 < els.len() {
                    y = els[k + 1].0;
                } else if k > 0 {
                    x = els[k - 1].1;
                }
                let _ = write!(log, " element {k} of {} dropped at {a};", els.len());
                text.drain(x..y);
            }
            // Any value replaced by one of another type.
            6 => {
                if toks.is_empty() {
                    continue;
                }
                let t = toks[rng.below(toks.len())];
                let with = rng.pick(&VALUES);
                if t.0 == Tok::Obj && t.1 == 0 {
                    continue; // the whole document: tried by the byte mutations
                }
                let _ = write!(log, " value at {} = {with};", t.1);
                replace(text, (t.1, t.2), with.as_bytes());
            }
            // A number copied over another.
            _ => {
                let nums = of(Tok::Num);
                if nums.len() < 2 {
                    continue;
                }
                let (from, to) = (nums[rng.below(nums.len())], nums[rng.below(nums.len())]);
                let with = text[from.0..from.1].to_vec();
                let _ = write!(
                    log,
                    " number at {} = `{}`;",
                    to.0,
                    String::from_utf8_lossy(&with)
                );
                replace(text, to, &with);
            }
        }
        if text.len() > max_len {
            text.truncate(max_len);
        }
    }
}

#[derive(Clone)]
pub enum Form {
    /// JSON text: token-level and byte-level mutations.
    Json(Vec<u8>),
    /// A `.glb` of this JSON chunk and binary chunk: its JSON mutated by tokens (the chunk
    /// lengths rebuilt) or the whole file by bytes.
    Glb(Vec<u8>, Vec<u8>),
    /// Any other bytes: byte-level mutations.
    Bytes(Vec<u8>),
}

#[derive(Clone)]
pub struct Seed {
    /// The path the loader is given (where relative references resolve).
    pub path: PathBuf,
    pub form: Form,
    /// Relative frequency among the seeds.
    pub weight: usize,
}

pub type Check = fn(&Path, &[u8]) -> Result<bool, String>;

pub struct Bytes {
    seeds: Vec<Seed>,
    path: PathBuf,
    input: Vec<u8>,
    check: Check,
}

impl Bytes {
    pub fn new(seeds: Vec<Seed>, check: Check) -> Self {
        Bytes {
            seeds,
            path: PathBuf::new(),
            input: Vec::new(),
            check,
        }
    }
}

impl Target for Bytes {
    fn mutate(&mut self, rng: &mut SplitMix64) -> String {
        let total: usize = self.seeds.iter().map(|s| s.weight).sum();
        let mut r = rng.below(total);
        let k = self
            .seeds
            .iter()
            .position(|s| {
                let hit = r < s.weight;
                r = r.saturating_sub(s.weight);
                hit
            })
            .unwrap();
        let seed = &self.seeds[k];
        self.path = seed.path.clone();
        let mut log = format!("seed {k}:");
        match &seed.form {
            Form::Json(text) => {
                let max = 2 * text.len() + 4096;
                self.input = text.clone();
                if rng.percent(70) {
                    mutate_json(rng, &mut self.input, max, &mut log);
                    if rng.percent(15) {
                        mutate_bytes(rng, &mut self.input, max, &mut log);
                    }
                } else {
                    mutate_bytes(rng, &mut self.input, max, &mut log);
                }
            }
            Form::Glb(json, bin) => {
                if rng.percent(50) {
                    let mut json = json.clone();
                    let max = 2 * json.len() + 4096;
                    mutate_json(rng, &mut json, max, &mut log);
                    self.input = glb(&json, bin);
                } else {
                    self.input = glb(json, bin);
                    let max = 2 * self.input.len() + 4096;
                    mutate_bytes(rng, &mut self.input, max, &mut log);
                }
            }
            Form::Bytes(bytes) => {
                self.input = bytes.clone();
                let max = 2 * bytes.len() + 4096;
                mutate_bytes(rng, &mut self.input, max, &mut log);
            }
        }
        log
    }

    fn call(&mut self) -> Result<bool, String> {
        (self.check)(&self.path, &self.input)
    }

    fn input(&self) -> Vec<u8> {
        self.input.clone()
    }
}
