// The GPU half of `access::Gpu`: rasterizes shadow polygons onto cube maps, one thread
// per polygon, exactly as `raster.rs` does on the CPU (same clipping, same coverage
// rules), in f32 and with a slack that errs on the blocked side: a pixel within SLACK
// (cube-face coordinates, a pixel is 2/N wide) of a shadow is marked.
//
// A draw is 40 words: map index, coverage (0 pixel centres, 1 whole cells), corner count
// (3 to 12), padding, then 12 corners (x, y, z) relative to the viewpoint.
// Map m's pixel (face, i, j) is bit (face·N + j)·N + i of words m·W .. (m + 1)·W.

struct Params {
    n: u32,
    words_per_map: u32,
    count: u32,
    pad: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> draws: array<u32>;
@group(0) @binding(2) var<storage, read_write> maps: array<atomic<u32>>;

const SLACK: f32 = 1e-5;
const DRAW_WORDS: u32 = 40u;

var<private> poly: array<vec3<f32>, 16>;
var<private> poly_len: u32;
var<private> flat: array<vec2<f32>, 16>;

fn set_span(map: u32, face: u32, j: u32, i0: u32, i1: u32) {
    if (i0 > i1) {
        return;
    }
    let n = params.n;
    let start = (face * n + j) * n;
    var k = start + i0;
    let end = start + i1 + 1u;
    let base = map * params.words_per_map;
    loop {
        if (k >= end) {
            break;
        }
        let w = k / 32u;
        let b = k % 32u;
        let len = min(32u - b, end - k);
        var mask = 0xffffffffu;
        if (len < 32u) {
            mask = (1u << len) - 1u;
        }
        atomicOr(&maps[base + w], mask << b);
        k = k + len;
    }
}

fn face_of(x: vec3<f32>) -> u32 {
    let a = abs(x);
    var axis = 0u;
    if (a.x >= a.y && a.x >= a.z) {
        axis = 0u;
    } else if (a.y >= a.z) {
        axis = 1u;
    } else {
        axis = 2u;
    }
    var neg = 0u;
    if (x[axis] < 0.0) {
        neg = 1u;
    }
    return 2u * axis + neg;
}

fn in_frame(face: u32, x: vec3<f32>) -> vec3<f32> {
    let a = face / 2u;
    var s = 1.0;
    if (face % 2u == 1u) {
        s = -1.0;
    }
    return vec3<f32>(x[(a + 1u) % 3u], x[(a + 2u) % 3u], s * x[a]);
}

fn plane(which: u32, x: vec3<f32>) -> f32 {
    switch which {
        case 0u: { return x.z - x.x; }
        case 1u: { return x.z + x.x; }
        case 2u: { return x.z - x.y; }
        default: { return x.z + x.y; }
    }
}

// Sutherland–Hodgman on `poly`: the part where plane(which) ≥ 0.
fn clip(which: u32) {
    var out: array<vec3<f32>, 16>;
    var len = 0u;
    for (var k = 0u; k < poly_len; k = k + 1u) {
        let a = poly[k];
        let b = poly[(k + 1u) % poly_len];
        let fa = plane(which, a);
        let fb = plane(which, b);
        if (fa >= 0.0 && len < 16u) {
            out[len] = a;
            len = len + 1u;
        }
        if ((fa >= 0.0) != (fb >= 0.0) && len < 16u) {
            let t = fa / (fa - fb);
            out[len] = a + t * (b - a);
            len = len + 1u;
        }
    }
    poly = out;
    poly_len = len;
}

fn cell_of(x: f32, h: f32) -> i32 {
    let n = i32(params.n);
    return clamp(i32(floor((x + 1.0) / h)), 0, n - 1);
}

fn raster_convex(map: u32, face: u32, len: u32, cov: u32) {
    let n = i32(params.n);
    let h = 2.0 / f32(params.n);
    var vmin = 1e30;
    var vmax = -1e30;
    for (var k = 0u; k < len; k = k + 1u) {
        vmin = min(vmin, flat[k].y);
        vmax = max(vmax, flat[k].y);
    }
    if (cov == 1u) {
        for (var j = cell_of(vmin - SLACK, h); j <= cell_of(vmax + SLACK, h); j = j + 1) {
            let lo = -1.0 + f32(j) * h - SLACK;
            let hi = -1.0 + f32(j + 1) * h + SLACK;
            var umin = 1e30;
            var umax = -1e30;
            for (var k = 0u; k < len; k = k + 1u) {
                let a = flat[k];
                let b = flat[(k + 1u) % len];
                if (a.y >= lo && a.y <= hi) {
                    umin = min(umin, a.x);
                    umax = max(umax, a.x);
                }
                for (var e = 0u; e < 2u; e = e + 1u) {
                    var border = lo;
                    if (e == 1u) {
                        border = hi;
                    }
                    if ((a.y - border) * (b.y - border) < 0.0) {
                        let t = (border - a.y) / (b.y - a.y);
                        let u = a.x + t * (b.x - a.x);
                        umin = min(umin, u);
                        umax = max(umax, u);
                    }
                }
            }
            if (umin <= umax) {
                set_span(map, face, u32(j), u32(cell_of(umin - SLACK, h)), u32(cell_of(umax + SLACK, h)));
            }
        }
    } else {
        let j0 = max(i32(ceil((vmin - SLACK + 1.0) / h - 0.5)), 0);
        let j1 = min(i32(floor((vmax + SLACK + 1.0) / h - 0.5)), n - 1);
        for (var j = j0; j <= j1; j = j + 1) {
            let v = clamp(-1.0 + (f32(j) + 0.5) * h, vmin, vmax);
            var umin = 1e30;
            var umax = -1e30;
            for (var k = 0u; k < len; k = k + 1u) {
                let a = flat[k];
                let b = flat[(k + 1u) % len];
                if ((a.y <= v && v <= b.y) || (b.y <= v && v <= a.y)) {
                    if (a.y == b.y) {
                        umin = min(umin, min(a.x, b.x));
                        umax = max(umax, max(a.x, b.x));
                    } else {
                        let u = a.x + (v - a.y) / (b.y - a.y) * (b.x - a.x);
                        umin = min(umin, u);
                        umax = max(umax, u);
                    }
                }
            }
            if (umin > umax) {
                continue;
            }
            let i0 = i32(ceil((umin - SLACK + 1.0) / h - 0.5));
            let i1 = i32(floor((umax + SLACK + 1.0) / h - 0.5));
            if (i0 <= i1 && i1 >= 0 && i0 < n) {
                set_span(map, face, u32(j), u32(clamp(i0, 0, n - 1)), u32(clamp(i1, 0, n - 1)));
            }
        }
    }
}

@compute @workgroup_size(64)
fn main(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let id = (wg.y * groups.x + wg.x) * 64u + local;
    if (id >= params.count) {
        return;
    }
    let at = id * DRAW_WORDS;
    let map = draws[at];
    let cov = draws[at + 1u];
    let len = min(draws[at + 2u], 12u);
    var q: array<vec3<f32>, 12>;
    var scale = 0.0;
    for (var k = 0u; k < len; k = k + 1u) {
        let o = at + 4u + 3u * k;
        q[k] = vec3<f32>(bitcast<f32>(draws[o]), bitcast<f32>(draws[o + 1u]), bitcast<f32>(draws[o + 2u]));
        scale = max(scale, length(q[k]));
    }
    // Fast path: every corner inside one face's pyramid.
    let f0 = face_of(q[0]);
    var same = true;
    for (var k = 1u; k < len; k = k + 1u) {
        if (face_of(q[k]) != f0) {
            same = false;
        }
    }
    if (same) {
        var ok = true;
        for (var k = 0u; k < len; k = k + 1u) {
            let x = in_frame(f0, q[k]);
            if (x.z <= 0.0) {
                ok = false;
                break;
            }
            flat[k] = vec2<f32>(x.x / x.z, x.y / x.z);
        }
        if (ok) {
            raster_convex(map, f0, len, cov);
            return;
        }
    }
    for (var face = 0u; face < 6u; face = face + 1u) {
        poly_len = len;
        var out0 = true;
        var out1 = true;
        var out2 = true;
        var out3 = true;
        for (var k = 0u; k < len; k = k + 1u) {
            let x = in_frame(face, q[k]);
            poly[k] = x;
            out0 = out0 && x.z < x.x;
            out1 = out1 && x.z < -x.x;
            out2 = out2 && x.z < x.y;
            out3 = out3 && x.z < -x.y;
        }
        if (out0 || out1 || out2 || out3) {
            continue;
        }
        clip(0u);
        clip(1u);
        clip(2u);
        clip(3u);
        if (poly_len == 0u) {
            continue;
        }
        var through = false;
        for (var k = 0u; k < poly_len; k = k + 1u) {
            if (poly[k].z <= 1e-6 * max(scale, 1e-30)) {
                through = true;
            }
        }
        if (through) {
            // The polygon passes through the viewpoint: it blocks the whole face.
            for (var j = 0u; j < params.n; j = j + 1u) {
                set_span(map, face, j, 0u, params.n - 1u);
            }
            continue;
        }
        for (var k = 0u; k < poly_len; k = k + 1u) {
            flat[k] = vec2<f32>(poly[k].x / poly[k].z, poly[k].y / poly[k].z);
        }
        raster_convex(map, face, poly_len, cov);
    }
}
