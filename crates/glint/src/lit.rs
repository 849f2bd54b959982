//! Lit counts per node: which flakes of the quadtree are lit for a query, decided top-down so
//! that a node inside the footprint contributes its lit count in O(1) and only nodes on the
//! footprint's boundary descend (WGSL twin: `shaders/glint/lit.inc.wgsl`).
//!
//! Each flake is lit independently with probability P, so a node of n flakes holds
//! L ~ Binomial(n, P) lit ones, and given L they are a uniformly random L-subset. The root's L
//! is the inverse CDF of Binomial(n, P) at a keyed uniform; a node's L is split among its
//! children (whose flake counts the positions' split fixed) by hypergeometric draws — first the
//! left and right halves, then each half's lower and upper quarter, as the positions split —
//! and a leaf picks its lit flakes by selection sampling (Knuth's Algorithm S). Every draw is an
//! inverse CDF at a uniform keyed on the node (or flake) and on the query's direction cell, so:
//! a node's L is one number whatever the footprint (nested footprints give nested counts); for
//! fixed keys every L is non-decreasing in P (a slowly moving light changes counts gradually);
//! and the distribution is that of independent flakes. Large draws use normal approximations
//! (mean above [`LIT_EXACT_MEAN`], splits of more than [`SPLIT_EXACT_MAX`]).

use crate::flakes::{Flake, FlakeField, Footprint, LEAF_FLAKES, MAX_DEPTH, normal_quantile};
use crate::tea::tea;
use glam::{DMat2, DVec2};

/// Binomial(n, P) draws of up to this mean are exact inverse CDFs (a loop of at most ~60
/// steps, once per query); larger ones use the continuity-corrected normal approximation.
pub const LIT_EXACT_MEAN: f64 = 30.0;
/// Hypergeometric splits of up to this many lit (or unlit) flakes are exact inverse CDFs (two
/// searches of at most this many steps, written out in WGSL); larger ones use the normal
/// approximation. Small because a walk splits eight chains three times per node, and llvmpipe
/// (lavapipe) caps the loop iterations of a shader invocation at 65 535: with loops of 32 steps
/// a render's unfiltered footprints came back short on lavapipe.
pub const SPLIT_EXACT_MAX: u64 = 8;
// lit.inc.wgsl writes the exact split's steps out, eight of them.
const _: () = assert!(SPLIT_EXACT_MAX <= 8);

/// The most nodes the WGSL walk's stack holds: each node popped pushes at most four children,
/// so a walk to depth [`MAX_DEPTH`] holds 3 · MAX_DEPTH + 1 (`STACK` in lit.inc.wgsl).
pub const STACK_DEPTH: u32 = 3 * MAX_DEPTH + 1;

/// The keys of one query's lit flakes: the hash of its direction cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LitKey(pub u32, pub u32);

impl LitKey {
    /// The key of direction cell `cell` ([`crate::flakes::direction_cell`]).
    pub fn of_cell(cell: (u32, u32)) -> Self {
        let c = tea(cell.0, cell.1);
        LitKey(c as u32, (c >> 32) as u32)
    }
}

/// pcg3d (Jarzynski & Olano 2020): three well-mixed words from three, cheap on a GPU.
pub fn pcg3d(v: [u32; 3]) -> [u32; 3] {
    let mut v = v.map(|x| x.wrapping_mul(1_664_525).wrapping_add(1_013_904_223));
    let mix = |v: &mut [u32; 3]| {
        v[0] = v[0].wrapping_add(v[1].wrapping_mul(v[2]));
        v[1] = v[1].wrapping_add(v[2].wrapping_mul(v[0]));
        v[2] = v[2].wrapping_add(v[0].wrapping_mul(v[1]));
    };
    mix(&mut v);
    v = v.map(|x| x ^ (x >> 16));
    mix(&mut v);
    v
}

/// A word to a uniform in [0, 1) with 24 bits (exact in f32).
pub fn unit(x: u32) -> f64 {
    (x >> 8) as f64 / 16_777_216.0
}

/// Inverse CDF of Binomial(n, p) at u (p may be any probability).
pub fn binomial_p(n: u64, p: f64, u: f64) -> u64 {
    if n == 0 || p <= 0.0 {
        return 0;
    }
    if p >= 1.0 {
        return n;
    }
    if p > 0.5 {
        // The unlit ones: Binomial(n, 1 − p) at 1 − u.
        return n - binomial_p(n, 1.0 - p, 1.0 - u);
    }
    let mean = n as f64 * p;
    if mean > LIT_EXACT_MEAN {
        let x = mean + (mean * (1.0 - p)).sqrt() * normal_quantile(u) + 0.5;
        return (x.max(0.0) as u64).min(n);
    }
    // P(0) = (1 − p)ⁿ, P(k + 1) = P(k) (n − k) p / ((k + 1)(1 − p)).
    let mut pmf = (n as f64 * ln_1m(p)).exp();
    let (mut k, mut cdf) = (0u64, pmf);
    let ratio = p / (1.0 - p);
    while cdf <= u && k < n {
        pmf *= (n - k) as f64 / (k + 1) as f64 * ratio;
        k += 1;
        cdf += pmf;
    }
    k
}

/// ln(1 − p), accurate for small p in f32 too (the WGSL twin has no log1p).
fn ln_1m(p: f64) -> f64 {
    if p < 0.01 {
        -p * (1.0 + p * (0.5 + p / 3.0))
    } else {
        (1.0 - p).ln()
    }
}

/// Inverse CDF at u of the lit flakes among the `m` of a node's `n` flakes that lie in one part,
/// when `l` of the n are lit: Hypergeometric(n, m, l). Non-decreasing in l for fixed u.
pub fn hypergeometric(n: u64, m: u64, l: u64, u: f64) -> u64 {
    debug_assert!(m <= n && l <= n);
    // More lit than unlit: split the unlit ones instead (the part's lit = m − its unlit).
    let flip_l = 2 * l > n;
    let l1 = if flip_l { n - l } else { l };
    // The part larger than half: count the other part's (this part's = l1 − the other's).
    let flip_m = 2 * m > n;
    let m1 = if flip_m { n - m } else { m };
    let k = hypergeometric_small(n, m1, l1, u);
    let k = if flip_m { l1 - k } else { k };
    if flip_l { m - k } else { k }
}

/// Hypergeometric(n, m, l) for m, l ≤ n/2, where the support starts at 0.
fn hypergeometric_small(n: u64, m: u64, l: u64, u: f64) -> u64 {
    if l == 0 || m == 0 {
        return 0;
    }
    let top = l.min(m);
    if l > SPLIT_EXACT_MAX {
        // Mean l m/n, variance l (m/n)(1 − m/n)(n − l)/(n − 1).
        let q = m as f64 / n as f64;
        let var = l as f64 * q * (1.0 - q) * (n - l) as f64 / (n - 1) as f64;
        let x = l as f64 * q + var.sqrt() * normal_quantile(u) + 0.5;
        return (x.max(0.0) as u64).min(top);
    }
    // P(0) = Π_{j<l} (n − m − j)/(n − j); P(k+1) = P(k) (m − k)(l − k) / ((k + 1)(n − m − l + k + 1)).
    let mut pmf = 1.0;
    for j in 0..l {
        pmf *= (n - m - j) as f64 / (n - j) as f64;
    }
    let (mut k, mut cdf) = (0u64, pmf);
    while cdf <= u && k < top {
        pmf *= ((m - k) * (l - k)) as f64 / ((k + 1) * (n - m - l + k + 1)) as f64;
        k += 1;
        cdf += pmf;
    }
    k
}

impl FlakeField {
    /// Lit flakes of the whole torus (the root) for P = `p` under `key`.
    pub fn root_lit(&self, p: f64, key: LitKey) -> u64 {
        let u = pcg3d([key.0, key.1, 0xffff_ffff]);
        binomial_p(self.root_count(), p, unit(u[0]))
    }

    /// The lit counts of the four children (order of [`FlakeField::split`]) of a node with
    /// `lit` lit flakes whose children hold `c` flakes.
    pub(crate) fn split_lit(&self, node: u64, c: [u64; 4], lit: u64, key: LitKey) -> [u64; 4] {
        if lit == 0 {
            return [0; 4];
        }
        let u = pcg3d([
            node as u32 ^ key.0,
            (node >> 32) as u32 ^ key.1,
            0x2545_f491,
        ])
        .map(unit);
        let (left, n) = (c[0] + c[2], c.iter().sum::<u64>());
        let lit_left = hypergeometric(n, left, lit, u[0]);
        let l00 = hypergeometric(left, c[0], lit_left, u[1]);
        let l10 = hypergeometric(n - left, c[1], lit - lit_left, u[2]);
        [l00, l10, lit_left - l00, lit - lit_left - l10]
    }

    /// Whether a leaf's flake `id` is lit, `needed` of its `remaining` flakes still to pick
    /// (Algorithm S: taken with probability needed / remaining, at a uniform keyed on the flake).
    pub(crate) fn leaf_lit(&self, id: u64, needed: u64, remaining: u64, key: LitKey) -> bool {
        let u = pcg3d([id as u32 ^ key.0, (id >> 32) as u32 ^ key.1, 0x27d4_eb2f]);
        unit(u[0]) * (remaining as f64) < needed as f64
    }

    /// Lit flakes in the footprint for P = `p` under `key`: interior nodes add their lit count,
    /// only nodes on the boundary descend.
    pub fn lit_count(&self, fp: &Footprint, p: f64, key: LitKey) -> u64 {
        let root = (self.root_count(), self.root_lit(p, key));
        fp.copies()
            .iter()
            .map(|c| self.visit_lit(c, &c.inverse(), 0, 0, 0, root, key, None))
            .sum()
    }

    /// Every lit flake in the footprint, found by descending to every leaf (the reference
    /// [`FlakeField::lit_count`] is checked against).
    pub fn lit_flakes_in(&self, fp: &Footprint, p: f64, key: LitKey) -> Vec<Flake> {
        let root = (self.root_count(), self.root_lit(p, key));
        let mut out = Vec::new();
        for c in fp.copies() {
            self.visit_lit(&c, &c.inverse(), 0, 0, 0, root, key, Some(&mut out));
        }
        out
    }

    /// Lit flakes of node (level, ix, iy), holding (n, lit), in `fp`; with `out` every lit flake
    /// is listed (no interior shortcut).
    #[allow(clippy::too_many_arguments)]
    fn visit_lit(
        &self,
        fp: &Footprint,
        inv: &DMat2,
        level: u32,
        ix: u32,
        iy: u32,
        (n, lit): (u64, u64),
        key: LitKey,
        mut out: Option<&mut Vec<Flake>>,
    ) -> u64 {
        if lit == 0 {
            return 0;
        }
        let size = 1.0 / (1u64 << level) as f64;
        let min = DVec2::new(ix as f64, iy as f64) * size;
        let ext = fp.half_extent();
        let (lo, hi) = (fp.center - ext, fp.center + ext);
        if min.x + size < lo.x || min.x > hi.x || min.y + size < lo.y || min.y > hi.y {
            return 0;
        }
        let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
        if out.is_none()
            && corners
                .iter()
                .all(|&(x, y)| fp.contains(inv, min + size * DVec2::new(x, y)))
        {
            return lit;
        }
        let h = self.node_hash(level, ix, iy);
        if n <= LEAF_FLAKES || level == MAX_DEPTH {
            // Flakes past the last lit one are not looked at, and only a lit flake's position
            // is hashed.
            let (mut needed, mut found) = (lit, 0);
            for k in 0..n {
                if needed == 0 {
                    break;
                }
                let id = FlakeField::leaf_flake_id(h, k as u32);
                if self.leaf_lit(id, needed, n - k, key) {
                    needed -= 1;
                    let flake = FlakeField::flake_at(id, min, size);
                    if fp.contains(inv, flake.uv) {
                        found += 1;
                        if let Some(o) = out.as_deref_mut() {
                            o.push(flake);
                        }
                    }
                }
            }
            return found;
        }
        let c = self.split(level, ix, iy, n);
        let l = self.split_lit(h, c, lit, key);
        (0..4)
            .map(|k| {
                let (dx, dy) = ((k & 1) as u32, (k >> 1) as u32);
                let child = (level + 1, 2 * ix + dx, 2 * iy + dy);
                self.visit_lit(
                    fp,
                    inv,
                    child.0,
                    child.1,
                    child.2,
                    (c[k], l[k]),
                    key,
                    out.as_deref_mut(),
                )
            })
            .sum()
    }
}

/// Width, in cells, of the band around a cell edge over which blended counts fade from one cell
/// to its neighbour; inside a cell, away from its edges, one cell's count is the count. A quarter
/// of a cell: a query reads (1 + ¼)² ≈ 1.56 cells on average instead of bilinear's 4 (half a
/// cell read 2.25 and made the glint stage ~1.4× slower on the demo); a count still changes
/// continuously with the half vector, at most twice as fast near an edge as with half a cell.
pub const BLEND_BAND: f64 = 0.25;

/// One axis of [`blend_cells`]: the cell x lies in and the neighbour across the nearer edge, with
/// weights that are 1 and 0 away from the edge and fade linearly to ½ and ½ at it.
fn blend_axis(x: f64) -> [(i64, f64); 2] {
    let c = x.floor();
    let f = x - c;
    let half = 0.5 * BLEND_BAND;
    if f < half {
        [
            (c as i64, 0.5 + f / BLEND_BAND),
            (c as i64 - 1, 0.5 - f / BLEND_BAND),
        ]
    } else if f > 1.0 - half {
        let g = 1.0 - f;
        [
            (c as i64, 0.5 + g / BLEND_BAND),
            (c as i64 + 1, 0.5 - g / BLEND_BAND),
        ]
    } else {
        [(c as i64, 1.0), (c as i64 + 1, 0.0)]
    }
}

/// The direction cells a query reads and their weights: the cell of
/// [`crate::flakes::direction_coords`] and, within [`BLEND_BAND`] of an edge, the neighbour
/// across it (four cells near a corner), weights continuous in the half vector and summing to
/// 1, so a count blended with them does not pop at cell edges (in the manner of Deliot & Belcour
/// 2023). Entries of weight 0 are not read.
pub fn blend_cells(coords: DVec2) -> [((u32, u32), f64); 4] {
    let (ax, ay) = (blend_axis(coords.x), blend_axis(coords.y));
    let q = |c: i64| (c + (1 << 24)) as u32;
    let cell = |i: usize, j: usize| ((q(ax[i].0), q(ay[j].0)), ax[i].1 * ay[j].1);
    [cell(0, 0), cell(1, 0), cell(0, 1), cell(1, 1)]
}
