// The GLT's light choice over a guiding snapshot, one invocation per query.
//
// This is guiding's `src/snapshot/sampling.rs` line for line, and the
// importance lanes of `src/cut/child_weights.rs` (gathered as
// `src/snapshot/importance.rs` gathers them) one lane at a time (read
// those for the why of each step); the snapshot's arrays sit end to end in one word buffer
// (`snap`), at the word offsets its first sixteen words give
// (`gpu/src/pack.rs`). Non-finite values are tested on their bits: WGSL
// lets a compiler assume floats are finite, and the snapshot stores NaN
// for a dark node's split.

struct Query {
    px: f32, py: f32, pz: f32,
    // The uniform number (sample) ...
    u: f32,
    // ... the normal (all zero: none) ...
    nx: f32, ny: f32, nz: f32,
    // ... and the light whose pmf is asked (pmf).
    light: u32,
}

struct Answer {
    // Emitter e: e; unbounded light i: 0x80000000 | i; nothing: 0xffffffff.
    light: u32,
    pmf: f32,
    visibility: f32,
    pad: u32,
}

@group(0) @binding(0) var<storage, read> snap: array<u32>;
@group(0) @binding(1) var<storage, read> queries: array<Query>;
@group(0) @binding(2) var<storage, read_write> answers: array<Answer>;

// Word offsets of the arrays, stored in the first words of `snap`.
const SPATIAL: u32 = 0u;
const CELLS: u32 = 1u;
const CUT_NODES: u32 = 2u;
const FRACTIONS: u32 = 3u;
const VISIBILITY: u32 = 4u;
const TREE: u32 = 5u;
const FIRST_RIGHT: u32 = 6u;
const BOUNDS: u32 = 7u;
const LEAF_POSITION: u32 = 8u;
const HEADER: u32 = 9u;

const LEAF: u32 = 0x80000000u;
const NO_EMITTER: u32 = 0xffffffffu;
const NOTHING: u32 = 0xffffffffu;
const BELOW_IMPORTANCE: u32 = 1u;
const PRIOR_IMPORTANCE: u32 = 2u;
const GRANDCHILDREN: u32 = 4u;
const MODULATED: u32 = 1u;
const PRIOR: u32 = 2u;
const OMNI: u32 = 1u;
const TWO_SIDED: u32 = 2u;
const COS_SLACK: f32 = 1e-4;
const BACK: f32 = 1e-3;
// The largest f32 below one.
const ONE_MINUS_EPS: f32 = 0.99999994;
const INFINITY_BITS: u32 = 0x7f800000u;

fn word(array: u32, i: u32) -> u32 {
    return snap[snap[array] + i];
}

fn float(array: u32, i: u32) -> f32 {
    return bitcast<f32>(word(array, i));
}

fn header(i: u32) -> u32 {
    return word(HEADER, i);
}

fn is_finite(x: f32) -> bool {
    return (bitcast<u32>(x) & INFINITY_BITS) != INFINITY_BITS;
}

fn is_nan(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7fffffffu) > INFINITY_BITS;
}

// ---------------------------------------------------------------------------
// Importance, one lane of src/cut/child_weights.rs at a time
// ---------------------------------------------------------------------------

fn from_bf16(b: u32) -> f32 {
    return bitcast<f32>(b << 16u);
}

// The signed 16-bit code in the low (`high` false) or high half of `w`,
// as `code / 32767`.
fn decode(w: u32, high: bool) -> f32 {
    var bits = w << 16u;
    if high {
        bits = w & 0xffff0000u;
    }
    return f32(bitcast<i32>(bits) >> 16u) * (1.0 / 32767.0);
}

fn sin_of(c: f32) -> f32 {
    return sqrt(max(1.0 - c * c, 0.0));
}

fn cos_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        return 1.0;
    }
    return cos_a * cos_b + sin_a * sin_b;
}

fn sin_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        return 0.0;
    }
    return sin_a * cos_b - cos_a * sin_b;
}

struct Point {
    p: vec3<f32>,
    n: vec3<f32>,
    has_normal: bool,
}

// The importance of the bounds record at word `at` of the bounds array as
// (numerator, squared distance).
fn importance(q: Point, at: u32) -> vec2<f32> {
    let power = float(BOUNDS, at + 7u);
    if !(power > 0.0) {
        return vec2<f32>(0.0, 1.0);
    }
    let c = vec3<f32>(float(BOUNDS, at), float(BOUNDS, at + 1u), float(BOUNDS, at + 2u));
    let to_p = vec3<f32>(q.p.x - c.x, q.p.y - c.y, q.p.z - c.z);
    let dist2 = to_p.x * to_p.x + to_p.y * to_p.y + to_p.z * to_p.z;
    let r2 = float(BOUNDS, at + 3u);
    if dist2 <= r2 {
        return vec2<f32>(power, r2);
    }
    if !is_finite(dist2) {
        return vec2<f32>(0.0, 1.0);
    }
    let inv = 1.0 / sqrt(dist2);
    let wi = vec3<f32>(to_p.x * inv, to_p.y * inv, to_p.z * inv);
    let sin2_b = r2 / dist2;
    let sin_b = sqrt(sin2_b);
    let cos_b = sqrt(max(1.0 - sin2_b, 0.0));
    let w_axis01 = word(BOUNDS, at + 4u);
    let w_axis2 = word(BOUNDS, at + 5u);
    let w_cones = word(BOUNDS, at + 6u);
    let flags = w_axis2 >> 16u;
    var cos_thetap = 1.0;
    if (flags & OMNI) == 0u {
        let axis = vec3<f32>(decode(w_axis01, false), decode(w_axis01, true), decode(w_axis2, false));
        var cos_w = clamp(axis.x * wi.x + axis.y * wi.y + axis.z * wi.z, -1.0, 1.0);
        if (flags & TWO_SIDED) != 0u {
            cos_w = abs(cos_w);
        }
        let x = from_bf16(w_cones & 0xffffu);
        let cos_o = 1.0 - x;
        let sin_o = sqrt(max(x * (2.0 - x), 0.0));
        let sin_w = sin_of(cos_w);
        let cos_x = cos_sub_clamped(sin_w, cos_w, sin_o, cos_o);
        let sin_x = sin_sub_clamped(sin_w, cos_w, sin_o, cos_o);
        cos_thetap = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
    }
    let reaches = cos_thetap >= 1.0 - from_bf16(w_cones >> 16u) - COS_SLACK;
    if !reaches {
        return vec2<f32>(0.0, 1.0);
    }
    var a = power * max(cos_thetap, BACK);
    if q.has_normal {
        let cos_i = min(abs(wi.x * q.n.x + wi.y * q.n.y + wi.z * q.n.z), 1.0);
        a *= max(cos_sub_clamped(sin_of(cos_i), cos_i, sin_b, cos_b), 0.0);
    }
    return vec2<f32>(a, dist2);
}

// Four lanes' numerators `a` and squared distances `d` brought to one
// scale: the smallest squared distance among the lanes that contribute.
fn scaled(a: vec4<f32>, d: vec4<f32>) -> vec4<f32> {
    var m = 3.40282347e+38;
    for (var i = 0u; i < 4u; i++) {
        if a[i] > 0.0 {
            m = min(m, d[i]);
        }
    }
    var w = vec4<f32>(0.0);
    for (var i = 0u; i < 4u; i++) {
        if d[i] <= m {
            w[i] = a[i];
        } else {
            w[i] = a[i] * (m / d[i]);
        }
    }
    return w;
}

// The weights of the two children of the node whose children are pair
// `k`, that node at depth `depth` (src/cut/child_weights.rs): at even
// depth each child by its two children's importances (a leaf child by
// its own), at odd depth by its own.
fn child_weights(q: Point, k: u32, depth: u32) -> vec2<f32> {
    if (depth & 1u) == 1u {
        let l = importance(q, k * 16u);
        let r = importance(q, k * 16u + 8u);
        let w = scaled(vec4<f32>(l.x, r.x, 0.0, 0.0), vec4<f32>(l.y, r.y, 1.0, 1.0));
        return vec2<f32>(w.x, w.y);
    }
    var a = vec4<f32>(0.0);
    var d = vec4<f32>(1.0);
    for (var s = 0u; s < 2u; s++) {
        let link = word(TREE, k * 4u + 2u * s + 1u);
        var x = vec2<f32>(0.0, 1.0);
        var y = vec2<f32>(0.0, 1.0);
        if (link & LEAF) == 0u {
            x = importance(q, link * 16u);
            y = importance(q, link * 16u + 8u);
        } else {
            x = importance(q, k * 16u + 8u * s);
        }
        a[2u * s] = x.x;
        d[2u * s] = x.y;
        a[2u * s + 1u] = y.x;
        d[2u * s + 1u] = y.y;
    }
    let w = scaled(a, d);
    return vec2<f32>(w.x + w.y, w.z + w.w);
}

// ---------------------------------------------------------------------------
// The sampling rule (src/snapshot/sampling.rs)
// ---------------------------------------------------------------------------

// A pair of probabilities, or none (`ok` false).
struct Pair {
    p: vec2<f32>,
    ok: bool,
}

fn probabilities(left: f32, right: f32) -> Pair {
    let total = left + right;
    if !(total > 0.0 && is_finite(total) && left >= 0.0 && right >= 0.0) {
        return Pair(vec2<f32>(0.0), false);
    }
    return Pair(vec2<f32>(left / total, right / total), true);
}

fn decode_split(s: f32) -> Pair {
    if is_nan(s) {
        return Pair(vec2<f32>(0.0), false);
    }
    let small = abs(s);
    let large = 1.0 - small;
    if (bitcast<u32>(s) >> 31u) != 0u {
        return Pair(vec2<f32>(large, small), true);
    }
    return Pair(vec2<f32>(small, large), true);
}

// One query's fixed parts.
struct Rule {
    q: Point,
    cell: u32,
    below_importance: bool,
    prior_importance: bool,
    grandchildren: bool,
    modulate: bool,
    prior: bool,
}

fn cell_word(r: Rule, field: u32) -> u32 {
    return word(CELLS, r.cell * 12u + field);
}

fn cell_float(r: Rule, field: u32) -> f32 {
    return float(CELLS, r.cell * 12u + field);
}

fn locate(p_in: vec3<f32>) -> u32 {
    var lo = vec3<f32>(bitcast<f32>(header(4u)), bitcast<f32>(header(5u)), bitcast<f32>(header(6u)));
    var hi = vec3<f32>(bitcast<f32>(header(8u)), bitcast<f32>(header(9u)), bitcast<f32>(header(10u)));
    let p = vec3<f32>(
        min(max(p_in.x, lo.x), hi.x),
        min(max(p_in.y, lo.y), hi.y),
        min(max(p_in.z, lo.z), hi.z),
    );
    var node = 0u;
    var axis = 0u;
    loop {
        let w = word(SPATIAL, node);
        if (w & LEAF) != 0u {
            return w & ~LEAF;
        }
        let mid = lo[axis] * 0.5 + hi[axis] * 0.5;
        if p[axis] < mid {
            hi[axis] = mid;
            node = w;
        } else {
            lo[axis] = mid;
            node = w + 1u;
        }
        axis = select(axis + 1u, 0u, axis == 2u);
    }
    // Not reached (every walk ends at a leaf); WGSL wants a return here.
    return 0u;
}

fn rule(query: Query) -> Rule {
    var q: Point;
    q.p = vec3<f32>(query.px, query.py, query.pz);
    let n = vec3<f32>(query.nx, query.ny, query.nz);
    let len2 = n.x * n.x + n.y * n.y + n.z * n.z;
    q.has_normal = false;
    q.n = vec3<f32>(0.0);
    if len2 > 0.0 && is_finite(len2) {
        let rcp = 1.0 / sqrt(len2);
        q.has_normal = is_finite(rcp) && rcp > 0.0;
        q.n = vec3<f32>(n.x * rcp, n.y * rcp, n.z * rcp);
    }
    var r: Rule;
    r.q = q;
    r.cell = locate(q.p);
    let flags = header(2u);
    let cell_flags = cell_word(r, 3u);
    r.below_importance = (flags & BELOW_IMPORTANCE) != 0u;
    r.prior_importance = (flags & PRIOR_IMPORTANCE) != 0u;
    r.grandchildren = (flags & GRANDCHILDREN) != 0u;
    r.modulate = (cell_flags & MODULATED) != 0u;
    r.prior = (cell_flags & PRIOR) != 0u;
    return r;
}

// The probabilities of both components at one inner node, and the cut
// node on each side (NOTHING where the cut ends).
struct Step {
    cut: Pair,
    prior: Pair,
    next: vec2<u32>,
}

// The step at the inner entry with split `split` and children pair `k`,
// inside the cut at cut node `cut` (NOTHING: below the cut).
fn step(r: Rule, split: f32, k: u32, cut: u32, depth: u32) -> Step {
    let power = decode_split(split);
    var needs_importance = r.prior_importance;
    if cut != NOTHING {
        needs_importance = needs_importance || r.modulate;
    } else {
        needs_importance = needs_importance || r.below_importance;
    }
    var has_imp = false;
    var imp = vec2<f32>(0.0);
    // The bounds array is empty when no rule reads importance.
    if needs_importance && snap[BOUNDS] != snap[LEAF_POSITION] {
        // Without the grandchildren's bound every level weighs as an odd
        // one does.
        imp = child_weights(r.q, k, select(1u, depth, r.grandchildren));
        has_imp = true;
    }
    var by_importance = power;
    if has_imp {
        let p = probabilities(imp.x, imp.y);
        if p.ok {
            by_importance = p;
        }
    }
    var s: Step;
    s.prior = Pair(vec2<f32>(0.0), false);
    if r.prior {
        s.prior = power;
        if r.prior_importance {
            s.prior = by_importance;
        }
    }
    if cut != NOTHING {
        let at = (cell_word(r, 0u) + cut) * 3u;
        let p = float(CUT_NODES, at);
        let learned = Pair(vec2<f32>(p, 1.0 - p), true);
        s.cut = learned;
        if has_imp && r.modulate {
            let m = probabilities(p * imp.x, (1.0 - p) * imp.y);
            if m.ok {
                s.cut = m;
            }
        }
        let slots = vec2<u32>(word(CUT_NODES, at + 1u), word(CUT_NODES, at + 2u));
        s.next = vec2<u32>(
            select(slots.x, NOTHING, (slots.x & LEAF) != 0u),
            select(slots.y, NOTHING, (slots.y & LEAF) != 0u),
        );
    } else {
        s.cut = power;
        if r.below_importance {
            s.cut = by_importance;
        }
        s.next = vec2<u32>(NOTHING, NOTHING);
    }
    return s;
}

// Multiplies the probabilities of `side` into the products.
fn apply(r: Rule, p: vec2<f32>, s: Step, side: u32) -> vec2<f32> {
    var out = p;
    out.x = select(0.0, p.x * s.cut.p[side], s.cut.ok);
    if r.prior {
        out.y = select(0.0, p.y * s.prior.p[side], s.prior.ok);
    }
    return out;
}

fn emitter_pmf(r: Rule, p: vec2<f32>) -> f32 {
    return cell_float(r, 7u) * p.x + cell_float(r, 8u) * p.y;
}

fn unbounded_pmf(r: Rule, i: u32) -> f32 {
    let k = header(3u);
    if i >= k {
        return 0.0;
    }
    let f = float(FRACTIONS, r.cell * k + i);
    return cell_float(r, 5u) * max(f, 0.0) + cell_float(r, 6u);
}

fn visibility(r: Rule, slot: u32) -> f32 {
    if header(15u) == 0u {
        return 1.0;
    }
    return float(VISIBILITY, cell_word(r, 2u) + slot);
}

fn positive(pmf: f32) -> f32 {
    if pmf > 0.0 && is_finite(pmf) {
        return pmf;
    }
    return 0.0;
}

fn nothing() -> Answer {
    return Answer(NOTHING, 0.0, 0.0, 0u);
}

fn finish(light: u32, pmf_in: f32, vis: f32) -> Answer {
    let pmf = positive(pmf_in);
    if pmf > 0.0 {
        return Answer(light, pmf, vis, 0u);
    }
    return nothing();
}

// The one-number descent: chooses a side of `pair` with `u`, rescales `u`.
struct Choice {
    side: u32,
    u: f32,
}

fn choose(u: f32, pair: vec2<f32>) -> Choice {
    if u < pair.x {
        return Choice(0u, min(u / pair.x, ONE_MINUS_EPS));
    }
    var v = 0.0;
    if pair.y > 0.0 {
        v = clamp((u - pair.x) / pair.y, 0.0, ONE_MINUS_EPS);
    }
    return Choice(1u, v);
}

fn position_is_finite(q: Query) -> bool {
    return is_finite(q.px) && is_finite(q.py) && is_finite(q.pz);
}

fn sample(query: Query) -> Answer {
    if !position_is_finite(query) {
        return nothing();
    }
    let r = rule(query);
    var u = 0.0;
    if query.u >= 0.0 {
        u = min(query.u, ONE_MINUS_EPS);
    }
    let c_unbounded = cell_float(r, 4u);
    let c_cut = cell_float(r, 7u);
    let c_prior = cell_float(r, 8u);
    let nodes = cell_word(r, 1u);
    if c_unbounded > 0.0 {
        let split = probabilities(c_unbounded, c_cut + c_prior);
        if !split.ok {
            return nothing();
        }
        let first = choose(u, split.p);
        u = first.u;
        if first.side == 0u {
            let k = header(3u);
            for (var i = 0u; i < k; i++) {
                var rest = 0.0;
                for (var j = i + 1u; j < k; j++) {
                    rest += unbounded_pmf(r, j);
                }
                let pair = probabilities(unbounded_pmf(r, i), rest);
                if !pair.ok {
                    return nothing();
                }
                let c = choose(u, pair.p);
                u = c.u;
                if c.side == 0u {
                    let slot = max(2u * nodes, 1u) + i;
                    return finish(LEAF | i, unbounded_pmf(r, i), visibility(r, slot));
                }
            }
            return nothing();
        }
    }
    var use_cut = true;
    if c_cut > 0.0 && r.prior {
        let pair = probabilities(c_cut, c_prior);
        if !pair.ok {
            return nothing();
        }
        let c = choose(u, pair.p);
        u = c.u;
        use_cut = c.side == 0u;
    } else if !(c_cut > 0.0) {
        if !r.prior {
            return nothing();
        }
        use_cut = false;
    }
    if header(13u) == 0u {
        return nothing();
    }
    var split = float(TREE, 0u);
    var link = word(TREE, 1u);
    var cut = select(NOTHING, 0u, nodes > 0u);
    var p = vec2<f32>(1.0, 1.0);
    var slot = 0u;
    var depth = 0u;
    while (link & LEAF) == 0u {
        let k = link;
        let s = step(r, split, k, cut, depth);
        depth += 1u;
        var pair = s.prior;
        if use_cut {
            pair = s.cut;
        }
        if !pair.ok {
            return nothing();
        }
        let c = choose(u, pair.p);
        u = c.u;
        p = apply(r, p, s, c.side);
        if cut != NOTHING {
            let next = s.next[c.side];
            if next == NOTHING {
                slot = 2u * cut + c.side;
            }
            cut = next;
        }
        split = float(TREE, k * 4u + 2u * c.side);
        link = word(TREE, k * 4u + 2u * c.side + 1u);
    }
    if link == NO_EMITTER {
        return nothing();
    }
    return finish(link & ~LEAF, emitter_pmf(r, p), visibility(r, slot));
}

fn pmf(query: Query) -> f32 {
    if !position_is_finite(query) {
        return 0.0;
    }
    let r = rule(query);
    let light = query.light;
    if (light & LEAF) != 0u {
        return positive(unbounded_pmf(r, light & ~LEAF));
    }
    if light >= header(14u) {
        return 0.0;
    }
    let position = word(LEAF_POSITION, light);
    if cell_float(r, 7u) <= 0.0 && !r.prior {
        return 0.0;
    }
    if header(13u) == 0u {
        return 0.0;
    }
    var split = float(TREE, 0u);
    var link = word(TREE, 1u);
    var cut = select(NOTHING, 0u, cell_word(r, 1u) > 0u);
    var p = vec2<f32>(1.0, 1.0);
    var depth = 0u;
    while (link & LEAF) == 0u {
        let k = link;
        let s = step(r, split, k, cut, depth);
        depth += 1u;
        let side = select(0u, 1u, position >= word(FIRST_RIGHT, k));
        p = apply(r, p, s, side);
        if cut != NOTHING {
            cut = s.next[side];
        }
        split = float(TREE, k * 4u + 2u * side);
        link = word(TREE, k * 4u + 2u * side + 1u);
    }
    if link != (LEAF | light) {
        return 0.0;
    }
    return positive(emitter_pmf(r, p));
}

// Queries are numbered along x, then rows of `num_workgroups.x` groups.
fn query_index(id: vec3<u32>, groups: vec3<u32>) -> u32 {
    return id.x + id.y * groups.x * 64u;
}

@compute @workgroup_size(64)
fn sample_main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = query_index(id, groups);
    if i >= arrayLength(&queries) {
        return;
    }
    answers[i] = sample(queries[i]);
}

@compute @workgroup_size(64)
fn pmf_main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = query_index(id, groups);
    if i >= arrayLength(&queries) {
        return;
    }
    answers[i] = Answer(queries[i].light, pmf(queries[i]), 1.0, 0u);
}
