//! Seeded, bounded mutation test of every loader that reads outside input: MERL tables, fit
//! JSON, neural BRDF JSON, RGL `.bsdf` tensor files (RGB, spectral, anisotropic), glTF scenes
//! (JSON and `.glb`, buffers embedded) and OpenEXR environment maps.
//!
//! Each loader gets valid seed inputs, built here, and thousands of mutated versions of them:
//! bit flips, bytes and words overwritten with interesting values, truncations, insertions,
//! deletions and duplicated chunks, and for JSON also token-level mutations (numbers replaced
//! by −1, 0, 1e308, huge integers or NaN-ish strings, strings replaced, arrays and objects
//! emptied, repeated or shortened, values of another type). Every case runs under
//! `catch_unwind` on a worker thread that the test watches: it must return within
//! [`CALL_BUDGET`], and either refuse the input with an error whose message names the path it
//! was given, or return a value that passes a sanity check (finite values, indices in range,
//! BRDFs finite and non-negative where evaluated).
//!
//! The PRNG is SplitMix64 with a fixed seed per loader, so a failure names a case (loader and
//! number) that a rerun makes again; the first input of each distinct failure is saved under
//! `CARGO_TARGET_TMPDIR/loader_mutation/`. `LOADER_MUTATION_SAVE=loader:case` saves that case's
//! input before the call (for a case that never returns); `LOADER_MUTATION_TRACE=1` prints each
//! case before its call (for a case that aborts the process, as a failed allocation does);
//! `LOADER_MUTATION_SCALE=N` runs N times the cases and `LOADER_MUTATION_SEED=S` other ones.

mod common;

use facet_fit::Brdf;
use facet_fit::export::rgl::{BsdfResolution, rgl_tensor};
use facet_fit::model::analytic::parse_analytic;
use facet_fit::model::material::{FittedMaterial, ModelChoice};
use facet_fit::model::merl_grid::{MAX_STORED, MerlTable, SAMPLES, SCALE};
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use facet_fit::sources::rgl::RglBsdf;
use facet_render::scene::data_uri::encode_base64;
use facet_render::scene::{EnvironmentMap, LoadOptions, Scene};
use glam::{DVec3, Vec2, Vec3};
use std::cell::{Cell, RefCell};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::{Once, OnceLock};
use std::time::{Duration, Instant};

/// One call of a loader that takes longer than this is a hang.
const CALL_BUDGET: Duration = Duration::from_secs(5);

// ---------------------------------------------------------------------------------------------
// The harness: PRNG, panic capture, the watched worker.

/// SplitMix64 (Steele, Lea, Flood 2014): tiny, deterministic, good enough to pick mutations.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (0 when `n` is 0).
    fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next() % n as u64) as usize
        }
    }

    /// True with probability `percent` / 100.
    fn percent(&mut self, percent: u64) -> bool {
        self.next() % 100 < percent
    }

    fn pick<T: Copy>(&mut self, xs: &[T]) -> T {
        xs[self.below(xs.len())]
    }
}

thread_local! {
    /// Set on the worker threads: their panics are recorded instead of printed.
    static CAPTURE: Cell<bool> = const { Cell::new(false) };
    static LAST_PANIC: RefCell<String> = const { RefCell::new(String::new()) };
}

/// A panic hook that records the message and location of a worker's panic (thousands of
/// caught panics would otherwise flood the output) and leaves other threads' panics alone.
fn install_panic_capture() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if CAPTURE.get() {
                LAST_PANIC.with_borrow_mut(|s| *s = info.to_string().replace('\n', " "));
            } else {
                default(info)
            }
        }));
    });
}

/// A loader under test with its seeds and the current mutated input.
trait Target: Send + 'static {
    /// Makes the next case's input from the seeds; returns how it was made.
    fn mutate(&mut self, rng: &mut SplitMix64) -> String;
    /// The loader on the current input. `Ok(true)`: accepted and sane; `Ok(false)`: refused
    /// with an error naming the path; `Err`: what is wrong.
    fn call(&mut self) -> Result<bool, String>;
    /// The current input as saved with a failure (MERL saves its recipe instead of 35 MB).
    fn input(&self) -> Vec<u8>;
    /// Undoes an in-place mutation.
    fn restore(&mut self) {}
}

#[derive(Default)]
struct Summary {
    cases: usize,
    accepted: usize,
    refused: usize,
    setup: Duration,
    run: Duration,
    /// Distinct failures by signature: (count, first example).
    failures: BTreeMap<String, (usize, String)>,
}

enum Msg {
    Case(usize, String),
    Done(Summary),
}

/// Where failing inputs are saved.
fn save_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("loader_mutation");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// What makes two failures the same: the panic's location, else the problem up to its first
/// `=`, `(`, `[` or a backquote (names), without digits.
fn signature(problem: &str) -> String {
    if let Some(at) = problem.find("panicked at ") {
        let rest = &problem[at..];
        return rest[..rest.find(": ").unwrap_or(rest.len())].to_string();
    }
    let head = &problem[..problem.find(['=', '(', '[', '`']).unwrap_or(problem.len())];
    head.chars()
        .filter(|c| !c.is_ascii_digit())
        .take(120)
        .collect()
}

/// Runs `cases` mutated inputs of the target that `setup` builds (on the worker, timed apart)
/// and fails the test with every distinct problem found; a case that does not return within
/// twice [`CALL_BUDGET`] fails it as a hang.
fn campaign<T: Target>(
    name: &'static str,
    seed: u64,
    cases: usize,
    setup: impl FnOnce() -> T + Send + 'static,
) {
    install_panic_capture();
    // Longer or other runs, to explore: LOADER_MUTATION_SCALE=10, LOADER_MUTATION_SEED=7.
    let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<u64>().ok());
    let cases = cases * env("LOADER_MUTATION_SCALE").unwrap_or(1) as usize;
    let seed = seed ^ env("LOADER_MUTATION_SEED").unwrap_or(0);
    let save_case: Option<usize> = std::env::var("LOADER_MUTATION_SAVE").ok().and_then(|v| {
        let (n, c) = v.split_once(':')?;
        (n == name).then(|| c.parse().ok())?
    });
    let trace = std::env::var_os("LOADER_MUTATION_TRACE").is_some();
    let (tx, rx) = mpsc::channel();
    std::thread::Builder::new()
        .name(format!("mutate-{name}"))
        .stack_size(8 << 20) // a main thread's, where the loaders run in the CLI
        .spawn(move || {
            let t0 = Instant::now();
            let mut target = setup();
            let mut s = Summary {
                setup: t0.elapsed(),
                ..Summary::default()
            };
            let t1 = Instant::now();
            let mut rng = SplitMix64(seed);
            CAPTURE.set(true);
            for case in 0..cases {
                let how = target.mutate(&mut rng);
                if tx.send(Msg::Case(case, how.clone())).is_err() {
                    return;
                }
                if trace {
                    eprintln!("{name} case {case}: {how}");
                }
                if save_case == Some(case) {
                    let file = save_dir().join(format!("{name}-case{case}.bin"));
                    std::fs::write(&file, target.input()).unwrap();
                    eprintln!("{name} case {case} ({how}) saved to {}", file.display());
                }
                let start = Instant::now();
                let verdict = catch_unwind(AssertUnwindSafe(|| target.call()));
                let took = start.elapsed();
                let problem = match verdict {
                    Ok(Ok(true)) => {
                        s.accepted += 1;
                        None
                    }
                    Ok(Ok(false)) => {
                        s.refused += 1;
                        None
                    }
                    Ok(Err(p)) => Some(p),
                    Err(_) => Some(LAST_PANIC.with_borrow_mut(std::mem::take)),
                };
                let problem = problem.or_else(|| {
                    (took > CALL_BUDGET)
                        .then(|| format!("took {took:.1?}, over the {CALL_BUDGET:?} budget"))
                });
                if let Some(problem) = problem {
                    let entry = s
                        .failures
                        .entry(signature(&problem))
                        .or_insert((0, String::new()));
                    entry.0 += 1;
                    if entry.0 == 1 {
                        let file = save_dir().join(format!("{name}-case{case}.bin"));
                        std::fs::write(&file, target.input()).unwrap();
                        entry.1 = format!(
                            "case {case} ({how}): {problem}\n    input: {}",
                            file.display()
                        );
                    }
                }
                s.cases += 1;
                target.restore();
            }
            s.run = t1.elapsed();
            let _ = tx.send(Msg::Done(s));
        })
        .unwrap();
    let mut current: Option<(usize, String)> = None;
    let s = loop {
        // Building the seeds may wait for another loader's (the MERL table is shared).
        let wait = match current {
            None => Duration::from_secs(600),
            Some(_) => 2 * CALL_BUDGET,
        };
        match rx.recv_timeout(wait) {
            Ok(Msg::Case(i, how)) => current = Some((i, how)),
            Ok(Msg::Done(s)) => break s,
            Err(RecvTimeoutError::Timeout) => {
                let (i, how) = current.unwrap_or((0, "building the seeds".into()));
                panic!(
                    "{name}: case {i} ({how}) has not returned after {wait:?}: a hang \
                     (LOADER_MUTATION_SAVE={name}:{i} saves its input)"
                );
            }
            Err(RecvTimeoutError::Disconnected) => panic!("{name}: the worker died"),
        }
    };
    println!(
        "{name}: {} cases ({} accepted, {} refused) in {:.1?}, seeds built in {:.1?}",
        s.cases, s.accepted, s.refused, s.run, s.setup
    );
    if !s.failures.is_empty() {
        let mut report = format!("{name}: {} distinct failure(s):\n", s.failures.len());
        for (count, example) in s.failures.values() {
            let _ = writeln!(report, "  ×{count}: {example}");
        }
        panic!("{report}");
    }
}

/// `Ok(false)` when the error's message names `path`, else what is wrong with it.
fn refused(path: &Path, e: impl std::fmt::Display) -> Result<bool, String> {
    let message = e.to_string();
    if message.contains(&path.display().to_string()) {
        Ok(false)
    } else {
        Err(format!(
            "the error does not name {}: {message}",
            path.display()
        ))
    }
}

// ---------------------------------------------------------------------------------------------
// Mutations.

/// Overwrites of one byte.
const BYTES: [u8; 4] = [0x00, 0xFF, 0x7F, 0x80];
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

// ---------------------------------------------------------------------------------------------
// Seeds shared between loaders.

/// GGX α = 0.2 sampled on the MERL grid.
fn ggx_table() -> &'static MerlTable {
    static TABLE: OnceLock<MerlTable> = OnceLock::new();
    TABLE.get_or_init(|| MerlTable::sample(&parse_analytic("ggx?alpha=0.2").unwrap()))
}

/// The fit of [`ggx_table`], as JSON.
fn ggx_fit_json() -> &'static str {
    static FIT: OnceLock<String> = OnceLock::new();
    FIT.get_or_init(|| {
        let src = MerlBrdf::from_table("ggx-0.2", ggx_table().clone()).unwrap();
        let fit =
            facet_fit::fit_material(&src, "ggx-0.2", &facet_fit::FitConfig::isotropic()).unwrap();
        serde_json::to_string(&fit.record).unwrap()
    })
}

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// Direction pairs (wi, wo) a BRDF is evaluated at: normal, mid, grazing, retro, forward.
fn direction_pairs() -> Vec<(DVec3, DVec3)> {
    let d = |theta: f64, phi: f64| {
        DVec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        )
    };
    vec![
        (d(0.0, 0.0), d(0.0, 0.0)),
        (d(0.3, 0.0), d(0.5, 3.1)),
        (d(1.2, 0.4), d(0.7, 2.0)),
        (d(1.56, 0.0), d(1.56, std::f64::consts::PI)),
        (d(0.8, 1.0), d(0.8, 1.0)),
        (d(1.5, -2.0), d(0.1, 3.0)),
    ]
}

/// Every value the BRDF gives at [`direction_pairs`] is finite and non-negative.
fn brdf_sane(what: &str, brdf: &dyn Brdf) -> Result<(), String> {
    for (wi, wo) in direction_pairs() {
        if let Some(v) = brdf.eval(wi, wo)
            && !v.iter().all(|x| x.is_finite() && *x >= 0.0)
        {
            return Err(format!("accepted, but {what}: f_r({wi}, {wo}) = {v:?}"));
        }
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// MERL: the 35 MB table is mutated in place (header, length, a few values) and restored.

const MERL_DIMS: [i32; 13] = [
    0,
    -1,
    1,
    2,
    89,
    90,
    91,
    180,
    181,
    8100,
    1_458_000,
    i32::MAX,
    i32::MIN,
];

const MERL_VALUES: [f64; 16] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    MAX_STORED,
    1.000_000_000_000_1e12,
    1e308,
    f64::MAX,
    f64::MIN,
    -0.0,
    0.0,
    -1.0,
    5e-324,
    f64::MIN_POSITIVE,
    1e-300,
    -1e300,
    1.0,
];

struct Merl {
    path: PathBuf,
    /// The valid file, plus bytes appended by a case.
    bytes: Vec<u8>,
    valid_len: usize,
    /// How much of `bytes` the case feeds.
    len: usize,
    /// A small table (tiny dimensions) fed instead, when set.
    small: Option<Vec<u8>>,
    /// Bytes overwritten by the case: (offset, original).
    saved: Vec<(usize, Vec<u8>)>,
    /// Values written by the case: (flat index, value), checked against the table on Ok.
    written: Vec<(usize, f64)>,
    recipe: String,
}

impl Merl {
    /// `tag` keeps apart the files of two tests that build one at once.
    fn new(tag: &str) -> Self {
        let dir = save_dir();
        let file = dir.join(format!("ggx-0.2-{tag}.binary"));
        ggx_table().write(&file).unwrap();
        let bytes = std::fs::read(&file).unwrap();
        std::fs::remove_file(&file).unwrap();
        Merl {
            path: dir.join("mutated.binary"),
            valid_len: bytes.len(),
            len: bytes.len(),
            bytes,
            small: None,
            saved: Vec::new(),
            written: Vec::new(),
            recipe: String::new(),
        }
    }

    fn overwrite(&mut self, at: usize, new: &[u8]) {
        self.saved
            .push((at, self.bytes[at..at + new.len()].to_vec()));
        self.bytes[at..at + new.len()].copy_from_slice(new);
    }

    /// Value `index` (flat, channel-major) overwritten; its original is restored afterwards.
    fn write_value(&mut self, index: usize, v: f64) {
        self.overwrite(12 + 8 * index, &v.to_le_bytes());
        self.written.retain(|w| w.0 != index); // the last write is what the file holds
        self.written.push((index, v));
    }
}

impl Target for Merl {
    fn mutate(&mut self, rng: &mut SplitMix64) -> String {
        let mut log = String::new();
        match rng.below(20) {
            // The header: dimensions replaced, swapped, or bytes flipped.
            0..=4 => {
                for _ in 0..1 + rng.below(2) {
                    match rng.below(3) {
                        0 => {
                            let (d, v) = (rng.below(3), rng.pick(&MERL_DIMS));
                            self.overwrite(4 * d, &v.to_le_bytes());
                            let _ = write!(log, " dimension {d} = {v};");
                        }
                        1 => {
                            let (a, b) = (rng.below(3), rng.below(3));
                            let (x, y) = (
                                self.bytes[4 * a..4 * a + 4].to_vec(),
                                self.bytes[4 * b..4 * b + 4].to_vec(),
                            );
                            self.overwrite(4 * a, &y);
                            self.overwrite(4 * b, &x);
                            let _ = write!(log, " dimensions {a} and {b} swapped;");
                        }
                        _ => {
                            let (at, bit) = (rng.below(12), rng.below(8));
                            let flipped = self.bytes[at] ^ (1 << bit);
                            self.overwrite(at, &[flipped]);
                            let _ = write!(log, " flip bit {bit} of byte {at};");
                        }
                    }
                }
            }
            // The length: truncated (anywhere, or by a few bytes) or extended.
            5..=7 => match rng.below(3) {
                0 => {
                    self.len = rng.below(self.valid_len);
                    let _ = write!(log, " truncated to {} bytes;", self.len);
                }
                1 => {
                    self.len = self.valid_len - rng.pick(&[1, 4, 7, 8, 12, 24, 25]);
                    let _ = write!(log, " truncated to {} bytes;", self.len);
                }
                _ => {
                    let n = rng.pick(&[1, 7, 8, 16, 24, 100]);
                    let fill = rng.pick(&BYTES);
                    self.bytes.resize(self.valid_len + n, fill);
                    self.len = self.bytes.len();
                    let _ = write!(log, " {n} bytes {fill:#04x} appended;");
                }
            },
            // A few values: interesting ones, or a bit of the stored one flipped.
            8..=16 => {
                for _ in 0..1 + rng.below(4) {
                    let index = match rng.below(4) {
                        0 => rng.pick(&[
                            0,
                            SAMPLES - 1,
                            SAMPLES,
                            2 * SAMPLES - 1,
                            2 * SAMPLES,
                            3 * SAMPLES - 1,
                        ]),
                        _ => rng.below(3 * SAMPLES),
                    };
                    let v = if rng.percent(60) {
                        rng.pick(&MERL_VALUES)
                    } else {
                        let at = 12 + 8 * index;
                        let old = f64::from_le_bytes(self.bytes[at..at + 8].try_into().unwrap());
                        // Bits 52..63: the exponent and the sign.
                        f64::from_bits(old.to_bits() ^ (1 << (52 + rng.below(12))))
                    };
                    self.write_value(index, v);
                    let _ = write!(log, " value {index} = {v:e};");
                }
            }
            // A small file: tiny dimensions, a body of about the size they need.
            _ => {
                let dims: [i32; 3] = std::array::from_fn(|_| rng.pick(&[-1, 0, 1, 2, 3, 90, 180]));
                let n: i64 = dims.iter().map(|&d| d as i64).product();
                let body = match rng.below(3) {
                    0 => (24 * n.max(0)) as usize,
                    1 => ((24 * n).max(0) as usize).saturating_sub(8),
                    _ => rng.below(200),
                }
                .min(1 << 20);
                let mut small: Vec<u8> = dims.iter().flat_map(|d| d.to_le_bytes()).collect();
                small.extend((0..body).map(|_| rng.next() as u8));
                let _ = write!(
                    log,
                    " small file: dimensions {dims:?}, {body} bytes of values;"
                );
                self.small = Some(small);
            }
        }
        self.recipe = format!("ggx?alpha=0.2 sampled and written as MERL, then{log}");
        self.recipe.clone()
    }

    fn call(&mut self) -> Result<bool, String> {
        let bytes = self.small.as_deref().unwrap_or(&self.bytes[..self.len]);
        let table = match MerlTable::parse(&self.path, bytes) {
            Ok(t) => t,
            Err(e) => return refused(&self.path, e),
        };
        if self.small.is_some() {
            return Err("accepted a table with non-standard dimensions".into());
        }
        // Every stored value as read: NaN, ∞ and values above MAX_STORED refused.
        for &(index, v) in &self.written {
            if v.is_nan() || v > MAX_STORED {
                return Err(format!("accepted a table whose value {index} is {v:e}"));
            }
            let (c, s) = (index / SAMPLES, index % SAMPLES);
            if let Some(rgb) = table.value_at(s)
                && (v < 0.0 || rgb[c] != v * SCALE[c])
            {
                return Err(format!("value {index} = {v:e} reads back as {:e}", rgb[c]));
            }
        }
        if let Some(s) = (0..SAMPLES).find(|&s| {
            table
                .value_at(s)
                .is_some_and(|v| !v.iter().all(|x| x.is_finite() && *x >= 0.0))
        }) {
            return Err(format!("sample {s} is {:?}", table.value_at(s)));
        }
        if let Ok(brdf) = MerlBrdf::from_table("mutated", table) {
            brdf_sane("the table as a BRDF", &brdf)?;
        }
        Ok(true)
    }

    fn input(&self) -> Vec<u8> {
        match &self.small {
            Some(small) => small.clone(),
            None => self.recipe.clone().into_bytes(),
        }
    }

    fn restore(&mut self) {
        for (at, old) in self.saved.drain(..).rev() {
            self.bytes[at..at + old.len()].copy_from_slice(&old);
        }
        self.bytes.truncate(self.valid_len);
        self.len = self.valid_len;
        self.small = None;
        self.written.clear();
    }
}

// ---------------------------------------------------------------------------------------------
// Loaders of bytes (JSON text, .glb, EXR): seeds mutated into a fresh buffer each case.

#[derive(Clone)]
enum Form {
    /// JSON text: token-level and byte-level mutations.
    Json(Vec<u8>),
    /// A `.glb` of this JSON chunk and binary chunk: its JSON mutated by tokens (the chunk
    /// lengths rebuilt) or the whole file by bytes.
    Glb(Vec<u8>, Vec<u8>),
    /// Any other bytes: byte-level mutations.
    Bytes(Vec<u8>),
}

#[derive(Clone)]
struct Seed {
    /// The path the loader is given (where relative references resolve).
    path: PathBuf,
    form: Form,
    /// Relative frequency among the seeds.
    weight: usize,
}

type Check = fn(&Path, &[u8]) -> Result<bool, String>;

struct Bytes {
    seeds: Vec<Seed>,
    path: PathBuf,
    input: Vec<u8>,
    check: Check,
}

impl Bytes {
    fn new(seeds: Vec<Seed>, check: Check) -> Self {
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

/// A `.glb`: 12-byte header, the JSON chunk padded with spaces, the BIN chunk padded with zeros.
fn glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let pad = |n: usize| n.div_ceil(4) * 4;
    let (jl, bl) = (pad(json.len()), pad(bin.len()));
    let total = 12 + 8 + jl + 8 + bl;
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(jl as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(json);
    out.resize(12 + 8 + jl, b' ');
    out.extend_from_slice(&(bl as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(bin);
    out.resize(total, 0);
    out
}

// ---------------------------------------------------------------------------------------------
// Fit JSON.

fn check_fit(path: &Path, bytes: &[u8]) -> Result<bool, String> {
    let text = String::from_utf8_lossy(bytes);
    let fit = match FittedMaterial::parse(path, &text) {
        Ok(fit) => fit,
        Err(e) => return refused(path, e),
    };
    for choice in [
        ModelChoice::Tabulated,
        ModelChoice::Ggx,
        ModelChoice::Beckmann,
    ] {
        if let Some(model) = fit.model(choice) {
            brdf_sane(&format!("its {choice:?} model"), model)?;
        }
    }
    Ok(true)
}

// ---------------------------------------------------------------------------------------------
// Neural BRDF JSON.

/// The first `n` networks of the embedded MERL-100 file, as a JSON object.
fn nbrdf_entries(n: usize) -> Vec<u8> {
    let text = std::fs::read_to_string(repo("crates/fit/data/nbrdf/merl100.json")).unwrap();
    let all: serde_json::Map<String, serde_json::Value> = serde_json::from_str(&text).unwrap();
    let some: serde_json::Map<String, serde_json::Value> = all.into_iter().take(n).collect();
    serde_json::to_vec(&some).unwrap()
}

fn check_nbrdf(path: &Path, bytes: &[u8]) -> Result<bool, String> {
    let text = String::from_utf8_lossy(bytes);
    let library = match NbrdfLibrary::parse(path, &text) {
        Ok(l) => l,
        Err(e) => return refused(path, e),
    };
    let mut any = false;
    for name in library.names() {
        match library.get(name) {
            Ok(brdf) => {
                brdf_sane(&format!("network `{name}`"), &brdf)?;
                any = true;
            }
            Err(e) => {
                refused(path, e)?;
            }
        }
    }
    Ok(any)
}

// ---------------------------------------------------------------------------------------------
// glTF.

/// A small scene with every part the loader reads, its buffer and image embedded: a quad with
/// normals, UVs, tangents and u16 indices, a second primitive with positions only, a mirrored
/// child node, a textured material and one with a Facet fit (`fit.json` beside the scene), a
/// camera, and point, spot and directional lights. Returns (JSON with the buffer as a data
/// URI, JSON for a `.glb` whose buffer is the BIN chunk, the buffer).
fn small_scene(fit: &str) -> (Vec<u8>, Vec<u8>, Vec<u8>) {
    let mut buf: Vec<u8> = Vec::new();
    let mut put = |vs: &[f32]| vs.iter().for_each(|v| buf.extend(v.to_le_bytes()));
    put(&[-1., 0., -1., 1., 0., -1., 1., 0., 1., -1., 0., 1.]); // 0: positions, 48 bytes
    put(&[0., 1., 0., 0., 1., 0., 0., 1., 0., 0., 1., 0.]); // 48: normals
    put(&[0., 0., 1., 0., 1., 1., 0., 1.]); // 96: UVs, 32 bytes
    put(&[
        1., 0., 0., 1., 1., 0., 0., 1., 1., 0., 0., 1., 1., 0., 0., 1.,
    ]); // 128: tangents
    for i in [0u16, 2, 1, 0, 3, 2] {
        buf.extend(i.to_le_bytes()); // 192: indices, 12 bytes
    }
    let mut png = Vec::new();
    image::RgbaImage::from_fn(2, 2, |x, y| {
        image::Rgba([255 * x as u8, 128, 255 * y as u8, 255])
    })
    .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
    .unwrap();
    let json = |buffer: String| {
        format!(
            r#"{{
"asset": {{"version": "2.0"}},
"extensionsUsed": ["KHR_lights_punctual"],
"scene": 0,
"scenes": [{{"nodes": [0, 2, 3, 4, 5]}}],
"nodes": [
  {{"name": "quad", "mesh": 0, "translation": [0, 0, -3], "rotation": [0, 0.3826834, 0, 0.9238795], "scale": [1, 2, 1], "children": [1]}},
  {{"name": "mirror", "mesh": 0, "matrix": [-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 1, 0, 1]}},
  {{"name": "eye", "camera": 0, "translation": [0, 1, 2]}},
  {{"name": "bulb", "translation": [0, 3, 0], "extensions": {{"KHR_lights_punctual": {{"light": 0}}}}}},
  {{"name": "spot", "rotation": [-0.7071068, 0, 0, 0.7071068], "extensions": {{"KHR_lights_punctual": {{"light": 1}}}}}},
  {{"name": "sun", "extensions": {{"KHR_lights_punctual": {{"light": 2}}}}}}
],
"cameras": [{{"type": "perspective", "perspective": {{"yfov": 0.8, "znear": 0.1, "zfar": 100, "aspectRatio": 1.5}}}}],
"extensions": {{"KHR_lights_punctual": {{"lights": [
  {{"type": "point", "color": [1, 0.9, 0.8], "intensity": 10}},
  {{"type": "spot", "intensity": 5, "spot": {{"innerConeAngle": 0.2, "outerConeAngle": 0.5}}}},
  {{"type": "directional", "intensity": 2}}
]}}}},
"meshes": [{{"name": "quad", "primitives": [
  {{"attributes": {{"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "TANGENT": 3}}, "indices": 4, "material": 0}},
  {{"attributes": {{"POSITION": 5}}, "material": 1}}
]}}],
"materials": [
  {{"name": "painted", "pbrMetallicRoughness": {{"baseColorFactor": [0.8, 0.2, 0.1, 1], "baseColorTexture": {{"index": 0}}, "metallicFactor": 0.5, "roughnessFactor": 0.4, "metallicRoughnessTexture": {{"index": 0}}}}, "normalTexture": {{"index": 0, "scale": 1}}, "emissiveFactor": [0.1, 0.1, 0.1], "emissiveTexture": {{"index": 0}}}},
  {{"name": "fitted", "extras": {{"facet": {{"fit": "{fit}", "model": "ggx", "glint": {{"density": 1000000, "gamma_deg": 2, "threshold": 50}}}}}}}}
],
"textures": [{{"source": 0, "sampler": 0}}],
"samplers": [{{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 33648}}],
"images": [{{"uri": "data:image/png;base64,{png}"}}],
"accessors": [
  {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, 0, -1], "max": [1, 0, 1]}},
  {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"}},
  {{"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}},
  {{"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC4"}},
  {{"bufferView": 4, "componentType": 5123, "count": 6, "type": "SCALAR"}},
  {{"bufferView": 0, "byteOffset": 12, "componentType": 5126, "count": 3, "type": "VEC3", "min": [-1, 0, -1], "max": [1, 0, 1]}}
],
"bufferViews": [
  {{"buffer": 0, "byteOffset": 0, "byteLength": 48, "target": 34962}},
  {{"buffer": 0, "byteOffset": 48, "byteLength": 48, "target": 34962}},
  {{"buffer": 0, "byteOffset": 96, "byteLength": 32, "target": 34962}},
  {{"buffer": 0, "byteOffset": 128, "byteLength": 64, "target": 34962}},
  {{"buffer": 0, "byteOffset": 192, "byteLength": 12, "target": 34963}}
],
"buffers": [{{"byteLength": {len}{buffer}}}]
}}"#,
            png = encode_base64(&png),
            len = buf.len(),
            fit = fit,
        )
        .into_bytes()
    };
    let embedded = json(format!(
        r#", "uri": "data:application/octet-stream;base64,{}""#,
        encode_base64(&buf)
    ));
    (embedded, json(String::new()), buf)
}

/// Everything the renderer relies on in a loaded scene.
fn scene_sane(scene: &Scene) -> Result<(), String> {
    let n = scene.positions.len();
    let unit = |v: Vec3| v.is_finite() && (v.length() - 1.0).abs() < 1e-3;
    if scene.normals.len() != n || scene.uvs.len() != n || scene.tangents.len() != n {
        return Err(format!(
            "{n} positions, {} normals, {} UVs, {} tangents",
            scene.normals.len(),
            scene.uvs.len(),
            scene.tangents.len()
        ));
    }
    if scene.indices.is_empty() || scene.triangle_material.len() != scene.indices.len() {
        return Err(format!(
            "{} triangles, {} triangle materials",
            scene.indices.len(),
            scene.triangle_material.len()
        ));
    }
    if let Some(p) = scene.positions.iter().find(|p| !p.is_finite()) {
        return Err(format!("a position is {p}"));
    }
    if let Some(v) = scene.normals.iter().find(|v| !unit(**v)) {
        return Err(format!("a normal is {v}"));
    }
    if let Some(t) = scene
        .tangents
        .iter()
        .find(|t| !unit(t.truncate()) || t.w.abs() != 1.0)
    {
        return Err(format!("a tangent is {t}"));
    }
    if let Some(uv) = scene.uvs.iter().find(|uv: &&Vec2| !uv.is_finite()) {
        return Err(format!("a UV is {uv}"));
    }
    if let Some(t) = scene
        .indices
        .iter()
        .find(|t| t.iter().any(|&i| i as usize >= n))
    {
        return Err(format!("triangle {t:?} with {n} vertices"));
    }
    let materials = scene.materials.len();
    if let Some(m) = scene
        .triangle_material
        .iter()
        .find(|&&m| m as usize >= materials)
    {
        return Err(format!("triangle material {m} of {materials}"));
    }
    for m in &scene.materials {
        let scalars = [m.metallic, m.roughness, m.specular, m.normal_scale];
        if !(m.base_color.is_finite()
            && m.emissive.is_finite()
            && scalars.iter().all(|x| x.is_finite()))
        {
            return Err(format!(
                "material `{}` has a non-finite factor: {m:?}",
                m.name
            ));
        }
        let textures = [
            m.base_color_texture,
            m.metallic_roughness_texture,
            m.normal_texture,
            m.emissive_texture,
        ];
        if let Some(t) = textures
            .iter()
            .flatten()
            .find(|&&t| t as usize >= scene.textures.len())
        {
            return Err(format!(
                "material `{}` uses texture {t} of {}",
                m.name,
                scene.textures.len()
            ));
        }
        if let Some(facet) = &m.facet {
            brdf_sane(&format!("the fit of material `{}`", m.name), &*facet.fit)?;
        }
    }
    for t in &scene.textures {
        if t.texels.len() != t.width as usize * t.height as usize || t.texels.is_empty() {
            return Err(format!(
                "texture `{}`: {} texels for {}×{}",
                t.name,
                t.texels.len(),
                t.width,
                t.height
            ));
        }
    }
    let c = &scene.camera;
    if !(c.position.is_finite()
        && unit(c.forward)
        && unit(c.up)
        && c.forward.dot(c.up).abs() < 1e-3
        && c.yfov > 0.0
        && c.yfov < std::f32::consts::PI)
    {
        return Err(format!("camera {c:?}"));
    }
    for light in &scene.lights {
        let ok = match *light {
            facet_render::scene::Light::Point {
                position,
                intensity,
            } => position.is_finite() && intensity.is_finite(),
            facet_render::scene::Light::Spot {
                position,
                direction,
                intensity,
                inner_cone,
                outer_cone,
            } => {
                position.is_finite()
                    && unit(direction)
                    && intensity.is_finite()
                    && inner_cone.is_finite()
                    && outer_cone.is_finite()
            }
            facet_render::scene::Light::Directional {
                direction,
                irradiance,
            } => unit(direction) && irradiance.is_finite(),
        };
        if !ok {
            return Err(format!("light {light:?}"));
        }
    }
    Ok(())
}

fn check_gltf(path: &Path, bytes: &[u8]) -> Result<bool, String> {
    match facet_render::scene::load_gltf_bytes(path, bytes, &LoadOptions::default()) {
        Ok(scene) => scene_sane(&scene)
            .map(|()| true)
            .map_err(|p| format!("accepted, but {p}")),
        Err(e) => refused(path, e),
    }
}

// ---------------------------------------------------------------------------------------------
// OpenEXR environment maps.

fn env_sane(map: &EnvironmentMap) -> Result<(), String> {
    let (w, h) = (map.width as usize, map.height as usize);
    if w == 0 || h == 0 || map.texels.len() != w * h {
        return Err(format!("{} texels for {w}×{h}", map.texels.len()));
    }
    if let Some(t) = map
        .texels
        .iter()
        .find(|t| !(t.is_finite() && t.min_element() >= 0.0))
    {
        return Err(format!("a texel is {t}"));
    }
    let monotone = |cdf: &[f32]| {
        cdf.windows(2).all(|p| p[0] <= p[1]) && cdf.iter().all(|x| (0.0..=1.0).contains(x))
    };
    if map.marginal_cdf.len() != h + 1
        || !monotone(&map.marginal_cdf)
        || !(map.total.is_finite() && map.total > 0.0)
    {
        return Err(format!(
            "marginal CDF {:?}…, total {}",
            &map.marginal_cdf[..map.marginal_cdf.len().min(4)],
            map.total
        ));
    }
    for u in [
        Vec2::new(0.1, 0.2),
        Vec2::new(0.5, 0.5),
        Vec2::new(0.999, 0.001),
    ] {
        let (d, pdf, radiance) = map.sample(u);
        if !(unit3(d) && pdf.is_finite() && pdf >= 0.0 && radiance.is_finite()) {
            return Err(format!("sample({u}) = ({d}, {pdf}, {radiance})"));
        }
        if !map.pdf(d).is_finite() || !map.lookup(d).is_finite() {
            return Err(format!("pdf or lookup at {d} not finite"));
        }
    }
    Ok(())
}

fn unit3(v: Vec3) -> bool {
    v.is_finite() && (v.length() - 1.0).abs() < 1e-3
}

fn check_exr(path: &Path, bytes: &[u8]) -> Result<bool, String> {
    match EnvironmentMap::from_exr_bytes(path, bytes) {
        Ok((map, _warnings)) => env_sane(&map)
            .map(|()| true)
            .map_err(|p| format!("accepted, but {p}")),
        Err(e) => refused(path, e),
    }
}

/// A tiny RGB EXR written by the exr crate (f32, its default compression).
fn tiny_exr() -> Vec<u8> {
    let file = save_dir().join("tiny-seed.exr");
    exr::prelude::write_rgb_file(&file, 8, 4, |x, y| (x as f32 * 0.25, y as f32 * 0.5, 1.0))
        .unwrap();
    let bytes = std::fs::read(&file).unwrap();
    std::fs::remove_file(&file).unwrap();
    bytes
}

// ---------------------------------------------------------------------------------------------
// The campaigns.

#[test]
fn merl_loader_survives_mutation() {
    campaign("merl", 0x4D45_524C, 600, || Merl::new("campaign"));
}

#[test]
fn fit_json_loader_survives_mutation() {
    campaign("fit_json", 0x4649_544A, 20000, || {
        let dir = save_dir();
        Bytes::new(
            vec![
                Seed {
                    path: dir.join("mutated-fit.json"),
                    form: Form::Json(ggx_fit_json().as_bytes().to_vec()),
                    weight: 3,
                },
                Seed {
                    path: dir.join("mutated-default-fit.json"),
                    form: Form::Json(std::fs::read(repo("assets/demo/default_fit.json")).unwrap()),
                    weight: 1,
                },
            ],
            check_fit,
        )
    });
}

#[test]
fn nbrdf_loader_survives_mutation() {
    campaign("nbrdf", 0x4E42_5244, 20000, || {
        let dir = save_dir();
        Bytes::new(
            vec![
                Seed {
                    path: dir.join("mutated-one.json"),
                    form: Form::Json(nbrdf_entries(1)),
                    weight: 3,
                },
                Seed {
                    path: dir.join("mutated-two.json"),
                    form: Form::Json(nbrdf_entries(2)),
                    weight: 1,
                },
            ],
            check_nbrdf,
        )
    });
}

#[test]
fn gltf_loader_survives_mutation() {
    campaign("gltf", 0x674C_5446, 20000, || {
        let dir = save_dir().join("gltf");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("fit.json"), ggx_fit_json()).unwrap();
        let (embedded, for_glb, bin) = small_scene("fit.json");
        Bytes::new(
            vec![
                Seed {
                    path: dir.join("mutated.gltf"),
                    form: Form::Json(embedded),
                    weight: 10,
                },
                Seed {
                    path: dir.join("mutated.glb"),
                    form: Form::Glb(for_glb, bin),
                    weight: 10,
                },
                Seed {
                    path: repo("assets/demo/demo.gltf"),
                    form: Form::Json(std::fs::read(repo("assets/demo/demo.gltf")).unwrap()),
                    weight: 1,
                },
            ],
            check_gltf,
        )
    });
}

#[test]
fn exr_loader_survives_mutation() {
    campaign("exr_env", 0x4558_5221, 20000, || {
        let dir = save_dir();
        Bytes::new(
            vec![
                Seed {
                    path: dir.join("mutated-tiny.exr"),
                    form: Form::Bytes(tiny_exr()),
                    weight: 1,
                },
                Seed {
                    path: dir.join("mutated-sky.exr"),
                    form: Form::Bytes(std::fs::read(repo("assets/demo/sky.exr")).unwrap()),
                    weight: 1,
                },
            ],
            check_exr,
        )
    });
}

// ---------------------------------------------------------------------------------------------
// RGL .bsdf: tensor files, RGB, spectral and anisotropic.

fn check_bsdf(path: &Path, bytes: &[u8]) -> Result<bool, String> {
    match RglBsdf::from_bytes(path, bytes.to_vec()) {
        Ok(file) => {
            brdf_sane("the .bsdf", &file)?;
            for (wi, wo) in direction_pairs() {
                let pdf = file.pdf(wi, wo);
                if !(pdf.is_finite() && pdf >= 0.0) {
                    return Err(format!("accepted, but pdf({wi}, {wo}) = {pdf}"));
                }
            }
            Ok(true)
        }
        Err(e) => refused(path, e),
    }
}

/// Small `.bsdf` seeds (grids of 4 to 8): an RGB plastic, its spectral twin, an anisotropic
/// metal.
fn bsdf_seeds() -> Vec<(&'static str, Vec<u8>)> {
    let res = BsdfResolution {
        theta_i: 4,
        phi_i: 5,
        sample: 6,
        vndf: 8,
        ndf: 8,
    };
    let bytes = |spec: &str| {
        let model = parse_analytic(spec).unwrap();
        rgl_tensor(&model, &model.ndf, res, spec)
            .unwrap()
            .0
            .to_bytes()
    };
    let rgb = bytes("ggx?alpha=0.3&f0=0.04&kd=0.3,0.1,0.05");
    let spectral = common::spectral_from_rgb(&rgb);
    vec![
        ("rgb", rgb),
        ("spectral", spectral),
        ("aniso", bytes("ggx?alpha_x=0.1&alpha_y=0.3&f0=0.9")),
    ]
}

#[test]
fn bsdf_loader_survives_mutation() {
    campaign("bsdf", 0x4253_4446, 20000, || {
        let dir = save_dir();
        Bytes::new(
            bsdf_seeds()
                .into_iter()
                .map(|(name, bytes)| Seed {
                    path: dir.join(format!("mutated-{name}.bsdf")),
                    form: Form::Bytes(bytes),
                    weight: 1,
                })
                .collect(),
            check_bsdf,
        )
    });
}

/// The seeds themselves load: a mutation test whose seeds are refused tests nothing.
#[test]
fn seeds_are_accepted() {
    let dir = save_dir().join("seeds");
    std::fs::create_dir_all(&dir).unwrap();
    let merl = Merl::new("seeds");
    assert!(MerlTable::parse(&merl.path, &merl.bytes).is_ok());
    check_fit(&dir.join("seed-fit.json"), ggx_fit_json().as_bytes()).unwrap();
    check_fit(
        &repo("assets/demo/default_fit.json"),
        &std::fs::read(repo("assets/demo/default_fit.json")).unwrap(),
    )
    .unwrap();
    assert!(check_nbrdf(&dir.join("seed-nbrdf.json"), &nbrdf_entries(2)).unwrap());
    std::fs::write(dir.join("fit.json"), ggx_fit_json()).unwrap();
    let (embedded, for_glb, bin) = small_scene("fit.json");
    assert!(check_gltf(&dir.join("seed.gltf"), &embedded).unwrap());
    assert!(check_gltf(&dir.join("seed.glb"), &glb(&for_glb, &bin)).unwrap());
    let demo = repo("assets/demo/demo.gltf");
    assert!(check_gltf(&demo, &std::fs::read(&demo).unwrap()).unwrap());
    assert!(check_exr(&dir.join("seed.exr"), &tiny_exr()).unwrap());
    let sky = repo("assets/demo/sky.exr");
    assert!(check_exr(&sky, &std::fs::read(&sky).unwrap()).unwrap());
    for (name, bytes) in bsdf_seeds() {
        assert!(
            check_bsdf(&dir.join(format!("seed-{name}.bsdf")), &bytes).unwrap(),
            "{name}"
        );
    }
}

/// The fuzz targets' seeds, `fuzz/corpus/<target>/seed-*`: (target, file name, bytes).
/// The `merl` target expands a short input (see `fuzz/fuzz_targets/merl.rs`): byte 0 bit 0
/// clear, byte 1 the length change, 12 bytes XORed into the header, 12-byte value records.
fn fuzz_seeds() -> Vec<(&'static str, &'static str, Vec<u8>)> {
    let record = |index: u32, v: f64| [index.to_le_bytes().as_slice(), &v.to_le_bytes()].concat();
    let expanded = |records: &[Vec<u8>]| [vec![0u8; 14], records.concat()].concat();
    let mut small = vec![1u8];
    small.extend([1i32, 1, 1].iter().flat_map(|d| d.to_le_bytes()));
    small.extend([0.5f64, 0.6, 0.7].iter().flat_map(|v| v.to_le_bytes()));
    // A fit of the demo's, its tables thinned (every 8th NDF node, every 16th G1 node, every
    // 9th Fresnel angle) to a few KB; still a valid fit.
    let mut fit: facet_fit::model::material::FitRecord =
        serde_json::from_slice(&std::fs::read(repo("assets/demo/default_fit.json")).unwrap())
            .unwrap();
    let every = |v: &[f64], k: usize| v.iter().step_by(k).copied().collect::<Vec<f64>>();
    let t = &mut fit.tabulated.tables;
    assert_eq!(t.nphi, 1);
    (t.d, t.g1) = (every(&t.d, 8), every(&t.g1, 16));
    (t.nu, t.ng) = (t.d.len(), t.g1.len());
    let thin = |f: &mut facet_fit::model::fresnel::FresnelTable| {
        f.theta_d = every(&f.theta_d, 9);
        f.rgb = f.rgb.iter().step_by(9).copied().collect();
    };
    thin(&mut fit.fresnel);
    fit.ggx
        .iter_mut()
        .chain(fit.beckmann.iter_mut())
        .for_each(|p| thin(&mut p.fresnel));
    let (embedded, for_glb, bin) = small_scene("default_fit.json");
    vec![
        ("merl", "seed-valid", vec![0]),
        (
            "merl",
            "seed-values",
            expanded(&[record(1000, 0.5), record(2 * SAMPLES as u32 + 5, -1.0)]),
        ),
        ("merl", "seed-small", small),
        (
            "fit_json",
            "seed-thinned-demo-fit.json",
            serde_json::to_vec(&fit).unwrap(),
        ),
        ("nbrdf", "seed-one.json", nbrdf_entries(1)),
        ("gltf", "seed-small.gltf", embedded),
        ("gltf", "seed-small.glb", glb(&for_glb, &bin)),
        ("exr_env", "seed-tiny.exr", tiny_exr()),
        (
            "exr_env",
            "seed-sky.exr",
            std::fs::read(repo("assets/demo/sky.exr")).unwrap(),
        ),
    ]
}

/// The fuzz seeds are accepted by their loaders, the committed ones as well as those built
/// here; `FACET_WRITE_FUZZ_SEEDS=1` (re)writes them under `fuzz/corpus/`.
#[test]
fn fuzz_seeds_are_accepted() {
    let corpus = repo("fuzz/corpus");
    // A glTF seed names `default_fit.json`: beside the demo scene, where the fuzzer's
    // scratch folder puts it too.
    let check = |target: &str, name: &str, bytes: &[u8]| match target {
        "fit_json" => assert!(check_fit(&corpus.join(name), bytes).unwrap(), "{name}"),
        "nbrdf" => assert!(check_nbrdf(&corpus.join(name), bytes).unwrap(), "{name}"),
        "gltf" => assert!(
            check_gltf(&repo("assets/demo").join(name), bytes).unwrap(),
            "{name}"
        ),
        "exr_env" => assert!(check_exr(&corpus.join(name), bytes).unwrap(), "{name}"),
        _ => {} // merl: its seeds are recipes, tried by the target
    };
    let write = std::env::var_os("FACET_WRITE_FUZZ_SEEDS").is_some();
    let mut total = 0;
    for (target, name, bytes) in fuzz_seeds() {
        check(target, name, &bytes);
        total += bytes.len();
        if write {
            std::fs::create_dir_all(corpus.join(target)).unwrap();
            std::fs::write(corpus.join(target).join(name), &bytes).unwrap();
        }
    }
    assert!(total < 100_000, "the seeds are {total} bytes");
    for dir in std::fs::read_dir(&corpus).into_iter().flatten() {
        let dir = dir.unwrap().path();
        let target = dir.file_name().unwrap().to_string_lossy().into_owned();
        for file in std::fs::read_dir(&dir).unwrap() {
            let file = file.unwrap().path();
            let name = file.file_name().unwrap().to_string_lossy().into_owned();
            if name.starts_with("seed-") {
                check(&target, &name, &std::fs::read(&file).unwrap());
            }
        }
    }
}
