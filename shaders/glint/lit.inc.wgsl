// Include-only. Lit counts per node (Rust twin: facet_glint::lit): the root's lit count from
// Binomial(n, P) at a keyed uniform, split down the quadtree by keyed hypergeometric draws as
// the positions split, a leaf's lit flakes a run of its flakes from a keyed start; a node inside the
// footprint adds its lit count, only boundary nodes descend. One walk serves the two queries of
// a shading point (light sample and BSDF sample), each blended over up to four direction cells:
// up to eight chains of lit counts share the positions' splits.
// Needs glint/tea.inc.wgsl, glint/flakes.inc.wgsl (with `field: Field`) and the walk's width:
// glint/chains8.inc.wgsl (every query blends its cells) or glint/chains2.inc.wgsl (each query
// reads one cell, select_cell).

// Set from Rust (facet_glint::lit), written once there.
override LIT_EXACT_MEAN: f32;
override SPLIT_EXACT_MAX: u32;
override BLEND_BAND: f32;

// Direction cells a pair of queries reads: 2 queries × 4 cells.
const CELLS: u32 = 8u;
// The walk's stack: a node pops and pushes at most 4 children, so a walk to depth MAX_DEPTH
// holds at most 3 · MAX_DEPTH + 1 nodes (facet_glint::lit::STACK_DEPTH, checked by a test).
const STACK: u32 = 61u;

// ln(1 − p), accurate for small p.
fn ln_1m(p: f32) -> f32 {
    if (p < 0.01) {
        return -p * (1.0 + p * (0.5 + p / 3.0));
    }
    return log(1.0 - p);
}

// Inverse CDF of Binomial(n, p) at u, p ≤ ½ (facet_glint::lit::binomial_p).
fn binomial_low(n: u32, p: f32, u: f32) -> u32 {
    let mean = f32(n) * p;
    if (mean > LIT_EXACT_MEAN) {
        let x = mean + sqrt(mean * (1.0 - p)) * normal_quantile(u) + 0.5;
        return min(u32(max(x, 0.0)), n);
    }
    var pmf = exp(f32(n) * ln_1m(p));
    var cdf = pmf;
    var k = 0u;
    let ratio = p / (1.0 - p);
    while (cdf <= u && k < n) {
        pmf *= f32(n - k) / f32(k + 1u) * ratio;
        k += 1u;
        cdf += pmf;
    }
    return k;
}

fn binomial_p(n: u32, p: f32, u: f32) -> u32 {
    if (n == 0u || p <= 0.0) {
        return 0u;
    }
    if (p >= 1.0) {
        return n;
    }
    if (p > 0.5) {
        return n - binomial_low(n, 1.0 - p, 1.0 - u);
    }
    return binomial_low(n, p, u);
}

// The next state of a split's uniforms (facet_glint::lit::next_state).
fn next_state(s: u32) -> u32 {
    return s * 747796405u + 2891336453u;
}

// A state's 24-bit uniform, PCG's output permutation (facet_glint::lit::state_unit).
fn state_unit(s: u32) -> f32 {
    let w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return unit24((w >> 22u) ^ w);
}

// One draw of the exact split: while draws remain (j < few), the j-th lands in the part with
// probability (the part's flakes left) / (flakes left).
fn split_draw(s: ptr<function, u32>, k: ptr<function, u32>, j: u32, few: u32, n: u32, m: u32) {
    if (j < few) {
        *s = next_state(*s);
        if (state_unit(*s) * f32(n - j) < f32(m - *k)) {
            *k += 1u;
        }
    }
}

// Hypergeometric(n, m, l) at u by the normal approximation, on the smaller part and the fewer
// of lit and unlit (support from 0).
fn hypergeometric_normal(n: u32, m: u32, l: u32, u: f32) -> u32 {
    let flip_l = 2u * l > n;
    let l1 = select(l, n - l, flip_l);
    let flip_m = 2u * m > n;
    let m1 = select(m, n - m, flip_m);
    var k = 0u;
    if (l1 > 0u && m1 > 0u) {
        let q = f32(m1) / f32(n);
        let v = f32(l1) * q * (1.0 - q) * f32(n - l1) / f32(n - 1u);
        let x = f32(l1) * q + sqrt(v) * normal_quantile(u) + 0.5;
        k = min(u32(max(x, 0.0)), min(l1, m1));
    }
    k = select(k, l1 - k, flip_m);
    return select(k, m - k, flip_l);
}

// Lit flakes among the m of n in one part when l of the n are lit (facet_glint::lit::hypergeometric):
// the fewer of lit and unlit drawn one by one up to SPLIT_EXACT_MAX = 8 of them (written out,
// not a loop: llvmpipe caps an invocation's loop iterations), the rest by the normal
// approximation from the flakes left.
fn hypergeometric(n: u32, m: u32, l: u32, seed: u32) -> u32 {
    let flip = l > n - l;
    let few = min(l, n - l);
    var s = seed;
    var k = 0u;
    split_draw(&s, &k, 0u, few, n, m);
    split_draw(&s, &k, 1u, few, n, m);
    split_draw(&s, &k, 2u, few, n, m);
    split_draw(&s, &k, 3u, few, n, m);
    split_draw(&s, &k, 4u, few, n, m);
    split_draw(&s, &k, 5u, few, n, m);
    split_draw(&s, &k, 6u, few, n, m);
    split_draw(&s, &k, 7u, few, n, m);
    if (few > SPLIT_EXACT_MAX) {
        let e = SPLIT_EXACT_MAX;
        k += hypergeometric_normal(n - e, m - k, few - e, unit24(seed));
    }
    return select(k, m - k, flip);
}

// A chain's lit counts of the four children (c: their flake counts), node hash h, of the left
// (x) and right (y) halves that `halves` asks for; a half not asked for is not split and reads 0
// (facet_glint::lit::split_lit splits both: each split has its own keyed seed, so the
// children asked for come out the same).
fn split_lit(h: vec2<u32>, c: vec4<u32>, lit: u32, key: vec2<u32>, halves: vec2<bool>) -> vec4<u32> {
    if (lit == 0u) {
        return vec4<u32>(0u);
    }
    let r = pcg3d(vec3<u32>(h.x ^ key.x, h.y ^ key.y, 0x2545f491u));
    let left = c.x + c.z;
    let n = left + c.y + c.w;
    let lit_left = hypergeometric(n, left, lit, r.x);
    var l = vec4<u32>(0u);
    if (halves.x) {
        let l00 = hypergeometric(left, c.x, lit_left, r.y);
        l.x = l00;
        l.z = lit_left - l00;
    }
    if (halves.y) {
        let l10 = hypergeometric(n - left, c.y, lit - lit_left, r.z);
        l.y = l10;
        l.w = lit - lit_left - l10;
    }
    return l;
}

// The first of a leaf's run of lit flakes (facet_glint::FlakeField::leaf_run_start).
fn leaf_run_start(h: vec2<u32>, n: u32, key: vec2<u32>) -> u32 {
    return pcg3d(vec3<u32>(h.x ^ key.x, h.y ^ key.y, 0x27d4eb2fu)).x % n;
}

struct LitNode {
    level: u32,
    ix: u32,
    iy: u32,
    n: u32,
    lit: array<u32, CHAINS>,
}

var<private> lit_stack: array<LitNode, STACK>;

// Only the first nc chains are live (llvmpipe caps each loop's iterations per invocation, so
// loops run over live chains only).
fn walk_lit(center: vec2<f32>, inv: mat2x2<f32>, ext: vec2<f32>, root: array<u32, CHAINS>, keys_in: array<vec2<u32>, CHAINS>, nc: u32) -> array<u32, CHAINS> {
    var acc: array<u32, CHAINS>;
    var keys = keys_in;
    if (!any_lit(root)) {
        return acc;
    }
    lit_stack[0] = LitNode(0u, 0u, 0u, field.root_count, root);
    var top = 1u;
    while (top > 0u) {
        top -= 1u;
        visit_lit(lit_stack[top], center, inv, ext, &keys, nc, &acc, &top);
    }
    return acc;
}

// One node of the walk: nothing outside the footprint's box; its lit count inside the
// footprint; its lit flakes tested at a leaf; else split, the children the box reaches pushed.
// (No early return: a return inside a loop's inlined call costs a compiler flag tested after
// every block, 10 % of the walk on llvmpipe.)
fn visit_lit(nd: LitNode, center: vec2<f32>, inv: mat2x2<f32>, ext: vec2<f32>, keys: ptr<function, array<vec2<u32>, CHAINS>>, nc: u32, acc: ptr<function, array<u32, CHAINS>>, top: ptr<function, u32>) {
    let size = 1.0 / f32(1u << nd.level);
    let lo = vec2<f32>(f32(nd.ix), f32(nd.iy)) * size;
    let hi = lo + size;
    if (hi.x < center.x - ext.x || lo.x > center.x + ext.x || hi.y < center.y - ext.y || lo.y > center.y + ext.y) {
        // Outside the box.
    } else if (corners_inside(lo, hi, center, inv)) {
        *acc = add_lit(*acc, nd.lit);
    } else if (nd.n <= LEAF_FLAKES || nd.level == MAX_DEPTH) {
        // Each chain's lit flakes: a keyed run of the leaf's (leaf_run_start), only their
        // positions hashed.
        let h = node_hash(nd.level, nd.ix, nd.iy);
        for (var c = 0u; c < nc; c++) {
            if (nd.lit[c] == 0u) {
                continue;
            }
            let start = leaf_run_start(h, nd.n, (*keys)[c]);
            for (var j = 0u; j < nd.lit[c]; j++) {
                var k = start + j;
                k = select(k, k - nd.n, k >= nd.n);
                let st = inv * (flake_uv(leaf_flake_id(h, k), lo, size) - center);
                (*acc)[c] += select(0u, 1u, dot(st, st) <= 1.0);
            }
        }
    } else {
        let h = node_hash(nd.level, nd.ix, nd.iy);
        let cn = split_counts(nd.level, nd.ix, nd.iy, nd.n, h);
        // The halves the footprint's box reaches (left: x below the node's midline).
        let mid = lo + 0.5 * size;
        let halves = vec2<bool>(mid.x >= center.x - ext.x, mid.x <= center.x + ext.x);
        var child: array<array<u32, CHAINS>, 4>;
        for (var c = 0u; c < nc; c++) {
            let l = split_lit(h, cn, nd.lit[c], (*keys)[c], halves);
            child[0][c] = l.x;
            child[1][c] = l.y;
            child[2][c] = l.z;
            child[3][c] = l.w;
        }
        // Children outside the footprint's box are not pushed (the test their pop would make:
        // the child's edges at the node's midlines are exact in f32).
        for (var k = 0u; k < 4u; k++) {
            let inx = select(mid.x >= center.x - ext.x, mid.x <= center.x + ext.x, (k & 1u) == 1u);
            let iny = select(mid.y >= center.y - ext.y, mid.y <= center.y + ext.y, (k >> 1u) == 1u);
            if (cn[k] > 0u && inx && iny && any_lit(child[k]) && *top < STACK) {
                lit_stack[*top] = LitNode(nd.level + 1u, 2u * nd.ix + (k & 1u), 2u * nd.iy + (k >> 1u), cn[k], child[k]);
                *top += 1u;
            }
        }
    }
}

// Whether the node [lo, hi] lies inside the footprint: its four corners within the ellipse.
fn corners_inside(lo: vec2<f32>, hi: vec2<f32>, center: vec2<f32>, inv: mat2x2<f32>) -> bool {
    let s00 = inv * (lo - center);
    let s10 = inv * (vec2<f32>(hi.x, lo.y) - center);
    let s01 = inv * (vec2<f32>(lo.x, hi.y) - center);
    let s11 = inv * (hi - center);
    return max(max(dot(s00, s00), dot(s10, s10)), max(dot(s01, s01), dot(s11, s11))) <= 1.0;
}

// One axis of the blend (facet_glint::lit::blend_axis): (cell, neighbour across the nearer
// edge) offsets from floor(x), and their weights.
fn blend_axis(x: f32) -> vec4<f32> {
    let f = x - floor(x);
    let half = 0.5 * BLEND_BAND;
    if (f < half) {
        return vec4<f32>(0.0, -1.0, 0.5 + f / BLEND_BAND, 0.5 - f / BLEND_BAND);
    }
    if (f > 1.0 - half) {
        let g = 1.0 - f;
        return vec4<f32>(0.0, 1.0, 0.5 + g / BLEND_BAND, 0.5 - g / BLEND_BAND);
    }
    return vec4<f32>(0.0, 1.0, 1.0, 0.0);
}

// The cells coords reads and their weights (facet_glint::lit::blend_cells); without blending,
// the one cell coords is in, weight 1.
fn cell_keys(coords: vec2<f32>, keys: ptr<function, array<vec2<u32>, CELLS>>, weights: ptr<function, array<f32, CELLS>>, first: u32) {
    let base = floor(coords);
    let bx = i32(base.x) + (1 << 24u);
    let by = i32(base.y) + (1 << 24u);
    let ax = blend_axis(coords.x);
    let ay = blend_axis(coords.y);
    for (var k = 0u; k < 4u; k++) {
        let i = k & 1u;
        let j = k >> 1u;
        (*keys)[first + k] = tea(u32(bx + i32(ax[i])), u32(by + i32(ay[j])));
        (*weights)[first + k] = select(select(0.0, 1.0, k == 0u), ax[2u + i] * ay[2u + j], field.blend != 0u);
    }
}

// One of the cells cell_keys reads, chosen with probability its weight by u: the x axis takes
// u, the y axis what is left of it rescaled; the result is the cell's centre, which lies
// outside every blend band and so reads that cell alone (facet_glint::lit::select_cell).
fn select_cell(coords: vec2<f32>, u: f32) -> vec2<f32> {
    let ax = blend_axis(coords.x);
    let ay = blend_axis(coords.y);
    let first_x = u < ax[2] || ax[3] <= 0.0;
    let v = select((u - ax[2]) / ax[3], u / ax[2], first_x);
    let first_y = v < ay[2] || ay[3] <= 0.0;
    return floor(coords) + vec2<f32>(select(ax[1], ax[0], first_x), select(ay[1], ay[0], first_y)) + 0.5;
}

// The counts of the two queries over the footprint (all its copies on the torus): blended lit
// counts, or N a P where the filter takes over; a query with p = 0 counts 0.
fn count_pair(q: Query) -> vec2<f32> {
    let area = footprint_area(q.a, q.b);
    let expected = field.density * area * q.p;
    let filt = vec2<bool>(field.filtered != 0u) & (expected > vec2<f32>(field.threshold));
    var cell_key: array<vec2<u32>, CELLS>;
    var cell_weight: array<f32, CELLS>;
    cell_keys(q.coords0, &cell_key, &cell_weight, 0u);
    cell_keys(q.coords1, &cell_key, &cell_weight, 4u);
    // The live chains, compacted: key, weight, query, root lit count (a walk of width 2 is
    // included only where each query reads one cell).
    var keys: array<vec2<u32>, CHAINS>;
    var weights: array<f32, CHAINS>;
    var query: array<u32, CHAINS>;
    var root: array<u32, CHAINS>;
    var nc = 0u;
    for (var c = 0u; c < CELLS; c++) {
        let j = c / 4u;
        if (cell_weight[c] > 0.0 && q.p[j] > 0.0 && !filt[j] && nc < CHAINS) {
            let r = pcg3d(vec3<u32>(cell_key[c].x, cell_key[c].y, 0xffffffffu));
            keys[nc] = cell_key[c];
            weights[nc] = cell_weight[c];
            query[nc] = j;
            root[nc] = binomial_p(field.root_count, q.p[j], unit24(r.x));
            nc += 1u;
        }
    }
    let m = mat2x2<f32>(q.a, q.b);
    let det = m[0].x * m[1].y - m[1].x * m[0].y;
    let inv = mat2x2<f32>(vec2<f32>(m[1].y, -m[0].y) / det, vec2<f32>(-m[1].x, m[0].x) / det);
    let ext = vec2<f32>(length(vec2<f32>(q.a.x, q.b.x)), length(vec2<f32>(q.a.y, q.b.y)));
    let lo = floor(q.center - ext);
    let hi = floor(q.center + ext);
    var total: array<u32, CHAINS>;
    for (var sx = i32(lo.x); sx <= i32(hi.x); sx++) {
        for (var sy = i32(lo.y); sy <= i32(hi.y); sy++) {
            var acc = walk_lit(q.center - vec2<f32>(f32(sx), f32(sy)), inv, ext, root, keys, nc);
            for (var c = 0u; c < nc; c++) {
                total[c] += acc[c];
            }
        }
    }
    var out = select(vec2<f32>(0.0), expected, filt);
    for (var c = 0u; c < nc; c++) {
        out[query[c]] += weights[c] * f32(total[c]);
    }
    return out;
}
