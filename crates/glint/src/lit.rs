//! Lit counts per node: which flakes of the quadtree are lit for a query, decided top-down so
//! that a node inside the footprint contributes its lit count in O(1) and only nodes on the
//! footprint's boundary descend (WGSL twin: `shaders/glint/lit.inc.wgsl`).
//!
//! Each flake is lit independently with probability P, so a node of n flakes holds
//! L ~ Binomial(n, P) lit ones, and given L they are a uniformly random L-subset. The root's L
//! is the inverse CDF of Binomial(n, P) at a keyed uniform; a node's L is split among its
//! children (whose flake counts the positions' split fixed) by hypergeometric draws — first the
//! left and right halves, then each half's lower and upper quarter, as the positions split —
//! and a leaf's L lit flakes are a run of its flakes from a keyed start
//! ([`FlakeField::leaf_run_start`]): a flake's position hashes its id, so any L distinct flakes
//! of a leaf lie at L independent uniform positions in it, and only the lit ones are looked at.
//! Every draw is keyed on the node (or leaf) and on the query's direction cell — an inverse CDF
//! at a keyed uniform, or for a split of few lit flakes one keyed draw a flake — so: a node's L
//! is one number whatever the footprint (nested footprints give nested counts); for fixed keys
//! every L is non-decreasing in P, and a leaf's larger L lights a superset (a slowly moving
//! light changes counts gradually);
//! and the distribution is that of independent flakes. Large draws use normal approximations
//! (mean above [`LIT_EXACT_MEAN`], splits of more than [`SPLIT_EXACT_MAX`]).

use crate::flakes::{Flake, FlakeField, Footprint, LEAF_FLAKES, MAX_DEPTH, normal_quantile};
use crate::tea::{pcg3d, tea, unit};
use glam::{DMat2, DVec2};

/// Binomial(n, P) draws of up to this mean are exact inverse CDFs (a loop of at most ~60
/// steps, once per query); larger ones use the continuity-corrected normal approximation.
pub const LIT_EXACT_MEAN: f64 = 30.0;
/// Hypergeometric splits of up to this many lit (or unlit) flakes are exact, one draw a flake
/// ([`hypergeometric`], written out in WGSL); larger ones use the normal approximation. Small
/// because a walk splits eight chains three times per node, and llvmpipe (lavapipe) caps the
/// loop iterations of a shader invocation at 65 535: with loops of 32 steps a render's
/// unfiltered footprints came back short on lavapipe.
pub const SPLIT_EXACT_MAX: u64 = 8;
// lit.inc.wgsl writes the exact split's draws out, eight of them.
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

/// The lit flakes among the `m` of a node's `n` flakes that lie in one part, when `l` of the n
/// are lit: Hypergeometric(n, m, l). The fewer of the lit and the unlit flakes are drawn one
/// by one, up to [`SPLIT_EXACT_MAX`] of them: the j-th lands in the part with probability
/// (the part's flakes left) / (flakes left), at the j-th uniform of `seed`'s sequence
/// ([`next_state`]). The rest, if any, split by the normal approximation of the hypergeometric
/// draw from the flakes left, at the uniform of `seed`. One more flake is one more draw (or a
/// normal draw of one more from the same population), so for a fixed seed and l ≤ n/2 (the
/// lit are drawn; glints' P is small) a count only grows. No division and no search: the walk
/// splits up to eight chains three times a node.
pub fn hypergeometric(n: u64, m: u64, l: u64, seed: u32) -> u64 {
    debug_assert!(m <= n && l <= n);
    // Few unlit: draw the unlit ones (the part's lit = m − its unlit).
    let flip = l > n - l;
    let few = l.min(n - l);
    let (mut s, mut k) = (seed, 0u64);
    for j in 0..few.min(SPLIT_EXACT_MAX) {
        s = next_state(s);
        // f32, as in WGSL: the product of a 24-bit uniform and the flakes left, rounded once.
        if state_unit(s) * ((n - j) as f32) < (m - k) as f32 {
            k += 1;
        }
    }
    if few > SPLIT_EXACT_MAX {
        let e = SPLIT_EXACT_MAX;
        k += hypergeometric_normal(n - e, m - k, few - e, unit(seed));
    }
    if flip { m - k } else { k }
}

/// The next state of a split's uniforms: a 32-bit LCG step (PCG's multiplier and increment).
pub fn next_state(s: u32) -> u32 {
    s.wrapping_mul(747_796_405).wrapping_add(2_891_336_453)
}

/// A state's uniform in [0, 1), 24 bits: PCG's output permutation (RXS-M-XS) of the state.
pub fn state_unit(s: u32) -> f32 {
    let w = ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277_803_737);
    (((w >> 22) ^ w) >> 8) as f32 / 16_777_216.0
}

/// Hypergeometric(n, m, l) at u by the continuity-corrected normal approximation, on the
/// smaller part and the fewer of lit and unlit (where the support starts at 0).
fn hypergeometric_normal(n: u64, m: u64, l: u64, u: f64) -> u64 {
    // More lit than unlit: split the unlit ones instead (the part's lit = m − its unlit).
    let flip_l = 2 * l > n;
    let l1 = if flip_l { n - l } else { l };
    // The part larger than half: count the other part's (this part's = l1 − the other's).
    let flip_m = 2 * m > n;
    let m1 = if flip_m { n - m } else { m };
    let k = if l1 == 0 || m1 == 0 {
        0
    } else {
        // Mean l m/n, variance l (m/n)(1 − m/n)(n − l)/(n − 1).
        let q = m1 as f64 / n as f64;
        let var = l1 as f64 * q * (1.0 - q) * (n - l1) as f64 / (n - 1) as f64;
        let x = l1 as f64 * q + var.sqrt() * normal_quantile(u) + 0.5;
        (x.max(0.0) as u64).min(l1.min(m1))
    };
    let k = if flip_m { l1 - k } else { k };
    if flip_l { m - k } else { k }
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
        let seeds = pcg3d([
            node as u32 ^ key.0,
            (node >> 32) as u32 ^ key.1,
            0x2545_f491,
        ]);
        let (left, n) = (c[0] + c[2], c.iter().sum::<u64>());
        let lit_left = hypergeometric(n, left, lit, seeds[0]);
        let l00 = hypergeometric(left, c[0], lit_left, seeds[1]);
        let l10 = hypergeometric(n - left, c[1], lit - lit_left, seeds[2]);
        [l00, l10, lit_left - l00, lit - lit_left - l10]
    }

    /// Where the run of a leaf's lit flakes starts: flakes start, start + 1, … (mod n) of the
    /// leaf of hash `h` and n flakes are its lit ones under `key`. Any L distinct flakes of a
    /// leaf are L independent uniform positions in it (a flake's position hashes its id), so
    /// the run gives the law of independent flakes, and a larger L lights a superset.
    pub fn leaf_run_start(&self, h: u64, n: u64, key: LitKey) -> u64 {
        let r = pcg3d([h as u32 ^ key.0, (h >> 32) as u32 ^ key.1, 0x27d4_eb2f]);
        (r[0] % n as u32) as u64
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
            // The lit flakes: a keyed run of the leaf's, only their positions hashed.
            let start = self.leaf_run_start(h, n, key);
            let mut found = 0;
            for j in 0..lit {
                let k = ((start + j) % n) as u32;
                let flake = FlakeField::flake_at(FlakeField::leaf_flake_id(h, k), min, size);
                if fp.contains(inv, flake.uv) {
                    found += 1;
                    if let Some(o) = out.as_deref_mut() {
                        o.push(flake);
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

/// One of the cells [`blend_cells`] reads, chosen with probability its weight by the uniform
/// `u` (stochastic filtering, as for textures in Pharr et al. 2024): the returned coordinates
/// are that cell's centre, which lies outside every blend band, so a count there reads that one
/// cell. Its expectation over u is the blended count, so a renderer that draws u per sample
/// converges to the blended image while a query walks one chain instead of up to four. The
/// x axis takes u, the y axis what is left of it: `u < wx` picks the first x cell, then
/// u / wx (or (u − wx) / (1 − wx)) is uniform again and picks the y cell. WGSL twin:
/// `select_cell` in lit.inc.wgsl.
pub fn select_cell(coords: DVec2, u: f64) -> DVec2 {
    let (ax, ay) = (blend_axis(coords.x), blend_axis(coords.y));
    let pick = |a: [(i64, f64); 2], u: f64| -> (i64, f64) {
        // u < w: the first cell, u rescaled to [0, 1) over its weight; else the second.
        if u < a[0].1 || a[1].1 <= 0.0 {
            (a[0].0, u / a[0].1)
        } else {
            (a[1].0, (u - a[0].1) / a[1].1)
        }
    };
    let (cx, v) = pick(ax, u);
    let (cy, _) = pick(ay, v);
    DVec2::new(cx as f64 + 0.5, cy as f64 + 0.5)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chosen cell is one [`blend_cells`] reads, its centre reads that cell alone (weight
    /// 1), and over 4·10⁵ uniforms each cell is chosen with its weight (within 4.5 standard
    /// errors), at an interior point, near an edge and near a corner.
    #[test]
    fn chosen_cells_follow_the_blend_weights() {
        const DRAWS: u32 = 400_000;
        for coords in [
            DVec2::new(3.5, -2.4),
            DVec2::new(3.03, 7.5),
            DVec2::new(-0.96, 12.02),
        ] {
            let cells = blend_cells(coords);
            let mut hits = [0u32; 4];
            for i in 0..DRAWS {
                let centre = select_cell(coords, (i as f64 + 0.5) / DRAWS as f64);
                let read = blend_cells(centre);
                assert_eq!(read[0].1, 1.0, "{centre}");
                let k = cells
                    .iter()
                    .position(|c| c.0 == read[0].0 && c.1 > 0.0)
                    .unwrap_or_else(|| panic!("{coords}: chose {centre}, not a blended cell"));
                hits[k] += 1;
            }
            for (k, &(_, w)) in cells.iter().enumerate() {
                let f = hits[k] as f64 / DRAWS as f64;
                let se = (w * (1.0 - w) / DRAWS as f64).sqrt();
                assert!(
                    (f - w).abs() <= 4.5 * se + 1e-5,
                    "{coords}: cell {k} chosen {f}, weight {w}"
                );
            }
        }
    }

    /// P(k) of Hypergeometric(n, m, l), from binomial coefficients in f64.
    fn pmf(n: u64, m: u64, l: u64, k: u64) -> f64 {
        let ln_choose = |a: u64, b: u64| -> f64 {
            (0..b).map(|i| ((a - i) as f64 / (b - i) as f64).ln()).sum()
        };
        if k > m || l - k > n - m {
            return 0.0;
        }
        (ln_choose(m, k) + ln_choose(n - m, l - k) - ln_choose(n, l)).exp()
    }

    /// The one-by-one draws give the hypergeometric law: over 2·10⁵ seeds every P(k) within
    /// 4.5 standard errors of the exact pmf, few lit (6 of 40) and few unlit (34 of 40).
    #[test]
    fn exact_splits_follow_the_hypergeometric_law() {
        const SEEDS: u32 = 200_000;
        for (n, m, l) in [
            (40u64, 13u64, 6u64),
            (40, 13, 34),
            (9, 4, 8),
            (1000, 999, 3),
        ] {
            let mut counts = vec![0u32; l as usize + 1];
            for i in 0..SEEDS {
                counts[hypergeometric(n, m, l, pcg3d([i, 7, 11])[0]) as usize] += 1;
            }
            for (k, &c) in counts.iter().enumerate() {
                let p = pmf(n, m, l, k as u64);
                let se = (p * (1.0 - p) / SEEDS as f64).sqrt();
                let f = c as f64 / SEEDS as f64;
                assert!(
                    (f - p).abs() <= 4.5 * se + 1e-9,
                    "({n}, {m}, {l}): P({k}) = {f} against {p}"
                );
            }
        }
    }

    /// Past the exact draws the mean and variance are still the hypergeometric law's
    /// (l m/n and l (m/n)(1 − m/n)(n − l)/(n − 1)), within 4 standard errors of the mean and
    /// 3 % of the variance (2·10⁵ seeds: the variance's own error is 0.3 %; the rest is the
    /// normal approximation's discreteness); and for a fixed seed the count never falls as l
    /// grows through the switch from exact to normal draws (on either side of n/2, where the
    /// draws switch from the lit to the unlit flakes).
    #[test]
    fn large_splits_keep_mean_variance_and_monotonicity() {
        const SEEDS: u32 = 200_000;
        for (n, m, l) in [
            (200u64, 70u64, 20u64),
            (5000, 2600, 400),
            (5000, 2600, 4990),
        ] {
            let (mut s1, mut s2) = (0.0, 0.0);
            for i in 0..SEEDS {
                let k = hypergeometric(n, m, l, pcg3d([i, 3, 5])[0]) as f64;
                (s1, s2) = (s1 + k, s2 + k * k);
            }
            let q = m as f64 / n as f64;
            let mean = l as f64 * q;
            let var = mean * (1.0 - q) * (n - l) as f64 / (n - 1) as f64;
            let got_mean = s1 / SEEDS as f64;
            let got_var = s2 / SEEDS as f64 - got_mean * got_mean;
            assert!(
                (got_mean - mean).abs() <= 4.0 * (var / SEEDS as f64).sqrt(),
                "({n}, {m}, {l}): mean {got_mean} against {mean}"
            );
            assert!(
                (got_var / var - 1.0).abs() <= 0.03,
                "({n}, {m}, {l}): variance {got_var} against {var}"
            );
        }
        // On each side of l = n/2 (the lit or the unlit are drawn; glints' P is far below ½).
        let (n, m) = (60u64, 25u64);
        for i in 0..2000u32 {
            let seed = pcg3d([i, 1, 2])[0];
            for ls in [0..=n / 2, n / 2 + 1..=n] {
                let mut last = None;
                for l in ls {
                    let k = hypergeometric(n, m, l, seed);
                    assert!(last <= Some(k), "seed {seed}: l = {l} gives {k} < {last:?}");
                    last = Some(k);
                }
            }
        }
    }
}
