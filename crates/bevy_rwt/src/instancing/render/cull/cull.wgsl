// Culling per instance: one dispatch per view, over every chunk the CPU kept in it (a
// record each, their instances in one slab). Each invocation finds its record and
// tests one instance against the view and, when it may be seen, copies it into
// the chunk's kept instances in the view and counts it in the chunk's indirect draw
// arguments.
//
// Occlusion takes two phases in a view with a depth pyramid (a camera, a light's cascade).
// The early phase (before the frame's passes) also tests each instance against last frame's
// pyramid, seen from last frame's view: one hidden there is not kept but marked. The late
// phase (after the early depth prepass or shadow map has been reduced into this frame's
// pyramid) tests the marked ones against it and keeps those it does not hide, into the
// draw's second range. A blade seen this frame is kept by one of the two: what the early
// depth holds, the frame holds too.

#import rwt::fade::{Lod, kept_fraction, growth}

// The view's dispatch (`CullView`).
struct View {
    // The view's half-spaces (normal, distance; inside where dot(n, p) + d > 0).
    planes: array<vec4<f32>, 6>,
    // In a directional light's cascade, the half-spaces of where the camera reads its
    // shadows (grown by a margin), and the direction the light travels (w: 1; 0 where every
    // caster counts).
    receivers: array<vec4<f32>, 6>,
    light: vec4<f32>,
    // The view's clip space from world space: last frame's in the early phase, this
    // frame's in the late one.
    clip_from_world: mat4x4<f32>,
    // Where the level of detail is measured from: the view's camera, or the main camera
    // for shadow views.
    eye: vec3<f32>,
    // Occlusion's phase (0: none, 1: early, 2: late).
    phase: u32,
    // The view's first record and how many it has; its workgroups, and how many along x.
    first_record: u32,
    records: u32,
    workgroups: u32,
    workgroups_x: u32,
};

// One chunk in the view (`CullRecord`).
struct Record {
    // The chunk's corner; the radius around its root of an instance of scale 1, its sway
    // and any lean or tilt included.
    origin: vec3<f32>,
    reach: f32,
    // The class's shadow distance from the eye in a shadow view (negative: none).
    shadow_distance: f32,
    // Distance from the eye within which instances are not drawn (the start of an
    // impostor's crossfade; 0 for other chunks) and beyond which they are not (the end of a
    // mesh's crossfade with its impostors; 0: none).
    fade_in_from: f32,
    fade_out_to: f32,
    // The chunk's level of detail: fall-off, growth and far thinning.
    lod: Lod,
    // Instances in the chunk, the first in the slab; the view's first workgroup testing it.
    instances: u32,
    first_instance: u32,
    first_workgroup: u32,
    // Where its kept instances go (instances into the view's binding of the pool) and the
    // word of the draw's instance count: in the early phase, in the late one.
    kept: u32,
    late_kept: u32,
    count_word: u32,
    late_count_word: u32,
    // The chunk's first word of marks.
    first_mark: u32,
};

// Every chunk's instances.
@group(0) @binding(0) var<storage, read> instances: array<u32>;
// Every view's records, each view's in the order of their first workgroups.
@group(0) @binding(1) var<storage, read> records: array<Record>;
// Storage buffers, not uniforms: lavapipe compiles a variant of a shader for each set of
// the uniform values its branches read.
@group(0) @binding(2) var<storage, read> view: View;
// The view's kept instances (bound at its place in the frame's pool).
@group(0) @binding(3) var<storage, read_write> kept_instances: array<u32>;
@group(0) @binding(4) var<storage, read_write> args: array<atomic<u32>>;
// One bit per instance: hidden in the early phase, to be tested again in the late one.
@group(0) @binding(5) var<storage, read_write> marks: array<atomic<u32>>;
// The view's depth pyramid (reversed depth, each texel the farthest of those it covers).
@group(1) @binding(0) var pyramid: texture_2d<f32>;
// The pyramid's levels occlusion reads: Bevy's single-pass downsampling writes levels 5 and
// up from a single invocation per workgroup and then a second dispatch, and those levels
// dropped visible blades under lavapipe (`examples/gpu_occlusion`), where levels 0 to 4
// never did. A rectangle wider than that reads up to `MOST_TEXELS` a side on level 4.
const TRUSTED_LEVELS: u32 = 5u;
const MOST_TEXELS: u32 = 5u;

// Words of one instance (`GpuInstance`: offset and scale, yaw and appearance, tint and
// tilt).
const WORDS: u32 = 6u;

// The record of the view's workgroup `group`: the last whose first workgroup is not after
// it.
fn record_of(group: u32) -> u32 {
    var lo = view.first_record;
    var hi = view.first_record + view.records;
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        if records[mid].first_workgroup <= group {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// Whether a sphere's shadow may fall where the cascade is read: inside or across each of
// those half-spaces, or carried into it by the light (`receivers.rs`).
fn casts(center: vec3<f32>, radius: f32) -> bool {
    for (var k = 0u; k < 6u; k++) {
        let plane = view.receivers[k];
        let outside = dot(plane.xyz, center) + plane.w + radius <= 0.0;
        if outside && dot(plane.xyz, view.light.xyz) <= 0.0 {
            return false;
        }
    }
    return true;
}

// Whether the instance may be seen: grown, within the shadow distance, its sphere (widened
// as thinning widens it) inside or across every half-space and, in a cascade, casting where
// it is read.
fn seen(r: Record, root: vec3<f32>, scale: f32, widen: f32) -> bool {
    if scale <= 0.0 {
        return false;
    }
    let radius = r.reach * scale * widen;
    let from_eye = distance(root, view.eye);
    if r.shadow_distance >= 0.0 && from_eye - radius > r.shadow_distance {
        return false;
    }
    let beyond = r.fade_out_to > 0.0 && from_eye >= r.fade_out_to;
    if from_eye < r.fade_in_from || beyond {
        return false;
    }
    for (var k = 0u; k < 6u; k++) {
        let plane = view.planes[k];
        if dot(plane.xyz, root) + plane.w + radius <= 0.0 {
            return false;
        }
    }
    return view.light.w == 0.0 || casts(root, radius);
}

// The pyramid's farthest depth at `at` on `level`; 0 (hides nothing) off its edge.
fn farthest(at: vec2<u32>, level: u32) -> f32 {
    let size = textureDimensions(pyramid, level);
    if any(at >= size) {
        return 0.0;
    }
    return textureLoad(pyramid, at, level).x;
}

// Whether the pyramid hides the box of half side `radius` around `center`, seen through
// `clip_from_world`: the box's nearest depth is farther than the farthest depth of the
// texels its screen rectangle covers, read on the level where they are at most two by two,
// or on `TRUSTED_LEVELS`' last with at most `MOST_TEXELS` a side. Never hidden when any
// corner is behind the eye or past the near plane, or the rectangle leaves the screen.
fn hidden(center: vec3<f32>, radius: f32, clip_from_world: mat4x4<f32>) -> bool {
    var lo = vec2<f32>(1.0);
    var hi = vec2<f32>(0.0);
    var nearest = 0.0;
    // A corner's clip position is the center's plus or minus each axis's column times the
    // radius: one product with the matrix rather than eight.
    let middle = clip_from_world * vec4<f32>(center, 1.0);
    let x = clip_from_world[0] * radius;
    let y = clip_from_world[1] * radius;
    let z = clip_from_world[2] * radius;
    for (var i = 0u; i < 8u; i++) {
        let clip = middle + select(-x, x, (i & 1u) != 0u) + select(-y, y, (i & 2u) != 0u)
            + select(-z, z, (i & 4u) != 0u);
        if clip.w <= 0.0 {
            return false;
        }
        let ndc = clip.xyz / clip.w;
        let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
        lo = min(lo, uv);
        hi = max(hi, uv);
        nearest = max(nearest, ndc.z);
    }
    if nearest >= 1.0 || any(lo < vec2<f32>(0.0)) || any(hi > vec2<f32>(1.0)) {
        return false;
    }
    let pixels = (hi - lo) * vec2<f32>(textureDimensions(pyramid, 0));
    let wanted = u32(max(ceil(log2(max(max(pixels.x, pixels.y), 1.0))), 0.0));
    let level = min(wanted, min(TRUSTED_LEVELS, textureNumLevels(pyramid)) - 1u);
    let size = vec2<f32>(textureDimensions(pyramid, level));
    let first = vec2<u32>(lo * size);
    let last = vec2<u32>(hi * size);
    if any(last - first >= vec2<u32>(MOST_TEXELS)) {
        return false;
    }
    var far = 1.0;
    for (var y = first.y; y <= last.y; y++) {
        for (var x = first.x; x <= last.x; x++) {
            far = min(far, farthest(vec2<u32>(x, y), level));
        }
    }
    return nearest < far;
}

// Copies the slab's instance `at` into the view's kept instances at `first` (instances),
// counted in the arguments' word `count`.
fn keep(at: u32, first: u32, count: u32) {
    let w = at * WORDS;
    let to = (first + atomicAdd(&args[count], 1u)) * WORDS;
    for (var k = 0u; k < WORDS; k++) {
        kept_instances[to + k] = instances[w + k];
    }
}

@compute @workgroup_size(64)
fn cull_instances(
    @builtin(workgroup_id) workgroup: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    let group = workgroup.x + workgroup.y * view.workgroups_x;
    if group >= view.workgroups {
        return;
    }
    // Each invocation searches (no workgroup barrier: lavapipe runs a shader with one as
    // coroutines, several times slower).
    let r = records[record_of(group)];
    let i = (group - r.first_workgroup) * 64u + lane;
    if i >= r.instances {
        return;
    }
    let mark = r.first_mark + i / 32u;
    let bit = 1u << (i % 32u);
    let late = view.phase == 2u;
    if late && (atomicLoad(&marks[mark]) & bit) == 0u {
        return;
    }
    let at = r.first_instance + i;
    let w = at * WORDS;
    let offset = vec3<f32>(
        bitcast<f32>(instances[w]),
        bitcast<f32>(instances[w + 1u]),
        bitcast<f32>(instances[w + 2u]),
    );
    let root = r.origin + offset;
    // The appearance factor is the high half of the fifth word (the yaw is the low half).
    let appear = f32(instances[w + 4u] >> 16u) / 65535.0;
    let kept = kept_fraction(r.lod, view.eye.xz, root);
    let scale = bitcast<f32>(instances[w + 3u]) * growth(r.lod, view.eye.xz, root, appear, kept);
    if !seen(r, root, scale, 1.0 / kept) {
        return;
    }
    if view.phase != 0u && hidden(root, r.reach * scale / kept, view.clip_from_world) {
        if !late {
            atomicOr(&marks[mark], bit);
        }
        return;
    }
    if late {
        keep(at, r.late_kept, r.late_count_word);
    } else {
        keep(at, r.kept, r.count_word);
    }
}
