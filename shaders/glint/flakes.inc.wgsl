// Include-only. The flake field and its counting (Rust twin: facet_glint::flakes): the
// quadtree walk with keyed binomial splits, leaf flakes from TEA, λ keyed on flake and cell.
// Needs `field: Field` declared by the includer, and glint/tea.inc.wgsl.

const PI_F: f32 = 3.14159265358979;
const STACK: u32 = 80u;

// Set from Rust (facet_glint::flakes), written once there.
override LEAF_FLAKES: u32;
override MAX_DEPTH: u32;
override BINOMIAL_EXACT_MAX: u32;

// Rust: facet_glint::gpu::GlintField.
struct Field {
    density: f32,
    seed: u32,
    root_count: u32,
    filtered: u32,
    threshold: f32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

// Rust: facet_glint::gpu::GlintQuery.
struct Query {
    center: vec2<f32>,
    a: vec2<f32>,
    b: vec2<f32>,
    p: f32,
    cell_x: u32,
    cell_y: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}


// Acklam's normal quantile (Rust twin: facet_glint::flakes::normal_quantile).
fn normal_quantile(u: f32) -> f32 {
    let p = clamp(u, 1e-7, 1.0 - 1e-7);
    if (p < 0.02425 || p > 1.0 - 0.02425) {
        let q = sqrt(-2.0 * log(min(p, 1.0 - p)));
        let x = (((((-7.784894002430293e-3 * q - 3.223964580411365e-1) * q - 2.400758277161838) * q - 2.549732539343734) * q + 4.374664141464968) * q + 2.938163982698783)
            / ((((7.784695709041462e-3 * q + 3.224671290700398e-1) * q + 2.445134137142996) * q + 3.754408661907416) * q + 1.0);
        return select(-x, x, p < 0.5);
    }
    let q = p - 0.5;
    let r = q * q;
    return (((((-3.969683028665376e1 * r + 2.209460984245205e2) * r - 2.759285104469687e2) * r + 1.383577518672690e2) * r - 3.066479806614716e1) * r + 2.506628277459239) * q
        / (((((-5.447609879822406e1 * r + 1.615858368580409e2) * r - 1.556989798598866e2) * r + 6.680131188771972e1) * r - 1.328068155288572e1) * r + 1.0);
}

// Inverse CDF of Binomial(n, ½) at u.
fn binomial(n: u32, u: f32) -> u32 {
    if (n == 0u) {
        return 0u;
    }
    if (n > BINOMIAL_EXACT_MAX) {
        let x = f32(n) / 2.0 + sqrt(f32(n)) / 2.0 * normal_quantile(u) + 0.5;
        return min(u32(max(x, 0.0)), n);
    }
    var k = 0u;
    var p = exp2(-f32(n));
    var cdf = p;
    while (cdf < u && k < n) {
        p *= f32(n - k) / f32(k + 1u);
        k += 1u;
        cdf += p;
    }
    return k;
}

fn node_hash(level: u32, ix: u32, iy: u32) -> vec2<u32> {
    return tea(ix | (level << 21u), iy ^ (field.seed * 0x9e3779b9u));
}

struct Node {
    level: u32,
    ix: u32,
    iy: u32,
    n: u32,
}

var<private> stack: array<Node, STACK>;

fn count_in(q: Query, center: vec2<f32>, inv: mat2x2<f32>, ext: vec2<f32>, cell: vec2<u32>) -> u32 {
    var top = 0u;
    stack[0] = Node(0u, 0u, 0u, field.root_count);
    top = 1u;
    var lit = 0u;
    while (top > 0u) {
        top -= 1u;
        let nd = stack[top];
        if (nd.n == 0u) {
            continue;
        }
        let size = 1.0 / f32(1u << nd.level);
        let lo = vec2<f32>(f32(nd.ix), f32(nd.iy)) * size;
        let hi = lo + size;
        if (hi.x < center.x - ext.x || lo.x > center.x + ext.x || hi.y < center.y - ext.y || lo.y > center.y + ext.y) {
            continue;
        }
        let h = node_hash(nd.level, nd.ix, nd.iy);
        if (nd.n <= LEAF_FLAKES || nd.level == MAX_DEPTH) {
            for (var k = 0u; k < nd.n; k++) {
                let id = tea(h.x ^ (k * 0x85ebca6bu), h.y ^ k);
                let uv = lo + size * vec2<f32>(tea_unit(id.x, 1u), tea_unit(id.x, 2u));
                let st = inv * (uv - center);
                if (dot(st, st) <= 1.0) {
                    let lambda = tea_unit(id.x ^ cell.x, id.y ^ cell.y);
                    if (lambda < q.p) {
                        lit += 1u;
                    }
                }
            }
            continue;
        }
        let u0 = tea_unit(h.x, 0u ^ h.y);
        let u1 = tea_unit(h.x, 1u ^ h.y);
        let u2 = tea_unit(h.x, 2u ^ h.y);
        let left = binomial(nd.n, u0);
        let l0 = binomial(left, u1);
        let r0 = binomial(nd.n - left, u2);
        let c = array<u32, 4>(l0, r0, left - l0, nd.n - left - r0);
        for (var k = 0u; k < 4u; k++) {
            if (top < STACK) {
                stack[top] = Node(nd.level + 1u, 2u * nd.ix + (k & 1u), 2u * nd.iy + (k >> 1u), c[k]);
                top += 1u;
            }
        }
    }
    return lit;
}


// Lit flakes in the footprint (all copies on the torus) for threshold p and cell key.
fn count_footprint(q: Query, cell: vec2<u32>) -> u32 {
    let m = mat2x2<f32>(q.a, q.b);
    let det = m[0].x * m[1].y - m[1].x * m[0].y;
    let inv = mat2x2<f32>(vec2<f32>(m[1].y, -m[0].y) / det, vec2<f32>(-m[1].x, m[0].x) / det);
    let ext = vec2<f32>(length(vec2<f32>(q.a.x, q.b.x)), length(vec2<f32>(q.a.y, q.b.y)));
    let lo = floor(q.center - ext);
    let hi = floor(q.center + ext);
    var lit = 0u;
    for (var sx = i32(lo.x); sx <= i32(hi.x); sx++) {
        for (var sy = i32(lo.y); sy <= i32(hi.y); sy++) {
            lit += count_in(q, q.center - vec2<f32>(f32(sx), f32(sy)), inv, ext, cell);
        }
    }
    return lit;
}

// Footprint area π |det [a b]|.
fn footprint_area(q: Query) -> f32 {
    return PI_F * abs(q.a.x * q.b.y - q.a.y * q.b.x);
}
