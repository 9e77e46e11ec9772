// Culling per instance: one dispatch per (view, chunk) the CPU kept. Each invocation tests
// one instance against the view and, when it may be seen, copies it into the view's kept
// instances and counts it in the chunk's indirect draw arguments.

struct Cull {
    // The view's half-spaces (normal, distance; inside where dot(n, p) + d > 0).
    planes: array<vec4<f32>, 6>,
    // Chunk corner (xyz); radius around its root of an instance of scale 1, its sway and
    // any lean or tilt included (w).
    origin: vec4<f32>,
    // Where the level of detail is measured from (xyz): the view's camera, or the main
    // camera for shadow views; the class's shadow distance from it (w; negative: none).
    eye: vec4<f32>,
    // Fall-off near, far, 1 when the fade is on, and its floor.
    falloff: vec4<f32>,
    // Fade band (x).
    fade: vec4<f32>,
    // Far thinning: its distance, its floor, 1 when on.
    thinning: vec4<f32>,
    // Instances in the chunk, the word of its draw's instance count in the arguments,
    // workgroups along x.
    slots: vec4<u32>,
};

@group(0) @binding(0) var<storage, read> instances: array<u32>;
@group(0) @binding(1) var<uniform> cull: Cull;
// The chunk's kept instances in this view (bound at its place in the frame's pool).
@group(0) @binding(2) var<storage, read_write> kept_instances: array<u32>;
@group(0) @binding(3) var<storage, read_write> args: array<atomic<u32>>;

// Words of one instance (`GpuInstance`: offset and scale, yaw and appearance, tint and
// tilt).
const WORDS: u32 = 6u;

// `instanced.wgsl`'s fraction kept by far thinning.
fn kept_fraction(root: vec3<f32>) -> f32 {
    let ratio = cull.thinning.x / max(length(root.xz - cull.eye.xz), 1e-3);
    let kept = clamp(ratio * ratio, cull.thinning.y, 1.0);
    return select(1.0, kept, cull.thinning.z != 0.0);
}

// `instanced.wgsl`'s growth: 0 until the level-of-detail factor at the root reaches the one
// at which the instance appears, then up to 1 over the fade band (1 without the fade); and
// as far thinning keeps it.
fn growth(root: vec3<f32>, appear: f32, kept: f32) -> f32 {
    let distance = length(root.xz - cull.eye.xz);
    let span = max(cull.falloff.y - cull.falloff.x, 1e-3);
    let factor = max(cull.falloff.w, clamp(1.0 - (distance - cull.falloff.x) / span, 0.0, 1.0));
    let grown = clamp((factor - appear) / cull.fade.x, 0.0, 1.0);
    let thinned = clamp((kept * (1.0 + cull.fade.x) - appear) / cull.fade.x, 0.0, 1.0);
    return select(grown, 1.0, cull.falloff.z == 0.0) * thinned;
}

// Whether the instance may be seen: grown, within the shadow distance, and its sphere
// (widened as thinning widens it) inside or across every half-space.
fn seen(root: vec3<f32>, scale: f32, widen: f32) -> bool {
    if scale <= 0.0 {
        return false;
    }
    let radius = cull.origin.w * scale * widen;
    if cull.eye.w >= 0.0 && distance(root, cull.eye.xyz) - radius > cull.eye.w {
        return false;
    }
    for (var k = 0u; k < 6u; k++) {
        let plane = cull.planes[k];
        if dot(plane.xyz, root) + plane.w + radius <= 0.0 {
            return false;
        }
    }
    return true;
}

@compute @workgroup_size(64)
fn cull_instances(
    @builtin(global_invocation_id) id: vec3<u32>,
) {
    let i = id.x + id.y * cull.slots.z * 64u;
    if i >= cull.slots.x {
        return;
    }
    let w = i * WORDS;
    let offset = vec3<f32>(
        bitcast<f32>(instances[w]),
        bitcast<f32>(instances[w + 1u]),
        bitcast<f32>(instances[w + 2u]),
    );
    let root = cull.origin.xyz + offset;
    // The appearance factor is the high half of the fifth word (the yaw is the low half).
    let appear = f32(instances[w + 4u] >> 16u) / 65535.0;
    let kept = kept_fraction(root);
    let scale = bitcast<f32>(instances[w + 3u]) * growth(root, appear, kept);
    if !seen(root, scale, 1.0 / kept) {
        return;
    }
    let to = atomicAdd(&args[cull.slots.y], 1u) * WORDS;
    for (var k = 0u; k < WORDS; k++) {
        kept_instances[to + k] = instances[w + k];
    }
}
